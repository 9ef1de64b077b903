"""The registered back ends ``lagrangian`` and ``lagrangian-exact``.

:class:`_LagrangianBase` runs a solve: candidate reduction, the ascent, (exact mode)
fixing probes and the window loop that closes the gap, then the result and its
status.  The two subclasses only set the name and the mode; ``@register`` adds them
to the registry when :mod:`assocopt.solvers` is imported.
"""

from __future__ import annotations

import math
import time
from typing import Any, Callable

import numpy as np

from ...problems.problem import AssignmentProblem
from ...model.solution import Status
from ..base import Backend, RawResult, SolveOptions, register
from ..kernels import spent
from ..twod.lap import LapInfeasibleError
from .ascent import PROBE_LARGE, _State, _ascent
from .compiled_ascent import _ascent_grid, applies
from .fixing import fixing_bounds, fixing_order, make_probe
from .local_search import _LocalSearch
from .options import OPTIONS, OPTIONS_EXACT, check_engines, resolve_defaults
from .reduction import dominated
from .relaxation import _Relaxation
from .policy import _OPEN_NODES, _SKIP_NODES, _SPLIT_MIN, _Skipper, _by_components, _search
from .window import (_COMPILED_NODES, _CPSAT_BUDGET, _CPSAT_MAX, _PROBE_SEARCH_MAX,
                     _PROBE_SEARCH_SMALL, _SEARCH_MAX, _SEARCH_NODES, _cpsat,
                     Outcome, _grow, _has_numba, _has_ortools, _ilp, _uncovered)

#: Dense axial 3-AP grids run the whole ascent compiled (:mod:`.compiled_ascent`);
#: False: the Python loop with the compiled evaluation (kept for comparisons).
_COMPILED_ASCENT = True
#: The exact mode runs the local search only above this many candidates.
_LS_MIN_K = 2000


class _LagrangianBase(Backend):
    """One solve of either mode; ``_exact`` switches on the exact phase."""

    integer = True
    lp = False
    gives_bound = True
    supports_time_limit = True
    _exact: bool = False
    own_method = True

    def solve(self, problem: AssignmentProblem, options: SolveOptions) -> RawResult:
        t_start = time.perf_counter()
        self._kernels0 = sum(spent())   # compiled window search: timed apart
        p = self.settings(problem, options)
        check_engines(p)
        if self._exact and options.mip_gap > 0:
            p["gap_tol"] = max(p["gap_tol"], options.mip_gap)
        deadline = None if options.time_limit is None else t_start + options.time_limit
        keep = problem.kept_axes(p["keep_axes"])
        c = problem.costs
        integer = problem.integer_costs
        st = _State(costs=c, integer=integer,
                    history={"bound": [], "best_bound": [], "objective": []}
                    if p["return_history"] else None)
        times: dict[str, float] = {}
        ncand: dict[str, Any] = {"input": problem.n_candidates}
        info: dict[str, Any] = {"parameters": {**p, "keep_axes": list(keep)},
                                "kept_axes": list(keep), "integer_costs": integer,
                                "candidates": ncand, "phase_times": times}

        # ---- candidate reduction (dominance: exact; gate: heuristic)
        t0 = time.perf_counter()
        pos = np.arange(problem.n_candidates)
        if p["reduce"]:
            drop = dominated(problem.sizes, problem.tuples, c)
            if drop.any():
                pos = pos[~drop]
            ncand["after_dominance"] = len(pos)
        gated = False
        if p["gate"] is not None:
            T = problem.tuples[pos]
            drop = ((T > 0).sum(axis=1) >= 2) & (c[pos] > p["gate"])
            gated = bool(drop.any())
            pos = pos[~drop]
            ncand["after_gate"] = len(pos)
        times["reduce"] = time.perf_counter() - t0

        # ---- ascent on the (reduced) candidate set
        t0 = time.perf_counter()
        try:
            whole = len(pos) == problem.n_candidates     # no copies of a dense grid
            rel = _Relaxation(problem.sizes, problem.tuples if whole else problem.tuples[pos],
                              c if whole else c[pos], keep, p["lap"])
            info["lap_structure"] = "uniform" if rel.uniform else "grouped"
            compiled = _COMPILED_ASCENT and applies(rel)
            info["parameters"].update(resolve_defaults(p, compiled))
            st.theta = p["step0"]
            upad = rel.initial_multipliers() if p["init"] == "share" else np.zeros(rel.u_len)
            # local search pays off on large problems; on small ones the exact mode's
            # fixing and window search settle the incumbent faster without it
            use_ls = p["local_search"] and (not self._exact or problem.n_candidates > _LS_MIN_K)
            ls = _LocalSearch(problem.sizes, problem.tuples, c) if use_ls else None
            probe = self._probe(rel, pos, st, problem) if self._exact else None
            run = _ascent_grid if compiled else _ascent
            upad = run(rel, pos[rel.pos], upad, st, p, deadline, self._exact, ls, probe)
        except LapInfeasibleError as exc:
            times["ascent"] = time.perf_counter() - t0
            if gated:
                return self._result(Status.ERROR, st, info, t_start,
                                    "the heuristic gate left no feasible assignment "
                                    f"of the kept axes ({exc}); raise or drop 'gate'")
            return self._result(Status.INFEASIBLE, st, info, t_start,
                                f"{self.name}: infeasible -- even the relaxed 2-D "
                                f"problem on axes {keep} has no assignment ({exc})")
        times["ascent"] = time.perf_counter() - t0
        info["ascent_stop"] = st.stop
        if self._exact and st.stop not in ("proven", "time_limit", "gap_tol"):
            self._close_gap(problem, rel, pos, upad, st, p, options, deadline, info, times)
        if st.incumbent is None and problem.n_candidates <= 200_000 and \
                (deadline is None or time.perf_counter() < deadline):
            from ..baseline.greedy import greedy_select
            sel, covered = greedy_select(problem)
            if covered.all():
                st.offer(sel)
                info["incumbent_from"] = "greedy"
        return self._finish(st, info, t_start, gated, options)

    # ------------------------------------------------------------- exact phase
    @staticmethod
    def _probe(rel: _Relaxation, pos: np.ndarray, st: _State, problem: AssignmentProblem
               ) -> Callable[[np.ndarray], str | None]:
        """Reduced-cost fixing test run now and then during the ascent (exact mode):
        stop when it proves the incumbent, or leaves a window small enough to search
        (:func:`.fixing.make_probe`)."""
        small = rel.K <= PROBE_LARGE
        return make_probe(rel, pos, st, problem, _has_numba(),
                          _PROBE_SEARCH_SMALL if small else _PROBE_SEARCH_MAX)

    def _close_gap(self, problem: AssignmentProblem, rel: _Relaxation, pos: np.ndarray,
                   upad: np.ndarray, st: _State, p: dict[str, Any], options: SolveOptions,
                   deadline: float | None, info: dict[str, Any], times: dict[str, float]
                   ) -> None:
        """Reduced-cost fixing, then ILPs over growing windows of the candidates.

        With the final multipliers, ``lb[k]`` bounds every solution that uses
        candidate k.  For a threshold ``T`` the *window* is ``{k : lb[k] < T}``: every
        solution outside it costs at least ``T``.  So if the best solution inside the
        window costs less than ``T`` it is optimal, and if none does, ``T`` is a new
        lower bound.  Windows grow (by candidate count) until ``T`` reaches the
        incumbent, whose window (with the incumbent added) is the classic fixing
        step.  Each window goes to its components (when it splits), the cover search,
        CP-SAT or HiGHS (see ``window``).
        """
        t0 = time.perf_counter()
        lb, red, base = fixing_bounds(rel, upad)
        gpos = pos[rel.pos]
        red_of = np.full(problem.n_candidates, np.inf)
        red_of[gpos] = red
        lo = float(math.ceil(st.bound - 1e-6)) if st.integer else st.bound
        lb, order = fixing_order(lb, lo, st.ub, st.integer)
        gpos = gpos[order]
        times["fixing"] = time.perf_counter() - t0
        t0 = time.perf_counter()
        windows: list[dict[str, Any]] = []
        info["windows"] = windows
        budget = 2 * problem.n_rows
        skip = _Skipper()
        while True:
            st.bound = max(st.bound, min(lo, st.ub))
            if st.incumbent is not None and st.closes(st.bound):
                st.proof = st.proof or "Lagrangian bound meets the objective"
                st.stop = "proven"
                break
            if deadline is not None and time.perf_counter() > deadline:
                st.stop = "time_limit"
                break
            if options.mip_gap > 0 and st.incumbent is not None and \
                    st.ub - st.bound <= options.mip_gap * max(abs(st.ub), 1e-12):
                st.stop = "gap_tol"
                break
            K = len(lb)
            # next threshold: one unit up for integer costs, unless that adds too few
            # candidates; then (and for real costs) the threshold reaching `budget`
            T = lo + 1.0 if st.integer else lo + st.tol()
            if int(np.searchsorted(lb, T, "left")) < budget and K:
                T = max(T, float(lb[min(budget, K - 1)]))
            T = skip.threshold(T, st.integer, st.ub)
            final = T >= st.ub
            if final:
                T = st.ub
            n_in = int(np.searchsorted(lb, T - (0.0 if st.integer else st.tol()), "left"))
            # closed: the window's optimum is the problem's (T reached the incumbent,
            # or every candidate is in); else it only decides "below T or not"
            closed = final or n_in >= K
            win = gpos[:n_in]
            if st.incumbent is not None and closed:
                win = np.union1d(win, st.incumbent)
            rec: dict[str, Any] = {"threshold": T, "candidates": int(len(win))}
            windows.append(rec)
            if closed and st.incumbent is not None and len(win) == len(st.incumbent):
                st.proof = "reduced-cost fixing left only the incumbent"
                st.bound = max(st.bound, st.ub)
                st.stop = "proven"
                break
            if len(_uncovered(problem, win)):
                rec["result"] = "uncovered"
                if closed:
                    st.stop = "infeasible"
                    break
                lo = T
                budget = max(budget, _grow(n_in, st.integer))
                continue
            cap = st.ub if closed else T          # only solutions below cap matter
            leave = skip.may_skip(closed, st.integer, lb, n_in, T)
            status, z, how = self._window(problem, win, red_of, base, lo, cap, closed,
                                          st, p, options, deadline, rec, leave, skip.retry)
            rec["result"], rec["solver"] = status.value, how
            if status is Outcome.GAVE_UP:     # a larger window holds this one
                skip.gave_up(T)
                budget = max(budget, _grow(n_in, st.integer))
                continue
            if status is Outcome.AT_BOUND or (status is Outcome.OPTIMAL and
                                              (closed or (z is not None and z < cap))):
                if st.incumbent is None:
                    st.stop = "infeasible"
                    break
                st.proof = ("optimum of the candidates left by reduced-cost fixing"
                            if closed else "optimum of a reduced-cost window")
                st.bound = max(st.bound, st.ub)
                st.stop = "proven"
                break
            if status is Outcome.NONE_BELOW or (status is Outcome.OPTIMAL and z is not None
                                                and z >= cap):
                if closed:        # nothing below the incumbent (or nothing at all)
                    if st.incumbent is None:
                        st.stop = "infeasible"
                        break
                    st.proof = "no solution below the incumbent in the fixing window"
                    st.bound = max(st.bound, st.ub)
                    st.stop = "proven"
                    break
                lo = T
                budget = max(budget, _grow(n_in, st.integer))
                continue
            st.stop = "time_limit" if status is Outcome.LIMIT else \
                f"window_{status.value}:{rec.get('native', how)}"
            break
        times["windows"] = time.perf_counter() - t0

    @staticmethod
    def _window(problem: AssignmentProblem, win: np.ndarray, red_of: np.ndarray, base: float,
                lo: float, cap: float, closed: bool, st: _State, p: dict[str, Any],
                options: SolveOptions, deadline: float | None, rec: dict[str, Any],
                skip: bool = False, searched: bool = False
                ) -> tuple[Outcome, float | None, str]:
        """Best solution among the candidates ``win`` costing less than ``cap``
        (``searched``: the compiled search gave up on this window before, so the
        engines take it without a search).

        Returns ``(outcome, objective, engine)``, the outcome in the engines' common
        terms (:class:`~.window.Outcome`); HiGHS's own status, when HiGHS ran, goes
        into the window record ``rec["native"]``.
        """
        compiled = _has_numba()
        skip = skip and compiled
        split = compiled and len(win) >= _SPLIT_MIN and bool((problem.tuples[win] == 0).any())
        args = (problem, win, red_of[win], base, cap, st, compiled, _SEARCH_MAX, _SEARCH_NODES)
        found = None if searched and compiled else \
            _search(*args, _OPEN_NODES if split else _SKIP_NODES if skip else _COMPILED_NODES,
                    floor=lo)
        if found is None and split and not searched:  # components, or (connected) search
            found = _by_components(problem, win, st, options, deadline) or \
                (None if skip else _search(*args, _COMPILED_NODES, floor=lo))
        if found is not None:
            return found
        if skip:                        # a larger window decides (see _Skipper)
            return Outcome.GAVE_UP, None, "compiled search" if compiled else "search"
        start = closed and st.incumbent is not None
        use_cp = st.integer and (p["window_solver"] == "cpsat" or (
            p["window_solver"] == "auto" and len(win) <= _CPSAT_MAX and _has_ortools()))
        if use_cp:
            # CP-SAT settles most small windows in milliseconds but stalls on a few
            # (measured: seconds on a Grundel n = 20 window HiGHS settles in 4 ms), so
            # it gets a short budget and HiGHS takes over when it runs out
            hi = cap - 1 if math.isfinite(cap) else float(np.abs(problem.costs).sum())
            budget = time.perf_counter() + _CPSAT_BUDGET
            cp_deadline = budget if deadline is None else min(budget, deadline)
            status, z = _cpsat(problem, win, st, options, cp_deadline, lo, hi, start=start)
            if status is not Outcome.LIMIT or (deadline is not None and
                                          time.perf_counter() >= deadline):
                return status, z, "cpsat"
            how = "cpsat+highs"
        else:
            how = "highs"
        target = lo if st.integer else lo + st.tol()
        status, z, rec["native"] = _ilp(problem, win, st, options, deadline, target,
                                        start=start)
        if status is Outcome.OPTIMAL and z is not None and z >= cap:
            return Outcome.NONE_BELOW, z, how
        return status, z, how

    # ------------------------------------------------------------- results
    def _finish(self, st: _State, info: dict[str, Any], t_start: float, gated: bool,
                options: SolveOptions) -> RawResult:
        info.update(iterations=st.iterations, stop=st.stop, proof=st.proof,
                    bound_raw=st.bound if math.isfinite(st.bound) else None)
        if st.history is not None:
            info["history"] = st.history
        if gated:
            if st.incumbent is None:
                return self._result(Status.ERROR, st, info, t_start,
                                    "the heuristic gate left no feasible assignment; "
                                    "raise or drop 'gate'")
            info["gated_bound"] = st.report_bound()
            st.bound = -math.inf
            status = Status.TIME_LIMIT if st.stop == "time_limit" else Status.FEASIBLE
            return self._result(status, st, info, t_start,
                                f"{self.name}: optimal at best for the gated candidates "
                                "(heuristic gate); no bound for the full problem",
                                with_bound=False)
        if st.stop == "infeasible":
            return self._result(Status.INFEASIBLE, st, info, t_start,
                                f"{self.name}: proven infeasible (no solution in the "
                                "candidate windows, which cover every candidate)")
        proven = st.stop == "proven" or (st.incumbent is not None and st.closes(st.bound))
        if proven and st.incumbent is not None:
            st.proof = st.proof or "Lagrangian bound meets the objective"
            info["proof"] = st.proof
            return self._result(Status.OPTIMAL, st, info, t_start,
                                f"{self.name}: proven optimal ({st.proof})")
        if st.stop == "time_limit":
            return self._result(Status.TIME_LIMIT, st, info, t_start,
                                f"{self.name}: stopped by the time limit")
        if st.incumbent is None:
            return self._result(Status.TIME_LIMIT, st, info, t_start,
                                f"{self.name}: no feasible solution found "
                                f"(stopped: {st.stop})")
        gap = (st.ub - st.report_bound()) / max(abs(st.ub), 1e-12) \
            if st.report_bound() is not None else math.inf
        return self._result(Status.FEASIBLE, st, info, t_start,
                            f"{self.name}: feasible, relative gap {gap:.3g} "
                            f"(stopped: {st.stop})")

    def _result(self, status: Status, st: _State, info: dict[str, Any], t_start: float,
                message: str, with_bound: bool = True) -> RawResult:
        bound = st.report_bound() if with_bound else None
        kernels = sum(spent()) - getattr(self, "_kernels0", 0.0)
        solve_time = max(time.perf_counter() - t_start - kernels, 0.0)
        if status is Status.INFEASIBLE:
            return RawResult(status, message=message, info=info, solve_time=solve_time)
        return RawResult(status, selected=st.incumbent, bound=bound, message=message,
                         info=info, solve_time=solve_time)


@register
class LagrangianBackend(_LagrangianBase):
    """Lagrangian relaxation to 2-D assignments: bound, feasible solution and gap."""

    name = "lagrangian"
    description = ("Lagrangian relaxation to 2-D assignments (Pattipati/Deb): lower bound, "
                   "recursive primal recovery, certified gap")
    exact = False
    _exact = False
    options = OPTIONS


@register
class LagrangianExactBackend(_LagrangianBase):
    """Lagrangian relaxation, reduced-cost fixing, then HiGHS on what is left: exact."""

    name = "lagrangian-exact"
    # highspy (the window ILPs) is a hard dependency of assocopt: no per-call lookup
    description = ("Lagrangian relaxation + reduced-cost fixing + HiGHS ILP on the "
                   "remaining candidates (proven optimum)")
    exact = True
    _exact = True
    options = OPTIONS_EXACT
