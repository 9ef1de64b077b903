"""Our three-node extension of paper 001: one S-D assignment over three TDOA systems
against the 2-D assignment of nodes 1 and 2 alone (docs/papers/yan2010.md).

Both decide single scans (no quality counter) at the times of ``setting["times"]``, on
pair-frame fused degrees.  Metrics per time T: ``correct12_T`` (node-1 tracks whose
node-2 partner is right) for both methods, and for the S-D model ``triple_T`` (node-1
tracks whose whole tuple is right).
"""

from __future__ import annotations

import time
from typing import Any, Mapping, Sequence

import numpy as np

from ...tracking.costs.association_degree import feature_degrees, fused_degree, statistical_distance
from ...tracking.decide.max_degree import assignment_rule
from ...tracking.decide.multi_node import three_node_decision
from .setting import degree_params, scenario_of

__all__ = ["three_node_metrics"]


def _degrees(run, k: int, a: int, b: int, params) -> np.ndarray:
    D = statistical_distance(run.x[a][k], run.P[a][k], run.x[b][k], run.P[b][k])
    return fused_degree(feature_degrees(D, run.features[a][k], run.features[b][k], params),
                        "pair")


def three_node_metrics(setting: Mapping[str, Any], methods: Sequence[str],
                       seed: np.random.SeedSequence) -> dict[str, dict[str, float]]:
    """One three-node run decided by ``"sd-3"`` and ``"pairwise-2d"``."""
    rng = np.random.default_rng(seed)
    sc = scenario_of(setting, nodes=3)
    run = sc.simulate(rng)
    eps = float(setting["eps"])
    params = {(a, b): degree_params(setting, sc, "pair", a, b) for a, b in ((0, 1), (0, 2), (1, 2))}
    out: dict[str, dict[str, float]] = {m: {"t_decide": 0.0} for m in methods}
    truth = np.stack(run.partners, axis=1)                   # (n1, 3): true tuple per track
    for T in setting["times"]:
        k = int(round(float(T) / sc.period)) - 1
        m = {ab: _degrees(run, k, *ab, params[ab]) for ab in params}
        tag = int(round(float(T)))
        if "sd-3" in methods:
            t0 = time.perf_counter()
            tup = three_node_decision(m[(0, 1)], m[(0, 2)], m[(1, 2)], eps, setting["solver"])
            out["sd-3"]["t_decide"] += time.perf_counter() - t0
            out["sd-3"][f"correct12_{tag}"] = float(np.mean(tup[:, 1] == run.partner))
            out["sd-3"][f"triple_{tag}"] = float(np.mean((tup == truth).all(axis=1)))
        if "pairwise-2d" in methods:
            t0 = time.perf_counter()
            p = assignment_rule(m[(0, 1)], eps, "neglog", setting["solver"])
            out["pairwise-2d"]["t_decide"] += time.perf_counter() - t0
            out["pairwise-2d"][f"correct12_{tag}"] = float(np.mean(p == run.partner))
    return out
