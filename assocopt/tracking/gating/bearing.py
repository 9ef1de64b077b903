"""Pairwise gates of bearing measurements, and the gated S-D problem of a bearing scan.

* :func:`bearing_pair_gate` -- compatibility of two bearing measurements: the
  two-sensor position estimate lies in front of both sensors (and within
  ``max_range``), and, where a pair over-determines the position (azimuth and
  elevation: 4 angles, 3 coordinates), its angle residual passes a chi-square test
  with the redundant degrees of freedom; a geometric pre-filter (sight rays that
  can meet in the plane, epipolar planes that can agree in space) leaves the exact
  test only the pairs that may pass it, so no all-pairs pass is made;
* :func:`build_gated_problem` -- the gated S-D problem of a bearing scan: the tuples
  of :func:`assocopt.tracking.gating.tuples.gated_tuples` over those pairs, with the
  costs of :mod:`assocopt.tracking.costs.sd_builder`.
"""

from __future__ import annotations

import numpy as np

from ..costs.sd_builder import Scan, tuple_costs, tuple_costs_in_chunks, tuple_geometry
from ...runtime.errors import InvalidProblemError
from ...problems.problem import AssignmentProblem
from .chi2 import chi2_threshold
from .tuples import gated_tuples

__all__ = ["bearing_pair_gate", "build_gated_problem"]


#: Slack (rad) on the geometric pre-filter's angular windows: rounding in the exact
#: test must never keep a pair the pre-filter dropped.
_ANGLE_SLACK = 1e-7


def bearing_pair_gate(scan: Scan, *, probability: float = 0.99,
                      max_range: float | None = None, localiser: str | None = None,
                      prefilter: bool = True):
    """Compatible measurement pairs of every sensor pair of a bearing scan.

    A pair is compatible when its two-sensor position estimate exists, lies in front
    of both sensors (positive range along both lines of sight) and, if ``max_range``
    is given, within that range of both; for azimuth-elevation sensors also when
    twice its Pattipati data term (the weighted squared angle residual at the
    maximum-likelihood position) is at most the ``probability`` quantile of
    chi-square with 1 degree of freedom (4 angles - 3 coordinates).  Azimuth-only
    pairs (2 angles, 2 coordinates) have no redundancy, so only the geometric tests
    apply.  ``localiser`` defaults to ``"ils"`` (maximum likelihood) in 3-D and
    ``"ls"`` in the plane.

    Returns ``{(s, t): sparse (n_s, n_t) boolean}`` (:class:`scipy.sparse.csr_matrix`,
    ``.toarray()`` for the dense matrix), as
    :func:`assocopt.tracking.gating.tuples.gated_tuples` takes it.

    The exact test runs only on the pairs a geometric pre-filter keeps
    (``prefilter=False`` tests every pair, the same result):

    * in the plane, the lines of sight of measurement ``i`` of sensor ``s`` meet the
      one of ``j`` of sensor ``t`` in front of both exactly when ``t``'s bearing
      ``beta_j`` lies in the arc of bearings, seen from ``t``, of the points of
      ``i``'s sight ray (up to ``max_range``); the arcs are windows on ``t``'s
      sorted bearings;
    * in space (with ``probability < 1``), the residual test bounds the angle
      errors of both measurements together (``q_s + q_t <= gamma``), so the
      estimated position's direction from each sensor lies in a cone around its
      line of sight; both directions lie in one plane through the two sensors (an
      epipolar plane), so the lines' own epipolar angles ``psi`` about the baseline
      can differ by at most a bound that follows from the cones and the
      lines' angles to the baseline: a window test on sorted angles.  Without the
      residual test (``probability=1``) every pair is tested.
    """
    from scipy import sparse

    if not 0.0 < probability <= 1.0:
        raise InvalidProblemError(f"probability must lie in (0, 1], got {probability}")
    sizes = scan.sizes
    N = len(sizes)
    dim = scan.sensors.shape[1]
    loc = localiser or ("ils" if dim == 3 else "ls")
    dof = 2 * (dim - 1) - dim                               # redundant equations of a pair
    gamma = chi2_threshold(probability, dof) if dof > 0 and probability < 1.0 else None
    blocks, spans, start = [], [], 0
    for s in range(N):
        for t in range(s + 1, N):
            if not prefilter or (dim == 3 and gamma is None):
                i, j = np.divmod(np.arange(sizes[s] * sizes[t], dtype=np.int64), sizes[t])
            elif dim == 2:
                i, j = _planar_candidates(scan, s, t, max_range)
            else:
                i, j = _epipolar_candidates(scan, s, t, gamma)
            T = np.zeros((len(i), N), dtype=np.int64)
            T[:, s], T[:, t] = i + 1, j + 1
            blocks.append(T)
            spans.append(((s, t), start, start + len(i)))
            start += len(i)
    T = np.concatenate(blocks) if blocks else np.zeros((0, N), np.int64)
    ok = _exact(scan, T, loc, max_range, gamma) if len(T) else np.zeros(0, bool)
    out = {}
    for (s, t), a, b in spans:
        i, j = T[a:b, s][ok[a:b]] - 1, T[a:b, t][ok[a:b]] - 1
        order = np.lexsort((j, i))
        i, j = i[order], j[order]
        ptr = np.zeros(sizes[s] + 1, np.int64)
        np.cumsum(np.bincount(i, minlength=sizes[s]), out=ptr[1:])
        M = sparse.csr_matrix((np.ones(len(j), bool), j, ptr), shape=(sizes[s], sizes[t]))
        M.has_sorted_indices = True
        out[(s, t)] = M
    return out


def _exact(scan: Scan, T: np.ndarray, loc: str, max_range: float | None,
           gamma: float | None, chunk: int = 1 << 16) -> np.ndarray:
    """The exact pair test of :func:`bearing_pair_gate` on the two-measurement tuples
    ``T``, in chunks (the geometry of a pair takes about 2 KB)."""
    ok = np.zeros(len(T), bool)
    for a in range(0, len(T), chunk):
        Tc = T[a:a + chunk]
        g = tuple_geometry(scan, Tc, localiser=loc)
        good = g.valid.copy()
        ranges = _ranges_along_sight(scan, g)               # (K, N), nan at dummies
        with np.errstate(invalid="ignore"):
            good &= np.where(g.mask, ranges > 0, True).all(axis=1)
            if max_range is not None:
                dist = np.linalg.norm(g.x[:, None, :] - scan.sensors[None], axis=2)
                good &= np.where(g.mask, dist <= max_range, True).all(axis=1)
        if gamma is not None:
            stat = 2.0 * tuple_costs(scan, g, "pattipati", normalisation="none").data
            with np.errstate(invalid="ignore"):
                good &= stat <= gamma
        ok[a:a + chunk] = good
    return ok


def _window_pairs(centre: np.ndarray, half: np.ndarray, angles: np.ndarray
                  ) -> tuple[np.ndarray, np.ndarray]:
    """Pairs ``(k, l)``: ``angles[l]`` within ``half[k]`` of ``centre[k]`` on the
    circle (windows of half-width >= pi take every angle), by binary search in the
    sorted angles, output-sensitive."""
    n = len(angles)
    if n == 0 or len(centre) == 0:
        return np.zeros(0, np.int64), np.zeros(0, np.int64)
    order = np.argsort(angles, kind="stable")
    v = np.mod(angles[order], 2 * np.pi)
    order = order[np.argsort(v, kind="stable")]
    v = np.sort(v)
    ext = np.concatenate([v - 2 * np.pi, v, v + 2 * np.pi])
    c = np.mod(centre, 2 * np.pi)
    whole = ~(half < np.pi)
    lo = np.where(whole, n, np.searchsorted(ext, c - half, "left"))
    hi = np.where(whole, 2 * n, np.searchsorted(ext, c + half, "right"))
    cnt = hi - lo
    k = np.repeat(np.arange(len(c), dtype=np.int64), cnt)
    first = np.repeat(lo - (np.cumsum(cnt) - cnt), cnt)
    pos = first + np.arange(int(cnt.sum()), dtype=np.int64)
    return k, order[pos % n]


def _bearing(v: np.ndarray) -> np.ndarray:
    return np.arctan2(v[..., 1], v[..., 0])


def _planar_candidates(scan: Scan, s: int, t: int, max_range: float | None
                       ) -> tuple[np.ndarray, np.ndarray]:
    """Pairs whose sight rays can meet (in front of both, within ``max_range`` of
    ``s``): ``beta_j`` in the arc of bearings from ``t`` of ``i``'s ray."""
    from ..localisation import wrap_angle
    ps, pt = scan.sensors[s], scan.sensors[t]
    bi = scan.meas[s][:, 0]
    bj = scan.meas[t][:, 0]
    phi = float(_bearing(ps - pt))                          # s seen from t
    sweep = wrap_angle(bi - phi)                            # signed arc to infinity
    if max_range is not None:
        u = np.stack([np.cos(bi), np.sin(bi)], axis=1)
        end = _bearing(ps + max_range * u - pt)
        short = wrap_angle(end - phi)
        sweep = np.where(np.sign(short) == np.sign(sweep), short, sweep)
    degenerate = (np.abs(sweep) < _ANGLE_SLACK) | (np.abs(sweep) > np.pi - _ANGLE_SLACK)
    centre = phi + 0.5 * sweep
    half = np.where(degenerate, np.pi, 0.5 * np.abs(sweep) + _ANGLE_SLACK)
    return _window_pairs(centre, half, bj)


def _directions(meas: np.ndarray) -> np.ndarray:
    alpha, beta = meas[:, 0], meas[:, 1]
    return np.stack([np.cos(alpha) * np.cos(beta), np.cos(alpha) * np.sin(beta),
                     np.sin(alpha)], axis=1)


#: Largest ``sqrt(gamma * lambda_max(R)) / sin(theta)`` of a line of sight whose
#: epipolar window is bounded linearly: below it ``arcsin(y) <= ARCSIN_SLOPE * y``
#: (``arcsin`` is convex: the chord from 0 to 0.5); wider ones pair with every line.
_LINEAR_MAX = 0.5
_ARCSIN_SLOPE = (np.pi / 6) / 0.5


def _epipolar_candidates(scan: Scan, s: int, t: int, gamma: float
                         ) -> tuple[np.ndarray, np.ndarray]:
    """Pairs whose epipolar-plane angles can agree.

    With ``q_k = Delta_k^T R_k^-1 Delta_k`` the residual of sensor ``k`` (``q_s + q_t
    <= gamma`` for a kept pair), the direction to the estimate lies within the angle
    ``e_k <= sqrt(q_k lambda_max(R_k))`` of the line of sight (the map from (alpha,
    beta) to the sphere shortens lengths), so its epipolar angle within
    ``arcsin(sin e_k / sin theta_k) <= ARCSIN_SLOPE * e_k / sin theta_k``; over the
    budget the sum of both is at most ``ARCSIN_SLOPE * sqrt(gamma (a_s^2 + a_t^2))``,
    ``a_k = sqrt(lambda_max(R_k)) / sin theta_k`` (Cauchy-Schwarz).  Found as windows
    of half-width ``sqrt(2) * ARCSIN_SLOPE * sqrt(gamma) * a`` from the side of the
    larger ``a``, then filtered exactly by that bound."""
    from ..localisation import wrap_angle
    b = scan.sensors[t] - scan.sensors[s]
    b = b / np.linalg.norm(b)
    e1 = np.cross(b, [1.0, 0.0, 0.0] if abs(b[0]) < 0.9 else [0.0, 1.0, 0.0])
    e1 /= np.linalg.norm(e1)
    e2 = np.cross(b, e1)
    root = np.sqrt(gamma)

    def psi_and_scale(k: int) -> tuple[np.ndarray, np.ndarray]:
        u = _directions(scan.meas[k])
        R = scan.R[k]
        lam = 0.5 * (R[:, 0, 0] + R[:, 1, 1]) + np.sqrt(
            0.25 * (R[:, 0, 0] - R[:, 1, 1]) ** 2 + R[:, 0, 1] ** 2)
        cos_t = np.clip(u @ b, -1.0, 1.0)
        sin_t = np.sqrt(np.maximum(1.0 - cos_t * cos_t, 0.0))
        with np.errstate(divide="ignore"):
            a = np.sqrt(lam) * (1.0 + 1e-6) / sin_t
        a = np.where(root * a <= _LINEAR_MAX, a, np.inf)   # wide: paired with all
        return np.arctan2(u @ e2, u @ e1), a

    pa, aa = psi_and_scale(s)
    pb, ab = psi_and_scale(t)
    w = np.sqrt(2.0) * _ARCSIN_SLOPE * root
    i1, j1 = _window_pairs(pa, w * aa + _ANGLE_SLACK, pb)
    keep = ab[j1] <= aa[i1]
    j2, i2 = _window_pairs(pb, w * ab + _ANGLE_SLACK, pa)
    keep2 = aa[i2] < ab[j2]
    i = np.concatenate([i1[keep], i2[keep2]])
    j = np.concatenate([j1[keep], j2[keep2]])
    with np.errstate(invalid="ignore"):
        bound = _ARCSIN_SLOPE * root * np.hypot(aa[i], ab[j]) + _ANGLE_SLACK
    close = ~(np.abs(wrap_angle(pa[i] - pb[j])) > bound)
    return i[close], j[close]


def _ranges_along_sight(scan: Scan, g) -> np.ndarray:
    """Signed distance of each tuple's position along each real line of sight."""
    d = g.x[:, None, :] - scan.sensors[None]                # (K, N, dim)
    beta = g.meas[..., -1]
    if scan.sensors.shape[1] == 2:
        u = np.stack([np.cos(beta), np.sin(beta)], axis=-1)
    else:
        alpha = g.meas[..., 0]
        u = np.stack([np.cos(alpha) * np.cos(beta), np.cos(alpha) * np.sin(beta),
                      np.sin(alpha)], axis=-1)
    return np.where(g.mask, (d * u).sum(axis=-1), np.nan)


def build_gated_problem(scan: Scan, method: str = "pattipati", *,
                        probability: float = 0.99, max_range: float | None = None,
                        pair_localiser: str | None = None, localiser: str = "ls",
                        covariance: str = "residual", normalisation: str = "printed",
                        name: str = "scan") -> AssignmentProblem:
    """The S-D problem of ``scan`` over the pairwise-gated tuples only.

    The costs are those of :func:`assocopt.tracking.costs.sd_builder.build_problem` (the same
    ``method``, ``localiser``, ``covariance`` and ``normalisation``); only the set of
    candidates differs.  ``name`` names the problem.

    Examples
    --------
    >>> from assocopt import solve
    >>> from assocopt.tracking.scenarios.lu2013 import Lu2013
    >>> scan, truth = Lu2013(n_targets=4, d=2.0).simulate(np.random.default_rng(0))
    >>> p = build_gated_problem(scan, name="scan-0")
    >>> p.n_candidates < 4 ** 3, p.name
    (True, 'scan-0')
    """
    ok = bearing_pair_gate(scan, probability=probability, max_range=max_range,
                           localiser=pair_localiser)
    T = gated_tuples(scan.sizes, ok, scan.pd, scan.clutter_density)
    c = tuple_costs_in_chunks(scan, T, method, localiser=localiser, covariance=covariance,
                              normalisation=normalisation)
    keep = np.isfinite(c)
    return AssignmentProblem.sparse(scan.sizes, T[keep], c[keep], name=name)
