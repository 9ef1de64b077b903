"""Solve the public 3-AP / LAP instances with every back end, side by side, in one run.

Times are reported as ratios to ``scipy.optimize.milp`` on the same instance in the
same process (ratio < 1: faster than scipy).  Every objective is checked against the
proven optimum recorded in ../shared/ap_instances.

    python benchmarks/backends.py --time-limit 60   # n = 10..50: docs/benchmarks.json + .md
    python benchmarks/backends.py --max-n 20        # quicker
    python benchmarks/backends.py --render          # rewrite the .md from the committed .json

The run (about 15-20 minutes on 2 cores with ``--time-limit 60``) writes the raw results
with the environment (versions, cores, load average at start and end, date, command
line, options) to ``docs/benchmarks.json``; the page is rendered from that JSON only,
and ``tests/test_benchmarks_backends.py`` re-renders it and checks it.
"""

from __future__ import annotations

import argparse
import csv
import json
import os
import platform
import statistics
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from assocopt import Status, solve  # noqa: E402
from assocopt.io import read_instance, write_text_atomically  # noqa: E402
from assocopt.solvers import registered  # noqa: E402

AP = ROOT.parent / "shared" / "ap_instances"
JSON = ROOT / "docs" / "benchmarks.json"
PAGE = ROOT / "docs" / "benchmarks.md"
REFERENCE = "scipy"
DEFAULT_SOLVERS = ["scipy", "highs", "ortools-cpsat", "ortools-mip", "cvxpy", "scipy-lsa",
                   "lagrangian-exact", "bnb", "auto"]


def instances(max_n: int, per_size: int) -> list[tuple[str, float]]:
    """(relative path, optimum) for Grundel and Balas-Saltzman 3-AP and assign100."""
    with open(AP / "known_values.csv", newline="") as fh:
        rows = [r for r in csv.DictReader(fh)
                if r["file"] != "balas_saltzman/BalasAndSaltzman.txt"]
    chosen: dict[tuple[str, int], list[tuple[str, float]]] = {}
    for r in rows:
        n = int(r["n"])
        if r["family"] == "orlib_lap":
            if r["file"].endswith("assign100.txt"):
                chosen.setdefault((r["family"], n), []).append((r["file"], float(r["value"])))
            continue
        if 10 <= n <= max_n:
            lst = chosen.setdefault((r["family"], n), [])
            if len(lst) < per_size:
                lst.append((r["file"], float(r["value"])))
    return [item for key in sorted(chosen) for item in chosen[key]]


def timed_solve(problem, name: str, time_limit: float, repeats: int
                ) -> tuple[list[float], object]:
    """Wall times of ``repeats`` solves (in-process latency, model build included)."""
    times, sol = [], None
    for _ in range(repeats):
        t0 = time.perf_counter()
        sol = solve(problem, name, time_limit=time_limit)
        times.append(time.perf_counter() - t0)
    return times, sol


def run(solvers: list[str], max_n: int, per_size: int, time_limit: float) -> list[dict]:
    records = []
    for rel, optimum in instances(max_n, per_size):
        p = read_instance(AP / rel)
        n = p.sizes[0]
        repeats = 3 if n <= 20 else 1
        row = {"instance": rel, "N": p.ndim, "n": n, "optimum": optimum, "results": {}}
        for name in solvers:
            cls = registered().get(name)
            if name != "auto" and (cls is None or not cls.is_available()
                                   or (cls.max_ndim is not None and p.ndim > cls.max_ndim)):
                continue
            times, sol = timed_solve(p, name, time_limit, repeats)
            t = statistics.median(times)
            ok = sol.status is Status.OPTIMAL and sol.objective == optimum
            row["results"][name] = {"time": t, "times": times, "status": str(sol.status),
                                    "objective": sol.objective, "correct": ok,
                                    "solver": sol.solver}
            print(f"{rel:45s} {name:17s} {t:9.4f}s {sol.status!s:10s} "
                  f"obj={sol.objective} {'ok' if ok else 'MISMATCH'}", flush=True)
        records.append(row)
    return records


# --------------------------------------------------------------------------- page
def ratio_to_reference(row: dict, name: str) -> float | None:
    """Time of ``name`` over scipy milp's on one instance (None: scipy not proven)."""
    ref = row["results"].get(REFERENCE)
    res = row["results"].get(name)
    if res is None or ref is None or not ref["correct"]:
        return None
    return res["time"] / ref["time"]


def geometric_means(data: dict) -> dict[str, tuple[float, int]]:
    """Per back end: geometric mean of the ratio to scipy milp, and over how many."""
    out = {}
    for s in used_solvers(data):
        ratios = [r for r in (ratio_to_reference(row, s) for row in data["records"])
                  if r is not None]
        if ratios:
            out[s] = (statistics.geometric_mean(ratios), len(ratios))
    return out


def used_solvers(data: dict) -> list[str]:
    return [s for s in data["options"]["solvers"]
            if any(s in r["results"] for r in data["records"])]


def _load(v: list[float] | None) -> str:
    return "?" if v is None else ", ".join(f"{x:.2f}" for x in v)


def render(data: dict) -> str:
    """The Markdown page, from the JSON only."""
    env, opt = data["environment"], data["options"]
    used = used_solvers(data)
    lines = [
        "# Back-end benchmark: public 3-AP and LAP instances",
        "",
        f"Generated by `{env['command']}` (numbers from [benchmarks.json](benchmarks.json); "
        "a test re-renders this page from it) on "
        f"{env['machine']} with {env['cores']} cores, Python {env['python']}, on "
        f"{env['date']} ({env['minutes']:.1f} min).  Each cell: wall time of "
        "`assocopt.solve` (model build + solve + checks, in process; median of 3 for "
        "n <= 20, one run above) and, in brackets, the ratio to `scipy` "
        "(`scipy.optimize.milp`) on the same instance in the same run (below 1 = "
        f"faster).  Time limit {opt['time_limit']:g} s per solve.  A cell marked `!` "
        "did not return the proven optimum (status in the cell).",
        "",
        "Versions: " + ", ".join(f"{s} {env['versions'][s]}" for s in used
                                 if s in env["versions"]),
        "",
        "| instance | N | n | optimum | " + " | ".join(used) + " |",
        "|---|---|---|---|" + "---|" * len(used),
    ]
    for r in data["records"]:
        cells = []
        for s in used:
            res = r["results"].get(s)
            if res is None:
                cells.append("")
                continue
            cell = f"{res['time']:.4f} s"
            ratio = ratio_to_reference(r, s)
            if ratio is not None:
                cell += f" ({ratio:.3g})"
            if not res["correct"]:
                cell += f" ! {res['status']}"
            cells.append(cell)
        lines.append(f"| {r['instance'].split('/')[-1]} | {r['N']} | {r['n']} | "
                     f"{r['optimum']:g} | " + " | ".join(cells) + " |")
    lines += ["", "Geometric mean of the ratio to scipy milp over the instances each back "
              "end ran:", ""]
    for s, (gm, k) in geometric_means(data).items():
        lines.append(f"* `{s}`: {gm:.3g} over {k} instances")
    lines += ["", f"The machine has {env['cores']} cores and was shared with other work "
              f"while this ran (load average {_load(env['load_start'])} at the start, "
              f"{_load(env['load_end'])} at the end: 1, 5 and 15 minutes); treat "
              "differences below ~20 % as noise, and single timings as upper bounds.", ""]
    return "\n".join(lines)


def readme_figure(data: dict, instance: str = "ap3.50.1.txt",
                  method: str = "lagrangian-exact") -> str:
    """The README's sentence on the largest Grundel instance, from the JSON."""
    row = next(r for r in data["records"] if r["instance"].endswith("/" + instance))
    ours, ref = row["results"][method], row["results"][REFERENCE]
    if not ours["correct"]:
        return f"`{method}` does not prove Grundel n = {row['n']} optimal ({ours['status']})"
    head = f"`{method}` proves Grundel n = {row['n']} optimal in {ours['time']:.2f} s where "
    if ref["correct"]:
        return head + f"scipy milp takes {ref['time']:.1f} s"
    return head + (f"scipy milp stops at the {data['options']['time_limit']:g} s time limit "
                   f"without a proof ({ref['time']:.1f} s, {ref['status']})")


def environment(argv: list[str], solvers: list[str]) -> dict:
    versions = {}
    for s in solvers:
        cls = registered().get(s)
        if cls is not None and cls.is_available():
            versions[s] = cls.version()
    return {"command": "python benchmarks/backends.py" + "".join(" " + a for a in argv),
            "date": time.strftime("%Y-%m-%d"), "machine": platform.machine(),
            "cores": os.cpu_count(), "python": platform.python_version(),
            "platform": platform.platform(), "versions": versions,
            "load_start": [round(x, 2) for x in os.getloadavg()]}


def write_atomic(path: Path, text: str) -> None:
    path.parent.mkdir(parents=True, exist_ok=True)
    write_text_atomically(path, text)


def main(argv: list[str] | None = None) -> int:
    argv = sys.argv[1:] if argv is None else argv
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--max-n", type=int, default=50)
    ap.add_argument("--per-size", type=int, default=1, help="instances per family and size")
    ap.add_argument("--time-limit", type=float, default=120.0)
    ap.add_argument("--solvers", default=",".join(DEFAULT_SOLVERS))
    ap.add_argument("--out", type=Path, default=None,
                    help="folder for benchmarks.json and benchmarks.md (default docs/)")
    ap.add_argument("--render", action="store_true",
                    help="rewrite the page from the JSON, run nothing")
    args = ap.parse_args(argv)
    json_path = JSON if args.out is None else args.out / JSON.name
    page_path = PAGE if args.out is None else args.out / PAGE.name
    if args.render:
        write_atomic(page_path, render(json.loads(json_path.read_text())))
        return 0
    if not AP.is_dir():
        print(f"{AP} not found: the benchmark needs ../shared/ap_instances", file=sys.stderr)
        return 2
    solvers = [s for s in args.solvers.split(",") if s == "auto" or s in registered()]
    env = environment(argv, solvers)
    t0 = time.perf_counter()
    records = run(solvers, args.max_n, args.per_size, args.time_limit)
    env["minutes"] = (time.perf_counter() - t0) / 60
    env["load_end"] = [round(x, 2) for x in os.getloadavg()]
    data = {"environment": env,
            "options": {"max_n": args.max_n, "per_size": args.per_size,
                        "time_limit": args.time_limit, "solvers": solvers},
            "records": records}
    write_atomic(json_path, json.dumps(data, indent=1) + "\n")
    write_atomic(page_path, render(data))
    print(f"wrote {json_path} and {page_path}")
    return 0


if __name__ == "__main__":
    # steady-state speed: the kernels compiled in the warm-up (by default a small
    # problem runs them as plain Python for its first seconds: first_use.py)
    os.environ.setdefault("ASSOCOPT_JIT", "compiled")
    raise SystemExit(main())
