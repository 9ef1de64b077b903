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

from typing import Any, Mapping, Sequence

import numpy as np
from numpy.typing import ArrayLike

from ...runtime.errors import InvalidProblemError

__all__ = ["gated_tuples", "PairGate", "pair_lists"]

#: A sensor pair's compatibility: a boolean ``(n_s, n_t)`` matrix (dense numpy or
#: scipy sparse) or an ``(m, 2)`` integer array of compatible ``(i, j)`` (0-based).
PairGate = Mapping[tuple[int, int], Any]


def gated_tuples(sizes: Sequence[int], compatible: PairGate, pd: ArrayLike,
                 clutter_density: ArrayLike | None = None) -> np.ndarray:
    """Candidate tuples (0 = dummy) whose real measurements are pairwise compatible.

    ``compatible[(s, t)]`` (``s < t``) is, in any of three forms, which measurement
    pairs of sensors ``s`` and ``t`` may come from one target:

    * a boolean numpy ``(n_s, n_t)`` matrix (a numeric matrix of that shape is read
      as its non-zeros, unless it is an integer array of two columns);
    * a scipy sparse ``(n_s, n_t)`` matrix or array (its stored non-zero entries);
    * an ``(m, 2)`` integer array of compatible pairs ``(i, j)``, 0-based
      (duplicates allowed).

    A sensor pair that is absent is fully compatible.  Internally every form
    becomes sorted CSR lists: nothing of size ``n_s x n_t`` is allocated, and the
    tuples are built in bulk (arrays of partial tuples, no Python loop per tuple).
    Rows are sorted lexicographically.

    >>> ok = {(0, 1): np.array([[True, False], [False, True]])}
    >>> gated_tuples((2, 2), ok, [1.0, 1.0]).tolist()
    [[1, 1], [2, 2]]
    >>> gated_tuples((2, 2), {(0, 1): np.array([[0, 0], [1, 1]])}, [1.0, 1.0]).tolist()
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
                keep[m] &= _member(pairs[(t, s)], i[m] - 1, j[m] - 1)
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
        ptr, cols = pairs[(t, s)][:2]
        r = partial[sel, t] - 1
        cnt = ptr[r + 1] - ptr[r]
        first = np.repeat(ptr[r] - (np.cumsum(cnt) - cnt), cnt)
        ks.append(np.repeat(sel, cnt))
        js.append(cols[first + np.arange(int(cnt.sum()))] + 1)
    return np.concatenate(ks).astype(np.int64), np.concatenate(js).astype(np.int64)


def _member(pair, i: np.ndarray, j: np.ndarray) -> np.ndarray:
    """Whether each ``(i[k], j[k])`` (0-based) is a compatible pair: a binary search
    in the pair's sorted keys ``i * n_t + j``."""
    keys, n_t = pair[2], pair[3]
    q = i * n_t + j
    if not len(keys):
        return np.zeros(len(q), bool)
    pos = np.minimum(np.searchsorted(keys, q), len(keys) - 1)
    return keys[pos] == q


def pair_lists(M: Any, shape: tuple[int, int], what: str = "compatibility"
               ) -> tuple[np.ndarray, np.ndarray]:
    """The compatible pairs of one sensor pair as sorted, distinct 0-based
    ``(rows, cols)`` (by row, then column), from any form :func:`gated_tuples`
    accepts; never allocates ``shape`` unless ``M`` is a dense matrix already."""
    n_s, n_t = shape
    if hasattr(M, "tocoo") and hasattr(M, "nnz"):            # scipy sparse
        if tuple(M.shape) != shape:
            raise InvalidProblemError(f"{what} must have shape {shape}, got {tuple(M.shape)}")
        C = M.tocoo()
        nz = np.asarray(C.data) != 0
        r = np.asarray(C.row, np.int64)[nz]
        c = np.asarray(C.col, np.int64)[nz]
    else:
        A = np.asarray(M)
        pairs_form = A.ndim == 2 and A.shape[1] == 2 and A.dtype != bool and (
            np.issubdtype(A.dtype, np.integer) or A.shape != shape) and A.size > 0
        if A.ndim == 2 and A.shape == (0, 2) and A.dtype != bool and shape != (0, 2):
            pairs_form = True                                  # no pair at all
        if pairs_form:
            if not np.issubdtype(A.dtype, np.integer):
                raise InvalidProblemError(f"{what}: an index-pair array must hold integers, "
                                          f"got {A.dtype}")
            r, c = A[:, 0].astype(np.int64), A[:, 1].astype(np.int64)
            if len(r) and (r.min() < 0 or r.max() >= n_s or c.min() < 0 or c.max() >= n_t):
                raise InvalidProblemError(
                    f"{what}: index pairs must lie in [0, {n_s}) x [0, {n_t}) (0-based)")
        else:
            if A.shape != shape:
                raise InvalidProblemError(f"{what} must have shape {shape}, got {A.shape}")
            flat = np.flatnonzero(np.asarray(A, dtype=bool))
            r, c = np.divmod(flat.astype(np.int64), max(n_t, 1))
            return r, c                                        # sorted and distinct
    keys = np.unique(r * n_t + c)
    return np.divmod(keys, max(n_t, 1))


def _pairs(sizes, compatible) -> dict:
    """For every sensor pair ``(s, t)``: None (not gated: all compatible), or its
    CSR lists ``(ptr, cols, keys, n_t)`` (0-based, real indices; ``keys`` the
    sorted ``i * n_t + j`` of the compatible pairs, for membership tests)."""
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
            r, c = pair_lists(compatible[(s, t)], (sizes[s], sizes[t]),
                              f"compatibility of sensors ({s}, {t})")
            ptr = np.zeros(sizes[s] + 1, np.int64)
            np.cumsum(np.bincount(r, minlength=sizes[s]), out=ptr[1:])
            out[(s, t)] = (ptr, c, r * sizes[t] + c, sizes[t])
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

