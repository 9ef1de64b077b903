"""Bearing geometry of angle-only sensors: angles, their Jacobians, the line-of-sight system.

Conventions: see :mod:`assocopt.tracking.localisation`.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

from ...runtime.errors import InvalidProblemError

__all__ = ["angles", "angle_jacobian", "wrap_angle", "los_system", "residual_jacobian",
           "METHODS", "COVARIANCES"]

#: Estimators accepted by :func:`localise`.
METHODS = ("ls", "ils", "tls")
#: Covariance forms accepted by :func:`localise` (``"ls"``/``"tls"`` only).
COVARIANCES = ("residual", "printed")


def wrap_angle(a: ArrayLike) -> np.ndarray:
    """Wrap angles (rad) to ``(-pi, pi]``.

    >>> float(wrap_angle(3 * np.pi / 2))
    -1.5707963267948966
    """
    a = np.asarray(a, dtype=np.float64)
    w = np.mod(a + np.pi, 2 * np.pi) - np.pi
    return np.where(w == -np.pi, np.pi, w)


def _check_sensors(sensors: ArrayLike) -> np.ndarray:
    S = np.asarray(sensors, dtype=np.float64)
    if S.ndim != 2 or S.shape[1] != 3 or len(S) < 2:
        raise InvalidProblemError(f"sensors must have shape (N, 3) with N >= 2, got {S.shape}")
    if not np.isfinite(S).all():
        raise InvalidProblemError("sensor positions must be finite")
    return S


def angles(points: ArrayLike, sensors: ArrayLike) -> np.ndarray:
    """True ``[alpha, beta]`` (rad) of every point seen from every sensor, eqs. (1)-(2).

    Parameters
    ----------
    points : array, shape (..., 3)
    sensors : array, shape (N, 3)

    Returns
    -------
    ndarray, shape (..., N, 2): elevation ``alpha`` then azimuth ``beta``.

    Examples
    --------
    >>> th = angles([[1.0, 1.0, 0.0]], [[0, 0, 0], [2, 0, 0]])
    >>> np.round(np.degrees(th), 6).tolist()
    [[[0.0, 45.0], [0.0, 135.0]]]
    """
    P = np.asarray(points, dtype=np.float64)
    S = _check_sensors(sensors)
    d = P[..., None, :] - S                        # (..., N, 3)
    rho = np.hypot(d[..., 0], d[..., 1])
    return np.stack([np.arctan2(d[..., 2], rho), np.arctan2(d[..., 1], d[..., 0])], axis=-1)


def angle_jacobian(points: ArrayLike, sensors: ArrayLike) -> np.ndarray:
    """Jacobian ``d[alpha, beta]/d(x, y, z)``, shape ``(..., N, 2, 3)``."""
    P = np.asarray(points, dtype=np.float64)
    S = _check_sensors(sensors)
    d = P[..., None, :] - S
    dx, dy, dz = d[..., 0], d[..., 1], d[..., 2]
    rho2 = dx * dx + dy * dy
    rho = np.sqrt(rho2)
    r2 = rho2 + dz * dz
    g = np.empty(d.shape[:-1] + (2, 3))
    g[..., 0, 0] = -dx * dz / (r2 * rho)
    g[..., 0, 1] = -dy * dz / (r2 * rho)
    g[..., 0, 2] = rho / r2
    g[..., 1, 0] = -dy / rho2
    g[..., 1, 1] = dx / rho2
    g[..., 1, 2] = 0.0
    return g


def _check_batch(meas: ArrayLike, mask: ArrayLike | None, N: int
                 ) -> tuple[np.ndarray, np.ndarray]:
    m = np.asarray(meas, dtype=np.float64)
    if m.ndim == 2:
        m = m[None]
    if m.ndim != 3 or m.shape[1:] != (N, 2):
        raise InvalidProblemError(
            f"meas must have shape (K, {N}, 2) ([alpha, beta] per sensor), got {m.shape}")
    if mask is None:
        mk = np.ones(m.shape[:2], dtype=bool)
    else:
        mk = np.asarray(mask, dtype=bool)
        if mk.ndim == 1:
            mk = mk[None]
        mk = np.broadcast_to(mk, m.shape[:2])
    if not np.isfinite(m[mk]).all():
        raise InvalidProblemError("meas contains NaN or inf at a real (unmasked) entry")
    m = np.where(mk[..., None], m, 0.0)
    return m, mk


def _check_R(R: ArrayLike, K: int, N: int) -> np.ndarray:
    Rm = np.asarray(R, dtype=np.float64)
    try:
        Rm = np.broadcast_to(Rm, (K, N, 2, 2))
    except ValueError as exc:
        raise InvalidProblemError(
            f"R must broadcast to (K, N, 2, 2) = ({K}, {N}, 2, 2), got {Rm.shape}") from exc
    return Rm


def los_system(meas: ArrayLike, sensors: ArrayLike, mask: ArrayLike | None = None
               ) -> tuple[np.ndarray, np.ndarray]:
    """The line-of-sight system ``H x = Y`` of eqs. (9)-(13), batched.

    Returns ``H`` with shape ``(K, 2N, 3)`` and ``Y`` with shape ``(K, 2N)``; rows
    ``2s`` and ``2s+1`` are sensor s's eqs. (9) and (10); dummy sensors give zero rows.
    """
    S = _check_sensors(sensors)
    m, mk = _check_batch(meas, mask, len(S))
    return _los(m, mk, S)


def _los(m: np.ndarray, mk: np.ndarray, S: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    K, N = mk.shape
    a, b = m[..., 0], m[..., 1]
    sa, ca, sb, cb = np.sin(a), np.cos(a), np.sin(b), np.cos(b)
    w = mk.astype(np.float64)
    H = np.empty((K, N, 2, 3))
    H[..., 0, 0] = sb
    H[..., 0, 1] = -cb
    H[..., 0, 2] = 0.0
    H[..., 1, 0] = cb * sa
    H[..., 1, 1] = sb * sa
    H[..., 1, 2] = -ca
    H *= w[..., None, None]
    Y = (H * S[None, :, None, :]).sum(axis=-1)    # rows of H applied to x*_s
    return H.reshape(K, 2 * N, 3), Y.reshape(K, 2 * N)


def residual_jacobian(meas: np.ndarray, x: np.ndarray, sensors: np.ndarray,
                      mask: np.ndarray | None = None, form: str = "residual") -> np.ndarray:
    """Per-sensor 2x2 Jacobian of the equation error w.r.t. ``[alpha, beta]`` (not of Y alone).

    ``form="residual"``: ``d(H(m) x - Y(m))/dm`` at ``x`` (correct);
    ``form="printed"``: the literal ``dY/dm`` of eq. (16) (origin-dependent, wrong).
    Rows: eq. (9), eq. (10); columns: alpha, beta.  Shape ``(K, N, 2, 2)``; zero for
    dummy sensors.
    """
    S = _check_sensors(sensors)
    m, mk = _check_batch(meas, mask, len(S))
    return _jac_e(m, mk, np.asarray(x, np.float64).reshape(-1, 3), S, form)


def _jac_e(m, mk, x, S, form):
    a, b = m[..., 0], m[..., 1]
    sa, ca, sb, cb = np.sin(a), np.cos(a), np.sin(b), np.cos(b)
    if form == "residual":
        d = x[:, None, :] - S[None]                 # x_hat - x*_s
    elif form == "printed":
        # dY/dm of (16) treats H as constant: it is de/dm with d = +x*_s (sign is
        # irrelevant for the covariance).  Depends on the origin; 0 at the origin.
        d = np.broadcast_to(S[None], (len(x),) + S.shape)
    else:
        raise InvalidProblemError(f"covariance must be one of {COVARIANCES}, got {form!r}")
    dx, dy, dz = d[..., 0], d[..., 1], d[..., 2]
    horiz = cb * dx + sb * dy
    J = np.empty(mk.shape + (2, 2))
    J[..., 0, 0] = 0.0
    J[..., 0, 1] = horiz
    J[..., 1, 0] = ca * horiz + sa * dz
    J[..., 1, 1] = sa * (-sb * dx + cb * dy)
    return J * mk[..., None, None]
