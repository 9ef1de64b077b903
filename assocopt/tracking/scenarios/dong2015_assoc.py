"""The association methods compared on paper 004's scenario, run over the steps of a
simulated run, and the metrics (defined once here; the page repeats them).

Topology methods (per step: Phi by :func:`~assocopt.tracking.decide.topology.phi_matrix`,
trial pairs, then the double-threshold rule over the steps).  The paper's reading first
(its order: the 2-D assignment, then the gate)::

    ``tsd-rect``     positions translated, velocities rotated, each reference pair's
                     rectangular assignment then the chi-square gate delta(0.01, 4), the
                     reference pair itself counted in lambda, row-wise trial pairs, dynamic
                     I/R;
    ``tsd-rect-noself`` the same with only the neighbour pairs in lambda;
    ``tsd-rect-obj``, ``tsd-rect-refcov``, ``tsd-rect-inflate`` the paper's reading with
                     one of our three changes each (objective degree; the reference's
                     covariance in B; the reference headings' variance in B, our
                     substitute for the lost T_1); ``tsd-rect-c`` with all three;
                     ``tsd-rect-noself-c`` the same on the neighbour-pairs reading;
    ``tsd-rect-global``, ``tsd-rect-noself-global`` both self-pair readings with
                     trial pairs by a global 2-D assignment on Phi (ours: the paper's
                     "smallest lambda" read row-wise is its own);
    ``tsd-rect-t1``, ``tsd-rect-noself-t1`` both with our substitute for the lost
                     heading threshold T_1 (``coef`` = C_1, 20 as the paper's);
    ``ted-rect``, ``ted-rect-noself`` the Euclidean baseline in the paper's reading.

Our earlier reading, with a dummy per row and column at half the gate::

    ``tsd``          as ``tsd-rect`` but dummies instead of the rectangular assignment;
    ``tsd-t1``       the same with our substitute for the lost heading threshold T_1
                     (``coef`` = the threshold coefficient; 20 as the paper's C_1);
    ``tsd-full``     full-state frame, reference pair left out of lambda;
    ``tsd-global``   trial pairs by a global 2-D assignment on Phi;
    ``tsd-min5``     lambda only from at least 5 confirmed pairs;
    ``tsd-obj``      lambda = the assignment cost per track, unconfirmed tracks at the
                     gate (ours);
    ``tsd-inflate``  ``tsd-obj`` with the reference-heading variance added to B (ours);
    ``tsd-c``        ``tsd-inflate`` with the reference's position covariance added
                     (ours: all three corrections); ``tsd-c-pregate`` with the coarse
                     speed pre-gate, ``tsd-c-global`` with global trial pairs;
    ``ted``          the Euclidean baseline: squared distance of the positions in the
                     reference frames, gate ``euclid_gate_m`` (ours: the paper's Euclidean
                     coefficient is lost), otherwise as ``tsd``; ``ted-obj`` with our
                     objective degree; ``ted-t1`` with the substitute threshold;
    ``tsd-obj-t1``, ``ted-obj-t1`` the objective degree with the substitute threshold.

Position baselines on the biased tracks (each step on its own, no I/R):
``nn`` (each sensor-1 track its nearest sensor-2 track in Mahalanobis distance of the
full state under the gate) and ``gnn`` (the 2-D assignment of the same costs with the
gate as non-assignment cost, through :func:`assocopt.solve`).

Metrics per step k: ``ec_kNN`` = correct pairs / common targets (the paper's E_c),
``fp_kNN`` = wrong pairs / common targets; ``ec_mean``; ``t_step_ms`` (volatile);
``pairs_frac``: fraction of reference pairs evaluated (pre-gate); heading errors
``hd1_kNN``, ``hd2_kNN`` (mean absolute, rad, every real target) and ``hd1t0_kNN``,
``hd2t0_kNN`` (the first common target, as the paper's Fig. 2), with method ``tsd``.
Calibration (methods marked ``calibrate``): ``cg_kNN`` the mean gamma_ij(u, v) of the
true neighbour pairs (i, j) under the true reference pairs (u, v), i != u, and
``cp_kNN`` the share of them under the chi-square gate (chi-square with 4 degrees of
freedom: mean 4, 99 % under delta(0.01, 4)).  Environment 1 only (``slot`` = index of
the target along the formation): ``tr0_kNN`` / ``tr12_kNN`` the share of common
sensor-1 tracks whose trial partner (the row's smallest lambda) is the true one / 1 or
2 slots from it, ``dec12_kNN`` the share whose decided partner is 1 or 2 slots off.
"""

from __future__ import annotations

import math
import time
from dataclasses import replace
from typing import Any, Mapping

import numpy as np

from ..decide.double_threshold import DoubleThreshold, IRRule
from ..decide.nearest import gnn_assign, nearest_neighbour
from ..decide.topology import (Duals, StepInputs, TopologyParams, assign_pairs,
                               coarse_pregate, degree_matrix, phi_matrix, prepare,
                               thresholds, trial_pairs)
from ..costs.topology import chi2_gate, headings
from .dong2015 import Run

__all__ = ["METHODS", "run_method", "position_costs", "step_metrics", "calibration",
           "slot_shares"]

METHODS: dict[str, dict[str, Any]] = {
    "tsd-rect": {"assignment": "rectangular", "calibrate": True},
    "tsd-rect-noself": {"assignment": "rectangular", "self_pair": "exclude"},
    "tsd-rect-obj": {"assignment": "rectangular", "degree": "objective"},
    "tsd-rect-refcov": {"assignment": "rectangular", "ref_cov": True, "calibrate": True},
    "tsd-rect-inflate": {"assignment": "rectangular", "inflate": True, "calibrate": True},
    "tsd-rect-c": {"assignment": "rectangular", "degree": "objective", "inflate": True,
                   "ref_cov": True, "calibrate": True},
    "tsd-rect-noself-c": {"assignment": "rectangular", "self_pair": "exclude",
                          "degree": "objective", "inflate": True, "ref_cov": True},
    "ted-rect": {"metric": "euclidean", "assignment": "rectangular"},
    "ted-rect-noself": {"metric": "euclidean", "assignment": "rectangular",
                        "self_pair": "exclude"},
    "tsd-rect-global": {"assignment": "rectangular", "trial": "assignment"},
    "tsd-rect-noself-global": {"assignment": "rectangular", "self_pair": "exclude",
                               "trial": "assignment"},
    "tsd-rect-t1": {"assignment": "rectangular", "threshold": "heading"},
    "tsd-rect-noself-t1": {"assignment": "rectangular", "self_pair": "exclude",
                           "threshold": "heading"},
    "tsd": {},
    "tsd-t1": {"threshold": "heading"},
    "tsd-full": {"frame": "full", "calibrate": True},
    "tsd-global": {"trial": "assignment"},
    "tsd-min5": {"min_pairs": 5},
    "tsd-obj": {"degree": "objective"},
    "tsd-inflate": {"degree": "objective", "inflate": True},
    "tsd-c": {"degree": "objective", "inflate": True, "ref_cov": True},
    "tsd-c-pregate": {"degree": "objective", "inflate": True, "ref_cov": True,
                      "pregate": True},
    "tsd-c-global": {"degree": "objective", "inflate": True, "ref_cov": True,
                     "trial": "assignment"},
    "ted": {"metric": "euclidean"},
    "ted-obj": {"metric": "euclidean", "degree": "objective"},
    "ted-t1": {"metric": "euclidean", "threshold": "heading"},
    "tsd-obj-t1": {"degree": "objective", "threshold": "heading"},
    "ted-obj-t1": {"metric": "euclidean", "degree": "objective", "threshold": "heading"},
    "nn": {"rule": "nn"},
    "gnn": {"rule": "gnn"},
}
_TOPO_KEYS = ("metric", "frame", "assignment", "self_pair", "inflate", "ref_cov", "degree",
              "threshold", "min_pairs")


def position_costs(X1, P1, X2, P2) -> np.ndarray:
    """Mahalanobis distance of the full states on the biased tracks, ``(n1, n2)``."""
    D = X1[:, None, :] - X2[None, :, :]
    B = P1[:, None] + P2[None, :]
    return np.einsum("ija,ija->ij", D, np.linalg.solve(B, D[..., None])[..., 0])


def step_metrics(partner: np.ndarray, truth: np.ndarray, n_common: int) -> tuple[float, float]:
    """(E_c, wrong pairs per common target) of one step's decided pairs."""
    ok = partner >= 0
    correct = int(np.sum(ok & (partner == truth)))
    wrong = int(np.sum(ok)) - correct
    if n_common == 0:
        return math.nan, math.nan
    return correct / n_common, wrong / n_common


def _params(opts: Mapping[str, Any], setting: Mapping[str, Any]) -> TopologyParams:
    kw = {k: opts[k] for k in _TOPO_KEYS if k in opts}
    return TopologyParams(alpha=float(setting.get("alpha", 0.01)),
                          coef=float(setting.get("coef", 20.0)),
                          euclid_gate_m=float(setting.get("euclid_gate_m", 1000.0)), **kw)


def run_method(run: Run, method: str, setting: Mapping[str, Any] | None = None,
               cache: dict | None = None) -> dict[str, float]:
    """Associate every step of ``run`` with ``method``; the metrics of the run.

    ``cache`` (a dict kept for one run): methods that differ only in ``self_pair``,
    ``degree`` or ``min_pairs`` share each step's assignments
    (:func:`~assocopt.tracking.decide.topology.assign_pairs`); the time of the shared
    solve is counted in every such method's ``t_step_ms``, as if it ran alone.
    """
    if method not in METHODS:
        raise ValueError(f"unknown dong2015 method {method!r}; valid: {sorted(METHODS)}")
    setting = dict(setting or {})
    opts = METHODS[method]
    truth = run.truth_partner()
    n_common = run.n_common
    n1, n2 = len(run.ids1), len(run.ids2)
    out: dict[str, float] = {}
    dt = DoubleThreshold(n1, n2, IRRule(setting.get("ir_schedule", "dynamic"),
                                        I=int(setting.get("ir_I", 2)),
                                        R=int(setting.get("ir_R", 3)),
                                        R_max=int(setting.get("ir_R_max", 4))))
    p = None if "rule" in opts else _params(opts, setting)
    gate = chi2_gate(float(setting.get("alpha", 0.01)), 4)
    t_total, evaluated = 0.0, 0
    duals = Duals()                        # warm start of the rectangular assignments
    for k, st in enumerate(run.steps, start=1):
        t0 = time.perf_counter()
        if opts.get("rule") == "nn":
            C = position_costs(st.X1, st.P1, st.X2, st.P2)
            partner = nearest_neighbour(C.T, gate)
        elif opts.get("rule") == "gnn":
            C = position_costs(st.X1, st.P1, st.X2, st.P2)
            partner = gnn_assign(C, gate)
        else:
            active = None
            if opts.get("pregate"):
                active = coarse_pregate(st.X1, st.P1, st.X2, st.P2,
                                        float(setting.get("pregate_alpha", 0.01)))
                evaluated += int(active.sum())
            else:
                evaluated += n1 * n2
            if cache is None:
                inp = prepare(st.X1, st.P1, st.X2, st.P2, p)
                phi, _ = phi_matrix(inp, p, active, duals=duals)
            else:
                inp, phi, shared = _shared_phi(cache, k, st, p, active)
                t0 -= shared
            trial = trial_pairs(phi, opts.get("trial", "row"))
            partner = dt.update(trial, phi)
        t_total += time.perf_counter() - t0
        ec, fp = step_metrics(partner, truth, n_common)
        out[f"ec_k{k:02d}"], out[f"fp_k{k:02d}"] = ec, fp
        if p is not None and opts.get("calibrate"):
            out[f"cg_k{k:02d}"], out[f"cp_k{k:02d}"] = calibration(inp, p, truth, gate)
        if p is not None and int(setting.get("env", 0)) == 1:
            for name, share in slot_shares(run, trial, partner).items():
                out[f"{name}_k{k:02d}"] = share
    K = len(run.steps)
    out["ec_mean"] = float(np.mean([out[f"ec_k{k:02d}"] for k in range(1, K + 1)]))
    out["t_step_ms"] = 1e3 * t_total / K
    if p is not None:
        out["pairs_frac"] = evaluated / (K * n1 * n2) if n1 * n2 else math.nan
    if method == "tsd":
        out.update(heading_errors(run))
    return out


def _shared_phi(cache: dict, k: int, st, p: TopologyParams, active
                ) -> tuple[StepInputs, np.ndarray, float]:
    """Phi of step ``k`` from the cached assignments of every method with the same
    assignment options; returns ``(inputs, Phi, seconds of the shared solve)`` (0 when
    computed now: the caller's clock already runs)."""
    key = (k, replace(p, self_pair="include", degree="mean", min_pairs=1),
           None if active is None else active.tobytes())
    took = 0.0
    if key not in cache:
        t0 = time.perf_counter()
        inp = prepare(st.X1, st.P1, st.X2, st.P2, p)
        duals = cache.setdefault(("duals",) + key[1:2], Duals())
        cache[key] = (inp, *assign_pairs(inp, p, active, duals=duals), thresholds(inp, p))
        cache[key + ("s",)] = time.perf_counter() - t0
    else:
        took = cache[key + ("s",)]
    inp, cols, gam, thr = cache[key]
    return inp, degree_matrix(cols, gam, thr, p)[0], took


def calibration(inp: StepInputs, p: TopologyParams, truth: np.ndarray, gate: float
                ) -> tuple[float, float]:
    """(mean gamma, share under ``gate``) of the true neighbour pairs (i, truth[i])
    under the true reference pairs (u, truth[u]), i != u: chi-square with 4 degrees of
    freedom would give 4 and 1 - alpha if B were the covariance of the difference."""
    U = np.flatnonzero(truth >= 0)
    V = truth[U]
    D = inp.X1r[U][:, U] - inp.X2r[V][:, V]
    B = inp.P1r[U][:, U] + inp.P2r[V][:, V]
    if p.inflate:
        v1 = np.where(np.isfinite(inp.var1[U]), inp.var1[U], 1e6)
        v2 = np.where(np.isfinite(inp.var2[V]), inp.var2[V], 1e6)
        J1, J2 = inp.J1[U][:, U], inp.J2[V][:, V]
        B = B + v1[:, None, None, None] * np.einsum("uia,uib->uiab", J1, J1) \
              + v2[:, None, None, None] * np.einsum("uia,uib->uiab", J2, J2)
    g = np.einsum("uia,uia->ui", D, np.linalg.solve(B, D[..., None])[..., 0])
    g = g[~np.eye(len(U), dtype=bool)]
    if g.size == 0:
        return math.nan, math.nan
    return float(g.mean()), float(np.mean(g <= gate))


def slot_shares(run: Run, trial: np.ndarray, partner: np.ndarray) -> dict[str, float]:
    """Environment 1's shifted-formation ambiguity: shares of the common sensor-1
    tracks whose trial partner is the true target (``tr0``) or 1-2 formation slots
    from it (``tr12``), and whose decided partner is 1-2 slots off (``dec12``)."""
    common = set(run.ids2[run.ids2 >= 0].tolist())
    rows = [u for u, t in enumerate(run.ids1) if t >= 0 and int(t) in common]
    if not rows:
        return {}

    def off(col: np.ndarray, u: int) -> int:
        j = int(col[u])
        return -1 if j < 0 or run.ids2[j] < 0 else abs(int(run.ids2[j]) - int(run.ids1[u]))

    dt = np.array([off(trial, u) for u in rows])
    dd = np.array([off(partner, u) for u in rows])
    return {"tr0": float(np.mean(dt == 0)),
            "tr12": float(np.mean((dt == 1) | (dt == 2))),
            "dec12": float(np.mean((dd == 1) | (dd == 2)))}


def heading_errors(run: Run) -> dict[str, float]:
    """Mean absolute heading error per step and sensor (rad), all real targets and the
    first common target."""
    out = {}
    common = sorted(set(run.ids1[run.ids1 >= 0].tolist()) & set(run.ids2[run.ids2 >= 0].tolist()))
    t0 = common[0] if common else None
    for k, st in enumerate(run.steps, start=1):
        for s, (X, ids, th) in enumerate(((st.X1, run.ids1, run.true_heading1),
                                          (st.X2, run.ids2, run.true_heading2)), start=1):
            e = np.abs((headings(X) - th[k - 1] + math.pi) % (2 * math.pi) - math.pi)
            out[f"hd{s}_k{k:02d}"] = float(np.nanmean(e))
            if t0 is not None:
                out[f"hd{s}t0_k{k:02d}"] = float(e[ids == t0][0])
    return out
