"""Seeded simulator of paper 002's scenarios (Lu et al. 2013, docs/papers/lu2013.md).

The paper gives: three angle-only sensors at S1 = (0, 20, 0), S2 = (20, 0, 0),
S3 = (0, 0, 0) km; angle noise sigma = 1.5 or 5 mrad; no false alarms, no missed
detections; two targets at (x, y, z) and (x + d, y, z) with (x, y, z) random "within
the observation region" (§4.1); M targets equally spaced by d on a straight line
(§4.2).  Everything else is **ours** and a named parameter of :class:`Lu2013`
(:data:`OURS` lists them): the region, the line's direction, the unit of d (km, by
the coordinate units), whether sigma is the same for azimuth and elevation, and the
extensions the paper leaves out (P_D < 1, Poisson false alarms uniform in the field
of view, more sensors).

Measurements of each sensor are put in a random order, so an index never reveals
the target.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass

import numpy as np

from ..costs.sd_builder import Scan
from ...runtime.errors import InvalidProblemError
from ..localisation import angles

__all__ = ["Lu2013", "Truth", "PAPER_SENSORS_KM", "PAPER", "OURS", "REPRODUCTION_REGION_KM"]

#: Sensor positions of §4 (km).
PAPER_SENSORS_KM = ((0.0, 20.0, 0.0), (20.0, 0.0, 0.0), (0.0, 0.0, 0.0))

#: Values the paper gives (recorded with every result).
PAPER = {
    "sensors_km": PAPER_SENSORS_KM,
    "sigma_mrad": [1.5, 5.0],
    "pd": 1.0,
    "false_alarms": 0,
    "runs": 1000,
    "d_grid_fig": "0:0.05:1.5",
    "table_M": [5, 10, 15, 20],
    "table_d": [0.5, 1.0, 1.5],
}

#: The observation region of ``assocopt reproduce lu2013`` (km; the paper gives none).
REPRODUCTION_REGION_KM = ((0.0, 50.0), (0.0, 50.0), (1.0, 10.0))

#: Parameters the paper does not give; our choices are the dataclass defaults.
OURS = ("region_km", "line_direction", "d_unit", "sigma_same_for_both_angles",
        "fov_rad", "clutter_rate", "pd")


@dataclass(frozen=True)
class Truth:
    """Ground truth of one scan.

    ``labels[s][i]`` is the target of measurement ``i`` (0-based) of sensor ``s``,
    ``-1`` for a false alarm.  ``targets`` holds the positions (km).
    """

    targets: np.ndarray
    labels: tuple

    def target_tuples(self) -> np.ndarray:
        """One S-D tuple (1-based indices, 0 = missed) per target detected at least once."""
        N = len(self.labels)
        T = np.zeros((len(self.targets), N), dtype=np.int64)
        for s, lab in enumerate(self.labels):
            for i, j in enumerate(lab):
                if j >= 0:
                    T[j, s] = i + 1
        return T[(T > 0).any(axis=1)]

    def partition(self) -> set[tuple[int, ...]]:
        """The true partition: target tuples plus one singleton per false alarm."""
        N = len(self.labels)
        parts = {tuple(int(v) for v in t) for t in self.target_tuples()}
        for s, lab in enumerate(self.labels):
            for i, j in enumerate(lab):
                if j < 0:
                    t = [0] * N
                    t[s] = i + 1
                    parts.add(tuple(t))
        return parts


@dataclass(frozen=True)
class Lu2013:
    """Scenario of paper 002.  Defaults: the paper's values where it gives them, ours
    (marked in :data:`OURS`) elsewhere.

    Parameters
    ----------
    n_targets : int
        M (2 for Fig. 1-2; 5, 10, 15, 20 for Tables 1-4).
    d : float
        Spacing between neighbouring targets, km (unit ours: not printed).
    sigma_mrad : float
        Angle noise standard deviation, mrad (of the azimuth, and of the elevation
        too unless ``sigma_elevation_mrad`` is given).
    sigma_elevation_mrad : float or None
        Elevation noise standard deviation, mrad; ``None`` (default, ours: the paper
        gives one sigma) means the same as ``sigma_mrad``.
    sensors_km : tuple of (x, y, z)
        Sensor positions; the paper's three by default (more sensors allowed).
    region_km : ((x0, x1), (y0, y1), (z0, z1))
        Box in which the first target is drawn uniformly (ours: not given).  The
        default is a wide field around the sensors, used by the benchmarks
        (``benchmarks/sd_scaling.py``); it is **not** the reproduction's region:
        ``assocopt reproduce lu2013`` uses [0, 50] x [0, 50] x [1, 10] km
        (:data:`REPRODUCTION_REGION_KM`, see ``docs/papers/lu2013.md``).
    line_direction : {"x", "horizontal", "3d"}
        Direction of the line of targets: along +x as the pair of §4.1 (ours),
        uniformly random in the horizontal plane, or uniformly random in 3-D.
    pd : float
        Detection probability (paper: 1).
    clutter_rate : float
        Mean number of false alarms per sensor per scan, Poisson (paper: 0).
    fov_rad : ((el0, el1), (az0, az1))
        Angular field of view in which false alarms fall uniformly (ours).

    Examples
    --------
    >>> scan, truth = Lu2013(n_targets=3, d=1.0).simulate(np.random.default_rng(1))
    >>> scan.sizes, len(truth.target_tuples())
    ((3, 3, 3), 3)
    """

    n_targets: int = 2
    d: float = 1.0
    sigma_mrad: float = 1.5
    sigma_elevation_mrad: float | None = None
    sensors_km: tuple = PAPER_SENSORS_KM
    region_km: tuple = ((-90.0, 110.0), (-90.0, 110.0), (1.0, 20.0))
    line_direction: str = "x"
    pd: float = 1.0
    clutter_rate: float = 0.0
    fov_rad: tuple = ((0.0, math.pi / 2), (-math.pi, math.pi))

    def __post_init__(self) -> None:
        if int(self.n_targets) != self.n_targets or self.n_targets < 1:
            raise InvalidProblemError(f"n_targets must be a positive integer, got {self.n_targets}")
        if not (self.d >= 0 and math.isfinite(self.d)):
            raise InvalidProblemError(f"d must be a finite number >= 0, got {self.d}")
        if not self.sigma_mrad > 0:
            raise InvalidProblemError(f"sigma_mrad must be > 0, got {self.sigma_mrad}")
        if self.sigma_elevation_mrad is not None and not self.sigma_elevation_mrad > 0:
            raise InvalidProblemError(
                f"sigma_elevation_mrad must be > 0 or None, got {self.sigma_elevation_mrad}")
        if not 0 < self.pd <= 1:
            raise InvalidProblemError(f"pd must lie in (0, 1], got {self.pd}")
        if not self.clutter_rate >= 0:
            raise InvalidProblemError(f"clutter_rate must be >= 0, got {self.clutter_rate}")
        if self.line_direction not in ("x", "horizontal", "3d"):
            raise InvalidProblemError(
                f"line_direction must be 'x', 'horizontal' or '3d', got {self.line_direction!r}")
        reg = np.asarray(self.region_km, dtype=float)
        if reg.shape != (3, 2) or not (reg[:, 1] >= reg[:, 0]).all():
            raise InvalidProblemError(f"region_km must be ((x0, x1), (y0, y1), (z0, z1)), "
                                      f"got {self.region_km}")
        S = np.asarray(self.sensors_km, dtype=float)
        if S.ndim != 2 or S.shape[1] != 3 or len(S) < 2:
            raise InvalidProblemError(f"sensors_km must be N >= 2 points (x, y, z), got {S.shape}")

    @property
    def sigma_rad(self) -> float:
        return self.sigma_mrad * 1e-3

    @property
    def sigma_same_for_both_angles(self) -> bool:
        return self.sigma_elevation_mrad is None or self.sigma_elevation_mrad == self.sigma_mrad

    @property
    def sigmas_rad(self) -> np.ndarray:
        """Noise standard deviations ``[elevation, azimuth]``, rad."""
        el = self.sigma_mrad if self.sigma_elevation_mrad is None else self.sigma_elevation_mrad
        return np.array([el, self.sigma_mrad]) * 1e-3

    @property
    def fov_area(self) -> float:
        """Angular area of the field of view, rad^2 (elevation span x azimuth span)."""
        (e0, e1), (a0, a1) = self.fov_rad
        return (e1 - e0) * (a1 - a0)

    def parameters(self) -> dict:
        """Every parameter, as JSON-ready values, with the ones that are ours listed."""
        p = asdict(self)
        p["d_unit"] = "km"
        p["sigma_same_for_both_angles"] = self.sigma_same_for_both_angles
        p["ours"] = list(OURS)
        return p

    def place_targets(self, rng: np.random.Generator) -> np.ndarray:
        """M targets: the first uniform in ``region_km``, the rest spaced by d on a line."""
        reg = np.asarray(self.region_km, dtype=float)
        first = reg[:, 0] + (reg[:, 1] - reg[:, 0]) * rng.random(3)
        if self.line_direction == "x":
            u = np.array([1.0, 0.0, 0.0])
        elif self.line_direction == "horizontal":
            phi = rng.uniform(-math.pi, math.pi)
            u = np.array([math.cos(phi), math.sin(phi), 0.0])
        else:
            v = rng.normal(size=3)
            u = v / np.linalg.norm(v)
        return first + self.d * np.arange(self.n_targets)[:, None] * u

    def simulate(self, rng: np.random.Generator) -> tuple[Scan, Truth]:
        """One scan: noisy, shuffled measurements of every sensor and the ground truth.

        ``rng`` is required (an explicit ``numpy.random.Generator``): no global state.
        """
        if not isinstance(rng, np.random.Generator):
            raise TypeError("rng must be a numpy.random.Generator")
        S = np.asarray(self.sensors_km, dtype=float)
        N = len(S)
        X = self.place_targets(rng)
        theta = angles(X, S)                                   # (M, N, 2)
        sig = self.sigmas_rad                                  # [elevation, azimuth]
        meas, labels = [], []
        (e0, e1), (a0, a1) = self.fov_rad
        for s in range(N):
            det = rng.random(self.n_targets) < self.pd if self.pd < 1 else \
                np.ones(self.n_targets, bool)
            js = np.flatnonzero(det)
            m = theta[js, s] + rng.normal(0.0, sig, size=(len(js), 2))
            lab = js.copy()
            n_fa = rng.poisson(self.clutter_rate) if self.clutter_rate > 0 else 0
            if n_fa:
                fa = np.stack([rng.uniform(e0, e1, n_fa), rng.uniform(a0, a1, n_fa)], axis=1)
                m = np.concatenate([m, fa])
                lab = np.concatenate([lab, -np.ones(n_fa, dtype=np.int64)])
            order = rng.permutation(len(m))
            m = m[order]
            m[:, 1] = np.mod(m[:, 1] + math.pi, 2 * math.pi) - math.pi
            meas.append(m)
            labels.append(lab[order].astype(np.int64))
        R = np.diag(sig ** 2)
        density = self.clutter_rate / self.fov_area if self.clutter_rate > 0 else 0.0
        scan = Scan.create(S, meas, R, pd=self.pd, clutter_density=density)
        return scan, Truth(targets=X, labels=tuple(labels))
