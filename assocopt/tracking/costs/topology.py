"""Target reference frames and the topology statistical distance (Dong et al. 2015).

A sensor's azimuth bias rotates its whole track picture about the sensor and its
offsets translate it; the relative geometry of the targets survives.  Describing every
track in a frame centred on one *reference* track and aligned with that track's own
heading removes both: the rotation enters the reference heading as well and cancels.

Conventions (the paper's printed formulas are lost; these are ours and stated on
``docs/papers/dong2015.md``):

* state ``X = [x, y, vx, vy]``; heading ``theta = atan2(vx, vy)``, measured clockwise
  from +y (north), the sense in which a radar measures azimuth;
* ``Rot(theta) = [[cos, -sin], [sin, cos]]`` maps the reference track's velocity
  ``V (sin theta, cos theta)`` to ``(0, V)``; ``T(u) = blockdiag(Rot, Rot)``;
* track ``i`` in the frame of reference ``u``: ``X_i(u) = T(u) (X_i - E X_u)`` with
  ``E`` keeping the position (positions translated, velocities only rotated), and
  ``P_i(u) = T(u) P_i T(u)^T``; the full-state variant subtracts the whole state
  (``E = I``, relative velocity), which maps the reference itself to the zero vector;
* ``gamma_ij(u, v) = D^T (P_1i(u) + P_2j(v))^-1 D`` with ``D = X_1i(u) - X_2j(v)``,
  gated by the chi-square quantile ``delta(alpha, n_x)``.

Every function works on all reference tracks at once (arrays indexed ``[u, i, ...]``).

>>> X = np.array([[0.0, 0.0, 0.0, 100.0], [1000.0, 0.0, 0.0, 100.0]])
>>> Xr, _ = reference_frames(X, np.broadcast_to(np.eye(4), (2, 4, 4)))
>>> Xr[0, 1].round(6).tolist()          # track 1 seen from track 0 (heading north)
[1000.0, 0.0, 0.0, 100.0]
>>> round(chi2_gate(0.01, 4), 4)
13.2767
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike
from scipy.stats import chi2

__all__ = ["headings", "rotations", "reference_frames", "heading_variance",
           "heading_jacobians", "pair_distances", "all_distances", "chi2_gate",
           "check_tracks"]


def check_tracks(X: ArrayLike, P: ArrayLike, name: str = "tracks") -> tuple[np.ndarray, np.ndarray]:
    """Validated ``(n, 4)`` states and ``(n, 4, 4)`` covariances (finite, matching n)."""
    X = np.asarray(X, dtype=np.float64)
    P = np.asarray(P, dtype=np.float64)
    if X.ndim != 2 or X.shape[1] != 4:
        raise ValueError(f"{name}: states must have shape (n, 4) [x, y, vx, vy], got {X.shape}")
    if P.shape != (X.shape[0], 4, 4):
        raise ValueError(f"{name}: covariances must have shape ({X.shape[0]}, 4, 4), "
                         f"got {P.shape}")
    if not (np.isfinite(X).all() and np.isfinite(P).all()):
        raise ValueError(f"{name}: states and covariances must be finite")
    return X, P


def headings(X: ArrayLike) -> np.ndarray:
    """Heading of each track, ``atan2(vx, vy)`` (radians clockwise from north)."""
    X = np.asarray(X, dtype=np.float64)
    return np.arctan2(X[..., 2], X[..., 3])


def rotations(theta: ArrayLike) -> np.ndarray:
    """``T = blockdiag(Rot(theta), Rot(theta))`` for each angle: shape ``(..., 4, 4)``."""
    th = np.asarray(theta, dtype=np.float64)
    c, s = np.cos(th), np.sin(th)
    T = np.zeros(th.shape + (4, 4))
    for o in (0, 2):
        T[..., o, o] = c
        T[..., o, o + 1] = -s
        T[..., o + 1, o] = s
        T[..., o + 1, o + 1] = c
    return T


def _offsets(X: np.ndarray, full_state: bool) -> np.ndarray:
    """``X_i - E X_u`` for every (u, i): shape ``(n, n, 4)``."""
    ref = X.copy() if full_state else np.concatenate([X[:, :2], np.zeros((len(X), 2))], 1)
    return X[None, :, :] - ref[:, None, :]


def reference_frames(X: ArrayLike, P: ArrayLike, full_state: bool = False,
                     ref_cov: bool = False) -> tuple[np.ndarray, np.ndarray]:
    """Every track in every reference track's frame.

    Returns ``Xr[u, i] = T(u) (X_i - E X_u)`` (shape ``(n, n, 4)``) and
    ``Pr[u, i] = T(u) P_i T(u)^T`` (shape ``(n, n, 4, 4)``).  ``full_state`` subtracts
    the whole reference state instead of its position only.  ``ref_cov`` (ours) uses
    the first-order covariance of ``X_i - E X_u`` instead: ``P_i + E P_u E^T`` for
    ``i != u`` (independent track errors); the reference's own entry keeps
    ``T P_u T^T`` as without it (its exact covariance is singular).
    """
    X, P = check_tracks(X, P)
    T = rotations(headings(X))
    Xr = np.einsum("uab,uib->uia", T, _offsets(X, full_state))
    if ref_cov:
        E = np.eye(4) if full_state else np.diag([1.0, 1.0, 0.0, 0.0])
        Q = P[None, :] + (E @ P @ E)[:, None]
        n = len(X)
        Q[np.arange(n), np.arange(n)] = P
        Pr = np.einsum("uab,uibc,udc->uiad", T, Q, T)
    else:
        Pr = np.einsum("uab,ibc,udc->uiad", T, P, T)
    return Xr, Pr


def heading_variance(X: ArrayLike, P: ArrayLike) -> np.ndarray:
    """First-order variance of each track's heading estimate (rad^2).

    ``(vy^2 P_vxvx - 2 vx vy P_vxvy + vx^2 P_vyvy) / (vx^2 + vy^2)^2``: the gradient of
    ``atan2(vx, vy)`` is ``(vy, -vx) / V^2``.  A track at rest gets ``inf``.
    """
    X, P = check_tracks(X, P)
    vx, vy = X[:, 2], X[:, 3]
    num = vy ** 2 * P[:, 2, 2] - 2 * vx * vy * P[:, 2, 3] + vx ** 2 * P[:, 3, 3]
    den = (vx ** 2 + vy ** 2) ** 2
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(den > 0, num / np.where(den > 0, den, 1.0), np.inf)


def heading_jacobians(X: ArrayLike, full_state: bool = False) -> np.ndarray:
    """``J[u, i] = d X_i(u) / d theta_u = T'(theta_u) (X_i - E X_u)``, shape ``(n, n, 4)``.

    ``Rot'(theta) = [[-sin, -cos], [cos, -sin]]``; used to add the reference heading's
    uncertainty to the distance's covariance (an option of ours).
    """
    X = np.asarray(X, dtype=np.float64)
    th = headings(X)
    c, s = np.cos(th), np.sin(th)
    dT = np.zeros(th.shape + (4, 4))
    for o in (0, 2):
        dT[..., o, o] = -s
        dT[..., o, o + 1] = -c
        dT[..., o + 1, o] = c
        dT[..., o + 1, o + 1] = -s
    return np.einsum("uab,uib->uia", dT, _offsets(X, full_state))


def pair_distances(X1r: np.ndarray, P1r: np.ndarray, X2r: np.ndarray, P2r: np.ndarray,
                   u: int, v: int, extra1: np.ndarray | None = None,
                   extra2: np.ndarray | None = None) -> np.ndarray:
    """``gamma_ij(u, v)`` for every (i, j) under one reference pair: shape ``(n1, n2)``.

    ``extra1[i]`` / ``extra2[j]`` (``(n, 4, 4)``, optional) are added to ``B_ij``
    (the heading-variance inflation).
    """
    B = P1r[u][:, None] + P2r[v][None, :]
    if extra1 is not None:
        B = B + extra1[:, None]
    if extra2 is not None:
        B = B + extra2[None, :]
    D = X1r[u][:, None, :] - X2r[v][None, :, :]
    return np.einsum("ija,ija->ij", D, np.linalg.solve(B, D[..., None])[..., 0])


def all_distances(X1r: np.ndarray, P1r: np.ndarray, X2r: np.ndarray, P2r: np.ndarray
                  ) -> np.ndarray:
    """The whole tensor ``gamma[u, v, i, j]`` (memory ``(n1 n2)^2``: small problems and
    tests; the decision path computes it one reference pair at a time, compiled)."""
    D = X1r[:, None, :, None, :] - X2r[None, :, None, :, :]
    B = P1r[:, None, :, None] + P2r[None, :, None, :]
    return np.einsum("...a,...a->...", D, np.linalg.solve(B, D[..., None])[..., 0])


def chi2_gate(alpha: float = 0.01, dof: int = 4) -> float:
    """``delta(alpha, n_x)``: the ``1 - alpha`` quantile of chi-square with ``dof`` degrees
    of freedom (13.2767 for the paper's alpha = 0.01, n_x = 4)."""
    if not 0.0 < alpha < 1.0:
        raise ValueError(f"alpha must be in (0, 1), got {alpha!r}")
    if not isinstance(dof, (int, np.integer)) or dof < 1:
        raise ValueError(f"dof must be a positive integer, got {dof!r}")
    return float(chi2.ppf(1.0 - alpha, dof))
