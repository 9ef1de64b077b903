"""Paper 001's association degrees (3)-(7) and both readings of their Dempster fusion,
against independent computations (a dictionary implementation of Dempster's rule)."""

from __future__ import annotations

import itertools
from functools import reduce

import numpy as np
import pytest
from hypothesis import given, settings, strategies as st

from assocopt.tracking.belief import MassFunction, dempster
from assocopt.tracking.costs.association_degree import (DegreeParams, feature_degree,
                                                        feature_degrees, fuse_candidate_frame,
                                                        fuse_pair_frame, fused_degree,
                                                        state_degree, statistical_distance,
                                                        tolerance)


# ------------------------------------------------------------------ feature degrees
@pytest.mark.parametrize("eps,a", [(1.0, 0.2), (7.2, 0.3), (1e-7, 1.0)])
def test_feature_degree_breakpoints_and_continuity(eps, a):
    f = lambda d: float(feature_degree(np.array([d]), eps, a)[0])  # noqa: E731
    assert f(0.0) == a and f(eps) == a
    assert f(1.5 * eps) == pytest.approx(a / 4)          # (1.5 - 2)^2 = 1/4
    assert f(2 * eps) == 0.0 and f(3 * eps) == 0.0
    h = 1e-9 * eps
    for x in (eps, 2 * eps):                             # left and right limits agree
        assert f(x - h) == pytest.approx(f(x + h), abs=1e-6 * a)
    # a convex quadratic, not a ramp: slope -2a/eps just right of eps, 0 at 2 eps
    assert (f(eps) - f(eps + h)) / h == pytest.approx(2 * a / eps, rel=1e-4)
    assert (f(2 * eps - h) - f(2 * eps)) / h == pytest.approx(0.0, abs=1e-6 * a / eps)
    assert f(1.5 * eps) != pytest.approx(a * 0.5)        # the linear ramp would give a/2


@given(st.lists(st.floats(0, 10, allow_nan=False), min_size=2, max_size=30))
@settings(max_examples=60, deadline=None)
def test_feature_degree_is_non_increasing_and_bounded(deltas):
    d = np.sort(np.asarray(deltas))
    v = feature_degree(d, 1.3, 0.25)
    assert np.all(np.diff(v) <= 1e-15) and np.all((v >= 0) & (v <= 0.25))
    assert np.array_equal(feature_degree(-d, 1.3, 0.25), v)          # absolute difference


def test_tolerance_and_bad_input():
    assert tolerance(2.0, 3.0, 2.0) == pytest.approx(2 * np.sqrt(13))
    with pytest.raises(ValueError, match="eps"):
        feature_degree([1.0], 0.0, 0.2)
    with pytest.raises(ValueError, match="weights"):
        DegreeParams(weights=(0.5, 0.5, 0.5, 0.5))
    with pytest.raises(ValueError, match="fusion"):
        DegreeParams(fusion="frame")
    with pytest.raises(ValueError, match="tolerances"):
        DegreeParams(tolerances=(1.0, -1.0, 1.0))


# -------------------------------------------------------------------- state degree
def test_statistical_distance_against_a_loop():
    rng = np.random.default_rng(0)
    x1, x2 = rng.normal(size=(3, 4)), rng.normal(size=(5, 4))
    A, B = rng.normal(size=(3, 4, 4)), rng.normal(size=(5, 4, 4))
    p1 = A @ A.transpose(0, 2, 1) + np.eye(4)
    p2 = B @ B.transpose(0, 2, 1) + np.eye(4)
    D = statistical_distance(x1, p1, x2, p2)
    for i, j in itertools.product(range(3), range(5)):
        d = x1[i] - x2[j]
        assert D[i, j] == pytest.approx(d @ np.linalg.inv(p1[i] + p2[j]) @ d)
    with pytest.raises(ValueError, match="shapes"):
        statistical_distance(x1, p1, x2[:, :2], p2)


def test_state_degree_values_guard_and_candidates():
    D = np.array([[4.0, 2.0, 8.0], [0.0, 1.0, 3.0]])
    m = state_degree(D, 0.4)
    assert np.allclose(m[0], [0.2, 0.4, 0.1])
    assert np.allclose(m[1], [0.4, 0.0, 0.0]) and np.all(np.isfinite(m))   # D = 0 guard
    m = state_degree(D, 0.4, candidates=[True, False, True])
    assert np.allclose(m[0], [0.4, 0.0, 0.2])
    # the smaller D, the larger the degree; the best candidate always gets a1
    rng = np.random.default_rng(1)
    D = rng.exponential(size=(6, 9))
    m = state_degree(D, 0.3)
    assert np.allclose(m.max(axis=1), 0.3)
    for row_d, row_m in zip(D, m):
        order = np.argsort(row_d)
        assert np.all(np.diff(row_m[order]) <= 1e-15)


# ------------------------------------------------------------------------ fusion
def _dict_dempster(masses: list[dict[frozenset, float]]) -> dict[frozenset, float]:
    """Dempster's rule (2) straight from its definition, on dictionaries."""
    def pair(m1, m2):
        out: dict[frozenset, float] = {}
        for (a, x), (b, y) in itertools.product(m1.items(), m2.items()):
            out[a & b] = out.get(a & b, 0.0) + x * y
        k = out.pop(frozenset(), 0.0)
        return {s: v / (1.0 - k) for s, v in out.items()}
    return reduce(pair, masses)


@given(st.integers(1, 5), st.integers(0, 10 ** 6))
@settings(max_examples=40, deadline=None)
def test_candidate_frame_is_dempster_on_normalised_singletons(n2, seed):
    rng = np.random.default_rng(seed)
    m = rng.uniform(0.01, 1.0, size=(4, 2, n2))
    fused = fuse_candidate_frame(m)
    assert np.allclose(fused.sum(axis=1), 1.0)
    prod = m.prod(axis=0)
    assert np.allclose(fused, prod / prod.sum(axis=1, keepdims=True))       # closed form
    frame = tuple(range(n2))
    for i in range(2):
        bpas = [{frozenset([j]): m[x, i, j] / m[x, i].sum() for j in frame} for x in range(4)]
        ref = _dict_dempster(bpas)
        lib = dempster(*[MassFunction(frame, b) for b in bpas])
        for j in frame:
            assert fused[i, j] == pytest.approx(ref[frozenset([j])])
            assert fused[i, j] == pytest.approx(lib[[j]])


def test_candidate_frame_weights_cancel_and_total_conflict_gives_zeros():
    rng = np.random.default_rng(2)
    m = rng.uniform(0.1, 1.0, size=(4, 3, 4))
    scaled = m * np.array([0.7, 0.1, 0.1, 0.1])[:, None, None]
    assert np.allclose(fuse_candidate_frame(m), fuse_candidate_frame(scaled))
    m[1, 0, :] = 0.0                                                     # frequency rules out all
    out = fuse_candidate_frame(m)
    assert np.all(out[0] == 0.0) and np.allclose(out[1:].sum(axis=1), 1.0)


@given(st.integers(0, 10 ** 6))
@settings(max_examples=40, deadline=None)
def test_pair_frame_is_one_minus_product_against_the_dictionary_rule(seed):
    rng = np.random.default_rng(seed)
    m = rng.uniform(0.0, 0.6, size=(4, 2, 3))
    fused = fuse_pair_frame(m)
    assert np.allclose(fused, 1.0 - np.prod(1.0 - m, axis=0))
    A, TH = frozenset("A"), frozenset("AN")
    for i, j in itertools.product(range(2), range(3)):
        bpas = [{A: m[x, i, j], TH: 1.0 - m[x, i, j]} for x in range(4)]
        assert fused[i, j] == pytest.approx(_dict_dempster(bpas).get(A, 0.0))


def test_pair_frame_keeps_the_weights_and_may_pass_several_candidates():
    p = DegreeParams(weights=(0.4, 0.2, 0.2, 0.2), tolerances=(1.0, 1.0, 1.0), fusion="pair")
    D = np.array([[1.0, 1.0]])
    f1, f2 = np.zeros((1, 3)), np.zeros((2, 3))
    m = feature_degrees(D, f1, f2, p)
    fused = fused_degree(m, "pair")
    assert np.allclose(fused, 1 - 0.6 * 0.8 ** 3) and np.all(fused > 0.5)
    assert np.allclose(fused_degree(m, "candidate"), 0.5)
    with pytest.raises(ValueError, match="fusion"):
        fused_degree(m, "x")
