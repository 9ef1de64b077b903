"""First use: what the first call of each public compiled path costs in a new process,
with numba's disk cache empty (cold) and filled (warm).

    python benchmarks/first_use.py              # writes docs/benchmarks-first-use.{md,json}
    python benchmarks/first_use.py --no-write
    python benchmarks/first_use.py --one scan   # one path, this process, JSON answer

Each path is one public call on a problem of a tracker's size (:data:`PATHS`).  Cold:
a fresh interpreter with ``NUMBA_CACHE_DIR`` an empty folder runs the path once;
warm: another fresh interpreter with the same folder, now filled, runs it again.  The
time of the first call (wall and CPU of the process, from before the call to after
it) is split by :func:`assocopt.solvers.kernels.spent` into compiling and loading
from the disk cache.  *All together*: one fresh cold interpreter runs every path in
turn (kernels shared between paths are compiled once).  The machine's load
(``os.getloadavg``) is recorded before and after.

Targets (from the issue that asked for a fast first use): every cold first call at
most 5 s, all together at most 15 s, a warm (cached) load at most 0.15 s.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from typing import Any, Callable

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "benchmarks"))
PAGE = ROOT / "docs" / "benchmarks-first-use.md"
DATA = ROOT / "docs" / "benchmarks-first-use.json"

#: Targets, seconds.
COLD_TARGET, ALL_TARGET, WARM_TARGET = 5.0, 15.0, 0.15


# ------------------------------------------------------------------ the paths
def _scan(n: int, N: int = 3, seed: int = 0):
    """A gated S-D scan (:mod:`tracking_scans`): N sensors, n targets."""
    from tracking_scans import ScanSpec, build_problem

    return build_problem(ScanSpec(N=N, n=n, seed=seed))[0]


def _sd(seed: int = 1):
    """A small gated S-D problem (random, 3 axes of 5 x 5 x 4 real indices)."""
    from assocopt.testing import random_problem

    return random_problem(np.random.default_rng(seed), "sd", sizes=(5, 5, 4), keep=0.4)


def _two_d_sparse(n: int, seed: int = 2):
    """A gated 2-D problem, ``n`` rows and columns, about 4 candidates a row, misses."""
    from assocopt import AssignmentProblem

    rng = np.random.default_rng(seed)
    k = 4
    rows = np.repeat(np.arange(1, n + 1), k)
    cols = np.clip(rows + rng.integers(-3, 4, rows.size), 1, n)
    pairs = np.unique(np.stack([rows, cols], axis=1), axis=0)
    T = np.concatenate([pairs, np.stack([np.arange(1, n + 1), np.zeros(n, int)], 1),
                        np.stack([np.zeros(n, int), np.arange(1, n + 1)], 1)])
    costs = np.concatenate([rng.random(len(pairs)) - 0.5, np.full(2 * n, 0.3)])
    return AssignmentProblem.sparse((n, n), T, costs)


def _two_d_dense(n: int, seed: int = 3):
    """A dense 2-D problem with miss costs (the ranking's input)."""
    from assocopt import AssignmentProblem

    rng = np.random.default_rng(seed)
    return AssignmentProblem.two_d(rng.random((n, n + 1)), row_miss=0.6, col_miss=0.4)


def _window(T: int, S: int, per: int, seed: int = 4):
    """A multi-frame window: ``T`` tracks, ``S`` slots, ``per`` hypotheses a track."""
    from assocopt.tracking.mfa import window_problem

    rng = np.random.default_rng(seed)
    track = np.repeat(np.arange(T), per)
    hist = rng.integers(0, T + 1, size=(T * per, S))
    hist[::per] = 0                          # every track may miss throughout
    cost = rng.random(T * per) * 5.0
    return window_problem(track, cost, hist)


def _answer(sol) -> dict[str, Any]:
    return {"status": sol.status.value, "objective": sol.objective,
            "selected": None if sol.selected is None else sol.selected.tolist(),
            "solver": sol.solver}


def path_bnb(small: bool) -> Callable[[], Any]:
    from assocopt import solve
    p = _sd()
    return lambda: _answer(solve(p, "bnb"))


def path_auto(small: bool) -> Callable[[], Any]:
    from assocopt import solve
    p = _sd()
    return lambda: _answer(solve(p))


def path_scan(small: bool) -> Callable[[], Any]:
    from assocopt import solve
    p = _scan(20 if small else 200)
    return lambda: _answer(solve(p))


def path_lagrangian(small: bool) -> Callable[[], Any]:
    from assocopt import solve
    p = _scan(8 if small else 40, seed=5)

    def call():
        sol = solve(p, "lagrangian")
        return _answer(sol) | {"bound": sol.bound}
    return call


def path_lagrangian_exact(small: bool) -> Callable[[], Any]:
    from assocopt import solve
    p = _scan(8 if small else 40, seed=6)
    return lambda: _answer(solve(p, "lagrangian-exact"))


def path_sparse2d(small: bool) -> Callable[[], Any]:
    from assocopt import solve
    p = _two_d_sparse(60 if small else 2000)
    return lambda: _answer(solve(p))


def path_kbest(small: bool) -> Callable[[], Any]:
    from assocopt import kbest
    p = _two_d_dense(4 if small else 8)
    return lambda: [_answer(s) for s in kbest(p, 10)]


def path_marginals(small: bool) -> Callable[[], Any]:
    from assocopt import marginals
    p = _two_d_dense(4 if small else 8, seed=7)

    def call():
        m = marginals(p, k=50)
        return {"candidate": m.candidate.tolist(), "hypotheses": m.hypotheses}
    return call


def path_mfa(small: bool) -> Callable[[], Any]:
    from assocopt.tracking.mfa import solve_window
    wp = _window(4 if small else 10, 3, 4)

    def call():
        sol, chosen = solve_window(wp)
        return _answer(sol) | {"chosen": None if chosen is None else chosen.tolist()}
    return call


#: (key, what, function): the public paths, in the order of the page; the function
#: builds the problem (``small``: a smaller one) and returns the call to time.
PATHS: list[tuple[str, str, Callable[[bool], Callable[[], Any]]]] = [
    ("bnb", "`solve(p, 'bnb')`, a gated S-D problem (5 x 5 x 4)", path_bnb),
    ("auto", "`solve(p)`, the same problem (`auto`)", path_auto),
    ("scan", "`solve(p)`, a gated 3-sensor scan of 200 targets (the batched components)",
     path_scan),
    ("lagrangian", "`solve(p, 'lagrangian')`, a 3-sensor scan of 40 targets",
     path_lagrangian),
    ("lagrangian-exact", "`solve(p, 'lagrangian-exact')`, a 3-sensor scan of 40 targets",
     path_lagrangian_exact),
    ("sparse2d", "`solve(p)`, a gated 2-D problem, 2000 x 2000 (the sparse LAP)",
     path_sparse2d),
    ("kbest", "`kbest(p, 10)`, a 2-D problem 8 x 9 with misses (Murty, compiled)",
     path_kbest),
    ("marginals", "`marginals(p, k=50)`, a 2-D problem 8 x 9 with misses", path_marginals),
    ("mfa", "`solve_window(window_problem(...))`, 10 tracks, 3 scans (multi-frame)",
     path_mfa),
]


def run_one(key: str, small: bool = False) -> dict[str, Any]:
    """Run path ``key`` once in this process: its answer and what the call cost (the
    call alone: the problem is built first, untimed)."""
    call = {k: f for k, _, f in PATHS}[key](small)
    from assocopt.solvers import kernels

    c0 = kernels.spent()
    t0, p0 = time.perf_counter(), time.process_time()
    answer = call()
    wall, cpu = time.perf_counter() - t0, time.process_time() - p0
    c1 = kernels.spent()
    return {"key": key, "answer": answer, "wall_s": wall, "cpu_s": cpu,
            "compile_s": c1[0] - c0[0], "cache_load_s": c1[1] - c0[1]}


#: Paths the test of NUMBA_DISABLE_JIT runs but the benchmark does not time (the
#: same kernels as another row: ``auto`` on that problem is ``bnb``).
NOT_TIMED = {"auto"}


def _load() -> list[float]:
    return [round(v, 2) for v in os.getloadavg()]


def _fresh(keys: list[str], cache: str) -> dict[str, Any]:
    """Run ``keys`` in a fresh interpreter with ``NUMBA_CACHE_DIR=cache``: the rows of
    :func:`run_one` and the process's own wall time (spawn to exit)."""
    env = {k: v for k, v in os.environ.items() if not k.startswith("NUMBA_")}
    env.update(NUMBA_CACHE_DIR=cache, PYTHONPATH=str(ROOT))
    t0 = time.perf_counter()
    done = subprocess.run([sys.executable, str(Path(__file__).resolve()), "--one", *keys],
                          env=env, cwd=ROOT, capture_output=True, text=True)
    wall = time.perf_counter() - t0
    if done.returncode != 0:
        raise RuntimeError(f"{keys} exited {done.returncode}: {done.stderr[-1500:]}")
    notes = [ln for ln in done.stderr.splitlines() if "compiling numba kernels" in ln]
    return {"rows": json.loads(done.stdout.splitlines()[-1]), "process_s": wall,
            "notes": len(notes)}


def _row(r: dict[str, Any]) -> dict[str, Any]:
    return {k: round(r[k], 4) for k in ("wall_s", "cpu_s", "compile_s", "cache_load_s")}


def measure(keys: list[str]) -> dict[str, Any]:
    """Cold and warm first calls of each path, then all of them in one cold process."""
    load_before = _load()
    rows = []
    for key in keys:
        cache = tempfile.mkdtemp(prefix="assocopt-first-use-")
        try:
            cold = _fresh([key], cache)
            warm = _fresh([key], cache)
        finally:
            shutil.rmtree(cache, ignore_errors=True)
        what = {k: w for k, w, _ in PATHS}[key]
        row = {"key": key, "what": what, "cold": _row(cold["rows"][0]),
               "warm": _row(warm["rows"][0]), "cold_process_s": round(cold["process_s"], 3),
               "warm_process_s": round(warm["process_s"], 3),
               "cold_notes": cold["notes"], "warm_notes": warm["notes"],
               "load": _load()}
        rows.append(row)
        print(f"{key:<17} cold {row['cold']['wall_s']:7.2f} s (CPU {row['cold']['cpu_s']:.2f}, "
              f"compile {row['cold']['compile_s']:.2f})  warm {row['warm']['wall_s']:.3f} s "
              f"(load {row['warm']['cache_load_s']:.3f})  load avg {row['load']}", flush=True)
    cache = tempfile.mkdtemp(prefix="assocopt-first-use-")
    try:
        together = _fresh(keys, cache)
    finally:
        shutil.rmtree(cache, ignore_errors=True)
    all_rows = together["rows"]
    total = {"wall_s": round(sum(r["wall_s"] for r in all_rows), 3),
             "cpu_s": round(sum(r["cpu_s"] for r in all_rows), 3),
             "compile_s": round(sum(r["compile_s"] for r in all_rows), 3),
             "process_s": round(together["process_s"], 3), "notes": together["notes"],
             "per_path": {r["key"]: _row(r) for r in all_rows}}
    print(f"all together: {total['wall_s']:.2f} s (CPU {total['cpu_s']:.2f})", flush=True)
    return {"targets": {"cold_s": COLD_TARGET, "all_s": ALL_TARGET, "warm_s": WARM_TARGET},
            "machine": {"python": platform.python_version(), "system": platform.system(),
                        "machine": platform.machine(), "cpus": os.cpu_count()},
            "versions": _versions(), "load_before": load_before, "load_after": _load(),
            "rows": rows, "together": total}


def _versions() -> dict[str, str]:
    import importlib.metadata as md
    out = {}
    for dist in ("numpy", "scipy", "numba", "llvmlite"):
        try:
            out[dist] = md.version(dist)
        except md.PackageNotFoundError:
            out[dist] = "-"
    return out


def _met(value: float, target: float) -> str:
    return "yes" if value <= target else "no"


def render(data: dict[str, Any]) -> str:
    """The docs page for the measurements ``data`` (tests/test_benchmarks_first_use.py
    checks that the committed page is this function of the committed json)."""
    m, v, t = data["machine"], data["versions"], data["targets"]
    lines = [
        "# First use: compiling the kernels",
        "",
        "Measured by `python benchmarks/first_use.py` (numbers below from "
        "`docs/benchmarks-first-use.json`, written by the same run). Each path is one "
        "public call in a fresh interpreter. *Cold*: `NUMBA_CACHE_DIR` is an empty "
        "folder, so numba compiles every kernel the call needs; *warm*: a second fresh "
        "interpreter with that folder filled, so the kernels are loaded from disk. "
        "Times are of the call alone (wall and CPU of the process from before the call "
        "to after it; the interpreter's start, `import assocopt` and building the problem "
        "are not in them); "
        "*compiling* and *cache load* are the parts of it (wall time) that "
        "`assocopt.solvers.kernels.ensure` timed; a warm call also imports numba "
        "(the first kernel a process uses imports it). *Note* says whether the call said, "
        "before compiling, that it would (one log line of the `assocopt` logger).",
        "",
        f"Machine: Python {m['python']}, {m['system']} {m['machine']}, {m['cpus']} CPUs; "
        f"numpy {v['numpy']}, scipy {v['scipy']}, numba {v['numba']}, llvmlite "
        f"{v['llvmlite']}. Load average (1, 5, 15 min) before the run "
        f"{', '.join(f'{x:g}' for x in data['load_before'])}, after it "
        f"{', '.join(f'{x:g}' for x in data['load_after'])}: on a loaded machine the "
        "wall times stretch, the CPU times much less.",
        "",
        f"Targets: a cold first call at most {t['cold_s']:g} s, all paths in one cold "
        f"process at most {t['all_s']:g} s, a warm (cached) first call at most "
        f"{t['warm_s']:g} s; judged here on CPU time.",
        "",
        "| path | cold (s) | cold CPU (s) | compiling (s) | note | met | warm (s) | "
        "cache load (s) | met | load avg |",
        "|---|---|---|---|---|---|---|---|---|---|",
    ]
    for r in data["rows"]:
        c, w = r["cold"], r["warm"]
        lines.append(
            f"| {r['what']} | {c['wall_s']:.2f} | {c['cpu_s']:.2f} | {c['compile_s']:.2f} | "
            f"{'yes' if r['cold_notes'] else 'no'} | {_met(c['cpu_s'], t['cold_s'])} | "
            f"{w['wall_s']:.3f} | {w['cache_load_s']:.3f} | "
            f"{_met(w['cpu_s'], t['warm_s'])} | {r['load'][0]:g} |")
    tg = data["together"]
    lines += [
        "",
        f"All paths in one cold process, in the order above: {tg['wall_s']:.2f} s "
        f"({tg['cpu_s']:.2f} s CPU; {tg['compile_s']:.2f} s of the wall time compiling; "
        "kernels two paths share are compiled once); target met: "
        f"{_met(tg['cpu_s'], t['all_s'])}. The process as a whole, interpreter start and "
        f"imports included, took {tg['process_s']:.2f} s.",
        "",
        "Where the compile time goes (numba's `numba:compile` events per function and "
        "signature, measured while cutting it): typing and lowering in numba's Python "
        "code and LLVM's optimisation of each kernel together with every kernel it "
        "calls; numba's own library functions (`np.argsort`, array slice assignment with "
        "its broadcasting checks, `heapq`) are compiled anew for each signature they "
        "meet. Cut so far: duplicate specialisations (a literal `-1` argument compiled "
        "`augment` twice; growing arrays by slice assignment compiled numba's "
        "broadcasting code for each dtype). A read-only install caches in the user's "
        "cache or, failing that, in a temporary folder of the process, which then "
        "compiles cold in every new process. `NUMBA_DISABLE_JIT=1` runs every kernel as "
        "plain Python with the same answers (tests/test_disable_jit.py).",
        "",
    ]
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--one", nargs="+", help="run these paths in this process (JSON)")
    ap.add_argument("--small", action="store_true", help="with --one: small problems")
    ap.add_argument("--paths", nargs="+", help="the paths to time (default: all)")
    ap.add_argument("--render", action="store_true",
                    help="write the page from the committed JSON only")
    ap.add_argument("--no-write", action="store_true", help="print only")
    args = ap.parse_args(argv)
    if args.one:
        out = [run_one(k, args.small) for k in args.one]
        print(json.dumps(out))
        return 0
    if args.render:
        PAGE.write_text(render(json.loads(DATA.read_text())))
        return 0
    keys = args.paths or [k for k, _, _ in PATHS if k not in NOT_TIMED]
    data = measure(keys)
    if not args.no_write:
        DATA.write_text(json.dumps(data, indent=2) + "\n")
        PAGE.write_text(render(data))
        print(f"wrote {PAGE.relative_to(ROOT)} and {DATA.relative_to(ROOT)}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
