"""Quick timing of ``auto`` and ``lagrangian-exact`` on the 120 public 3-AP instances.

Loads the instances as benchmarks/sd_scaling.py does (``ap_instances``), warms up
like its ``warm_up`` (every engine twice on a 4 x 4 x 4 problem, kernels compiled),
then solves each instance with each method in turn (``auto`` first, as there) and
prints the seconds per family and size and the totals; every solve must be proven
optimal at the recorded optimum.  No page, no JSON: for comparing two checkouts
side by side (run it from each, alternately).

    PYTHONPATH=$PWD python benchmarks/ap3_quick.py [METHODS] [--verbose]
"""

from __future__ import annotations

import argparse
import os
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))

from assocopt import AssignmentProblem, solve  # noqa: E402
from sd_scaling import ROOT, ap_instances  # noqa: E402

WARM = ("ortools-cpsat", "highs", "scipy", "auto", "lagrangian-exact", "lagrangian")


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("methods", nargs="?", default="auto,lagrangian-exact")
    ap.add_argument("--ap-dir", default=str(ROOT.parent / "shared" / "ap_instances"))
    ap.add_argument("--verbose", action="store_true", help="one line per instance")
    args = ap.parse_args(argv)
    methods = args.methods.split(",")
    insts = ap_instances(Path(args.ap_dir), False)
    if not insts:
        print(f"no instances in {args.ap_dir}")
        return 1
    small = AssignmentProblem.dense(np.random.default_rng(0).random((4, 4, 4)))
    for m in WARM:
        solve(small, m)
        solve(small, m)
    total = dict.fromkeys(methods, 0.0)
    groups: dict[tuple[str, int, str], float] = {}
    bad = 0
    for inst in insts:
        row = []
        for m in methods:
            t0 = time.perf_counter()
            sol = solve(inst.problem, m)
            dt = time.perf_counter() - t0
            ok = sol.status.value == "optimal" and abs(sol.objective - inst.optimum) < 1e-6
            bad += not ok
            total[m] += dt
            key = (inst.family, inst.size, m)
            groups[key] = groups.get(key, 0.0) + dt
            row.append(f"{m}={dt:.3f}" + ("" if ok else f" WRONG {sol.status.value}"))
        if args.verbose:
            print(inst.name, *row, flush=True)
    for (family, size, m), dt in sorted(groups.items()):
        print(f"{family:15s} n={size:3d} {m:17s} {dt:7.3f} s")
    print("total", {m: round(v, 3) for m, v in total.items()}, f"wrong {bad}",
          f"instances {len(insts)}")
    return 1 if bad else 0


if __name__ == "__main__":
    os.environ.setdefault("ASSOCOPT_JIT", "compiled")     # steady state, as sd_scaling
    raise SystemExit(main())
