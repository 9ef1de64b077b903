"""Paper 001 with partial coverage: the scenario options (single-node emitters, TDOA
noise scale, class defaults), the two correct-association rates, and the bulk pieces
the grid relies on (statistical distance, shared feature degrees)."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings, strategies as st

from assocopt.reproduce.yan2010.experiment import (DEFAULTS, FEATURE_SETS, experiments,
                                                   scenario_of, trial, _common)
from assocopt.reproduce.yan2010.setting import SCENARIO_KEYS as _SCENARIO_KEYS
from assocopt.reproduce.yan2010.scoring import rates
from assocopt.tracking.costs.association_degree import (DegreeParams, pair_feature_degrees,
                                                        statistical_distance)
from assocopt.tracking.decide.max_degree import DecisionOptions, TrackAssociator
from assocopt.tracking.scenarios.yan2010 import Yan2010


# ------------------------------------------------------------------ scenario
def test_class_defaults_equal_the_reproductions():
    sc = Yan2010()
    for k in _SCENARIO_KEYS:
        v = DEFAULTS[k]
        assert getattr(sc, k) == (tuple(v) if isinstance(v, list) else v), k


@pytest.mark.parametrize("nodes", [2, 3])
def test_single_node_emitters(nodes):
    sc = Yan2010(n_targets=40, nodes=nodes, single_node_fraction=0.2, duration=6.0)
    run = sc.simulate(np.random.default_rng(7))
    seen = np.zeros((nodes, 40), int)
    for n, e in enumerate(run.emitter_of):
        assert len(np.unique(e)) == len(e)
        seen[n, e] = 1
    counts = seen.sum(axis=0)
    assert (counts == 1).sum() == 8 and (counts == nodes).sum() == 32   # round(0.2 * 40)
    assert np.array_equal(run.emitter_of[0], np.sort(run.emitter_of[0]))
    for n in range(nodes):
        p = run.partners[n]
        has = p >= 0
        assert np.array_equal(run.emitter_of[n][p[has]], run.emitter_of[0][has])
        assert np.array_equal(run.partners_between(0, n), p)
        assert np.all(~np.isin(run.emitter_of[0][~has], run.emitter_of[n]))
        assert run.x[n].shape == (6, len(run.emitter_of[n]), 4)
        assert run.features[n].shape == (6, len(run.emitter_of[n]), 3)
        # each node's track follows its emitter
        gap = np.linalg.norm(run.x[n][-1, :, :2] - run.truth[-1, run.emitter_of[n], :2], axis=1)
        assert np.median(gap) < 5e3
    assert np.array_equal(run.partner, run.partners[1])


def test_full_coverage_draws_are_unchanged_and_noise_scales():
    a = Yan2010(n_targets=10, duration=5.0).simulate(np.random.default_rng(3))
    b = Yan2010(n_targets=10, duration=5.0, single_node_fraction=0.0).simulate(
        np.random.default_rng(3))
    assert np.array_equal(a.x[1], b.x[1]) and np.array_equal(a.partner, b.partner)
    s1, s3 = Yan2010().systems(), Yan2010(tdoa_sigma_scale=3.0).systems()
    assert [s.sigma * 3 for s in s1] == pytest.approx([s.sigma for s in s3])
    with pytest.raises(ValueError, match="single_node_fraction"):
        Yan2010(single_node_fraction=1.5)
    with pytest.raises(ValueError, match="tdoa_sigma_scale"):
        Yan2010(tdoa_sigma_scale=0.0)


def test_per_emitter_features_overlap_grows_with_n():
    """With fixed bands, the share of emitters with a feature-compatible impostor grows."""
    def impostors(n):
        sc = scenario_of({**_common(DEFAULTS), **FEATURE_SETS["per-emitter"], "n": n})
        e = sc.emitters(np.random.default_rng(0))
        close = np.abs(e[:, None, 2] - e[None, :, 2]) < 0.27
        np.fill_diagonal(close, False)
        return close.any(axis=1).mean()
    assert impostors(100) > impostors(10) + 0.2


# ------------------------------------------------------------------ scoring
def _rates_loop(decided, truth, n2):
    common = [decided[i] == truth[i] for i in range(len(truth)) if truth[i] >= 0]
    ok = [decided[i] == truth[i] for i in range(len(truth))]
    for j in range(n2):
        takers = [i for i in range(len(decided)) if decided[i] == j]
        owner = [i for i in range(len(truth)) if truth[i] == j]
        ok.append(takers == owner)
    return (np.mean(common) if common else 1.0, np.mean(ok) if ok else 1.0)


@given(st.integers(0, 6), st.integers(0, 6), st.integers(0, 10 ** 6))
@settings(max_examples=80, deadline=None)
def test_rates_against_a_loop(n1, n2, seed):
    rng = np.random.default_rng(seed)
    truth = np.full(n1, -1)
    k = rng.integers(0, min(n1, n2) + 1)
    truth[rng.choice(n1, k, replace=False)] = rng.choice(n2, k, replace=False)
    decided = rng.integers(-1, n2, size=n1) if n2 else np.full(n1, -1)
    assert rates(decided, truth, n2) == pytest.approx(_rates_loop(decided, truth, n2))


def test_rates_rejects_bad_input():
    with pytest.raises(ValueError, match="one shape"):
        rates(np.array([0]), np.array([0, 1]), 2)
    with pytest.raises(ValueError, match="below n2"):
        rates(np.array([2]), np.array([0]), 2)


# ------------------------------------------------------------------ bulk pieces
def test_statistical_distance_against_solve_with_fallback():
    rng = np.random.default_rng(1)
    A = rng.normal(size=(5, 4, 4))
    p1 = A @ A.transpose(0, 2, 1) + 0.1 * np.eye(4)
    p2 = -p1[:3] + np.diag([3.0, -2.0, 1.0, 5.0])      # some sums indefinite, not singular
    p2[0] = p1[0]
    x1, x2 = rng.normal(size=(5, 4)), rng.normal(size=(3, 4))
    d = x1[:, None] - x2[None]
    ref = (d * np.linalg.solve(p1[:, None] + p2[None], d[..., None])[..., 0]).sum(-1)
    assert statistical_distance(x1, p1, x2, p2) == pytest.approx(ref, rel=1e-9)
    with pytest.raises(ValueError, match="singular"):
        statistical_distance(x1, np.zeros_like(p1), x2, np.zeros((3, 4, 4)))


def test_shared_feature_degrees_decide_the_same():
    rng = np.random.default_rng(2)
    params = DegreeParams(tolerances=(1.0, 0.1, 0.1))
    a, b = (TrackAssociator(6, 4, params, DecisionOptions(counter="floor", fix_at=2))
            for _ in range(2))
    for _ in range(5):
        D = rng.exponential(3.0, size=(6, 4))
        f1, f2 = rng.normal(size=(6, 3)) * 0.1, rng.normal(size=(4, 3)) * 0.1
        assert np.array_equal(a.step(D, f1, f2),
                              b.step(D, f1, f2, pair_feature_degrees(f1, f2, params)))


def test_grid_trial_pairs_the_rule_and_the_assignment():
    exp = next(e for e in experiments(1, 0, {"grid_n": (12,)}, parts=("grid",)))
    s = next(x for x in exp.settings if x["variant"] == "per-emitter, 20 % single")
    assert s["sparse"] and s["single_node_fraction"] == 0.2 and s["emitter_types"] == 0
    r = trial({**s, "duration": 10.0}, ["ds-max-nocounter", "ds-assign-nocounter"],
              np.random.SeedSequence(5))
    got = r["ds-assign-nocounter"]
    assert got["dall_5"] == pytest.approx(got["all_5"] - r["ds-max-nocounter"]["all_5"])
    assert set(r["ds-max-nocounter"]) >= {"correct_5", "all_5", "shared_5", "fixed_final"}
