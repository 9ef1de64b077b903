"""Benchmark: assocopt's Stone Soup associator beside Stone Soup's GNNWith2DAssignment.

Both associators get the same hypotheses at every step of a constant-velocity
scenario with clutter (targets spread so that each gate holds a few detections), and
the time of their ``associate`` call is measured: hypothesis generation is done once
per step beforehand and served from a cache, because Stone Soup's
``DistanceHypothesiser`` would evaluate every track-detection pair in Python
(10^6 pairs at 1000 targets) and dominate both.  The cached hypotheses are the ones
``DistanceHypothesiser(measure=Mahalanobis(), missed_distance=3)`` produces: Stone
Soup's own predictions, measurement predictions and Mahalanobis distances, for the
pairs that a KD-tree gate finds within distance 3.  The associations of the two
associators are compared at every step.

Usage::

    python benchmarks/stonesoup_assoc.py [--sizes 10,100,1000] [--steps 5] [--repeat 3] [--seed 0]
        [--out docs/benchmarks-stonesoup]

writes ``OUT.json`` and ``OUT.md``.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import statistics
import sys
import time
from datetime import datetime, timedelta
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from assocopt.tracking.gating import gate  # noqa: E402
from assocopt.tracking.scenarios.simulate import CVScenario  # noqa: E402

MISSED_DISTANCE = 3.0


def scenario(n: int, steps: int) -> CVScenario:
    """n targets at a constant density (400 area units each), clutter n/2 per scan."""
    half = 10.0 * np.sqrt(n)
    return CVScenario(n_targets=n, n_steps=steps, clutter_rate=0.5 * n, pd=0.9,
                      region=((-half, half), (-half, half)))


def _stonesoup_setup(sc: CVScenario):
    from stonesoup.models.measurement.linear import LinearGaussian
    from stonesoup.models.transition.linear import (CombinedLinearGaussianTransitionModel,
                                                    ConstantVelocity)
    from stonesoup.predictor.kalman import KalmanPredictor
    from stonesoup.updater.kalman import KalmanUpdater

    transition = CombinedLinearGaussianTransitionModel(
        [ConstantVelocity(sc.q), ConstantVelocity(sc.q)])
    mm = LinearGaussian(ndim_state=4, mapping=(0, 2), noise_covar=sc.R)
    return KalmanPredictor(transition), KalmanUpdater(mm), mm


def _hypotheses(tracks, dets, t, predictor, updater, mm):
    """What DistanceHypothesiser(Mahalanobis, missed_distance=3) returns, gated by a KD-tree."""
    from stonesoup.measures import Mahalanobis
    from stonesoup.types.detection import MissedDetection
    from stonesoup.types.hypothesis import SingleDistanceHypothesis
    from stonesoup.types.multihypothesis import MultipleHypothesis

    measure = Mahalanobis()
    preds = [predictor.predict(tr, timestamp=t) for tr in tracks]
    mpreds = [updater.predict_measurement(p, mm) for p in preds]
    z_pred = np.array([m.state_vector.ravel() for m in mpreds], dtype=float)
    S = np.array([m.covar for m in mpreds], dtype=float)
    dets = list(dets)
    z = np.array([d.state_vector.ravel() for d in dets], dtype=float).reshape(-1, 2)
    g = gate(z_pred, S, z, threshold=MISSED_DISTANCE ** 2 * (1 + 1e-6))
    per_track = [[SingleDistanceHypothesis(p, MissedDetection(timestamp=t), MISSED_DISTANCE)]
                 for p in preds]
    for i, j in zip(g.rows.tolist(), g.cols.tolist()):
        d = measure(mpreds[i], dets[j])
        if d < MISSED_DISTANCE:
            per_track[i].append(SingleDistanceHypothesis(preds[i], dets[j], d, mpreds[i]))
    return {tr: MultipleHypothesis(sorted(h, reverse=True))
            for tr, h in zip(tracks, per_track)}


def _best_of(call, repeat: int):
    """``(result, best wall-clock seconds of repeat calls)`` (the machine is shared)."""
    best = float("inf")
    for _ in range(repeat):
        t0 = time.perf_counter()
        out = call()
        best = min(best, time.perf_counter() - t0)
    return out, best


def run_size(n: int, steps: int, seed: int, repeat: int = 3) -> dict:
    from stonesoup.dataassociator.neighbour import GNNWith2DAssignment
    from stonesoup.hypothesiser import Hypothesiser
    from stonesoup.types.detection import Clutter, Detection
    from stonesoup.types.state import GaussianState
    from stonesoup.types.track import Track

    from assocopt.tracking.stonesoup import AssocoptGNN

    class Cached(Hypothesiser):
        """Serves the hypotheses computed for this step."""

        def hypothesise(self, track, detections, timestamp, **kwargs):
            return self.table[track]

    sc = scenario(n, steps)
    out = sc.simulate(np.random.default_rng(seed))
    predictor, updater, mm = _stonesoup_setup(sc)
    cached = Cached()
    ours = AssocoptGNN(cached, solver="auto")
    ref = GNNWith2DAssignment(cached)
    start = datetime(2026, 1, 1)
    tracks = [Track([GaussianState(x[:, None], np.diag([1.0, 0.5, 1.0, 0.5]),
                                   timestamp=start)]) for x in out.truth[0]]
    t_ours, t_ref, same, n_hyp = [], [], [], []
    for k, (zs, lab) in enumerate(zip(out.meas, out.labels), start=1):
        t = start + timedelta(seconds=k * sc.dt)
        dets = {(Clutter if lab[m] < 0 else Detection)(zs[m][:, None], timestamp=t,
                                                        measurement_model=mm)
                for m in range(len(zs))}
        cached.table = _hypotheses(tracks, dets, t, predictor, updater, mm)
        n_hyp.append(sum(len(h) for h in cached.table.values()))
        a, dt = _best_of(lambda: ours.associate(set(tracks), dets, t), repeat)
        t_ours.append(dt)
        b, dt = _best_of(lambda: ref.associate(set(tracks), dets, t), repeat)
        t_ref.append(dt)
        same.append({tr: h.measurement for tr, h in a.items()} ==
                    {tr: h.measurement for tr, h in b.items()})
        for tr, h in a.items():
            tr.append(updater.update(h) if h else h.prediction)
    return {"targets": n, "steps": steps, "detections_per_step": float(np.mean(
                [len(z) for z in out.meas])),
            "hypotheses_per_step": float(np.mean(n_hyp)),
            "assocopt_s": statistics.median(t_ours), "stonesoup_s": statistics.median(t_ref),
            "ratio": statistics.median(t_ours) / statistics.median(t_ref),
            "same_associations": all(same)}


def render(result: dict) -> str:
    """The markdown page of a result (tests/test_stonesoup_benchmark.py checks it)."""
    m = result["machine"]
    lines = [
        "# assocopt inside Stone Soup: time per association step",
        "",
        f"Generated by `{result['command']}`.  Median over the steps of the best of "
        f"{result['repeat']} wall-clock times of one `associate` call, both associators given the same cached hypotheses "
        "(those of `DistanceHypothesiser(measure=Mahalanobis(), missed_distance=3)`; "
        "see the script's docstring for why generation is cached).  `AssocoptGNN` "
        "builds the sparse 2-D problem of the hypotheses and solves it with "
        "`solver=\"auto\"`; `GNNWith2DAssignment` fills a dense tracks x (detections "
        "+ tracks) matrix and calls `scipy.optimize.linear_sum_assignment`.  "
        "Targets at constant density (400 area units each), P_D = 0.9, clutter n/2 "
        "per scan.",
        "",
        f"Machine: {m['cpu_count']} logical cores, {m['platform']}; Python {m['python']}, "
        f"numpy {m['numpy']}, scipy {m['scipy']}, stonesoup {m['stonesoup']}; load "
        f"average {m['load_start']} at start, {m['load_end']} at end (the cores are "
        "shared, so small timings are noisy).",
        "",
        "| targets | detections / step | hypotheses / step | AssocoptGNN s | "
        "GNNWith2DAssignment s | ratio | same associations at every step |",
        "|---|---|---|---|---|---|---|",
    ]
    for r in result["rows"]:
        lines.append(f"| {r['targets']} | {r['detections_per_step']:.1f} | "
                     f"{r['hypotheses_per_step']:.1f} | {r['assocopt_s']:.4f} | "
                     f"{r['stonesoup_s']:.4f} | {r['ratio']:.3f} | "
                     f"{'yes' if r['same_associations'] else 'NO'} |")
    lines += ["", "ratio = AssocoptGNN / GNNWith2DAssignment (below 1: assocopt is faster).",
              ""]
    return "\n".join(lines)


def command(script: str, argv) -> str:
    """The command line a page records: ``script`` and its arguments, ``--out`` (and
    its value) left out."""
    given = list(argv if argv is not None else sys.argv[1:])
    extra = [a for i, a in enumerate(given) if not a.startswith("--out")
             and not (i and given[i - 1] == "--out")]
    return " ".join([script] + extra)


def machine(load_start: list, **versions: str) -> dict:
    """The machine block of a result: cores, platform, the load average at start and
    now, Python, numpy and the given package versions."""
    return {"cpu_count": os.cpu_count(), "platform": platform.platform(),
            "load_start": load_start, "load_end": [round(v, 2) for v in os.getloadavg()],
            "python": platform.python_version(), "numpy": np.__version__, **versions}


def write_pages(out: Path, result: dict, render) -> None:
    """``OUT.json`` (the result) and ``OUT.md`` (``render(result)``), printed too."""
    out.with_suffix(".json").write_text(json.dumps(result, indent=1) + "\n")
    out.with_suffix(".md").write_text(render(result))
    print(render(result))


def main(argv=None) -> dict:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--sizes", default="10,100,1000")
    ap.add_argument("--steps", type=int, default=5)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--out", default=str(ROOT / "docs" / "benchmarks-stonesoup"))
    args = ap.parse_args(argv)
    import scipy
    import stonesoup

    load_start = [round(v, 2) for v in os.getloadavg()]
    rows = [run_size(int(n), args.steps, args.seed, args.repeat)
            for n in args.sizes.split(",")]
    result = {"command": command("python benchmarks/stonesoup_assoc.py", argv),
              "rows": rows, "repeat": args.repeat,
              "machine": machine(load_start, scipy=scipy.__version__,
                                 stonesoup=stonesoup.__version__)}
    write_pages(Path(args.out), result, render)
    return result


if __name__ == "__main__":
    # steady-state speed: the kernels compiled in the warm-up (by default a small
    # problem runs them as plain Python for its first seconds: first_use.py)
    os.environ.setdefault("ASSOCOPT_JIT", "compiled")
    main()
