"""Paper 004 in the paper's own reading (rectangular assignment, then the gate; the
reference pair in or out of lambda) and with each change of ours on top: pinned small
seeded runs, the shared assignment giving the same numbers as solving each reading
alone, the calibration metric against a per-pair loop, and environment 1's slot
shares."""

from __future__ import annotations

import numpy as np
import pytest

from assocopt.tracking.decide.topology import TopologyParams, pair_gammas, prepare
from assocopt.tracking.scenarios.dong2015 import Dong2015, Run
from assocopt.tracking.scenarios.dong2015_assoc import (METHODS, calibration, run_method,
                                                         slot_shares)
from assocopt.tracking.costs.topology import chi2_gate

PINNED = {   # E_c at steps 1..6, in eighths (8 common targets)
    "tsd-rect": [5, 2, 4, 4, 3, 4],
    "tsd-rect-noself": [5, 1, 3, 3, 1, 3],
    "tsd-rect-global": [4, 1, 3, 3, 3, 4],
    "tsd-rect-noself-global": [3, 1, 2, 2, 1, 3],
    "tsd-rect-t1": [2, 1, 3, 3, 5, 5],
    "tsd-rect-noself-t1": [2, 1, 3, 3, 3, 4],
    "tsd-rect-obj": [5, 3, 4, 4, 5, 5],
    "tsd-rect-refcov": [0, 0, 0, 0, 0, 1],
    "tsd-rect-inflate": [1, 0, 0, 0, 0, 0],
    "tsd-rect-c": [6, 5, 6, 6, 8, 8],
    "tsd-rect-noself-c": [6, 5, 6, 6, 8, 8],
    "ted-rect": [6, 0, 1, 0, 0, 1],
    "ted-rect-noself": [4, 2, 4, 4, 2, 3],
}


@pytest.fixture(scope="module")
def small_run() -> Run:
    run = Dong2015(env=3, n_targets=12, missed=2, false_tracks=2,
                   n_steps=6).simulate(np.random.default_rng(5))
    assert run.n_common == 8
    return run


def test_pinned_small_seeded_run_of_each_reading(small_run):
    cache: dict = {}
    for m, want in PINNED.items():
        alone = run_method(small_run, m)
        shared = run_method(small_run, m, cache=cache)
        got = [alone[f"ec_k{k:02d}"] for k in range(1, 7)]
        assert got == pytest.approx([w / 8 for w in want]), m
        for key, value in alone.items():           # sharing changes no number
            if key != "t_step_ms":
                assert shared[key] == pytest.approx(value, nan_ok=True), (m, key)


def test_paper_readings_are_rectangular_and_differ_only_in_the_self_pair():
    assert METHODS["tsd-rect"]["assignment"] == "rectangular"
    assert TopologyParams(assignment="rectangular").self_pair == "include"
    assert METHODS["tsd-rect-noself"]["self_pair"] == "exclude"
    for m in ("tsd-rect-obj", "tsd-rect-refcov", "tsd-rect-inflate"):
        changed = {k for k in METHODS[m] if k not in ("assignment", "calibrate")}
        assert len(changed) == 1, m                 # one change of ours at a time
    for base in ("tsd-rect", "tsd-rect-noself"):  # global trial pairs, T_1 stand-in
        for extra, change in (("-global", {"trial": "assignment"}),
                              ("-t1", {"threshold": "heading"})):
            assert METHODS[base + extra] == {
                **{k: v for k, v in METHODS[base].items() if k != "calibrate"}, **change}


def test_calibration_against_a_loop_over_true_pairs(small_run):
    truth = small_run.truth_partner()
    gate = chi2_gate(0.01, 4)
    st = small_run.steps[3]
    for kw in ({}, {"ref_cov": True}, {"inflate": True}):
        p = TopologyParams(assignment="rectangular", **kw)
        inp = prepare(st.X1, st.P1, st.X2, st.P2, p)
        vals = [pair_gammas(inp, p, u, truth[u])[i, truth[i]]
                for u in np.flatnonzero(truth >= 0) for i in np.flatnonzero(truth >= 0)
                if i != u]
        mean, share = calibration(inp, p, truth, gate)
        assert mean == pytest.approx(np.mean(vals), rel=1e-9)
        assert share == pytest.approx(np.mean(np.array(vals) <= gate))


def test_slot_shares_count_offsets_along_the_formation():
    run = Run(steps=[], ids1=np.array([0, 1, 2, 3, -1]), ids2=np.array([3, 2, 1, 0, -2]),
              true_heading1=np.zeros((1, 5)), true_heading2=np.zeros((1, 5)))
    trial = np.array([3, 1, 3, 4, 0])       # true, 1 off, 2 off, a false track, (false)
    partner = np.array([2, -1, 0, 0, -1])   # 1 off, none, 1 off, true
    s = slot_shares(run, trial, partner)
    assert s == {"tr0": 0.25, "tr12": 0.5, "dec12": 0.5}


def test_environment_1_reports_the_slot_shares_per_step():
    run = Dong2015(env=1, n_targets=10, n_steps=4).simulate(np.random.default_rng(2))
    r = run_method(run, "tsd-rect", {"env": 1})
    for k in range(1, 5):
        t0, t12 = r[f"tr0_k{k:02d}"], r[f"tr12_k{k:02d}"]
        assert 0 <= t0 <= 1 and 0 <= t12 <= 1 and t0 + t12 <= 1
    assert [r[f"tr0_k{k:02d}"] for k in range(1, 5)] == pytest.approx([0.8, 0.6, 0.6, 0.8])
    assert "tr0_k01" not in run_method(run, "tsd-rect", {"env": 2})
