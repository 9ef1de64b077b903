"""Paper 001's sensors: the linear TDOA fix (unbiased, with the stated covariance), the
Kalman filters (consistent on a straight-line target) and the scenario simulator."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.stats import chi2

from assocopt.tracking.filters import cv_model, nees, predict, two_point_init, update
from assocopt.tracking.localisation.tdoa import C_LIGHT, TdoaSystem
from assocopt.tracking.scenarios.yan2010 import Yan2010

S1 = TdoaSystem(main=(100e3, 0.0), baseline=25e3, sigma=30e-9)


def _band(dof_each: int, n: int, p: float = 0.999) -> tuple[float, float]:
    """Two-sided chi-square band of a mean of n NEES values of dof_each degrees."""
    lo, hi = chi2.ppf([(1 - p) / 2, (1 + p) / 2], dof_each * n)
    return lo / n, hi / n


def test_stations_and_noise_free_fix():
    st = S1.stations
    assert np.allclose(np.linalg.norm(st[1:] - st[0], axis=1), 25e3)
    u = (st[1:] - st[0]) / 25e3
    assert np.allclose(u @ u.T, [[1, -.5, -.5], [-.5, 1, -.5], [-.5, -.5, 1]])  # 120 degrees
    x = np.random.default_rng(0).uniform(-150e3, 150e3, size=(50, 2))
    assert np.allclose(S1.fix(S1.tdoa(x)).position, x, atol=1e-4)
    assert S1.range_sigma == pytest.approx(C_LIGHT * 30e-9)


def test_jacobian_against_finite_differences():
    x = np.array([[30e3, -40e3], [-120e3, 80e3]])
    J = S1.jacobian(x)
    h = 1.0
    for a in range(2):
        dx = np.zeros(2)
        dx[a] = h
        fd = (S1.range_differences(x + dx) - S1.range_differences(x - dx)) / (2 * h)
        assert np.allclose(J[..., a], fd, atol=1e-8)


@pytest.mark.parametrize("x0", [(40e3, 60e3), (-100e3, 50e3), (120e3, 10e3), (0.0, -90e3)])
def test_fix_is_unbiased_with_the_stated_covariance(x0):
    rng = np.random.default_rng(42)
    n = 3000
    x = np.tile(x0, (n, 1))
    fx = S1.fix(S1.tdoa(x, rng))
    e = fx.position - x
    P_true = S1.fix(S1.tdoa(x[:1])).covariance[0]
    se = np.sqrt(np.diag(P_true) / n)
    assert np.all(np.abs(e.mean(axis=0)) < 4 * se)                       # unbiased
    lo, hi = _band(2, n)
    assert lo < nees(fx.position, P_true, x).mean() < hi                 # covariance at truth
    assert lo < nees(fx.position, fx.covariance, x).mean() < hi          # at the estimate


def test_filters_basic_algebra():
    F, Q = cv_model(2.0, 3.0)
    assert np.allclose(F[:2, 2:], 2 * np.eye(2)) and np.allclose(Q[0, 0], 3 * 8 / 3)
    x, P = two_point_init(np.zeros((1, 2)), np.eye(2)[None], np.ones((1, 2)), np.eye(2)[None], 1.0)
    assert np.allclose(x, [[1, 1, 1, 1]]) and np.allclose(P[0, 2:, 2:], 2 * np.eye(2))
    x2, P2 = update(x, P, np.zeros((1, 2)), np.hstack([np.eye(2), np.zeros((2, 2))]),
                    np.eye(2)[None])
    assert np.allclose(x2, x) and np.all(np.linalg.eigvalsh(P2) > 0)
    assert np.trace(P2[0]) < np.trace(P[0])
    with pytest.raises(ValueError, match="T > 0"):
        cv_model(0.0, 1.0)


@pytest.mark.parametrize("tracker", ["ekf", "kf-fix"])
def test_tracker_is_consistent_on_straight_lines(tracker):
    rng = np.random.default_rng(7)
    sc = Yan2010(n_targets=300, tracker=tracker, q_filter=1e-3)
    N, K0 = 300, 41
    pos = rng.uniform(-60e3, 60e3, size=(N, 2))
    head = rng.uniform(0, 2 * np.pi, N)
    vel = rng.uniform(100, 300, N)[:, None] * np.stack([np.cos(head), np.sin(head)], 1)
    t = np.arange(K0)[:, None, None]
    truth = np.concatenate([pos + t * vel, np.broadcast_to(vel, (K0, N, 2))], axis=-1)
    x, P = sc.track(S1, truth, rng)
    ne = nees(x, P, truth[1:])
    lo, hi = _band(4, N)
    for k in (0, 10, 39):
        assert lo < ne[k].mean() < hi, (k, ne[k].mean())


def test_scenario_is_seeded_and_labels_are_shuffled():
    sc = Yan2010(n_targets=12)
    a, b = sc.simulate(np.random.default_rng(3)), sc.simulate(np.random.default_rng(3))
    assert np.array_equal(a.x[1], b.x[1]) and np.array_equal(a.partner, b.partner)
    assert a.x[0].shape == (80, 12, 4) and a.P[1].shape == (80, 12, 4, 4)
    assert a.features[0].shape == (80, 12, 3) and a.times[-1] == 80.0
    assert sorted(a.partner.tolist()) == list(range(12)) and not \
        np.array_equal(a.partner, np.arange(12))
    # node-2 track partner[i] follows emitter i: its estimate is near node 1's track i
    gap = np.linalg.norm(a.x[0][-1, :, :2] - a.x[1][-1, a.partner, :2], axis=1)
    assert np.median(gap) < 5e3
    f_err = a.features[1][:, a.partner] - a.features[0]
    assert np.allclose(f_err.std(axis=(0, 1)), np.hypot([2, .025, .045], [3, .030, .050]),
                       rtol=0.15)
    speeds = np.linalg.norm(a.truth[0, :, 2:], axis=1)
    assert np.all((speeds > 80) & (speeds < 1020))
    with pytest.raises(ValueError, match="tracker"):
        Yan2010(tracker="imm")
    three = Yan2010(n_targets=5, nodes=3).simulate(np.random.default_rng(1))
    assert len(three.x) == 3 and len(three.partners) == 3


@pytest.mark.parametrize("tracker,init", [("ekf", "two-point"), ("kf-fix", "one-point")])
def test_nodes_filtered_in_one_batch_equal_node_by_node(tracker, init):
    sc = Yan2010(n_targets=9, duration=12.0, tracker=tracker, init=init, nodes=3)
    truth = sc.trajectories(np.random.default_rng(3))
    rng = np.random.default_rng(4)
    tdoas = [s.tdoa(truth[:, :, :2], rng) for s in sc.systems()]
    xs, Ps = sc.filter_nodes(sc.systems(), tdoas)
    for s, t, x, P in zip(sc.systems(), tdoas, xs, Ps):
        x1, P1 = sc.filter_nodes([s], [t])
        assert np.array_equal(x, x1[0]) and np.array_equal(P, P1[0])
