"""Ranked 2-D assignments, compiled: the LAP form of a 2-D problem, one call of the
Murty kernel (:mod:`assocopt.solvers.kernels.murty2d`), the answers as Solutions in bulk.

LAP forms (every row of the form assigned, its columns free at no cost), each with
one *real* row per row of the problem (the rows whose choices Murty splits on), so that
every 2-D solution is one choice vector of the real rows:

* *plain*: no row or column may be left out, ``n1 = n2``: the matrix itself.
* *rectangular*: every column may be left out: ``C[i, j] - cm[j]`` (a column left out
  costs 0, the constant ``sum(cm)`` is left out of the ranking), and one extra column
  per row that may be left out, its own, at ``rm[i]`` (``inf`` in the other rows).  A
  rectangular ``dense`` problem is the case ``cm = 0`` with no extra columns.  Taken
  transposed when every row may be left out instead (or both, and ``n1 > n2``: fewer
  rows to split on).
* *augmented*: otherwise (some rows and some columns must be assigned), the classical
  ``(n1 + n2) x (n2 + n1)`` matrix ``[[C, diag(rm)], [diag(cm), 0]]`` (``inf`` off the
  diagonals), transposed first when ``n1 > n2``.  Real row ``i`` takes a column ``j`` or
  its own miss column ``n2 + i``; the dummy rows ``n1 + j`` take column ``j`` (column
  left out) or any zero entry, and their many equivalent arrangements are never split
  on, so no 2-D solution comes back twice.

Ties: the answers are sorted by objective (``math.fsum`` of the chosen costs, as
:func:`assocopt.solve` reports it), equal objectives by their candidate positions
(``Solution.selected``, lexicographically).  Which of several solutions tied at the
``k``-th place are returned is fixed by the kernel's deterministic heap order: the
same on every run.
"""

from __future__ import annotations

import importlib.util
import math
from typing import NamedTuple

import numpy as np

from ..problems.problem import AssignmentProblem
from ..model.solution import Solution, Status

__all__ = ["available", "lap_form", "form_entries", "kbest_2d", "NAME"]

#: The name the compiled ranking reports as its solver.
NAME = "murty2d"
#: Largest LAP form (entries) ranked by the kernel; larger problems use the generic path.
MAX_FORM_ENTRIES = 8_000_000


def available() -> bool:
    """Whether numba (the kernel's compiler) is installed."""
    return importlib.util.find_spec("numba") is not None


class LapForm(NamedTuple):
    """A LAP form (see the module docstring): ``A`` (rows <= columns, or infeasible),
    its first ``P`` rows real, ``transposed`` (rows are the problem's columns),
    ``n_real_cols`` (columns of ``A`` below that index are the other side's real
    indices; the rest stand for misses)."""

    A: np.ndarray
    P: int
    transposed: bool
    n_real_cols: int


def lap_form(C: np.ndarray, rm: np.ndarray, cm: np.ndarray) -> LapForm | None:
    """The LAP form of the 2-D problem ``(C, rm, cm)`` (minimisation, ``inf`` forbids);
    None when it plainly has no solution (no misses and ``n1 != n2``)."""
    n1, n2 = C.shape
    fr, fc = np.isfinite(rm), np.isfinite(cm)
    if not fr.any() and not fc.any():
        return LapForm(np.array(C, np.float64), n1, False, n2) if n1 == n2 else None
    if fc.all() and (not fr.all() or n1 <= n2):
        return _rectangular(C, rm, fr, cm, False)
    if fr.all():
        return _rectangular(C.T, cm, fc, rm, True)
    tr = n1 > n2
    if tr:
        C, rm, cm = C.T, cm, rm
        n1, n2 = n2, n1
    A = np.full((n1 + n2, n2 + n1), np.inf)
    A[:n1, :n2] = C
    A[np.arange(n1), n2 + np.arange(n1)] = rm
    A[n1 + np.arange(n2), np.arange(n2)] = cm
    A[n1:, n2:] = 0.0
    return LapForm(A, n1, tr, n2)


def form_entries(rm: np.ndarray, cm: np.ndarray) -> int:
    """How many entries :func:`lap_form` allocates for miss costs ``(rm, cm)`` (sizes
    ``n1 = len(rm)``, ``n2 = len(cm)``), without building it."""
    n1, n2 = len(rm), len(cm)
    fr, fc = int(np.isfinite(rm).sum()), int(np.isfinite(cm).sum())
    if fr == 0 and fc == 0:
        return n1 * n2
    if fc == n2 and (fr < n1 or n1 <= n2):
        return n1 * (n2 + fr)
    if fr == n1:
        return n2 * (n1 + fc)
    return (n1 + n2) ** 2


def _rectangular(C: np.ndarray, a_miss: np.ndarray, a_free: np.ndarray,
                 b_miss: np.ndarray, transposed: bool) -> LapForm:
    """``[C - b_miss, own miss columns of the rows that may be left out]``."""
    n_a, n_b = C.shape
    free = np.flatnonzero(a_free)
    A = np.full((n_a, n_b + len(free)), np.inf)
    np.subtract(C, b_miss[None, :], out=A[:, :n_b])
    A[free, n_b + np.arange(len(free))] = a_miss[free]
    return LapForm(A, n_a, transposed, n_b)


def kbest_2d(problem: AssignmentProblem, k: int) -> tuple[list[Solution], bool, int,
                                                          dict[str, float]] | None:
    """``(solutions best first, exhausted, subproblems solved, kernel times)`` of a
    2-D problem, or None when it is not for this path (empty side, too large)."""
    from ..solvers.kernels import pick, spent

    d = problem.dense_view
    n1, n2 = problem.sizes
    if min(n1, n2) == 0:
        return None
    rm, cm = (d.rm, d.cm) if d is not None else problem.miss_costs()
    if form_entries(rm, cm) > MAX_FORM_ENTRIES:
        return None
    C = d.C if d is not None else problem.to_cost_matrix()
    form = lap_form(C, rm, cm)
    if form is None:
        return [], True, 1, {}
    finite = np.abs(form.A[np.isfinite(form.A)])
    tol = 1e-9 * max(1.0, float(finite.max()) if finite.size else 1.0)
    k = min(k, 2**62)              # the kernel counts in int64
    k0 = spent()
    murty = pick("murty2d.murty", form.A, form.P, k, tol, work=min(k, 10**9) * form.A.size)
    k1 = spent()
    X, _, n, exhausted, solved = murty(form.A, form.P, k, tol)
    X = np.where(X < form.n_real_cols, X, -1)
    cor = _invert(X, n1) if form.transposed else X
    sols = _solutions_dense(problem, cor) if d is not None else _solutions_list(problem, cor)
    times = {"compile": k1[0] - k0[0], "cache_load": k1[1] - k0[1]}
    return sols, bool(exhausted), int(solved), {a: b for a, b in times.items() if b > 0}


def _invert(roc: np.ndarray, n1: int) -> np.ndarray:
    """``col_of_row`` answers from ``row_of_col`` ones (``-1``: none)."""
    cor = np.full((roc.shape[0], n1), -1, np.int64)
    s, j = np.nonzero(roc >= 0)
    cor[s, roc[s, j]] = j
    return cor


def _solutions_dense(problem: AssignmentProblem, cor: np.ndarray) -> list[Solution]:
    """The answers ``cor`` (``K x n1``) of a problem with a dense view, priced,
    checked and placed in bulk (candidate order: pairs row-major, row misses, column
    misses, so one sort per answer orders ``selected``)."""
    d = problem.dense_view
    K, n1 = cor.shape
    n2 = d.C.shape[1]
    rows = np.arange(n1)
    assigned = cor >= 0
    ci = np.where(assigned, cor, 0)
    flat = rows * n2 + ci
    pair_pos = flat if d._pair_rank is None else d._pair_rank[flat]
    r_idx, c_idx = d.miss_index
    base_r = d.n_pairs
    base_c = base_r + len(r_idx)
    rmiss_pos = base_r + (rows if len(r_idx) == n1 else np.searchsorted(r_idx, rows))
    cols = np.arange(n2)
    cmiss_pos = base_c + (cols if len(c_idx) == n2 else np.searchsorted(c_idx, cols))
    used = np.zeros((K, n2), bool)
    s_idx, i_idx = np.nonzero(assigned)
    used[s_idx, cor[s_idx, i_idx]] = True
    n_pairs = assigned.sum(axis=1)
    vals = np.hstack([np.where(assigned, d.C[rows, ci], d.rm), np.where(used, 0.0, d.cm)])
    if not np.isfinite(vals).all() or (used.sum(axis=1) != n_pairs).any():
        raise RuntimeError("kbest produced an infeasible selection (a forbidden entry, "
                           "or a column assigned twice)")
    pos = np.hstack([np.where(assigned, pair_pos, rmiss_pos), np.where(used, -1, cmiss_pos)])
    order = np.argsort(pos, axis=1, kind="stable")
    pos = np.take_along_axis(pos, order, axis=1)
    tup = np.zeros((K, n1 + n2, 2), np.int64)
    tup[:, :n1, 0] = rows + 1
    tup[:, :n1, 1] = cor + 1
    tup[:, n1:, 1] = cols + 1
    tup = np.take_along_axis(tup, order[:, :, None], axis=1)
    objs = [math.fsum(v) for v in vals.tolist()]
    slack = d.slack
    out = []
    for s, a in enumerate(n_pairs.tolist()):       # views of per-call arrays
        out.append((objs[s], pos[s, a:], tup[s, a:2 * a] if slack else tup[s, a:]))
    return _ranked(problem, out)


def _solutions_list(problem: AssignmentProblem, cor: np.ndarray) -> list[Solution]:
    """The answers of a problem given as a candidate list (positions looked up)."""
    from ..solvers.twod.dense import _answer_positions

    out = []
    for c in cor:
        sel = np.sort(_answer_positions(problem, c))
        why = problem.violations(sel)
        if why is not None:
            raise RuntimeError(f"kbest produced an infeasible selection: {why}")
        out.append((problem.objective_of(sel), sel,
                    problem.tuples[sel[~problem.slack[sel]]].copy()))
    return _ranked(problem, out)


def _ranked(problem: AssignmentProblem, out: list) -> list[Solution]:
    """Solutions from ``(objective, selected, tuples)``, sorted by objective, then
    ``selected`` (minimisation sense; flipped for a maximisation problem)."""
    from .._version import __version__

    objs = [e[0] for e in out]
    if any(a >= b for a, b in zip(objs, objs[1:])):   # ties (or rounding): reorder
        out.sort(key=lambda e: (e[0], e[1].tolist()))
    sols = []
    sign = -1.0 if problem.maximize else 1.0
    for rank, (obj, sel, tuples) in enumerate(out, 1):
        if not math.isfinite(obj):
            raise RuntimeError("kbest produced a non-finite objective")
        sols.append(Solution(status=Status.OPTIMAL if rank == 1 else Status.FEASIBLE,
                             objective=sign * obj, bound=sign * obj if rank == 1 else None,
                             selected=sel, tuples=tuples, solver=NAME,
                             solver_version=__version__, message=f"kbest: rank {rank}",
                             info={"rank": rank}, maximize=problem.maximize))
    return sols

