"""Paper 003's experiments: the options, the trial and the Experiment grid (the two
experiments, ``main`` and ``sweep``, are described in :mod:`assocopt.reproduce.xue1999`).
"""

from __future__ import annotations

import time
from dataclasses import fields
from typing import Any, Mapping, Sequence

import numpy as np

from ...experiments import Experiment
from ...tracking.scenarios.xue1999 import OURS as SCENARIO_OURS, Xue1999
from ...tracking.scenarios.xue1999_tracker import (METHODS, TrackerParams, run_metrics,
                                                  run_tracker)

__all__ = ["DEFAULTS", "PAPER_CLAIMS", "LABELS", "METRICS", "VOLATILE", "experiments",
           "trial", "parameters"]

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
    "sweep_methods": ("did", "did-q0", "gnn", "nn"),
    "noise_grid": (0.5, 1.0, 2.0, 3.0),
    "clutter_grid": (0.0, 10.0, 30.0),
    "sweep_divisor": 5,
    "example_seed": 3,
}

LABELS = {"did": "DID (as printed)", "did-literal": "DID, literal selection",
          "did-origin": "DID, origin-dependent error", "did-q0": "DID, q from stage 1 (ours)",
          "gnn": "GNN (2-D assignment)", "nn": "NN"}
METRICS = ("correct_rate", "swaps", "false_tracks", "held_at_end", "stage2_rate",
           "nonconverged_rate")
VOLATILE = ("t_run",)


def _options(options: Mapping[str, Any] | None) -> dict[str, Any]:
    opts = {**DEFAULTS, **(options or {})}
    unknown = set(opts) - set(DEFAULTS)
    if unknown:
        raise ValueError(f"unknown xue1999 option(s) {sorted(unknown)}; valid: {sorted(DEFAULTS)}")
    for m in tuple(opts["main_methods"]) + tuple(opts["sweep_methods"]):
        if m not in METHODS:
            raise ValueError(f"unknown xue1999 method {m!r}; valid: {sorted(METHODS)}")
    if not isinstance(opts["sweep_divisor"], int) or opts["sweep_divisor"] < 1:
        raise ValueError("sweep_divisor must be a positive integer")
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
                parts: Sequence[str] = ("main", "sweep")) -> list[Experiment]:
    """The Experiments of the reproduction (``options`` override :data:`DEFAULTS`)."""
    o = _options(options)
    common = {k: o[k] for k in _SCENARIO + _TRACKER}
    out = []
    if "main" in parts:
        s = {"part": "main", "noise_scale": o["noise_scale"], "clutter_mean": o["clutter_mean"],
             **common}
        out.append(Experiment("xue1999-main", [s], tuple(o["main_methods"]), trial, runs,
                              seed, params={"experiment": "main"}, volatile=VOLATILE))
    if "sweep" in parts:
        settings = [{"part": "sweep", "noise_scale": f, "clutter_mean": c, **common}
                    for c in o["clutter_grid"] for f in o["noise_grid"]]
        out.append(Experiment("xue1999-sweep", settings, tuple(o["sweep_methods"]), trial,
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
            "did_conflict": "a track chosen by several reports keeps the one with the "
                            "largest q; the others are dropped",
            "noise_grid": list(o["noise_grid"]), "clutter_grid": list(o["clutter_grid"]),
            "sweep_runs": f"runs // {o['sweep_divisor']}",
            "metrics": run_metrics.__doc__.split("\n\n", 1)[1].strip(),
            "ours": list(SCENARIO_OURS) + list(_TRACKER) + ["did_scale", "did_conflict",
                                                           "noise_grid", "clutter_grid",
                                                           "metrics"],
        },
    }
