"""A batched MFA hypothesiser for linear-Gaussian models (Stone Soup extra).

:class:`LinearGaussianMFAHypothesiser` returns the hypotheses of Stone Soup's
``MFAHypothesiser(DistanceGater(PDAHypothesiser(...), Mahalanobis(), gate)))`` -- the
same tags, weights and probabilities, states and measurement predictions, in the same
order -- but computes them in bulk: one Kalman prediction of all mixture components
of a track, their measurement predictions, and the squared Mahalanobis distances and
Gaussian log-densities of every component x detection pair as numpy arrays.  Stone
Soup's chain evaluates every pair in Python, and creates a hypothesis object for each
before the gate drops most of them; here objects are made only for the hypotheses
that pass.

What it computes, per component ``c`` (weight ``w_c``, tag ``tau_c``) and detection
``i`` (PDA, Bar-Shalom and Fortmann; the notation of ``PDAHypothesiser``):

* miss: ``1 - P_D P_G``; detection: ``N(z_i; z_hat, S) P_D / lambda`` for the
  detections inside the ``P_G`` chi-square gate (all of them with ``include_all``);
* normalised over the component's hypotheses (``normalise=True``), then gated by the
  Mahalanobis distance ``< gate_threshold`` and sorted by probability, highest first
  (``DistanceGater``; without a gate: the miss, then the detections in the order
  they are given);
* MFA weight ``w_c p / sum_c w_c`` and tag ``[*tau_c, i + 1]`` (0 for the miss).

Anything else (a nonlinear or non-Gaussian model, no clutter density, detections or
components at several times, extra keyword arguments) is handed to the Stone Soup
chain itself, so the result is always Stone Soup's.
"""

from __future__ import annotations

import math

import numpy as np

try:
    from scipy.stats import chi2
    from stonesoup.base import Property
    from stonesoup.gater.distance import DistanceGater
    from stonesoup.hypothesiser import Hypothesiser
    from stonesoup.hypothesiser.mfa import MFAHypothesiser
    from stonesoup.hypothesiser.probability import PDAHypothesiser
    from stonesoup.measures import Mahalanobis
    from stonesoup.models.base import LinearModel
    from stonesoup.predictor.kalman import KalmanPredictor
    from stonesoup.types.array import CovarianceMatrix, Matrix, StateVector
    from stonesoup.types.detection import MissedDetection
    from stonesoup.types.hypothesis import SingleProbabilityHypothesis
    from stonesoup.types.multihypothesis import MultipleHypothesis
    from stonesoup.types.numeric import Probability
    from stonesoup.types.prediction import (GaussianMeasurementPrediction,
                                            TaggedWeightedGaussianStatePrediction)
    from stonesoup.updater.kalman import KalmanUpdater
except ImportError as exc:  # pragma: no cover - exercised in a subprocess-free test
    raise ImportError("assocopt.tracking.stonesoup.hypothesiser needs Stone Soup: "
                      "pip install assocopt[stonesoup]") from exc

__all__ = ["LinearGaussianMFAHypothesiser"]


class LinearGaussianMFAHypothesiser(Hypothesiser):
    """``MFAHypothesiser(DistanceGater(PDAHypothesiser, Mahalanobis(), gate))``, batched.

    Build it from the PDA hypothesiser and the gate, or from the Stone Soup chain
    with :meth:`from_stonesoup`.  See the module docstring for what it computes.
    """

    hypothesiser: PDAHypothesiser = Property(
        doc="The PDAHypothesiser (Kalman predictor and updater, linear-Gaussian models)")
    gate_threshold: float = Property(
        default=None, doc="Mahalanobis distance gate, as DistanceGater (strict <); "
                          "None: no distance gate")

    @classmethod
    def from_stonesoup(cls, mfa_hypothesiser) -> "LinearGaussianMFAHypothesiser":
        """The batched equivalent of ``MFAHypothesiser(DistanceGater(PDA, Mahalanobis(),
        g))`` or ``MFAHypothesiser(PDA)``."""
        inner = mfa_hypothesiser.hypothesiser
        gate = None
        if isinstance(inner, DistanceGater):
            if type(inner.measure) is not Mahalanobis or inner.measure.mapping is not None:
                raise TypeError("the distance gate must use Mahalanobis() on the whole "
                                "measurement")
            inner, gate = inner.hypothesiser, inner.gate_threshold
        if not isinstance(inner, PDAHypothesiser):
            raise TypeError(f"expected an MFAHypothesiser over a PDAHypothesiser, got "
                            f"{type(inner).__name__}")
        return cls(inner, gate)

    @property
    def reference(self) -> MFAHypothesiser:
        """The Stone Soup chain this computes (used for what it does not batch)."""
        inner = self.hypothesiser if self.gate_threshold is None else DistanceGater(
            self.hypothesiser, Mahalanobis(), self.gate_threshold)
        return MFAHypothesiser(inner)

    # ------------------------------------------------------------------ checks
    def _batchable(self, comps, detections, timestamp, kwargs):
        pda = self.hypothesiser
        if kwargs or pda.clutter_spatial_density is None or not comps:
            return None
        predictor, updater = pda.predictor, pda.updater
        if type(predictor).predict is not KalmanPredictor.predict or \
                type(updater).predict_measurement is not KalmanUpdater.predict_measurement:
            return None
        tm = predictor.transition_model
        control = getattr(predictor, "control_model", None)
        if not isinstance(tm, LinearModel) or any(       # only the default null control
                np.any(np.asarray(getattr(control, name, 0), float) != 0)
                for name in ("control_matrix", "control_noise")):
            return None
        if len({c.timestamp for c in comps}) != 1 or any(
                d.timestamp != timestamp for d in detections):
            return None
        models = {id(d.measurement_model or updater.measurement_model): (
            d.measurement_model or updater.measurement_model) for d in detections}
        mm = next(iter(models.values())) if models else updater.measurement_model
        if len(models) > 1 or not isinstance(mm, LinearModel):
            return None
        return tm, mm

    # -------------------------------------------------------------- hypothesise
    def hypothesise(self, track, detections, timestamp, detections_tuple, **kwargs):
        """The MFA hypotheses of ``track`` (a Gaussian-mixture track) and ``detections``.

        Returns
        -------
        : :class:`~.MultipleHypothesis`
            One :class:`~.SingleProbabilityHypothesis` per component and detection that
            passes the gates, and one per component for the missed detection.
        """
        given, detections = detections, list(detections)
        comps = list(track.state.components)
        models = self._batchable(comps, detections, timestamp, kwargs)
        if models is None:
            return self.reference.hypothesise(track, given, timestamp, detections_tuple,
                                              **kwargs)
        tm, mm = models
        pda = self.hypothesiser
        dt = timestamp - comps[0].timestamp
        F = np.asarray(tm.matrix(time_interval=dt), float)
        Q = np.asarray(tm.covar(time_interval=dt), float)
        H, R = np.asarray(mm.matrix(), float), np.asarray(mm.covar(), float)
        X = np.stack([np.asarray(c.state_vector, float)[:, 0] for c in comps])
        P = np.stack([np.asarray(c.covar, float) for c in comps])
        Xp = X @ F.T
        Pp = F @ P @ F.T + Q
        zp = Xp @ H.T
        cross = Pp @ H.T
        S = H @ cross + R
        n = H.shape[0]
        Z = np.array([np.asarray(d.state_vector, float)[:, 0] for d in detections]
                     ).reshape(len(detections), n)
        Sinv = np.linalg.inv(S)
        diff = Z[None, :, :] - zp[:, None, :]
        md2 = np.einsum("cmi,cij,cmj->cm", diff, Sinv, diff)
        logdet = np.linalg.slogdet(S)[1]
        logpdf = -0.5 * (md2 + logdet[:, None] + n * math.log(2 * math.pi))
        included = np.ones_like(md2, bool) if pda.include_all else \
            md2 <= chi2.ppf(float(pda.prob_gate), n)
        logp = logpdf + math.log(float(pda.prob_detect)) - \
            math.log(float(pda.clutter_spatial_density))
        log_miss = math.log(1 - float(pda.prob_detect) * float(pda.prob_gate))
        logp = np.where(included, logp, -np.inf)
        if pda.normalise:
            total = np.logaddexp(log_miss, np.logaddexp.reduce(logp, axis=1)) \
                if len(detections) else np.full(len(comps), log_miss)
        else:
            total = np.zeros(len(comps))
        keep = included if self.gate_threshold is None else \
            included & (np.sqrt(md2) < self.gate_threshold)
        log_w = np.array([Probability(c.weight).log_value for c in comps])
        log_wsum = float(np.logaddexp.reduce(log_w))
        det_index = {id(d): i + 1 for i, d in enumerate(detections_tuple)}
        missed = MissedDetection(timestamp=timestamp)
        out = []
        for c, comp in enumerate(comps):
            cols = np.flatnonzero(keep[c])
            lp = np.concatenate([[log_miss], logp[c, cols]]) - total[c]
            order = np.argsort(-lp, kind="stable") if self.gate_threshold is not None \
                else np.arange(len(lp))                # DistanceGater sorts, PDA does not
            x, p = StateVector(Xp[c][:, None]), CovarianceMatrix(Pp[c])
            mp = None
            for k in order.tolist():
                weight = Probability(log_w[c] + lp[k] - log_wsum, log_value=True)
                j = -1 if k == 0 else int(cols[k - 1])
                tag = [*comp.tag, 0 if j < 0 else det_index[id(detections[j])]]
                pred = TaggedWeightedGaussianStatePrediction(
                    x, p, timestamp=timestamp, weight=weight, tag=tag,
                    transition_model=tm, prior=comp)
                if j < 0:
                    out.append(SingleProbabilityHypothesis(
                        pred, missed, Probability(lp[k], log_value=True)))
                    continue
                if mp is None:
                    mp = GaussianMeasurementPrediction(
                        StateVector(zp[c][:, None]), CovarianceMatrix(S[c]),
                        timestamp=timestamp, cross_covar=Matrix(cross[c]))
                out.append(SingleProbabilityHypothesis(
                    pred, detections[j], Probability(lp[k], log_value=True), mp))
        return MultipleHypothesis(out)
