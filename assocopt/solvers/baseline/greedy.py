"""Greedy heuristic: take candidates in increasing cost while they fit.

The classic baseline of tracking (global nearest neighbour done greedily).  Slack
candidates (the free surplus indices of rectangular dense problems) are considered
last, so they never block a real assignment.  With dummies for every index (S-D
problems with single-measurement tuples, 2-D with miss costs) or a full dense tensor
it always completes; otherwise it may reach a dead end, reported as ``ERROR`` with the
uncovered index (the instance may still be feasible).
"""

from __future__ import annotations

import time

import numpy as np

from ...problems.problem import AssignmentProblem
from ...model.solution import Status
from ..base import Backend, RawResult, SolveOptions, register

__all__ = ["GreedyBackend", "greedy_select", "take_in_order"]


def greedy_select(problem: AssignmentProblem) -> tuple[np.ndarray, np.ndarray]:
    """Greedy selection; returns (selected positions, covered-row mask)."""
    order = np.lexsort((np.arange(problem.n_candidates), problem.costs, problem.slack))
    return take_in_order(problem, order)


def take_in_order(problem: AssignmentProblem, order: np.ndarray
                  ) -> tuple[np.ndarray, np.ndarray]:
    """Candidates taken in ``order`` while they fit: (selected positions, sorted, and
    the covered-row mask); stops once every row is covered.

    The sequential scan is inherent to the rule; its per-candidate work is a few
    array lookups on the precomputed row indices (no model is built).
    """
    rows = problem.entry_rows
    covered = np.zeros(problem.n_rows + 1, dtype=bool)   # last slot absorbs the -1 rows
    chosen = []
    remaining = problem.n_rows
    for k in np.asarray(order).tolist():
        if remaining == 0:
            break
        r = rows[k]
        if covered[r].any():
            continue
        covered[r] = True
        covered[-1] = False
        chosen.append(k)
        remaining -= int((r >= 0).sum())
    return np.array(sorted(chosen), dtype=np.int64), covered[:-1]


@register
class GreedyBackend(Backend):
    """Greedy by increasing cost; feasible, not optimal, no bound."""

    name = "greedy"
    description = "greedy by increasing cost (heuristic baseline, no bound)"
    exact = False
    gives_bound = False

    own_method = True

    def solve(self, problem: AssignmentProblem, options: SolveOptions) -> RawResult:
        self.settings(problem, options)          # no options of its own: rejects any
        t0 = time.perf_counter()
        selected, covered = greedy_select(problem)
        dt = time.perf_counter() - t0
        if not covered.all():
            label = problem.row_label(int(np.flatnonzero(~covered)[0]))
            return RawResult(Status.ERROR, solve_time=dt,
                             message=f"greedy reached a dead end: {label} "
                                     "cannot be covered by a remaining candidate "
                                     "(the instance may still be feasible)")
        return RawResult(Status.FEASIBLE, selected=selected, solve_time=dt,
                         message="greedy: feasible, not proven optimal")
