"""The assignment problem: one sparse S-D cost tensor for every case.

Notation (as in docs/papers/): there are N index sets ("axes": sensors, or rows and
columns in 2-D) of sizes ``n_1 .. n_N``.  A *candidate tuple* ``(i_1, ..., i_N)``
picks one index per axis; ``i_s = 0`` is the **dummy** (missed detection / not
assigned) and ``1 .. n_s`` are the real indices.  A feasible solution chooses
candidates so that **every real index of every axis is covered exactly once**; the
dummy may be reused by any number of tuples; the all-dummy tuple is never a
candidate.  The objective is the sum of the chosen candidates' costs.

Every user-facing case is stored in this one form:

* ``AssignmentProblem.dense(C)`` -- axial N-D (N >= 2) on a full cost array.  With
  unequal sizes the smallest axis is fully assigned and the other axes' surplus
  indices stay free (scipy's rectangular ``linear_sum_assignment`` semantics): they
  are covered by zero-cost *slack* candidates, which solutions never report.
* ``AssignmentProblem.two_d(C, row_miss, col_miss)`` -- 2-D with non-assignment
  costs: ``(i, 0)`` costs ``row_miss[i]``, ``(0, j)`` costs ``col_miss[j]``.
* ``AssignmentProblem.sparse(sizes, tuples, costs)`` -- general S-D with dummies.

``+inf`` costs mean "forbidden": such candidates are dropped and never reach a
solver.  NaN and ``-inf`` are errors.
"""

from __future__ import annotations

import functools
import math

from dataclasses import dataclass, field
from typing import Any, Sequence

import numpy as np
from numpy.typing import ArrayLike

from ..runtime.errors import InvalidProblemError
from .indexing import OPT_TOL, IndexArithmetic, index_label, kept_axes
from .twod import MAX_DENSE_CANDIDATES, LazyView, from_matrix, miss_vector
from .validation import (MAX_ABS_COST, MAX_SIZE, check_sizes, check_tuples,  # noqa: F401
                         require_memory)
from .values import _as_cost_array, _as_matrix, _reject_non_finite

__all__ = ["AssignmentProblem", "OPT_TOL", "kept_axes", "index_label", "MAX_DENSE_CANDIDATES"]


def _index_grid(sizes: tuple[int, ...]) -> np.ndarray:
    """Every real tuple ``(i_1, .., i_N)``, 1-based, in C order: ``(prod(sizes), N)``
    int64 (what ``np.nonzero`` of an all-true array gives, plus one, without its cost)."""
    N = len(sizes)
    out = np.empty(sizes + (N,), dtype=np.int64)
    for axis, n in enumerate(sizes):
        shape = [1] * N
        shape[axis] = n
        out[..., axis] = np.arange(1, n + 1).reshape(shape)
    return out.reshape(-1, N)


def _freeze(arr: np.ndarray) -> np.ndarray:
    arr.setflags(write=False)
    return arr


@dataclass(frozen=True, eq=False)
class AssignmentProblem(IndexArithmetic):
    """A validated S-D assignment problem (see the module docstring for the model).

    Build it with :meth:`dense`, :meth:`two_d` or :meth:`sparse`, not directly.

    Attributes
    ----------
    sizes : tuple of int
        ``n_s``, the number of real indices on each axis.
    tuples : ndarray of int64, shape (K, N)
        Candidate tuples; ``0`` is the dummy, real indices are ``1..n_s``.
    costs : ndarray of float64, shape (K,)
        Finite candidate costs.
    slack : ndarray of bool, shape (K,)
        Candidates added by :meth:`dense` to leave surplus indices free; they
        cost 0 and are left out of reported solutions.
    kind : str
        ``"dense"``, ``"two_d"`` or ``"sparse"``: how the problem was built.
    maximize : bool
        Built with ``maximize=True``: the given values are scores to maximise; the
        problem stores them negated (``costs`` is always in the minimisation sense)
        and :class:`~assocopt.Solution` reports objective and bound in the user's sense.
    name : str or None
    optimum : float or None
        A recorded, proven optimum (from an instance file), used for checks only.

    Examples
    --------
    >>> import numpy as np
    >>> p = AssignmentProblem.dense(np.array([[4.0, 1.0], [2.0, 3.0]]))
    >>> p.sizes, p.n_candidates
    ((2, 2), 4)
    """

    sizes: tuple[int, ...]
    tuples: np.ndarray
    costs: np.ndarray
    slack: np.ndarray
    kind: str = "sparse"
    name: str | None = None
    optimum: float | None = None
    meta: dict[str, Any] = field(default_factory=dict)
    maximize: bool = False
    #: The dense 2-D view (:class:`assocopt.problems.twod.Dense2D`) when built from a matrix.
    _dense: Any = field(default=None, init=False, repr=False)

    # ------------------------------------------------------------------ builders
    @classmethod
    def dense(cls, costs: ArrayLike, *, name: str | None = None,
              optimum: float | None = None, maximize: bool = False) -> "AssignmentProblem":
        """Axial assignment on a full ``n_1 x ... x n_N`` cost array (N >= 2).

        The smallest axis is assigned completely; surplus indices of larger axes
        stay unassigned at no cost.  ``+inf`` entries are forbidden tuples.
        ``maximize=True``: the values are scores (log-likelihoods...) to maximise, as
        scipy's ``maximize``; ``-inf`` is then forbidden.  A 2-D matrix is kept as
        given (no candidate list until a back end needs one).
        """
        C, all_finite, amax = _as_matrix(costs, "cost array", maximize)
        if C.ndim == 2:
            return from_matrix(cls, C, None, None, all_finite, amax=(amax, 0.0, 0.0),
                               kind="dense", name=name, optimum=optimum,
                               maximize=maximize)
        _reject_non_finite(C, "cost array", maximize)
        if C.ndim < 2:
            raise InvalidProblemError(
                f"cost array must have at least 2 dimensions, got shape {C.shape}")
        if C.size > MAX_DENSE_CANDIDATES:
            raise InvalidProblemError(
                f"cost array of shape {C.shape} has {C.size} entries, more than "
                f"{MAX_DENSE_CANDIDATES}; build a sparse problem of the gated candidates")
        sizes = tuple(int(n) for n in C.shape)
        finite = np.isfinite(C)
        if finite.all():        # every tuple is a candidate: a grid, C in C order
            tuples, costs_list = [_index_grid(sizes)], [C.reshape(-1)]
        else:
            tuples = [np.stack(np.nonzero(finite), axis=1).astype(np.int64) + 1]
            costs_list = [C[finite]]
        n_min = min(sizes)
        # Slack singletons leave the surplus indices of larger axes free.
        for axis, n in enumerate(sizes):
            if n > n_min:
                t = np.zeros((n, len(sizes)), dtype=np.int64)
                t[:, axis] = np.arange(1, n + 1)
                tuples.append(t)
                costs_list.append(np.zeros(n))
        slack = np.zeros(sum(len(c) for c in costs_list), dtype=bool)
        slack[len(costs_list[0]):] = True
        if len(tuples) > 1:
            tuples, costs_list = [np.concatenate(tuples)], [np.concatenate(costs_list)]
        return cls._build(sizes, tuples[0], costs_list[0], slack, kind="dense", name=name,
                          optimum=optimum, maximize=maximize)

    @classmethod
    def two_d(cls, costs: ArrayLike, row_miss: ArrayLike | None = None,
              col_miss: ArrayLike | None = None, *, name: str | None = None,
              optimum: float | None = None, maximize: bool = False) -> "AssignmentProblem":
        """2-D assignment of an ``n1 x n2`` cost matrix with non-assignment costs.

        Row ``i`` left unassigned costs ``row_miss[i]``, column ``j`` costs
        ``col_miss[j]`` (scalars broadcast).  ``inf`` forbids leaving it
        unassigned.  With neither given this is :meth:`dense` (the smaller side
        fully assigned); with only one given, the other side must be assigned.
        ``maximize=True``: matrix and misses are scores to maximise (``-inf`` forbids).
        """
        C, all_finite, amax = _as_matrix(costs, "cost matrix", maximize)
        if C.ndim != 2:
            raise InvalidProblemError(f"cost matrix must be 2-D, got shape {C.shape}")
        if row_miss is None and col_miss is None:
            return from_matrix(cls, C, None, None, all_finite, amax=(amax, 0.0, 0.0),
                               kind="dense", name=name, optimum=optimum,
                               maximize=maximize)
        n1, n2 = C.shape
        (rm, fr, ar), (cm, fc, ac) = (miss_vector(row_miss, n1, "row_miss", maximize),
                                      miss_vector(col_miss, n2, "col_miss", maximize))
        return from_matrix(cls, C, rm, cm, all_finite, (fr, fc), amax=(amax, ar, ac),
                           kind="two_d", name=name, optimum=optimum, maximize=maximize)

    @property
    def dense_view(self) -> Any:
        """The :class:`~assocopt.problems.twod.Dense2D` of a problem built from a 2-D
        matrix, else None."""
        return self._dense

    @classmethod
    def sparse(cls, sizes: Sequence[int], tuples: ArrayLike, costs: ArrayLike, *,
               name: str | None = None, optimum: float | None = None,
               maximize: bool = False) -> "AssignmentProblem":
        """General S-D problem from candidate tuples (index 0 = dummy) and costs.

        Candidates with ``+inf`` cost are dropped (``-inf`` with ``maximize=True``,
        where ``costs`` are scores to maximise).  Indices must be integers in
        ``0..n_s``; duplicate tuples and the all-dummy tuple are errors.
        """
        sizes_t = cls._check_sizes(sizes)
        N = len(sizes_t)
        T = cls._check_tuples(tuples, sizes_t)
        c = _as_cost_array(costs, "costs", maximize)
        if c.ndim != 1 or len(c) != len(T):
            raise InvalidProblemError(
                f"costs must have shape ({len(T)},) to match tuples of shape "
                f"({len(T)}, {N}), got shape {c.shape}")
        keep = np.isfinite(c)
        if not keep.all():
            T, c = T[keep], c[keep]
        return cls._build(sizes_t, T, c, np.zeros(len(c), bool), kind="sparse",
                          name=name, optimum=optimum, maximize=maximize)

    @staticmethod
    def _check_sizes(sizes: Sequence[int]) -> tuple[int, ...]:
        return check_sizes(sizes)

    @staticmethod
    def _check_tuples(tuples: ArrayLike, sizes: tuple[int, ...]) -> np.ndarray:
        return check_tuples(tuples, sizes)

    @classmethod
    def _build(cls, sizes, tuples, costs, slack, **kw) -> "AssignmentProblem":
        return cls(sizes=tuple(sizes), tuples=_freeze(np.ascontiguousarray(tuples, np.int64)),
                   costs=_freeze(np.ascontiguousarray(costs, np.float64)),
                   slack=_freeze(np.ascontiguousarray(slack, bool)), **kw)

    # ------------------------------------------------------------- properties
    @property
    def ndim(self) -> int:
        """N, the number of axes."""
        return len(self.sizes)

    @property
    def n_candidates(self) -> int:
        """K, the number of candidate tuples (slack included)."""
        if self._dense is not None:
            return self._dense.n_candidates
        return len(self.costs)

    @property
    def n_rows(self) -> int:
        """Number of coverage constraints: one per real index, ``sum(n_s)``."""
        return int(sum(self.sizes))

    @functools.cached_property
    def row_offsets(self) -> np.ndarray:
        """Row of real index 1 of each axis in the constraint matrix (cached: the
        problem is immutable, and small solves call this several times)."""
        off = np.concatenate([[0], np.cumsum(self.sizes)[:-1]]).astype(np.int64)
        off.setflags(write=False)
        return off

    def uncovered(self, limit: int | None = None) -> list[tuple[int, int]]:
        """Real indices ``(axis, index)`` that no candidate covers (1-based index), at
        most ``limit``; for a dense 2-D problem read from the matrix, without building
        the candidate list (else from the candidates alone, see IndexArithmetic)."""
        if self._dense is not None:
            return self._dense.uncovered()[:limit]
        return super().uncovered(limit)

    @property
    def n_uncovered(self) -> int:
        """How many real indices no candidate covers."""
        if self._dense is not None:
            return len(self._dense.uncovered())
        return super().n_uncovered

    # ------------------------------------------------------------- solutions
    def violations(self, selected: ArrayLike) -> str | None:
        """Why ``selected`` (candidate positions) is not feasible, or None if it is."""
        sel = np.asarray(selected, dtype=np.int64)
        if sel.ndim != 1:
            return "selection must be a 1-D array of candidate positions"
        if len(sel) and (sel.min() < 0 or sel.max() >= self.n_candidates):
            return "selection refers to a candidate that does not exist"
        R = self._rows_at(sel)
        if self._exact_cover(sel, R):
            return None
        if len(np.unique(sel)) != len(sel):
            return "a candidate is selected twice"
        rows, count = np.unique(R[R >= 0], return_counts=True)
        twice = np.flatnonzero(count > 1)
        if len(twice):
            r = int(rows[twice[0]])
            return f"{self.row_label(r)} is covered {int(count[twice[0]])} times, not once"
        if len(rows) < self.n_rows:
            gap = np.flatnonzero(rows != np.arange(len(rows)))
            r = int(gap[0]) if len(gap) else len(rows)
            return f"{self.row_label(r)} is covered 0 times, not once"
        return None

    def _exact_cover(self, sel: np.ndarray, R: np.ndarray) -> bool:
        """Quick yes of :meth:`violations` for a sorted selection (every solve checks
        its answer): distinct candidates whose real indices number the rows and
        cover none twice cover each once.  False: not sure (the full check says)."""
        r = R[R >= 0]
        if len(r) != self.n_rows or (len(sel) > 1 and not bool((sel[1:] > sel[:-1]).all())):
            return False
        return len(r) == 0 or int(np.bincount(r, minlength=self.n_rows).max()) == 1

    def objective_of(self, selected: ArrayLike) -> float:
        """Sum of the costs of the selected candidates (math.fsum, exact rounding)."""
        import math
        return math.fsum(self.costs[np.asarray(selected, dtype=np.int64)].tolist())

    def value_of(self, selected: ArrayLike) -> float:
        """:meth:`objective_of` in the user's sense (scores' sum for ``maximize=True``)."""
        v = self.objective_of(selected)
        return -v if self.maximize else v

    def to_cost_matrix(self, fill: float = np.inf) -> np.ndarray:
        """Dense array of the all-real candidates' costs (``fill`` elsewhere)."""
        if self._dense is not None and fill == np.inf:
            return self._dense.C.copy()
        require_memory(8 * math.prod(self.sizes), "the dense cost array",
                       "shape " + " x ".join(map(str, self.sizes)))
        M = np.full(self.sizes, fill, dtype=np.float64)
        real = (self.tuples > 0).all(axis=1)
        M[tuple((self.tuples[real] - 1).T)] = self.costs[real]
        return M

    def miss_costs(self) -> tuple[np.ndarray, np.ndarray]:
        """For a 2-D problem: ``(row_miss, col_miss)`` with ``inf`` where forbidden."""
        if self.ndim != 2:
            raise InvalidProblemError("miss costs are defined for 2-D problems only")
        if self._dense is not None:
            return self._dense.rm.copy(), self._dense.cm.copy()
        rm = np.full(self.sizes[0], np.inf)
        cm = np.full(self.sizes[1], np.inf)
        T = self.tuples
        r = (T[:, 0] > 0) & (T[:, 1] == 0)
        c = (T[:, 0] == 0) & (T[:, 1] > 0)
        rm[T[r, 0] - 1] = self.costs[r]
        cm[T[c, 1] - 1] = self.costs[c]
        return rm, cm

    def __repr__(self) -> str:
        label = f" {self.name!r}" if self.name else ""
        return (f"<AssignmentProblem{label} kind={self.kind} sizes={self.sizes} "
                f"candidates={self.n_candidates}>")


for _name in ("tuples", "costs", "slack"):
    setattr(AssignmentProblem, _name, LazyView(_name))
del _name
