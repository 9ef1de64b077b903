"""Stone Soup hypotheses read once into arrays, and the 2-D problems built from them.

A hypothesiser returns, per track, a list of hypotheses (one per gated detection and
usually one missed detection).  :func:`hypothesis_table` reads every hypothesis once
(its measurement, and its probability or distance) and numbers rows and columns;
everything after that is numpy in bulk: the score matrix, the candidate list,
duplicate checks and the mapping of answers back to hypotheses.

:func:`probability_problem` is the problem of JPDA (:class:`~.jpda.AssocoptJPDA`):
row ``i`` = track ``i``, column ``j`` = detection ``j``, score of ``(i, j)`` the log
of the hypothesis probability, the track's miss scored by the log of its
missed-detection probability, a detection left to clutter scored 0 and a pair without
a hypothesis forbidden (``-inf``); with ``maximize=True`` and temperature 1 the weight
of a joint association is the product of its hypotheses' probabilities, as in Stone
Soup's JPDA, so :func:`assocopt.marginals` gives its association probabilities.

The problem is kept dense (an ``n x m`` matrix, the 2-D engines' fast path, where
:func:`assocopt.kbest` and :func:`assocopt.marginals` price answers in bulk) when the
matrix is small or not much larger than the list of hypotheses (:func:`use_dense`),
else sparse (a candidate list: a scene of 1000 tracks with 2 gated detections each).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

try:
    from stonesoup.types.detection import MissedDetection
    from stonesoup.types.hypothesis import SingleProbabilityHypothesis
    from stonesoup.types.multihypothesis import MultipleHypothesis
    from stonesoup.types.numeric import Probability
except ImportError as exc:  # pragma: no cover - exercised in a subprocess-free test
    raise ImportError("assocopt.tracking.stonesoup.problems needs Stone Soup: "
                      "pip install assocopt[stonesoup]") from exc

from ...problems.problem import AssignmentProblem

__all__ = ["HypothesisTable", "hypothesis_table", "ProbabilityProblem",
           "probability_problem", "use_dense", "DENSE_SMALL", "DENSE_RATIO"]

#: A matrix of at most this many entries is always kept dense.
DENSE_SMALL = 4096
#: ... and a larger one while it has at most this many entries per hypothesis.
DENSE_RATIO = 16


def use_dense(n_rows: int, n_cols: int, n_hypotheses: int) -> bool:
    """Whether the ``n_rows x n_cols`` problem of ``n_hypotheses`` is kept as a matrix.

    Dense answers are priced in bulk (Murty's k best: ~50x faster than the candidate
    list on an 8-track JPDA cluster), but a dense 1000 x 1400 scene with two gated
    detections per track is 30x slower to validate and solve than its candidate list.
    """
    size = n_rows * n_cols
    return size <= DENSE_SMALL or size <= DENSE_RATIO * n_hypotheses


@dataclass(frozen=True, eq=False)
class HypothesisTable:
    """Every hypothesis of a hypothesiser's output, read once (:func:`hypothesis_table`).

    Attributes
    ----------
    tracks : list
        The tracks with at least one hypothesis; row ``i`` (0-based) is ``tracks[i]``.
    empty : list
        The tracks without any hypothesis (left out of the problem, as Stone Soup does).
    detections : list
        The detections some hypothesis names; column ``j`` (0-based) is ``detections[j]``.
    hypotheses : list
        All hypotheses of ``tracks``, track by track in the input order.
    row, col : ndarray of int64, shape (H,)
        Row and column of each hypothesis (``col = -1``: the missed detection).
    offsets : ndarray of int64, shape (len(tracks) + 1,)
        Hypotheses of ``tracks[i]`` are ``hypotheses[offsets[i]:offsets[i + 1]]``.
    """

    tracks: list
    empty: list
    detections: list
    hypotheses: list
    row: np.ndarray
    col: np.ndarray
    offsets: np.ndarray

    @property
    def shape(self) -> tuple[int, int]:
        """``(tracks, detections)``."""
        return len(self.tracks), len(self.detections)

    def log_probabilities(self) -> np.ndarray:
        """Natural log of each hypothesis's probability (``-inf`` for 0), read once.

        Raises
        ------
        TypeError
            A hypothesis without a probability (e.g. a distance hypothesis).
        ValueError
            A negative or NaN probability.
        """
        try:
            probs = [h.probability for h in self.hypotheses]
        except AttributeError:
            bad = next(h for h in self.hypotheses if not hasattr(h, "probability"))
            raise TypeError(f"hypothesis of type {type(bad).__name__} has no probability: "
                            "JPDA needs probability hypotheses (PDAHypothesiser)") from None
        out = np.fromiter((p.log_value if type(p) is Probability else _log(p)
                           for p in probs), np.float64, len(probs))
        if np.isnan(out).any():
            raise ValueError("a hypothesis probability is NaN")
        return out


def _log(p) -> float:
    """Log of a probability given as a float (or a Probability subclass)."""
    if isinstance(p, Probability):
        return float(p.log_value)
    p = float(p)
    if math.isnan(p):
        raise ValueError("a hypothesis probability is NaN")
    if p < 0:
        raise ValueError(f"hypothesis probability must be >= 0, got {p}")
    return math.log(p) if p > 0 else -math.inf


def hypothesis_table(hypotheses) -> HypothesisTable:
    """Read a hypothesiser's output (mapping track -> hypotheses) into arrays.

    Each hypothesis's ``measurement`` is read once; a ``MissedDetection`` (or ``None``)
    is the track's miss, any other measurement a column, numbered in first-seen order
    (detections are told apart by identity, as Stone Soup does).

    Raises
    ------
    ValueError
        A track with two hypotheses for one detection, or two missed detections.
    """
    tracks, empty, counts = [], [], []
    for track, hyps in hypotheses.items():
        n = len(hyps)
        if n:
            tracks.append(track)
            counts.append(n)
        else:
            empty.append(track)
    flat = [h for t in tracks for h in hypotheses[t]]
    meas = [h.measurement for h in flat]
    index: dict[int, int] = {}
    detections: list = []
    cols = np.empty(len(flat), np.int64)
    for k, m in enumerate(meas):
        if m is None or isinstance(m, MissedDetection):
            cols[k] = -1
        else:
            j = index.setdefault(id(m), len(index))
            if j == len(detections):
                detections.append(m)
            cols[k] = j
    counts_a = np.asarray(counts, np.int64)
    offsets = np.zeros(len(tracks) + 1, np.int64)
    np.cumsum(counts_a, out=offsets[1:])
    rows = np.repeat(np.arange(len(tracks), dtype=np.int64), counts_a)
    key = rows * (len(detections) + 1) + cols + 1
    uniq, first, seen = np.unique(key, return_index=True, return_counts=True)
    if (seen > 1).any():
        k = int(first[np.argmax(seen > 1)])
        what = "a missed detection" if cols[k] < 0 else "one detection"
        raise ValueError(f"track {int(rows[k])} has two hypotheses for {what}")
    return HypothesisTable(tracks, empty, detections, flat, rows, cols, offsets)


@dataclass(frozen=True, eq=False)
class ProbabilityProblem:
    """The JPDA problem of probability hypotheses (:func:`probability_problem`).

    Attributes
    ----------
    problem : AssignmentProblem
        2-D, ``maximize=True``: scores are log-probabilities (module docstring).
    table : HypothesisTable
        Rows, columns and hypotheses.
    score : ndarray, shape (H,)
        Log-probability of each hypothesis of ``table.hypotheses``.
    """

    problem: AssignmentProblem
    table: HypothesisTable
    score: np.ndarray

    def hypothesis_probabilities(self, pairs: np.ndarray, row_miss: np.ndarray
                                 ) -> np.ndarray:
        """Each hypothesis's probability from the 2-D marginals (``pairs[i, j]``: row
        ``i`` takes column ``j``; ``row_miss[i]``: row ``i`` is missed)."""
        t = self.table
        miss = t.col < 0
        return np.where(miss, row_miss[t.row], pairs[t.row, np.where(miss, 0, t.col)])

    def posterior(self, probabilities: np.ndarray) -> dict:
        """Track -> :class:`~stonesoup.types.multihypothesis.MultipleHypothesis` of
        :class:`~stonesoup.types.hypothesis.SingleProbabilityHypothesis` with the given
        probabilities (one per hypothesis of ``table.hypotheses``), normalised per
        track; hypotheses in the hypothesiser's order, each keeping its prediction,
        measurement and measurement prediction.  A track without hypotheses gets an
        empty one.

        The normalisation is done here in bulk (log-sum-exp per track, numpy) rather
        than by ``MultipleHypothesis(..., normalise=True)``, whose per-track Probability
        arithmetic costs ~0.7 ms a track; the result's ``normalise`` flag is set as that
        call would leave it (the flag is read only by the constructor)."""
        t = self.table
        P = np.asarray(probabilities, np.float64)
        if P.shape != (len(t.hypotheses),):
            raise ValueError(f"{len(t.hypotheses)} probabilities needed, got shape {P.shape}")
        if (P < 0).any() or not np.isfinite(P).all():
            raise ValueError("probabilities must be finite and >= 0")
        with np.errstate(divide="ignore"):
            logp = np.log(P)
        top = np.full(len(t.tracks), -np.inf)
        np.maximum.at(top, t.row, logp)
        if np.isneginf(top).any():
            i = int(np.flatnonzero(np.isneginf(top))[0])
            raise ValueError(f"every hypothesis of track {i} has probability 0")
        z = np.log(np.bincount(t.row, weights=np.exp(logp - top[t.row]),
                               minlength=len(t.tracks))) + top
        logp -= z[t.row]
        new = [SingleProbabilityHypothesis(h.prediction, h.measurement,
                                           measurement_prediction=h.measurement_prediction,
                                           probability=Probability(lp, log_value=True))
               for h, lp in zip(t.hypotheses, logp.tolist())]
        off = t.offsets.tolist()
        out = {}
        for track, a, b in zip(t.tracks, off, off[1:]):
            mh = out[track] = MultipleHypothesis(new[a:b], False, 1)
            mh.normalise = True
        for track in t.empty:
            out[track] = MultipleHypothesis([], True, 1)
        return out


def probability_problem(hypotheses, *, dense: bool | None = None) -> ProbabilityProblem:
    """The 2-D JPDA problem of probability hypotheses (module docstring), in bulk.

    Parameters
    ----------
    hypotheses : mapping track -> iterable of SingleProbabilityHypothesis
        What ``DataAssociator.generate_hypotheses`` returns (e.g. of a
        :class:`~stonesoup.hypothesiser.probability.PDAHypothesiser`).
    dense : bool, optional
        Keep the problem as a matrix (True) or a candidate list (False); by default
        :func:`use_dense` decides.

    Returns
    -------
    ProbabilityProblem

    Examples
    --------
    >>> import numpy as np
    >>> from stonesoup.types.detection import Detection, MissedDetection
    >>> from stonesoup.types.hypothesis import SingleProbabilityHypothesis as H
    >>> d = Detection(np.zeros((2, 1)))
    >>> pp = probability_problem({"a": [H(None, MissedDetection(), 0.2), H(None, d, 0.8)],
    ...                           "b": [H(None, MissedDetection(), 0.5), H(None, d, 0.5)]})
    >>> pp.problem.sizes, pp.problem.maximize
    ((2, 1), True)
    """
    table = hypothesis_table(hypotheses)
    score = table.log_probabilities()
    if np.isposinf(score).any():
        raise ValueError("a hypothesis probability is infinite")
    n, m = table.shape
    miss = table.col < 0
    pair = ~miss
    if dense is None:
        dense = use_dense(n, m, len(score))
    if dense:
        S = np.full((n, m), -np.inf)
        S[table.row[pair], table.col[pair]] = score[pair]
        rm = np.full(n, -np.inf)
        rm[table.row[miss]] = score[miss]
        problem = AssignmentProblem.two_d(S, rm, 0.0, maximize=True, name="stonesoup-jpda")
    else:
        tuples = np.zeros((len(score) + m, 2), np.int64)
        tuples[:len(score), 0] = table.row + 1
        tuples[:len(score), 1] = table.col + 1          # the miss: column 0
        tuples[len(score):, 1] = np.arange(1, m + 1)
        scores = np.concatenate([score, np.zeros(m)])
        problem = AssignmentProblem.sparse((n, m), tuples, scores, maximize=True,
                                           name="stonesoup-jpda")
    return ProbabilityProblem(problem, table, score)
