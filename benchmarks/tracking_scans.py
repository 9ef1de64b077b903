"""Gated S-D scans of the kind a multi-sensor tracker solves (the generator of
``benchmarks/sd_tracking.py``; tests draw from it too).

``N`` position sensors in the plane see ``n`` targets (each detected with probability
``pd``, Gaussian noise ``sigma`` per coordinate) plus ``clutter * n`` false alarms
per sensor, uniform over the surveillance square.  The square's side is
``spacing * gate_radius * sqrt(n)``: ``spacing`` is the mean distance between
neighbouring targets in gate radii (4: well separated, below 1: targets closer than
the gate, one dense cluster).  ``gate_radius = sigma * sqrt(2 * gamma)`` is the
distance at which two measurements of one target stop being compatible, ``gamma``
the ``gate`` quantile of chi-square with 2 degrees of freedom.

Tuples are gated pairwise (the chi-square gate of each sensor pair, a distance test
here, by KD-trees; :func:`assocopt.tracking.gating.gated_tuples` for the cliques), and each tuple
costs its negative log-likelihood ratio against "all its measurements are false
alarms" (Deb et al. 1997, positions known up to the ML estimate):

    c = sum_i |z_i - x|^2 / (2 sigma^2) + m log(2 pi sigma^2 lambda / pd)
        - (N - m) log(1 - pd),

``m`` real measurements, ``x`` their mean, ``lambda`` the clutter density (per unit
area; at least one false alarm per square so that the ratio is defined);
single-measurement tuples cost 0 (the reference).
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass

import numpy as np

from assocopt import AssignmentProblem
from assocopt.tracking.gating import chi2_threshold, gated_tuples

__all__ = ["ScanSpec", "draw_scan", "pair_gate", "gated", "nllr", "build_problem"]


@dataclass(frozen=True)
class ScanSpec:
    """One scan's parameters (all recorded in the benchmark's JSON)."""

    N: int                  # sensors
    n: int                  # targets
    spacing: float = 4.0    # mean target spacing, in gate radii
    clutter: float = 0.2    # false alarms per sensor, as a share of n
    pd: float = 0.9
    sigma: float = 1.0
    gate: float = 0.999     # pairwise gate probability
    seed: int = 0

    @property
    def gamma(self) -> float:
        return chi2_threshold(self.gate, 2)

    @property
    def gate_radius(self) -> float:
        return self.sigma * math.sqrt(2.0 * self.gamma)

    @property
    def side(self) -> float:
        return self.spacing * self.gate_radius * math.sqrt(self.n)


def draw_scan(spec: ScanSpec) -> list[np.ndarray]:
    """The measurements of each sensor, ``(M_s, 2)`` in random order (one seed)."""
    rng = np.random.default_rng(spec.seed)
    L = spec.side
    targets = rng.random((spec.n, 2)) * L
    out = []
    for _ in range(spec.N):
        seen = targets[rng.random(spec.n) < spec.pd]
        fa = rng.random((rng.poisson(spec.clutter * spec.n), 2)) * L
        z = np.concatenate([seen + rng.normal(0.0, spec.sigma, seen.shape), fa])
        out.append(z[rng.permutation(len(z))])
    return out


def pair_gate(spec: ScanSpec, meas: list[np.ndarray]) -> dict[tuple[int, int], np.ndarray]:
    """Compatible measurement pairs of every sensor pair: the chi-square gate on
    ``z_s - z_t`` (covariance ``2 sigma^2 I``, so the Mahalanobis test is a distance
    test: ``|z_s - z_t| <= gate_radius``), by KD-trees; each pair's compatible
    ``(i, j)`` as an ``(m, 2)`` index array (no ``n_s x n_t`` matrix)."""
    from scipy.spatial import cKDTree
    N = spec.N
    trees = [cKDTree(z) for z in meas]
    ok = {}
    for s in range(N):
        for t in range(s + 1, N):
            D = trees[s].sparse_distance_matrix(trees[t], spec.gate_radius,
                                                output_type="ndarray")
            ok[(s, t)] = np.stack([D["i"], D["j"]], axis=1).astype(np.int64)
    return ok


def gated(spec: ScanSpec, meas: list[np.ndarray], ok=None) -> np.ndarray:
    """The pairwise-gated tuples (0 = dummy): :func:`pair_gate`, then the cliques
    (:func:`assocopt.tracking.gating.gated_tuples`)."""
    ok = pair_gate(spec, meas) if ok is None else ok
    # single-measurement tuples: a false alarm is always possible
    return gated_tuples([len(z) for z in meas], ok, np.full(spec.N, spec.pd),
                        np.ones(spec.N))


def nllr(spec: ScanSpec, meas: list[np.ndarray], T: np.ndarray) -> np.ndarray:
    """Negative log-likelihood ratio of each tuple (single measurements: 0)."""
    N = spec.N
    real = T > 0
    m = real.sum(axis=1)
    xs = np.zeros((len(T), 2))
    for s in range(N):
        xs[real[:, s]] += meas[s][T[real[:, s], s] - 1]
    x = xs / np.maximum(m, 1)[:, None]
    r2 = np.zeros(len(T))
    for s in range(N):
        k = real[:, s]
        r2[k] += ((meas[s][T[k, s] - 1] - x[k]) ** 2).sum(axis=1)
    lam = max(spec.clutter * spec.n, 1.0) / spec.side ** 2
    c = r2 / (2 * spec.sigma ** 2) + m * math.log(2 * math.pi * spec.sigma ** 2 * lam / spec.pd) \
        - (N - m) * math.log(1 - spec.pd)
    c[m < 2] = 0.0
    return c


def build_problem(spec: ScanSpec) -> tuple[AssignmentProblem, dict]:
    """The scan's S-D problem and the times of its parts: ``gate_s`` the pairwise
    gate, ``tuples_s`` :func:`gated_tuples`, ``costs_s`` the costs."""
    meas = draw_scan(spec)
    t0 = time.perf_counter()
    ok = pair_gate(spec, meas)
    tg = time.perf_counter()
    T = gated(spec, meas, ok)
    t1 = time.perf_counter()
    c = nllr(spec, meas, T)
    t2 = time.perf_counter()
    p = AssignmentProblem.sparse([len(z) for z in meas], T, c,
                                 name=f"N{spec.N}-n{spec.n}-s{spec.spacing:g}-"
                                      f"c{spec.clutter:g}-seed{spec.seed}")
    return p, {"gate_s": tg - t0, "tuples_s": t1 - tg, "costs_s": t2 - t1}
