"""Mass functions (basic belief assignments) on small finite frames.

A frame of discernment is an ordered tuple of ``n`` element names; a subset ``A``
is the bitmask with bit ``k`` set when element ``k`` is in ``A`` (so ``0`` is the
empty set and ``2**n - 1`` the whole frame).  A mass function is a float64 vector
of length ``2**n`` indexed by bitmask.  The frames of paper 000 are tiny
(``{M, Mbar}`` and 6 target types), so the whole vector is stored.

Two layers:

* :class:`MassFunction` and the functions :func:`conjunctive`, :func:`dempster`,
  :func:`conflict`, :func:`discount`, :func:`pignistic`, :func:`zhang_conflict`,
  :func:`zhang_combination` -- one mass function at a time, validated, with
  element names.
* ``*_vectors`` / ``*_matrix`` functions -- the same operations on stacked mass
  vectors ``(..., 2**n)`` (numpy broadcasting), used to compute matching measures
  for every observation pair in bulk (:mod:`assocopt.group_matching`).

Rules (SPEC.md 000.2):

* Smets' unnormalised conjunctive rule:
  ``m(C) = sum_{A & B = C} m1(A) m2(B)``; the conflict ``K0 = m(empty)`` (eq. 3).
* Dempster's rule: the conjunctive result with ``m(empty)`` removed and the rest
  divided by ``1 - K0``; undefined (:class:`TotalConflictError`) when ``K0 = 1``.
* Paper 000's new conflict measure (eq. 4):
  ``K = sum_{A,B} m1(A) m2(B) (1 - |A & B| / (|A| |B|))`` (disjoint or empty pairs
  count fully), equal to ``1 - <BetP1, BetP2>`` (D0.2).
* Paper 000's new combination rule (eqs. 10-11): for ``C != empty``
  ``m(C) = sum_{A & B = C} m1(A) m2(B) |C| / (|A| |B|)``, and ``m(empty)`` is the
  new conflict of ``m1`` and ``m2``; it sums to 1 (D0.3) and equals Smets' rule when
  every focal set is a singleton.

Examples
--------
>>> m1 = MassFunction(("a", "b", "c"), {frozenset("a"): 0.6, frozenset("ab"): 0.4})
>>> m2 = MassFunction(("a", "b", "c"), {frozenset("b"): 0.5, frozenset("abc"): 0.5})
>>> round(conflict(m1, m2), 10)
0.3
>>> dempster(m1, m2).to_dict() == {frozenset("a"): 0.3 / 0.7, frozenset("b"): 0.2 / 0.7,
...                                 frozenset("ab"): 0.2 / 0.7}
True
"""

from __future__ import annotations

import math
import numbers
from collections.abc import Hashable, Iterable, Mapping
from functools import lru_cache

import numpy as np
from numpy.typing import ArrayLike

from .errors import AssocoptError

__all__ = [
    "InvalidMassError", "TotalConflictError", "MassFunction",
    "conjunctive", "dempster", "conflict", "discount", "pignistic",
    "zhang_conflict", "zhang_combination",
    "conjunctive_vectors", "zhang_combination_vectors", "conflict_vectors",
    "zhang_conflict_vectors", "discount_vectors", "pignistic_vectors",
    "conflict_matrix", "zhang_conflict_matrix", "check_vectors",
    "MAX_FRAME_SIZE", "MASS_TOL", "CONFLICT_TOL",
]

#: Largest frame stored as a dense vector of 2**n masses.
MAX_FRAME_SIZE = 20
#: Tolerance on "masses sum to 1" and on tiny negative round-off.
MASS_TOL = 1e-9
#: Dempster's rule is refused when 1 - K0 <= CONFLICT_TOL.
CONFLICT_TOL = 1e-12


class InvalidMassError(AssocoptError, ValueError):
    """A mass function is malformed (negative mass, sum != 1, unknown element, frame mismatch)."""


class TotalConflictError(AssocoptError, ValueError):
    """Dempster's rule is undefined: the combined masses are in total conflict (K0 = 1)."""


# --------------------------------------------------------------------- tables
@lru_cache(maxsize=None)
def _popcount(size: int) -> np.ndarray:
    """``|A|`` for every bitmask ``A`` in ``0 .. size-1``."""
    a = np.arange(size, dtype=np.int64)
    count = np.zeros(size, dtype=np.int64)
    while a.any():
        count += a & 1
        a >>= 1
    count.setflags(write=False)
    return count


@lru_cache(maxsize=None)
def _and_table(size: int) -> np.ndarray:
    """``A & B`` for every pair of bitmasks (``size x size``)."""
    a = np.arange(size, dtype=np.int64)
    t = a[:, None] & a[None, :]
    t.setflags(write=False)
    return t


@lru_cache(maxsize=None)
def _overlap_weight(size: int) -> np.ndarray:
    """``|A & B| / (|A| |B|)``; 0 when A or B is empty (``size x size``)."""
    pc = _popcount(size)
    inter = pc[_and_table(size)].astype(np.float64)
    denom = (pc[:, None] * pc[None, :]).astype(np.float64)
    w = np.divide(inter, denom, out=np.zeros_like(inter), where=denom > 0)
    w.setflags(write=False)
    return w


@lru_cache(maxsize=None)
def _disjoint(size: int) -> np.ndarray:
    """1.0 where ``A & B`` is empty (``size x size``)."""
    d = (_and_table(size) == 0).astype(np.float64)
    d.setflags(write=False)
    return d


@lru_cache(maxsize=None)
def _betp_matrix(size: int) -> np.ndarray:
    """``P[A, w] = [w in A] / |A|`` (row of the empty set is 0): ``m @ P`` is BetP*(1-m0)."""
    n = size.bit_length() - 1
    a = np.arange(size, dtype=np.int64)
    member = ((a[:, None] >> np.arange(n)[None, :]) & 1).astype(np.float64)
    pc = _popcount(size).astype(np.float64)
    P = np.divide(member, pc[:, None], out=np.zeros_like(member), where=pc[:, None] > 0)
    P.setflags(write=False)
    return P


def _size_of(vectors: np.ndarray, what: str) -> int:
    size = vectors.shape[-1] if vectors.ndim else 0
    if size < 2 or size & (size - 1):
        raise InvalidMassError(
            f"{what} must have a last axis of length 2**n (n >= 1 frame elements), "
            f"got shape {vectors.shape}")
    return size


# ---------------------------------------------------------------- the class
class MassFunction:
    """A mass function (BBA) on a finite frame, validated on construction.

    Parameters
    ----------
    frame : sequence of hashable
        The frame's element names, in a fixed order (at most
        :data:`MAX_FRAME_SIZE`, no duplicates).  A bare string is refused: write
        ``("a", "b")``, not ``"ab"``.
    masses : mapping
        ``{focal set: mass}``; a focal set is a ``frozenset`` (or set, tuple, list)
        of element names; ``frozenset()`` is the empty set, allowed (open world).
        Masses must be finite, non-negative and sum to 1 (within
        :data:`MASS_TOL`); zero masses are dropped.

    Raises
    ------
    InvalidMassError
        Negative or non-finite mass, sum not 1, element outside the frame, a focal
        set given twice, or a malformed frame.

    Examples
    --------
    >>> m = MassFunction(("M", "Mbar"), {frozenset({"M"}): 0.7, frozenset({"M", "Mbar"}): 0.3})
    >>> m[{"M"}], m.belief({"M"}), m.plausibility({"Mbar"})
    (0.7, 0.7, 0.3)
    """

    __slots__ = ("_frame", "_index", "_m")

    def __init__(self, frame: Iterable[Hashable], masses: Mapping) -> None:
        self._frame = _check_frame(frame)
        self._index = {e: k for k, e in enumerate(self._frame)}
        if not isinstance(masses, Mapping):
            raise InvalidMassError(
                f"masses must be a mapping {{focal set: mass}}, got {type(masses).__name__}")
        vec = np.zeros(1 << len(self._frame))
        seen: set[int] = set()
        for key, value in masses.items():
            mask = self._mask(key)
            if mask in seen:
                raise InvalidMassError(f"focal set {self._label(mask)} is given twice")
            seen.add(mask)
            vec[mask] = _check_mass_value(value, self._label(mask))
        self._m = _finish_vector(vec, "masses")

    # ------------------------------------------------------------ builders
    @classmethod
    def from_vector(cls, frame: Iterable[Hashable], vector: ArrayLike) -> "MassFunction":
        """Mass function from its bitmask-indexed vector (length ``2**len(frame)``).

        Bit ``k`` of the index stands for ``frame[k]``.

        >>> m = MassFunction.from_vector(("x", "y"), [0, 0.25, 0, 0.75])
        >>> m.to_dict() == {frozenset({"x"}): 0.25, frozenset({"x", "y"}): 0.75}
        True
        """
        self = cls.__new__(cls)
        self._frame = _check_frame(frame)
        self._index = {e: k for k, e in enumerate(self._frame)}
        try:
            vec = np.array(vector, dtype=np.float64)
        except (TypeError, ValueError) as exc:
            raise InvalidMassError(f"mass vector must be numeric: {exc}") from exc
        if vec.shape != (1 << len(self._frame),):
            raise InvalidMassError(
                f"mass vector for a frame of {len(self._frame)} elements must have shape "
                f"({1 << len(self._frame)},), got {vec.shape}")
        check_vectors(vec, "mass vector")
        self._m = _finish_vector(np.clip(vec, 0.0, None), "mass vector")
        return self

    @classmethod
    def vacuous(cls, frame: Iterable[Hashable]) -> "MassFunction":
        """Total ignorance: all mass on the whole frame (the neutral element of ``conjunctive``)."""
        f = _check_frame(frame)
        vec = np.zeros(1 << len(f))
        vec[-1] = 1.0
        return cls.from_vector(f, vec)

    # ---------------------------------------------------------- accessors
    @property
    def frame(self) -> tuple:
        """The element names, in bit order."""
        return self._frame

    @property
    def vector(self) -> np.ndarray:
        """A copy of the bitmask-indexed mass vector."""
        return self._m.copy()

    def focal_sets(self) -> list[frozenset]:
        """Subsets carrying positive mass (the empty set included when it does)."""
        return [self._subset(int(a)) for a in np.flatnonzero(self._m > 0)]

    def to_dict(self) -> dict[frozenset, float]:
        """``{focal set: mass}`` for every subset with positive mass, empty set included."""
        return {self._subset(int(a)): float(self._m[a]) for a in np.flatnonzero(self._m > 0)}

    def __getitem__(self, subset: Iterable[Hashable]) -> float:
        return float(self._m[self._mask(subset)])

    def mass(self, subset: Iterable[Hashable]) -> float:
        """``m(subset)``."""
        return self[subset]

    @property
    def empty_mass(self) -> float:
        """``m(empty set)`` (the conflict carried by an unnormalised mass function)."""
        return float(self._m[0])

    def belief(self, subset: Iterable[Hashable]) -> float:
        """``Bel(A) = sum of m(B)`` over non-empty ``B`` inside ``A``."""
        a = self._mask(subset)
        idx = np.arange(1, len(self._m))
        return float(self._m[idx[(idx & ~a) == 0]].sum())

    def plausibility(self, subset: Iterable[Hashable]) -> float:
        """``Pl(A) = sum of m(B)`` over ``B`` meeting ``A``."""
        a = self._mask(subset)
        idx = np.arange(len(self._m))
        return float(self._m[(idx & a) != 0].sum())

    def commonality(self, subset: Iterable[Hashable]) -> float:
        """``q(A) = sum of m(B)`` over ``B`` containing ``A``."""
        a = self._mask(subset)
        idx = np.arange(len(self._m))
        return float(self._m[(idx & a) == a].sum())

    def isclose(self, other: "MassFunction", atol: float = 1e-12) -> bool:
        """Same frame (as a set) and every mass within ``atol``."""
        if not isinstance(other, MassFunction) or set(other.frame) != set(self.frame):
            return False
        return bool(np.allclose(self._m, _aligned(other, self._frame), rtol=0.0, atol=atol))

    def __repr__(self) -> str:
        parts = ", ".join(f"{self._label(int(a))}: {self._m[a]:.6g}"
                          for a in np.flatnonzero(self._m > 0))
        return f"MassFunction(frame={self._frame!r}, {{{parts}}})"

    # ------------------------------------------------------------ helpers
    def _mask(self, subset: object) -> int:
        if isinstance(subset, (str, bytes)) or not isinstance(subset, Iterable):
            raise InvalidMassError(
                f"a focal set must be a set of element names, got {subset!r}; "
                f"write frozenset({{{subset!r}}}) for a singleton")
        mask = 0
        unknown = []
        for e in subset:
            try:
                mask |= 1 << self._index[e]
            except (KeyError, TypeError):
                unknown.append(e)
        if unknown:
            raise InvalidMassError(
                f"element(s) {unknown!r} are not in the frame {self._frame!r}")
        return mask

    def _subset(self, mask: int) -> frozenset:
        return frozenset(e for k, e in enumerate(self._frame) if mask >> k & 1)

    def _label(self, mask: int) -> str:
        s = self._subset(mask)
        return "{" + ", ".join(repr(e) for e in self._frame if e in s) + "}"

    @classmethod
    def _wrap(cls, frame: tuple, vec: np.ndarray) -> "MassFunction":
        """Trusted constructor for results computed here (already valid)."""
        self = cls.__new__(cls)
        self._frame = frame
        self._index = {e: k for k, e in enumerate(frame)}
        vec = np.clip(vec, 0.0, None)
        vec.setflags(write=False)
        self._m = vec
        return self


def _check_frame(frame: Iterable[Hashable]) -> tuple:
    if isinstance(frame, (str, bytes)):
        raise InvalidMassError(
            f"frame must be a sequence of element names, got the string {frame!r}; "
            f"write a tuple such as {tuple(frame)!r}")
    if isinstance(frame, (set, frozenset)):
        raise InvalidMassError("frame must be an ordered sequence (tuple or list), "
                               "not a set: the order fixes the bit of each element")
    try:
        f = tuple(frame)
    except TypeError as exc:
        raise InvalidMassError(f"frame must be a sequence of element names: {exc}") from exc
    if not f:
        raise InvalidMassError("frame must have at least one element")
    if len(f) > MAX_FRAME_SIZE:
        raise InvalidMassError(f"frame has {len(f)} elements, more than {MAX_FRAME_SIZE}")
    try:
        if len(set(f)) != len(f):
            dup = sorted({repr(e) for e in f if f.count(e) > 1})
            raise InvalidMassError(f"frame has duplicate elements: {', '.join(dup)}")
    except TypeError as exc:
        raise InvalidMassError(f"frame elements must be hashable: {exc}") from exc
    return f


def _check_mass_value(value: object, label: str) -> float:
    if isinstance(value, bool) or not isinstance(value, numbers.Real):
        raise InvalidMassError(f"mass of {label} must be a real number, got {value!r}")
    v = float(value)
    if not math.isfinite(v):
        raise InvalidMassError(f"mass of {label} is {v}, not finite")
    if v < -MASS_TOL:
        raise InvalidMassError(f"mass of {label} is negative ({v})")
    return max(v, 0.0)


def _finish_vector(vec: np.ndarray, what: str) -> np.ndarray:
    total = math.fsum(vec.tolist())
    if abs(total - 1.0) > MASS_TOL:
        raise InvalidMassError(f"{what} sum to {total!r}, not 1")
    vec.setflags(write=False)
    return vec


def check_vectors(vectors: ArrayLike, what: str = "mass vectors") -> np.ndarray:
    """Validate stacked mass vectors ``(..., 2**n)``: finite, >= 0, each summing to 1.

    Returns them as float64 (tiny negative round-off within :data:`MASS_TOL` clipped).
    """
    try:
        v = np.asarray(vectors, dtype=np.float64)
    except (TypeError, ValueError) as exc:
        raise InvalidMassError(f"{what} must be numeric: {exc}") from exc
    _size_of(v, what)
    if not np.isfinite(v).all():
        raise InvalidMassError(f"{what} contain NaN or inf")
    if (v < -MASS_TOL).any():
        where = tuple(int(i) for i in np.argwhere(v < -MASS_TOL)[0])
        raise InvalidMassError(f"{what} have a negative mass at index {where}")
    sums = v.sum(axis=-1)
    bad = np.abs(sums - 1.0) > MASS_TOL
    if bad.any():
        where = tuple(int(i) for i in np.argwhere(bad)[0]) if sums.ndim else ()
        raise InvalidMassError(f"{what} at {where} sum to {float(sums[where])!r}, not 1")
    return np.clip(v, 0.0, None) if (v < 0).any() else v


def _aligned(m: MassFunction, frame: tuple) -> np.ndarray:
    """``m``'s vector re-indexed to ``frame`` (same elements, possibly another order)."""
    if m.frame == frame:
        return m._m
    if set(m.frame) != set(frame) or len(m.frame) != len(frame):
        raise InvalidMassError(
            f"mass functions are on different frames: {m.frame!r} and {frame!r}")
    pos = np.array([frame.index(e) for e in m.frame], dtype=np.int64)
    old = np.arange(len(m._m), dtype=np.int64)
    new = np.zeros_like(old)
    for k, p in enumerate(pos):
        new |= ((old >> k) & 1) << p
    out = np.zeros_like(m._m)
    out[new] = m._m
    return out


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


def zhang_conflict(m1: MassFunction, m2: MassFunction) -> float:
    """Paper 000's new conflict measure (eq. 4) between two mass functions.

    ``K = K0 + sum over intersecting (A, B) of m1(A) m2(B) (|A||B| - |A & B|) / (|A||B|)``;
    equal to ``1 - <BetP1, BetP2>`` (D0.2).  Not zero for a mass function with
    itself when it has non-singleton focal sets (E0.4).

    >>> v = MassFunction.vacuous(tuple("abcdef"))
    >>> round(zhang_conflict(v, v), 12)   # 1 - 1/6
    0.833333333333
    """
    _, (a, b) = _operands((m1, m2), "zhang_conflict", exactly=2)
    return float(zhang_conflict_vectors(a, b))


def zhang_combination(m1: MassFunction, m2: MassFunction) -> MassFunction:
    """Paper 000's new combination rule (eqs. 10-11), unnormalised.

    ``m(C) = sum_{A & B = C} m1(A) m2(B) |C| / (|A| |B|)`` for ``C`` non-empty and
    ``m(empty) = zhang_conflict(m1, m2)`` (eq. 11 with the erratum E0.6: the conflict
    between the two combined functions).  Sums to 1; equals :func:`conjunctive`
    when every focal set is a singleton.  Commutative, not associative, so it is
    defined for two operands only.
    """
    frame, (a, b) = _operands((m1, m2), "zhang_combination", exactly=2)
    return MassFunction._wrap(frame, _combine_pair(a, b, weighted=True))


def _check_reliability(r: object, what: str) -> float:
    if isinstance(r, bool) or not isinstance(r, numbers.Real) or not (0.0 <= float(r) <= 1.0):
        raise InvalidMassError(f"{what} must be a number in [0, 1], got {r!r}")
    return float(r)


# ------------------------------------------------- bulk (stacked vectors)
def conjunctive_vectors(a: ArrayLike, b: ArrayLike) -> np.ndarray:
    """Smets' conjunctive rule on stacked vectors ``(..., 2**n)`` (broadcast), unchecked."""
    return _combine_stacked(a, b, weighted=False)


def zhang_combination_vectors(a: ArrayLike, b: ArrayLike) -> np.ndarray:
    """Paper 000's new rule (10)-(11) on stacked vectors ``(..., 2**n)`` (broadcast), unchecked."""
    return _combine_stacked(a, b, weighted=True)


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


def zhang_conflict_vectors(a: ArrayLike, b: ArrayLike) -> np.ndarray:
    """New conflict (eq. 4) of stacked vector pairs (broadcast)."""
    a = np.asarray(a, dtype=np.float64)
    b = np.asarray(b, dtype=np.float64)
    size = _size_of(a, "a")
    w = _overlap_weight(size)
    return a.sum(axis=-1) * b.sum(axis=-1) - ((a @ w) * b).sum(axis=-1)


def conflict_matrix(a: ArrayLike, b: ArrayLike) -> np.ndarray:
    """``K0[i, j]`` between rows of ``a`` (N1 x 2**n) and ``b`` (N2 x 2**n): eq. (3) in bulk."""
    a = np.asarray(a, dtype=np.float64)
    b = np.asarray(b, dtype=np.float64)
    return a @ _disjoint(_size_of(a, "a")) @ b.T


def zhang_conflict_matrix(a: ArrayLike, b: ArrayLike) -> np.ndarray:
    """New conflict ``K[i, j]`` (eq. 4) between rows of ``a`` and ``b``, via D0.2 in bulk.

    ``K = 1 - <u_i, u_j>`` with ``u = m @ P`` the (unnormalised) pignistic vectors.
    """
    a = np.asarray(a, dtype=np.float64)
    b = np.asarray(b, dtype=np.float64)
    P = _betp_matrix(_size_of(a, "a"))
    return np.outer(a.sum(axis=-1), b.sum(axis=-1)) - (a @ P) @ (b @ P).T


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
