"""Benchmark: exact association probabilities (``assocopt.marginals``) beside Stone
Soup's JPDA family and pyehm, on scenes built with Stone Soup's own models.

Scenes (seeded): tracks with a constant-velocity model (``ConstantVelocity(0.05)`` per
axis), linear-Gaussian position measurements (unit variance), predicted 1 s ahead;
each track detected with P_D = 0.9, clutter uniform at ``1e-3`` per unit area over the
cluster's box plus 5 on each side; hypotheses by ``PDAHypothesiser`` (P_D 0.9, its
default gate).  *Entangled clusters*: ``n`` tracks on a square grid 2 apart (n = 3 .. 20).
*Scene*: about 100 tracks in clusters of 1 to 4 (grid, 2 apart), the clusters 100 apart.

The hypotheses are generated once and served from a cache, so every associator times
only its association.  Columns (CPU time of this process, per call, after a warm-up;
calls under 1 s repeated for at least 0.3 s):

* ours (engine): ``marginals(problem, method="exact")`` on the problem built from the
  hypotheses; ours (Stone Soup in and out): the hypotheses converted to the problem,
  the marginals, and a ``MultipleHypothesis`` of ``SingleProbabilityHypothesis`` per
  track built, as a drop-in associator would;
* Stone Soup ``JPDA`` (brute force), ``JPDAwithEHM``, ``JPDAwithEHM2``,
  ``JPDAwithLBP``: their ``associate``; pyehm 2.2 ``JPDAWithEHM2``: its ``associate``, and
  its engine ``EHM2().run(validation, likelihood)`` alone;
* ours kbest (``k`` = 100 per cluster) and lbp (tolerance 1e-10), with the error bound
  kbest certifies and lbp's iterations.

Errors: the largest difference of any track's probability (each measurement and the
miss) from ours exact.  The slow pure-Python associators run only up to a size
(``--caps``).  S-D scans: 3 sensors, each seeing every target of a cluster (grid 2
apart) with P_D 0.9 and unit noise, clutter 1e-3 per unit area; candidate tuples gated
at 4 apart pairwise; ours exact beside enumeration of every hypothesis (small only) and
kbest with its bound.

Usage::

    python benchmarks/marginals.py [--sizes 3,5,8,12,16,20] [--scene 100] [--seed 0]
        [--caps JPDA=5,JPDAwithEHM=12,JPDAwithEHM2=12,pyehm=16] [--out docs/benchmarks-marginals]
    python benchmarks/marginals.py --render

writes ``OUT.json`` and ``OUT.md``.
"""

from __future__ import annotations

import argparse
import datetime
import json
import math
import os
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "benchmarks"))

from stonesoup_assoc import command, machine, write_pages  # noqa: E402

LAMBDA = 1e-3
T0 = datetime.datetime(2024, 1, 1)
T1 = T0 + datetime.timedelta(seconds=1)
CAPS = "JPDA=5,JPDAwithEHM=12,JPDAwithEHM2=12,pyehm=16"
METHODS = ("ours", "ours_ss", "JPDA", "JPDAwithEHM", "JPDAwithEHM2", "JPDAwithLBP",
           "pyehm", "pyehm_engine", "kbest", "lbp")


def _models():
    from stonesoup.hypothesiser.probability import PDAHypothesiser
    from stonesoup.models.measurement.linear import LinearGaussian
    from stonesoup.models.transition.linear import (CombinedLinearGaussianTransitionModel,
                                                    ConstantVelocity)
    from stonesoup.predictor.kalman import KalmanPredictor
    from stonesoup.updater.kalman import KalmanUpdater

    trans = CombinedLinearGaussianTransitionModel([ConstantVelocity(0.05)] * 2)
    meas = LinearGaussian(ndim_state=4, mapping=(0, 2), noise_covar=np.eye(2))
    hyp = PDAHypothesiser(KalmanPredictor(trans), KalmanUpdater(meas),
                          clutter_spatial_density=LAMBDA, prob_detect=0.9)
    return meas, hyp


def _cluster(rng, n: int, origin: tuple[float, float], meas):
    """``n`` tracks on a grid 2 apart at ``origin``, their detections and clutter."""
    from stonesoup.types.detection import Clutter, Detection
    from stonesoup.types.state import GaussianState
    from stonesoup.types.track import Track

    cols = int(math.ceil(math.sqrt(n)))
    tracks, dets = [], []
    for i in range(n):
        x, y = origin[0] + 2.0 * (i % cols), origin[1] + 2.0 * (i // cols)
        tracks.append(Track([GaussianState(np.array([[x], [1.0], [y], [0.0]]),
                                           np.diag([1.0, 0.3, 1.0, 0.3]), timestamp=T0)]))
        if rng.random() < 0.9:
            z = np.array([[x + 1.0], [y]]) + rng.normal(size=(2, 1))
            dets.append(Detection(z, timestamp=T1, measurement_model=meas))
    w, h = 2.0 * cols + 10, 2.0 * ((n - 1) // cols) + 10
    for _ in range(rng.poisson(LAMBDA * w * h)):
        z = np.array([[origin[0] - 5 + rng.random() * w], [origin[1] - 5 + rng.random() * h]])
        dets.append(Clutter(z, timestamp=T1, measurement_model=meas))
    return tracks, dets


class _Cached:
    """A hypothesiser serving precomputed hypotheses (the association alone is timed)."""

    def __init__(self, hyps):
        self.hyps = hyps

    def hypothesise(self, track, detections, timestamp, **kwargs):
        return self.hyps[track]


def problem_of(tracks, dets, hyps):
    """The 2-D problem of JPDA hypotheses: score ``log p`` of each (track, detection)
    and of each miss, a detection left as clutter scores 0 (PDA weights are already
    relative to clutter); ``maximize=True``."""
    from assocopt import AssignmentProblem

    index = {d: j for j, d in enumerate(dets)}
    S = np.full((len(tracks), len(dets)), -np.inf)
    miss = np.full(len(tracks), -np.inf)
    for i, t in enumerate(tracks):
        for h in hyps[t]:
            p = float(h.probability)
            if p <= 0:
                continue
            if h:
                S[i, index[h.measurement]] = math.log(p)
            else:
                miss[i] = math.log(p)
    return AssignmentProblem.two_d(S, miss, 0.0, maximize=True)


def ours_associate(tracks, dets, hyps, method: str = "exact"):
    """Hypotheses in, Stone Soup ``MultipleHypothesis`` per track out (a drop-in's work:
    the probabilities are normalised already, so ``MultipleHypothesis`` is told not to
    normalise them again; a miss keeps its hypothesis's ``MissedDetection``)."""
    from stonesoup.types.hypothesis import SingleProbabilityHypothesis
    from stonesoup.types.multihypothesis import MultipleHypothesis
    from stonesoup.types.numeric import Probability

    from assocopt import marginals

    m = marginals(problem_of(tracks, dets, hyps), method=method)
    index = {d: j for j, d in enumerate(dets)}
    out = {}
    for i, t in enumerate(tracks):
        single = []
        for h in hyps[t]:
            p = m.pairs[i, index[h.measurement]] if h else m.row_miss[i]
            single.append(SingleProbabilityHypothesis(
                h.prediction, h.measurement, measurement_prediction=h.measurement_prediction,
                probability=Probability(float(p))))
        out[t] = MultipleHypothesis(single, False)
    return out


def _matrix(tracks, dets, result) -> np.ndarray:
    """Probabilities of a Stone Soup answer: column 0 the miss, then the detections."""
    index = {d: j for j, d in enumerate(dets)}
    P = np.zeros((len(tracks), len(dets) + 1))
    for i, t in enumerate(tracks):
        for h in result[t]:
            P[i, index[h.measurement] + 1 if h else 0] = float(h.probability)
    return P


def _time(f):
    """``(CPU s per call, result)``: one warm-up call, kept when over 1 s, else
    repeated for at least 0.3 s."""
    t0 = time.process_time()
    out = f()
    first = time.process_time() - t0
    if first > 1.0:
        return first, out
    n, t0 = 0, time.process_time()
    while time.process_time() - t0 < 0.3 or n == 0:
        out = f()
        n += 1
    return (time.process_time() - t0) / n, out


def run_scene(label: str, tracks, dets, hyp, caps: dict) -> dict:
    """Every method on one scene (see the module docstring)."""
    from stonesoup.dataassociator.probability import (JPDA, JPDAwithEHM, JPDAwithEHM2,
                                                      JPDAwithLBP)

    from assocopt import marginals

    H = {t: hyp.hypothesise(t, set(dets), T1) for t in tracks}
    cached = _Cached(H)
    p = problem_of(tracks, dets, H)
    n = len(tracks)
    t_ours, m = _time(lambda: marginals(p, method="exact"))
    ref = np.column_stack([m.row_miss, m.pairs])
    row = {"scene": label, "tracks": n, "detections": len(dets),
           "hypotheses": int(sum(len(H[t]) for t in tracks)), "clusters": m.clusters,
           "largest_cluster": _largest(p), "nodes": m.nodes, "times": {}, "errors": {}}
    row["times"]["ours"] = t_ours
    row["errors"]["ours"] = float(np.abs(ref.sum(axis=1) - 1.0).max())    # rows sum to 1
    t, res = _time(lambda: ours_associate(tracks, dets, H))
    row["times"]["ours_ss"] = t
    row["errors"]["ours_ss"] = float(np.abs(_matrix(tracks, dets, res) - ref).max())
    for name, cls in (("JPDA", JPDA), ("JPDAwithEHM", JPDAwithEHM),
                      ("JPDAwithEHM2", JPDAwithEHM2), ("JPDAwithLBP", JPDAwithLBP),
                      ("pyehm", _pyehm())):
        size = n if name == "JPDA" else row["largest_cluster"]    # JPDA: no clusters
        if cls is None or size > caps.get(name, math.inf):
            continue
        assoc = cls(hypothesiser=cached)
        t, res = _time(lambda: assoc.associate(set(tracks), set(dets), T1))
        row["times"][name] = t
        row["errors"][name] = float(np.abs(_matrix(tracks, dets, res) - ref).max())
    if _pyehm() is not None and "pyehm" in row["times"]:
        from pyehm.core import EHM2

        L = np.column_stack([np.exp(-p.miss_costs()[0]), np.exp(-p.to_cost_matrix())])
        V = (L > 0).astype(int)
        t, A = _time(lambda: EHM2().run(V, L))
        row["times"]["pyehm_engine"] = t
        row["errors"]["pyehm_engine"] = float(np.abs(A - ref).max())
    t, k = _time(lambda: marginals(p, k=100, method="kbest"))
    row["times"]["kbest"] = t
    row["errors"]["kbest"] = float(np.abs(k.candidate - m.candidate).max())
    row["kbest_bound"] = k.error_bound
    t, b = _time(lambda: marginals(p, method="lbp"))
    row["times"]["lbp"] = t
    row["errors"]["lbp"] = float(np.abs(b.candidate - m.candidate).max())
    row["lbp_iterations"] = b.iterations
    row["lbp_residual"] = b.residual
    print(label, {k: f"{v:.4g}" for k, v in row["times"].items()},
          {k: f"{v:.1e}" for k, v in row["errors"].items()}, flush=True)
    return row


def _largest(p) -> int:
    from assocopt.ranking.clusters import clusters

    return max(c.sizes(p)[0] for c in clusters(p))


def _pyehm():
    try:
        from pyehm.plugins.stonesoup import JPDAWithEHM2
    except ImportError:
        return None
    return JPDAWithEHM2


def sd_scene(rng, n: int):
    """3 sensors on ``n`` targets on a grid 2 apart: the gated S-D problem.  Cost of a
    tuple: minus its log-likelihood ratio against clutter (each of its measurements
    ``log(P_D N(z; mean, I) / lambda)``, each sensor it leaves out ``log(1 - P_D)``);
    a singleton (a false alarm) costs 0."""
    from assocopt import AssignmentProblem

    cols = int(math.ceil(math.sqrt(n)))
    truth = np.array([[2.0 * (i % cols), 2.0 * (i // cols)] for i in range(n)])
    box = (truth.min(0) - 5, truth.max(0) + 5)
    Z = []
    for s in range(3):
        seen = truth[rng.random(n) < 0.9]
        seen = seen + rng.normal(size=seen.shape)
        area = float(np.prod(box[1] - box[0]))
        clutter = box[0] + rng.random((rng.poisson(LAMBDA * area), 2)) * (box[1] - box[0])
        Z.append(np.vstack([seen, clutter]))
    grids = np.meshgrid(*[np.arange(len(z) + 1) for z in Z], indexing="ij")
    tup = np.stack([g.ravel() for g in grids], axis=1)
    tup = tup[(tup > 0).any(axis=1)]
    pts = np.stack([np.where(tup[:, s:s + 1] > 0, np.vstack([[0, 0], Z[s]])[tup[:, s]], np.nan)
                    for s in range(3)], axis=1)                       # K x 3 x 2
    ok = np.ones(len(tup), bool)
    for a in range(3):
        for b in range(a + 1, 3):
            d = np.linalg.norm(pts[:, a] - pts[:, b], axis=1)
            ok &= ~(d >= 4.0)                                         # NaN (a dummy) passes
    tup, pts = tup[ok], pts[ok]
    real = tup > 0
    mean = np.nanmean(pts, axis=1)
    r2 = np.nansum((pts - mean[:, None]) ** 2, axis=2)
    llr = np.where(real, np.log(0.9 / LAMBDA) - math.log(2 * math.pi) - r2 / 2,
                   math.log(0.1)).sum(axis=1)
    cost = np.where(real.sum(axis=1) == 1, 0.0, -llr)
    return AssignmentProblem.sparse(tuple(len(z) for z in Z), tup, cost)


def run_sd(n: int, seed: int) -> dict:
    from assocopt import marginals

    p = sd_scene(np.random.default_rng(seed + 1000 * n), n)
    t, m = _time(lambda: marginals(p, method="exact"))
    row = {"targets": n, "sizes": list(p.sizes), "candidates": p.n_candidates,
           "clusters": m.clusters, "nodes": m.nodes, "exact_s": t,
           "coverage_error": float(np.abs(p.coverage_matrix() @ m.candidate - 1).max())}
    from assocopt import ProblemTooLargeError

    try:
        te, e = _time(lambda: marginals(p, method="enumerate"))
        row["enumerate_s"] = te
        row["enumerate_error"] = float(np.abs(e.candidate - m.candidate).max())
        row["hypotheses"] = e.hypotheses
    except ProblemTooLargeError:             # more than 2 million search nodes
        row["hypotheses"] = "> 2M nodes"
    tk, k = _time(lambda: marginals(p, k=100, method="kbest"))
    row.update(kbest_s=tk, kbest_error=float(np.abs(k.candidate - m.candidate).max()),
               kbest_bound=k.error_bound)
    print("sd", n, row, flush=True)
    return row


NAMES = {"ours": "ours (engine)", "ours_ss": "ours (Stone Soup in and out)",
         "JPDA": "Stone Soup JPDA", "JPDAwithEHM": "Stone Soup JPDAwithEHM",
         "JPDAwithEHM2": "Stone Soup JPDAwithEHM2", "JPDAwithLBP": "Stone Soup JPDAwithLBP",
         "pyehm": "pyehm JPDAWithEHM2", "pyehm_engine": "pyehm EHM2 engine",
         "kbest": "ours kbest (k=100)", "lbp": "ours lbp"}


def _ms(v) -> str:
    return "—" if v is None else f"{v * 1e3:.3g}"


def _ratio(a, b) -> str:
    return "—" if a is None or b is None else f"{a / b:.0f}x" if a / b >= 10 else f"{a / b:.1f}x"


def render(result: dict) -> str:
    """The markdown page of a result (tests/test_benchmarks_marginals.py checks it)."""
    m = result["machine"]
    rows = result["scenes"]
    lines = [
        "# Association probabilities: exact marginals beside Stone Soup's JPDA and pyehm", "",
        f"Generated by `{result['command']}` (the script's docstring says what is "
        "measured).  Scenes from Stone Soup's models: constant velocity, linear-Gaussian "
        "position measurements, `PDAHypothesiser` with P_D = 0.9 and clutter 1e-3 per "
        "unit area; *cluster n*: n tracks on a grid 2 apart (truly entangled); "
        f"*scene*: {result['scene_tracks']} tracks in small clusters far apart.  Every "
        "associator gets the same cached hypotheses; times are CPU milliseconds of "
        "this process per call (one warm-up call first; a call over 1 s is timed once), "
        "measured side by side in one run.  Errors: the largest difference of any "
        "track's probability from ours exact.", "",
        f"Machine: {m['cpu_count']} logical cores, {m['platform']}; Python {m['python']}, "
        f"numpy {m['numpy']}, stonesoup {m['stonesoup']}, pyehm {m['pyehm']}; load "
        f"average {m['load_start']} at start, {m['load_end']} at end (a shared machine: "
        "CPU times, ratios side by side).", "",
        "## Time (CPU ms per call)", "",
        "| scene | tracks | detections | largest cluster | net nodes | "
        + " | ".join(NAMES[k] for k in METHODS) + " |", "|" + "---|" * (5 + len(METHODS))]
    for r in rows:
        t = r["times"]
        lines.append(f"| {r['scene']} | {r['tracks']} | {r['detections']} | "
                     f"{r['largest_cluster']} | {r['nodes']} | "
                     + " | ".join(_ms(t.get(k)) for k in METHODS) + " |")
    big = max((r for r in rows if r["scene"].startswith("cluster")), key=lambda r: r["tracks"])
    lines += ["", f"The largest entangled cluster ({big['tracks']} tracks, "
              f"{big['detections']} detections) is exact in {_ms(big['times']['ours'])} ms "
              f"(engine), {_ms(big['times']['ours_ss'])} ms with Stone Soup's hypotheses in "
              "and out.", "",
              "In and out, both sides build the same Stone Soup hypothesis objects (a "
              "`SingleProbabilityHypothesis` per hypothesis, a `MultipleHypothesis` per "
              "track), which is most of our time on the small clusters and the scene; the "
              "engines alone are compared in the last column of the speed-ups.", "",
              "— : not run (the pure-Python associators above the sizes "
              f"`{result['caps']}`; Stone Soup's `JPDA` enumerates the whole scene at once).",
              "", "## Speed-ups", "",
              "| scene | JPDAwithEHM2 / ours (in and out) | pyehm JPDAWithEHM2 / ours (in and "
              "out) | pyehm engine / ours engine |", "|---|---|---|---|"]
    for r in rows:
        t = r["times"]
        lines.append(f"| {r['scene']} | {_ratio(t.get('JPDAwithEHM2'), t['ours_ss'])} | "
                     f"{_ratio(t.get('pyehm'), t['ours_ss'])} | "
                     f"{_ratio(t.get('pyehm_engine'), t['ours'])} |")
    lines += ["", "## Errors (largest |P - P_exact|)", "",
              "| scene | " + " | ".join(NAMES[k] for k in METHODS[1:]) +
              " | kbest certified bound | lbp iterations |", "|" + "---|" * (len(METHODS) + 2)]
    for r in rows:
        e = r["errors"]
        cells = ["—" if e.get(k) is None else f"{e[k]:.1e}" for k in METHODS[1:]]
        lines.append(f"| {r['scene']} | " + " | ".join(cells) +
                     f" | {r['kbest_bound']:.1e} | {r['lbp_iterations']} |")
    lines += ["", "The bound of kbest is certified (an upper bound on its error, from the "
              "weight it leaves out: the k-th hypothesis's weight times a count bound of "
              "the hypotheses not summed, or, in 2-D, the product of the rows' option "
              "sums less what was summed; the smaller); it is loose on entangled "
              "clusters, where k = 100 leaves most of the weight out.  lbp has none; "
              "ours and Stone Soup's `JPDAwithLBP` agree, errors and all.", "",
              "Cold start: the exact engine's kernels compile once per machine (numba's "
              "disk cache); the times above are warm.", "",
              "## Multi-sensor (S-D) scans, 3 sensors", "",
              "Every target of a cluster (grid 2 apart) seen by each sensor with P_D 0.9, "
              "unit noise, clutter 1e-3 per unit area; candidate tuples within 4 of each "
              "other pairwise; cost: minus the tuple's log-likelihood ratio against "
              "clutter.  Exact: per cluster by the hypothesis net; enumeration: every "
              "hypothesis one by one (small only).", "",
              "| targets | measurements per sensor | candidates | clusters | net nodes | "
              "exact ms | enumeration ms | hypotheses | exact vs enumeration | "
              "kbest ms | kbest error | kbest bound |", "|" + "---|" * 12]
    for r in result["sd"]:
        lines.append(
            f"| {r['targets']} | {' / '.join(map(str, r['sizes']))} | {r['candidates']} | "
            f"{r['clusters']} | {r['nodes']} | {_ms(r['exact_s'])} | "
            f"{_ms(r.get('enumerate_s'))} | {r.get('hypotheses', '—')} | "
            + (f"{r['enumerate_error']:.1e}" if "enumerate_error" in r else "—")
            + f" | {_ms(r['kbest_s'])} | {r['kbest_error']:.1e} | {r['kbest_bound']:.1e} |")
    return "\n".join(lines) + "\n"


def main(argv=None) -> dict:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--sizes", default="3,5,8,12,16,20")
    ap.add_argument("--scene", type=int, default=100, help="tracks of the many-cluster scene")
    ap.add_argument("--sd", default="3,4,6,9,12", help="S-D scans: targets")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--caps", default=CAPS)
    ap.add_argument("--out", default=str(ROOT / "docs" / "benchmarks-marginals"))
    ap.add_argument("--render", action="store_true", help="only redraw OUT.md from OUT.json")
    args = ap.parse_args(argv)
    out = Path(args.out)
    if args.render:
        out.with_suffix(".md").write_text(render(json.loads(out.with_suffix(".json").read_text())))
        return {}
    import stonesoup

    caps = {k: int(v) for k, v in (c.split("=") for c in args.caps.split(","))}
    meas, hyp = _models()
    load_start = [round(v, 2) for v in os.getloadavg()]
    scenes = []
    for n in (int(v) for v in args.sizes.split(",")):
        rng = np.random.default_rng(args.seed + n)
        tracks, dets = _cluster(rng, n, (0.0, 0.0), meas)
        scenes.append(run_scene(f"cluster {n}", tracks, dets, hyp, caps))
    rng = np.random.default_rng(args.seed + 7)
    tracks, dets, i = [], [], 0
    while len(tracks) < args.scene:
        k = int(min(rng.integers(1, 5), args.scene - len(tracks)))
        t, d = _cluster(rng, k, (100.0 * (i % 10), 100.0 * (i // 10)), meas)
        tracks += t
        dets += d
        i += 1
    scenes.append(run_scene("scene", tracks, dets, hyp, caps))
    sd = [run_sd(int(n), args.seed) for n in args.sd.split(",") if n]
    try:
        import pyehm
        pyehm_version = getattr(pyehm, "__version__", "2.2")
    except ImportError:
        pyehm_version = "not installed"
    result = {"command": command("python benchmarks/marginals.py", argv), "scenes": scenes,
              "sd": sd, "caps": args.caps, "seed": args.seed, "scene_tracks": args.scene,
              "machine": machine(load_start, stonesoup=stonesoup.__version__,
                                 pyehm=pyehm_version)}
    write_pages(out, result, render)
    return result


if __name__ == "__main__":
    # steady-state speed: the kernels compiled in the warm-up (by default a small
    # problem runs them as plain Python for its first seconds: first_use.py)
    os.environ.setdefault("ASSOCOPT_JIT", "compiled")
    main()
