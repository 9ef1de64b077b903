"""Paper 002's experiments: the methods, grids, printed values, trial functions and
the experiment definitions (see :mod:`assocopt.reproduce.lu2013`).
"""


from __future__ import annotations

import math
import time
from dataclasses import replace
from typing import Any, Mapping, Sequence

import numpy as np

from ...solving.api import solve
from ...tracking.costs.sd_builder import COSTS, build_costs, build_problem
from ...experiments import Experiment, association_metrics
from ...tracking.scenarios.lu2013 import PAPER, REPRODUCTION_REGION_KM, Lu2013
from ...problems.problem import AssignmentProblem
from ...model.solution import Status
from ...solvers.baseline.bruteforce import enumerate_solutions
from ...solving import lp_fixing

__all__ = ["METHODS", "PAPER_TABLES", "PAPER_FIG2_GAIN", "DEFAULTS", "experiments",
           "fig_trial", "table_trial", "parameters", "D_GRID", "TABLE_GRID", "TABLE_COLUMNS",
           "table_experiment_name", "outcome_disagreements", "DISAGREEMENT_PAIRS"]

#: Methods run by the reproduction: the paper's three as printed, then ours.
METHODS = tuple(COSTS)
#: Paper's method label -> our method name.
PAPER_LABELS = {"ref. [2]": "pattipati", "KLD": "kld-printed", "SKLD": "skld-printed"}

PRINTED = ("pattipati", "kld-printed", "skld-printed")
D_GRID = tuple(round(0.05 * i, 2) for i in range(31))        # 0 : 0.05 : 1.5
SIGMAS = (1.5, 5.0)
TABLE_GRID = tuple((M, s, d) for M in (5, 10, 15, 20) for s in SIGMAS for d in (0.5, 1.0, 1.5))

#: Tables 1-4 of the paper (docs/papers/lu2013.md): PAPER_TABLES[M][label] = 6 values in the
#: column order (1.5, 0.5) (1.5, 1) (1.5, 1.5) (5, 0.5) (5, 1) (5, 1.5).
PAPER_TABLES: dict[int, dict[str, tuple[float, ...]]] = {
    5: {"ref. [2]": (0.8268, 0.9566, 0.9806, 0.3934, 0.6354, 0.7992),
        "KLD": (0.8368, 0.9634, 0.9838, 0.3941, 0.6382, 0.8110),
        "SKLD": (0.8546, 0.9676, 0.9890, 0.4082, 0.6560, 0.8288)},
    10: {"ref. [2]": (0.8201, 0.9541, 0.9819, 0.3357, 0.6001, 0.7532),
         "KLD": (0.8330, 0.9558, 0.9819, 0.3360, 0.6104, 0.7598),
         "SKLD": (0.8514, 0.9627, 0.9875, 0.3533, 0.6338, 0.7869)},
    15: {"ref. [2]": (0.7595, 0.9318, 0.9673, 0.2927, 0.5178, 0.6638),
         "KLD": (0.7671, 0.9365, 0.9692, 0.2851, 0.5207, 0.6728),
         "SKLD": (0.7923, 0.9549, 0.9765, 0.3081, 0.5557, 0.7004)},
    20: {"ref. [2]": (0.7443, 0.9270, 0.9618, 0.2585, 0.5117, 0.6503),
         "KLD": (0.7585, 0.9260, 0.9634, 0.2648, 0.5132, 0.6522),
         "SKLD": (0.7836, 0.9431, 0.9704, 0.2776, 0.5496, 0.6900)},
}
#: Fig. 2 text: average correct-rate improvement over ref. [2] (unit not given).
PAPER_FIG2_GAIN = {"KLD": {1.5: 0.23, 5.0: 0.2}, "SKLD": {1.5: 0.78, 5.0: 1.4}}

#: Defaults of the parameters the paper does not give (ours), and run options:
#: ``region_km`` (scenario, ours); ``line_directions`` (the line geometries of
#: Tables 1-4, each run as its own experiment; the pair of Figs. 1-2 always lies along
#: +x, as §4.1 prints it); ``elevation_sigma_ratio`` (elevation sigma / azimuth
#: sigma, 1 = the same sigma for both angles); ``solver`` (exact back end for the ILP,
#: any exact name of :func:`assocopt.solvers.available`); ``ilp_strategy``
#: ("lp-fixing" or "full"); ``localiser`` ("ls", "ils", "tls"); ``covariance``
#: ("residual", "printed"); ``normalisation`` ("printed", "gaussian", "none");
#: ``other_geometry_runs`` (runs per point for every geometry after the first; None =
#: ``runs``); ``region_scan_L`` (side lengths L of the regions [0, L]^2 x [1, 10] km
#: of the region scan, run with ref. [2] at M = 5, sigma = 1.5, d = 0.5 and
#: ``max(2, runs // 5)`` runs; () skips it).
DEFAULTS: dict[str, Any] = {
    "region_km": REPRODUCTION_REGION_KM,
    "line_directions": ("x", "horizontal"),
    "elevation_sigma_ratio": 1.0,
    # "highs", not "auto": when this was written "auto" resolved to "lagrangian-exact"
    # for S-D, which raised TypeError (lagrangian _close_gap, incumbent None) or
    # searched for minutes on some of the small restricted ILPs left by the fixing step.
    "solver": "highs",
    "ilp_strategy": "lp-fixing",
    "localiser": "ls",
    "covariance": "residual",
    "normalisation": "printed",
    "other_geometry_runs": None,
    "region_scan_L": (20.0, 30.0, 40.0, 50.0),
}
#: Which parameters are modelling choices of ours (vs. run options).
OURS_PARAMS = ("region_km", "line_directions", "d_unit", "sigma_same_for_both_angles",
               "localiser", "covariance", "normalisation", "r_convention",
               "correct_rate_definitions")
#: Keys of an option set that enter every setting (they change the simulated data or
#: the costs); the rest are run options.
_SCENARIO_OPTS = ("region_km", "localiser", "covariance", "normalisation",
                  "elevation_sigma_ratio")
_SOLVER_OPTS = ("solver", "ilp_strategy")
#: The region scan's cell (the one cell of Table 1 the region was chosen on).
REGION_SCAN_CELL = {"M": 5, "sigma_mrad": 1.5, "d": 0.5}


def _scenario(setting: Mapping[str, Any], n_targets: int) -> Lu2013:
    sigma = float(setting["sigma_mrad"])
    ratio = float(setting.get("elevation_sigma_ratio", 1.0))
    return Lu2013(n_targets=n_targets, d=float(setting["d"]), sigma_mrad=sigma,
                  sigma_elevation_mrad=None if ratio == 1.0 else ratio * sigma,
                  region_km=tuple(tuple(r) for r in setting["region_km"]),
                  line_direction=setting["line_direction"])


def _cost_opts(setting: Mapping[str, Any]) -> dict[str, str]:
    return {k: setting[k] for k in ("localiser", "covariance", "normalisation")}


def fig_trial(setting: Mapping[str, Any], methods: Sequence[str],
              seed: np.random.SeedSequence) -> dict[str, dict[str, float]]:
    """Two targets: enumerate all feasible partitions, record correctness and r."""
    rng = np.random.default_rng(seed)
    scan, truth = _scenario(setting, 2).simulate(rng)
    part, targets = truth.partition(), truth.target_tuples()
    t0 = time.perf_counter()
    costs = build_costs(scan, methods, **_cost_opts(setting))
    t_cost = (time.perf_counter() - t0) / len(methods)
    out: dict[str, dict[str, float]] = {}
    sols_cache: dict[bytes, np.ndarray] = {}
    for m in methods:
        c = costs[m]
        keep = np.flatnonzero(np.isfinite(c.total))
        key = c.tuples[keep].tobytes()
        if key not in sols_cache:
            prob = build_problem(scan, m, costs=c)
            sols_cache[key] = list(enumerate_solutions(prob))
        sols = sols_cache[key]
        tot = np.array([c.total[keep][s].sum() for s in sols])
        dat = np.array([c.data[keep][s].sum() for s in sols])
        best = int(np.argmin(tot))
        others = np.arange(len(sols)) != best
        chosen = c.tuples[keep][sols[best]]
        res = association_metrics(chosen, part, targets)
        res["n_solutions"] = float(len(sols))
        res["r_data"] = _ratio(dat[best], dat[others])
        res["r_full"] = _ratio(tot[best], tot[others])
        res["t_cost"] = t_cost
        out[m] = res
    return out


def _problems(scan, costs) -> dict[str, AssignmentProblem]:
    """One S-D problem per method.  When every method's costs are finite (the paper's
    case) the candidate tuples are identical, so the validated problem of the first
    method is reused with the other methods' costs (no re-validation of the tuples)."""
    out: dict[str, AssignmentProblem] = {}
    base = None
    for m, c in costs.items():
        finite = bool(np.isfinite(c.total).all())
        if base is not None and finite:
            arr = np.array(c.total, dtype=np.float64)
            arr.setflags(write=False)
            out[m] = replace(base, costs=arr, name=f"lu2013-{m}")
        else:
            out[m] = build_problem(scan, m, costs=c, name=f"lu2013-{m}")
            if base is None and finite:
                base = out[m]
    return out


def _ratio(best: float, others: np.ndarray) -> float:
    if len(others) == 0:
        return math.nan
    ave = float(np.mean(others))
    return best / ave if ave != 0 else math.nan


def table_trial(setting: Mapping[str, Any], methods: Sequence[str],
                seed: np.random.SeedSequence) -> dict[str, dict[str, float]]:
    """M targets on a line: solve each method's S-D problem, record the metrics."""
    rng = np.random.default_rng(seed)
    scan, truth = _scenario(setting, int(setting["M"])).simulate(rng)
    part, targets = truth.partition(), truth.target_tuples()
    t0 = time.perf_counter()
    costs = build_costs(scan, methods, **_cost_opts(setting))
    t_cost = (time.perf_counter() - t0) / len(methods)
    probs = _problems(scan, costs)
    lps: dict[str, Any] = {m: None for m in probs}
    t_lp = 0.0
    if setting["ilp_strategy"] == "lp-fixing":
        t0 = time.perf_counter()
        lps = dict(zip(probs, lp_fixing.lp_relaxations(list(probs.values()))))
        t_lp = (time.perf_counter() - t0) / len(probs)
    out = {}
    for m, prob in probs.items():
        out[m] = {**_solve_metrics(prob, setting, lps[m], t_lp), "t_cost": t_cost}
        sol_tuples = out[m].pop("_tuples")
        out[m].update(association_metrics(sol_tuples, part, targets))
    return out


def _solve_metrics(prob, setting: Mapping[str, Any], lp: "lp_fixing.LPResult | None" = None,
                   t_lp: float = 0.0) -> dict[str, Any]:
    """LP relaxation statistics and the exact solution of one S-D problem.

    ``ilp_strategy="lp-fixing"``: LP by HiGHS with duals (:func:`lp_fixing.lp_relaxation`);
    an integral LP optimum is an ILP optimum; otherwise :func:`lp_fixing.solve_with_fixing`
    solves a small ILP through :func:`assocopt.solve` with ``solver``.
    ``ilp_strategy="full"`` (or no ``lp`` given): LP and full ILP both through
    :func:`assocopt.solve`.
    """
    if lp is not None:
        x, integral, lp_obj = lp.x, lp.integral, lp.objective
    else:
        t0 = time.perf_counter()
        core = solve(prob, "highs", relax="lp", presolve="off")
        if core.status is not Status.OPTIMAL:
            raise RuntimeError(f"LP relaxation not solved: {core.status} {core.message}")
        x, integral, lp_obj = core.x, bool(core.integral and core.has_solution), core.objective
        t_lp = time.perf_counter() - t0
    rounded = np.flatnonzero(x > 0.5)
    round_infeasible = prob.violations(rounded) is not None
    t1 = time.perf_counter()
    kept = None
    if integral and lp is not None:
        sol_tuples, objective, gap = prob.tuples[rounded], prob.objective_of(rounded), 0.0
        t_ilp = 0.0
    else:
        if lp is not None:
            sol, kept = lp_fixing.solve_with_fixing(prob, lp, setting["solver"])
        else:
            sol = solve(prob, setting["solver"])
            kept = prob.n_candidates
        if not sol.has_solution:
            raise RuntimeError(f"S-D problem not solved: {sol.status} {sol.message}")
        sol_tuples, objective = sol.tuples, sol.objective
        gap = sol.gap if sol.gap is not None else math.nan
        t_ilp = time.perf_counter() - t1
    same = (not round_infeasible and
            set(map(tuple, prob.tuples[rounded].tolist())) == set(map(tuple, sol_tuples.tolist())))
    return {"lp_integral": float(integral), "lp_round_infeasible": float(round_infeasible),
            "lp_round_wrong": float(not same), "ilp_solved": float(kept is not None),
            "ilp_columns": None if kept is None else float(kept),
            "gap": gap, "objective": objective, "lp_bound": lp_obj,
            "t_lp": t_lp, "t_ilp": t_ilp, "_tuples": sol_tuples}


def _options(options: Mapping[str, Any] | None) -> dict[str, Any]:
    opts = {**DEFAULTS, **(options or {})}
    unknown = set(opts) - set(DEFAULTS)
    if unknown:
        raise ValueError(f"unknown lu2013 option(s) {sorted(unknown)}; valid: {sorted(DEFAULTS)}")
    dirs = tuple(opts["line_directions"])
    if not dirs or len(set(dirs)) != len(dirs):
        raise ValueError(f"line_directions must be distinct names, got {dirs!r}")
    for ld in dirs:                                                   # validate
        Lu2013(region_km=opts["region_km"], line_direction=ld)
    if not float(opts["elevation_sigma_ratio"]) > 0:
        raise ValueError(f"elevation_sigma_ratio must be > 0, got {opts['elevation_sigma_ratio']!r}")
    if opts["ilp_strategy"] not in ("lp-fixing", "full"):
        raise ValueError(f"ilp_strategy must be 'lp-fixing' or 'full', got {opts['ilp_strategy']!r}")
    og = opts["other_geometry_runs"]
    if og is not None and (not isinstance(og, int) or isinstance(og, bool) or og < 1):
        raise ValueError(f"other_geometry_runs must be a positive integer or None, got {og!r}")
    return opts


def table_experiment_name(line_direction: str, first: bool) -> str:
    """Store name of the Tables 1-4 experiment of one line geometry."""
    return "lu2013-tables" if first else f"lu2013-tables-{line_direction}"


def experiments(runs: int, seed: int, options: Mapping[str, Any] | None = None,
                parts: Sequence[str] = ("fig", "tables", "region")) -> list[Experiment]:
    """The Experiments of the reproduction (``options`` override :data:`DEFAULTS`).

    ``tables`` gives one experiment per line geometry (``line_directions``); the
    first keeps the store name ``lu2013-tables``.
    """
    opts = _options(options)
    common = {k: (list(map(list, opts[k])) if k == "region_km" else opts[k])
              for k in _SCENARIO_OPTS}
    common["elevation_sigma_ratio"] = float(common["elevation_sigma_ratio"])
    solver = {k: opts[k] for k in _SOLVER_OPTS}
    out = []
    if "fig" in parts:
        settings = [{"part": "fig", "sigma_mrad": s, "d": d, "line_direction": "x", **common}
                    for s in SIGMAS for d in D_GRID]
        out.append(Experiment("lu2013-fig", settings, METHODS, fig_trial, runs, seed,
                              params={"experiment": "fig"},
                              volatile=("t_cost",)))
    if "tables" in parts:
        for i, ld in enumerate(opts["line_directions"]):
            settings = [{"part": "tables", "M": M, "sigma_mrad": s, "d": d,
                         "line_direction": ld, **common, **solver}
                        for M, s, d in TABLE_GRID]
            n = runs if i == 0 or opts["other_geometry_runs"] is None else \
                min(runs, opts["other_geometry_runs"])
            out.append(Experiment(table_experiment_name(ld, i == 0), settings, METHODS,
                                  table_trial, n, seed, params={"experiment": "tables"},
                                  volatile=("t_cost", "t_lp", "t_ilp")))
    if "region" in parts and opts["region_scan_L"]:
        settings = [{"part": "region", "L": float(L), **REGION_SCAN_CELL, "line_direction": "x",
                     **{**common, "region_km": [[0.0, float(L)], [0.0, float(L)], [1.0, 10.0]]},
                     **solver} for L in opts["region_scan_L"]]
        out.append(Experiment("lu2013-region", settings, ("pattipati",), table_trial,
                              max(2, runs // 5), seed, params={"experiment": "region"},
                              volatile=("t_cost", "t_lp", "t_ilp")))
    return out


def parameters(options: Mapping[str, Any] | None = None) -> dict[str, Any]:
    """The parameters of a run: the paper's, ours (marked), and run options."""
    opts = _options(options)
    sc = Lu2013(region_km=opts["region_km"])
    return {
        "paper": {**PAPER, "sensors_km": [list(s) for s in PAPER["sensors_km"]],
                  "solver": "lp_solve (LP relaxation)"},
        "ours": {
            "region_km": [list(r) for r in sc.region_km],
            "line_directions": list(opts["line_directions"]),
            "line_layout": "first target uniform in region_km, others at +k*d along the "
                           "line: 'x' = along +x (as the pair of §4.1), 'horizontal' = in a "
                           "uniformly random horizontal direction per run",
            "fig_pair": "(x, y, z) and (x + d, y, z), as §4.1 prints it",
            "d_unit": "km",
            "sigma_same_for_both_angles": float(opts["elevation_sigma_ratio"]) == 1.0,
            "elevation_sigma_ratio": float(opts["elevation_sigma_ratio"]),
            "localiser": opts["localiser"],
            "covariance": opts["covariance"] + (
                " (LS covariance with the residual Jacobian; the printed dY/dm form is too "
                "small)" if opts["covariance"] == "residual" else ""),
            "normalisation": opts["normalisation"] + (
                " (constants ln(sqrt(2 pi det R)/P_D) as printed)"
                if opts["normalisation"] == "printed" else ""),
            "r_convention": "r_data: C_best/C_ave on the costs without the constant terms "
                            "; r_full: on the costs as printed (radians)",
            "correct_rate_definitions": "partition_correct: whole partition right; "
                                        "tuple_rate: fraction of true target tuples found",
            "measurement_order": "shuffled per sensor",
            "ours": list(OURS_PARAMS),
        },
        "run": {"solver": opts["solver"], "ilp_strategy": opts["ilp_strategy"],
                "lp_solver": "highs (presolve off)",
                "other_geometry_runs": opts["other_geometry_runs"],
                "region_scan_L": list(opts["region_scan_L"])},
    }


TABLE_COLUMNS = tuple((s, d) for s in SIGMAS for d in (0.5, 1.0, 1.5))
#: Pairs of costs whose per-trial outcomes are compared (how often they decide differently).
DISAGREEMENT_PAIRS = (("kld-printed", "skld-printed"), ("kld-reversed", "kld-printed"),
                      ("kld-exact", "pattipati"), ("kld-joint", "pattipati"),
                      ("skld-exact", "pattipati"), ("pattipati-ml", "pattipati"))


def outcome_disagreements(store, exp: Experiment, a: str, b: str) -> dict[str, int]:
    """In how many trials methods ``a`` and ``b`` differ in tuple rate or partition
    correctness (trials 0 .. runs-1 where both are stored)."""
    from ...experiments import ResultStore, setting_key
    keys = {setting_key(s) for s in exp.settings}
    got: dict[tuple[str, int], dict[str, tuple]] = {}
    with ResultStore(store) as st:
        for s, m, t, metrics in st.rows():
            if s in keys and t < exp.runs and m in (a, b):
                got.setdefault((s, t), {})[m] = (metrics.get("tuple_rate"),
                                                 metrics.get("partition_correct"))
    both = [v for v in got.values() if a in v and b in v]
    return {"differ": sum(v[a] != v[b] for v in both), "trials": len(both)}
