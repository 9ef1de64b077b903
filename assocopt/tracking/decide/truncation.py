"""Observation-sequence truncation, paper 000's decision rule "MD-ND" (docs/papers/zhang2009.md).

Input: the pooled matching-measure matrix ``pi`` (``N x N``, similarity, diagonal
unused) and each observation's sensor.  Three steps:

A. **Sequence construction** -- single-linkage ordering of the observations,
   giving ``v_1 .. v_N`` and ``l_1 .. l_{N-1}`` (Prim's algorithm on the
   similarity, ``l_{n-1}`` the value at which ``v_n`` joins; or the leaf order of the
   single-linkage dendrogram; the paper does not spell the ordering out).
B. **Coarse truncation** -- ``f(1) = 1``, ``f(n) = l_{n-1}`` (eq. 13); cut just before
   ``v_i`` when ``f(i) < f(i+1)``, ``i = 2 .. N-1``.  Inside a segment ``l_{t,k}`` joins
   ``v_{t,k}`` and ``v_{t,k+1}``; the link to the previous segment is dropped.
C. **Fine truncation** -- the paper's Steps 1-2 on each segment, literally, with the
   readings of the fine truncation the paper leaves open as named
   options (:class:`TruncationOptions`).

Every observation ends in exactly one relation (matched pair or isolated): the
result is a :class:`~assocopt.tracking.belief.group_matching.Relations`, which checks it.

A derived property (D, checked by the tests on random inputs under every
combination of options): with undecided nodes isolated at the end, Step C's
*partition* does not depend on those readings.  It matches exactly the
cross-sensor pairs ``(v_{t,m}, v_{t,m+1})`` whose measure ``l_{t,m}`` is a strict
local maximum of ``c^l_t`` (an end measure compared with its one neighbour; a
two-node segment always matches when its nodes come from different sensors), and
isolates every other node.  Reason: a pair can only be matched at the step of its
own measure, the match conditions are exactly the strict local-maximum tests, and
at that step neither node can have been decided (only the steps of the two
neighbouring, smaller measures touch them, and they come later).  The readings
change only which clause isolates a node.  The options are kept so that every
reading is recorded; what does change the result is Step A (ordering, start node,
ties) and Step B.

Examples
--------
Two well-separated cross-sensor pairs (0, 2) and (1, 3) and an isolated sensor-2
observation 4:

>>> import numpy as np
>>> pi = np.array([[np.nan, .01, .90, .02, .05],
...                [.01, np.nan, .03, .80, .04],
...                [.90, .03, np.nan, .02, .06],
...                [.02, .80, .02, np.nan, .01],
...                [.05, .04, .06, .01, np.nan]])
>>> rel = md_nd(pi, [1, 1, 2, 2, 2])
>>> rel.pairs, rel.isolated
(((0, 2), (1, 3)), (4,))
"""

from __future__ import annotations

from dataclasses import asdict, dataclass, field
from typing import Any, Sequence

import numpy as np
from numpy.typing import ArrayLike

from ..belief.group_matching import Relations

__all__ = ["ORDERINGS", "TIE_BREAKS", "TRAVERSED_READINGS", "VISITED_READINGS",
           "MIDDLE_RULES", "TruncationOptions", "TruncationResult", "single_linkage_order",
           "coarse_truncation", "fine_truncation", "truncate", "md_nd", "check_pi"]

#: Step A (not spelled out by the paper): Prim order or single-linkage dendrogram leaf order.
ORDERINGS = ("prim", "dendrogram")
#: Ties between equal measures (Prim's next node, Step 1's largest measure): lowest
#: or highest index first.
TIE_BREAKS = ("lowest", "highest")
#: When the measure chosen in Step 1 counts as traversed: at once ("on_selection",
#: so the "every element traversed" tests include it) or only after the step.
TRAVERSED_READINGS = ("on_selection", "after_step")
#: What V_ed ("traversed nodes") holds: nodes already decided, or every endpoint of
#: a measure selected in an earlier step.
VISITED_READINGS = ("decided", "endpoints")
#: Step 2(2)(a)(ii): test ``l_m <= l_{m-1}`` first and decide one node ("first"), or
#: apply both sub-rules ("both").
MIDDLE_RULES = ("first", "both")


@dataclass(frozen=True)
class TruncationOptions:
    """The readings of Steps A-C the paper leaves open (docs/papers/zhang2009.md).

    Defaults are the readings the reproduction uses.  ``start`` is the pooled index of
    Step A's first node (``0``: the first observation of sensor 1; ignored by the
    dendrogram ordering).  Fixed readings, recorded by :meth:`as_dict`: an empty
    ``V_t`` goes back to Step 1, a single-node segment is an isolated point, and any
    node still undecided when a segment's Step 1 ends is isolated.
    """

    ordering: str = "prim"
    start: int = 0
    tie_break: str = "lowest"
    traversed: str = "on_selection"
    visited: str = "decided"
    middle_rule: str = "first"

    def __post_init__(self) -> None:
        for name, allowed in (("ordering", ORDERINGS), ("tie_break", TIE_BREAKS),
                              ("traversed", TRAVERSED_READINGS),
                              ("visited", VISITED_READINGS), ("middle_rule", MIDDLE_RULES)):
            if getattr(self, name) not in allowed:
                raise ValueError(f"{name} must be one of {allowed}, got {getattr(self, name)!r}")
        if not (isinstance(self.start, (int, np.integer)) and self.start >= 0):
            raise ValueError(f"start must be a non-negative index, got {self.start!r}")

    def as_dict(self) -> dict[str, Any]:
        d = asdict(self)
        d.update(empty_V="back to Step 1", single_node_segment="isolated",
                 undecided_at_end="isolated")
        return d


@dataclass(frozen=True)
class TruncationResult:
    """Relations plus the intermediate sequences, for inspection and tests.

    ``order``: ``v`` (pooled indices); ``measures``: ``l`` (``len(order) - 1``);
    ``segments``: ``(first, last)`` positions in ``order`` of each candidate cluster
    (inclusive).
    """

    relations: Relations
    order: np.ndarray
    measures: np.ndarray
    segments: tuple[tuple[int, int], ...]
    options: TruncationOptions = field(default_factory=TruncationOptions)


def check_pi(pi: ArrayLike, sensor: ArrayLike) -> tuple[np.ndarray, np.ndarray]:
    """Validate a pooled matrix ``pi`` (N x N, finite off the diagonal) and sensor labels."""
    P = np.asarray(pi, dtype=np.float64)
    s = np.asarray(sensor)
    if P.ndim != 2 or P.shape[0] != P.shape[1]:
        raise ValueError(f"pi must be a square matrix, got shape {P.shape}")
    if s.shape != (len(P),):
        raise ValueError(f"sensor must have shape ({len(P)},), got {s.shape}")
    if not np.isin(s, (1, 2)).all():
        raise ValueError("sensor labels must be 1 or 2")
    off = ~np.eye(len(P), dtype=bool)
    if not np.isfinite(P[off]).all():
        raise ValueError("pi must be finite off the diagonal")
    return P, s.astype(np.int64)


# ------------------------------------------------------------------ Step A
def single_linkage_order(pi: ArrayLike, *, start: int = 0, tie_break: str = "lowest",
                         ordering: str = "prim") -> tuple[np.ndarray, np.ndarray]:
    """Step A: the observation sequence ``v`` and measure sequence ``l``.

    ``"prim"``: ``v_1 = start``; each next node is the unvisited ``w``
    maximising ``max_{u visited} pi[u, w]``, and ``l_{n-1}`` is that maximum.
    ``"dendrogram"``: leaf order of scipy's single-linkage dendrogram on the
    dissimilarity ``max(pi) - pi``, with ``l_n`` the similarity at which ``v_n`` and
    ``v_{n+1}`` merge.
    """
    P = np.asarray(pi, dtype=np.float64)
    n = len(P)
    if n == 0:
        return np.zeros(0, np.int64), np.zeros(0)
    if ordering == "dendrogram":
        return _dendrogram_order(P)
    if ordering != "prim":
        raise ValueError(f"ordering must be one of {ORDERINGS}, got {ordering!r}")
    if not 0 <= start < n:
        raise ValueError(f"start must be in 0..{n - 1}, got {start}")
    visited = np.zeros(n, dtype=bool)
    visited[start] = True
    best = np.where(np.arange(n) == start, -np.inf, P[start])
    order = [start]
    levels = []
    for _ in range(n - 1):
        cand = np.where(visited, -np.inf, best)
        w = int(np.argmax(cand)) if tie_break == "lowest" else n - 1 - int(np.argmax(cand[::-1]))
        order.append(w)
        levels.append(cand[w])
        visited[w] = True
        best = np.fmax(best, P[w])        # fmax skips the NaN diagonal
    return np.asarray(order, np.int64), np.asarray(levels, np.float64)


def _dendrogram_order(P: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    from scipy.cluster.hierarchy import cophenet, leaves_list, linkage
    from scipy.spatial.distance import squareform
    n = len(P)
    if n == 1:
        return np.zeros(1, np.int64), np.zeros(0)
    S = np.where(np.eye(n, dtype=bool), np.nan, P)
    S = 0.5 * (S + S.T)
    top = np.nanmax(S)
    D = top - S
    np.fill_diagonal(D, 0.0)
    Z = linkage(squareform(D, checks=False), method="single")
    order = leaves_list(Z).astype(np.int64)
    coph = squareform(cophenet(Z))
    return order, top - coph[order[:-1], order[1:]]


# ------------------------------------------------------------------ Step B
def coarse_truncation(measures: ArrayLike) -> list[tuple[int, int]]:
    """Step B: segments ``(first, last)`` (inclusive positions in ``v``).

    With ``f = [1, l_1, ..., l_{N-1}]`` (eq. 13, 1-based), cut just before ``v_i``
    when ``f(i) < f(i+1)`` for ``i = 2 .. N-1``; in 0-based positions: cut before
    position ``p`` when ``l[p-1] < l[p]``, ``p = 1 .. N-2``.
    """
    L = np.asarray(measures, dtype=np.float64)
    n = len(L) + 1
    cuts = [p for p in range(1, n - 1) if L[p - 1] < L[p]]
    bounds = [0] + cuts + [n]
    return [(bounds[k], bounds[k + 1] - 1) for k in range(len(bounds) - 1)]


# ------------------------------------------------------------------ Step C
def fine_truncation(nodes: Sequence[int], measures: Sequence[float], sensor: ArrayLike,
                    options: TruncationOptions | None = None) -> list[tuple[int, ...]]:
    """Step C on one segment: clusters of one (isolated) or two (matched) nodes.

    ``nodes``: ``v_{t,1} .. v_{t,n+1}`` (pooled indices); ``measures``:
    ``l_{t,1} .. l_{t,n}`` (``l_{t,k}`` between nodes k and k+1); ``sensor``: pooled
    sensor labels.  Implements Steps 1-2 of the paper's truncation literally.
    """
    opt = options or TruncationOptions()
    c = [int(x) for x in nodes]
    L = [float(x) for x in measures]
    n = len(L)
    if len(c) != n + 1:
        raise ValueError(f"a segment of {len(c)} nodes needs {len(c) - 1} measures, got {n}")
    s = np.asarray(sensor)
    if n == 0:
        return [(c[0],)]
    traversed = [False] * n
    decided: set[int] = set()
    endpoints: set[int] = set()
    clusters: list[tuple[int, ...]] = []

    def in_ved(x: int) -> bool:
        return x in decided or (opt.visited == "endpoints" and x in endpoints)

    def isolate(x: int) -> None:
        clusters.append((x,))
        decided.add(x)

    def isolate_rest() -> None:
        for x in [x for x in c if not in_ved(x)]:
            isolate(x)

    def match(x: int, y: int) -> None:
        clusters.append((x, y))
        decided.update((x, y))

    while not all(traversed):
        # Step 1: the largest untraversed measure (ties: option)
        cand = [k for k in range(n) if not traversed[k]]
        key = (lambda k: (L[k], -k)) if opt.tie_break == "lowest" else (lambda k: (L[k], k))
        k = max(cand, key=key)
        m = k + 1                                   # the paper's 1-based m
        if opt.traversed == "on_selection":
            traversed[k] = True
            all_done = all(traversed)
        else:
            all_done = False                        # m itself is not yet traversed
        a, b = c[k], c[k + 1]
        V = [x for x in (a, b) if not in_ved(x)]
        stop = _step2(V, m, n, L, s, all_done, opt, isolate, isolate_rest, match)
        traversed[k] = True
        endpoints.update((a, b))
        if stop:
            break
    for x in c:                                     # our reading: undecided at the end: isolated
        if x not in decided:
            isolate(x)
    return clusters


def _step2(V, m, n, L, s, all_done, opt, isolate, isolate_rest, match) -> bool:
    """Step 2 for the chosen measure ``l_m`` (1-based); True when the segment ends."""
    if not V:
        return False                                # our reading: empty V_t: back to Step 1
    if len(V) == 1:
        isolate(V[0])
        return False
    x, y = V
    lm = L[m - 1]
    if s[x] == s[y]:                                # (1) same sensor
        if all_done:
            isolate_rest()
        elif m == 1:
            isolate(x)
        elif m == n:
            isolate(y)
        return False
    if 2 <= m <= n - 1:                             # (2)(a)
        left, right = L[m - 2], L[m]
        if lm > right and lm > left:
            match(x, y)
        elif lm <= left:
            isolate(x)
            if opt.middle_rule == "both" and lm <= right:
                isolate(y)
        elif lm <= right:
            isolate(y)
        return False
    if n == 1:                                      # (2)(b)(i)
        match(x, y)
        return True
    holds = lm > L[1] if m == 1 else lm > L[n - 2]  # (2)(b)(ii)
    if holds:
        match(x, y)
    elif all_done:
        isolate_rest()
    else:
        isolate(x if m == 1 else y)
    return False


# --------------------------------------------------------------- together
def truncate(pi: ArrayLike, sensor: ArrayLike,
             options: TruncationOptions | None = None) -> TruncationResult:
    """Steps A-C on a pooled matrix ``pi``; returns relations and intermediate sequences."""
    opt = options or TruncationOptions()
    P, s = check_pi(pi, sensor)
    n = len(P)
    if n and opt.start >= n:
        raise ValueError(f"start = {opt.start} is not an observation index (N = {n})")
    v, l = single_linkage_order(P, start=opt.start, tie_break=opt.tie_break,
                                ordering=opt.ordering)
    segments = coarse_truncation(l) if n else []
    clusters: list[tuple[int, ...]] = []
    for first, last in segments:
        clusters += fine_truncation(v[first:last + 1], l[first:last], s, opt)
    return TruncationResult(Relations.from_clusters(clusters, s), v, l, tuple(segments), opt)


def md_nd(pi: ArrayLike, sensor: ArrayLike,
          options: TruncationOptions | None = None) -> Relations:
    """Paper 000's decision "MD-ND": the relations found by :func:`truncate`."""
    return truncate(pi, sensor, options).relations
