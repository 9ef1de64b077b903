"""Paper 002 scenario simulator and reproduction (lu2013)."""

from __future__ import annotations

import json

import numpy as np
import pytest

from assocopt import InvalidProblemError, solve
from assocopt.tracking.costs import build_costs, build_problem
from assocopt.runtime.errors import AssocoptError
from assocopt.experiments import trial_seed
from assocopt.reproduce import PAPERS, list_papers, reproduce
from assocopt.reproduce import lu2013 as L
from assocopt.solving import lp_fixing
from assocopt.tracking.scenarios.lu2013 import PAPER_SENSORS_KM, Lu2013
from assocopt.solvers.baseline.bruteforce import enumerate_solutions
from conftest import rerun_committed


# ---------------------------------------------------------------------- scenario
def test_simulator_is_seeded_and_uses_no_global_state():
    sc = Lu2013(n_targets=5, d=1.0)
    a, ta = sc.simulate(np.random.default_rng(3))
    np.random.seed(0)
    b, tb = sc.simulate(np.random.default_rng(3))
    for s in range(3):
        np.testing.assert_array_equal(a.meas[s], b.meas[s])
        np.testing.assert_array_equal(ta.labels[s], tb.labels[s])
    with pytest.raises(TypeError, match="Generator"):
        sc.simulate(3)


def test_targets_on_a_line_spaced_by_d_and_truth_is_consistent():
    sc = Lu2013(n_targets=4, d=1.5, sigma_mrad=1e-6)
    scan, truth = sc.simulate(np.random.default_rng(1))
    X = truth.targets
    np.testing.assert_allclose(np.diff(X, axis=0), [[1.5, 0, 0]] * 3)
    reg = np.asarray(sc.region_km)
    assert (reg[:, 0] <= X[0]).all() and (X[0] <= reg[:, 1]).all()
    T = truth.target_tuples()
    assert T.shape == (4, 3) and (T > 0).all()
    assert len(truth.partition()) == 4
    # shuffled: measurement i of sensor s is target labels[s][i]
    assert any(not np.array_equal(lab, np.arange(4)) for lab in truth.labels)
    from assocopt.tracking.localisation import angles
    th = angles(X, np.array(PAPER_SENSORS_KM))
    for s in range(3):
        np.testing.assert_allclose(scan.meas[s], th[truth.labels[s], s], atol=1e-6)


def test_missed_detections_and_false_alarms_extension():
    sc = Lu2013(n_targets=6, d=1.0, pd=0.7, clutter_rate=3.0)
    scan, truth = sc.simulate(np.random.default_rng(2))
    labels = np.concatenate(truth.labels)
    assert (labels == -1).any() and len(labels) != 18
    assert scan.clutter_density[0] == pytest.approx(3.0 / sc.fov_area)
    part = truth.partition()
    assert sum(1 for t in part if sum(v > 0 for v in t) == 1) >= (labels == -1).sum()
    p = build_problem(scan, "pattipati", normalisation="gaussian")
    sol = solve(p, "highs")
    assert sol.status.value == "optimal"


def test_more_sensors_and_parameter_errors():
    S = PAPER_SENSORS_KM + ((20.0, 20.0, 0.5),)
    scan, _ = Lu2013(n_targets=3, sensors_km=S).simulate(np.random.default_rng(0))
    assert scan.sizes == (3, 3, 3, 3)
    assert build_problem(scan, "skld-exact").n_candidates == 81
    with pytest.raises(InvalidProblemError, match="line_direction"):
        Lu2013(line_direction="y")
    with pytest.raises(InvalidProblemError, match="pd must lie"):
        Lu2013(pd=1.5)
    with pytest.raises(InvalidProblemError, match="region_km"):
        Lu2013(region_km=((1, 0), (0, 1), (0, 1)))


def test_parameters_mark_ours():
    p = Lu2013().parameters()
    assert "region_km" in p["ours"] and p["d_unit"] == "km"
    q = L.parameters()
    assert q["paper"]["sensors_km"] == [[0, 20, 0], [20, 0, 0], [0, 0, 0]]
    assert q["paper"]["sigma_mrad"] == [1.5, 5.0] and q["paper"]["runs"] == 1000
    assert "region_km" in q["ours"]["ours"]


# ------------------------------------------------------------------ two targets
def _fig_setting(d=0.3, sigma=5.0):
    base = L.experiments(1, 0, parts=("fig",))[0].settings[0]
    return dict(base, sigma_mrad=sigma, d=d)


def _table_setting(**kw):
    base = L.experiments(1, 0, parts=("tables",))[0].settings[0]
    return dict(base, **kw)


def test_two_targets_enumeration_agrees_with_the_exact_solver():
    st = _fig_setting()
    for t in range(5):
        rng = np.random.default_rng(trial_seed(0, st, t))
        scan, _ = L._scenario(st, 2).simulate(rng)
        costs = build_costs(scan)
        for m, c in costs.items():
            p = build_problem(scan, m, costs=c)
            sols = list(enumerate_solutions(p))
            assert len(sols) == 4
            best = min(p.objective_of(s) for s in sols)
            assert solve(p, "highs").objective == pytest.approx(best, rel=1e-9, abs=1e-9)


def test_fig_trial_metrics_and_r_convention():
    res = L.fig_trial(_fig_setting(d=0.5), list(L.METHODS), trial_seed(0, "x", 1))
    assert set(res) == set(L.METHODS)
    for m, r in res.items():
        assert r["n_solutions"] == 4
        assert r["partition_correct"] == r["tuple_rate"]           # coincide for M = 2
    # with non-negative data terms the best solution is below the average: r_data <= 1
    for m in ("pattipati", "kld-exact", "skld-exact", "kld-joint", "skld-joint"):
        assert 0 <= res[m]["r_data"] <= 1
    # with the printed constants (radians) all costs are negative: r_full > 1
    assert res["pattipati"]["r_full"] > 1


# ---------------------------------------------------------------- M targets
def test_lp_fixing_is_exact_on_fractional_instances():
    found = 0
    for seed in range(60):
        scan, _ = Lu2013(n_targets=10, d=0.5, sigma_mrad=5.0,
                         region_km=L.DEFAULTS["region_km"]).simulate(np.random.default_rng(seed))
        for m, c in build_costs(scan, ["pattipati", "skld-printed"]).items():
            p = build_problem(scan, m, costs=c)
            lp = lp_fixing.lp_relaxation(p)
            core = solve(p, "highs", relax="lp")
            assert lp.objective == pytest.approx(core.objective, rel=1e-9, abs=1e-9)
            assert lp.integral == core.integral
            if lp.integral:
                continue
            found += 1
            sol, kept = lp_fixing.solve_with_fixing(p, lp, "highs")
            ref = solve(p, "highs")
            assert kept < p.n_candidates
            # the fixing bound is valid: L(u) <= LP optimum <= ILP optimum
            L_u = lp.u.sum() + np.minimum(lp.d, 0).sum()
            assert L_u <= lp.objective + 1e-7 * (1 + abs(lp.objective)) <= ref.objective + 1e-6
            assert sol.objective == pytest.approx(ref.objective, rel=1e-9, abs=1e-9)
            assert sol.status.value == "optimal" and sol.gap == 0
        if found >= 3:
            break
    assert found >= 1, "no fractional LP found; the check did not run"


def test_table_trial_strategies_agree():
    st = _table_setting(M=6, sigma_mrad=5.0, d=0.5)
    full = dict(st, ilp_strategy="full", solver="highs")
    for t in range(3):
        seed = trial_seed(0, st, t)
        a = L.table_trial(st, ["pattipati", "skld-printed"], seed)
        b = L.table_trial(full, ["pattipati", "skld-printed"], seed)
        for m in a:
            for k in ("partition_correct", "tuple_rate", "lp_integral", "lp_round_wrong"):
                assert a[m][k] == b[m][k], (m, k)
            assert a[m]["objective"] == pytest.approx(b[m]["objective"], rel=1e-9)
            assert a[m]["gap"] == 0


# -------------------------------------------------------------- reproduction
def test_registry_and_errors():
    assert "lu2013" in [p["name"] for p in list_papers()]
    assert PAPERS["lu2013"].default_runs == 1000
    with pytest.raises(AssocoptError, match="unknown paper 'nope'"):
        reproduce("nope", out="x")
    with pytest.raises(AssocoptError, match="runs must be a positive integer"):
        reproduce("lu2013", runs=0, out="x")
    with pytest.raises(AssocoptError, match="unknown lu2013 option"):
        reproduce("lu2013", runs=1, out="x", options={"regoin_km": 1})


def test_reproduce_writes_summary_figures_and_resumes(tmp_path):
    printed = []
    s = reproduce("lu2013", runs=1, workers=1, seed=5, out=tmp_path, echo=printed.append)
    js = json.loads((tmp_path / "summary.json").read_text())
    assert js["runs"] == 1 and js["seed"] == 5
    assert js["parameters"]["ours"]["region_km"] == [[0.0, 50.0], [0.0, 50.0], [1.0, 10.0]]
    rec = js["records"][0]
    assert {"experiment", "setting", "method", "metric", "value", "runs"} <= set(rec)
    metrics = {(r["experiment"], r["metric"]) for r in js["records"]}
    assert ("fig", "r_data") in metrics and ("tables", "lp_integral") in metrics
    assert ("tables", "tuple_rate") in metrics and ("tables", "gap") in metrics
    n_table = {(r["method"], r["setting"]["M"], r["setting"]["sigma_mrad"], r["setting"]["d"],
                r["setting"]["line_direction"])
               for r in js["records"] if r["experiment"] == "tables"}
    assert len(n_table) == len(L.METHODS) * 24 * 2
    assert "Table 4 — M = 20" in printed[0]
    assert printed[0] == L.render_tables(js)          # tables.md is a function of summary.json
    if s["figures"]:
        assert (tmp_path / "fig1_r.png").stat().st_size > 1000
    again = reproduce("lu2013", runs=1, workers=1, seed=5, out=tmp_path, echo=lambda t: None)
    assert all(v["done"] == 0 for v in again["timing"].values())
    assert again["records"] == s["records"] or _same_nonvolatile(again, s)
    with pytest.raises(AssocoptError, match="seed=5"):
        reproduce("lu2013", runs=1, seed=6, out=tmp_path, echo=lambda t: None)


def _same_nonvolatile(a, b):
    key = lambda r: (r["experiment"], json.dumps(r["setting"], sort_keys=True), r["method"],  # noqa: E731
                     r["metric"])
    va = {key(r): r["value"] for r in a["records"] if not r["volatile"]}
    vb = {key(r): r["value"] for r in b["records"] if not r["volatile"]}
    return va == vb


# ------------------------------------------------------- pinned reproduced numbers
def test_pinned_table_trials_at_a_small_seeded_run():
    """Six seeded trials of one Table-1 cell (M = 5, sigma = 5, d = 0.5, line along +x):
    the tuple rates and ref. [2]'s optimal costs, pinned when the reproduction was run.
    A change of simulator, localisation, cost or solver shows up here."""
    st = [s for s in L.experiments(1, 0, parts=("tables",))[0].settings
          if (s["M"], s["sigma_mrad"], s["d"]) == (5, 5.0, 0.5)][0]
    methods = ["pattipati", "skld-exact", "pattipati-ml", "kld-reversed"]
    got = {m: [] for m in methods}
    obj = []
    for t in range(6):
        r = L.table_trial(st, methods, trial_seed(0, st, t))
        for m in methods:
            got[m].append(r[m]["tuple_rate"])
        obj.append(r["pattipati"]["objective"])
    assert got == {"pattipati": [0.2, 0.0, 0.0, 1.0, 0.6, 0.0],
                   "skld-exact": [0.2, 0.6, 0.0, 1.0, 0.6, 0.6],
                   "pattipati-ml": [0.2, 0.6, 0.0, 1.0, 0.6, 0.0],
                   "kld-reversed": [0.2, 0.6, 0.0, 1.0, 0.6, 0.6]}
    assert obj == pytest.approx([-141.57453275029727, -134.12521558573013, -139.0522195967661,
                                 -138.60089407656324, -123.65764638632808, -141.83170507933698],
                                rel=1e-9)


def test_pinned_fig_trial():
    st = [s for s in L.experiments(1, 0, parts=("fig",))[0].settings
          if (s["sigma_mrad"], s["d"]) == (1.5, 0.5)][0]
    r = L.fig_trial(st, ["pattipati", "kld-reversed", "pattipati-ml"], trial_seed(0, st, 0))
    assert {m: v["partition_correct"] for m, v in r.items()} == {
        "pattipati": 1.0, "kld-reversed": 1.0, "pattipati-ml": 1.0}
    assert [r[m]["r_data"] for m in ("pattipati", "kld-reversed", "pattipati-ml")] == \
        pytest.approx([0.05389969691307301, 0.1209636438467431, 0.05654420609350907], rel=1e-9)


def test_committed_summary_regenerates_from_the_code(tmp_path):
    """Recompute one cell of the committed run from scratch (the region scan's L = 20,
    its full run count) and compare with docs/papers/lu2013/summary.json exactly."""
    rows, recs = rerun_committed(L, "lu2013", "region", lambda s: s["L"] == 20.0,
                                 tmp_path / "r.sqlite")
    mine = {r["metric"]: r["value"] for r in rows}
    committed = {r["metric"]: r["value"] for r in recs if not r["volatile"] and not r["paired"]}
    assert committed and mine["tuple_rate"] == committed["tuple_rate"]
    assert {k: mine[k] for k in committed} == pytest.approx(committed, rel=1e-12)


def test_options_are_real_parameters():
    """The elevation sigma and the geometries are parameters that change the data."""
    base = _table_setting(M=5, sigma_mrad=1.5, d=1.0)
    seed = trial_seed(0, base, 0)
    a = L._scenario(base, 5).simulate(np.random.default_rng(seed))[0]
    b = L._scenario(dict(base, elevation_sigma_ratio=2.0), 5).simulate(
        np.random.default_rng(seed))[0]
    assert np.allclose(a.R[0][:, 0, 0] * 4, b.R[0][:, 0, 0])     # elevation variance x 4
    assert np.allclose(a.R[0][:, 1, 1], b.R[0][:, 1, 1])         # azimuth unchanged
    assert L.parameters({"elevation_sigma_ratio": 2.0})["ours"][
        "sigma_same_for_both_angles"] is False
    names = [e.name for e in L.experiments(1, 0, {"line_directions": ("horizontal", "3d")},
                                           parts=("tables",))]
    assert names == ["lu2013-tables", "lu2013-tables-3d"]
    with pytest.raises(ValueError, match="elevation_sigma_ratio"):
        L.experiments(1, 0, {"elevation_sigma_ratio": 0})
