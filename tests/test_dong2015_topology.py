"""Paper 004 (Dong et al. 2015): reference-frame transforms, the topology statistical
distance, its gate, and the per-reference-pair assignment (compiled against
``assocopt.solve``)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.stats import chi2

from assocopt.tracking.decide.topology import (LARGE, TopologyParams, assign_pairs,
                                               coarse_pregate, degree_matrix, phi_matrix,
                                               phi_reference, prepare, thresholds,
                                               trial_pairs)
from assocopt.tracking.costs.topology import (all_distances, chi2_gate, heading_jacobians,
                                        heading_variance, headings, pair_distances,
                                        reference_frames, rotations)


def _tracks(rng, n, spread=1e4, speed=200.0):
    X = np.column_stack([rng.uniform(0, spread, (n, 2)), rng.normal(0, speed, (n, 2))])
    A = rng.normal(size=(n, 4, 4))
    P = A @ A.transpose(0, 2, 1) * np.array([400, 400, 4, 4.0])[None, :, None] ** 0.5 \
        + np.diag([2500, 2500, 25, 25.0])
    P = 0.5 * (P + P.transpose(0, 2, 1))
    return X, P


def _picture_moved(X, P, phi, shift):
    """The whole picture rotated by ``phi`` about the origin and shifted."""
    c, s = math.cos(phi), math.sin(phi)
    R = np.array([[c, -s], [s, c]])
    T = np.kron(np.eye(2), R)
    Y = X @ T.T
    Y[:, :2] += shift
    return Y, T @ P @ T.T


def test_gate_is_the_chi_square_quantile():
    assert chi2_gate(0.01, 4) == pytest.approx(chi2.ppf(0.99, 4), rel=1e-12)
    assert round(chi2_gate(0.01, 4), 4) == 13.2767
    assert chi2_gate(0.05, 2) == pytest.approx(chi2.isf(0.05, 2))
    with pytest.raises(ValueError, match="alpha"):
        chi2_gate(1.5, 4)


def test_rotation_sends_each_heading_to_north():
    rng = np.random.default_rng(0)
    X, _ = _tracks(rng, 12)
    T = rotations(headings(X))
    v = np.einsum("nab,nb->na", T[:, 2:, 2:], X[:, 2:])
    assert np.allclose(v[:, 0], 0, atol=1e-9)
    assert np.allclose(v[:, 1], np.hypot(X[:, 2], X[:, 3]))


@pytest.mark.parametrize("full", [False, True])
def test_transforms_match_a_per_pair_loop(full):
    rng = np.random.default_rng(1)
    X, P = _tracks(rng, 7)
    Xr, Pr = reference_frames(X, P, full)
    for u in range(len(X)):
        th = math.atan2(X[u, 2], X[u, 3])
        c, s = math.cos(th), math.sin(th)
        T = np.array([[c, -s, 0, 0], [s, c, 0, 0], [0, 0, c, -s], [0, 0, s, c]])
        E = np.eye(4) if full else np.diag([1.0, 1, 0, 0])
        for i in range(len(X)):
            assert np.allclose(Xr[u, i], T @ (X[i] - E @ X[u]))
            assert np.allclose(Pr[u, i], T @ P[i] @ T.T)
    if full:
        assert np.allclose(Xr[np.arange(7), np.arange(7)], 0)


@pytest.mark.parametrize("full", [False, True])
def test_rotating_and_translating_one_picture_leaves_every_gamma_unchanged(full):
    rng = np.random.default_rng(2)
    X1, P1 = _tracks(rng, 6)
    X2, P2 = X1 + rng.normal(0, [30, 30, 3, 3], X1.shape), P1
    g = all_distances(*reference_frames(X1, P1, full), *reference_frames(X2, P2, full))
    for phi, shift in ((0.035, (1200.0, -800.0)), (-1.3, (0.0, 5e4)), (math.pi, (7.0, 7.0))):
        Y2, Q2 = _picture_moved(X2, P2, phi, np.array(shift))
        h = all_distances(*reference_frames(X1, P1, full), *reference_frames(Y2, Q2, full))
        assert np.allclose(h, g, rtol=1e-8, atol=1e-8)


def test_pair_distances_are_slices_of_the_tensor():
    rng = np.random.default_rng(3)
    X1, P1 = _tracks(rng, 5)
    X2, P2 = _tracks(rng, 4)
    f1, f2 = reference_frames(X1, P1), reference_frames(X2, P2)
    g = all_distances(*f1, *f2)
    for u in range(5):
        for v in range(4):
            assert np.allclose(pair_distances(*f1, *f2, u, v), g[u, v])
    D = f1[0][1, 2] - f2[0][3, 1]
    assert g[1, 3, 2, 1] == pytest.approx(D @ np.linalg.solve(f1[1][1, 2] + f2[1][3, 1], D))


def test_heading_variance_and_jacobian_against_finite_differences():
    rng = np.random.default_rng(4)
    X, P = _tracks(rng, 5)
    h = 1e-6
    var = heading_variance(X, P)
    for n in range(5):
        grad = np.zeros(4)
        for a in (2, 3):
            e = np.zeros(4)
            e[a] = h
            grad[a] = (headings(X[n] + e) - headings(X[n] - e)) / (2 * h)
        assert var[n] == pytest.approx(grad @ P[n] @ grad, rel=1e-6)
    J = heading_jacobians(X)
    th = headings(X)
    off = X[None, :, :] - np.concatenate([X[:, :2], np.zeros((5, 2))], 1)[:, None, :]
    num = (np.einsum("uab,uib->uia", rotations(th + h), off)
           - np.einsum("uab,uib->uia", rotations(th - h), off)) / (2 * h)
    assert np.allclose(J, num, rtol=1e-5, atol=1e-6)


OPTIONS = [{}, {"degree": "objective"}, {"ref_cov": True, "frame": "full"},
           {"ref_cov": True, "inflate": True}, {"assignment": "rectangular"},
           {"frame": "full"}, {"inflate": True},
           {"metric": "euclidean"}, {"threshold": "heading", "coef": 50.0},
           {"min_pairs": 3}, {"assignment": "rectangular", "metric": "euclidean"},
           {"assignment": "rectangular", "self_pair": "exclude"},
           {"assignment": "rectangular", "ref_cov": True, "inflate": True,
            "degree": "objective"},
           {"self_pair": "exclude"}, {"frame": "full", "self_pair": "include"}]


def _option_id(kw) -> str:
    return ",".join(f"{k}={v}" for k, v in kw.items()) or "default"


@pytest.mark.parametrize("kw", OPTIONS, ids=_option_id)
@pytest.mark.parametrize("seed", [5, 6])
def test_compiled_phi_agrees_with_solve_one_pair_at_a_time(kw, seed):
    rng = np.random.default_rng(seed)
    n1, n2 = (6, 5) if seed == 5 else (4, 7)
    X1, P1 = _tracks(rng, max(n1, n2), spread=3000.0, speed=150.0)
    X2 = X1 + rng.normal(0, [60, 60, 4, 4], X1.shape)
    p = TopologyParams(**kw)
    inp = prepare(X1[:n1], P1[:n1], X2[:n2], P1[:n2], p)
    phi, M = phi_matrix(inp, p)
    phi_r, M_r = phi_reference(inp, p)
    assert (M == M_r).all()
    assert np.allclose(phi, phi_r, rtol=1e-9)
    assert (phi[M < p.min_pairs] == LARGE).all()
    assert (M > 0).any()


@pytest.mark.parametrize("kw", OPTIONS, ids=_option_id)
def test_shared_assignment_gives_the_same_phi_for_every_degree(kw):
    rng = np.random.default_rng(8)
    X1, P1 = _tracks(rng, 7, spread=3000.0, speed=150.0)
    X2 = X1 + rng.normal(0, [60, 60, 4, 4], X1.shape)
    base = TopologyParams(**kw)
    inp = prepare(X1, P1, X2[:6], P1[:6], base)
    cols, gam = assign_pairs(inp, base)
    for extra in ({}, {"self_pair": "exclude"}, {"self_pair": "include"},
                  {"degree": "objective"}, {"min_pairs": 3}):
        p = TopologyParams(**{**kw, **extra})
        phi, M = phi_matrix(inp, p)
        phi_s, M_s = degree_matrix(cols, gam, thresholds(inp, p), p)
        assert (M == M_s).all() and np.allclose(phi, phi_s, rtol=1e-12)


def test_self_pair_is_separate_from_the_frame():
    assert TopologyParams().self_pair == "include"
    assert TopologyParams(frame="full").self_pair == "exclude"
    assert TopologyParams(frame="full", self_pair="include").self_pair == "include"
    assert TopologyParams(self_pair="exclude").frame == "position"
    with pytest.raises(ValueError, match="self_pair"):
        TopologyParams(self_pair="both")
    rng = np.random.default_rng(9)
    X1, P1 = _tracks(rng, 6, spread=3000.0, speed=150.0)
    X2 = X1 + rng.normal(0, [60, 60, 4, 4], X1.shape)
    for kw in ({}, {"assignment": "rectangular"}):
        inc, exc = TopologyParams(**kw), TopologyParams(self_pair="exclude", **kw)
        _, M_in = phi_matrix(prepare(X1, P1, X2, P1, inc), inc)
        _, M_ex = phi_matrix(prepare(X1, P1, X2, P1, exc), exc)
        # leaving the reference pair out drops at most that one pair from each count
        assert ((M_in - M_ex >= 0) & (M_in - M_ex <= 1)).all() and (M_in > M_ex).any()


def test_pregate_skips_pairs_and_phi_leaves_them_large():
    rng = np.random.default_rng(7)
    X1, P1 = _tracks(rng, 8)
    X2 = X1 + rng.normal(0, [30, 30, 2, 2], X1.shape)
    ok = coarse_pregate(X1, P1, X2, P1)
    assert ok.diagonal().all() and not ok.all()
    p = TopologyParams()
    inp = prepare(X1, P1, X2, P1, p)
    phi, M = phi_matrix(inp, p, active=ok)
    full, _ = phi_matrix(inp, p)
    assert (phi[~ok] == LARGE).all() and np.allclose(phi[ok], full[ok])


def test_trial_pairs_row_and_assignment():
    phi = np.array([[1.0, 2.0, LARGE], [0.5, 3.0, LARGE], [LARGE, LARGE, LARGE]])
    assert trial_pairs(phi, "row").tolist() == [0, 0, -1]
    got = trial_pairs(phi, "assignment")
    assert got.tolist() == [1, 0, -1]
    real = got[got >= 0]
    assert len(set(real.tolist())) == len(real)
    with pytest.raises(ValueError, match="rule"):
        trial_pairs(phi, "greedy")


def test_bad_inputs_are_refused():
    with pytest.raises(ValueError, match=r"shape \(n, 4\)"):
        reference_frames(np.zeros((3, 2)), np.zeros((3, 4, 4)))
    with pytest.raises(ValueError, match="assignment"):
        TopologyParams(assignment="lsa")
