"""assocopt inside Stone Soup: data associators solved by any assocopt back end.

Install with ``pip install assocopt[stonesoup]``.  :class:`AssocoptGNN` is a drop-in
replacement for Stone Soup's :class:`~stonesoup.dataassociator.neighbour.GNNWith2DAssignment`:
it takes the same hypothesiser, turns its hypotheses into a sparse 2-D
:class:`~assocopt.problems.problem.AssignmentProblem` and returns a
:class:`~stonesoup.types.hypothesis.JointHypothesis` (a mapping track -> hypothesis)
from the optimum.  :class:`AssocoptKBest` is not a data associator: its ``rank`` returns
the ``k`` best joint hypotheses (Murty's ranking, :func:`assocopt.kbest`).
:class:`AssocoptMFA` replaces :class:`~stonesoup.dataassociator.mfa.MFADataAssociator`:
the sliding window of scans solved exactly as one S-D problem
(:mod:`assocopt.tracking.mfa`), optionally keeping the ``k`` best global hypotheses.

The problem (rows = tracks, columns = detections):

* a detection hypothesis of track ``i`` and detection ``j`` is candidate ``(i, j)``
  with cost its distance (:class:`~stonesoup.types.hypothesis.SingleDistanceHypothesis`)
  or minus its probability (``probability_score="linear"``, the sum of probabilities
  that ``GNNWith2DAssignment`` maximises) or minus its log-probability
  (``probability_score="log"``: the most probable joint association);
* the missed-detection hypothesis of track ``i`` is its miss candidate ``(i, 0)``
  (a track without one must be assigned a detection);
* a detection left unassigned costs 0.

Tracks without any hypothesis are left out of the association, as in Stone Soup.
"""

from __future__ import annotations

import numpy as np

try:
    from stonesoup.base import Base, Property
    from stonesoup.dataassociator.base import DataAssociator
    from stonesoup.hypothesiser import Hypothesiser
    from stonesoup.types.hypothesis import (JointHypothesis, SingleDistanceHypothesis,
                                            SingleProbabilityHypothesis)
    from stonesoup.types.multihypothesis import MultipleHypothesis
except ImportError as exc:  # pragma: no cover - exercised in a subprocess-free test
    raise ImportError("assocopt.tracking.stonesoup needs Stone Soup: "
                      "pip install assocopt[stonesoup]") from exc

from ...solving.api import solve
from ...problems.problem import AssignmentProblem
from ...model.solution import Status
from .problems import hypothesis_table, use_dense

__all__ = ["AssocoptGNN", "AssocoptKBest", "AssocoptMFA", "hypotheses_problem",
           "mfa_reference_cost"]

#: Accepted values of ``probability_score``.
PROBABILITY_SCORES = ("linear", "log")


def hypotheses_problem(hypotheses, probability_score: str = "linear", *,
                       dense: bool | None = None):
    """The 2-D problem of a hypothesiser's output (module docstring), built in bulk.

    Each hypothesis is read once (:func:`~.problems.hypothesis_table`); costs,
    checks and the candidate list are numpy.

    Parameters
    ----------
    hypotheses : mapping track -> iterable of SingleHypothesis
        What ``DataAssociator.generate_hypotheses`` returns.
    probability_score : "linear" or "log"
    dense : bool, optional
        Keep the problem as a matrix (the 2-D engines' fast path: Murty's k best
        prices its answers in bulk there) or a candidate list; by default
        :func:`~.problems.use_dense` decides from the sizes.

    Returns
    -------
    problem : AssignmentProblem
    tracks : list of tracks (row ``i + 1`` of the problem is ``tracks[i]``)
    table : dict mapping a candidate tuple ``(i, j)`` to its hypothesis
    """
    if probability_score not in PROBABILITY_SCORES:
        raise ValueError(f"probability_score must be one of {PROBABILITY_SCORES}, "
                         f"got {probability_score!r}")
    t = hypothesis_table(hypotheses)
    kinds = set()
    for kind in {type(h) for h in t.hypotheses}:
        if issubclass(kind, SingleProbabilityHypothesis):
            kinds.add("probability")
        elif issubclass(kind, SingleDistanceHypothesis):
            kinds.add("distance")
        else:
            raise TypeError(f"hypothesis of type {kind.__name__} has neither a "
                            "distance nor a probability")
    if len(kinds) > 1:
        raise RuntimeError("2d assignment does not support mixed hypothesis types")
    if kinds == {"distance"}:
        cost = np.fromiter((h.distance for h in t.hypotheses), np.float64,
                           len(t.hypotheses))
    else:
        log_p = t.log_probabilities()
        cost = -np.exp(log_p) if probability_score == "linear" else -log_p
    n, m = t.shape
    miss = t.col < 0
    if dense is None:
        dense = use_dense(n, m, len(cost))
    if dense:
        C = np.full((n, m), np.inf)
        C[t.row[~miss], t.col[~miss]] = cost[~miss]
        rm = np.full(n, np.inf)
        rm[t.row[miss]] = cost[miss]
        problem = AssignmentProblem.two_d(C, rm, 0.0, name="stonesoup-hypotheses")
    else:
        tuples = np.zeros((len(cost) + m, 2), np.int64)
        tuples[:len(cost), 0] = t.row + 1
        tuples[:len(cost), 1] = t.col + 1            # the miss: column 0
        tuples[len(cost):, 1] = np.arange(1, m + 1)
        problem = AssignmentProblem.sparse((n, m), tuples, np.concatenate(
            [cost, np.zeros(m)]), name="stonesoup-hypotheses")
    table = dict(zip(zip((t.row + 1).tolist(), (t.col + 1).tolist()), t.hypotheses))
    return problem, t.tracks, table


def _joint(tuples: np.ndarray, tracks: list, table: dict) -> JointHypothesis:
    chosen = {tracks[i - 1]: table[(i, j)] for i, j in tuples.tolist() if i > 0}
    return JointHypothesis(chosen)


def _fits_dense(hypotheses) -> bool | None:
    """Dense for the ranking (the compiled 2-D ranking forms the matrix anyway) unless
    the matrix would be huge; None: :func:`~.problems.use_dense` decides."""
    n = sum(1 for h in hypotheses.values() if len(h))
    return True if n * (sum(len(h) for h in hypotheses.values()) + 1) <= 1 << 22 else None


class AssocoptGNN(DataAssociator):
    """Global nearest neighbour association solved by an assocopt back end.

    Builds the sparse 2-D assignment problem of the hypothesiser's hypotheses
    (distance or probability hypotheses, missed-detection hypotheses included; see
    :mod:`assocopt.tracking.stonesoup`) and returns the optimal
    :class:`~.JointHypothesis`.  With distance hypotheses it gives the associations
    of :class:`~.GNNWith2DAssignment` (whenever the optimum is unique).
    """

    hypothesiser: Hypothesiser = Property(
        doc="Generate a set of hypotheses for each prediction-detection pair")
    solver: str = Property(
        default="auto",
        doc="assocopt back end that solves the problem (``assocopt solvers`` lists "
            "them); ``auto`` picks the 2-D fast path")
    solver_options: dict = Property(
        default=None,
        doc="Keyword options passed to :func:`assocopt.solve` (e.g. ``time_limit``)")
    probability_score: str = Property(
        default="linear",
        doc="How probability hypotheses become costs: ``linear`` maximises the sum of "
            "probabilities as GNNWith2DAssignment does; ``log`` their product")

    def associate(self, tracks, detections, timestamp, **kwargs):
        """Associate ``detections`` with ``tracks``.

        Returns
        -------
        : :class:`~.JointHypothesis`
            Mapping of each track that has hypotheses to its chosen hypothesis
        """
        hypotheses = self.generate_hypotheses(tracks, detections, timestamp, **kwargs)
        return self.associate_hypotheses(hypotheses)

    def associate_hypotheses(self, hypotheses) -> JointHypothesis:
        """The optimal joint hypothesis of already generated ``hypotheses``."""
        problem, tracks, table = hypotheses_problem(hypotheses, self.probability_score)
        sol = solve(problem, self.solver, **(self.solver_options or {}))
        if sol.status is Status.INFEASIBLE:
            raise RuntimeError("Assignment was not feasible")
        if not sol.has_solution:
            raise RuntimeError(f"assocopt back end {sol.solver!r} found no association: "
                               f"{sol.status.value} {sol.message}".strip())
        return _joint(sol.tuples, tracks, table)


class AssocoptKBest(Base):
    """Ranked joint hypotheses: the ``k`` best, by Murty's ranking (:func:`assocopt.kbest`).

    Not a :class:`~.DataAssociator` (whose ``associate`` returns one mapping track ->
    hypothesis): :meth:`rank` returns a list of up to ``k`` :class:`~.JointHypothesis`,
    best first (all of them when fewer feasible associations exist), for
    multiple-hypothesis trackers and k-best approximations of JPDA.  The first is the
    one :class:`AssocoptGNN` returns with the same settings; ``last_ranked`` keeps the
    core's :class:`~assocopt.Ranked` (costs, ``exhausted``) of the latest call.
    """

    hypothesiser: Hypothesiser = Property(
        doc="Generate a set of hypotheses for each prediction-detection pair")
    k: int = Property(default=5, doc="Number of joint hypotheses to return")
    solver: str = Property(default="auto", doc="assocopt back end of the subproblems")
    solver_options: dict = Property(
        default=None, doc="Keyword options passed to :func:`assocopt.kbest`")
    probability_score: str = Property(
        default="linear", doc="As for :class:`AssocoptGNN`: ``linear`` or ``log``")

    def __init__(self, *args, **kwargs):
        super().__init__(*args, **kwargs)
        self.last_ranked = None

    def rank(self, tracks, detections, timestamp, **kwargs) -> list:
        """The ``k`` best joint hypotheses of ``tracks`` and ``detections``, best first.

        Returns
        -------
        : list of :class:`~.JointHypothesis`
        """
        hypotheses = {track: self.hypothesiser.hypothesise(track, detections, timestamp,
                                                           **kwargs) for track in tracks}
        return self.rank_hypotheses(hypotheses)

    def rank_hypotheses(self, hypotheses) -> list:
        """The ``k`` best joint hypotheses of already generated ``hypotheses``."""
        from ...ranking.kbest import kbest

        if isinstance(self.k, bool) or int(self.k) != self.k or self.k < 1:
            raise ValueError(f"k must be a positive integer, got {self.k!r}")
        problem, tracks, table = hypotheses_problem(hypotheses, self.probability_score,
                                                    dense=_fits_dense(hypotheses))
        self.last_ranked = kbest(problem, int(self.k), solver=self.solver,
                                 **(self.solver_options or {}))
        return [_joint(s.tuples, tracks, table) for s in self.last_ranked]


class AssocoptMFA(DataAssociator):
    """Multi-frame assignment over a sliding window, solved exactly by an assocopt back end.

    A drop-in replacement for Stone Soup's
    :class:`~stonesoup.dataassociator.mfa.MFADataAssociator` (same ``hypothesiser`` and
    ``slide_window``): the hypotheses of an ``MFAHypothesiser`` or
    ``MHMFAHypothesiser`` (histories in ``prediction.tag``, cost ``-log(weight)``)
    become one S-D problem (:mod:`assocopt.tracking.mfa`: one axis for the tracks, one
    per scan of the window), solved to a proven optimum, and each track gets back
    the :class:`~.MultipleHypothesis` of its hypotheses that survive n-scan pruning.
    A detection is one resource per scan whatever ``MHMFAHypothesiser``'s
    hypothesiser index (its hypothesisers model the same detections), as in Stone
    Soup's constraints; pruning compares the whole tag entry, as Stone Soup does.

    With ``k > 1`` the pruning keeps the union of the ``k`` best global hypotheses'
    histories (an M-best multi-frame assignment).  After each call ``last_solution``
    is the window's :class:`~assocopt.Solution` (objective = the chosen hypotheses'
    summed ``-log(weight)``, bound, gap, status, times), ``last_costs`` the costs of
    the global hypotheses kept (best first) and ``last_window`` the
    :class:`~assocopt.tracking.mfa.WindowProblem`.
    """

    hypothesiser: Hypothesiser = Property(
        doc="An MFAHypothesiser or MHMFAHypothesiser (tags hold the histories)")
    slide_window: int = Property(doc="Length of the sliding window, in scans")
    solver: str = Property(default="auto", doc="assocopt back end of the window problem")
    solver_options: dict = Property(
        default=None, doc="Keyword options passed to :func:`assocopt.solve` / ``kbest``")
    k: int = Property(default=1, doc="Global hypotheses whose histories pruning keeps")
    drop_dominated: bool = Property(
        default=False,
        doc="With ``k = 1``, leave out of the window problem the hypotheses that a "
            "cheaper one of their track with fewer detections dominates (same optimum, "
            "smaller problem; :func:`assocopt.tracking.mfa.dominated`): for back ends "
            "whose time grows with the candidates (``highs``, ``lagrangian-exact``); "
            "``auto``'s ``bnb`` was not faster with it (docs/benchmarks-mfa.md)")

    def __init__(self, *args, **kwargs):
        super().__init__(*args, **kwargs)
        self.last_solution = self.last_window = None
        self.last_costs: list = []

    def associate(self, tracks, detections, timestamp, **kwargs):
        """Associate ``detections`` with ``tracks`` over the window.

        Returns
        -------
        : dict of :class:`~.Track` to :class:`~.MultipleHypothesis`
            The pruned hypotheses of each track (empty for a track without any)
        """
        self.last_solution, self.last_window, self.last_costs = None, None, []
        if not tracks:
            return {}
        hypotheses = self.generate_hypotheses(tracks, detections, timestamp,
                                              detections_tuple=tuple(detections), **kwargs)
        return self.associate_hypotheses(hypotheses)

    def associate_hypotheses(self, hypotheses) -> dict:
        """The pruned hypotheses of already generated ``hypotheses`` (track -> list)."""
        from ..mfa import log_costs, nscan_prune, ranked_window, solve_window, tag_arrays
        from ..mfa import window_problem

        if isinstance(self.k, bool) or int(self.k) != self.k or self.k < 1:
            raise ValueError(f"k must be a positive integer, got {self.k!r}")
        order = [t for t, hyps in hypotheses.items() if len(hyps)]
        flat = [h for t in order for h in hypotheses[t]]
        track_id = np.repeat(np.arange(len(order)),
                             [len(hypotheses[t]) for t in order]).astype(np.int64)
        preds = [h.prediction for h in flat]
        cost = log_costs([p.weight for p in preds])
        history, labels = tag_arrays([p.tag for p in preds], self.slide_window)
        wp = window_problem(track_id, cost, history, n_tracks=len(order),
                            drop_dominated=bool(self.drop_dominated) and self.k == 1)
        opts = self.solver_options or {}
        if self.k == 1:
            sol, choice = solve_window(wp, self.solver, **opts)
            best = [choice] if sol.has_solution else []
            costs = [sol.objective] if sol.has_solution else []
        else:
            costs, best, ranked = ranked_window(wp, int(self.k), self.solver, **opts)
            sol = ranked[0] if len(ranked) else solve(wp.problem, self.solver, **opts)
        self.last_solution, self.last_window, self.last_costs = sol, wp, costs
        if not sol.has_solution:
            raise RuntimeError(f"no global hypothesis of the window: {sol.status.value} "
                               f"{sol.message}".strip())
        keep = nscan_prune(track_id, labels, best)
        out = {t: MultipleHypothesis([]) for t in hypotheses}
        counts = np.bincount(track_id, minlength=len(order))
        for t, hi, n in zip(order, np.cumsum(counts).tolist(), counts.tolist()):
            out[t] = MultipleHypothesis([flat[j] for j in range(hi - n, hi) if keep[j]])
        return out


def mfa_reference_cost(hypotheses, window: int) -> float:
    """The cost (summed ``-log(weight)``) of the global hypothesis Stone Soup's
    :class:`~stonesoup.dataassociator.mfa.MFADataAssociator` selects from
    ``hypotheses`` (track -> hypotheses): its own Lagrangian/SCIP steps
    (``stonesoup.dataassociator.mfa._init`` / ``_step``, private) rerun as its
    ``associate`` runs them, for comparing costs on the same inputs.  Reads the
    hypotheses only."""
    from stonesoup.dataassociator.mfa import _init, _step
    hyps = [_init.Hyp.create(trackID=i, cost=-np.log(h.prediction.weight),
                             measHistory=h.prediction.tag, slide_window=window)
            for i, mh in enumerate(hypotheses.values()) for h in mh]
    info = _init.init_hyp_info(hyps, window)
    state = _step.AlgorithmState.initialise(window, len(info.hyps))
    for _ in range(_step.MAX_ITERATION_COUNT):
        _step.algorithm_step(state, info)
        if state.should_break:
            break
    return float(info.all_costs[state.get_best_hypothesis_indices()].sum())
