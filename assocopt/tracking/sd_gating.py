"""S-D candidate tuples gated pairwise across sensors, before any tuple cost is built.

With ``N`` sensors of ``n`` measurements each there are up to ``(n + 1)^N`` tuples
(28.6 million for 30 targets and 5 sensors), almost all of them impossible: two of
their measurements cannot come from one target.  This module first decides, for
every pair of sensors ``(s, t)``, which measurement pairs are *compatible*, then
enumerates only the tuples whose real measurements are pairwise compatible (the
cliques of the compatibility graph), sensor by sensor, keeping the partial tuples
in arrays.  The tuple costs (paper 002's Pattipati, KLD and SKLD costs) are then
computed for the survivors only.

* :func:`gated_tuples` -- the enumeration, for any pairwise compatibility;
* :func:`bearing_pair_gate` -- compatibility of two bearing measurements: the
  two-sensor position estimate lies in front of both sensors (and within
  ``max_range``), and, where a pair over-determines the position (azimuth and
  elevation: 4 angles, 3 coordinates), its angle residual passes a chi-square test
  with the redundant degrees of freedom;
* :func:`build_gated_problem` -- the gated S-D problem of a bearing scan.

The detection model of :func:`assocopt.tracking.costs.sd_builder.candidate_tuples` is kept:
a dummy in sensor ``s`` needs ``P_Ds < 1``, and a single-measurement tuple exists
when its measurement may be a false alarm or every other sensor may miss.
"""

from __future__ import annotations

from typing import Mapping, Sequence

import numpy as np
from numpy.typing import ArrayLike

from .costs.sd_builder import Scan, tuple_costs, tuple_geometry
from ..runtime.errors import InvalidProblemError
from ..problems.problem import AssignmentProblem

__all__ = ["gated_tuples", "bearing_pair_gate", "build_gated_problem"]

PairGate = Mapping[tuple[int, int], np.ndarray]


def gated_tuples(sizes: Sequence[int], compatible: PairGate, pd: ArrayLike,
                 clutter_density: ArrayLike | None = None) -> np.ndarray:
    """Candidate tuples (0 = dummy) whose real measurements are pairwise compatible.

    ``compatible[(s, t)]`` (``s < t``) is a boolean ``(n_s, n_t)`` matrix; a sensor
    pair that is absent is fully compatible.  Rows are sorted lexicographically.

    >>> ok = {(0, 1): np.array([[True, False], [False, True]])}
    >>> gated_tuples((2, 2), ok, [1.0, 1.0]).tolist()
    [[1, 1], [2, 2]]
    """
    sizes = tuple(int(n) for n in sizes)
    N = len(sizes)
    pd_a = np.broadcast_to(np.asarray(pd, float), (N,))
    cd = np.zeros(N) if clutter_density is None else \
        np.broadcast_to(np.asarray(clutter_density, float), (N,))
    pairs = _pairs(sizes, compatible)
    may_miss = pd_a < 1.0
    # multi-measurement tuples: a dummy only where the sensor may miss
    partial = np.arange(sizes[0] + 1, dtype=np.int64)[:, None]
    if not may_miss[0]:
        partial = partial[1:]
    for s in range(1, N):
        k, j = _extensions(partial, s, sizes[s], pairs)
        keep = np.ones(len(k), dtype=bool)
        for t in range(s):
            if pairs[(t, s)] is not None:      # a dummy in t is compatible with all
                i = partial[k, t]
                m = np.flatnonzero(i > 0)
                keep[m] &= pairs[(t, s)][0][i[m] - 1, j[m] - 1]
        k, j = k[keep], j[keep]
        if may_miss[s]:
            k = np.concatenate([np.arange(len(partial)), k])
            j = np.concatenate([np.zeros(len(partial), np.int64), j])
        partial = np.concatenate([partial[k], j[:, None]], axis=1)
    multi = partial[(partial > 0).sum(axis=1) >= 2]
    singles = _singletons(sizes, may_miss, cd)
    T = np.concatenate([multi, singles]).reshape(-1, N)
    return T[np.lexsort(T.T[::-1])]


def _extensions(partial: np.ndarray, s: int, n_s: int, pairs) -> tuple[np.ndarray, np.ndarray]:
    """Pairs ``(k, j)``: partial tuple k and a real measurement j of sensor ``s``
    compatible with k's first real measurement (every j for a partial tuple without
    one, or whose first sensor's pair with ``s`` is not gated); the caller checks the
    other members.  Only the gate's neighbours are listed (CSR lists of each
    measurement's compatible ones), never a (partial tuples x n_s) table."""
    real = partial > 0
    anchor = np.where(real.any(axis=1), np.argmax(real, axis=1), -1)
    ks, js = [], []
    every = anchor < 0
    for t in range(s):
        if pairs[(t, s)] is None:
            every |= anchor == t
    full = np.flatnonzero(every)
    ks.append(np.repeat(full, n_s))
    js.append(np.tile(np.arange(1, n_s + 1, dtype=np.int64), len(full)))
    for t in range(s):
        sel = np.flatnonzero(anchor == t)
        if pairs[(t, s)] is None or not len(sel):
            continue
        _, ptr, cols = pairs[(t, s)]
        r = partial[sel, t] - 1
        cnt = ptr[r + 1] - ptr[r]
        first = np.repeat(ptr[r] - (np.cumsum(cnt) - cnt), cnt)
        ks.append(np.repeat(sel, cnt))
        js.append(cols[first + np.arange(int(cnt.sum()))] + 1)
    return np.concatenate(ks).astype(np.int64), np.concatenate(js).astype(np.int64)


def _pairs(sizes, compatible) -> dict:
    """For every sensor pair ``(s, t)``: None (not gated: all compatible), or the
    boolean matrix with its CSR lists ``(M, ptr, cols)`` (0-based, real indices)."""
    N = len(sizes)
    for key in compatible:
        if not (isinstance(key, tuple) and len(key) == 2 and
                all(isinstance(v, (int, np.integer)) for v in key) and
                0 <= key[0] < key[1] < N):
            raise InvalidProblemError(f"compatibility key {key} must be a sensor pair "
                                      f"(s, t) with 0 <= s < t < {N}")
    out: dict = {}
    for s in range(N):
        for t in range(s + 1, N):
            if (s, t) not in compatible:
                out[(s, t)] = None
                continue
            M = np.ascontiguousarray(compatible[(s, t)], dtype=bool)
            if M.shape != (sizes[s], sizes[t]):
                raise InvalidProblemError(
                    f"compatibility of sensors ({s}, {t}) must have shape "
                    f"({sizes[s]}, {sizes[t]}), got {M.shape}")
            flat = np.flatnonzero(M)
            ptr = np.zeros(sizes[s] + 1, np.int64)
            np.cumsum(np.bincount(flat // max(sizes[t], 1), minlength=sizes[s]),
                      out=ptr[1:])
            out[(s, t)] = (M, ptr, flat % max(sizes[t], 1))
    return out


def _singletons(sizes, may_miss, cd) -> np.ndarray:
    N = len(sizes)
    rows = []
    for s, n in enumerate(sizes):
        others_miss = bool(np.delete(may_miss, s).all())
        if n and (cd[s] > 0 or others_miss):
            t = np.zeros((n, N), dtype=np.int64)
            t[:, s] = np.arange(1, n + 1)
            rows.append(t)
    return np.concatenate(rows) if rows else np.zeros((0, N), dtype=np.int64)


def _pair_tuples(sizes: tuple[int, ...]) -> tuple[np.ndarray, list]:
    """Every two-measurement tuple of every sensor pair, and where each pair's block is."""
    N = len(sizes)
    blocks, spans, start = [], [], 0
    for s in range(N):
        for t in range(s + 1, N):
            i, j = np.divmod(np.arange(sizes[s] * sizes[t], dtype=np.int64), sizes[t])
            T = np.zeros((len(i), N), dtype=np.int64)
            T[:, s], T[:, t] = i + 1, j + 1
            blocks.append(T)
            spans.append(((s, t), start, start + len(i)))
            start += len(i)
    return (np.concatenate(blocks) if blocks else np.zeros((0, N), np.int64)), spans


def bearing_pair_gate(scan: Scan, *, probability: float = 0.99,
                      max_range: float | None = None, localiser: str | None = None
                      ) -> dict[tuple[int, int], np.ndarray]:
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
    """
    from scipy.stats import chi2

    if not 0.0 < probability <= 1.0:
        raise InvalidProblemError(f"probability must lie in (0, 1], got {probability}")
    T, spans = _pair_tuples(scan.sizes)
    dim = scan.sensors.shape[1]
    loc = localiser or ("ils" if dim == 3 else "ls")
    g = tuple_geometry(scan, T, localiser=loc)
    ok = g.valid.copy()
    ranges = _ranges_along_sight(scan, g)                   # (K, N), nan at dummies
    with np.errstate(invalid="ignore"):
        ok &= np.where(g.mask, ranges > 0, True).all(axis=1)
        if max_range is not None:
            dist = np.linalg.norm(g.x[:, None, :] - scan.sensors[None], axis=2)
            ok &= np.where(g.mask, dist <= max_range, True).all(axis=1)
    dof = 2 * g.meas.shape[2] - dim                         # redundant equations of a pair
    if dof > 0 and probability < 1.0:
        stat = 2.0 * tuple_costs(scan, g, "pattipati", normalisation="none").data
        with np.errstate(invalid="ignore"):
            ok &= stat <= chi2.ppf(probability, dof)
    return {key: ok[a:b].reshape(scan.sizes[key[0]], scan.sizes[key[1]])
            for key, a, b in spans}


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
    g = tuple_geometry(scan, T, localiser=localiser, covariance=covariance)
    c = tuple_costs(scan, g, method, normalisation=normalisation)
    keep = np.isfinite(c.total)
    return AssignmentProblem.sparse(scan.sizes, T[keep], c.total[keep], name=name)
