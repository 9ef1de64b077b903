"""Which back end ``solver="auto"`` picks for a problem, by size and structure.

Kept apart from :mod:`assocopt.solving.api` so that :mod:`assocopt.solving.decompose`
can choose per component without importing ``solve``.
"""
from __future__ import annotations

import numpy as np

from ..problems.problem import AssignmentProblem
from ..solvers.base import module_installed

__all__ = ["choose_solver", "bnb_cap", "BNB_MAX_CANDIDATES", "BNB_MAX_GATED",
           "BNB_MAX_GATED_COMPILED", "BNB_MAX_GATED_WIDE", "BNB_MAX_KEPT", "BNB_MAX_GRID"]


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
#: ... lowered to this many where ``lagrangian-exact``'s gated relaxation runs compiled
#: (:mod:`assocopt.solvers.lagrangian.compiled_sparse`: compiled mode, or its kernels
#: loaded in this process): there it beat ``bnb`` from about 700-1,000 candidates on
#: the components of the N = 3-6 scans at spacing 1.5, seeds 41-42 (summed over the
#: 1,000-2,000-candidate components of N = 4, seed 42: 112 ms against 21 ms; 700-1,000:
#: 10.6 against 6.6 ms; 500-700: 6.1 against 6.9 ms, ``bnb`` ahead below); checked on
#: the components of every setting's seed 51 (not tuned on): 700-1,000 candidates
#: 25.6 ms against 15.1 (9 components), 1,000-1,500: 69.3 against 24.3 (13), 500-700:
#: 18.0 against 15.9 (10), ``bnb`` ahead below 500 (on 200 of 201 components).
#: Checked again once the relaxation's layout, fixing bounds and window search had
#: lost most of their Python overhead (seeds 51-52 of the N = 3-6 settings): alone,
#: ``lagrangian-exact`` was ahead from about 400-600 candidates, but on whole scans
#: caps of 400 and 500 were level with 700 or slower (the batch has no per-component
#: overhead), so it stays.
BNB_MAX_GATED_COMPILED = 700
#: ... raised to this many at N >= 5 once ``bnb`` started its search from a greedy
#: cover (:mod:`assocopt.solvers.kernels.greedy`): on the scans of seeds 51-52 at
#: N = 5-6 a cap of 1,500 was 12 % quicker than 700 (geometric mean of the five N >= 5
#: settings), 2,000 and 3,000 level with it; at N = 4 (spacing 1.5) it was slower.  On
#: the 1,000-1,500-candidate multi-frame components of benchmarks/mfa_components.py
#: (N = 5-7, up to 20 indices an axis) it is slower: 13.0 ms against 9.3 on the five
#: in the runs of docs/benchmarks-mfa-components.md before and after (the widest, 19-20 an
#: axis: 5.1 against 2.4 ms), still 5-58x ahead of HiGHS there.
BNB_MAX_GATED_WIDE = 1_500


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
    gated = problem.n_candidates > 0 and int(problem.tuples.min()) == 0   # a dummy index
    cap = bnb_cap(gated, problem.ndim) if gated or not _square_grid(problem) \
        else BNB_MAX_GRID
    if problem.n_candidates <= cap and _bnb_usable(problem):
        return "bnb"
    return "lagrangian-exact"


def _square_grid(problem: AssignmentProblem) -> bool:
    """Every triple of three equal axes (a dense axial 3-AP)."""
    s = problem.sizes
    return len(s) == 3 and s[0] == s[1] == s[2] and problem.n_candidates == s[0] ** 3


def bnb_cap(gated, ndim: int = 3):
    """The most candidates ``auto`` gives ``bnb``: :data:`BNB_MAX_GATED` for a problem
    (or, elementwise, component) with dummies (at most :data:`BNB_MAX_GATED_COMPILED`
    where the gated relaxation runs compiled, :data:`BNB_MAX_GATED_WIDE` there at
    ``ndim`` >= 5), else :data:`BNB_MAX_CANDIDATES`."""
    cap = BNB_MAX_GATED
    if np.any(gated) and _sparse_relaxation_compiled(cap):
        cap = min(cap, BNB_MAX_GATED_WIDE if ndim >= 5 else BNB_MAX_GATED_COMPILED)
    return np.where(gated, cap, BNB_MAX_CANDIDATES)


def _sparse_relaxation_compiled(candidates: int) -> bool:
    """``compiled_sparse.compiled_route`` without importing the Lagrangian package
    (a first small solve never loads it): numba installed and the tier rule choosing
    the gated relaxation's kernel."""
    from ..solvers.kernels import tiers
    return _numba_installed() and not tiers.interpret("sparse_relax.sparse_eval",
                                                      candidates, lambda: False)


def _bnb_usable(problem: AssignmentProblem) -> bool:
    from ..solvers.bnb.backend import kept_sizes
    return _numba_installed() and sum(kept_sizes(problem)) <= BNB_MAX_KEPT


def _numba_installed() -> bool:
    return module_installed("numba")
