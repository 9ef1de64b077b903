"""Ranked assignments: the k best feasible solutions, by Murty's partitioning.

:func:`kbest` returns the ``k`` cheapest feasible solutions of any problem, in order of
objective (best first; for a ``maximize=True`` problem, highest score first).  Murty's
method: the best solution ``S`` of a subproblem ``(forced F, forbidden X)`` is reported,
and the rest of that subproblem is split into children ``t = 1..m``: "``s_1 .. s_{t-1}``
forced in, ``s_t`` forbidden", over the chosen candidates ``s_1 .. s_m`` of ``S`` not
already forced.  Every other solution of the subproblem lies in exactly one child (the
first ``s_t`` it lacks), so the children's optima, taken cheapest first, rank every
feasible solution exactly once.  Slack candidates (the free surplus of a rectangular
``dense`` problem) are never split on: the real tuples fix them.

2-D problems (``solver="auto"``, numba installed, a LAP form of at most
:data:`assocopt.ranking.kbest2d.MAX_FORM_ENTRIES` entries) are ranked in one compiled call
(:mod:`assocopt.ranking.kbest2d`, kernel :mod:`assocopt.solvers.kernels.murty2d`): each
subproblem is solved from its parent's solution and duals by one shortest augmenting
path, children wait on the heap unsolved under a lower bound, and the partition is
taken over the real rows of a LAP form in which every 2-D solution (misses included)
is one choice vector, so none comes back twice.  Equal objectives come out in the
order of their candidate positions (``Solution.selected``, lexicographically).

The generic path below serves S-D problems, named 2-D solvers (``"scipy-lsa"``,
``"lapjv"``), 2-D problems when numba is missing and larger ones: children are put on the heap
*unsolved*, with their parent's objective as a lower bound, and solved only when they
reach the top; a 2-D problem's subproblems are solved on its dense matrix with
forbidden entries set to ``inf`` (the dense engine of :mod:`assocopt.solvers.twod.dense`),
without warm starts (scipy and lapx expose no duals).  Ties are broken
deterministically: equal objectives come out in the order of their candidate positions
where the subproblems' optima allow it.  An infeasible subproblem is dropped.  When
fewer than ``k`` feasible solutions exist, all of them are returned and
:attr:`Ranked.exhausted` is True.  S-D problems use the exact S-D back ends
(``solver="auto"``: ``bnb`` or ``lagrangian-exact``) on the candidate list restricted
to each subproblem.
"""

from __future__ import annotations

import heapq
import itertools
import math
import time
from dataclasses import dataclass, field
from typing import Any, Iterator

import numpy as np

from ..runtime.errors import InvalidProblemError, SolverCapabilityError
from ..problems.problem import AssignmentProblem
from ..model.solution import Solution, Status

__all__ = ["kbest", "Ranked"]

#: 2-D solvers whose subproblems run on the dense matrix.
_TWO_D_SOLVERS = {"auto": "scipy", "scipy-lsa": "scipy", "lapjv": "lapx"}
#: A 2-D candidate list is densified for the ranking up to this many matrix entries.
_DENSIFY_MAX = 4_000_000


@dataclass
class Ranked:
    """The result of :func:`kbest`: a sequence of :class:`~assocopt.Solution`, best first.

    ``solutions[r]`` is the ``r+1``-th best feasible solution (status ``optimal`` for
    the first, ``feasible`` for the others; ``info["rank"]`` its 1-based rank).
    ``exhausted``: True when no further feasible solution exists (always so when fewer
    than ``k`` came back).  ``subproblems``: how many subproblems were solved.
    """

    solutions: list[Solution]
    k: int
    exhausted: bool
    solver: str
    subproblems: int
    times: dict[str, float] = field(default_factory=dict)

    def __len__(self) -> int:
        return len(self.solutions)

    def __iter__(self) -> Iterator[Solution]:
        return iter(self.solutions)

    def __getitem__(self, i: int) -> Solution:
        return self.solutions[i]

    @property
    def objectives(self) -> list[float]:
        """The objectives, best first (in the user's sense)."""
        return [s.objective for s in self.solutions]

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready summary."""
        return {"k": self.k, "found": len(self.solutions), "exhausted": self.exhausted,
                "solver": self.solver, "subproblems": self.subproblems,
                "time_s": self.times.get("total"),
                "solutions": [s.to_dict() for s in self.solutions]}


def kbest(problem: AssignmentProblem, k: int, solver: str = "auto", **options: Any
          ) -> Ranked:
    """The ``k`` best feasible solutions of ``problem``, best first (see the module).

    ``k``: a positive integer (any size: fewer come back when fewer exist).
    ``solver``: an exact back end for the subproblems (``"auto"``: the compiled 2-D
    ranking, reported as ``"murty2d"`` and also accepted by that name, or the exact S-D
    back end :func:`assocopt.choose_solver` picks); ``options`` go to it (``relax`` is
    refused: the ranking is over integer solutions).  ``Ranked.times`` has ``total``
    and, when the call compiled the 2-D kernel or loaded it from numba's disk cache,
    ``compile`` / ``cache_load`` seconds.

    Examples
    --------
    >>> from assocopt import AssignmentProblem, kbest
    >>> r = kbest(AssignmentProblem.dense([[1.0, 2.0], [3.0, 5.0]]), 3)
    >>> r.objectives, r.exhausted
    ([5.0, 6.0], True)
    """
    t0 = time.perf_counter()
    if not isinstance(problem, AssignmentProblem):
        raise InvalidProblemError(
            f"problem must be an AssignmentProblem, got {type(problem).__name__}")
    if isinstance(k, bool) or not isinstance(k, (int, np.integer)) or k < 1:
        raise InvalidProblemError(f"k must be a positive integer, got {k!r}")
    if options.get("relax") is not None:
        raise InvalidProblemError(
            f"kbest ranks integer solutions; relax={options['relax']!r} is not supported")
    if solver == "murty2d":                 # the name the compiled ranking reports
        if problem.ndim != 2:
            raise SolverCapabilityError(
                f"solver 'murty2d' ranks 2-D problems only; this one has {problem.ndim} "
                "axes (use solver='auto' or an exact S-D back end)")
        solver = "auto"
    if problem.ndim == 2 and solver == "auto" and not options:
        from . import kbest2d

        fast = kbest2d.kbest_2d(problem, int(k)) if kbest2d.available() else None
        if fast is not None:
            sols, exhausted, solved, times = fast
            return Ranked(sols, int(k), exhausted, kbest2d.NAME, solved,
                          times={**times, "total": time.perf_counter() - t0})
    engine = _TWO_D_SOLVERS.get(solver) if problem.ndim == 2 and not options else None
    if engine is not None and (problem.dense_view is not None or
                               problem.sizes[0] * problem.sizes[1] <= _DENSIFY_MAX):
        space: _Space = _Dense2DSpace(problem, engine)
    else:
        space = _CandidateSpace(problem, solver, options)
    found, exhausted, solved = _murty(space, int(k))
    sols = [_solution(problem, sel, r, space.name) for r, sel in enumerate(found, 1)]
    return Ranked(sols, int(k), exhausted, space.name, solved,
                  times={"total": time.perf_counter() - t0})


# --------------------------------------------------------------------------- Murty
def _murty(space: "_Space", k: int) -> tuple[list[np.ndarray], bool, int]:
    """Lazy Murty: ``(selections best first, exhausted, subproblems solved)``."""
    seq = itertools.count()
    heap: list[tuple] = []
    solved = 0
    root = space.solve((), ())
    solved += 1
    if root is not None:
        heapq.heappush(heap, (root[0], 1, tuple(root[1].tolist()), next(seq), (), (), root))
    found: list[np.ndarray] = []
    while heap and len(found) < k:
        value, is_solved, _, _, forced, banned, sol = heapq.heappop(heap)
        if not is_solved:
            sol = space.solve(forced, banned)
            solved += 1
            if sol is not None:
                heapq.heappush(heap, (sol[0], 1, tuple(sol[1].tolist()), next(seq),
                                      forced, banned, sol))
            continue
        obj, sel, items = sol
        found.append(sel)
        fixed = set(forced)
        new = [s for s in items if s not in fixed]
        for t, s in enumerate(new):
            heapq.heappush(heap, (obj, 0, (), next(seq), forced + tuple(new[:t]),
                                  banned + (s,), None))
    if len(found) < k:
        return found, True, solved
    while heap:        # is there any further solution?  settle the unsolved tops
        value, is_solved, _, _, forced, banned, sol = heapq.heappop(heap)
        if is_solved or space.solve(forced, banned) is not None:
            return found, False, solved + (0 if is_solved else 1)
        solved += 1
    return found, True, solved


class _Space:
    """Solves a subproblem ``(forced items, banned items)``: ``(objective, selected
    candidate positions, items to split on)`` in the minimisation sense, or None."""

    name = ""

    def solve(self, forced: tuple, banned: tuple) -> tuple | None:
        raise NotImplementedError


class _Dense2DSpace(_Space):
    """2-D subproblems on the dense matrix; an item is a pair ``(i, j)`` (``j = -1``: row
    i left out, ``i = -1``: column j left out)."""

    def __init__(self, problem: AssignmentProblem, engine: str) -> None:
        self.problem = problem
        self.engine = engine
        self.name = "scipy-lsa" if engine == "scipy" else "lapjv"
        d = problem.dense_view
        if d is not None:
            self.C, self.rm, self.cm, self.slack = d.C, d.rm, d.cm, d.slack
        else:
            self.C = problem.to_cost_matrix()
            self.rm, self.cm = problem.miss_costs()
            self.slack = bool(problem.slack.any())

    def solve(self, forced: tuple, banned: tuple) -> tuple | None:
        from ..solvers.twod.dense import assign_dense
        from ..solvers.twod.lap import LapInfeasibleError

        C, rm, cm = self.C.copy(), self.rm.copy(), self.cm.copy()
        for i, j in banned:
            if i < 0:
                cm[j] = np.inf
            elif j < 0:
                rm[i] = np.inf
            else:
                C[i, j] = np.inf
        for i, j in forced:
            if i >= 0:
                keep = C[i, j] if j >= 0 else None
                C[i, :] = np.inf
                if j >= 0:
                    C[i, j] = keep
                    rm[i] = np.inf
            if j >= 0:
                keep = C[i, j] if i >= 0 else None
                C[:, j] = np.inf
                if i >= 0:
                    C[i, j] = keep
                    cm[j] = np.inf
        try:
            cor, _ = assign_dense(C, rm, cm, False, self.engine)
        except LapInfeasibleError:
            return None
        sel, items = self._positions(cor)
        return self.problem.objective_of(sel), sel, items

    def _positions(self, cor: np.ndarray) -> tuple[np.ndarray, list]:
        from ..solvers.twod.dense import _answer_positions

        d = self.problem.dense_view
        if d is not None:
            checked = d.check(cor)
            if isinstance(checked, str):
                raise RuntimeError(f"kbest: a subproblem answer is infeasible: {checked}")
            sel = np.sort(checked.selected)
        else:
            sel = np.sort(_answer_positions(self.problem, cor))
        rows = np.flatnonzero(cor >= 0)
        items = [(int(i), int(j)) for i, j in zip(rows, cor[rows])]
        if not self.slack:
            used = np.zeros(len(self.cm), bool)
            used[cor[rows]] = True
            items += [(int(i), -1) for i in np.flatnonzero(cor < 0)]
            items += [(-1, int(j)) for j in np.flatnonzero(~used)]
        return sel, items


class _CandidateSpace(_Space):
    """Subproblems as restrictions of the candidate list (any N), solved by an exact back
    end; an item is a candidate position."""

    def __init__(self, problem: AssignmentProblem, solver: str, options: dict) -> None:
        from ..solvers import registered

        self.problem, self.solver, self.options = problem, solver, options
        if solver != "auto":
            cls = registered().get(solver)
            if cls is not None and not cls.exact:
                raise SolverCapabilityError(
                    f"kbest needs an exact solver; {solver!r} does not prove optimality")
        self.A = problem.coverage_matrix().tocsc()
        self.Ar = self.A.tocsr()
        self.name = solver

    def solve(self, forced: tuple, banned: tuple) -> tuple | None:
        from ..solving.api import solve

        p = self.problem
        mask = np.ones(p.n_candidates, bool)
        mask[list(banned)] = False
        if forced:
            f = np.asarray(forced, np.int64)
            rows = np.unique(self.A[:, f].indices)
            touching = np.unique(self.Ar[rows].indices)
            mask[touching] = False
            mask[f] = True
        idx = np.flatnonzero(mask)
        sub = AssignmentProblem._build(p.sizes, p.tuples[idx], p.costs[idx], p.slack[idx],
                                       kind="sparse")
        sol = solve(sub, self.solver, **self.options)
        self.name = sol.solver or self.name
        if sol.status is Status.INFEASIBLE:
            return None
        if sol.status is not Status.OPTIMAL:
            raise SolverCapabilityError(
                f"kbest: the subproblem solver {sol.solver!r} returned {sol.status} "
                f"({sol.message}); ranking needs proven optima")
        sel = np.sort(idx[sol.selected])
        items = [int(s) for s in sel if not p.slack[s]]
        return p.objective_of(sel), sel, items


def _solution(problem: AssignmentProblem, sel: np.ndarray, rank: int,
              solver: str) -> Solution:
    """A re-checked :class:`Solution` for the ``rank``-th selection."""
    from ..solving.api import to_user_sense
    from ..solvers import get_backend

    why = problem.violations(sel)
    if why is not None:
        raise RuntimeError(f"kbest produced an infeasible selection: {why}")
    obj = problem.objective_of(sel)
    sol = Solution(status=Status.OPTIMAL if rank == 1 else Status.FEASIBLE,
                   objective=obj, bound=obj if rank == 1 else None, selected=sel,
                   tuples=problem.tuples[sel[~problem.slack[sel]]].copy(), solver=solver,
                   solver_version=get_backend(solver).version() if solver != "auto" else "",
                   message=f"kbest: rank {rank}", info={"rank": rank})
    if not math.isfinite(obj):
        raise RuntimeError("kbest produced a non-finite objective")
    return to_user_sense(sol) if problem.maximize else sol
