"""The ascent of :func:`.ascent._ascent` on a dense axial 3-D grid, by the compiled
kernel :func:`assocopt.solvers.kernels.grid_ascent.ascent_block`.

Same iterations, rules and results (bound, incumbent, proof, stop, history); the
kernel hands back to Python only what must stay here: offering a recovered solution
(and the local search on records), the fixing probes, the stops, and the deadline
check between blocks of iterations.
"""

from __future__ import annotations

import math
import time
from typing import Any

import numpy as np

from .ascent import _State, _record
from .local_search import _LocalSearch
from .options import OPT_TOL
from .relaxation import _Relaxation

#: A block of iterations evaluates at most this many grid entries (n = 50: 32
#: iterations, some 5 ms) before Python runs again (Ctrl-C can act); with a deadline,
#: blocks end by it at the pace measured so far, the first after one iteration.
_BLOCK_ENTRIES = 4_000_000


def applies(rel: _Relaxation) -> bool:
    """Whether the compiled ascent runs on ``rel``: a compiled square grid (all three
    axes of the same size, so that the recovery and the local search are square
    LAPs)."""
    return bool(rel.compiled) and rel.m == rel.na


def sorted_rows(rel: _Relaxation) -> tuple[np.ndarray, np.ndarray]:
    """Each pair's costs in increasing order and their relaxed indices (made once per
    relaxation), for the kernels' early-stopping minimum over the relaxed axis."""
    if getattr(rel, "sorted_rows", None) is None:
        order = np.argsort(rel.Cg, axis=1)
        rel.sorted_rows = (np.ascontiguousarray(np.take_along_axis(rel.Cg, order, 1)),
                           order.astype(np.int32))
    return rel.sorted_rows


def _ascent_grid(rel: _Relaxation, pos: np.ndarray, upad: np.ndarray, st: _State,
                 p: dict[str, Any], deadline: float | None, exact: bool,
                 ls: "_LocalSearch | None" = None, probe: Any = None) -> np.ndarray:
    """:func:`.ascent._ascent` for ``rel.compiled`` relaxations; returns the best
    multipliers (padded, as there)."""
    from ..kernels import pick
    from ..kernels import grid_ascent as K

    m, n = rel.m, rel.na
    off = int(rel.u_off[0])
    max_iter = int(p["max_iter"])
    w = np.ascontiguousarray(upad[off + 1: off + 1 + m], np.float64).copy()
    best_w, d_prev, g = w.copy(), np.zeros(m), np.zeros(m)
    sel = np.zeros(n, np.int64)
    win = np.zeros(max(max_iter, 1))
    hist = np.zeros((3, max(max_iter, 1) if st.history is not None else 1))
    v_eval, v_rec = np.zeros(n), np.zeros(n)
    if len(rel.v_eval) == n:
        v_eval[:] = rel.v_eval
    if len(rel.v_rec) == n:
        v_rec[:] = rel.v_rec
    si = np.zeros(15, np.int64)
    si[K.SI_NEXT_PROBE] = 2 if rel.K <= 5_000 else 10
    si[K.SI_HAS_VE], si[K.SI_HAS_VR] = len(rel.v_eval) == n, len(rel.v_rec) == n
    sf = np.zeros(8)
    sf[K.SF_BEST], sf[K.SF_THETA] = -math.inf, st.theta
    pi = np.array([max_iter, int(p["recover_every"]), int(p["patience"]),
                   int(p["stall_iter"]), exact, probe is not None, ls is not None,
                   st.integer, st.history is not None], np.int64)
    pf = np.array([p["step_decay"], p["step_min"], p["deflect"], p["gap_tol"],
                   p["stall_tol"], OPT_TOL], np.float64)
    block = max(1, int(_BLOCK_ENTRIES // max(rel.K, 1)))
    Cs, Is = sorted_rows(rel)
    args = (rel.Cg, Cs, Is, n, w, best_w, d_prev, g, sel, win, hist, v_eval, v_rec,
            np.zeros(n, np.int64), si, sf, pi, pf)
    kernel = pick("grid_ascent.ascent_block", *args, work=math.inf)
    flushed = 0
    t0 = time.perf_counter()

    def padded(x: np.ndarray) -> np.ndarray:
        u = upad.copy()
        u[off + 1: off + 1 + m] = x
        return u

    while True:
        if si[K.SI_STAGE] == 0 and si[K.SI_IT] >= si[K.SI_END]:
            step = block
            if deadline is not None:
                now = time.perf_counter()
                if si[K.SI_IT] and now > deadline:
                    st.stop = "time_limit"
                    break
                # a block that ends by the deadline, at the pace so far (first: one)
                pace = (now - t0) / max(int(si[K.SI_IT]), 1)
                step = 1 if not si[K.SI_IT] else \
                    max(1, min(block, int(0.5 * (deadline - now) / max(pace, 1e-9))))
            si[K.SI_END] = si[K.SI_IT] + step
        sf[K.SF_UB], sf[K.SF_BEST_REC], sf[K.SF_BOUND] = st.ub, st.best_recovered, st.bound
        n_before = int(si[K.SI_EVALS])
        event = kernel(*args)
        st.iterations += int(si[K.SI_EVALS]) - n_before
        st.bound = float(sf[K.SF_BOUND])
        flushed = _flush(st, hist, int(si[K.SI_NHIST]), flushed)
        if event == K.BLOCK_END:
            continue
        if event == K.OFFER:
            if si[K.SI_LS]:               # a record recovery, improved by the kernel
                st.best_recovered = float(sf[K.SF_COST])
                si[K.SI_NEXT_LS] = si[K.SI_IT] + 5
            st.offer(pos[sel])
            continue
        if event == K.PROBE:
            verdict = probe(padded(best_w))
            if verdict:
                st.stop = verdict
                break
            continue
        if event == K.ZERO:
            st.offer(pos[sel])
            L = float(sf[K.SF_L])
            st.bound = max(st.bound, min(L, st.ub))
            st.proof = st.proof or "relaxed solution feasible (zero subgradient)"
            st.stop = "proven"
            _record(st, L, float(sf[K.SF_BEST]))
            _keep_warm(rel, v_eval, v_rec, si, K)
            st.theta = float(sf[K.SF_THETA])
            return padded(w)
        if event == K.EVAL_FAIL:
            from ..twod.lap import LapInfeasibleError
            raise LapInfeasibleError("no finite assignment of the kept axes")
        if event == K.PROVEN:
            st.proof = st.proof or "Lagrangian bound meets the objective"
            st.stop = "proven"
        else:
            st.stop = {K.GAP: "gap_tol", K.STALLED: "stalled", K.STEP_MIN: "step_min",
                       K.MAX_ITER: "max_iter"}[int(event)]
        break
    _keep_warm(rel, v_eval, v_rec, si, K)
    st.theta = float(sf[K.SF_THETA])
    return padded(best_w)


def _flush(st: _State, hist: np.ndarray, n: int, done: int) -> int:
    """Append the kernel's history rows ``done..n`` to ``st.history``."""
    if st.history is None or n <= done:
        return n
    h = st.history
    h["bound"].extend(hist[0, done:n].tolist())
    h["best_bound"].extend(hist[1, done:n].tolist())
    h["objective"].extend(x if math.isfinite(x) else None for x in hist[2, done:n].tolist())
    return n


def _keep_warm(rel: _Relaxation, v_eval: np.ndarray, v_rec: np.ndarray, si: np.ndarray,
               K: Any) -> None:
    """Leave the LAP potentials on ``rel`` for its later evaluations (the fixing)."""
    if si[K.SI_HAS_VE]:
        rel.v_eval = v_eval.copy()
    if si[K.SI_HAS_VR]:
        rel.v_rec = v_rec.copy()
