"""Helpers for users' own test suites: random problems and optimality assertions.

>>> import numpy as np
>>> from assocopt import solve
>>> from assocopt.testing import random_problem, assert_optimal
>>> p = random_problem(np.random.default_rng(0), "sd", sizes=(3, 3, 2))
>>> assert_optimal(p, solve(p, "highs"))

``problems()`` and ``generated_problems()`` are hypothesis strategies (hypothesis is
imported only when they are called, so this module works without it; without it
they raise an ImportError naming the package);
``stored_instances()`` lists the project's instances with proven optima, for
``pytest.mark.parametrize``:

>>> from assocopt.io import read_instance
>>> from assocopt.testing import stored_instances
>>> for path in stored_instances():
...     p = read_instance(path)
...     assert_optimal(p, solve(p, "highs"))
"""

from __future__ import annotations

import math
import os
from pathlib import Path
from typing import Any, Sequence

import numpy as np

from .problems.problem import AssignmentProblem
from .model.solution import Solution, Status

__all__ = ["KINDS", "random_problem", "random_scans", "problems", "generated_problems", "assert_optimal",
           "assert_feasible", "assert_valid_bound", "reference_optimum", "stored_instances",
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


def random_scans(rng: np.random.Generator, n_sensors: int, n_targets: int, *,
                 pd: float, clutter: float, sigma: float) -> list[np.ndarray]:
    """One scan per sensor of ``n_targets`` targets placed uniformly in the unit square:
    each target is detected with probability ``pd`` and seen with Gaussian position
    noise ``sigma``, plus Poisson(``clutter``) false alarms uniform in the square; each
    scan is an ``(M_s, 2)`` array in random order (the measurements behind
    tracking-like S-D test problems).

    >>> scans = random_scans(np.random.default_rng(0), 3, 4, pd=1.0, clutter=0.0, sigma=0.01)
    >>> [z.shape for z in scans]
    [(4, 2), (4, 2), (4, 2)]
    """
    targets = rng.random((n_targets, 2))
    scans = []
    for _ in range(n_sensors):
        seen = targets[rng.random(n_targets) < pd]
        fa = rng.random((rng.poisson(clutter), 2))
        z = np.concatenate([seen + rng.normal(0, sigma, seen.shape), fa])
        scans.append(z[rng.permutation(len(z))])
    return scans


def _hypothesis(helper: str = "draw_costs") -> Any:
    """``hypothesis.strategies``, or an error that says what to install (an
    ImportError, and an AssocoptError the CLI shows on one line)."""
    try:
        from hypothesis import strategies as st
    except ModuleNotFoundError as exc:
        if exc.name is None or exc.name.split(".")[0] != "hypothesis":
            raise
        from .runtime.errors import MissingDependencyError
        raise MissingDependencyError(
            f"assocopt.testing.{helper}() is a hypothesis strategy and needs the "
            "hypothesis package: pip install hypothesis (or pip install "
            "'assocopt[dev]')") from None
    return st


def _cost(st: Any, integer: bool) -> Any:
    """One cost, shrinking towards 0: a small integer (ties: the hard case for index
    bookkeeping) or a number of two decimals in [-3, 3] (not exact in binary, so sums
    carry round-off, while distinct objectives differ by far more than MIP solvers'
    absolute tolerances of about 1e-6)."""
    if integer:
        return st.integers(-5, 19).map(float)
    return st.integers(-300, 300).map(lambda v: v / 100)


def draw_costs(draw: Any, shape: Any, integer: bool, *, forbid: bool = False,
               nonnegative: bool = False) -> np.ndarray:
    """An array of drawn costs of ``shape`` (inside a ``st.composite``); ``forbid``:
    also draw which entries are ``inf``; ``nonnegative``: absolute values."""
    st = _hypothesis()
    shape = tuple(np.atleast_1d(shape)) if np.ndim(shape) else (int(shape),)
    size = int(np.prod(shape))
    vals = np.array(draw(st.lists(_cost(st, integer), min_size=size, max_size=size)),
                    dtype=np.float64).reshape(shape)
    if nonnegative:
        vals = np.abs(vals)
    if forbid and size:
        mask = draw(st.lists(st.booleans(), min_size=size, max_size=size))
        vals[np.array(mask, bool).reshape(shape)] = np.inf
    return vals


def draw_sd(draw: Any, sizes: tuple[int, ...], integer: bool) -> AssignmentProblem:
    """An S-D problem with dummies on ``sizes``: every single-index tuple (so it is
    feasible, at a non-negative cost) and a drawn subset of the multi-index ones."""
    st = _hypothesis("draw_sd")
    grids = np.meshgrid(*[np.arange(n + 1) for n in sizes], indexing="ij")
    T = np.stack([g.ravel() for g in grids], axis=1)
    n_real = (T > 0).sum(axis=1)
    multi = np.flatnonzero(n_real >= 2)
    keep = np.array(draw(st.lists(st.booleans(), min_size=len(multi), max_size=len(multi))),
                    dtype=bool)
    T = T[np.sort(np.concatenate([np.flatnonzero(n_real == 1), multi[keep]]))]
    costs = draw_costs(draw, len(T), integer)
    single = (T > 0).sum(axis=1) == 1
    costs[single] = np.abs(costs[single])   # false alarms: a non-negative cost
    return AssignmentProblem.sparse(sizes, T, costs)


def problems(kinds: tuple[str, ...] = KINDS, integer: bool | None = None) -> Any:
    """Hypothesis strategy of small problems of the families :data:`KINDS`.

    Structural: it draws the sizes, the candidate tuples and the costs themselves (not
    a seed), so a failing example shrinks to a small one with simple costs.  Sizes
    keep brute force fast.
    """
    st = _hypothesis("problems")

    @st.composite
    def _draw(draw: Any) -> AssignmentProblem:
        kind = draw(st.sampled_from(kinds))
        use_int = draw(st.booleans()) if integer is None else integer
        n = st.integers(1, 5)
        if kind == "square":
            k = draw(n)
            return AssignmentProblem.dense(draw_costs(draw, (k, k), use_int))
        if kind == "rect":
            return AssignmentProblem.dense(draw_costs(draw, (draw(n), draw(n)), use_int))
        if kind == "miss":
            n1, n2 = draw(st.integers(1, 4)), draw(st.integers(1, 4))
            C = draw_costs(draw, (n1, n2), use_int, forbid=draw(st.booleans()))
            return AssignmentProblem.two_d(
                C, row_miss=draw_costs(draw, n1, use_int, nonnegative=True),
                col_miss=draw_costs(draw, n2, use_int, nonnegative=True))
        if kind in ("axial3", "axial4"):
            N = 3 if kind == "axial3" else 4
            k = draw(st.integers(1, 4 if N == 3 else 3))
            return AssignmentProblem.dense(draw_costs(draw, (k,) * N, use_int))
        N = draw(st.integers(3, 4))
        sizes = tuple(draw(st.lists(st.integers(1, 3), min_size=N, max_size=N)))
        return draw_sd(draw, sizes, use_int)
    return _draw()


def assert_feasible(problem: AssignmentProblem, solution: Solution) -> None:
    """The solution covers every real index exactly once and its objective adds up."""
    assert solution.selected is not None, (
        f"no solution attached: status={solution.status}, message={solution.message!r}")
    why = problem.violations(solution.selected)
    assert why is None, f"infeasible solution from {solution.solver}: {why}"
    total = problem.value_of(solution.selected)
    assert math.isclose(total, solution.objective, rel_tol=1e-9, abs_tol=1e-9), (
        f"objective {solution.objective} != sum of chosen costs {total}")


def reference_optimum(problem: AssignmentProblem) -> tuple[float, str]:
    """The optimum to test against, and where it comes from.

    The recorded optimum if the problem carries one, brute force on problems of at
    most :data:`BRUTE_FORCE_MAX_CANDIDATES` candidates, HiGHS otherwise.
    """
    return _reference_optimum(problem)


def _reference_optimum(problem: AssignmentProblem) -> tuple[float, str]:
    from .solving.api import solve
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
                   rel: float = 1e-9, abs_tol: float = 1e-9,
                   reference: float | None = None) -> None:
    """Assert ``solution`` is feasible and optimal for ``problem``.

    The reference is ``reference`` when given, else the recorded optimum if the
    problem carries one, brute force on small problems, HiGHS otherwise.  The
    failure message names the solver, its status and message.
    """
    assert solution.status is Status.OPTIMAL, (
        f"{solution.solver}: status {solution.status}, message {solution.message!r}")
    assert_feasible(problem, solution)
    ref, how = ((float(reference), "the given reference") if reference is not None
                else _reference_optimum(problem))
    assert math.isclose(solution.objective, ref, rel_tol=rel, abs_tol=abs_tol), (
        f"{solution.solver}: objective {solution.objective!r} != {how} {ref!r} "
        f"({solution.message})")
    if solution.bound is not None:     # a lower bound; an upper one when maximising
        sign = -1.0 if problem.maximize else 1.0
        assert sign * solution.bound <= sign * solution.objective + abs_tol + rel * abs(ref)


def assert_valid_bound(problem: AssignmentProblem, solution: Solution, *,
                       rel: float = 1e-9, abs_tol: float = 1e-9) -> None:
    """Assert the lower bound of ``solution`` does not exceed the optimum (for a
    ``maximize=True`` problem: the upper bound is not below it).

    The bound is ``solution.bound``, or for an LP relaxation its objective.  Use it
    for relaxations and heuristics whose answers need not be optimal.
    """
    bound = solution.bound
    if bound is None and solution.relaxation == "lp":
        bound = solution.objective
    assert bound is not None, (
        f"{solution.solver}: no bound reported (status {solution.status}, "
        f"message {solution.message!r})")
    ref, how = _reference_optimum(problem)
    sign = -1.0 if problem.maximize else 1.0
    assert sign * bound <= sign * ref + abs_tol + rel * abs(ref), (
        f"{solution.solver}: bound {bound!r} exceeds the {how} {ref!r} ({solution.message})")


def stored_instances(directory: str | os.PathLike[str] | None = None) -> list[Path]:
    """The instance files (``*.json``) of ``directory``, sorted.

    Default: ``./instances`` when it exists, else the ``instances/`` folder of the
    assocopt source checkout, else the copies installed with the package.
    """
    from .workflow.generate import default_instances_dir

    folder = Path(directory) if directory is not None else default_instances_dir()
    if not folder.is_dir():
        return []
    return sorted(folder.glob("*.json"))


def generated_problems(kinds: Sequence[str] = ("dense", "sparse", "planted"), *,
                       max_axes: int = 4, max_size: int = 4) -> Any:
    """Hypothesis strategy of instances from :func:`assocopt.workflow.generate.generate`.

    Draws a generator, 2..``max_axes`` axes of size 1..``max_size`` and a seed.
    ``"planted"`` problems carry their optimum (known by construction), so
    :func:`assert_optimal` checks against it without a reference solve.
    """
    st = _hypothesis("generated_problems")

    from .workflow.generate import GENERATORS, generate

    bad = [k for k in kinds if k not in GENERATORS]
    if bad or not kinds:
        raise ValueError(f"kinds must be among {GENERATORS}, got {list(kinds)}")

    @st.composite
    def _draw(draw: Any) -> AssignmentProblem:
        kind = draw(st.sampled_from(list(kinds)))
        n_axes = draw(st.integers(2, max_axes))
        sizes = tuple(draw(st.lists(st.integers(1, max_size), min_size=n_axes,
                                    max_size=n_axes)))
        seed = draw(st.integers(0, 2**32 - 1))
        return generate(kind, seed=seed, sizes=sizes, verify=False)
    return _draw()
