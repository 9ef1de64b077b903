"""The dense 2-D view of a problem: the cost matrix kept as given, no tuple round trip.

A 2-D problem built from a matrix (:meth:`AssignmentProblem.dense` or
:meth:`AssignmentProblem.two_d`) keeps that ``n1 x n2`` matrix and two miss vectors
here; the S-D candidate list (``problem.tuples`` / ``costs`` / ``slack``) is built from
it only when a back end asks for it (:meth:`Dense2D.candidates`).  The 2-D engines answer
with ``col_of_row`` (the column of every row, ``-1`` = row not assigned), which
:meth:`Dense2D.check` re-checks and prices in bulk (numpy, no per-index Python loop).

Both kinds are one model: every row ``i`` is assigned to one column or left out at
``row_miss[i]``, every column likewise at ``col_miss[j]``; ``inf`` forbids.  A
``dense`` rectangular problem is the case where the larger side's indices may be left
out at cost 0 and the smaller side's may not; those zero-cost "misses" are the
problem's *slack* candidates and are never reported.

Candidate order (the positions ``Solution.selected`` refers to): the finite entries of
the matrix in row-major order, then the row misses, then the column misses (for
``dense``: the slack rows, then the slack columns), each in index order.
"""

from __future__ import annotations

import math
import functools
from typing import Any, NamedTuple

import numpy as np

from ..runtime.errors import InvalidProblemError
from .validation import MAX_ABS_COST
from .values import _as_matrix
from .twod_tables import _finite_amax, _index_set, _pair_base, _row_offsets

__all__ = ["Dense2D", "Checked", "LazyView", "from_matrix", "miss_vector",
           "MAX_DENSE_CANDIDATES"]

#: Answers of problems with at most this many rows + columns are checked on lists.
SMALL = 64

#: Largest number of candidates a dense constructor will enumerate.
MAX_DENSE_CANDIDATES = 50_000_000


def from_matrix(cls: type, C: np.ndarray, rm: np.ndarray | None, cm: np.ndarray | None,
                all_finite: bool, known_finite: tuple[bool, bool] = (False, False),
                amax: tuple[float | None, float | None, float | None] = (None, None, None),
                **kw: Any) -> Any:
    """A 2-D ``AssignmentProblem`` kept as its dense matrix (``C`` validated, owned).

    ``amax``: upper bounds on the largest finite magnitudes of ``C``, ``rm``, ``cm``
    where the validation found them (None: computed when needed).  Filled in directly rather than
    through the dataclass's generated ``__init__``: this is the per-scan hot path,
    where every microsecond is measured against scipy."""
    if C.size > MAX_DENSE_CANDIDATES:
        raise InvalidProblemError(
            f"cost matrix of shape {C.shape} has {C.size} entries, more than "
            f"{MAX_DENSE_CANDIDATES}; build a sparse problem of the gated candidates")
    p = object.__new__(cls)
    p.__dict__.update({"sizes": C.shape, "_tuples": None, "_costs": None, "_slack": None,
                       "name": None, "optimum": None, "meta": {}, "maximize": False,
                       "kind": "sparse",
                       "_dense": Dense2D.build(C, rm, cm, all_finite, known_finite,
                                              amax)},
                      **kw)
    return p


class LazyView:
    """Data descriptor for ``tuples`` / ``costs`` / ``slack``: the stored array, or, for
    a problem kept as a dense 2-D matrix, the candidate list built on first read."""

    def __init__(self, name: str) -> None:
        self.slot = "_" + name

    def __get__(self, obj: Any, owner: Any = None) -> Any:
        if obj is None:
            return self
        value = obj.__dict__.get(self.slot)
        dense = obj.__dict__.get("_dense")
        if value is None and dense is not None:
            for name, arr in zip(("_tuples", "_costs", "_slack"), dense.candidates()):
                arr = np.ascontiguousarray(arr)
                arr.setflags(write=False)
                obj.__dict__[name] = arr
            value = obj.__dict__[self.slot]
        return value

    def __set__(self, obj: Any, value: Any) -> None:
        obj.__dict__[self.slot] = value


@functools.lru_cache(maxsize=256)
def _constant(n: int, value: float) -> np.ndarray:
    """A shared read-only array of ``n`` times ``value`` (the slack misses of a dense
    problem: the same for every scan of a size, so built once)."""
    a = np.full(n, value)
    a.setflags(write=False)
    return a


@functools.lru_cache(maxsize=256)
def _arange(n: int) -> np.ndarray:
    a = np.arange(n)
    a.setflags(write=False)
    return a


def miss_vector(values: Any, n: int, what: str, maximize: bool
                ) -> tuple[np.ndarray, bool, float | None]:
    """A validated miss-cost vector (minimisation sense; None: all forbidden), whether
    it is known to be all finite, and then its largest magnitude (else None)."""
    if values is None:
        return _constant(n, np.inf), False, 0.0
    if isinstance(values, (int, float)) and not isinstance(values, bool) and \
            abs(values) <= MAX_ABS_COST:       # a finite scalar in range: a constant
        v = -float(values) if maximize else float(values)
        return _constant(n, v), True, abs(v)
    arr, finite, amax = _as_matrix(values, what, maximize)
    if arr.ndim == 0:
        return np.full(n, float(arr)), finite, amax
    if arr.shape != (n,):
        raise InvalidProblemError(f"{what} must be a scalar or have shape ({n},), "
                                  f"got shape {arr.shape}")
    return arr, finite, amax


def _finite_index(a: np.ndarray) -> np.ndarray:
    """Positions of the finite entries (``arange`` when all are; a validated miss
    vector holds no NaN or -inf, so a finite sum means all finite)."""
    if math.isfinite(a.sum()):
        return _arange(len(a))
    return np.isfinite(a).nonzero()[0]


class Checked(NamedTuple):
    """A re-checked 2-D answer: candidate positions, objective and reported tuples."""

    selected: np.ndarray
    objective: float
    tuples: np.ndarray


class Dense2D:
    """Validated dense 2-D data (internal, minimisation sense; ``inf`` = forbidden).

    ``C``: ``n1 x n2`` costs; ``rm`` / ``cm``: miss cost of each row / column;
    ``slack``: True for a ``dense`` problem (misses are zero-cost slack, not reported);
    ``all_finite``: no forbidden matrix entry; ``n_pairs``: number of finite entries;

    ``miss_index``: the rows and the columns whose miss is a candidate (finite cost);
    ``miss_flags``: ``(all rm finite, all cm finite)``; ``amax``: upper bounds on the
    largest finite magnitudes of ``C``, ``rm``, ``cm`` where known (see
    :meth:`cost_bound`).
    Read-only by convention (a plain class with slots: built once per scan).
    """

    __slots__ = tuple("C rm cm slack all_finite n_pairs miss_index miss_flags amax _rank".split())

    def __init__(self, C: np.ndarray, rm: np.ndarray, cm: np.ndarray, slack: bool,
                 all_finite: bool, n_pairs: int,
                 miss_index: tuple[np.ndarray, np.ndarray],
                 miss_flags: tuple[bool, bool],
                 amax: tuple[float | None, float | None, float | None] = (None, None, None)
                 ) -> None:
        self.C, self.rm, self.cm, self.slack = C, rm, cm, slack
        self.all_finite, self.n_pairs = all_finite, n_pairs
        self.miss_index, self.miss_flags = miss_index, miss_flags
        self.amax = amax
        self._rank: np.ndarray | None = None

    @classmethod
    def build(cls, C: np.ndarray, rm: np.ndarray | None, cm: np.ndarray | None,
              all_finite: bool, known_finite: tuple[bool, bool] = (False, False),
              amax: tuple[float | None, float | None, float | None] = (None, None, None)
              ) -> "Dense2D":
        """From a validated matrix; ``rm = cm = None`` means the ``dense`` kind;
        ``known_finite``: the caller knows all of ``rm`` / ``cm`` is finite (scalars);
        ``amax``: the magnitude bounds the validation found (None: not known)."""
        n1, n2 = C.shape
        slack = rm is None and cm is None
        if slack:      # the larger side's surplus is free: known without looking
            rm = _constant(n1, 0.0 if n1 > n2 else np.inf)
            cm = _constant(n2, 0.0 if n2 > n1 else np.inf)
            index = (_arange(n1 if n1 > n2 else 0), _arange(n2 if n2 > n1 else 0))
            flags = (n1 > n2 or n1 == 0, n2 > n1 or n2 == 0)
        else:
            index = (_arange(n1) if known_finite[0] else _finite_index(rm),
                     _arange(n2) if known_finite[1] else _finite_index(cm))
            flags = (len(index[0]) == n1, len(index[1]) == n2)
            rm.setflags(write=False)
            cm.setflags(write=False)
        n_pairs = C.size if all_finite else int(np.count_nonzero(np.isfinite(C)))
        C.setflags(write=False)
        if slack:      # the slack misses are 0 or forbidden: magnitude 0
            amax = (amax[0], 0.0, 0.0)
        return cls(C, rm, cm, slack, all_finite, n_pairs, index, flags, amax)

    def cost_bound(self) -> float:
        """An upper bound on the largest finite ``|cost|`` of the matrix and the misses
        (0 when none), for the cost-scaling test of :func:`assocopt.solve`: the bounds
        the validation found are reused (``sqrt`` of a sum of squares, or the exact
        magnitude), the missing ones computed (and kept) here."""
        known = self.amax
        if None in known:
            known = tuple(_finite_amax(a) if m is None else m
                          for a, m in zip((self.C, self.rm, self.cm), known))
            self.amax = known
        return max(known)

    def max_abs_cost(self) -> float:
        """The largest finite ``|cost|`` of the matrix and the misses (0 when none)."""
        return max(_finite_amax(a) for a in (self.C, self.rm, self.cm))

    @property
    def shape(self) -> tuple[int, int]:
        return self.C.shape

    @property
    def n_candidates(self) -> int:
        r, c = self.miss_index
        return self.n_pairs + len(r) + len(c)

    # ------------------------------------------------------------ candidate view
    def candidates(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """``(tuples, costs, slack)`` in the S-D convention (0 = dummy, 1-based)."""
        C = self.C
        if self.all_finite:
            n1, n2 = C.shape
            ii, jj = np.divmod(np.arange(C.size, dtype=np.int64), n2)
            pairs = np.stack([ii + 1, jj + 1], axis=1)
            pc = C.ravel()
        else:
            finite = np.isfinite(C)
            pairs = np.stack(np.nonzero(finite), axis=1).astype(np.int64) + 1
            pc = C[finite]
        r, c = self.miss_index
        z_r, z_c = np.zeros(len(r), np.int64), np.zeros(len(c), np.int64)
        tuples = np.concatenate([pairs, np.stack([r + 1, z_r], axis=1),
                                 np.stack([z_c, c + 1], axis=1)])
        costs = np.concatenate([pc, self.rm[r], self.cm[c]])
        slack = np.zeros(len(costs), bool)
        if self.slack:
            slack[len(pc):] = True
        return tuples, costs, slack

    def uncovered(self) -> list[tuple[int, int]]:
        """``(axis, 1-based index)`` of the rows / columns no candidate covers."""
        if self.all_finite and min(self.C.shape) > 0:
            return []
        finite = np.isfinite(self.C)
        rows = np.flatnonzero(~finite.any(axis=1) & ~np.isfinite(self.rm))
        cols = np.flatnonzero(~finite.any(axis=0) & ~np.isfinite(self.cm))
        return [(0, int(i) + 1) for i in rows] + [(1, int(j) + 1) for j in cols]

    # ------------------------------------------------------------ positions
    @property
    def _pair_rank(self) -> np.ndarray | None:
        """Position of each finite entry (flat row-major index -> candidate position);
        None when all entries are finite (position = flat index).  Built on first use."""
        if self.all_finite:
            return None
        if self._rank is None:
            self._rank = np.cumsum(np.isfinite(self.C).ravel()) - 1
        return self._rank

    def positions(self, rows: np.ndarray, cols: np.ndarray, miss_r: np.ndarray,
                  miss_c: np.ndarray) -> np.ndarray:
        """Candidate positions of the pairs ``(rows, cols)`` and the misses (0-based)."""
        n2 = self.C.shape[1]
        flat = rows * n2 + cols
        pos = flat if self._pair_rank is None else self._pair_rank[flat]
        r, c = self.miss_index
        base_r = self.n_pairs
        base_c = base_r + len(r)
        pr = miss_r + base_r if len(r) == len(self.rm) else np.searchsorted(r, miss_r) + base_r
        pc = miss_c + base_c if len(c) == len(self.cm) else np.searchsorted(c, miss_c) + base_c
        return np.concatenate([pos, pr, pc])

    # ------------------------------------------------------------ checking
    def check(self, col_of_row: np.ndarray) -> Checked | str:
        """Re-check an engine's answer and price it from the costs, in bulk.

        Returns a :class:`Checked`, or the reason the answer is not feasible.
        """
        n1, n2 = self.C.shape
        cor = np.asarray(col_of_row, dtype=np.int64)
        if cor.shape != (n1,):
            return f"the answer has {cor.shape} row entries, not ({n1},)"
        if self.slack and n1 == n2:
            return self._check_permutation(cor)
        if n1 + n2 <= SMALL:
            return self._check_small(cor)
        return self._check_bulk(cor)

    def _check_bulk(self, cor: np.ndarray) -> Checked | str:
        """:meth:`check` in numpy (any size)."""
        n1, n2 = self.C.shape
        assigned = cor >= 0
        rows = assigned.nonzero()[0]
        cols = cor[rows]
        lst = cols.tolist()
        if lst and (max(lst) >= n2 or len(set(lst)) != len(lst)):
            return "a column is assigned twice, or a column index is out of range"
        used = np.zeros(n2, bool)
        used[cols] = True
        miss_c = (~used).nonzero()[0]
        miss_r = (~assigned).nonzero()[0]
        objective = math.fsum(self.C[rows, cols].tolist() + self.rm.take(miss_r).tolist()
                              + self.cm.take(miss_c).tolist())
        if not math.isfinite(objective):      # no -inf or NaN exists: some part is +inf
            return self._why_infinite(rows, cols, miss_r, miss_c)
        selected = self.positions(rows, cols, miss_r, miss_c)
        k = len(rows)
        if self.slack:
            tuples = np.empty((k, 2), np.int64)
            tuples[:, 0] = rows + 1
            tuples[:, 1] = cols + 1
        else:
            kr = k + len(miss_r)
            tuples = np.zeros((kr + len(miss_c), 2), np.int64)
            tuples[:k, 0] = rows + 1
            tuples[:k, 1] = cols + 1
            tuples[k:kr, 0] = miss_r + 1
            tuples[kr:, 1] = miss_c + 1
        return Checked(selected, objective, tuples)

    def _check_small(self, cor: np.ndarray) -> Checked | str:
        """:meth:`check` on Python lists: for a scan's few rows the numpy calls of
        :meth:`_check_bulk` cost more than the work (same answers, tested).  One pass
        splits the rows; the pairs are priced through the positions array (their flat
        indices when every entry is finite), the misses from the miss lists."""
        n1, n2 = self.C.shape
        rows: list[int] = []
        cols: list[int] = []
        miss_r: list[int] = []
        for i, j in enumerate(cor.tolist()):
            if j < 0:
                miss_r.append(i)
            else:
                rows.append(i)
                cols.append(j)
        taken = set(cols)
        if cols and (max(cols) >= n2 or len(taken) != len(cols)):
            return "a column is assigned twice, or a column index is out of range"
        miss_c = [j for j in range(n2) if j not in taken]
        k = len(rows)
        r_idx, c_idx = self.miss_index
        selected = None
        if self.all_finite and len(r_idx) == n1 and len(c_idx) == n2:
            base_r = self.n_pairs
            base_c = base_r + n1
            selected = np.array([i * n2 + j for i, j in zip(rows, cols)]
                                + [base_r + i for i in miss_r]
                                + [base_c + j for j in miss_c], np.int64)
            flat = selected[:k]
        else:
            flat = np.array([i * n2 + j for i, j in zip(rows, cols)], np.int64)
        rl, cl = self.rm.tolist(), self.cm.tolist()
        objective = math.fsum(self.C.take(flat).tolist() + [rl[i] for i in miss_r]
                              + [cl[j] for j in miss_c])
        if not math.isfinite(objective):
            return self._why_infinite(*(np.array(v, np.int64) for v in (
                rows, cols, miss_r, miss_c)))
        if selected is None:
            selected = self.positions(*(np.array(v, np.int64) for v in (
                rows, cols, miss_r, miss_c)))
        if self.slack:                 # the free surplus is never reported
            first, second = rows, cols
        else:                          # misses reported as (i, 0) and (0, j)
            first = rows + miss_r + [-1] * len(miss_c)
            second = cols + [-1] * len(miss_r) + miss_c
        tuples = np.empty((len(first), 2), np.int64)
        tuples[:, 0] = first
        tuples[:, 1] = second
        tuples += 1
        return Checked(selected, objective, tuples)

    def _why_infinite(self, rows: np.ndarray, cols: np.ndarray, miss_r: np.ndarray,
                      miss_c: np.ndarray) -> str:
        if not np.isfinite(self.C[rows, cols]).all():
            return "the answer uses a forbidden pair"
        if not np.isfinite(self.rm[miss_r]).all():
            return "the answer leaves out a row that must be assigned"
        return "the answer leaves out a column that must be assigned"

    def _check_permutation(self, cor: np.ndarray) -> Checked | str:
        """:meth:`check` for a square problem without misses: ``cor`` a permutation
        (checked as a Python set against the cached ``{0, ..., n-1}``: faster than numpy
        reductions for a scan's few rows, negligible beside the LAP for many)."""
        n = len(cor)
        if set(cor.tolist()) != _index_set(n):
            return "the answer is not a permutation of the columns"
        flat = _row_offsets(n, n) + cor
        objective = math.fsum(self.C.take(flat).tolist())
        if not math.isfinite(objective):
            return "the answer uses a forbidden pair"
        selected = flat if self._pair_rank is None else self._pair_rank[flat]
        tuples = _pair_base(n).copy()       # rows 1..n in column 0, 1 in column 1
        tuples[:, 1] += cor
        return Checked(selected, objective, tuples)
