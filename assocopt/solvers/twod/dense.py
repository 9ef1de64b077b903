"""2-D assignment with miss costs on a dense matrix, without enlarging it.

Model: every row ``i`` is matched to one column or left out at ``rm[i]``, every column
``j`` likewise at ``cm[j]`` (``inf`` forbids; ``C[i, j] = inf`` forbids the pair).

When every column may be left out (all ``cm`` finite), the problem is one LAP on the
*clipped reduced costs* of the same size (``n1 <= n2``; otherwise padded, below)::

    R[i, j] = min(C[i, j] - rm[i] - cm[j], 0)   for a row that may be left out,
    R[i, j] = C[i, j] - cm[j]                    for a row that must be assigned,

in which every row is assigned, and row ``i`` counts as matched to ``j`` exactly when
it must be assigned or ``R[i, j] < 0`` (an ``inf`` pair clips to 0: never matched).

*Proof.*  Write ``F`` for the rows that may be left out.  A 2-D solution with pairs
``P`` costs ``sum_j cm_j + sum_{i in F} rm_i + sum_P r_ij`` with
``r_ij = C_ij - cm_j - [i in F] rm_i`` (unmatched rows of ``F`` pay ``rm_i``, unmatched
columns ``cm_j``).  (a) Complete ``P`` to a row-complete assignment by giving the
unmatched rows (all in ``F``) distinct unused columns (there are enough, ``n1 <= n2``);
its ``R``-cost is at most ``sum_P r_ij`` since ``R <= r`` and ``R <= 0`` on rows of
``F``.  (b) From a row-complete assignment ``s`` keep the pairs of rows outside ``F``
and the pairs with ``R < 0``: a 2-D solution whose ``sum_P r_ij`` equals the
``R``-cost of ``s``.  So the optima coincide, up to the constant.  With ``n1 > n2`` the
matrix gets ``n1 - n2`` extra columns, 0 for rows of ``F`` and ``inf`` for the others.
When instead every row may be left out the same holds for the transpose; when both may,
the smaller side becomes the rows.  Only when some rows *and* some columns must be
assigned is the classical ``(n1 + n2) x (n2 + n1)`` augmentation used.  Measured
(``benchmarks/twod.py``, ``docs/benchmarks-2d.md``): the clipped LAP takes about half
the time of the augmented one with scipy, and a half to two thirds with lapx.

Without misses (a ``dense`` problem: the smaller side fully assigned, the surplus of
the larger free at no cost) the matrix goes to the LAP as it is.
"""

from __future__ import annotations

import time

import numpy as np

from ...model.solution import Status
from ..base import RawResult, empty_answer
from .lap import LapInfeasibleError, augmented_matrix, linear_assignment
from .sparse import (assign_sparse_edges, prefer_sparse, selected_from_edges,
                       split_candidates)

__all__ = ["assign_dense", "clipped_matrix", "solve_2d"]


def clipped_matrix(C: np.ndarray, a_miss: np.ndarray, b_miss: np.ndarray,
                   all_free: bool | None = None) -> tuple[np.ndarray, np.ndarray | None]:
    """The clipped reduced costs ``R`` (see the module docstring; ``b_miss`` finite)
    and the mask of rows that may be left out (None when all may: ``all_free``)."""
    n_a, n_b = C.shape
    if all_free is None:
        all_free = bool(np.isfinite(a_miss).all())
    R = np.subtract(C, b_miss[None, :])
    if all_free:
        R -= a_miss[:, None]
        np.minimum(R, 0.0, out=R)
        if n_a > n_b:
            R = np.hstack([R, np.zeros((n_a, n_a - n_b))])
        return R, None
    free = np.isfinite(a_miss)
    if free.all():
        R -= a_miss[:, None]
        np.minimum(R, 0.0, out=R)
    elif free.any():
        R[free] = np.minimum(R[free] - a_miss[free, None], 0.0)
    if n_a > n_b:
        pad = np.where(free, 0.0, np.inf)[:, None]
        R = np.hstack([R, np.broadcast_to(pad, (n_a, n_a - n_b))])
    return R, free


def _lap(C: np.ndarray, method: str) -> tuple[np.ndarray, np.ndarray]:
    """:func:`linear_assignment`, with scipy called directly (the per-scan hot path)."""
    if method != "scipy":
        return linear_assignment(C, method)
    try:
        from scipy.optimize import linear_sum_assignment   # (imported on first use)
        return linear_sum_assignment(C)
    except ValueError as exc:
        if "infeasible" in str(exc):
            raise LapInfeasibleError(str(exc)) from exc
        raise


def assign_dense(C: np.ndarray, rm: np.ndarray, cm: np.ndarray, slack: bool = False,
                 method: str = "scipy", flags: tuple[bool, bool] | None = None
                 ) -> tuple[np.ndarray, str]:
    """Optimal ``col_of_row`` (``-1`` = row left out) and the form that was solved.

    ``slack``: a ``dense`` problem (misses are the free surplus of the larger side).
    ``method``: the LAP engine of :func:`assocopt.solvers.twod.lap.linear_assignment`.
    ``flags``: ``(all rm finite, all cm finite)`` if already known.

    Raises
    ------
    LapInfeasibleError
        When no assignment exists.
    """
    n1, n2 = C.shape
    if slack:
        r, c = _lap(C, method)
        if len(r) == n1:         # every row assigned (n1 <= n2): r is 0..n1-1
            return c.astype(np.int64, copy=False), "plain"
        cor = np.full(n1, -1, np.int64)
        cor[r] = c
        return cor, "plain"
    cor = np.empty(n1, np.int64)    # np.full's Python wrapper costs more at scan size
    cor.fill(-1)
    rows_free, cols_free = flags if flags is not None else \
        (bool(np.isfinite(rm).all()), bool(np.isfinite(cm).all()))
    if cols_free and (not rows_free or n1 <= n2):
        return _clipped(C, rm, cm, cor, method, False, rows_free)
    if rows_free:
        return _clipped(C.T, cm, rm, cor, method, True, cols_free)
    if np.isinf(rm).all() and np.isinf(cm).all():
        if n1 != n2:
            raise LapInfeasibleError(f"{n1} rows cannot all meet {n2} columns")
        r, c = linear_assignment(C, method)
        cor[r] = c
        return cor, "plain"
    r, c = linear_assignment(augmented_matrix(C, rm, cm), method)
    real = (r < n1) & (c < n2)
    cor[r[real]] = c[real]
    return cor, "augmented"


def _clipped(C: np.ndarray, a_miss: np.ndarray, b_miss: np.ndarray, cor: np.ndarray,
             method: str, transposed: bool, all_free: bool) -> tuple[np.ndarray, str]:
    n_a, n_b = C.shape
    if n_a == 0 or n_b == 0:
        if not all_free:
            raise LapInfeasibleError("an index that must be assigned has no partner")
        return cor, "reduced-T" if transposed else "reduced"
    R, free = clipped_matrix(C, a_miss, b_miss, all_free)
    r, c = _lap(R, method)
    if len(r) != n_a:
        raise LapInfeasibleError("not every index can be assigned")
    if free is None and not transposed and n_a <= n_b and method == "scipy":
        # r is 0..n_a-1 (every row assigned, scipy's order): one pass, no scatter
        return np.where(R[r, c] < 0, c, -1), "reduced"
    if free is None:
        real = R[r, c] < 0
    else:
        real = c < n_b
        real[real] &= ~free[r[real]] | (R[r[real], c[real]] < 0)
    if transposed:
        cor[c[real]] = r[real]
    else:
        cor[r[real]] = c[real]
    return cor, "reduced-T" if transposed else "reduced"


def solve_2d(problem, options, engine: str, label: str, mode: str = "auto"):
    """The 2-D back ends' common solve.

    ``engine``: the dense LAP (``"scipy"`` or ``"lapx"``); ``mode``: ``"auto"``,
    ``"dense"`` or ``"sparse"``.  A problem with a dense view is solved on it (answer as
    ``col_of_row``, re-checked by :func:`assocopt.solve` in bulk); one given as a
    candidate list is densified when small, else solved by the sparse engine without
    densifying (answer as candidate positions).
    """
    t0 = t1 = time.perf_counter()
    if not problem.n_rows:
        return empty_answer(problem, options, label)
    d = problem.dense_view
    try:
        if d is not None and mode != "sparse":
            cor, how = assign_dense(d.C, d.rm, d.cm, d.slack, engine, d.miss_flags)
            selected = None
        else:
            rows, cols, w, pos, rm, cm, rpos, cpos = split_candidates(problem)
            n1, n2 = problem.sizes
            t1 = time.perf_counter()
            if mode == "sparse" or (mode == "auto" and
                                    prefer_sparse(problem.sizes, len(w))):
                edge, how = assign_sparse_edges(n1, n2, rows, cols, w, rm, cm)
                selected = selected_from_edges(edge, cols, pos, rpos, cpos)
            else:
                C = np.full((n1, n2), np.inf)
                C[rows, cols] = w
                cor, how = assign_dense(C, rm, cm, False, engine)
                selected = _answer_positions(problem, cor)
    except LapInfeasibleError as exc:
        return RawResult(Status.INFEASIBLE, message=f"{label}: infeasible ({exc})",
                         build_time=t1 - t0, solve_time=time.perf_counter() - t1)
    t2 = time.perf_counter()
    msg = f"{label}: optimal"
    if options.time_limit is not None:
        msg += f" (time_limit not supported by {label}; ran to completion)"
    return RawResult(Status.OPTIMAL, selected=selected,
                     col_of_row=cor if selected is None else None, message=msg,
                     info={"lsa_mode": how}, build_time=t1 - t0, solve_time=t2 - t1)


def _answer_positions(problem, cor: np.ndarray) -> np.ndarray:
    """Candidate positions of a ``col_of_row`` answer in the problem's tuple list."""
    n1, n2 = problem.sizes
    assigned = cor >= 0
    rows = np.flatnonzero(assigned)
    used = np.zeros(n2, bool)
    used[cor[rows]] = True
    miss_r = np.flatnonzero(~assigned)
    miss_c = np.flatnonzero(~used)
    pairs = np.concatenate([np.stack([rows + 1, cor[rows] + 1], axis=1),
                            np.stack([miss_r + 1, 0 * miss_r], axis=1),
                            np.stack([0 * miss_c, miss_c + 1], axis=1)]).astype(np.int64)
    return _positions(problem, pairs)


def _positions(problem: AssignmentProblem, pairs: np.ndarray) -> np.ndarray:
    """Candidate positions of the 2-D tuples ``pairs`` (bulk search on packed keys)."""
    n2 = problem.sizes[1] + 1
    keys = problem.tuples[:, 0] * n2 + problem.tuples[:, 1]
    order = np.argsort(keys, kind="stable")
    want = pairs[:, 0] * n2 + pairs[:, 1]
    pos = np.searchsorted(keys[order], want)
    pos = np.minimum(pos, len(keys) - 1)
    found = keys[order][pos] == want
    if not found.all():
        missing = pairs[~found][0].tolist()
        raise RuntimeError(f"the 2-D LAP chose {missing}, which is not a candidate")
    return order[pos]
