"""Joint probabilistic data association (JPDA) in Stone Soup, exact, by assocopt.

:class:`AssocoptJPDA` is a drop-in replacement for Stone Soup's
:class:`~stonesoup.dataassociator.probability.JPDAwithEHM2` (and ``JPDA``,
``JPDAwithEHM``): the same hypothesiser, the same answer (per track a normalised
:class:`~stonesoup.types.multihypothesis.MultipleHypothesis` of
:class:`~stonesoup.types.hypothesis.SingleProbabilityHypothesis`, the missed detection
included, in the hypothesiser's order), the same probabilities: the exact marginal
association probabilities of the scan, computed by :func:`assocopt.marginals` on the
problem of :func:`~.problems.probability_problem`.

Exact per cluster: :func:`assocopt.marginals` (``method="exact"``) splits the scan into
its independent clusters (tracks linked by shared detections) and runs a hypothesis net
on each; a cluster too large for the net's memory budget (``max_nodes``) is an error
naming its size, never an approximation.
"""

from __future__ import annotations

import numpy as np

try:
    from stonesoup.base import Property
    from stonesoup.dataassociator.base import DataAssociator
    from stonesoup.hypothesiser import Hypothesiser
except ImportError as exc:  # pragma: no cover - exercised in a subprocess-free test
    raise ImportError("assocopt.tracking.stonesoup.jpda needs Stone Soup: "
                      "pip install assocopt[stonesoup]") from exc

from ...ranking.marginals import marginals
from .problems import ProbabilityProblem, probability_problem

__all__ = ["AssocoptJPDA", "association_probabilities"]


def association_probabilities(pp: ProbabilityProblem, max_nodes: int | None = None
                              ) -> np.ndarray:
    """The exact marginal probability of each hypothesis of ``pp.table.hypotheses``.

    ``max_nodes``: the memory budget of each cluster's hypothesis net (None: the
    default of :func:`assocopt.marginals`).

    Raises
    ------
    assocopt.ProblemTooLargeError
        A cluster too large for the budget (the message names its size).
    """
    n, m = pp.table.shape
    if n == 0:
        return np.zeros(0)
    if m == 0:                                      # every track missed
        return np.ones(len(pp.score))
    budget = {} if max_nodes is None else {"max_nodes": max_nodes}
    mg = marginals(pp.problem, method="exact", **budget)
    return pp.hypothesis_probabilities(mg.pairs, mg.row_miss)


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
