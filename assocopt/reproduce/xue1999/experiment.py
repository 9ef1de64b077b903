"""Paper 003's experiments: the options, the trial, the method labels and the
Experiment grid (the three experiments, ``tune``, ``main`` and ``sweep``, are described
in :mod:`assocopt.reproduce.xue1999`).
"""

from __future__ import annotations

import time
from dataclasses import fields
from typing import Any, Mapping, Sequence

import numpy as np

from ...experiments import Experiment
from ...tracking.scenarios.xue1999 import OURS as SCENARIO_OURS, Xue1999
from ...tracking.scenarios.xue1999_tracker import (CONFLICTS, METHODS, TrackerParams,
                                                  run_metrics, run_tracker, split_method,
                                                  tuned_name)

__all__ = ["DEFAULTS", "PAPER_CLAIMS", "LABELS", "METRICS", "VOLATILE", "experiments",
           "trial", "parameters", "label", "tune_grid", "best_pairs"]

PAPER_CLAIMS = {
    "figs2_3": "four targets in the (x, y) plane; Fig. 2 tracks and noise data, Fig. 3 "
               "the tracks after association (figures not in our copy)",
    "result": "correct association results even with many track crossings and strong "
              "noise signals; no parameter, metric or number is given",
}

_SCENARIO = ("n_scans", "T", "p_d", "sigma_p", "sigma_v", "p_iff", "clutter_v")
_TRACKER = tuple(f.name for f in fields(TrackerParams))

#: Run options and the parameters the paper does not give (all ours).
DEFAULTS: dict[str, Any] = {
    **{k: getattr(Xue1999(), k) for k in _SCENARIO},
    "noise_scale": 1.0, "clutter_mean": 10.0,
    **{k: (list(v) if isinstance(v, tuple) else v)
       for k, v in TrackerParams().as_dict().items()},
    "main_methods": tuple(METHODS),
    "sweep_methods": ("did-printed", "did-q0", "gnn", "nn"),
    "noise_grid": (0.5, 1.0, 2.0, 3.0),
    "clutter_grid": (0.0, 10.0, 30.0),
    "sweep_divisor": 5,
    "tune_methods": tuple(m for m, o in METHODS.items() if o["rule"] == "did"),
    "tune_B": (0.00002, 0.00005, 0.0001, 0.0002, 0.0005, 0.001, 0.002, 0.005, 0.01, 0.02,
               0.05, 0.1, 0.2, 0.4),
    "tune_M_prime": (1.0, 2.0, 3.0, 4.0, 6.0, 10.0, 20.0, 40.0),
    "tune_divisor": 5,
    "at_printed_best": ("did-printed-q0", "did-conflict-q0", "did-conflict-new"),
    "example_seed": 3,
}

#: What each DID method changes; "as printed" only for eq. (10) with the literal selection.
LABELS = {"did-printed": "DID as printed (eq. 10, literal selection)",
          "did-dowhile": "DID as printed, step 5 as do-while",
          "did-zscore": "DID, z-score error instead of eq. 10 (ours)",
          "did-movable": "DID, movable selection (ours)",
          "did-printed-q0": "DID, q from stage 1 (ours)",
          "did-majority": "DID, unsettled record judged by its majority (ours)",
          "did-conflict-q0": "DID, conflict settled by stage-1 q (not from the paper)",
          "did-conflict-new": "DID, conflict losers start tracks (not from the paper)",
          "did-zm": "DID, z-score error + movable selection (ours)",
          "did-q0": "DID, z-score error + movable selection + q from stage 1 (ours)",
          "gnn": "GNN (2-D assignment)", "nn": "NN"}
METRICS = ("correct_rate", "decision_precision", "swaps", "false_tracks", "held_at_end",
           "stage2_rate", "nonconverged_rate", "conflict_rate")
VOLATILE = ("t_run",)


def label(method: str) -> str:
    """The table label of a method name (one with B, M' set says so)."""
    base, over = split_method(method)
    if not over:
        return LABELS[base]
    return f"{LABELS[base]}, at B = {over['did_B']:g}, M′ = {over['did_M_prime']:g}"


def tune_grid(options: Mapping[str, Any] | None = None) -> list[str]:
    """The tuning part's methods: every tuned method at every (B, M') of the grid."""
    o = _options(options)
    return [tuned_name(m, B, Mp) for m in o["tune_methods"] for B in o["tune_B"]
            for Mp in o["tune_M_prime"]]


def best_pairs(records, options: Mapping[str, Any] | None = None) -> dict[str, dict[str, Any]]:
    """Per tuned method: the (B, M') of the largest correct rate on the tuning seeds
    (ties: the first in grid order), its rate and the range over the grid."""
    o = _options(options)
    rate = {r["method"]: r["value"] for r in records
            if r["experiment"] == "tune" and r["metric"] == "correct_rate"}
    out = {}
    for m in o["tune_methods"]:
        grid = [(B, Mp, rate[tuned_name(m, B, Mp)]) for B in o["tune_B"]
                for Mp in o["tune_M_prime"] if tuned_name(m, B, Mp) in rate]
        if not grid:
            continue
        B, Mp, v = max(grid, key=lambda g: g[2])        # max keeps the first of equals
        out[m] = {"B": B, "M_prime": Mp, "correct_rate": v, "method": tuned_name(m, B, Mp),
                  "range": [min(g[2] for g in grid), max(g[2] for g in grid)]}
    return out


def _options(options: Mapping[str, Any] | None) -> dict[str, Any]:
    opts = {**DEFAULTS, **(options or {})}
    unknown = set(opts) - set(DEFAULTS)
    if unknown:
        raise ValueError(f"unknown xue1999 option(s) {sorted(unknown)}; valid: {sorted(DEFAULTS)}")
    for m in (tuple(opts["main_methods"]) + tuple(opts["sweep_methods"])
              + tuple(opts["tune_methods"]) + tuple(opts["at_printed_best"])):
        if m not in METHODS:
            raise ValueError(f"unknown xue1999 method {m!r}; valid: {sorted(METHODS)}")
    for m in tuple(opts["tune_methods"]) + tuple(opts["at_printed_best"]):
        if METHODS[m]["rule"] != "did":
            raise ValueError(f"tune_methods / at_printed_best: {m!r} is not a DID method")
    for k in ("sweep_divisor", "tune_divisor"):
        if not isinstance(opts[k], int) or opts[k] < 1:
            raise ValueError(f"{k} must be a positive integer")
    _scenario({**opts})
    _tracker(opts)
    return opts


def _scenario(s: Mapping[str, Any]) -> Xue1999:
    return Xue1999(noise_scale=float(s["noise_scale"]), clutter_mean=float(s["clutter_mean"]),
                   **{k: s[k] for k in _SCENARIO})


def _tracker(s: Mapping[str, Any]) -> TrackerParams:
    kw = {k: s[k] for k in _TRACKER}
    kw["did_origin_floor"] = tuple(kw["did_origin_floor"])
    return TrackerParams(**kw)


def trial(setting: Mapping[str, Any], methods: Sequence[str],
          seed: np.random.SeedSequence) -> dict[str, dict[str, float]]:
    """One simulated run tracked by every method (module level: picklable)."""
    sc = _scenario(setting)
    tp = _tracker(setting)
    scans = sc.simulate(np.random.default_rng(seed))
    out = {}
    for m in methods:
        t0 = time.perf_counter()
        log = run_tracker(scans, m, sc, tp)
        res = run_metrics(log, sc)
        res["t_run"] = time.perf_counter() - t0
        out[m] = res
    return out


def experiments(runs: int, seed: int, options: Mapping[str, Any] | None = None,
                parts: Sequence[str] = ("tune", "main", "sweep"),
                tuned: Mapping[str, str] | None = None) -> list[Experiment]:
    """The Experiments of the reproduction (``options`` override :data:`DEFAULTS`).

    ``tuned`` maps a tuned method to its best-pair method name (:func:`best_pairs`);
    those are added to ``main`` and, for the sweep's methods, to ``sweep``; the
    methods of ``at_printed_best`` (our changes to the printed rule) join ``main`` at
    the best pair of ``did-printed`` too.  The tuning
    part's setting differs from the main one (``part``), so its trial seeds
    (:func:`~assocopt.experiments.trial_seed`) are independent of the reported ones.
    """
    o = _options(options)
    tuned = dict(tuned or {})
    common = {k: o[k] for k in _SCENARIO + _TRACKER}
    base = {"noise_scale": o["noise_scale"], "clutter_mean": o["clutter_mean"], **common}
    out = []
    if "tune" in parts:
        out.append(Experiment("xue1999-tune", [{"part": "tune", **base}],
                              tuple(tune_grid(o)), trial, max(1, runs // o["tune_divisor"]),
                              seed, params={"experiment": "tune"}, volatile=VOLATILE))
    if "main" in parts:
        methods = tuple(o["main_methods"]) + tuple(tuned[m] for m in o["tune_methods"]
                                                   if m in tuned)
        if "did-printed" in tuned:
            best = split_method(tuned["did-printed"])[1]
            methods += tuple(tuned_name(m, best["did_B"], best["did_M_prime"])
                             for m in o["at_printed_best"])
        methods = tuple(dict.fromkeys(methods))     # a method's own best may be printed's
        out.append(Experiment("xue1999-main", [{"part": "main", **base}], methods, trial,
                              runs, seed, params={"experiment": "main"}, volatile=VOLATILE))
    if "sweep" in parts:
        settings = [{"part": "sweep", "noise_scale": f, "clutter_mean": c, **common}
                    for c in o["clutter_grid"] for f in o["noise_grid"]]
        methods = tuple(o["sweep_methods"]) + tuple(tuned[m] for m in o["sweep_methods"]
                                                    if m in tuned)
        out.append(Experiment("xue1999-sweep", settings, methods, trial,
                              max(1, runs // o["sweep_divisor"]), seed,
                              params={"experiment": "sweep"}, volatile=VOLATILE))
    return out


def parameters(options: Mapping[str, Any] | None = None) -> dict[str, Any]:
    """Every parameter of a run; the paper gives none, so all are ours."""
    o = _options(options)
    sc = _scenario(o)
    tp = _tracker(o)
    return {
        "paper": {"given": "none: no region, noise, sampling, M, M', B, record update "
                           "rule or metric is stated"},
        "ours": {
            "scenario": sc.as_dict(),
            "tracker": tp.as_dict(),
            "c_new": tp.c_new(),
            "iff_mismatch_cost": tp.iff_mismatch_cost(sc.p_iff),
            "methods": {m: METHODS[m] for m in METHODS},
            "did_factors": ["x", "y", "vx", "vy", "IFF (categorical)"],
            "did_scale": "innovation standard deviation sqrt(S_ii) of each kinematic factor",
            "did_conflict": {"rules": list(CONFLICTS), "default": "q_final",
                             "text": "a track chosen by several reports of a scan keeps "
                                     "the one with the largest printed q (q_final) or "
                                     "stage-1 q (q_initial), the others are dropped; "
                                     "new_track: the others start new tracks"},
            "noise_grid": list(o["noise_grid"]), "clutter_grid": list(o["clutter_grid"]),
            "sweep_runs": f"runs // {o['sweep_divisor']}",
            "tuning": {"methods": list(o["tune_methods"]), "B": list(o["tune_B"]),
                       "at_printed_best": list(o["at_printed_best"]),
                       "M_prime": list(o["tune_M_prime"]),
                       "runs": f"runs // {o['tune_divisor']}",
                       "criterion": "largest mean correct_rate (ties: first in grid order)",
                       "seeds": "trial_seed(seed, tuning setting, trial); the tuning "
                                "setting (part 'tune') differs from the main one, so "
                                "its draws are independent of the reported runs"},
            "metrics": run_metrics.__doc__.split("\n\n", 1)[1].strip(),
            "ours": list(SCENARIO_OURS) + list(_TRACKER) + ["did_scale", "did_conflict",
                                                           "noise_grid", "clutter_grid",
                                                           "tuning", "metrics"],
        },
    }
