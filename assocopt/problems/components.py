"""Connected components of an S-D problem: two candidates are connected when they
share a real index, and no constraint couples two components, so each can be solved
alone.  Used by :mod:`assocopt.solving.decompose` (whole problems) and by the
``lagrangian-exact`` windows (candidate subsets left by reduced-cost fixing, which
split much further than the problem they come from).

Components are found in bulk: a graph on the real indices (constraint rows) with an
edge from each candidate's first real index to each of its other ones, and
:func:`scipy.sparse.csgraph.connected_components` on it; or, where the solvers run
it compiled, one union-find pass (:mod:`assocopt.solvers.kernels.components`, the same
labels: components in the order of their smallest row).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

import numpy as np

from .problem import AssignmentProblem

__all__ = ["Split", "split", "split_rows", "local_tuples", "subproblem", "gather",
           "component_tuples", "plan"]


@dataclass(frozen=True)
class Split:
    """The components of a problem.

    ``n``: how many; ``of_row`` (E,) and ``of_cand`` (K,): the component of each
    real index (constraint row) and candidate; ``order`` the candidates sorted by
    component, ``ptr`` (n+1,) where each component's run starts; ``trivial`` (n,):
    every real index of the component has exactly one candidate.
    """

    n: int
    of_row: np.ndarray
    of_cand: np.ndarray
    order: np.ndarray
    ptr: np.ndarray
    trivial: np.ndarray
    #: with ``split(..., scan=True)``: each row's index within its component and axis
    #: (E,), ``1..``; the components' axis sizes (n, N); whether a component holds a
    #: tuple with a dummy (n,)
    local: np.ndarray | None = None
    csizes: np.ndarray | None = None
    gated: np.ndarray | None = None

    @property
    def sizes(self) -> np.ndarray:
        """Candidates per component."""
        return np.diff(self.ptr)


def split(problem: AssignmentProblem, run: Callable | None = None,
          scan: bool = False) -> Split:
    """The connected components of ``problem`` (every real index covered).

    ``run``: :func:`assocopt.solvers.kernels.routed` (the solvers pass it), which runs
    the compiled kernel :func:`assocopt.solvers.kernels.components.split_rows` where
    that costs less, else the numpy route below (same answer).  ``scan``: also the
    local row indices, axis sizes and dummy flags of the components (the kernel
    ``scan_parts``), which :func:`gather` and :func:`component_tuples` read."""
    E = problem.n_rows
    if scan:
        axis = np.repeat(np.arange(problem.ndim, dtype=np.int64), problem.sizes)
        fallback = lambda T, off, E, axis: _scan_parts(problem, E, axis)  # noqa: E731
        if run is None:
            return Split(*fallback(None, None, E, axis))
        return Split(*run("components.scan_parts", fallback, problem.tuples,
                          problem.row_offsets, E, axis, work=problem.n_candidates))
    if run is None:
        return Split(*split_rows(problem.entry_rows, E))
    # the kernel reads the tuples (no entry-row array built); numpy reads the rows
    return Split(*run("components.split_rows",
                      lambda T, off, E: split_rows(problem.entry_rows, E),
                      problem.tuples, problem.row_offsets, E, work=problem.n_candidates))


def split_rows(R: np.ndarray, E: int) -> tuple:
    """``(n, of_row, of_cand, order, ptr, trivial)`` of entry rows ``R`` (K, N; -1 a
    dummy) over ``E`` rows: numpy and scipy's ``connected_components``."""
    from scipy.sparse import csr_matrix
    from scipy.sparse.csgraph import connected_components

    K = len(R)
    real = R >= 0
    first = R[np.arange(K), np.argmax(real, axis=1)]
    src = np.broadcast_to(first[:, None], R.shape)[real]
    dst = R[real][np.argsort(src, kind="stable")]
    ptr = np.zeros(E + 1, np.int64)                # CSR built directly (no COO pass)
    np.cumsum(np.bincount(src, minlength=E), out=ptr[1:])
    idx = np.int32 if E < 2 ** 31 else np.int64
    graph = csr_matrix((np.ones(len(dst)), dst.astype(idx), ptr.astype(idx)), shape=(E, E))
    n, of_row = connected_components(graph, directed=False)
    of_row = of_row.astype(np.int64)
    of_cand = of_row[first]
    order = np.argsort(of_cand, kind="stable")
    ptr = np.zeros(n + 1, np.int64)
    np.cumsum(np.bincount(of_cand, minlength=n), out=ptr[1:])
    cover = np.bincount(R[real], minlength=E)
    trivial = np.bincount(of_row[cover > 1], minlength=n) == 0
    return n, of_row, of_cand, order, ptr, trivial


def _scan_parts(problem: AssignmentProblem, E: int, axis_of_row: np.ndarray) -> tuple:
    """The kernel ``scan_parts`` in numpy."""
    from .indexing import real_counts
    N = problem.ndim
    n, of_row, of_cand, order, ptr, trivial = split_rows(problem.entry_rows, E)
    local, counts = _local_index(of_row, n, axis_of_row, N)
    gated = np.bincount(of_cand[real_counts(problem.tuples) < N], minlength=n) > 0
    return n, of_row, of_cand, order, ptr, trivial, local, counts.reshape(n, N), gated


def _local_index(part_of_row: np.ndarray, n_parts: int, axis_of_row: np.ndarray,
                 N: int) -> tuple[np.ndarray, np.ndarray]:
    """Each row's index ``1..`` within its part and axis, in row order, and the rows
    per (part, axis), ``(n_parts * N,)``."""
    key = part_of_row * N + axis_of_row
    order = np.argsort(key, kind="stable")
    counts = np.bincount(key, minlength=n_parts * N)
    start = np.concatenate([[0], np.cumsum(counts)[:-1]])
    local = np.empty(len(key), np.int64)
    local[order] = np.arange(len(key)) - start[key[order]] + 1
    return local, counts


def component_tuples(problem: AssignmentProblem, sp: Split, cand: np.ndarray
                     ) -> np.ndarray:
    """The tuples of candidates ``cand`` relabelled within their components (a split
    with ``scan=True``), ``(len(cand), N)``."""
    R = problem.entry_rows[cand]
    return np.where(R >= 0, sp.local[np.maximum(R, 0)], 0)


def gather(problem: AssignmentProblem, sp: Split, comps: np.ndarray,
           run: Callable | None = None) -> tuple[np.ndarray, ...]:
    """``(T, c, kp, cand)`` of the batch kernel for components ``comps`` of ``sp``
    (split with ``scan=True``): their candidates one component after the other, in
    ``sp.order`` (``cand``: the problem's candidate at each position), tuples
    relabelled within their components, ``kp`` where each starts.  ``run``: as for
    :func:`split` (the kernel ``gather_parts``)."""
    comps = np.ascontiguousarray(comps, np.int64)

    def numpy_route(T0, costs, off, local, order, ptr, comps):
        counts = ptr[comps + 1] - ptr[comps]
        kp = np.zeros(len(comps) + 1, np.int64)
        np.cumsum(counts, out=kp[1:])
        cand = order[np.repeat(ptr[comps] - kp[:-1], counts) + np.arange(kp[-1])]
        return component_tuples(problem, sp, cand), costs[cand], kp, cand
    args = (problem.tuples, problem.costs, problem.row_offsets, sp.local, sp.order,
            sp.ptr, comps)
    if run is None:
        return numpy_route(*args)
    return run("components.gather_parts", numpy_route, *args,
               work=int((sp.ptr[comps + 1] - sp.ptr[comps]).sum()))


def plan(problem: AssignmentProblem, sp: Split, bnb_rule: bool, cap_gated: int,
         cap_plain: int, max_kept: int, max_dense: int, run: Callable | None = None
         ) -> tuple[np.ndarray, ...]:
    """``(batch, rest, T, c, kp, cand)``: the non-trivial components of ``sp`` (split with
    ``scan=True``) a batch of the ``bnb`` kernels takes (by the rule the kernel
    ``plan_parts`` states), the others, and :func:`gather` of ``batch``.  ``run``: as
    for :func:`split` (the kernel ``plan_parts``)."""
    def numpy_route(T0, costs, off, local, order, ptr, csizes, gated, trivial, bnb_rule,
                    cap_gated, cap_plain, max_kept, max_dense):
        todo = np.flatnonzero(~trivial)
        top2 = np.sort(csizes[todo], axis=1)[:, -2:]
        fits = top2.sum(axis=1) <= max_kept
        if bnb_rule:
            fits &= (top2[:, 0] + 1) * (top2[:, 1] + 1) <= max_dense
        else:
            fits &= np.diff(ptr)[todo] <= np.where(gated[todo], cap_gated, cap_plain)
        return (todo[fits], todo[~fits]) + gather(problem, sp, todo[fits])
    args = (problem.tuples, problem.costs, problem.row_offsets, sp.local, sp.order,
            sp.ptr, sp.csizes, sp.gated, sp.trivial, bool(bnb_rule), int(cap_gated),
            int(cap_plain), int(max_kept), int(max_dense))
    if run is None:
        return numpy_route(*args)
    return run("components.plan_parts", numpy_route, *args, work=problem.n_candidates)


def local_tuples(problem: AssignmentProblem, part_of_row: np.ndarray, n_parts: int,
                 run: Callable | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Each candidate's tuple relabelled within its part (parts: groups of whole
    components), ``(K, N)``, and the parts' axis sizes, ``(n_parts, N)``: the real
    indices of a part on axis s become ``1..n_s`` in their original order.  ``run``:
    as for :func:`split` (the kernel ``local_rows``, same answer)."""
    N = problem.ndim
    axis_of_row = np.repeat(np.arange(N), problem.sizes)
    if run is not None:
        return run("components.local_rows",
                   lambda T, off, *rest: _local_rows(problem.entry_rows, *rest),
                   problem.tuples, problem.row_offsets,
                   np.ascontiguousarray(part_of_row, np.int64), int(n_parts),
                   axis_of_row.astype(np.int64), work=problem.n_candidates)
    return _local_rows(problem.entry_rows, part_of_row, n_parts, axis_of_row)


def _local_rows(R: np.ndarray, part_of_row: np.ndarray, n_parts: int,
                axis_of_row: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """:func:`local_tuples` in numpy."""
    N = R.shape[1]
    local, counts = _local_index(part_of_row, n_parts, axis_of_row, N)
    T = np.where(R >= 0, local[np.maximum(R, 0)], 0)
    return T, counts.reshape(n_parts, N)


def subproblem(problem: AssignmentProblem, T: np.ndarray, sizes: np.ndarray,
               cand: np.ndarray, gathered: bool = False) -> AssignmentProblem:
    """The problem of candidates ``cand`` (tuples already relabelled in ``T``: all
    candidates' rows, or with ``gathered`` those of ``cand`` only)."""
    return AssignmentProblem._build(tuple(int(v) for v in sizes),
                                    T if gathered else T[cand],
                                    problem.costs[cand], problem.slack[cand],
                                    kind="sparse")
