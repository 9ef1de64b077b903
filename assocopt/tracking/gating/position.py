"""Pairwise gate of position-like reports across sensors, with a spatial index.

Two reports :math:`z_i` (sensor ``s``, noise :math:`R_i`) and :math:`z_j` (sensor
``t``, noise :math:`R_j`) of one target differ by a zero-mean Gaussian of covariance
:math:`C_{ij} = R_i + R_j`, so they are *compatible* when

.. math:: (z_i - z_j)^\\top C_{ij}^{-1} (z_i - z_j) \\le \\gamma,

:math:`\\gamma` the ``probability`` quantile of chi-square with ``d`` degrees of
freedom.  Since the left side is at least :math:`\\lVert z_i - z_j \\rVert^2 /
\\lambda_{\\max}(C_{ij})` and :math:`\\lambda_{\\max}(C_{ij}) \\le \\lambda_{\\max}(R_i)
+ \\lambda_{\\max}(R_j)`, every compatible pair lies within the Euclidean radius
:math:`\\sqrt{\\gamma\\,(\\lambda_{\\max}(R_i) + \\max_j \\lambda_{\\max}(R_j))}` of
:math:`z_i`: a :class:`scipy.spatial.cKDTree` returns those candidates (no
all-pairs pass), and the exact test keeps the compatible ones.  The result, one
sparse boolean matrix per sensor pair, is what
:func:`assocopt.tracking.gating.tuples.gated_tuples` takes.
"""

from __future__ import annotations

import itertools
from typing import Sequence

import numpy as np
from numpy.typing import ArrayLike

from ...runtime.errors import InvalidProblemError
from .chi2 import _RADIUS_SLACK, chi2_threshold

__all__ = ["position_pair_gate", "check_reports"]


def check_reports(reports: Sequence[ArrayLike], R: Sequence[ArrayLike] | ArrayLike
                  ) -> tuple[list[np.ndarray], list[np.ndarray]]:
    """Validated reports ``(n_s, d)`` and covariances ``(n_s, d, d)`` (a read-only
    broadcast view where one matrix is shared by a sensor's reports).

    ``R`` is one ``(d, d)`` matrix for every sensor, or a sequence with, per sensor,
    one ``(d, d)`` matrix or one ``(n_s, d, d)`` matrix per report.  Raises
    :class:`InvalidProblemError` naming the sensor (and report) for NaN/inf, a shape
    or dimension mismatch, or a covariance that is not symmetric positive definite.
    """
    Z: list[np.ndarray] = []
    if isinstance(reports, np.ndarray) and reports.ndim == 2:
        raise InvalidProblemError("reports must be one (n_s, d) array per sensor, "
                                  f"got one array of shape {reports.shape}")
    for s, z in enumerate(reports):
        a = np.asarray(z, dtype=np.float64)
        if a.ndim == 1 and a.size == 0:
            a = a.reshape(0, Z[0].shape[1] if Z else 0)
        if a.ndim != 2:
            raise InvalidProblemError(f"reports of sensor {s} must have shape (n_s, d), "
                                      f"got {a.shape}")
        if not np.isfinite(a).all():
            bad = int(np.flatnonzero(~np.isfinite(a).all(axis=1))[0])
            raise InvalidProblemError(f"report {bad} (0-based) of sensor {s} contains "
                                      "NaN or inf")
        Z.append(a)
    if len(Z) < 2:
        raise InvalidProblemError(f"reports must come from at least 2 sensors, got {len(Z)}")
    dims = [a.shape[1] for a in Z if a.shape[1] or len(a)]
    d = dims[0] if dims else 0
    if d < 1 or any(v != d for v in dims):
        raise InvalidProblemError("every sensor's reports must have the same dimension "
                                  f"d >= 1, got {[a.shape[1] for a in Z]}")
    Z = [a.reshape(len(a), d) for a in Z]
    N = len(Z)
    if not isinstance(R, (list, tuple)) and np.asarray(R).ndim == 2:
        Rs = [R] * N
    else:
        Rs = list(R)
        if len(Rs) != N:
            raise InvalidProblemError(f"R must be one (d, d) matrix, or one entry per sensor "
                                      f"({N}), got {len(Rs)}")
    out = []
    for s, (r, z) in enumerate(zip(Rs, Z)):
        a = np.asarray(r, dtype=np.float64)
        if a.shape == (d, d):
            a = np.broadcast_to(a, (len(z), d, d))
            rep = a[:1]
        elif a.shape == (len(z), d, d):
            rep = a[:1] if len(a) and a.strides[0] == 0 else a
        else:
            raise InvalidProblemError(f"R of sensor {s} must have shape ({d}, {d}) or "
                                      f"({len(z)}, {d}, {d}), got {a.shape}")
        if not np.isfinite(rep).all():
            raise InvalidProblemError(f"R of sensor {s} contains NaN or inf")
        if len(rep):
            asym = np.abs(rep - np.swapaxes(rep, 1, 2)).max(axis=(1, 2))
            scale = np.abs(rep).max(axis=(1, 2))
            bad = np.flatnonzero(asym > 1e-9 * np.maximum(scale, 1e-300))
            if len(bad):
                raise InvalidProblemError(f"R of sensor {s} (report {int(bad[0])}) is not "
                                          "symmetric")
            lam = np.linalg.eigvalsh(rep)[:, 0]
            bad = np.flatnonzero(~(lam > 0))
            if len(bad):
                what = f"R of sensor {s}" + ("" if rep.shape[0] != len(z) or len(z) == 1 and a.strides[0] == 0
                                             else f" (report {int(bad[0])})")
                raise InvalidProblemError(f"{what} is not positive definite "
                                          f"(smallest eigenvalue {lam[bad[0]]:.3g})")
        out.append(a)
    return Z, out


def position_pair_gate(reports: Sequence[ArrayLike], R: Sequence[ArrayLike] | ArrayLike, *,
                       probability: float = 0.999):
    """Compatible report pairs of every sensor pair: ``{(s, t): sparse (n_s, n_t)}``.

    ``reports`` holds one ``(n_s, d)`` array per sensor (positions, or any reports
    of one target's state with Gaussian noise), ``R`` one ``(d, d)`` covariance per
    sensor or one ``(n_s, d, d)`` per report (or a single ``(d, d)`` for all).  Pair
    ``(i, j)`` of sensors ``s < t`` is compatible when its difference passes the
    chi-square(d) test at ``probability`` with covariance ``R_i + R_j`` (module
    docstring); the candidates come from a KD-tree, never from all pairs.  The
    values are boolean :class:`scipy.sparse.csr_matrix` with sorted indices, ready
    for :func:`assocopt.tracking.gating.tuples.gated_tuples`.

    >>> ok = position_pair_gate([[[0.0, 0.0], [5.0, 5.0]], [[0.1, 0.0]]], np.eye(2))
    >>> ok[(0, 1)].toarray().tolist()
    [[True], [False]]
    """
    from scipy import sparse
    from scipy.spatial import cKDTree

    Z, Rs = check_reports(reports, R)
    d = Z[0].shape[1]
    gamma = chi2_threshold(probability, d)
    lam = [_lam_max(r) for r in Rs]                  # (n_s,) largest eigenvalue per report
    trees = [cKDTree(z) if len(z) else None for z in Z]
    out = {}
    for s, t in itertools.combinations(range(len(Z)), 2):
        n_s, n_t = len(Z[s]), len(Z[t])
        rows, cols = _candidates(Z, trees, lam, s, t, gamma)
        if len(rows):
            keep = _d2(Z[s], Z[t], Rs[s], Rs[t], rows, cols) <= gamma
            rows, cols = rows[keep], cols[keep]
        order = np.lexsort((cols, rows))
        rows, cols = rows[order], cols[order]
        ptr = np.zeros(n_s + 1, np.int64)
        np.cumsum(np.bincount(rows, minlength=n_s), out=ptr[1:])
        M = sparse.csr_matrix((np.ones(len(cols), bool), cols, ptr), shape=(n_s, n_t))
        M.has_sorted_indices = True
        out[(s, t)] = M
    return out


def _lam_max(r: np.ndarray) -> np.ndarray:
    """Largest eigenvalue of each report's covariance (once for a shared one)."""
    if len(r) and r.strides[0] == 0:
        return np.full(len(r), np.linalg.eigvalsh(r[:1])[0, -1])
    return np.linalg.eigvalsh(r)[:, -1] if len(r) else np.zeros(0)


def _candidates(Z, trees, lam, s, t, gamma) -> tuple[np.ndarray, np.ndarray]:
    """Pairs within the conservative Euclidean radius: the tree of the sensor with
    the smaller spread of noise is queried with a ball per report of the other."""
    if trees[s] is None or trees[t] is None:
        return np.zeros(0, np.int64), np.zeros(0, np.int64)
    ls, lt = lam[s], lam[t]
    if ls.max() == ls.min() and lt.max() == lt.min():      # one radius: tree against tree
        radius = np.sqrt(gamma * (ls[0] + lt[0])) * (1.0 + _RADIUS_SLACK)
        D = trees[s].sparse_distance_matrix(trees[t], radius, output_type="ndarray")
        return D["i"].astype(np.int64), D["j"].astype(np.int64)
    # a radius per report of one sensor, the other's largest eigenvalue added
    swap = lt.max() - lt.min() > ls.max() - ls.min()
    a, b = (t, s) if swap else (s, t)
    radius = np.sqrt(gamma * (lam[a] + lam[b].max())) * (1.0 + _RADIUS_SLACK)
    hits = trees[b].query_ball_point(Z[a], radius, return_sorted=False)
    counts = np.fromiter(map(len, hits), dtype=np.int64, count=len(hits))
    other = np.fromiter(itertools.chain.from_iterable(hits), dtype=np.int64,
                        count=int(counts.sum()))
    mine = np.repeat(np.arange(len(hits), dtype=np.int64), counts)
    return (other, mine) if swap else (mine, other)


def _d2(zs, zt, Rs, Rt, rows, cols, chunk: int = 1 << 18) -> np.ndarray:
    """Squared Mahalanobis distance of each pair's difference, covariance R_i + R_j
    (one Cholesky factor when both sensors share one covariance), in chunks."""
    v = zs[rows] - zt[cols]
    if Rs.strides[0] == 0 and Rt.strides[0] == 0:
        L = np.linalg.cholesky(Rs[0] + Rt[0])
        w = np.linalg.solve(L, v.T)
        return np.einsum("ik,ik->k", w, w)
    out = np.empty(len(rows))
    for a in range(0, len(rows), chunk):
        sl = slice(a, a + chunk)
        C = Rs[rows[sl]] + Rt[cols[sl]]
        w = np.linalg.solve(np.linalg.cholesky(C), v[sl][..., None])[..., 0]
        out[sl] = np.einsum("ki,ki->k", w, w)
    return out
