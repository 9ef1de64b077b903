"""Index arithmetic of an assignment problem, in one place for every back end.

A problem with axes of sizes ``n_1 .. n_N`` has one coverage constraint ("row") per
real index: row ``offset_s + i - 1`` stands for real index ``i`` (1-based) of axis
``s`` (0-based), ``offset_s = n_1 + ... + n_{s-1}``.  :class:`IndexArithmetic` gives
:class:`~assocopt.problems.problem.AssignmentProblem` the global row of every tuple entry, the
coverage matrix (of all candidates or a window of them), the uncovered rows and
indices, their labels, the kept-axes rule of the Lagrangian relaxations and whether
the costs are integers; :data:`OPT_TOL` is the one relative tolerance of "a bound
meets an objective".  Back ends use these instead of their own copies.
"""

from __future__ import annotations

import functools
import math
from typing import TYPE_CHECKING, Any, Sequence

import numpy as np
from numpy.typing import ArrayLike

from ..runtime.errors import InvalidProblemError
from .validation import require_memory

if TYPE_CHECKING:   # pragma: no cover
    import scipy.sparse as sp

__all__ = ["OPT_TOL", "IndexArithmetic", "index_label", "kept_axes", "real_counts"]

#: Relative tolerance of "a bound meets an objective" for non-integer costs
#: (floating-point round-off): the one tolerance the exact back ends share.
OPT_TOL = 1e-9


def index_label(axis: int, index: int) -> str:
    """``"index i of axis s"`` with the conventions spelled out (axis 0-based, index 1-based)."""
    return f"real index {index} (1-based) of axis {axis} (0-based)"


def real_counts(tuples: np.ndarray) -> np.ndarray:
    """How many real (non-dummy) indices each tuple of ``tuples`` (shape (k, N)) has.

    Column by column: ``(T > 0).sum(axis=1)`` reduces along the short axis, five
    times slower on a dense 3-AP's 125,000 tuples (2 ms).

    >>> real_counts(np.array([[1, 0, 2], [0, 0, 3]])).tolist()
    [2, 1]
    """
    T = np.asarray(tuples)
    out = np.zeros(len(T), np.int64)
    for s in range(T.shape[1] if T.ndim == 2 else 0):
        out += T[:, s] > 0
    return out


def kept_axes(sizes: Sequence[int], keep: Any = None) -> tuple[int, int]:
    """The two axes a Lagrangian relaxation keeps, sorted: ``keep`` checked, or by
    default the two largest (the lower axis number first on ties).

    >>> kept_axes((3, 5, 4)), kept_axes((3, 5, 4), keep=(2, 0))
    ((1, 2), (0, 2))
    """
    N = len(sizes)
    if keep is None:
        order = sorted(range(N), key=lambda s: (-sizes[s], s))
        return min(order[:2]), max(order[:2])
    try:
        a, b = (int(v) for v in keep)
    except (TypeError, ValueError):
        raise InvalidProblemError(f"keep_axes must be two axis numbers, got {keep!r}") from None
    if not (0 <= a < N and 0 <= b < N and a != b):
        raise InvalidProblemError(f"keep_axes must be two different axes in 0..{N - 1}, "
                                  f"got {keep!r}")
    return min(a, b), max(a, b)


class IndexArithmetic:
    """Mixin of :class:`~assocopt.problems.problem.AssignmentProblem`: needs ``sizes``,
    ``tuples``, ``costs``, ``n_rows`` and ``row_offsets``."""

    sizes: tuple[int, ...]
    tuples: np.ndarray
    costs: np.ndarray
    n_rows: int
    row_offsets: np.ndarray

    def rows_of(self, tuples: np.ndarray) -> np.ndarray:
        """Global constraint row of every entry of ``tuples`` (shape (k, N)), ``-1``
        for dummies: row ``offset_s + i - 1`` stands for real index ``i`` of axis s."""
        T = np.asarray(tuples, dtype=np.int64)
        R = T + (self.row_offsets - 1)            # (an add and a masked store: 2.5x
        np.putmask(R, T <= 0, -1)                 # quicker than np.where)
        return R

    @functools.cached_property
    def entry_rows(self) -> np.ndarray:
        """:meth:`rows_of` the candidate tuples, ``(K, N)``, read-only (cached)."""
        rows = self.rows_of(self.tuples)
        rows.setflags(write=False)
        return rows

    def coverage_matrix(self, pos: ArrayLike | None = None) -> "sp.csr_matrix":
        """CSR matrix ``A`` (sum n_s x K): ``A[r, k] = 1`` if candidate k covers row r.

        With ``pos``, the columns of those candidates only (a window of them).
        Row ``offset_s + i - 1`` stands for real index ``i`` of axis ``s``.
        Built in bulk from the tuple array.
        """
        import scipy.sparse as sp     # here: importing assocopt need not load scipy

        R = self._rows_at(pos)
        real = R >= 0
        require_memory(8 * (self.n_rows + 1) + 16 * int(real.sum()), "the constraint matrix",
                       f"{self.n_rows} rows x {len(R)} candidates")
        cols = np.broadcast_to(np.arange(len(R))[:, None], R.shape)[real]
        A = sp.csr_matrix((np.ones(len(cols)), (R[real], cols)),
                          shape=(self.n_rows, len(R)))
        A.sort_indices()
        return A

    def uncovered_rows(self, pos: ArrayLike | None = None) -> np.ndarray:
        """Constraint rows that no candidate (of ``pos``, if given) covers."""
        # per axis: no row numbers needed (nor the cache of all candidates' rows)
        T = self.tuples if pos is None else self.tuples[np.asarray(pos, np.int64)]
        return np.concatenate([
            np.flatnonzero(np.bincount(T[:, s], minlength=n + 1)[1:] == 0) + self.row_offsets[s]
            for s, n in enumerate(self.sizes)]).astype(np.int64)

    def _rows_at(self, pos: ArrayLike | None) -> np.ndarray:
        """:attr:`entry_rows` of the candidates ``pos`` (all when None), from the cache
        when it is built, else of those candidates only: a window of a fifth of a
        dense 3-AP's candidates need not pay for all of them."""
        if pos is None:
            return self.entry_rows
        pos = np.asarray(pos, np.int64)
        if "entry_rows" in self.__dict__:
            return self.entry_rows[pos]
        return self.rows_of(self.tuples[pos])

    def uncovered(self, limit: int | None = None) -> list[tuple[int, int]]:
        """Real indices ``(axis, index)`` that no candidate covers (1-based index),
        at most ``limit`` of them (all when None); :attr:`n_uncovered` counts them.

        Any such index makes the problem infeasible.  Computed from the candidates
        alone (sorted covered indices per axis), never with an array of ``n_s``
        entries, so huge declared sizes with few candidates cost nothing.
        """
        if limit is None:
            limit = self.n_uncovered
        out: list[tuple[int, int]] = []
        for axis, covered in enumerate(self._covered):
            prev = 0
            for c in list(covered) + [self.sizes[axis] + 1]:
                for i in range(prev + 1, min(int(c), prev + 1 + limit - len(out))):
                    out.append((axis, i))
                if len(out) >= limit:
                    return out
                prev = int(c)
        return out

    @property
    def n_uncovered(self) -> int:
        """How many real indices no candidate covers (0 for a feasible-looking problem).

        A full grid of all-real tuples (they are distinct) covers every index: known
        without counting them (every solve asks; 2 ms on a dense 3-AP of n = 50)."""
        K = len(self.tuples)
        if K and K == math.prod(self.sizes) and int(self.tuples.min()) > 0:
            return 0
        return int(sum(n - len(c) for n, c in zip(self.sizes, self._covered)))

    @functools.cached_property
    def _covered(self) -> tuple[np.ndarray, ...]:
        """Sorted distinct real indices each axis's candidates cover (counted when the
        axis is not much longer than the candidate list: a sort of a dense 3-AP's
        125 000 indices per axis cost 2 ms, the count a tenth of that)."""
        T = self.tuples
        K = len(T)
        return tuple(np.flatnonzero(np.bincount(T[:, s], minlength=n + 1)[1:]) + 1
                     if n <= 4 * K + 1024 else np.unique(T[:, s][T[:, s] > 0])
                     for s, n in enumerate(self.sizes))

    def axis_index(self, row: int) -> tuple[int, int]:
        """``(axis, real index)`` (index 1-based) of constraint row ``row``."""
        a = int(np.searchsorted(self.row_offsets, row, side="right") - 1)
        return a, int(row - self.row_offsets[a] + 1)

    def kept_axes(self, keep: Any = None) -> tuple[int, int]:
        """The two kept axes of a Lagrangian relaxation (see :func:`kept_axes`)."""
        return kept_axes(self.sizes, keep)

    @functools.cached_property
    def integer_costs(self) -> bool:
        """Whether every cost is an integer small enough to be exact in float64."""
        c = self.costs
        return bool(np.all(c == np.round(c)) and np.abs(c).max(initial=0) < 2 ** 52)

    def row_label(self, row: int) -> str:
        """Human-readable name of constraint row ``row``: its axis and real index."""
        return index_label(*self.axis_index(row))
