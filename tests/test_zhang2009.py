"""Paper 000 end to end: the scenario simulator, MD-2DA through every back end, and
both decision rules on random scenarios (each observation in exactly one relation)."""

from __future__ import annotations

import itertools

import numpy as np
import pytest

from assocopt.tracking.belief import MassFunction, pignistic
from assocopt.tracking.decide import (TruncationOptions, gate_threshold, md_2da, md_2da_problem,
                                      md_nd)
from assocopt.tracking.group_matching import MeasureParams, matching_matrix
from assocopt.tracking.scenarios.zhang2009 import Zhang2009, confusion_sets, mean_nearest_distance

from conftest import EXACT, installed

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
    from assocopt.tracking.group_matching import correct_match_rate
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
    s = repro.run(2, 1, 3, tmp_path, echo=printed.append)
    data = json.loads((tmp_path / "summary.json").read_text())
    assert data["paper"] == "zhang2009" and data["runs"] == 2
    assert data["paper_values"]["table1"]["MD-2DA"][0] == 0.0046
    assert "f_grid" in data["parameters"]["ours"]["ours"]
    rec = data["records"][0]
    assert {"setting", "method", "metric", "value", "runs", "experiment"} <= set(rec)
    exps = {r["experiment"] for r in data["records"]}
    assert exps == {"main", "weights", "table1", "sensitivity"}
    assert all(r["runs"] == 2 for r in data["records"] if r["metric"] == "correct_rate")
    text = printed[0]
    assert "paper: MD-2DA | 0.0046" in text and "Fig. 3" in text
    for f in s["figures"]:
        assert (tmp_path / f).stat().st_size > 0
    again = repro.run(2, 1, 3, tmp_path, echo=lambda t: None)
    assert all(v["done"] == 0 for v in again["timing"].values())
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


def test_reproduction_rejects_unknown_options():
    from assocopt.reproduce import zhang2009 as repro
    with pytest.raises(ValueError, match="unknown zhang2009 option"):
        repro.experiments(2, 0, {"bogus": 1})
