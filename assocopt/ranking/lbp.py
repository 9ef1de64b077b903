"""Loopy belief propagation for 2-D association marginals (Williams and Lau,
"Approximate evaluation of marginal association probabilities with belief
propagation", IEEE TAES 2014).

With the weights of each pair taken relative to its column's miss,
``w_ij = exp(-(c_ij - cm_j) / T)``, and the row's miss ``w_i0 = exp(-rm_i / T)``, the
messages are

    mu_ij = w_ij / (w_i0 + sum_{j' != j} w_ij' nu_j'i),
    nu_ji = 1 / (1 + sum_{i' != i} mu_i'j),

iterated from ``nu = 1`` until the largest change of ``nu`` is below the tolerance; then
``P(i, j) = w_ij nu_ji / (w_i0 + sum_j' w_ij' nu_j'i)``.  ``mu`` is unchanged by scaling
a row's weights, so each row is scaled to its largest (no overflow).  In bulk over
the pair list (numpy ``bincount``), all clusters at once.  Every column must be
allowed to stay unassigned (its miss finite); rows may have to be assigned.
"""

from __future__ import annotations

import numpy as np

from ..runtime.errors import InvalidProblemError
from ..problems.problem import AssignmentProblem

__all__ = ["lbp_marginals"]


def lbp_marginals(problem: AssignmentProblem, logw: np.ndarray, tolerance: float,
                  max_iterations: int) -> tuple[np.ndarray, int, float]:
    """``(P, iterations, residual)``: candidate marginals of the 2-D ``problem`` (log
    weights ``logw``) by loopy belief propagation (see the module docstring)."""
    if problem.ndim != 2:
        raise InvalidProblemError("method='lbp' is for 2-D problems; use method='exact' "
                                  "or 'kbest' for S-D ones")
    if not (tolerance > 0) or int(max_iterations) < 1:
        raise InvalidProblemError(f"lbp needs tolerance > 0 and max_iterations >= 1, got "
                                  f"{tolerance!r}, {max_iterations!r}")
    n1, n2 = problem.sizes
    tup = problem.tuples
    pair = (tup[:, 0] > 0) & (tup[:, 1] > 0)
    rmiss = (tup[:, 0] > 0) & (tup[:, 1] == 0)
    cmiss = (tup[:, 0] == 0) & (tup[:, 1] > 0)
    lcm = np.full(n2, -np.inf)
    lcm[tup[cmiss, 1] - 1] = logw[cmiss]
    if not np.isfinite(lcm).all():
        j = int(np.flatnonzero(~np.isfinite(lcm))[0]) + 1
        raise InvalidProblemError(f"method='lbp' needs every column allowed to stay "
                                  f"unassigned; column {j} is not: use method='exact'")
    r = tup[pair, 0] - 1
    c = tup[pair, 1] - 1
    lw = logw[pair] - lcm[c]
    lr = np.full(n1, -np.inf)
    lr[tup[rmiss, 0] - 1] = logw[rmiss]
    top = lr.copy()
    np.maximum.at(top, r, lw)
    w = np.exp(lw - top[r])
    w0 = np.exp(lr - top)
    nu = np.ones(len(r))
    residual = np.inf
    it = 0
    with np.errstate(divide="ignore", invalid="ignore"):
        while it < max_iterations and residual > tolerance:
            it += 1
            wn = w * nu
            S = w0 + np.bincount(r, wn, minlength=n1)
            mu = w / np.maximum(S[r] - wn, 0.0)
            fin = np.isfinite(mu)
            Tc = np.bincount(c, np.where(fin, mu, 0.0), minlength=n2)
            ninf = np.bincount(c, ~fin, minlength=n2)
            others = Tc[c] - np.where(fin, mu, 0.0)
            new = np.where(ninf[c] - ~fin > 0, 0.0, 1.0 / (1.0 + others))
            residual = float(np.abs(new - nu).max(initial=0.0))
            nu = new
    wn = w * nu
    S = w0 + np.bincount(r, wn, minlength=n1)
    P = np.zeros(problem.n_candidates)
    P[pair] = wn / S[r]
    P[rmiss] = (w0 / S)[tup[rmiss, 0] - 1]
    taken = np.bincount(c, P[pair], minlength=n2)
    P[cmiss] = np.clip(1.0 - taken[tup[cmiss, 1] - 1], 0.0, 1.0)
    return P, it, residual
