"""Chi-square gating of track-measurement pairs, with a spatial index.

A track ``i`` with predicted measurement :math:`\\hat z_i` and innovation covariance
:math:`S_{ij}` and a measurement :math:`z_j` form a *gated pair* when the squared
Mahalanobis distance

.. math:: d^2_{ij} = (z_j - \\hat z_i)^\\top S_{ij}^{-1} (z_j - \\hat z_i)

is at most the gate threshold :math:`\\gamma`, by default the ``probability``
quantile of the chi-square distribution with ``m`` (measurement dimension) degrees
of freedom, so a true pair falls inside the gate with that probability.

Pairs are found without an all-pairs pass: since
:math:`d^2 \\ge \\lVert v \\rVert^2 / \\lambda_{\\max}(S)`, every gated measurement lies
within the Euclidean radius :math:`\\sqrt{\\gamma\\,\\lambda_{\\max}(S_i)}` of
:math:`\\hat z_i`; a :class:`scipy.spatial.cKDTree` of the measurements returns those
candidates, and the exact Mahalanobis test (batched Cholesky whitening) keeps the
pairs inside the gate.  The innovation covariance is either given per track
(``S``), or per track plus a measurement noise ``R`` that may differ per measurement
(:math:`S_{ij} = S_i + R_j`; the radius then uses
:math:`\\lambda_{\\max}(S_i) + \\max_j \\lambda_{\\max}(R_j)`, still conservative).
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from ...runtime.errors import InvalidProblemError
from ...problems.validation import finite_floats

__all__ = ["Gate", "chi2_threshold", "predict_measurements", "gate", "pair_statistics"]

#: Relative slack on the Euclidean pre-filter radius (rounding must never drop a pair
#: the exact test would keep).
_RADIUS_SLACK = 1e-9


@dataclass(frozen=True)
class Gate:
    """The gated track-measurement pairs of one scan.

    Attributes
    ----------
    rows, cols : ndarray of int64, shape (K,)
        Track and measurement of each gated pair, **0-based**, sorted by (row, col).
    d2 : ndarray (K,)
        Squared Mahalanobis distance of each pair.
    logdet : ndarray (K,)
        :math:`\\ln\\det S_{ij}` of each pair (for likelihood costs).
    n_tracks, n_meas, dim : int
        Numbers of tracks and measurements, measurement dimension ``m``.
    threshold : float
        The gate :math:`\\gamma` (``inf`` = no gate: every pair is kept).
    probability : float
        The gate probability :math:`P_G`: the chi-square probability of
        ``threshold`` with ``dim`` degrees of freedom (1 when ungated).
    """

    rows: np.ndarray
    cols: np.ndarray
    d2: np.ndarray
    logdet: np.ndarray
    n_tracks: int
    n_meas: int
    dim: int
    threshold: float
    probability: float

    @property
    def n_pairs(self) -> int:
        return len(self.rows)


def chi2_threshold(probability: float, dim: int) -> float:
    """Gate threshold: the ``probability`` quantile of chi-square with ``dim`` dof.

    Computed as scipy.stats.chi2.ppf does (``2 * gammaincinv(dim / 2, p)``), from
    scipy.special, without importing scipy.stats (about a second).

    >>> round(chi2_threshold(0.99, 2), 4)
    9.2103
    """
    from scipy.special import gammaincinv

    if not 0.0 < float(probability) < 1.0:
        raise InvalidProblemError(f"gate probability must lie in (0, 1), got {probability}")
    if int(dim) < 1:
        raise InvalidProblemError(f"measurement dimension must be >= 1, got {dim}")
    return float(2.0 * gammaincinv(int(dim) / 2.0, float(probability)))


def predict_measurements(x: ArrayLike, P: ArrayLike, H: ArrayLike,
                         R: ArrayLike | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Predicted measurements :math:`H x_i` and covariances :math:`H P_i H^T (+ R)`.

    ``x`` is ``(n, d)``, ``P`` is ``(n, d, d)`` or one ``(d, d)``, ``H`` is ``(m, d)``;
    ``R`` (``(m, m)``) is added when given.  ``P`` and ``R`` are covariances: each must
    be symmetric and positive semi-definite (an indefinite or negative-definite one is
    an error, not a silently wrong gate).

    >>> z, S = predict_measurements([[1.0, 0.5]], np.eye(2), [[1.0, 0.0]], [[0.1]])
    >>> z.tolist(), S.tolist()
    ([[1.0]], [[[1.1]]])
    """
    X = finite_floats(x, "x")
    if X.ndim != 2:
        raise InvalidProblemError(f"x must have shape (n, d), got {X.shape}")
    n, d = X.shape
    Pm = _per_item(P, "P", n, d)
    _check_covariance(P, "P")
    Hm = finite_floats(H, "H")
    if Hm.ndim != 2 or Hm.shape[1] != d:
        raise InvalidProblemError(f"H must have shape (m, {d}), got {Hm.shape}")
    z = X @ Hm.T
    S = np.einsum("ij,njk,lk->nil", Hm, Pm, Hm)
    if R is not None:
        Rm = finite_floats(R, "R")
        m = Hm.shape[0]
        if Rm.shape != (m, m):
            raise InvalidProblemError(f"R must have shape ({m}, {m}), got {Rm.shape}")
        _check_covariance(Rm, "R")
        S = S + Rm
    return z, S


def gate(z_pred: ArrayLike, S: ArrayLike, z: ArrayLike, *, R: ArrayLike | None = None,
         probability: float = 0.99, threshold: float | None = None) -> Gate:
    """Gated pairs of predicted measurements ``z_pred`` and measurements ``z``.

    Parameters
    ----------
    z_pred : (n, m) predicted measurement of each track
    S : (n, m, m) or (m, m)
        Innovation covariance of each track (with ``R`` given: its predicted
        measurement covariance :math:`H P H^T`, to which ``R`` is added).
    z : (M, m) measurements
    R : (m, m) or (M, m, m), optional
        Measurement noise, shared or one per measurement.
    probability : gate probability (chi-square quantile with m dof)
    threshold : explicit gate on :math:`d^2` instead (``inf``: keep every pair)

    Examples
    --------
    >>> g = gate([[0.0, 0.0], [10.0, 0.0]], np.eye(2), [[0.5, 0.0], [10.0, 4.0]])
    >>> g.rows.tolist(), g.cols.tolist(), g.d2.tolist()
    ([0], [0], [0.25])
    """
    zp, Sm, Z, Rm = _check(z_pred, S, z, R)
    n, m = zp.shape
    M = len(Z)
    gamma = _threshold(probability, threshold, m)
    L_track, logdet_track = _cholesky(Sm, "S", "track") if Rm is None else (None, None)
    if Rm is not None:
        _cholesky(Rm, "R", "measurement")
    rows, cols = _candidates(zp, Sm, Z, Rm, gamma)
    d2, logdet = _pair_stats(zp, Z, rows, cols, Sm, Rm, L_track, logdet_track)
    keep = d2 <= gamma
    rows, cols, d2, logdet = rows[keep], cols[keep], d2[keep], logdet[keep]
    order = np.lexsort((cols, rows))
    return Gate(rows[order], cols[order], d2[order], logdet[order], n, M, m, gamma,
                _gate_probability(gamma, m))


def pair_statistics(z_pred: ArrayLike, S: ArrayLike, z: ArrayLike, rows: ArrayLike,
                    cols: ArrayLike, *, R: ArrayLike | None = None
                    ) -> tuple[np.ndarray, np.ndarray]:
    """``(d2, logdet)`` of the given pairs (0-based ``rows``/``cols``), no gate."""
    zp, Sm, Z, Rm = _check(z_pred, S, z, R)
    r = np.asarray(rows, dtype=np.int64)
    c = np.asarray(cols, dtype=np.int64)
    if r.shape != c.shape or r.ndim != 1:
        raise InvalidProblemError("rows and cols must be 1-D arrays of equal length")
    if len(r) and (r.min() < 0 or r.max() >= len(zp) or c.min() < 0 or c.max() >= len(Z)):
        raise InvalidProblemError("rows/cols refer to a track or measurement that does not exist")
    L, ld = _cholesky(Sm, "S", "track") if Rm is None else (None, None)
    return _pair_stats(zp, Z, r, c, Sm, Rm, L, ld)


# ---------------------------------------------------------------- internals
def _check(z_pred, S, z, R):
    zp = finite_floats(z_pred, "z_pred")
    if zp.ndim == 1:
        zp = zp[:, None]
    if zp.ndim != 2:
        raise InvalidProblemError(f"z_pred must have shape (n, m), got {zp.shape}")
    n, m = zp.shape
    Z = finite_floats(z, "z")
    if Z.ndim == 1 and m == 1:
        Z = Z[:, None]
    if Z.size == 0:
        Z = Z.reshape(0, m)
    if Z.ndim != 2 or Z.shape[1] != m:
        raise InvalidProblemError(f"z must have shape (M, {m}) like z_pred, got {Z.shape}")
    Sm = _per_item(S, "S", n, m)
    Rm = None
    if R is not None:
        Rm = finite_floats(R, "R")
        if Rm.shape == (m, m):
            Sm = Sm + Rm                    # shared noise: fold it into S
            Rm = None
        elif Rm.shape != (len(Z), m, m):
            raise InvalidProblemError(f"R must have shape ({m}, {m}) or ({len(Z)}, {m}, {m}),"
                                      f" got {Rm.shape}")
    return zp, Sm, Z, Rm


def _per_item(a: ArrayLike, what: str, n: int, k: int) -> np.ndarray:
    """``a`` as ``(n, k, k)``: one ``(k, k)`` matrix shared by all ``n`` items (a
    read-only broadcast view) or one per item."""
    A = finite_floats(a, what)
    if A.shape == (k, k):
        A = np.broadcast_to(A, (n, k, k))
    if A.shape != (n, k, k):
        raise InvalidProblemError(f"{what} must have shape ({n}, {k}, {k}) or ({k}, {k}), "
                                  f"got {A.shape}")
    return A


#: Relative round-off allowed in a covariance's symmetry and smallest eigenvalue.
_COV_TOL = 1e-9


def _check_covariance(a: ArrayLike, what: str) -> None:
    """Raise unless every ``(k, k)`` matrix of ``a`` is symmetric positive
    semi-definite (to a relative :data:`_COV_TOL` of its largest entry)."""
    A = np.asarray(a, dtype=np.float64)
    if A.ndim == 2:
        A = A[None]
    if A.size == 0:
        return
    scale = np.abs(A).max(axis=(1, 2))
    tol = _COV_TOL * np.maximum(scale, np.finfo(np.float64).tiny)
    asym = np.abs(A - A.transpose(0, 2, 1)).max(axis=(1, 2))
    bad = np.flatnonzero(asym > tol)
    if len(bad):
        i = int(bad[0])
        where = f"{what}[{i}]" if np.ndim(a) == 3 else what
        raise InvalidProblemError(f"{where} is not symmetric (largest |{what} - {what}^T| "
                                  f"entry {asym[i]:.3g}): a covariance must be")
    low = np.linalg.eigvalsh(A)[:, 0]
    bad = np.flatnonzero(low < -tol)
    if len(bad):
        i = int(bad[0])
        where = f"{what}[{i}]" if np.ndim(a) == 3 else what
        kind = "negative definite" if np.linalg.eigvalsh(A[i])[-1] < 0 else "indefinite"
        raise InvalidProblemError(f"{where} is not positive semi-definite (it is {kind}: "
                                  f"smallest eigenvalue {low[i]:.6g}); a covariance must be")


def _threshold(probability: float, threshold: float | None, m: int) -> float:
    if threshold is None:
        return chi2_threshold(probability, m)
    t = float(threshold)
    if np.isnan(t) or t <= 0:
        raise InvalidProblemError(f"gate threshold must be > 0 (or inf), got {threshold}")
    return t


def _gate_probability(gamma: float, m: int) -> float:
    if np.isinf(gamma):
        return 1.0
    from scipy.stats import chi2
    return float(chi2.cdf(gamma, m))


def _cholesky(S: np.ndarray, what: str, item: str) -> tuple[np.ndarray, np.ndarray]:
    """Batched Cholesky factors and log-determinants; names the first non-PD matrix."""
    if len(S) == 0:
        return S.copy(), np.zeros(0)
    try:
        L = np.linalg.cholesky(S)
    except np.linalg.LinAlgError as exc:
        sym = 0.5 * (S + np.swapaxes(S, -1, -2))
        bad = int(np.argmin(np.linalg.eigvalsh(sym)[:, 0]))
        raise InvalidProblemError(
            f"{what} of {item} {bad} (0-based) is not positive definite") from exc
    logdet = 2.0 * np.log(np.diagonal(L, axis1=-2, axis2=-1)).sum(axis=-1)
    return L, logdet


def _candidates(zp, S, Z, R, gamma) -> tuple[np.ndarray, np.ndarray]:
    """Pairs within the conservative Euclidean radius (all pairs when ungated)."""
    n, M = len(zp), len(Z)
    if n == 0 or M == 0:
        return np.zeros(0, np.int64), np.zeros(0, np.int64)
    if np.isinf(gamma):
        rows, cols = np.divmod(np.arange(n * M, dtype=np.int64), M)
        return rows, cols
    from scipy.spatial import cKDTree

    lam = np.linalg.eigvalsh(0.5 * (S + np.swapaxes(S, -1, -2)))[:, -1]
    if R is not None:
        lam = lam + float(np.linalg.eigvalsh(0.5 * (R + np.swapaxes(R, -1, -2)))[:, -1].max())
    radius = np.sqrt(gamma * lam) * (1.0 + _RADIUS_SLACK)
    hits = cKDTree(Z).query_ball_point(zp, radius, return_sorted=False)
    counts = np.fromiter(map(len, hits), dtype=np.int64, count=n)
    cols = np.fromiter(itertools.chain.from_iterable(hits), dtype=np.int64,
                       count=int(counts.sum()))
    rows = np.repeat(np.arange(n, dtype=np.int64), counts)
    return rows, cols


def _pair_stats(zp, Z, rows, cols, S, R, L_track, logdet_track):
    """Squared Mahalanobis distance and log det S of each pair, whitened by Cholesky."""
    v = Z[cols] - zp[rows]
    if len(rows) == 0:
        return np.zeros(0), np.zeros(0)
    if R is None:
        Linv = np.linalg.inv(L_track)                       # one per track
        w = np.einsum("kij,kj->ki", Linv[rows], v)
        return np.einsum("ki,ki->k", w, w), logdet_track[rows]
    L, logdet = _cholesky(S[rows] + R[cols], "S + R", "pair")
    w = np.linalg.solve(L, v[..., None])[..., 0]
    return np.einsum("ki,ki->k", w, w), logdet
