"""Helpers for users' own test suites: random problems and optimality assertions.

>>> import numpy as np
>>> from assocopt import solve
>>> from assocopt.testing import random_problem, assert_optimal
>>> p = random_problem(np.random.default_rng(0), "sd", sizes=(3, 3, 2))
>>> assert_optimal(p, solve(p, "highs"))

``problems()`` is a hypothesis strategy (hypothesis is imported only when it is
called, so this module works without it).
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from .problem import AssignmentProblem
from .solution import Solution, Status

__all__ = ["KINDS", "random_problem", "problems", "assert_optimal", "assert_feasible",
           "BRUTE_FORCE_MAX_CANDIDATES"]

#: Problem families produced by :func:`random_problem`.
KINDS = ("square", "rect", "miss", "axial3", "axial4", "sd")

#: Largest candidate count for which :func:`assert_optimal` runs brute force.
BRUTE_FORCE_MAX_CANDIDATES = 400


def _costs(rng: np.random.Generator, shape: Any, integer: bool) -> np.ndarray:
    if integer:   # small integers create ties: the hard case for index bookkeeping
        return rng.integers(-5, 20, size=shape).astype(float)
    return rng.normal(size=shape)


def random_problem(rng: np.random.Generator, kind: str, sizes: tuple[int, ...] | None = None,
                   *, integer: bool = False, forbid: float = 0.0,
                   keep: float = 0.6) -> AssignmentProblem:
    """A random feasible problem of family ``kind`` (see :data:`KINDS`).

    ``forbid``: share of all-real candidates made ``inf`` (forbidden) where that
    keeps the problem feasible (families with dummies).  ``keep``: for ``"sd"``, the
    share of multi-index tuples kept (single-index dummy tuples are always kept, so
    the S-D problem is always feasible).
    """
    if kind not in KINDS:
        raise ValueError(f"kind must be one of {KINDS}, got {kind!r}")
    if kind == "square":
        n = sizes[0] if sizes else int(rng.integers(1, 6))
        return AssignmentProblem.dense(_costs(rng, (n, n), integer))
    if kind == "rect":
        shape = sizes or tuple(int(v) for v in rng.integers(1, 6, size=2))
        return AssignmentProblem.dense(_costs(rng, shape, integer))
    if kind == "miss":
        n1, n2 = sizes or tuple(int(v) for v in rng.integers(1, 5, size=2))
        C = _costs(rng, (n1, n2), integer)
        C[rng.random(C.shape) < forbid] = np.inf
        return AssignmentProblem.two_d(C, row_miss=np.abs(_costs(rng, n1, integer)),
                                       col_miss=np.abs(_costs(rng, n2, integer)))
    if kind in ("axial3", "axial4"):
        N = 3 if kind == "axial3" else 4
        shape = sizes or (int(rng.integers(1, 5 if N == 3 else 4)),) * N
        return AssignmentProblem.dense(_costs(rng, shape, integer))
    return _random_sd(rng, sizes, integer, keep)


def _random_sd(rng: np.random.Generator, sizes: tuple[int, ...] | None, integer: bool,
               keep: float) -> AssignmentProblem:
    sizes = sizes or tuple(int(v) for v in rng.integers(1, 4, size=int(rng.integers(3, 5))))
    grids = np.meshgrid(*[np.arange(n + 1) for n in sizes], indexing="ij")
    T = np.stack([g.ravel() for g in grids], axis=1)
    n_real = (T > 0).sum(axis=1)
    T = T[(n_real == 1) | ((n_real >= 2) & (rng.random(len(T)) < keep))]
    costs = _costs(rng, len(T), integer)
    single = (T > 0).sum(axis=1) == 1
    costs[single] = np.abs(costs[single])   # false alarms: a non-negative cost
    return AssignmentProblem.sparse(sizes, T, costs)


def problems(kinds: tuple[str, ...] = KINDS, integer: bool | None = None) -> Any:
    """Hypothesis strategy of small random problems (brute force stays fast)."""
    from hypothesis import strategies as st

    @st.composite
    def _draw(draw: Any) -> AssignmentProblem:
        kind = draw(st.sampled_from(kinds))
        seed = draw(st.integers(0, 2**32 - 1))
        use_int = draw(st.booleans()) if integer is None else integer
        return random_problem(np.random.default_rng(seed), kind, integer=use_int,
                              forbid=draw(st.sampled_from([0.0, 0.3])))
    return _draw()


def assert_feasible(problem: AssignmentProblem, solution: Solution) -> None:
    """The solution covers every real index exactly once and its objective adds up."""
    assert solution.selected is not None, (
        f"no solution attached: status={solution.status}, message={solution.message!r}")
    why = problem.violations(solution.selected)
    assert why is None, f"infeasible solution from {solution.solver}: {why}"
    total = problem.objective_of(solution.selected)
    assert math.isclose(total, solution.objective, rel_tol=1e-9, abs_tol=1e-9), (
        f"objective {solution.objective} != sum of chosen costs {total}")


def _reference_optimum(problem: AssignmentProblem) -> tuple[float, str]:
    from .api import solve
    if problem.optimum is not None:
        return float(problem.optimum), "recorded optimum"
    if problem.n_candidates <= BRUTE_FORCE_MAX_CANDIDATES:
        ref = solve(problem, "bruteforce")
        if ref.status is Status.OPTIMAL:
            return float(ref.objective), "brute force"
    ref = solve(problem, "highs")
    assert ref.status is Status.OPTIMAL, f"HiGHS could not prove a reference: {ref.message}"
    return float(ref.objective), "HiGHS"


def assert_optimal(problem: AssignmentProblem, solution: Solution, *,
                   rel: float = 1e-9, abs_tol: float = 1e-9) -> None:
    """Assert ``solution`` is feasible and optimal for ``problem``.

    The reference is the recorded optimum if the problem carries one, brute force on
    small problems, HiGHS otherwise.  The failure message names the solver, its
    status and message.
    """
    assert solution.status is Status.OPTIMAL, (
        f"{solution.solver}: status {solution.status}, message {solution.message!r}")
    assert_feasible(problem, solution)
    ref, how = _reference_optimum(problem)
    assert math.isclose(solution.objective, ref, rel_tol=rel, abs_tol=abs_tol), (
        f"{solution.solver}: objective {solution.objective!r} != {how} {ref!r} "
        f"({solution.message})")
    if solution.bound is not None:
        assert solution.bound <= solution.objective + abs_tol + rel * abs(ref)
