"""Paper 001's track-association degrees (eqs. 3-7) and their Dempster fusion, in bulk.

Node-1 tracks ``i`` are rows, node-2 tracks ``j`` columns; every function returns an
``(n1, n2)`` matrix.  The equations and the corrections we apply are stated in
docs/papers/yan2010.md ("Corrections to the paper"); in short:

* statistical distance (3): ``D_ij = d^T (P1_i + P2_j)^-1 d``, ``d = X1_i - X2_j``;
* state degree (4): ``m_d = a1 * min_j' D_ij' / D_ij``, with ``m_d = a1`` when
  ``D_ij <= d_tiny`` (the printed formula divides by zero there);
* feature degrees (5)-(7): ``a`` for ``delta <= eps``, the convex quadratic
  ``a (delta - 2 eps)^2 / eps^2`` for ``eps < delta < 2 eps`` (``a`` at ``eps``, 0 at
  ``2 eps``: continuous), 0 beyond; the tolerance ``eps`` of each feature is
  ``k_tol * sqrt(sigma1^2 + sigma2^2)`` (ours: the paper only says "set by the noise");
* fusion (:data:`FUSIONS`): ``"candidate"`` -- the frame is node 2's track set, each
  feature's degrees normalised over the candidates are a Bayesian mass function and
  Dempster's rule gives ``prod_x m_x / sum_j prod_x m_x`` (the weights cancel);
  ``"pair"`` -- the frame is {associated, not associated} per pair, each degree is
  the mass of "associated" with the rest on the whole frame, and Dempster's rule (no
  conflict) gives ``1 - prod_x (1 - m_x)``.

>>> import numpy as np
>>> feature_degree(np.array([0.0, 1.0, 1.5, 2.0, 3.0]), eps=1.0, weight=0.2).tolist()
[0.2, 0.2, 0.05, 0.0, 0.0]
"""

from __future__ import annotations

from dataclasses import asdict, dataclass

import numpy as np
from numpy.typing import ArrayLike

from ..belief import conjunctive_vectors

__all__ = ["FUSIONS", "DegreeParams", "statistical_distance", "state_degree",
           "feature_degree", "tolerance", "fuse_candidate_frame", "fuse_pair_frame",
           "pair_feature_degrees", "feature_degrees", "fused_degree"]

#: Readings of "fuse the degrees with Dempster's rule" (module docstring).
FUSIONS = ("candidate", "pair")


@dataclass(frozen=True)
class DegreeParams:
    """Weights, tolerances and guards of the degrees (a1..a4 and tolerances are ours).

    ``weights`` = (a1, a2, a3, a4) for state, frequency, PW, PRI, summing to 1;
    ``tolerances`` = (f_eps, t_eps, Tr_eps) in the units of the features;
    ``d_tiny``: a distance at or below it counts as zero in (4).
    """

    weights: tuple[float, float, float, float] = (0.4, 0.2, 0.2, 0.2)
    tolerances: tuple[float, float, float] = (1.0, 1.0, 1.0)
    fusion: str = "candidate"
    d_tiny: float = 1e-12

    def __post_init__(self) -> None:
        w = np.asarray(self.weights, dtype=float)
        if w.shape != (4,) or np.any(w < 0) or abs(w.sum() - 1.0) > 1e-9:
            raise ValueError(f"weights must be 4 non-negative numbers summing to 1, "
                             f"got {self.weights!r}")
        t = np.asarray(self.tolerances, dtype=float)
        if t.shape != (3,) or not np.all(np.isfinite(t) & (t > 0)):
            raise ValueError(f"tolerances must be 3 positive numbers, got {self.tolerances!r}")
        if self.fusion not in FUSIONS:
            raise ValueError(f"fusion must be one of {FUSIONS}, got {self.fusion!r}")
        if not self.d_tiny >= 0:
            raise ValueError(f"d_tiny must be >= 0, got {self.d_tiny!r}")

    def as_dict(self) -> dict:
        return {k: (list(v) if isinstance(v, tuple) else v) for k, v in asdict(self).items()}


def tolerance(sigma1: float, sigma2: float, k_tol: float) -> float:
    """Feature tolerance ``k_tol * sqrt(sigma1^2 + sigma2^2)`` (ours).

    >>> tolerance(3.0, 4.0, 2.0)
    10.0
    """
    if not (k_tol > 0 and sigma1 >= 0 and sigma2 >= 0 and sigma1 + sigma2 > 0):
        raise ValueError(f"need k_tol > 0 and non-negative sigmas not both 0, got "
                         f"{k_tol!r}, {sigma1!r}, {sigma2!r}")
    return float(k_tol * np.hypot(sigma1, sigma2))


def statistical_distance(x1: ArrayLike, p1: ArrayLike, x2: ArrayLike, p2: ArrayLike) -> np.ndarray:
    """Eq. (3) for every pair: ``(n1, nx)``, ``(n1, nx, nx)``, ``(n2, nx)``, ``(n2, nx, nx)``
    -> ``(n1, n2)``.

    ``P1_i + P2_j`` is factored ``L L^T`` (Cholesky) for all pairs at once, entry by
    entry over ``(n1, n2)`` arrays (:func:`_spd_quadratic_form`), and ``D = |L^-1 d|^2``;
    pairs whose sum is not positive definite fall back to ``np.linalg.solve``.
    """
    x1, p1, x2, p2 = (np.asarray(a, dtype=np.float64) for a in (x1, p1, x2, p2))
    if x1.ndim != 2 or x2.ndim != 2 or x1.shape[1] != x2.shape[1] or \
            p1.shape != x1.shape + x1.shape[1:] or p2.shape != x2.shape + x2.shape[1:]:
        raise ValueError(f"shapes must be (n1, nx), (n1, nx, nx), (n2, nx), (n2, nx, nx); "
                         f"got {x1.shape}, {p1.shape}, {x2.shape}, {p2.shape}")
    out, ok = _spd_quadratic_form(x1, p1, x2, p2)
    if not ok.all():
        i, j = np.nonzero(~ok)
        d = x1[i] - x2[j]
        try:
            y = np.linalg.solve(p1[i] + p2[j], d[..., None])[..., 0]
        except np.linalg.LinAlgError as exc:
            raise ValueError("P1_i + P2_j is singular for some pair") from exc
        out[i, j] = (d * y).sum(axis=-1)
    return out


def _spd_quadratic_form(x1: np.ndarray, p1: np.ndarray, x2: np.ndarray, p2: np.ndarray
                        ) -> tuple[np.ndarray, np.ndarray]:
    """``d^T S^-1 d`` with ``d = x1_i - x2_j``, ``S = p1_i + p2_j`` for every pair, by an
    elementwise Cholesky on ``(n1, n2)`` arrays (never forming the ``(n1, n2, nx, nx)``
    stack); also the mask of pairs whose ``S`` is positive definite (elsewhere the
    value is meaningless)."""
    nx = x1.shape[1]
    ok = np.ones((len(x1), len(x2)), dtype=bool)
    L: list[list] = [[None] * nx for _ in range(nx)]
    y: list[np.ndarray] = []                                  # forward solve L y = d
    for i in range(nx):
        for j in range(i + 1):
            acc = p1[:, None, i, j] + p2[None, :, i, j]
            for k in range(j):
                acc -= L[i][k] * L[j][k]
            if i == j:
                ok &= acc > 0
                L[i][i] = np.sqrt(np.where(acc > 0, acc, 1.0))
            else:
                L[i][j] = acc / L[j][j]
        acc = x1[:, None, i] - x2[None, :, i]
        for k in range(i):
            acc -= L[i][k] * y[k]
        y.append(acc / L[i][i])
    out = y[0] * y[0]
    for v in y[1:]:
        out += v * v
    return out, ok


def state_degree(D: ArrayLike, weight: float, d_tiny: float = 1e-12,
                 candidates: ArrayLike | None = None) -> np.ndarray:
    """Eq. (4): ``weight * min_j D_ij / D_ij`` over the candidate columns, guarded.

    ``candidates`` (bool, ``(n1, n2)`` or ``(n2,)``) restricts the minimum and the
    result; non-candidates get 0.  ``D_ij <= d_tiny`` gives ``weight``.
    """
    D = np.asarray(D, dtype=np.float64)
    cand = np.ones(D.shape, bool) if candidates is None else \
        np.broadcast_to(np.asarray(candidates, bool), D.shape)
    Dc = np.where(cand, D, np.inf)
    dmin = Dc.min(axis=1, keepdims=True) if D.shape[1] else np.zeros((D.shape[0], 1))
    with np.errstate(divide="ignore", invalid="ignore"):
        ratio = np.where(D > d_tiny, np.maximum(dmin, 0.0) / np.where(D > d_tiny, D, 1.0), 1.0)
    return np.where(cand, weight * np.clip(ratio, 0.0, 1.0), 0.0)


def feature_degree(delta: ArrayLike, eps: float, weight: float) -> np.ndarray:
    """Eqs. (5)-(7): ``weight`` up to ``eps``, ``weight (delta - 2 eps)^2 / eps^2`` up to
    ``2 eps``, then 0 (``delta`` is the absolute feature difference)."""
    if not eps > 0:
        raise ValueError(f"tolerance eps must be > 0, got {eps!r}")
    d = np.abs(np.asarray(delta, dtype=np.float64))
    mid = weight * (d - 2.0 * eps) ** 2 / eps ** 2
    return np.where(d <= eps, weight, np.where(d < 2.0 * eps, mid, 0.0))


def pair_feature_degrees(f1: ArrayLike, f2: ArrayLike, params: DegreeParams) -> np.ndarray:
    """The frequency (5), PW (6) and PRI (7) degrees of every pair, ``(3, n1, n2)``.

    They do not depend on which tracks are still candidates, so a caller deciding
    several ways on one scan computes them once (:meth:`TrackAssociator.step`).
    """
    f1 = np.asarray(f1, dtype=np.float64)
    f2 = np.asarray(f2, dtype=np.float64)
    a = params.weights
    return np.stack([feature_degree(f1[:, None, k] - f2[None, :, k], params.tolerances[k],
                                    a[k + 1]) for k in range(3)])


def feature_degrees(D: ArrayLike, f1: ArrayLike, f2: ArrayLike, params: DegreeParams,
                    candidates: ArrayLike | None = None) -> np.ndarray:
    """The four degrees ``(4, n1, n2)``: state (4), frequency (5), PW (6), PRI (7).

    ``f1`` ``(n1, 3)`` and ``f2`` ``(n2, 3)`` hold frequency, PW and PRI per track.
    """
    state = state_degree(D, params.weights[0], params.d_tiny, candidates)
    m = np.concatenate([state[None], pair_feature_degrees(f1, f2, params)])
    if candidates is not None:
        m = m * np.broadcast_to(np.asarray(candidates, bool), m.shape[1:])
    return m


def fuse_candidate_frame(m: ArrayLike) -> np.ndarray:
    """Dempster's rule on the frame of node-2 candidates, per row.

    ``m`` ``(n_features, n1, n2)``: feature ``x`` gives candidate ``j`` of row ``i`` the
    singleton mass ``m[x, i, j] / sum_j m[x, i, j]``.  With singletons only, Dempster's
    rule is the normalised product ``prod_x m / sum_j prod_x m``.  A row whose product
    is 0 for every candidate (total conflict) gets all zeros: no association.
    """
    m = np.asarray(m, dtype=np.float64)
    prod = np.prod(m, axis=0)
    tot = prod.sum(axis=1, keepdims=True)
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where(tot > 0, prod / np.where(tot > 0, tot, 1.0), 0.0)


def fuse_pair_frame(m: ArrayLike) -> np.ndarray:
    """Dempster's rule on {associated, not associated} per pair, through
    :func:`assocopt.tracking.belief.conjunctive_vectors`.

    Feature ``x`` gives "associated" the mass ``m[x]`` and the whole frame ``1 - m[x]``;
    there is no conflict, so Dempster's rule is the conjunctive rule and the fused
    mass of "associated" is ``1 - prod_x (1 - m[x])``.
    """
    m = np.asarray(m, dtype=np.float64)
    if np.any((m < 0) | (m > 1)):
        raise ValueError("degrees must lie in [0, 1]")
    # bit 0 = associated, bit 1 = not associated; vectors over {}, {A}, {N}, {A, N}
    vec = np.zeros(m.shape + (4,))
    vec[..., 1] = m
    vec[..., 3] = 1.0 - m
    out = vec[0]
    for v in vec[1:]:
        out = conjunctive_vectors(out, v)
    return out[..., 1]


def fused_degree(m: ArrayLike, fusion: str) -> np.ndarray:
    """Fuse ``(n_features, n1, n2)`` degrees under ``fusion`` (one of :data:`FUSIONS`)."""
    if fusion == "candidate":
        return fuse_candidate_frame(m)
    if fusion == "pair":
        return fuse_pair_frame(m)
    raise ValueError(f"fusion must be one of {FUSIONS}, got {fusion!r}")
