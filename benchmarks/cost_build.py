"""Benchmark: building paper 002's S-D cost tensor (localisation + costs), M targets x 3 sensors.

Target (issue): M = 20, 3 sensors, P_D = 1 -> 8000 candidate tuples, under 20 ms per
cost tensor.  The peer is the straightforward implementation: one small LS solve and
one divergence per tuple in a Python loop (run on a subset and scaled), so the ratio
shows what the batched/gathered formulation buys.

Usage::

    python benchmarks/cost_build.py [--M 20] [--repeat 20] [--json out.json]

Prints the median time of: candidate enumeration + localisation of all tuples
(``tuple_geometry``), each cost alone (geometry included), all seven costs sharing
one geometry, and the per-tuple loop peer.
"""

from __future__ import annotations

import argparse
import json
import platform
import statistics
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from assocopt.tracking.costs import COSTS, build_costs, tuple_geometry  # noqa: E402
from assocopt.tracking.localisation import localise, pseudo_measurements, wrap_angle  # noqa: E402
from assocopt.tracking.scenarios.lu2013 import Lu2013  # noqa: E402


def _median_ms(fn, repeat: int) -> float:
    fn()                                    # warm-up
    ts = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        fn()
        ts.append(time.perf_counter() - t0)
    return 1e3 * statistics.median(ts)


def _per_tuple_peer(scan, tuples) -> np.ndarray:
    """One tuple at a time: LS (14)-(15), pseudo-measurements (22)-(23), cost (7)."""
    out = np.empty(len(tuples))
    for k, t in enumerate(tuples):
        m = np.stack([scan.meas[s][t[s] - 1] for s in range(3)])[None]
        R = np.stack([scan.R[s][t[s] - 1] for s in range(3)])[None]
        loc = localise(m, scan.sensors, R)
        pm = pseudo_measurements(loc.x, loc.P, scan.sensors)
        d = m[0] - pm.mean[0]
        d[:, 1] = wrap_angle(d[:, 1])
        out[k] = 0.5 * sum(d[s] @ np.linalg.solve(R[0, s], d[s]) for s in range(3))
    return out


def main(argv=None) -> dict:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--M", type=int, default=20)
    ap.add_argument("--repeat", type=int, default=20)
    ap.add_argument("--peer-tuples", type=int, default=300,
                    help="tuples timed in the per-tuple loop (scaled to all)")
    ap.add_argument("--json", type=Path)
    args = ap.parse_args(argv)

    scan, _ = Lu2013(n_targets=args.M, d=1.0).simulate(np.random.default_rng(0))
    K = int(np.prod(scan.sizes))
    res = {"M": args.M, "tuples": K, "python": platform.python_version(),
           "numpy": np.__version__, "machine": platform.machine(), "ms": {}}
    res["ms"]["geometry (enumerate + localise + pseudo-measurements)"] = _median_ms(
        lambda: tuple_geometry(scan), args.repeat)
    for m in COSTS:
        res["ms"][f"cost {m} (geometry included)"] = _median_ms(
            lambda m=m: build_costs(scan, [m]), args.repeat)
    res["ms"]["all 7 costs, one geometry"] = _median_ms(lambda: build_costs(scan), args.repeat)
    g = tuple_geometry(scan)
    sub = g.tuples[:args.peer_tuples]
    t0 = time.perf_counter()
    peer = _per_tuple_peer(scan, sub)
    per_tuple = (time.perf_counter() - t0) / len(sub)
    res["ms"]["peer: per-tuple loop, pattipati (scaled to all tuples)"] = 1e3 * per_tuple * K
    fast = build_costs(scan, ["pattipati"])["pattipati"].data[:len(sub)]
    res["peer_max_abs_diff"] = float(np.max(np.abs(fast - peer)))
    res["speedup_vs_peer"] = (res["ms"]["peer: per-tuple loop, pattipati (scaled to all tuples)"]
                              / res["ms"]["cost pattipati (geometry included)"])
    width = max(map(len, res["ms"]))
    print(f"M = {args.M}: {K} tuples, median of {args.repeat}")
    for k, v in res["ms"].items():
        print(f"  {k:<{width}}  {v:9.2f} ms")
    print(f"  speed-up of the batched builder over the per-tuple loop: "
          f"{res['speedup_vs_peer']:.0f}x (max |diff| {res['peer_max_abs_diff']:.1e})")
    if args.json:
        args.json.write_text(json.dumps(res, indent=1))
    return res


if __name__ == "__main__":
    main()
