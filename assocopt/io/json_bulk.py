"""Bulk (numpy) conversion of the parsed arrays of a JSON instance file.

The strict readers of :mod:`.json_format` walk every entry in Python so that an
error names the bad entry's position; on a large file that walk costs several
times the JSON parse itself.  The functions here convert a well-formed array in
a few C-level passes and prove in bulk that the walk would accept it with the
same values.  Whenever they cannot prove it (a ragged list, a bool, a string
other than ``"inf"``, NaN, ``-inf``, a number beyond ``1e300``...) they return
``None`` and the caller runs the walk, which raises its usual error (or, for the
few odd inputs it accepts, returns the same array).  Every message therefore
stays the walk's.

``literals`` is :attr:`.json_scan.JsonScan.literals` of the whole file: ``False``
proves there is no ``true``/``false``/``null`` anywhere, so a numeric numpy
array cannot hide a bool (numpy turns ``[1.0, True]`` into ``[1.0, 1.0]``).
With ``literals=True`` the entries' types are checked instead (as they are when
``strings``, :attr:`.json_scan.JsonScan.inf_strings`, says ``"inf"`` entries may
occur: numpy would turn the whole array into text first).
"""

from __future__ import annotations

import math
from itertools import chain
from typing import Any, Sequence

import numpy as np

from ..problems.validation import MAX_ABS_COST

#: Spellings of a forbidden (``+inf``) cost as a JSON string (after strip + lower).
INF_WORDS = frozenset({"inf", "+inf", "infinity", "+infinity"})
#: Index values the bulk path converts itself (beyond, the strict path decides).
_MAX_INDEX = 2.0 ** 62


def _numeric(v: Any, shape: tuple[int, ...]) -> np.ndarray | None:
    """``np.array(v)`` when it has ``shape`` and an integer or float dtype.

    That dtype proves every entry is an int, float or bool (strings, None, dicts
    and ints beyond 64 bits give another dtype; ragged lists raise).
    """
    try:
        a = np.array(v)
    except (ValueError, TypeError, OverflowError):
        return None
    if a.shape != shape or a.dtype.kind not in "iuf":
        return None
    return a


def _leaves(v: list, shape: tuple[int, ...]) -> list | None:
    """The entries of rectangular nested lists of ``shape``, in C order, or None."""
    nodes = v
    for n in shape[1:]:
        if set(map(type, nodes)) != {list} or set(map(len, nodes)) != {n}:
            return None
        nodes = list(chain.from_iterable(nodes))
    return nodes


def _inf_strings(leaves: list) -> np.ndarray | None:
    """``leaves`` with every ``"inf"`` string replaced by ``math.inf``; None if another
    string is present."""
    kinds = np.fromiter(map(type, leaves), dtype=object, count=len(leaves))
    is_str = kinds == str
    obj = np.array(leaves, dtype=object)
    if not all(s.strip().lower() in INF_WORDS for s in set(obj[is_str])):
        return None
    obj[is_str] = math.inf
    return obj


def _in_range(arr: np.ndarray) -> bool:
    """No NaN, no ``-inf`` and every finite cost within ``MAX_ABS_COST``."""
    if arr.size == 0:
        return True
    lo, hi = arr.min(), arr.max()       # NaN propagates and fails both tests
    if lo >= -MAX_ABS_COST and hi <= MAX_ABS_COST:
        return True
    if lo >= -MAX_ABS_COST and hi == math.inf:          # forbidden entries
        return bool(arr.max(where=arr < math.inf, initial=-math.inf) <= MAX_ABS_COST)
    return False


def bulk_costs(v: list, shape: Sequence[int], literals: bool,
               strings: bool = True) -> np.ndarray | None:
    """Nested lists of costs as float64 of ``shape``, or None when the walk must decide.

    Accepts ints and floats (``+inf`` included) and the strings of
    :data:`INF_WORDS`, with no NaN, ``-inf`` or finite value beyond ``MAX_ABS_COST``.
    """
    shape = tuple(shape)
    if not literals and not strings:
        a = _numeric(v, shape)
        if a is not None:
            a = a.astype(np.float64, copy=False)
            return a if _in_range(a) else None
    leaves = _leaves(v, shape)
    if leaves is None:
        return None
    types = set(map(type, leaves))
    if not types <= {int, float, str}:
        return None
    values: list | np.ndarray | None = leaves
    if str in types:
        values = _inf_strings(leaves)
        if values is None:
            return None
    try:
        arr = np.array(values, dtype=np.float64).reshape(shape)
    except (ValueError, TypeError, OverflowError):
        return None
    return arr if _in_range(arr) else None


def bulk_indices(rows: list, n_axes: int, literals: bool) -> np.ndarray | None:
    """A list of ``n_axes``-long integer lists as an int64 ``(K, n_axes)`` array, or None.

    Integer-valued floats count as integers (as in the strict reader).
    """
    shape = (len(rows), n_axes)
    if literals:
        leaves = _leaves(rows, shape)
        if leaves is None or not set(map(type, leaves)) <= {int, float}:
            return None
    a = _numeric(rows, shape)
    if a is None or a.dtype.kind == "u":
        return None
    if a.dtype.kind == "f":
        if a.size and not (np.abs(a).max() < _MAX_INDEX and (a == np.floor(a)).all()):
            return None
    return a.astype(np.int64, copy=False)
