"""Start-up cost of the command line, as a ratio to ``python -c "import scipy.optimize"``.

    python benchmarks/startup.py            # writes docs/benchmarks-startup.{md,json}
    python benchmarks/startup.py --rounds 9 --no-write

Every command runs as a fresh subprocess of this interpreter (wall time, from spawn
to exit), with this checkout first on ``PYTHONPATH`` and the repository root as the
working directory.  Each command runs once unmeasured first (warm: bytecode and
numba's on-disk kernel cache exist, the files are in the page cache), then ``--rounds``
times interleaved with the others, so a noisy moment hits all of them alike; the
best of the rounds is kept.  A machine-independent figure is the ratio of a
command's best time to the baseline's best time in the same run.

Targets (from the issue that asked for a fast start): a 2-D solve within 1.15x the
baseline, a small S-D solve (``bnb``, numba) within 1.4x.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import resource
import subprocess
import sys
import time
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parents[1]
PAGE = ROOT / "docs" / "benchmarks-startup.md"
DATA = ROOT / "docs" / "benchmarks-startup.json"

BASELINE = "import scipy.optimize"
#: (key, what, argv after the interpreter, target ratio or None)
COMMANDS: list[tuple[str, str, list[str], float | None]] = [
    ("baseline", f'python -c "{BASELINE}"', ["-c", BASELINE], None),
    ("python", 'python -c "pass" (the interpreter alone)', ["-c", "pass"], None),
    ("import", 'python -c "import assocopt"', ["-c", "import assocopt"], None),
    ("help", "assocopt --help", ["-m", "assocopt", "--help"], None),
    ("solve-2d", "assocopt solve instances/example-2d-miss.json",
     ["-m", "assocopt", "solve", "instances/example-2d-miss.json"], 1.15),
    ("solve-sd", "assocopt solve instances/example-sd.json",
     ["-m", "assocopt", "solve", "instances/example-sd.json"], 1.4),
    ("solve-sd-bnb", "assocopt solve instances/example-sd.json --solver bnb",
     ["-m", "assocopt", "solve", "instances/example-sd.json", "--solver", "bnb"], None),
]


def _env() -> dict[str, str]:
    env = dict(os.environ)
    # warm means bytecode on disk, as after pip install (which compiles it): let the
    # unmeasured first run write it even where the environment turns that off
    env.pop("PYTHONDONTWRITEBYTECODE", None)
    env["PYTHONPATH"] = os.pathsep.join([str(ROOT)] + [p for p in
                                         env.get("PYTHONPATH", "").split(os.pathsep) if p])
    return env


def time_once(argv: list[str]) -> tuple[float, float]:
    """Wall seconds and CPU seconds (user + system) of one ``python ARGV`` subprocess
    (it must exit 0).  CPU time is reported too: it varies far less than wall time
    on a busy machine."""
    r0 = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = time.perf_counter()
    done = subprocess.run([sys.executable, *argv], cwd=ROOT, env=_env(),
                          stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    dt = time.perf_counter() - t0
    r1 = resource.getrusage(resource.RUSAGE_CHILDREN)
    if done.returncode != 0:
        raise RuntimeError(f"python {' '.join(argv)} exited {done.returncode}: "
                           f"{done.stderr.decode(errors='replace')[-500:]}")
    return dt, (r1.ru_utime - r0.ru_utime) + (r1.ru_stime - r0.ru_stime)


def measure(rounds: int) -> dict[str, Any]:
    """Warm every command, then time ``rounds`` interleaved rounds; best of each."""
    load_start = os.getloadavg()[0]
    for _key, _what, argv, _target in COMMANDS:
        time_once(argv)
    times: dict[str, list[float]] = {key: [] for key, *_ in COMMANDS}
    cpu: dict[str, list[float]] = {key: [] for key, *_ in COMMANDS}
    for _ in range(rounds):
        for key, _what, argv, _target in COMMANDS:
            wall, used = time_once(argv)
            times[key].append(wall)
            cpu[key].append(used)
    base, base_cpu = min(times["baseline"]), min(cpu["baseline"])
    rows = []
    for key, what, _argv, target in COMMANDS:
        best = min(times[key])
        ratio = best / base
        rows.append({"key": key, "command": what, "best_s": round(best, 4),
                     "all_s": [round(t, 4) for t in times[key]],
                     "ratio": round(ratio, 3), "target": target,
                     "met": None if target is None else bool(ratio <= target),
                     "cpu_best_s": round(min(cpu[key]), 4),
                     "cpu_ratio": round(min(cpu[key]) / base_cpu, 3)})
    return {"rounds": rounds, "baseline": f'python -c "{BASELINE}"',
            "machine": {"python": platform.python_version(), "system": platform.system(),
                        "machine": platform.machine(), "cpus": os.cpu_count(),
                        "load": [round(load_start, 2), round(os.getloadavg()[0], 2)]},
            "versions": _versions(), "rows": rows}


def _versions() -> dict[str, str]:
    import importlib.metadata as md
    out = {}
    for dist in ("numpy", "scipy", "numba"):
        try:
            out[dist] = md.version(dist)
        except md.PackageNotFoundError:
            out[dist] = "-"
    return out


def render(data: dict[str, Any]) -> str:
    """The docs page for the measurements ``data`` (tests/test_startup.py checks that
    the committed page is this function of the committed json)."""
    m, v = data["machine"], data["versions"]
    lines = [
        "# Start-up time of the command line",
        "",
        "Measured by `python benchmarks/startup.py` (numbers below from "
        "`docs/benchmarks-startup.json`, written by the same run). Each command is a "
        "fresh process, timed from spawn to exit, warm (run once unmeasured first, so "
        "bytecode and numba's kernel cache exist), best of "
        f"{data['rounds']} interleaved rounds. The ratio is to the baseline "
        f"`{data['baseline']}` in the same run, which makes it comparable across "
        "machines; the targets apply to it. The CPU columns (user + system time of "
        "the process, best of the same rounds) vary less on a busy machine. "
        "`assocopt ...` runs as `python -m assocopt ...` with the checkout "
        "first on `PYTHONPATH`, from the repository root.",
        "",
        f"Machine: Python {m['python']}, {m['system']} {m['machine']}, {m['cpus']} CPUs; "
        f"numpy {v['numpy']}, scipy {v['scipy']}, numba {v['numba']}"
        + (f"; load average {m['load'][0]:.1f} at the start, {m['load'][1]:.1f} at the end "
           "(a shared machine: the absolute times grow with the load, the ratios less)."
           if "load" in m else "."),
        "",
        "| command | best (s) | ratio to baseline | target | met | CPU best (s) | CPU ratio |",
        "|---|---|---|---|---|---|---|",
    ]
    for r in data["rows"]:
        target = "-" if r["target"] is None else f"<= {r['target']:g}x"
        met = "-" if r["met"] is None else ("yes" if r["met"] else "no")
        lines.append(f"| `{r['command']}` | {r['best_s']:.3f} | {r['ratio']:.2f}x | "
                     f"{target} | {met} | {r['cpu_best_s']:.3f} | {r['cpu_ratio']:.2f}x |")
    lines += [
        "",
        "What loads: `import assocopt` loads the problem, solution and registry modules "
        "(numpy only); a back end's module is imported when it is asked for, and its "
        "optional package (highspy, ortools, cvxpy, numba) inside its `solve`. "
        "`assocopt solve` without `--solver` solves one small problem by the route that "
        "costs least to load for one solve in a fresh process (`assocopt/cli/one_shot.py`): "
        "an S-D problem of at most 64 candidates is enumerated (`bruteforce`, numpy only, "
        "at most 2,000 search nodes), and one of at most 1,000 candidates, or a small 2-D "
        "problem, goes to HiGHS (highspy), which loads faster than numba's kernels or "
        "`scipy.optimize` (what `auto` takes in a library process, where the load is "
        "paid once): one problem per process does not repay the "
        "kernels' load. The last row is the compiled path that `auto` takes for larger "
        "problems and in a library process: it imports numba (which imports "
        "scipy.linalg) and loads from numba's disk cache only the two kernels `bnb` "
        "calls; its cost is numba's, about `import numba` plus its first-use set-up.",
        "",
    ]
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--rounds", type=int, default=5, help="timed rounds (best kept)")
    ap.add_argument("--no-write", action="store_true", help="print only")
    args = ap.parse_args(argv)
    data = measure(args.rounds)
    for r in data["rows"]:
        print(f"{r['key']:<12} {r['best_s']:.3f} s  {r['ratio']:.2f}x  "
              f"(CPU {r['cpu_best_s']:.3f} s, {r['cpu_ratio']:.2f}x)"
              + ("" if r["target"] is None else
                 f"  (target {r['target']:g}x: {'met' if r['met'] else 'MISSED'})"))
    if not args.no_write:
        DATA.write_text(json.dumps(data, indent=2) + "\n")
        PAGE.write_text(render(data))
        print(f"wrote {PAGE.relative_to(ROOT)} and {DATA.relative_to(ROOT)}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
