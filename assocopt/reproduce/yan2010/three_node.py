"""Our three-node extension of paper 001: one S-D assignment over three TDOA systems
against deciding nodes 1 and 2 alone (docs/papers/yan2010.md).

All decide single scans (no quality counter) at the times of ``setting["times"]``, on
pair-frame fused degrees: ``"sd-3"`` one S-D assignment over the three nodes,
``"pairwise-2d"`` the 2-D assignment of nodes 1-2, ``"pairwise-max"`` the paper's
maximum-degree rule on nodes 1-2.  Metrics per time T: ``correct12_T`` (common-track
rate of nodes 1-2) and ``all12_T`` (all-track rate, :mod:`.scoring`) for every method,
and for the S-D model ``triple_T`` (node-1 tracks whose whole tuple is right, a node
that does not see the emitter counting right only when left out).
"""

from __future__ import annotations

import time
from typing import Any, Mapping, Sequence

import numpy as np

from ...tracking.costs.association_degree import feature_degrees, fused_degree, statistical_distance
from ...tracking.decide.max_degree import assignment_rule, max_degree_rule
from ...tracking.decide.multi_node import three_node_decision
from .scoring import rates
from .setting import degree_params, scenario_of

__all__ = ["three_node_metrics"]


def _degrees(run, k: int, a: int, b: int, params) -> np.ndarray:
    D = statistical_distance(run.x[a][k], run.P[a][k], run.x[b][k], run.P[b][k])
    return fused_degree(feature_degrees(D, run.features[a][k], run.features[b][k], params),
                        "pair")


def three_node_metrics(setting: Mapping[str, Any], methods: Sequence[str],
                       seed: np.random.SeedSequence) -> dict[str, dict[str, float]]:
    """One three-node run decided by ``"sd-3"``, ``"pairwise-2d"`` and ``"pairwise-max"``."""
    rng = np.random.default_rng(seed)
    sc = scenario_of(setting, nodes=3)
    run = sc.simulate(rng)
    eps = float(setting["eps"])
    n2 = len(run.emitter_of[1])
    params = {(a, b): degree_params(setting, sc, "pair", a, b) for a, b in ((0, 1), (0, 2), (1, 2))}
    out: dict[str, dict[str, float]] = {m: {"t_decide": 0.0} for m in methods}
    truth = np.stack(run.partners, axis=1)                   # (n1, 3): true tuple per track
    for T in setting["times"]:
        k = int(round(float(T) / sc.period)) - 1
        m = {ab: _degrees(run, k, *ab, params[ab]) for ab in params}
        tag = int(round(float(T)))
        for meth in methods:
            t0 = time.perf_counter()
            if meth == "sd-3":
                tup = three_node_decision(m[(0, 1)], m[(0, 2)], m[(1, 2)], eps,
                                          setting["solver"])
                p = tup[:, 1]
                out[meth][f"triple_{tag}"] = float(np.mean((tup == truth).all(axis=1))) \
                    if len(tup) else 1.0
            elif meth == "pairwise-2d":
                p = assignment_rule(m[(0, 1)], eps, "neglog", setting["solver"])
            elif meth == "pairwise-max":
                p = max_degree_rule(m[(0, 1)], eps)
            else:
                raise ValueError(f"unknown three-node method {meth!r}")
            out[meth]["t_decide"] += time.perf_counter() - t0
            out[meth][f"correct12_{tag}"], out[meth][f"all12_{tag}"] = rates(p, run.partner, n2)
    return out
