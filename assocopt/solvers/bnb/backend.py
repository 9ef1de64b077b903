"""``bnb``: compiled Lagrangian branch and bound, the fast exact path for small S-D.

Monte Carlo studies solve tens of thousands of small S-D problems (paper 002 alone
solves 72,000), where per-call latency, not asymptotics, decides.  This back end
runs everything in one compiled call (numba, :mod:`assocopt.solvers.bnb.kernels`):

1. *Ascent.*  The Lagrangian relaxation of :mod:`assocopt.solvers.lagrangian`: keep
   two axes, price the others with multipliers ``y``, solve the 2-D assignment with
   misses by a dense Hungarian method, take a deflected Polyak subgradient step
   towards the incumbent.  For N = 3 every iteration also recovers a feasible
   solution (Pattipati et al. 1992): keep the relaxed solution's pairs and attach the
   third axis by one more 2-D assignment with misses.
2. *Reduced costs.*  The multipliers plus the Hungarian duals give a dual ``y`` on
   every real index, raised greedily where a row's candidates all have slack;
   ``r[k] = c[k] - sum_{e in k} y[e]`` and ``base = sum(y) + sum_k min(r[k], 0)``.
   Every exact cover ``X`` costs at least ``base + sum_{k in X} max(r[k], 0)``,
   whatever ``y`` is, so the bound is valid by construction and the ascent only
   tightens it.  Candidates whose reduced cost alone reaches the incumbent are
   dropped (reduced-cost fixing).
3. *Branch and bound.*  Depth-first exact-cover search: branch on the uncovered
   index with the fewest live candidates, cheapest reduced cost first; cut a node when
   ``base + acc + max_s sum_{uncovered e on axis s} min live r`` reaches the
   incumbent (integer costs: the incumbent minus one).  Short searches run during
   the ascent as well and often finish the proof early.  A search that completes
   proves the incumbent optimal.

The search stops after ``max_nodes`` nodes; then, with ``fallback=True`` (default),
the problem goes to ``lagrangian-exact`` with what is left of ``time_limit``, so the
answer is still a proven optimum.  Problems too large for the kernels' dense 2-D
matrices (:data:`MAX_DENSE`, :data:`MAX_KEPT`) go there directly.  The compiled part runs in a worker thread that stops
it at the time limit (with its incumbent and bound: ``TIME_LIMIT``, no fallback) or on
Ctrl-C, within one ascent iteration or 1024 search nodes.  ``solver="auto"`` uses this back end for small N >= 3
problems (see :func:`assocopt.solving.api.choose_solver`).

Options (all recorded in ``info["parameters"]``): ``max_iter`` (100) subgradient
iterations; ``probe_every`` (15) iterations between short searches (0: none);
``probe_nodes`` (200) nodes per short search; ``max_nodes`` (200,000) nodes of the
final search; ``step0`` (2.0), ``patience`` (10), ``step_min`` (1e-3): Polyak step
scale, halved after ``patience`` iterations without a better bound, the ascent ends
below ``step_min``; ``deflect`` (0.5): share of the previous direction kept;
``recover_every`` (1): N = 3 primal recovery every k iterations (0: never);
``warm_start`` (True): each Hungarian solve starts from the previous potentials;
``stall_tol`` (0: off): leave the ascent for the final search when the bound gained
less than this share of the gap since the last short search (0.02 trims the slowest
draws a little, measured; off by default because an early search on weaker
multipliers can run into the fallback);
``keep_axes`` (None: the two largest axes); ``fallback`` (True).  The defaults were
tuned on paper-002 problems and random 3-AP with n <= 10
(``benchmarks/sd_scaling.py``).

Examples
--------
>>> import numpy as np
>>> from assocopt import AssignmentProblem, solve
>>> p = AssignmentProblem.dense(np.random.default_rng(0).random((6, 6, 6)))
>>> sol = solve(p, "bnb")
>>> sol.status.value, abs(sol.objective - solve(p, "highs").objective) < 1e-9
('optimal', True)
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass
from typing import Any

import numpy as np

from ...runtime.errors import ProblemTooLargeError
from ...problems.problem import AssignmentProblem
from ...model.solution import Status
from ...problems.problem import OPT_TOL
from ..base import (Backend, Option, RawResult, SolveOptions, _distribution_version,
                   empty_answer, get_backend, register)
from ..interruptible import new_stop
from .kernels import run_tiered

__all__ = ["BranchBoundBackend", "DEFAULTS", "BnbInput", "MAX_DENSE", "MAX_KEPT",
           "kept_sizes", "too_large"]

#: Relative tolerance of "bound meets objective" for non-integer costs (round-off),
#: the same as the Lagrangian back ends' ``OPT_TOL``.
TOL = OPT_TOL
#: Problems with at most this many candidates run the kernel in the calling thread
#: when no time limit is set (their whole node budget takes well under a second, and
#: a worker thread would add about 0.1 ms to solves of 0.1-1 ms); larger ones run in
#: a worker thread that Ctrl-C and the clock can stop (:mod:`.interruptible`).
INLINE_CANDIDATES = 500

#: Largest dense matrix (entries) the kernels allocate: ``(n_a+1)(n_b+1)`` for the
#: 2-D subproblem, ``(n_a+1)(n_b+1)(n_c+1)`` for the N = 3 recovery lookup.
MAX_DENSE = 4_000_000
#: Largest ``n_a + n_b`` (the dense Hungarian's size, misses included): each ascent
#: iteration costs O((n_a + n_b)^3), so beyond this ``lagrangian-exact`` (sparse LAP)
#: is the better engine.
MAX_KEPT = 400

def kept_sizes(problem: AssignmentProblem, keep_axes: Any = None) -> tuple[int, int]:
    """``(n_a, n_b)``: the sizes of the two kept axes."""
    a, b = problem.kept_axes(keep_axes)
    return problem.sizes[a], problem.sizes[b]


def too_large(problem: AssignmentProblem, keep_axes: Any = None) -> str | None:
    """Why the kernels' dense matrices do not suit ``problem`` (None: they do)."""
    na, nb = kept_sizes(problem, keep_axes)
    if (na + 1) * (nb + 1) > MAX_DENSE:
        return f"(n_a+1)(n_b+1) = {(na + 1) * (nb + 1)} > MAX_DENSE = {MAX_DENSE}"
    if na + nb > MAX_KEPT:
        return f"n_a + n_b = {na + nb} > MAX_KEPT = {MAX_KEPT}"
    return None


@dataclass(frozen=True)
class BnbInput:
    """The arrays the kernels take, built in bulk from a problem."""

    G: np.ndarray           # (K, N) global row of each real index, -1 for dummies
    c: np.ndarray           # (K,) costs
    a: int                  # kept axes
    b: int
    relaxed: np.ndarray     # the other axes
    off: np.ndarray         # row offset of each axis
    plain: bool             # no misses on the kept axes and n_a == n_b
    axis_of: np.ndarray     # (E,) axis of each row
    ptr: np.ndarray         # (E+1,) CSR: candidates of each row
    lst: np.ndarray
    int_costs: bool
    y0: np.ndarray          # starting multipliers (0 on kept rows)

    @classmethod
    def build(cls, problem: AssignmentProblem, keep_axes: Any = None) -> "BnbInput":
        from . import kernels as kern

        a, b = problem.kept_axes(keep_axes)
        relaxed = np.array([s for s in range(problem.ndim) if s not in (a, b)],
                           dtype=np.int64)
        c = np.ascontiguousarray(problem.costs, np.float64)
        args = (problem.tuples, problem.row_offsets, np.asarray(problem.sizes, np.int64),
                c, a, b)
        prepare = kern.pick(kern.name("prepare"), *args, work=problem.n_candidates)
        with kern.uninterrupted():      # a Ctrl-C inside numba's call crashed the process
            G, ptr, lst, y0, axis_of, int_costs, plain = prepare(*args)
        return cls(G=G, c=c, a=a, b=b, relaxed=relaxed, off=problem.row_offsets,
                   plain=bool(plain), axis_of=axis_of, ptr=ptr, lst=lst,
                   int_costs=bool(int_costs), y0=y0)


OPTIONS: tuple[Option, ...] = (
    Option("max_iter", "int", 100, "subgradient iterations", low=0),
    Option("probe_every", "int", 15, "iterations between short searches (0: none)", low=0),
    Option("probe_nodes", "int", 200, "nodes per short search", low=0),
    Option("max_nodes", "int", 200_000, "nodes of the final search", low=1),
    Option("step0", "float", 2.0, "Polyak step scale", low=0.0, low_open=True),
    Option("patience", "int", 10, "iterations without a better bound before the step "
           "scale halves", low=1),
    Option("step_min", "float", 1e-3, "step scale at which the ascent ends", low=0.0,
           low_open=True),
    Option("keep_axes", "axes", None, "the two kept axes (None: the two largest)",
           nullable=True),
    Option("fallback", "bool", True, "hand the problem to lagrangian-exact when the node "
           "budget is spent or it is too large for the kernels"),
    Option("deflect", "float", 0.5, "share of the previous direction kept", low=0.0,
           high=1.0, high_open=True),
    Option("recover_every", "int", 1, "N = 3 primal recovery every k iterations "
           "(0: never)", low=0),
    Option("warm_start", "bool", True, "each Hungarian solve starts from the previous "
           "potentials"),
    Option("stall_tol", "float", 0.0, "leave the ascent when the bound gained less than "
           "this share of the gap since the last short search (0: off)", low=0.0,
           high=1.0, high_open=True),
)
DEFAULTS: dict[str, Any] = {o.name: o.default for o in OPTIONS}


@register
class BranchBoundBackend(Backend):
    """Compiled Lagrangian branch and bound (numba); exact, for small S-D problems."""

    name = "bnb"
    module = "numba"
    imports = ()             # numba: only when a kernel is compiled (kernels.tiers)
    distribution = "numba"
    description = ("compiled Lagrangian-bounded exact-cover branch and bound "
                   "(numba; small S-D problems)")
    supports_time_limit = True
    options = OPTIONS
    own_method = True        # numba only compiles it


    def solve(self, problem: AssignmentProblem, options: SolveOptions) -> RawResult:
        p = self.settings(problem, options)
        if (empty := empty_answer(problem, options, self.name)) is not None:
            return empty
        from . import kernels as kern      # numba: imported when a kernel compiles
        t0 = time.perf_counter()
        k0 = sum(kern.spent())    # compile / cache load: reported apart (api.solve)

        why = too_large(problem, p["keep_axes"])
        if why is not None:
            if not p["fallback"]:
                raise ProblemTooLargeError(
                    f"solver 'bnb' works on dense kept-axes matrices and this problem is "
                    f"too large for them ({why}); use 'lagrangian-exact' or fallback=True")
            return self._fallback(problem, options, {"parameters": dict(p), "reason": why},
                                  t0, k0)
        inp = BnbInput.build(problem, p["keep_axes"])
        na, nb = problem.sizes[inp.a], problem.sizes[inp.b]
        probe_nodes = p["probe_nodes"]
        T = problem.tuples
        # N = 3: primal recovery through a dense (n_a+1)(n_b+1)(n_c+1) tuple lookup
        n3 = problem.ndim == 3 and math.prod(s + 1 for s in problem.sizes) <= MAX_DENSE
        c_axis = int(inp.relaxed[0]) if len(inp.relaxed) == 1 else 0
        off_c, n_c = int(inp.off[c_axis]), int(problem.sizes[c_axis])
        stop = new_stop()
        args = (
            inp.G, T[:, inp.a].copy(), T[:, inp.b].copy(), inp.c, inp.relaxed,
            inp.a, inp.b, int(inp.off[inp.a]), int(inp.off[inp.b]), na, nb, inp.plain,
            inp.axis_of, inp.ptr, inp.lst, inp.int_costs, TOL, inp.y0, p["max_iter"],
            p["probe_every"], probe_nodes, p["max_nodes"], p["step0"], p["patience"],
            p["step_min"], p["deflect"], p["recover_every"], n3, off_c, n_c,
            p["warm_start"], p["stall_tol"], stop)
        kern.pick(kern.name("solve"), *args, work=problem.n_candidates)   # compile now
        t_build = time.perf_counter() - t0 - (sum(kern.spent()) - k0)
        t1 = time.perf_counter()
        # the limit counts building, not the one-off compilation / cache load
        deadline = None if options.time_limit is None else \
            t1 + max(options.time_limit - t_build, 0.0)
        (out, sel, n_sel, ub, bound, iters, nodes), by_clock = run_tiered(
            kern.name("solve"), args, stop, work=problem.n_candidates, deadline=deadline,
            inline=problem.n_candidates <= INLINE_CANDIDATES)
        dt = t_build + time.perf_counter() - t1
        params = {k: v for k, v in p.items()}
        params.update(keep_axes=[inp.a, inp.b], tol=TOL)
        info: dict[str, Any] = {"iterations": int(iters), "nodes": int(nodes),
                                "lagrangian_bound": float(bound), "parameters": params,
                                "integer_costs": inp.int_costs,
                                "numba_version": _distribution_version("numba")}
        selected = np.sort(sel[:n_sel]) if n_sel > 0 else None
        if out == kern.INFEASIBLE or (out == kern.PROVEN and selected is None):
            why = ("the kept axes admit no assignment" if out == kern.INFEASIBLE
                   else "the search found no exact cover")
            return RawResult(Status.INFEASIBLE, message=f"bnb: infeasible ({why})",
                             info=info, build_time=t_build, solve_time=dt - t_build)
        if out == kern.PROVEN:
            info["proof"] = "Lagrangian branch and bound completed"
            return RawResult(Status.OPTIMAL, selected=selected, bound=float(ub),
                             message=f"bnb: optimal after {iters} iterations, {nodes} nodes",
                             info=info, build_time=t_build, solve_time=dt - t_build)
        if by_clock:
            info["stopped_by"] = "time limit"
            return RawResult(Status.TIME_LIMIT, selected=selected,
                             bound=float(bound) if np.isfinite(bound) else None,
                             message=f"bnb: stopped by the time limit after {iters} "
                                     f"iterations, {nodes} nodes",
                             info=info, build_time=t_build, solve_time=dt - t_build)
        if p["fallback"]:
            return self._fallback(problem, options, info, t0, k0)
        return RawResult(Status.NODE_LIMIT, selected=selected,
                         bound=float(bound) if np.isfinite(bound) else None,
                         message=f"bnb: node budget {p['max_nodes']} spent",
                         info=info, build_time=t_build, solve_time=dt - t_build)

    @staticmethod
    def _fallback(problem: AssignmentProblem, options: SolveOptions,
                  info: dict[str, Any], t0: float, k0: float) -> RawResult:
        """Node budget spent (or the problem too large): ``lagrangian-exact``."""
        left = None
        if options.time_limit is not None:
            left = max(options.time_limit - (time.perf_counter() - t0), 1e-3)
        sub = SolveOptions(time_limit=left, mip_gap=options.mip_gap,
                           threads=options.threads, verbose=options.verbose)
        raw = get_backend("lagrangian-exact")().solve(problem, sub)
        why = info.get("reason", "node budget spent")
        raw.info = dict(raw.info, bnb=info, requested="bnb", fallback=why)
        raw.solver = "lagrangian-exact"      # the method that produced the answer
        raw.message = f"bnb: {why}, then {raw.message}"
        from . import kernels as kern
        kernels = sum(kern.spent()) - k0     # reported apart by api.solve
        raw.solve_time = max(time.perf_counter() - t0 - raw.build_time - kernels, 0.0)
        return raw
