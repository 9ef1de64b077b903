"""What a call costs when it is the only one: a one-shot CLI solve, and many small
problems in one call.

    python benchmarks/one_shot.py               # writes docs/benchmarks-one-shot.{md,json}
    python benchmarks/one_shot.py --rounds 3 --no-write

1. **One-shot CLI solve.**  ``python -m assocopt solve NAME`` of every stored instance
   (a fresh interpreter each, as a user runs it) against the same command with
   ``--solver highs``, the two run in turn, ``--rounds`` pairs: the median wall time of
   each and the median of the pairwise ratios (default path / highs).  The default
   path's ``--json`` record says which back end answered and its ``times`` (import,
   build, solve, compile / cache load).
2. **Loop against batch.**  ``--problems`` small S-D problems (dense 3x4x3, and gated
   3-sensor scans of 3 targets with dummies), each solved by a Python loop of
   ``assocopt.solve`` and by one ``assocopt.solve_many``, side by side in this
   process: CPU seconds (``time.process_time``, robust on loaded cores) per problem,
   the median of ``--rounds``, and the ratio; the answers are compared.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import statistics
import subprocess
import sys
import time
from pathlib import Path
from typing import Any

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

PAGE = ROOT / "docs" / "benchmarks-one-shot.md"
DATA = ROOT / "docs" / "benchmarks-one-shot.json"
INSTANCES = ("example-sd", "example-3d", "sparse-4d-5x6x4x5", "sd-bearing-3s",
             "axial-4d-4x4x4x4", "planted-3d-8", "grundel-ap3.10.1", "example-2d-miss",
             "rect-2d-5x8")


def _cli(args: list[str]) -> tuple[float, float, dict[str, Any]]:
    """``(wall, cpu, record)`` of one ``assocopt solve ... --json`` process (cpu: its
    user + system seconds, as the system accounts the reaped child)."""
    import resource

    env = dict(os.environ, PYTHONPATH=str(ROOT))
    r0 = resource.getrusage(resource.RUSAGE_CHILDREN)
    t = time.perf_counter()
    out = subprocess.run([sys.executable, "-m", "assocopt", "solve", *args, "--json"],
                         capture_output=True, text=True, env=env, cwd=ROOT, check=True)
    wall = time.perf_counter() - t
    r1 = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = (r1.ru_utime - r0.ru_utime) + (r1.ru_stime - r0.ru_stime)
    return wall, cpu, json.loads(out.stdout)


def one_shot(rounds: int) -> list[dict[str, Any]]:
    rows = []
    for name in INSTANCES:
        _cli([name]), _cli([name, "--solver", "highs"])      # numba's cache, disk cache
        auto, highs, ratio, cpu_a, cpu_h, cpu_ratio = [], [], [], [], [], []
        rec: dict[str, Any] = {}
        for _ in range(rounds):
            a, ca, rec = _cli([name])
            h, ch, hrec = _cli([name, "--solver", "highs"])
            auto.append(a)
            highs.append(h)
            ratio.append(a / h)
            cpu_a.append(ca)
            cpu_h.append(ch)
            cpu_ratio.append(ca / ch)
        assert abs(rec["objective"] - hrec["objective"]) <= 1e-9 * max(1, abs(rec["objective"]))
        rows.append({"instance": name, "sizes": rec["sizes"],
                     "candidates": None, "solver": rec["solver"],
                     "auto_s": round(statistics.median(auto), 3),
                     "highs_s": round(statistics.median(highs), 3),
                     "ratio": round(statistics.median(ratio), 3),
                     "auto_cpu_s": round(statistics.median(cpu_a), 3),
                     "highs_cpu_s": round(statistics.median(cpu_h), 3),
                     "cpu_ratio": round(statistics.median(cpu_ratio), 3),
                     "times": {k: round(v, 4) for k, v in rec["times"].items()}})
        print(rows[-1], flush=True)
    from assocopt.io import read_instance
    for r in rows:
        r["candidates"] = read_instance(ROOT / "instances" / f"{r['instance']}.json"
                                        ).n_candidates
    return rows


def _families(n: int) -> dict[str, list[Any]]:
    from assocopt import AssignmentProblem
    from assocopt.testing import random_problem

    rng = np.random.default_rng(34)
    return {"dense 3x4x3": [AssignmentProblem.dense(rng.random((3, 4, 3)))
                            for _ in range(n)],
            "S-D with dummies, 3 x 3 x 3": [random_problem(rng, "sd", (3, 3, 3))
                                            for _ in range(n)]}


def loop_vs_batch(n: int, rounds: int) -> list[dict[str, Any]]:
    from assocopt import solve, solve_many

    rows = []
    for label, ps in _families(n).items():
        solve_many(ps[:4]), [solve(p) for p in ps[:4]]       # kernels loaded beforehand
        loop, batch = [], []
        for _ in range(rounds):
            t = time.process_time()
            a = [solve(p) for p in ps]
            t1 = time.process_time()
            b = solve_many(ps)
            t2 = time.process_time()
            loop.append(t1 - t)
            batch.append(t2 - t1)
        same = all(x.status is y.status and abs(x.objective - y.objective) <= 1e-9
                   for x, y in zip(a, b))
        rows.append({"family": label, "problems": n,
                     "loop_us": round(1e6 * statistics.median(loop) / n, 1),
                     "batch_us": round(1e6 * statistics.median(batch) / n, 1),
                     "ratio": round(statistics.median(loop) / statistics.median(batch), 2),
                     "same_answers": same,
                     "batched": sum("batch" in s.info for s in b)})
        print(rows[-1], flush=True)
    return rows


def measure(rounds: int, problems: int) -> dict[str, Any]:
    load0 = os.getloadavg()
    shot = one_shot(rounds)
    load1 = os.getloadavg()
    batch = loop_vs_batch(problems, rounds)
    load2 = os.getloadavg()
    return {"rounds": rounds, "cpus": os.cpu_count(), "python": platform.python_version(),
            "load": [round(x[0], 2) for x in (load0, load1, load2)],
            "one_shot": shot, "batch": batch,
            "command": "python benchmarks/one_shot.py"}


def render(js: dict[str, Any]) -> str:
    """The generated part of docs/benchmarks-one-shot.md."""
    l0, l1, l2 = js["load"]
    lines = [f"{js['cpus']} cores, Python {js['python']}, {js['rounds']} rounds; load "
             f"average {l0} at the start, {l1} after the CLI runs, {l2} at the end.", "",
             "One-shot `assocopt solve NAME` (a fresh process each; median wall and CPU "
             "seconds of the whole command, and the medians of the pairs' ratios):", "",
             "| instance | candidates | default path: back end | default wall / CPU (s) | "
             "`--solver highs` wall / CPU (s) | ratio wall / CPU | default path's "
             "times (s) |", "|---|---|---|---|---|---|---|"]
    for r in js["one_shot"]:
        times = ", ".join(f"{k.replace('_', ' ')} {v:.3g}" for k, v in r["times"].items())
        lines.append(f"| `{r['instance']}` | {r['candidates']} | `{r['solver']}` | "
                     f"{r['auto_s']:.2f} / {r['auto_cpu_s']:.2f} | {r['highs_s']:.2f} / "
                     f"{r['highs_cpu_s']:.2f} | {r['ratio']:.2f} / {r['cpu_ratio']:.2f} | "
                     f"{times} |")
    lines += ["", "Many small S-D problems: a loop of `solve` against one `solve_many` "
              "(CPU microseconds per problem, median of the rounds):", "",
              "| problems | how many | loop of `solve` (us) | `solve_many` (us) | "
              "speed-up | batched | same answers |", "|---|---|---|---|---|---|---|"]
    for r in js["batch"]:
        lines.append(f"| {r['family']} | {r['problems']} | {r['loop_us']:.1f} | "
                     f"{r['batch_us']:.1f} | {r['ratio']:.2f}x | {r['batched']} | "
                     f"{'yes' if r['same_answers'] else '**no**'} |")
    return "\n".join(lines)


def summary_sentence(js: dict[str, Any]) -> str:
    """The README's sentence on these figures."""
    worst = max(js["one_shot"], key=lambda r: r["ratio"])
    worst_cpu = max(js["one_shot"], key=lambda r: r["cpu_ratio"])
    low = min(r["ratio"] for r in js["batch"])
    return (f"a one-shot `assocopt solve` of a stored instance takes at most "
            f"{worst['ratio']:.2f}x the wall time (`{worst['instance']}`) and "
            f"{worst_cpu['cpu_ratio']:.2f}x the CPU time (`{worst_cpu['instance']}`) of "
            f"the same command with `--solver highs`, and `solve_many` is {low:.1f}x or more faster than "
            f"a loop of `solve` on thousands of small S-D problems "
            f"([docs/benchmarks-one-shot.md](docs/benchmarks-one-shot.md))")


def write_page(js: dict[str, Any]) -> None:
    text = PAGE.read_text()
    head, rest = text.split("<!-- one-shot:begin -->")
    _, tail = rest.split("<!-- one-shot:end -->")
    PAGE.write_text(f"{head}<!-- one-shot:begin -->\n{render(js)}\n<!-- one-shot:end -->"
                    f"{tail}")


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--rounds", type=int, default=5)
    ap.add_argument("--problems", type=int, default=3000)
    ap.add_argument("--no-write", action="store_true")
    args = ap.parse_args(argv)
    js = measure(args.rounds, args.problems)
    print(render(js))
    if not args.no_write:
        DATA.write_text(json.dumps(js, indent=1) + "\n")
        write_page(js)
    return 0


if __name__ == "__main__":
    sys.exit(main())
