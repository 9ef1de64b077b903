"""Azimuth-only sensors in the plane: localisation and pseudo-measurements.

The planar counterpart of :mod:`assocopt.tracking.localisation` (azimuth and elevation in 3-D).
A sensor at :math:`(x_s, y_s)` measures the azimuth
:math:`\\beta = \\operatorname{atan2}(y - y_s, x - x_s)` (rad, four-quadrant).  Its
line of sight gives one linear equation in the target position :math:`p = (x, y)`,

.. math:: \\sin\\beta\\,(x - x_s) - \\cos\\beta\\,(y - y_s) = 0,

so a tuple with at least two real azimuths is localised by linear least squares on
these equations (the planar form of paper 002's line-of-sight system).  Its
covariance is the sandwich :math:`A^{-1} (\\sum_s r_s h_s^2 H_s^T H_s) A^{-1}` with
:math:`A = \\sum_s H_s^T H_s`, :math:`H_s = [\\sin\\beta_s, -\\cos\\beta_s]` and
:math:`h_s` the derivative of the equation residual with respect to the azimuth, the
range along the line of sight :math:`\\cos\\beta_s (x - x_s) + \\sin\\beta_s (y - y_s)`
(``covariance="residual"``; ``"printed"`` evaluates it at the sensor position as
paper 002 prints it).  The pseudo-measurement of sensor ``s`` is the azimuth of the
estimate, with variance :math:`g_s P g_s^T`, :math:`g_s = (-\\Delta y, \\Delta x)/\\rho^2`.
"""

from __future__ import annotations

from typing import Sequence

import numpy as np
from numpy.typing import ArrayLike

from ...runtime.errors import InvalidProblemError
from .estimate import RCOND_MIN, Localisation
from .geometry import COVARIANCES
from .pseudo import PseudoMeasurements

__all__ = ["azimuths", "localise_azimuths", "azimuth_pseudo_measurements",
           "planar_tuple_geometry"]


def _check_sensors(sensors: ArrayLike) -> np.ndarray:
    S = np.asarray(sensors, dtype=np.float64)
    if S.ndim != 2 or S.shape[1] != 2 or len(S) < 2:
        raise InvalidProblemError(f"planar sensors must have shape (N, 2) with N >= 2, "
                                  f"got {S.shape}")
    if not np.isfinite(S).all():
        raise InvalidProblemError("sensor positions must be finite")
    return S


def azimuths(points: ArrayLike, sensors: ArrayLike) -> np.ndarray:
    """True azimuth (rad) of every point from every sensor, shape ``(..., N)``.

    >>> azimuths([[1.0, 1.0]], [[0.0, 0.0], [2.0, 0.0]]).round(4).tolist()
    [[0.7854, 2.3562]]
    """
    P = np.asarray(points, dtype=np.float64)
    S = _check_sensors(sensors)
    d = P[..., None, :] - S
    return np.arctan2(d[..., 1], d[..., 0])


def localise_azimuths(meas: Sequence[ArrayLike], R: Sequence[ArrayLike], sensors: ArrayLike,
                      tuples: ArrayLike, *, covariance: str = "residual") -> Localisation:
    """Least-squares positions of S-D candidate tuples of azimuth-only measurements.

    ``meas[s]`` holds sensor s's azimuths ``(n_s,)`` (or ``(n_s, 1)``), ``R[s]`` their
    variances (``(n_s,)`` or ``(n_s, 1, 1)``); ``tuples`` is ``(K, N)`` with 1-based
    indices and 0 for a dummy.  Built by gathering per-measurement parts of the normal
    equations (no matrix per tuple).

    >>> S = np.array([[0.0, 0.0], [10.0, 0.0]])
    >>> b = azimuths([[4.0, 3.0]], S)[0]
    >>> loc = localise_azimuths([b[:1], b[1:]], [[1e-6], [1e-6]], S, [[1, 1]])
    >>> np.round(loc.x, 9).tolist(), loc.valid.tolist()
    ([[4.0, 3.0]], [True])
    """
    S = _check_sensors(sensors)
    N = len(S)
    T = np.asarray(tuples, dtype=np.int64)
    if T.ndim != 2 or T.shape[1] != N:
        raise InvalidProblemError(f"tuples must have shape (K, {N}), got {T.shape}")
    if covariance not in COVARIANCES:
        raise InvalidProblemError(f"covariance must be one of {COVARIANCES}, got {covariance!r}")
    if len(meas) != N or len(R) != N:
        raise InvalidProblemError(f"meas and R must list {N} arrays (one per sensor)")
    K = len(T)
    mask = T > 0
    parts = [_sensor_parts(meas[s], R[s], S[s], T[:, s], s) for s in range(N)]
    A = sum(p["A"][T[:, s]] for s, p in enumerate(parts))          # (K, 3): xx, xy, yy
    b = sum(p["b"][T[:, s]] for s, p in enumerate(parts))          # (K, 2)
    xx, xy, yy = A[:, 0], A[:, 1], A[:, 2]
    det = xx * yy - xy * xy
    tr = xx + yy
    with np.errstate(invalid="ignore", divide="ignore"):
        disc = np.sqrt(np.maximum(0.25 * tr * tr - det, 0.0))
        lam_min, lam_max = 0.5 * tr - disc, 0.5 * tr + disc
        ok = (mask.sum(axis=1) >= 2) & (lam_max > 0) & (lam_min > RCOND_MIN * lam_max)
        inv = np.stack([yy, -xy, -xy, xx], axis=1).reshape(K, 2, 2) / det[:, None, None]
    inv = np.where(ok[:, None, None], inv, 0.0)
    x = (inv @ b[..., None])[..., 0]
    mid = np.zeros((K, 2, 2))
    for s, p in enumerate(parts):
        idx = T[:, s]
        sb, cb = p["sb"][idx], p["cb"][idx]
        d = (x - S[s]) if covariance == "residual" else np.broadcast_to(S[s], x.shape)
        h = cb * d[:, 0] + sb * d[:, 1]
        w = p["r"][idx] * h * h
        Hs = np.stack([sb, -cb], axis=1)
        mid += w[:, None, None] * Hs[:, :, None] * Hs[:, None, :]
    P = inv @ mid @ inv
    x = np.where(ok[:, None], x, np.nan)
    P = np.where(ok[:, None, None], P, np.nan)
    return Localisation(x=x, P=P, valid=ok, n_real=mask.sum(axis=1), method="ls",
                        covariance=covariance)


def _sensor_parts(meas, R, sensor, col, s) -> dict[str, np.ndarray]:
    """Per-measurement normal-equation parts, index 0 = dummy (zeros)."""
    b = np.asarray(meas, dtype=np.float64).reshape(-1)
    r = np.asarray(R, dtype=np.float64).reshape(-1)
    if len(b) != len(r):
        raise InvalidProblemError(f"sensor {s}: {len(b)} azimuths but {len(r)} variances")
    if len(col) and col.max(initial=0) > len(b):
        raise InvalidProblemError(f"tuples refer to measurement {col.max()} of sensor {s}, "
                                  f"which has {len(b)}")
    pad = np.concatenate([[0.0], np.ones(len(b))])
    beta = np.concatenate([[0.0], b])
    sb, cb = np.sin(beta) * pad, np.cos(beta) * pad
    y = sb * sensor[0] - cb * sensor[1]
    return {"A": np.stack([sb * sb, -sb * cb, cb * cb], axis=1),
            "b": np.stack([sb * y, -cb * y], axis=1),
            "sb": sb, "cb": cb, "r": np.concatenate([[0.0], r])}


def azimuth_pseudo_measurements(x: ArrayLike, P: ArrayLike, sensors: ArrayLike
                                ) -> PseudoMeasurements:
    """Azimuth of each estimate from each sensor and its first-order variance.

    Shapes: ``mean (K, N, 1)``, ``cov (K, N, 1, 1)``, ``jac (K, N, 1, 2)``.

    >>> pm = azimuth_pseudo_measurements([[3.0, 4.0]], np.eye(2)[None] * 1e-2,
    ...                                  [[0.0, 0.0], [6.0, 0.0]])
    >>> pm.cov[0, :, 0, 0].round(6).tolist()                  # 1e-2 / range^2
    [0.0004, 0.0004]
    """
    X = np.asarray(x, dtype=np.float64).reshape(-1, 2)
    Pm = np.asarray(P, dtype=np.float64).reshape(-1, 2, 2)
    S = _check_sensors(sensors)
    d = X[:, None, :] - S[None]                                   # (K, N, 2)
    rho2 = (d * d).sum(axis=-1)
    g = np.stack([-d[..., 1], d[..., 0]], axis=-1) / rho2[..., None]
    var = np.einsum("kni,kij,knj->kn", g, Pm, g)
    return PseudoMeasurements(mean=np.arctan2(d[..., 1], d[..., 0])[..., None],
                              cov=var[..., None, None], jac=g[:, :, None, :])


def planar_tuple_geometry(scan, tuples: np.ndarray, localiser: str = "ls",
                          covariance: str = "residual") -> tuple[np.ndarray, ...]:
    """Positions, covariances, validity and pseudo-measurements of the tuples of an
    azimuth-only :class:`~assocopt.tracking.costs.sd_builder.Scan` (for its ``tuple_geometry``).

    Returns ``(x, P, valid, pm_mean, pm_cov)``; pseudo-measurements of tuples that
    cannot be localised are 0 with unit variance (their costs are forbidden anyway).
    """
    if localiser != "ls":
        raise InvalidProblemError(f"azimuth-only sensors support localiser='ls', "
                                  f"got {localiser!r}")
    K, N = tuples.shape
    loc = localise_azimuths([m[:, 0] for m in scan.meas], [r[:, 0, 0] for r in scan.R],
                            scan.sensors, tuples, covariance=covariance)
    pm_mean = np.zeros((K, N, 1))
    pm_cov = np.ones((K, N, 1, 1))
    good = np.flatnonzero(loc.valid)
    if len(good):
        pm = azimuth_pseudo_measurements(loc.x[good], loc.P[good], scan.sensors)
        pm_mean[good], pm_cov[good] = pm.mean, pm.cov
    return loc.x, loc.P, loc.valid, pm_mean, pm_cov
