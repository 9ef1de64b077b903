"""numpy's sum of a float64 array, compiled, to the last bit.

``np.add.reduce`` on a contiguous float64 array sums pairwise: blocks of at most 128
entries with eight interleaved partial sums, halves (rounded down to a multiple of 8)
above that.  A plain loop rounds differently, so a kernel that must give the numpy
route's values exactly (the gated relaxation's ``L(u)``, whose comparisons steer the
ascent) sums with :func:`np_sum`.  ``tests/test_lagrangian_sparse_kernels.py`` checks
it against ``np.sum`` bit for bit.

May import: numpy and the kernels' :mod:`.jit` only.
"""

from __future__ import annotations

import numpy as np

from .jit import njit

__all__ = ["np_sum"]


@njit(cache=True, nogil=True)
def _block(a, lo, n):
    """numpy's ``pairwise_sum`` of ``a[lo:lo + n]`` for ``n <= 128``: eight
    interleaved partial sums (a plain loop below 8 entries)."""
    if n < 8:
        res = 0.0
        for i in range(lo, lo + n):
            res += a[i]
        return res
    r0, r1, r2, r3 = a[lo], a[lo + 1], a[lo + 2], a[lo + 3]
    r4, r5, r6, r7 = a[lo + 4], a[lo + 5], a[lo + 6], a[lo + 7]
    i = 8
    while i < n - n % 8:
        j = lo + i
        r0 += a[j]
        r1 += a[j + 1]
        r2 += a[j + 2]
        r3 += a[j + 3]
        r4 += a[j + 4]
        r5 += a[j + 5]
        r6 += a[j + 6]
        r7 += a[j + 7]
        i += 8
    res = ((r0 + r1) + (r2 + r3)) + ((r4 + r5) + (r6 + r7))
    while i < n:
        res += a[lo + i]
        i += 1
    return res


@njit(cache=True, nogil=True)
def np_sum(a):
    """``float(np.sum(a))`` for a 1-D float64 array, the same bits.

    Above 128 entries numpy halves the range (the first half rounded down to a
    multiple of 8) and adds the halves' sums: the same tree, walked with a stack
    (a recursive kernel does not link from numba's disk cache)."""
    n = a.shape[0]
    if n <= 128:
        return 0.0 + _block(a, 0, n)
    lo = np.empty(64, np.int64)
    nn = np.empty(64, np.int64)
    half = np.empty(64, np.int64)
    left = np.empty(64)
    right_next = np.zeros(64, np.bool_)        # the left half is summed
    top = 0
    lo[0] = 0
    nn[0] = n
    while True:
        if nn[top] > 128:                      # split, then sum the left half first
            n2 = nn[top] // 2
            n2 -= n2 % 8
            half[top] = n2
            right_next[top] = False
            lo[top + 1] = lo[top]
            nn[top + 1] = n2
            top += 1
            continue
        v = _block(a, lo[top], nn[top])
        top -= 1
        while top >= 0 and right_next[top]:    # both halves done: add them
            v = left[top] + v
            top -= 1
        if top < 0:
            return 0.0 + v
        left[top] = v                          # the left half done: the right one
        right_next[top] = True
        lo[top + 1] = lo[top] + half[top]
        nn[top + 1] = nn[top] - half[top]
        top += 1
