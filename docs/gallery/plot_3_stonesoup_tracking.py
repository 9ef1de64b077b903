"""
A tracking loop with the Stone Soup associator
==============================================

:class:`~assocopt.tracking.stonesoup.AssocoptGNN` is a Stone Soup data associator:
it takes any Stone Soup hypothesiser, builds the assignment problem of each scan from
its hypotheses (missed-detection hypotheses become the miss costs) and solves it with
the assocopt back end you name.  Five targets with nearly constant velocity, a position
sensor with detection probability 0.9 and clutter, simulated by
:class:`~assocopt.tracking.scenarios.simulate.CVScenario`.
"""

from datetime import datetime, timedelta

import matplotlib.pyplot as plt
import numpy as np
from stonesoup.hypothesiser.distance import DistanceHypothesiser
from stonesoup.measures import Mahalanobis
from stonesoup.models.measurement.linear import LinearGaussian
from stonesoup.models.transition.linear import (CombinedLinearGaussianTransitionModel,
                                                ConstantVelocity)
from stonesoup.predictor.kalman import KalmanPredictor
from stonesoup.types.detection import Detection
from stonesoup.types.state import GaussianState
from stonesoup.types.track import Track
from stonesoup.updater.kalman import KalmanUpdater

from assocopt.tracking.scenarios.simulate import CVScenario
from assocopt.tracking.stonesoup import AssocoptGNN, AssocoptKBest

sc = CVScenario(n_targets=5, n_steps=25, q=0.01, pd=0.9, clutter_rate=8.0,
                region=((-40.0, 40.0), (-40.0, 40.0)))
scans = sc.simulate(np.random.default_rng(7))

start = datetime(2026, 1, 1)
transition = CombinedLinearGaussianTransitionModel([ConstantVelocity(sc.q),
                                                    ConstantVelocity(sc.q)])
sensor = LinearGaussian(ndim_state=4, mapping=(0, 2), noise_covar=sc.R)
predictor, updater = KalmanPredictor(transition), KalmanUpdater(sensor)
hypothesiser = DistanceHypothesiser(predictor, updater, measure=Mahalanobis(),
                                    missed_distance=3)
associator = AssocoptGNN(hypothesiser, solver="auto")     # any assocopt back end

tracks = [Track([GaussianState(x0[:, None], np.diag([1.0, 0.5, 1.0, 0.5]),
                               timestamp=start)]) for x0 in scans.truth[0]]
for k, z in enumerate(scans.meas, start=1):
    t = start + timedelta(seconds=k * sc.dt)
    detections = {Detection(zj[:, None], timestamp=t, measurement_model=sensor)
                  for zj in z}
    for track, hypothesis in associator.associate(set(tracks), detections, t).items():
        track.append(updater.update(hypothesis) if hypothesis else hypothesis.prediction)

est = np.array([[s.state_vector[[0, 2], 0] for s in tr.states] for tr in tracks])
err = est.transpose(1, 0, 2) - scans.truth[:, :, [0, 2]]
print(f"position RMSE {float(np.sqrt((err ** 2).sum(axis=2).mean())):.2f} "
      f"(measurement sigma {sc.sigma})")

# %%
# The tracks against the truth, with every measurement (clutter included).
fig, ax = plt.subplots(figsize=(6, 6))
z_all = np.concatenate(scans.meas)
ax.scatter(z_all[:, 0], z_all[:, 1], s=6, c="0.6", label="measurements and clutter")
for i in range(scans.truth.shape[1]):
    ax.plot(scans.truth[:, i, 0], scans.truth[:, i, 2], "k--", lw=1,
            label="truth" if i == 0 else None)
    ax.plot(est[i, :, 0], est[i, :, 1], "-o", ms=3, label=f"track {i}")
ax.set_aspect("equal")
ax.set_xlabel("x")
ax.set_ylabel("y")
ax.legend(fontsize=8, loc="best")
plt.show()

# %%
# For multiple-hypothesis tracking, :class:`~assocopt.tracking.stonesoup.AssocoptKBest`
# returns the k best joint hypotheses of a scan (Murty's ranking), best first.
ranked = AssocoptKBest(hypothesiser, k=3).rank(set(tracks), detections, t)
print([round(float(joint.distance), 2) for joint in ranked])
