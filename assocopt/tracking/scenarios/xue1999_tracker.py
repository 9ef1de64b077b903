"""Kalman tracker for paper 003's scenario, with DID, GNN or NN deciding each scan.

The paper says neither how stored records are created nor how they are updated
(everything here is ours, recorded by the reproduction):

* **Records**: one Kalman filter per track, constant-velocity model with white-noise
  acceleration of density ``q``; reports measure (x, y, vx, vy) with the scenario's
  noise.  A track's stored record is its prediction (x, y, vx, vy) and its IFF (the
  majority of the IFF values it received, ties: the latest).
* **Initiation**: every report left unassociated starts a tentative track (x = the
  report, P = R).  A tentative track is confirmed after ``confirm_hits`` hits in a row
  and deleted at its first miss; a confirmed track is deleted after
  ``delete_misses`` consecutive misses.
* **Costs** (GNN and NN): the Mahalanobis distance ``nu' S^-1 nu`` of the 4
  kinematic factors plus ``iff_cost`` when the IFF values differ; ``iff_cost`` is
  ``2 ln((1 - p_iff) / p_iff)`` by default (the IFF likelihood ratio in the same
  -2 log units).  New-target cost ``c_new`` = the chi-square(4) quantile of level
  ``1 - gate_alpha``; pairs costing ``c_new`` or more are never used.
* **DID**: stored records as columns, factors (x, y, vx, vy, IFF); the ``"scale"``
  reading divides each kinematic difference by that factor's innovation standard
  deviation ``sqrt(S_ii)``.  The paper decides one report at a time and says nothing
  about several reports of one scan choosing the same record; the rule
  (``conflict``, not from the paper) is one of :data:`CONFLICTS`: ``"q_final"``
  (the track keeps the report with the largest printed score q, the others are
  dropped: they were judged to belong to a known target), ``"q_initial"`` (the same
  ranked by the stage-1 q) or ``"new_track"`` (largest printed q kept, the others
  start new tracks).
* **Methods**: the keys of :data:`METHODS`, or ``"NAME@B=0.05,Mp=3"`` with DID's B
  and M' set (:func:`tuned_name`; the reproduction's tuning).

>>> from assocopt.tracking.scenarios.xue1999 import Xue1999
>>> sc = Xue1999(clutter_mean=0.0, p_d=1.0)
>>> log = run_tracker(sc.simulate(np.random.default_rng(1)), "gnn", sc)
>>> m = run_metrics(log, sc)
>>> m["correct_rate"] > 0.95, m["false_tracks"]
(True, 0.0)
"""

from __future__ import annotations

import math
import re
from dataclasses import asdict, dataclass, field, replace
from typing import Any

import numpy as np
from scipy.stats import chi2

from ..decide.did import DIDParams, did_decide, initial_states, relative_errors
from ..decide.nearest import gnn_assign, nearest_neighbour
from ..filters import cv_model
from .xue1999 import Scan, Xue1999

__all__ = ["TrackerParams", "METHODS", "CONFLICTS", "RunLog", "run_tracker", "run_metrics",
           "association_costs", "method_options", "tuned_name", "split_method"]

#: Rules for several reports of one scan choosing one track (none is the paper's).
CONFLICTS = ("q_final", "q_initial", "new_track")

_PRINTED = {"rule": "did", "error": "origin", "select": "literal", "score": "final",
            "min_updates": 0, "conflict": "q_final", "unresolved": "reject"}
#: Association methods: name -> options (``rule`` did / gnn / nn; DID options).  The
#: DID methods are the printed rule (eq. (10) with the literal selection; step 5 as a
#: while or a do-while loop) and the printed rule with our changes.
METHODS: dict[str, dict[str, Any]] = {
    "did-printed": dict(_PRINTED),
    "did-dowhile": {**_PRINTED, "min_updates": 1},
    "did-zscore": {**_PRINTED, "error": "scale"},
    "did-movable": {**_PRINTED, "select": "movable"},
    "did-printed-q0": {**_PRINTED, "score": "initial"},
    "did-majority": {**_PRINTED, "unresolved": "majority"},
    "did-conflict-q0": {**_PRINTED, "conflict": "q_initial"},
    "did-conflict-new": {**_PRINTED, "conflict": "new_track"},
    "did-zm": {**_PRINTED, "error": "scale", "select": "movable"},
    "did-q0": {**_PRINTED, "error": "scale", "select": "movable", "score": "initial"},
    "gnn": {"rule": "gnn"},
    "nn": {"rule": "nn"},
}

_TUNED = re.compile(r"^(?P<base>[\w-]+)@B=(?P<B>[0-9.e+-]+),Mp=(?P<Mp>[0-9.e+-]+)$")


def tuned_name(base: str, B: float, M_prime: float) -> str:
    """The method ``base`` with DID's B and M' set: ``"did-printed@B=0.05,Mp=3"``."""
    if base not in METHODS or METHODS[base]["rule"] != "did":
        raise ValueError(f"{base!r} is not a DID method of METHODS")
    return f"{base}@B={float(B):g},Mp={float(M_prime):g}"


def split_method(name: str) -> tuple[str, dict[str, float]]:
    """``(base, {"did_B": B, "did_M_prime": M'})`` of a method name (``{}``: no override)."""
    m = _TUNED.match(name)
    base, over = (m["base"], {"did_B": float(m["B"]), "did_M_prime": float(m["Mp"])}) \
        if m else (name, {})
    if base not in METHODS or (over and METHODS[base]["rule"] != "did"):
        raise ValueError(f"unknown method {name!r}; valid: {sorted(METHODS)}, or a DID "
                         "method as NAME@B=<B>,Mp=<M'>")
    return base, over


def method_options(name: str) -> dict[str, Any]:
    """The options of a method name (a key of :data:`METHODS`, or one with B, M' set)."""
    return METHODS[split_method(name)[0]]


@dataclass(frozen=True)
class TrackerParams:
    """Tracker and decision parameters (all ours; see the module docstring)."""

    q: float = 0.5
    confirm_hits: int = 3
    delete_misses: int = 3
    gate_alpha: float = 0.01
    iff_cost: float | None = None
    did_M: float = 1.0
    did_M_prime: float = 6.0
    did_B: float = 0.2
    did_max_iter: int = 100
    did_origin_M: float = 0.05
    did_origin_floor: tuple = (100.0, 100.0, 1.0, 1.0, 1.0)
    solver: str = "auto"

    def c_new(self) -> float:
        return float(chi2.ppf(1.0 - self.gate_alpha, 4))

    def iff_mismatch_cost(self, p_iff: float) -> float:
        if self.iff_cost is not None:
            return float(self.iff_cost)
        p = min(max(p_iff, 1e-6), 0.5)
        return 2.0 * math.log((1.0 - p) / p)

    def did_params(self, opts: dict[str, Any]) -> DIDParams:
        M = self.did_origin_M if opts["error"] == "origin" else self.did_M
        return DIDParams(M=M, M_prime=self.did_M_prime, B=self.did_B,
                         max_iter=self.did_max_iter, select=opts["select"],
                         score=opts.get("score", "final"), min_updates=opts.get("min_updates", 0),
                         unresolved=opts.get("unresolved", "reject"))

    def as_dict(self) -> dict[str, Any]:
        d = asdict(self)
        d["did_origin_floor"] = list(self.did_origin_floor)
        return d


@dataclass
class _Tracks:
    x: np.ndarray                      # (n, 4)
    P: np.ndarray                      # (n, 4, 4)
    ids: list = field(default_factory=list)
    hits: list = field(default_factory=list)
    misses: list = field(default_factory=list)
    confirmed: list = field(default_factory=list)
    iff_counts: list = field(default_factory=list)
    last_iff: list = field(default_factory=list)

    def iff(self) -> np.ndarray:
        c = np.array(self.iff_counts, dtype=np.int64).reshape(-1, 2)
        return np.where(c[:, 1] > c[:, 0], 1, np.where(c[:, 1] < c[:, 0], 0,
                                                       np.array(self.last_iff, dtype=np.int64)))


@dataclass
class RunLog:
    """What the metrics need: per scan, each report's source and the track ids it went
    to (``[]`` = none), the owners of the tracks alive before the scan; per track its
    owner, whether it was ever confirmed, its report sources and estimated positions."""

    scans: list = field(default_factory=list)          # (source, list of track ids, live owners)
    owner: dict = field(default_factory=dict)
    confirmed: dict = field(default_factory=dict)
    sources: dict = field(default_factory=dict)
    path: dict = field(default_factory=dict)           # id -> [(k, x, y)]
    did_stats: dict = field(default_factory=lambda: {"decisions": 0, "stage2": 0,
                                                     "nonconverged": 0, "conflicts": 0})


def association_costs(z: np.ndarray, z_iff: np.ndarray, x: np.ndarray, S: np.ndarray,
                      t_iff: np.ndarray, iff_cost: float) -> np.ndarray:
    """Reports x tracks: Mahalanobis distance on (x, y, vx, vy) + ``iff_cost`` per IFF
    mismatch."""
    nu = z[:, None, :] - x[None, :, :]
    Sinv = np.linalg.inv(S)
    d2 = np.einsum("rni,nij,rnj->rn", nu, Sinv, nu)
    return d2 + iff_cost * (z_iff[:, None] != t_iff[None, :])


def _associate(opts: dict[str, Any], z, z_iff, x, S, t_iff, sc: Xue1999, p: TrackerParams,
               log: RunLog) -> tuple[list[tuple[int, int]], np.ndarray]:
    """(report, track) pairs and the mask of reports that start new tracks."""
    R, n = len(z), len(x)
    if n == 0:
        return [], np.ones(R, dtype=bool)
    if opts["rule"] in ("gnn", "nn"):
        C = association_costs(z, z_iff, x, S, t_iff, p.iff_mismatch_cost(sc.p_iff))
        if opts["rule"] == "gnn":
            a = gnn_assign(C, p.c_new(), p.solver)
            pairs = [(r, int(a[r])) for r in range(R) if a[r] >= 0]
        else:
            a = nearest_neighbour(C, p.c_new())
            pairs = [(int(a[j]), j) for j in range(n) if a[j] >= 0]
        used = np.zeros(R, dtype=bool)
        used[[r for r, _ in pairs]] = True
        return pairs, ~used
    factors = np.column_stack([z, z_iff])
    records = np.column_stack([x, t_iff]).T                          # (5, n)
    dp = p.did_params(opts)
    if opts["error"] == "scale":
        scale = np.vstack([np.sqrt(np.diagonal(S, axis1=1, axis2=2)).T, np.ones((1, n))])
        delta = relative_errors(factors, records, error="scale", scale=scale,
                                categorical=[False] * 4 + [True])
    else:
        delta = relative_errors(factors, records, error="origin",
                                floor=np.asarray(p.did_origin_floor, dtype=np.float64),
                                categorical=[False] * 4 + [True])
    s0 = initial_states(delta, dp)
    res = did_decide(s0, dp)
    log.did_stats["decisions"] += R
    log.did_stats["stage2"] += int((res.stage == 2).sum())
    log.did_stats["nonconverged"] += int((~res.converged).sum())
    return _settle_conflicts(res.choice, res.score, s0, opts.get("conflict", "q_final"), log)


def _settle_conflicts(choice: np.ndarray, score: np.ndarray, s0: np.ndarray, rule: str,
                      log: RunLog) -> tuple[list[tuple[int, int]], np.ndarray]:
    """One report per track (rule of :data:`CONFLICTS`): the pairs and the reports that
    start new tracks."""
    if rule not in CONFLICTS:
        raise ValueError(f"conflict must be one of {CONFLICTS}, got {rule!r}")
    q = np.nan_to_num(score, nan=-np.inf)
    if rule == "q_initial":
        k = np.maximum(choice, 0)
        q = np.where(choice >= 0, s0[np.arange(len(choice)), :, k].sum(axis=1), -np.inf)
    best: dict[int, int] = {}                 # track -> the report with the largest q
    initiate = choice < 0
    for r in np.argsort(-q, kind="stable"):
        j = int(choice[r])
        if j >= 0 and j not in best:
            best[j] = int(r)
        elif j >= 0:
            log.did_stats["conflicts"] += 1
            initiate[r] = rule == "new_track"
    return sorted((r, j) for j, r in best.items()), initiate


def run_tracker(scans: list[Scan], method: str, sc: Xue1999,
                params: TrackerParams | None = None) -> RunLog:
    """Track one simulated run with ``method`` (a key of :data:`METHODS`, or one with
    DID's B and M' set, see :func:`tuned_name`)."""
    base, over = split_method(method)
    opts = METHODS[base]
    p = replace(params or TrackerParams(), **over)
    F, Q = cv_model(sc.T, p.q)
    Rm = np.diag(sc.sigma ** 2)
    tr = _Tracks(np.zeros((0, 4)), np.zeros((0, 4, 4)))
    log = RunLog()
    next_id = 0
    for k, scan in enumerate(scans):
        live_owners = [log.owner[i] for i in tr.ids]
        if k:
            tr.x = tr.x @ F.T
            tr.P = F @ tr.P @ F.T + Q
        S = tr.P + Rm
        pairs, initiate = _associate(opts, scan.reports, scan.iff, tr.x, S, tr.iff(),
                                     sc, p, log)
        went: list[list[int]] = [[] for _ in range(len(scan.source))]
        hit = np.zeros(len(tr.ids), dtype=bool)
        for r, j in pairs:
            nu = scan.reports[r] - tr.x[j]
            K = tr.P[j] @ np.linalg.inv(S[j])
            tr.x[j] = tr.x[j] + K @ nu
            Pj = (np.eye(4) - K) @ tr.P[j]
            tr.P[j] = 0.5 * (Pj + Pj.T)
            hit[j] = True
            tid = tr.ids[j]
            went[r].append(tid)
            log.sources[tid].append(int(scan.source[r]))
            log.path[tid].append((k, float(tr.x[j, 0]), float(tr.x[j, 1])))
            tr.iff_counts[j][int(scan.iff[r])] += 1
            tr.last_iff[j] = int(scan.iff[r])
        keep = []
        for j in range(len(tr.ids)):
            if hit[j]:
                tr.hits[j] += 1
                tr.misses[j] = 0
                if not tr.confirmed[j] and tr.hits[j] >= p.confirm_hits:
                    tr.confirmed[j] = True
                    log.confirmed[tr.ids[j]] = True
            else:
                tr.misses[j] += 1
            limit = p.delete_misses if tr.confirmed[j] else 1
            keep.append(tr.misses[j] < limit)
        _keep(tr, np.array(keep, dtype=bool))
        new = np.flatnonzero(initiate)
        new_ids = set()
        for r in new:
            tid = next_id
            new_ids.add(tid)
            next_id += 1
            src = int(scan.source[r])
            log.owner[tid], log.confirmed[tid] = src, p.confirm_hits <= 1
            log.sources[tid] = [src]
            log.path[tid] = [(k, float(scan.reports[r, 0]), float(scan.reports[r, 1]))]
            went[r].append(tid)
            counts = [0, 0]
            counts[int(scan.iff[r])] += 1
            tr.ids.append(tid)
            tr.hits.append(1)
            tr.misses.append(0)
            tr.confirmed.append(p.confirm_hits <= 1)
            tr.iff_counts.append(counts)
            tr.last_iff.append(int(scan.iff[r]))
        if len(new):
            tr.x = np.vstack([tr.x, scan.reports[new]])
            tr.P = np.concatenate([tr.P, np.broadcast_to(Rm, (len(new), 4, 4))])
        log.scans.append((scan.source.copy(), went, live_owners, new_ids))
    return log


def _keep(tr: _Tracks, mask: np.ndarray) -> None:
    tr.x, tr.P = tr.x[mask], tr.P[mask]
    for name in ("ids", "hits", "misses", "confirmed", "iff_counts", "last_iff"):
        setattr(tr, name, [v for v, m in zip(getattr(tr, name), mask) if m])


def run_metrics(log: RunLog, sc: Xue1999) -> dict[str, float]:
    """Metrics of one run (defined once here; the reproduction page repeats them).

    ``correct_rate``: over every target report of scans 1.., the fraction decided
    correctly: it went to a track started by that target, or, when no such track was
    alive, it started a new track.  ``car_kNN``: the same per scan.  ``swaps``: changes
    of true target along the reports of every once-confirmed track (clutter reports
    skipped).  ``false_tracks``: once-confirmed tracks with a majority of clutter
    reports.  ``held_at_end``: fraction of targets whose report last fed a live,
    confirmed track started by that target.  ``decision_precision``: over every
    association of a report with an existing track, the fraction where the report
    came from the target of the track's previous report (a clutter report, or a
    track whose previous report was clutter, counts as wrong): a swap is one wrong
    decision here, while ``correct_rate`` counts every later report of the swapped
    targets as wrong.  DID only: ``stage2_rate``, ``nonconverged_rate`` and
    ``conflict_rate`` (reports that lost a track to another report of the scan), per
    report.
    """
    out: dict[str, float] = {}
    tot_ok = tot_n = 0
    for k, (source, went, live_owners, new) in enumerate(log.scans):
        if k == 0:
            continue
        ok = n = 0
        for r, src in enumerate(source):
            if src < 0:
                continue
            n += 1
            started = [tid for tid in went[r] if tid in new]
            assoc = [tid for tid in went[r] if tid not in new]
            if src in live_owners:
                ok += any(log.owner[t] == src for t in assoc)
            else:
                ok += bool(started) and not assoc
        out[f"car_k{k:02d}"] = ok / n if n else math.nan
        tot_ok += ok
        tot_n += n
    out["correct_rate"] = tot_ok / tot_n if tot_n else math.nan
    swaps = false = dec = dec_ok = 0
    for tid, srcs in log.sources.items():
        dec += len(srcs) - 1
        dec_ok += sum(b >= 0 and a == b for a, b in zip(srcs, srcs[1:]))
        if not log.confirmed.get(tid):
            continue
        tgt = [s for s in srcs if s >= 0]
        swaps += sum(a != b for a, b in zip(tgt, tgt[1:]))
        false += (len(srcs) - len(tgt)) * 2 > len(srcs)
    out["swaps"] = float(swaps)
    out["false_tracks"] = float(false)
    out["held_at_end"] = _held_at_end(log, sc)
    out["decision_precision"] = dec_ok / dec if dec else math.nan
    d = log.did_stats
    if d["decisions"]:
        out["stage2_rate"] = d["stage2"] / d["decisions"]
        out["nonconverged_rate"] = d["nonconverged"] / d["decisions"]
        out["conflict_rate"] = d["conflicts"] / d["decisions"]
    return out


def _held_at_end(log: RunLog, sc: Xue1999) -> float:
    last = len(log.scans) - 1
    held = set()
    for tid, path in log.path.items():
        if log.confirmed.get(tid) and path[-1][0] >= last - 2 and log.owner[tid] >= 0:
            if log.sources[tid][-1] == log.owner[tid]:
                held.add(log.owner[tid])
    return len(held) / sc.n_targets
