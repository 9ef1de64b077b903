"""Cost values: one bulk validation for every constructor.

Every constructor turns its values into a fresh float64 array in the minimisation sense
(negated for ``maximize=True``), tests it once (its sum is finite) and only when
that fails looks for what is wrong: NaN, or the infinity that does not mean "forbidden"
(``-inf`` for costs, ``+inf`` for scores).  Complex, boolean and text data and finite
magnitudes beyond ``validation.MAX_ABS_COST`` (1e300) are rejected first.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike

from .errors import InvalidProblemError
from .validation import check_cost_dtype, check_cost_range

__all__ = ["_as_cost_array", "_as_matrix", "_reject_non_finite"]


def _as_cost_array(values: ArrayLike, what: str, maximize: bool = False) -> np.ndarray:
    """Return ``values`` as a fresh float64 array in the minimisation sense (negated
    when ``maximize``), rejecting NaN and the infinity that does not mean "forbidden"
    (``-inf`` for costs, ``+inf`` for scores)."""
    return _as_matrix(values, what, maximize)[0]


def _reject_non_finite(arr: np.ndarray, what: str, maximize: bool) -> None:
    """Raise on NaN and on the infinity that is not "forbidden" (see _as_cost_array)."""
    if np.isnan(arr).any():
        where = tuple(int(i) for i in np.argwhere(np.isnan(arr))[0])
        raise InvalidProblemError(f"{what} contains NaN (first at index {where})")
    if np.isneginf(arr).any():
        where = tuple(int(i) for i in np.argwhere(np.isneginf(arr))[0])
        bad, ok = ("+inf", "-inf") if maximize else ("-inf", "+inf")
        extra = " with maximize=True" if maximize else ""
        raise InvalidProblemError(f"{what} contains {bad} (first at index {where}); "
                                  f"{ok} means forbidden{extra}")


def _as_matrix(values: ArrayLike, what: str, maximize: bool) -> tuple[np.ndarray, bool]:
    """A fresh float64 array in the minimisation sense and whether all of it is finite;
    NaN and the wrong infinity are rejected (checked only when not all finite)."""
    raw = check_cost_dtype(values, what)      # complex, booleans, text, huge integers
    arr = np.array(raw, dtype=np.float64)
    check_cost_range(arr, what)               # |c| <= MAX_ABS_COST: no sum can overflow
    if maximize:
        np.negative(arr, out=arr)
    # One pass, no temporary: a finite sum means no NaN and no infinity (a huge but
    # finite matrix may overflow the sum; then the exact test decides).
    if math.isfinite(arr.sum()) or np.isfinite(arr).all():
        return arr, True
    _reject_non_finite(arr, what, maximize)
    return arr, False
