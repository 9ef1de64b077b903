"""Matching measures of paper 000 (MM-NCR, MM-TBM, MM-WA) in bulk: the chi-square
p-value form of m^p, the sum to 1, the closed forms on {M, Mbar}, agreement with the
one-at-a-time belief API, and relation bookkeeping."""

from __future__ import annotations

import itertools

import numpy as np
import pytest
from hypothesis import given, strategies as st
from scipy.stats import chi2

from assocopt.tracking.belief import (MassFunction, conjunctive, discount, zhang_combination,
                             zhang_conflict, conflict)
from assocopt.tracking.belief.group_matching import (MATCH_FRAME, InvalidObservationsError, MeasureParams,
                                     Observations, Relations, attribute_conflict,
                                     combined_masses, correct_match_rate, matching_matrix,
                                     mm_ncr, mm_tbm, mm_wa, position_belief,
                                     squared_mahalanobis, true_relations)

TYPES = ("t1", "t2", "t3")
unit = st.floats(0.0, 1.0)


def _random_obs(rng, n1=3, n2=4, types=TYPES):
    n = n1 + n2
    P = rng.normal(size=(n, 2)) * 3
    L = rng.normal(size=(n, 2, 2))
    C = L @ L.transpose(0, 2, 1) + 0.5 * np.eye(2)
    A = rng.random((n, 1 << len(types))) * (rng.random((n, 1 << len(types))) < 0.5)
    A[:, -1] += 0.1
    A[:, 0] = 0.0
    A /= A.sum(axis=1, keepdims=True)
    return Observations(P, C, A, np.r_[np.ones(n1, int), np.full(n2, 2)], types)


def test_squared_mahalanobis_matches_explicit_inverse():
    rng = np.random.default_rng(3)
    obs = _random_obs(rng)
    d2 = squared_mahalanobis(obs.positions, obs.covariances, obs.positions, obs.covariances)
    for i, j in itertools.product(range(obs.n), repeat=2):
        diff = obs.positions[i] - obs.positions[j]
        S = obs.covariances[i] + obs.covariances[j]
        assert d2[i, j] == pytest.approx(diff @ np.linalg.inv(S) @ diff, rel=1e-10, abs=1e-12)


def test_position_belief_is_chi2_survival_function():   # m^p = chi-square(2) p-value
    d2 = np.linspace(0, 30, 61)
    assert np.allclose(position_belief(d2), chi2.sf(d2, 2), rtol=1e-12, atol=0)
    assert position_belief(0.0) == 1.0


def _closed_forms(p_m, K, r_p, r_a):
    p1, p0, pT = r_p * p_m, r_p * (1 - p_m), 1 - r_p
    a1, a0, aT = r_a * (1 - K), r_a * K, 1 - r_a
    return p1, p0, pT, a1, a0, aT


@given(unit, unit, unit, unit)
def test_ncr_masses_equal_closed_form_d04(p_m, K, r_p, r_a):
    p1, p0, pT, a1, a0, aT = _closed_forms(p_m, K, r_p, r_a)
    m = combined_masses(np.array(p_m), np.array(K), r_p=r_p, r_a=r_a, rule="zhang")
    assert m[1] == pytest.approx(p1 * a1 + (p1 * aT + pT * a1) / 2, abs=1e-12)
    assert m[2] == pytest.approx(p0 * a0 + (p0 * aT + pT * a0) / 2, abs=1e-12)
    assert m[3] == pytest.approx(pT * aT / 2, abs=1e-12)
    assert m[0] == pytest.approx(p1 * a0 + p0 * a1 + (p1 * aT + pT * a1 + p0 * aT + pT * a0) / 2
                                 + pT * aT / 2, abs=1e-12)
    assert m.sum() == pytest.approx(1.0, abs=1e-12)                       # sums to 1
    assert mm_ncr(p_m, K, r_p, r_a) == pytest.approx(m[1], abs=1e-15)


@given(unit, unit, unit, unit)
def test_tbm_and_wa_equal_closed_form(p_m, K, r_p, r_a):
    p1, p0, pT, a1, a0, aT = _closed_forms(p_m, K, r_p, r_a)
    assert mm_tbm(p_m, K, r_p, r_a) == pytest.approx(p1 * a1 + p1 * aT + pT * a1, abs=1e-12)
    m = combined_masses(np.array(p_m), np.array(K), r_p=r_p, r_a=r_a, rule="conjunctive")
    assert m.sum() == pytest.approx(1.0, abs=1e-12)
    assert m[0] == pytest.approx(p1 * a0 + p0 * a1, abs=1e-12)
    assert mm_wa(p_m, K, r_p, r_a) == pytest.approx(r_p * p_m + r_a * (1 - K), abs=1e-12)


def test_erratum_e06_using_attribute_conflict_on_empty_set_breaks_sum():
    # eq. (11) as printed (K^a on the empty set) does not sum to 1; K^pa does.
    p_m, K, r_p, r_a = 0.7, 0.4, 1.0, 0.6
    m = combined_masses(np.array(p_m), np.array(K), r_p=r_p, r_a=r_a, rule="zhang")
    assert m.sum() == pytest.approx(1.0)
    assert m[1:].sum() + K != pytest.approx(1.0)


def _scalar_pi(obs, i, j, params):
    """pi through the one-at-a-time MassFunction API with element names."""
    ai = MassFunction.from_vector(obs.types, obs.attributes[i])
    aj = MassFunction.from_vector(obs.types, obs.attributes[j])
    diff = obs.positions[i] - obs.positions[j]
    S = obs.covariances[i] + obs.covariances[j]
    pm = float(np.exp(-0.5 * diff @ np.linalg.inv(S) @ diff))
    K = zhang_conflict(ai, aj) if params.measure != "tbm" else conflict(ai, aj)
    if params.measure == "wa":
        return params.w_p * pm + params.w_a * (1 - K)
    M, Mb = frozenset({"M"}), frozenset({"Mbar"})
    mp = discount(MassFunction(MATCH_FRAME, {M: pm, Mb: 1 - pm}), params.r_p)
    ma = discount(MassFunction(MATCH_FRAME, {M: 1 - K, Mb: K}), params.r_a)
    rule = zhang_combination if params.measure == "ncr" else conjunctive
    return rule(mp, ma)[M]


@pytest.mark.parametrize("params", [MeasureParams("ncr", r_p=1.0, r_a=0.6),
                                    MeasureParams("ncr", r_p=0.4, r_a=0.9),
                                    MeasureParams("tbm", r_p=0.8, r_a=0.6),
                                    MeasureParams("wa", w_p=0.3, w_a=0.7)])
def test_matching_matrix_equals_pairwise_belief_api(params):
    obs = _random_obs(np.random.default_rng(7))
    pi = matching_matrix(obs, params)
    assert np.isnan(np.diag(pi)).all()
    assert np.allclose(pi, pi.T, equal_nan=True)
    for i, j in itertools.permutations(range(obs.n), 2):
        assert pi[i, j] == pytest.approx(_scalar_pi(obs, i, j, params), abs=1e-12)


def test_same_sensor_reading_zero():
    obs = _random_obs(np.random.default_rng(1))
    pi = matching_matrix(obs, same_sensor="zero")
    same = obs.sensor[:, None] == obs.sensor[None, :]
    off = ~np.eye(obs.n, dtype=bool)
    assert (pi[same & off] == 0).all() and (pi[~same] > 0).all()


def test_attribute_conflict_kinds():
    obs = _random_obs(np.random.default_rng(2))
    A = obs.attributes
    new, old = attribute_conflict(A, A, "new"), attribute_conflict(A, A, "traditional")
    assert (new >= old - 1e-12).all()
    with pytest.raises(ValueError, match="kind"):
        attribute_conflict(A, A, "other")


@pytest.mark.parametrize("kw, match", [
    (dict(positions=np.zeros((2, 3))), "positions"),
    (dict(covariances=-np.ones((2, 2, 2))), "positive definite"),
    (dict(attributes=np.full((2, 8), 0.2)), "sum to"),
    (dict(sensor=np.array([1, 3])), "sensor"),
    (dict(positions=np.array([[0, np.nan], [0, 0]])), "NaN"),
])
def test_observations_validation(kw, match):
    base = dict(positions=np.zeros((2, 2)), covariances=np.stack([np.eye(2)] * 2),
                attributes=np.eye(8)[[7, 7]], sensor=np.array([1, 2]), types=TYPES)
    base.update(kw)
    with pytest.raises(InvalidObservationsError, match=match):
        Observations(**base)


def test_measure_params_validation():
    with pytest.raises(ValueError, match="measure"):
        MeasureParams("xyz")
    with pytest.raises(ValueError, match="r_a"):
        MeasureParams(r_a=1.5)


# ------------------------------------------------------------------ relations
def test_relations_partition_is_checked():
    sensor = [1, 1, 2, 2]
    rel = Relations.from_clusters([(2, 0), (1,), (3,)], sensor)
    assert rel.pairs == ((0, 2),) and rel.isolated == (1, 3)
    with pytest.raises(AssertionError, match="exactly one"):
        Relations.from_clusters([(0, 2), (2,), (1,), (3,)], sensor)
    with pytest.raises(AssertionError, match="exactly one"):
        Relations.from_clusters([(0, 2), (1,)], sensor)
    with pytest.raises(AssertionError, match="sensor"):
        Relations.from_clusters([(0, 1), (2,), (3,)], sensor)


def test_true_relations_and_correct_match_rate():
    target = [5, 3, 5, 7]            # obs 0 (s1) and 2 (s2) see target 5
    sensor = [1, 1, 2, 2]
    truth = true_relations(target, sensor)
    assert truth.pairs == ((0, 2),) and truth.isolated == (1, 3)
    assert correct_match_rate(truth, truth) == 1.0
    wrong = Relations.from_clusters([(0, 3), (1, 2)], sensor)
    assert correct_match_rate(wrong, truth) == 0.0
    half = Relations.from_clusters([(0,), (2,), (1,), (3,)], sensor)
    assert correct_match_rate(half, truth) == pytest.approx(2 / 3)
    empty = Relations.from_clusters([], [])
    assert correct_match_rate(empty, true_relations([], [])) == 1.0
