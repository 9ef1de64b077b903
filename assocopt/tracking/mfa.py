"""Multi-frame assignment: a sliding window of scans as one S-D assignment problem.

Each track ``t`` carries hypotheses ``h``, each a measurement history over the window
(one measurement index per *slot*, 0 = missed) and a cost ``c_h = -log(w_h)``.  A
global hypothesis picks exactly one hypothesis per track, and no measurement of any
slot is used twice; a measurement no chosen hypothesis uses is left free (clutter or a
new track).  A slot is a scan, or a (scan, sensor) pair when several sensors report
separately.

In the core's terms (:meth:`assocopt.AssignmentProblem.sparse`; real indices covered
exactly once, the dummy 0 reusable) this is an S-D problem with ``1 + S`` axes:

* axis 0: the tracks ``1..T``; hypothesis ``h`` of track ``t`` is the candidate
  ``(t, m_1, ..., m_S)`` with cost ``c_h`` (``m_s`` its measurement in slot ``s``,
  renumbered ``1..n_s`` per slot, 0 for a miss).  Covering track ``t`` exactly once
  is "exactly one hypothesis per track"; the all-missed history ``(t, 0, ..., 0)`` is a
  valid candidate since ``t`` is real;
* axes ``1..S``: the measurements of each slot; covering one exactly once is "used by
  at most one chosen hypothesis", with the singleton candidate ``(0, .., m, .., 0)``
  of cost ``free_cost`` (0, Stone Soup's false-alarm cost) for "left free".

Hypotheses of one track with the same window history (they differ before the window,
or only in a label such as :class:`~stonesoup.hypothesiser.mfa.MHMFAHypothesiser`'s
hypothesiser index) are one candidate tuple: the cheapest stands for them in the
problem, and :func:`ranked_window` expands the others when ranking global hypotheses.

A hypothesis whose history holds that of a cheaper hypothesis of its track (the same
measurements in some slots, misses in the others) is in no optimum: swapping it for
the cheaper one frees measurements and lowers the cost.  ``drop_dominated`` leaves
such hypotheses out of the problem (the optimum is unchanged, the problem smaller and
often split into more components); it changes the ranking below the best, so
:func:`ranked_window` needs the full problem.

:func:`nscan_prune` is the n-scan pruning rule: keep, for each track, the hypotheses
that agree with the best global hypothesis (or with any of the ``k`` best) on the
window's oldest scan, the one that leaves the window at the next scan.  Applied at
every scan, the kept hypotheses of a track then agree on every scan before the window.
"""

from __future__ import annotations

import heapq
import itertools
import math
from dataclasses import dataclass
from typing import Any, Sequence

import numpy as np

from .. import AssignmentProblem, Solution, kbest, solve

__all__ = ["WindowProblem", "window_problem", "dominated", "chosen_hypotheses",
           "ranked_window", "nscan_prune", "tag_arrays"]


@dataclass(frozen=True)
class WindowProblem:
    """The S-D problem of a window and the maps back to the hypotheses.

    Attributes
    ----------
    problem : AssignmentProblem
        Candidates ``0..U-1`` are the distinct hypothesis tuples, then the free
        singletons of every slot's measurements.
    track, cost, history : ndarray
        The input hypotheses (``history`` shape ``(H, S)``); hypotheses with
        ``cost = +inf`` (weight 0) never enter the problem.
    candidate : ndarray of int64, shape (H,)
        Position in ``problem.tuples`` of each hypothesis's tuple (-1 for ``+inf``, and
        for a dominated tuple left out).
    representative : ndarray of int64, shape (U,)
        The cheapest hypothesis of each distinct tuple (first in input order on ties).
    measurements : list of ndarray
        Per slot, the original measurement ids in the order of their index ``1..n_s``.
    n_dominated : int
        Distinct tuples left out as dominated (``drop_dominated=True``; 0 otherwise).
    drop_dominated : bool
        Whether dominated tuples were looked for and left out.
    """

    problem: AssignmentProblem
    track: np.ndarray
    cost: np.ndarray
    history: np.ndarray
    candidate: np.ndarray
    representative: np.ndarray
    measurements: list
    n_dominated: int = 0
    drop_dominated: bool = False

    @property
    def n_tracks(self) -> int:
        """T, the number of tracks (axis 0 of the problem)."""
        return self.problem.sizes[0]

    @property
    def n_hypotheses(self) -> int:
        """U, the number of distinct hypothesis tuples in the problem."""
        return len(self.representative)


def _check_inputs(track, cost, history, n_tracks):
    track = np.asarray(track)
    cost = np.asarray(cost, dtype=np.float64)
    history = np.asarray(history)
    if track.ndim != 1 or cost.shape != track.shape:
        raise ValueError(f"track and cost must be 1-D arrays of one length, got shapes "
                         f"{track.shape} and {cost.shape}")
    if history.ndim != 2 or len(history) != len(track):
        raise ValueError(f"history must have shape ({len(track)}, S) (one row per "
                         f"hypothesis, one column per slot), got {history.shape}")
    for name, arr in (("track", track), ("history", history)):
        if arr.size and not np.issubdtype(arr.dtype, np.integer):
            raise ValueError(f"{name} must hold integers, got dtype {arr.dtype}")
        if arr.size and arr.min() < 0:
            raise ValueError(f"{name} must be non-negative (0 = missed in history), got "
                             f"{int(arr.min())}")
    bad = np.isnan(cost) | (cost == -np.inf)
    if bad.any():
        raise ValueError(f"cost of hypothesis {int(np.argmax(bad))} is {cost[bad][0]}: "
                         "costs must be finite or +inf (weight 0)")
    T = int(track.max()) + 1 if n_tracks is None and track.size else int(n_tracks or 0)
    if track.size and track.max() >= T:
        raise ValueError(f"track id {int(track.max())} is not below n_tracks={T}")
    has = np.zeros(T, bool)
    has[track[np.isfinite(cost)]] = True
    if not has.all():
        raise ValueError(f"track {int(np.argmin(has))} has no hypothesis of finite cost: "
                         "a global hypothesis must pick one for every track")
    return track.astype(np.int64), cost, history.astype(np.int64), T


def window_problem(track, cost, history, *, n_tracks: int | None = None,
                   free_cost: float = 0.0, drop_dominated: bool = False,
                   name: str = "mfa-window") -> WindowProblem:
    """The window's S-D problem (module docstring), built in bulk.

    Parameters
    ----------
    track : (H,) int
        Track id ``0..T-1`` of each hypothesis.
    cost : (H,) float
        ``-log(weight)``; ``+inf`` for a hypothesis that cannot be chosen.
    history : (H, S) int
        Measurement id of each hypothesis in each slot of the window, 0 = missed
        (any positive ids; they are renumbered per slot).
    n_tracks : int, optional
        T (default ``max(track) + 1``); every track needs a hypothesis.
    free_cost : float
        Cost of leaving one measurement unused (0: Stone Soup's false-alarm cost).
    drop_dominated : bool
        Leave out the tuples :func:`dominated` finds (module docstring): same optimum,
        smaller problem; not for ranking.
    """
    track, cost, history, T = _check_inputs(track, cost, history, n_tracks)
    H, S = history.shape
    ok = np.flatnonzero(np.isfinite(cost))
    hist = history[ok]
    compact = np.zeros_like(hist)
    measurements = []
    for s in range(S):
        ids = np.unique(hist[:, s][hist[:, s] > 0])
        measurements.append(ids)
        real = hist[:, s] > 0
        compact[real, s] = np.searchsorted(ids, hist[real, s]) + 1
    tuples = np.column_stack([track[ok] + 1, compact])
    c = cost[ok]
    # distinct tuples, cheapest first within each (lexsort is stable: input order on ties)
    order = np.lexsort((c,) + tuple(tuples[:, ::-1].T))
    srt = tuples[order]
    first = np.ones(len(order), bool)
    first[1:] = (srt[1:] != srt[:-1]).any(axis=1)
    group = np.cumsum(first) - 1
    representative = ok[order[first]]
    distinct, distinct_cost = srt[first], c[order[first]]
    n_dominated = 0
    if drop_dominated:
        kept = ~dominated(distinct, distinct_cost, free_cost)
        n_dominated = int(len(kept) - kept.sum())
        group = np.where(kept, np.cumsum(kept) - 1, -1)[group]
        representative, distinct, distinct_cost = \
            representative[kept], distinct[kept], distinct_cost[kept]
    candidate = np.full(H, -1, np.int64)
    candidate[ok[order]] = group
    sizes = [len(ids) for ids in measurements]
    n_free = int(sum(sizes))
    free = np.zeros((n_free, 1 + S), np.int64)
    axis = np.repeat(np.arange(1, S + 1), sizes)
    free[np.arange(n_free), axis] = np.concatenate(
        [np.arange(1, n + 1) for n in sizes]) if n_free else []
    problem = AssignmentProblem.sparse(
        (T, *sizes), np.concatenate([distinct, free]).reshape(-1, 1 + S),
        np.concatenate([distinct_cost, np.full(n_free, float(free_cost))]), name=name)
    return WindowProblem(problem, track, cost, history, candidate, representative,
                         measurements, n_dominated, bool(drop_dominated))


#: At most this many slots get every subset of their measurements tried by
#: :func:`dominated` (2**S - 1 lookups per tuple); longer windows try one or two slots.
ALL_SUBSETS_MAX_SLOTS = 8


def dominated(tuples: np.ndarray, costs: np.ndarray, free_cost: float = 0.0
              ) -> np.ndarray:
    """Which distinct window tuples ``(t, m_1..m_S)`` are dominated (boolean mask).

    Tuple ``u`` is dominated when the same track has a tuple ``v`` equal to ``u`` with
    some of its measurements replaced by misses, and ``c_v + free_cost * (measurements
    freed) < c_u`` (by more than rounding): in any global hypothesis choosing ``u``,
    ``v`` plus the freed measurements left free is feasible and cheaper, so ``u`` is in
    no optimum.  Found in bulk: each tuple's masked versions are looked up among the
    tuples by a mixed-radix key (a key that would overflow int64: nothing is dropped).
    """
    U, N = tuples.shape
    out = np.zeros(U, bool)
    if U < 2 or N < 2:
        return out
    radix = [int(v) + 1 for v in tuples.max(axis=0)]
    if math.prod(radix) >= 2 ** 62:
        return out
    mult = np.array([math.prod(radix[i + 1:]) for i in range(N)], np.int64)
    key = tuples @ mult
    order = np.argsort(key, kind="stable")
    sorted_key, sorted_cost = key[order], costs[order]
    meas, weight = tuples[:, 1:], tuples[:, 1:] * mult[1:]
    S = N - 1
    sizes = range(1, S + 1) if S <= ALL_SUBSETS_MAX_SLOTS else (1, 2)
    margin = 1e-12 * np.maximum(1.0, np.abs(costs))
    for r in sizes:
        for slots in itertools.combinations(range(S), r):
            cols = list(slots)
            freed = (meas[:, cols] > 0).sum(axis=1)
            masked = key - weight[:, cols].sum(axis=1)
            pos = np.minimum(np.searchsorted(sorted_key, masked), U - 1)
            found = (freed > 0) & (sorted_key[pos] == masked)
            out |= found & (sorted_cost[pos] + free_cost * freed < costs - margin)
    return out


def chosen_hypotheses(wp: WindowProblem, solution: Solution) -> np.ndarray:
    """The hypothesis (index into the input arrays) chosen for each track ``0..T-1``."""
    if not solution.has_solution:
        raise ValueError(f"the window problem has no solution: {solution.status}")
    sel = np.asarray(solution.selected, np.int64)
    hyp = wp.representative[sel[sel < wp.n_hypotheses]]
    out = np.full(wp.n_tracks, -1, np.int64)
    out[wp.track[hyp]] = hyp
    return out


def solve_window(wp: WindowProblem, solver: str = "auto", **options: Any
                 ) -> tuple[Solution, np.ndarray | None]:
    """The optimal global hypothesis: the core's :func:`~assocopt.solve` and its choice."""
    sol = solve(wp.problem, solver, **options)
    return sol, (chosen_hypotheses(wp, sol) if sol.has_solution else None)


def _k_smallest_sums(lists: list[np.ndarray], k: int) -> list[tuple[float, tuple]]:
    """The ``k`` smallest sums picking one entry of each ascending list (best first)."""
    start = tuple(0 for _ in lists)
    heap = [(float(sum(a[0] for a in lists)), start)]
    seen, out = {start}, []
    while heap and len(out) < k:
        total, pick = heapq.heappop(heap)
        out.append((total, pick))
        for i, a in enumerate(lists):
            if pick[i] + 1 < len(a):
                nxt = pick[:i] + (pick[i] + 1,) + pick[i + 1:]
                if nxt not in seen:
                    seen.add(nxt)
                    heapq.heappush(heap, (total - a[pick[i]] + a[pick[i] + 1], nxt))
    return out


def ranked_window(wp: WindowProblem, k: int, solver: str = "auto", **options: Any
                  ) -> tuple[list[float], list[np.ndarray], Any]:
    """The ``k`` best global hypotheses, best first: costs, choices, the core's ranking.

    :func:`assocopt.kbest` ranks the distinct tuples; each of its solutions stands for
    every combination of same-tuple hypotheses (same cost or dearer), so the ``k``
    best of the expansions of its ``k`` best solutions are the ``k`` best global
    hypotheses (a solution ranked below ``k`` costs at least the ``k``-th of them).
    """
    if wp.drop_dominated:
        raise ValueError("ranked_window needs the full window problem: build it with "
                         "drop_dominated=False (dominated hypotheses rank below the best)")
    ranked = kbest(wp.problem, k, solver=solver, **options)
    members: dict[int, np.ndarray] = {}
    ok = np.flatnonzero(wp.candidate >= 0)
    if len(ok) > wp.n_hypotheses:                   # some tuples stand for several
        order = ok[np.lexsort((wp.cost[ok], wp.candidate[ok]))]
        bounds = np.searchsorted(wp.candidate[order], np.arange(wp.n_hypotheses + 1))
        for u in np.flatnonzero(np.diff(bounds) > 1):
            members[int(u)] = order[bounds[u]:bounds[u + 1]]
    found = []
    for rank, sol in enumerate(ranked):
        base = chosen_hypotheses(wp, sol)
        extra = [t for t in range(wp.n_tracks) if int(wp.candidate[base[t]]) in members]
        alts = [members[int(wp.candidate[base[t]])] for t in extra]
        for total, pick in _k_smallest_sums([wp.cost[a] - wp.cost[a[0]] for a in alts], k):
            choice = base.copy()
            for t, a, i in zip(extra, alts, pick):
                choice[t] = a[i]
            found.append((float(sol.objective) + total, rank, pick, choice))
    found.sort(key=lambda f: (f[0], f[1], f[2]))
    return [float(f[0]) for f in found[:k]], [f[3] for f in found[:k]], ranked


def nscan_prune(track, labels, best: Sequence[np.ndarray], n_old: int = 1) -> np.ndarray:
    """n-scan pruning: which hypotheses to keep (boolean mask).

    Keeps hypothesis ``h`` when, on the ``n_old`` oldest scans of the window, its
    ``labels`` equal those of the hypothesis chosen for its track by one of the
    global hypotheses in ``best`` (one: the best; several: the union of the k best).

    Parameters
    ----------
    track : (H,) int
    labels : (H, L, ...) array
        What must agree per scan (measurement ids; with (measurement, hypothesiser)
        tags both, as Stone Soup compares them).
    best : sequence of (T,) int arrays
        Chosen hypothesis per track of each global hypothesis kept.
    n_old : int
        Scans that leave the window at the next scan (1 when pruning every scan).
    """
    track = np.asarray(track, np.int64)
    labels = np.asarray(labels)
    old = labels[:, :n_old].reshape(len(labels), -1)
    keep = np.zeros(len(track), bool)
    for choice in best:
        keep |= (old == old[np.asarray(choice, np.int64)[track]]).all(axis=1)
    return keep


def tag_arrays(tags: Sequence[Sequence], window: int) -> tuple[np.ndarray, np.ndarray]:
    """Stone Soup MFA tags as arrays over the window's ``window`` last scans.

    A tag lists one entry per scan: a detection index (1-based, 0 = missed;
    :class:`~stonesoup.hypothesiser.mfa.MFAHypothesiser`) or a pair (detection index,
    hypothesiser index) (``MHMFAHypothesiser``).  Tags shorter than the window are
    padded at the front with misses, as Stone Soup does.

    Returns
    -------
    history : (H, window) int64
        Detection index per scan (the problem's slots).
    labels : (H, window, 2) int64
        (detection index, hypothesiser index) per scan (-1 as the padding's
        hypothesiser index; 0 throughout for plain tags): what :func:`nscan_prune`
        compares.
    """
    if isinstance(window, bool) or int(window) != window or window < 1:
        raise ValueError(f"window must be a positive integer, got {window!r}")
    window = int(window)
    first = next((tag[-1] for tag in tags if len(tag)), 0)
    pairs = isinstance(first, (tuple, list, np.ndarray))
    pad = [(0, -1)] if pairs else [0]
    try:
        arr = np.array([pad * (window - len(tag)) + list(tag[-window:]) for tag in tags],
                       dtype=np.int64)
    except (TypeError, ValueError) as exc:
        raise ValueError("tags must all hold detection indices, or all (detection, "
                         f"hypothesiser) pairs: {exc}") from None
    if pairs:
        if arr.ndim != 3 or arr.shape[2] != 2:
            raise ValueError(f"tag entries must be (detection, hypothesiser) pairs, got "
                             f"an array of shape {arr.shape}")
        return arr[:, :, 0].copy(), arr
    arr = arr.reshape(len(tags), window)
    return arr, np.stack([arr, np.zeros_like(arr)], axis=2)


def log_costs(weights: Sequence) -> np.ndarray:
    """:func:`log_cost` of every weight, in one pass when all are ``Probability``
    (their ``log_value`` read directly; no per-weight type test)."""
    try:
        return -np.fromiter((w.log_value for w in weights), np.float64, len(weights))
    except AttributeError:
        return np.array([log_cost(w) for w in weights], np.float64)


def log_cost(weight: Any) -> float:
    """``-log(weight)`` of a float or a Stone Soup ``Probability`` (its log kept exact)."""
    log_value = getattr(weight, "log_value", None)
    if log_value is not None:
        return -float(log_value)
    w = float(weight)
    return math.inf if w == 0 else -math.log(w)
