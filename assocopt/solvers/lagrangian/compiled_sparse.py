"""The compiled route of the gated (sparse) Lagrangian relaxation.

:class:`_Relaxation` on a gated problem with dummies (not a dense grid,
``lap="sparse"``, miss groups present: the tracking scans that ``auto`` hands to
``lagrangian-exact`` with its tracking options, their components whose kept-axes
pairs all hold the same tails included, where the numpy fast path for such groups
cost 2.1 against 0.9 ms on three components of 300-700 candidates) evaluates ``L(u)``
and recovers primal solutions by the kernels of
:mod:`assocopt.solvers.kernels.sparse_relax` instead of about forty numpy calls per
evaluation and a lexsort plus LAP per relaxed axis per recovery.  The kernels repeat
the numpy code step for step (the same augmented edge lists, in the same order, to the
same compiled LAP), so the selections are identical, and the sums numpy takes
pairwise (``L(u)`` itself) are taken in numpy's order, so the values are too.

Used when numba is installed and the candidate set is large enough
(:data:`assocopt.solvers.kernels.tiers.LIMITS` ``"sparse_relax.sparse_eval"``, or
the kernel already compiled in this process); else, and for the rare LAP without any
finite miss cost (numpy hands that one to scipy), the numpy code runs.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from ..base import module_installed
from ..twod.lap import Assignment2D, LapInfeasibleError

__all__ = ["sparse_kernels", "compiled_route", "SparseKernels"]

EVAL = "sparse_relax.sparse_eval"
RECOVER = "sparse_relax.sparse_recover"
FIXING = "fixing_duals.sparse_fixing"


def _i64(a: Any) -> np.ndarray:
    return np.ascontiguousarray(a, np.int64)


def sparse_kernels(rel: Any, result: type) -> "SparseKernels | None":
    """The compiled route for relaxation ``rel``, or None where the numpy code runs
    (module doc); ``result`` is the relaxation's evaluation type (``_Eval``: handed
    in, as the relaxation module imports this one)."""
    if rel.grid or rel.lap != "sparse" or not rel.has_miss or not rel.K \
            or not rel.relaxed:
        return None
    if not compiled_route(rel.K):
        return None                      # small: numpy beats the interpreted kernel
    return SparseKernels(rel, result)


def compiled_route(candidates: float) -> bool:
    """Whether a gated relaxation of ``candidates`` runs compiled: numba installed
    and :mod:`assocopt.solvers.kernels.tiers` choosing the kernel (compiled mode, the
    kernel loaded in this process, or a candidate set above its limit)."""
    if not module_installed("numba"):
        return False
    from ..kernels import tiers
    return not tiers.interpret(EVAL, candidates, lambda: False)


class SparseKernels:
    """The kernels' arguments for one relaxation, converted once."""

    def __init__(self, rel: Any, result: type):
        self.result = result
        self.nf, self.na, self.nb = int(rel.nf), int(rel.na), int(rel.nb)
        self.c = np.ascontiguousarray(rel.c, np.float64)
        # multiplier slot, per relaxed axis (the compiled layout's own array if any)
        self.U = rel.U_all if rel.U_all is not None else _i64(np.stack(rel.uidx))
        self.u_off = _i64(rel.u_off)
        self.sizes = _i64([rel.sizes[r] for r in rel.relaxed])
        self.groups = (_i64(rel.g_start), _i64(rel.g_count))
        self.lap = (_i64(rel.gkey), self.na, self.nb, _i64(rel.pair_g), _i64(rel.pr),
                    _i64(rel.pc), _i64(rel.rm_g), _i64(rel.rm_i), _i64(rel.cm_g),
                    _i64(rel.cm_j))
        self.fix = (_i64(rel.g_row), _i64(rel.g_col), _i64(rel.g_count), self.nf)
        self.fns: dict[str, Any] = {}

    def _fn(self, name: str, args: tuple) -> Any:
        """:func:`pick`'s answer, asked once per relaxation: the arguments' types never
        change within one (the ascent calls hundreds of times, and ``pick`` typing 18
        arguments cost about as much as a small evaluation)."""
        if name not in self.fns:
            from ..kernels import pick_fixed
            self.fns[name] = pick_fixed(name, *args, work=np.inf)
        return self.fns[name]

    def evaluate(self, upad: np.ndarray) -> Any:
        """``_Relaxation.evaluate`` (an ``_Eval``, reduced costs included), or None:
        left to the numpy code."""
        upad = np.ascontiguousarray(upad, np.float64)
        args = (self.c, self.U, self.u_off, upad, self.nf) + self.groups + self.lap
        status, rc, gmin, chosen, sel, neg, g, cor, roc, value, free_value = \
            self._fn(EVAL, args)(*args)
        if status == 2:
            return None
        if status == 1:
            raise LapInfeasibleError("no perfect matching of the augmented edges")
        return self.result(value, sel, g, chosen, rc, gmin, Assignment2D(cor, roc, "sparse"),
                           free_value)

    def fixing(self, ev: Any, upad: np.ndarray) -> tuple[np.ndarray, np.ndarray, float]:
        """``_Relaxation.fixing_bounds`` from the evaluation ``ev`` at ``upad`` (the
        potentials and reduced costs by :mod:`..kernels.fixing_duals`)."""
        asg = ev.assignment
        args = (ev.rc, ev.gmin, _i64(asg.col_of_row), _i64(asg.row_of_col)) + \
            self.lap[1:] + self.fix
        alpha, beta, red = self._fn(FIXING, args)(*args)
        const = ev.free_value + float(upad.sum())     # summed as the numpy code does
        l_dual = float(alpha.sum() + beta.sum()) + const
        lb = l_dual + red
        nf = self.nf
        lb[:nf] = np.maximum(lb[:nf], ev.value + red[:nf])
        return lb, red, l_dual

    def recover(self, upad: np.ndarray, chosen: np.ndarray) -> tuple[bool, Any]:
        """``(True, _Relaxation.recover's answer)``, or ``(False, None)``: left to the
        numpy code."""
        args = (self.c, self.U, self.u_off, self.sizes,
                np.ascontiguousarray(upad, np.float64), self.nf) + self.groups \
            + (_i64(chosen),)
        status, sel = self._fn(RECOVER, args)(*args)
        if status == 2:
            return False, None
        return True, (sel if status == 0 else None)
