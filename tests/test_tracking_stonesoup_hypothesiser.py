"""The batched MFA hypothesiser returns Stone Soup's hypotheses: same tags, order,
weights (to 1e-9), states and measurement predictions, over a tracker run in which the
mixtures grow and are pruned; what it does not batch goes to Stone Soup's chain."""

from __future__ import annotations

from datetime import datetime, timedelta

import numpy as np
import pytest

pytest.importorskip("stonesoup", reason="Stone Soup not installed (pip install assocopt[stonesoup])")

from stonesoup.gater.distance import DistanceGater  # noqa: E402
from stonesoup.hypothesiser.mfa import MFAHypothesiser  # noqa: E402
from stonesoup.hypothesiser.probability import PDAHypothesiser  # noqa: E402
from stonesoup.measures import Mahalanobis  # noqa: E402
from stonesoup.models.measurement.linear import LinearGaussian  # noqa: E402
from stonesoup.models.transition.linear import (  # noqa: E402
    CombinedLinearGaussianTransitionModel, ConstantVelocity)
from stonesoup.predictor.kalman import KalmanPredictor  # noqa: E402
from stonesoup.types.detection import Detection  # noqa: E402
from stonesoup.types.update import GaussianMixtureUpdate  # noqa: E402
from stonesoup.updater.kalman import KalmanUpdater  # noqa: E402

from assocopt.tracking.scenarios.simulate import CrossingScenario  # noqa: E402
from assocopt.tracking.stonesoup import AssocoptMFA  # noqa: E402
from assocopt.tracking.stonesoup.hypothesiser import LinearGaussianMFAHypothesiser  # noqa: E402
from assocopt.tracking.stonesoup.scenario import mixture_tracks, scan_detections  # noqa: E402

START = datetime(2026, 1, 1)


def _same(a, b):
    """Two MultipleHypothesis are equal hypothesis by hypothesis."""
    assert [h.prediction.tag for h in a] == [h.prediction.tag for h in b]
    assert [h.measurement for h in a if h] == [h.measurement for h in b if h]
    np.testing.assert_allclose([float(h.prediction.weight) for h in a],
                               [float(h.prediction.weight) for h in b], rtol=1e-9, atol=0)
    np.testing.assert_allclose([float(h.probability) for h in a],
                               [float(h.probability) for h in b], rtol=1e-9, atol=0)
    for x, y in zip(a, b):
        np.testing.assert_allclose(x.prediction.state_vector, y.prediction.state_vector,
                                   rtol=1e-12, atol=1e-12)
        np.testing.assert_allclose(x.prediction.covar, y.prediction.covar, rtol=1e-12,
                                   atol=1e-12)
        assert x.prediction.timestamp == y.prediction.timestamp
        assert x.prediction.prior is y.prediction.prior
        assert (x.measurement_prediction is None) == (y.measurement_prediction is None)
        if x.measurement_prediction is not None:
            for attr in ("state_vector", "covar", "cross_covar"):
                np.testing.assert_allclose(getattr(x.measurement_prediction, attr),
                                           getattr(y.measurement_prediction, attr),
                                           rtol=1e-12, atol=1e-12)


def _run(n, steps, window, seed, **pda_kw):
    sc = CrossingScenario(n_targets=n, n_steps=steps, clutter_rate=3.0, pd=0.9,
                          region=((-15.0, 15.0),) * 2)
    out = sc.simulate(np.random.default_rng(seed))
    tm = CombinedLinearGaussianTransitionModel([ConstantVelocity(sc.q)] * 2)
    mm = LinearGaussian(ndim_state=4, mapping=(0, 2), noise_covar=sc.R)
    updater = KalmanUpdater(mm)
    pda = PDAHypothesiser(KalmanPredictor(tm), updater, **{
        "clutter_spatial_density": sc.clutter_density, "prob_detect": sc.pd,
        "prob_gate": 0.99, **pda_kw})
    return sc, out, mm, updater, pda


@pytest.mark.parametrize("gate,pda_kw", [
    (4.0, {"include_all": True}), (None, {}), (3.0, {"normalise": False})])
def test_same_hypotheses_as_stone_soups_chain_over_a_tracker_run(gate, pda_kw):
    sc, out, mm, updater, pda = _run(4, 6, 3, seed=1, **pda_kw)
    ref = MFAHypothesiser(pda if gate is None else DistanceGater(pda, Mahalanobis(), gate))
    fast = LinearGaussianMFAHypothesiser.from_stonesoup(ref)
    assert fast.gate_threshold == gate
    assoc = AssocoptMFA(fast, slide_window=3)
    tracks = mixture_tracks(out.truth[0], START)
    n_hyp = 0
    for k, (zs, lab) in enumerate(zip(out.meas, out.labels), start=1):
        t = START + timedelta(seconds=k * sc.dt)
        dets = scan_detections(zs, lab, t, mm)
        dt_ = tuple(dets)
        for track in tracks:
            assert fast._batchable(list(track.state.components), list(dets), t, {})
            a = fast.hypothesise(track, dets, t, dt_)
            _same(a, ref.hypothesise(track, dets, t, dt_))
            n_hyp += len(a)
        for track, hyps in assoc.associate(set(tracks), dets, t).items():
            track.append(GaussianMixtureUpdate(
                components=[updater.update(h) if h else h.prediction for h in hyps],
                hypothesis=hyps))
    assert max(len(tr.state.components) for tr in tracks) >= 4      # mixtures grew
    assert n_hyp > 100


def test_what_is_not_batched_is_stone_soups_own_answer():
    sc, out, mm, updater, pda = _run(2, 1, 2, seed=2, clutter_spatial_density=None)
    ref = MFAHypothesiser(DistanceGater(pda, Mahalanobis(), 4.0))
    fast = LinearGaussianMFAHypothesiser.from_stonesoup(ref)
    track, = mixture_tracks(out.truth[0][:1], START, covar=np.eye(4))
    t = START + timedelta(seconds=1)
    dets = {Detection(z[:, None], timestamp=t, measurement_model=mm) for z in out.meas[0]}
    assert fast._batchable(list(track.state.components), list(dets), t, {}) is None
    _same(fast.hypothesise(track, dets, t, tuple(dets)),
          ref.hypothesise(track, dets, t, tuple(dets)))


def test_from_stonesoup_refuses_what_it_cannot_reproduce():
    sc, out, mm, updater, pda = _run(2, 1, 2, seed=2)
    from stonesoup.measures import Euclidean
    with pytest.raises(TypeError, match="Mahalanobis"):
        LinearGaussianMFAHypothesiser.from_stonesoup(
            MFAHypothesiser(DistanceGater(pda, Euclidean(), 4.0)))
    with pytest.raises(TypeError, match="PDAHypothesiser"):
        LinearGaussianMFAHypothesiser.from_stonesoup(MFAHypothesiser(MFAHypothesiser(pda)))
