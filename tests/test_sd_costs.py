"""S-D cost builders of paper 002: dummy conventions, vectorised vs per-tuple, optimality."""

from __future__ import annotations

import itertools
import math

import numpy as np
import pytest

from assocopt import InvalidProblemError, solve
from assocopt.tracking.costs import (COSTS, Scan, build_costs, build_problem, candidate_tuples,
                            tuple_geometry)
from assocopt.tracking.costs.kld import (kld_exact, kld_gauss, kld_printed, skld_exact,
                                       skld_gauss, skld_printed)
from assocopt.tracking.costs.pattipati import measurement_constant
from assocopt.tracking.localisation import angles, localise, pseudo_measurements, wrap_angle
from assocopt.tracking.scenarios.lu2013 import Lu2013
from assocopt.solvers.baseline.bruteforce import count_solutions

S = np.array([[0.0, 20.0, 0.0], [20.0, 0.0, 0.0], [0.0, 0.0, 0.0]])


def _scan(M=3, pd=1.0, clutter=0.0, seed=0, sigma=1.5, d=1.0):
    sc = Lu2013(n_targets=M, d=d, sigma_mrad=sigma, pd=pd, clutter_rate=clutter,
                region_km=((0, 20), (0, 20), (1, 5)))
    return sc.simulate(np.random.default_rng(seed))


# --------------------------------------------------------------- candidate tuples
def test_pd_one_gives_only_fully_real_tuples():
    T = candidate_tuples((3, 2, 4), [1.0, 1.0, 1.0])
    assert len(T) == 24 and (T > 0).all()


def test_dummies_allowed_only_where_pd_below_one_and_never_all_dummy():
    T = candidate_tuples((2, 2, 2), [0.9, 1.0, 0.9])
    assert not (T == 0).all(axis=1).any()
    assert (T[:, 1] > 0).all()                              # sensor 1 may not miss
    n_real = (T > 0).sum(axis=1)
    # singletons only in sensor 1 (the others may miss), and only with dummies elsewhere
    singles = T[n_real == 1]
    assert len(singles) == 2 and (singles[:, 1] > 0).all()
    # axes 0 and 2 may miss (index 0..2), axis 1 may not (1..2): every such tuple,
    # none duplicated (none is all-dummy, since axis 1 is always real)
    expected = {(a, b, c) for a in range(3) for b in range(1, 3) for c in range(3)}
    assert len({tuple(t) for t in T.tolist()}) == len(T) == len(expected) == 18
    assert {tuple(t) for t in T.tolist()} == expected


def test_false_alarms_allow_singletons_even_with_pd_one():
    T = candidate_tuples((2, 2, 2), [1.0, 1.0, 1.0], clutter_density=[0.5, 0.0, 0.0])
    n_real = (T > 0).sum(axis=1)
    assert ((n_real == 3) | (n_real == 1)).all()
    assert sorted(map(tuple, T[n_real == 1].tolist())) == [(1, 0, 0), (2, 0, 0)]


def test_two_targets_have_exactly_four_feasible_solutions():
    scan, _ = _scan(M=2)
    for m in ("pattipati", "skld-exact"):
        p = build_problem(scan, m)
        assert p.n_candidates == 8 and count_solutions(p) == 4


# ------------------------------------------------------------ costs and conventions
def test_costs_are_finite_with_pd_one_and_dummies_never_reach_the_problem():
    scan, _ = _scan(M=4)
    for m, c in build_costs(scan).items():
        assert np.isfinite(c.total).all(), m
        p = build_problem(scan, m, costs=c)
        assert (p.tuples > 0).all() and np.isfinite(p.costs).all()


def test_single_measurement_tuples_cost_zero_and_dummy_terms_use_pd():
    scan, _ = _scan(M=3, pd=0.8, clutter=1.0, seed=2)
    costs = build_costs(scan, ["pattipati", "kld-exact"])
    for c in costs.values():
        n_real = (c.tuples > 0).sum(axis=1)
        assert (c.total[n_real == 1] == 0).all()
        assert np.isfinite(c.total).all()
    c = costs["pattipati"]
    # a two-real tuple carries one -ln(1 - P_D) dummy term
    k = np.flatnonzero((c.tuples > 0).sum(axis=1) == 2)[0]
    s_real = np.flatnonzero(c.tuples[k] > 0)
    R = np.eye(2) * (1.5e-3) ** 2
    want = 2 * float(measurement_constant(R, np.array(0.8))) - math.log(0.2)
    assert c.const[k] == pytest.approx(want)
    assert len(s_real) == 2


def test_printed_constant_matches_E2_3():
    c = measurement_constant(np.eye(2) * (1.5e-3) ** 2, np.array(1.0))
    assert float(c) == pytest.approx(-12.08, abs=0.01)
    g = measurement_constant(np.eye(2) * (1.5e-3) ** 2, np.array(1.0), "gaussian")
    assert float(g) == pytest.approx(math.log(2 * math.pi * 2.25e-6))


def test_noise_free_truth_has_zero_statistical_distance_and_is_optimal():
    X = np.array([[8.0, 6.0, 2.0], [10.0, 6.0, 2.0], [12.0, 6.0, 2.0], [14.0, 6.0, 2.0]])
    th = angles(X, S)                                        # exact angles
    order = [np.random.default_rng(s).permutation(4) for s in range(3)]
    scan = Scan.create(S, [th[order[s], s] for s in range(3)], np.eye(2) * 1e-12)
    c = build_costs(scan, ["pattipati"])["pattipati"]
    inv = [np.argsort(o) + 1 for o in order]                 # target j -> measurement index
    true = {tuple(int(inv[s][j]) for s in range(3)) for j in range(4)}
    idx = [i for i, t in enumerate(c.tuples.tolist()) if tuple(t) in true]
    assert np.abs(c.data[idx]).max() < 1e-3                  # rounding of the LS estimate only
    sol = solve(build_problem(scan, costs=c), "highs")
    assert {tuple(t) for t in sol.tuples.tolist()} == true


def test_printed_kld_data_term_is_negative_for_true_tuples_in_paper_geometry():
    """Printed (27): pseudo-measurement spread is below sigma, so (27) goes negative."""
    scan, truth = _scan(M=3, seed=5)
    c = build_costs(scan, ["kld-printed", "kld-exact"])
    true = {tuple(t) for t in truth.target_tuples().tolist()}
    idx = [i for i, t in enumerate(c["kld-printed"].tuples.tolist()) if tuple(t) in true]
    assert (c["kld-printed"].data[idx] < 0).all()
    assert (c["kld-exact"].data >= 0).all()


def _reference_cost(scan, t, method):
    """Straightforward per-tuple implementation of (7)/(24)/(25) for one tuple."""
    N = len(scan.sensors)
    real = [s for s in range(N) if t[s] > 0]
    if len(real) == 1:
        return 0.0
    m = np.zeros((1, N, 2))
    R = np.tile(np.eye(2), (1, N, 1, 1))
    for s in real:
        m[0, s] = scan.meas[s][t[s] - 1]
        R[0, s] = scan.R[s][t[s] - 1]
    loc = localise(m, scan.sensors, R, np.array([[t[s] > 0 for s in range(N)]]),
                   method="ils" if method == "pattipati-ml" else "ls")
    pm = pseudo_measurements(loc.x, loc.P, scan.sensors)
    total = 0.0
    for s in range(N):
        if t[s] == 0:
            total += -math.log1p(-scan.pd[s])
            continue
        Rs = R[0, s]
        total += math.log(math.sqrt(2 * math.pi * np.linalg.det(Rs)) / scan.pd[s])
        delta = m[0, s] - pm.mean[0, s]
        delta[1] = wrap_angle(delta[1])
        mu_t = m[0, s] + delta
        St = pm.cov[0, s]
        if method in ("pattipati", "pattipati-ml"):
            total += 0.5 * delta @ np.linalg.solve(Rs, delta)
        elif method == "kld-reversed":        # KL(measurement || pseudo-measurement)
            total += 0.5 * sum(
                0.5 * (Rs[c, c] / St[c, c] - 1 - math.log(Rs[c, c] / St[c, c])
                       + (mu_t[c] - m[0, s, c]) ** 2 / St[c, c]) for c in (0, 1))
        elif method.endswith("joint"):
            f = kld_gauss if method.startswith("kld") else skld_gauss
            total += 0.5 * float(f(mu_t, St, m[0, s], Rs))
        else:
            f = {"kld-printed": kld_printed, "skld-printed": skld_printed,
                 "kld-exact": kld_exact, "skld-exact": skld_exact}[method]
            total += 0.5 * sum(float(f(mu_t[c], St[c, c], m[0, s, c], Rs[c, c]))
                               for c in (0, 1))
    return total


@pytest.mark.parametrize("method", list(COSTS))
def test_vectorised_builder_matches_per_tuple_reference(method):
    scan, _ = _scan(M=3, pd=0.9, clutter=0.5, seed=3)
    c = build_costs(scan, [method])[method]
    assert len(c.tuples) > 20
    ref = np.array([_reference_cost(scan, t, method) for t in c.tuples.tolist()])
    np.testing.assert_allclose(c.total, ref, rtol=1e-7, atol=1e-7)


@pytest.mark.parametrize("method", ["pattipati", "kld-printed", "skld-exact", "kld-joint"])
def test_sd_optimum_matches_brute_force_with_dummies_and_false_alarms(method):
    scan, _ = _scan(M=2, pd=0.85, clutter=0.4, seed=7)
    p = build_problem(scan, method)
    bf = solve(p, "bruteforce")
    hi = solve(p, "highs")
    assert bf.objective == pytest.approx(hi.objective, rel=1e-9, abs=1e-9)


def test_costs_do_not_depend_on_measurement_order():
    scan, _ = _scan(M=4, seed=11)
    rng = np.random.default_rng(0)
    perms = [rng.permutation(len(m)) for m in scan.meas]
    scan2 = Scan.create(scan.sensors, [m[p] for m, p in zip(scan.meas, perms)],
                        [r[p] for r, p in zip(scan.R, perms)])
    a = solve(build_problem(scan, "skld-printed"), "highs")
    b = solve(build_problem(scan2, "skld-printed"), "highs")
    assert a.objective == pytest.approx(b.objective, rel=1e-12)


def test_azimuth_difference_is_wrapped_near_pi():
    """Targets west of sensor S2 = (20, 0, 0) just either side of y = 0: beta ~ +-pi."""
    X = np.array([[10.0, 0.001, 2.0], [12.0, -0.002, 3.0]])
    th = angles(X, S)
    assert np.sign(th[0, 1, 1]) != np.sign(th[1, 1, 1])
    scan = Scan.create(S, [th[:, s] for s in range(3)], np.eye(2) * 1e-6)
    c = build_costs(scan, ["pattipati", "skld-exact"])
    k = [i for i, t in enumerate(c["pattipati"].tuples.tolist()) if t == [1, 1, 1]][0]
    assert c["pattipati"].data[k] < 1e-12          # unwrapped, it would be ~ (2 pi)^2 / 1e-6
    # the divergence sees the same (wrapped) mean difference: only its variance term is left
    g = tuple_geometry(scan)
    st = np.diagonal(g.pm_cov[k], axis1=-2, axis2=-1)
    want = 0.5 * skld_exact(0.0, st, 0.0, 1e-6).sum()
    assert c["skld-exact"].data[k] == pytest.approx(want, rel=1e-9)


def test_unknown_cost_and_bad_scan_are_errors():
    scan, _ = _scan(M=2)
    with pytest.raises(InvalidProblemError, match="unknown cost 'kld'"):
        build_costs(scan, ["kld"])
    with pytest.raises(InvalidProblemError, match="pd must lie in"):
        Scan.create(S, [np.zeros((1, 2))] * 3, np.eye(2), pd=0.0)
    with pytest.raises(InvalidProblemError, match="positive definite"):
        Scan.create(S, [np.zeros((1, 2))] * 3, -np.eye(2))
    with pytest.raises(InvalidProblemError, match="normalisation must be one of"):
        build_costs(scan, ["pattipati"], normalisation="deb")


def test_builder_records_its_options():
    scan, _ = _scan(M=2)
    c = build_costs(scan, ["kld-exact"], normalisation="gaussian")["kld-exact"]
    assert c.options == {"normalisation": "gaussian", "localiser": "ls",
                         "covariance": "residual"}
    assert set(COSTS) == {"pattipati", "kld-printed", "skld-printed", "kld-exact",
                          "skld-exact", "kld-joint", "skld-joint", "pattipati-ml",
                          "kld-reversed"}
    ml = build_costs(scan, ["pattipati-ml"])["pattipati-ml"]
    assert ml.options["localiser"] == "ils"          # its own localiser, whatever the run's


def test_all_real_tuple_count_for_m20():
    T = candidate_tuples((20, 20, 20), [1, 1, 1])
    assert len(T) == 8000
    assert {tuple(t) for t in T[:3].tolist()} <= set(itertools.product(range(1, 21), repeat=3))
