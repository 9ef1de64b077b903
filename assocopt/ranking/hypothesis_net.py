"""Exact marginals by a hypothesis net per cluster (the EHM / EHM2 class), any N.

A joint hypothesis is an exact cover of a cluster's real indices (tracks,
measurements, or the measurements of S sensors) by disjoint candidate tuples.  The
indices are put in an order; at its turn an index is either already covered (by a
candidate taken at an earlier index) or takes a candidate whose other indices all
come later and are still free.  The state between two turns is the set of *later*
indices already covered, and only indices that some earlier-taken candidate can reach
need a bit: the net's nodes are (turn, state), merged when equal, so the net grows
with the *frontier* of the order, not with the number of joint events.  For a 2-D
problem with tracks first this is EHM2: a node per (track, set of measurements used
so far that later tracks may still want); a measurement takes its turn once the
tracks that gate it are done, as "used, or clutter".  The order is greedy: next the
frontier index that adds the fewest new indices to the frontier.

All of it (clusters, orders, bits, nets) is one compiled call
(:mod:`assocopt.solvers.kernels.ehm_exact`).  A cluster whose frontier needs more than
64 bits, or whose net has more than ``max_nodes`` nodes (``8 * max_nodes`` edges), is
reported, never approximated: :func:`too_large` words the error.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from ..problems.problem import AssignmentProblem
from .clusters import Cluster

__all__ = ["exact_marginals", "ExactResult", "MAX_NODES", "describe", "too_large"]

#: Default memory budget of one cluster's net: nodes (8 bytes each for each sum) and up
#: to eight times as many edges (12 bytes each): about 250 MB at most.
MAX_NODES = 2_000_000


class ExactResult(NamedTuple):
    """What :func:`exact_marginals` found: ``P`` (every candidate; 0 in failed
    clusters), per cluster ``log_z``, ``status`` (0 ok, 1 over the node budget, 2 no
    hypothesis, 3 frontier over 64 bits), ``nodes`` and ``width`` (frontier bits);
    ``label`` / ``cand_label``: the cluster of each row / candidate (:meth:`cluster`)."""

    P: np.ndarray
    log_z: np.ndarray
    status: np.ndarray
    nodes: np.ndarray
    width: np.ndarray
    label: np.ndarray
    cand_label: np.ndarray

    def cluster(self, c: int) -> Cluster:
        """Cluster ``c`` as a :class:`~assocopt.ranking.clusters.Cluster`."""
        return Cluster(np.flatnonzero(self.label == c), np.flatnonzero(self.cand_label == c))


def exact_marginals(problem: AssignmentProblem, logw: np.ndarray,
                    max_nodes: int = MAX_NODES) -> ExactResult:
    """Exact marginals of every cluster of ``problem`` whose net fits (log weights
    ``logw`` of the candidates); see the module docstring."""
    from ..solvers.kernels import pick

    E = np.ascontiguousarray(problem.entry_rows, np.int64)
    args = (E, np.ascontiguousarray(logw, np.float64), int(problem.n_rows), int(max_nodes))
    kernel = pick("ehm_exact.exact_marginals", *args, work=len(E))
    label, cand_label, P, log_z, status, nodes, width = kernel(*args)
    return ExactResult(P, log_z, status, nodes, width, label, cand_label)


def describe(problem: AssignmentProblem, cluster: Cluster) -> str:
    """``"a cluster of 12 x 15 indices (90 candidates)"``: a cluster's size."""
    sizes = " x ".join(map(str, cluster.sizes(problem)))
    return f"a cluster of {sizes} indices ({len(cluster.candidates)} candidates)"


def too_large(problem: AssignmentProblem, cluster: Cluster, status: int, width: int,
              max_nodes: int) -> str:
    """The message of a cluster the exact net cannot hold (status 1 or 3)."""
    if status == 3:
        why = "has a frontier of more than 64 indices (the net's key)"
    else:
        why = (f"needs a hypothesis net of more than max_nodes={max_nodes} nodes (or "
               f"{8 * max_nodes} edges; frontier {width} indices)")
    return (f"method='exact': {describe(problem, cluster)} {why}; raise max_nodes, or "
            "use method='auto' (k-best sums with an error bound where exact does not "
            "fit), 'kbest' or 'lbp'")
