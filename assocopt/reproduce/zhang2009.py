"""Reproduction of paper 000 (Zhang et al. 2009): Figs. 1-5 and Table 1.

Four experiments, each with its own results store ``OUT/zhang2009-*.sqlite``:

``main``         P_c versus the noise factor f (P_d fixed) and versus P_d (f fixed)
                 for MM-TBM and MM-NCR decided by truncation (Experiment 1a, Figs.
                 1-2) and for MM-NCR decided by truncation (MD-ND), by our gated 2-D
                 assignment (MD-2DA) and by the plain rectangular assignment (tau = 0)
                 (Experiment 2, Figs. 4-5).  r_p = 1, r_a = 0.6 (the paper's values
                 for 1a; not given for 2, presumably the same).
``weights``      MM-WA versus MM-NCR over k = 1..10 with the paper's w and r
                 matrices, truncation decision (Experiment 1b, Fig. 3).
``table1``       decision time versus P_d: MD-ND, MD-2DA solved by the default 2-D
                 back end (scipy's linear_sum_assignment) and by HiGHS (ILP).
``sensitivity``  ours: MD-2DA's gate level alpha, tau = 0, and the alternative
                 readings of truncation (dendrogram ordering E0.10, same-sensor
                 pi = 0 E0.8) at three noise levels.

Every method of a trial decides on the same simulated run (paired comparison).
The metric is :func:`~assocopt.tracking.group_matching.correct_match_rate` (P_c, SPEC.md 5)
and ``all_correct`` (the run's relations entirely right); timings are volatile
metrics (seconds per decision, the matching measures excluded).
"""

from __future__ import annotations

import math
import time
from pathlib import Path
from typing import Any, Mapping, Sequence

import numpy as np

from ..io.writers import write_json_atomically
from ..api import choose_solver
from ..tracking.decide.md2da import gate_threshold, md_2da
from ..tracking.decide.truncation import TruncationOptions, md_nd
from ..experiments import Experiment, report_records, run_all, summarise
from ..tracking.group_matching import MeasureParams, correct_match_rate, matching_matrix, pair_components
from ..problem import AssignmentProblem
from ..tracking.scenarios.zhang2009 import OURS, PAPER, Zhang2009

__all__ = ["W", "R", "PAPER_TABLE1", "PAPER_CLAIMS", "DEFAULTS", "METHODS", "experiments",
           "trial", "parameters", "run", "render_tables", "make_figures"]

#: Experiment 1b (§5.1): MM-WA weights w(1,k), w(2,k) and MM-NCR reliabilities r(1,k), r(2,k).
W = ((0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.7, 0.8, 0.9, 1.0),
     (0.9, 0.8, 0.7, 0.6, 0.5, 0.4, 0.3, 0.2, 0.1, 0.0))
R = ((0.2, 0.4, 0.6, 0.8, 1.0, 1.0, 1.0, 1.0, 1.0, 1.0),
     (1.0, 1.0, 1.0, 1.0, 1.0, 0.8, 0.6, 0.4, 0.2, 0.0))

#: Table 1 (s per decision) versus P_d.
TABLE1_PD = (0.5, 0.6, 0.7, 0.8, 0.9, 1.0)
PAPER_TABLE1 = {"MD-2DA": (0.0046, 0.0187, 0.0635, 0.2404, 0.6176, 0.8699),
                "MD-ND": (8.7e-4, 9.78e-4, 0.0013, 0.0013, 0.0017, 0.0023)}

#: The paper's qualitative claims (figures are not in the seed).
PAPER_CLAIMS = {
    "1a": "§5.1 text: 'MM-TBM' better than 'MM-NCR' at every f and P_d, more so at high "
          "noise and low P_d -- labels almost certainly swapped (E0.7): the conclusion says "
          "the new rule matches better than Smets' rule",
    "1b": "MM-NCR better than MM-WA for every k, and its curve flatter",
    "2": "MD-ND better than MD-2DA at every f and P_d, most clearly at low noise and low P_d",
    "table1": "MD-2DA time grows from a few times to a few hundred times MD-ND's",
}

#: Parameters the paper does not give (ours) and run options.
DEFAULTS: dict[str, Any] = {
    "f_grid": (0.05, 0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.8, 1.0),
    "p_d_grid": TABLE1_PD,
    "f_fixed": 0.3,            # f of the P_d sweeps, of Exp. 1b and of Table 1
    "p_d_fixed": 0.8,          # P_d of the f sweeps and of Exp. 1b
    "r_p": 1.0,                # Exp. 2 (not given; Exp. 1a's values)
    "r_a": 0.6,
    "alpha": 0.01,             # MD-2DA gate level -> tau (decide.md2da.gate_threshold)
    "cost": "linear",          # MD-2DA cost reading
    "solver": "auto",          # MD-2DA back end
    "region": (100.0, 100.0),
    "type_assignment": "cover",
    "confusion_size": 2,
    "confusion_includes_true": True,
    "noise_reference": "per_run",
    "same_sensor": "formula",
    "ordering": "prim",
    "sensitivity_f": (0.1, 0.3, 0.6),
    "sensitivity_alpha": (0.001, 0.01, 0.05, 0.2),
}
_SCENARIO_KEYS = ("region", "type_assignment", "confusion_size", "confusion_includes_true",
                  "noise_reference")

#: Method name -> (measure, decision, options).  decision "nd" (truncation) or "2da".
METHODS: dict[str, tuple[str, str, dict[str, Any]]] = {
    "tbm+nd": ("tbm", "nd", {}),
    "ncr+nd": ("ncr", "nd", {}),
    "wa+nd": ("wa", "nd", {}),
    "ncr+2da": ("ncr", "2da", {}),
    "ncr+2da-rect": ("ncr", "2da", {"tau": 0.0}),
    "ncr+2da-highs": ("ncr", "2da", {"solver": "highs"}),
    "ncr+nd-dendrogram": ("ncr", "nd", {"ordering": "dendrogram"}),
    "ncr+nd-samezero": ("ncr", "nd", {"same_sensor": "zero"}),
}
for _a in DEFAULTS["sensitivity_alpha"]:
    METHODS[f"ncr+2da-a{_a:g}"] = ("ncr", "2da", {"alpha": _a})

LABELS = {"tbm+nd": "MM-TBM (truncation)", "ncr+nd": "MM-NCR / MD-ND",
          "wa+nd": "MM-WA (truncation)", "ncr+2da": "MD-2DA (gated, ours)",
          "ncr+2da-rect": "MD-2DA (tau = 0, rectangular)",
          "ncr+2da-highs": "MD-2DA via HiGHS", "ncr+nd-dendrogram": "MD-ND, dendrogram order",
          "ncr+nd-samezero": "MD-ND, same-sensor pi = 0"}
LABELS.update({f"ncr+2da-a{a:g}": f"MD-2DA, alpha = {a:g}" for a in DEFAULTS["sensitivity_alpha"]})

#: Methods as the paper defines them (MD-2DA's cost and threshold are ours, E0.12).
PAPER_METHODS = ("tbm+nd", "ncr+nd", "wa+nd")
MAIN_METHODS = ("tbm+nd", "ncr+nd", "ncr+2da", "ncr+2da-rect")
TABLE1_METHODS = ("ncr+nd", "ncr+2da", "ncr+2da-highs")
VOLATILE = ("t_decide", "t_backend")


# ------------------------------------------------------------------- trial
def trial(setting: Mapping[str, Any], methods: Sequence[str],
          seed: np.random.SeedSequence) -> dict[str, dict[str, float]]:
    """One simulated run decided by every method (module level: picklable)."""
    rng = np.random.default_rng(seed)
    sc = Zhang2009(f=float(setting["f"]), p_d=float(setting["p_d"]),
                   **{k: (tuple(v) if k == "region" else v)
                      for k, v in setting.items() if k in _SCENARIO_KEYS})
    draw = sc.simulate(rng)
    obs = draw.observations
    comps = pair_components(obs)
    out: dict[str, dict[str, float]] = {}
    for name in methods:
        measure, decision, opts = METHODS[name]
        o = {**{k: setting[k] for k in ("alpha", "cost", "solver", "same_sensor", "ordering")
                if k in setting}, **opts}
        params = _measure_params(setting, measure, o["same_sensor"])
        pi = matching_matrix(obs, params, components=comps)
        res: dict[str, float] = {}
        t0 = time.perf_counter()
        if decision == "nd":
            rel = md_nd(pi, obs.sensor, TruncationOptions(ordering=o["ordering"]))
            res["t_decide"] = time.perf_counter() - t0
        else:
            tau = o["tau"] if "tau" in o else gate_threshold(params, o["alpha"])
            r = md_2da(pi, obs.sensor, tau=tau, cost=o["cost"], solver=o["solver"])
            res["t_decide"] = time.perf_counter() - t0
            res["t_backend"] = r.solution.times.get("solve", math.nan)
            rel = r.relations
        res["correct_rate"] = correct_match_rate(rel, draw.truth)
        res["all_correct"] = float(rel == draw.truth)
        res["n_obs"] = float(obs.n)
        res["n_pairs_true"] = float(len(draw.truth.pairs))
        res["n_pairs_decided"] = float(len(rel.pairs))
        out[name] = res
    return out


def _measure_params(setting: Mapping[str, Any], measure: str, same_sensor: str) -> MeasureParams:
    if "k" in setting:                                  # Exp. 1b
        k = int(setting["k"]) - 1
        return MeasureParams(measure, r_p=R[0][k], r_a=R[1][k], w_p=W[0][k], w_a=W[1][k],
                             same_sensor=same_sensor)
    return MeasureParams(measure, r_p=float(setting["r_p"]), r_a=float(setting["r_a"]),
                         same_sensor=same_sensor)


# ------------------------------------------------------------- experiments
def _options(options: Mapping[str, Any] | None) -> dict[str, Any]:
    opts = {**DEFAULTS, **(options or {})}
    unknown = set(opts) - set(DEFAULTS)
    if unknown:
        raise ValueError(f"unknown zhang2009 option(s) {sorted(unknown)}; "
                         f"valid: {sorted(DEFAULTS)}")
    Zhang2009(f=opts["f_fixed"], p_d=opts["p_d_fixed"],
              **{k: opts[k] for k in _SCENARIO_KEYS})                     # validate
    MeasureParams("ncr", r_p=opts["r_p"], r_a=opts["r_a"], same_sensor=opts["same_sensor"])
    TruncationOptions(ordering=opts["ordering"])
    return opts


def experiments(runs: int, seed: int, options: Mapping[str, Any] | None = None,
                parts: Sequence[str] = ("main", "weights", "table1", "sensitivity")
                ) -> list[Experiment]:
    """The Experiments of the reproduction (``options`` override :data:`DEFAULTS`)."""
    o = _options(options)
    common = {k: (list(o[k]) if k == "region" else o[k])
              for k in _SCENARIO_KEYS + ("r_p", "r_a", "alpha", "cost", "solver",
                                         "same_sensor", "ordering")}
    out = []
    if "main" in parts:
        settings = ([{"sweep": "f", "f": f, "p_d": o["p_d_fixed"], **common}
                     for f in o["f_grid"]] +
                    [{"sweep": "p_d", "f": o["f_fixed"], "p_d": p, **common}
                     for p in o["p_d_grid"]])
        out.append(Experiment("zhang2009-main", settings, MAIN_METHODS, trial, runs, seed,
                              params={"experiment": "main"}, volatile=VOLATILE))
    if "weights" in parts:
        settings = [{"sweep": "k", "k": k, "f": o["f_fixed"], "p_d": o["p_d_fixed"], **common}
                    for k in range(1, 11)]
        out.append(Experiment("zhang2009-weights", settings, ("wa+nd", "ncr+nd"), trial, runs,
                              seed, params={"experiment": "weights"}, volatile=VOLATILE))
    if "table1" in parts:
        settings = [{"sweep": "table1", "f": o["f_fixed"], "p_d": p, **common}
                    for p in TABLE1_PD]
        out.append(Experiment("zhang2009-table1", settings, TABLE1_METHODS, trial, runs, seed,
                              params={"experiment": "table1"}, volatile=VOLATILE))
    if "sensitivity" in parts:
        settings = [{"sweep": "sensitivity", "f": f, "p_d": o["p_d_fixed"], **common}
                    for f in o["sensitivity_f"]]
        ms = (("ncr+nd", "ncr+nd-dendrogram", "ncr+nd-samezero", "ncr+2da-rect") +
              tuple(f"ncr+2da-a{a:g}" for a in o["sensitivity_alpha"]))
        for m in ms:
            if m not in METHODS:
                raise ValueError(f"sensitivity alpha {m} is not one of the defined methods "
                                 f"({DEFAULTS['sensitivity_alpha']})")
        out.append(Experiment("zhang2009-sensitivity", settings, ms, trial, runs, seed,
                              params={"experiment": "sensitivity"}, volatile=VOLATILE))
    return out


def parameters(options: Mapping[str, Any] | None = None) -> dict[str, Any]:
    """The parameters of a run: the paper's, ours (marked), and run options."""
    o = _options(options)
    ncr = MeasureParams("ncr", r_p=o["r_p"], r_a=o["r_a"])
    p = AssignmentProblem.two_d(np.zeros((1, 1)), 0.0, 0.0)
    solver = choose_solver(p) if o["solver"] == "auto" else o["solver"]
    return {
        "paper": {**PAPER, "r_p_exp1a": 1.0, "r_a_exp1a": 0.6, "w": [list(r) for r in W],
                  "r": [list(r) for r in R], "c": 2, "table1_p_d": list(TABLE1_PD)},
        "ours": {
            "f_grid": list(o["f_grid"]), "p_d_grid": list(o["p_d_grid"]),
            "f_fixed": o["f_fixed"], "p_d_fixed": o["p_d_fixed"],
            "exp1b_f_p_d": [o["f_fixed"], o["p_d_fixed"]],
            "table1_f": o["f_fixed"],
            "r_p_r_a_exp2": [o["r_p"], o["r_a"]],
            "region": list(o["region"]), "type_assignment": o["type_assignment"],
            "confusion_sets": f"type k with types k..k+{o['confusion_size'] - 1} (mod 6)"
                              if o["confusion_includes_true"] else
                              f"types k+1..k+{o['confusion_size']} (mod 6)",
            "confusion_size": o["confusion_size"],
            "confusion_includes_true": o["confusion_includes_true"],
            "noise_reference": o["noise_reference"] + " (E0.14)",
            "covariance_in_d2": "Sigma_1i + Sigma_2j, the true noise covariances (R0.1)",
            "same_sensor_pi": o["same_sensor"] + " (E0.8)",
            "ordering": o["ordering"] + " (E0.10; start = first sensor-1 observation, "
                                        "ties lowest index)",
            "truncation_readings": TruncationOptions(ordering=o["ordering"]).as_dict(),
            "md2da_cost": o["cost"] + ": cost -pi per pair, -tau/2 per unpaired observation",
            "md2da_threshold": f"tau = gate_threshold(alpha={o['alpha']}) = pi of a pair on "
                               f"the chi2(2) gate of level alpha with K = 0 "
                               f"(= {gate_threshold(ncr, o['alpha']):.6g} for MM-NCR, "
                               f"r_p={o['r_p']}, r_a={o['r_a']})",
            "mm_wa_attribute_conflict": "new conflict (4), as eq. (5) defines m^a (R0.2)",
            "metric": "correct_rate: correct relations / true relations per run, averaged; "
                      "all_correct: fraction of runs entirely right (SPEC.md 5)",
            "observation_order": "shuffled per sensor",
            "ours": list(OURS) + ["f_grid", "p_d_grid", "f_fixed", "p_d_fixed", "r_p_r_a_exp2",
                                  "md2da_cost", "md2da_threshold", "metric", "ordering",
                                  "same_sensor_pi", "mm_wa_attribute_conflict"],
        },
        "run": {"md2da_solver": solver, "table1_solvers": [solver, "highs"],
                "timing": "time.perf_counter around the decision only (pi excluded); "
                          "t_backend = the back end's own solve time"},
    }


# --------------------------------------------------------------------- run
def run(runs: int, workers: int, seed: int, out, *, progress: bool = False,
        executor: Any = None, options: Mapping[str, Any] | None = None,
        parts: Sequence[str] = ("main", "weights", "table1", "sensitivity"),
        echo=print) -> dict[str, Any]:
    """Run (or resume) the reproduction into ``out`` and write its report files.

    Writes ``out/summary.json``, ``out/tables.md``, PNG figures (when matplotlib is
    installed) and the stores ``out/zhang2009-*.sqlite``; prints the tables with
    ``echo``.  Returns the summary dict.
    """
    out = Path(out)
    exps = experiments(runs, seed, options, parts)
    timing = run_all(exps, out, workers=workers, executor=executor, progress=progress)
    records: list[dict[str, Any]] = []
    for exp in exps:
        rows = summarise(out / f"{exp.name}.sqlite", exp, include_volatile=True)
        for r in report_records(rows, exp, ("sweep", "f", "p_d", "k")):
            r["method_is_ours"] = r["method"] not in PAPER_METHODS
            records.append(r)
    paired = []
    for exp in exps:
        paired += paired_differences(out / f"{exp.name}.sqlite", exp)
    summary = {
        "paper": "zhang2009",
        "title": "Group member matching with position + attribute belief functions "
                 "(Zhang et al. 2009, SPEC.md paper 000)",
        "runs": runs, "seed": seed, "workers": workers,
        "methods": {m: {"measure": METHODS[m][0], "decision": METHODS[m][1],
                        "options": METHODS[m][2], "label": LABELS.get(m, m)}
                    for m in sorted({r["method"] for r in records})},
        "parameters": parameters(options),
        "paper_values": {"table1": {k: list(v) for k, v in PAPER_TABLE1.items()},
                         "table1_p_d": list(TABLE1_PD), "claims": PAPER_CLAIMS},
        "records": records,
        "paired": paired,
        "timing": timing,
    }
    text = render_tables(summary)
    summary["figures"] = make_figures(summary, out)
    write_json_atomically(out / "summary.json", summary, indent=1)
    (out / "tables.md").write_text(text)
    echo(text)
    return summary


#: Paired comparisons (same simulated runs): (experiment, method A, method B).
PAIRS = (("main", "ncr+nd", "tbm+nd"), ("weights", "ncr+nd", "wa+nd"),
         ("main", "ncr+2da", "ncr+nd"), ("main", "ncr+2da-rect", "ncr+nd"))


def paired_differences(store: Path, exp: Experiment,
                       metric: str = "correct_rate") -> list[dict[str, Any]]:
    """Mean and standard error of the per-run difference A - B of ``metric``.

    Both methods decide on the same simulated runs, so the paired standard error is
    much smaller than the two curves' own.
    """
    from ..experiments import ResultStore, setting_key
    part = exp.params["experiment"]
    wanted = [(a, b) for e, a, b in PAIRS if e == part and {a, b} <= set(exp.methods)]
    if not wanted:
        return []
    keys = {setting_key(s): s for s in exp.settings}
    vals: dict[tuple[str, str], dict[int, float]] = {}
    with ResultStore(store) as st:
        for s, m, t, metrics in st.rows():
            if s in keys and t < exp.runs and metrics.get(metric) is not None:
                vals.setdefault((s, m), {})[t] = metrics[metric]
    out = []
    for k, setting in keys.items():
        for a, b in wanted:
            va, vb = vals.get((k, a), {}), vals.get((k, b), {})
            common = sorted(set(va) & set(vb))
            if len(common) < 2:
                continue
            d = np.array([va[t] - vb[t] for t in common])
            out.append({"experiment": part, "setting": {x: setting[x] for x in
                                                       ("sweep", "f", "p_d", "k") if x in setting},
                        "method": f"{a} - {b}", "metric": metric, "value": float(d.mean()),
                        "stderr": float(d.std(ddof=1) / math.sqrt(len(d))), "runs": len(d)})
    return out


def _paired_table(summary) -> list[str]:
    rows = summary.get("paired", [])
    if not rows:
        return []
    lines = ["### Paired differences of P_c (same simulated runs; mean ± standard error)", "",
             "| experiment | sweep | f | P_d | k | A - B | mean | s.e. |",
             "|---|---|---|---|---|---|---|---|"]
    for r in rows:
        s = r["setting"]
        lines.append(f"| {r['experiment']} | {s['sweep']} | {s['f']:g} | {s['p_d']:g} | "
                     f"{s.get('k', '')} | {r['method']} | {r['value']:+.4f} | {r['stderr']:.4f} |")
    return lines + [""]


def _lookup(records, experiment: str, metric: str, sweep: str | None = None):
    """{(method, x): (value, runs, stderr)} with x = f, p_d or k depending on the sweep."""
    out = {}
    for r in records:
        s = r["setting"]
        if r["experiment"] != experiment or r["metric"] != metric:
            continue
        if sweep is not None and s.get("sweep") != sweep:
            continue
        x = {"f": s.get("f"), "p_d": s.get("p_d"), "k": s.get("k"),
             "table1": s.get("p_d"), "sensitivity": s.get("f")}[s["sweep"]]
        out[(r["method"], x)] = (r["value"], r["runs"], r.get("stderr"))
    return out


def _f(v, digits=3) -> str:
    return "—" if v is None or (isinstance(v, float) and math.isnan(v)) else f"{v:.{digits}f}"


def _sweep_table(recs, experiment, sweep, methods, metric, xname, title) -> list[str]:
    tab = _lookup(recs, experiment, metric, sweep)
    if not tab:
        return []
    xs = sorted({x for (_, x) in tab})
    runs = max(v[1] for v in tab.values())
    se = max((v[2] or 0.0) for v in tab.values())
    lines = [f"### {title} ({runs} runs per point; largest standard error {se:.3f})", "",
             f"| {xname} | " + " | ".join(LABELS.get(m, m) for m in methods) + " |",
             "|---" * (len(methods) + 1) + "|"]
    for x in xs:
        lines.append(f"| {x:g} | " + " | ".join(_f(tab.get((m, x), (None,))[0])
                                               for m in methods) + " |")
    return lines + [""]


def render_tables(summary: Mapping[str, Any]) -> str:
    """Markdown tables: ours, with the paper's Table 1 beside ours."""
    recs = summary["records"]
    L: list[str] = []
    L += _sweep_table(recs, "main", "f", ("tbm+nd", "ncr+nd"), "correct_rate", "f",
                      "Exp. 1a / Fig. 1 — P_c versus f (P_d fixed)")
    L += _sweep_table(recs, "main", "p_d", ("tbm+nd", "ncr+nd"), "correct_rate", "P_d",
                      "Exp. 1a / Fig. 2 — P_c versus P_d (f fixed)")
    L += _weights_table(recs)
    L += _sweep_table(recs, "main", "f", ("ncr+nd", "ncr+2da", "ncr+2da-rect"),
                      "correct_rate", "f", "Exp. 2 / Fig. 4 — P_c versus f (P_d fixed)")
    L += _sweep_table(recs, "main", "p_d", ("ncr+nd", "ncr+2da", "ncr+2da-rect"),
                      "correct_rate", "P_d", "Exp. 2 / Fig. 5 — P_c versus P_d (f fixed)")
    L += _sweep_table(recs, "main", "f", MAIN_METHODS, "all_correct", "f",
                      "Fraction of runs entirely correct versus f")
    L += _table1(summary)
    L += _paired_table(summary)
    if any(r["experiment"] == "sensitivity" for r in recs):
        ms = [m for m in summary["methods"] if any(
            r["experiment"] == "sensitivity" and r["method"] == m for r in recs)]
        ms = sorted(ms, key=lambda m: (("2da" in m), m))
        L += _sweep_table(recs, "sensitivity", "sensitivity", ms, "correct_rate", "f",
                          "Ours — sensitivity of MD-2DA to alpha (tau) and of MD-ND to "
                          "its readings (P_d fixed)")
    return "\n".join(L)


def _weights_table(recs) -> list[str]:
    tab = _lookup(recs, "weights", "correct_rate", "k")
    if not tab:
        return []
    runs = max(v[1] for v in tab.values())
    lines = [f"### Exp. 1b / Fig. 3 — P_c versus k ({runs} runs per point)", "",
             "| k | w_p | w_a | r_p | r_a | MM-WA | MM-NCR |", "|---|---|---|---|---|---|---|"]
    for k in range(1, 11):
        if ("wa+nd", k) not in tab:
            continue
        lines.append(f"| {k} | {W[0][k-1]:g} | {W[1][k-1]:g} | {R[0][k-1]:g} | {R[1][k-1]:g} | "
                     f"{_f(tab[('wa+nd', k)][0])} | {_f(tab[('ncr+nd', k)][0])} |")
    return lines + [""]


def _table1(summary) -> list[str]:
    recs = summary["records"]
    t = _lookup(recs, "table1", "t_decide", "table1")
    b = _lookup(recs, "table1", "t_backend", "table1")
    if not t:
        return []
    runs = max(v[1] for v in t.values())
    solver = summary["parameters"]["run"]["md2da_solver"]
    cols = " | ".join(f"{p:g}" for p in TABLE1_PD)
    lines = [f"### Table 1 — decision time (s) versus P_d (f = "
             f"{summary['parameters']['ours']['table1_f']}; ours: mean of {runs} runs)", "",
             f"| method | {cols} |", "|---" * (len(TABLE1_PD) + 1) + "|"]
    for k, v in PAPER_TABLE1.items():
        lines.append(f"| paper: {k} | " + " | ".join(f"{x:.3g}" for x in v) + " |")
    lines.append("| paper: ratio 2DA/ND | " + " | ".join(
        f"{a / n:.1f}" for a, n in zip(PAPER_TABLE1["MD-2DA"], PAPER_TABLE1["MD-ND"])) + " |")
    rows = [("ours: MD-ND (truncation, Python)", t, "ncr+nd"),
            (f"ours: MD-2DA via solve(), {solver}", t, "ncr+2da"),
            (f"ours: MD-2DA, {solver} back end only", b, "ncr+2da"),
            ("ours: MD-2DA via solve(), highs (ILP)", t, "ncr+2da-highs"),
            ("ours: MD-2DA, highs back end only", b, "ncr+2da-highs")]
    for label, tab, m in rows:
        lines.append(f"| {label} | " + " | ".join(
            f"{tab[(m, p)][0]:.3g}" if (m, p) in tab else "—" for p in TABLE1_PD) + " |")
    lines.append(f"| ours: ratio 2DA ({solver}, solve())/ND | " + " | ".join(
        f"{t[('ncr+2da', p)][0] / t[('ncr+nd', p)][0]:.1f}"
        if ("ncr+2da", p) in t and ("ncr+nd", p) in t else "—" for p in TABLE1_PD) + " |")
    pc = _lookup(recs, "table1", "correct_rate", "table1")
    for m in TABLE1_METHODS:
        lines.append(f"| ours: P_c {LABELS.get(m, m)} | " + " | ".join(
            _f(pc.get((m, p), (None,))[0]) for p in TABLE1_PD) + " |")
    return lines + [""]


# ----------------------------------------------------------------- figures
def make_figures(summary: Mapping[str, Any], out) -> list[str]:
    """Figs. 1-5, Table 1 and the sensitivity study as PNG; [] without matplotlib."""
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        return []
    out = Path(out)
    recs = summary["records"]
    made: list[str] = []

    def curve(fname, experiment, sweep, methods, xlabel, title, metric="correct_rate"):
        tab = _lookup(recs, experiment, metric, sweep)
        if not tab:
            return
        fig, ax = plt.subplots(figsize=(6, 4.2))
        for m in methods:
            xs = sorted(x for (mm, x) in tab if mm == m)
            ys = np.array([tab[(m, x)][0] for x in xs])
            se = np.array([tab[(m, x)][2] or 0.0 for x in xs])
            ax.errorbar(xs, ys, yerr=1.96 * se, marker="o", ms=3, capsize=2,
                        label=LABELS.get(m, m))
        runs = max(v[1] for v in tab.values())
        ax.set_xlabel(xlabel)
        ax.set_ylabel("correct matching rate P_c" if metric == "correct_rate" else metric)
        ax.set_title(f"{title}\n(ours, {runs} runs per point, 95% CI)", fontsize=10)
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8)
        fig.tight_layout()
        fig.savefig(out / fname, dpi=110)
        plt.close(fig)
        made.append(fname)

    curve("fig1_pc_vs_f_measures.png", "main", "f", ("tbm+nd", "ncr+nd"), "noise factor f",
          "Fig. 1: MM-TBM vs MM-NCR (truncation)")
    curve("fig2_pc_vs_pd_measures.png", "main", "p_d", ("tbm+nd", "ncr+nd"),
          "detection probability P_d", "Fig. 2: MM-TBM vs MM-NCR (truncation)")
    curve("fig3_pc_vs_k.png", "weights", "k", ("wa+nd", "ncr+nd"), "k (w(:,k) for MM-WA, "
          "r(:,k) for MM-NCR)", "Fig. 3: MM-WA vs MM-NCR (truncation)")
    curve("fig4_pc_vs_f_decisions.png", "main", "f", ("ncr+nd", "ncr+2da", "ncr+2da-rect"),
          "noise factor f", "Fig. 4: MD-ND vs MD-2DA (MM-NCR)")
    curve("fig5_pc_vs_pd_decisions.png", "main", "p_d", ("ncr+nd", "ncr+2da", "ncr+2da-rect"),
          "detection probability P_d", "Fig. 5: MD-ND vs MD-2DA (MM-NCR)")
    sens = sorted({r["method"] for r in recs if r["experiment"] == "sensitivity"},
                  key=lambda m: (("2da" in m), m))
    curve("sensitivity.png", "sensitivity", "sensitivity", sens, "noise factor f",
          "Ours: MD-2DA gate level and MD-ND readings")

    t = _lookup(recs, "table1", "t_decide", "table1")
    if t:
        fig, ax = plt.subplots(figsize=(6, 4.2))
        ax.semilogy(TABLE1_PD, PAPER_TABLE1["MD-2DA"], "k--s", label="paper: MD-2DA")
        ax.semilogy(TABLE1_PD, PAPER_TABLE1["MD-ND"], "k--o", label="paper: MD-ND")
        solver = summary["parameters"]["run"]["md2da_solver"]
        for m, lab in (("ncr+nd", "ours: MD-ND"), ("ncr+2da", f"ours: MD-2DA ({solver})"),
                       ("ncr+2da-highs", "ours: MD-2DA (highs)")):
            xs = [p for p in TABLE1_PD if (m, p) in t]
            ax.semilogy(xs, [t[(m, p)][0] for p in xs], "-o", ms=3, label=lab)
        ax.set_xlabel("detection probability P_d")
        ax.set_ylabel("seconds per decision")
        ax.set_title("Table 1: decision time (paper's hardware not given)", fontsize=10)
        ax.grid(alpha=0.3, which="both")
        ax.legend(fontsize=8)
        fig.tight_layout()
        fig.savefig(out / "table1_time.png", dpi=110)
        plt.close(fig)
        made.append("table1_time.png")
    return made
