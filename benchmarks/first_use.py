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
import math
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


def path_bnb(small: bool) -> Any:
    from assocopt import solve
    return _answer(solve(_sd(), "bnb"))


def path_auto(small: bool) -> Any:
    from assocopt import solve
    return _answer(solve(_sd()))


def path_scan(small: bool) -> Any:
    from assocopt import solve
    return _answer(solve(_scan(20 if small else 200)))


def path_lagrangian(small: bool) -> Any:
    from assocopt import solve
    sol = solve(_scan(8 if small else 40, seed=5), "lagrangian")
    return _answer(sol) | {"bound": sol.bound}


def path_lagrangian_exact(small: bool) -> Any:
    from assocopt import solve
    return _answer(solve(_scan(8 if small else 40, seed=6), "lagrangian-exact"))


def path_sparse2d(small: bool) -> Any:
    from assocopt import solve
    sol = solve(_two_d_sparse(60 if small else 2000))
    return _answer(sol)


def path_kbest(small: bool) -> Any:
    from assocopt import kbest
    ranked = kbest(_two_d_dense(4 if small else 8), 10)
    return [_answer(s) for s in ranked]


def path_marginals(small: bool) -> Any:
    from assocopt import marginals
    m = marginals(_two_d_dense(4 if small else 8, seed=7), k=50)
    return {"candidate": m.candidate.tolist(), "hypotheses": m.hypotheses}


def path_mfa(small: bool) -> Any:
    from assocopt.tracking.mfa import solve_window
    sol, chosen = solve_window(_window(4 if small else 10, 3, 4))
    return _answer(sol) | {"chosen": None if chosen is None else chosen.tolist()}


#: (key, what, function): the public paths, in the order of the page.
PATHS: list[tuple[str, str, Callable[[bool], Any]]] = [
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
    """Run path ``key`` once in this process: its answer and what the call cost."""
    fn = {k: f for k, _, f in PATHS}[key]
    from assocopt.solvers import kernels

    c0 = kernels.spent()
    t0, p0 = time.perf_counter(), time.process_time()
    answer = fn(small)
    wall, cpu = time.perf_counter() - t0, time.process_time() - p0
    c1 = kernels.spent()
    return {"key": key, "answer": answer, "wall_s": wall, "cpu_s": cpu,
            "compile_s": c1[0] - c0[0], "cache_load_s": c1[1] - c0[1]}


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--one", nargs="+", help="run these paths in this process (JSON)")
    ap.add_argument("--small", action="store_true", help="with --one: small problems")
    ap.add_argument("--no-write", action="store_true", help="print only")
    args = ap.parse_args(argv)
    if args.one:
        out = [run_one(k, args.small) for k in args.one]
        print(json.dumps(out))
        return 0
    raise SystemExit("measurement not written yet")


if __name__ == "__main__":
    sys.exit(main())
