"""Kinematic GNN costs of gated track-measurement pairs, as a sparse 2-D problem.

Two standard costs, computed in bulk from a :class:`~assocopt.tracking.gating.Gate`:

``"mahalanobis"``
    :math:`c_{ij} = d^2_{ij}`, the squared Mahalanobis distance; a track left
    unassigned costs ``miss_cost`` (by default the gate threshold :math:`\\gamma`, so
    a pair is preferred to a miss exactly when it lies inside the gate).

``"nllr"``
    The negative log-likelihood ratio of "measurement j comes from track i" against
    "measurement j is clutter", with detection probability :math:`P_D`, clutter
    density :math:`\\lambda_j` (false alarms per unit measurement volume) and gate
    probability :math:`P_G`:

    .. math::

        c_{ij} = -\\ln \\frac{P_D\\,\\mathcal N(z_j;\\hat z_i, S_{ij})}{\\lambda_j}
               = \\tfrac12 d^2_{ij} + \\tfrac12 \\ln\\det(2\\pi S_{ij})
                 - \\ln P_D + \\ln \\lambda_j .

    In words: half the squared distance, plus half the log-determinant of
    :math:`2\\pi S`, minus the log detection probability, plus the log clutter density.
    The miss cost that follows from the same likelihood is the cost of a track that
    is not detected inside its gate, :math:`c_{i0} = -\\ln(1 - P_D P_G)`, and a
    measurement left unassigned (declared clutter) costs :math:`c_{0j} = 0` (its
    clutter likelihood is the reference of the ratio).  The optimum of the problem
    is then the most likely joint association (the likelihood of a pair inside the
    gate is the truncated Gaussian :math:`\\mathcal N / P_G`, detected with
    probability :math:`P_D P_G`; the two :math:`P_G` cancel).

The problem: rows are tracks, columns measurements; candidate ``(i, j)`` for every
gated pair, ``(i, 0)`` for a track miss (dropped when its cost is ``inf``, e.g.
:math:`P_D = P_G = 1`), ``(0, j)`` at cost 0 for every measurement.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

from ...runtime.errors import InvalidProblemError
from ...problems.problem import AssignmentProblem
from ..gating.chi2 import Gate, gate as make_gate

__all__ = ["COSTS", "mahalanobis_costs", "nllr_costs", "nllr_miss_cost", "gated_problem",
           "build_problem"]

#: Cost names accepted by :func:`build_problem`.
COSTS = ("nllr", "mahalanobis")


def mahalanobis_costs(g: Gate) -> np.ndarray:
    """:math:`d^2_{ij}` of every gated pair."""
    return g.d2.copy()


def nllr_costs(g: Gate, pd: ArrayLike, clutter_density: ArrayLike) -> np.ndarray:
    """Negative log-likelihood ratio of every gated pair (module docstring).

    ``pd`` is a scalar or one value per track, in (0, 1]; ``clutter_density`` a
    scalar or one value per measurement, > 0.

    >>> from assocopt.tracking.gating import gate
    >>> g = gate([[0.0]], [[1.0]], [[0.0]])
    >>> c = nllr_costs(g, 1.0, 1.0)                 # 1/2 ln(2 pi)
    >>> round(float(c[0]), 6)
    0.918939
    """
    pd_t = _per(pd, g.n_tracks, "pd", "track")
    if not ((pd_t > 0) & (pd_t <= 1)).all():
        raise InvalidProblemError(f"pd must lie in (0, 1], got {np.unique(pd_t).tolist()}")
    lam = _per(clutter_density, g.n_meas, "clutter_density", "measurement")
    if not (lam > 0).all():
        raise InvalidProblemError("clutter_density must be > 0 for the log-likelihood "
                                  "ratio (use the Mahalanobis cost without clutter)")
    return (0.5 * g.d2 + 0.5 * (g.logdet + g.dim * np.log(2.0 * np.pi))
            - np.log(pd_t[g.rows]) + np.log(lam[g.cols]))


def nllr_miss_cost(pd: ArrayLike, gate_probability: float = 1.0) -> np.ndarray:
    """Cost of a track with no measurement: :math:`-\\ln(1 - P_D P_G)` (``inf`` at 1).

    >>> round(float(nllr_miss_cost(0.9, 0.99)), 6)
    2.216407
    """
    pd_a = np.asarray(pd, dtype=np.float64)
    with np.errstate(divide="ignore"):
        return -np.log1p(-pd_a * float(gate_probability))


def gated_problem(g: Gate, costs: ArrayLike, row_miss: ArrayLike,
                  col_miss: ArrayLike = 0.0, *, name: str | None = None
                  ) -> AssignmentProblem:
    """Sparse 2-D problem of the gated pairs with per-track and per-measurement misses.

    ``costs`` has one entry per gated pair; ``row_miss`` (scalar or per track) and
    ``col_miss`` (scalar or per measurement) are the non-assignment costs, ``inf``
    forbidding the miss.
    """
    c = np.asarray(costs, dtype=np.float64)
    if c.shape != (g.n_pairs,):
        raise InvalidProblemError(f"costs must have shape ({g.n_pairs},), one per gated "
                                  f"pair, got {c.shape}")
    rm = _per(row_miss, g.n_tracks, "row_miss", "track", allow_inf=True)
    cm = _per(col_miss, g.n_meas, "col_miss", "measurement", allow_inf=True)
    r_idx = np.arange(1, g.n_tracks + 1, dtype=np.int64)
    c_idx = np.arange(1, g.n_meas + 1, dtype=np.int64)
    tuples = np.concatenate([
        np.stack([g.rows + 1, g.cols + 1], axis=1),
        np.stack([r_idx, np.zeros_like(r_idx)], axis=1),
        np.stack([np.zeros_like(c_idx), c_idx], axis=1)]).reshape(-1, 2)
    return AssignmentProblem.sparse((g.n_tracks, g.n_meas), tuples,
                                    np.concatenate([c, rm, cm]), name=name)


def build_problem(z_pred: ArrayLike, S: ArrayLike, z: ArrayLike, *, cost: str = "nllr",
                  R: ArrayLike | None = None, probability: float = 0.99,
                  threshold: float | None = None, pd: ArrayLike = 0.9,
                  clutter_density: ArrayLike = 1.0, miss_cost: ArrayLike | None = None,
                  name: str | None = None) -> AssignmentProblem:
    """Gate, cost and assemble one scan's 2-D problem (tracks x measurements).

    ``cost="nllr"`` uses ``pd``, ``clutter_density`` and the gate probability;
    ``cost="mahalanobis"`` uses ``miss_cost`` (default: the gate threshold).  See
    :func:`assocopt.tracking.gating.gate` for ``z_pred``, ``S``, ``R``, ``probability``
    and ``threshold``.

    Examples
    --------
    >>> from assocopt import solve
    >>> p = build_problem([[0.0, 0.0], [5.0, 5.0]], np.eye(2) * 0.5,
    ...                   [[5.1, 4.9], [0.2, -0.1], [40.0, 40.0]],
    ...                   pd=0.9, clutter_density=1e-3, name="scan-0")
    >>> solve(p).tuples.tolist()                    # track 1 <- z2, track 2 <- z1
    [[1, 2], [2, 1], [0, 3]]
    """
    if cost not in COSTS:
        raise InvalidProblemError(f"unknown cost {cost!r}; valid: {', '.join(COSTS)}")
    g = make_gate(z_pred, S, z, R=R, probability=probability, threshold=threshold)
    if cost == "nllr":
        c = nllr_costs(g, pd, clutter_density)
        rm = nllr_miss_cost(pd, g.probability) if miss_cost is None else miss_cost
    else:
        c = mahalanobis_costs(g)
        rm = g.threshold if miss_cost is None else miss_cost
    return gated_problem(g, c, rm, 0.0, name=name or f"gated-{cost}")


def _per(value: ArrayLike, n: int, what: str, item: str, *,
         allow_inf: bool = False) -> np.ndarray:
    arr = np.asarray(value, dtype=np.float64)
    if arr.ndim == 0:
        arr = np.full(n, float(arr))
    if arr.shape != (n,):
        raise InvalidProblemError(f"{what} must be a scalar or one value per {item} "
                                  f"(shape ({n},)), got shape {arr.shape}")
    bad = np.isnan(arr) | (np.isinf(arr) if not allow_inf else np.isneginf(arr))
    if bad.any():
        raise InvalidProblemError(f"{what} of {item} {int(np.argmax(bad))} is "
                                  f"{arr[np.argmax(bad)]}")
    return arr
