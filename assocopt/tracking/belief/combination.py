"""Classical combination rules and transforms.

Smets' unnormalised conjunctive rule, the traditional conflict ``K0`` (eq. 3),
Dempster's rule, Shafer's discounting (eqs. 7-9) and the pignistic transform --
one :class:`~assocopt.tracking.belief.mass.MassFunction` at a time and, as ``*_vectors`` /
``*_matrix`` functions, on stacked mass vectors in bulk.  The pairwise kernels
here (:func:`_combine_pair`, :func:`_combine_stacked`) also serve paper 000's
weighted rule in :mod:`assocopt.tracking.belief.zhang`.
"""

from __future__ import annotations

import numbers

import numpy as np
from numpy.typing import ArrayLike

from ._bitmask import _and_table, _betp_matrix, _disjoint, _overlap_weight
from .mass import (CONFLICT_TOL, InvalidMassError, MassFunction, TotalConflictError, _aligned,
                   _size_of)

__all__ = [
    "conjunctive", "dempster", "conflict", "discount", "pignistic",
    "conjunctive_vectors", "conflict_vectors", "discount_vectors", "pignistic_vectors",
    "conflict_matrix",
]


def _operands(ms: tuple, name: str, exactly: int | None = None) -> tuple[tuple, list]:
    if exactly is not None and len(ms) != exactly:
        raise TypeError(f"{name} takes exactly {exactly} mass functions, got {len(ms)}")
    if not ms:
        raise TypeError(f"{name} needs at least one mass function")
    for m in ms:
        if not isinstance(m, MassFunction):
            raise TypeError(f"{name} combines MassFunction objects, got {type(m).__name__}")
    frame = ms[0].frame
    return frame, [_aligned(m, frame) for m in ms]


def _combine_pair(a: np.ndarray, b: np.ndarray, weighted: bool) -> np.ndarray:
    """Conjunctive (or paper-000 weighted) combination of two vectors, over focal sets only."""
    size = len(a)
    fa, fb = np.flatnonzero(a), np.flatnonzero(b)
    prod = a[fa][:, None] * b[fb][None, :]
    inter = fa[:, None] & fb[None, :]
    if weighted:
        w = _overlap_weight(size)[fa[:, None], fb[None, :]]
        out = np.bincount(inter.ravel(), weights=(prod * w).ravel(), minlength=size)
        out[0] = float((prod * (1.0 - w)).sum())
        return out
    return np.bincount(inter.ravel(), weights=prod.ravel(), minlength=size)


# -------------------------------------------------------------- operations
def conjunctive(*ms: MassFunction) -> MassFunction:
    """Smets' unnormalised conjunctive rule of one or more mass functions.

    ``m(C) = sum over A1 & ... & Ak = C of prod m_i(A_i)``; the conflict stays on
    the empty set.  Commutative and associative; the vacuous mass function is its
    neutral element.  Frames must hold the same elements (order may differ; the
    result uses the first operand's order).

    >>> f = ("a", "b")
    >>> m1 = MassFunction(f, {frozenset("a"): 0.5, frozenset("ab"): 0.5})
    >>> m2 = MassFunction(f, {frozenset("b"): 0.4, frozenset("ab"): 0.6})
    >>> conjunctive(m1, m2).to_dict() == {frozenset(): 0.2, frozenset("a"): 0.3,
    ...                                   frozenset("b"): 0.2, frozenset("ab"): 0.3}
    True
    """
    frame, vecs = _operands(ms, "conjunctive")
    out = vecs[0].copy()
    for v in vecs[1:]:
        out = _combine_pair(out, v, weighted=False)
    return MassFunction._wrap(frame, out)


def conflict(*ms: MassFunction) -> float:
    """Traditional conflict ``K0``: the mass the conjunctive rule puts on the empty set (eq. 3)."""
    return conjunctive(*ms).empty_mass


def dempster(*ms: MassFunction) -> MassFunction:
    """Dempster's rule: the conjunctive combination normalised by ``1 - K0``.

    Raises
    ------
    TotalConflictError
        When the combined conflict ``K0`` is 1 (within :data:`CONFLICT_TOL`).
    """
    c = conjunctive(*ms)
    k = c.empty_mass
    if 1.0 - k <= CONFLICT_TOL:
        raise TotalConflictError(
            f"Dempster's rule is undefined: the mass functions are in total conflict "
            f"(K0 = {k!r}); use conjunctive() to keep the conflict on the empty set")
    out = c._m.copy()
    out[0] = 0.0
    out /= 1.0 - k
    return MassFunction._wrap(c.frame, out)


def discount(m: MassFunction, reliability: float) -> MassFunction:
    """Shafer's discounting (eqs. 7-9): ``r m(A)`` for ``A != frame``, the rest on the frame.

    >>> m = MassFunction(("M", "Mbar"), {frozenset({"M"}): 1.0})
    >>> discount(m, 0.6).to_dict() == {frozenset({"M"}): 0.6, frozenset({"M", "Mbar"}): 0.4}
    True
    """
    if not isinstance(m, MassFunction):
        raise TypeError(f"discount takes a MassFunction, got {type(m).__name__}")
    r = _check_reliability(reliability, "reliability")
    out = r * m._m
    out[-1] += 1.0 - r
    return MassFunction._wrap(m.frame, out)


def pignistic(m: MassFunction) -> dict:
    """Pignistic probability ``BetP(w) = sum_{A containing w} m(A) / (|A| (1 - m(empty)))``.

    Returns ``{element: probability}`` in frame order.

    Raises
    ------
    TotalConflictError
        When ``m(empty) = 1`` (nothing left to distribute).

    >>> pignistic(MassFunction(("a", "b"), {frozenset("a"): 0.5, frozenset("ab"): 0.5}))
    {'a': 0.75, 'b': 0.25}
    """
    if not isinstance(m, MassFunction):
        raise TypeError(f"pignistic takes a MassFunction, got {type(m).__name__}")
    p = pignistic_vectors(m._m)
    return {e: float(p[k]) for k, e in enumerate(m.frame)}


def _check_reliability(r: object, what: str) -> float:
    if isinstance(r, bool) or not isinstance(r, numbers.Real) or not (0.0 <= float(r) <= 1.0):
        raise InvalidMassError(f"{what} must be a number in [0, 1], got {r!r}")
    return float(r)


# ------------------------------------------------- bulk (stacked vectors)
def conjunctive_vectors(a: ArrayLike, b: ArrayLike) -> np.ndarray:
    """Smets' conjunctive rule on stacked vectors ``(..., 2**n)`` (broadcast), unchecked."""
    return _combine_stacked(a, b, weighted=False)


def _combine_stacked(a: ArrayLike, b: ArrayLike, weighted: bool) -> np.ndarray:
    a = np.asarray(a, dtype=np.float64)
    b = np.asarray(b, dtype=np.float64)
    size = _size_of(a, "a")
    if b.shape[-1] != size:
        raise InvalidMassError(f"vectors of different frames: last axes {size} and {b.shape[-1]}")
    shape = np.broadcast_shapes(a.shape, b.shape)
    A = np.broadcast_to(a, shape).reshape(-1, size)
    B = np.broadcast_to(b, shape).reshape(-1, size)
    k = len(A)
    prod = A[:, :, None] * B[:, None, :]
    if weighted:
        w = _overlap_weight(size)
        empty = np.einsum("kab,ab->k", prod, 1.0 - w)
        prod = prod * w
    idx = (np.arange(k)[:, None] * size + _and_table(size).ravel()[None, :]).ravel()
    out = np.bincount(idx, weights=prod.reshape(k, -1).ravel(), minlength=k * size)
    out = out.reshape(k, size)
    if weighted:
        out[:, 0] = empty
    return out.reshape(shape)


def conflict_vectors(a: ArrayLike, b: ArrayLike) -> np.ndarray:
    """Traditional conflict ``K0`` (eq. 3) of stacked vector pairs (broadcast)."""
    a = np.asarray(a, dtype=np.float64)
    b = np.asarray(b, dtype=np.float64)
    size = _size_of(a, "a")
    return ((a @ _disjoint(size)) * b).sum(axis=-1)


def conflict_matrix(a: ArrayLike, b: ArrayLike) -> np.ndarray:
    """``K0[i, j]`` between rows of ``a`` (N1 x 2**n) and ``b`` (N2 x 2**n): eq. (3) in bulk."""
    a = np.asarray(a, dtype=np.float64)
    b = np.asarray(b, dtype=np.float64)
    return a @ _disjoint(_size_of(a, "a")) @ b.T


def discount_vectors(a: ArrayLike, reliability: ArrayLike) -> np.ndarray:
    """Discount stacked vectors by reliabilities (broadcast against the leading axes)."""
    a = np.asarray(a, dtype=np.float64)
    _size_of(a, "a")
    r = np.asarray(reliability, dtype=np.float64)
    if not np.all((r >= 0.0) & (r <= 1.0)):
        raise InvalidMassError(f"reliability must be in [0, 1], got {r!r}")
    out = r[..., None] * a
    out[..., -1] += 1.0 - r
    return out


def pignistic_vectors(a: ArrayLike) -> np.ndarray:
    """Pignistic probabilities ``(..., n)`` of stacked vectors ``(..., 2**n)``."""
    a = np.asarray(a, dtype=np.float64)
    size = _size_of(a, "a")
    rest = a.sum(axis=-1) - a[..., 0]
    if np.any(rest <= CONFLICT_TOL):
        raise TotalConflictError("pignistic probability is undefined when m(empty) = 1")
    return (a @ _betp_matrix(size)) / rest[..., None]
