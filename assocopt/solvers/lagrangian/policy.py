"""Which engine decides a window of ``lagrangian-exact``, beyond the one-engine
rules of :mod:`.window`: windows of problems with dummies solved by connected
components (:func:`_by_components`), and windows the compiled search may give up on
for a larger window to decide (:class:`_Skipper`).
"""

from __future__ import annotations

import contextvars
import dataclasses
import math
import time

import numpy as np

from ...model.solution import Status
from ...problems.components import local_tuples, split, subproblem
from ..kernels import routed
from ...problems.problem import AssignmentProblem
from ..base import SolveOptions, get_backend
from .ascent import _State
from .window import Outcome, _compiled_search, _cover_search

#: The compiled search gets this many nodes on a window that is not the last (a
#: larger one can decide) and on a window that may split: it gives up there in a few
#: milliseconds instead of tenths of a second.
_OPEN_NODES = 10_000
#: ... and this many on a window it may give up on for a larger one (integer costs,
#: :class:`_Skipper`): 10 000 nodes took 11-13 ms on the three Grundel n = 50 first
#: windows (666-837 candidates) that hold no solution below the threshold, while
#: the next window, ten times larger, settled in 1-3 ms.  Over the 120 public 3-AP
#: instances 2 000 and 1 000 took the same time; 500 was too few on Grundel
#: ap3.50.10 (its second window gave up too, and the first went to the engines:
#: 0.24 s where it takes 0.03).
_SKIP_NODES = 2_000
#: The first window is left so only when the next (one cost unit up) holds at least
#: this many times its candidates (Grundel n = 40-50: 2.3-15 times; Balas-Saltzman, whose
#: windows do not get easier as they grow: about 1.3).
_SKIP_GROWTH = 2.0
#: Windows of problems with dummies, of at least this many candidates, are solved by
#: connected components when they split (fixing cuts the couplings: the largest
#: windows of the gated N = 4-5 scans, 800-3 100 candidates, split into 50-100
#: components of at most 80-620; ``bnb`` settled them in 2-140 ms where the search
#: over the whole window ran out of nodes and HiGHS took 0.3-1.3 s).
_SPLIT_MIN = 200
#: Set while the components of a window are solved (their own windows stay whole).
_NESTED = contextvars.ContextVar("assocopt_window_nested", default=False)


class _Skipper:
    """Which windows the compiled search may give up on (after :data:`_SKIP_NODES`
    nodes) for a larger window to decide: the first one, when the next is much
    larger, and then the next; if that one gives up too, the first gets the full
    treatment (search, CP-SAT, HiGHS) after all (measured on Grundel n = 50: the
    small first window sometimes holds the optimum, which CP-SAT finds there in
    0.15 s and HiGHS needs 2 s for in the next).  Integer costs only."""

    def __init__(self) -> None:
        self.tries, self.first, self.force, self.floor = 2, None, None, -math.inf
        #: the window now is the first one again: the compiled search gave up on it
        #: (the engines take it at once: on Grundel ap3.50.4 the search failed there
        #: with 10 000, 100 000 and 1 000 000 nodes, 0.01-1.1 s, CP-SAT took 0.04 s)
        self.retry = False

    def threshold(self, T: float, integer: bool, ub: float) -> float:
        """The next threshold: the first window again, or one above those given up."""
        self.retry = False
        if self.force is not None:
            T, self.force, self.retry = self.force, None, True
        elif T <= self.floor:
            T = self.floor + 1.0 if integer else ub
        return T

    def may_skip(self, closed: bool, integer: bool, lb: np.ndarray, n_in: int,
                 T: float) -> bool:
        if self.tries == 1:
            return True
        return self.tries == 2 and integer and not closed and \
            int(np.searchsorted(lb, T + 1.0, "left")) >= _SKIP_GROWTH * max(n_in, 1)

    def gave_up(self, T: float) -> None:
        self.tries -= 1
        if self.first is None:
            self.first = self.floor = T
        else:
            self.force, self.floor, self.tries = self.first, -math.inf, 0


def _search(problem: AssignmentProblem, pos: np.ndarray, red: np.ndarray, base: float,
            cap: float, st: _State, compiled: bool, search_max: int, search_nodes: int,
            nodes: int, floor: float = -math.inf) -> tuple[Outcome, float | None, str] | None:
    """The window ``pos`` by the compiled search (``nodes``) or, without numba and up
    to ``search_max`` candidates, the Python one (``search_nodes``); None when it ran
    out of nodes (or did not run)."""
    if compiled:
        sel, complete = _compiled_search(problem, pos, red, base, cap, st.integer, nodes,
                                         floor)
        how = "compiled search"
    elif len(pos) <= search_max:
        sel, complete = _cover_search(problem, pos, red, base, cap, node_limit=search_nodes,
                                      floor=floor)
        how = "search"
    else:
        return None
    if not complete:
        return None
    if sel is None:
        return Outcome.NONE_BELOW, None, how
    st.offer(sel)
    return Outcome.OPTIMAL, math.fsum(problem.costs[sel].tolist()), how


def _by_components(problem: AssignmentProblem, pos: np.ndarray, st: _State,
                   options: SolveOptions, deadline: float | None
                   ) -> tuple[Outcome, float | None, str] | None:
    """The best solution of the window ``pos`` (every row covered), component by
    component (``bnb`` on each, which hands what it cannot settle to
    ``lagrangian-exact``); None when the window is connected, or nested, or a
    component was not settled (time limit): the caller's engines decide then."""
    if _NESTED.get():
        return None
    W = AssignmentProblem._build(problem.sizes, problem.tuples[pos], problem.costs[pos],
                                 problem.slack[pos], kind="sparse")
    sp = split(W, routed)
    if sp.n < 2:
        return None
    T, csizes = local_tuples(W, sp.of_row, sp.n, routed)
    bnb, sel = get_backend("bnb"), []
    token = _NESTED.set(True)
    try:
        for c in range(sp.n):
            cand = sp.order[sp.ptr[c]:sp.ptr[c + 1]]
            left = None if deadline is None else deadline - time.perf_counter()
            if left is not None and left <= 0:
                return None
            if sp.trivial[c]:
                sel.append(cand)              # the only cover
                continue
            o = dataclasses.replace(options, extra={}, parsed=False, time_limit=left,
                                    mip_gap=0.0)
            raw = bnb().solve(subproblem(W, T, csizes[c], cand), o)
            if raw.status is Status.INFEASIBLE:
                return Outcome.NONE_BELOW, None, "components"
            if raw.status is not Status.OPTIMAL or raw.selected is None:
                return None
            sel.append(cand[np.asarray(raw.selected, np.int64)])
    finally:
        _NESTED.reset(token)
    chosen = np.sort(pos[np.concatenate(sel)])
    st.offer(chosen)
    return Outcome.OPTIMAL, math.fsum(problem.costs[chosen].tolist()), "components"
