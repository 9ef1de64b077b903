"""The ascent of a gated relaxation on its compiled route, run by one kernel between
events (:mod:`assocopt.solvers.kernels.sparse_ascent`).

:func:`sparse_ascent` is :func:`.ascent._ascent` for a relaxation whose evaluation
is compiled (:mod:`.compiled_sparse`), without a deadline, a local search or a
history: the kernel takes the steps of the loop, bit for bit as the Python loop takes
them, and hands back the recoveries (with their offers), the fixing probes and the
stops, which run here as they do there.  Used where
:data:`assocopt.solvers.kernels.tiers.LIMITS` ``"sparse_ascent.ascent_run"`` (or
the kernel already compiled in this process) says; else the Python loop runs, its
time counted towards compiling the kernel.
"""

from __future__ import annotations

import math
import time
from typing import Any, Callable

import numpy as np

from ..twod.lap import Assignment2D, LapInfeasibleError
from .options import OPT_TOL

__all__ = ["eligible", "applies", "sparse_ascent", "charged"]

KERNEL = "sparse_ascent.ascent_run"


def eligible(rel: Any, deadline: float | None, ls: Any, st: Any) -> bool:
    """Whether the kernel can run this ascent: the evaluation compiled, no deadline,
    local search or history (module doc)."""
    return rel.kern is not None and deadline is None and ls is None and \
        st.history is None


def applies(rel: Any) -> bool:
    """Whether the kernel runs an eligible ascent now (:mod:`..kernels.tiers`)."""
    from ..kernels import tiers
    return not tiers.interpret(KERNEL, rel.K, _cached)


def _cached() -> bool:
    from ..bnb.kernels import cached
    from ..kernels import tiers
    return cached(tiers.compiled(KERNEL))


def charged(run: Callable[[], np.ndarray]) -> np.ndarray:
    """``run()`` (the Python loop standing in for the kernel), its time counted into
    the kernel's budget (:func:`assocopt.solvers.kernels.tiers.charge`)."""
    from ..kernels import tiers
    t0 = time.perf_counter()
    try:
        return run()
    finally:
        tiers.charge(KERNEL, time.perf_counter() - t0)


def sparse_ascent(rel: Any, pos: np.ndarray, upad: np.ndarray, st: Any,
                  p: dict[str, Any], exact: bool, probe: Any, next_probe: int,
                  growth: float) -> np.ndarray:
    """:func:`.ascent._ascent` by the kernel; returns the best multipliers."""
    from ..kernels import pick_fixed
    from ..kernels import sparse_ascent as K
    from .relaxation import _Eval
    k = rel.kern
    max_iter = int(p["max_iter"])
    u = np.array(upad, np.float64)
    S = np.array([-math.inf, st.theta, st.ub, st.bound, 0.0, 0.0])
    I = np.array([0, 0, 0, st.iterations, next_probe, 0], np.int64)
    best_u, d_prev, gcur = u.copy(), np.zeros(len(u)), np.zeros(len(u))
    window = np.empty(max_iter + 1)
    tail = (k.c, k.U, k.u_off, k.nf) + k.groups + k.lap + (
        max_iter, int(p["recover_every"] or 0), bool(exact),
        bool(exact and probe is not None), float(growth), bool(st.integer), OPT_TOL,
        float(p["gap_tol"]), int(p["stall_iter"]), float(p["stall_tol"]),
        int(p["patience"]), float(p["step_decay"]), float(p["step_min"]),
        float(p["deflect"]))
    phase = K.START
    fn = None
    stops = {K.CLOSED: "proven", K.GAP: "gap_tol", K.STALLED: "stalled",
             K.STEP_MIN: "step_min", K.MAX_ITER: "max_iter"}
    while True:
        S[K.UB], S[K.BOUND], I[K.ITERS] = st.ub, st.bound, st.iterations
        args = (phase, S, I, u, best_u, d_prev, gcur, window) + tail
        if fn is None:
            fn = pick_fixed(KERNEL, *args, work=math.inf)
        event, fresh, sel, chosen, g, rc, gmin, cor, roc, free = fn(*args)
        st.bound, st.iterations = float(S[K.BOUND]), int(I[K.ITERS])
        if fresh and event != K.MAX_ITER:        # the fixing probe's evaluation
            rel.remember(u, _Eval(float(S[K.LVAL]), sel, g, chosen, rc, gmin,
                                  Assignment2D(cor, roc, "sparse"), free))
        if event == K.INFEASIBLE:
            raise LapInfeasibleError("no perfect matching of the augmented edges")
        if event == K.ZERO:                      # relaxed solution feasible: optimal
            st.offer(pos[sel])
            st.bound = max(st.bound, min(float(S[K.LVAL]), st.ub))
            st.proof = st.proof or "relaxed solution feasible (zero subgradient)"
            st.stop = "proven"
            return u.copy()
        if event == K.RECOVER:
            found = rel.recover(u, chosen)
            if found is not None:
                st.offer(pos[found])
            phase = K.AFTER_RECOVER
            continue
        if event == K.PROBE:
            verdict = probe(best_u.copy())
            if verdict:
                st.stop = verdict
                break
            phase = K.AFTER_PROBE
            continue
        st.stop = stops[event]
        if event == K.CLOSED:
            st.proof = st.proof or "Lagrangian bound meets the objective"
        break
    st.theta = float(S[K.THETA])
    return best_u.copy()
