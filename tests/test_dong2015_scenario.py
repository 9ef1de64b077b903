"""Paper 004's scenario (two biased radars, local Kalman trackers) and the methods run
over it: common observation rate, heading convergence, bias invariance of the
topology decision, and a pinned small seeded run."""

from __future__ import annotations

import math

import numpy as np
import pytest

from assocopt.tracking.decide.topology import TopologyParams, phi_matrix, prepare
from assocopt.tracking.scenarios.dong2015 import Dong2015
from assocopt.tracking.scenarios.dong2015_assoc import METHODS, run_method
from assocopt.tracking.costs.topology import headings


def test_environments_geometry_and_common_observation_rate():
    r1 = Dong2015(env=1).simulate(np.random.default_rng(0))
    assert r1.n_common == 30 and r1.common_observation_rate == 1.0
    r3 = Dong2015(env=3).simulate(np.random.default_rng(0))
    assert (len(r3.ids1), len(r3.ids2), r3.n_common) == (30, 30, 20)
    assert r3.common_observation_rate == pytest.approx(0.5)
    tp = r3.truth_partner()
    assert (tp >= 0).sum() == 20 and (r3.ids2[tp[tp >= 0]] == r3.ids1[tp >= 0]).all()
    # env 1: 400 m/s, heading 60 degrees clockwise from north, at the first step
    st = r1.steps[-1]
    assert np.median(np.hypot(st.X1[:, 2], st.X1[:, 3])) == pytest.approx(400, abs=10)
    assert np.nanmedian(r1.true_heading1) == pytest.approx(math.radians(60))
    with pytest.raises(ValueError, match="env"):
        Dong2015(env=4)


def test_heading_error_converges():
    errs = []
    for seed in range(3):
        run = Dong2015(env=2).simulate(np.random.default_rng(seed))
        errs.append([np.nanmean(np.abs((headings(s.X2) - run.true_heading2[k] + math.pi)
                                       % (2 * math.pi) - math.pi))
                     for k, s in enumerate(run.steps)])
    e = np.mean(errs, 0)
    assert e[0] > 0.2 and e[5] < 0.1 and e[-1] < e[3]


def _biased(bias_az):
    return Dong2015(env=2, bias_r=(0.0, 0.0), bias_az_deg=bias_az)


def test_azimuth_bias_leaves_the_topology_decision_unchanged():
    """Same noise draws, with and without azimuth biases (range bias 0): every gamma,
    hence every lambda and decision, is the same to rounding; the position baseline
    is not."""
    a = _biased((0.0, 0.0)).simulate(np.random.default_rng(11))
    b = _biased((2.0, -2.0)).simulate(np.random.default_rng(11))
    p = TopologyParams(degree="objective", inflate=True, ref_cov=True)
    for sa, sb in zip(a.steps[2::4], b.steps[2::4]):
        pa, _ = phi_matrix(prepare(sa.X1, sa.P1, sa.X2, sa.P2, p), p)
        pb, _ = phi_matrix(prepare(sb.X1, sb.P1, sb.X2, sb.P2, p), p)
        assert np.allclose(pa, pb, rtol=1e-6)
    for m in ("tsd", "tsd-c"):
        ra, rb = run_method(a, m), run_method(b, m)
        assert all(ra[f"ec_k{k:02d}"] == rb[f"ec_k{k:02d}"] for k in range(1, 13)), m
    ga, gb = run_method(a, "gnn"), run_method(b, "gnn")
    assert ga["ec_mean"] > 0.9 and gb["ec_mean"] < 0.1


def test_run_method_refuses_unknown_methods():
    run = Dong2015(env=2, n_targets=4, n_steps=2).simulate(np.random.default_rng(0))
    with pytest.raises(ValueError, match="unknown dong2015 method"):
        run_method(run, "fuzzy")


def test_pinned_small_seeded_run():
    run = Dong2015(env=3, n_targets=12, missed=2, false_tracks=2,
                   n_steps=6).simulate(np.random.default_rng(5))
    assert run.n_common == 8
    got = {m: [run_method(run, m)[f"ec_k{k:02d}"] for k in range(1, 7)]
           for m in ("tsd", "tsd-c", "ted-obj", "gnn")}
    pinned = {"tsd": [0, 0, 0, 0, 0, 0], "tsd-c": [7 / 8, 5 / 8, 1, 1, 1, 1],
              "ted-obj": [4 / 8, 3 / 8, 5 / 8, 5 / 8, 4 / 8, 5 / 8], "gnn": [0, 0, 0, 0, 0, 0]}
    for m, want in pinned.items():
        assert got[m] == pytest.approx(want), m


def test_every_method_runs_and_reports_each_step():
    run = Dong2015(env=3, n_targets=8, missed=1, false_tracks=1,
                   n_steps=3).simulate(np.random.default_rng(1))
    for m in METHODS:
        r = run_method(run, m)
        assert {f"ec_k{k:02d}" for k in (1, 2, 3)} <= set(r)
        assert all(0 <= r[f"ec_k{k:02d}"] <= 1 for k in (1, 2, 3))
