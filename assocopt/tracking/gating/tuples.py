"""S-D candidate tuples gated pairwise across sensors, before any tuple cost is built.

With ``N`` sensors of ``n`` measurements each there are up to ``(n + 1)^N`` tuples
(28.6 million for 30 targets and 5 sensors), almost all of them impossible: two of
their measurements cannot come from one target.  This module first decides, for
every pair of sensors ``(s, t)``, which measurement pairs are *compatible*, then
enumerates only the tuples whose real measurements are pairwise compatible (the
cliques of the compatibility graph), sensor by sensor, keeping the partial tuples
in arrays.  The tuple costs (paper 002's Pattipati, KLD and SKLD costs) are then
computed for the survivors only.

:func:`gated_tuples` is the enumeration, for any pairwise compatibility; the
compatibility of bearing measurements and the gated problem of a bearing scan are in
:mod:`assocopt.tracking.gating.bearing`.

The detection model of :func:`assocopt.tracking.costs.sd_builder.candidate_tuples` is kept:
a dummy in sensor ``s`` needs ``P_Ds < 1``, and a single-measurement tuple exists
when its measurement may be a false alarm or every other sensor may miss.
"""

from __future__ import annotations

from typing import Mapping, Sequence

import numpy as np
from numpy.typing import ArrayLike

from ...runtime.errors import InvalidProblemError

__all__ = ["gated_tuples", "PairGate"]

PairGate = Mapping[tuple[int, int], np.ndarray]


def gated_tuples(sizes: Sequence[int], compatible: PairGate, pd: ArrayLike,
                 clutter_density: ArrayLike | None = None) -> np.ndarray:
    """Candidate tuples (0 = dummy) whose real measurements are pairwise compatible.

    ``compatible[(s, t)]`` (``s < t``) is a boolean ``(n_s, n_t)`` matrix; a sensor
    pair that is absent is fully compatible.  Rows are sorted lexicographically.

    >>> ok = {(0, 1): np.array([[True, False], [False, True]])}
    >>> gated_tuples((2, 2), ok, [1.0, 1.0]).tolist()
    [[1, 1], [2, 2]]
    """
    sizes = tuple(int(n) for n in sizes)
    N = len(sizes)
    pd_a = np.broadcast_to(np.asarray(pd, float), (N,))
    cd = np.zeros(N) if clutter_density is None else \
        np.broadcast_to(np.asarray(clutter_density, float), (N,))
    pairs = _pairs(sizes, compatible)
    may_miss = pd_a < 1.0
    # multi-measurement tuples: a dummy only where the sensor may miss
    partial = np.arange(sizes[0] + 1, dtype=np.int64)[:, None]
    if not may_miss[0]:
        partial = partial[1:]
    for s in range(1, N):
        k, j = _extensions(partial, s, sizes[s], pairs)
        keep = np.ones(len(k), dtype=bool)
        for t in range(s):
            if pairs[(t, s)] is not None:      # a dummy in t is compatible with all
                i = partial[k, t]
                m = np.flatnonzero(i > 0)
                keep[m] &= pairs[(t, s)][0][i[m] - 1, j[m] - 1]
        k, j = k[keep], j[keep]
        if may_miss[s]:
            k = np.concatenate([np.arange(len(partial)), k])
            j = np.concatenate([np.zeros(len(partial), np.int64), j])
        partial = np.concatenate([partial[k], j[:, None]], axis=1)
    multi = partial[(partial > 0).sum(axis=1) >= 2]
    singles = _singletons(sizes, may_miss, cd)
    T = np.concatenate([multi, singles]).reshape(-1, N)
    return T[np.lexsort(T.T[::-1])]


def _extensions(partial: np.ndarray, s: int, n_s: int, pairs) -> tuple[np.ndarray, np.ndarray]:
    """Pairs ``(k, j)``: partial tuple k and a real measurement j of sensor ``s``
    compatible with k's first real measurement (every j for a partial tuple without
    one, or whose first sensor's pair with ``s`` is not gated); the caller checks the
    other members.  Only the gate's neighbours are listed (CSR lists of each
    measurement's compatible ones), never a (partial tuples x n_s) table."""
    real = partial > 0
    anchor = np.where(real.any(axis=1), np.argmax(real, axis=1), -1)
    ks, js = [], []
    every = anchor < 0
    for t in range(s):
        if pairs[(t, s)] is None:
            every |= anchor == t
    full = np.flatnonzero(every)
    ks.append(np.repeat(full, n_s))
    js.append(np.tile(np.arange(1, n_s + 1, dtype=np.int64), len(full)))
    for t in range(s):
        sel = np.flatnonzero(anchor == t)
        if pairs[(t, s)] is None or not len(sel):
            continue
        _, ptr, cols = pairs[(t, s)]
        r = partial[sel, t] - 1
        cnt = ptr[r + 1] - ptr[r]
        first = np.repeat(ptr[r] - (np.cumsum(cnt) - cnt), cnt)
        ks.append(np.repeat(sel, cnt))
        js.append(cols[first + np.arange(int(cnt.sum()))] + 1)
    return np.concatenate(ks).astype(np.int64), np.concatenate(js).astype(np.int64)


def _pairs(sizes, compatible) -> dict:
    """For every sensor pair ``(s, t)``: None (not gated: all compatible), or the
    boolean matrix with its CSR lists ``(M, ptr, cols)`` (0-based, real indices)."""
    N = len(sizes)
    for key in compatible:
        if not (isinstance(key, tuple) and len(key) == 2 and
                all(isinstance(v, (int, np.integer)) for v in key) and
                0 <= key[0] < key[1] < N):
            raise InvalidProblemError(f"compatibility key {key} must be a sensor pair "
                                      f"(s, t) with 0 <= s < t < {N}")
    out: dict = {}
    for s in range(N):
        for t in range(s + 1, N):
            if (s, t) not in compatible:
                out[(s, t)] = None
                continue
            M = np.ascontiguousarray(compatible[(s, t)], dtype=bool)
            if M.shape != (sizes[s], sizes[t]):
                raise InvalidProblemError(
                    f"compatibility of sensors ({s}, {t}) must have shape "
                    f"({sizes[s]}, {sizes[t]}), got {M.shape}")
            flat = np.flatnonzero(M)
            ptr = np.zeros(sizes[s] + 1, np.int64)
            np.cumsum(np.bincount(flat // max(sizes[t], 1), minlength=sizes[s]),
                      out=ptr[1:])
            out[(s, t)] = (M, ptr, flat % max(sizes[t], 1))
    return out


def _singletons(sizes, may_miss, cd) -> np.ndarray:
    N = len(sizes)
    rows = []
    for s, n in enumerate(sizes):
        others_miss = bool(np.delete(may_miss, s).all())
        if n and (cd[s] > 0 or others_miss):
            t = np.zeros((n, N), dtype=np.int64)
            t[:, s] = np.arange(1, n + 1)
            rows.append(t)
    return np.concatenate(rows) if rows else np.zeros((0, N), dtype=np.int64)

