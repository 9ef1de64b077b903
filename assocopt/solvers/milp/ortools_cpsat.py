"""Google OR-Tools CP-SAT on the exact-cover ILP (integer costs required).

CP-SAT only takes integer objective coefficients, so float costs are multiplied by
a power of ten and rounded to int64.  When that rounding is exact (integer costs,
or decimals such as 0.25 with scale 100) CP-SAT's optimum is the true optimum; when
it is not, the lower bound accounts for the rounding (see :func:`_scaled_costs`), and
CP-SAT's optimum is reported ``OPTIMAL`` when that corrected bound is within the
relative gap every other back end counts as zero (:data:`~assocopt.solvers.status.GAP_ZERO`)
of the solution's true cost, else ``FEASIBLE``.

The CpModelProto is filled in bulk: all K Boolean variables in one
``variables.extend`` of a shared template, the objective with two numpy
``extend`` calls, and one ``exactly_one`` constraint per coverage row.

Extra options (``assocopt.solve(..., solver="ortools-cpsat", **extra)``):

``scale``  positive number, or ``"auto"`` (default): 1 for integer costs, else
           the largest ``10**k`` (k <= 12) keeping ``max|c| * scale * rows`` below
           1e15 (exact in float64) and ``sum|c| * scale`` below 2**62 (CP-SAT's
           int64 overflow check).
``num_workers``  CP-SAT workers (default :data:`DEFAULT_WORKERS` = 8 unless ``threads``
           is given; recorded in ``info``).
``seed``   CP-SAT ``random_seed`` (default 0).  Runs are reproducible with
           ``threads=1``; with several workers CP-SAT's portfolio is not
           deterministic in general (CP-SAT's default uses every core).
any other key is set on CP-SAT's ``SatParameters`` by name (``max_number_of_conflicts=...``,
``interleave_search=True``...); an unknown name is an error.
"""

from __future__ import annotations

import dataclasses
import math
import time
from typing import Any

import numpy as np

from ...runtime.errors import InvalidProblemError
from ...model.formulation import LinearModel
from ...problems.problem import AssignmentProblem
from ...model.solution import Status, relative_gap
from ..base import Backend, Option, RawResult, SolveOptions, register, remaining
from ..interruptible import run_cancellable
from .answer import built_model, note_isolated
from .limited import ISOLATE, solve_isolated_or_here
from ..status import GAP_ZERO, from_table, settle_optimal

__all__ = ["CpSatBackend", "run_model"]

#: Scaled objective magnitudes stay below this (integers exact in float64).
_MAX_SCALED_TOTAL = 1e15
#: Sum of |scaled coefficient| must stay below this (CP-SAT rejects possible int64 overflow).
_MAX_SCALED_SUM = 2.0 ** 62
#: CP-SAT workers when ``threads`` is not given.  CP-SAT's own default (one worker per
#: core) runs a 1-2 worker portfolio on a 2-core machine, which does not prove OR-Library
#: assign100 in 300 s; 8 workers (interleaved on the cores) prove it in about 3.5 s.
DEFAULT_WORKERS = 8
#: Largest decimal exponent "auto" scaling uses.
_MAX_EXPONENT = 12

# Native CP-SAT status -> assocopt status, before the rounding and gap refinements
# made in ``CpSatBackend._status``.  CP-SAT's FEASIBLE means "stopped before proving
# optimality" (our model always has an objective), i.e. a limit was hit.
_STATUS_TABLE: dict[str, Status] = {
    "OPTIMAL": Status.OPTIMAL,
    "FEASIBLE": Status.TIME_LIMIT,
    "INFEASIBLE": Status.INFEASIBLE,
    "UNKNOWN": Status.TIME_LIMIT,       # a limit stopped it before any solution
    "MODEL_INVALID": Status.ERROR,
}


def _auto_scale(costs: np.ndarray, n_rows: int) -> float:
    """The ``"auto"`` scale: 1 for (small enough) integer costs, else a power of ten."""
    amax = float(np.abs(costs).max(initial=0.0))
    asum = float(np.abs(costs).sum())
    if amax == 0.0:
        return 1.0

    def fits(s: float) -> bool:
        return amax * s * n_rows <= _MAX_SCALED_TOTAL and asum * s <= _MAX_SCALED_SUM

    if np.all(costs == np.round(costs)) and fits(1.0):
        return 1.0
    k = min(_MAX_EXPONENT, math.floor(math.log10(_MAX_SCALED_TOTAL / (amax * n_rows))))
    while not fits(10.0 ** k):          # the sum condition, or log10 rounding
        k -= 1
    return 10.0 ** k


def _scaled_costs(costs: np.ndarray, n_rows: int,
                  scale_opt: Any) -> tuple[float, np.ndarray, float]:
    """``(scale, int64 costs, max rounding error)`` for the ``scale`` option.

    The rounding error ``e = max_k |round(c_k * scale) / scale - c_k|`` turns CP-SAT's
    bound ``B`` on the scaled problem into a valid bound ``B / scale - rows * e`` on
    the original one: a feasible solution picks at most ``rows`` candidates (each
    covers at least one row, and rows are covered once).
    """
    scale = _auto_scale(costs, n_rows) if scale_opt == "auto" else float(scale_opt)
    scaled = costs * scale
    if float(np.abs(scaled).sum()) > _MAX_SCALED_SUM:
        raise InvalidProblemError(
            f"ortools-cpsat scale={scale:g} makes the integer objective overflow int64 "
            f"(sum |c| * scale must stay below 2**62); use a smaller scale")
    rounded = np.rint(scaled).astype(np.int64)
    max_err = float(np.abs(rounded / scale - costs).max(initial=0.0))
    return scale, rounded, max_err


def _apply_parameters(params: Any, options: SolveOptions, extra: dict[str, Any]) -> None:
    """Common options, then pass-through ``SatParameters`` fields from ``extra``
    (their names were checked by :func:`~assocopt.solvers.options.parse_options`)."""
    seed = extra.pop("seed")
    params.log_search_progress = bool(options.verbose)
    # CP-SAT's own SIGINT handler aborts the process (std::bad_function_call in
    # OR-tools 9.15); Python's handler and the worker thread handle Ctrl-C instead.
    params.catch_sigint_signal = False
    params.random_seed = int(seed)
    if options.time_limit is not None:
        params.max_time_in_seconds = float(options.time_limit)
    params.relative_gap_limit = float(options.mip_gap)
    if options.threads is not None:
        params.num_workers = int(options.threads)
    elif "num_workers" not in extra:
        params.num_workers = DEFAULT_WORKERS
    for key, value in extra.items():
        try:
            setattr(params, key, value)
        except (TypeError, ValueError) as exc:
            raise InvalidProblemError(
                f"ortools-cpsat option {key}={value!r} was rejected: {exc}") from exc


def run_model(model: LinearModel, icosts: np.ndarray, options: SolveOptions, *,
              time_limit: float | None = None) -> dict[str, Any]:
    """Fill a CP-SAT model with ``model``'s rows and the integer costs ``icosts`` and
    solve it in this process; what the result needs, as plain values (the same in a
    worker process, :mod:`.limited`).  ``time_limit`` replaces the options' limit (what
    is left of it)."""
    from ortools.sat.python import cp_model

    t0 = time.perf_counter()
    if time_limit is not None:
        options = dataclasses.replace(options, time_limit=time_limit)
    A, K, n_rows = model.A, model.shape[1], model.shape[0]
    cp = cp_model.CpModel()
    proto = cp.proto
    # Variables: one template proto copied K times.  Measured for K = 27 000 /
    # 1 000 000: extend 7 ms / 0.65 s; merge_text_format 17 ms / 1.0 s;
    # new_bool_var loop 72 ms / 4.2 s (new_bool_var_series is that loop in pandas).
    template = cp.new_bool_var("")
    proto.variables.extend([proto.variables[template.index]] * (K - 1))
    # Objective straight into the proto: the equivalent of LinearExpr.weighted_sum
    # without K Python variable objects (3 ms vs 60 ms for K = 27 000).
    proto.objective.vars.extend(np.arange(K, dtype=np.int64))
    proto.objective.coeffs.extend(icosts)
    indptr, indices = A.indptr, A.indices.astype(np.int64)
    for r in range(n_rows):           # one exactly-one constraint per coverage row
        proto.constraints.add().exactly_one.literals.extend(indices[indptr[r]:indptr[r + 1]])

    solver = cp_model.CpSolver()
    _apply_parameters(solver.parameters, remaining(options, t0), dict(options.extra))
    t1 = time.perf_counter()
    # in a worker thread: Ctrl-C calls stop_search and CP-SAT returns at once; so
    # does the deadline (CP-SAT's own clock is not looked at in every phase)
    native, _ = run_cancellable(solver.solve, (cp,), solver.stop_search, deadline=None
                                if options.time_limit is None else t0 + options.time_limit)
    t2 = time.perf_counter()
    response = solver.response_proto
    name = native.name
    has_solution = name in ("OPTIMAL", "FEASIBLE")
    values = np.fromiter(response.solution, dtype=np.int64, count=K) if has_solution \
        else None
    return {"status": name, "fill_time": t1 - t0, "solve_time": t2 - t1,
            "selected": None if values is None else np.flatnonzero(values > 0),
            "objective": float(response.objective_value),
            "bound": float(response.best_objective_bound),
            "num_workers": int(solver.parameters.num_workers),
            "random_seed": int(solver.parameters.random_seed),
            "num_conflicts": int(response.num_conflicts),
            "num_branches": int(response.num_branches),
            "wall_time": float(response.wall_time),
            "invalid": cp.validate() if name == "MODEL_INVALID" else ""}


@register
class CpSatBackend(Backend):
    """OR-Tools CP-SAT (clause learning + LP + portfolio search) on scaled integer costs."""

    name = "ortools-cpsat"
    module = "ortools"
    imports = ("ortools.sat.python.cp_model", "scipy.sparse")
    distribution = "ortools"
    description = "OR-Tools CP-SAT on the exact-cover ILP, costs scaled to integers"
    lp = False
    supports_time_limit = True
    exact_float_costs = False   # proves optimality of the integer-scaled costs only
    options = (
        Option("scale", "float", "auto", "cost scale before rounding to integers; 'auto': "
               "1 for integer costs, else the largest safe power of ten",
               low=0.0, low_open=True, high=math.inf, high_open=True, choices=("auto",)),
        Option("seed", "int", 0, "CP-SAT random_seed (reproducible with threads=1)"),
        ISOLATE,
    )
    native_options = "any CP-SAT SatParameters field by name (max_number_of_conflicts=...)"

    @classmethod
    def is_native_option(cls, name: str) -> bool:
        if not cls.is_available():
            return False
        from ortools.sat import sat_parameters_pb2
        return name in sat_parameters_pb2.SatParameters.DESCRIPTOR.fields_by_name

    def solve(self, problem: AssignmentProblem, options: SolveOptions) -> RawResult:
        extra = self.settings(problem, options)
        scale_opt = extra.pop("scale")
        isolate = extra.pop("isolate", None)
        model, t0, start = built_model(problem, options)
        n_rows = model.shape[0]
        scale, icosts, max_err = _scaled_costs(model.c, n_rows, scale_opt)
        sub = SolveOptions(relax=options.relax, time_limit=options.time_limit,
                           mip_gap=options.mip_gap, threads=options.threads,
                           verbose=options.verbose, extra=extra, parsed=True)
        t1 = time.perf_counter()
        out = solve_isolated_or_here(self.name, run_model, (model, icosts, sub), options,
                                     isolate, start, t0, t1)
        if isinstance(out, RawResult):
            return out
        name = out["status"]
        info: dict[str, Any] = {
            "cpsat_status": name, "cpsat_scale": scale, "max_rounding_error": max_err,
            "num_workers": out["num_workers"],
            "num_workers_source": ("threads" if options.threads is not None else
                                   "option" if "num_workers" in options.extra else
                                   "assocopt default (CP-SAT's portfolio needs several "
                                   "workers even on small machines)"),
            "random_seed": out["random_seed"], "num_conflicts": out["num_conflicts"],
            "num_branches": out["num_branches"], "cpsat_wall_time": out["wall_time"],
        }
        note_isolated(info, out)
        # the proto's filling counts as building, as it did in this process
        result = RawResult(status=Status.ERROR, info=info,
                           build_time=t1 - t0 + out["fill_time"], solve_time=out["solve_time"])
        if out["selected"] is not None:
            result.selected = out["selected"]
            info["cpsat_objective"] = out["objective"]
            info["cpsat_bound"] = out["bound"]
            # Bound on the scaled problem -> valid bound on the original costs.
            result.bound = out["bound"] / scale - n_rows * max_err
            true_cost = math.fsum(model.c[out["selected"]].tolist())
            info["rounding_gap"] = relative_gap(true_cost, result.bound)
        result.status, result.message = self._status(name, out, max_err, options,
                                                     info.get("rounding_gap"))
        return result

    @staticmethod
    def _status(name: str, out: dict[str, Any], max_err: float,
                options: SolveOptions, rounding_gap: float | None = None
                ) -> tuple[Status, str]:
        """Map CP-SAT's status through ``_STATUS_TABLE``, then refine OPTIMAL.

        ``rounding_gap``: the relative gap between the solution's cost in the
        original costs and the rounding-corrected bound."""
        status = from_table(_STATUS_TABLE, name)
        message = f"CP-SAT: {name}"
        if name == "MODEL_INVALID":
            return status, f"CP-SAT: model invalid: {out['invalid']}"
        if status is not Status.OPTIMAL:
            return status, message
        gap = relative_gap(out["objective"], out["bound"])
        if max_err > 0.0:
            if rounding_gap is not None and rounding_gap <= GAP_ZERO:
                return Status.OPTIMAL, (
                    f"CP-SAT: OPTIMAL for costs rounded to 1/scale (max rounding error "
                    f"{max_err:.3g}); the bound corrected for the rounding is within "
                    f"relative gap {rounding_gap:.3g} of the original costs' objective")
            return Status.FEASIBLE, (
                f"CP-SAT: optimal for costs rounded to 1/scale (max rounding error "
                f"{max_err:.3g}); only near-optimal for the original costs, bound "
                "corrected for the rounding")
        status, note = settle_optimal(status, gap, options.mip_gap)
        return status, f"CP-SAT: {note}" if note else message
