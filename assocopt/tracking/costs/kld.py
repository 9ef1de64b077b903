"""Gaussian divergences used by paper 002's costs: the printed formulas and the exact ones.

Argument order follows the paper: ``KLD(p(x~), p(x))`` with ``x~`` the pseudo-measurement
(mean ``mu_t``, variance ``var_t``) first and the measurement density ``x`` (mean
``mu``, variance ``var``) second.  All functions are vectorised (numpy broadcasting).

* :func:`kld_printed` -- eq. (27) **as printed**.  Not the KL divergence: it is
  negative whenever ``var_t < var`` and has units of 1/variance.
* :func:`skld_printed` -- eq. (28) **as printed**, not the symmetric KL either: the
  printed (27) plus its
  swap; the variance-mismatch term is missing.
* :func:`kld_exact`, :func:`skld_exact` -- the exact 1-D Gaussian forms.
* :func:`kld_gauss`, :func:`skld_gauss` -- the exact d-dimensional Gaussian forms.

Never label the printed ones plain "KLD" (docs/papers/lu2013.md, "Corrections to the paper").
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

__all__ = ["kld_printed", "skld_printed", "kld_exact", "skld_exact",
           "kld_gauss", "skld_gauss"]


def kld_printed(mu_t: ArrayLike, var_t: ArrayLike, mu: ArrayLike, var: ArrayLike) -> np.ndarray:
    """Eq. (27) as printed: ``((s~^2 - s^2) + (mu~ - mu)^2) / (2 s^2 s~^2)``.

    Not a divergence: negative when ``var_t < var`` and the mean difference is small.

    >>> float(kld_printed(0.0, 1.0, 0.0, 4.0))   # s~ < s: negative
    -0.375
    """
    mu_t, var_t, mu, var = map(np.asarray, (mu_t, var_t, mu, var))
    return ((var_t - var) + (mu_t - mu) ** 2) / (2.0 * var * var_t)


def skld_printed(mu_t: ArrayLike, var_t: ArrayLike, mu: ArrayLike, var: ArrayLike) -> np.ndarray:
    """Eq. (28) as printed: ``(mu~ - mu)^2 / (s^2 s~^2)`` (no variance-mismatch term).

    >>> float(skld_printed(1.0, 1.0, 0.0, 4.0))
    0.25
    """
    mu_t, var_t, mu, var = map(np.asarray, (mu_t, var_t, mu, var))
    return (mu_t - mu) ** 2 / (var * var_t)


def kld_exact(mu_t: ArrayLike, var_t: ArrayLike, mu: ArrayLike, var: ArrayLike) -> np.ndarray:
    """Exact ``KL(N(mu_t, var_t) || N(mu, var))``; always >= 0.

    ``1/2 [var_t/var - 1 - ln(var_t/var) + (mu_t - mu)^2 / var]``

    >>> float(kld_exact(0.0, 1.0, 0.0, 1.0))
    0.0
    >>> round(float(kld_exact(1.0, 1.0, 0.0, 4.0)), 6)
    0.443147
    """
    mu_t, var_t, mu, var = map(np.asarray, (mu_t, var_t, mu, var))
    q = var_t / var
    return 0.5 * (q - 1.0 - np.log(q) + (mu_t - mu) ** 2 / var)


def skld_exact(mu_t: ArrayLike, var_t: ArrayLike, mu: ArrayLike, var: ArrayLike) -> np.ndarray:
    """Exact symmetric KL (Jeffreys) divergence of two 1-D Gaussians (both KL directions).

    ``1/2 (var_t/var + var/var_t - 2) + 1/2 (mu_t - mu)^2 (1/var + 1/var_t)``

    >>> round(float(skld_exact(1.0, 1.0, 0.0, 4.0)), 6)
    1.75
    """
    mu_t, var_t, mu, var = map(np.asarray, (mu_t, var_t, mu, var))
    d2 = (mu_t - mu) ** 2
    return 0.5 * (var_t / var + var / var_t - 2.0) + 0.5 * d2 * (1.0 / var + 1.0 / var_t)


def _inv_logdet(S: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Inverse and log-determinant; closed form for 2x2 (the per-sensor case, fast)."""
    if S.shape[-2:] == (2, 2):
        a, b, c, d = S[..., 0, 0], S[..., 0, 1], S[..., 1, 0], S[..., 1, 1]
        det = a * d - b * c
        inv = np.stack([np.stack([d, -b], -1), np.stack([-c, a], -1)], -2) / det[..., None, None]
        with np.errstate(invalid="ignore", divide="ignore"):
            return inv, np.log(det)
    sign, logdet = np.linalg.slogdet(S)
    return np.linalg.inv(S), np.where(sign > 0, logdet, np.nan)


def _trace_prod(A: np.ndarray, B: np.ndarray) -> np.ndarray:
    """``tr(A @ B)`` over the last two axes."""
    return (A * np.swapaxes(B, -1, -2)).sum(axis=(-2, -1))


def _quad(v: np.ndarray, M: np.ndarray) -> np.ndarray:
    """``v^T M v`` over the last axes."""
    return (v[..., None, :] @ M @ v[..., :, None])[..., 0, 0]


def _gauss_pair(mu0: ArrayLike, S0: ArrayLike, mu1: ArrayLike, S1: ArrayLike) -> tuple:
    """``(d, mu1 - mu0, (S0, S0^-1, ln det S0), (S1, S1^-1, ln det S1))`` of two stacked
    d-dimensional Gaussians, as float arrays."""
    mu0, S0, mu1, S1 = (np.asarray(a, dtype=np.float64) for a in (mu0, S0, mu1, S1))
    return mu0.shape[-1], mu1 - mu0, (S0, *_inv_logdet(S0)), (S1, *_inv_logdet(S1))


def kld_gauss(mu0: ArrayLike, S0: ArrayLike, mu1: ArrayLike, S1: ArrayLike) -> np.ndarray:
    """Exact ``KL(N(mu0, S0) || N(mu1, S1))`` for stacked d-dimensional Gaussians.

    ``1/2 [tr(S1^-1 S0) + (mu1-mu0)^T S1^-1 (mu1-mu0) - d + ln(det S1 / det S0)]``.
    ``mu*`` have shape ``(..., d)``, ``S*`` shape ``(..., d, d)`` (positive definite).

    >>> float(kld_gauss([0.0, 0.0], np.eye(2), [0.0, 0.0], np.eye(2)))
    0.0
    """
    d, diff, (S0, S0inv, logdet0), (S1, S1inv, logdet1) = _gauss_pair(mu0, S0, mu1, S1)
    tr = _trace_prod(S1inv, S0)
    maha = _quad(diff, S1inv)
    return 0.5 * (tr + maha - d + logdet1 - logdet0)


def skld_gauss(mu0: ArrayLike, S0: ArrayLike, mu1: ArrayLike, S1: ArrayLike) -> np.ndarray:
    """Exact symmetric KL divergence of stacked d-dimensional Gaussians.

    ``1/2 [tr(S1^-1 S0) + tr(S0^-1 S1) - 2d + diff^T (S0^-1 + S1^-1) diff]``.

    >>> round(float(skld_gauss([1.0], [[1.0]], [0.0], [[4.0]])), 6)
    1.75
    """
    d, diff, (S0, S0inv, _), (S1, S1inv, _) = _gauss_pair(mu0, S0, mu1, S1)
    tr = _trace_prod(S1inv, S0) + _trace_prod(S0inv, S1)
    maha = _quad(diff, S0inv + S1inv)
    return 0.5 * (tr - 2.0 * d + maha)
