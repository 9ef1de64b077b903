"""Batched Kalman filters for nearly-constant-velocity targets in the plane.

State ``[x, y, vx, vy]``.  Every function works on a batch of ``N`` independent
tracks at once (leading axis), so a whole node's tracks are filtered in one call.

* :func:`cv_model` -- transition ``F`` and process noise ``Q`` of the white-noise
  acceleration model with intensity ``q`` (m^2/s^3):
  ``Q = q [[T^3/3, T^2/2], [T^2/2, T]]`` per axis;
* :func:`predict`, :func:`update` -- the linear Kalman filter (Joseph-form update);
  :func:`update` takes the measurement function's value and Jacobian, so the same
  call is the extended Kalman filter's update for a nonlinear measurement;
* :func:`two_point_init` -- the state and covariance from two position fixes.

>>> import numpy as np
>>> F, Q = cv_model(1.0, 0.0)
>>> x, P = predict(np.array([[0.0, 0.0, 1.0, 2.0]]), np.eye(4)[None], F, Q)
>>> x.tolist()
[[1.0, 2.0, 1.0, 2.0]]
"""

from __future__ import annotations

import numpy as np

__all__ = ["cv_model", "predict", "update", "two_point_init", "nees"]


def cv_model(T: float, q: float) -> tuple[np.ndarray, np.ndarray]:
    """``F`` and ``Q`` of the nearly-constant-velocity model (module docstring)."""
    if not (T > 0 and q >= 0):
        raise ValueError(f"need T > 0 and q >= 0, got T={T!r}, q={q!r}")
    I2 = np.eye(2)
    F = np.block([[I2, T * I2], [0 * I2, I2]])
    Q = q * np.block([[T ** 3 / 3 * I2, T ** 2 / 2 * I2], [T ** 2 / 2 * I2, T * I2]])
    return F, Q


def predict(x: np.ndarray, P: np.ndarray, F: np.ndarray, Q: np.ndarray
            ) -> tuple[np.ndarray, np.ndarray]:
    """One prediction step for ``x`` ``(N, 4)`` and ``P`` ``(N, 4, 4)``."""
    return x @ F.T, F @ P @ F.T + Q


def update(x: np.ndarray, P: np.ndarray, residual: np.ndarray, H: np.ndarray,
           R: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Kalman update with innovation ``residual`` ``(N, m)``, Jacobian ``H`` ``(m, 4)`` or
    ``(N, m, 4)`` and noise ``R`` ``(m, m)`` or ``(N, m, m)`` (Joseph form, symmetric)."""
    H = np.broadcast_to(H, (len(x),) + np.shape(H)[-2:])
    Ht = np.swapaxes(H, -1, -2)
    S = H @ P @ Ht + R
    K = np.swapaxes(np.linalg.solve(S, H @ P), -1, -2)            # P H^T S^-1 (S symmetric)
    x = x + (K @ residual[..., None])[..., 0]
    IKH = np.eye(P.shape[-1]) - K @ H
    P = IKH @ P @ np.swapaxes(IKH, -1, -2) + K @ R @ np.swapaxes(K, -1, -2)
    return x, 0.5 * (P + np.swapaxes(P, -1, -2))


def two_point_init(z0: np.ndarray, R0: np.ndarray, z1: np.ndarray, R1: np.ndarray,
                   T: float) -> tuple[np.ndarray, np.ndarray]:
    """State at the second fix from two position fixes ``T`` apart (velocity by differencing).

    ``x = [z1, (z1 - z0) / T]``; ``P = [[R1, R1/T], [R1/T, (R0 + R1)/T^2]]``.
    """
    x = np.concatenate([z1, (z1 - z0) / T], axis=-1)
    P = np.block([[R1, R1 / T], [R1 / T, (R0 + R1) / T ** 2]])
    return x, P


def nees(x: np.ndarray, P: np.ndarray, truth: np.ndarray) -> np.ndarray:
    """Normalised estimation error squared ``e^T P^-1 e`` per track."""
    e = x - truth
    return np.einsum("...i,...i->...", e, np.linalg.solve(P, e[..., None])[..., 0])
