"""The subgradient ascent of a gated (sparse) relaxation, compiled between its events.

:func:`assocopt.solvers.lagrangian.ascent._ascent` on the compiled route of the gated
relaxation (:mod:`.sparse_relax`) spent about 17 us of Python per iteration around a
40 us evaluation (on a 10,000-candidate component of a gated N = 4 scan).
:func:`ascent_run` takes the same steps in the same order, with the same floating
point operations (the sums numpy takes pairwise by :func:`.sums.np_sum`, the others
term by term), so that it leaves the multipliers, bounds and counters bit for bit
where the Python loop leaves them.  It returns to its caller at each *event*, the
steps that stay in Python: a primal recovery and its offer, a fixing probe, and the
ends of the ascent.  The caller then resumes it at the step after the event
(``phase``).

State, shared with the caller: ``S`` (float) ``[best_L, theta, ub, bound, L,
norm2]``, ``I`` (int) ``[it, since, has_d_prev, iterations, next_probe, n_window]``;
``upad``, ``best_u``, ``d_prev`` and ``window`` are updated in place.

May import: numpy, the kernels' :mod:`.jit`, :mod:`.sparse_relax`, :mod:`.sums` and
:mod:`.grid_ascent` (the dense grid's ascent: its test of the bound).
"""

from __future__ import annotations

import numpy as np

from .grid_ascent import _closes
from .jit import njit
from .sparse_relax import sparse_eval
from .sums import np_sum

__all__ = ["ascent_run", "EVENTS"]

#: Where :func:`ascent_run` starts (``phase``) and why it returned (events).
START, AFTER_RECOVER, AFTER_PROBE = 0, 1, 2
INFEASIBLE, ZERO, RECOVER, CLOSED, GAP, PROBE, STALLED, STEP_MIN, MAX_ITER = range(9)
EVENTS = ("infeasible", "zero", "recover", "closed", "gap_tol", "probe", "stalled",
          "step_min", "max_iter")
B_L, THETA, UB, BOUND, LVAL, NORM2 = range(6)
IT, SINCE, HAS_D, ITERS, NEXT_PROBE, NWIN = range(6)


@njit(cache=True, nogil=True)
def ascent_run(phase, S, I, upad, best_u, d_prev, gcur, window, c, U, u_off, nf, g_start,
               g_count, gkey, na, nb, pair_g, pr, pc, rm_g, rm_i, cm_g, cm_j,
               max_iter, recover_every, exact, probing, growth, integer, tol, gap_tol,
               stall_iter, stall_tol, patience, step_decay, step_min, deflect):
    """Run the ascent from ``phase`` until the next event; returns ``(event, fresh,
    sel, chosen, g, rc, gmin, cor, roc, free_value)``: ``fresh`` 1 when this call
    evaluated ``L``, and then the pieces of its last evaluation (at ``upad`` for
    every event but ``MAX_ITER``).  ``gcur`` holds the current subgradient between
    calls.  ``probing``: a fixing probe is wanted (exact mode with a probe); ``tol``:
    the relative optimality tolerance."""
    it = I[IT]
    fresh = 0
    g = gcur
    e64 = np.empty(0, np.int64)
    sel, chosen, rc, gmin, cor, roc = e64, e64, np.empty(0), np.empty(0), e64, e64
    free_value = 0.0
    while True:
        if phase == START:
            if it >= max_iter:
                I[IT] = it
                return MAX_ITER, fresh, sel, chosen, g, rc, gmin, cor, roc, free_value
            status, rc, gmin, chosen, sel, neg, g, cor, roc, value, free_value = \
                sparse_eval(c, U, u_off, upad, nf, g_start, g_count, gkey, na, nb,
                            pair_g, pr, pc, rm_g, rm_i, cm_g, cm_j)
            fresh = 1
            gcur[:] = g
            if status != 0:
                I[IT] = it
                return INFEASIBLE, fresh, sel, chosen, g, rc, gmin, cor, roc, free_value
            I[ITERS] += 1
            L = value
            S[LVAL] = L
            if it == 0 or L > S[B_L] + 1e-12 * max(1.0, abs(S[B_L])):
                S[B_L] = L
                best_u[:] = upad
                I[SINCE] = 0
            else:
                I[SINCE] += 1
            norm2 = 0.0                    # integer entries: exact in any order
            for x in range(g.shape[0]):
                norm2 += g[x] * g[x]
            S[NORM2] = norm2
            I[IT] = it
            if norm2 == 0.0:
                return ZERO, fresh, sel, chosen, g, rc, gmin, cor, roc, free_value
            if recover_every > 0 and it % recover_every == 0:
                return RECOVER, fresh, sel, chosen, g, rc, gmin, cor, roc, free_value
            phase = AFTER_RECOVER
        if phase == AFTER_RECOVER:
            best_L = S[B_L]
            ub = S[UB]
            S[BOUND] = max(S[BOUND], min(best_L, ub))
            if _closes(best_L, ub, integer, tol):
                return CLOSED, fresh, sel, chosen, g, rc, gmin, cor, roc, free_value
            if np.isfinite(ub) and gap_tol > 0 and \
                    ub - best_L <= gap_tol * max(abs(ub), 1e-12):
                return GAP, fresh, sel, chosen, g, rc, gmin, cor, roc, free_value
            if probing and it + 1 >= I[NEXT_PROBE] and np.isfinite(ub):
                I[NEXT_PROBE] = max(it + 2, int(I[NEXT_PROBE] * growth))
                return PROBE, fresh, sel, chosen, g, rc, gmin, cor, roc, free_value
            phase = AFTER_PROBE
        # phase == AFTER_PROBE: the stall rule, the step size, the step
        best_L = S[B_L]
        ub = S[UB]
        if exact and np.isfinite(ub):
            window[I[NWIN]] = best_L
            I[NWIN] += 1
            n = I[NWIN]
            if n > stall_iter and \
                    window[n - 1] - window[n - 1 - stall_iter] < stall_tol * (ub - best_L):
                return STALLED, fresh, sel, chosen, g, rc, gmin, cor, roc, free_value
        if I[SINCE] >= patience:
            S[THETA] *= step_decay
            I[SINCE] = 0
            if S[THETA] < step_min:
                return STEP_MIN, fresh, sel, chosen, g, rc, gmin, cor, roc, free_value
        target = ub if np.isfinite(ub) else best_L + max(1e-3, 0.05 * abs(best_L))
        L = S[LVAL]
        norm2 = S[NORM2]
        d = gcur.copy()
        if I[HAS_D]:
            for x in range(d.shape[0]):
                d[x] = gcur[x] + deflect * d_prev[x]
        sq = np.empty(d.shape[0])
        for x in range(d.shape[0]):
            sq[x] = d[x] * d[x]
        dn = np_sum(sq)
        if dn <= 1e-12 * norm2:            # the deflection cancelled the subgradient
            d[:] = gcur
            dn = norm2
        step = S[THETA] * max(target - L, 1e-12 * max(1.0, abs(L))) / dn
        for x in range(upad.shape[0]):
            upad[x] = upad[x] + step * d[x]
        d_prev[:] = d
        I[HAS_D] = 1
        it += 1
        I[IT] = it
        phase = START
