"""Reproduction of paper 003 (Xue et al. 1999): DID against GNN and nearest neighbour.

The paper shows four crossing targets (Figs. 2-3) and claims correct associations
despite many crossings and strong noise; it gives no parameter and no number.  Two
experiments, each with its own store ``OUT/xue1999-*.sqlite``:

``main``   the base scene (noise scale 1, clutter mean ``clutter_mean``): every method
           of :data:`~assocopt.tracking.scenarios.xue1999_tracker.METHODS`, per-scan
           correct association rate, track swaps, false tracks, targets held at the
           end, and DID's stage-2 and non-convergence rates.
``sweep``  noise scale x clutter mean grid (``noise_grid`` x ``clutter_grid``) with
           ``sweep_methods``, ``runs // sweep_divisor`` runs per point.

Every method of a trial tracks the same simulated run (paired comparison).  All
parameters are ours and recorded in ``summary.json``; the page is
``docs/papers/xue1999.md``.
"""

from __future__ import annotations

import json
import os
import time
from dataclasses import fields
from pathlib import Path
from typing import Any, Mapping, Sequence

import numpy as np

from ..experiments import Experiment, report_records, run_all, summarise
from ..tracking.scenarios.xue1999 import OURS as SCENARIO_OURS, Xue1999
from ..tracking.scenarios.xue1999_tracker import (METHODS, TrackerParams, run_metrics,
                                                  run_tracker)

__all__ = ["DEFAULTS", "PAPER_CLAIMS", "experiments", "trial", "parameters", "run",
           "render_tables", "LABELS"]

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


def run(runs: int, workers: int, seed: int, out, *, progress: bool = False,
        executor: Any = None, options: Mapping[str, Any] | None = None,
        parts: Sequence[str] = ("main", "sweep"), echo=print) -> dict[str, Any]:
    """Run (or resume) the reproduction into ``out`` and write its report files.

    Writes ``out/summary.json``, ``out/tables.md``, PNG figures (with matplotlib) and
    the stores ``out/xue1999-*.sqlite``; prints the tables with ``echo``.
    """
    from .xue1999_figures import make_figures

    out = Path(out)
    t0 = time.perf_counter()
    exps = experiments(runs, seed, options, parts)
    timing = run_all(exps, out, workers=workers, executor=executor, progress=progress)
    records: list[dict[str, Any]] = []
    for exp in exps:
        rows = summarise(out / f"{exp.name}.sqlite", exp, include_volatile=True)
        for r in report_records(rows, exp, ("part", "noise_scale", "clutter_mean")):
            if exp.params["experiment"] == "sweep" and r["metric"].startswith("car_k"):
                continue                        # per-scan curves: base scene only
            r["method_is_ours"] = True
            records.append(r)
    o = _options(options)
    summary = {
        "paper": "xue1999",
        "title": "Target data association by distributed inference decision (Xue et al. 1999)",
        "runs": runs, "sweep_runs": max(1, runs // o["sweep_divisor"]), "seed": seed,
        "workers": workers,
        "methods": {m: {**METHODS[m], "label": LABELS[m]}
                    for m in sorted({r["method"] for r in records})},
        "parameters": parameters(options),
        "paper_values": {"claims": PAPER_CLAIMS},
        "records": records,
        "timing": timing,
    }
    summary["figures"] = make_figures(summary, out, o)
    summary["wall_s"] = time.perf_counter() - t0
    text = render_tables(summary)
    _write_json_atomic(out / "summary.json", summary)
    (out / "tables.md").write_text(text)
    echo(text)
    return summary


def _write_json_atomic(path: Path, obj: Any) -> None:
    tmp = path.with_suffix(path.suffix + ".tmp")
    tmp.write_text(json.dumps(obj, indent=1, default=_json_default))
    os.replace(tmp, path)


def _json_default(o: Any) -> Any:
    if isinstance(o, (np.floating, np.integer)):
        return o.item()
    if isinstance(o, tuple):
        return list(o)
    raise TypeError(f"not JSON-serialisable: {type(o).__name__}")


# ------------------------------------------------------------------ tables
def lookup(records, part: str, metric: str) -> dict[tuple, tuple]:
    """{(method, noise_scale, clutter_mean): (value, runs, stderr)}."""
    return {(r["method"], r["setting"]["noise_scale"], r["setting"]["clutter_mean"]):
            (r["value"], r["runs"], r.get("stderr"))
            for r in records if r["experiment"] == part and r["metric"] == metric}


def _ci(v) -> str:
    if v is None:
        return "—"
    value, _, se = v
    return f"{value:.3f} ± {1.96 * se:.3f}" if se is not None else f"{value:.3f}"


def render_tables(summary: Mapping[str, Any]) -> str:
    """Markdown tables of the summary (the page embeds them verbatim)."""
    recs = summary["records"]
    L: list[str] = []
    main = {m: lookup(recs, "main", m) for m in METRICS}
    if main["correct_rate"]:
        (_, f, c) = next(iter(main["correct_rate"]))
        runs = max(v[1] for v in main["correct_rate"].values())
        methods = [m for m in METHODS if (m, f, c) in main["correct_rate"]]
        L += [f"### Base scene (noise scale {f:g}, clutter mean {c:g} per scan; {runs} runs; "
              "mean ± 95 % half-width)", "",
              "| method | correct association rate | track swaps | false tracks | "
              "targets held at end | stage-2 rate | non-converged rate |",
              "|---|---|---|---|---|---|---|"]
        for m in methods:
            L.append(f"| {LABELS[m]} | " + " | ".join(_ci(main[k].get((m, f, c)))
                                                       for k in METRICS) + " |")
        L.append("")
    for metric, title in (("correct_rate", "correct association rate"),
                          ("swaps", "track swaps per run"),
                          ("false_tracks", "false tracks per run")):
        tab = lookup(recs, "sweep", metric)
        if not tab:
            continue
        runs = max(v[1] for v in tab.values())
        methods = [m for m in METHODS if any(k[0] == m for k in tab)]
        cells = sorted({(k[2], k[1]) for k in tab})
        L += [f"### Sweep: {title} ({runs} runs per point; mean ± 95 % half-width)", "",
              "| clutter mean | noise scale | " + " | ".join(LABELS[m] for m in methods) + " |",
              "|---|---|" + "---|" * len(methods)]
        for c, f in cells:
            L.append(f"| {c:g} | {f:g} | " + " | ".join(_ci(tab.get((m, f, c)))
                                                       for m in methods) + " |")
        L.append("")
    if "wall_s" in summary:
        L.append(f"Wall time of this run: {summary['wall_s']:.0f} s "
                 f"({summary['workers']} worker(s)).")
    return "\n".join(L)


def render_parameters(summary: Mapping[str, Any]) -> str:
    """The parameter table of the page (every value ours; the paper gives none)."""
    o = summary["parameters"]["ours"]
    sc, tp = o["scenario"], o["tracker"]
    rows = [
        ("scans, period", f"{sc['n_scans']} scans, T = {sc['T']:g} s"),
        ("region", f"{sc['region'][0] / 1e3:g} km x {sc['region'][1] / 1e3:g} km"),
        ("targets (start m, velocity m/s, IFF)", "; ".join(
            f"({p[0]:g}, {p[1]:g}), ({v[0]:g}, {v[1]:g}), {'friend' if i else 'foe'}"
            for p, v, i in zip(sc["starts"], sc["velocities"], sc["iff"]))),
        ("detection probability", f"{sc['p_d']:g}"),
        ("report noise (noise scale 1)", f"sigma_p = {sc['sigma_p']:g} m, "
                                         f"sigma_v = {sc['sigma_v']:g} m/s"),
        ("IFF reported wrong", f"p_iff = {sc['p_iff']:g}"),
        ("clutter", f"Poisson, mean {sc['clutter_mean']:g} per scan (base), uniform in the "
                    f"region, velocity uniform in ±{sc['clutter_v']:g} m/s, IFF random"),
        ("tracker", f"Kalman CV, q = {tp['q']:g} m²/s³; confirm after {tp['confirm_hits']} "
                    f"hits in a row, tentative deleted at 1 miss, confirmed after "
                    f"{tp['delete_misses']}"),
        ("new-target cost c_new", f"chi-square(4) at 1 - {tp['gate_alpha']:g} = "
                                  f"{o['c_new']:.3f}"),
        ("IFF mismatch cost", f"2 ln((1 - p_iff) / p_iff) = {o['iff_mismatch_cost']:.3f}"),
        ("DID M, M', B, iteration cap", f"M = {tp['did_M']:g}, M' = {tp['did_M_prime']:g}, "
                                        f"B = {tp['did_B']:g} (all pairs), "
                                        f"{tp['did_max_iter']} updates per record"),
        ("DID origin-dependent reading", f"M = {tp['did_origin_M']:g}, floors "
                                         f"{tp['did_origin_floor']} (x, y, vx, vy, IFF)"),
        ("sweep", f"noise scale {o['noise_grid']} x clutter mean {o['clutter_grid']}, "
                  f"{summary['sweep_runs']} runs per point"),
        ("2-D assignment back end", f"{tp['solver']} (through assocopt.solve)"),
    ]
    return "\n".join(["| parameter (paper: not given) | ours |", "|---|---|"] +
                     [f"| {a} | {b} |" for a, b in rows])


def render_headline(summary: Mapping[str, Any]) -> str:
    """The key numbers quoted in the page's text."""
    main = lookup(summary["records"], "main", "correct_rate")
    swaps = lookup(summary["records"], "main", "swaps")
    false = lookup(summary["records"], "main", "false_tracks")
    L = []
    for m in METHODS:
        k = next((k for k in main if k[0] == m), None)
        if k is not None:
            L.append(f"- {LABELS[m]}: correct association rate {_ci(main[k])}, "
                     f"{swaps[k][0]:.2f} track swaps and {false[k][0]:.2f} false tracks "
                     "per run")
    t = summary["timing"]
    L.append(f"- wall time of the full run: {summary['wall_s']:.0f} s with "
             f"{summary['workers']} worker processes (main {t['xue1999-main']['wall_s']:.0f} s "
             f"for {summary['runs']} runs, sweep {t['xue1999-sweep']['wall_s']:.0f} s)"
             if {"xue1999-main", "xue1999-sweep"} <= set(t) else
             f"- wall time: {summary['wall_s']:.0f} s")
    return "\n".join(L)
