"""Cached constant arrays and small helpers of the dense 2-D check (:mod:`assocopt.problems.twod`):
built once per size, shared read-only by every scan of that size."""

from __future__ import annotations

import functools
import math

import numpy as np

__all__ = ["_finite_amax", "_index_set", "_row_offsets", "_pair_base", "_tuple_table"]


def _finite_amax(a: np.ndarray) -> float:
    """Largest finite ``|a|`` (0 when there is none)."""
    if a.size == 0:
        return 0.0
    hi, lo = float(a.max()), float(a.min())
    if not (math.isfinite(hi) and math.isfinite(lo)):
        a = a[np.isfinite(a)]
        if a.size == 0:
            return 0.0
        hi, lo = float(a.max()), float(a.min())
    return max(hi, -lo, 0.0)


@functools.lru_cache(maxsize=256)
def _index_set(n: int) -> frozenset[int]:
    """``{0, ..., n-1}``: the values of a permutation of ``n`` items."""
    return frozenset(range(n))


@functools.lru_cache(maxsize=256)
def _row_offsets(n1: int, n2: int) -> np.ndarray:
    """``i * n2`` for each row ``i``: flat row-major index of row ``i``'s first entry."""
    a = np.arange(n1, dtype=np.int64) * n2
    a.setflags(write=False)
    return a


@functools.lru_cache(maxsize=256)
def _pair_base(n: int) -> np.ndarray:
    """``[[1, 1], [2, 1], ..., [n, 1]]``: the reported pairs of rows ``1..n`` before
    their 0-based columns are added to column 1 (copied, never written)."""
    a = np.ones((n, 2), np.int64)
    a[:, 0] = np.arange(1, n + 1)
    a.setflags(write=False)
    return a


@functools.lru_cache(maxsize=256)
def _tuple_table(n1: int, n2: int) -> np.ndarray:
    """The reported tuple of every candidate position of an ``n1 x n2`` problem whose
    entries and misses are all candidates: ``(i + 1, j + 1)`` in row-major order, then
    ``(i + 1, 0)``, then ``(0, j + 1)``; a checked answer's tuples are one ``take``."""
    ii, jj = np.divmod(np.arange(n1 * n2, dtype=np.int64), n2)
    rows, cols = np.arange(1, n1 + 1), np.arange(1, n2 + 1)
    t = np.concatenate([np.stack([ii + 1, jj + 1], axis=1),
                        np.stack([rows, np.zeros(n1, np.int64)], axis=1),
                        np.stack([np.zeros(n2, np.int64), cols], axis=1)])
    t.setflags(write=False)
    return t
