"""Options of the Lagrangian back ends: their declarations, and the engine checks.

Kept apart from the algorithm so that the option set (documented in the package
docstring) can be read in one place.  Values are checked by the one parser of
:mod:`assocopt.solvers.options`; :func:`check_engines` adds the one check that
depends on what is installed.  :data:`OPT_TOL` and the kept-axes rule live in
:mod:`assocopt.problems.problem` and are re-exported here.
"""

from __future__ import annotations

from typing import Any

from ...runtime.errors import SolverNotInstalledError
from ...problems.problem import OPT_TOL, kept_axes
from ..twod.lap import LAP_METHODS, lapx_available
from ..options import Option

__all__ = ["OPT_TOL", "OPTIONS", "OPTIONS_EXACT", "check_engines", "resolve_defaults"]

#: Values of the options declared None, on the dense square 3-D grids whose ascent
#: runs compiled (:mod:`.compiled_ascent`) and elsewhere.  Measured on the 120 public
#: 3-AP instances: a half step first (the incumbent the Polyak step aims at is far
#: above the bound early on, and the full step overshot: no better bound for the first
#: 10-20 iterations at n = 50) and a recovery every third iteration (its LAP cost as
#: much as the evaluation's) took 25-30% off the total; on gated tracking scans (not
#: grids) the half step doubled the iterations, so it stays 1.0 there.  Then a
#: patience of 7 and a stall share of 0.1 (the ascent stops once the bound gains less
#: than a tenth of the gap in ``stall_iter`` iterations: with integer costs the bound
#: reaches its final ceiling after 25-75 of 150-210 iterations at n = 50, and the
#: windows make up for the last hundredths).  The share was 0.003 until it was tuned
#: on Grundel n = 30-40 and Balas-Saltzman n = 20-26 (0.82 -> 0.62-0.76 s for the 40,
#: noisy) and checked on Grundel n = 50, not tuned on (0.80-0.91 -> 0.53 s).
GRID_DEFAULTS = {"step0": 0.5, "recover_every": 3, "patience": 7, "stall_tol": 0.1}
OTHER_DEFAULTS = {"step0": 1.0, "recover_every": 1, "patience": 10, "stall_tol": 1e-3}


def resolve_defaults(p: dict[str, Any], grid: bool) -> dict[str, Any]:
    """Fill the options left None in ``p`` (in place) for a grid or not; returns
    what was filled."""
    table = GRID_DEFAULTS if grid else OTHER_DEFAULTS
    filled = {k: v for k, v in table.items() if p.get(k) is None}
    p.update(filled)
    return filled


def _options(exact: bool) -> tuple[Option, ...]:
    """The declared options of ``lagrangian`` (``exact=False``) or ``lagrangian-exact``."""
    opts = [
        Option("max_iter", "int", 500 if exact else 1000, "subgradient iterations", low=0),
        Option("gap_tol", "float", 0.0 if exact else 1e-4, "relative gap that stops the "
               "ascent (exact mode: 0, or mip_gap)", low=0.0),
        Option("step0", "float", None, "initial Polyak step scale (None: 0.5 on dense "
               "square 3-D grids, else 1.0)", low=0.0, low_open=True, high=2.0,
               nullable=True),
        Option("step_decay", "float", 0.5, "factor applied to the step scale after "
               "`patience` iterations without a better bound", low=0.0, low_open=True,
               high=1.0),
        Option("patience", "int", None, "iterations without a better bound before the "
               "step scale decays (None: 7 on dense square 3-D grids, else 10)", low=1,
               nullable=True),
        Option("step_min", "float", 1e-4, "step scale at which the ascent stops", low=0.0),
        Option("deflect", "float", 0.5, "momentum: share of the previous direction kept",
               low=0.0, high=0.99),
        Option("recover_every", "int", None, "primal recovery every k iterations (0: "
               "never; None: 3 on dense square 3-D grids, else 1)", low=0, nullable=True),
        Option("keep_axes", "axes", None, "the two axes kept in the 2-D subproblem (None: "
               "the two largest)", nullable=True),
        Option("lap", "choice", "auto", "2-D assignment engine", choices=LAP_METHODS),
        Option("reduce", "bool", True, "drop dominated candidates first (exact rule)"),
        Option("gate", "float", None, "heuristic gate: drop multi-index candidates costing "
               "more (answer then FEASIBLE, no bound)", nullable=True),
        Option("return_history", "bool", False, "per-iteration bound, best bound and "
               "objective in info['history']"),
        Option("stall_iter", "int", 60, "exact mode: iterations over which the bound must "
               "gain stall_tol of the gap", low=1),
        Option("stall_tol", "float", None, "exact mode: share of the gap the bound must "
               "gain in stall_iter iterations to go on (None: 0.1 on dense square 3-D "
               "grids, else 0.001)", low=0.0, nullable=True),
        Option("local_search", "bool", True, "axis-wise re-assignment of record solutions "
               "(exact mode: above 2,000 candidates)"),
        Option("init", "choice", "share", "starting multipliers", choices=("share", "zero")),
    ]
    if exact:
        opts.append(Option("window_solver", "choice", "auto", "engine for the candidate "
                           "windows that close the gap", choices=("auto", "highs", "cpsat")))
    return tuple(opts)


OPTIONS = _options(exact=False)
OPTIONS_EXACT = _options(exact=True)
_COMMON = {o.name: o.default for o in OPTIONS}
_EXACT = {o.name: o.default for o in OPTIONS_EXACT}


def check_engines(p: dict[str, Any]) -> None:
    """The check that depends on what is installed: ``lap='lapx'`` needs lapx."""
    if p["lap"] == "lapx" and not lapx_available():
        raise SolverNotInstalledError("option lap='lapx' needs the Python package 'lapx': "
                                      "pip install lapx")


def _parse(extra: dict[str, Any], exact: bool, name: str) -> dict[str, Any]:
    """Defaults merged with ``extra``, each option checked (kept for old callers)."""
    from ..base import get_backend

    p = get_backend(name).parse_options(extra)
    check_engines(p)
    return p


def _keep_axes(sizes: tuple[int, ...], keep: Any) -> tuple[int, int]:
    """The two kept axes (see :func:`assocopt.problems.problem.kept_axes`)."""
    return kept_axes(sizes, keep)


