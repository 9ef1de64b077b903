"""Do time limits hold?  Every back end that advertises a limit, on Grundel n = 50,
with every core kept busy by spinning processes.

    python benchmarks/time_limits.py                  # writes docs/benchmarks-limits.{md,json}
    python benchmarks/time_limits.py --limits 1 --no-write

For each back end and limit: the wall time of ``solve(problem, name, time_limit=L)``
(building the model included; each back end's package imported beforehand, as in a
program that already uses it), its overshoot past ``L`` and whether it is within the
tolerance max(1 s, 10 % of L).  HiGHS, scipy, cvxpy and OR-tools run in a warm worker
process under a limit (``isolate``, :mod:`assocopt.solvers.milp.limited`); they are also
run in this process (``isolate=False``) for comparison.  The instance is ``ap3.50.1``
from ``../shared/ap_instances`` (the public Grundel set), or, without it, the tests'
hard50 (dense 3-D n = 50, costs 1000..2000, seed 5).

Before the spinning processes start, the cost of a generous limit (600 s) is measured
for every back end with a limit on a small problem (3x3x3, or 3x3 for the 2-D ones):
``--rounds`` pairs of calls with and without the limit, side by side, and the median
of the differences; for the worker back ends also the first call under a limit (the
worker's start: an interpreter and the solver's import, best and median over
``--rounds`` fresh workers).
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

from assocopt import AssignmentProblem, solve  # noqa: E402
from assocopt.solvers import registered  # noqa: E402

PAGE = ROOT / "docs" / "benchmarks-limits.md"
DATA = ROOT / "docs" / "benchmarks-limits.json"
GRUNDEL = ROOT.parent / "shared" / "ap_instances" / "grundel_ap3" / "ap3.50.1.txt"
ISOLATING = ("highs", "scipy", "cvxpy", "ortools-cpsat", "ortools-mip")


def tolerance(limit: float) -> float:
    """How far past its limit a run may end: max(1 s, 10 %)."""
    return max(1.0, 0.1 * limit)


def instance(path: Path = GRUNDEL) -> tuple[str, AssignmentProblem]:
    if path.is_file():
        from assocopt.io import read_instance
        return f"Grundel {path.stem}", read_instance(path)
    from assocopt.workflow.generate import generate_dense
    return "hard50 (dense 3-D n = 50, seed 5)", generate_dense(
        np.random.default_rng(5), (50, 50, 50), low=1000, high=2000)


def busy(n: int) -> list[subprocess.Popen]:
    """``n`` processes spinning on a core each (ended by :func:`stop`, or when this
    process dies: they spin while their parent is this one)."""
    code = f"import os\nwhile os.getppid() == {os.getpid()}: pass"
    return [subprocess.Popen([sys.executable, "-c", code]) for _ in range(n)]


def stop(procs: list[subprocess.Popen]) -> None:
    for p in procs:
        p.kill()
        p.wait()


def run_one(problem: AssignmentProblem, name: str, limit: float,
            isolate: bool | None) -> dict[str, Any]:
    kw = {} if isolate is None else {"isolate": isolate}
    t = time.perf_counter()
    sol = solve(problem, name, time_limit=limit, **kw)
    wall = time.perf_counter() - t
    return {"solver": name, "limit": limit, "isolate": isolate,
            "wall": round(wall, 3), "overshoot": round(wall - limit, 3),
            "within": wall <= limit + tolerance(limit), "status": sol.status.value,
            "objective": sol.objective, "startup": sol.info.get("isolated")}


def _small(name: str) -> AssignmentProblem:
    costs = np.round(100 * np.random.default_rng(0).random((3, 3, 3)))
    return AssignmentProblem.dense(costs[0] if registered()[name].max_ndim == 2 else costs)


def startup(rounds: int) -> dict[str, dict[str, float]]:
    """Seconds until a *new* worker is ready (its first call), idle cores, tiny problem."""
    from assocopt.solvers.milp.limited import shutdown

    out = {}
    for name in ISOLATING:
        if not registered()[name].is_available():
            continue
        got = []
        for _ in range(rounds):
            shutdown()                      # no warm worker: this call starts one
            got.append(solve(_small(name), name, time_limit=600.0).info["isolated"])
        out[name] = {"best": min(got), "median": statistics.median(got)}
    return out


def overhead(names: list[str], rounds: int) -> dict[str, dict[str, float]]:
    """What a generous limit (600 s) adds to a call on a small problem, warm: the
    median of ``rounds`` paired differences (with minus without), in milliseconds."""
    out = {}
    for name in names:
        p = _small(name)
        solve(p, name, time_limit=600.0)    # the worker is started outside the timing
        diffs, plain = [], []
        for _ in range(rounds):
            t = time.perf_counter()
            solve(p, name)
            t1 = time.perf_counter()
            solve(p, name, time_limit=600.0)
            t2 = time.perf_counter()
            plain.append(t1 - t)
            diffs.append((t2 - t1) - (t1 - t))
        out[name] = {"without_ms": round(1000 * statistics.median(plain), 2),
                     "added_ms": round(1000 * statistics.median(diffs), 2)}
    return out


def measure(limits: list[float], n_busy: int, rounds: int,
            path: Path = GRUNDEL) -> dict[str, Any]:
    label, problem = instance(path)
    names = sorted(n for n, c in registered().items()
                   if c.supports_time_limit and c.is_available())
    tiny = AssignmentProblem.dense(np.ones((3, 3, 3)))
    for name in names:              # imports (and bnb's compilation) outside the timing
        solve(tiny, name)
    load_startup = round(os.getloadavg()[0], 2)
    idle = startup(rounds)
    added = overhead(names, 8 * rounds)
    load_overhead = round(os.getloadavg()[0], 2)
    runs = []
    spinners = busy(n_busy)
    try:
        time.sleep(1.0)
        load = os.getloadavg()
        for limit in limits:
            for name in names:
                runs.append(run_one(problem, name, limit, None))
                print(runs[-1], flush=True)
                if name in ISOLATING:
                    runs.append(run_one(problem, name, limit, False))
                    print(runs[-1], flush=True)
        load_end = os.getloadavg()
    finally:
        stop(spinners)
    return {"instance": label, "limits": limits, "busy": n_busy, "cpus": os.cpu_count(),
            "load_start": [round(x, 2) for x in load], "load_end":
            [round(x, 2) for x in load_end], "python": platform.python_version(),
            "startup_idle": idle, "load_startup": load_startup, "overhead": added,
            "load_overhead": load_overhead, "overhead_rounds": 8 * rounds, "runs": runs,
            "command": "python benchmarks/time_limits.py"}


def startup_sentence(js: dict[str, Any]) -> str:
    """The worker's start and a warm call's cost in words, as the README and the
    guide quote them."""
    parts = [f"{s['median']:.1f} s for `{name}`" for name, s in js["startup_idle"].items()]
    worst = max(js["overhead"].items(), key=lambda kv: kv[1]["added_ms"])
    return "the first solve under a limit starts the worker: about " + ", ".join(parts) + \
        f" (median of the rounds on {js['cpus']} cores at load average " \
        f"{js.get('load_startup', '?')}); every later one reuses it, and a generous limit " \
        f"adds at most {max(worst[1]['added_ms'], 0.0):.1f} ms a call (`{worst[0]}`; median of " \
        f"{js['overhead_rounds']} paired calls at load average {js['load_overhead']}; " \
        "`benchmarks/time_limits.py`)"


def render(js: dict[str, Any]) -> str:
    """The generated part of docs/benchmarks-limits.md."""
    lines = [f"Instance: {js['instance']}; {js['busy']} spinning processes on "
             f"{js['cpus']} cores; load average {js['load_start'][0]} at the start, "
             f"{js['load_end'][0]} at the end (Python {js['python']}).", "",
             "| back end | limit (s) | where | wall (s) | overshoot (s) | within max(1 s, 10 %) "
             "| status | worker ready after (s) |", "|---|---|---|---|---|---|---|---|"]
    for r in js["runs"]:
        where = ("this process" if r["isolate"] is False else
                 "worker process" if r["solver"] in ISOLATING else "this process")
        ready = r["startup"] if r["startup"] is not None else ""
        lines.append(f"| `{r['solver']}` | {r['limit']:g} | {where} | {r['wall']:.2f} | "
                     f"{r['overshoot']:+.2f} | {'yes' if r['within'] else '**no**'} | "
                     f"{r['status']} | {ready} |")
    lines += ["", "Start of a new worker process: its first call under a limit (3x3x3 "
              "problem, no spinning processes, load average "
              f"{js.get('load_startup', '?')}; best / median of the rounds):", ""]
    for name, s in js["startup_idle"].items():
        lines.append(f"* `{name}`: {s['best']:.2f} s / {s['median']:.2f} s")
    lines += ["", "What a generous limit (600 s) adds to a warm call on a small problem "
              "(3x3x3; 3x3 for the 2-D back ends): median of "
              f"{js['overhead_rounds']} paired differences, no spinning processes, load "
              f"average {js['load_overhead']}:", "",
              "| back end | call without a limit (ms) | added by the limit (ms) |",
              "|---|---|---|"]
    for name, o in js["overhead"].items():
        lines.append(f"| `{name}` | {o['without_ms']:.2f} | {o['added_ms']:+.2f} |")
    return "\n".join(lines)


def write_page(js: dict[str, Any]) -> None:
    text = PAGE.read_text()
    head, rest = text.split("<!-- limits:begin -->")
    _, tail = rest.split("<!-- limits:end -->")
    PAGE.write_text(f"{head}<!-- limits:begin -->\n{render(js)}\n<!-- limits:end -->{tail}")


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--limits", default="1,5", help="time limits, seconds (comma list)")
    ap.add_argument("--busy", type=int, default=os.cpu_count() or 2,
                    help="spinning processes (default: one per core)")
    ap.add_argument("--rounds", type=int, default=5, help="start-up measurements")
    ap.add_argument("--instance", type=Path, default=GRUNDEL,
                    help="Grundel file (default: ../shared/ap_instances/grundel_ap3/"
                         "ap3.50.1.txt beside the checkout)")
    ap.add_argument("--no-write", action="store_true")
    args = ap.parse_args(argv)
    js = measure([float(x) for x in args.limits.split(",")], args.busy, args.rounds,
                 args.instance)
    print(render(js))
    if not args.no_write:
        DATA.write_text(json.dumps(js, indent=1) + "\n")
        write_page(js)
    return 0


if __name__ == "__main__":
    # steady-state speed: the kernels compiled in the warm-up (by default a small
    # problem runs them as plain Python for its first seconds: first_use.py)
    os.environ.setdefault("ASSOCOPT_JIT", "compiled")
    sys.exit(main())
