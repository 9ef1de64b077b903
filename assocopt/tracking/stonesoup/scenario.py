"""Stone Soup objects for assocopt's simulated scans (Stone Soup extra).

The benchmarks and tests that run a Stone Soup tracker on a scenario of
:mod:`assocopt.tracking.scenarios.simulate` (or :mod:`assocopt.tracking.scenarios`) turn its
arrays into Stone Soup's detections and tracks the same way; this is that way, once.
:func:`entangled_scan` is one scan of clusters of close tracks, built with Stone Soup's
own models, for comparing JPDA associators.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from datetime import datetime, timedelta
from typing import Any, Sequence

import numpy as np

try:
    from stonesoup.hypothesiser.probability import PDAHypothesiser
    from stonesoup.models.measurement.linear import LinearGaussian
    from stonesoup.models.transition.linear import (CombinedLinearGaussianTransitionModel,
                                                    ConstantVelocity)
    from stonesoup.predictor.kalman import KalmanPredictor
    from stonesoup.types.detection import Clutter, Detection
    from stonesoup.types.mixture import GaussianMixture
    from stonesoup.types.numeric import Probability
    from stonesoup.types.state import GaussianState, TaggedWeightedGaussianState
    from stonesoup.types.track import Track
    from stonesoup.updater.kalman import KalmanUpdater
except ImportError as exc:  # pragma: no cover - exercised in a subprocess-free test
    raise ImportError("assocopt.tracking.stonesoup.scenario needs Stone Soup: "
                      "pip install assocopt[stonesoup]") from exc

__all__ = ["scan_detections", "mixture_tracks", "MIXTURE_COVAR", "JPDAScan",
           "entangled_scan"]

#: Initial covariance of :func:`mixture_tracks` (state ``[x, vx, y, vy]``).
MIXTURE_COVAR = np.diag([1.0, 0.5, 1.0, 0.5])


def scan_detections(zs: np.ndarray, labels: Sequence[int], timestamp: Any,
                    measurement_model: Any) -> set:
    """One scan's measurements ``zs`` (m, d) as Stone Soup detections: a
    :class:`~stonesoup.types.detection.Clutter` where ``labels`` is negative (the
    simulators' clutter label), a :class:`~stonesoup.types.detection.Detection` else."""
    if len(zs) != len(labels):
        raise ValueError(f"{len(zs)} measurements but {len(labels)} labels")
    return {(Clutter if labels[m] < 0 else Detection)(
        np.asarray(zs[m], float)[:, None], timestamp=timestamp,
        measurement_model=measurement_model) for m in range(len(zs))}


def mixture_tracks(states: np.ndarray, timestamp: Any,
                   covar: np.ndarray = MIXTURE_COVAR) -> list:
    """An MFA tracker's initial tracks: one :class:`~stonesoup.types.track.Track` per
    row of ``states`` (n, dim), each a Gaussian mixture of one component of weight 1
    and empty tag (no history yet)."""
    return [Track([GaussianMixture([TaggedWeightedGaussianState(
        np.asarray(x, float)[:, None], covar, timestamp=timestamp, weight=Probability(1),
        tag=[])])]) for x in np.asarray(states)]


@dataclass(frozen=True)
class JPDAScan:
    """One scan of :func:`entangled_scan`: the tracks (priors one second earlier), the
    detections (targets and clutter) and the models a JPDA tracker of it uses."""

    tracks: list
    detections: set
    timestamp: datetime
    predictor: Any
    updater: Any
    clutter_density: float
    prob_detect: float

    def hypothesiser(self, **kwargs: Any) -> Any:
        """The scan's :class:`~stonesoup.hypothesiser.probability.PDAHypothesiser`
        (known clutter density and detection probability; ``kwargs`` override)."""
        opts = {"clutter_spatial_density": self.clutter_density,
                "prob_detect": self.prob_detect, **kwargs}
        return PDAHypothesiser(self.predictor, self.updater, **opts)


def entangled_scan(rng: np.random.Generator, n_clusters: int = 1, cluster_size: int = 4,
                   spacing: float = 2.0, clutter_rate: float = 3.0, pd: float = 0.9,
                   sigma: float = 0.5, q: float = 0.05,
                   start: datetime = datetime(2026, 1, 1)) -> JPDAScan:
    """Clusters of ``cluster_size`` tracks ``spacing`` apart on a square grid (a
    position gate of a PDA hypothesiser holds several of a cluster's detections, so
    its tracks are entangled), clusters 1 km apart (independent).

    Stone Soup's models throughout: constant velocity (noise ``q``) per axis,
    linear-Gaussian position measurements (noise ``sigma``).  Each track's prior at
    ``start`` (covariance ``diag(1, 0.5, 1, 0.5)``) is its target's state jittered by
    0.3 in position; one second later each target is detected with probability ``pd``
    and each cluster gets a Poisson(``clutter_rate``) number of false alarms uniform in
    a box around it (the scan's clutter density is ``clutter_rate`` per box area).
    ``rng`` fixes every draw.
    """
    if not isinstance(rng, np.random.Generator):
        raise TypeError("rng must be a numpy.random.Generator")
    if n_clusters < 0 or cluster_size < 1:
        raise ValueError(f"need n_clusters >= 0 and cluster_size >= 1, got "
                         f"{n_clusters}, {cluster_size}")
    transition = CombinedLinearGaussianTransitionModel([ConstantVelocity(q)] * 2)
    mm = LinearGaussian(ndim_state=4, mapping=(0, 2), noise_covar=np.eye(2) * sigma ** 2)
    t1 = start + timedelta(seconds=1)
    width = math.ceil(math.sqrt(cluster_size))
    k = np.arange(cluster_size)
    grid = spacing * np.stack([k % width, k // width], axis=1).astype(float)
    box = spacing * (width - 1) + 10.0
    F = transition.matrix(time_interval=timedelta(seconds=1))
    tracks, detections = [], set()
    for c in range(n_clusters):
        centre = np.array([1000.0 * c, 0.0])
        pos = centre + grid + rng.normal(0.0, 0.3, grid.shape)
        heading = rng.uniform(-np.pi, np.pi, cluster_size)
        X = np.stack([pos[:, 0], np.cos(heading), pos[:, 1], np.sin(heading)], axis=1)
        prior = X + rng.normal(0.0, 0.3, X.shape) * np.array([1.0, 0.0, 1.0, 0.0])
        tracks += [Track([GaussianState(x[:, None], np.diag([1.0, 0.5, 1.0, 0.5]),
                                        timestamp=start)]) for x in prior]
        truth = X @ F.T
        seen = rng.random(cluster_size) < pd
        z = truth[seen][:, [0, 2]] + rng.normal(0.0, sigma, (int(seen.sum()), 2))
        lo = centre + grid.mean(axis=0) - box / 2
        zc = lo + rng.uniform(0.0, box, (rng.poisson(clutter_rate), 2))
        detections |= scan_detections(np.concatenate([z, zc]),
                                      [0] * len(z) + [-1] * len(zc), t1, mm)
    return JPDAScan(tracks, detections, t1, KalmanPredictor(transition), KalmanUpdater(mm),
                    clutter_rate / box ** 2, pd)
