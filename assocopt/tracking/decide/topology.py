"""Topology association for one time step: a 2-D assignment per reference pair, the
association degree lambda_uv, the degree matrix Phi and the trial pairs (Dong 2015).

For every reference pair (u, v) of sensor-1 track u and sensor-2 track v, every
neighbour is described in u's (resp. v's) frame (:mod:`assocopt.tracking.costs.topology`),
the distances gamma_ij(u, v) form an ``n1 x n2`` matrix, its 2-D assignment picks
neighbour pairs, and the assigned pairs under the gate are *confirmed*.
``lambda_uv`` is the mean gamma over the confirmed pairs (a large value when there are
none, or fewer than ``min_pairs``); ``Phi = [lambda_uv]``.

The n1 n2 assignments of a step run in one compiled loop (dense Hungarian of
:mod:`assocopt.solvers.kernels`): through :func:`assocopt.solve` each small problem
costs far more in model building than in solving (measured on the page).
:func:`phi_reference` does the same through ``solve``, one pair at a time; the tests
check that both agree.

Options (:class:`TopologyParams`; every reading not fixed by the paper is named)::

    ``metric``      ``"statistical"`` (gamma, the paper's) or ``"euclidean"`` (squared
                    distance of the positions, the Euclidean baseline);
    ``frame``       ``"position"`` (positions translated, velocities rotated) or ``"full"``
                    (whole state subtracted: the reference is then the zero vector on
                    both sensors);
    ``self_pair``   ``"include"`` (the reference pair (u, v) itself counts among the
                    confirmed pairs of lambda, as the paper converts "the data of target u
                    itself" too) or ``"exclude"`` (only the *neighbour* pairs count, as the
                    abstract's wording has it); it stays in the assignment either way.
                    Default (``None``): ``"exclude"`` with the full-state frame (where it
                    would always confirm itself at gamma = 0), ``"include"`` otherwise;
    ``assignment``  ``"dummy"`` (default: a dummy per row and column at half the gate,
                    so a pair is used only when it beats leaving both tracks out; solved
                    over the gated entries only, which is exact and fast) or
                    ``"rectangular"`` (the paper's order: the smaller side fully assigned,
                    then gated; exact, with distances computed lazily, see
                    :func:`~assocopt.tracking.decide._topology_kernel.phi_kernel`);
    ``inflate``     add the reference headings' variance to B (ours: a substitute for the
                    paper's heading-adjusted threshold T_1, whose formula is lost);
    ``ref_cov``     first-order covariance of the offsets from the reference: adds the
                    reference's own position covariance (ours: a modelling improvement;
                    the paper rotates P_i only);
    ``degree``      ``"mean"`` (the paper's lambda: mean gamma over the confirmed pairs) or
                    ``"objective"`` (ours: the assignment cost per track with every
                    unconfirmed track at the gate, so a pair confirming few neighbours can
                    no longer beat one confirming many);
    ``threshold``   ``"chi2"`` (gate delta(alpha, 4), or ``euclid_gate_m^2``) or
                    ``"heading"``: our substitute for the paper's lost threshold T_1,
                    ``gate * (1 + coef * (var(theta_1u) + var(theta_2v)))`` (flagged as ours).
"""

from __future__ import annotations

from dataclasses import asdict, dataclass
from typing import Any

import numpy as np

from ...solving.api import solve
from ...problems.problem import AssignmentProblem
from ..costs.topology import (check_tracks, chi2_gate, heading_jacobians, heading_variance,
                        pair_distances, reference_frames)

__all__ = ["TopologyParams", "StepInputs", "Duals", "prepare", "thresholds", "pair_gammas",
           "phi_matrix", "phi_reference", "assign_pairs", "degree_matrix",
           "coarse_pregate", "trial_pairs", "LARGE"]

#: "A sufficiently large value" of lambda_uv when (u, v) has no confirmed pair.
LARGE = 1e9


@dataclass(frozen=True)
class TopologyParams:
    """Options of the per-step topology association (see the module docstring)."""

    metric: str = "statistical"
    frame: str = "position"
    assignment: str = "dummy"
    inflate: bool = False
    ref_cov: bool = False
    degree: str = "mean"
    threshold: str = "chi2"
    coef: float = 20.0
    alpha: float = 0.01
    euclid_gate_m: float = 1000.0
    min_pairs: int = 1
    self_pair: str | None = None        # last: positional construction keeps working

    def __post_init__(self) -> None:
        for name, valid in (("metric", ("statistical", "euclidean")),
                            ("frame", ("position", "full")),
                            ("assignment", ("rectangular", "dummy")),
                            ("threshold", ("chi2", "heading")),
                            ("degree", ("mean", "objective")),
                            ("self_pair", (None, "include", "exclude"))):
            if getattr(self, name) not in valid:
                raise ValueError(f"{name} must be one of {valid}, got {getattr(self, name)!r}")
        if self.coef < 0 or self.euclid_gate_m <= 0:
            raise ValueError("coef must be >= 0 and euclid_gate_m > 0")
        if not isinstance(self.min_pairs, int) or self.min_pairs < 1:
            raise ValueError(f"min_pairs must be a positive integer, got {self.min_pairs!r}")
        chi2_gate(self.alpha, 4)
        if self.self_pair is None:
            object.__setattr__(self, "self_pair",
                               "exclude" if self.frame == "full" else "include")

    def base_gate(self) -> float:
        """delta(alpha, 4) for the statistical distance, the squared gate in m^2 for the
        Euclidean one."""
        return chi2_gate(self.alpha, 4) if self.metric == "statistical" else self.euclid_gate_m ** 2

    def as_dict(self) -> dict[str, Any]:
        return asdict(self)


@dataclass
class StepInputs:
    """Both sensors' tracks in every reference frame, with the heading terms."""

    X1r: np.ndarray
    P1r: np.ndarray
    X2r: np.ndarray
    P2r: np.ndarray
    J1: np.ndarray
    J2: np.ndarray
    var1: np.ndarray
    var2: np.ndarray


def prepare(X1, P1, X2, P2, params: TopologyParams) -> StepInputs:
    """Transform both sensors' tracks (all reference targets at once)."""
    X1, P1 = check_tracks(X1, P1, "sensor 1")
    X2, P2 = check_tracks(X2, P2, "sensor 2")
    full = params.frame == "full"
    X1r, P1r = reference_frames(X1, P1, full, params.ref_cov)
    X2r, P2r = reference_frames(X2, P2, full, params.ref_cov)
    return StepInputs(X1r, P1r, X2r, P2r, heading_jacobians(X1, full),
                      heading_jacobians(X2, full), heading_variance(X1, P1),
                      heading_variance(X2, P2))


def thresholds(inp: StepInputs, params: TopologyParams) -> np.ndarray:
    """Gate of every reference pair, ``(n1, n2)``."""
    n1, n2 = inp.X1r.shape[1], inp.X2r.shape[1]
    g = params.base_gate()
    if params.threshold == "chi2":
        return np.full((n1, n2), g)
    v = np.minimum(inp.var1[:, None] + inp.var2[None, :], 1e6)
    return g * (1.0 + params.coef * v)


def _kernel_args(inp: StepInputs, params: TopologyParams, active):
    n1, n2 = inp.X1r.shape[1], inp.X2r.shape[1]
    act = np.ones((n1, n2), bool) if active is None else np.asarray(active, bool)
    if act.shape != (n1, n2):
        raise ValueError(f"active must have shape {(n1, n2)}, got {act.shape}")
    v1 = np.where(np.isfinite(inp.var1), inp.var1, 1e6)
    v2 = np.where(np.isfinite(inp.var2), inp.var2, 1e6)
    return (inp.X1r, inp.P1r, inp.X2r, inp.P2r, inp.J1, v1, inp.J2, v2, params.inflate,
            params.metric == "euclidean", thresholds(inp, params),
            params.assignment == "dummy"), act


@dataclass
class Duals:
    """Column duals of every reference pair's last rectangular assignment, kept from
    one step to the next as the Hungarian's warm start (the same tracks in the same
    order; a change of shape starts cold).  Speed only: the optimum is the same."""

    V: np.ndarray | None = None
    have: np.ndarray | None = None

    def arrays(self, n1: int, n2: int) -> tuple[np.ndarray, np.ndarray]:
        n = max(n1, n2)
        if self.V is None or self.V.shape != (n1, n2, n):
            self.V, self.have = np.zeros((n1, n2, n)), np.zeros((n1, n2), bool)
        return self.V, self.have


def _warm(duals: Duals | None, n1: int, n2: int) -> tuple[np.ndarray, np.ndarray, bool]:
    if duals is None:
        return np.zeros((0, 0, 0)), np.zeros((0, 0), bool), False
    return (*duals.arrays(n1, n2), True)


def _batch_args(args):
    """The :mod:`._topology_batch` arrays from :func:`_kernel_args`' tuple."""
    from ._topology_batch import soa
    X1r, P1r, X2r, P2r, J1, v1, J2, v2, inflate, euclid, thr, _ = args
    return (*soa(X1r, P1r, J1, v1, inflate), *soa(X2r, P2r, J2, v2, inflate), euclid, thr)


def phi_matrix(inp: StepInputs, params: TopologyParams,
               active: np.ndarray | None = None, *, plain: bool = False,
               duals: Duals | None = None) -> tuple[np.ndarray, np.ndarray]:
    """``(Phi, M)``: lambda_uv and the confirmed-pair count of every reference pair
    (compiled; ``active`` False skips a pair, e.g. after :func:`coarse_pregate`).
    The rectangular reading runs on :mod:`._topology_batch` (vectorised distances)
    unless ``plain``, which keeps the scalar loop of :mod:`._topology_kernel` (the
    same answers; kept for the check and for timing before / after); ``duals``
    (rectangular, not ``plain``): warm-start the assignments from the previous step's
    (:class:`Duals`, updated in place)."""
    from ._topology_kernel import phi_kernel
    n1, n2 = inp.X1r.shape[1], inp.X2r.shape[1]
    if n1 == 0 or n2 == 0:
        return np.full((n1, n2), LARGE), np.zeros((n1, n2), np.int64)
    args, act = _kernel_args(inp, params, active)
    if params.assignment == "rectangular" and not plain:
        from ._topology_batch import rect_phi_kernel
        return rect_phi_kernel(*_batch_args(args), params.self_pair == "exclude",
                               params.min_pairs, act, LARGE, params.degree == "objective",
                               *_warm(duals, n1, n2))
    return phi_kernel(*args, params.self_pair == "exclude", params.min_pairs, act, LARGE,
                      params.degree == "objective")


def assign_pairs(inp: StepInputs, params: TopologyParams,
                 active: np.ndarray | None = None, *, plain: bool = False,
                 duals: Duals | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Every reference pair's assignment, before any degree is formed: ``(cols,
    gam)``, ``cols[u, v, i]`` the sensor-2 track assigned to neighbour i under (u, v)
    (``-1``: none, or nothing under the gate) and ``gam[u, v, i]`` its distance.
    :func:`degree_matrix` turns them into Phi for any ``self_pair``, ``degree`` and
    ``min_pairs`` (which do not change the assignment), so several readings can share
    one solve; ``degree_matrix(*assign_pairs(inp, p), thresholds(inp, p), p)`` equals
    ``phi_matrix(inp, p)``; ``plain`` and ``duals`` as in :func:`phi_matrix`."""
    from ._topology_kernel import assign_kernel
    n1, n2 = inp.X1r.shape[1], inp.X2r.shape[1]
    if n1 == 0 or n2 == 0:
        return np.full((n1, n2, n1), -1, np.int64), np.full((n1, n2, n1), np.inf)
    args, act = _kernel_args(inp, params, active)
    if params.assignment == "rectangular" and not plain:
        from ._topology_batch import rect_assign_kernel
        return rect_assign_kernel(*_batch_args(args), act, *_warm(duals, n1, n2))
    return assign_kernel(*args, act)


def degree_matrix(cols: np.ndarray, gam: np.ndarray, thr: np.ndarray,
                  params: TopologyParams) -> tuple[np.ndarray, np.ndarray]:
    """``(Phi, M)`` from :func:`assign_pairs`' output and the gates ``thr``."""
    n1, n2 = thr.shape
    ok = (cols >= 0) & (gam <= thr[:, :, None])
    if params.self_pair == "exclude" and n1 and n2:
        u = np.arange(n1)[:, None]
        ok[u, np.arange(n2)[None, :], u] &= cols[u, np.arange(n2)[None, :], u] != \
            np.arange(n2)[None, :]
    M = ok.sum(-1)
    s = np.where(ok, gam, 0.0).sum(-1)
    phi = np.full((n1, n2), LARGE)
    real = (M > 0) & (M >= params.min_pairs)
    if params.degree == "objective":
        nn = min(n1, n2) - (params.self_pair == "exclude")
        phi[real] = (s[real] + (nn - M[real]) * thr[real]) / nn
    else:
        phi[real] = s[real] / M[real]
    return phi, M.astype(np.int64)


def pair_gammas(inp: StepInputs, params: TopologyParams, u: int, v: int) -> np.ndarray:
    """The ``n1 x n2`` distance matrix of one reference pair (numpy)."""
    if params.metric == "euclidean":
        D = inp.X1r[u][:, None, :2] - inp.X2r[v][None, :, :2]
        return (D ** 2).sum(-1)
    e1 = e2 = None
    if params.inflate:
        v1 = inp.var1[u] if np.isfinite(inp.var1[u]) else 1e6
        v2 = inp.var2[v] if np.isfinite(inp.var2[v]) else 1e6
        e1 = v1 * np.einsum("ia,ib->iab", inp.J1[u], inp.J1[u])
        e2 = v2 * np.einsum("ja,jb->jab", inp.J2[v], inp.J2[v])
    return pair_distances(inp.X1r, inp.P1r, inp.X2r, inp.P2r, u, v, e1, e2)


def phi_reference(inp: StepInputs, params: TopologyParams, solver: str = "auto",
                  active: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
    """:func:`phi_matrix` one pair at a time, each assignment through
    :func:`assocopt.solve` (``AssignmentProblem.dense`` or ``two_d`` with dummies)."""
    n1, n2 = inp.X1r.shape[1], inp.X2r.shape[1]
    thr = thresholds(inp, params)
    phi = np.full((n1, n2), LARGE)
    M = np.zeros((n1, n2), np.int64)
    for u in range(n1):
        for v in range(n2):
            if active is not None and not active[u, v]:
                continue
            G = pair_gammas(inp, params, u, v)
            t = thr[u, v]
            if params.assignment == "dummy":
                prob = AssignmentProblem.two_d(G, row_miss=t / 2, col_miss=t / 2)
            else:
                prob = AssignmentProblem.dense(G)
            rows, cols = solve(prob, solver).assignment()
            ok = G[rows, cols] <= t
            if params.self_pair == "exclude":
                ok &= ~((rows == u) & (cols == v))
            M[u, v] = int(ok.sum())
            if M[u, v] >= params.min_pairs:
                phi[u, v] = float(G[rows, cols][ok].mean())
                if params.degree == "objective":
                    nn = min(n1, n2) - (params.self_pair == "exclude")
                    phi[u, v] = (float(G[rows, cols][ok].sum()) + (nn - M[u, v]) * t) / nn
    return phi, M


def coarse_pregate(X1, P1, X2, P2, alpha: float = 0.001, turn1=None, turn2=None,
                   turn_var1=None, turn_var2=None) -> np.ndarray:
    """Reference pairs worth evaluating: bias-free quantities must agree.

    Speed (azimuth and offset biases leave it unchanged): ``(s_1u - s_2v)^2 /
    (var s_1u + var s_2v) <= chi2_1(1 - alpha)``; with turn rates (rad/s) and their
    variances given, the same test on the turn rate as well.  Returns ``(n1, n2)`` bool.
    """
    X1, P1 = check_tracks(X1, P1, "sensor 1")
    X2, P2 = check_tracks(X2, P2, "sensor 2")
    g = chi2_gate(alpha, 1)

    def speed(X, P):
        s = np.hypot(X[:, 2], X[:, 3])
        w = np.stack([X[:, 2], X[:, 3]], 1) / np.maximum(s, 1e-9)[:, None]
        return s, np.einsum("na,nab,nb->n", w, P[:, 2:, 2:], w)

    s1, q1 = speed(X1, P1)
    s2, q2 = speed(X2, P2)
    ok = (s1[:, None] - s2[None, :]) ** 2 <= g * (q1[:, None] + q2[None, :])
    if turn1 is not None and turn2 is not None:
        w1, w2 = np.asarray(turn1, float), np.asarray(turn2, float)
        var = np.asarray(turn_var1, float)[:, None] + np.asarray(turn_var2, float)[None, :]
        ok &= (w1[:, None] - w2[None, :]) ** 2 <= g * var
    return ok


def trial_pairs(phi: np.ndarray, rule: str = "row", solver: str = "auto") -> np.ndarray:
    """Sensor-2 trial partner of each sensor-1 track (``-1``: none).

    ``"row"``: each row's smallest lambda (the paper's "the pair with the smallest
    lambda"; several rows may choose one column).  ``"assignment"``: a global 2-D
    assignment on Phi through :func:`assocopt.solve`, pairs at the large value
    forbidden, so no column is chosen twice.
    """
    phi = np.asarray(phi, dtype=np.float64)
    n1, n2 = phi.shape
    out = np.full(n1, -1, dtype=np.int64)
    if n1 == 0 or n2 == 0:
        return out
    real = phi < LARGE
    if rule == "row":
        best = np.argmin(phi, axis=1)
        ok = real[np.arange(n1), best]
        out[ok] = best[ok]
        return out
    if rule != "assignment":
        raise ValueError(f"rule must be 'row' or 'assignment', got {rule!r}")
    if not real.any():
        return out
    C = np.where(real, phi, np.inf)
    big = 2.0 * float(C[real].max()) + 1.0       # any real pair beats leaving both out
    rows, cols = solve(AssignmentProblem.two_d(C, row_miss=big, col_miss=big),
                       solver).assignment()
    out[rows] = cols
    return out
