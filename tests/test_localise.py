"""Bearing geometry and least-squares localisation (paper 002, eqs. (1)-(2), (9)-(23))."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, strategies as st

from assocopt import InvalidProblemError
from assocopt.tracking.localisation import (angle_jacobian, angles, localise, localise_indexed,
                                            los_system, pseudo_measurements, residual_jacobian,
                                            wrap_angle)

S = np.array([[0.0, 20.0, 0.0], [20.0, 0.0, 0.0], [0.0, 0.0, 0.0]])   # paper, km
X0 = np.array([12.0, 9.0, 5.0])                                        # docs/papers/lu2013.md
SIG = 1.5e-3


def test_azimuth_uses_four_quadrant_atan2():
    th = angles([[-1.0, -1.0, 0.0], [-1.0, 1.0, 1.0]], [[0, 0, 0], [5, 0, 0]])
    assert th[0, 0, 1] == pytest.approx(-3 * np.pi / 4)       # arctan would give +pi/4
    assert th[1, 0, 1] == pytest.approx(3 * np.pi / 4)
    assert th[1, 0, 0] == pytest.approx(np.arctan2(1.0, np.sqrt(2.0)))   # elevation first
    assert th[0, 1, 1] == pytest.approx(-(np.pi - np.arctan2(1, 6)))


def test_wrap_angle_range():
    a = wrap_angle(np.array([np.pi, -np.pi, 3 * np.pi, 2 * np.pi + 0.1, -0.1]))
    np.testing.assert_allclose(a, [np.pi, np.pi, np.pi, 0.1, -0.1], atol=1e-12)


def test_line_of_sight_equations_hold_at_the_true_position():
    th = angles(X0, S)[None]
    H, Y = los_system(th, S)
    assert H.shape == (1, 6, 3) and Y.shape == (1, 6)
    np.testing.assert_allclose(H[0] @ X0, Y[0], atol=1e-12)


@pytest.mark.parametrize("method", ["ls", "ils", "tls"])
def test_noise_free_estimate_is_exact_with_two_or_three_sensors(method):
    th = np.repeat(angles(X0, S)[None], 4, axis=0)
    mask = np.array([[1, 1, 1], [1, 1, 0], [0, 1, 1], [1, 0, 1]], bool)
    loc = localise(th, S, np.eye(2) * SIG ** 2, mask, method=method)
    assert loc.valid.all()
    np.testing.assert_allclose(loc.x, np.tile(X0, (4, 1)), atol=1e-9)
    assert loc.n_real.tolist() == [3, 2, 2, 2]


def test_one_measurement_and_degenerate_geometry_are_flagged_not_raised():
    th = np.repeat(angles(X0, S)[None], 2, axis=0)
    loc = localise(th, S, np.eye(2) * SIG ** 2, [[1, 0, 0], [1, 1, 1]])
    assert loc.valid.tolist() == [False, True]
    assert np.isnan(loc.x[0]).all() and np.isnan(loc.P[0]).all()
    # target on the line through both sensors: the bearings do not intersect
    S2 = np.array([[0.0, 0.0, 0.0], [10.0, 0.0, 0.0]])
    th2 = angles([20.0, 0.0, 0.0], S2)[None]
    assert not localise(th2, S2, np.eye(2) * SIG ** 2).valid[0]


def _monte_carlo(method, n=4000, seed=1):
    rng = np.random.default_rng(seed)
    m = angles(X0, S)[None] + rng.normal(0.0, SIG, (n, 3, 2))
    loc = localise(m, S, np.eye(2) * SIG ** 2, method=method)
    return np.var(loc.x, axis=0), np.mean(np.diagonal(loc.P, axis1=1, axis2=2), axis=0)


def test_ls_covariance_matches_spec_numbers_and_monte_carlo():
    """Residual-Jacobian covariance formula (3.30, 3.07, 2.04)e-4 km^2; MC agrees."""
    th = angles(X0, S)[None]
    P = localise(th, S, np.eye(2) * SIG ** 2).P[0]
    np.testing.assert_allclose(np.diag(P) * 1e4, [3.30, 3.07, 2.04], rtol=0.01)
    emp, formula = _monte_carlo("ls")
    np.testing.assert_allclose(formula, emp, rtol=0.10)     # 4000 runs: ~2% sd


def test_printed_dY_dm_covariance_is_too_small():
    """The literal dY/dm of (16) gives (1.30, 1.06, 0.97)e-4: about 2.5x too small."""
    th = angles(X0, S)[None]
    P = localise(th, S, np.eye(2) * SIG ** 2, covariance="printed").P[0]
    np.testing.assert_allclose(np.diag(P) * 1e4, [1.30, 1.06, 0.97], rtol=0.02)
    emp, _ = _monte_carlo("ls")
    assert (emp / np.diag(P) > 2.0).all()


def test_printed_jacobian_vanishes_for_the_sensor_at_the_origin():
    th = angles(X0, S)[None]
    J = residual_jacobian(th, X0[None], S, form="printed")
    assert np.abs(J[0, 2]).max() == 0.0          # S_3 = (0, 0, 0)
    Jr = residual_jacobian(th, X0[None], S)
    # residual form: [[0, rho], [r, 0]] approximately
    d = X0 - S[2]
    rho, r = np.hypot(d[0], d[1]), np.linalg.norm(d)
    np.testing.assert_allclose(Jr[0, 2], [[0, rho], [r, 0]], atol=1e-9)


def test_iterated_ls_covariance_matches_monte_carlo():
    emp, formula = _monte_carlo("ils", seed=2)
    np.testing.assert_allclose(formula, emp, rtol=0.10)


def test_indexed_fast_path_equals_matrix_form_with_dummies():
    rng = np.random.default_rng(4)
    meas = [angles(rng.uniform(5, 30, (4, 3)), S)[:, s] + rng.normal(0, SIG, (4, 2))
            for s in range(3)]
    R = [np.tile(np.diag([SIG ** 2, (2 * SIG) ** 2]), (4, 1, 1)) for _ in range(3)]
    T = np.array([[i, j, k] for i in range(5) for j in range(5) for k in range(5)
                  if (i > 0) + (j > 0) + (k > 0) >= 2])
    fast = localise_indexed(meas, R, S, T)
    m = np.stack([np.concatenate([np.zeros((1, 2)), meas[s]])[T[:, s]] for s in range(3)], 1)
    Rm = np.stack([np.concatenate([np.eye(2)[None], R[s]])[T[:, s]] for s in range(3)], 1)
    ref = localise(m, S, Rm, T > 0)
    assert (fast.valid == ref.valid).all() and fast.valid.all()
    np.testing.assert_allclose(fast.x, ref.x, rtol=1e-9, atol=1e-9)
    np.testing.assert_allclose(fast.P, ref.P, rtol=1e-7, atol=1e-14)
    # other estimators route through the matrix form
    t = localise_indexed(meas, R, S, T, method="tls")
    assert t.method == "tls" and t.valid.all()


def test_angle_jacobian_matches_finite_differences():
    x = np.array([7.0, -4.0, 3.0])
    g = angle_jacobian(x, S)
    h = 1e-6
    fd = np.stack([(angles(x + h * e, S) - angles(x - h * e, S)) / (2 * h)
                   for e in np.eye(3)], axis=-1)
    np.testing.assert_allclose(g, fd, rtol=1e-6, atol=1e-9)


def test_pseudo_measurement_covariance_blocks_and_full_matrix():
    P = np.array([[3.3, 0.4, 0.1], [0.4, 3.1, -0.2], [0.1, -0.2, 2.0]]) * 1e-4
    pm = pseudo_measurements(X0[None], P[None], S, full=True)
    np.testing.assert_allclose(pm.mean[0], angles(X0, S), atol=1e-15)
    for s in range(3):
        np.testing.assert_allclose(pm.full[0, 2 * s:2 * s + 2, 2 * s:2 * s + 2], pm.cov[0, s],
                                   rtol=1e-12)
    # cross-sensor blocks are not zero and the full matrix has rank 3
    assert np.abs(pm.full[0, 0:2, 2:4]).max() > 1e-3 * np.abs(pm.cov[0, 0]).max()
    assert np.linalg.matrix_rank(pm.full[0], tol=1e-12 * np.abs(pm.full).max()) == 3


def test_pseudo_measurement_covariance_matches_monte_carlo():
    P = np.diag([3.3e-4, 3.1e-4, 2.0e-4])
    rng = np.random.default_rng(3)
    xs = rng.multivariate_normal(X0, P, 20000)
    emp = np.cov(angles(xs, S).reshape(-1, 6).T)
    pm = pseudo_measurements(X0[None], P[None], S, full=True)
    np.testing.assert_allclose(pm.full[0], emp, rtol=0.05, atol=0.05 * np.abs(emp).max())


@given(st.floats(-50, 50), st.floats(-50, 50), st.floats(0.5, 20))
def test_localise_recovers_random_points(x, y, z):
    p = np.array([x, y, z])
    if np.min(np.linalg.norm(S[:, :2] - p[:2], axis=1)) < 0.5:
        return                                   # azimuth undefined above a sensor
    loc = localise(angles(p, S)[None], S, np.eye(2) * SIG ** 2)
    assert loc.valid[0]
    np.testing.assert_allclose(loc.x[0], p, atol=1e-6 * (1 + np.abs(p).max()))


def test_input_errors_name_the_problem():
    with pytest.raises(InvalidProblemError, match="sensors must have shape"):
        localise(np.zeros((1, 3, 2)), [[0, 0, 0]], np.eye(2))
    with pytest.raises(InvalidProblemError, match=r"meas must have shape \(K, 3, 2\)"):
        localise(np.zeros((1, 2, 2)), S, np.eye(2))
    with pytest.raises(InvalidProblemError, match="NaN"):
        localise(np.full((1, 3, 2), np.nan), S, np.eye(2))
    with pytest.raises(InvalidProblemError, match="method must be one of"):
        localise(np.zeros((1, 3, 2)), S, np.eye(2), method="ml")
    with pytest.raises(InvalidProblemError, match="R must broadcast"):
        localise(np.zeros((1, 3, 2)), S, np.eye(3))
