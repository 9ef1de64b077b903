"""Cost values: one bulk validation for every constructor.

Every constructor turns its values into a fresh float64 array in the minimisation sense
(negated for ``maximize=True``), tests it once (its minimum and maximum lie within
``validation.MAX_ABS_COST``) and only when that fails looks for what is wrong: NaN, or the infinity that does not mean "forbidden"
(``-inf`` for costs, ``+inf`` for scores).  Complex, boolean and text data and finite
magnitudes beyond ``validation.MAX_ABS_COST`` (1e300) are rejected first.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike

from ..runtime.errors import InvalidProblemError
from .validation import MAX_ABS_COST, check_cost_dtype, check_cost_range

__all__ = ["_as_cost_array", "_as_matrix", "_reject_non_finite"]


def _as_cost_array(values: ArrayLike, what: str, maximize: bool = False) -> np.ndarray:
    """Return ``values`` as a fresh float64 array in the minimisation sense (negated
    when ``maximize``), rejecting NaN and the infinity that does not mean "forbidden"
    (``-inf`` for costs, ``+inf`` for scores)."""
    return _as_matrix(values, what, maximize)[0]


def _reject_non_finite(arr: np.ndarray, what: str, maximize: bool) -> None:
    """Raise on NaN and on the infinity that is not "forbidden" (see _as_cost_array)."""
    if np.isnan(arr).any():
        raise InvalidProblemError(f"{what} {_where_first(np.isnan(arr), 'NaN')}")
    if np.isneginf(arr).any():
        bad, ok = ("+inf", "-inf") if maximize else ("-inf", "+inf")
        extra = " with maximize=True" if maximize else ""
        raise InvalidProblemError(f"{what} {_where_first(np.isneginf(arr), bad)}; "
                                  f"{ok} means forbidden{extra}")


def _where_first(mask: np.ndarray, bad: str) -> str:
    """``is NaN`` for a scalar, ``contains NaN (first at index (i, j))`` for an array."""
    if mask.ndim == 0:
        return f"is {bad}"
    where = tuple(int(i) for i in np.argwhere(mask)[0])
    return f"contains {bad} (first at index {where})"


def _as_matrix(values: ArrayLike, what: str, maximize: bool
               ) -> tuple[np.ndarray, bool, float | None]:
    """A fresh float64 array in the minimisation sense, whether all of it is finite,
    and, when it is, an upper bound on its largest magnitude (None otherwise); NaN and
    the wrong infinity are rejected (looked for only when not all finite).

    The common case (a float64 array, all finite, in range) costs a copy and one BLAS
    pass: a finite sum of squares proves every entry finite and within range, and its
    square root bounds the magnitude for the solve's cost-scaling test.  Otherwise
    ``min`` and ``max`` inside ``[-MAX_ABS_COST, MAX_ABS_COST]`` prove the range and
    the absence of NaN (which fails every comparison) and of infinities at once, and
    give the exact magnitude."""
    if type(values) is np.ndarray and values.dtype.char == "d":
        arr = np.array(values, dtype=np.float64)       # the hot path: no dtype checks
    else:
        raw = check_cost_dtype(values, what)  # complex, booleans, text, huge integers
        arr = np.array(raw, dtype=np.float64)
    if arr.size:
        squares = float(_VDOT(arr, arr))
        if squares <= _MAX_SQUARES:         # finite: every entry is, and |c| <= 1.3e154
            if maximize:
                np.negative(arr, out=arr)
            return arr, True, math.sqrt(squares) * _ROUNDING + _UNDERFLOW
        lo = float(_MIN(arr, axis=None))
        hi = float(_MAX(arr, axis=None))
        if -MAX_ABS_COST <= lo and hi <= MAX_ABS_COST:
            if maximize:
                np.negative(arr, out=arr)
            return arr, True, max(hi, -lo)
    else:
        return arr, True, 0.0
    check_cost_range(arr, what)               # |c| <= MAX_ABS_COST: no sum can overflow
    if maximize:
        np.negative(arr, out=arr)
    _reject_non_finite(arr, what, maximize)
    return arr, False, None


_MIN, _MAX = np.minimum.reduce, np.maximum.reduce
#: Below this many entries the sum of squares is taken without BLAS: OpenBLAS splits a
#: dot product of 10 000 entries or more over its threads, and when the cores are busy
#: the hand-off alone took 0.5-9 ms for 18 000 costs (2 us on one thread).
_BLAS_MIN = 1 << 20


def _VDOT(a: np.ndarray, b: np.ndarray) -> float:
    """``sum(a * b)`` of two same-shape float64 arrays (BLAS only for large ones)."""
    if a.size < _BLAS_MIN:
        return float(np.einsum("i,i", a.reshape(-1), b.reshape(-1)))
    return float(np.vdot(a, b))
#: The sum of squares of costs is finite below this; then every cost is finite and
#: within sqrt(1.7e308) = 1.3e154 < MAX_ABS_COST: one BLAS pass proves it (the common
#: case); only when it overflows are min and max taken (and what is wrong looked for).
_MAX_SQUARES = 1.7e308
#: The rounded sum of n squares is at least (1 - n * 1.1e-16) times the exact one, so
#: for n up to the 5e7 entries of a dense problem its root times this bounds every |c|;
#: squares of magnitudes below 1e-154 underflow, which the added constant covers.
_ROUNDING = 1.0 + 1e-6
_UNDERFLOW = 1e-150
