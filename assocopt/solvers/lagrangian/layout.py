"""How a Lagrangian relaxation lays out its candidates: sorted by kept-axes pair,
grouped, each group's kind (pair, row miss, column miss) and node in the augmented
2-D graph, and each candidate's multiplier slot on every relaxed axis.

:func:`group_layout` is the numpy code; gated relaxations that run their kernels
compiled take :func:`assocopt.solvers.kernels.groups.layout` instead (the same
arrays, one call instead of about thirty numpy calls), and :func:`initial_shares`
likewise.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from ...problems.indexing import real_counts
from .compiled_sparse import compiled_route

__all__ = ["group_layout", "initial_shares", "stacked"]


def _compiled(lap: str, K: int, relaxed: list[int]) -> bool:
    """Where the kernels run: the gated relaxation's compiled route (``lap="sparse"``,
    the tier rule choosing compiled code for ``K`` candidates)."""
    return lap == "sparse" and K > 0 and bool(relaxed) and compiled_route(K)


def group_layout(T: np.ndarray, c: np.ndarray, keep: tuple[int, int],
                 sizes: tuple[int, ...], relaxed: list[int], u_off: np.ndarray,
                 lap: str) -> tuple[Any, ...]:
    """``(pos, T, c, uidx, nf, g_start, g_count, gkey, pair_g, pr, pc, rm_g, rm_i,
    cm_g, cm_j, g_row, g_col, U)``: ``pos`` the stable sort by pair, ``T`` and ``c``
    sorted, ``uidx`` the slots (one array per relaxed axis), ``nf`` the free
    candidates (the all-dummy pair, first), then the groups: start, count, key, the
    pairs' groups and indices, the misses', and each group's row and column node;
    ``U`` the slots as one array (compiled route; else None)."""
    a, b = keep
    na, nb = sizes[a], sizes[b]
    K = len(c)
    if _compiled(lap, K, relaxed):
        from ..kernels import pick_fixed
        args = (np.ascontiguousarray(T, np.int64), np.ascontiguousarray(c, np.float64),
                a, b, na, nb, np.asarray(relaxed, np.int64), u_off)
        out = pick_fixed("groups.layout", *args, work=K)(*args)
        return out[:3] + (list(out[3]),) + out[4:] + (out[3],)
    key = T[:, a] * (nb + 1) + T[:, b]
    if K < 2 or bool((key[1:] >= key[:-1]).all()):     # dense input: already sorted
        pos = np.arange(K)
    else:
        pos = np.argsort(key, kind="stable")
        T, c, key = T[pos], c[pos], key[pos]
    uidx = [u_off[t] + T[:, r] for t, r in enumerate(relaxed)]
    starts = np.concatenate(([0], np.flatnonzero(key[1:] != key[:-1]) + 1)) if K \
        else np.zeros(0, np.int64)
    gkey = key[starts]
    counts = np.diff(np.append(starts, K)).astype(np.int64)
    nf = int(counts[0]) if K > 0 and gkey[0] == 0 else 0
    if nf:
        starts, gkey, counts = starts[1:], gkey[1:], counts[1:]
    gi, gj = gkey // (nb + 1), gkey % (nb + 1)
    pair, rmiss, cmiss = (gi > 0) & (gj > 0), (gi > 0) & (gj == 0), (gi == 0) & (gj > 0)
    g_row = np.where(gi > 0, gi - 1, na + gj - 1)
    g_col = np.where(gj > 0, gj - 1, nb + gi - 1)
    return (pos, T, c, uidx, nf, starts.astype(np.int64), counts, gkey,
            np.flatnonzero(pair), gi[pair] - 1, gj[pair] - 1, np.flatnonzero(rmiss),
            gi[rmiss] - 1, np.flatnonzero(cmiss), gj[cmiss] - 1, g_row, g_col, None)


def stacked(rel: Any) -> np.ndarray:
    """The slots ``rel.uidx`` as one ``(relaxed axes, K)`` int64 array: the compiled
    layout's own (``rel.U_all``, no copy), else stacked."""
    if rel.U_all is not None:
        return rel.U_all
    return np.ascontiguousarray(np.stack(rel.uidx), np.int64)


def initial_shares(rel: Any) -> np.ndarray:
    """Each relaxed index's least share ``c_k / (real indices of k)`` among the
    candidates that cover it (0 where none does and in the dummy slots)."""
    if _compiled(rel.lap, rel.K, rel.relaxed):
        from ..kernels import pick_fixed
        args = (np.ascontiguousarray(rel.T, np.int64), np.ascontiguousarray(rel.c),
                stacked(rel), int(rel.u_len), rel.u_off)
        return pick_fixed("groups.initial_shares", *args, work=rel.K)(*args)
    share = rel.c / np.maximum(real_counts(rel.T), 1)
    best = np.full(rel.u_len, np.inf)
    for ui in rel.uidx:
        np.minimum.at(best, ui, share)
    best[~np.isfinite(best)] = 0.0
    best[rel.u_off] = 0.0
    return best
