"""Pairwise gates of bearing measurements, and the gated S-D problem of a bearing scan.

* :func:`bearing_pair_gate` -- compatibility of two bearing measurements: the
  two-sensor position estimate lies in front of both sensors (and within
  ``max_range``), and, where a pair over-determines the position (azimuth and
  elevation: 4 angles, 3 coordinates), its angle residual passes a chi-square test
  with the redundant degrees of freedom;
* :func:`build_gated_problem` -- the gated S-D problem of a bearing scan: the tuples
  of :func:`assocopt.tracking.gating.tuples.gated_tuples` over those pairs, with the
  costs of :mod:`assocopt.tracking.costs.sd_builder`.
"""

from __future__ import annotations

import numpy as np

from ..costs.sd_builder import Scan, tuple_costs, tuple_geometry
from ...runtime.errors import InvalidProblemError
from ...problems.problem import AssignmentProblem
from .chi2 import chi2_threshold
from .tuples import gated_tuples

__all__ = ["bearing_pair_gate", "build_gated_problem"]


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
            ok &= stat <= chi2_threshold(probability, dof)
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
