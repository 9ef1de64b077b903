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
    ("kbest", "`kbest(p, 10)`, a 2-D problem 8 x 9 with misses (Murty)",
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
    from assocopt.solvers.kernels import tiers

    c0, i0 = kernels.spent(), sum(tiers.interpreted_seconds().values())
    t0, p0 = time.perf_counter(), time.process_time()
    answer = call()
    wall, cpu = time.perf_counter() - t0, time.process_time() - p0
    c1, i1 = kernels.spent(), sum(tiers.interpreted_seconds().values())
    return {"key": key, "answer": answer, "wall_s": wall, "cpu_s": cpu,
            "compile_s": c1[0] - c0[0], "cache_load_s": c1[1] - c0[1],
            "interpreted_s": i1 - i0, "numba": "numba" in sys.modules}


#: Paths the test of NUMBA_DISABLE_JIT runs but the benchmark does not time (the
#: same kernels as another row: ``auto`` on that problem is ``bnb``).
NOT_TIMED = {"auto"}


def _load() -> list[float]:
    return [round(v, 2) for v in os.getloadavg()]


def _fresh(keys: list[str], cache: str, mode: str | None) -> dict[str, Any]:
    """Run ``keys`` in a fresh interpreter with ``NUMBA_CACHE_DIR=cache`` and
    ``ASSOCOPT_JIT=mode`` (None: unset, the default rule): the rows of :func:`run_one`
    and the process's own wall time (spawn to exit)."""
    env = {k: v for k, v in os.environ.items()
           if not k.startswith("NUMBA_") and k != "ASSOCOPT_JIT"}
    env.update(NUMBA_CACHE_DIR=cache, PYTHONPATH=str(ROOT))
    if mode:
        env["ASSOCOPT_JIT"] = mode
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
    out = {k: round(r[k], 4) for k in ("wall_s", "cpu_s", "compile_s", "cache_load_s",
                                        "interpreted_s")}
    return out | {"numba": r["numba"]}


def _together(keys: list[str], mode: str | None) -> dict[str, Any]:
    """All ``keys`` in one fresh interpreter with an empty cache."""
    cache = tempfile.mkdtemp(prefix="assocopt-first-use-")
    try:
        run = _fresh(keys, cache, mode)
    finally:
        shutil.rmtree(cache, ignore_errors=True)
    rows = run["rows"]
    return {"wall_s": round(sum(r["wall_s"] for r in rows), 3),
            "cpu_s": round(sum(r["cpu_s"] for r in rows), 3),
            "compile_s": round(sum(r["compile_s"] for r in rows), 3),
            "process_s": round(run["process_s"], 3), "notes": run["notes"],
            "per_path": {r["key"]: _row(r) for r in rows}}


def measure(keys: list[str]) -> dict[str, Any]:
    """Per path, three fresh processes on one cache folder: the default rule with the
    cache empty, compiled with it empty (it fills it), compiled again (it loads);
    then all paths in one cold process, by the default rule and compiled."""
    load_before = _load()
    rows = []
    for key in keys:
        cache = tempfile.mkdtemp(prefix="assocopt-first-use-")
        try:
            auto = _fresh([key], cache, None)
            cold = _fresh([key], cache, "compiled")
            warm = _fresh([key], cache, "compiled")
        finally:
            shutil.rmtree(cache, ignore_errors=True)
        what = {k: w for k, w, _ in PATHS}[key]
        row = {"key": key, "what": what, "auto": _row(auto["rows"][0]),
               "cold": _row(cold["rows"][0]), "warm": _row(warm["rows"][0]),
               "auto_notes": auto["notes"], "cold_notes": cold["notes"],
               "warm_notes": warm["notes"], "load": _load()}
        rows.append(row)
        print(f"{key:<17} default {row['auto']['wall_s']:.3f} s (CPU "
              f"{row['auto']['cpu_s']:.3f})  compiled cold {row['cold']['wall_s']:7.2f} s "
              f"(CPU {row['cold']['cpu_s']:.2f})  warm {row['warm']['wall_s']:.3f} s  "
              f"load avg {row['load']}", flush=True)
    together = {"auto": _together(keys, None), "compiled": _together(keys, "compiled")}
    for mode, t in together.items():
        print(f"all together ({mode}): {t['wall_s']:.2f} s (CPU {t['cpu_s']:.2f})",
              flush=True)
    from assocopt.solvers.kernels import tiers
    return {"targets": {"cold_s": COLD_TARGET, "all_s": ALL_TARGET, "warm_s": WARM_TARGET},
            "machine": {"python": platform.python_version(), "system": platform.system(),
                        "machine": platform.machine(), "cpus": os.cpu_count()},
            "versions": _versions(), "load_before": load_before, "load_after": _load(),
            "rule": {"budget_cold_s": tiers.BUDGET_COLD,
                     "budget_cached_s": tiers.BUDGET_CACHED,
                     "budget_warm_s": tiers.BUDGET_WARM, "limits": dict(tiers.LIMITS)},
            "rows": rows, "together": together}


def _versions() -> dict[str, str]:
    import importlib.metadata as md
    out = {}
    for dist in ("numpy", "scipy", "numba", "llvmlite"):
        try:
            out[dist] = md.version(dist)
        except md.PackageNotFoundError:
            out[dist] = "-"
    return out


from first_use_page import render, route  # noqa: E402,F401  (the page, from the JSON)


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
