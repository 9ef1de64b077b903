"""ILP and LP relaxation of the S-D assignment problem as solver-neutral arrays.

One binary variable ``rho_k`` per candidate tuple k (eq. (6) of paper 002); one equality
row per real index (eq. (8)): ``sum_{k covers (s, i)} rho_k = 1``.  The LP relaxation
replaces ``rho_k in {0, 1}`` by ``0 <= rho_k <= 1``.  Everything is built in bulk from
the tuple array (one CSR matrix), never one call per variable; each back end turns
this into its own API in bulk as well.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from ..problems.problem import AssignmentProblem

if TYPE_CHECKING:
    import scipy.sparse as sp

__all__ = ["LinearModel", "build_model", "RELAXATIONS"]

#: Accepted values of ``relax``: None (the ILP) or "lp" (the LP relaxation).
RELAXATIONS = (None, "lp")


@dataclass(frozen=True)
class LinearModel:
    """``min c @ x  s.t.  row_lower <= A @ x <= row_upper,  lb <= x <= ub``.

    ``integrality[k] = 1`` marks binary variables (all of them for the ILP, none for
    the LP relaxation), in scipy.optimize.milp's convention.
    """

    c: np.ndarray
    A: sp.csr_matrix
    row_lower: np.ndarray
    row_upper: np.ndarray
    lb: np.ndarray
    ub: np.ndarray
    integrality: np.ndarray

    @property
    def shape(self) -> tuple[int, int]:
        return self.A.shape

    @property
    def is_mip(self) -> bool:
        return bool(self.integrality.any())


def build_model(problem: AssignmentProblem, relax: str | None = None) -> LinearModel:
    """The ILP (``relax=None``) or its LP relaxation (``relax="lp"``) of ``problem``."""
    if relax not in RELAXATIONS:
        raise ValueError(f"relax must be one of {RELAXATIONS}, got {relax!r}")
    K = problem.n_candidates
    A = problem.coverage_matrix()
    ones_rows = np.ones(problem.n_rows)
    return LinearModel(
        c=np.array(problem.costs, dtype=np.float64),
        A=A,
        row_lower=ones_rows,
        row_upper=ones_rows.copy(),
        lb=np.zeros(K),
        ub=np.ones(K),
        integrality=np.full(K, 0 if relax == "lp" else 1, dtype=np.uint8),
    )
