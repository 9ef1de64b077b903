"""``bnb`` over a batch of independent components, in one compiled call.

Used by :mod:`assocopt.solving.decompose`: the components ``bnb`` suits are concatenated
(each relabelled to its own indices) and handed to
:func:`assocopt.solvers.kernels.batch.solve_batch`, which runs ``bnb``'s ascent and
search on each in turn, at ``bnb``'s default settings but for more frequent short
searches (:data:`BATCH_PROBE_EVERY`), or with ``solver="bnb"`` at ``bnb``'s own.
Components whose node budget runs out are returned to the caller, which solves them
alone (``lagrangian-exact``); a time limit or Ctrl-C stops
the call between two ascent iterations or 1024 search nodes (small components run
first in the calling thread, up to a bounded amount of work, as ``bnb`` runs a small
problem; the rest in a worker thread: :func:`run_batch`).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from ...model.solution import Status
from ..base import SolveOptions
from .backend import DEFAULTS, INLINE_CANDIDATES, TOL
from ..interruptible import new_stop
from ..kernels.outcomes import STOPPED
from .kernels import run_tiered

__all__ = ["solve_components", "run_batch", "INLINE_WORK", "BATCH_PROBE_EVERY"]

#: Work (candidates x (ascent iterations + search nodes), summed over components) that
#: a batch does in the calling thread before the rest goes to a worker thread: about
#: 10-20 ms (a gated scan's component of 300 candidates: 1 iteration, 100 nodes, 30k).
INLINE_WORK = 10_000_000
#: Ascent iterations between short searches in a batch that runs without ``bnb``
#: options (``auto``; ``solver="bnb"`` keeps ``bnb``'s own ``probe_every``, 15).  A
#: gated component's ascent iteration costs about as much as tens of search nodes, and
#: most components are proven by their first or second short search: over the batches
#: of 22 tuning scans (N = 3-6, seeds 51-52) the kernel took 52-57 ms at 2-4 against
#: 67 ms at 15 (N = 3 alone: 22 against 35 ms).  Dense grids keep 15: there 3 was
#: slower (n = 12-14: 23-31 against 18-23 ms).
BATCH_PROBE_EVERY = 3


def run_batch(T: np.ndarray, c: np.ndarray, kp: np.ndarray, sizes: np.ndarray,
              params: dict[str, Any] | None = None, deadline: float | None = None
              ) -> tuple[tuple[np.ndarray, ...], bool]:
    """The kernel on ``(T, c, kp, sizes)`` (local tuples, ``sizes`` (parts, N)):
    ``((outcome, ub, bound, chosen), stopped_by_clock)``.

    Without a deadline the components of at most ``bnb.INLINE_CANDIDATES``
    candidates are solved first in the calling thread, as ``bnb`` solves such a
    problem, until :data:`INLINE_WORK` is done (so that a Ctrl-C waits for at most
    that and one component); the rest go to a worker thread that Ctrl-C and the clock
    can stop.  Handing a scan's batch to a thread cost 0.1 ms of its 1-2 ms."""
    p = {**DEFAULTS, "probe_every": BATCH_PROBE_EVERY, **(params or {})}
    C = len(kp) - 1
    outcome = np.full(C, STOPPED, np.int64)
    ub = np.full(C, np.inf)
    lb = np.full(C, -np.inf)
    chosen = np.zeros(len(T), np.int8)
    head = (np.ascontiguousarray(T, np.int64), np.ascontiguousarray(c, np.float64),
            kp, np.ascontiguousarray(sizes, np.int64), TOL, p["max_iter"],
            p["probe_every"], p["probe_nodes"], p["max_nodes"], p["step0"], p["patience"],
            p["step_min"], p["deflect"], p["recover_every"], p["warm_start"],
            p["stall_tol"])
    answer = (outcome, ub, lb, chosen)

    def args(todo: np.ndarray, cap: float) -> tuple:
        return head + (todo, float(cap)) + answer + (new_stop(),)
    # the argument types never change here (options arrive parsed): the compiled
    # kernel is handed out without typing 23 arguments again (pick_fixed)
    from ..kernels import pick_fixed
    todo = np.arange(C, dtype=np.int64)
    pick_fixed("batch.solve_batch", *args(todo, np.inf), work=len(T))  # compile now
    if deadline is None:
        small = np.diff(kp) <= INLINE_CANDIDATES
        first = todo[small]
        a = args(first, INLINE_WORK)
        done, _ = run_tiered("batch.solve_batch", a, a[-1], work=len(T), inline=True,
                             fixed=True)
        todo = np.concatenate([first[done:], todo[~small]])
        if len(todo) == 0:
            return answer, False
    a = args(todo, np.inf)
    _, by_clock = run_tiered("batch.solve_batch", a, a[-1], work=len(T), deadline=deadline,
                             fixed=True)
    return answer, by_clock


def solve_components(sp: Any, comps: np.ndarray, arrays: tuple[np.ndarray, ...],
                     opts: SolveOptions, left: float | None, out: Any) -> np.ndarray:
    """Solve components ``comps`` of the split ``sp`` (``split(..., scan=True)``) in
    one kernel call, adding their answers to ``out``
    (:class:`assocopt.solving.decompose._Outcome`); returns the components whose node
    budget ran out, for the caller to solve alone.  ``arrays``: their ``(T, c, kp,
    cand)`` (:func:`assocopt.problems.components.plan` or ``gather``)."""
    import time
    if len(comps) == 0:
        return comps
    Tb, cb, kp, cand = arrays
    params = {k: v for k, v in opts.extra.items() if k in DEFAULTS} \
        if opts.parsed else {}
    params.pop("keep_axes", None)
    params.pop("fallback", None)
    deadline = None if left is None else time.perf_counter() + max(left, 0.0)
    (outcome, ub, lb, chosen), by_clock = run_batch(Tb, cb, kp, sp.csizes[comps], params,
                                                    deadline)
    from ..kernels.outcomes import INFEASIBLE, PROVEN
    proven = outcome == PROVEN
    found = np.isfinite(ub)
    ok = proven & found
    if ok.any():
        sel = cand[chosen.view(np.bool_)]
        out.add(Status.OPTIMAL, sel, float(ub[ok].sum()), "bnb", int(ok.sum()))
    bad = (outcome == INFEASIBLE) | (proven & ~found)
    if bad.any():
        out.add(Status.INFEASIBLE, None, None, "bnb", int(bad.sum()),
                "a component admits no exact cover")
    stopped = ~proven & ~(outcome == INFEASIBLE)
    if by_clock and stopped.any():
        out.add(Status.TIME_LIMIT, None, None, "bnb", int(stopped.sum()),
                "stopped by the time limit")
        return comps[:0]
    return comps[stopped]
