"""The mass-function type and its validation.

:class:`MassFunction` (a validated, element-named mass function stored as a
bitmask-indexed vector), the package's exceptions and tolerances, and the
validation helpers shared by the operations: :func:`check_vectors` for stacked
vectors, frame and mass checks, and re-indexing a mass function onto another
ordering of the same frame.  Everything else in :mod:`assocopt.tracking.belief` builds on
this module; it depends on nothing else in the package.
"""

from __future__ import annotations

import math
import numbers
from collections.abc import Hashable, Iterable, Mapping

import numpy as np
from numpy.typing import ArrayLike

from ...runtime.errors import AssocoptError

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
