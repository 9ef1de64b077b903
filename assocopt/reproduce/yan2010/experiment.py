"""Paper 001's experiments: the methods, the printed values, the trial function and the
experiment definitions (see :mod:`assocopt.reproduce.yan2010`).
"""

from __future__ import annotations

import time
from typing import Any, Mapping, Sequence

import numpy as np

from ...experiments import Experiment
from ...tracking.costs.association_degree import pair_feature_degrees, statistical_distance
from ...tracking.decide.max_degree import DecisionOptions, TrackAssociator, shared_columns
from ...tracking.scenarios.yan2010 import OURS, PAPER
from .scoring import rates
from .setting import SCENARIO_KEYS, degree_params, scenario_of
from .three_node import three_node_metrics

__all__ = ["PAPER_TABLE1", "TABLE1_N", "DEFAULTS", "METHODS", "LABELS", "PAPER_METHODS",
           "FEATURE_SETS", "GRID_METHODS", "VERSUS", "experiments", "trial", "parameters",
           "scenario_of", "degree_params"]

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
for _m in ("ds-max", "ds-max-nocounter", "ds-assign", "ds-assign-nocounter"):
    METHODS[f"{_m}-k1"] = {**METHODS[_m], "k_tol": 1.0}      # tolerance factor 1, not 2
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
    **{f"{m}-k1": f"{m}, tolerance factor 1" for m in ("ds-max", "ds-max-nocounter",
                                                        "ds-assign", "ds-assign-nocounter")},
}
#: The grid (ours): the paper's rule and the assignment, with and without the counter,
#: tolerance factor 2 (default) and 1.
GRID_METHODS = ("ds-max", "ds-max-nocounter", "ds-assign", "ds-assign-nocounter",
                "ds-max-k1", "ds-max-nocounter-k1", "ds-assign-k1", "ds-assign-nocounter-k1")
#: Assignment method -> the maximum-degree method it is compared with, paired.
VERSUS = {"ds-assign": "ds-max", "ds-assign-nocounter": "ds-max-nocounter",
          "ds-assign-k1": "ds-max-k1", "ds-assign-nocounter-k1": "ds-max-nocounter-k1"}
#: Emitter feature sets of the grid (ours): the 10-type catalogue (default), every
#: emitter its own values with the PRI in a 10 us band (so the number of emitters whose
#: features overlap grows with n), every emitter one type (features carry nothing).
FEATURE_SETS: dict[str, dict[str, Any]] = {
    "types10": {},
    "per-emitter": {"emitter_types": 0, "pri_range": [1000.0, 1010.0]},
    "one-type": {"emitter_types": 1},
}
#: The paper's methods (under our readings of what it leaves open).
PAPER_METHODS = ("ds-max", "weighted")
TABLE1_METHODS = ("ds-max", "ds-max-pair", "ds-assign", "weighted")
FIG4_METHODS = ("ds-max", "ds-max-pair", "ds-max-nocounter", "ds-max-literal", "ds-assign",
                "ds-assign-pair", "ds-assign-nocounter", "weighted", "weighted-counter")
THREE_NODE_METHODS = ("sd-3", "pairwise-2d", "pairwise-max")
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
    "tdoa-x3": {"tdoa_sigma_scale": 3.0},      # TDOA errors 90 ns instead of 30 ns
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
    "single_node_fraction": 0.0,
    "tdoa_sigma_scale": 1.0,
    "grid_n": TABLE1_N,
    "grid_coverage": (0.0, 0.1, 0.2),      # single-node fractions of the grid
    "grid_features": ("types10", "per-emitter"),
    "grid_one_type_coverage": (0.0,),      # the "features matter" check: one type
    "confirm": None,                       # (features, coverage): a grid cell rerun on
                                           # fresh seeds (part "confirm")
    "grid_runs": None,                     # runs of the parts that are ours: sensitivity,
                                           # grid, three nodes (None: runs)
    "fig4_n": 60,                          # Fig. 1's 60 targets
    "sensitivity_n": 100,
    "three_node_n": (10, 30, 60),
    "three_node_times": (5.0, 20.0, 80.0),
    "three_node_coverage": (0.0, 0.2),
    "three_node_features": ("types10", "per-emitter"),
}
_RUN_KEYS = ("weights", "eps", "k_tol", "fix_at", "cost", "gate_alpha", "solver")


def decision_options(setting: Mapping[str, Any], method: str) -> DecisionOptions:
    m = METHODS[method]
    return DecisionOptions(rule=m["rule"], eps=float(setting["eps"]), counter=m["counter"],
                           fix_at=int(setting["fix_at"]), cost=setting["cost"],
                           gate_alpha=float(setting["gate_alpha"]), solver=setting["solver"])


# ------------------------------------------------------------------- trial
REPORT_TIMES = (5, 10, 20, 40, 80)


def _block(n1: int, n2: int, r: np.ndarray, c: np.ndarray, fill: float, compute,
           lead: tuple[int, ...] = ()) -> np.ndarray:
    """An ``lead + (n1, n2)`` matrix computed on rows ``r`` x columns ``c`` only (the
    pairs some associator still tests), ``fill`` elsewhere (never read)."""
    if len(r) == n1 and len(c) == n2:
        return compute(slice(None), slice(None))
    out = np.full(lead + (n1, n2), fill)
    if len(r) and len(c):
        out[..., r[:, None], c[None, :]] = compute(r, c)
    return out


def trial(setting: Mapping[str, Any], methods: Sequence[str],
          seed: np.random.SeedSequence) -> dict[str, dict[str, float]]:
    """One simulated run decided by every method, step by step (paired comparison).

    Metrics per method: ``correct_T`` (common-track rate at time T) and ``all_T``
    (all-track rate, :mod:`.scoring`); for an assignment method with its
    maximum-degree counterpart in ``methods`` (:data:`VERSUS`), ``dcommon_T`` and
    ``dall_T``: its rate minus the counterpart's on the same run.
    """
    if setting.get("part") == "three_node":
        return three_node_metrics(setting, methods, seed)
    rng = np.random.default_rng(seed)
    sc = scenario_of(setting)
    run = sc.simulate(rng)
    n1, n2 = len(run.emitter_of[0]), len(run.emitter_of[1])
    K = len(run.times)
    assoc = {m: TrackAssociator(n1, n2, degree_params(setting, sc, METHODS[m]["fusion"],
                                                      k_tol=METHODS[m].get("k_tol")),
                                decision_options(setting, m)) for m in methods}
    sparse = bool(setting.get("sparse", False))
    series = setting.get("series", False)
    report = [series or (int(round(t)) in REPORT_TIMES) for t in run.times]
    common = {m: np.full(K, np.nan) for m in methods}
    every = {m: np.full(K, np.nan) for m in methods}
    shared = {m: np.full(K, np.nan) for m in methods}
    spent = dict.fromkeys(methods, 0.0)
    for k in range(K):
        # sparse (the grid): a method without counter decides each scan on its own, so
        # it is run at the reported scans only; the others at every scan
        live = [m for m in methods if report[k] or not sparse or
                METHODS[m]["counter"] != "off"]
        busy = [m for m in live if assoc[m].needs_input]
        if busy:                            # the distances of the pairs still open
            r = np.flatnonzero(np.any([assoc[m].counter.open_rows for m in busy], axis=0))
            c = np.flatnonzero(np.any([assoc[m].counter.open_cols for m in busy], axis=0))
            f1, f2 = run.features[0][k], run.features[1][k]
            D = _block(n1, n2, r, c, np.inf, lambda r, c: statistical_distance(
                run.x[0][k][r], run.P[0][k][r], run.x[1][k][c], run.P[1][k][c]))
            F = {}                          # feature degrees, once per tolerance set
            memo: dict = {}                 # fused degrees, once per (params, open set)
        for m in live:
            t0 = time.perf_counter()
            if m in busy:
                a = assoc[m]
                key = a.params.tolerances + a.params.weights
                if key not in F:
                    F[key] = _block(n1, n2, r, c, 0.0, lambda r, c, q=a.params:
                                    pair_feature_degrees(f1[r], f2[c], q), lead=(3,))
                p = a.step(D, f1, f2, F[key], memo)
            else:                           # nothing open: the fixed pairs stand
                fx = assoc[m].counter.fixed
                p = np.where(fx >= 0, fx, -1)
            spent[m] += time.perf_counter() - t0
            if report[k] or not sparse:
                common[m][k], every[m][k] = rates(p, run.partner, n2)
                shared[m][k] = shared_columns(p)
    tags = [(k, int(round(t))) for k, t in enumerate(run.times) if report[k]]
    out: dict[str, dict[str, float]] = {}
    for m in methods:
        fixed = assoc[m].counter.fixed
        res = {f"correct_{t}": float(common[m][k]) for k, t in tags}
        res.update({f"all_{t}": float(every[m][k]) for k, t in tags})
        res.update({"fixed_final": float(np.mean(fixed >= 0)) if n1 else 0.0,
                    "wrong_fixed_final": float(np.mean((fixed >= 0) & (fixed != run.partner)))
                    if n1 else 0.0, "t_decide": spent[m]})
        if sparse:                          # shared node-2 tracks / n2 at each reported time
            res.update({f"shared_{t}": float(shared[m][k] / max(n2, 1)) for k, t in tags})
        else:
            res.update({"shared_steps": float(np.mean(shared[m] > 0)),
                        "shared_cols": float(np.mean(shared[m]) / max(n2, 1)),
                        "correct_mean": float(np.mean(common[m])),
                        "all_mean": float(np.mean(every[m]))})
        out[m] = res
    for m, base in VERSUS.items():
        if m in out and base in out:
            for k, t in tags:
                out[m][f"dcommon_{t}"] = float(common[m][k] - common[base][k])
                out[m][f"dall_{t}"] = float(every[m][k] - every[base][k])
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
                parts: Sequence[str] = ("table1", "fig4", "sensitivity", "grid",
                                        "three_node")
                ) -> list[Experiment]:
    """The Experiments of the reproduction (``options`` override :data:`DEFAULTS`)."""
    o = _options(options)
    common = _common(o)
    grid_runs = runs if o["grid_runs"] is None else int(o["grid_runs"])
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
        out.append(Experiment("yan2010-sensitivity", settings, SENS_METHODS, trial, grid_runs,
                              seed,
                              params={"experiment": "sensitivity"}, volatile=VOLATILE))
    if "grid" in parts:
        cells = [(f, c) for f in o["grid_features"] for c in o["grid_coverage"]] + \
            [("one-type", c) for c in o["grid_one_type_coverage"]]
        settings = [_grid_setting("grid", n, f, c, common) for n in o["grid_n"]
                    for f, c in cells]
        out.append(Experiment("yan2010-grid", settings, GRID_METHODS, trial, grid_runs, seed,
                              params={"experiment": "grid"}, volatile=VOLATILE))
    if "confirm" in parts and o["confirm"] is not None:
        f, c = o["confirm"]                 # "part" differs from the grid's: fresh seeds
        settings = [_grid_setting("confirm", n, f, c, common) for n in o["grid_n"]]
        out.append(Experiment("yan2010-confirm", settings, GRID_METHODS, trial, grid_runs,
                              seed, params={"experiment": "confirm"}, volatile=VOLATILE))
    if "three_node" in parts:
        settings = [{**_grid_setting("three_node", n, f, c, common),
                     "times": list(o["three_node_times"])} for n in o["three_node_n"]
                    for f in o["three_node_features"] for c in o["three_node_coverage"]]
        out.append(Experiment("yan2010-three_node", settings, THREE_NODE_METHODS, trial,
                              grid_runs, seed, params={"experiment": "three_node"},
                              volatile=VOLATILE))
    return out


def variant_name(features: str, coverage: float) -> str:
    """Name of a grid cell, e.g. ``"per-emitter, 10 % single"``."""
    return f"{features}, {int(round(100 * coverage))} % single"


def _grid_setting(part: str, n: int, features: str, coverage: float,
                  common: Mapping[str, Any]) -> dict[str, Any]:
    if features not in FEATURE_SETS:
        raise ValueError(f"feature set must be one of {sorted(FEATURE_SETS)}, got {features!r}")
    return {"part": part, "n": int(n), "variant": variant_name(features, coverage),
            "sparse": part in ("grid", "confirm"),
            "features": features, "coverage": float(coverage),
            **{**common, **FEATURE_SETS[features], "single_node_fraction": float(coverage)}}


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
            "metric": "correct_T (common-track rate): node-1 tracks with a true partner whose "
                      "decided partner at time T is it (no partner = wrong); all_T (all-track "
                      "rate): every track of both nodes, a track without a true partner "
                      "correct only when left unassociated, a node-2 track correct only when "
                      "exactly its partner took it; both averaged over runs",
            "single_node": "single_node_fraction of the emitters (rounded) seen by one node "
                           "only, that node drawn uniformly",
            "feature_sets": FEATURE_SETS,
            "grid": {"n": list(o["grid_n"]), "coverage": list(o["grid_coverage"]),
                     "features": list(o["grid_features"]),
                     "one_type_coverage": list(o["grid_one_type_coverage"]),
                     "methods": list(GRID_METHODS), "runs": o["grid_runs"]},
            "confirm": None if o["confirm"] is None else list(o["confirm"]),
            "fig4_n": o["fig4_n"], "sensitivity_n": o["sensitivity_n"],
            "sensitivity_variants": SENS_VARIANTS,
            "three_node": {"n": list(o["three_node_n"]), "times": list(o["three_node_times"]),
                           "coverage": list(o["three_node_coverage"]),
                           "features": list(o["three_node_features"]),
                           "third_system": "main station (0, 100 km), 28 km baselines, 30 ns; "
                                           "feature errors the mean of the two nodes'"},
        },
        "run": {"solver": o["solver"]},
    }
