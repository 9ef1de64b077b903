"""``solve_many``: many independent problems in one call, the small S-D ones batched.

A loop of :func:`assocopt.solve` pays its dispatch, option parsing, a compiled call and
the answer's checks once per problem, more than the small S-D solve itself costs
(``benchmarks/one_shot.py`` measures both, docs/benchmarks-one-shot.md).  Here
the problems ``bnb`` would get (``solver="auto"`` choosing ``bnb``, or ``solver="bnb"``;
no options, no relaxation, no limit, no gap; small enough for ``bnb``'s kernels, costs
in range) are stacked, each keeping its own indices, and handed to the batch kernel of
:mod:`assocopt.solvers.bnb.batch` in one compiled call, as the components of one
decomposed problem are; each answer is then checked and finished exactly as ``solve``
finishes one (feasibility, objective recomputed, maximisation sense).  A problem whose
node budget runs out in the batch, and every other problem, goes to ``solve`` itself, so
the answers are ``solve``'s: the same status and objective (where a problem has several
optimal assignments, the one returned may differ).
"""

from __future__ import annotations

import math
import time
from typing import Any, Iterable

import numpy as np

from ..model.solution import Solution, Status
from ..problems.problem import AssignmentProblem
from ..runtime.errors import InvalidProblemError
from ..solvers.base import get_backend
from ..solvers.kernels import spent
from .api import solve, to_user_sense
from .decompose import MIN_CANDIDATES

__all__ = ["solve_many"]

#: Problems below this many candidates are batched; from it on ``solve`` decomposes
#: a problem into components and batches those itself.
BATCH_BELOW = MIN_CANDIDATES


def solve_many(problems: Iterable[AssignmentProblem], solver: str = "auto",
               **options: Any) -> list[Solution]:
    """One :class:`~assocopt.Solution` per problem, in order, as
    ``[solve(p, solver, **options) for p in problems]`` gives, but faster for many
    small S-D problems: those ``solve`` would hand to ``bnb`` are solved together in
    one compiled call (``Solution.info["batch"]`` then says how many shared it, and
    ``times`` holds each problem's share of the call).

    Parameters
    ----------
    problems : iterable of AssignmentProblem
    solver : str
        As for :func:`assocopt.solve`; ``"auto"`` and ``"bnb"`` batch.
    **options
        As for :func:`assocopt.solve` (``relax``, ``time_limit``, back-end options...);
        with any of them given, every problem goes to ``solve`` one by one.

    Examples
    --------
    >>> import numpy as np
    >>> from assocopt import AssignmentProblem, solve_many
    >>> rng = np.random.default_rng(0)
    >>> ps = [AssignmentProblem.dense(rng.random((3, 3, 3))) for _ in range(3)]
    >>> [s.status.value for s in solve_many(ps)]
    ['optimal', 'optimal', 'optimal']
    """
    items = list(problems)
    for i, p in enumerate(items):
        if not isinstance(p, AssignmentProblem):
            raise InvalidProblemError(
                f"problems[{i}] must be an AssignmentProblem, got {type(p).__name__}")
    out: list[Solution | None] = [None] * len(items)
    if not options and solver in ("auto", "bnb") and _numba_installed():
        groups: dict[int, list[int]] = {}
        for i, p in enumerate(items):
            if p.ndim >= 3 and p._dense is None and 0 < p.n_candidates < BATCH_BELOW:
                groups.setdefault(p.ndim, []).append(i)
        for members in groups.values():
            if len(members) >= 2:
                for i, sol in zip(members, _solve_batch([items[i] for i in members],
                                                        solver)):
                    out[i] = sol
    for i, p in enumerate(items):
        if out[i] is None:
            out[i] = solve(p, solver, **options)
    return out  # type: ignore[return-value]


def _numba_installed() -> bool:
    from .choice import _numba_installed as installed
    return installed()


def _solve_batch(probs: list[AssignmentProblem], solver: str) -> list[Solution | None]:
    """The batch kernel on ``probs`` (S-D problems with one N; whole problems as its
    parts), checked in bulk; None for a problem left to ``solve``: one the kernel does
    not take as ``solve`` would give it to ``bnb`` (an uncovered index, too large kept
    axes, costs out of range), or did not settle (infeasible, node budget spent)."""
    from ..solvers.bnb.backend import MAX_KEPT
    from ..solvers.bnb.batch import run_batch
    from ..solvers.kernels.outcomes import PROVEN
    from ..solvers.scaling import SCALE_ABOVE
    from .choice import BNB_MAX_KEPT

    t0 = time.perf_counter()
    k0 = spent()
    P = len(probs)
    sizes = np.array([p.sizes for p in probs], np.int64)                 # (P, N)
    counts = np.fromiter((len(p.costs) for p in probs), np.int64, P)
    kp = np.zeros(P + 1, np.int64)
    np.cumsum(counts, out=kp[1:])
    T = np.concatenate([p.tuples for p in probs]).astype(np.int64, copy=False)
    c = np.concatenate([p.costs for p in probs]).astype(np.float64, copy=False)
    pid = np.repeat(np.arange(P), counts)
    # every problem's rows one after the other: global row of each real entry
    n_rows = sizes.sum(axis=1)
    base = np.cumsum(sizes, axis=1) - sizes + (np.cumsum(n_rows) - n_rows)[:, None]
    G = np.where(T > 0, T - 1 + base[pid], -1)
    row_pid = np.repeat(np.arange(P), n_rows)
    cover = np.bincount(G[G >= 0], minlength=int(n_rows.sum()))
    uncovered = np.bincount(row_pid[cover == 0], minlength=P) > 0
    top2 = np.sort(sizes, axis=1)[:, -2:].sum(axis=1)
    amax = np.maximum.reduceat(np.where(np.isfinite(c), np.abs(c), 0.0), kp[:-1])
    ok = ~uncovered & (top2 <= (BNB_MAX_KEPT if solver == "auto" else MAX_KEPT)) & \
        (amax <= SCALE_ABOVE)
    result: list[Solution | None] = [None] * P
    if ok.sum() < 1:
        return result
    keep = ok[pid]
    kq = np.zeros(int(ok.sum()) + 1, np.int64)
    np.cumsum(counts[ok], out=kq[1:])
    t1 = time.perf_counter()
    (outcome, ub, _, chosen), _ = run_batch(T[keep], c[keep], kq, sizes[ok])
    dt = time.perf_counter() - t1
    # the answers' check, in bulk: every row of a settled problem covered exactly once
    picked = np.zeros(len(T), bool)
    picked[keep] = chosen.astype(bool)
    rows = G[picked]
    once = np.bincount(rows[rows >= 0], minlength=len(cover))
    wrong = np.bincount(row_pid[once != 1], minlength=P) > 0
    settled = np.zeros(P, bool)
    settled[ok] = (outcome == PROVEN) & np.isfinite(ub)
    settled &= ~wrong
    k1 = spent()
    version = get_backend("bnb").version()
    share = (time.perf_counter() - t0 - dt) / P + dt / int(ok.sum())
    info = {"batch": {"problems": int(ok.sum()), "kernel_seconds": dt}}
    if k1 != k0:
        info.update(compile_time=k1[0] - k0[0], cache_load_time=k1[1] - k0[1])
    ub_of = np.full(P, np.nan)
    ub_of[ok] = ub
    for j in np.flatnonzero(settled).tolist():
        p = probs[j]
        sel = np.flatnonzero(picked[kp[j]:kp[j + 1]])
        obj = math.fsum(p.costs[sel].tolist())
        sol = Solution(Status.OPTIMAL, objective=obj, bound=min(float(ub_of[j]), obj),
                       selected=sel, tuples=p.tuples[sel[~p.slack[sel]]], solver="bnb",
                       solver_version=version, message="bnb: optimal (batch kernel)",
                       info=dict(info, options={}),
                       times={"build": 0.0, "solve": share, "total": share})
        result[j] = to_user_sense(sol) if p.maximize else sol
    return result
