"""Costs of S-D tuples of position-like reports, in bulk, and their gated problem.

A tuple assigns to one target at most one report of each sensor (index 0: the
sensor missed it).  Its cost is the negative log generalised likelihood ratio of
"these reports come from one target, the other sensors missed it" against "every
one of them is a false alarm" (Deb et al. 1997), the target's position at its
maximum-likelihood estimate (the information-weighted mean of the reports):

.. math::

    c = \\sum_{i \\in \\text{real}} \\Big[ \\tfrac12 (z_i - \\hat x)^\\top R_i^{-1}
        (z_i - \\hat x) + \\tfrac12 \\ln\\det(2\\pi R_i) - \\ln P_{D,s_i}
        + \\ln \\lambda_{s_i} \\Big] - \\sum_{s \\in \\text{missed}} \\ln(1 - P_{D,s}),
    \\qquad \\hat x = \\Big(\\sum_i R_i^{-1}\\Big)^{-1} \\sum_i R_i^{-1} z_i,

:math:`\\lambda_s` the false alarms per unit volume of sensor ``s``.  A
single-report tuple is the reference (a false alarm, or a target seen once) and
costs 0.  Everything is computed over all tuples at once, in chunks (no loop per
tuple): :func:`position_tuple_costs`; :func:`build_position_problem` chains
:func:`assocopt.tracking.gating.position_pair_gate`,
:func:`assocopt.tracking.gating.gated_tuples` and these costs into a sparse
:class:`~assocopt.problems.problem.AssignmentProblem`.
"""

from __future__ import annotations

import math
from typing import Sequence

import numpy as np
from numpy.typing import ArrayLike

from ...problems.problem import AssignmentProblem
from ...runtime.errors import InvalidProblemError

__all__ = ["position_tuple_costs", "build_position_problem"]


def _detection(pd: ArrayLike, clutter_density: ArrayLike, N: int
               ) -> tuple[np.ndarray, np.ndarray]:
    pd_a = np.broadcast_to(np.asarray(pd, dtype=np.float64), (N,)).copy()
    if not ((pd_a > 0) & (pd_a <= 1)).all():
        raise InvalidProblemError(f"pd must lie in (0, 1], got {pd_a.tolist()}")
    cd = np.broadcast_to(np.asarray(clutter_density, dtype=np.float64), (N,)).copy()
    if not (np.isfinite(cd).all() and (cd > 0).all()):
        raise InvalidProblemError("clutter_density must be > 0 and finite (the reference "
                                  f"of the likelihood ratio), got {cd.tolist()}")
    return pd_a, cd


def position_tuple_costs(reports: Sequence[ArrayLike], R: Sequence[ArrayLike] | ArrayLike,
                         tuples: ArrayLike, pd: ArrayLike, clutter_density: ArrayLike, *,
                         chunk: int = 1 << 18) -> np.ndarray:
    """Negative log-likelihood ratio of every tuple (module docstring), ``(K,)``.

    ``reports`` and ``R`` as :func:`assocopt.tracking.gating.position_pair_gate`
    takes them; ``tuples`` ``(K, N)``, 1-based report indices, 0 = missed; ``pd``
    and ``clutter_density`` one value or one per sensor.  A tuple with a miss at a
    sensor with ``P_D = 1`` costs ``inf`` (impossible).

    >>> c = position_tuple_costs([[[0.0, 0.0]], [[1.0, 0.0]]], np.eye(2), [[1, 1], [1, 0]],
    ...                          0.9, 1e-3)
    >>> round(float(c[0]), 4), float(c[1])
    (-9.679, 0.0)
    """
    from ..gating.position import check_reports

    Z, Rs = check_reports(reports, R)
    N, d = len(Z), Z[0].shape[1]
    T = np.asarray(tuples, dtype=np.int64)
    if T.ndim != 2 or T.shape[1] != N:
        raise InvalidProblemError(f"tuples must have shape (K, {N}), got {T.shape}")
    sizes = np.array([len(z) for z in Z])
    if len(T) and ((T < 0).any() or (T > sizes).any()):
        raise InvalidProblemError("tuples refer to a report that does not exist "
                                  f"(sizes {sizes.tolist()}, 1-based, 0 = missed)")
    pd_a, cd = _detection(pd, clutter_density, N)
    # per report: information matrix, information-weighted report, constant term
    info, wz, const = [], [], []
    for z, r, p, lam in zip(Z, Rs, pd_a, cd):
        shared = len(r) > 0 and r.strides[0] == 0
        base = r[:1] if shared else r
        Ri = np.linalg.inv(base) if len(base) else np.zeros((0, d, d))
        ld = np.linalg.slogdet(2 * np.pi * base)[1] if len(base) else np.zeros(0)
        if shared:
            Ri = np.broadcast_to(Ri, (len(z), d, d))
            ld = np.broadcast_to(ld, (len(z),))
        pad = np.zeros((1, d, d))
        info.append(np.concatenate([pad, Ri]))
        wz.append(np.concatenate([np.zeros((1, d)), np.einsum("nij,nj->ni", Ri, z)]))
        const.append(np.concatenate([[0.0], 0.5 * ld - math.log(p) + math.log(lam)]))
    with np.errstate(divide="ignore"):
        miss = -np.log1p(-pd_a)                    # inf where P_D = 1
    out = np.empty(len(T))
    for a in range(0, len(T), chunk):
        Tc = T[a:a + chunk]
        real = Tc > 0
        I = sum(info[s][Tc[:, s]] for s in range(N))
        y = sum(wz[s][Tc[:, s]] for s in range(N))
        n_real = real.sum(axis=1)
        multi = n_real >= 2
        x = np.zeros((len(Tc), d))
        if multi.any():
            x[multi] = np.linalg.solve(I[multi], y[multi][..., None])[..., 0]
        c = np.zeros(len(Tc))
        for s in range(N):
            k = np.flatnonzero(real[:, s] & multi)
            v = Z[s][Tc[k, s] - 1] - x[k]
            c[k] += 0.5 * np.einsum("ki,kij,kj->k", v, info[s][Tc[k, s]], v) + \
                const[s][Tc[k, s]]
            if np.isfinite(miss[s]):
                c += np.where(~real[:, s] & multi, miss[s], 0.0)
            else:
                c[~real[:, s] & multi] = np.inf
        c[~multi] = 0.0
        out[a:a + chunk] = c
    return out


def build_position_problem(reports: Sequence[ArrayLike], R: Sequence[ArrayLike] | ArrayLike,
                           *, pd: ArrayLike = 0.9, clutter_density: ArrayLike = 1e-3,
                           probability: float = 0.999, name: str = "position-reports"
                           ) -> AssignmentProblem:
    """The gated S-D problem of one scan of position-like reports.

    Report pairs are gated by :func:`assocopt.tracking.gating.position_pair_gate`
    (``probability``), the tuples are the cliques of
    :func:`assocopt.tracking.gating.gated_tuples` under the detection model (a miss
    at sensor ``s`` needs ``P_D < 1``; every single report is a candidate, since a
    report may be a false alarm), priced by :func:`position_tuple_costs`.  Nothing
    of size ``n_s x n_t`` is allocated on the way.

    >>> from assocopt import solve
    >>> z = [np.array([[0.0, 0.0], [9.0, 9.0]]), np.array([[9.1, 9.0], [0.1, 0.0]])]
    >>> p = build_position_problem(z, np.eye(2) * 0.01)
    >>> sorted(solve(p).tuples.tolist())
    [[1, 2], [2, 1]]
    """
    from ..gating.position import check_reports
    from ..gating.position import position_pair_gate
    from ..gating.tuples import gated_tuples

    Z, Rs = check_reports(reports, R)
    N = len(Z)
    pd_a, cd = _detection(pd, clutter_density, N)
    ok = position_pair_gate(Z, Rs, probability=probability)
    sizes = [len(z) for z in Z]
    T = gated_tuples(sizes, ok, pd_a, cd)
    c = position_tuple_costs(Z, Rs, T, pd_a, cd)
    keep = np.isfinite(c)
    return AssignmentProblem.sparse(sizes, T[keep], c[keep], name=name)
