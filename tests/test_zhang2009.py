"""Paper 000 end to end: the scenario simulator, MD-2DA through every back end, and
both decision rules on random scenarios (each observation in exactly one relation)."""

from __future__ import annotations

import itertools

import numpy as np
import pytest

from assocopt.tracking.belief import MassFunction, pignistic
from assocopt.tracking.decide import (TruncationOptions, gate_threshold, md_2da, md_2da_problem,
                                      md_nd)
from assocopt.tracking.belief.group_matching import MeasureParams, matching_matrix
from assocopt.tracking.scenarios.zhang2009 import Zhang2009, confusion_sets, mean_nearest_distance

from conftest import EXACT, installed, rerun_committed

NCR = MeasureParams("ncr", r_p=1.0, r_a=0.6)


# ------------------------------------------------------------------ scenario
def test_same_seed_same_draw_and_shapes():
    sc = Zhang2009(f=0.3, p_d=0.7)
    a = sc.simulate(np.random.default_rng(5))
    b = sc.simulate(np.random.default_rng(5))
    assert np.array_equal(a.observations.positions, b.observations.positions)
    assert np.array_equal(a.observations.attributes, b.observations.attributes)
    assert a.truth == b.truth
    obs = a.observations
    assert obs.attributes.shape == (obs.n, 64) and obs.types == sc.types
    assert sorted(set(a.target_types.tolist())) == list(range(6))     # "cover": all 6 types


def test_detection_probability_extremes():
    rng = np.random.default_rng(0)
    full = Zhang2009(p_d=1.0).simulate(rng)
    assert full.observations.n == 18 and len(full.truth.pairs) == 9
    none = Zhang2009(p_d=0.0).simulate(rng)
    assert none.observations.n == 0 and len(none.truth) == 0


def test_noise_is_f_times_mean_nearest_distance():
    sc = Zhang2009(f=0.4)
    d = sc.simulate(np.random.default_rng(2))
    assert d.sigma == pytest.approx(0.4 * mean_nearest_distance(d.positions))
    assert np.allclose(d.observations.covariances, d.sigma ** 2 * np.eye(2))
    fixed = Zhang2009(f=0.4, noise_reference="mean_over_runs")
    s1 = fixed.simulate(np.random.default_rng(1)).sigma
    assert s1 == fixed.simulate(np.random.default_rng(2)).sigma > 0


def test_noise_statistics():
    sc = Zhang2009(f=0.5, p_d=1.0)
    rng = np.random.default_rng(11)
    z = []
    for _ in range(300):
        d = sc.simulate(rng)
        z.append((d.observations.positions - d.positions[d.target]) / d.sigma)
    z = np.concatenate(z)
    assert abs(z.mean()) < 0.05 and abs(z.std() - 1) < 0.05


def test_attribute_generators():
    sc = Zhang2009(p_d=1.0)
    conf = confusion_sets(6, 2, True)
    assert conf.tolist() == [0b11, 0b110, 0b1100, 0b11000, 0b110000, 0b100001]
    rng = np.random.default_rng(4)
    n_gen2 = n_total = 0
    for _ in range(50):
        d = sc.simulate(rng)
        for i, row in enumerate(d.observations.attributes):
            t = d.target_types[d.target[i]]
            m = MassFunction.from_vector(sc.types, row)          # validates sum and sign
            c = int(conf[t])
            focal = set(np.flatnonzero(row > 0).tolist())
            assert focal <= {1 << t, c, 63, 63 & ~c}
            n_total += 1
            if row[63 & ~c] > 0:                                 # generator 2
                n_gen2 += 1
                assert row[63 & ~c] <= min(row[1 << t], row[c], row[63])
            assert max(pignistic(m), key=pignistic(m).get) == sc.types[t]
    assert 0.4 < n_gen2 / n_total < 0.6


def test_observation_order_does_not_reveal_targets():
    rng = np.random.default_rng(8)
    firsts = [Zhang2009(p_d=1.0).simulate(rng).target[0] for _ in range(200)]
    assert len(set(firsts)) == 9


def test_invalid_scenario_parameters():
    with pytest.raises(ValueError, match="p_d"):
        Zhang2009(p_d=1.5)
    with pytest.raises(ValueError, match="confusion_size"):
        Zhang2009(confusion_size=6)
    with pytest.raises(ValueError, match="noise_reference"):
        Zhang2009(noise_reference="x")


# ------------------------------------------------------------------- MD-2DA
def test_md2da_cost_model():
    pi = np.array([[np.nan, .5, .2], [.5, np.nan, .1], [.2, .1, np.nan]])
    prob, rows, cols = md_2da_problem(pi, [1, 2, 2], tau=0.3)
    assert rows.tolist() == [0] and cols.tolist() == [1, 2]
    assert np.allclose(prob.to_cost_matrix(), [[-.5, -.2]])
    rm, cm = prob.miss_costs()
    assert np.allclose(rm, -0.15) and np.allclose(cm, -0.15)
    assert md_2da(pi, [1, 2, 2], tau=0.3).relations.pairs == ((0, 1),)
    assert md_2da(pi, [1, 2, 2], tau=0.6).relations.pairs == ()
    with pytest.raises(ValueError, match="tau"):
        md_2da_problem(pi, [1, 2, 2], tau=-1.0)


def test_gate_threshold_blocks_pairs_outside_the_position_gate():
    assert gate_threshold(NCR, 0.01) == pytest.approx(0.008)
    assert gate_threshold(MeasureParams("tbm", r_p=1.0, r_a=0.6)) == pytest.approx(0.01)
    assert gate_threshold(MeasureParams("wa", w_p=0.5, w_a=0.5), 0.01) == pytest.approx(0.505)
    rng = np.random.default_rng(3)
    sc = Zhang2009(f=0.5, p_d=0.7)
    tau = gate_threshold(NCR, 0.01)
    for _ in range(30):
        d = sc.simulate(rng)
        obs = d.observations
        pi = matching_matrix(obs, NCR)
        rel = md_2da(pi, obs.sensor, tau=tau).relations
        diff = obs.positions[:, None] - obs.positions[None]
        d2 = (diff ** 2).sum(-1) / (2 * d.sigma ** 2)
        for i, j in rel.pairs:
            assert np.exp(-d2[i, j] / 2) >= 0.01 and pi[i, j] >= tau


def test_md2da_tau_zero_is_rectangular_assignment():
    rng = np.random.default_rng(6)
    for _ in range(10):
        d = Zhang2009(p_d=0.6).simulate(rng)
        obs = d.observations
        rel = md_2da(matching_matrix(obs, NCR), obs.sensor, tau=0.0).relations
        assert len(rel.pairs) == min((obs.sensor == 1).sum(), (obs.sensor == 2).sum())


@pytest.mark.parametrize("cost", ["linear", "log"])
@pytest.mark.parametrize("name", [installed(n) for n in EXACT])
def test_md2da_every_exact_backend_gives_the_same_decisions(name, cost):
    rng = np.random.default_rng(21)
    tau = gate_threshold(NCR)
    for run in range(6):
        d = Zhang2009(f=0.4, p_d=0.8).simulate(rng)
        obs = d.observations
        pi = matching_matrix(obs, NCR)
        ref = md_2da(pi, obs.sensor, tau=tau, cost=cost, solver="scipy-lsa")
        res = md_2da(pi, obs.sensor, tau=tau, cost=cost, solver=name)
        assert res.relations == ref.relations, (name, run, res.solution)
        assert res.solution.objective == pytest.approx(ref.solution.objective, abs=1e-7)


def _experiment_trials(f: float, n: int):
    """The first ``n`` simulated runs of the f sweep of the committed experiment at ``f``
    (their measures pi, sensors and truths)."""
    from assocopt.experiments import trial_seed
    from assocopt.reproduce import zhang2009 as repro
    from assocopt.reproduce.zhang2009.experiment import _measure_params
    exp = repro.experiments(1, 0, parts=("main",))[0]
    st = [s for s in exp.settings if s["sweep"] == "f" and s["f"] == f][0]
    params = _measure_params(st, "ncr", st["same_sensor"])
    for t in range(n):
        rng = np.random.default_rng(trial_seed(0, st, t))
        d = Zhang2009(f=f, p_d=st["p_d"], region=tuple(st["region"])).simulate(rng)
        yield matching_matrix(d.observations, params), d.observations.sensor, d.truth


@pytest.mark.parametrize("name", [installed(n) for n in EXACT] + ["auto"])
def test_md2da_tau_zero_same_accuracy_on_every_exact_backend(name):
    """tau = 0 has no non-assignment option (a tie between "unpaired" and "paired at
    pi = 0" would leave the answer to each back end's tie rule): on the experiment's own
    runs at f = 0.05 and 0.3 every exact back end decides min(N1, N2) pairs with the
    same accuracy as scipy-lsa."""
    from assocopt.tracking.belief.group_matching import correct_match_rate
    for f in (0.05, 0.3):
        for pi, sensor, truth in _experiment_trials(f, 8):
            ref = md_2da(pi, sensor, tau=0.0, solver="scipy-lsa")
            res = md_2da(pi, sensor, tau=0.0, solver=name)
            assert len(res.relations.pairs) == min((sensor == 1).sum(), (sensor == 2).sum())
            assert res.solution.objective == pytest.approx(ref.solution.objective, abs=1e-9)
            assert (correct_match_rate(res.relations, truth) ==
                    correct_match_rate(ref.relations, truth)), (name, f)


def test_md2da_bruteforce_agrees_on_small_scenarios():
    rng = np.random.default_rng(9)
    for _ in range(6):
        d = Zhang2009(f=0.4, p_d=0.4, n_targets=6).simulate(rng)
        obs = d.observations
        pi = matching_matrix(obs, NCR)
        tau = gate_threshold(NCR)
        ref = md_2da(pi, obs.sensor, tau=tau, solver="highs").relations
        assert md_2da(pi, obs.sensor, tau=tau, solver="bruteforce").relations == ref


def test_md2da_with_one_sensor_empty():
    pi = np.array([[np.nan, .4], [.4, np.nan]])
    rel = md_2da(pi, [2, 2], tau=0.1).relations
    assert rel.pairs == () and rel.isolated == (0, 1)


# ------------------------------------------- every random scenario: a partition
@pytest.mark.parametrize("measure", ["ncr", "tbm", "wa"])
def test_every_observation_in_exactly_one_relation_on_random_scenarios(measure):
    rng = np.random.default_rng(13)
    params = MeasureParams(measure, r_p=1.0, r_a=0.6)
    options = [TruncationOptions(), TruncationOptions(ordering="dendrogram"),
               TruncationOptions(visited="endpoints", traversed="after_step")]
    for f, p_d in itertools.product((0.05, 0.3, 1.0), (0.3, 0.7, 1.0)):
        sc = Zhang2009(f=f, p_d=p_d)
        for _ in range(5):
            d = sc.simulate(rng)
            obs = d.observations
            pi = matching_matrix(obs, params)
            for opt in options:
                rel = md_nd(pi, obs.sensor, opt)            # Relations asserts the partition
                assert rel.n == obs.n
            rel = md_2da(pi, obs.sensor, tau=gate_threshold(params)).relations
            assert rel.n == obs.n


def test_low_noise_full_detection_is_mostly_correct():
    from assocopt.tracking.belief.group_matching import correct_match_rate
    rng = np.random.default_rng(17)
    sc = Zhang2009(f=0.02, p_d=1.0)
    rates = []
    for _ in range(20):
        d = sc.simulate(rng)
        pi = matching_matrix(d.observations, NCR)
        rates.append(correct_match_rate(md_nd(pi, d.observations.sensor), d.truth))
    assert np.mean(rates) > 0.9


# ------------------------------------------------------------- reproduction
def test_reproduction_writes_summary_tables_and_resumes(tmp_path):
    import json
    from assocopt.reproduce import zhang2009 as repro
    printed = []
    # one enumerating run per P_d, stopped at 500000 nodes (the enumeration was 85 % of
    # the run's time; with seed 3 the runs at P_d >= 0.8 stop, the others finish)
    few = {"enum_runs": 1, "enum_max_nodes": 500_000}
    s = repro.run(2, 1, 3, tmp_path, options=few, echo=printed.append)
    data = json.loads((tmp_path / "summary.json").read_text())
    assert data["paper"] == "zhang2009" and data["runs"] == 2
    assert "f_grid" in data["parameters"]["ours"]["ours"]
    rec = data["records"][0]
    assert {"setting", "method", "metric", "value", "runs", "experiment"} <= set(rec)
    exps = {r["experiment"] for r in data["records"]}
    assert exps == {"main", "weights", "table1", "table1-enum", "sensitivity"}
    assert all(r["runs"] == (1 if r["experiment"] == "table1-enum" else 2)
               for r in data["records"] if r["metric"] == "correct_rate")
    text = printed[0]
    # the paper's Table 1 in the paper's own digits (not rounded to 3 figures)
    assert "| paper: MD-2DA | 0.0046 | 0.0187 | 0.0635 | 0.2404 | 0.6176 | 0.8699 |" in text
    assert "| paper: MD-ND | 0.00087 | 0.000978 | 0.0013 | 0.0013 | 0.0017 | 0.0023 |" in text
    assert "(derived)" in text and "Fig. 3" in text
    assert text == repro.render_tables(data)          # tables.md is a function of summary.json
    for f in s["figures"]:
        assert (tmp_path / f).stat().st_size > 0
    again = repro.run(2, 1, 3, tmp_path, options=few, echo=lambda t: None)
    assert all(v["done"] == 0 for v in again["timing"].values())
    # the resumed run computed nothing: the history keeps the first invocation only
    assert [h["runs"] for h in again["timing_history"]] == [2]
    assert again["timing_history"][0]["experiments"] == s["timing"]
    stored = again["trial_seconds"]
    assert set(stored) == set(s["timing"]) and all(t["trials"] > 0 for t in stored.values())
    stable = lambda recs: sorted((json.dumps(r["setting"], sort_keys=True), r["method"],
                                  r["metric"], r["value"]) for r in recs if not r["volatile"])
    assert stable(again["records"]) == stable(s["records"])


def test_reproduction_same_numbers_with_two_workers(tmp_path):
    from assocopt.reproduce import zhang2009 as repro
    one = repro.run(3, 1, 5, tmp_path / "a", parts=("weights",), echo=lambda t: None)
    two = repro.run(3, 2, 5, tmp_path / "b", parts=("weights",), echo=lambda t: None)
    pick = lambda s: sorted((r["setting"]["k"], r["method"], r["metric"], r["value"])
                            for r in s["records"] if not r["volatile"])
    assert pick(one) == pick(two)


def test_a_run_of_some_parts_keeps_the_others_from_the_summary(tmp_path):
    """Rerunning only the parts whose code changed keeps the other parts' records (and
    their paired rows and compute times) from the folder's summary.json, in part order;
    a summary of another seed is refused."""
    from assocopt.reproduce import zhang2009 as repro
    quiet = lambda t: None
    full = repro.run(2, 1, 3, tmp_path, parts=("weights", "sensitivity"), echo=quiet)
    (tmp_path / "zhang2009-sensitivity.sqlite").unlink()       # recomputed from scratch
    again = repro.run(2, 1, 3, tmp_path, parts=("sensitivity",), echo=quiet)
    assert again["kept_parts"] == ["main", "weights", "table1", "table1-enum"]
    stable = lambda recs: [r for r in recs if not r["volatile"]]      # timings vary
    assert stable(again["records"]) == stable(full["records"]) and stable(full["records"])
    assert again["paired"] == full["paired"]
    assert set(again["trial_seconds"]) == {"zhang2009-weights", "zhang2009-sensitivity"}
    with pytest.raises(ValueError, match="other runs, seed or parameters"):
        repro.run(2, 1, 4, tmp_path, parts=("sensitivity",), echo=quiet)
    with pytest.raises(ValueError, match="unknown zhang2009 part"):
        repro.experiments(2, 0, parts=("table2",))


def test_reproduction_rejects_unknown_options():
    from assocopt.reproduce import zhang2009 as repro
    with pytest.raises(ValueError, match="unknown zhang2009 option"):
        repro.experiments(2, 0, {"bogus": 1})


# ------------------------------------------------------- pinned reproduced numbers
def test_pinned_trials_at_a_small_seeded_run():
    """Eight seeded runs of the f sweep at f = 0.3: P_c of every method of the main
    experiment, pinned when the reproduction was run, and one enumerated MD-2DA."""
    from assocopt.experiments import trial_seed
    from assocopt.reproduce import zhang2009 as repro
    exps = {e.name: e for e in repro.experiments(1, 0)}
    st = [s for s in exps["zhang2009-main"].settings if s["sweep"] == "f" and s["f"] == 0.3][0]
    got = {m: [] for m in repro.MAIN_METHODS}
    for t in range(8):
        r = repro.trial(st, list(got), trial_seed(0, st, t))
        for m in got:
            got[m].append(r[m]["correct_rate"])
    want = {
        "tbm+nd": [1.0, 6 / 7, 8 / 9, 1.0, 5 / 9, 1.0, 8 / 9, 6 / 7],
        "ncr+nd": [1.0, 1.0, 1.0, 1.0, 5 / 9, 1.0, 8 / 9, 6 / 7],
        "ncr+2da": [1.0, 1.0, 1.0, 1.0, 7 / 9, 1.0, 1.0, 1.0],
        "ncr+2da-rect": [5 / 7, 5 / 7, 7 / 9, 1.0, 2 / 3, 1.0, 5 / 9, 5 / 7]}
    assert set(got) == set(want)
    for m in want:                   # approx takes no nested containers (pytest >= 9.1)
        assert got[m] == pytest.approx(want[m], rel=1e-12), m
    st2 = exps["zhang2009-table1-enum"].settings[0]
    r = repro.trial(st2, ["ncr+2da-enum"], trial_seed(0, st2, 0))["ncr+2da-enum"]
    assert (r["stopped"], r["n_feasible"], r["correct_rate"]) == (0.0, 229.0, 1.0)


def test_enumeration_reports_a_stopped_run():
    from assocopt.experiments import trial_seed
    from assocopt.reproduce import zhang2009 as repro
    st = dict(repro.experiments(1, 0, {"enum_max_nodes": 50})[-2].settings[-1])
    assert st["p_d"] == 1.0 and st["enum_max_nodes"] == 50
    r = repro.trial(st, ["ncr+2da-enum"], trial_seed(0, st, 0))["ncr+2da-enum"]
    assert r["stopped"] == 1.0 and r["correct_rate"] is None and r["t_decide_finished"] is None


def test_expected_matchings_against_enumeration():
    """The derived Table 1 rows: closed form against brute-force counting."""
    import itertools
    import math
    from assocopt.reproduce.zhang2009.report import expected_matchings

    def count(a, b):
        n = 0
        for k in range(min(a, b) + 1):
            n += sum(1 for _ in itertools.combinations(range(a), k)) * math.perm(b, k)
        return n
    n, p = 4, 0.6
    pmf = [math.comb(n, k) * p ** k * (1 - p) ** (n - k) for k in range(n + 1)]
    feas = sum(pmf[a] * pmf[b] * count(a, b) for a in range(n + 1) for b in range(n + 1))
    comp = sum(pmf[a] * pmf[b] * len(list(itertools.permutations(range(max(a, b)), min(a, b))))
               for a in range(n + 1) for b in range(n + 1))
    assert expected_matchings(p, n) == pytest.approx((feas, comp), rel=1e-12)


def test_covariance_scale_is_a_real_parameter():
    from assocopt.tracking.scenarios.zhang2009 import Zhang2009
    a = Zhang2009(f=0.3, p_d=1.0).simulate(np.random.default_rng(4))
    b = Zhang2009(f=0.3, p_d=1.0, covariance_scale=4.0).simulate(np.random.default_rng(4))
    assert np.allclose(a.observations.positions, b.observations.positions)
    assert np.allclose(4 * a.observations.covariances, b.observations.covariances)
    with pytest.raises(ValueError, match="covariance_scale"):
        Zhang2009(covariance_scale=0.0)


def test_committed_summary_regenerates_from_the_code(tmp_path):
    """Recompute one point of the committed run from scratch (Exp. 1b, k = 1, its full
    run count) and compare with docs/papers/zhang2009/summary.json exactly."""
    from assocopt.reproduce import zhang2009 as repro
    rows, recs = rerun_committed(repro, "zhang2009", "weights", lambda s: s["k"] == 1,
                                 tmp_path / "w.sqlite")
    mine = {(r["method"], r["metric"]): r["value"] for r in rows}
    committed = {(r["method"], r["metric"]): r["value"] for r in recs if not r["volatile"]}
    assert committed and {k: mine[k] for k in committed} == pytest.approx(committed, rel=1e-12)
