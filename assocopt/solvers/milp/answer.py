"""What the MILP back ends share around their solver call: the model built under the
clock, and the solver's answer unpacked into a :class:`~assocopt.solvers.base.RawResult`.

Every MILP back end reads its settings and answers an empty problem alike
(:func:`opening`), builds the same CSR model (:func:`built_model`), runs its solver
in this process or in a child that can be ended (:mod:`.limited`, which reports the
child's start-up as ``out["startup"]``: :func:`note_isolated`), and turns the point
the solver returns into a selection (the ILP: ``x > 0.5``, the variables being 0/1)
or into LP values and their objective (:func:`take_point`).
"""

from __future__ import annotations

import time
from typing import Any

import numpy as np

from ...model.formulation import LinearModel, build_model
from ...problems.problem import AssignmentProblem
from ..base import Backend, RawResult, SolveOptions, empty_answer

__all__ = ["opening", "built_model", "note_isolated", "take_point"]


def opening(backend: Backend, problem: AssignmentProblem, options: SolveOptions
            ) -> tuple[dict[str, Any], bool | None, RawResult | None]:
    """The back end's checked settings without ``isolate``, the ``isolate`` setting
    (:mod:`.limited`), and the answer when there is nothing to cover (None otherwise):
    settings are checked first, so a bad option is an error even on an empty problem."""
    extra = backend.settings(problem, options)
    isolate = extra.pop("isolate", None)
    return extra, isolate, empty_answer(problem, options, backend.name)


def built_model(problem: AssignmentProblem,
                options: SolveOptions) -> tuple[LinearModel, float, float]:
    """The ILP (or, with ``relax="lp"``, the LP) of ``problem`` and the clocks started
    just before building it: ``(model, t0, start)``, ``t0`` from
    :func:`time.perf_counter` (build time), ``start`` from :func:`time.monotonic` (the
    time limit counts from it)."""
    t0 = time.perf_counter()
    start = time.monotonic()
    return build_model(problem, options.relax), t0, start


def note_isolated(info: dict[str, Any], out: dict[str, Any]) -> dict[str, Any]:
    """``info`` with the seconds until the worker process had read the model (a new
    worker's start included; ``info["isolated"]``) when the solve ran in one."""
    if "startup" in out:
        info["isolated"] = round(out["startup"], 4)
    return info


def take_point(result: RawResult, x: np.ndarray | None, objective: float | None,
               is_mip: bool) -> RawResult:
    """``result`` with the solver's point, if it returned one: the chosen candidates of
    an ILP (values above 0.5), or an LP's values and objective."""
    if x is not None:
        if is_mip:
            result.selected = np.flatnonzero(x > 0.5)
        else:
            result.x = np.asarray(x, dtype=np.float64)
            result.objective = None if objective is None else float(objective)
    return result
