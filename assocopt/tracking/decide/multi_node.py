"""Our extension of paper 001 to three nodes: one S-D (3-D) assignment on the pairwise
fused degrees, solved by :func:`assocopt.solve` (docs/papers/yan2010.md).

The paper takes M = 2 nodes.  With three, deciding node pairs separately can give
inconsistent answers (i~j, j~l, but not i~l).  The S-D model decides the three at once.
A candidate tuple ``(i, j, l)`` (1-based track numbers of nodes 1, 2, 3, 0 = the node
has no track of this emitter) costs::

    c(i, j, l) = - sum over the real pairs (a, b) of the tuple of ln(m_ab / eps)

where ``m_ab`` is the fused degree of the pair (any fusion reading; the pair frame is
symmetric, which suits a model with no reference node).  A pair is a candidate only
when ``m_ab > eps`` (so every pair term is negative, "beats the threshold", like the
2-D rule), and a triple only when all three of its pairs are candidates.  Every single
track ``(i, 0, 0)``, ``(0, j, 0)``, ``(0, 0, l)`` costs 0, so leaving a track alone is
always feasible.  For two nodes this is exactly the 2-D assignment rule with the
``-ln`` cost.
"""

from __future__ import annotations

import numpy as np

from ...solving.api import solve
from ...problems.problem import AssignmentProblem

__all__ = ["three_node_problem", "three_node_decision"]


def three_node_problem(m12: np.ndarray, m13: np.ndarray, m23: np.ndarray,
                       eps: float) -> AssignmentProblem:
    """The S-D model of the module docstring from the three ``(n_a, n_b)`` degree matrices."""
    m12, m13, m23 = (np.asarray(m, dtype=np.float64) for m in (m12, m13, m23))
    n1, n2 = m12.shape
    n3 = m13.shape[1]
    if m13.shape[0] != n1 or m23.shape != (n2, n3):
        raise ValueError(f"degree matrices must be (n1, n2), (n1, n3), (n2, n3); got "
                         f"{m12.shape}, {m13.shape}, {m23.shape}")
    if not 0 < eps < 1:
        raise ValueError(f"eps must be in (0, 1), got {eps!r}")

    def gain(m):
        with np.errstate(divide="ignore"):
            return np.where(m > eps, -np.log(np.where(m > eps, m, 1.0) / eps), np.inf)

    g12, g13, g23 = gain(m12), gain(m13), gain(m23)
    tup, cost = [], []
    for g, axes in ((g12, (0, 1)), (g13, (0, 2)), (g23, (1, 2))):
        a, b = np.nonzero(np.isfinite(g))
        t = np.zeros((len(a), 3), dtype=np.int64)
        t[:, axes[0]], t[:, axes[1]] = a + 1, b + 1
        tup.append(t)
        cost.append(g[a, b])
    i, j = np.nonzero(np.isfinite(g12))
    if len(i):
        tri = g12[i, j][:, None] + g13[i] + g23[j]                     # (pairs, n3)
        p, l = np.nonzero(np.isfinite(tri))
        tup.append(np.stack([i[p] + 1, j[p] + 1, l + 1], axis=1))
        cost.append(tri[p, l])
    for ax, n in enumerate((n1, n2, n3)):
        t = np.zeros((n, 3), dtype=np.int64)
        t[:, ax] = np.arange(1, n + 1)
        tup.append(t)
        cost.append(np.zeros(n))
    return AssignmentProblem.sparse((n1, n2, n3), np.concatenate(tup), np.concatenate(cost))


def three_node_decision(m12: np.ndarray, m13: np.ndarray, m23: np.ndarray, eps: float,
                        solver: str = "auto") -> np.ndarray:
    """Chosen tuples ``(n1, 3)``, one per node-1 track: 0-based partners, ``-1`` = none.

    >>> import numpy as np
    >>> m = np.array([[0.9, 0.1], [0.1, 0.9]])
    >>> three_node_decision(m, m, m, 0.5).tolist()
    [[0, 0, 0], [1, 1, 1]]
    """
    prob = three_node_problem(m12, m13, m23, eps)
    sol = solve(prob, solver=solver)
    if sol.tuples is None:
        raise RuntimeError(f"S-D assignment failed: status {sol.status}")
    n1 = np.shape(m12)[0]
    out = np.full((n1, 3), -1)
    T = np.asarray(sol.tuples)
    T = T[T[:, 0] > 0]
    out[T[:, 0] - 1] = T - 1
    return out
