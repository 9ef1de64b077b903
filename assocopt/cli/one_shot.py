"""The one-shot route of ``assocopt solve`` without ``--solver``: one small problem in a
fresh process, solved by whatever costs least to load for one solve."""

from __future__ import annotations

from typing import Any

#: ``assocopt solve`` without ``--solver`` solves one problem per process, where
#: ``auto``'s ``bnb`` would first import numba and load its compiled kernels (0.4-0.5 s
#: of a 0.5-1.4 s command).  So an S-D problem this small is first enumerated
#: exhaustively (``bruteforce``, numpy only, at most :data:`ONE_SHOT_NODES` search
#: nodes: an attempt that runs out of them costs 10-30 ms, 20,000 cost 0.2 s
#: under load), and one of at most :data:`ONE_SHOT_HIGHS` candidates
#: goes to HiGHS (its import and solve cost less than numba's load there: measured
#: by ``benchmarks/one_shot.py``, docs/benchmarks-one-shot.md).  So does a 2-D problem
#: of that size: scipy.optimize, which ``auto``'s 2-D path imports, costs more to
#: import than HiGHS and scipy.sparse (1.4x the command's CPU seconds measured).
#: Larger problems, or a search that runs out of nodes, go to ``auto``'s choice, and so
#: does an S-D problem whose ``bnb`` kernels would run as plain Python (a fresh process,
#: the default rule of :mod:`assocopt.solvers.kernels.tiers`: no numba to load, which
#: is cheaper than HiGHS's import).
ONE_SHOT_CANDIDATES = 64
ONE_SHOT_NODES = 2_000
ONE_SHOT_HIGHS = 1_000


def one_shot(problem: Any, relax: str | None) -> Any:
    """The exact answer of a small problem by the cheapest route for one solve in a
    fresh process (see above), or None for ``auto`` to answer."""
    from ..solving.api import solve
    from ..model.solution import Status
    from ..solvers.base import module_installed

    if relax is not None:
        return None
    if problem.ndim >= 3 and problem.n_candidates <= ONE_SHOT_CANDIDATES:
        sol = solve(problem, "bruteforce", max_nodes=ONE_SHOT_NODES)
        if sol.status in (Status.OPTIMAL, Status.INFEASIBLE):
            sol.message = (f"{sol.message} (auto: one small problem, enumerated rather "
                           "than loading the compiled bnb kernels)")
            sol.info.update(requested="auto", one_shot=True)
            return sol
    if problem.n_candidates > ONE_SHOT_HIGHS or not module_installed("highspy"):
        return None
    if problem.ndim >= 3 and _interpreted(problem.n_candidates):
        return None
    sol = solve(problem, "highs")
    if sol.status not in (Status.OPTIMAL, Status.INFEASIBLE):
        return None
    rather = "importing scipy.optimize" if problem.ndim == 2 else \
        "loading the compiled bnb kernels"
    sol.message = (f"{sol.message} (auto: one small problem in a fresh process, solved "
                   f"by HiGHS rather than {rather})")
    sol.info.update(requested="auto", one_shot=True)
    return sol


def _interpreted(n_candidates: int) -> bool:
    """Whether ``bnb``'s kernels would run as plain Python on a problem this size in
    this process (nothing compiled yet, the default rule)."""
    from ..solvers.kernels import tiers
    return all(tiers.interpret(k, n_candidates, lambda: False)
               for k in ("driver.solve", "batch.solve_batch"))
