"""Stone Soup objects for assocopt's simulated scans (Stone Soup extra).

The benchmarks and tests that run a Stone Soup tracker on a scenario of
:mod:`assocopt.tracking.scenarios.simulate` (or :mod:`assocopt.tracking.scenarios`) turn its
arrays into Stone Soup's detections and tracks the same way; this is that way, once.
"""

from __future__ import annotations

from typing import Any, Sequence

import numpy as np

try:
    from stonesoup.types.detection import Clutter, Detection
    from stonesoup.types.mixture import GaussianMixture
    from stonesoup.types.numeric import Probability
    from stonesoup.types.state import TaggedWeightedGaussianState
    from stonesoup.types.track import Track
except ImportError as exc:  # pragma: no cover - exercised in a subprocess-free test
    raise ImportError("assocopt.tracking.stonesoup.scenario needs Stone Soup: "
                      "pip install assocopt[stonesoup]") from exc

__all__ = ["scan_detections", "mixture_tracks", "MIXTURE_COVAR"]

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
