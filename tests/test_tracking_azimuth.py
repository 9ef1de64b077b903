"""Azimuth-only (planar) sensors in the bearing builders."""

from __future__ import annotations

import math

import numpy as np
import pytest

from assocopt import solve
from assocopt.tracking.costs import kld as dv
from assocopt.tracking.costs.sd_builder import Scan, build_costs, build_problem, tuple_geometry
from assocopt.runtime.errors import InvalidProblemError
from assocopt.tracking.localisation.azimuth import (azimuth_pseudo_measurements, azimuths,
                                       localise_azimuths)
from assocopt.tracking.gating import build_gated_problem

SENSORS = np.array([[0.0, 0.0], [30.0, 0.0], [15.0, -25.0]])


def _scan(rng, targets, sigma=1e-3, pd=1.0, shuffle=True):
    th = azimuths(targets, SENSORS)                       # (M, N)
    meas, perms = [], []
    for s in range(len(SENSORS)):
        order = rng.permutation(len(targets)) if shuffle else np.arange(len(targets))
        meas.append(th[order, s] + rng.normal(0, sigma, size=len(targets)))
        perms.append(order)
    return Scan.create(SENSORS, meas, sigma ** 2, pd=pd), perms


def test_ls_position_equals_lstsq_and_covariance_equals_the_jacobian_sandwich():
    rng = np.random.default_rng(0)
    X = rng.uniform(5, 25, size=(6, 2))
    b = azimuths(X, SENSORS)
    r = np.array([1e-6, 4e-6, 2.5e-6])
    T = np.array([[k + 1, k + 1, k + 1] for k in range(6)] + [[1, 0, 1], [0, 2, 2]])
    loc = localise_azimuths([b[:, s] for s in range(3)], [np.full(6, r[s]) for s in range(3)],
                            SENSORS, T)
    for k, t in enumerate(T):
        real = np.flatnonzero(t > 0)
        beta = b[t[real] - 1, real]
        H = np.stack([np.sin(beta), -np.cos(beta)], axis=1)
        Y = np.sin(beta) * SENSORS[real, 0] - np.cos(beta) * SENSORS[real, 1]
        np.testing.assert_allclose(loc.x[k], np.linalg.lstsq(H, Y, rcond=None)[0], atol=1e-9)

        def solve_ls(beta):
            H = np.stack([np.sin(beta), -np.cos(beta)], axis=1)
            Y = np.sin(beta) * SENSORS[real, 0] - np.cos(beta) * SENSORS[real, 1]
            return np.linalg.lstsq(H, Y, rcond=None)[0]
        eps = 1e-7
        J = np.stack([(solve_ls(beta + eps * e) - solve_ls(beta - eps * e)) / (2 * eps)
                      for e in np.eye(len(real))], axis=1)
        np.testing.assert_allclose(loc.P[k], J @ np.diag(r[real]) @ J.T, rtol=1e-5)
    assert loc.valid.all()


def test_single_measurement_and_parallel_lines_are_not_localised():
    S = np.array([[0.0, 0.0], [10.0, 0.0]])
    loc = localise_azimuths([[0.0], [0.0]], [[1e-6], [1e-6]], S, [[1, 0], [1, 1]])
    assert loc.valid.tolist() == [False, False]          # one line; two parallel lines


def test_pseudo_measurement_variance_is_first_order():
    x = np.array([[12.0, 7.0]])
    P = np.array([[[0.04, 0.01], [0.01, 0.09]]])
    pm = azimuth_pseudo_measurements(x, P, SENSORS)
    eps = 1e-6
    for s in range(3):
        g = np.array([(azimuths(x + eps * e, SENSORS)[0, s] - azimuths(x - eps * e, SENSORS)[0, s])
                      / (2 * eps) for e in np.eye(2)])
        assert pm.cov[0, s, 0, 0] == pytest.approx(g @ P[0] @ g, rel=1e-6)
        assert pm.mean[0, s, 0] == pytest.approx(azimuths(x, SENSORS)[0, s])


@pytest.mark.parametrize("method", ["pattipati", "kld-exact", "skld-exact", "kld-printed",
                                    "skld-printed", "kld-joint", "skld-joint"])
def test_planar_tuple_costs_are_the_one_dimensional_forms(method):
    rng = np.random.default_rng(1)
    scan, _ = _scan(rng, rng.uniform(5, 25, size=(3, 2)), pd=0.9)
    c = build_costs(scan, [method], normalisation="gaussian")[method]
    g = tuple_geometry(scan)
    fn = {"pattipati": lambda mt, vt, m, v: (mt - m) ** 2 / v,
          "kld-exact": dv.kld_exact, "skld-exact": dv.skld_exact,
          "kld-printed": dv.kld_printed, "skld-printed": dv.skld_printed,
          "kld-joint": dv.kld_exact, "skld-joint": dv.skld_exact}[method]
    for k, t in enumerate(c.tuples):
        real = np.flatnonzero(t > 0)
        if len(real) < 2:
            assert c.total[k] == 0.0
            continue
        data = 0.0
        const = 0.0
        for s in range(3):
            if t[s] == 0:
                const -= math.log(1 - 0.9)
                continue
            m, v = scan.meas[s][t[s] - 1, 0], scan.R[s][t[s] - 1, 0, 0]
            mt, vt = g.pm_mean[k, s, 0], g.pm_cov[k, s, 0, 0]
            mt = m + math.remainder(mt - m, 2 * math.pi)
            data += 0.5 * fn(mt, vt, m, v)
            const += math.log(math.sqrt(2 * math.pi * v) / 0.9)
        assert c.data[k] == pytest.approx(data, rel=1e-9, abs=1e-12)
        assert c.total[k] == pytest.approx(const + data, rel=1e-9)


def test_planar_scan_recovers_the_true_association():
    rng = np.random.default_rng(4)
    X = np.array([[5.0, 5.0], [12.0, 18.0], [26.0, 12.0], [2.0, 24.0]])  # no two collinear
    scan, perms = _scan(rng, X)
    truth = {tuple(int(np.flatnonzero(perms[s] == j)[0]) + 1 for s in range(3))
             for j in range(len(X))}
    for p in (build_problem(scan, "skld-exact", name="plane"),
              build_gated_problem(scan, "skld-exact", name="plane-gated")):
        assert {tuple(t) for t in solve(p).tuples.tolist()} == truth
    assert build_problem(scan, "skld-exact", name="plane").name == "plane"
    assert build_problem(scan).name == "bearing-pattipati"
    assert build_gated_problem(scan).n_candidates < build_problem(scan).n_candidates


def test_planar_input_errors_are_named():
    with pytest.raises(InvalidProblemError, match="azimuth only"):
        Scan.create(np.zeros((2, 4)), [[0.1], [0.2]], 1e-6)
    with pytest.raises(InvalidProblemError, match="a variance, \\(N,\\)"):
        Scan.create(SENSORS, [[0.1], [0.2], [0.3]], np.eye(2))
    with pytest.raises(InvalidProblemError, match="positive definite"):
        Scan.create(SENSORS, [[0.1], [0.2], [0.3]], -1.0)
    scan = Scan.create(SENSORS, [[0.1], [0.2], [0.3]], 1e-6)
    with pytest.raises(InvalidProblemError, match="localiser='ls'"):
        tuple_geometry(scan, localiser="ils")
