"""Pairwise-gated S-D tuples against brute-force enumeration + filter."""

from __future__ import annotations

import itertools

import numpy as np
import pytest
from hypothesis import given, strategies as st

from assocopt.tracking.costs.sd_builder import candidate_tuples, tuple_costs, tuple_geometry
from assocopt.runtime.errors import InvalidProblemError
from assocopt.tracking.localisation import angles
from assocopt.tracking.scenarios.lu2013 import Lu2013
from assocopt.tracking.gating import bearing_pair_gate, build_gated_problem, gated_tuples

FIVE = ((0.0, 20.0, 0.0), (20.0, 0.0, 0.0), (0.0, 0.0, 0.0), (-20.0, 0.0, 0.0),
        (0.0, -20.0, 0.0))


def _brute(sizes, ok, pd, cd):
    """Every candidate of the detection model, kept when all its real pairs are compatible."""
    T = candidate_tuples(sizes, pd, cd)
    keep = []
    for t in T.tolist():
        good = all(ok[(s, u)][t[s] - 1, t[u] - 1]
                   for s, u in itertools.combinations(range(len(sizes)), 2)
                   if t[s] > 0 and t[u] > 0 and (s, u) in ok)
        keep.append(good)
    return {tuple(t) for t, k in zip(T.tolist(), keep) if k}


@given(st.integers(0, 10_000), st.integers(2, 4), st.booleans(), st.booleans())
def test_gated_tuples_equal_brute_force(seed, N, miss, clutter):
    rng = np.random.default_rng(seed)
    sizes = tuple(int(v) for v in rng.integers(0, 4, size=N))
    pd = np.where(rng.random(N) < 0.5, 1.0, 0.8) if miss else np.ones(N)
    cd = rng.choice([0.0, 0.5], size=N) if clutter else np.zeros(N)
    ok = {(s, t): rng.random((sizes[s], sizes[t])) < 0.5
          for s, t in itertools.combinations(range(N), 2) if rng.random() < 0.8}
    got = gated_tuples(sizes, ok, pd, cd)
    assert {tuple(t) for t in got.tolist()} == _brute(sizes, ok, pd, cd)
    assert len(got) == len({tuple(t) for t in got.tolist()})      # no duplicates
    assert (got == got[np.lexsort(got.T[::-1])]).all()


@pytest.mark.parametrize("pd, clutter", [(1.0, 0.0), (0.8, 1.0)])
def test_gated_problem_equals_brute_force_tuples_and_costs(pd, clutter):
    sc = Lu2013(n_targets=3, d=2.0, sensors_km=FIVE[:4], pd=pd, clutter_rate=clutter)
    scan, _ = sc.simulate(np.random.default_rng(11))
    ok = bearing_pair_gate(scan, probability=0.99)
    want = np.array(sorted(_brute(scan.sizes, ok, scan.pd, scan.clutter_density)))
    g = tuple_geometry(scan, want)
    c = tuple_costs(scan, g, "skld-exact")
    keep = np.isfinite(c.total)
    p = build_gated_problem(scan, "skld-exact", probability=0.99, name="mine")
    got = dict(zip(map(tuple, p.tuples.tolist()), p.costs.tolist()))
    assert got == pytest.approx(dict(zip(map(tuple, want[keep].tolist()),
                                         c.total[keep].tolist())))
    assert p.name == "mine"
    assert p.n_candidates < len(candidate_tuples(scan.sizes, scan.pd, scan.clutter_density))


def test_true_pairs_pass_the_pair_gate_and_far_ones_do_not():
    rng = np.random.default_rng(3)
    X = np.array([[10.0, 12.0, 5.0], [-15.0, 30.0, 8.0]])
    S = np.array(FIVE[:2])
    th = angles(X, S)                                          # (2 targets, 2 sensors, 2)
    from assocopt.tracking.costs.sd_builder import Scan
    sig = 1e-3
    meas = [th[:, s] + rng.normal(0, sig, size=(2, 2)) for s in range(2)]
    scan = Scan.create(S, meas, np.eye(2) * sig ** 2)
    ok = bearing_pair_gate(scan, probability=0.999)[(0, 1)]
    assert ok[0, 0] and ok[1, 1] and not ok[0, 1] and not ok[1, 0]


def test_behind_and_max_range_gates_in_the_plane():
    from assocopt.tracking.costs.sd_builder import Scan
    S = np.array([[0.0, 0.0], [10.0, 0.0]])
    # target at (5, 5): azimuths 45 deg from sensor 0, 135 deg from sensor 1;
    # the second measurement of sensor 1 points away (-45 deg): its lines meet behind it
    meas = [np.array([np.pi / 4]), np.array([3 * np.pi / 4, -np.pi / 4])]
    scan = Scan.create(S, meas, 1e-6)
    ok = bearing_pair_gate(scan)[(0, 1)].toarray()
    assert ok.tolist() == [[True, False]]
    assert bearing_pair_gate(scan, max_range=5.0)[(0, 1)].toarray().tolist() == [[False, False]]


def test_thirty_targets_five_sensors_without_enumerating_every_tuple():
    sc = Lu2013(n_targets=30, d=3.0, sensors_km=FIVE, pd=0.9, clutter_rate=1.0)
    scan, truth = sc.simulate(np.random.default_rng(5))
    p = build_gated_problem(scan, probability=0.99)
    full = np.prod(np.array(scan.sizes) + 1)
    assert full > 10_000_000 and p.n_candidates < full / 100
    assert not p.uncovered()


def test_bad_compatibility_is_named():
    with pytest.raises(InvalidProblemError, match=r"sensors \(0, 1\) must have shape"):
        gated_tuples((2, 2), {(0, 1): np.ones((3, 2), bool)}, 1.0)
    with pytest.raises(InvalidProblemError, match="must be a sensor pair"):
        gated_tuples((2, 2), {(1, 0): np.ones((2, 2), bool)}, 1.0)


def _forms(M: np.ndarray, rng) -> list:
    """One compatibility matrix in every form gated_tuples accepts."""
    from scipy import sparse
    i, j = np.nonzero(M)
    pairs = np.stack([i, j], axis=1).astype(np.int64)
    dup = pairs[rng.integers(0, len(pairs), size=len(pairs) // 2)] if len(pairs) else pairs
    coo = sparse.coo_matrix((np.ones(len(i), bool), (i, j)), shape=M.shape)
    return [sparse.csr_matrix(M), sparse.csc_array(M), coo,
            np.concatenate([pairs, dup])[rng.permutation(len(pairs) + len(dup))]]


@given(st.integers(0, 10_000), st.integers(2, 4), st.booleans(), st.booleans())
def test_sparse_and_index_pair_forms_give_the_dense_result(seed, N, miss, clutter):
    rng = np.random.default_rng(seed)
    sizes = tuple(int(v) for v in rng.integers(0, 5, size=N))
    pd = np.where(rng.random(N) < 0.5, 1.0, 0.8) if miss else np.ones(N)
    cd = rng.choice([0.0, 0.5], size=N) if clutter else np.zeros(N)
    ok = {(s, t): rng.random((sizes[s], sizes[t])) < 0.4
          for s, t in itertools.combinations(range(N), 2) if rng.random() < 0.8}
    want = gated_tuples(sizes, ok, pd, cd)
    per_key = {k: _forms(M, rng) for k, M in ok.items()}
    for f in range(4):
        got = gated_tuples(sizes, {k: v[f] for k, v in per_key.items()}, pd, cd)
        assert np.array_equal(got, want), f
    mixed = {k: v[int(rng.integers(0, 4))] for k, v in per_key.items()}
    assert np.array_equal(gated_tuples(sizes, mixed, pd, cd), want)


def test_sparse_gates_never_allocate_the_pair_matrices():
    """20 000 measurements a sensor: a dense compatibility matrix would take 400 MB."""
    import tracemalloc
    from scipy import sparse
    n = 20_000
    rng = np.random.default_rng(0)
    perm = [rng.permutation(n) for _ in range(3)]
    eye = {(s, t): sparse.csr_matrix((np.ones(n, bool), (perm[s], perm[t])), shape=(n, n))
           for s, t in itertools.combinations(range(3), 2)}
    tracemalloc.start()
    T = gated_tuples((n, n, n), eye, 0.9)
    peak = tracemalloc.get_traced_memory()[1]
    tracemalloc.stop()
    assert peak < 60e6
    full = T[(T > 0).all(axis=1)]
    assert len(full) == n and len(T) == 7 * n       # triples, three pair kinds, singles
    assert (perm[1][np.argsort(perm[0])][full[:, 0] - 1] == full[:, 1] - 1).all()


def test_bad_index_pairs_are_named():
    with pytest.raises(InvalidProblemError, match=r"index pairs must lie in"):
        gated_tuples((2, 2), {(0, 1): np.array([[0, 2]])}, 1.0)
    with pytest.raises(InvalidProblemError, match=r"must have shape"):
        from scipy import sparse
        gated_tuples((2, 2), {(0, 1): sparse.csr_matrix((3, 2), dtype=bool)}, 1.0)


def _same_gate(scan, **kw):
    fast = bearing_pair_gate(scan, **kw)
    slow = bearing_pair_gate(scan, prefilter=False, **kw)
    assert set(fast) == set(slow)
    for k in slow:
        assert np.array_equal(fast[k].toarray(), slow[k].toarray()), k
    return slow


@pytest.mark.parametrize("seed", range(6))
def test_prefiltered_bearing_gate_equals_the_all_pairs_test_in_space(seed):
    rng = np.random.default_rng(seed)
    n = int(rng.integers(3, 12))
    sc = Lu2013(n_targets=n, d=float(rng.choice([0.5, 2.0])), sensors_km=FIVE[:3 + seed % 3],
                pd=float(rng.choice([1.0, 0.8])), clutter_rate=float(rng.choice([0.0, 2.0])),
                sigma_mrad=float(rng.choice([1.5, 5.0])))
    scan, _ = sc.simulate(rng)
    for p in (0.9, 0.99, 0.9999):
        slow = _same_gate(scan, probability=p)
        assert any(M.nnz for M in slow.values())
    _same_gate(scan, probability=0.99, max_range=30.0)
    _same_gate(scan, probability=1.0)                      # no residual test: all pairs


@pytest.mark.parametrize("seed", range(6))
def test_prefiltered_bearing_gate_equals_the_all_pairs_test_in_the_plane(seed):
    from assocopt.tracking.costs.sd_builder import Scan
    rng = np.random.default_rng(seed)
    S = rng.uniform(-20, 20, size=(int(rng.integers(2, 5)), 2))
    X = rng.uniform(-30, 30, size=(int(rng.integers(2, 15)), 2))
    meas = [np.arctan2(X[:, 1] - p[1], X[:, 0] - p[0]) + rng.normal(0, 1e-3, len(X))
            for p in S]
    meas = [np.concatenate([m, rng.uniform(-np.pi, np.pi, 3)]) for m in meas]
    scan = Scan.create(S, meas, 1e-6)
    slow = _same_gate(scan)
    assert any(M.nnz for M in slow.values()) and not all(
        M.nnz == M.shape[0] * M.shape[1] for M in slow.values())
    for r in (5.0, 20.0, 60.0):
        _same_gate(scan, max_range=r)


def _volume_scan(n, seed, sigma=1.5e-3):
    """Targets spread through a volume, three sensors at different heights."""
    from assocopt.tracking.costs.sd_builder import Scan
    rng = np.random.default_rng(seed)
    S = np.array([[0.0, 0.0, 0.0], [60.0, 0.0, 0.5], [30.0, -50.0, 1.0]])
    X = np.column_stack([rng.uniform(-100, 150, n), rng.uniform(40, 200, n),
                         rng.uniform(1, 15, n)])
    th = angles(X, S)
    meas = [th[rng.permutation(n), s] + rng.normal(0, sigma, (n, 2)) for s in range(3)]
    return Scan.create(S, meas, np.eye(2) * sigma ** 2)


@pytest.mark.parametrize("seed", range(2))
def test_prefilter_keeps_few_more_than_the_exact_test(seed):
    scan = _volume_scan(120, seed)
    from assocopt.tracking.gating import bearing as bg
    slow = _same_gate(scan, probability=0.99)
    for (s, t), M in slow.items():
        cand = len(bg._epipolar_candidates(scan, s, t, bg.chi2_threshold(0.99, 1))[0])
        assert M.nnz <= cand < 2 * M.nnz + 50
        assert cand < 0.3 * 120 * 120


@pytest.mark.parametrize("method", ["pattipati", "skld-exact", "pattipati-ml"])
def test_costs_in_chunks_equal_the_costs_of_all_tuples(method):
    from assocopt.tracking.costs.sd_builder import tuple_costs_in_chunks
    from assocopt.tracking.costs.sd_builder import COST_LOCALISER
    sc = Lu2013(n_targets=5, d=2.0, sensors_km=FIVE[:3], pd=0.8, clutter_rate=1.0)
    scan, _ = sc.simulate(np.random.default_rng(2))
    T = candidate_tuples(scan.sizes, scan.pd, scan.clutter_density)
    g = tuple_geometry(scan, T, localiser=COST_LOCALISER.get(method, "ls"))
    want = tuple_costs(scan, g, method).total
    got = tuple_costs_in_chunks(scan, T, method, chunk=17)
    assert np.array_equal(np.isinf(got), np.isinf(want))
    assert got[np.isfinite(want)] == pytest.approx(want[np.isfinite(want)], rel=1e-12)
