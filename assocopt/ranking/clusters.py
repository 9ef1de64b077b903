"""Independent clusters of an assignment problem.

Two real indices (of any axes) are linked when some candidate tuple covers both; the
connected components of that graph are the problem's *clusters*.  A joint hypothesis
is a choice per cluster, independently, so its weight is the product of the clusters'
weights: marginals are computed cluster by cluster and the log-partition is the sum
of the clusters' log-partitions.  Found in bulk (one sparse graph, scipy's
``connected_components``), for 2-D and S-D problems alike.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from ..problems.problem import AssignmentProblem

__all__ = ["Cluster", "clusters"]


class Cluster(NamedTuple):
    """One independent component: ``rows``, its constraint rows (real indices in the
    numbering of :meth:`AssignmentProblem.coverage_matrix`, sorted) and
    ``candidates``, the positions of the candidates covering them (sorted)."""

    rows: np.ndarray
    candidates: np.ndarray

    def sizes(self, problem: AssignmentProblem) -> tuple[int, ...]:
        """How many real indices of each axis the cluster holds."""
        edges = np.concatenate([problem.row_offsets, [problem.n_rows]])
        return tuple(int(n) for n in np.histogram(self.rows, bins=edges)[0])


def clusters(problem: AssignmentProblem) -> list[Cluster]:
    """The independent clusters of ``problem`` (see the module docstring), ordered by
    their smallest constraint row; every real index lies in exactly one and every
    candidate in the cluster of the indices it covers."""
    import scipy.sparse as sp
    from scipy.sparse.csgraph import connected_components

    R = problem.entry_rows
    n = problem.n_rows
    if n == 0:
        return []
    real = R >= 0
    # one real row of each candidate (every candidate covers at least one)
    first = np.max(np.where(real, R, -1), axis=1)
    src = np.broadcast_to(first[:, None], R.shape)[real]
    dst = R[real]
    g = sp.csr_matrix((np.ones(len(src), np.int8), (src, dst)), shape=(n, n))
    _, label = connected_components(g, directed=False)
    # renumber components by their smallest row, so the order is fixed by the problem
    order = np.full(label.max() + 1 if n else 0, n, np.int64)
    np.minimum.at(order, label, np.arange(n))
    rank = np.empty_like(order)
    rank[np.argsort(order, kind="stable")] = np.arange(len(order))
    label = rank[label]
    cand_label = label[first] if len(first) else np.zeros(0, np.int64)
    rows_by = _group(label, len(order))
    cands_by = _group(cand_label, len(order))
    return [Cluster(r, c) for r, c in zip(rows_by, cands_by)]


def _group(label: np.ndarray, n: int) -> list[np.ndarray]:
    """Positions with each label ``0..n-1``, sorted, in bulk (one stable sort)."""
    order = np.argsort(label, kind="stable")
    cuts = np.searchsorted(label[order], np.arange(1, n))
    return [a.astype(np.int64) for a in np.split(order, cuts)]
