"""Axis-wise re-assignment local search, used to improve recovered solutions.

One move re-attaches the real indices of one axis to the other axes' partial tuples
by an exact 2-D assignment with misses; :class:`_LocalSearch` cycles over the axes
until none improves.  Independent of the relaxation: it works on problem positions.
"""

from __future__ import annotations

import math

import numpy as np

from ...problems.problem import OPT_TOL
from ..twod.lap import LapInfeasibleError, assign_with_misses


class _LocalSearch:
    """Axis-wise re-assignment ("dimension-wise variation") of a feasible solution.

    For one axis s, the chosen tuples with axis s blanked are *groups*; re-attaching
    the real indices of axis s to the groups (or to no group: a single-index
    candidate; or none to a group: the blanked tuple itself) is a 2-D assignment
    with misses, solved exactly.  Cycling over the axes until no axis improves gives
    a local optimum for this neighbourhood, which contains the current solution.
    Candidates are looked up by a mixed-radix key of the full tuple.
    """

    def __init__(self, sizes: tuple[int, ...], T: np.ndarray, c: np.ndarray):
        self.sizes, self.T, self.c = sizes, T, c
        self.ok = len(T) > 0 and math.prod(n + 1 for n in sizes) < 2 ** 62
        if self.ok:
            radix = np.cumprod([1] + [n + 1 for n in sizes[::-1]])[:-1][::-1]
            self.radix = radix.astype(np.int64)
            key = T @ self.radix
            order = np.argsort(key)
            self.skey, self.spos = key[order], order

    def _find(self, X: np.ndarray) -> np.ndarray:
        kx = X @ self.radix
        p = np.minimum(np.searchsorted(self.skey, kx), len(self.skey) - 1)
        return np.where(self.skey[p] == kx, self.spos[p], -1)

    def improve(self, sel: np.ndarray, max_sweeps: int = 20) -> np.ndarray:
        if not self.ok:
            return sel
        c, N = self.c, len(self.sizes)
        cur = np.asarray(sel, np.int64)
        cost = float(c[cur].sum())
        stale = 0
        s = 0
        for _ in range(max_sweeps * N):
            new = self._axis(cur, s)
            if new is not None:
                nc = float(c[new].sum())
                if nc < cost - OPT_TOL * max(1.0, abs(cost)):
                    cur, cost, stale = new, nc, 0
                else:
                    stale += 1
            else:
                stale += 1
            if stale >= N:
                break
            s = (s + 1) % N
        return np.sort(cur)

    def _axis(self, cur: np.ndarray, s: int) -> np.ndarray | None:
        n = self.sizes[s]
        if n == 0:
            return None
        P = self.T[cur].copy()
        P[:, s] = 0
        grp = P[(P > 0).any(axis=1)]
        G = len(grp)
        S = np.zeros((n, len(self.sizes)), np.int64)
        S[:, s] = np.arange(1, n + 1)
        ks = self._find(S)
        cm = np.where(ks >= 0, self.c[np.maximum(ks, 0)], np.inf)
        if G * n <= max(4 * len(self.T), 250_000):
            # look every (group, index) pair up: G * n searches
            X = np.repeat(grp, n, axis=0)
            X[:, s] = np.tile(np.arange(1, n + 1), G)
            k = self._find(X).reshape(G, n)
            er, ec = np.nonzero(k >= 0)
            ek = k[er, ec]
            kr = self._find(grp)
        else:
            # scan the candidates: K searches among the G group keys, O(K) memory
            gk = grp @ self.radix
            go = np.argsort(gk)
            gks = gk[go]
            pk = self.skey - self.T[self.spos, s] * self.radix[s]
            q = np.minimum(np.searchsorted(gks, pk), G - 1) if G else np.zeros(0, np.int64)
            hit = np.flatnonzero(gks[q] == pk) if G else np.zeros(0, np.int64)
            g_of, kk = go[q[hit]], self.spos[hit]
            j = self.T[kk, s]
            on = j > 0
            er, ec, ek = g_of[on], j[on] - 1, kk[on]
            kr = np.full(G, -1, np.int64)
            kr[g_of[~on]] = kk[~on]
        rm = np.where(kr >= 0, self.c[np.maximum(kr, 0)], np.inf)
        try:
            a = assign_with_misses(G, n, er, ec, self.c[ek], rm, cm)
        except LapInfeasibleError:
            return None
        g = np.arange(G)
        m = a.col_of_row >= 0
        pair_k = np.zeros(0, np.int64)
        if m.any():
            code = er * n + ec
            order = np.argsort(code)
            want = g[m] * n + a.col_of_row[m]
            pair_k = ek[order][np.searchsorted(code[order], want)]
        return np.concatenate([pair_k, kr[~m], ks[a.row_of_col < 0]]).astype(np.int64)
