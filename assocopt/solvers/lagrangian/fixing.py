"""Reduced-cost fixing of the exact mode: the bounds (compiled on a square dense
grid), and the probe the ascent runs now and then.

:func:`fixing_bounds` is :meth:`.relaxation._Relaxation.fixing_bounds`, by the kernel
:func:`assocopt.solvers.kernels.grid_ascent.grid_fixing` where the compiled ascent
runs (one pass over the grid instead of some ten numpy passes: n = 50, 4 ms -> under
1 ms).  :func:`make_probe` builds the probe: stop the ascent when fixing proves the
incumbent, or leaves a window small enough to search.
"""

from __future__ import annotations

import math
from typing import Callable

import numpy as np

from ...problems.problem import AssignmentProblem
from .ascent import _State
from .compiled_ascent import applies, sorted_rows
from .relaxation import _Relaxation
from .window import _compiled_search, _cover_search


def fixing_bounds(rel: _Relaxation, upad: np.ndarray) -> tuple[np.ndarray, np.ndarray, float]:
    """``(lb, red, base)`` of :meth:`.relaxation._Relaxation.fixing_bounds`."""
    if not applies(rel):
        return rel.fixing_bounds(upad)
    from ..kernels import pick
    off = int(rel.u_off[0])
    w = np.ascontiguousarray(upad[off + 1: off + 1 + rel.m], np.float64)
    Cs, Is = sorted_rows(rel)
    v0 = rel.v_eval if len(rel.v_eval) == rel.na else np.zeros(0)
    args = (rel.Cg, Cs, Is, w, rel.na, v0, max(50, rel.na))
    ok, lb, red, base = pick("grid_ascent.grid_fixing", *args, work=math.inf)(*args)
    if not ok:
        return rel.fixing_bounds(upad)
    return lb, red, float(base)


def make_probe(rel: _Relaxation, pos: np.ndarray, st: _State, problem: AssignmentProblem,
               compiled: bool, search_max: int) -> Callable[[np.ndarray], str | None]:
    """The fixing probe at multipliers ``u``: ``"proven"`` when fixing leaves only the
    incumbent, or a window of at most ``search_max`` candidates (8 times that with the
    ``compiled`` search) that a short search settles; else None."""
    gpos = pos[rel.pos]
    local = np.full(len(st.costs), -1, np.int64)      # candidate -> entry of lb
    local[gpos] = np.arange(len(gpos))
    # the last window the short search gave up on, and the incumbent then: a window
    # no smaller, below the same incumbent, is not searched again (Balas-Saltzman
    # n = 16: four searches of 3.4 ms on windows of 613, 613, 613 and 581 candidates)
    failed = {"n": math.inf, "ub": math.nan}

    def probe(u: np.ndarray) -> str | None:
        if st.incumbent is None:          # nothing to prove (the kernels probe with one)
            return None
        lb, red, base = fixing_bounds(rel, u)
        if st.integer:        # ceil(lb - 1e-6) < ub, ub a whole number
            keep = lb <= st.ub - 1.0 + 1e-6
        else:
            keep = lb - st.tol() < st.ub
        mine = local[st.incumbent]
        n = int(np.count_nonzero(keep)) - int(np.count_nonzero(keep[mine[mine >= 0]]))
        if n == 0:
            st.proof = "reduced-cost fixing left only the incumbent"
            st.bound = max(st.bound, st.ub)
            return "proven"
        if n + len(st.incumbent) <= (8 if compiled else 1) * search_max and \
                not (n >= failed["n"] and st.ub == failed["ub"]):
            win = np.union1d(gpos[keep], st.incumbent)
            red_of = np.full(len(st.costs), np.inf)
            red_of[gpos] = red
            if compiled:
                sel, complete = _compiled_search(problem, win, red_of[win], base,
                                                 st.ub, st.integer, 3_000, st.bound)
            else:
                sel, complete = _cover_search(problem, win, red_of[win], base, st.ub,
                                              node_limit=3_000, floor=st.bound)
            if complete:
                if sel is not None:
                    st.offer(sel)
                st.proof = "search over the candidates left by reduced-cost fixing"
                st.bound = max(st.bound, st.ub)
                return "proven"
            failed.update(n=n, ub=st.ub)
        return None
    return probe


def fixing_order(lb: np.ndarray, lo: float, ub: float, integer: bool
                 ) -> tuple[np.ndarray, np.ndarray]:
    """The fixing bounds in the order the windows grow, ``(bounds, order)``: rounded
    up to whole units for integer costs (:func:`_levels`), else sorted as far as the
    incumbent ``ub`` (:func:`_sort_below`).  ``lo`` is the bound the windows start at."""
    if integer:
        return _levels(lb, lo, ub)
    order = _sort_below(lb, ub)
    return lb[order], order


def _levels(lb: np.ndarray, lo: float, ub: float) -> tuple[np.ndarray, np.ndarray]:
    """Integer costs: the fixing bounds rounded up to whole units and put in order,
    ``(levels, order)``.  Windows are unions of whole levels, so the order within a
    level does not matter, and levels below ``lo`` (in every window) or above the
    incumbent (in none) are merged: a counting sort of small integers, about a sixth
    of a full sort of 125,000 bounds on Grundel n = 50."""
    top = ub - lo + 1.0
    if not (math.isfinite(top) and top < np.iinfo(np.int16).max):
        order = _sort_below(lb, ub)
        return np.ceil(lb[order] - 1e-6), order
    lev = np.ceil(lb - 1e-6) - lo
    np.clip(lev, 0.0, top, out=lev)
    order = np.argsort(lev.astype(np.int16), kind="stable")    # radix sort
    return lev[order] + lo, order


def _sort_below(lb: np.ndarray, ub: float) -> np.ndarray:
    """The stable order of ``lb`` as far as windows look (the entries below ``ub``;
    those at or above it, which no window below the incumbent holds, follow in any
    order): sorting only those costs a fraction on Grundel n = 50."""
    below = np.flatnonzero(lb < ub)
    if len(below) == len(lb):
        return np.argsort(lb, kind="stable")
    rest = np.flatnonzero(~(lb < ub))
    return np.concatenate([below[np.argsort(lb[below], kind="stable")], rest])
