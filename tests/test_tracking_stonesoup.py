"""assocopt inside Stone Soup: the same associations and tracks as GNNWith2DAssignment."""

from __future__ import annotations

from datetime import datetime, timedelta

import numpy as np
import pytest

pytest.importorskip("stonesoup", reason="Stone Soup not installed (pip install assocopt[stonesoup])")

from stonesoup.dataassociator.neighbour import GNNWith2DAssignment  # noqa: E402
from stonesoup.hypothesiser.distance import DistanceHypothesiser  # noqa: E402
from stonesoup.hypothesiser.probability import PDAHypothesiser  # noqa: E402
from stonesoup.measures import Mahalanobis  # noqa: E402
from stonesoup.models.measurement.linear import LinearGaussian  # noqa: E402
from stonesoup.models.transition.linear import (  # noqa: E402
    CombinedLinearGaussianTransitionModel, ConstantVelocity)
from stonesoup.predictor.kalman import KalmanPredictor  # noqa: E402
from stonesoup.types.detection import Clutter, Detection  # noqa: E402
from stonesoup.types.state import GaussianState  # noqa: E402
from stonesoup.types.track import Track  # noqa: E402
from stonesoup.updater.kalman import KalmanUpdater  # noqa: E402

from assocopt.tracking.scenarios.simulate import CVScenario  # noqa: E402
from assocopt.tracking.stonesoup import (AssocoptGNN, AssocoptKBest,  # noqa: E402
                                        hypotheses_problem)
from conftest import fresh_python  # noqa: E402

START = datetime(2026, 1, 1)


def _scene(sc: CVScenario, seed: int):
    out = sc.simulate(np.random.default_rng(seed))
    transition = CombinedLinearGaussianTransitionModel(
        [ConstantVelocity(sc.q), ConstantVelocity(sc.q)])
    mm = LinearGaussian(ndim_state=4, mapping=(0, 2), noise_covar=sc.R)
    scans = []
    for k, (z, lab) in enumerate(zip(out.meas, out.labels), start=1):
        t = START + timedelta(seconds=k * sc.dt)
        scans.append((t, {(Clutter if lab[m] < 0 else Detection)(
            z[m][:, None], timestamp=t, measurement_model=mm) for m in range(len(z))}))
    priors = [GaussianState(x[:, None], np.diag([1.0, 0.5, 1.0, 0.5]), timestamp=START)
              for x in out.truth[0]]
    predictor = KalmanPredictor(transition)
    updater = KalmanUpdater(mm)
    return out, scans, priors, predictor, updater


def _run(associator, updater, priors, scans):
    """A tutorial-style GNN loop; returns the tracks and each step's associations."""
    tracks = [Track([p]) for p in priors]
    history = []
    for t, dets in scans:
        assoc = associator.associate(set(tracks), dets, t)
        history.append({tracks.index(tr): (h.measurement if h else None)
                        for tr, h in assoc.items()})
        for tr, h in assoc.items():
            tr.append(updater.update(h) if h else h.prediction)
    return tracks, history


@pytest.mark.parametrize("solver", ["auto", "highs"])
def test_same_associations_and_identical_tracks_as_gnn_with_2d_assignment(solver):
    sc = CVScenario(n_targets=5, n_steps=25, clutter_rate=4.0, pd=0.9)
    out, scans, priors, predictor, updater = _scene(sc, seed=3)
    hyp = DistanceHypothesiser(predictor, updater, measure=Mahalanobis(), missed_distance=3)
    ours_tracks, ours = _run(AssocoptGNN(hyp, solver=solver), updater, priors, scans)
    ref_tracks, ref = _run(GNNWith2DAssignment(hyp), updater, priors, scans)
    assert ours == ref                                          # at every step
    assert sum(m is not None for step in ref for m in step.values()) > 80
    assert sum(m is None for step in ref for m in step.values()) > 5   # misses happen
    for a, b in zip(ours_tracks, ref_tracks):
        assert len(a) == len(b) == sc.n_steps + 1
        for sa, sb in zip(a.states, b.states):
            assert np.array_equal(sa.state_vector, sb.state_vector)
            assert np.array_equal(sa.covar, sb.covar)


def test_probability_hypotheses_match_gnn_with_2d_assignment():
    sc = CVScenario(n_targets=4, n_steps=10, clutter_rate=3.0, pd=0.9)
    out, scans, priors, predictor, updater = _scene(sc, seed=8)
    hyp = PDAHypothesiser(predictor, updater, clutter_spatial_density=sc.clutter_density,
                          prob_detect=0.9)
    _, ours = _run(AssocoptGNN(hyp), updater, priors, scans)
    _, ref = _run(GNNWith2DAssignment(hyp), updater, priors, scans)
    assert ours == ref


def test_log_score_maximises_the_product_of_probabilities():
    sc = CVScenario(n_targets=4, n_steps=1, clutter_rate=3.0, pd=0.9)
    out, scans, priors, predictor, updater = _scene(sc, seed=2)
    hyp = PDAHypothesiser(predictor, updater, clutter_spatial_density=sc.clutter_density,
                          prob_detect=0.9)
    tracks = {Track([p]) for p in priors}
    t, dets = scans[0]
    hypotheses = {tr: hyp.hypothesise(tr, dets, t) for tr in tracks}
    best = AssocoptGNN(hyp, probability_score="log").associate_hypotheses(hypotheses)
    from stonesoup.dataassociator.neighbour import GlobalNearestNeighbour
    exhaustive = max(GlobalNearestNeighbour.enumerate_joint_hypotheses(hypotheses))
    assert {tr: h.measurement for tr, h in best.items()} == \
        {tr: h.measurement for tr, h in exhaustive.items()}


def test_problem_from_hypotheses_has_the_miss_candidates():
    sc = CVScenario(n_targets=3, n_steps=1, clutter_rate=2.0)
    out, scans, priors, predictor, updater = _scene(sc, seed=1)
    hyp = DistanceHypothesiser(predictor, updater, measure=Mahalanobis(), missed_distance=3)
    t, dets = scans[0]
    hypotheses = {Track([p]): hyp.hypothesise(Track([p]), dets, t) for p in priors}
    p, tracks, table = hypotheses_problem(hypotheses)
    rm, cm = p.miss_costs()
    np.testing.assert_array_equal(rm, 3.0)
    np.testing.assert_array_equal(cm, 0.0)
    n_hyp = sum(len(h) for h in hypotheses.values())
    assert p.n_candidates == n_hyp + p.sizes[1] and len(table) == n_hyp
    for (i, j), h in table.items():
        assert (j == 0) == (not h)


@pytest.mark.parametrize("module", ["stonesoup", "stonesoup.associators",
                                    "stonesoup.hypothesiser", "stonesoup.scenario",
                                    "stonesoup.jpda", "stonesoup.problems"])
def test_missing_stonesoup_names_the_extra(module):
    code = ("import sys; sys.modules['stonesoup'] = None\n"
            f"try:\n    import assocopt.tracking.{module}\n"
            "except ImportError as exc:\n    print(exc)")
    assert "pip install assocopt[stonesoup]" in fresh_python(code)


def test_importing_tracking_does_not_import_stonesoup():
    code = ("import sys, assocopt.tracking, assocopt.tracking.gating, "
            "assocopt.tracking.costs.kinematic, assocopt.tracking.gating.tuples, "
            "assocopt.tracking.mfa, assocopt.tracking.scenarios.simulate; "
            "print('stonesoup' in sys.modules)")
    assert fresh_python(code).strip() == "False"



@pytest.mark.parametrize("k", [1, 4, 50])
def test_k_best_joint_hypotheses_equal_stone_soups_enumeration(k):
    from stonesoup.dataassociator.neighbour import GlobalNearestNeighbour

    sc = CVScenario(n_targets=3, n_steps=1, clutter_rate=2.0, region=((-6.0, 6.0),) * 2)
    out, scans, priors, predictor, updater = _scene(sc, seed=7)
    hyp = DistanceHypothesiser(predictor, updater, measure=Mahalanobis(), missed_distance=4)
    tracks = {Track([p]) for p in priors}
    t, dets = scans[0]
    hypotheses = {tr: hyp.hypothesise(tr, dets, t) for tr in tracks}
    ranker = AssocoptKBest(hyp, k=k)
    ranked = ranker.rank_hypotheses(hypotheses)
    every = sorted(float(j.distance) for j in
                   GlobalNearestNeighbour.enumerate_joint_hypotheses(hypotheses))
    assert 8 < len(every) < 50                       # the scene has real alternatives
    assert [float(j.distance) for j in ranked] == pytest.approx(every[:k])
    keys = [frozenset((tr, h.measurement) for tr, h in j.items()) for j in ranked]
    assert len(set(keys)) == len(keys)                    # distinct joint hypotheses
    best = AssocoptGNN(hyp).associate_hypotheses(hypotheses)
    assert keys[0] == frozenset((tr, h.measurement) for tr, h in best.items())
    assert ranker.last_ranked.objectives == pytest.approx(every[:k])
    assert [float(j.distance) for j in ranker.rank(tracks, dets, t)] == pytest.approx(every[:k])
    with pytest.raises(ValueError, match="positive integer"):
        AssocoptKBest(hyp, k=0).rank_hypotheses(hypotheses)


def test_every_data_associator_returns_a_mapping_and_the_ranker_is_not_one():
    """A DataAssociator's associate returns track -> hypothesis (what trackers use);
    the k-best ranking, which returns a list, has its own interface."""
    from stonesoup.dataassociator.base import DataAssociator
    from stonesoup.tracker.simple import MultiTargetTracker
    from assocopt.tracking.stonesoup import associators as mod

    assert not issubclass(AssocoptKBest, DataAssociator)
    assert not hasattr(AssocoptKBest, "associate")
    sc = CVScenario(n_targets=3, n_steps=4, clutter_rate=2.0)
    out, scans, priors, predictor, updater = _scene(sc, seed=4)
    hyp = DistanceHypothesiser(predictor, updater, measure=Mahalanobis(), missed_distance=3)
    assert {c for c in vars(mod).values() if isinstance(c, type) and issubclass(
        c, DataAssociator) and c is not DataAssociator} == {AssocoptGNN, mod.AssocoptMFA}

    class Feed:                                   # a detector yielding the scans
        def __iter__(self):
            return iter(scans)

    class Never:                                  # no initiation, no deletion
        def initiate(self, *a, **k):
            return set()

        def delete_tracks(self, tracks):
            return set()

    tracker = MultiTargetTracker(initiator=Never(), deleter=Never(), detector=Feed(),
                                 data_associator=AssocoptGNN(hyp), updater=updater)
    tracker._tracks = {Track([p]) for p in priors}
    steps = [len(tracks) for _, tracks in tracker]
    assert steps == [3] * sc.n_steps
    assert all(len(tr) == sc.n_steps + 1 for tr in tracker.tracks)


def test_guide_figure_script_draws_both_loops(tmp_path):
    from conftest import load_script
    mod = load_script("docs/tracking_figure.py", "tracking_figure")
    blocks = mod.section_blocks()          # the section's examples, the two loops last
    assert len(blocks) >= 2 and "AssocoptGNN" in blocks[-1] and "build_problem" in blocks[-2]
    out = mod.main(["--out", str(tmp_path / "fig.png")])
    assert out.stat().st_size > 10_000
