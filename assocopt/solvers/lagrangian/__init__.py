"""Lagrangian relaxation of S-D assignment to 2-D assignments, with certified gaps.

The method of Pattipati et al. (1992) and Deb et al. (1997).  Keep two axes ``a, b``
(by default the two largest) and move the coverage constraints of the other N-2
axes into the objective with multipliers ``u`` (one per *real* index; dummies are
never constrained).  For every ``u`` the relaxed problem

    L(u) = sum(u) + min  sum_k (c_k - sum_{s relaxed, i_s > 0} u_s[i_s]) x_k
           s.t. every real index of axes a and b covered exactly once

is a 2-D assignment with miss costs: for each pair ``(i_a, i_b)`` only the candidate
of least reduced cost matters, ``(i, 0)`` and ``(0, j)`` pairs are the miss costs, and
candidates with a dummy on both kept axes are unconstrained (taken when their reduced
cost is negative).  ``L(u)`` is a valid lower bound for *every* ``u``; its maximum is
the LP bound.  Each iteration costs one pass over the candidates and one 2-D
assignment (:mod:`assocopt.solvers.twod.lap`).

Multipliers follow a Polyak subgradient step towards the best feasible objective
(momentum-deflected, scale halved when the bound stalls), started from each index's
least per-index cost share.  Feasible solutions come from the recursive scheme: keep
the kept-axes pairs of the relaxed solution as groups and attach the relaxed axes one
at a time, each by a 2-D assignment (groups x indices, with misses) on costs that
still carry the multipliers of the axes not yet attached; record solutions are then
improved by an axis-wise re-assignment local search (:class:`_LocalSearch`).

Back ends
---------
``lagrangian``: the bound, the best feasible solution and the gap.  ``OPTIMAL`` only
with a proof: the relaxed solution is itself feasible, or the bound meets the
objective (integer costs: ``ceil(bound) >= objective``; otherwise to within
:data:`OPT_TOL` relative, floating-point round-off).  Else ``FEASIBLE`` (stopped by
gap, iteration or step rules) or ``TIME_LIMIT``.

``lagrangian-exact``: the same ascent, then reduced-cost fixing with the final
multipliers and the LAP duals: every solution using candidate k costs at least
``lb[k]``.  The *window* ``{k : lb[k] < T}`` holds every solution cheaper than ``T``,
so solving it settles "is the optimum below T?"; windows grow one cost unit (integer
costs) or a doubling of candidates at a time until ``T`` reaches the incumbent.  Each
window is solved by a depth-first exact-cover search (small windows), CP-SAT (integer
costs, up to 1,500 candidates, when OR-Tools is installed) or HiGHS (told to stop at
the proven bound).  Small candidate sets are probed during the ascent as well.
``OPTIMAL`` only when proven; ``info["proof"]`` says how.

Candidate reduction (both back ends, exact): a candidate with two or more real
indices is dominated, and dropped, when its cost is at least that of covering the same
real indices by a split into two candidates (or into single-index candidates).
Optional *heuristic* gate ``gate=g``: drop multi-index candidates costing more than
``g``; the answer is then optimal for the gated problem only, so it is reported as
``FEASIBLE`` and without a bound.

Options (``solve(..., **options)``), all recorded in ``info["parameters"]``:

``max_iter`` (1000; exact: 500) subgradient iterations;
``gap_tol`` (1e-4; exact: 0, or ``mip_gap``) relative gap that stops the ascent;
``step0`` (1.0), ``step_decay`` (0.5), ``patience`` (10), ``step_min`` (1e-4):
Polyak step scale, its decay after ``patience`` iterations without a better bound,
and the scale at which the ascent stops;  ``deflect`` (0.5): momentum of the
previous direction;  ``init`` ("share" or "zero"): starting multipliers;
``stall_iter`` (60), ``stall_tol`` (1e-3): exact mode leaves the ascent when the bound
gained less than ``stall_tol`` of the gap in ``stall_iter`` iterations;
``recover_every`` (1): primal recovery every k iterations (0: never).  On dense
square 3-D grids, whose ascent runs compiled (:mod:`.compiled_ascent`), ``step0``,
``recover_every``, ``patience`` and ``stall_tol`` default to 0.5, 3, 7 and 3e-3
(:data:`.options.GRID_DEFAULTS`);
``local_search`` (True; the exact mode uses it above 2,000 candidates);
``keep_axes`` (None: the two largest axes);  ``lap`` ("auto", "scipy", "lapx",
"sparse"): 2-D engine;  ``reduce`` (True): dominance rule;  ``gate`` (None);
``window_solver`` ("auto", "highs", "cpsat"; exact only);  ``return_history``
(False): per-iteration bound, best bound and objective in ``info["history"]``.
``time_limit`` gives ``TIME_LIMIT`` with the incumbent and the bound; ``threads`` and
``verbose`` are passed to HiGHS / CP-SAT.

Modules
-------
:mod:`.options` (``OPT_TOL``, option defaults and checks, kept axes),
:mod:`.relaxation` (the 2-D subproblem: evaluation, primal recovery, fixing bounds;
:func:`lagrangian_bound`), :mod:`.local_search` (axis-wise re-assignment),
:mod:`.reduction` (the dominance rule :func:`dominated`), :mod:`.ascent` (solve
state and the subgradient ascent), :mod:`.compiled_ascent` (the same ascent on dense
square 3-D grids, by one kernel), :mod:`.fixing` (reduced-cost fixing bounds, the
probes of the exact mode), :mod:`.window` (exact search, CP-SAT and HiGHS on
candidate windows), :mod:`.policy` (windows solved by components, windows left to a
larger one), :mod:`.backend` (the two registered back ends).

May import: :mod:`assocopt.runtime`, :mod:`assocopt.problems`, :mod:`assocopt.model`;
in :mod:`assocopt.solvers` the top-level modules (:mod:`assocopt.solvers.base`,
:mod:`assocopt.solvers.options`, :mod:`assocopt.solvers.status`,
:mod:`assocopt.solvers.scaling`, :mod:`assocopt.solvers.interruptible`), the kernels
(:mod:`assocopt.solvers.kernels`) and the parts it builds on: the 2-D engines
(:mod:`assocopt.solvers.twod`), HiGHS for windows (:mod:`assocopt.solvers.milp`), the
``bnb`` kernels (:mod:`assocopt.solvers.bnb`) and ``greedy``
(:mod:`assocopt.solvers.baseline`).

Examples
--------
>>> import numpy as np
>>> from assocopt import AssignmentProblem, solve
>>> p = AssignmentProblem.dense(np.random.default_rng(0).integers(0, 9, (6, 6, 6)))
>>> sol = solve(p, "lagrangian-exact")
>>> sol.status.value, sol.objective == solve(p, "highs").objective
('optimal', True)
"""

from __future__ import annotations

from .ascent import _State, _ascent, _record  # noqa: F401
from .backend import (_LS_MIN_K, LagrangianBackend, LagrangianExactBackend,  # noqa: F401
                      _LagrangianBase)
from .local_search import _LocalSearch  # noqa: F401
from .options import _COMMON, _EXACT, OPT_TOL, _keep_axes, _parse  # noqa: F401
from .reduction import dominated  # noqa: F401
from .relaxation import (_Eval, _first_per_label, _ranges, _Relaxation,  # noqa: F401
                         lagrangian_bound)
from .window import (_CPSAT_BUDGET, _CPSAT_MAX, _HIGHS_OPTIONS, _PROBE_SEARCH_MAX,  # noqa: F401
                     _SEARCH_MAX, _SEARCH_NODES, _cover_search, _coverage, _cpsat, _grow,
                     _has_ortools, _ilp, _uncovered)

__all__ = ["LagrangianBackend", "LagrangianExactBackend", "OPT_TOL", "dominated",
           "lagrangian_bound"]

# The private names above are re-exported so that ``lagrangian.<name>`` keeps
# working for every name the single-module version had (tests, notebooks, tools).
# Note: rebinding a tuning constant here (``lagrangian._SEARCH_MAX = ...``) does not
# reach the code that uses it; patch it in its own module (``lagrangian.window``).
