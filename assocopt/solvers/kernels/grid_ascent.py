"""The subgradient ascent of ``lagrangian-exact`` on a dense axial 3-D grid, compiled.

The Python loop of :func:`assocopt.solvers.lagrangian.ascent._ascent` spent about
half of each iteration on a dense 3-AP (n = 50: 0.4 ms, of which the kernels of
:mod:`.grid` 0.2 ms) building the subgradient, the step and the history.
:func:`ascent_block` runs the same iterations (evaluation by :func:`.grid.grid_eval`,
subgradient, best multipliers, primal recovery by :func:`.grid.grid_recover`, the
stall and step rules, the deflected Polyak step) until an *event* that needs the
caller: a recovered solution that may improve the incumbent (the caller offers it,
and runs its local search), a fixing probe, a stop, or the end of a block of
iterations (the caller checks its deadline there).  The caller resumes the
interrupted iteration at the stage the kernel left it in.

State lives in arrays the caller owns (indices below: ``SI_*``, ``SF_*``, ``PI_*``,
``PF_*``), so a block can stop anywhere and go on.
"""

from __future__ import annotations

import numpy as np

from .grid import assign_pairs, grid_recover
from .hungarian import hungarian_warm
from .jit import njit

# integer state
SI_IT, SI_SINCE, SI_NEXT_PROBE, SI_NEXT_LS, SI_HAS_D, SI_NWIN, SI_STAGE, SI_EVENT, \
    SI_NHIST, SI_HAS_VE, SI_HAS_VR, SI_END, SI_EVALS, SI_LS, SI_HAS_LAST = range(15)
# float state
SF_BEST, SF_THETA, SF_UB, SF_BEST_REC, SF_L, SF_NORM2, SF_COST, SF_BOUND = range(8)
# integer parameters
PI_MAX_ITER, PI_RECOVER, PI_PATIENCE, PI_STALL_ITER, PI_EXACT, PI_PROBE, PI_LS, \
    PI_INTEGER, PI_HISTORY = range(9)
# float parameters
PF_DECAY, PF_STEP_MIN, PF_DEFLECT, PF_GAP_TOL, PF_STALL_TOL, PF_OPT_TOL = range(6)

# events
BLOCK_END, ZERO, OFFER, PROVEN, GAP, PROBE, STALLED, STEP_MIN, MAX_ITER, EVAL_FAIL = \
    range(10)


@njit(cache=True)
def _closes(bound, ub, integer, opt_tol):
    """Whether ``bound`` proves an incumbent of value ``ub`` optimal."""
    if not (np.isfinite(ub) and np.isfinite(bound)):
        return False
    if integer:
        return np.ceil(bound - 1e-6) >= ub
    return bound >= ub - opt_tol * max(1.0, abs(ub))


@njit(cache=True)
def _same(chosen, last, si):
    """Whether ``chosen`` are the pairs recovered last; if not, they become those."""
    if si[SI_HAS_LAST]:
        same = True
        for i in range(chosen.shape[0]):
            if chosen[i] != last[i]:
                same = False
                break
        if same:
            return True
    last[:] = chosen
    si[SI_HAS_LAST] = 1
    return False


#: Entries of each sorted pair :func:`grid_eval_sorted` reads before its early stop
#: (Grundel n = 50: 3.8 entries a pair are needed; 8 read unconditionally took 61 us
#: an evaluation where the test at every entry took 78 us).
_HEAD = 8


@njit(cache=True)
def grid_eval_sorted(Cs, Is, w, n, v0):
    """:func:`.grid.grid_eval` (same answers, ties to the least relaxed index) on the
    sorted rows (``Cs``: each pair's costs in increasing order, ``Is``: their relaxed
    indices): a pair's scan stops at the first cost that,
    less the largest multiplier, exceeds the pair's best so far (Grundel n = 50: a
    fifth of the entries).  The first :data:`_HEAD` entries are taken without the
    test: the minimum is almost always among them, and the loop without a branch to
    mispredict runs a fifth faster."""
    G, m = Cs.shape
    am = np.empty(G, np.int64)
    gmin = np.empty(G)
    wmax = -np.inf
    for j in range(m):
        wmax = max(wmax, w[j])
    head = min(_HEAD, m)
    for g in range(G):
        best = np.inf
        k = m
        for t in range(head):
            j = Is[g, t]
            x = Cs[g, t] - w[j]
            if x < best or (x == best and j < k):
                best = x
                k = j
        for t in range(head, m):
            c = Cs[g, t]
            if c - wmax > best:
                break
            j = Is[g, t]
            x = c - w[j]
            if x < best or (x == best and j < k):
                best = x
                k = j
        am[g] = k
        gmin[g] = best
    ok, value, chosen, v = assign_pairs(gmin, n, w, v0)
    return ok, value, chosen, am, gmin, v


@njit(cache=True)
def grid_local_search(Cg, n, sel, max_sweeps, opt_tol):
    """Axis-wise re-assignment of the solution ``sel`` of a square grid (``Cg``
    (n*n, n); candidate ``(i * n + j) * n + k`` is the triple ``(i, j, k)``): per axis
    the triples with that axis blanked get its indices back by a square LAP, axes in
    turn until none improves (the moves of
    :class:`assocopt.solvers.lagrangian.local_search._LocalSearch`, whose
    neighbourhood on a dense grid this is).  Returns the solution, sorted."""
    tri = np.empty((n, 3), np.int64)
    for t in range(n):
        r = sel[t]
        tri[t, 0] = r // (n * n)
        tri[t, 1] = (r // n) % n
        tri[t, 2] = r % n
    cost = 0.0
    for t in range(n):
        cost += Cg.flat[sel[t]]
    M = np.empty((n, n))
    stale = 0
    s = 0
    for _ in range(max_sweeps * 3):
        for t in range(n):
            for x in range(n):
                i = x if s == 0 else tri[t, 0]
                j = x if s == 1 else tri[t, 1]
                k = x if s == 2 else tri[t, 2]
                M[t, x] = Cg[i * n + j, k]
        ok, col, _, _, nc = hungarian_warm(M, np.empty(0))
        if ok and nc < cost - opt_tol * max(1.0, abs(cost)):
            for t in range(n):
                tri[t, s] = col[t]
            cost = nc
            stale = 0
        else:
            stale += 1
        if stale >= 3:
            break
        s = (s + 1) % 3
    out = np.empty(n, np.int64)
    for t in range(n):
        out[t] = (tri[t, 0] * n + tri[t, 1]) * n + tri[t, 2]
    return np.sort(out)


@njit(cache=True)
def ascent_block(Cg, Cs, Is, n, w, best_w, d_prev, g, sel, win, hist, v_eval, v_rec, last,
                 si, sf, pi, pf):
    """Iterations of the ascent from the state ``si``/``sf`` until an event, which is
    returned (and left in ``si[SI_EVENT]``).  ``w``: the multipliers of the relaxed
    axis, updated in place; ``best_w`` the best so far; ``sel``: the relaxed solution
    (event ZERO) or the recovered one (event OFFER: improved by
    :func:`grid_local_search` when ``si[SI_LS]``, its cost before in ``sf[SF_COST]``); ``win``: the best bounds the
    stall rule looks back on; ``hist`` (3, max_iter): per iteration ``L``, best ``L``
    and incumbent value, when ``pi[PI_HISTORY]``; ``last``: the pairs last recovered
    (the same pairs again: the same solution, not recovered again)."""
    m = Cg.shape[1]
    opt_tol = pf[PF_OPT_TOL]
    while True:
        it = si[SI_IT]
        if si[SI_STAGE] == 0:
            if it >= pi[PI_MAX_ITER]:
                si[SI_EVENT] = MAX_ITER
                return MAX_ITER
            if it >= si[SI_END]:
                si[SI_EVENT] = BLOCK_END
                return BLOCK_END
            v0 = v_eval if si[SI_HAS_VE] else v_eval[:0]
            ok, L, chosen, am, _, v = grid_eval_sorted(Cs, Is, w, n, v0)
            if not ok:
                si[SI_EVENT] = EVAL_FAIL
                return EVAL_FAIL
            v_eval[:] = v
            si[SI_HAS_VE] = 1
            si[SI_EVALS] += 1
            best = sf[SF_BEST]
            if it == 0 or L > best + 1e-12 * max(1.0, abs(best)):
                sf[SF_BEST] = L
                best_w[:] = w
                si[SI_SINCE] = 0
            else:
                si[SI_SINCE] += 1
            g[:] = 1.0
            for i in range(n):
                g[am[chosen[i]]] -= 1.0
            norm2 = 0.0
            for j in range(m):
                norm2 += g[j] * g[j]
            sf[SF_L] = L
            sf[SF_NORM2] = norm2
            if norm2 == 0.0:
                for i in range(n):
                    sel[i] = chosen[i] * m + am[chosen[i]]
                si[SI_EVENT] = ZERO
                return ZERO
            si[SI_STAGE] = 1
            rec = pi[PI_RECOVER]
            if rec > 0 and it % rec == 0 and not _same(chosen, last, si):
                v0 = v_rec if si[SI_HAS_VR] else v_rec[:0]
                ok, s, v = grid_recover(Cg, chosen, v0)
                if ok:
                    v_rec[:] = v
                    si[SI_HAS_VR] = 1
                    cost = 0.0
                    for i in range(n):
                        cost += Cg.flat[s[i]]
                    ub = sf[SF_UB]
                    ls = pi[PI_LS] != 0 and cost < sf[SF_BEST_REC] and it >= si[SI_NEXT_LS]
                    if ls:
                        s = grid_local_search(Cg, n, s, 20, opt_tol)
                    if ls or cost < ub - (1e-12 * max(1.0, abs(ub)) if np.isfinite(ub)
                                          else 0.0):
                        sel[:] = s
                        sf[SF_COST] = cost
                        si[SI_LS] = 1 if ls else 0
                        si[SI_EVENT] = OFFER
                        return OFFER
        if si[SI_STAGE] == 1:
            best = sf[SF_BEST]
            ub = sf[SF_UB]
            sf[SF_BOUND] = max(sf[SF_BOUND], min(best, ub))
            if pi[PI_HISTORY]:
                k = si[SI_NHIST]
                hist[0, k] = sf[SF_L]
                hist[1, k] = best
                hist[2, k] = ub
                si[SI_NHIST] = k + 1
            if _closes(best, ub, pi[PI_INTEGER] != 0, opt_tol):
                si[SI_EVENT] = PROVEN
                return PROVEN
            if np.isfinite(ub) and pf[PF_GAP_TOL] > 0 and \
                    ub - best <= pf[PF_GAP_TOL] * max(abs(ub), 1e-12):
                si[SI_EVENT] = GAP
                return GAP
            si[SI_STAGE] = 2
            if pi[PI_EXACT] and pi[PI_PROBE] and it + 1 == si[SI_NEXT_PROBE] and \
                    np.isfinite(ub):
                si[SI_NEXT_PROBE] *= 2
                si[SI_EVENT] = PROBE
                return PROBE
        # stage 2: the stall and step rules, the step
        best = sf[SF_BEST]
        ub = sf[SF_UB]
        if pi[PI_EXACT] and np.isfinite(ub):
            k = si[SI_NWIN]
            win[k] = best
            si[SI_NWIN] = k + 1
            back = pi[PI_STALL_ITER]
            if k + 1 > back and win[k] - win[k - back] < pf[PF_STALL_TOL] * (ub - best):
                si[SI_EVENT] = STALLED
                return STALLED
        if si[SI_SINCE] >= pi[PI_PATIENCE]:
            sf[SF_THETA] *= pf[PF_DECAY]
            si[SI_SINCE] = 0
            if sf[SF_THETA] < pf[PF_STEP_MIN]:
                si[SI_EVENT] = STEP_MIN
                return STEP_MIN
        if np.isfinite(ub):
            target = ub
        else:
            target = best + max(1e-3, 0.05 * abs(best))
        L = sf[SF_L]
        norm2 = sf[SF_NORM2]
        deflect = pf[PF_DEFLECT] if si[SI_HAS_D] else 0.0
        dn = 0.0
        for j in range(m):
            x = g[j] + deflect * d_prev[j]
            dn += x * x
        if dn <= 1e-12 * norm2:          # the deflection cancelled the subgradient
            deflect, dn = 0.0, norm2
        step = sf[SF_THETA] * max(target - L, 1e-12 * max(1.0, abs(L))) / dn
        for j in range(m):
            d = g[j] + deflect * d_prev[j]
            w[j] += step * d
            d_prev[j] = d
        si[SI_HAS_D] = 1
        si[SI_IT] = it + 1
        si[SI_STAGE] = 0


@njit(cache=True)
def grid_fixing(Cg, Cs, Is, w, n, v0, max_sweeps):
    """The fixing bounds of
    :meth:`assocopt.solvers.lagrangian.relaxation._Relaxation.fixing_bounds` on a
    square grid, in one pass: the relaxed 2-D problem at ``w`` (as
    :func:`grid_eval_sorted`), its duals by the shortest-path sweeps of
    :func:`assocopt.solvers.twod.lap.assignment_duals` (Jacobi, same tolerance), the
    reduced costs.  Returns ``(ok, lb, red, l_dual)`` in the grid's order."""
    G, m = Cg.shape
    ok, _, chosen, _, gmin, _ = grid_eval_sorted(Cs, Is, w, n, v0)
    lb = np.empty(G * m)
    red = np.empty(G * m)
    if not ok:
        return False, lb, red, np.inf
    col = np.empty(n, np.int64)
    for i in range(n):
        col[i] = chosen[i] - i * n
    beta = np.zeros(n)
    best = np.empty(n)
    for _ in range(max_sweeps):
        best[:] = np.inf
        for i in range(n):
            c = col[i]
            b0 = beta[c] - gmin[i * n + c]
            for j in range(n):
                if j != c:
                    x = b0 + gmin[i * n + j]
                    if x < best[j]:
                        best[j] = x
        changed = False
        for j in range(n):
            if best[j] < beta[j] - 1e-12 * (1.0 + abs(beta[j])):
                beta[j] = best[j]
                changed = True
        if not changed:
            break
    alpha = np.empty(n)
    for i in range(n):
        a = np.inf
        for j in range(n):
            a = min(a, gmin[i * n + j] - beta[j])
        alpha[i] = a
    l_dual = alpha.sum() + beta.sum() + w.sum()
    for i in range(n):
        for j in range(n):
            g = i * n + j
            for k in range(m):
                r = Cg[g, k] - w[k] - alpha[i] - beta[j]
                red[g * m + k] = max(r, 0.0)
                lb[g * m + k] = l_dual + red[g * m + k]
    return True, lb, red, l_dual
