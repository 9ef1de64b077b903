"""Which back end ``solver="auto"`` picks for a problem, by size and structure.

Kept apart from :mod:`assocopt.solving.api` so that :mod:`assocopt.solving.decompose`
can choose per component without importing ``solve``.
"""
from __future__ import annotations

import numpy as np

from ..problems.problem import AssignmentProblem
from ..solvers.base import module_installed

__all__ = ["choose_solver", "bnb_cap", "BNB_MAX_CANDIDATES", "BNB_MAX_GATED",
           "BNB_MAX_KEPT", "BNB_MAX_GRID"]


#: ``auto`` sends N >= 3 problems with at most this many candidates to ``bnb``
#: (compiled branch and bound) when numba is installed; measured faster than
#: ``lagrangian-exact`` up to Grundel n = 20 (8,000 candidates), slower at n = 30
#: (docs/benchmarks-sd.md).
BNB_MAX_CANDIDATES = 10_000
#: ... but dense square 3-D grids (axial 3-AP) with more candidates than this go to
#: ``lagrangian-exact``, whose ascent runs there as one compiled kernel
#: (:mod:`assocopt.solvers.lagrangian.compiled_ascent`): measured on the public
#: instances, Grundel n = 20 (8,000 candidates) 0.032 s against 0.156 s for ten,
#: Balas-Saltzman n = 16-20 (4,096-8,000) 1.5-2.5 times faster, level at n = 12-14.
BNB_MAX_GRID = 3_000
#: ... and with at most this many real indices on the two kept axes: ``bnb``'s dense
#: Hungarian costs O((n_a + n_b)^3) per iteration, ``lagrangian-exact``'s sparse LAP
#: far less on large sparse problems.
BNB_MAX_KEPT = 100
#: ... and, for problems with dummies (gated tracking scans and their components), at
#: most this many candidates: above it ``lagrangian-exact`` (dominance rule, sparse
#: LAP, fixing probes) beat ``bnb`` on the 300-12,000-candidate components of the
#: N = 3-6 scans of benchmarks/sd_tracking.py (seeds 51-53, not the page's): from
#: about 2,500 candidates by 1.2-12x (5,823 candidates at N = 5: 0.29 s against
#: 0.023 s), level around 1,500-2,000, ``bnb`` ahead below.
BNB_MAX_GATED = 2_000


def choose_solver(problem: AssignmentProblem, relax: str | None = None) -> str:
    """The back end ``solver="auto"`` picks, by size and structure (measured in
    docs/benchmarks-sd.md): the 2-D fast path; for S-D (N >= 3) the compiled branch
    and bound ``bnb`` up to :data:`BNB_MAX_CANDIDATES` candidates (:data:`BNB_MAX_GATED`
    with dummies) and :data:`BNB_MAX_KEPT` kept-axes indices (numba installed), else
    the Lagrangian exact method; HiGHS for LP relaxations."""
    if relax is not None:
        return "highs"
    if problem.ndim == 2:
        return "scipy-lsa"
    gated = bool((problem.tuples == 0).any())
    cap = bnb_cap(gated) if gated or not _square_grid(problem) else BNB_MAX_GRID
    if problem.n_candidates <= cap and _bnb_usable(problem):
        return "bnb"
    return "lagrangian-exact"


def _square_grid(problem: AssignmentProblem) -> bool:
    """Every triple of three equal axes (a dense axial 3-AP)."""
    s = problem.sizes
    return len(s) == 3 and s[0] == s[1] == s[2] and problem.n_candidates == s[0] ** 3


def bnb_cap(gated):
    """The most candidates ``auto`` gives ``bnb``: :data:`BNB_MAX_GATED` for a problem
    (or, elementwise, component) with dummies, else :data:`BNB_MAX_CANDIDATES`."""
    return np.where(gated, BNB_MAX_GATED, BNB_MAX_CANDIDATES)


def _bnb_usable(problem: AssignmentProblem) -> bool:
    from ..solvers.bnb.backend import kept_sizes
    return _numba_installed() and sum(kept_sizes(problem)) <= BNB_MAX_KEPT


def _numba_installed() -> bool:
    return module_installed("numba")
