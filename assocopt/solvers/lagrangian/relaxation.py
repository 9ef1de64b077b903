"""The Lagrangian subproblem: the relaxed S-D problem as a 2-D assignment.

:class:`_Relaxation` holds one candidate set sorted by kept-axes pair; it evaluates
``L(u)`` and its subgradient (:class:`_Eval`), recovers feasible solutions by the
recursive 2-D scheme, and gives the per-candidate fixing bounds used by the exact
mode.  :func:`lagrangian_bound` is the public entry point for user multipliers.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from ...runtime.errors import InvalidProblemError
from ...problems.problem import AssignmentProblem
from ..base import module_installed
from ..twod.lap import (Assignment2D, LapInfeasibleError, assign_with_misses, assignment_duals,
                   linear_assignment)
from .compiled_sparse import sparse_kernels
from .layout import group_layout, initial_shares


def _numba_installed(work: float = 0.0) -> bool:
    """numba installed, and worth compiling for ``work`` (else numpy: kernels.tiers)."""
    from ..kernels import tiers
    return module_installed("numba") and not tiers.interpret("grid.grid_eval", work,
                                                             lambda: False)


def _ranges(starts: np.ndarray, counts: np.ndarray) -> np.ndarray:
    """Concatenation of ``arange(s, s + n)`` for every (s, n), in bulk."""
    total = int(counts.sum())
    if total == 0:
        return np.zeros(0, np.int64)
    ends = np.cumsum(counts)
    return np.arange(total) - np.repeat(ends - counts, counts) + np.repeat(starts, counts)


def _first_per_label(labels: np.ndarray) -> np.ndarray:
    """Positions where a new label starts in a label array sorted by label."""
    if not len(labels):
        return labels
    return np.concatenate(([0], np.flatnonzero(labels[1:] != labels[:-1]) + 1))


@dataclass
class _Eval:
    """One evaluation of the relaxed problem at some multipliers."""

    value: float            # L(u)
    selected: np.ndarray    # relaxed solution (positions in the relaxation's order)
    subgradient: np.ndarray
    chosen: np.ndarray      # chosen groups (kept-axes pairs)
    rc: np.ndarray | None   # reduced costs (full), when computed
    gmin: np.ndarray
    assignment: Any
    free_value: float


class _Relaxation:
    """The 2-D Lagrangian subproblem over one candidate set (kept axes ``a, b``).

    Candidates are sorted once by their kept-axes pair; each pair is a *group*.  The
    multipliers live in one padded vector: one block of ``n_s + 1`` slots per relaxed
    axis, slot 0 (the dummy) always 0.
    """

    def __init__(self, sizes: tuple[int, ...], T: np.ndarray, c: np.ndarray,
                 keep: tuple[int, int], lap: str):
        a, b = keep
        self.sizes, self.keep, self.lap = sizes, keep, lap
        self.relaxed = [s for s in range(len(sizes)) if s not in keep]
        na, nb = sizes[a], sizes[b]
        self.na, self.nb = na, nb
        K = len(c)
        self.K = K
        blocks = [sizes[r] + 1 for r in self.relaxed]
        self.u_off = (np.cumsum([0] + blocks[:-1]) if blocks else np.zeros(0)).astype(np.int64)
        self.u_len = int(sum(blocks))
        (self.pos, self.T, self.c, self.uidx, self.nf, self.g_start, self.g_count, gkey,
         self.pair_g, self.pr, self.pc, self.rm_g, self.rm_i, self.cm_g, self.cm_j,
         self.g_row, self.g_col, self.U_all) = group_layout(T, c, keep, sizes, self.relaxed,
                                                            self.u_off, lap)
        counts = self.g_count
        G = len(gkey)
        self.G = G
        self.has_miss = bool(len(self.rm_g) or len(self.cm_g))
        self.gkey = gkey                      # sorted: group id = position
        self.g_range = np.arange(G)
        # uniform fast path: every group holds the same relaxed-axes tails (dense tensors)
        self.uniform = self.simple = self.grid = False
        if G and (counts == counts[0]).all() and K - self.nf == G * counts[0]:
            m = int(counts[0])
            tails = self.T[self.nf:][:, self.relaxed].reshape(G, m, len(self.relaxed))
            if (tails == tails[:1]).all():
                self.uniform, self.m = True, m
                self.Cg = self.c[self.nf:].reshape(G, m)
                self.tail_idx = [ui[self.nf:self.nf + m] for ui in self.uidx]
                # one relaxed axis, every index once per group, no free candidates:
                # the recovery is a single square LAP on the chosen rows of Cg
                r = self.relaxed[0] if len(self.relaxed) == 1 else -1
                self.simple = (r >= 0 and self.nf == 0 and m == sizes[r] and
                               np.array_equal(np.sort(tails[0, :, 0]), np.arange(1, m + 1)))
                # full grid of real pairs in row-major order, tails 1..m in order:
                # evaluate() needs no gathers at all (dense axial 3-D tensors)
                self.grid = (self.simple and G == na * nb and not self.has_miss and
                             np.array_equal(tails[0, :, 0], np.arange(1, m + 1)))
        # square dense grid (axial 3-AP): compiled evaluation and recovery when numba
        # is installed (the LAP method left to us); column potentials kept warm
        self.compiled = self.grid and na == nb and lap in ("auto", "sparse") and \
            _numba_installed(na * na * m)
        if self.compiled:
            self.Cg = np.ascontiguousarray(self.Cg, np.float64)
            self.v_eval = self.v_rec = np.empty(0)
        self.dense = None
        if na * nb <= 4_000_000 and (na * nb <= 40_000 or 8 * len(self.pair_g) >= na * nb):
            self.dense = np.full((na, nb), np.inf)
            self.dense_flat = self.pr * nb + self.pc
        self.kern = sparse_kernels(self, _Eval)   # gated scans: compiled, else None
        self._last: tuple[np.ndarray, _Eval] | None = None   # (multipliers, evaluation)

    def remember(self, upad: np.ndarray, ev: _Eval) -> None:
        """Keep ``ev``, the compiled route's evaluation at ``upad`` (a copy is kept),
        for :meth:`_evaluated`."""
        self._last = (upad.copy(), ev)

    def _evaluated(self, upad: np.ndarray) -> _Eval:
        """The compiled route's evaluation at ``upad``: the last one when it was at the
        same multipliers (the fixing probe runs at the ascent's best multipliers, most
        often those it has just evaluated), else a new one."""
        last = self._last
        if last is not None and np.array_equal(last[0], upad):
            return last[1]
        return self.evaluate(upad, full_rc=True)

    def initial_multipliers(self) -> np.ndarray:
        """Each relaxed index gets the least per-index share ``c_k / (real indices of
        k)`` among the candidates that cover it: a start close to a dual solution."""
        if not self.K or not self.uidx:
            return np.zeros(self.u_len)
        return initial_shares(self)

    # ------------------------------------------------------------ evaluation
    def reduced_costs(self, upad: np.ndarray) -> np.ndarray:
        rc = self.c.copy()
        for ui in self.uidx:
            rc -= upad[ui]
        return rc

    def _evaluate_grid(self, upad: np.ndarray, full_rc: bool = False) -> _Eval:
        off = int(self.u_off[0])
        w = upad[off + 1: off + 1 + self.m]
        ev = self._evaluate_compiled(w, off) if self.compiled and not full_rc else None
        if ev is not None:
            return ev
        Mg = self.Cg - w
        am = Mg.argmin(axis=1)
        gmin = Mg[self.g_range, am]
        D = gmin.reshape(self.na, self.nb)
        r, c = linear_assignment(D, self.lap if self.lap != "sparse" else "auto")
        chosen = r * self.nb + c
        value = float(gmin[chosen].sum() + w.sum())
        sel = chosen * self.m + am[chosen]
        g = np.zeros(self.u_len)
        g[off + 1: off + 1 + self.m] = 1.0 - np.bincount(am[chosen], minlength=self.m)
        asg = None
        if full_rc:
            cor = np.full(self.na, -1, np.int64)
            roc = np.full(self.nb, -1, np.int64)
            cor[r], roc[c] = c, r
            asg = Assignment2D(cor, roc, "plain")
        return _Eval(value, sel, g, chosen, Mg.ravel() if full_rc else None, gmin, asg, 0.0)

    def _evaluate_compiled(self, w: np.ndarray, off: int) -> _Eval | None:
        """:meth:`_evaluate_grid` by the kernel (None: its LAP found no matching)."""
        from ..kernels import pick
        args = (self.Cg, np.ascontiguousarray(w), self.na, self.v_eval)
        ok, value, chosen, am, gmin, v = pick("grid.grid_eval", *args, work=np.inf)(*args)
        if not ok:
            return None
        self.v_eval = v
        g = np.zeros(self.u_len)
        g[off + 1: off + 1 + self.m] = 1.0 - np.bincount(am[chosen], minlength=self.m)
        return _Eval(value, chosen * self.m + am[chosen], g, chosen, None, gmin, None, 0.0)

    def _recover_compiled(self, chosen: np.ndarray) -> np.ndarray | None:
        from ..kernels import pick
        args = (self.Cg, np.ascontiguousarray(chosen, np.int64), self.v_rec)
        ok, sel, v = pick("grid.grid_recover", *args, work=np.inf)(*args)
        if not ok:
            return None
        self.v_rec = v
        return sel

    def evaluate(self, upad: np.ndarray, full_rc: bool = False) -> _Eval:
        if self.grid:
            return self._evaluate_grid(upad, full_rc)
        nf = self.nf
        rc = None
        if self.kern is not None and (ev := self.kern.evaluate(upad)) is not None:
            self.remember(upad, ev)
            return ev
        if self.uniform and not full_rc:
            w = np.zeros(self.m)
            for ti in self.tail_idx:
                w += upad[ti]
            Mg = self.Cg - w
            am = Mg.argmin(axis=1)
            gmin = Mg[self.g_range, am]
            rc_free = self.c[:nf].copy()
            for ui in self.uidx:
                rc_free -= upad[ui[:nf]]
        else:
            rc = self.reduced_costs(upad)
            rc_free = rc[:nf]
            gmin = (np.minimum.reduceat(rc[nf:], self.g_start - nf) if self.G
                    else np.zeros(0))
        neg = np.flatnonzero(rc_free < 0)
        free_value = float(rc_free[neg].sum())
        pw = gmin[self.pair_g]
        rm = np.full(self.na, np.inf)
        rm[self.rm_i] = gmin[self.rm_g]
        cm = np.full(self.nb, np.inf)
        cm[self.cm_j] = gmin[self.cm_g]
        dense = None
        if self.dense is not None:
            self.dense.flat[self.dense_flat] = pw
            dense = self.dense
        asg = assign_with_misses(self.na, self.nb, self.pr, self.pc, pw, rm, cm,
                                 method=self.lap, dense=dense)
        cor, roc = asg.col_of_row, asg.row_of_col
        i, j, w = np.arange(self.na), np.arange(self.nb), self.nb + 1
        keys = np.concatenate([(i[cor >= 0] + 1) * w + cor[cor >= 0] + 1,
                               (i[cor < 0] + 1) * w, j[roc < 0] + 1])
        chosen = np.searchsorted(self.gkey, keys)
        value = float(gmin[chosen].sum()) + free_value + float(upad.sum())
        if self.uniform and rc is None:
            cand = nf + chosen * self.m + am[chosen]
        else:
            idx = _ranges(self.g_start[chosen], self.g_count[chosen])
            lab = np.repeat(np.arange(len(chosen)), self.g_count[chosen])
            hit = np.flatnonzero(rc[idx] == gmin[chosen][lab])
            cand = idx[hit[_first_per_label(lab[hit])]]
        sel = np.concatenate([cand, neg])
        cover = np.bincount(np.concatenate([ui[sel] for ui in self.uidx]) if self.uidx
                            else np.zeros(0, np.int64), minlength=self.u_len)
        g = 1.0 - cover
        g[self.u_off] = 0.0
        return _Eval(value, sel, g, chosen, rc, gmin, asg, free_value)

    # ------------------------------------------------------------ primal recovery
    def recover(self, upad: np.ndarray, chosen: np.ndarray) -> np.ndarray | None:
        """Feasible solution from the relaxed pairs (recursive 2-D scheme), or None."""
        if self.simple:
            # every chosen group is a pair or a miss: give each one index of the relaxed
            # axis (square: as many groups as indices only when nothing was missed)
            if self.compiled and len(chosen) == self.m:
                sel = self._recover_compiled(chosen)
                if sel is not None:
                    return sel
            M = self.Cg[chosen]
            if M.shape[0] == M.shape[1]:
                try:
                    r, c = linear_assignment(M)
                except LapInfeasibleError:
                    return None
                return np.sort(chosen[r] * self.m + c)
        if self.kern is not None and (out := self.kern.recover(upad, chosen))[0]:
            return out[1]
        if self.uniform:
            cand = (self.nf + chosen[:, None] * self.m + np.arange(self.m)).ravel()
            lab = np.repeat(np.arange(len(chosen)), self.m)
        else:
            cand = _ranges(self.g_start[chosen], self.g_count[chosen])
            lab = np.repeat(np.arange(len(chosen)), self.g_count[chosen])
        G = len(chosen)
        cand = np.concatenate([cand, np.arange(self.nf)])
        lab = np.concatenate([lab, np.full(self.nf, G)])
        for step, r in enumerate(self.relaxed):
            w = self.c[cand].copy()
            for t in range(step + 1, len(self.relaxed)):
                w -= upad[self.uidx[t][cand]]
            jr = self.T[cand, r]
            nr = self.sizes[r]
            key = lab * (nr + 1) + jr
            o = np.lexsort((w, key))
            first = _first_per_label(key[o])
            ukey, umin = key[o][first], w[o][first]
            ul, uj = ukey // (nr + 1), ukey % (nr + 1)
            edge = (ul < G) & (uj > 0)
            rm = np.full(G, np.inf)
            on = (ul < G) & (uj == 0)
            rm[ul[on]] = umin[on]
            cm = np.full(nr, np.inf)
            on = (ul == G) & (uj > 0)
            cm[uj[on] - 1] = umin[on]
            try:
                asg = assign_with_misses(G, nr, ul[edge], uj[edge] - 1, umin[edge], rm, cm,
                                         method=self.lap)
            except LapInfeasibleError:
                return None
            jg = asg.col_of_row + 1                          # 0 = dummy on axis r
            new_cols = np.flatnonzero(asg.row_of_col < 0) + 1
            lab_of_col = np.full(nr + 1, -1, np.int64)
            lab_of_col[new_cols] = G + np.arange(len(new_cols))
            null = G + len(new_cols)
            lab_of_col[0] = null
            real = lab < G
            keep_real = real & (jr == jg[np.minimum(lab, G - 1)]) if G else \
                np.zeros(len(lab), bool)
            lab_null = lab_of_col[jr]          # -1: column taken by a group
            new_lab = np.where(real, lab, lab_null)
            keep = keep_real | (~real & (lab_null >= 0))
            cand, lab, G = cand[keep], new_lab[keep], null
        cand, lab = cand[lab < G], lab[lab < G]
        if len(cand) and len(np.unique(lab)) != len(lab):
            return None    # cannot happen: after the last axis every group is one tuple
        return np.sort(cand)

    # ------------------------------------------------------------ fixing
    def fixing_bounds(self, upad: np.ndarray) -> tuple[np.ndarray, np.ndarray, float]:
        """Per candidate, a lower bound on every solution that uses it.

        Returns ``(lb, red, base)`` in the relaxation's order: every feasible ``S``
        of this candidate set costs at least ``base + sum_{k in S} red[k]``
        (``red >= 0``: LAP-dual reduced costs, ``max(rc, 0)`` for the candidates free
        in the relaxation), and ``lb[k] >= base + red[k]`` bounds any ``S`` holding k.
        """
        if self.kern is not None:               # gated: one compiled call
            return self.kern.fixing(self._evaluated(upad), upad)
        ev = self.evaluate(upad, full_rc=True)
        rc, gmin, na, nb = ev.rc, ev.gmin, self.na, self.nb
        cor, roc = ev.assignment.col_of_row, ev.assignment.row_of_col
        pw = gmin[self.pair_g]
        if not self.has_miss:
            size = na
            er, ec, ew = self.pr, self.pc, pw
            match = cor
        else:
            size = na + nb
            er = np.concatenate([self.pr, self.rm_i, na + self.cm_j, na + self.pc])
            ec = np.concatenate([self.pc, nb + self.rm_i, self.cm_j, nb + self.pr])
            ew = np.concatenate([pw, gmin[self.rm_g], gmin[self.cm_g], np.zeros(len(pw))])
            match = np.empty(size, np.int64)
            i, j = np.arange(na), np.arange(nb)
            match[:na] = np.where(cor >= 0, cor, nb + i)
            match[na:] = np.where(roc >= 0, nb + roc, j)
        alpha, beta = assignment_duals(size, er, ec, ew, match, max_sweeps=max(50, size))
        const = ev.free_value + float(upad.sum())
        l_dual = float(alpha.sum() + beta.sum()) + const
        nf, red = self.nf, np.empty(self.K)
        red[:nf] = np.maximum(rc[:nf], 0.0)
        if self.G:
            grp = np.repeat(np.arange(self.G), self.g_count)
            red[nf:] = np.maximum(rc[nf:] - alpha[self.g_row[grp]] - beta[self.g_col[grp]], 0.0)
        lb = l_dual + red
        lb[:nf] = np.maximum(lb[:nf], ev.value + red[:nf])
        return lb, red, l_dual


def lagrangian_bound(problem: AssignmentProblem, multipliers: dict[int, np.ndarray],
                     keep_axes: tuple[int, int] | None = None) -> float:
    """``L(u)`` for user multipliers: a lower bound on the optimum for any values.

    ``multipliers[s]`` has one value per real index of relaxed axis ``s`` (length
    ``n_s``); axes left out get zeros.  Raises ``ValueError`` when even the relaxed
    2-D problem is infeasible (then so is the problem).

    Examples
    --------
    >>> p = AssignmentProblem.dense(np.arange(8.0).reshape(2, 2, 2))
    >>> lagrangian_bound(p, {2: np.array([5.0, -5.0])}) <= 7.0
    True
    """
    keep = problem.kept_axes(keep_axes)
    rel = _Relaxation(problem.sizes, problem.tuples, problem.costs, keep, "auto")
    upad = np.zeros(rel.u_len)
    for t, r in enumerate(rel.relaxed):
        if r in multipliers:
            v = np.asarray(multipliers[r], np.float64)
            if v.shape != (problem.sizes[r],):
                raise InvalidProblemError(f"multipliers[{r}] must have shape "
                                          f"({problem.sizes[r]},), got {v.shape}")
            upad[rel.u_off[t] + 1: rel.u_off[t] + 1 + len(v)] = v
    return rel.evaluate(upad).value
