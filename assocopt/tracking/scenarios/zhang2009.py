"""Seeded simulator of paper 000's group scenario (Zhang et al. 2009, docs/papers/zhang2009.md).

The paper gives: 9 member targets of 6 types placed completely at random in a
region; two sensors with the same detection probability ``P_d``; Gaussian position
noise whose standard deviation in x and in y is ``f`` times "the average of the
minimum distances between member targets"; attribute BBAs on the 6 types drawn by
one of two generators with probability 1/2 each:

1. three U(0,1) numbers, normalised, to ``{true type}``, the confusion set and
   ``Omega``, in the order drawn;
2. four U(0,1) numbers, normalised; the smallest to the complement of the
   confusion set, the other three in order to ``{true type}``, the confusion set
   and ``Omega``.

Everything else is **ours** and a named parameter of :class:`Zhang2009`
(:data:`OURS` lists them): the region (square, 100 x 100 by default; results do not
depend on its size because the noise scales with the inter-target distance), which
target has which type, the confusion sets (type k is confused with type k+1, the
set containing the true type), the reading of "average minimum distance" (ambiguous),
and the order of each sensor's observations (random, so an index never reveals the
target).  Positions are registered (no bias), and the noise covariance used in the
Mahalanobis distance is the true one, ``sigma^2 I`` per measurement (the paper does not say).

Examples
--------
>>> import numpy as np
>>> draw = Zhang2009(f=0.2, p_d=1.0).simulate(np.random.default_rng(0))
>>> draw.observations.n, len(draw.truth.pairs)
(18, 9)
"""

from __future__ import annotations

from dataclasses import asdict, dataclass
from functools import lru_cache
from typing import Any

import numpy as np

from ..belief.group_matching import Observations, Relations, true_relations

__all__ = ["Zhang2009", "Draw", "PAPER", "OURS", "TYPE_NAMES", "TYPE_ASSIGNMENTS",
           "NOISE_REFERENCES", "confusion_sets", "mean_nearest_distance"]

#: Values the paper gives (recorded with every result).
PAPER = {
    "n_targets": 9,
    "n_types": 6,
    "sensors": 2,
    "same_pd_both_sensors": True,
    "generator_probability": 0.5,
    "runs": 1000,
}

#: Parameters the paper does not give; our choices are the dataclass defaults.
OURS = ("region", "type_assignment", "confusion_size", "confusion_includes_true",
        "noise_reference", "shuffle", "covariance_scale")

TYPE_NAMES = tuple(f"type{k}" for k in range(1, 7))

#: ``"cover"``: every type used at least once, the rest random, shuffled per run;
#: ``"cyclic"``: target k has type k mod n_types (fixed); ``"uniform"``: i.i.d. uniform.
TYPE_ASSIGNMENTS = ("cover", "cyclic", "uniform")

#: The paper's noise reference is ambiguous.  ``"per_run"`` -- each run's mean
#: nearest-neighbour distance of its targets;
#: ``"mean_over_runs"`` -- the expectation of that quantity (a fixed constant for the
#: region, estimated once by a seeded Monte Carlo of 20 000 layouts).
NOISE_REFERENCES = ("per_run", "mean_over_runs")


@dataclass(frozen=True)
class Draw:
    """One simulated run: pooled observations (sensor 1 first) and ground truth.

    ``target[i]`` is the member target (0-based) of pooled observation ``i``;
    ``truth`` the true relations; ``sigma`` the position-noise standard deviation.
    """

    observations: Observations
    target: np.ndarray
    truth: Relations
    positions: np.ndarray
    target_types: np.ndarray
    sigma: float


def confusion_sets(n_types: int, size: int, includes_true: bool) -> np.ndarray:
    """Bitmask of each type's confusion set (ours): types ``k+1`` to ``k+size-1`` mod n,
    plus ``k`` itself when ``includes_true`` (otherwise ``k+1`` to ``k+size``)."""
    k = np.arange(n_types)
    offsets = range(0, size) if includes_true else range(1, size + 1)
    masks = np.zeros(n_types, dtype=np.int64)
    for o in offsets:
        masks |= 1 << ((k + o) % n_types)
    return masks


def mean_nearest_distance(points: np.ndarray) -> float:
    """Mean over points of the distance to the nearest other point."""
    d = np.linalg.norm(points[:, None, :] - points[None, :, :], axis=-1)
    np.fill_diagonal(d, np.inf)
    return float(d.min(axis=1).mean())


@lru_cache(maxsize=16)
def _expected_mean_nearest(n_targets: int, region: tuple[float, float]) -> float:
    rng = np.random.default_rng(20090801)
    pts = rng.random((20_000, n_targets, 2)) * np.asarray(region)
    d = np.linalg.norm(pts[:, :, None, :] - pts[:, None, :, :], axis=-1)
    idx = np.arange(n_targets)
    d[:, idx, idx] = np.inf
    return float(d.min(axis=2).mean())


@dataclass(frozen=True)
class Zhang2009:
    """Scenario of paper 000.  Defaults: the paper's values where it gives them, ours
    (listed in :data:`OURS`) elsewhere.

    Parameters
    ----------
    f : float
        Noise-level factor (paper: swept; grid not given).
    p_d : float
        Detection probability of both sensors (paper: swept; grid not given).
    n_targets, n_types : int
        9 and 6 in the paper.
    region : (width, height)
        Rectangle in which targets are uniform (ours: not given).
    type_assignment : str
        See :data:`TYPE_ASSIGNMENTS` (ours).
    confusion_size : int
        Number of types in a confusion set (ours: 2).
    confusion_includes_true : bool
        Whether a type's confusion set contains the type itself (ours: True).
    noise_reference : str
        See :data:`NOISE_REFERENCES` (the paper's reference is ambiguous; ours: "per_run").
    generator_probability : float
        Probability of attribute generator 1 (paper: 1/2).
    shuffle : bool
        Put each sensor's observations in random order (ours: True).
    covariance_scale : float
        The position covariance the matcher is given, as a multiple of the true noise
        covariance ``sigma^2 I`` (ours: 1, the true one; the paper does not say which
        covariance enters d^2).  The noise actually drawn is always ``sigma^2 I``.
    """

    f: float = 0.3
    p_d: float = 0.8
    n_targets: int = 9
    n_types: int = 6
    region: tuple[float, float] = (100.0, 100.0)
    type_assignment: str = "cover"
    confusion_size: int = 2
    confusion_includes_true: bool = True
    noise_reference: str = "per_run"
    generator_probability: float = 0.5
    shuffle: bool = True
    covariance_scale: float = 1.0

    def __post_init__(self) -> None:
        if not (isinstance(self.f, (int, float)) and self.f > 0):
            raise ValueError(f"f must be a positive number, got {self.f!r}")
        if not (isinstance(self.p_d, (int, float)) and 0.0 <= self.p_d <= 1.0):
            raise ValueError(f"p_d must be in [0, 1], got {self.p_d!r}")
        if not (isinstance(self.n_targets, int) and self.n_targets >= 2):
            raise ValueError(f"n_targets must be an integer >= 2, got {self.n_targets!r}")
        if not (isinstance(self.n_types, int) and 2 <= self.n_types <= 12):
            raise ValueError(f"n_types must be an integer in 2..12, got {self.n_types!r}")
        if not (isinstance(self.confusion_size, int)
                and 1 <= self.confusion_size <= self.n_types - 1):
            raise ValueError(f"confusion_size must be in 1..{self.n_types - 1}, "
                             f"got {self.confusion_size!r}")
        if self.type_assignment not in TYPE_ASSIGNMENTS:
            raise ValueError(f"type_assignment must be one of {TYPE_ASSIGNMENTS}, "
                             f"got {self.type_assignment!r}")
        if self.type_assignment == "cover" and self.n_targets < self.n_types:
            raise ValueError("type_assignment='cover' needs n_targets >= n_types")
        if self.noise_reference not in NOISE_REFERENCES:
            raise ValueError(f"noise_reference must be one of {NOISE_REFERENCES}, "
                             f"got {self.noise_reference!r}")
        if len(self.region) != 2 or min(self.region) <= 0:
            raise ValueError(f"region must be (width, height) > 0, got {self.region!r}")
        if not (isinstance(self.covariance_scale, (int, float)) and self.covariance_scale > 0):
            raise ValueError(f"covariance_scale must be a positive number, "
                             f"got {self.covariance_scale!r}")
        if not 0.0 <= self.generator_probability <= 1.0:
            raise ValueError("generator_probability must be in [0, 1]")
        object.__setattr__(self, "region", tuple(float(v) for v in self.region))

    @property
    def types(self) -> tuple[str, ...]:
        return TYPE_NAMES[:self.n_types] if self.n_types <= 6 else tuple(
            f"type{k}" for k in range(1, self.n_types + 1))

    def as_dict(self) -> dict[str, Any]:
        """All parameters, with the ones that are ours listed under ``"ours"``."""
        d = asdict(self)
        d["region"] = list(self.region)
        d["ours"] = list(OURS)
        return d

    # ------------------------------------------------------------- simulate
    def simulate(self, rng: np.random.Generator) -> Draw:
        """One run: targets, detections, noisy positions, attribute BBAs, truth."""
        n, T = self.n_targets, self.n_types
        truth_pos = rng.random((n, 2)) * np.asarray(self.region)
        types = self._types(rng)
        ref = (mean_nearest_distance(truth_pos) if self.noise_reference == "per_run"
               else _expected_mean_nearest(n, self.region))
        sigma = self.f * ref
        conf = confusion_sets(T, self.confusion_size, self.confusion_includes_true)
        cov = self.covariance_scale * sigma * sigma * np.eye(2)    # as given to the matcher

        parts = []
        for _ in (1, 2):
            detected = np.flatnonzero(rng.random(n) < self.p_d)
            if self.shuffle:
                detected = rng.permutation(detected)
            pos = truth_pos[detected] + sigma * rng.standard_normal((len(detected), 2))
            att = self._attributes(rng, types[detected], conf)
            parts.append((detected, pos, att))
        (t1, p1, a1), (t2, p2, a2) = parts
        obs = Observations.from_sensors(
            p1, a1, p2, a2, covariances1=np.broadcast_to(cov, (len(t1), 2, 2)),
            covariances2=np.broadcast_to(cov, (len(t2), 2, 2)), types=self.types)
        target = np.concatenate([t1, t2]).astype(np.int64)
        return Draw(obs, target, true_relations(target, obs.sensor), truth_pos, types, sigma)

    def _types(self, rng: np.random.Generator) -> np.ndarray:
        n, T = self.n_targets, self.n_types
        if self.type_assignment == "cyclic":
            return np.arange(n) % T
        if self.type_assignment == "uniform":
            return rng.integers(0, T, size=n)
        return rng.permutation(np.concatenate([np.arange(T), rng.integers(0, T, size=n - T)]))

    def _attributes(self, rng: np.random.Generator, types: np.ndarray,
                    conf: np.ndarray) -> np.ndarray:
        """Attribute BBAs (k x 2**T) of the paper's two generators, vectorised."""
        k, T = len(types), self.n_types
        full = (1 << T) - 1
        use_first = rng.random(k) < self.generator_probability
        u3 = rng.random((k, 3))
        u3 /= u3.sum(axis=1, keepdims=True)
        u4 = rng.random((k, 4))
        u4 /= u4.sum(axis=1, keepdims=True)
        # generator 2: the smallest number to the complement, the others in order
        smallest = np.argmin(u4, axis=1)
        keep = np.ones((k, 4), dtype=bool)
        keep[np.arange(k), smallest] = False
        rest = u4[keep].reshape(k, 3)
        comp_mass = u4[np.arange(k), smallest]
        single = np.where(use_first, u3[:, 0], rest[:, 0])
        confm = np.where(use_first, u3[:, 1], rest[:, 1])
        omega = np.where(use_first, u3[:, 2], rest[:, 2])
        compm = np.where(use_first, 0.0, comp_mass)
        out = np.zeros((k, 1 << T))
        rows = np.arange(k)
        c = conf[types]
        np.add.at(out, (rows, 1 << types), single)     # add.at: a set may coincide with another
        np.add.at(out, (rows, c), confm)
        np.add.at(out, (rows, np.full(k, full)), omega)
        np.add.at(out, (rows, full & ~c), compm)
        return out
