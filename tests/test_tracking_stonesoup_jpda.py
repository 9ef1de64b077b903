"""Stone Soup JPDA with assocopt's marginals: the hypotheses read in bulk, and the
probabilities (and tracks) of Stone Soup's own JPDAwithEHM2, checked with Stone Soup."""

from __future__ import annotations

from datetime import timedelta

import numpy as np
import pytest

pytest.importorskip("stonesoup", reason="Stone Soup not installed (pip install assocopt[stonesoup])")

from stonesoup.dataassociator.probability import JPDA, JPDAwithEHM2  # noqa: E402
from stonesoup.hypothesiser import Hypothesiser  # noqa: E402
from stonesoup.hypothesiser.distance import DistanceHypothesiser  # noqa: E402
from stonesoup.measures import Mahalanobis  # noqa: E402
from stonesoup.types.detection import MissedDetection  # noqa: E402
from stonesoup.types.hypothesis import SingleProbabilityHypothesis  # noqa: E402
from stonesoup.types.multihypothesis import MultipleHypothesis  # noqa: E402
from stonesoup.types.numeric import Probability  # noqa: E402
from stonesoup.types.state import GaussianState  # noqa: E402
from stonesoup.types.track import Track  # noqa: E402

import assocopt  # noqa: E402
from assocopt.tracking.stonesoup import (AssocoptJPDA, AssocoptKBest,  # noqa: E402
                                        hypotheses_problem, probability_problem)
from assocopt.tracking.stonesoup import jpda as jpda_mod  # noqa: E402
from assocopt.tracking.stonesoup.problems import hypothesis_table  # noqa: E402
from assocopt.tracking.stonesoup.scenario import entangled_scan  # noqa: E402

class Cached(Hypothesiser):
    """Serves fixed hypotheses, so that both associators get the very same objects."""

    def hypothesise(self, track, detections, timestamp, **kwargs):
        return self.table[track]


def _hypotheses(scan, **kwargs):
    hyp = scan.hypothesiser(**kwargs)
    return {tr: hyp.hypothesise(tr, scan.detections, scan.timestamp) for tr in scan.tracks}


def _same_posterior(ours: dict, ref: dict, tol: float = 1e-9) -> float:
    """Equal structure (tracks, hypotheses in order, same objects) and probabilities
    within ``tol``; returns the largest difference."""
    assert set(ours) == set(ref)
    worst = 0.0
    for track, mh in ref.items():
        got = ours[track]
        assert isinstance(got, MultipleHypothesis) and got.normalise
        assert len(got) == len(mh)
        for a, b in zip(got, mh):
            assert isinstance(a, SingleProbabilityHypothesis)
            assert isinstance(a.probability, Probability)
            assert a.measurement is b.measurement and a.prediction is b.prediction
            assert a.measurement_prediction is b.measurement_prediction
            worst = max(worst, abs(float(a.probability) - float(b.probability)))
        if len(got):
            assert abs(sum(float(h.probability) for h in got) - 1.0) < 1e-12
            assert isinstance(got[0].measurement, MissedDetection)
    assert worst <= tol
    return worst


# ------------------------------------------------------------------ bulk conversion
def test_probability_problem_scores_are_the_log_probabilities_dense_or_sparse():
    scan = entangled_scan(np.random.default_rng(0), n_clusters=1, cluster_size=4)
    hyps = _hypotheses(scan)
    dense, sparse = probability_problem(hyps, dense=True), probability_problem(hyps,
                                                                               dense=False)
    assert dense.problem.dense_view is not None and sparse.problem.dense_view is None
    t = dense.table
    assert t.tracks == list(hyps) and t.hypotheses == [h for v in hyps.values() for h in v]
    for k, h in enumerate(t.hypotheses):
        assert dense.score[k] == h.probability.log_value
        assert (t.col[k] < 0) == (not h)
        if h:
            assert t.detections[t.col[k]] is h.measurement
        assert t.tracks[t.row[k]] is next(tr for tr, v in hyps.items() if h in v)
    assert len(t.detections) == len({id(h.measurement) for h in t.hypotheses if h})
    for pp in (dense, sparse):
        p = pp.problem
        assert p.maximize and p.sizes == t.shape
        S = np.full(t.shape, -np.inf)
        pair = t.col >= 0
        S[t.row[pair], t.col[pair]] = pp.score[pair]
        np.testing.assert_array_equal(-p.to_cost_matrix(), S)
        rm, cm = p.miss_costs()
        np.testing.assert_array_equal(-rm, pp.score[~pair])
        np.testing.assert_array_equal(cm, 0.0)
    a, b = (assocopt.marginals(pp.problem, k=10**4) for pp in (dense, sparse))
    assert a.exhaustive and b.exhaustive
    np.testing.assert_allclose(a.pairs, b.pairs, atol=1e-12)


def test_hypothesis_probabilities_read_the_pairs_and_the_misses():
    scan = entangled_scan(np.random.default_rng(1), n_clusters=1, cluster_size=3)
    pp = probability_problem(_hypotheses(scan))
    n, m = pp.table.shape
    pairs = np.arange(n * m, dtype=float).reshape(n, m) + 1.0
    miss = -np.arange(1.0, n + 1)
    P = pp.hypothesis_probabilities(pairs, miss)
    for k, h in enumerate(pp.table.hypotheses):
        i, j = pp.table.row[k], pp.table.col[k]
        assert P[k] == (miss[i] if not h else pairs[i, j])


def test_hypotheses_problem_is_the_same_problem_dense_or_sparse_and_ranks_alike():
    scan = entangled_scan(np.random.default_rng(2), n_clusters=1, cluster_size=5)
    hyps = _hypotheses(scan)
    for score in ("linear", "log"):
        (pd_, tr_d, tab_d), (ps, tr_s, tab_s) = (hypotheses_problem(hyps, score, dense=d)
                                                 for d in (True, False))
        assert pd_.dense_view is not None and ps.dense_view is None
        assert tr_d == tr_s and tab_d == tab_s and pd_.n_candidates == ps.n_candidates
        np.testing.assert_array_equal(pd_.to_cost_matrix(), ps.to_cost_matrix())
        for x, y in zip(pd_.miss_costs(), ps.miss_costs()):
            np.testing.assert_array_equal(x, y)
        for (i, j), h in tab_d.items():
            p = float(h.probability)
            c = pd_.to_cost_matrix()[i - 1, j - 1] if j else pd_.miss_costs()[0][i - 1]
            assert c == pytest.approx(-p if score == "linear" else -np.log(p), rel=1e-12)
        a, b = assocopt.kbest(pd_, 40), assocopt.kbest(ps, 40)
        assert a.objectives == pytest.approx(b.objectives, rel=1e-12, abs=1e-12)


def test_the_ranker_gets_a_dense_problem():
    scan = entangled_scan(np.random.default_rng(3), n_clusters=1, cluster_size=4)
    hyps = _hypotheses(scan)
    ranker = AssocoptKBest(Cached(), k=30, probability_score="log")
    ranked = ranker.rank_hypotheses(hyps)
    assert len(ranked) == 30 and ranker.last_ranked.solver == "murty2d"
    every = sorted(-sum(np.log(float(h.probability)) for h in j.values())
                   for j in JPDA.enumerate_JPDA_hypotheses(list(hyps), hyps))
    assert ranker.last_ranked.objectives == pytest.approx(every[:30], rel=1e-9)


def test_bad_hypotheses_are_clear_errors():
    scan = entangled_scan(np.random.default_rng(4), n_clusters=1, cluster_size=2)
    hyps = _hypotheses(scan)
    tr = scan.tracks[0]
    with pytest.raises(ValueError, match="track 0 has two hypotheses for one detection"):
        hypothesis_table({tr: list(hyps[tr]) + [hyps[tr][1]]})
    with pytest.raises(ValueError, match="two hypotheses for a missed detection"):
        hypothesis_table({tr: list(hyps[tr]) + [hyps[tr][0]]})
    dist = DistanceHypothesiser(scan.predictor, scan.updater, measure=Mahalanobis(),
                                missed_distance=3)
    with pytest.raises(TypeError, match="no probability"):
        probability_problem({tr: dist.hypothesise(tr, scan.detections, scan.timestamp)})
    nan = SingleProbabilityHypothesis(hyps[tr][0].prediction, MissedDetection(), 0.5)
    nan.probability = float("nan")
    with pytest.raises(ValueError, match="NaN"):
        probability_problem({tr: [nan]})
    neg = SingleProbabilityHypothesis(hyps[tr][0].prediction, MissedDetection(), 0.5)
    neg.probability = -0.5
    with pytest.raises(ValueError, match=">= 0"):
        probability_problem({tr: [neg]})


# --------------------------------------------------------------------------- JPDA
@pytest.mark.parametrize("seed", range(6))
def test_probabilities_equal_jpda_with_ehm2_on_entangled_scenes(seed):
    rng = np.random.default_rng(100 + seed)
    size = 1 + seed % 5                                 # 1 .. 5 tracks per cluster
    scan = entangled_scan(rng, n_clusters=3, cluster_size=size,
                          spacing=float(rng.uniform(1.0, 3.0)),
                          clutter_rate=float(rng.uniform(1.0, 6.0)))
    cached = Cached()
    cached.table = _hypotheses(scan)
    ref = JPDAwithEHM2(cached).associate(set(scan.tracks), scan.detections, scan.timestamp)
    pp = probability_problem(cached.table)
    P = jpda_mod.association_probabilities(pp)
    _same_posterior(pp.posterior(P), ref)
    ours = AssocoptJPDA(cached).associate(set(scan.tracks), scan.detections, scan.timestamp)
    _same_posterior(ours, ref)
    # entangled clusters: the joint probabilities are not the single-track PDA ones
    pda = np.exp(pp.score - np.repeat(np.logaddexp.reduceat(pp.score, pp.table.offsets[:-1]),
                                      np.diff(pp.table.offsets)))
    assert (np.abs(P - pda).max() > 1e-2) == (size > 1)


def test_equal_to_jpda_brute_force_with_the_hypothesiser_as_given():
    """Unnormalised hypotheses (PDAHypothesiser(normalise=False)), each associator
    calling the hypothesiser itself; Stone Soup's brute-force JPDA as the reference
    too (one cluster: it enumerates the product over all tracks)."""
    scan = entangled_scan(np.random.default_rng(7), n_clusters=1, cluster_size=4,
                          clutter_rate=4.0)
    hyp = scan.hypothesiser(normalise=False)
    args = (set(scan.tracks), scan.detections, scan.timestamp)
    ours = AssocoptJPDA(hyp).associate(*args)

    def table(out):
        return {tr: [(h.measurement if h else None, float(h.probability)) for h in mh]
                for tr, mh in out.items()}

    got = table(ours)
    for ref in (JPDA(hyp).associate(*args), JPDAwithEHM2(hyp).associate(*args)):
        want = table(ref)
        assert set(got) == set(want)
        for tr in want:
            assert [m for m, _ in got[tr]] == [m for m, _ in want[tr]]
            np.testing.assert_allclose([p for _, p in got[tr]], [p for _, p in want[tr]],
                                       rtol=0, atol=1e-9)


def test_edge_cases_no_detections_an_ungated_track_one_track_no_track():
    scan = entangled_scan(np.random.default_rng(8), n_clusters=1, cluster_size=3)
    far = Track([GaussianState(np.array([[5000.0], [1.0], [5000.0], [0.0]]),
                               np.diag([1.0, 0.5, 1.0, 0.5]),
                               timestamp=scan.tracks[0][-1].timestamp)])
    hyp = scan.hypothesiser()
    ours, ref = AssocoptJPDA(hyp), JPDAwithEHM2(hyp)
    t = scan.timestamp
    cases = {"no detections": (set(scan.tracks), set()),
             "a track with no gated detection": (set(scan.tracks) | {far}, scan.detections),
             "a single track": ({scan.tracks[0]}, scan.detections),
             "only the ungated track": ({far}, scan.detections)}
    for name, (tracks, dets) in cases.items():
        cached = Cached()
        cached.table = {tr: hyp.hypothesise(tr, dets, t) for tr in tracks}
        a = AssocoptJPDA(cached).associate(tracks, dets, t)
        _same_posterior(a, JPDAwithEHM2(cached).associate(tracks, dets, t))
        if name == "no detections" or name.startswith("only"):
            assert all(len(mh) == 1 and float(mh[0].probability) == 1.0 for mh in a.values())
    assert len(AssocoptJPDA(hyp).associate(set(scan.tracks) | {far}, scan.detections, t)[
        far]) == 1
    assert ours.associate(set(), scan.detections, t) == {} == ref.associate(
        set(), scan.detections, t)


def test_a_track_without_hypotheses_gets_an_empty_one():
    scan = entangled_scan(np.random.default_rng(9), n_clusters=1, cluster_size=2)
    hyps = _hypotheses(scan)
    extra = Track()
    hyps[extra] = MultipleHypothesis([])
    out = AssocoptJPDA(Cached()).associate_hypotheses(hyps)
    assert len(out[extra]) == 0 and set(out) == set(hyps)


def test_a_cluster_over_the_budget_is_an_error_naming_its_size():
    scan = entangled_scan(np.random.default_rng(10), n_clusters=1, cluster_size=4,
                          spacing=1.0)
    pp = probability_problem(_hypotheses(scan))
    with pytest.raises(assocopt.ProblemTooLargeError, match="cluster of"):
        jpda_mod.association_probabilities(pp, max_nodes=2)


@pytest.mark.parametrize("seed", [0, 1])
def test_same_tracks_as_jpda_with_ehm2_in_the_mixture_tracker(seed):
    """A multi-step scene through Stone Soup's MultiTargetMixtureTracker (PDA updater):
    the same states, step by step, with either associator."""
    from stonesoup.tracker.simple import MultiTargetMixtureTracker

    rng = np.random.default_rng(seed)
    first = entangled_scan(rng, n_clusters=1, cluster_size=4, spacing=2.0)
    mm = first.updater.measurement_model
    transition = first.predictor.transition_model
    steps = 8
    X = np.array([tr[-1].state_vector.ravel() for tr in first.tracks])
    scans = []
    from assocopt.tracking.stonesoup.scenario import scan_detections
    for k in range(1, steps + 1):
        X = X @ transition.matrix(time_interval=timedelta(seconds=1)).T
        seen = rng.random(len(X)) < 0.9
        z = X[seen][:, [0, 2]] + rng.normal(0.0, 0.5, (int(seen.sum()), 2))
        zc = X[:, [0, 2]].mean(axis=0) - 8 + rng.uniform(0, 16, (rng.poisson(3.0), 2))
        t = first.timestamp + timedelta(seconds=k - 1)
        scans.append((t, scan_detections(np.concatenate([z, zc]),
                                         [0] * len(z) + [-1] * len(zc), t, mm)))

    class Feed:
        def __iter__(self):
            return iter(scans)

    class Never:
        def initiate(self, *a, **k):
            return set()

        def delete_tracks(self, tracks):
            return set()

    def run(associator):
        tracker = MultiTargetMixtureTracker(initiator=Never(), deleter=Never(),
                                            detector=Feed(), data_associator=associator,
                                            updater=first.updater)
        tracker._tracks = {Track(list(tr.states)) for tr in first.tracks}
        for _ in tracker:
            pass
        return sorted(tracker.tracks, key=lambda tr: tuple(tr.states[0].state_vector.ravel()))

    hyp = first.hypothesiser()
    ours, ref = run(AssocoptJPDA(hyp)), run(JPDAwithEHM2(hyp))
    assert len(ours) == len(ref) == 4
    updates = 0
    for a, b in zip(ours, ref):
        assert len(a) == len(b) == steps + 1
        for sa, sb in zip(a.states, b.states):
            assert type(sa) is type(sb)
            np.testing.assert_allclose(sa.state_vector, sb.state_vector, rtol=0, atol=1e-9)
            np.testing.assert_allclose(sa.covar, sb.covar, rtol=0, atol=1e-9)
            updates += hasattr(sa, "hypothesis")
    assert updates > 10                            # detections were used


@pytest.mark.parametrize("dense", [True, False])
def test_the_whole_scan_is_one_exact_marginals_call(monkeypatch, dense):
    """One ``marginals(method="exact")`` call on the whole scan (it splits the clusters),
    dense or sparse problem, mapped back to the hypotheses as EHM2 gives them."""
    scan = entangled_scan(np.random.default_rng(11), n_clusters=2, cluster_size=3)
    cached = Cached()
    cached.table = _hypotheses(scan)
    ref = JPDAwithEHM2(cached).associate(set(scan.tracks), scan.detections, scan.timestamp)
    pp = probability_problem(cached.table, dense=dense)
    calls = []

    def spy(problem, method, **kw):
        calls.append(method)
        return assocopt.marginals(problem, method=method, **kw)

    monkeypatch.setattr(jpda_mod, "marginals", spy)
    P = jpda_mod.association_probabilities(pp)
    assert calls == ["exact"]
    _same_posterior(pp.posterior(P), ref)
