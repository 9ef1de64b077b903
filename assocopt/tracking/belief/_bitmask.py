"""Cached lookup tables over the bitmask encoding of subsets.

A subset of an ``n``-element frame is the integer with bit ``k`` set when element
``k`` is in it, and a mass function is a float vector of length ``size = 2**n``
indexed by that integer (see :mod:`assocopt.tracking.belief`).  The combination rules and
conflict measures in :mod:`assocopt.tracking.belief.combination` and
:mod:`assocopt.tracking.belief.zhang` are vectorised over these read-only ``size``-indexed
tables (popcounts, pairwise intersections, overlap weights, pignistic
redistribution), computed once per frame size and shared.  Private to the package.
"""

from __future__ import annotations

from functools import lru_cache

import numpy as np


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
