"""The direct route of dense 2-D problems: matrix to :class:`Solution` in one pass.

A tracker solves a 2-D assignment every scan, often a small one.  At ten rows scipy's
LAP takes about a microsecond, so the general route of :func:`assocopt.solve` (solver
dispatch, option parsing, the back end's raw result, the common checks) would cost
many times the solve.  :func:`solve_direct` does the same work without that route for
a problem kept as a dense matrix, solved by ``scipy-lsa`` (what ``auto`` picks) with no
options, costs in the unscaled range:

* square without misses: the matrix goes to the LAP as it is, the answer must be a
  permutation (any size);
* every row and column may be left out, no more rows than columns, at most
  :data:`SMALL` rows plus columns: the LAP of the clipped reduced costs
  ``min(C - rm - cm, 0)`` of :mod:`assocopt.solvers.twod.dense`, split and priced on
  Python lists (for a scan's few rows each numpy call costs more than the work);
* any other: :func:`~assocopt.solvers.twod.dense.assign_dense` and
  :meth:`~assocopt.problems.twod.Dense2D.check`, as the general route does.

The answer is re-checked as the general route re-checks it (distinct columns in range,
no forbidden pair or miss used) and priced by exact summation (``math.fsum``), so the
``Solution`` is the general route's, field for field (``tests/test_twod_direct.py``).
Anything it does not expect (an infeasible problem, a failed re-check) it leaves to the
general route by returning None, so every error is reported in one place.
"""

from __future__ import annotations

import math
import time

import numpy as np
from scipy.optimize import linear_sum_assignment as _lsa

from ..scaling import SCALE_ABOVE      # beyond it the general route answers
from ...model.solution import Solution, Status
from ...problems.twod import Checked
from ...problems.twod_tables import _index_set, _pair_base, _row_offsets, _tuple_table
from .dense import assign_dense
from .lap import LapInfeasibleError

__all__ = ["solve_direct", "SMALL"]

#: Problems with misses and at most this many rows + columns are split on lists.
SMALL = 64
_NAME = "scipy-lsa"
_MESSAGE = "scipy-lsa: optimal"


def solve_direct(problem, d, t0: float) -> Solution | None:
    """The :class:`Solution` of ``problem`` (dense view ``d``) by scipy's LAP, or None
    when the general route must answer.  ``t0``: when :func:`assocopt.solve` began."""
    C = d.C
    n1, n2 = C.shape
    if n1 == 0 or n2 == 0 or d.cost_bound() > SCALE_ABOVE:
        return None
    t1 = time.perf_counter()
    try:
        if d.all_finite and d.slack and n1 == n2:
            checked, how = _square(C, d), "plain"
        elif d.all_finite and not d.slack and n1 <= n2 and n1 + n2 <= SMALL and \
                d.miss_flags == (True, True):
            checked, how = _clipped(C, d), "reduced"
        else:
            cor, how = assign_dense(C, d.rm, d.cm, d.slack, "scipy", d.miss_flags)
            checked = d.check(cor)
    except LapInfeasibleError:
        return None
    if type(checked) is not Checked:
        return None            # the general route re-solves and reports why
    t2 = time.perf_counter()
    obj = checked.objective
    sol = Solution(Status.OPTIMAL, obj, obj, checked.selected, checked.tuples, _NAME,
                   _version(), {"build": 0.0, "solve": t2 - t1}, None, None, None,
                   _MESSAGE, {"lsa_mode": how, "options": {}})
    if problem.maximize:
        sol.maximize = True
        sol.objective = sol.bound = -obj
    sol.times["total"] = time.perf_counter() - t0
    return sol


_VERSION: list[str] = []


def _version() -> str:
    """scipy's version, looked up once (the package cannot change under a process)."""
    if not _VERSION:
        from .scipy_lsa import ScipyLsaBackend
        _VERSION.append(ScipyLsaBackend.version())
    return _VERSION[0]


def _square(C: np.ndarray, d) -> Checked | None:
    """A square matrix without misses: the LAP's columns must be a permutation."""
    n = C.shape[0]
    cor = _lsa(C)[1]
    if set(cor.tolist()) != _index_set(n):
        return None
    flat = _row_offsets(n, n) + cor
    objective = math.fsum(C.take(flat).tolist())
    tuples = _pair_base(n).copy()          # rows 1..n in column 0, 1 in column 1
    tuples[:, 1] += cor
    return Checked(flat, objective, tuples)


def _clipped(C: np.ndarray, d) -> Checked | None:
    """Every entry finite, every row and column may be left out, ``n1 <= n2``: the LAP of
    the clipped reduced costs, row ``i`` matched to its column when ``R[i, j] < 0``.
    Split and priced on Python lists (for a scan's few rows each numpy call costs more
    than the work); the tuples are read from the cached table of candidate tuples."""
    n1, n2 = C.shape
    R = C - d.cm                 # as clipped_matrix: (C - cm) - rm, clipped at 0
    R -= d.rm[:, None]
    np.minimum(R, 0.0, out=R)
    cols = _lsa(R)[1]
    flat = _row_offsets(n1, n2) + cols
    reduced = R.take(flat).tolist()
    prices = C.take(flat).tolist()
    flat_l = flat.tolist()
    col_l = cols.tolist()
    if len(set(col_l)) != n1 or min(col_l) < 0 or max(col_l) >= n2:
        return None              # the LAP's answer re-checked: distinct, in range
    rl = d.rm.tolist()
    base_r = n1 * n2
    pos: list[int] = []          # candidate positions: the pairs (row order) ...
    misses: list[int] = []       # ... then the row misses, then the column misses
    terms: list[float] = []
    used = [False] * n2
    for i in range(n1):
        if reduced[i] < 0.0:
            used[col_l[i]] = True
            pos.append(flat_l[i])
            terms.append(prices[i])
        else:
            misses.append(base_r + i)
            terms.append(rl[i])
    cl = d.cm.tolist()
    base_c = base_r + n1
    for j in range(n2):
        if not used[j]:
            misses.append(base_c + j)
            terms.append(cl[j])
    selected = np.array(pos + misses, np.int64)
    return Checked(selected, math.fsum(terms), _tuple_table(n1, n2).take(selected, axis=0))
