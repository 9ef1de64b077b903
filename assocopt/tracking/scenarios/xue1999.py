"""Seeded simulator of paper 003's setting (Xue et al. 1999): four crossing targets.

The paper simulates four targets in an (x, y) surveillance region with many track
crossings and strong noise (its Figs. 2-3) and gives no parameter at all.  Every value
here is **ours**, a named field of :class:`Xue1999` (:data:`OURS` lists them):

* four constant-velocity targets over ``n_scans`` scans of period ``T``: targets 0
  and 1 meet at (5, 5) km at scan 20 (crossing angle 32 degrees) and share their IFF
  attribute, targets 2 and 3 meet at (5, 7.5) km at scan 30 (51 degrees) with different
  IFF, and the lines of 0/1 and 2/3 cross each other at other times (six crossings in
  all).  No two targets share a position or velocity component away from their
  meeting point;
* each target is detected with probability ``p_d``; a report holds position and
  velocity (x, y, vx, vy) with Gaussian noise ``noise_scale * (sigma_p, sigma_p,
  sigma_v, sigma_v)``, and an IFF attribute (1 friend, 0 foe) reported wrong with
  probability ``p_iff``;
* clutter: Poisson(``clutter_mean``) reports per scan, uniform over the region, with
  velocity uniform in ``[-clutter_v, clutter_v]^2`` and a random IFF.

Reports of a scan are in random order, so an index never reveals the source.

>>> sc = Xue1999(clutter_mean=0.0, p_d=1.0)
>>> scans = sc.simulate(np.random.default_rng(0))
>>> len(scans), sorted(scans[0].source.tolist())
(40, [0, 1, 2, 3])
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass
from typing import Any

import numpy as np

__all__ = ["Xue1999", "Scan", "OURS", "TARGET_STARTS", "TARGET_VELOCITIES", "TARGET_IFF"]

#: Start positions (m) and velocities (m/s) of the four targets (ours).
TARGET_STARTS = ((0.0, 4000.0), (1000.0, 6500.0), (2000.0, 0.0), (8750.0, 750.0))
TARGET_VELOCITIES = ((50.0, 10.0), (40.0, -15.0), (20.0, 50.0), (-25.0, 45.0))
#: IFF of each target: 1 friend, 0 foe (ours): the shallow pair shares it.
TARGET_IFF = (0, 0, 1, 0)

#: Every parameter of the scenario is ours: the paper gives none.
OURS = ("n_scans", "T", "region", "starts", "velocities", "iff", "p_d", "sigma_p",
        "sigma_v", "noise_scale", "p_iff", "clutter_mean", "clutter_v")


@dataclass(frozen=True)
class Scan:
    """One scan: ``reports`` (R, 4) as (x, y, vx, vy), ``iff`` (R,) in {0, 1} and the
    true ``source`` (R,): target index, -1 for clutter."""

    reports: np.ndarray
    iff: np.ndarray
    source: np.ndarray


@dataclass(frozen=True)
class Xue1999:
    """Four crossing targets with noise, clutter and an unreliable IFF (all ours)."""

    n_scans: int = 40
    T: float = 5.0
    region: tuple[float, float] = (10000.0, 10000.0)
    starts: tuple = TARGET_STARTS
    velocities: tuple = TARGET_VELOCITIES
    iff: tuple = TARGET_IFF
    p_d: float = 0.95
    sigma_p: float = 50.0
    sigma_v: float = 5.0
    noise_scale: float = 1.0
    p_iff: float = 0.1
    clutter_mean: float = 10.0
    clutter_v: float = 60.0

    def __post_init__(self) -> None:
        if not isinstance(self.n_scans, (int, np.integer)) or self.n_scans < 1:
            raise ValueError(f"n_scans must be a positive integer, got {self.n_scans!r}")
        for name in ("T", "sigma_p", "sigma_v", "noise_scale", "clutter_v"):
            v = getattr(self, name)
            if not (isinstance(v, (int, float)) and math.isfinite(v) and v > 0):
                raise ValueError(f"{name} must be a finite number > 0, got {v!r}")
        for name in ("p_d", "p_iff"):
            v = getattr(self, name)
            if not 0.0 <= v <= 1.0:
                raise ValueError(f"{name} must lie in [0, 1], got {v!r}")
        if not (math.isfinite(self.clutter_mean) and self.clutter_mean >= 0):
            raise ValueError(f"clutter_mean must be >= 0, got {self.clutter_mean!r}")
        if not (len(self.starts) == len(self.velocities) == len(self.iff) >= 1):
            raise ValueError("starts, velocities and iff must have one entry per target")
        if len(self.region) != 2 or min(self.region) <= 0:
            raise ValueError(f"region must be (width, height) > 0, got {self.region!r}")

    @property
    def n_targets(self) -> int:
        return len(self.starts)

    @property
    def sigma(self) -> np.ndarray:
        """Report noise standard deviations (x, y, vx, vy)."""
        return self.noise_scale * np.array([self.sigma_p, self.sigma_p,
                                            self.sigma_v, self.sigma_v])

    def truth(self) -> np.ndarray:
        """True states, shape (n_scans, n_targets, 4): (x, y, vx, vy) at t = k T."""
        t = self.T * np.arange(self.n_scans)[:, None, None]
        p0 = np.asarray(self.starts, dtype=np.float64)[None]
        v = np.asarray(self.velocities, dtype=np.float64)[None]
        vel = np.broadcast_to(v, (self.n_scans,) + v.shape[1:])
        return np.concatenate([p0 + t * v, vel], axis=2)

    def simulate(self, rng: np.random.Generator) -> list[Scan]:
        """One run: a :class:`Scan` per scan."""
        X = self.truth()
        sig = self.sigma
        true_iff = np.asarray(self.iff, dtype=np.int64)
        scans = []
        for k in range(self.n_scans):
            det = np.flatnonzero(rng.random(self.n_targets) < self.p_d)
            z = X[k, det] + rng.normal(size=(len(det), 4)) * sig
            flip = rng.random(len(det)) < self.p_iff
            iff = np.where(flip, 1 - true_iff[det], true_iff[det])
            nc = int(rng.poisson(self.clutter_mean))
            cz = np.column_stack([rng.uniform(0, self.region[0], nc),
                                  rng.uniform(0, self.region[1], nc),
                                  rng.uniform(-self.clutter_v, self.clutter_v, (nc, 2))])
            ciff = rng.integers(0, 2, nc)
            reports = np.concatenate([z, cz]).reshape(-1, 4)
            allff = np.concatenate([iff, ciff]).astype(np.int64)
            source = np.concatenate([det, np.full(nc, -1)]).astype(np.int64)
            order = rng.permutation(len(source))
            scans.append(Scan(reports[order], allff[order], source[order]))
        return scans

    def as_dict(self) -> dict[str, Any]:
        d = asdict(self)
        return {k: (list(map(list, v)) if k in ("starts", "velocities") else
                    list(v) if isinstance(v, tuple) else v) for k, v in d.items()}
