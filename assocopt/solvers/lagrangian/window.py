"""Exact solving of candidate *windows* (exact mode): search, CP-SAT and HiGHS.

A window is a subset of the candidates left by reduced-cost fixing.  Small windows
go to the depth-first exact-cover search :func:`_cover_search`, integer-cost ones of
moderate size to CP-SAT (:func:`_cpsat`), the rest to HiGHS (:func:`_ilp`).  The
tuning constants that route windows between them live here too; the policy that
grows windows is :meth:`~.backend._LagrangianBase._close_gap`.
"""

from __future__ import annotations

import enum
import math
import time
from typing import TYPE_CHECKING, Any

import numpy as np

from ...problems.problem import AssignmentProblem
from ..base import SolveOptions, module_installed
from .ascent import _State
from .options import OPT_TOL

if TYPE_CHECKING:
    import scipy.sparse as sp

#: During the ascent, fixing windows up to this size are tried by a short search
#: (8 times as many with the compiled search), ``_PROBE_SEARCH_SMALL`` on candidate
#: sets of at most :data:`.ascent.PROBE_LARGE`: there the windows shrink fast between
#: probes, and a window of 520-640 candidates can take thousands of nodes (1.5 ms)
#: that the next probe's smaller window saves.  Measured interleaved on the gated
#: N = 4-6 scans' components of 700-5,000 candidates: 4/500/1.5 40.3 -> 34.8 ms
#: (seeds 51-52), 35.3 -> 32.5 ms (71-72), the rest level; 50 (400) was as quick
#: there but slower on multi-frame windows (292 -> 315 ms over 42 problems).
_PROBE_SEARCH_MAX = 80
_PROBE_SEARCH_SMALL = 65
#: Windows of at most this many candidates are first tried by :func:`_cover_search`
#: with at most this many nodes (about 25 ms): it settles most windows in
#: milliseconds (the reduced costs prune hard), and gives up quickly on the rest
#: (Balas-Saltzman windows of 200+ candidates), which go to CP-SAT or HiGHS.
_SEARCH_MAX = 2000
_SEARCH_NODES = 5000
#: With numba installed the compiled search (:func:`_compiled_search`) takes every
#: window first, with this many nodes (tens of milliseconds).
_COMPILED_NODES = 100_000
#: Windows up to this many candidates (integer costs) go to CP-SAT, larger ones to
#: HiGHS: CP-SAT settles the small exact-cover windows of Balas-Saltzman instances
#: several times faster, HiGHS's LP wins on large ones (measured, Grundel n = 50).
_CPSAT_MAX = 1500
#: Seconds CP-SAT may spend on one window before HiGHS takes it over.
_CPSAT_BUDGET = 1.0
#: Extra HiGHS settings for the restricted ILPs.  Empty: turning presolve or
#: feasibility jump off was tried on Grundel n = 50 and did not pay, so HiGHS runs
#: with its defaults (plus the objective target set below).
_HIGHS_OPTIONS: dict[str, Any] = {}


class Outcome(str, enum.Enum):
    """What solving one window settled, whichever engine ran (search, CP-SAT, HiGHS).

    ``OPTIMAL``: the window's best solution was found (or, with no objective or one
    at least the cap, none below the cap exists); ``NONE_BELOW``: proven that nothing
    in the window costs less than the cap; ``AT_BOUND``: a solution at the proven
    lower bound was found (so it is optimal); ``LIMIT``: a time limit stopped the
    engine; ``ERROR``: the engine failed (its own status is in the window record);
    ``GAVE_UP``: nothing settled, the next window decides.
    """

    OPTIMAL = "optimal"
    NONE_BELOW = "none_below_cap"
    AT_BOUND = "at_bound"
    LIMIT = "limit"
    ERROR = "error"
    #: the compiled search spent its nodes on a window that is not the last: a larger
    #: window (which holds this one) decides instead of CP-SAT or HiGHS (see
    #: :mod:`.policy`)
    GAVE_UP = "gave_up"

    def __str__(self) -> str:
        return self.value


#: HiGHS model status -> window outcome (the objective target is the proven bound).
_HIGHS_OUTCOME: dict[str, Outcome] = {
    "kOptimal": Outcome.OPTIMAL, "kInfeasible": Outcome.NONE_BELOW,
    "kObjectiveTarget": Outcome.AT_BOUND, "kTimeLimit": Outcome.LIMIT,
    "kInterrupt": Outcome.LIMIT,
}


def _grow(n: int, integer: bool) -> int:
    """Least size of the next window: integer thresholds step by one unit while that
    grows the window by a quarter; real ones double it."""
    return int(n * (1.25 if integer else 2.0)) + 1


def _has_numba() -> bool:
    return module_installed("numba")


def _compiled_search(problem: AssignmentProblem, pos: np.ndarray, red: np.ndarray,
                     base: float, cap: float, integer: bool, node_limit: int,
                     floor: float = -math.inf) -> tuple[np.ndarray | None, bool]:
    """:func:`_cover_search` compiled (the ``bnb`` kernels' depth-first search):
    same contract, about a hundred times faster per node.

    The candidates every cover below the limit must use are taken first (unit
    propagation, :func:`assocopt.solvers.kernels.forcing.window_lists`) and the
    search runs on the rows they leave: on a gated N = 4 scan's 419-candidate window,
    102 forced and 163 of 443 rows left (each node scans every uncovered row)."""
    from ..bnb import kernels as kern

    T = np.ascontiguousarray(problem.tuples[pos], np.int64)
    c = np.ascontiguousarray(problem.costs[pos], np.float64)
    rp = np.ascontiguousarray(red, np.float64)
    sizes = np.asarray(problem.sizes, np.int64)
    work = len(pos)                          # small: the kernels may run interpreted
    limit = kern.pick_fixed(kern.name("improve_limit"), cap, integer, OPT_TOL,
                            work=work)(cap, integer, OPT_TOL)
    args = (T, c, problem.row_offsets, sizes, rp, limit - base)
    status, forced, rest, c0, r0, G, sptr, slst, axis_of, c2, rp2 = kern.pick_fixed(
        "forcing.window_lists", *args, work=work)(*args)
    if status:                               # a row has no candidate below the limit
        return None, True
    if len(rest) == 0:                       # the forced candidates cover every row
        return (pos[np.sort(forced)] if c0 < limit else None), True
    best = np.full(len(sptr), -1, np.int64)
    from ..interruptible import new_stop

    stop = new_stop()
    args = (G, c2, rp2, base + r0, sptr, slst, axis_of, problem.ndim, integer, OPT_TOL,
            cap, best, -1, node_limit, stop, float(floor), c0)
    (out, _, n, _), _ = kern.run_tiered(kern.name("dfs"), args, stop, work=work,
                                        inline=node_limit <= 20_000, fixed=True)
    sel = np.sort(np.concatenate([forced, rest[best[:n]]])) if n > 0 else None
    return (pos[sel] if sel is not None else None), out == kern.COMPLETE


def _has_ortools() -> bool:
    return module_installed("ortools")


def _uncovered(problem: AssignmentProblem, pos: np.ndarray) -> np.ndarray:
    """Constraint rows that none of the candidates ``pos`` covers."""
    return problem.uncovered_rows(pos)


def _coverage(problem: AssignmentProblem, pos: np.ndarray) -> sp.csr_matrix:
    """The coverage matrix of the candidates ``pos`` (one column each)."""
    return problem.coverage_matrix(pos)


def _cover_search(problem: AssignmentProblem, pos: np.ndarray, red: np.ndarray,
                  base: float, cap: float, node_limit: int = 20_000,
                  floor: float = -math.inf) -> tuple[np.ndarray | None, bool]:
    """Cheapest exact cover by the candidates ``pos`` costing less than ``cap``
    (``floor``: a lower bound proven elsewhere; a cover reaching it ends the search).

    Depth-first branch and bound for small windows.  Every solution ``S`` costs at
    least ``base + sum_{k in S} red[k]`` (``red >= 0``, from the Lagrangian duals, see
    :meth:`_Relaxation.fixing_bounds`); a branch is cut when that bound, plus for each
    uncovered row the least share ``red[k] / rows(k)`` of a candidate covering it,
    reaches the cap or the best cost found.  Branches on the uncovered row with the
    fewest usable candidates (Knuth's rule for exact cover), cheapest reduced cost
    first.  Returns ``(selection or None, complete)``;
    ``complete`` is False when the node limit stopped the search (nothing proven).
    """
    K = len(pos)
    rows_of = problem.rows_of(problem.tuples[pos]).tolist()
    cost = problem.costs[pos].tolist()
    rd = np.asarray(red, np.float64).tolist()
    cols = [[r for r in rk if r >= 0] for rk in rows_of]
    masks = [sum(1 << r for r in rows) for rows in cols]
    R = problem.n_rows
    by_row: list[list[int]] = [[] for _ in range(R)]
    for k in range(K):
        if math.isfinite(rd[k]):
            for r in cols[k]:
                by_row[r].append(k)
    if any(not b for b in by_row):
        return None, True
    for b in by_row:
        b.sort(key=lambda k: (rd[k], cost[k]))
    share = [min(rd[k] / len(cols[k]) for k in b) for b in by_row]
    msum = [sum(share[r] for r in cols[k]) for k in range(K)]
    full = (1 << R) - 1
    tol = OPT_TOL * max(1.0, abs(cap)) if math.isfinite(cap) else 0.0
    best = [cap - tol, None]
    nodes = [0]
    chosen: list[int] = []
    reach = floor + OPT_TOL * max(1.0, abs(floor)) if math.isfinite(floor) else -math.inf
    done = [False]

    def search(covered: int, acc: float, racc: float, rest: float) -> bool:
        if covered == full:
            if acc < best[0]:
                best[0], best[1] = acc, list(chosen)
                if acc <= reach:                 # optimal: stop the whole search
                    done[0] = True
                    return False
            return True
        nodes[0] += 1
        if nodes[0] > node_limit:
            return False
        if base + racc + rest >= best[0]:
            return True
        # branch on the uncovered row with the fewest usable candidates
        opts = None
        free = ~covered & full
        while free:
            low = free & -free
            r = low.bit_length() - 1
            free ^= low
            o = [k for k in by_row[r] if not masks[k] & covered]
            if opts is None or len(o) < len(opts):
                opts = o
                if len(o) <= 1:
                    break
        for k in opts:
            r2 = racc + rd[k]
            if base + r2 >= best[0]:
                break                    # sorted by red: the rest cannot do better
            chosen.append(k)
            ok = search(covered | masks[k], acc + cost[k], r2, rest - msum[k])
            chosen.pop()
            if not ok:
                return False
        return True

    complete = search(0, 0.0, 0.0, sum(share)) or done[0]
    sel = None if best[1] is None else np.sort(pos[np.array(best[1], np.int64)])
    return sel, complete


def _ilp(problem: AssignmentProblem, pos: np.ndarray, st: _State, options: SolveOptions,
         deadline: float | None, target: float | None, start: bool
         ) -> tuple[Outcome, float | None, str]:
    """HiGHS on the candidates ``pos``; offers any solution found to ``st``.

    ``target``: stop as soon as a solution this good is found (it is then optimal:
    ``target`` is a proven lower bound).  ``start``: pass the incumbent (which must be
    among ``pos``) as the starting solution.  Returns HiGHS's model status name and
    the objective of its solution (None when it has none), as
    ``(outcome, objective, HiGHS's status name)``.
    """
    import highspy

    from ...model.formulation import LinearModel
    from ..milp.highs import highs_from_model, run_highs

    K = len(pos)
    model = LinearModel(c=problem.costs[pos].astype(np.float64), A=_coverage(problem, pos),
                        row_lower=np.ones(problem.n_rows), row_upper=np.ones(problem.n_rows),
                        lb=np.zeros(K), ub=np.ones(K), integrality=np.ones(K, np.uint8))
    limit = None if deadline is None else max(deadline - time.perf_counter(), 1e-3)
    extra: dict[str, Any] = dict(_HIGHS_OPTIONS)
    if target is not None and math.isfinite(target):
        extra["objective_target"] = float(target)
    h = highs_from_model(model, SolveOptions(time_limit=limit, mip_gap=0.0,
                                             threads=options.threads,
                                             verbose=options.verbose, extra=extra))
    if start and st.incumbent is not None:
        x0 = highspy.HighsSolution()
        x0.col_value = np.isin(pos, st.incumbent).astype(np.float64).tolist()
        x0.value_valid = True
        h.setSolution(x0)
    run_highs(h, deadline)            # a worker thread: Ctrl-C and the deadline stop it
    status = h.getModelStatus().name
    z = None
    if h.getInfo().primal_solution_status == 2:
        sel = pos[np.asarray(h.getSolution().col_value) > 0.5]
        if problem.violations(sel) is None:
            st.offer(sel)
            z = math.fsum(problem.costs[sel].tolist())
    return _HIGHS_OUTCOME.get(status, Outcome.ERROR), z, status


def _cpsat(problem: AssignmentProblem, pos: np.ndarray, st: _State, options: SolveOptions,
           deadline: float | None, lo: float, cap: float, start: bool
           ) -> tuple[Outcome, float | None]:
    """CP-SAT on the candidates ``pos`` (integer costs), objective at most ``cap``.

    ``lo`` (a proven lower bound) is not passed to CP-SAT, see below; ``cap`` is the
    largest objective of interest.  Returns ``(Outcome.OPTIMAL, z)``,
    ``(Outcome.NONE_BELOW, None)`` (nothing in the window costs at most ``cap``) or
    ``(Outcome.LIMIT, z)``.
    """
    from ortools.sat.python import cp_model

    K = len(pos)
    m = cp_model.CpModel()
    x = [m.NewBoolVar("") for _ in range(K)]
    A = _coverage(problem, pos)
    for r in range(problem.n_rows):
        m.AddExactlyOne([x[k] for k in A.indices[A.indptr[r]:A.indptr[r + 1]].tolist()])
    cost = problem.costs[pos].astype(np.int64).tolist()
    obj = cp_model.LinearExpr.WeightedSum(x, cost)
    m.Add(obj <= int(math.floor(cap)))
    # no "obj >= lo" constraint: with cap == lo it turns the cut into an equality,
    # which CP-SAT propagates poorly (measured: seconds instead of milliseconds)
    m.Minimize(obj)
    if start and st.incumbent is not None:
        on = np.isin(pos, st.incumbent)
        for k in range(K):
            m.AddHint(x[k], bool(on[k]))
    solver = cp_model.CpSolver()
    solver.parameters.num_workers = int(options.threads or 1)
    solver.parameters.log_search_progress = bool(options.verbose)
    if deadline is not None:
        solver.parameters.max_time_in_seconds = max(deadline - time.perf_counter(), 1e-3)
    solver.parameters.catch_sigint_signal = False     # see solvers.milp.ortools_cpsat
    from ..interruptible import run_cancellable
    code, _ = run_cancellable(solver.Solve, (m,), solver.stop_search)    # Ctrl-C at once
    z = None
    if code in (cp_model.OPTIMAL, cp_model.FEASIBLE):
        sel = pos[np.array([solver.BooleanValue(v) for v in x], bool)]
        if problem.violations(sel) is None:
            st.offer(sel)
            z = math.fsum(problem.costs[sel].tolist())
    if code == cp_model.OPTIMAL:
        return Outcome.OPTIMAL, z
    if code == cp_model.INFEASIBLE:
        return Outcome.NONE_BELOW, None
    return Outcome.LIMIT, z
