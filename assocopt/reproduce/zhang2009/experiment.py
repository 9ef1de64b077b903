"""Paper 000's experiments: methods, grids, printed values, the trial function, the
experiment definitions and the paired comparisons (see :mod:`assocopt.reproduce.zhang2009`).
"""


from __future__ import annotations

import math
import time
from pathlib import Path
from typing import Any, Mapping, Sequence

import numpy as np

from ...solving.api import choose_solver, solve
from ...experiments import Experiment
from ...problems.problem import AssignmentProblem
from ...model.solution import Status
from ...tracking.decide.md2da import gate_threshold, md_2da, md_2da_problem
from ...tracking.decide.truncation import TruncationOptions, md_nd
from ...tracking.belief.group_matching import (MeasureParams, Relations, correct_match_rate,
                                        matching_matrix, pair_components)
from ...tracking.scenarios.zhang2009 import OURS, PAPER, Zhang2009

__all__ = ["W", "R", "PAPER_TABLE1", "PAPER_CLAIMS", "DEFAULTS", "METHODS", "PARTS", "experiments",
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
          "noise and low P_d -- labels almost certainly swapped: the conclusion says "
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
    "covariance_scale": 1.0,   # covariance in d^2 = scale x the true noise covariance
    "enum_runs": 20,           # runs per P_d of the enumerating MD-2DA (Table 1)
    "enum_max_nodes": 2_000_000,   # its search-node limit (then: stopped, reported)
}
_SCENARIO_KEYS = ("region", "type_assignment", "confusion_size", "confusion_includes_true",
                  "noise_reference", "covariance_scale")

#: Method name -> (measure, decision, options).  decision "nd" (truncation) or "2da".
METHODS: dict[str, tuple[str, str, dict[str, Any]]] = {
    "tbm+nd": ("tbm", "nd", {}),
    "ncr+nd": ("ncr", "nd", {}),
    "wa+nd": ("wa", "nd", {}),
    "ncr+2da": ("ncr", "2da", {}),
    "ncr+2da-rect": ("ncr", "2da", {"tau": 0.0}),
    "ncr+2da-highs": ("ncr", "2da", {"solver": "highs"}),
    "ncr+2da-enum": ("ncr", "2da", {"solver": "bruteforce"}),
    "ncr+nd-dendrogram": ("ncr", "nd", {"ordering": "dendrogram"}),
    "ncr+nd-samezero": ("ncr", "nd", {"same_sensor": "zero"}),
}
for _a in DEFAULTS["sensitivity_alpha"]:
    METHODS[f"ncr+2da-a{_a:g}"] = ("ncr", "2da", {"alpha": _a})

LABELS = {"tbm+nd": "MM-TBM (truncation)", "ncr+nd": "MM-NCR / MD-ND",
          "wa+nd": "MM-WA (truncation)", "ncr+2da": "MD-2DA (gated, ours)",
          "ncr+2da-rect": "MD-2DA (tau = 0, rectangular)",
          "ncr+2da-highs": "MD-2DA via HiGHS",
          "ncr+2da-enum": "MD-2DA by enumeration (brute force)",
          "ncr+nd-dendrogram": "MD-ND, dendrogram order",
          "ncr+nd-samezero": "MD-ND, same-sensor pi = 0"}
LABELS.update({f"ncr+2da-a{a:g}": f"MD-2DA, alpha = {a:g}" for a in DEFAULTS["sensitivity_alpha"]})

#: Methods as the paper defines them (MD-2DA's cost and threshold are ours).
PAPER_METHODS = ("tbm+nd", "ncr+nd", "wa+nd")
MAIN_METHODS = ("tbm+nd", "ncr+nd", "ncr+2da", "ncr+2da-rect")
TABLE1_METHODS = ("ncr+nd", "ncr+2da", "ncr+2da-highs")
VOLATILE = ("t_decide", "t_backend", "t_decide_finished")


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
        elif o["solver"] == "bruteforce":
            res.update(_enumerate(pi, obs.sensor, params, o, int(setting["enum_max_nodes"]),
                                  draw.truth))
            res["n_obs"] = float(obs.n)
            out[name] = res
            continue
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


def _enumerate(pi, sensor, params: MeasureParams, o: Mapping[str, Any], max_nodes: int,
               truth) -> dict[str, float | None]:
    """MD-2DA by exhaustive enumeration of every feasible matching (the brute-force
    back end), stopped after ``max_nodes`` search nodes.  A stopped run reports
    ``stopped = 1``, its time up to the stop and no P_c (its answer is not proven)."""
    tau = o["tau"] if "tau" in o else gate_threshold(params, o["alpha"])
    problem, rows, cols = md_2da_problem(pi, sensor, tau, o["cost"])
    t0 = time.perf_counter()
    sol = solve(problem, "bruteforce", max_nodes=max_nodes)
    dt = time.perf_counter() - t0
    stopped = sol.status is not Status.OPTIMAL
    res: dict[str, float | None] = {"t_decide": dt, "stopped": float(stopped),
                                    "t_decide_finished": None if stopped else dt,
                                    "correct_rate": None, "all_correct": None}
    if not stopped:
        r, c = sol.assignment()
        matched = set(rows[r].tolist()) | set(cols[c].tolist())
        clusters = [(int(rows[i]), int(cols[j])) for i, j in zip(r, c)]
        clusters += [(i,) for i in range(len(sensor)) if i not in matched]
        rel = Relations.from_clusters(clusters, np.asarray(sensor))
        res["correct_rate"] = correct_match_rate(rel, truth)
        res["all_correct"] = float(rel == truth)
        res["n_feasible"] = float(sol.info.get("solutions", math.nan))
    return res


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
    for k in ("enum_runs", "enum_max_nodes"):
        if not isinstance(opts[k], int) or isinstance(opts[k], bool) or opts[k] < 1:
            raise ValueError(f"{k} must be a positive integer, got {opts[k]!r}")
    return opts


#: The parts of the reproduction, one Experiment each, in the order they run.
PARTS = ("main", "weights", "table1", "table1-enum", "sensitivity")


def experiments(runs: int, seed: int, options: Mapping[str, Any] | None = None,
                parts: Sequence[str] = PARTS) -> list[Experiment]:
    """The Experiments of the reproduction (``options`` override :data:`DEFAULTS`)."""
    unknown = set(parts) - set(PARTS)
    if unknown:
        raise ValueError(f"unknown zhang2009 part(s) {sorted(unknown)}; valid: {list(PARTS)}")
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
    if "table1-enum" in parts:
        settings = [{"sweep": "table1", "f": o["f_fixed"], "p_d": p,
                     "enum_max_nodes": int(o["enum_max_nodes"]), **common} for p in TABLE1_PD]
        out.append(Experiment("zhang2009-table1-enum", settings, ("ncr+2da-enum",), trial,
                              min(runs, int(o["enum_runs"])), seed,
                              params={"experiment": "table1-enum"}, volatile=VOLATILE))
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
            "noise_reference": o["noise_reference"] + (
                " (sigma = f times the mean nearest-neighbour distance of the run's targets)"
                if o["noise_reference"] == "per_run" else ""),
            "covariance_in_d2": f"Sigma_1i + Sigma_2j with Sigma = {o['covariance_scale']:g} x "
                                "the true noise covariance sigma^2 I",
            "covariance_scale": o["covariance_scale"],
            "same_sensor_pi": o["same_sensor"] + " (pi of two observations of one sensor; "
                                                 "the paper does not define it)",
            "ordering": o["ordering"] + " (single-linkage order; start = first sensor-1 observation, "
                                        "ties lowest index)",
            "truncation_readings": TruncationOptions(ordering=o["ordering"]).as_dict(),
            "md2da_cost": o["cost"] + ": cost -pi per pair, -tau/2 per unpaired observation",
            "md2da_threshold": f"tau = gate_threshold(alpha={o['alpha']}) = pi of a pair on "
                               f"the chi2(2) gate of level alpha with K = 0 "
                               f"(= {gate_threshold(ncr, o['alpha']):.6g} for MM-NCR, "
                               f"r_p={o['r_p']}, r_a={o['r_a']})",
            "mm_wa_attribute_conflict": "new conflict (4), as eq. (5) defines m^a",
            "metric": "correct_rate: correct relations / true relations per run, averaged; "
                      "all_correct: fraction of runs entirely right",
            "observation_order": "shuffled per sensor",
            "ours": list(OURS) + ["covariance_in_d2", "f_grid", "p_d_grid", "f_fixed", "p_d_fixed", "r_p_r_a_exp2",
                                  "md2da_cost", "md2da_threshold", "metric", "ordering",
                                  "same_sensor_pi", "mm_wa_attribute_conflict"],
        },
        "run": {"md2da_solver": solver, "table1_solvers": [solver, "highs", "bruteforce"],
                "enum_runs": o["enum_runs"], "enum_max_nodes": o["enum_max_nodes"],
                "timing": "time.perf_counter around the decision only (pi excluded); "
                          "t_backend = the back end's own solve time"},
    }


#: Paired comparisons (same simulated runs): (experiment, method A, method B).
PAIRS = (("main", "ncr+nd", "tbm+nd"), ("weights", "ncr+nd", "wa+nd"),
         ("main", "ncr+2da", "ncr+nd"), ("main", "ncr+2da-rect", "ncr+nd"))


def paired_differences(store: Path, exp: Experiment,
                       metric: str = "correct_rate") -> list[dict[str, Any]]:
    """Mean and standard error of the per-run difference A - B of ``metric``.

    Both methods decide on the same simulated runs, so the paired standard error is
    much smaller than the two curves' own.
    """
    from ...experiments import ResultStore, setting_key
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
