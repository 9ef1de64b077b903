"""Exhaustive enumeration of every feasible solution: the test oracle for tiny problems.

A feasible solution is an *exact cover* of the real indices by candidate tuples.
The search branches on the lowest uncovered real index (every feasible solution
covers it with exactly one candidate), so each exact cover is produced exactly once,
and takes the minimum of the enumerated costs.  No bounding, no pruning by cost: the
oracle must be simple enough to trust.

:func:`enumerate_solutions` is public: paper 002's "solution discrimination" needs
the costs of *all* feasible solutions.
"""

from __future__ import annotations

import math
import time
from typing import Iterator

import numpy as np

from ...problems.problem import AssignmentProblem
from ...model.solution import Status
from ..base import Backend, Option, RawResult, SolveOptions, register

__all__ = ["BruteForceBackend", "enumerate_solutions", "count_solutions"]

#: Default cap on search nodes; beyond it the search stops with NODE_LIMIT.
DEFAULT_MAX_NODES = 2_000_000


class _NodeLimit(Exception):
    pass


class _OutOfTime(Exception):
    pass


#: Candidates whose bit masks are built between two looks at the clock.
_MASK_CHUNK = 4096


def _candidate_masks(problem: AssignmentProblem, deadline: float | None = None
                     ) -> tuple[list[int], list[list[int]]]:
    """Bit mask of covered rows per candidate; candidates covering each row (in
    candidate order).  Straight from the tuple array: no scipy.sparse to import.
    Past ``deadline`` (looked at every :data:`_MASK_CHUNK` candidates) it raises
    :class:`TimeoutError`: the masks of Grundel n = 50 took 6 s on loaded cores."""
    T = problem.tuples
    real = T > 0
    rows = np.where(real, T - 1 + problem.row_offsets[None, :], -1)
    masks: list[int] = []
    for lo in range(0, len(rows), _MASK_CHUNK):
        if deadline is not None and time.perf_counter() > deadline:
            raise TimeoutError("brute force stopped by the time limit before its search")
        masks += [sum(1 << r for r in row if r >= 0)
                  for row in rows[lo:lo + _MASK_CHUNK].tolist()]
    ks = np.broadcast_to(np.arange(len(T))[:, None], T.shape)[real]
    rs = rows[real]
    order = np.lexsort((ks, rs))
    splits = np.cumsum(np.bincount(rs, minlength=problem.n_rows))[:-1]
    by_row = [part.tolist() for part in np.split(ks[order], splits)]
    return masks, by_row


def enumerate_solutions(problem: AssignmentProblem, *, max_nodes: int = DEFAULT_MAX_NODES,
                        deadline: float | None = None) -> Iterator[np.ndarray]:
    """Yield the candidate positions of every feasible solution, each exactly once.

    ``deadline`` (a ``time.perf_counter()`` value) stops the search with
    :class:`TimeoutError` when passed; the clock is read every 4096 candidates while
    their bit masks are built (0.6-6 s for Grundel n = 50 under load) and every 256 nodes (a node can
    scan thousands of candidates of its row: 1024 nodes overshot a 1 s limit by 0.6 s).

    Raises
    ------
    assocopt.ProblemTooLargeError
        If the search visits more than ``max_nodes`` nodes.

    Examples
    --------
    >>> from assocopt import AssignmentProblem
    >>> p = AssignmentProblem.dense([[1.0, 2.0], [3.0, 4.0]])
    >>> sorted(s.tolist() for s in enumerate_solutions(p))
    [[0, 3], [1, 2]]
    """
    from ...runtime.errors import ProblemTooLargeError

    masks, by_row = _candidate_masks(problem, deadline)
    if deadline is not None and time.perf_counter() > deadline:
        raise TimeoutError("brute force stopped by the time limit before its search")
    full = (1 << problem.n_rows) - 1
    nodes = 0
    chosen: list[int] = []

    def search(covered: int) -> Iterator[np.ndarray]:
        nonlocal nodes
        if covered == full:
            yield np.array(sorted(chosen), dtype=np.int64)
            return
        free = ~covered & full
        row = (free & -free).bit_length() - 1        # lowest uncovered row
        for k in by_row[row]:
            if masks[k] & covered:
                continue
            nodes += 1
            if nodes > max_nodes:
                raise _NodeLimit
            if deadline is not None and not nodes & 255 and time.perf_counter() > deadline:
                raise _OutOfTime
            chosen.append(k)
            yield from search(covered | masks[k])
            chosen.pop()

    try:
        yield from search(0)
    except _NodeLimit:
        raise ProblemTooLargeError(
            f"brute force visited more than {max_nodes} nodes; the instance is too large "
            "for exhaustive enumeration (raise max_nodes or use an exact MIP back end)"
        ) from None
    except _OutOfTime:
        raise TimeoutError(f"brute force stopped by the time limit after {nodes} nodes") \
            from None


def count_solutions(problem: AssignmentProblem, *, max_nodes: int = DEFAULT_MAX_NODES) -> int:
    """Number of feasible solutions (exact covers)."""
    return sum(1 for _ in enumerate_solutions(problem, max_nodes=max_nodes))


@register
class BruteForceBackend(Backend):
    """Exact by enumeration; for tiny instances and as the test oracle.

    Extra option ``max_nodes`` (default 2,000,000): past it the search stops with
    ``NODE_LIMIT`` and the best solution seen so far, if any (a ``time_limit`` that
    runs out first gives ``TIME_LIMIT``).
    """

    name = "bruteforce"
    description = "exhaustive enumeration of exact covers (tiny instances, test oracle)"
    options = (Option("max_nodes", "int", DEFAULT_MAX_NODES,
                      "search nodes; past them the search stops with node_limit", low=1),)
    supports_time_limit = True

    own_method = True

    def solve(self, problem: AssignmentProblem, options: SolveOptions) -> RawResult:
        from ...runtime.errors import ProblemTooLargeError

        max_nodes = self.settings(problem, options)["max_nodes"]
        t0 = time.perf_counter()
        deadline = None if options.time_limit is None else t0 + options.time_limit
        best, best_cost, count = None, math.inf, 0
        costs = problem.costs
        try:
            for sel in enumerate_solutions(problem, max_nodes=max_nodes, deadline=deadline):
                count += 1
                cost = math.fsum(costs[sel].tolist())
                if cost < best_cost:
                    best, best_cost = sel, cost
        except (ProblemTooLargeError, TimeoutError) as exc:
            status = Status.NODE_LIMIT if isinstance(exc, ProblemTooLargeError) \
                else Status.TIME_LIMIT
            return RawResult(status, selected=best, message=str(exc),
                             info={"solutions_seen": count},
                             solve_time=time.perf_counter() - t0)
        dt = time.perf_counter() - t0
        if best is None:
            return RawResult(Status.INFEASIBLE, message="bruteforce: no exact cover exists",
                             info={"solutions": 0}, solve_time=dt)
        return RawResult(Status.OPTIMAL, selected=best, bound=best_cost,
                         message=f"bruteforce: best of {count} feasible solutions",
                         info={"solutions": count}, solve_time=dt)
