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
def _pairwise(a, lo, n):
    """numpy's ``pairwise_sum`` of ``a[lo:lo + n]``."""
    if n < 8:
        res = 0.0
        for i in range(lo, lo + n):
            res += a[i]
        return res
    if n <= 128:
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
    n2 = n // 2
    n2 -= n2 % 8
    return _pairwise(a, lo, n2) + _pairwise(a, lo + n2, n - n2)


@njit(cache=True, nogil=True)
def np_sum(a):
    """``float(np.sum(a))`` for a 1-D float64 array, the same bits."""
    return 0.0 + _pairwise(a, 0, a.shape[0])
