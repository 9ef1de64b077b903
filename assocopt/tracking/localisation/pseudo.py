"""Pseudo-measurements: the bearings a localised position implies, with their covariance."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from .geometry import _check_sensors

__all__ = ["pseudo_measurements", "PseudoMeasurements"]


@dataclass(frozen=True)
class PseudoMeasurements:
    """First-order statistics of the pseudo-measurements ``G(x)``, ``x ~ N(x_hat, P)``.

    Attributes
    ----------
    mean : ndarray (K, N, 2)
        ``G(x_hat)`` (22): ``[alpha, beta]`` per sensor, rad.
    cov : ndarray (K, N, 2, 2)
        Diagonal blocks of ``g P g^T`` (23), one 2x2 block per sensor.
    jac : ndarray (K, N, 2, 3)
        ``g_x(x_hat)``.
    full : ndarray (K, 2N, 2N) or None
        The whole ``g P g^T`` with the cross-sensor blocks (the paper keeps
        only the diagonal blocks), when asked for.
        Its rank is at most 3 (all pseudo-measurements derive from one 3-D point).
    """

    mean: np.ndarray
    cov: np.ndarray
    jac: np.ndarray
    full: np.ndarray | None = None


def pseudo_measurements(x: ArrayLike, P: ArrayLike, sensors: ArrayLike, *,
                        full: bool = False) -> PseudoMeasurements:
    """Mean (22) and covariance (23) of the pseudo-measurements, by linearisation (21).

    Examples
    --------
    >>> S = np.array([[0, 20, 0], [20, 0, 0], [0, 0, 0.0]])
    >>> pm = pseudo_measurements([[12.0, 9.0, 5.0]], 1e-4 * np.eye(3)[None], S, full=True)
    >>> pm.mean.shape, pm.cov.shape, pm.full.shape
    ((1, 3, 2), (1, 3, 2, 2), (1, 6, 6))
    """
    X = np.asarray(x, dtype=np.float64).reshape(-1, 3)
    Pm = np.asarray(P, dtype=np.float64).reshape(-1, 3, 3)
    S = _check_sensors(sensors)
    K, N = len(X), len(S)
    mean = np.empty((K, N, 2))
    g = np.empty((K, N, 2, 3))
    cov = np.empty((K, N, 2, 2))
    p = [[Pm[:, i, j] for j in range(3)] for i in range(3)]
    for s in range(N):                      # loop over sensors only, elementwise inside
        dx, dy, dz = X[:, 0] - S[s, 0], X[:, 1] - S[s, 1], X[:, 2] - S[s, 2]
        rho2 = dx * dx + dy * dy
        rho = np.sqrt(rho2)
        r2 = rho2 + dz * dz
        mean[:, s, 0] = np.arctan2(dz, rho)
        mean[:, s, 1] = np.arctan2(dy, dx)
        ga = (-dx * dz / (r2 * rho), -dy * dz / (r2 * rho), rho / r2)
        gb = (-dy / rho2, dx / rho2, np.zeros_like(dx))
        g[:, s, 0] = np.stack(ga, axis=-1)
        g[:, s, 1] = np.stack(gb, axis=-1)
        Pga = [p[i][0] * ga[0] + p[i][1] * ga[1] + p[i][2] * ga[2] for i in range(3)]
        Pgb = [p[i][0] * gb[0] + p[i][1] * gb[1] for i in range(3)]
        cov[:, s, 0, 0] = ga[0] * Pga[0] + ga[1] * Pga[1] + ga[2] * Pga[2]
        cov[:, s, 1, 1] = gb[0] * Pgb[0] + gb[1] * Pgb[1]
        cov[:, s, 0, 1] = cov[:, s, 1, 0] = gb[0] * Pga[0] + gb[1] * Pga[1]
    F = None
    if full:
        gf = g.reshape(K, 2 * N, 3)
        F = gf @ Pm @ np.swapaxes(gf, -1, -2)
    return PseudoMeasurements(mean=mean, cov=cov, jac=g, full=F)
