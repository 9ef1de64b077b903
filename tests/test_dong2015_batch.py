"""Paper 004 (Dong et al. 2015): the batched rectangular reading
(:mod:`assocopt.tracking.decide._topology_batch`, vectorised distances) gives the same
Phi, confirmed counts and assignments as the plain compiled loop it replaced
(``plain=True``), on random instances of several sizes and options, also when each
step's assignments are warm-started from the previous step's duals."""

from __future__ import annotations

import zlib

import numpy as np
import pytest

from assocopt.tracking.decide.topology import (Duals, TopologyParams, assign_pairs,
                                               phi_matrix, prepare)
from assocopt.tracking.scenarios.dong2015 import Dong2015

OPTIONS = [{}, {"self_pair": "exclude"}, {"metric": "euclidean"},
           {"inflate": True, "ref_cov": True, "degree": "objective"},
           {"threshold": "heading", "coef": 20.0}, {"min_pairs": 3},
           {"self_pair": "exclude", "inflate": True}]


def _instance(rng, n1, n2):
    n = max(n1, n2)
    X1 = np.column_stack([rng.uniform(0, 4000, (n, 2)), rng.normal(0, 150, (n, 2))])
    A = rng.normal(size=(n, 4, 4))
    P = A @ A.transpose(0, 2, 1) * 30.0 + np.diag([2500, 2500, 25, 25.0])
    X2 = X1 + rng.normal(0, [80, 80, 5, 5], X1.shape)
    return X1[:n1], P[:n1], X2[:n2], P[:n2]


@pytest.mark.parametrize("kw", OPTIONS, ids=lambda kw: ",".join(kw) or "default")
@pytest.mark.parametrize("shape", [(7, 7), (9, 5), (4, 8), (15, 13)])
def test_batched_rectangular_equals_the_plain_loop(kw, shape):
    rng = np.random.default_rng(zlib.crc32(repr((shape, kw)).encode()))
    p = TopologyParams(assignment="rectangular", **kw)
    for trial in range(3):
        inp = prepare(*_instance(rng, *shape), p)
        active = rng.random(shape) < 0.8 if trial == 2 else None
        phi, M = phi_matrix(inp, p, active)
        phi0, M0 = phi_matrix(inp, p, active, plain=True)
        assert (M == M0).all() and np.allclose(phi, phi0, rtol=1e-9, atol=0)
        assert (M > 0).any()
        cols, gam = assign_pairs(inp, p, active)
        cols0, gam0 = assign_pairs(inp, p, active, plain=True)
        assert (cols == cols0).all()
        assert np.allclose(np.where(cols >= 0, gam, 0), np.where(cols0 >= 0, gam0, 0),
                           rtol=1e-9)


def test_batched_equals_plain_on_the_paper_scene():
    """Environment 2 with 30 targets a side, first and last step."""
    run = Dong2015(env=2, n_targets=30).simulate(np.random.default_rng(3))
    for kw in ({}, {"self_pair": "exclude"}):
        p = TopologyParams(assignment="rectangular", **kw)
        for st in (run.steps[0], run.steps[-1]):
            inp = prepare(st.X1, st.P1, st.X2, st.P2, p)
            phi, M = phi_matrix(inp, p)
            phi0, M0 = phi_matrix(inp, p, plain=True)
            assert (M == M0).all() and np.allclose(phi, phi0, rtol=1e-9)


def test_not_positive_definite_gives_inf_in_both():
    rng = np.random.default_rng(0)
    X1, P1, X2, P2 = _instance(rng, 5, 5)
    P1 = P1.copy()
    P1[2] = -np.eye(4) * 1e6                 # track 2 of sensor 1: B not PD
    p = TopologyParams(assignment="rectangular")
    from assocopt.tracking.decide.topology import _kernel_args, _batch_args
    from assocopt.tracking.decide._topology_batch import fill_exact
    inp = prepare(X1, P1, X2, P2, p)
    X1s, Q1, X2s, Q2, euclid, _ = _batch_args(_kernel_args(inp, p, None)[0])
    G = np.empty((5, 5))
    fill_exact(X1s, Q1, X2s, Q2, 0, 0, euclid, G)
    assert np.isinf(G[2]).all() and np.isfinite(np.delete(G, 2, 0)).all()
    phi, M = phi_matrix(inp, p)
    phi0, M0 = phi_matrix(inp, p, plain=True)
    assert (M == M0).all() and np.allclose(phi, phi0)


@pytest.mark.parametrize("kw", [{}, {"self_pair": "exclude"}, {"inflate": True}],
                         ids=lambda kw: ",".join(kw) or "default")
@pytest.mark.parametrize("env", [1, 2, 3])
def test_warm_started_steps_equal_the_plain_loop(kw, env):
    """A whole run, every step warm-started from the last (as the experiment does)."""
    run = Dong2015(env=env, n_targets=12, missed=2, false_tracks=2,
                   n_steps=6).simulate(np.random.default_rng(env))
    p = TopologyParams(assignment="rectangular", **kw)
    d_phi, d_as = Duals(), Duals()
    for st in run.steps:
        inp = prepare(st.X1, st.P1, st.X2, st.P2, p)
        phi, M = phi_matrix(inp, p, duals=d_phi)
        phi0, M0 = phi_matrix(inp, p, plain=True)
        assert (M == M0).all() and np.allclose(phi, phi0, rtol=1e-9)
        cols, _ = assign_pairs(inp, p, duals=d_as)
        assert (cols == assign_pairs(inp, p, plain=True)[0]).all()
    assert d_phi.have.any() and d_as.have.any()


def test_duals_restart_cold_when_the_shape_changes():
    d = Duals()
    V, have = d.arrays(3, 4)
    have[:] = True
    V2, have2 = d.arrays(4, 4)
    assert V2.shape == (4, 4, 4) and not have2.any()
    assert d.arrays(4, 4)[0] is V2
