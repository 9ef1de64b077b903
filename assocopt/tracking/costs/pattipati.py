"""The classical passive-sensor S-D cost, eq. (7) (Pattipati et al., ref. [2] of paper 002).

For a tuple with real measurements in the sensors ``s in T`` and dummies elsewhere::

    c = sum_{s in T} [ ln( norm(R_s) / P_Ds ) + 1/2 Delta_s^T R_s^-1 Delta_s ]
        - sum_{s not in T} ln(1 - P_Ds)

with ``Delta_s = m_s - G_s(x_hat)`` (azimuth difference wrapped to (-pi, pi]).  We keep
the two parts apart: the *data term* (the statistical distance, or in (24)-(25) the
divergence) and the *constant term* (the log-normalisation and the dummy terms).

Constant conventions (the printed normalisation of (7) is not a Gaussian's, see
docs/papers/lu2013.md), the ``normalisation`` option:

``"printed"`` (default, reproduces the paper)
    ``norm(R) = sqrt(2 pi det R)`` as printed, no false-alarm density.  In radians this
    is about -12.1 per real measurement at sigma = 1.5 mrad.
``"gaussian"``
    The correct 2-D Gaussian normalisation ``2 pi sqrt(det R)``, multiplied by the
    false-alarm spatial density ``beta_s`` (false alarms per rad^2 of the field of view)
    of the Deb et al. likelihood ratio when the scan has one (``beta_s > 0``).
``"none"``
    No constant at all (data term only), the convention we use for the solution
    discrimination r, which depends on the constant.

With ``P_D = 1`` and no false alarms the constant is the same for every feasible
solution, so it never changes the argmin; it does change r.
"""

from __future__ import annotations

import numpy as np

from ...runtime.errors import InvalidProblemError
from ..localisation import wrap_angle

__all__ = ["NORMALISATIONS", "measurement_constant", "dummy_constant",
           "constant_terms", "mahalanobis_data"]

#: Accepted values of the ``normalisation`` option.
NORMALISATIONS = ("printed", "gaussian", "none")


def measurement_constant(R: np.ndarray, pd: np.ndarray, normalisation: str = "printed",
                         clutter_density: np.ndarray | None = None) -> np.ndarray:
    """Constant of one real measurement: ``ln(norm(R) / P_D)`` (see module docstring).

    ``R`` has shape ``(..., 2, 2)`` (or ``(..., 1, 1)`` for azimuth only, where the
    printed and the Gaussian normalisation coincide); ``pd`` and ``clutter_density`` broadcast against
    ``R.shape[:-2]``.

    >>> c = measurement_constant(np.eye(2) * 1.5e-3 ** 2, np.array(1.0))
    >>> round(float(c), 2)
    -12.09
    """
    if normalisation not in NORMALISATIONS:
        raise InvalidProblemError(
            f"normalisation must be one of {NORMALISATIONS}, got {normalisation!r}")
    w = R.shape[-1]                         # angles per measurement: 2, or 1 (azimuth)
    det = R[..., 0, 0] if w == 1 else R[..., 0, 0] * R[..., 1, 1] - R[..., 0, 1] * R[..., 1, 0]
    if normalisation == "none":
        return np.zeros_like(det)
    if normalisation == "printed":
        return np.log(np.sqrt(2.0 * np.pi * det) / pd)
    beta = np.ones_like(det) if clutter_density is None else np.asarray(clutter_density, float)
    beta = np.where(beta > 0, beta, 1.0)
    return np.log(np.sqrt((2.0 * np.pi) ** w * det) * beta / pd)


def dummy_constant(pd: np.ndarray, normalisation: str = "printed") -> np.ndarray:
    """``-ln(1 - P_D)`` per sensor (``+inf`` when ``P_D = 1``); 0 for ``"none"``.

    With ``"none"`` the dummy term is still ``+inf`` at ``P_D = 1``: dropping a
    constant must not turn a forbidden tuple into an allowed one.
    """
    pd = np.asarray(pd, dtype=np.float64)
    with np.errstate(divide="ignore"):
        c = -np.log1p(-pd)
    if normalisation == "none":
        return np.where(np.isinf(c), np.inf, 0.0)
    return c


def constant_terms(mask: np.ndarray, R: np.ndarray, pd: np.ndarray,
                   normalisation: str = "printed",
                   clutter_density: np.ndarray | None = None) -> np.ndarray:
    """Constant part of (7)/(24)/(25) for each tuple.

    Parameters
    ----------
    mask : (K, N) bool, real measurements
    R : (K, N, 2, 2) noise covariance of each tuple's measurements (dummy entries ignored)
    pd : (N,) detection probabilities
    clutter_density : (N,) false alarms per rad^2, optional
    """
    pd = np.asarray(pd, dtype=np.float64)
    meas_c = measurement_constant(R, pd[None, :], normalisation,
                                  None if clutter_density is None
                                  else np.asarray(clutter_density, float)[None, :])
    dum_c = dummy_constant(pd, normalisation)
    real = np.where(mask, meas_c, 0.0).sum(axis=1)
    dummies = np.where(~mask, dum_c[None, :], 0.0)
    with np.errstate(invalid="ignore"):
        return real + dummies.sum(axis=1)


def mahalanobis_data(meas: np.ndarray, pred: np.ndarray, Rinv: np.ndarray,
                     mask: np.ndarray) -> np.ndarray:
    """Data term of (7): ``sum_s 1/2 Delta_s^T R_s^-1 Delta_s`` over real sensors.

    ``meas``/``pred``: (K, N, 2) ``[alpha, beta]``; ``Rinv``: (K, N, 2, 2).
    """
    delta = meas - pred
    delta[..., 1] = wrap_angle(delta[..., 1])
    q = (delta[..., None, :] @ Rinv @ delta[..., :, None])[..., 0, 0]
    return 0.5 * np.where(mask, q, 0.0).sum(axis=1)
