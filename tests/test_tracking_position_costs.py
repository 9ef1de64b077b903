"""Position-report tuple costs in bulk against a per-tuple computation, and the
gated problem of position reports against the ungated one."""

from __future__ import annotations

import itertools
import math

import numpy as np
import pytest
from hypothesis import given, settings, strategies as st

from assocopt import AssignmentProblem, solve
from assocopt.runtime.errors import InvalidProblemError
from assocopt.tracking.costs.position import build_position_problem, position_tuple_costs
from assocopt.tracking.costs.sd_builder import candidate_tuples


def _one(Z, R, t, pd, cd):
    """The cost of one tuple, written out."""
    real = [s for s in range(len(Z)) if t[s] > 0]
    if len(real) < 2:
        return 0.0
    zs = [Z[s][t[s] - 1] for s in real]
    Rs = [R[s][t[s] - 1] for s in real]
    I = sum(np.linalg.inv(r) for r in Rs)
    x = np.linalg.solve(I, sum(np.linalg.inv(r) @ z for r, z in zip(Rs, zs)))
    c = 0.0
    for s, z, r in zip(real, zs, Rs):
        v = z - x
        c += 0.5 * v @ np.linalg.solve(r, v) + 0.5 * math.log(np.linalg.det(2 * math.pi * r))
        c += -math.log(pd[s]) + math.log(cd[s])
    for s in range(len(Z)):
        if t[s] == 0:
            c += -math.log(1 - pd[s]) if pd[s] < 1 else math.inf
    return c


@settings(max_examples=40, deadline=None)
@given(st.integers(0, 10_000), st.integers(2, 4), st.integers(1, 3), st.booleans())
def test_bulk_costs_equal_the_per_tuple_formula(seed, N, d, per_report):
    rng = np.random.default_rng(seed)
    sizes = [int(v) for v in rng.integers(1, 4, size=N)]
    Z = [rng.normal(size=(n, d)) for n in sizes]
    def cov(n=None):
        A = rng.normal(size=(d, d) if n is None else (n, d, d))
        return A @ np.swapaxes(A, -1, -2) + 0.1 * np.eye(d)
    R = [cov(n) for n in sizes] if per_report else [cov() for _ in sizes]
    full = R if per_report else [np.broadcast_to(r, (n, d, d)) for r, n in zip(R, sizes)]
    pd = rng.choice([0.7, 0.95, 1.0], size=N)
    cd = rng.uniform(0.01, 1.0, size=N)
    T = candidate_tuples(sizes, np.minimum(pd, 0.9), cd)
    got = position_tuple_costs(Z, R, T, pd, cd, chunk=7)
    want = np.array([_one(Z, full, t, pd, cd) for t in T.tolist()])
    assert np.array_equal(np.isinf(got), np.isinf(want))
    fin = np.isfinite(want)
    assert got[fin] == pytest.approx(want[fin], rel=1e-9, abs=1e-9)


def test_isotropic_costs_equal_the_tracking_benchmark_formula():
    from benchmarks.tracking_scans import ScanSpec, draw_scan, gated, nllr
    spec = ScanSpec(N=3, n=40, spacing=1.0, seed=3)
    meas = draw_scan(spec)
    T = gated(spec, meas)
    lam = max(spec.clutter * spec.n, 1.0) / spec.side ** 2
    got = position_tuple_costs(meas, np.eye(2) * spec.sigma ** 2, T, spec.pd, lam)
    assert got == pytest.approx(nllr(spec, meas, T), rel=1e-9, abs=1e-9)


def test_gated_position_problem_has_the_optimum_of_the_full_problem():
    rng = np.random.default_rng(8)
    X = rng.uniform(0, 12, size=(8, 2))
    Z = [np.concatenate([X[rng.random(8) < 0.9], rng.uniform(0, 12, (1, 2))]) for _ in range(3)]
    Z = [z + rng.normal(0, 0.3, z.shape) for z in Z]
    R = np.eye(2) * 0.09
    p = build_position_problem(Z, R, pd=0.9, clutter_density=0.01, probability=0.999)
    T = candidate_tuples([len(z) for z in Z], 0.9, 0.01)
    c = position_tuple_costs(Z, R, T, 0.9, 0.01)
    full = AssignmentProblem.sparse([len(z) for z in Z], T, c)
    a, b = solve(p), solve(full)
    assert a.objective == pytest.approx(b.objective, abs=1e-9)
    assert p.n_candidates < full.n_candidates


def test_bad_cost_input_is_named():
    Z = [np.zeros((1, 2)), np.ones((1, 2))]
    with pytest.raises(InvalidProblemError, match="clutter_density must be > 0"):
        position_tuple_costs(Z, np.eye(2), [[1, 1]], 0.9, 0.0)
    with pytest.raises(InvalidProblemError, match="does not exist"):
        position_tuple_costs(Z, np.eye(2), [[2, 1]], 0.9, 1.0)
    with pytest.raises(InvalidProblemError, match=r"shape \(K, 2\)"):
        position_tuple_costs(Z, np.eye(2), [[1, 1, 1]], 0.9, 1.0)
