"""Batched least-squares localisation of candidate tuples (LS, iterated LS, TLS) with covariances.

Estimators and covariance forms: see :mod:`assocopt.tracking.localisation`.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Sequence

import numpy as np
from numpy.typing import ArrayLike

from ...runtime.errors import InvalidProblemError
from .geometry import (COVARIANCES, METHODS, _check_batch, _check_R, _check_sensors, _jac_e,
                       _los, angle_jacobian, angles, wrap_angle)

__all__ = ["localise", "Localisation", "localise_indexed", "METHODS", "COVARIANCES", "RCOND_MIN"]

#: Tuples whose normal matrix has reciprocal condition number below this are
#: reported as not localisable (``valid = False``) instead of returning garbage.
RCOND_MIN = 1e-12


@dataclass(frozen=True)
class Localisation:
    """Batched position estimates.

    Attributes
    ----------
    x : ndarray (K, 3)
        Position estimates (NaN where not ``valid``).
    P : ndarray (K, 3, 3)
        Their covariances (NaN where not ``valid``).
    valid : ndarray (K,) bool
        At least 2 real measurements and a well-conditioned normal matrix.
    n_real : ndarray (K,) int
        Number of real measurements in each tuple.
    method, covariance : str
        What produced them.
    """

    x: np.ndarray
    P: np.ndarray
    valid: np.ndarray
    n_real: np.ndarray
    method: str
    covariance: str


def _sym3_inverse(A: np.ndarray, ok: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Inverse of stacked symmetric 3x3 matrices by the adjugate (fast, vectorised).

    Ill-conditioned matrices are flagged in ``ok`` (not raised): the scale-free ratio
    ``det(A) / (tr(A)/3)^3`` (<= 27 lambda_min/lambda_max) must exceed
    :data:`RCOND_MIN`.
    """
    a, b, c = A[:, 0, 0], A[:, 0, 1], A[:, 0, 2]
    d, e, f = A[:, 1, 1], A[:, 1, 2], A[:, 2, 2]
    c00 = d * f - e * e
    c01 = c * e - b * f
    c02 = b * e - c * d
    c11 = a * f - c * c
    c12 = b * c - a * e
    c22 = a * d - b * b
    det = a * c00 + b * c01 + c * c02
    scale = ((a + d + f) / 3.0) ** 3
    with np.errstate(invalid="ignore", divide="ignore"):
        ratio = det / scale
    ok = ok & np.isfinite(ratio) & (ratio > RCOND_MIN)
    det = np.where(ok, det, 1.0)
    inv = np.stack([c00, c01, c02, c01, c11, c12, c02, c12, c22], axis=-1)
    inv = inv.reshape(-1, 3, 3) / det[:, None, None]
    return np.where(ok[:, None, None], inv, np.nan), ok


def _inv2(R: np.ndarray) -> np.ndarray:
    """Inverse of stacked 2x2 matrices (closed form)."""
    a, b, c, d = R[..., 0, 0], R[..., 0, 1], R[..., 1, 0], R[..., 1, 1]
    det = a * d - b * c
    out = np.empty_like(R)
    out[..., 0, 0] = d / det
    out[..., 0, 1] = -b / det
    out[..., 1, 0] = -c / det
    out[..., 1, 1] = a / det
    return out


def localise(meas: ArrayLike, sensors: ArrayLike, R: ArrayLike,
             mask: ArrayLike | None = None, *, method: str = "ls",
             covariance: str = "residual", iterations: int = 5) -> Localisation:
    """Position estimate and covariance for each of K tuples of bearings, batched.

    Parameters
    ----------
    meas : array (K, N, 2)
        Measured ``[alpha, beta]`` in rad (entries of dummy sensors are ignored).
    sensors : array (N, 3)
        Sensor positions.
    R : array broadcastable to (K, N, 2, 2)
        Measurement noise covariance of each measurement (rad^2), order alpha, beta.
    mask : array (K, N) bool, optional
        Real measurements (default: all real).
    method : {"ls", "ils", "tls"}
        Estimator, see the module docstring.
    covariance : {"residual", "printed"}
        Covariance form for ``"ls"``/``"tls"`` (residual Jacobian or the printed dY/dm);
        ignored by ``"ils"``.
    iterations : int
        Gauss-Newton steps for ``"ils"``.

    Returns
    -------
    Localisation

    Examples
    --------
    >>> S = np.array([[0, 20, 0], [20, 0, 0], [0, 0, 0.0]])
    >>> th = angles([12.0, 9.0, 5.0], S)
    >>> loc = localise(th[None], S, np.eye(2) * 1.5e-3 ** 2)
    >>> np.round(loc.x, 9).tolist(), bool(loc.valid[0])
    ([[12.0, 9.0, 5.0]], True)
    """
    if method not in METHODS:
        raise InvalidProblemError(f"method must be one of {METHODS}, got {method!r}")
    if covariance not in COVARIANCES:
        raise InvalidProblemError(f"covariance must be one of {COVARIANCES}, got {covariance!r}")
    S = _check_sensors(sensors)
    m, mk = _check_batch(meas, mask, len(S))
    K, N = mk.shape
    Rm = _check_R(R, K, N)
    n_real = mk.sum(axis=1)
    ok = n_real >= 2
    H, Y = _los(m, mk, S)
    Ht = np.swapaxes(H, 1, 2)
    A = Ht @ H
    Ainv, ok = _sym3_inverse(A, ok)
    if method == "tls":
        x = _tls(H, Y, ok)
        ok &= np.isfinite(x).all(axis=1)
    else:
        x = (Ainv @ (Ht @ Y[..., None]))[..., 0]
    x = np.where(ok[:, None], x, 0.0)
    if method == "ils":
        x, P, ok = _gauss_newton(m, mk, S, Rm, x, ok, iterations)
    else:
        J = _jac_e(m, mk, x, S, covariance)                            # (K,N,2,2)
        dY = J @ Rm @ np.swapaxes(J, -1, -2)                           # (K,N,2,2)
        DY = np.zeros((K, N, 2, N, 2))
        idx = np.arange(N)
        DY[:, idx, :, idx, :] = np.moveaxis(dY, 1, 0)                  # block diagonal
        middle = Ht @ DY.reshape(K, 2 * N, 2 * N) @ H
        P = Ainv @ middle @ Ainv
    x = np.where(ok[:, None], x, np.nan)
    P = np.where(ok[:, None, None], P, np.nan)
    return Localisation(x=x, P=P, valid=ok, n_real=n_real, method=method,
                        covariance="fisher" if method == "ils" else covariance)


def _sym6(M: np.ndarray) -> tuple:
    return M[..., 0, 0], M[..., 0, 1], M[..., 0, 2], M[..., 1, 1], M[..., 1, 2], M[..., 2, 2]


def _full3(c: Sequence[np.ndarray]) -> np.ndarray:
    xx, xy, xz, yy, yz, zz = c
    return np.stack([xx, xy, xz, xy, yy, yz, xz, yz, zz], axis=-1).reshape(-1, 3, 3)


def localise_indexed(meas: Sequence[ArrayLike], R: Sequence[ArrayLike], sensors: ArrayLike,
                     tuples: ArrayLike, *, method: str = "ls",
                     covariance: str = "residual", iterations: int = 5) -> Localisation:
    """:func:`localise` for S-D candidate tuples given as indices into per-sensor lists.

    ``meas[s]`` is ``(n_s, 2)``, ``R[s]`` is ``(n_s, 2, 2)``; ``tuples`` is ``(K, N)``
    with 1-based indices and 0 for a dummy.  For ``method="ls"`` this is the fast path
    used by the cost builders: the per-measurement parts of ``H^T H`` and ``H^T Y`` are
    computed once per measurement and summed per tuple by gathering (no matrix per
    tuple), and the covariance (15) with the residual Jacobian is assembled from
    closed-form 3-vectors.  It agrees with :func:`localise` to rounding.

    Examples
    --------
    >>> S = np.array([[0, 20, 0], [20, 0, 0], [0, 0, 0.0]])
    >>> th = angles([[12.0, 9.0, 5.0]], S)[0]            # (N, 2)
    >>> R = [np.eye(2)[None] * 1e-6] * 3
    >>> loc = localise_indexed([th[s:s + 1] for s in range(3)], R, S, [[1, 1, 1], [1, 0, 1]])
    >>> np.round(loc.x, 9).tolist()
    [[12.0, 9.0, 5.0], [12.0, 9.0, 5.0]]
    """
    S = _check_sensors(sensors)
    N = len(S)
    T = np.asarray(tuples, dtype=np.int64)
    if T.ndim != 2 or T.shape[1] != N:
        raise InvalidProblemError(f"tuples must have shape (K, {N}), got {T.shape}")
    if len(meas) != N or len(R) != N:
        raise InvalidProblemError(f"meas and R must list {N} arrays (one per sensor)")
    if method != "ls":
        K = len(T)
        m = np.zeros((K, N, 2))
        Rm = np.broadcast_to(np.eye(2), (K, N, 2, 2)).copy()
        for s in range(N):
            ms, Rs = np.asarray(meas[s], float).reshape(-1, 2), np.asarray(R[s], float)
            real = T[:, s] > 0
            m[real, s] = ms[T[real, s] - 1]
            Rm[real, s] = Rs[T[real, s] - 1]
        return localise(m, S, Rm, T > 0, method=method, covariance=covariance,
                        iterations=iterations)
    if covariance not in COVARIANCES:
        raise InvalidProblemError(f"covariance must be one of {COVARIANCES}, got {covariance!r}")
    K = len(T)
    mask = T > 0
    n_real = mask.sum(axis=1)
    # per-measurement quantities, padded with a zero row at index 0 (the dummy)
    trig, Rc, Apart, bpart = [], [], [], []
    for s in range(N):
        ms = np.asarray(meas[s], dtype=np.float64).reshape(-1, 2)
        Rs = np.asarray(R[s], dtype=np.float64).reshape(-1, 2, 2)
        if len(ms) != len(Rs):
            raise InvalidProblemError(f"sensor {s}: {len(ms)} measurements but {len(Rs)} R")
        if len(ms) and T[:, s].max(initial=0) > len(ms):
            raise InvalidProblemError(f"tuples refer to measurement {T[:, s].max()} of "
                                      f"sensor {s}, which has {len(ms)}")
        a = np.concatenate([[0.0], ms[:, 0]])
        b = np.concatenate([[0.0], ms[:, 1]])
        pad = np.concatenate([[0.0], np.ones(len(ms))])
        sa, ca, sb, cb = np.sin(a), np.cos(a) * pad, np.sin(b), np.cos(b) * pad
        xs, ys, zs = S[s]
        y9 = sb * xs - cb * ys
        y10 = cb * sa * xs + sb * sa * ys - ca * zs
        Apart.append(np.stack([sb * sb + cb * cb * sa * sa, -sb * cb * ca * ca, -cb * sa * ca,
                               cb * cb + sb * sb * sa * sa, -sb * sa * ca, ca * ca], axis=1))
        bpart.append(np.stack([sb * y9 + cb * sa * y10, -cb * y9 + sb * sa * y10,
                               -ca * y10], axis=1))
        trig.append((sa, ca, sb, cb))
        Rp = np.concatenate([np.zeros((1, 2, 2)), Rs])
        Rc.append((Rp[:, 0, 0], Rp[:, 0, 1], Rp[:, 1, 1]))
    A = Apart[0][T[:, 0]]
    bvec = bpart[0][T[:, 0]]
    for s in range(1, N):
        A = A + Apart[s][T[:, s]]
        bvec = bvec + bpart[s][T[:, s]]
    Ainv, ok = _sym3_inverse(_full3(A.T), n_real >= 2)
    Ainv0 = np.where(ok[:, None, None], Ainv, 0.0)
    x = (Ainv0 @ bvec[..., None])[..., 0]
    mid = [np.zeros(K) for _ in range(6)]
    for s in range(N):
        idx = T[:, s]
        sa, ca, sb, cb = (t[idx] for t in trig[s])
        d = (x - S[s]) if covariance == "residual" else np.broadcast_to(S[s], x.shape)
        dx, dy, dz = d[:, 0], d[:, 1], d[:, 2]
        h = cb * dx + sb * dy
        j10a = ca * h + sa * dz
        j10b = sa * (-sb * dx + cb * dy)
        h10 = (cb * sa, sb * sa, -ca)
        h9 = (sb, -cb, 0.0)
        va = [h10[i] * j10a for i in range(3)]
        vb = [h9[i] * h + h10[i] * j10b for i in range(3)]
        raa, rab, rbb = (r[idx] for r in Rc[s])
        for n, (i, j) in enumerate(((0, 0), (0, 1), (0, 2), (1, 1), (1, 2), (2, 2))):
            mid[n] += (raa * va[i] * va[j] + rab * (va[i] * vb[j] + vb[i] * va[j])
                       + rbb * vb[i] * vb[j])
    P = Ainv0 @ _full3(mid) @ Ainv0
    x = np.where(ok[:, None], x, np.nan)
    P = np.where(ok[:, None, None], P, np.nan)
    return Localisation(x=x, P=P, valid=ok, n_real=n_real, method="ls", covariance=covariance)


def _tls(H: np.ndarray, Y: np.ndarray, ok: np.ndarray) -> np.ndarray:
    """Total least squares of ``H x = Y``: smallest right singular vector of [H, -Y]."""
    C = np.concatenate([H, -Y[..., None]], axis=2)          # (K, 2N, 4)
    C = np.where(ok[:, None, None], C, np.eye(C.shape[1], 4))
    _, _, Vt = np.linalg.svd(C, full_matrices=False)
    v = Vt[:, -1, :]
    with np.errstate(divide="ignore", invalid="ignore"):
        x = v[:, :3] / v[:, 3:4]
    return np.where(np.abs(v[:, 3:4]) > 1e-12, x, np.nan)


def _gauss_newton(m, mk, S, Rm, x, ok, iterations):
    """Weighted Gauss-Newton on the angle residuals (the ML estimate); Fisher covariance."""
    K, N = mk.shape
    Rinv = _inv2(np.where(mk[..., None, None], Rm, np.eye(2))) * mk[..., None, None]
    for _ in range(max(int(iterations), 0) + 1):
        pred = angles(x, S)                                    # (K, N, 2)
        res = m - pred
        res[..., 1] = wrap_angle(res[..., 1])
        res *= mk[..., None]
        g = angle_jacobian(x, S)                               # (K, N, 2, 3)
        gt = np.swapaxes(g, -1, -2)
        F = (gt @ Rinv @ g).sum(axis=1)
        Finv, ok2 = _sym3_inverse(F, ok & np.isfinite(F).all(axis=(1, 2)))
        grad = (gt @ Rinv @ res[..., None]).sum(axis=1)       # (K, 3, 1)
        step = (np.where(ok2[:, None, None], Finv, 0.0) @ grad)[..., 0]
        if _ == iterations:
            break
        x = np.where(ok2[:, None], x + step, x)
    return x, Finv, ok2
