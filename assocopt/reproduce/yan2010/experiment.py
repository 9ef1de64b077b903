"""Paper 001's experiments: the methods, the printed values, the trial function and the
experiment definitions (see :mod:`assocopt.reproduce.yan2010`).
"""

from __future__ import annotations

import time
from typing import Any, Mapping, Sequence

import numpy as np

from ...experiments import Experiment
from ...tracking.costs.association_degree import statistical_distance
from ...tracking.decide.max_degree import DecisionOptions, TrackAssociator, shared_columns
from ...tracking.scenarios.yan2010 import OURS, PAPER
from .setting import SCENARIO_KEYS, degree_params, scenario_of
from .three_node import three_node_metrics

__all__ = ["PAPER_TABLE1", "TABLE1_N", "DEFAULTS", "METHODS", "LABELS", "PAPER_METHODS",
           "experiments", "trial", "parameters", "scenario_of", "degree_params"]

#: Table 1: correct association probability of the proposed algorithm at t = 80 s.
TABLE1_N = (10, 20, 30, 40, 50, 60, 70, 80, 90, 100)
PAPER_TABLE1 = (0.9980, 0.9860, 0.9853, 0.9795, 0.9696, 0.9683, 0.9603, 0.9540, 0.9451, 0.9428)
PAPER_CLAIMS = {
    "fig4": "the proposed algorithm's correct rate is clearly higher than the weighted "
            "method's, especially at track start, when the EKF estimates are still poor",
    "table1": "performance falls only slowly with the number of targets (0.9428 at 100)",
}

#: Method name -> decision options and fusion reading.  "weighted" ignores the fusion.
METHODS: dict[str, dict[str, Any]] = {
    "ds-max": {"rule": "max-degree", "fusion": "candidate", "counter": "floor"},
    "ds-max-pair": {"rule": "max-degree", "fusion": "pair", "counter": "floor"},
    "ds-max-nocounter": {"rule": "max-degree", "fusion": "candidate", "counter": "off"},
    "ds-max-literal": {"rule": "max-degree", "fusion": "candidate", "counter": "literal"},
    "ds-assign": {"rule": "assignment", "fusion": "candidate", "counter": "floor"},
    "ds-assign-pair": {"rule": "assignment", "fusion": "pair", "counter": "floor"},
    "ds-assign-nocounter": {"rule": "assignment", "fusion": "candidate", "counter": "off"},
    "weighted": {"rule": "weighted", "fusion": "candidate", "counter": "off"},
    "weighted-counter": {"rule": "weighted", "fusion": "candidate", "counter": "floor"},
}
LABELS = {
    "ds-max": "D-S, max degree, counter (paper; candidate frame)",
    "ds-max-pair": "D-S, max degree, counter (pair frame)",
    "ds-max-nocounter": "D-S, max degree, no counter",
    "ds-max-literal": "D-S, max degree, counter as printed (no floor)",
    "ds-assign": "D-S, 2-D assignment, counter (ours)",
    "ds-assign-pair": "D-S, 2-D assignment, counter, pair frame (ours)",
    "ds-assign-nocounter": "D-S, 2-D assignment, no counter (ours)",
    "weighted": "weighted chi-square test (ref. [2])",
    "weighted-counter": "weighted test with the counter (ours)",
}
#: The paper's methods (under our readings of what it leaves open).
PAPER_METHODS = ("ds-max", "weighted")
TABLE1_METHODS = ("ds-max", "ds-max-pair", "ds-assign", "weighted")
FIG4_METHODS = ("ds-max", "ds-max-pair", "ds-max-nocounter", "ds-max-literal", "ds-assign",
                "ds-assign-pair", "ds-assign-nocounter", "weighted", "weighted-counter")
SENS_METHODS = ("ds-max", "ds-max-nocounter", "ds-assign", "weighted", "weighted-counter")
#: Sensitivity (ours): one parameter the paper leaves open changed at a time.
SENS_VARIANTS: dict[str, dict[str, Any]] = {
    "default": {},
    "one-type": {"emitter_types": 1},          # features carry no information
    "unique-features": {"emitter_types": 0},   # every emitter its own parameters
    "one-point-init": {"init": "one-point"},
    "kf-on-fixes": {"tracker": "kf-fix"},
    "mismatched-filter": {"q_filter": 1.0},
    "period-5s": {"period": 5.0},
    "crowded": {"region_scale": 0.1},          # a 20 km box instead of 200 km: stress test
}
VOLATILE = ("t_decide",)

#: Parameters the paper does not give (ours) and run options.
DEFAULTS: dict[str, Any] = {
    "weights": (0.4, 0.2, 0.2, 0.2),      # a1..a4
    "eps": 0.5,                            # threshold (paper: 0.5 <= eps < 1)
    "k_tol": 2.0,                          # tolerance = k_tol * sqrt(s1^2 + s2^2)
    "fix_at": 6,                           # the paper's value
    "cost": "neglog",                      # assignment cost
    "gate_alpha": 0.01,                    # weighted test's chi-square tail
    "solver": "auto",
    "tracker": "ekf",
    "init": "two-point",
    "q_true": 1.0,
    "q_filter": 20.0,
    "period": 1.0,
    "duration": 80.0,
    "freq_range": (9000.0, 9100.0),
    "pw_range": (0.8, 1.2),
    "pri_range": (950.0, 1050.0),
    "emitter_types": 10,
    "region_scale": 1.0,
    "fig4_n": 60,                          # Fig. 1's 60 targets
    "sensitivity_n": 100,
    "three_node_n": (10, 30, 60),
    "three_node_times": (5.0, 20.0, 80.0),
}
_RUN_KEYS = ("weights", "eps", "k_tol", "fix_at", "cost", "gate_alpha", "solver")


def decision_options(setting: Mapping[str, Any], method: str) -> DecisionOptions:
    m = METHODS[method]
    return DecisionOptions(rule=m["rule"], eps=float(setting["eps"]), counter=m["counter"],
                           fix_at=int(setting["fix_at"]), cost=setting["cost"],
                           gate_alpha=float(setting["gate_alpha"]), solver=setting["solver"])


# ------------------------------------------------------------------- trial
def trial(setting: Mapping[str, Any], methods: Sequence[str],
          seed: np.random.SeedSequence) -> dict[str, dict[str, float]]:
    """One simulated run decided by every method, step by step (paired comparison)."""
    if setting.get("part") == "three_node":
        return three_node_metrics(setting, methods, seed)
    rng = np.random.default_rng(seed)
    sc = scenario_of(setting)
    run = sc.simulate(rng)
    n, K = sc.n_targets, len(run.times)
    assoc = {m: TrackAssociator(n, n, degree_params(setting, sc, METHODS[m]["fusion"]),
                                decision_options(setting, m)) for m in methods}
    correct = {m: np.zeros(K) for m in methods}
    shared = {m: np.zeros(K) for m in methods}
    spent = dict.fromkeys(methods, 0.0)
    for k in range(K):
        D = statistical_distance(run.x[0][k], run.P[0][k], run.x[1][k], run.P[1][k])
        for m in methods:
            t0 = time.perf_counter()
            p = assoc[m].step(D, run.features[0][k], run.features[1][k])
            spent[m] += time.perf_counter() - t0
            correct[m][k] = float(np.mean(p == run.partner))
            shared[m][k] = shared_columns(p)
    every = setting.get("series", False)
    out: dict[str, dict[str, float]] = {}
    for m in methods:
        fixed = assoc[m].counter.fixed
        res = {f"correct_{int(round(t))}": float(c) for t, c in zip(run.times, correct[m])
               if every or int(round(t)) in (5, 10, 20, 40, 80)}
        res.update({"shared_steps": float(np.mean(shared[m] > 0)),
                    "shared_cols": float(np.mean(shared[m]) / n),
                    "fixed_final": float(np.mean(fixed >= 0)),
                    "wrong_fixed_final": float(np.mean((fixed >= 0) & (fixed != run.partner))),
                    "correct_mean": float(np.mean(correct[m])),
                    "t_decide": spent[m]})
        out[m] = res
    return out


# ------------------------------------------------------------- experiments
def _options(options: Mapping[str, Any] | None) -> dict[str, Any]:
    opts = {**DEFAULTS, **(options or {})}
    unknown = set(opts) - set(DEFAULTS)
    if unknown:
        raise ValueError(f"unknown yan2010 option(s) {sorted(unknown)}; valid: {sorted(DEFAULTS)}")
    common = _common(opts)
    sc = scenario_of({**common, "n": 2})                                     # validate
    degree_params(common, sc)
    for m in METHODS:
        decision_options(common, m)
    return opts


def _common(o: Mapping[str, Any]) -> dict[str, Any]:
    return {k: (list(o[k]) if isinstance(o[k], tuple) else o[k])
            for k in SCENARIO_KEYS + _RUN_KEYS}


def experiments(runs: int, seed: int, options: Mapping[str, Any] | None = None,
                parts: Sequence[str] = ("table1", "fig4", "sensitivity", "three_node")
                ) -> list[Experiment]:
    """The Experiments of the reproduction (``options`` override :data:`DEFAULTS`)."""
    o = _options(options)
    common = _common(o)
    out = []
    if "table1" in parts:
        settings = [{"part": "table1", "n": n, **common} for n in TABLE1_N]
        out.append(Experiment("yan2010-table1", settings, TABLE1_METHODS, trial, runs, seed,
                              params={"experiment": "table1"}, volatile=VOLATILE))
    if "fig4" in parts:
        settings = [{"part": "fig4", "n": int(o["fig4_n"]), "series": True, **common}]
        out.append(Experiment("yan2010-fig4", settings, FIG4_METHODS, trial, runs, seed,
                              params={"experiment": "fig4"}, volatile=VOLATILE))
    if "sensitivity" in parts:
        settings = [{"part": "sensitivity", "n": int(o["sensitivity_n"]), "variant": v,
                     **{**common, **ov}} for v, ov in SENS_VARIANTS.items()]
        out.append(Experiment("yan2010-sensitivity", settings, SENS_METHODS, trial, runs, seed,
                              params={"experiment": "sensitivity"}, volatile=VOLATILE))
    if "three_node" in parts:
        settings = [{"part": "three_node", "n": n, "times": list(o["three_node_times"]),
                     **common} for n in o["three_node_n"]]
        out.append(Experiment("yan2010-three_node", settings, ("sd-3", "pairwise-2d"), trial,
                              runs, seed, params={"experiment": "three_node"},
                              volatile=VOLATILE))
    return out


def parameters(options: Mapping[str, Any] | None = None) -> dict[str, Any]:
    """The parameters of a run: the paper's, ours (marked), and run options."""
    o = _options(options)
    common = _common(o)
    sc = scenario_of({**common, "n": int(o["fig4_n"])})
    dp = degree_params(common, sc)
    return {
        "paper": {**PAPER, "fix_at": 6, "eps_range": [0.5, 1.0], "table1_n": list(TABLE1_N)},
        "ours": {
            "scenario": sc.as_dict(),
            "scenario_ours": list(OURS),
            "weights_a1_a4": list(o["weights"]), "eps": o["eps"], "k_tol": o["k_tol"],
            "tolerances_f_pw_pri": list(dp.tolerances),
            "tolerance_rule": "k_tol * sqrt(sigma_1^2 + sigma_2^2) per feature",
            "d_tiny": dp.d_tiny,
            "assignment_cost": o["cost"] + " per pair; half the cost of a pair of degree eps "
                                           "per unassigned row or column",
            "weighted_gate": f"chi-square, 4 degrees of freedom, tail {o['gate_alpha']}",
            "counter_floor": "floor at 0 for the counter methods unless named 'literal'",
            "fixing": "a fixed pair is reported from then on; its row and column leave the "
                      "later tests; simultaneous candidates fixed greedily, highest count first",
            "fusion_default": "candidate frame",
            "metric": "correct_T: node-1 tracks whose decided partner at time T is the true "
                      "one, over all node-1 tracks (no partner = wrong), averaged over runs",
            "fig4_n": o["fig4_n"], "sensitivity_n": o["sensitivity_n"],
            "sensitivity_variants": SENS_VARIANTS,
            "three_node": {"n": list(o["three_node_n"]), "times": list(o["three_node_times"]),
                           "third_system": "main station (0, 100 km), 28 km baselines, 30 ns; "
                                           "feature errors the mean of the two nodes'"},
        },
        "run": {"solver": o["solver"]},
    }
