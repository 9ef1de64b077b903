"""Distributed inference decision (DID) of Xue et al. 1999 for report-to-record association.

A new report ``A_0`` (m factors) is compared with n stored records (the columns of
``A``, m x n).  Every (factor, record) pair gets an on/off state; the report joins the
record whose factors all end up "on", or none (a new target).  Page:
``docs/papers/xue1999.md``.

**Stage 1** (preliminary decision), per factor i and record j:

* relative error ``delta_ij``.  The printed form ``|a_i - a_ij| / a_ij`` is undefined
  at ``a_ij = 0``, negative for ``a_ij < 0`` and depends on where the coordinate
  origin is.  Two readings (``error=``): ``"scale"`` (default, ours) divides by a
  scale per factor (e.g. the innovation standard deviation of that factor),
  ``"origin"`` divides by ``max(|a_ij|, floor_i)`` (the printed form made defined).
  Categorical factors (IFF) have ``delta = 0`` when equal and ``inf`` otherwise;
* difference degree ``eta_ij = delta_ij / M`` (M: the sensor's relative accuracy);
* normalisation ``s_off = 1`` if ``eta >= M'``, else ``eta / M'`` (``M' >= 1``), and
  ``s_on = 1 - s_off``.  The paper's threshold variable is undefined; we read it as
  ``eta``, which keeps ``s_off`` continuous and in [0, 1];
* dominance: a factor is on when ``s_on >= s_off`` (i.e. ``eta <= M'/2``).

Then: no factor on anywhere -> new target; exactly one record all on and every other
record all off -> that record; otherwise stage 2.

**Stage 2** (distributed decision), on every record with at least one factor on,
independently: repeatedly take the most ambiguous factor ``i*`` (smallest
``|s_on - 0.5|``) and move it by the others' evidence,
``s_on[i*] += sum_{l != i*} B[i*, l] (s_on[l] - s_off[l])``, ``s_off = 1 - s_on``,
with states clipped to [0, 1] (the paper gives no clipping), until all the record's
factors agree (all on or all off).  Step 5 ("重复第三步, 直到各关联因素一致",
repeat step 3 until the factors agree) comes after one update (steps 3-4), so it
reads as a while loop (``min_updates=0``: a record that already agrees is not
moved) or as a do-while (``min_updates=1``: every record left in stage 2, even one
already all on, gets at least one update); both are literal.  ``B`` is symmetric
with entries in [0, 1] and a zero diagonal.  The loop is capped at ``max_iter`` updates (convergence is asserted in
the paper, not shown); a record that does not settle is *not converged*, is reported
as such and is not associated (``unresolved="reject"``) or is judged by the majority
of its factors (``"majority"``).  With ``select="literal"`` the most ambiguous factor
is taken among all factors, exactly as printed; a saturated factor whose push points
out of [0, 1] then never moves and the loop stalls (stopped, reported not converged).
``select="movable"`` (default, ours) takes it among the factors the update can move.

Finally: no record all on -> new target; one -> it; several -> the one with the largest
score ``q_k = sum_i s_on[i, k]`` over all factors (ties: the lowest index), summed over
the states after stage 2 as printed (``score="final"``) or, as our variant, over the
stage-1 states (``score="initial"``: stage 2 inflates the states it pushes to "on",
so a contradictory record can outscore a consistent one).

The rule as printed is ``error="origin"``, ``select="literal"``, ``score="final"``
with ``min_updates`` 0 or 1; the defaults ``"scale"`` and ``"movable"`` are ours.

Stage 1 is vectorised over reports and records; stage 2 runs every unsettled
(report, record) column through one compiled (numba) loop.

Examples
--------
>>> import numpy as np
>>> p = DIDParams(M=1.0, M_prime=6.0, B=0.2)
>>> delta = np.array([[[0.5, 5.0], [1.0, 4.0], [0.0, np.inf]]])   # 1 report, 3 factors, 2 records
>>> res = did_decide(initial_states(delta, p), p)
>>> int(res.choice[0]), int(res.stage[0])
(0, 1)
"""

from __future__ import annotations

from dataclasses import dataclass, asdict
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from ...solvers.kernels.jit import njit

__all__ = ["DIDParams", "DIDResult", "ERRORS", "SELECTS", "UNRESOLVED", "relative_errors",
           "SCORES", "initial_states", "dominance", "stage1_case", "stage2", "did_decide",
           "strength_matrix"]

ERRORS = ("scale", "origin")
SELECTS = ("movable", "literal")
SCORES = ("final", "initial")
UNRESOLVED = ("reject", "majority")

#: Stage-1 outcomes (``DIDResult.stage1``).
NEW, UNIQUE, AMBIGUOUS = 0, 1, 2


@dataclass(frozen=True)
class DIDParams:
    """Parameters of DID (none is given by the paper; all defaults are ours).

    Attributes
    ----------
    M : float
        Relative accuracy of the sensor (> 0): ``eta = delta / M``.
    M_prime : float
        Normalisation parameter (>= 1): a factor is off beyond ``eta = M'/2``.
    B : float or (m, m) array
        Inference strengths: a scalar gives the same strength to every pair of factors.
    max_iter : int
        Cap on the stage-2 updates of one record.
    select : {"movable", "literal"}
        Which factors compete for "most ambiguous" (see the module docstring).
    unresolved : {"reject", "majority"}
        What a record that did not settle counts as in the final decision.
    score : {"final", "initial"}
        States summed by the final score q: after stage 2 (as printed) or the
        stage-1 states (ours: stage 2 only decides which records are associated).
    min_updates : int
        Updates every stage-2 record gets before its agreement is checked: 0 reads
        step 5 as a while loop, 1 as a do-while (both literal; see the module
        docstring).
    """

    M: float = 1.0
    M_prime: float = 6.0
    B: Any = 0.2
    max_iter: int = 50
    select: str = "movable"
    unresolved: str = "reject"
    score: str = "final"
    min_updates: int = 0

    def __post_init__(self) -> None:
        if not (np.isfinite(self.M) and self.M > 0):
            raise ValueError(f"M must be a finite number > 0, got {self.M!r}")
        if not (np.isfinite(self.M_prime) and self.M_prime >= 1):
            raise ValueError(f"M_prime must be a finite number >= 1, got {self.M_prime!r}")
        if not isinstance(self.max_iter, (int, np.integer)) or self.max_iter < 0:
            raise ValueError(f"max_iter must be a non-negative integer, got {self.max_iter!r}")
        if not isinstance(self.min_updates, (int, np.integer)) or self.min_updates < 0:
            raise ValueError(f"min_updates must be a non-negative integer, "
                             f"got {self.min_updates!r}")
        if self.select not in SELECTS:
            raise ValueError(f"select must be one of {SELECTS}, got {self.select!r}")
        if self.unresolved not in UNRESOLVED:
            raise ValueError(f"unresolved must be one of {UNRESOLVED}, got {self.unresolved!r}")
        if self.score not in SCORES:
            raise ValueError(f"score must be one of {SCORES}, got {self.score!r}")
        if np.ndim(self.B) == 0:
            b = float(self.B)
            if not 0.0 <= b <= 1.0:
                raise ValueError(f"B must lie in [0, 1], got {self.B!r}")

    def as_dict(self) -> dict[str, Any]:
        d = asdict(self)
        d["B"] = np.asarray(self.B).tolist()
        return d


def strength_matrix(B: ArrayLike, m: int) -> np.ndarray:
    """The (m, m) inference-strength matrix: symmetric, in [0, 1], zero diagonal."""
    if np.ndim(B) == 0:
        out = np.full((m, m), float(B))
        np.fill_diagonal(out, 0.0)
        return out
    out = np.array(B, dtype=np.float64)
    if out.shape != (m, m):
        raise ValueError(f"B must be a scalar or an ({m}, {m}) matrix, got shape {out.shape}")
    if not np.all(np.isfinite(out)) or (out < 0).any() or (out > 1).any():
        raise ValueError("B entries must lie in [0, 1]")
    if not np.array_equal(out, out.T):
        raise ValueError("B must be symmetric (the paper's omega_ij = omega_ji)")
    if np.diag(out).any():
        raise ValueError("B must have a zero diagonal (a factor does not infer itself)")
    return out


# ------------------------------------------------------------------ stage 1
def relative_errors(reports: ArrayLike, records: ArrayLike, *, error: str = "scale",
                    scale: ArrayLike | None = None, floor: ArrayLike | None = None,
                    categorical: ArrayLike | None = None) -> np.ndarray:
    """``delta`` of every (report, factor, record): shape (R, m, n).

    Parameters
    ----------
    reports : (R, m) array
        The new reports' factors (one row per report).
    records : (m, n) array
        The stored records, one column per record (the paper's ``A``).
    error : {"scale", "origin"}
        ``"scale"``: ``|a_i - a_ij| / scale``, ``scale`` of shape (m,) or (m, n), > 0.
        ``"origin"``: ``|a_i - a_ij| / max(|a_ij|, floor_i)``, ``floor`` (m,) > 0.
    categorical : (m,) bool array, optional
        Factors compared for equality only: ``delta`` 0 if equal, ``inf`` otherwise.
    """
    a0 = np.atleast_2d(np.asarray(reports, dtype=np.float64))
    A = np.asarray(records, dtype=np.float64)
    if A.ndim != 2 or a0.shape[1] != A.shape[0]:
        raise ValueError(f"reports (R, m) and records (m, n) disagree: {a0.shape} vs {A.shape}")
    if not (np.all(np.isfinite(a0)) and np.all(np.isfinite(A))):
        raise ValueError("reports and records must be finite")
    m = A.shape[0]
    diff = np.abs(a0[:, :, None] - A[None, :, :])
    if error == "scale":
        if scale is None:
            raise ValueError("error='scale' needs a scale per factor")
        s = np.asarray(scale, dtype=np.float64)
        s = s[:, None] if s.ndim == 1 else s
        if s.shape not in ((m, 1), A.shape) or not np.all(s > 0):
            raise ValueError(f"scale must be > 0 with shape ({m},) or {A.shape}")
        delta = diff / s[None]
    elif error == "origin":
        f = np.full(m, 1e-12) if floor is None else np.asarray(floor, dtype=np.float64)
        if f.shape != (m,) or not np.all(f > 0):
            raise ValueError(f"floor must be > 0 with shape ({m},)")
        delta = diff / np.maximum(np.abs(A), f[:, None])[None]
    else:
        raise ValueError(f"error must be one of {ERRORS}, got {error!r}")
    if categorical is not None:
        cat = np.asarray(categorical, dtype=bool)
        if cat.shape != (m,):
            raise ValueError(f"categorical must be a boolean mask of shape ({m},)")
        delta[:, cat, :] = np.where(diff[:, cat, :] == 0, 0.0, np.inf)
    return delta


def initial_states(delta: ArrayLike, params: DIDParams) -> np.ndarray:
    """``s_on`` after the normalisation, from ``delta`` (any shape; ``s_off = 1 - s_on``)."""
    d = np.asarray(delta, dtype=np.float64)
    if np.isnan(d).any() or (d < 0).any():
        raise ValueError("relative errors must be >= 0 (inf allowed, NaN not)")
    eta = d / params.M
    s_off = np.where(eta >= params.M_prime, 1.0, eta / params.M_prime)
    return 1.0 - s_off


def dominance(s_on: ArrayLike) -> np.ndarray:
    """True where a factor is on: ``s_on >= s_off``."""
    s = np.asarray(s_on)
    return s >= 1.0 - s


def stage1_case(s_on: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Stage-1 outcome per report (NEW, UNIQUE or AMBIGUOUS) and the UNIQUE record (else -1).

    ``s_on`` has shape (R, m, n).
    """
    on = dominance(s_on)
    all_on, all_off = on.all(axis=1), (~on).all(axis=1)            # (R, n)
    new = all_off.all(axis=1)
    unique = (all_on.sum(axis=1) == 1) & (all_on | all_off).all(axis=1)
    case = np.where(new, NEW, np.where(unique, UNIQUE, AMBIGUOUS))
    first = np.argmax(all_on, axis=1) if all_on.shape[1] else np.zeros(len(case), np.int64)
    k = np.where(unique, first, -1)                # no records: every report is NEW
    return case, k


# ------------------------------------------------------------------ stage 2
def stage2(s_on: ArrayLike, B: np.ndarray, max_iter: int, select: str = "movable",
           min_updates: int = 0) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Run the stage-2 loop on independent columns.

    ``s_on`` has shape (P, m): one row per (report, record) column.  The first
    ``min_updates`` updates are made without checking agreement (do-while reading).
    Returns the final states, whether each column settled (all factors agree) and
    its number of updates.
    """
    s = np.array(s_on, dtype=np.float64)
    if s.ndim != 2:
        raise ValueError(f"stage-2 columns must have shape (P, m), got {s.shape}")
    iters = _stage2_kernel(s, np.ascontiguousarray(B, dtype=np.float64), int(max_iter),
                           select == "movable", int(min_updates))
    on = dominance(s)
    settled = on.all(axis=1) | (~on).all(axis=1)
    return s, settled, iters


@njit(cache=True)
def _stage2_kernel(s, B, max_iter, movable, min_updates):   # pragma: no cover - compiled
    """In place: the stage-2 loop of every column (row) of ``s``; returns the updates."""
    P, m = s.shape
    iters = np.zeros(P, np.int64)
    y = np.empty(m)
    for p in range(P):
        for it in range(max_iter):
            n_on = 0
            for i in range(m):
                if s[p, i] >= 1.0 - s[p, i]:
                    n_on += 1
            if it >= min_updates and (n_on == 0 or n_on == m):
                break                                   # the factors agree: settled
            for i in range(m):
                acc = 0.0
                for l in range(m):
                    if l != i:
                        acc += B[i, l] * (s[p, l] - (1.0 - s[p, l]))
                y[i] = acc
            best, bt = -1, np.inf
            for i in range(m):
                if movable and not ((y[i] > 0 and s[p, i] < 1.0) or (y[i] < 0 and s[p, i] > 0.0)):
                    continue
                t = abs(s[p, i] - 0.5)
                if t < bt:
                    best, bt = i, t
            if best < 0:
                break                                   # nothing can move: stalled
            new = min(max(s[p, best] + y[best], 0.0), 1.0)
            if new == s[p, best]:
                break                                   # the chosen factor is stuck
            s[p, best] = new
            iters[p] += 1
    return iters


@dataclass(frozen=True)
class DIDResult:
    """DID's decision for each of R reports against n records.

    ``choice[r]``: the chosen record (0-based) or -1 (new target / noise);
    ``stage1[r]``: NEW, UNIQUE or AMBIGUOUS; ``stage[r]``: 1 or 2 (where it was
    decided); ``converged[r]``: every stage-2 column of that report settled;
    ``iterations[r]``: stage-2 updates summed over its columns; ``score[r]``: q of the
    chosen record (nan if none); ``states``: final s_on, (R, m, n).
    """

    choice: np.ndarray
    stage1: np.ndarray
    stage: np.ndarray
    converged: np.ndarray
    iterations: np.ndarray
    score: np.ndarray
    states: np.ndarray


def did_decide(s_on: ArrayLike, params: DIDParams) -> DIDResult:
    """Both stages for R reports at once; ``s_on`` (R, m, n) from :func:`initial_states`."""
    S = np.array(s_on, dtype=np.float64)
    if S.ndim != 3:
        raise ValueError(f"states must have shape (R, m, n), got {S.shape}")
    if np.isnan(S).any() or (S < 0).any() or (S > 1).any():
        raise ValueError("states must lie in [0, 1]")
    R, m, n = S.shape
    case, k1 = stage1_case(S)
    choice = k1.copy()
    converged = np.ones(R, dtype=bool)
    iterations = np.zeros(R, dtype=np.int64)
    score = np.full(R, np.nan)
    if R and n:
        rows = np.arange(R)
        score[case == UNIQUE] = S[rows, :, choice][case == UNIQUE].sum(axis=1)
    amb = np.flatnonzero(case == AMBIGUOUS)
    if amb.size:
        on = dominance(S[amb])
        keep = on.any(axis=1)                                     # (A, n): not all off
        r_idx, k_idx = np.nonzero(keep)
        cols = S[amb[r_idx], :, k_idx]                            # (P, m)
        final, settled, it = stage2(cols, strength_matrix(params.B, m), params.max_iter,
                                    params.select, params.min_updates)
        S[amb[r_idx], :, k_idx] = final
        on_f = dominance(final)
        if params.unresolved == "reject":
            assoc = on_f.all(axis=1)
        else:
            assoc = np.where(settled, on_f.all(axis=1), on_f.sum(axis=1) > m / 2)
        q = np.where(assoc, (final if params.score == "final" else cols).sum(axis=1), -np.inf)
        best = np.full(len(amb), -np.inf)
        np.maximum.at(best, r_idx, q)
        np.logical_and.at(converged, amb[r_idx], settled)
        np.add.at(iterations, amb[r_idx], it)
        for a in range(len(amb)):                     # lowest index among the maxima
            sel = (r_idx == a) & (q == best[a]) & np.isfinite(q)
            if sel.any():
                choice[amb[a]] = k_idx[sel][0]
                score[amb[a]] = best[a]
            else:
                choice[amb[a]] = -1
    stage = np.where(case == AMBIGUOUS, 2, 1)
    return DIDResult(choice, case, stage, converged, iterations, score, S)
