"""Joint probabilistic data association (JPDA) in Stone Soup, exact, by assocopt.

:class:`AssocoptJPDA` is a drop-in replacement for Stone Soup's
:class:`~stonesoup.dataassociator.probability.JPDAwithEHM2` (and ``JPDA``,
``JPDAwithEHM``): the same hypothesiser, the same answer (per track a normalised
:class:`~stonesoup.types.multihypothesis.MultipleHypothesis` of
:class:`~stonesoup.types.hypothesis.SingleProbabilityHypothesis`, the missed detection
included, in the hypothesiser's order), the same probabilities: the exact marginal
association probabilities of the scan, computed by :func:`assocopt.marginals` on the
problem of :func:`~.problems.probability_problem`.

Which engine: when the installed :func:`assocopt.marginals` offers ``method="exact"``
(checked once, at import) the whole scan is one call to it.  Otherwise the scan is split
here into its independent clusters (tracks linked by shared detections): a track that
shares no detection gets its own normalised probabilities (in bulk), and each larger
cluster sums every one of its joint associations (Murty's ranking until it is
exhausted, so the result is exact; a cluster with more than
:data:`MAX_JOINT` of them is an error naming its size rather than an approximation).
"""

from __future__ import annotations

import inspect
import sys

import numpy as np

try:
    from stonesoup.base import Property
    from stonesoup.dataassociator.base import DataAssociator
    from stonesoup.hypothesiser import Hypothesiser
except ImportError as exc:  # pragma: no cover - exercised in a subprocess-free test
    raise ImportError("assocopt.tracking.stonesoup.jpda needs Stone Soup: "
                      "pip install assocopt[stonesoup]") from exc

from ...problems.problem import AssignmentProblem
from ...ranking.marginals import marginals
from ...runtime.errors import ProblemTooLargeError
from .problems import ProbabilityProblem, probability_problem

__all__ = ["AssocoptJPDA", "association_probabilities", "EXACT_METHOD", "MAX_JOINT"]

#: Most joint associations one cluster may have where no exact engine is installed.
MAX_JOINT = 1 << 20


def _exact_method() -> str | None:
    """``"exact"`` if the installed :func:`assocopt.marginals` accepts
    ``method="exact"``, else None (read from its signature and its ``METHODS``)."""
    if "method" not in inspect.signature(marginals).parameters:
        return None
    methods = getattr(sys.modules.get(marginals.__module__), "METHODS", ())
    return "exact" if "exact" in methods else None


#: ``"exact"`` when :func:`assocopt.marginals` has its exact engine (then used for the
#: whole scan), None when :class:`AssocoptJPDA` sums each cluster's joint associations.
EXACT_METHOD = _exact_method()


def association_probabilities(pp: ProbabilityProblem, method: str | None = EXACT_METHOD
                              ) -> np.ndarray:
    """The exact marginal probability of each hypothesis of ``pp.table.hypotheses``.

    ``method``: the :func:`assocopt.marginals` method run on the whole problem
    (default: :data:`EXACT_METHOD`); None: clusters summed here (module docstring).

    Raises
    ------
    assocopt.ProblemTooLargeError
        Without an exact engine, a cluster with more than :data:`MAX_JOINT` joint
        associations.
    """
    n, m = pp.table.shape
    if n == 0:
        return np.zeros(0)
    if m == 0:                                      # every track missed
        return np.ones(len(pp.score))
    if method is not None:
        mg = marginals(pp.problem, method=method)
        return pp.hypothesis_probabilities(mg.pairs, mg.row_miss)
    return _by_cluster(pp)


def _by_cluster(pp: ProbabilityProblem) -> np.ndarray:
    """Exact probabilities without an exact engine: singletons in bulk, each larger
    cluster by exhaustive ranking."""
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components

    t = pp.table
    n, m = t.shape
    pair = (t.col >= 0) & np.isfinite(pp.score)
    r, c = t.row[pair], t.col[pair] + n
    graph = coo_matrix((np.ones(len(r)), (r, c)), shape=(n + m, n + m))
    _, label = connected_components(graph, directed=False)
    rows_in = np.bincount(label[:n], minlength=n + m)
    alone = rows_in[label[t.row]] == 1                # the hypothesis's track is alone
    P = np.zeros(len(pp.score))
    # a lone track: its own probabilities normalised (a detection it leaves is clutter)
    s = np.where(alone, pp.score, -np.inf)
    top = np.full(n, -np.inf)
    np.maximum.at(top, t.row, s)
    top = np.where(np.isfinite(top), top, 0.0)
    w = np.exp(s - top[t.row])
    z = np.bincount(t.row, weights=w, minlength=n)
    P[alone] = w[alone] / z[t.row[alone]]
    for comp in np.unique(label[t.row[~alone]]).tolist():
        rows = np.flatnonzero(label[:n] == comp)
        cols = np.flatnonzero(label[n:] == comp)
        h = np.flatnonzero(label[t.row] == comp)
        ri = np.searchsorted(rows, t.row[h])
        S = np.full((len(rows), len(cols)), -np.inf)
        rm = np.full(len(rows), -np.inf)
        miss = t.col[h] < 0
        keep = ~miss & np.isfinite(pp.score[h])
        S[ri[keep], np.searchsorted(cols, t.col[h][keep])] = pp.score[h][keep]
        rm[ri[miss]] = pp.score[h][miss]
        sub = AssignmentProblem.two_d(S, rm, 0.0, maximize=True)
        bound = float(np.prod(np.isfinite(S).sum(axis=1) + 1.0))
        mg = _exhaustive(sub, len(rows), bound)
        ci = np.searchsorted(cols, np.where(keep, t.col[h], cols[0]))
        P[h] = np.where(miss, mg.row_miss[ri], np.where(keep, mg.pairs[ri, ci], 0.0))
    return P


def _exhaustive(problem: AssignmentProblem, n_tracks: int, bound: float):
    """Marginals over every joint association of a cluster (Murty's ranking, ``k``
    grown until exhausted); ``bound``: an upper bound on how many there are."""
    k = int(min(bound, 4096, MAX_JOINT))      # all of them, or a start
    while True:
        mg = marginals(problem, k=k, method="kbest")
        if mg.exhaustive:
            return mg
        if k >= MAX_JOINT:
            raise ProblemTooLargeError(
                f"a JPDA cluster of {n_tracks} tracks has more than {MAX_JOINT} joint "
                "associations: too many to sum without assocopt's exact marginals engine")
        k = min(16 * k, MAX_JOINT)


class AssocoptJPDA(DataAssociator):
    """Joint probabilistic data association with exact marginals from assocopt.

    A drop-in replacement for Stone Soup's
    :class:`~stonesoup.dataassociator.probability.JPDAwithEHM2`: the hypothesiser's
    probability hypotheses become the 2-D problem of
    :func:`~assocopt.tracking.stonesoup.probability_problem` (log-probabilities,
    forbidden pairs ``-inf``, built in bulk) and each hypothesis gets its exact
    marginal association probability (:func:`association_probabilities`).

    ``associate`` returns, for every track, a
    :class:`~stonesoup.types.multihypothesis.MultipleHypothesis` of
    :class:`~stonesoup.types.hypothesis.SingleProbabilityHypothesis` (normalised to 1,
    the missed detection included, in the hypothesiser's order), as ``JPDAwithEHM2``
    does, for use with a PDA updater in
    :class:`~stonesoup.tracker.simple.MultiTargetMixtureTracker`.  After each call
    ``last_problem`` is the scan's :class:`~.problems.ProbabilityProblem`.
    """

    hypothesiser: Hypothesiser = Property(
        doc="Generate a set of probability hypotheses for each prediction-detection "
            "pair (e.g. a :class:`~stonesoup.hypothesiser.probability.PDAHypothesiser`)")

    def __init__(self, *args, **kwargs):
        super().__init__(*args, **kwargs)
        self.last_problem = None

    def associate(self, tracks, detections, timestamp, **kwargs):
        """Associate ``detections`` with ``tracks``.

        Parameters
        ----------
        tracks : set of :class:`~stonesoup.types.track.Track`
            Tracks which detections will be associated to.
        detections : set of :class:`~stonesoup.types.detection.Detection`
            Detections to be associated to tracks.
        timestamp : datetime.datetime
            Timestamp to be used for missed detections and to predict to.

        Returns
        -------
        : dict of :class:`~stonesoup.types.track.Track` to :class:`~.MultipleHypothesis`
            Each track's hypotheses with their joint association probabilities
        """
        hypotheses = self.generate_hypotheses(tracks, detections, timestamp, **kwargs)
        return self.associate_hypotheses(hypotheses)

    def associate_hypotheses(self, hypotheses) -> dict:
        """The JPDA posterior of already generated ``hypotheses`` (track -> hypotheses)."""
        pp = probability_problem(hypotheses)
        self.last_problem = pp
        return pp.posterior(association_probabilities(pp))
