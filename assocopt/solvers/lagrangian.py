"""Lagrangian relaxation of S-D assignment to 2-D assignments, with certified gaps.

The method of Pattipati et al. (1992) and Deb et al. (1997).  Keep two axes ``a, b``
(by default the two largest) and move the coverage constraints of the other N-2
axes into the objective with multipliers ``u`` (one per *real* index; dummies are
never constrained).  For every ``u`` the relaxed problem

    L(u) = sum(u) + min  sum_k (c_k - sum_{s relaxed, i_s > 0} u_s[i_s]) x_k
           s.t. every real index of axes a and b covered exactly once

is a 2-D assignment with miss costs: for each pair ``(i_a, i_b)`` only the candidate
of least reduced cost matters, ``(i, 0)`` and ``(0, j)`` pairs are the miss costs, and
candidates with a dummy on both kept axes are unconstrained (taken when their reduced
cost is negative).  ``L(u)`` is a valid lower bound for *every* ``u``; its maximum is
the LP bound.  Each iteration costs one pass over the candidates and one 2-D
assignment (:mod:`assocopt.solvers.lap`).

Multipliers follow a Polyak subgradient step towards the best feasible objective
(momentum-deflected, scale halved when the bound stalls), started from each index's
least per-index cost share.  Feasible solutions come from the recursive scheme: keep
the kept-axes pairs of the relaxed solution as groups and attach the relaxed axes one
at a time, each by a 2-D assignment (groups x indices, with misses) on costs that
still carry the multipliers of the axes not yet attached; record solutions are then
improved by an axis-wise re-assignment local search (:class:`_LocalSearch`).

Back ends
---------
``lagrangian``: the bound, the best feasible solution and the gap.  ``OPTIMAL`` only
with a proof: the relaxed solution is itself feasible, or the bound meets the
objective (integer costs: ``ceil(bound) >= objective``; otherwise to within
:data:`OPT_TOL` relative, floating-point round-off).  Else ``FEASIBLE`` (stopped by
gap, iteration or step rules) or ``TIME_LIMIT``.

``lagrangian-exact``: the same ascent, then reduced-cost fixing with the final
multipliers and the LAP duals: every solution using candidate k costs at least
``lb[k]``.  The *window* ``{k : lb[k] < T}`` holds every solution cheaper than ``T``,
so solving it settles "is the optimum below T?"; windows grow one cost unit (integer
costs) or a doubling of candidates at a time until ``T`` reaches the incumbent.  Each
window is solved by a depth-first exact-cover search (small windows), CP-SAT (integer
costs, up to 1,500 candidates, when OR-Tools is installed) or HiGHS (told to stop at
the proven bound).  Small candidate sets are probed during the ascent as well.
``OPTIMAL`` only when proven; ``info["proof"]`` says how.

Candidate reduction (both back ends, exact): a candidate with two or more real
indices is dominated, and dropped, when its cost is at least that of covering the same
real indices by a split into two candidates (or into single-index candidates).
Optional *heuristic* gate ``gate=g``: drop multi-index candidates costing more than
``g``; the answer is then optimal for the gated problem only, so it is reported as
``FEASIBLE`` and without a bound.

Options (``solve(..., **options)``), all recorded in ``info["parameters"]``:

``max_iter`` (1000; exact: 500) subgradient iterations;
``gap_tol`` (1e-4; exact: 0, or ``mip_gap``) relative gap that stops the ascent;
``step0`` (1.0), ``step_decay`` (0.5), ``patience`` (10), ``step_min`` (1e-4):
Polyak step scale, its decay after ``patience`` iterations without a better bound,
and the scale at which the ascent stops;  ``deflect`` (0.5): momentum of the
previous direction;  ``init`` ("share" or "zero"): starting multipliers;
``stall_iter`` (60), ``stall_tol`` (1e-3): exact mode leaves the ascent when the bound
gained less than ``stall_tol`` of the gap in ``stall_iter`` iterations;
``recover_every`` (1): primal recovery every k iterations (0: never);
``local_search`` (True; the exact mode uses it above 2,000 candidates);
``keep_axes`` (None: the two largest axes);  ``lap`` ("auto", "scipy", "lapx",
"sparse"): 2-D engine;  ``reduce`` (True): dominance rule;  ``gate`` (None);
``window_solver`` ("auto", "highs", "cpsat"; exact only);  ``return_history``
(False): per-iteration bound, best bound and objective in ``info["history"]``.
``time_limit`` gives ``TIME_LIMIT`` with the incumbent and the bound; ``threads`` and
``verbose`` are passed to HiGHS / CP-SAT.

Examples
--------
>>> import numpy as np
>>> from assocopt import AssignmentProblem, solve
>>> p = AssignmentProblem.dense(np.random.default_rng(0).integers(0, 9, (6, 6, 6)))
>>> sol = solve(p, "lagrangian-exact")
>>> sol.status.value, sol.objective == solve(p, "highs").objective
('optimal', True)
"""

from __future__ import annotations

import functools
import math
import time
from dataclasses import dataclass
from typing import Any

import numpy as np
import scipy.sparse as sp

from ..errors import InvalidProblemError, SolverNotInstalledError
from ..problem import AssignmentProblem
from ..solution import Status
from .base import Backend, RawResult, SolveOptions, register
from .lap import (LAP_METHODS, Assignment2D, LapInfeasibleError, assign_with_misses,
                  assignment_duals, lapx_available, linear_assignment)

__all__ = ["LagrangianBackend", "LagrangianExactBackend", "OPT_TOL", "dominated",
           "lagrangian_bound"]

#: Relative tolerance for "bound meets objective" with non-integer costs (round-off).
OPT_TOL = 1e-9

_COMMON = {
    "max_iter": 1000, "gap_tol": 1e-4, "step0": 1.0, "step_decay": 0.5, "patience": 10,
    "step_min": 1e-4, "deflect": 0.5, "recover_every": 1, "keep_axes": None,
    "lap": "auto", "reduce": True, "gate": None, "return_history": False,
    "stall_iter": 60, "stall_tol": 1e-3, "local_search": True, "init": "share",
}
_EXACT = dict(_COMMON, max_iter=500, gap_tol=0.0, window_solver="auto")


# ----------------------------------------------------------------------- helpers
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
        key = T[:, a] * (nb + 1) + T[:, b]
        K = len(c)
        if K < 2 or bool((key[1:] >= key[:-1]).all()):     # dense input: already sorted
            self.pos, self.T, self.c = np.arange(K), T, c
        else:
            order = np.argsort(key, kind="stable")
            self.pos, self.T, self.c = order, T[order], c[order]
            key = key[order]
        self.K = K
        blocks = [sizes[r] + 1 for r in self.relaxed]
        self.u_off = (np.cumsum([0] + blocks[:-1]) if blocks else np.zeros(0)).astype(np.int64)
        self.u_len = int(sum(blocks))
        self.uidx = [self.u_off[t] + self.T[:, r] for t, r in enumerate(self.relaxed)]
        # groups
        starts = np.concatenate(([0], np.flatnonzero(key[1:] != key[:-1]) + 1)) if K \
            else np.zeros(0, np.int64)
        gkey = key[starts]
        counts = np.diff(np.append(starts, K)).astype(np.int64)
        has_free = K > 0 and gkey[0] == 0
        self.nf = int(counts[0]) if has_free else 0
        if has_free:
            starts, gkey, counts = starts[1:], gkey[1:], counts[1:]
        self.g_start, self.g_count = starts.astype(np.int64), counts
        G = len(gkey)
        self.G = G
        gi, gj = gkey // (nb + 1), gkey % (nb + 1)
        pair, rmiss, cmiss = (gi > 0) & (gj > 0), (gi > 0) & (gj == 0), (gi == 0) & (gj > 0)
        self.pair_g = np.flatnonzero(pair)
        self.pr, self.pc = gi[pair] - 1, gj[pair] - 1
        self.rm_g, self.rm_i = np.flatnonzero(rmiss), gi[rmiss] - 1
        self.cm_g, self.cm_j = np.flatnonzero(cmiss), gj[cmiss] - 1
        self.has_miss = bool(len(self.rm_g) or len(self.cm_g))
        self.gkey = gkey                      # sorted: group id = position
        self.g_range = np.arange(G)
        # node of each group in the (augmented) 2-D graph, for the duals
        self.g_row = np.where(gi > 0, gi - 1, na + gj - 1)
        self.g_col = np.where(gj > 0, gj - 1, nb + gi - 1)
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
        self.dense = None
        if na * nb <= 4_000_000 and (na * nb <= 40_000 or 8 * len(self.pair_g) >= na * nb):
            self.dense = np.full((na, nb), np.inf)
            self.dense_flat = self.pr * nb + self.pc

    def initial_multipliers(self) -> np.ndarray:
        """Each relaxed index gets the least per-index share ``c_k / (real indices of
        k)`` among the candidates that cover it: a start close to a dual solution."""
        upad = np.zeros(self.u_len)
        if not self.K or not self.uidx:
            return upad
        share = self.c / np.maximum((self.T > 0).sum(axis=1), 1)
        best = np.full(self.u_len, np.inf)
        for ui in self.uidx:
            np.minimum.at(best, ui, share)
        best[~np.isfinite(best)] = 0.0
        best[self.u_off] = 0.0
        return best

    # ------------------------------------------------------------ evaluation
    def reduced_costs(self, upad: np.ndarray) -> np.ndarray:
        rc = self.c.copy()
        for ui in self.uidx:
            rc -= upad[ui]
        return rc

    def _evaluate_grid(self, upad: np.ndarray, full_rc: bool = False) -> _Eval:
        off = int(self.u_off[0])
        w = upad[off + 1: off + 1 + self.m]
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

    def evaluate(self, upad: np.ndarray, full_rc: bool = False) -> _Eval:
        if self.grid:
            return self._evaluate_grid(upad, full_rc)
        nf = self.nf
        rc = None
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
        i = np.arange(self.na)
        j = np.arange(self.nb)
        w = self.nb + 1
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
            M = self.Cg[chosen]
            if M.shape[0] == M.shape[1]:
                try:
                    r, c = linear_assignment(M)
                except LapInfeasibleError:
                    return None
                return np.sort(chosen[r] * self.m + c)
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
            if G:
                keep_real = real & (jr == jg[np.minimum(lab, G - 1)])
            else:
                keep_real = np.zeros(len(lab), bool)
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
        ev = self.evaluate(upad, full_rc=True)
        rc, gmin = ev.rc, ev.gmin
        na, nb = self.na, self.nb
        cor = ev.assignment.col_of_row
        roc = ev.assignment.row_of_col
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
            i = np.arange(na)
            j = np.arange(nb)
            match[:na] = np.where(cor >= 0, cor, nb + i)
            match[na:] = np.where(roc >= 0, nb + roc, j)
        alpha, beta = assignment_duals(size, er, ec, ew, match, max_sweeps=max(50, size))
        const = ev.free_value + float(upad.sum())
        l_dual = float(alpha.sum() + beta.sum()) + const
        nf = self.nf
        red = np.empty(self.K)
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
    keep = _keep_axes(problem.sizes, keep_axes)
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


def _keep_axes(sizes: tuple[int, ...], keep: Any) -> tuple[int, int]:
    N = len(sizes)
    if keep is None:
        order = sorted(range(N), key=lambda s: (-sizes[s], s))
        return tuple(sorted(order[:2]))    # type: ignore[return-value]
    try:
        a, b = (int(v) for v in keep)
    except (TypeError, ValueError) as exc:
        raise InvalidProblemError(f"keep_axes must be two axis numbers, got {keep!r}") from exc
    if not (0 <= a < N and 0 <= b < N and a != b):
        raise InvalidProblemError(f"keep_axes must be two different axes in 0..{N - 1}, "
                                  f"got {keep!r}")
    return (min(a, b), max(a, b))


# ----------------------------------------------------------------------- local search
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
        T, c, N = self.T, self.c, len(self.sizes)
        cur = np.asarray(sel, np.int64)
        cost = float(c[cur].sum())
        stale = 0
        s = 0
        for _ in range(max_sweeps * N):
            new = self._axis(cur, s)
            if new is not None:
                nc = float(c[new].sum())
                if nc < cost - 1e-9 * max(1.0, abs(cost)):
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


# ----------------------------------------------------------------------- dominance
def dominated(sizes: tuple[int, ...], T: np.ndarray, c: np.ndarray) -> np.ndarray:
    """Mask of candidates that a split into cheaper-or-equal candidates dominates.

    A candidate with two or more real indices is dropped when its cost is at least
    the cost of covering the same real indices with (i) their single-index candidates,
    or (ii) two candidates splitting them (each taken as a candidate if it exists,
    else as single-index candidates).  Replacing a dropped candidate by its split
    keeps a solution feasible at no extra cost, and splits have strictly fewer real
    indices (single-index candidates are never dropped), so the optimum is kept.

    Examples
    --------
    >>> T = np.array([[1, 1, 0], [1, 0, 0], [0, 1, 0]])
    >>> dominated((1, 1, 1), T, np.array([5.0, 2.0, 3.0])).tolist()
    [True, False, False]
    """
    K, N = T.shape
    real = T > 0
    nreal = real.sum(axis=1)
    multi = nreal >= 2
    if K == 0 or not multi.any() or nreal.min() == nreal.max():
        return np.zeros(K, bool)
    single = np.flatnonzero(nreal == 1)
    S = [np.full(n + 1, np.inf) for n in sizes]
    s_axis = real[single].argmax(axis=1)
    for s in range(N):
        on = single[s_axis == s]
        S[s][T[on, s]] = c[on]
        S[s][0] = 0.0

    def singles(X: np.ndarray) -> np.ndarray:
        tot = np.zeros(len(X))
        for s in range(N):
            tot += S[s][X[:, s]]
        return tot

    best = np.where(multi, singles(T), np.inf)
    radix = np.cumprod([1] + [n + 1 for n in sizes[::-1]])[:-1][::-1]
    if math.prod(n + 1 for n in sizes) < 2 ** 62:
        radix = radix.astype(np.int64)
        key = T @ radix
        order = np.argsort(key)
        skey, scost = key[order], c[order]
        pick = np.flatnonzero(multi & (nreal >= 2))
        Tm = T[pick]

        def cover(X: np.ndarray) -> np.ndarray:
            kx = X @ radix
            p = np.minimum(np.searchsorted(skey, kx), K - 1)
            direct = np.where(skey[p] == kx, scost[p], np.inf)
            return np.minimum(direct, singles(X))

        for mask in range(1, 2 ** N - 1, 2):          # subsets A holding axis 0
            inA = np.array([(mask >> s) & 1 for s in range(N)], bool)
            XA = np.where(inA, Tm, 0)
            XB = np.where(inA, 0, Tm)
            ok = (XA > 0).any(axis=1) & (XB > 0).any(axis=1)
            if not ok.any():
                continue
            val = cover(XA[ok]) + cover(XB[ok])
            rows = pick[ok]
            best[rows] = np.minimum(best[rows], val)
    return multi & (c >= best)


# ----------------------------------------------------------------------- ascent
@dataclass
class _State:
    """Progress shared by the phases of one solve (best solution, bound, history)."""

    costs: np.ndarray                   # problem costs
    integer: bool
    incumbent: np.ndarray | None = None   # problem positions
    ub: float = math.inf
    bound: float = -math.inf            # best valid lower bound on the optimum
    theta: float = 2.0
    iterations: int = 0
    history: dict[str, list] | None = None
    proof: str | None = None
    stop: str = ""
    best_recovered: float = math.inf

    def offer(self, positions: np.ndarray) -> None:
        vals = self.costs[positions]
        if float(vals.sum()) > self.ub + 1e-9 * max(1.0, abs(self.ub)):
            return
        obj = math.fsum(vals.tolist())
        if obj < self.ub:
            self.ub, self.incumbent = obj, np.sort(positions)

    def tol(self) -> float:
        return OPT_TOL * max(1.0, abs(self.ub))

    def closes(self, bound: float) -> bool:
        """Whether ``bound`` proves the incumbent optimal."""
        if not (math.isfinite(self.ub) and math.isfinite(bound)):
            return False
        if self.integer:
            return math.ceil(bound - 1e-6) >= self.ub
        return bound >= self.ub - self.tol()

    def report_bound(self) -> float | None:
        if not math.isfinite(self.bound):
            return None
        b = self.bound
        if self.integer:
            b = float(math.ceil(b - 1e-6))
        return min(b, self.ub) if math.isfinite(self.ub) else b


def _ascent(rel: _Relaxation, pos: np.ndarray, upad: np.ndarray, st: _State,
            p: dict[str, Any], deadline: float | None, exact: bool,
            ls: "_LocalSearch | None" = None, probe: Any = None) -> np.ndarray:
    """Subgradient ascent on ``L(u)``; returns the best multipliers.

    ``pos`` maps the relaxation's candidates to problem positions.  Every bound found
    is a bound on the optimum of the candidate set, which is at least
    ``min(st.ub, optimum)`` of the problem (removed candidates cannot beat the
    incumbent), so ``st.bound`` is updated with ``min(L, ub)``.
    """
    best_L, best_u = -math.inf, upad.copy()
    since, d_prev = 0, None
    theta = st.theta
    window: list[float] = []
    # fixing probes: early and often on small candidate sets (cheap, and they settle
    # most small problems), rarely on large ones
    next_probe = 2 if rel.K <= 5_000 else 10
    next_ls = 0
    for it in range(int(p["max_iter"])):
        if it and deadline is not None and time.perf_counter() > deadline:
            st.stop = "time_limit"
            break
        ev = rel.evaluate(upad)
        st.iterations += 1
        L = ev.value
        if it == 0 or L > best_L + 1e-12 * max(1.0, abs(best_L)):
            best_L, best_u, since = L, upad.copy(), 0
        else:
            since += 1
        g = ev.subgradient
        norm2 = float(g @ g)
        if norm2 == 0.0:          # relaxed solution feasible: optimal by exactness
            st.offer(pos[ev.selected])
            st.bound = max(st.bound, min(L, st.ub))
            st.proof = st.proof or "relaxed solution feasible (zero subgradient)"
            st.stop = "proven"
            _record(st, L, best_L)
            return upad.copy()
        if p["recover_every"] and it % int(p["recover_every"]) == 0:
            sel = rel.recover(upad, ev.chosen)
            if sel is not None:
                sol = pos[sel]
                cost = float(st.costs[sol].sum())
                if ls is not None and cost < st.best_recovered and it >= next_ls:
                    st.best_recovered = cost      # improve record recoveries, at most
                    next_ls = it + 5              # every fifth iteration
                    sol = ls.improve(sol)
                st.offer(sol)
        st.bound = max(st.bound, min(best_L, st.ub))
        _record(st, L, best_L)
        if st.closes(best_L):
            st.proof = st.proof or "Lagrangian bound meets the objective"
            st.stop = "proven"
            break
        if math.isfinite(st.ub) and p["gap_tol"] > 0 and \
                st.ub - best_L <= p["gap_tol"] * max(abs(st.ub), 1e-12):
            st.stop = "gap_tol"
            break
        if exact and probe is not None and it + 1 == next_probe and math.isfinite(st.ub):
            next_probe *= 2
            verdict = probe(best_u)
            if verdict:
                st.stop = verdict
                break
        if exact and math.isfinite(st.ub):
            window.append(best_L)
            k = int(p["stall_iter"])
            if len(window) > k and \
                    window[-1] - window[-1 - k] < p["stall_tol"] * (st.ub - best_L):
                st.stop = "stalled"
                break
        if since >= p["patience"]:
            theta *= p["step_decay"]
            since = 0
            if theta < p["step_min"]:
                st.stop = "step_min"
                break
        target = st.ub if math.isfinite(st.ub) else \
            best_L + max(1e-3, 0.05 * abs(best_L))
        d = g if d_prev is None else g + p["deflect"] * d_prev
        dn = float(d @ d)
        if dn <= 1e-12 * norm2:          # the deflection cancelled the subgradient
            d, dn = g, norm2
        step = theta * max(target - L, 1e-12 * max(1.0, abs(L))) / dn
        upad = upad + step * d
        d_prev = d
    else:
        st.stop = "max_iter"
    st.theta = theta
    return best_u


def _record(st: _State, L: float, best: float) -> None:
    if st.history is not None:
        st.history["bound"].append(L)
        st.history["best_bound"].append(best)
        st.history["objective"].append(st.ub if math.isfinite(st.ub) else None)


# ----------------------------------------------------------------------- back ends
def _parse(extra: dict[str, Any], exact: bool, name: str) -> dict[str, Any]:
    defaults = _EXACT if exact else _COMMON
    unknown = sorted(set(extra) - set(defaults))
    if unknown:
        raise InvalidProblemError(f"unknown option(s) for solver {name!r}: {unknown}; "
                                  f"valid: {sorted(defaults)}")
    p = dict(defaults)
    p.update(extra)
    for key in ("max_iter", "patience", "stall_iter", "recover_every"):
        v = p[key]
        if isinstance(v, bool) or not isinstance(v, (int, np.integer)) or v < 0 or \
                (key in ("patience", "stall_iter") and v < 1):
            raise InvalidProblemError(f"option {key} must be a non-negative integer"
                                      f"{' >= 1' if key in ('patience', 'stall_iter') else ''}"
                                      f", got {v!r}")
        p[key] = int(v)
    for key, lo, hi in (("gap_tol", 0.0, math.inf), ("step0", 0.0, 2.0), ("deflect", 0.0, 0.99),
                        ("step_decay", 0.0, 1.0), ("step_min", 0.0, math.inf),
                        ("stall_tol", 0.0, math.inf)):
        v = p[key]
        ok = isinstance(v, (int, float, np.floating)) and not isinstance(v, bool) and \
            lo <= float(v) <= hi and not (key in ("step0", "step_decay") and float(v) == 0)
        if not ok:
            raise InvalidProblemError(f"option {key} must be a number in "
                                      f"{'(' if key in ('step0', 'step_decay') else '['}"
                                      f"{lo}, {hi}], got {v!r}")
        p[key] = float(v)
    if exact and p["window_solver"] not in ("auto", "highs", "cpsat"):
        raise InvalidProblemError(f"option window_solver must be 'auto', 'highs' or 'cpsat', "
                                  f"got {p['window_solver']!r}")
    if p["init"] not in ("share", "zero"):
        raise InvalidProblemError(f"option init must be 'share' or 'zero', got {p['init']!r}")
    if p["lap"] not in LAP_METHODS:
        raise InvalidProblemError(f"option lap must be one of {LAP_METHODS}, got {p['lap']!r}")
    if p["lap"] == "lapx" and not lapx_available():
        raise SolverNotInstalledError("option lap='lapx' needs the Python package 'lapx': "
                                      "pip install lapx")
    if p["gate"] is not None:
        g = p["gate"]
        if isinstance(g, bool) or not isinstance(g, (int, float, np.floating)) or math.isnan(g):
            raise InvalidProblemError(f"option gate must be a number or None, got {g!r}")
        p["gate"] = float(g)
    for key in ("reduce", "return_history", "local_search"):
        if not isinstance(p[key], (bool, np.bool_)):
            raise InvalidProblemError(f"option {key} must be True or False, got {p[key]!r}")
        p[key] = bool(p[key])
    return p


def _grow(n: int, integer: bool) -> int:
    """Least size of the next window: integer thresholds step by one unit while that
    grows the window by a quarter; real ones double it."""
    return int(n * (1.25 if integer else 2.0)) + 1


@functools.lru_cache(maxsize=1)
def _has_ortools() -> bool:
    import importlib.util
    try:
        return importlib.util.find_spec("ortools") is not None
    except (ImportError, ValueError):
        return False


def _uncovered(problem: AssignmentProblem, pos: np.ndarray) -> np.ndarray:
    """Constraint rows that none of the candidates ``pos`` covers."""
    T = problem.tuples[pos]
    rows = (T - 1 + problem.row_offsets[None, :])[T > 0]
    return np.flatnonzero(np.bincount(rows, minlength=problem.n_rows) == 0)


def _coverage(problem: AssignmentProblem, pos: np.ndarray) -> sp.csr_matrix:
    T = problem.tuples[pos]
    real = T > 0
    rows = (T - 1 + problem.row_offsets[None, :])[real]
    cols = np.broadcast_to(np.arange(len(T))[:, None], T.shape)[real]
    A = sp.csr_matrix((np.ones(len(rows)), (rows, cols)), shape=(problem.n_rows, len(T)))
    A.sort_indices()
    return A


def _cover_search(problem: AssignmentProblem, pos: np.ndarray, red: np.ndarray,
                  base: float, cap: float, node_limit: int = 20_000
                  ) -> tuple[np.ndarray | None, bool]:
    """Cheapest exact cover by the candidates ``pos`` costing less than ``cap``.

    Depth-first branch and bound for small windows.  Every solution ``S`` costs at
    least ``base + sum_{k in S} red[k]`` (``red >= 0``, from the Lagrangian duals, see
    :meth:`_Relaxation.fixing_bounds`); a branch is cut when that bound, plus for each
    uncovered row the least share ``red[k] / rows(k)`` of a candidate covering it,
    reaches the cap or the best cost found.  Branches on the uncovered row with the
    fewest usable candidates (Knuth's rule for exact cover), cheapest reduced cost
    first.  Returns ``(selection or None, complete)``;
    ``complete`` is False when the node limit stopped the search (nothing proven).
    """
    K = len(pos)
    T = problem.tuples[pos]
    rows_of = np.where(T > 0, T - 1 + problem.row_offsets[None, :], -1).tolist()
    cost = problem.costs[pos].tolist()
    rd = np.asarray(red, np.float64).tolist()
    cols = [[r for r in rk if r >= 0] for rk in rows_of]
    masks = [sum(1 << r for r in rows) for rows in cols]
    R = problem.n_rows
    by_row: list[list[int]] = [[] for _ in range(R)]
    for k in range(K):
        if math.isfinite(rd[k]):
            for r in cols[k]:
                by_row[r].append(k)
    if any(not b for b in by_row):
        return None, True
    for b in by_row:
        b.sort(key=lambda k: (rd[k], cost[k]))
    share = [min(rd[k] / len(cols[k]) for k in b) for b in by_row]
    msum = [sum(share[r] for r in cols[k]) for k in range(K)]
    full = (1 << R) - 1
    tol = OPT_TOL * max(1.0, abs(cap)) if math.isfinite(cap) else 0.0
    best = [cap - tol, None]
    nodes = [0]
    chosen: list[int] = []

    def search(covered: int, acc: float, racc: float, rest: float) -> bool:
        if covered == full:
            if acc < best[0]:
                best[0], best[1] = acc, list(chosen)
            return True
        nodes[0] += 1
        if nodes[0] > node_limit:
            return False
        if base + racc + rest >= best[0]:
            return True
        # branch on the uncovered row with the fewest usable candidates
        opts = None
        free = ~covered & full
        while free:
            low = free & -free
            r = low.bit_length() - 1
            free ^= low
            o = [k for k in by_row[r] if not masks[k] & covered]
            if opts is None or len(o) < len(opts):
                opts = o
                if len(o) <= 1:
                    break
        for k in opts:
            r2 = racc + rd[k]
            if base + r2 >= best[0]:
                break                    # sorted by red: the rest cannot do better
            chosen.append(k)
            ok = search(covered | masks[k], acc + cost[k], r2, rest - msum[k])
            chosen.pop()
            if not ok:
                return False
        return True

    complete = search(0, 0.0, 0.0, sum(share))
    sel = None if best[1] is None else np.sort(pos[np.array(best[1], np.int64)])
    return sel, complete


#: During the ascent, fixing windows up to this size are tried by a short search.
_PROBE_SEARCH_MAX = 80
#: The exact mode runs the local search only above this many candidates.
_LS_MIN_K = 2000
#: Windows of at most this many candidates are first tried by :func:`_cover_search`
#: with at most this many nodes (about 25 ms): it settles most windows in
#: milliseconds (the reduced costs prune hard), and gives up quickly on the rest
#: (Balas-Saltzman windows of 200+ candidates), which go to CP-SAT or HiGHS.
_SEARCH_MAX = 2000
_SEARCH_NODES = 5000


def _ilp(problem: AssignmentProblem, pos: np.ndarray, st: _State, options: SolveOptions,
         deadline: float | None, target: float | None, start: bool) -> tuple[str, float | None]:
    """HiGHS on the candidates ``pos``; offers any solution found to ``st``.

    ``target``: stop as soon as a solution this good is found (it is then optimal:
    ``target`` is a proven lower bound).  ``start``: pass the incumbent (which must be
    among ``pos``) as the starting solution.  Returns HiGHS's model status name and
    the objective of its solution (None when it has none).
    """
    import highspy

    from ..formulation import LinearModel
    from .highs import highs_from_model

    K = len(pos)
    model = LinearModel(c=problem.costs[pos].astype(np.float64), A=_coverage(problem, pos),
                        row_lower=np.ones(problem.n_rows), row_upper=np.ones(problem.n_rows),
                        lb=np.zeros(K), ub=np.ones(K), integrality=np.ones(K, np.uint8))
    limit = None if deadline is None else max(deadline - time.perf_counter(), 1e-3)
    extra: dict[str, Any] = dict(_HIGHS_OPTIONS)
    if target is not None and math.isfinite(target):
        extra["objective_target"] = float(target)
    h = highs_from_model(model, SolveOptions(time_limit=limit, mip_gap=0.0,
                                             threads=options.threads,
                                             verbose=options.verbose, extra=extra))
    if start and st.incumbent is not None:
        x0 = highspy.HighsSolution()
        x0.col_value = np.isin(pos, st.incumbent).astype(np.float64).tolist()
        x0.value_valid = True
        h.setSolution(x0)
    h.run()
    status = h.getModelStatus().name
    z = None
    if h.getInfo().primal_solution_status == 2:
        sel = pos[np.asarray(h.getSolution().col_value) > 0.5]
        if problem.violations(sel) is None:
            st.offer(sel)
            z = math.fsum(problem.costs[sel].tolist())
    return status, z


def _cpsat(problem: AssignmentProblem, pos: np.ndarray, st: _State, options: SolveOptions,
           deadline: float | None, lo: float, cap: float, start: bool) -> tuple[str, float | None]:
    """CP-SAT on the candidates ``pos`` (integer costs), objective at most ``cap``.

    ``lo`` (a proven lower bound) is not passed to CP-SAT, see below; ``cap`` is the
    largest objective of interest.  Returns ``("kOptimal", z)``, ``("kInfeasible",
    None)`` (nothing in the window costs at most ``cap``) or ``("kTimeLimit", z)``.
    """
    from ortools.sat.python import cp_model

    K = len(pos)
    m = cp_model.CpModel()
    x = [m.NewBoolVar("") for _ in range(K)]
    A = _coverage(problem, pos)
    for r in range(problem.n_rows):
        m.AddExactlyOne([x[k] for k in A.indices[A.indptr[r]:A.indptr[r + 1]].tolist()])
    cost = problem.costs[pos].astype(np.int64).tolist()
    obj = cp_model.LinearExpr.WeightedSum(x, cost)
    m.Add(obj <= int(math.floor(cap)))
    # no "obj >= lo" constraint: with cap == lo it turns the cut into an equality,
    # which CP-SAT propagates poorly (measured: seconds instead of milliseconds)
    m.Minimize(obj)
    if start and st.incumbent is not None:
        on = np.isin(pos, st.incumbent)
        for k in range(K):
            m.AddHint(x[k], bool(on[k]))
    solver = cp_model.CpSolver()
    solver.parameters.num_workers = int(options.threads or 1)
    solver.parameters.log_search_progress = bool(options.verbose)
    if deadline is not None:
        solver.parameters.max_time_in_seconds = max(deadline - time.perf_counter(), 1e-3)
    code = solver.Solve(m)
    z = None
    if code in (cp_model.OPTIMAL, cp_model.FEASIBLE):
        sel = pos[np.array([solver.BooleanValue(v) for v in x], bool)]
        if problem.violations(sel) is None:
            st.offer(sel)
            z = math.fsum(problem.costs[sel].tolist())
    if code == cp_model.OPTIMAL:
        return "kOptimal", z
    if code == cp_model.INFEASIBLE:
        return "kInfeasible", None
    return "kTimeLimit", z


#: Windows up to this many candidates (integer costs) go to CP-SAT, larger ones to
#: HiGHS: CP-SAT settles the small exact-cover windows of Balas-Saltzman instances
#: several times faster, HiGHS's LP wins on large ones (measured, Grundel n = 50).
_CPSAT_MAX = 1500
#: Seconds CP-SAT may spend on one window before HiGHS takes it over.
_CPSAT_BUDGET = 1.0


#: HiGHS settings for the restricted ILPs: presolve spends seconds on these
#: degenerate models for little reduction, and the root LP with cuts and rounding
#: finds solutions faster than feasibility jump (measured on Grundel n = 50).
_HIGHS_OPTIONS = {}


class _LagrangianBase(Backend):
    integer = True
    lp = False
    gives_bound = True
    supports_time_limit = True
    _exact: bool = False

    @classmethod
    def version(cls) -> str:
        from .. import __version__
        return __version__

    def solve(self, problem: AssignmentProblem, options: SolveOptions) -> RawResult:
        t_start = time.perf_counter()
        p = _parse(options.extra, self._exact, self.name)
        if self._exact and options.mip_gap > 0:
            p["gap_tol"] = max(p["gap_tol"], options.mip_gap)
        deadline = None if options.time_limit is None else t_start + options.time_limit
        keep = _keep_axes(problem.sizes, p["keep_axes"])
        c = problem.costs
        integer = bool(np.all(c == np.round(c)) and np.abs(c).max(initial=0) < 2 ** 52)
        st = _State(costs=c, integer=integer, theta=p["step0"],
                    history={"bound": [], "best_bound": [], "objective": []}
                    if p["return_history"] else None)
        times: dict[str, float] = {}
        ncand: dict[str, Any] = {"input": problem.n_candidates}
        info: dict[str, Any] = {"parameters": {**p, "keep_axes": list(keep)},
                                "kept_axes": list(keep), "integer_costs": integer,
                                "candidates": ncand, "phase_times": times}

        # ---- candidate reduction (dominance: exact; gate: heuristic)
        t0 = time.perf_counter()
        pos = np.arange(problem.n_candidates)
        if p["reduce"]:
            pos = pos[~dominated(problem.sizes, problem.tuples, c)]
            ncand["after_dominance"] = len(pos)
        gated = False
        if p["gate"] is not None:
            T = problem.tuples[pos]
            drop = ((T > 0).sum(axis=1) >= 2) & (c[pos] > p["gate"])
            gated = bool(drop.any())
            pos = pos[~drop]
            ncand["after_gate"] = len(pos)
        times["reduce"] = time.perf_counter() - t0

        # ---- ascent on the (reduced) candidate set
        t0 = time.perf_counter()
        try:
            rel = _Relaxation(problem.sizes, problem.tuples[pos], c[pos], keep, p["lap"])
            info["lap_structure"] = "uniform" if rel.uniform else "grouped"
            upad = rel.initial_multipliers() if p["init"] == "share" else np.zeros(rel.u_len)
            # local search pays off on large problems; on small ones the exact mode's
            # fixing and window search settle the incumbent faster without it
            use_ls = p["local_search"] and (not self._exact or problem.n_candidates > _LS_MIN_K)
            ls = _LocalSearch(problem.sizes, problem.tuples, c) if use_ls else None
            probe = self._probe(rel, pos, st, problem) if self._exact else None
            upad = _ascent(rel, pos[rel.pos], upad, st, p, deadline, self._exact, ls, probe)
        except LapInfeasibleError as exc:
            times["ascent"] = time.perf_counter() - t0
            if gated:
                return self._result(Status.ERROR, st, info, t_start,
                                    "the heuristic gate left no feasible assignment "
                                    f"of the kept axes ({exc}); raise or drop 'gate'")
            return self._result(Status.INFEASIBLE, st, info, t_start,
                                f"{self.name}: infeasible -- even the relaxed 2-D "
                                f"problem on axes {keep} has no assignment ({exc})")
        times["ascent"] = time.perf_counter() - t0
        info["ascent_stop"] = st.stop

        if self._exact and st.stop not in ("proven", "time_limit", "gap_tol"):
            self._close_gap(problem, rel, pos, upad, st, p, options, deadline, info, times)

        if st.incumbent is None and problem.n_candidates <= 200_000 and \
                (deadline is None or time.perf_counter() < deadline):
            from .greedy import greedy_select
            sel, covered = greedy_select(problem)
            if covered.all():
                st.offer(sel)
                info["incumbent_from"] = "greedy"
        return self._finish(st, info, t_start, gated, options)

    # ------------------------------------------------------------- exact phase
    @staticmethod
    def _probe(rel: _Relaxation, pos: np.ndarray, st: _State, problem: AssignmentProblem):
        """Reduced-cost fixing test run now and then during the ascent (exact mode):
        stop when it proves the incumbent, or leaves a window small enough to search."""
        gpos = pos[rel.pos]

        def probe(u: np.ndarray) -> str | None:
            lb, red, base = rel.fixing_bounds(u)
            if st.integer:
                keep = np.ceil(lb - 1e-6) < st.ub
            else:
                keep = lb - st.tol() < st.ub
            inc = np.isin(gpos, st.incumbent)
            keep &= ~inc
            n = int(keep.sum())
            if n == 0:
                st.proof = "reduced-cost fixing left only the incumbent"
                st.bound = max(st.bound, st.ub)
                return "proven"
            if n + len(st.incumbent) <= _PROBE_SEARCH_MAX:
                win = np.union1d(gpos[keep], st.incumbent)
                red_of = np.full(len(st.costs), np.inf)
                red_of[gpos] = red
                sel, complete = _cover_search(problem, win, red_of[win], base, st.ub,
                                              node_limit=3_000)
                if complete:
                    if sel is not None:
                        st.offer(sel)
                    st.proof = "search over the candidates left by reduced-cost fixing"
                    st.bound = max(st.bound, st.ub)
                    return "proven"
            return None
        return probe


    def _close_gap(self, problem, rel, pos, upad, st, p, options, deadline, info, times):
        """Reduced-cost fixing, then ILPs over growing windows of the candidates.

        With the final multipliers, ``lb[k]`` bounds every solution that uses
        candidate k.  For a threshold ``T`` the *window* is ``{k : lb[k] < T}``: every
        solution outside it costs at least ``T``.  So if the best solution inside the
        window costs less than ``T`` it is optimal, and if none does, ``T`` is a new
        lower bound.  Windows grow (by candidate count) until ``T`` reaches the
        incumbent, whose window (with the incumbent added) is the classic fixing
        step.  Each window is solved by HiGHS, told to stop at the proven bound.
        """
        t0 = time.perf_counter()
        lb, red, base = rel.fixing_bounds(upad)
        gpos = pos[rel.pos]
        red_of = np.full(problem.n_candidates, np.inf)
        red_of[gpos] = red
        order = np.argsort(lb, kind="stable")
        lb, gpos = lb[order], gpos[order]
        if st.integer:
            lb = np.ceil(lb - 1e-6)
        lo = st.bound
        if st.integer:
            lo = float(math.ceil(lo - 1e-6))
        times["fixing"] = time.perf_counter() - t0
        t0 = time.perf_counter()
        windows: list[dict[str, Any]] = []
        info["windows"] = windows
        budget = 2 * problem.n_rows
        while True:
            st.bound = max(st.bound, min(lo, st.ub))
            if st.incumbent is not None and st.closes(st.bound):
                st.proof = st.proof or "Lagrangian bound meets the objective"
                st.stop = "proven"
                break
            if deadline is not None and time.perf_counter() > deadline:
                st.stop = "time_limit"
                break
            if options.mip_gap > 0 and st.incumbent is not None and \
                    st.ub - st.bound <= options.mip_gap * max(abs(st.ub), 1e-12):
                st.stop = "gap_tol"
                break
            K = len(lb)
            # next threshold: one unit up for integer costs, unless that adds too few
            # candidates; then (and for real costs) the threshold reaching `budget`
            T = lo + 1.0 if st.integer else lo + st.tol()
            if int(np.searchsorted(lb, T, "left")) < budget and K:
                T = max(T, float(lb[min(budget, K - 1)]))
            final = T >= st.ub
            if final:
                T = st.ub
            n_in = int(np.searchsorted(lb, T - (0.0 if st.integer else st.tol()), "left"))
            # closed: the window's optimum is the problem's (T reached the incumbent,
            # or every candidate is in); else it only decides "below T or not"
            closed = final or n_in >= K
            win = gpos[:n_in]
            if st.incumbent is not None and closed:
                win = np.union1d(win, st.incumbent)
            rec: dict[str, Any] = {"threshold": T, "candidates": int(len(win))}
            windows.append(rec)
            if closed and st.incumbent is not None and len(win) == len(st.incumbent):
                st.proof = "reduced-cost fixing left only the incumbent"
                st.bound = max(st.bound, st.ub)
                st.stop = "proven"
                break
            if len(_uncovered(problem, win)):
                rec["result"] = "uncovered"
                if closed:
                    st.stop = "infeasible"
                    break
                lo = T
                budget = max(budget, _grow(n_in, st.integer))
                continue
            cap = st.ub if closed else T          # only solutions below cap matter
            status, z, how = self._window(problem, win, red_of, base, lo, cap, closed,
                                          st, p, options, deadline)
            rec["result"], rec["solver"] = status, how
            if status == "kObjectiveTarget" or (status == "kOptimal" and
                                                 (closed or (z is not None and z < cap))):
                if st.incumbent is None:
                    st.stop = "infeasible"
                    break
                st.proof = ("optimum of the candidates left by reduced-cost fixing"
                            if closed else "optimum of a reduced-cost window")
                st.bound = max(st.bound, st.ub)
                st.stop = "proven"
                break
            if status == "kInfeasible" or (status == "kOptimal" and z is not None and z >= cap):
                if closed:        # nothing below the incumbent (or nothing at all)
                    if st.incumbent is None:
                        st.stop = "infeasible"
                        break
                    st.proof = "no solution below the incumbent in the fixing window"
                    st.bound = max(st.bound, st.ub)
                    st.stop = "proven"
                    break
                lo = T
                budget = max(budget, _grow(n_in, st.integer))
                continue
            st.stop = "time_limit" if status in ("kTimeLimit", "kInterrupt") else "ilp_" + status
            break
        times["windows"] = time.perf_counter() - t0

    @staticmethod
    def _window(problem, win, red_of, base, lo, cap, closed, st, p, options, deadline):
        """Best solution among the candidates ``win`` costing less than ``cap``.

        Returns ``(status, objective, engine)`` in HiGHS's vocabulary: ``kOptimal``
        (the window's best found, or proven none below ``cap`` when the objective is
        None or >= cap), ``kInfeasible`` (nothing below ``cap``), ``kObjectiveTarget``
        (a solution at the proven bound ``lo``: optimal), else a limit.
        """
        if len(win) <= _SEARCH_MAX:
            sel, complete = _cover_search(problem, win, red_of[win], base, cap,
                                          node_limit=_SEARCH_NODES)
            if complete:
                if sel is None:
                    return "kInfeasible", None, "search"
                st.offer(sel)
                return "kOptimal", math.fsum(problem.costs[sel].tolist()), "search"
        start = closed and st.incumbent is not None
        use_cp = st.integer and (p["window_solver"] == "cpsat" or (
            p["window_solver"] == "auto" and len(win) <= _CPSAT_MAX and _has_ortools()))
        if use_cp:
            # CP-SAT settles most small windows in milliseconds but stalls on a few
            # (measured: seconds on a Grundel n = 20 window HiGHS settles in 4 ms), so
            # it gets a short budget and HiGHS takes over when it runs out
            hi = cap - 1 if math.isfinite(cap) else float(np.abs(problem.costs).sum())
            budget = time.perf_counter() + _CPSAT_BUDGET
            cp_deadline = budget if deadline is None else min(budget, deadline)
            status, z = _cpsat(problem, win, st, options, cp_deadline, lo, hi, start=start)
            if status != "kTimeLimit" or (deadline is not None and
                                          time.perf_counter() >= deadline):
                return status, z, "cpsat"
            how = "cpsat+highs"
        else:
            how = "highs"
        target = lo if st.integer else lo + st.tol()
        status, z = _ilp(problem, win, st, options, deadline, target, start=start)
        if status == "kOptimal" and z is not None and z >= cap:
            return "kInfeasible", z, how
        return status, z, how

    # ------------------------------------------------------------- results
    def _finish(self, st: _State, info, t_start, gated, options) -> RawResult:
        info["iterations"] = st.iterations
        info["stop"] = st.stop
        info["proof"] = st.proof
        info["bound_raw"] = st.bound if math.isfinite(st.bound) else None
        if st.history is not None:
            info["history"] = st.history
        if gated:
            if st.incumbent is None:
                return self._result(Status.ERROR, st, info, t_start,
                                    "the heuristic gate left no feasible assignment; "
                                    "raise or drop 'gate'")
            info["gated_bound"] = st.report_bound()
            st.bound = -math.inf
            status = Status.TIME_LIMIT if st.stop == "time_limit" else Status.FEASIBLE
            return self._result(status, st, info, t_start,
                                f"{self.name}: optimal at best for the gated candidates "
                                "(heuristic gate); no bound for the full problem",
                                with_bound=False)
        if st.stop == "infeasible":
            return self._result(Status.INFEASIBLE, st, info, t_start,
                                f"{self.name}: proven infeasible (no solution in the "
                                "candidate windows, which cover every candidate)")
        proven = st.stop == "proven" or (st.incumbent is not None and st.closes(st.bound))
        if proven and st.incumbent is not None:
            st.proof = st.proof or "Lagrangian bound meets the objective"
            info["proof"] = st.proof
            return self._result(Status.OPTIMAL, st, info, t_start,
                                f"{self.name}: proven optimal ({st.proof})")
        if st.stop == "time_limit":
            return self._result(Status.TIME_LIMIT, st, info, t_start,
                                f"{self.name}: stopped by the time limit")
        if st.incumbent is None:
            return self._result(Status.TIME_LIMIT, st, info, t_start,
                                f"{self.name}: no feasible solution found "
                                f"(stopped: {st.stop})")
        gap = (st.ub - st.report_bound()) / max(abs(st.ub), 1e-12) \
            if st.report_bound() is not None else math.inf
        return self._result(Status.FEASIBLE, st, info, t_start,
                            f"{self.name}: feasible, relative gap {gap:.3g} "
                            f"(stopped: {st.stop})")

    def _result(self, status: Status, st: _State, info, t_start, message,
                with_bound: bool = True) -> RawResult:
        bound = st.report_bound() if with_bound else None
        if status is Status.INFEASIBLE:
            return RawResult(status, message=message, info=info,
                             solve_time=time.perf_counter() - t_start)
        return RawResult(status, selected=st.incumbent, bound=bound, message=message,
                         info=info, solve_time=time.perf_counter() - t_start)


@register
class LagrangianBackend(_LagrangianBase):
    """Lagrangian relaxation to 2-D assignments: bound, feasible solution and gap."""

    name = "lagrangian"
    description = ("Lagrangian relaxation to 2-D assignments (Pattipati/Deb): lower bound, "
                   "recursive primal recovery, certified gap")
    exact = False
    _exact = False


@register
class LagrangianExactBackend(_LagrangianBase):
    """Lagrangian relaxation, reduced-cost fixing, then HiGHS on what is left: exact."""

    name = "lagrangian-exact"
    # highspy (the window ILPs) is a hard dependency of assocopt: no per-call lookup
    description = ("Lagrangian relaxation + reduced-cost fixing + HiGHS ILP on the "
                   "remaining candidates (proven optimum)")
    exact = True
    _exact = True
