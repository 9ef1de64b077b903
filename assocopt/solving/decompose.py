"""Connected components of an S-D problem, solved independently.

Two candidates are *connected* when they share a real index; a connected component
is a set of candidates and the real indices they cover, and no constraint couples
two components.  So the optimum of the whole is the union of the components'
optima, its objective and its bound the sums of theirs.  A gated tracking scan
splits into hundreds of components of a few candidates and a few larger ones; a MILP
or Lagrangian solver pays for the whole however small its parts.

Components are found in bulk: a graph on the real indices (constraint rows) with an
edge from each candidate's first real index to each of its other ones, and
:func:`scipy.sparse.csgraph.connected_components` on it.  Components in which every
real index has exactly one candidate are settled without a solver (all their
candidates are the only cover).  The rest are solved by the chosen back end, per
component, except that

* ``solver="auto"`` (no options) and ``solver="bnb"`` send the components ``bnb``
  suits (:func:`assocopt.solving.api.choose_solver`) to one compiled call over the batch
  (:mod:`assocopt.solvers.kernels.batch`), and the others to ``lagrangian-exact``;
* the MILP / CP back ends get the small components (at most :data:`GROUP_MAX`
  candidates each) together as one problem, in one call, and each large one alone.

A time limit is shared: each solve gets what is left of it, and a component stopped
by it (or not reached) makes the whole ``time_limit``.
"""

from __future__ import annotations

import time
from typing import Any

import numpy as np

from ..problems.components import (Split, gather, local_tuples, plan, split,
                                   subproblem as _subproblem)
from ..solvers.kernels import routed
from ..problems.problem import AssignmentProblem
from ..model.solution import Status
from ..solvers.base import RawResult, SolveOptions, get_backend

__all__ = ["Split", "split", "solve_decomposed", "MIN_CANDIDATES", "GROUP_MAX"]

#: ``decompose=None`` (the default) looks for components in problems with at least
#: this many candidates: the search costs about 0.1-0.2 ms (measured on a 280-candidate
#: scan, 2 loaded cores), against 0.5 ms for ``bnb`` on all of it, so smaller problems
#: are solved whole.
MIN_CANDIDATES = 200
#: MILP / CP back ends solve components of at most this many candidates together, as
#: one problem (one model, one call), and larger ones one by one.
GROUP_MAX = 2_000
#: Back ends that see small components together (a model per call costs more than
#: its small solve).
GROUPED = {"highs", "scipy", "ortools-cpsat", "ortools-mip", "cvxpy"}
#: ``lagrangian-exact`` settings ``auto`` uses on a large component with dummies (a
#: gated tracking scan closer than the gate): the sparse LAP (the relaxed 2-D problem
#: is gated too), primal recovery every 5th iteration, no local search.  Measured on
#: the dense scans of benchmarks/sd_tracking.py (N = 3, n = 300, spacing 0.7: 11.1 s
#: at the defaults, 1.1 s so; N = 5, n = 100, spacing 1: 0.6 s), where the recovery
#: and local search took two thirds of the time at the defaults.  The stall rule
#: (leave the ascent for fixing and windows when the bound gained less than 1 % of
#: the gap in 15 iterations) cut the time on the largest components of the dense
#: scans (spacing 0.5-1, N = 3-5, seeds 51-52) by a further 28 % (1.53 s -> 1.10 s
#: summed, min of 3, load 8).  Dense axial problems (no dummy) keep the defaults,
#: tuned on the public 3-AP instances.
TRACKING_OPTIONS = {"local_search": False, "lap": "sparse", "recover_every": 5,
                    "stall_iter": 15, "stall_tol": 0.01}
#: ... and without the dominance rule (``reduce=False``) at N >= 5 up to this many
#: candidates: there the rule's splits (up to 2^(N-1) - 1 a candidate) cost more than
#: the 10-25 % of candidates it drops saves.  Measured on the components above 700
#: candidates of the N = 5-6 scans of benchmarks/sd_tracking.py (seeds 51-52, not
#: the page's): 1,200-8,000 candidates 30-50 % faster without it (N = 6, n = 100,
#: spacing 2: 12.9 -> 10.4 ms and 9.1 -> 6.8 ms for the 9-10 components of a scan),
#: 37,000-57,000 level or faster (15.4 -> 11.2 ms; one 22.6 -> 23.7), while at N = 5
#: 88,000-121,000 it is slower (60 -> 77 ms, 82 -> 96 ms).  At N = 3-4 the rule pays
#: (N = 3, spacing 0.7: 29 ms with it, 36 without) and stays.
NO_DOMINANCE_MAX = 60_000


def tracking_options(problem: AssignmentProblem) -> dict[str, Any]:
    """The ``lagrangian-exact`` options ``auto`` gives a problem with dummies:
    :data:`TRACKING_OPTIONS`, and ``reduce=False`` where :data:`NO_DOMINANCE_MAX`
    says."""
    extra = dict(TRACKING_OPTIONS)
    if problem.ndim >= 5 and problem.n_candidates <= NO_DOMINANCE_MAX:
        extra["reduce"] = False
    return extra


def _full_grid(problem: AssignmentProblem) -> bool:
    """Every real tuple is a candidate (a dense axial problem without forbidden
    entries): one component, nothing to look for."""
    import math
    return problem.kind == "dense" and \
        int((~problem.slack).sum()) == math.prod(problem.sizes)


class _Outcome:
    """The components' answers, combined: selection, bound, statuses, solvers."""

    def __init__(self) -> None:
        self.selected: list[np.ndarray] = []
        self.missing = 0                 # components without a selection
        self.bound: float | None = 0.0
        self.statuses: set[Status] = set()
        self.solvers: dict[str, int] = {}
        self.messages: list[str] = []

    def add(self, status: Status, selected: np.ndarray | None, bound: float | None,
            solver: str, count: int = 1, message: str = "") -> None:
        self.statuses.add(status)
        self.solvers[solver] = self.solvers.get(solver, 0) + count
        if selected is None:
            self.missing += count
        else:
            self.selected.append(selected)
        if bound is None or self.bound is None:
            self.bound = None
        else:
            self.bound += bound
        if status is not Status.OPTIMAL and message:
            self.messages.append(f"{solver}: {message}")

    def add_raw(self, raw: RawResult, cand: np.ndarray, solver: str, count: int = 1
                ) -> None:
        sel = None if raw.selected is None else cand[np.asarray(raw.selected, np.int64)]
        self.add(raw.status, sel, raw.bound, raw.solver or solver, count, raw.message)

    def status(self) -> Status:
        for s in (Status.ERROR, Status.INFEASIBLE, Status.TIME_LIMIT, Status.NODE_LIMIT,
                  Status.FEASIBLE):
            if s in self.statuses:
                return s
        return Status.OPTIMAL


def solve_decomposed(problem: AssignmentProblem, requested: str, name: str,
                     opts: SolveOptions, decompose: bool | None) -> RawResult | None:
    """Solve ``problem`` (every real index covered, ILP, costs in range) component by
    component, as the module docstring says (one component: by ``name`` whole); None
    when ``decompose`` is None and the problem is below :data:`MIN_CANDIDATES` or a
    full grid of candidates, for the caller to solve whole.  ``requested``: the
    solver the user named (``"auto"`` only when no back-end option was given), ``name``
    the back end it stands for (whose options ``opts.extra`` holds)."""
    if decompose is None and (problem.n_candidates < MIN_CANDIDATES or _full_grid(problem)):
        return None
    t0 = time.perf_counter()
    sp = split(problem, routed, scan=True)
    if sp.n == 1 and not sp.trivial[0]:        # one component: the whole problem
        if requested == "auto":
            opts = _auto_options(problem, name, opts)
        raw = get_backend(name)().solve(problem, opts)
        raw.info = dict(raw.info, decomposition={
            "components": 1, "largest": int(problem.n_candidates), "settled": 0,
            "batched": 0, "solvers": {raw.solver or name: 1}})
        return raw
    out = _Outcome()
    trivial = np.flatnonzero(sp.trivial)
    if len(trivial):
        settled = sp.order[sp.trivial[sp.of_cand[sp.order]]]
        out.add(Status.OPTIMAL, settled, float(problem.costs[settled].sum()),
                "settled", len(trivial))
    todo = np.flatnonzero(~sp.trivial)
    batched = _solve_parts(problem, sp, todo, requested, name, opts, t0, out) \
        if len(todo) else 0
    status = out.status()
    sel = None
    if out.missing == 0 and status not in (Status.INFEASIBLE, Status.ERROR):
        sel = np.sort(np.concatenate(out.selected)) if out.selected else \
            np.zeros(0, np.int64)
    largest = int(sp.sizes.max(initial=0))
    solved = {k: v for k, v in out.solvers.items() if k != "settled"}
    main = max(solved, key=solved.get) if solved else name
    info = {"decomposition": {"components": int(sp.n), "largest": largest,
                              "settled": int(len(trivial)), "batched": batched,
                              "solvers": out.solvers}}
    msg = f"{sp.n} components (largest {largest} candidates, {len(trivial)} settled " \
          f"without a solver)"
    if out.messages:
        msg += "; " + "; ".join(out.messages[:3])
    return RawResult(status, selected=sel, bound=out.bound if sel is not None or
                     status.is_limit else None, message=msg, info=info,
                     solve_time=time.perf_counter() - t0, solver=main)


def _solve_parts(problem: AssignmentProblem, sp: Split, todo: np.ndarray,
                 requested: str, name: str, opts: SolveOptions, t0: float,
                 out: _Outcome) -> int:
    """Solve the components ``todo`` (none trivial); returns how many the batch
    kernel settled."""
    from .choice import BNB_MAX_KEPT, _numba_installed, bnb_cap

    csizes = sp.csizes
    plain_auto = requested == "auto"
    single, grouped, n_batched = todo, todo[:0], 0
    batch = (plain_auto or name == "bnb") and _numba_installed()
    if batch:
        from ..solvers.bnb.backend import MAX_DENSE, MAX_KEPT
        from ..solvers.bnb.batch import solve_components
        from .choice import BNB_MAX_CANDIDATES
        # bnb asked for: all that its kernels take; auto: what bnb suits
        comps, rest, *arrays = plan(
            problem, sp, name == "bnb", int(bnb_cap(True, problem.ndim)),
            BNB_MAX_CANDIDATES, MAX_KEPT if name == "bnb" else BNB_MAX_KEPT, MAX_DENSE,
            routed)
        left = _left(opts, t0)()
        # bnb's own options only when bnb was asked for: with plain ``auto`` ``opts``
        # holds the whole problem's choice's (lagrangian-exact's max_iter, step0, ...,
        # or bnb's defaults, which would override the batch's own probe_every)
        bnb_opts = opts if requested == "bnb" else _defaults(opts)
        redo = solve_components(sp, comps, arrays, bnb_opts, left, out)
        n_batched = len(comps) - len(redo)
        single = np.concatenate([redo, rest]).astype(np.int64)
    elif name in GROUPED:
        small = sp.sizes[todo] <= GROUP_MAX
        single, grouped = todo[~small], todo[small]
    jobs = [(csizes[c], sp.order[sp.ptr[c]:sp.ptr[c + 1]], 1, c) for c in single]
    T = None
    if len(grouped):
        T, _ = local_tuples(problem, sp.of_row, sp.n, routed)
        jobs.append(_group(T, csizes, sp, grouped) + (None,))
    for sizes, cand, count, c in jobs:
        remaining = _left(opts, t0)()
        if remaining is not None and remaining <= 0:
            out.add(Status.TIME_LIMIT, None, None, name, count,
                    "time limit reached before this component")
            continue
        sub = _subproblem(problem, T, sizes, cand) if c is None else \
            _subproblem(problem, gather(problem, sp, np.array([c]), routed)[0], sizes,
                        cand, gathered=True)
        # with the batch: what it left is past bnb's caps (choose_solver would say
        # lagrangian-exact) or spent bnb's node budget
        solver = ("lagrangian-exact" if batch else _auto_choice(sub)) if plain_auto \
            else name
        o = _auto_options(sub, solver, _defaults(opts)) if plain_auto else opts
        out.add_raw(_solve_one(sub, solver, o, remaining), cand, solver, count)
    return n_batched


def _group(T: np.ndarray, csizes: np.ndarray, sp: Split, comps: np.ndarray
           ) -> tuple[np.ndarray, np.ndarray, int]:
    """The components ``comps`` as one part: their local indices shifted past those
    of the components before them in the group (``T`` is changed in place for
    their candidates)."""
    offs = np.cumsum(csizes[comps], axis=0) - csizes[comps]
    shift = np.zeros((sp.n, T.shape[1]), np.int64)
    shift[comps] = offs
    cand = sp.order[np.isin(sp.of_cand[sp.order], comps)]
    Tc = T[cand]
    T[cand] = np.where(Tc > 0, Tc + shift[sp.of_cand[cand]], 0)
    return csizes[comps].sum(axis=0), cand, len(comps)


def _auto_choice(sub: AssignmentProblem) -> str:
    from .choice import choose_solver
    return choose_solver(sub)


def _auto_options(problem: AssignmentProblem, solver: str, opts: SolveOptions
                  ) -> SolveOptions:
    """``opts`` with :func:`tracking_options` for ``lagrangian-exact`` on a problem
    with dummies (else as they are)."""
    import dataclasses
    if solver != "lagrangian-exact" or not (problem.tuples == 0).any():
        return opts
    extra = tracking_options(problem)
    key = tuple(sorted(extra.items()))
    if key not in _PARSED:                    # parsed once (a component's solve
        from ..solvers.base import get_backend   # parsed them again: 10 us)
        _PARSED[key] = get_backend("lagrangian-exact").parse_options(extra)
    return dataclasses.replace(opts, extra=_PARSED[key], parsed=True)


#: :func:`tracking_options` parsed by the back end, by their items.
_PARSED: dict[tuple, dict[str, Any]] = {}


def _defaults(opts: SolveOptions) -> SolveOptions:
    """``opts`` without back-end options (``auto`` picks a back end per component,
    each then runs at its defaults)."""
    import dataclasses
    return dataclasses.replace(opts, extra={}, parsed=False)


def _left(opts: SolveOptions, t0: float):
    """A function giving what is left of the time limit (None: no limit)."""
    def left() -> float | None:
        if opts.time_limit is None:
            return None
        return opts.time_limit - (time.perf_counter() - t0)
    return left


def _solve_one(sub: AssignmentProblem, solver: str, opts: SolveOptions,
               remaining: float | None) -> RawResult:
    """One part by one back end (costs are in range: checked by the caller)."""
    import dataclasses
    o = opts if remaining is None else dataclasses.replace(opts, time_limit=remaining)
    return get_backend(solver)().solve(sub, o)
