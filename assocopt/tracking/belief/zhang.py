"""Paper 000's conflict measure (eq. 4) and combination rule (eqs. 10-11).

:func:`zhang_conflict` (``K = 1 - <BetP1, BetP2>``) and
:func:`zhang_combination` (the weighted, unnormalised rule whose empty-set mass is
that conflict: eq. (11) as printed says K^a, which breaks the sum to 1), for one pair
of mass functions and, as ``*_vectors``
/ ``*_matrix`` functions, for stacked mass vectors in bulk.  Kept apart from the
classical rules in :mod:`assocopt.tracking.belief.combination`, whose kernels it reuses.
(The module is not called ``conflict`` so that it cannot shadow the
:func:`assocopt.tracking.belief.conflict` function as a package attribute.)
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

from ._bitmask import _betp_matrix, _overlap_weight
from .combination import _combine_pair, _combine_stacked, _operands
from .mass import MassFunction, _size_of

__all__ = [
    "zhang_conflict", "zhang_combination",
    "zhang_combination_vectors", "zhang_conflict_vectors", "zhang_conflict_matrix",
]


def zhang_conflict(m1: MassFunction, m2: MassFunction) -> float:
    """Paper 000's new conflict measure (eq. 4) between two mass functions.

    ``K = K0 + sum over intersecting (A, B) of m1(A) m2(B) (|A||B| - |A & B|) / (|A||B|)``;
    equal to ``1 - <BetP1, BetP2>``.  Not zero for a mass function with
    itself when it has non-singleton focal sets (two vacuous reports on 6 types give 5/6).

    >>> v = MassFunction.vacuous(tuple("abcdef"))
    >>> round(zhang_conflict(v, v), 12)   # 1 - 1/6
    0.833333333333
    """
    _, (a, b) = _operands((m1, m2), "zhang_conflict", exactly=2)
    return float(zhang_conflict_vectors(a, b))


def zhang_combination(m1: MassFunction, m2: MassFunction) -> MassFunction:
    """Paper 000's new combination rule (eqs. 10-11), unnormalised.

    ``m(C) = sum_{A & B = C} m1(A) m2(B) |C| / (|A| |B|)`` for ``C`` non-empty and
    ``m(empty) = zhang_conflict(m1, m2)`` (eq. 11 corrected, docs/papers/zhang2009.md: the conflict
    between the two combined functions).  Sums to 1; equals :func:`conjunctive`
    when every focal set is a singleton.  Commutative, not associative, so it is
    defined for two operands only.
    """
    frame, (a, b) = _operands((m1, m2), "zhang_combination", exactly=2)
    return MassFunction._wrap(frame, _combine_pair(a, b, weighted=True))


def zhang_combination_vectors(a: ArrayLike, b: ArrayLike) -> np.ndarray:
    """Paper 000's new rule (10)-(11) on stacked vectors ``(..., 2**n)`` (broadcast), unchecked."""
    return _combine_stacked(a, b, weighted=True)


def zhang_conflict_vectors(a: ArrayLike, b: ArrayLike) -> np.ndarray:
    """New conflict (eq. 4) of stacked vector pairs (broadcast)."""
    a = np.asarray(a, dtype=np.float64)
    b = np.asarray(b, dtype=np.float64)
    size = _size_of(a, "a")
    w = _overlap_weight(size)
    return a.sum(axis=-1) * b.sum(axis=-1) - ((a @ w) * b).sum(axis=-1)


def zhang_conflict_matrix(a: ArrayLike, b: ArrayLike) -> np.ndarray:
    """New conflict ``K[i, j]`` (eq. 4) between rows of ``a`` and ``b``, in bulk.

    Computed as ``1 - <BetP_a, BetP_b>``.

    ``K = 1 - <u_i, u_j>`` with ``u = m @ P`` the (unnormalised) pignistic vectors.
    """
    a = np.asarray(a, dtype=np.float64)
    b = np.asarray(b, dtype=np.float64)
    P = _betp_matrix(_size_of(a, "a"))
    return np.outer(a.sum(axis=-1), b.sum(axis=-1)) - (a @ P) @ (b @ P).T
