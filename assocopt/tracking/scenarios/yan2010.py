"""Paper 001's scenario: emitters in the plane seen by two three-baseline TDOA systems,
each tracking every emitter locally and measuring its frequency, PW and PRI.

The paper's values (:data:`PAPER`): main stations at (100 km, 0) and (-100 km, 0);
baselines 25 km and 30 km, 120 degrees apart; TDOA RMS error 30 ns; frequency RMS error
2 and 3 MHz, PW 25 and 30 ns, PRI 45 and 50 ns; initial positions uniform in
[-100, 100] km per axis, speed uniform in 100-1000 m/s, heading uniform in [0, 2 pi);
manoeuvres and velocity process noise; fixed frequency, PW and PRI; local tracking by
an extended Kalman filter.  Everything else is ours (:data:`OURS`, the fields of
:class:`Yan2010` not in :data:`PAPER`), recorded with every result:

* sampling period 1 s, time 0..80 s; tracks report from the second scan on
  (``init="two-point"``: state from the first two fixes; ``"one-point"``: the first fix,
  zero velocity with the speed prior's variance, then filtered);
* the baselines point at 90, 210 and 330 degrees;
* velocity process noise: a random walk of intensity ``q_true`` (m^2/s^3);
* manoeuvres: every emitter makes one coordinated turn, starting at a time uniform
  in ``turn_start``, lasting ``turn_duration``, with lateral acceleration uniform in
  ``turn_accel`` (sign random);
* emitter parameters: a catalogue of ``emitter_types`` radar types with frequency,
  PW and PRI uniform in ``freq_range`` (MHz), ``pw_range`` and ``pri_range``
  (microseconds); each emitter carries a type drawn uniformly, so emitters of one type
  share their nominal parameters (``emitter_types = 0``: every emitter its own draw
  from the bands, so with fixed bands the feature overlap grows with the number of
  emitters); measured afresh at every scan with the paper's RMS errors;
* coverage: ``single_node_fraction`` of the emitters (rounded) are seen by one node
  only, that node drawn uniformly among the nodes; the others by every node (the
  paper's "common observation area" holds the common ones);
* ``tdoa_sigma_scale`` multiplies every system's TDOA RMS error (1 = the paper's);
* trackers (``tracker``): ``"ekf"`` -- the paper's EKF on the three range differences;
  ``"kf-fix"`` -- a linear Kalman filter on the linear TDOA fixes with their
  covariances; both with the nearly-constant-velocity model of intensity ``q_filter``;
* ``region_scale`` shrinks the box of initial positions (1 = the paper's; a stress
  test only);
* node 2 numbers its tracks in a random order (the association is not given away).
"""

from __future__ import annotations

from dataclasses import asdict, dataclass, fields
from typing import NamedTuple

import numpy as np

from ..filters import cv_model, predict, two_point_init, update
from ..localisation.tdoa import C_LIGHT, TdoaSystem, range_differences, range_jacobian

__all__ = ["PAPER", "OURS", "TRACKERS", "INITS", "Yan2010", "Yan2010Run"]

TRACKERS = ("ekf", "kf-fix")
INITS = ("two-point", "one-point")

#: The paper's parameters (metres, seconds, MHz, microseconds).
PAPER = {
    "main_stations_m": [[100e3, 0.0], [-100e3, 0.0]],
    "baselines_m": [25e3, 30e3],
    "baseline_angle_deg": 120.0,
    "tdoa_sigma_s": [30e-9, 30e-9],
    "freq_sigma_mhz": [2.0, 3.0],
    "pw_sigma_us": [0.025, 0.030],
    "pri_sigma_us": [0.045, 0.050],
    "initial_position_m": [-100e3, 100e3],
    "speed_range_mps": [100.0, 1000.0],
    "heading_range_rad": [0.0, 2 * np.pi],
    "local_tracker": "extended Kalman filter",
    "table1_time_s": 80.0,
}


class Yan2010Run(NamedTuple):
    """One simulated run: truth and every node's track outputs at every reported scan.

    ``times`` ``(K,)``; ``truth`` ``(K, N, 4)``; ``x[n]`` ``(K, n_n, 4)`` and ``P[n]``
    ``(K, n_n, 4, 4)`` node ``n``'s track estimates (``n_n`` tracks: the emitters it
    sees); ``features[n]`` ``(K, n_n, 3)`` (frequency MHz, PW us, PRI us) as measured
    at each scan; ``emitter_of[n][j]`` the emitter of node ``n``'s track ``j`` (node 1
    in emitter order, the other nodes shuffled); ``partners[n][i]`` the node-``n`` track
    of the emitter of node-1 track ``i``, ``-1`` when node ``n`` does not see it
    (``partners[0]`` is the identity); ``partner = partners[1]``.
    """

    times: np.ndarray
    truth: np.ndarray
    x: tuple[np.ndarray, ...]
    P: tuple[np.ndarray, ...]
    features: tuple[np.ndarray, ...]
    partner: np.ndarray
    partners: tuple[np.ndarray, ...]
    emitter_of: tuple[np.ndarray, ...]

    def partners_between(self, a: int, b: int) -> np.ndarray:
        """Node-``b`` track of the emitter of each node-``a`` track, ``-1`` for none."""
        where = np.full(self.truth.shape[1], -1)
        where[self.emitter_of[b]] = np.arange(len(self.emitter_of[b]))
        return where[self.emitter_of[a]]


@dataclass(frozen=True)
class Yan2010:
    """The scenario; parameters the paper does not give are ours (module docstring)."""

    n_targets: int = 60
    duration: float = 80.0
    period: float = 1.0
    tracker: str = "ekf"
    init: str = "two-point"
    q_true: float = 1.0
    q_filter: float = 20.0
    turn_start: tuple[float, float] = (10.0, 60.0)
    turn_duration: tuple[float, float] = (5.0, 20.0)
    turn_accel: tuple[float, float] = (2.0, 20.0)
    freq_range: tuple[float, float] = (9000.0, 9100.0)
    pw_range: tuple[float, float] = (0.8, 1.2)
    pri_range: tuple[float, float] = (950.0, 1050.0)
    emitter_types: int = 10
    region_scale: float = 1.0
    baseline_angles_deg: tuple[float, float, float] = (90.0, 210.0, 330.0)
    nodes: int = 2
    single_node_fraction: float = 0.0
    tdoa_sigma_scale: float = 1.0

    def __post_init__(self) -> None:
        if not (isinstance(self.n_targets, int) and self.n_targets >= 1):
            raise ValueError(f"n_targets must be a positive integer, got {self.n_targets!r}")
        if self.tracker not in TRACKERS:
            raise ValueError(f"tracker must be one of {TRACKERS}, got {self.tracker!r}")
        if not (self.period > 0 and self.duration >= 2 * self.period):
            raise ValueError(f"need period > 0 and duration >= 2 periods, got "
                             f"{self.period!r}, {self.duration!r}")
        if not self.region_scale > 0:
            raise ValueError(f"region_scale must be > 0, got {self.region_scale!r}")
        if self.init not in INITS:
            raise ValueError(f"init must be one of {INITS}, got {self.init!r}")
        if not (isinstance(self.emitter_types, int) and self.emitter_types >= 0):
            raise ValueError(f"emitter_types must be an integer >= 0, got {self.emitter_types!r}")
        if self.nodes not in (2, 3):
            raise ValueError(f"nodes must be 2 or 3, got {self.nodes!r}")
        if not 0.0 <= self.single_node_fraction <= 1.0:
            raise ValueError(f"single_node_fraction must be in [0, 1], got "
                             f"{self.single_node_fraction!r}")
        if not self.tdoa_sigma_scale > 0:
            raise ValueError(f"tdoa_sigma_scale must be > 0, got {self.tdoa_sigma_scale!r}")
        for name in ("freq_range", "pw_range", "pri_range", "turn_start", "turn_duration",
                     "turn_accel"):
            lo, hi = getattr(self, name)
            if not lo <= hi:
                raise ValueError(f"{name} must be (low, high) with low <= high")

    def as_dict(self) -> dict:
        return {k: (list(v) if isinstance(v, tuple) else v) for k, v in asdict(self).items()}

    # ------------------------------------------------------------------ sensors
    def systems(self) -> list[TdoaSystem]:
        """The TDOA systems: the paper's two, and (``nodes=3``, ours) a third at (0, 100 km)
        with 28 km baselines."""
        mains, Ls, sig = PAPER["main_stations_m"], PAPER["baselines_m"], PAPER["tdoa_sigma_s"]
        k = self.tdoa_sigma_scale
        out = [TdoaSystem(tuple(mains[n]), Ls[n], k * sig[n], self.baseline_angles_deg)
               for n in range(2)]
        if self.nodes == 3:
            out.append(TdoaSystem((0.0, 100e3), 28e3, k * 30e-9, self.baseline_angles_deg))
        return out

    def feature_sigmas(self) -> np.ndarray:
        """``(nodes, 3)`` RMS errors of frequency (MHz), PW and PRI (us)."""
        s = np.array([PAPER["freq_sigma_mhz"], PAPER["pw_sigma_us"], PAPER["pri_sigma_us"]]).T
        return np.vstack([s, s.mean(axis=0)]) if self.nodes == 3 else s

    # ------------------------------------------------------------------ truth
    def trajectories(self, rng: np.random.Generator) -> np.ndarray:
        """True states ``(K0, N, 4)`` at scans ``0, T, 2T, ...`` up to ``duration``."""
        N, T = self.n_targets, self.period
        K0 = int(round(self.duration / T)) + 1
        lo, hi = (self.region_scale * v for v in PAPER["initial_position_m"])
        pos = rng.uniform(lo, hi, size=(N, 2))
        speed = rng.uniform(*PAPER["speed_range_mps"], size=N)
        head = rng.uniform(0.0, 2 * np.pi, size=N)
        vel = speed[:, None] * np.stack([np.cos(head), np.sin(head)], axis=1)
        t0 = rng.uniform(*self.turn_start, size=N)
        t1 = t0 + rng.uniform(*self.turn_duration, size=N)
        acc = rng.uniform(*self.turn_accel, size=N) * rng.choice([-1.0, 1.0], size=N)
        out = np.empty((K0, N, 4))
        out[0] = np.hstack([pos, vel])
        for k in range(1, K0):
            t = (k - 1) * T
            turning = (t >= t0) & (t < t1)
            w = np.where(turning, acc / np.maximum(np.linalg.norm(vel, axis=1), 1.0), 0.0) * T
            c, s = np.cos(w), np.sin(w)
            new = np.stack([c * vel[:, 0] - s * vel[:, 1], s * vel[:, 0] + c * vel[:, 1]], 1)
            pos = pos + 0.5 * T * (vel + new)
            vel = new + rng.normal(0.0, np.sqrt(self.q_true * T), size=(N, 2))
            out[k] = np.hstack([pos, vel])
        return out

    def emitters(self, rng: np.random.Generator) -> np.ndarray:
        """Nominal (frequency, PW, PRI) per emitter ``(N, 3)``: drawn from a catalogue of
        ``emitter_types`` radar types (each emitter a type uniformly at random), or one
        draw per emitter when ``emitter_types`` is 0."""
        n = self.emitter_types or self.n_targets
        cat = np.stack([rng.uniform(*r, size=n) for r in
                        (self.freq_range, self.pw_range, self.pri_range)], axis=1)
        return cat[rng.integers(n, size=self.n_targets)] if self.emitter_types else cat

    # ------------------------------------------------------------------ tracking
    def track(self, system: TdoaSystem, truth: np.ndarray, rng: np.random.Generator
              ) -> tuple[np.ndarray, np.ndarray]:
        """One node's track estimates ``(K, N, 4)``, ``(K, N, 4, 4)`` at scans 1..K0-1
        (its TDOA noise drawn from ``rng``)."""
        xs, Ps = self.filter_nodes([system], [system.tdoa(truth[:, :, :2], rng)])
        return xs[0], Ps[0]

    def filter_nodes(self, systems: list[TdoaSystem], tdoas: list[np.ndarray]
                     ) -> tuple[list[np.ndarray], list[np.ndarray]]:
        """Every node's track estimates (as :meth:`track`) from its measured TDOAs
        ``(K0, N, 3)``: the nodes' filters run as one batch of ``nodes * N`` tracks (each
        with its own stations and noise), so a scan costs one filter step, not one per
        node."""
        F, Q = cv_model(self.period, self.q_filter)
        K0, N = tdoas[0].shape[:2]
        x, P = (np.concatenate(a) for a in zip(*(self._init(s, t) for s, t in
                                                  zip(systems, tdoas))))
        first = 2 if self.init == "two-point" else 1
        xs, Ps = ([x], [P]) if first == 2 else ([], [])
        if self.tracker == "ekf":
            st = np.repeat(np.stack([s.stations for s in systems]), N, axis=0)   # (nodes N, 4, 2)
            R = np.repeat(np.stack([s.range_sigma ** 2 * np.eye(3) for s in systems]), N, axis=0)
            z = C_LIGHT * np.concatenate(tdoas, axis=1)                        # range differences
        else:
            fixes = [s.fix(t) for s, t in zip(systems, tdoas)]
            z = np.concatenate([f.position for f in fixes], axis=1)
            R = np.concatenate([f.covariance for f in fixes], axis=1)
            Hpos = np.hstack([np.eye(2), np.zeros((2, 2))])
        for k in range(first, K0):
            x, P = predict(x, P, F, Q)
            if self.tracker == "ekf":
                J = range_jacobian(x[:, :2], st)
                H = np.concatenate([J, np.zeros(J.shape)], axis=-1)
                x, P = update(x, P, z[k] - range_differences(x[:, :2], st), H, R)
            else:
                x, P = update(x, P, z[k] - x[:, :2], Hpos, R[k])
            xs.append(x)
            Ps.append(P)
        X, PP = np.stack(xs), np.stack(Ps)
        cut = [slice(n * N, (n + 1) * N) for n in range(len(systems))]
        return [X[:, c] for c in cut], [PP[:, c] for c in cut]

    def _init(self, system: TdoaSystem, tdoa: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """A node's initial state and covariance: at the second scan from the first two
        fixes (``"two-point"``), or at the first from its fix (``"one-point"``)."""
        f0, f1 = system.fix(tdoa[0]), system.fix(tdoa[1])
        if self.init == "two-point":
            return two_point_init(f0.position, f0.covariance, f1.position, f1.covariance,
                                  self.period)
        N = tdoa.shape[1]
        x = np.concatenate([f0.position, np.zeros((N, 2))], axis=1)
        vv = PAPER["speed_range_mps"][1] ** 2 / 2 * np.eye(2)   # E|v|^2 / 2 per axis
        P = np.zeros((N, 4, 4))
        P[:, :2, :2], P[:, 2:, 2:] = f0.covariance, vv
        return x, P

    def coverage(self, rng: np.random.Generator) -> np.ndarray:
        """``(nodes, N)`` bool: which node sees which emitter (``single_node_fraction``
        of them, rounded, by one node only, drawn uniformly; no draw when it is 0)."""
        N = self.n_targets
        seen = np.ones((self.nodes, N), dtype=bool)
        k = int(round(self.single_node_fraction * N))
        if k:
            only = rng.choice(N, size=k, replace=False)
            seen[:, only] = False
            seen[rng.integers(self.nodes, size=k), only] = True
        return seen

    def simulate(self, rng: np.random.Generator) -> Yan2010Run:
        """Truth, both (or three) nodes' tracks and measured features; seeded by ``rng``.

        With ``single_node_fraction = 0`` the draws are those of the full-coverage
        scenario (the coverage draw comes last and draws nothing then).
        """
        truth = self.trajectories(rng)
        N = self.n_targets
        emit = self.emitters(rng)
        sig = self.feature_sigmas()
        K = truth.shape[0] - 1
        tdoas, feats = [], []
        perms = [np.arange(N)] + [rng.permutation(N) for _ in range(self.nodes - 1)]
        systems = self.systems()
        for n, system in enumerate(systems):       # draws node by node: TDOAs, features
            tdoas.append(system.tdoa(truth[:, :, :2], rng))
            feats.append(emit[None] + rng.normal(size=(K, N, 3)) * sig[n])
        xs, Ps = self.filter_nodes(systems, tdoas)
        seen = self.coverage(rng)
        emitter_of = tuple(p[seen[n][p]] for n, p in enumerate(perms))   # node n's track j
        where = np.full((self.nodes, N), -1)
        for n, e in enumerate(emitter_of):
            where[n, e] = np.arange(len(e))
        partners = tuple(where[n][emitter_of[0]] for n in range(self.nodes))
        times = self.period * np.arange(1, K + 1)
        return Yan2010Run(times, truth[1:], tuple(x[:, e] for x, e in zip(xs, emitter_of)),
                          tuple(P[:, e] for P, e in zip(Ps, emitter_of)),
                          tuple(f[:, e] for f, e in zip(feats, emitter_of)), partners[1],
                          partners, emitter_of)


#: Names of the parameters that are ours (every field of :class:`Yan2010`).
OURS = tuple(f.name for f in fields(Yan2010))
