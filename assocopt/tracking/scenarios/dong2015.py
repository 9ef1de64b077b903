"""Seeded simulator of paper 004's setting (Dong et al. 2015): two biased 2-D radars,
each with its own local Kalman trackers, reporting tracks to a fusion centre.

The paper's values: radars at (0, 0) and (100, 0) km; range noise 100 m and azimuth
noise 0.3 degrees (both); range bias 100 m (both); azimuth bias +2 and -2 degrees;
period 4 s; 12 steps; 30 targets in straight-line motion.  Environments:

1. dense formation: target 1 at (30, 20) km, the others 300 m apart along x, all at
   400 m/s with heading 60 degrees;
2. random targets: positions uniform in the square (50, 50)-(60, 60) km, speed uniform
   in 150-220 m/s, heading uniform in [0, 2 pi);
3. environment 2 with a common observation rate P_c = ``|U1 n U2| / |U1 u U2|`` = 0.5.

Ours (named fields, :data:`OURS`): azimuth and heading measured clockwise from north
(so environment 1's 60 degrees points north-east); how P_c = 0.5 is produced
(``missed`` targets of each sensor seen only by the other, plus ``false_tracks`` per
sensor: stable tracks of non-existent targets drawn like environment 2's, which for 30
targets gives 20 common of 40 observed); the local trackers: a constant-velocity Kalman
filter per target on converted measurements (range/azimuth to Cartesian, covariance by
linearisation at the measured point), white-noise acceleration of density ``q``,
started by two-point differencing.  Association step k = 1..n_steps uses the tracks
after measurement k (measurement 0 only starts them), so step 1 is the two-point track.
Local association is perfect (the subject is the track-to-track association).

>>> sc = Dong2015(env=3)
>>> run = sc.simulate(np.random.default_rng(0))
>>> len(run.steps), run.n_common, round(run.common_observation_rate, 3)
(12, 20, 0.5)
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass
from typing import Any

import numpy as np

from ..filters import cv_model

__all__ = ["Dong2015", "Run", "Step", "OURS"]

#: Parameters that are ours (the paper does not give them).
OURS = ("heading convention", "q", "missed", "false_tracks", "local tracker",
        "track initiation")


@dataclass(frozen=True)
class Step:
    """Both sensors' tracks at one association step (common Cartesian frame, m, m/s)."""

    X1: np.ndarray
    P1: np.ndarray
    X2: np.ndarray
    P2: np.ndarray


@dataclass(frozen=True)
class Run:
    """A simulated run: the steps, each track's true target id (``-1 - f`` for false
    tracks, never shared), and the true heading of each track per step."""

    steps: list
    ids1: np.ndarray
    ids2: np.ndarray
    true_heading1: np.ndarray          # (n_steps, n1), nan for false tracks
    true_heading2: np.ndarray

    @property
    def n_common(self) -> int:
        real1, real2 = self.ids1[self.ids1 >= 0], self.ids2[self.ids2 >= 0]
        return len(set(real1.tolist()) & set(real2.tolist()))

    @property
    def common_observation_rate(self) -> float:
        """P_c = ``|U1 n U2| / |U1 u U2|`` (false tracks count as observed targets)."""
        union = len(set(self.ids1.tolist()) | set(self.ids2.tolist()))
        return self.n_common / union if union else math.nan

    def truth_partner(self) -> np.ndarray:
        """Sensor-2 index of each sensor-1 track's target (``-1``: not common)."""
        where = {int(t): j for j, t in enumerate(self.ids2) if t >= 0}
        return np.array([where.get(int(t), -1) if t >= 0 else -1 for t in self.ids1],
                        dtype=np.int64)


@dataclass(frozen=True)
class Dong2015:
    """Scenario parameters (paper's values as defaults; see :data:`OURS`)."""

    env: int = 2
    n_targets: int = 30
    n_steps: int = 12
    T: float = 4.0
    sensor2_x: float = 100e3
    sigma_r: float = 100.0
    sigma_az_deg: float = 0.3
    bias_r: tuple = (100.0, 100.0)
    bias_az_deg: tuple = (2.0, -2.0)
    q: float = 0.01
    missed: int = 5
    false_tracks: int = 5
    env1_start: tuple = (30e3, 20e3)
    env1_spacing: float = 300.0
    env1_speed: float = 400.0
    env1_heading_deg: float = 60.0
    env2_box: tuple = (50e3, 60e3)
    env2_speed: tuple = (150.0, 220.0)

    def __post_init__(self) -> None:
        if self.env not in (1, 2, 3):
            raise ValueError(f"env must be 1, 2 or 3, got {self.env!r}")
        if self.n_targets < 1 or self.n_steps < 1:
            raise ValueError("n_targets and n_steps must be positive")
        if self.env == 3 and 2 * self.missed >= self.n_targets:
            raise ValueError("2 * missed must be smaller than n_targets")

    def as_dict(self) -> dict[str, Any]:
        d = asdict(self)
        return {k: (list(v) if isinstance(v, tuple) else v) for k, v in d.items()}

    # ----------------------------------------------------------------- truth
    def _initial(self, rng: np.random.Generator, n: int, env: int) -> np.ndarray:
        if env == 1:
            x = self.env1_start[0] + self.env1_spacing * np.arange(n)
            y = np.full(n, self.env1_start[1])
            sp = np.full(n, self.env1_speed)
            hd = np.full(n, math.radians(self.env1_heading_deg))
        else:
            lo, hi = self.env2_box
            x, y = rng.uniform(lo, hi, n), rng.uniform(lo, hi, n)
            sp = rng.uniform(*self.env2_speed, n)
            hd = rng.uniform(0.0, 2 * math.pi, n)
        return np.column_stack([x, y, sp * np.sin(hd), sp * np.cos(hd)])

    def truth(self, x0: np.ndarray) -> np.ndarray:
        """True states ``(n_steps + 1, n, 4)`` at the measurement times 0..n_steps."""
        t = self.T * np.arange(self.n_steps + 1)[:, None]
        X = np.repeat(x0[None], self.n_steps + 1, axis=0)
        X[..., 0] += t * x0[:, 2]
        X[..., 1] += t * x0[:, 3]
        return X

    # ----------------------------------------------------------- measuring
    def _measure(self, rng, X: np.ndarray, s: int) -> tuple[np.ndarray, np.ndarray]:
        """Converted measurements ``(K, n, 2)`` and covariances ``(K, n, 2, 2)``."""
        origin = np.array([0.0, 0.0]) if s == 0 else np.array([self.sensor2_x, 0.0])
        d = X[..., :2] - origin
        r = (np.hypot(d[..., 0], d[..., 1]) + self.bias_r[s]
             + rng.normal(0, self.sigma_r, d.shape[:-1]))
        sa = math.radians(self.sigma_az_deg)
        az = (np.arctan2(d[..., 0], d[..., 1]) + math.radians(self.bias_az_deg[s])
              + rng.normal(0, sa, d.shape[:-1]))
        z = origin + np.stack([r * np.sin(az), r * np.cos(az)], -1)
        J = np.stack([np.stack([np.sin(az), r * np.cos(az)], -1),
                      np.stack([np.cos(az), -r * np.sin(az)], -1)], -2)
        R = J @ np.diag([self.sigma_r ** 2, sa ** 2]) @ np.swapaxes(J, -1, -2)
        return z, R

    def _track(self, z: np.ndarray, R: np.ndarray) -> list[tuple[np.ndarray, np.ndarray]]:
        """Local Kalman tracks after each measurement 1..K-1 (two-point start)."""
        F, Q = cv_model(self.T, self.q)
        T = self.T
        x = np.concatenate([z[1], (z[1] - z[0]) / T], -1)
        n = z.shape[1]
        P = np.zeros((n, 4, 4))
        P[:, :2, :2] = R[1]
        P[:, :2, 2:] = P[:, 2:, :2] = R[1] / T
        P[:, 2:, 2:] = (R[1] + R[0]) / T ** 2
        out = [(x.copy(), P.copy())]
        for k in range(2, z.shape[0]):
            x = x @ F.T
            P = F @ P @ F.T + Q
            S = P[:, :2, :2] + R[k]
            K = P[:, :, :2] @ np.linalg.inv(S)
            x = x + np.einsum("nab,nb->na", K, z[k] - x[:, :2])
            P = P - K @ P[:, :2, :]
            P = 0.5 * (P + np.swapaxes(P, 1, 2))
            out.append((x.copy(), P.copy()))
        return out

    # -------------------------------------------------------------- a run
    def simulate(self, rng: np.random.Generator) -> Run:
        """One run: truth, both sensors' measurements and local tracks."""
        N = self.n_targets
        x0 = self._initial(rng, N, 1 if self.env == 1 else 2)
        seen1 = np.arange(N)
        seen2 = np.arange(N)
        extra1 = extra2 = np.zeros((0, 4))
        if self.env == 3:
            perm = rng.permutation(N)
            only1, only2 = perm[:self.missed], perm[self.missed:2 * self.missed]
            seen1 = np.setdiff1d(np.arange(N), only2)
            seen2 = np.setdiff1d(np.arange(N), only1)
            extra1 = self._initial(rng, self.false_tracks, 2)
            extra2 = self._initial(rng, self.false_tracks, 2)
        ids1 = np.concatenate([seen1, -1 - np.arange(len(extra1))])
        ids2 = np.concatenate([seen2, -1 - len(extra1) - np.arange(len(extra2))])
        X1 = self.truth(np.concatenate([x0[seen1], extra1]))
        X2 = self.truth(np.concatenate([x0[seen2], extra2]))
        o1, o2 = rng.permutation(len(ids1)), rng.permutation(len(ids2))
        ids1, ids2, X1, X2 = ids1[o1], ids2[o2], X1[:, o1], X2[:, o2]
        t1 = self._track(*self._measure(rng, X1, 0))
        t2 = self._track(*self._measure(rng, X2, 1))
        steps = [Step(a[0], a[1], b[0], b[1]) for a, b in zip(t1, t2)]
        hd = lambda X, ids: np.where(ids[None] >= 0, np.arctan2(X[1:, :, 2], X[1:, :, 3]), np.nan)
        return Run(steps, ids1, ids2, hd(X1, ids1), hd(X2, ids2))
