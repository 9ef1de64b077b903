"""Paper 001's decisions: the maximum-degree rule with threshold, the association-quality
counter with fixing, and two counterparts (a one-to-one 2-D assignment, ours; the
weighted chi-square test of the paper's ref. [2]).  See docs/papers/yan2010.md.

Rules (:data:`RULES`), each deciding at every time step which node-2 track (column)
goes with each node-1 track (row), ``-1`` for none:

``"max-degree"``
    the paper's rule: ``j* = argmax_j m_ij``; row ``i`` takes ``j*`` if ``m_ij* > eps``.
    Nothing stops two rows from taking the same column.
``"assignment"``
    ours: a one-to-one 2-D assignment on the fused degrees, solved by
    :func:`assocopt.solve`.  A pair costs ``-ln m`` (``cost="neglog"``) or ``1 - m``
    (``cost="one-minus"``); leaving a row or a column unassigned costs half the cost of
    a pair of degree ``eps``, so, in isolation, a pair is taken exactly when its degree
    beats ``eps``.  Pairs of degree 0 are forbidden.
``"weighted"``
    the weighted track-association test of ref. [2]: pair ``(i, j)`` passes when its
    statistical distance (3) is below the chi-square gate of ``n_x`` degrees of freedom;
    row ``i`` takes the passing column of smallest distance.

Association quality (eqs. 8-9) with fixing, :class:`QualityCounter`: a pair decided
at step k gains 1, every other pair of the open rows and columns loses 1, and a pair
whose count reaches ``fix_at`` (6 in the paper) becomes fixed: it is reported as
associated from then on and its row and column leave the later tests.  The paper's
decrement makes never-associated pairs negative although it says a first association
goes from 0 to 1; the semantics are a named option (:data:`COUNTER_SEMANTICS`):
``"literal"`` (eq. 9 as printed, unbounded), ``"floor"`` (never below 0), ``"seen"``
(only pairs associated before are decremented, without floor), ``"off"`` (no
counter, no fixing: the decision of each step stands alone).
"""

from __future__ import annotations

from dataclasses import asdict, dataclass

import numpy as np
from scipy.stats import chi2

from ...solving.api import solve
from ...problems.problem import AssignmentProblem
from ..costs.association_degree import (DegreeParams, fused_degree, pair_feature_degrees,
                                        state_degree)

__all__ = ["RULES", "ASSIGNMENT_COSTS", "COUNTER_SEMANTICS", "DecisionOptions",
           "QualityCounter", "max_degree_rule", "assignment_rule", "weighted_rule",
           "TrackAssociator", "shared_columns"]

RULES = ("max-degree", "assignment", "weighted")
ASSIGNMENT_COSTS = ("neglog", "one-minus")
COUNTER_SEMANTICS = ("literal", "floor", "seen", "off")


@dataclass(frozen=True)
class DecisionOptions:
    """How a :class:`TrackAssociator` decides (every field recorded with results).

    ``eps``: the degree threshold (paper: 0.5 <= eps < 1, value not given);
    ``gate_alpha``: the weighted test's chi-square tail probability (ours);
    ``solver``: back end of the assignment rule.
    """

    rule: str = "max-degree"
    eps: float = 0.5
    counter: str = "floor"
    fix_at: int = 6
    cost: str = "neglog"
    gate_alpha: float = 0.01
    solver: str = "auto"

    def __post_init__(self) -> None:
        if self.rule not in RULES:
            raise ValueError(f"rule must be one of {RULES}, got {self.rule!r}")
        if self.counter not in COUNTER_SEMANTICS:
            raise ValueError(f"counter must be one of {COUNTER_SEMANTICS}, got {self.counter!r}")
        if self.cost not in ASSIGNMENT_COSTS:
            raise ValueError(f"cost must be one of {ASSIGNMENT_COSTS}, got {self.cost!r}")
        if not 0.0 < self.eps < 1.0:
            raise ValueError(f"eps must be in (0, 1), got {self.eps!r}")
        if not (isinstance(self.fix_at, int) and self.fix_at >= 1):
            raise ValueError(f"fix_at must be a positive integer, got {self.fix_at!r}")
        if not 0.0 < self.gate_alpha < 1.0:
            raise ValueError(f"gate_alpha must be in (0, 1), got {self.gate_alpha!r}")

    def as_dict(self) -> dict:
        return asdict(self)


# ------------------------------------------------------------------- single-step rules
def max_degree_rule(m: np.ndarray, eps: float) -> np.ndarray:
    """The paper's rule on fused degrees ``(n1, n2)``: partner column per row, -1 for none.

    >>> max_degree_rule(np.array([[0.7, 0.3], [0.6, 0.4], [0.5, 0.5]]), 0.5).tolist()
    [0, 0, -1]
    """
    m = np.asarray(m, dtype=np.float64)
    if m.shape[1] == 0:
        return np.full(m.shape[0], -1)
    j = np.argmax(m, axis=1)
    return np.where(m[np.arange(len(m)), j] > eps, j, -1)


def _pair_cost(m: np.ndarray, cost: str) -> np.ndarray:
    if cost == "neglog":
        with np.errstate(divide="ignore"):
            return np.where(m > 0, -np.log(np.where(m > 0, m, 1.0)), np.inf)
    return np.where(m > 0, 1.0 - m, np.inf)


def assignment_rule(m: np.ndarray, eps: float, cost: str = "neglog",
                    solver: str = "auto") -> np.ndarray:
    """One-to-one 2-D assignment on fused degrees (module docstring), via :func:`solve`.

    >>> assignment_rule(np.array([[0.7, 0.3], [0.6, 0.4], [0.5, 0.5]]), 0.5).tolist()
    [0, -1, -1]
    """
    m = np.asarray(m, dtype=np.float64)
    n1, n2 = m.shape
    out = np.full(n1, -1)
    if n1 == 0 or n2 == 0:
        return out
    C = _pair_cost(m, cost)
    if not np.isfinite(C).any():
        return out
    miss = float(_pair_cost(np.array([eps]), cost)[0]) / 2.0
    sol = solve(AssignmentProblem.two_d(C, row_miss=miss, col_miss=miss), solver=solver)
    if sol.tuples is None:
        raise RuntimeError(f"2-D assignment failed: status {sol.status}")
    r, c = sol.assignment()
    out[r] = c
    return out


def weighted_rule(D: np.ndarray, gate: float) -> np.ndarray:
    """Ref. [2]'s weighted test: nearest column among those with ``D_ij <= gate``.

    >>> weighted_rule(np.array([[1.0, 3.0], [20.0, 30.0]]), 13.28).tolist()
    [0, -1]
    """
    D = np.asarray(D, dtype=np.float64)
    if D.shape[1] == 0:
        return np.full(D.shape[0], -1)
    j = np.argmin(D, axis=1)
    return np.where(D[np.arange(len(D)), j] <= gate, j, -1)


def shared_columns(partner: np.ndarray) -> int:
    """Number of columns taken by two or more rows at once."""
    p = np.asarray(partner)
    p = p[p >= 0]
    return int((np.bincount(p) > 1).sum()) if len(p) else 0


# ------------------------------------------------------------------- quality counter
class QualityCounter:
    """Association quality (8)-(9) of every pair, and the fixed pairs (module docstring)."""

    def __init__(self, n1: int, n2: int, semantics: str = "floor", fix_at: int = 6):
        if semantics not in COUNTER_SEMANTICS:
            raise ValueError(f"counter semantics must be one of {COUNTER_SEMANTICS}, "
                             f"got {semantics!r}")
        self.semantics, self.fix_at = semantics, fix_at
        self.delta = np.zeros((n1, n2), dtype=np.int64)
        self.seen = np.zeros((n1, n2), dtype=bool)
        self.fixed = np.full(n1, -1)            # fixed partner per row
        self.col_fixed = np.zeros(n2, dtype=bool)

    @property
    def open_rows(self) -> np.ndarray:
        return self.fixed < 0

    @property
    def open_cols(self) -> np.ndarray:
        return ~self.col_fixed

    def update(self, partner: np.ndarray) -> None:
        """Count the decisions of one step (``partner`` per row, -1 none) and fix pairs.

        Only the block of open rows and columns changes (and the count of a pair that
        an open row took in a closed column, +1), so the work is done on that block.
        """
        if self.semantics == "off":
            return
        partner = np.asarray(partner)
        if partner.shape != self.fixed.shape:
            raise ValueError(f"partner must have shape {self.fixed.shape}, got {partner.shape}")
        ri, cj = np.flatnonzero(self.open_rows), np.flatnonzero(self.open_cols)
        i = ri[partner[ri] >= 0]
        j = partner[i]
        col_at = np.full(self.delta.shape[1], -1)
        col_at[cj] = np.arange(len(cj))
        row_at = np.full(self.delta.shape[0], -1)
        row_at[ri] = np.arange(len(ri))
        inside = col_at[j] >= 0
        blk = np.ix_(ri, cj)
        assoc = np.zeros((len(ri), len(cj)), dtype=bool)
        assoc[row_at[i[inside]], col_at[j[inside]]] = True
        dec = ~assoc
        if self.semantics == "seen":
            dec &= self.seen[blk]
        d = self.delta[blk] + assoc.astype(np.int64) - dec.astype(np.int64)
        if self.semantics == "floor":
            np.maximum(d, 0, out=d)
        self.delta[blk] = d
        self.delta[i[~inside], j[~inside]] += 1           # outside the open block
        self.seen[i, j] = True
        cand = np.argwhere(d >= self.fix_at)
        if len(cand):
            order = np.lexsort((cand[:, 0], -d[cand[:, 0], cand[:, 1]]))
            for a, b in zip(ri[cand[order, 0]], cj[cand[order, 1]]):   # highest count first
                if self.fixed[a] < 0 and not self.col_fixed[b]:
                    self.fixed[a] = b
                    self.col_fixed[b] = True


# ------------------------------------------------------------------------- associator
class TrackAssociator:
    """Step-by-step track-to-track association between two nodes.

    ``step(D, f1, f2)`` takes the statistical distances (3) of every pair and the
    feature vectors (frequency, PW, PRI) of both nodes' tracks, computes the degrees
    over the open rows and columns, decides, updates the counter and returns each
    row's partner (fixed pairs included), ``-1`` for none.
    """

    def __init__(self, n1: int, n2: int, params: DegreeParams,
                 options: DecisionOptions = DecisionOptions(), n_x: int = 4):
        self.params, self.options = params, options
        self.counter = QualityCounter(n1, n2, options.counter, options.fix_at)
        self.gate = float(chi2.ppf(1.0 - options.gate_alpha, n_x))
        self.last_open_partner = np.full(n1, -1)

    @property
    def needs_input(self) -> bool:
        """Whether a step has anything to decide (an open row and an open column)."""
        return bool(self.counter.open_rows.any() and self.counter.open_cols.any())

    def step(self, D: np.ndarray, f1: np.ndarray, f2: np.ndarray,
             feature_m: np.ndarray | None = None, memo: dict | None = None) -> np.ndarray:
        """One scan; ``feature_m`` optionally gives :func:`pair_feature_degrees` of all
        pairs (computed once when several associators decide the same scan).  ``memo``
        (a dict the caller empties for every scan) shares the fused degrees between
        associators that decide that scan with equal :class:`DegreeParams` over the same
        open rows and columns."""
        o, ctr = self.options, self.counter
        n1, n2 = ctr.delta.shape
        D, f1, f2 = np.asarray(D, float), np.asarray(f1, float), np.asarray(f2, float)
        if D.shape != (n1, n2):
            raise ValueError(f"D must have shape ({n1}, {n2}), got {D.shape}")
        if f1.shape != (n1, 3) or f2.shape != (n2, 3):
            raise ValueError(f"features must have shapes ({n1}, 3) and ({n2}, 3), got "
                             f"{f1.shape} and {f2.shape}")
        rows, cols = np.flatnonzero(ctr.open_rows), np.flatnonzero(ctr.open_cols)
        sub = np.full(len(rows), -1)
        if len(rows) and len(cols):
            Dsub = D[np.ix_(rows, cols)]
            if o.rule == "weighted":
                sub = weighted_rule(Dsub, self.gate)
            else:
                key = (self.params, rows.tobytes(), cols.tobytes())
                m = None if memo is None else memo.get(key)
                if m is None:
                    m = self._fused(Dsub, f1[rows], f2[cols],
                                    None if feature_m is None else feature_m[:, rows][:, :, cols])
                    if memo is not None:
                        memo[key] = m
                sub = (max_degree_rule(m, o.eps) if o.rule == "max-degree" else
                       assignment_rule(m, o.eps, o.cost, o.solver))
        partner = np.full(D.shape[0], -1)
        took = sub >= 0                      # no open column left: every open row gets -1
        partner[rows[took]] = cols[sub[took]]
        self.last_open_partner = partner.copy()
        out = np.where(ctr.fixed >= 0, ctr.fixed, partner)
        ctr.update(partner)
        return out

    def _fused(self, D: np.ndarray, f1: np.ndarray, f2: np.ndarray,
               F: np.ndarray | None) -> np.ndarray:
        """Fused degrees (4)-(7) of the open block: distances ``D``, features ``f1``,
        ``f2`` and, when given, their feature degrees ``F``."""
        p = self.params
        F = pair_feature_degrees(f1, f2, p) if F is None else F
        return fused_degree(np.concatenate([state_degree(D, p.weights[0], p.d_tiny)[None], F]),
                            p.fusion)
