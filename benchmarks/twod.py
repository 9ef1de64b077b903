"""2-D association at full speed: assocopt against scipy (and lapx), one process.

    python benchmarks/twod.py            # full run: docs/benchmarks-2d.json and .md
    python benchmarks/twod.py --quick    # smoke run (small sizes, few repeats)
    python benchmarks/twod.py --render   # rewrite the .md from the committed .json
    python benchmarks/twod.py --sections dense   # rerun one section, keep the others

Sections (every number on the page comes from the JSON this command writes):

* dense: ``solve(AssignmentProblem.dense(C))`` timed from the constructor on, against
  ``scipy.optimize.linear_sum_assignment(C)``; with miss costs
  ``solve(AssignmentProblem.two_d(C, rm, cm))`` against scipy on the usual
  ``(n1 + n2) x (n2 + n1)`` augmented matrix, built beforehand (not timed); the same
  with ``solver="lapjv"`` and raw ``lap.lapjvh`` when lapx is installed.  Best of
  several repeats, the two sides interleaved; objectives compared.
* sparse gated: ``gated_2d(n, k)`` scans solved by ``solve`` (problem built beforehand)
  against ``min_weight_full_bipartite_matching`` on the same graph plus miss edges
  (the classical augmentation, built beforehand), objectives compared.
* k-best: ``kbest(problem, k)`` (the compiled ranking) against the generic path with
  scipy per subproblem and against enumerating every feasible solution and sorting.
* marginals: how close the k-best marginals get to the exact ones (full enumeration).
"""

from __future__ import annotations

import argparse
import json
import math
import platform
import os
import sys
import time
from pathlib import Path
from typing import Any, Callable

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from assocopt import AssignmentProblem, kbest, marginals, solve  # noqa: E402
from assocopt.workflow.generate import gated_2d  # noqa: E402
from assocopt.solvers.baseline.bruteforce import enumerate_solutions  # noqa: E402
from assocopt.solvers.twod.lap import augmented_edges, augmented_matrix, lapx_available  # noqa: E402

JSON = ROOT / "docs" / "benchmarks-2d.json"
PAGE = ROOT / "docs" / "benchmarks-2d.md"
MISS = 0.3          # miss cost of every row and column, costs uniform on [0, 1)


def best_of(fns: dict[str, Callable[[], Any]], repeats: int, inner: int) -> dict[str, float]:
    """Best per-call seconds of each function, the functions interleaved."""
    best = {k: math.inf for k in fns}
    for _ in range(repeats):
        for k, f in fns.items():
            t0 = time.perf_counter()
            for _ in range(inner):
                f()
            best[k] = min(best[k], (time.perf_counter() - t0) / inner)
    return best


def best_of_both(fns: dict[str, Callable[[], Any]], repeats: int, inner: int
                 ) -> tuple[dict[str, float], dict[str, float]]:
    """Best per-call (wall, CPU) seconds of each function, the functions interleaved.
    CPU time is this thread's (``time.thread_time``): every side here runs in the
    calling thread, and on a shared machine it leaves out the waits for a core."""
    wall = {k: math.inf for k in fns}
    cpu = {k: math.inf for k in fns}
    for _ in range(repeats):
        for k, f in fns.items():
            w0, c0 = time.perf_counter(), time.thread_time()
            for _ in range(inner):
                f()
            c1, w1 = time.thread_time(), time.perf_counter()
            wall[k] = min(wall[k], (w1 - w0) / inner)
            cpu[k] = min(cpu[k], (c1 - c0) / inner)
    return wall, cpu


def dense_rows(sizes: list[int], quick: bool) -> list[dict]:
    from scipy.optimize import linear_sum_assignment as lsa

    rows = []
    for n in sizes:
        rng = np.random.default_rng(n)
        C = rng.random((n, n))
        rm = np.full(n, MISS)
        cm = np.full(n, MISS)
        M = augmented_matrix(C, rm, cm)
        repeats, inner = ((25, 200) if n <= 10 else (15, 20) if n <= 100 else
                          (7, 1) if n <= 1000 else (5, 1))
        if quick:
            repeats, inner = 2, max(1, inner // 10)
        plain = {"scipy": lambda: lsa(C), "assocopt": lambda: solve(AssignmentProblem.dense(C))}
        miss = {"scipy": lambda: lsa(M),
                "assocopt": lambda: solve(AssignmentProblem.two_d(C, rm, cm))}
        if lapx_available():
            import lap
            plain["lapjv"] = lambda: solve(AssignmentProblem.dense(C), "lapjv")
            plain["lapx"] = lambda: lap.lapjvh(C)
            miss["lapjv"] = lambda: solve(AssignmentProblem.two_d(C, rm, cm), "lapjv")
            miss["lapx"] = lambda: lap.lapjvh(M)
        for case, fns in (("plain", plain), ("miss", miss)):
            wall, t = best_of_both(fns, repeats, inner)
            r, c = lsa(C if case == "plain" else M)
            ref = float((C if case == "plain" else M)[r, c].sum())
            p = AssignmentProblem.dense(C) if case == "plain" else \
                AssignmentProblem.two_d(C, rm, cm)
            objs = {"assocopt": solve(p).objective}
            if lapx_available():
                objs["lapjv"] = solve(p, "lapjv").objective
            rows.append({"n": n, "case": case, "times_s": t, "wall_s": wall,
                         "scipy_objective": ref,
                         "objectives": objs,
                         "equal": all(abs(v - ref) <= 1e-9 * max(1.0, abs(ref))
                                      for v in objs.values())})
            print(f"dense n={n} {case} (CPU): " + ", ".join(f"{k} {v * 1e6:.1f} us"
                                                         for k, v in t.items()), flush=True)
    return rows


SPATIAL_CLUTTER = 0.1    # clutter points per track in the spatial scans
SPATIAL_PD = 0.9


def spatial_scan(n: int, k: float, seed: int) -> AssignmentProblem:
    """A tracking scan in a plane: ``n`` tracks uniform in a square sized so that a
    99 % chi-square gate (unit innovation covariance) holds about ``k`` measurements
    on average; each track detected with probability 0.9 (unit noise), plus
    ``0.1 n`` clutter points; costs and misses are the negative log-likelihood
    ratios of :func:`assocopt.tracking.costs.kinematic.build_problem`."""
    from assocopt.tracking.costs.kinematic import build_problem
    from assocopt.tracking.gating import chi2_threshold

    rng = np.random.default_rng(seed)
    n_clutter = int(SPATIAL_CLUTTER * n)
    n_meas = SPATIAL_PD * n + n_clutter
    side = math.sqrt(n_meas * math.pi * chi2_threshold(0.99, 2) / k)
    x = rng.uniform(0.0, side, (n, 2))
    seen = rng.random(n) < SPATIAL_PD
    z = np.concatenate([x[seen] + rng.normal(size=(int(seen.sum()), 2)),
                        rng.uniform(0.0, side, (n_clutter, 2))])
    return build_problem(x, np.eye(2), z, pd=SPATIAL_PD,
                         clutter_density=n_clutter / side ** 2,
                         name=f"spatial-n{n}-k{k}-s{seed}")


def make_scan(scan: str, n: int, k: float) -> AssignmentProblem:
    """The benchmark's sparse problems: ``gated_2d`` (banded) or ``spatial``."""
    return gated_2d(n, int(k), seed=0) if scan == "gated_2d" else spatial_scan(n, k, 0)


def _components(p: AssignmentProblem) -> tuple[int, int]:
    """Number of connected components of the gated graph (pairs cheaper than leaving
    both out; isolated indices count) and the size (rows + columns) of the largest."""
    import scipy.sparse as sp
    from scipy.sparse.csgraph import connected_components
    from assocopt.solvers.twod.sparse import prune_dominated, split_candidates

    n1, n2 = p.sizes
    rows, cols, w, _, rm, cm, _, _ = split_candidates(p)
    keep = prune_dominated(rows, cols, w, rm, cm)
    A = sp.csr_matrix((np.ones(int(keep.sum())), (rows[keep], n1 + cols[keep])),
                      shape=(n1 + n2, n1 + n2))
    count, label = connected_components(A, directed=False)
    return int(count), int(np.bincount(label).max(initial=0))


def _first_call(scan: str, n: int, k: float) -> dict:
    """``solve(p)`` in a fresh process: numba's import and the load of the compiled
    kernel from its disk cache (or its compilation) come with it."""
    import subprocess
    code = ("import json, sys, time; sys.path.insert(0, sys.argv[1]); import twod; "
            f"p = twod.make_scan({scan!r}, {n}, {k}); pre = 'numba' in sys.modules; "
            "t0 = time.perf_counter(); s = twod.solve(p); "
            "t = time.perf_counter() - t0; print(json.dumps({'first_call_s': t, "
            "'numba_imported_before': pre, 'compile_s': s.times.get('compile', 0.0), "
            "'cache_load_s': s.times.get('cache_load', 0.0)}))")
    out = subprocess.run([sys.executable, "-c", code, str(ROOT / "benchmarks")],
                         capture_output=True, text=True, check=True)
    return json.loads(out.stdout.strip().splitlines()[-1])


def sparse_rows(cases: list[tuple[str, int, float]], quick: bool) -> list[dict]:
    import scipy.sparse as sp
    from scipy.sparse.csgraph import min_weight_full_bipartite_matching as mwfbm
    from assocopt.solvers.twod.sparse import split_candidates

    rows = []
    for scan, n, k in cases:
        t0 = time.perf_counter()
        p = make_scan(scan, n, k)
        build = time.perf_counter() - t0
        n1, n2 = p.sizes
        r0, c0, w0, _, rm, cm, _, _ = split_candidates(p)
        ar, ac, aw = augmented_edges(n1, n2, r0, c0, w0, rm, cm)
        shift = 1.0 - min(0.0, float(aw.min()))
        size = n1 + n2
        G = sp.csr_matrix((aw + shift, (ar, ac)), shape=(size, size))
        first = _first_call(scan, n, k)
        out: dict[str, Any] = {}
        fns = {"mwfbm": lambda: out.__setitem__("m", mwfbm(G)),
               "assocopt": lambda: out.__setitem__("s", solve(p))}
        if n < 100_000:          # one untimed call of each side first (cheap here)
            best_of(fns, 1, 1)
        t = best_of(fns, 1 if quick or n >= 100_000 else 3, 1)
        r, cc = out["m"]
        ref = float(np.asarray(G[r, cc]).sum() - shift * size)
        obj = out["s"].objective
        n_comp, largest = _components(p)
        rows.append({"scan": scan, "n": n, "k": k, "sizes": [n1, n2],
                     "candidates": p.n_candidates, "pairs": len(w0),
                     "components": n_comp, "largest_component": largest,
                     "build_s": build, "times_s": t, **first,
                     "mwfbm_objective": ref, "objective": obj,
                     "mode": out["s"].info.get("lsa_mode"),
                     "equal": abs(obj - ref) <= 1e-9 * max(1.0, abs(ref))})
        print(f"sparse {scan} n={n} k={k}: " + ", ".join(f"{a} {v:.3f} s"
                                                         for a, v in t.items())
              + f", first call {first['first_call_s']:.3f} s", flush=True)
    return rows


def _kbest_problems(seed: int, quick: bool) -> list[tuple[str, AssignmentProblem, bool]]:
    """``(label, problem, small enough to enumerate)``."""
    rng = np.random.default_rng(seed)
    C = rng.random((6, 6))
    C[rng.random(C.shape) < 0.3] = np.inf
    out = [("dense 7x7", AssignmentProblem.dense(rng.random((7, 7))), True),
           ("miss 5x5, 30% forbidden", AssignmentProblem.two_d(C[:5, :5], 0.3, 0.3), True),
           ("miss 6x6", AssignmentProblem.two_d(rng.random((6, 6)), 0.3, 0.3), True)]
    for n in ([20] if quick else [20, 50]):
        out.append((f"miss {n}x{n}", AssignmentProblem.two_d(rng.random((n, n)), MISS, MISS),
                    False))
    return out


def _best_time(fn: Callable[[], Any], repeats: int) -> tuple[float, Any]:
    best, out = math.inf, None
    for _ in range(repeats):
        t0 = time.perf_counter()
        out = fn()
        best = min(best, time.perf_counter() - t0)
    return best, out


def kbest_rows(ks: list[int], quick: bool) -> list[dict]:
    """The compiled ranking (``kbest(p, k)``) against the generic path with scipy per
    subproblem (``solver="scipy-lsa"``) and, where feasible, full enumeration."""
    rows = []
    kbest(AssignmentProblem.two_d(np.ones((2, 2)), 1.0, 1.0), 2)   # compile / load first
    for label, p, small in _kbest_problems(1, quick):
        objs, t_enum = None, None
        if small:
            t0 = time.perf_counter()
            objs = sorted(p.objective_of(s) for s in enumerate_solutions(p, max_nodes=10**8))
            t_enum = time.perf_counter() - t0
        for k in ks if small else [k for k in ks if k >= 10]:
            t_k, r = _best_time(lambda: kbest(p, k), 1 if quick else 15)
            t_g, g = _best_time(lambda: kbest(p, k, "scipy-lsa"), 1 if quick or not small
                                else 3)
            got = [float(v) for v in r.objectives]
            same = got == objs[:k] if small else \
                bool(np.allclose(got, g.objectives, rtol=0, atol=1e-9))
            rows.append({"problem": label, "feasible": len(objs) if small else None,
                         "k": k, "found": len(r), "kbest_s": t_k, "generic_s": t_g,
                         "enumerate_s": t_enum, "subproblems": r.subproblems,
                         "generic_subproblems": g.subproblems,
                         "reference": "enumeration" if small else "scipy-lsa path",
                         "equal": same})
            print(f"kbest {label} k={k}: {t_k * 1e3:.3f} ms (scipy per subproblem "
                  f"{t_g * 1e3:.1f} ms)", flush=True)
    return rows


def marginal_rows(ks: list[int], seeds: int) -> list[dict]:
    rows = []
    problems = [AssignmentProblem.two_d(np.random.default_rng(100 + seed).random((6, 6)),
                                        MISS, MISS) for seed in range(seeds)]
    hypotheses = _count()
    for T in (0.02, 0.05, 0.1):
        exacts = [marginals(p, temperature=T, method="enumerate") for p in problems]
        for k in ks:
            errs, masses = [], []
            for p, exact in zip(problems, exacts):
                approx = marginals(p, k=k, temperature=T, method="kbest")
                errs.append(float(np.abs(approx.candidate - exact.candidate).max()))
                masses.append(float(math.exp(approx.log_partition - exact.log_partition)))
            rows.append({"temperature": T, "k": k, "problems": seeds,
                         "hypotheses": hypotheses, "max_abs_error": max(errs),
                         "median_abs_error": float(np.median(errs)),
                         "min_mass_covered": min(masses)})
            print(f"marginals T={T} k={k}: max error {max(errs):.2e}", flush=True)
    return rows


def _count() -> int:
    p = AssignmentProblem.two_d(np.ones((6, 6)), MISS, MISS)
    return sum(1 for _ in enumerate_solutions(p))


# --------------------------------------------------------------------------- page
def _us(s: float) -> str:
    return f"{s * 1e6:.1f} us" if s < 1e-3 else f"{s * 1e3:.2f} ms" if s < 1 else f"{s:.2f} s"


def _ratio(x: float) -> str:
    return f"{x:.0f}x" if x >= 10 else f"{x:.1f}x"


def _wall_ratio(row: dict) -> str:
    w = row.get("wall_s")
    return f"{w['assocopt'] / w['scipy']:.2f}" if w else "-"


def _dense_summary(rows: list[dict]) -> list[str]:
    """One sentence: the largest difference at n = 10 and the largest ratio above."""
    small = [r["times_s"]["assocopt"] - r["times_s"]["scipy"] for r in rows if r["n"] <= 10]
    large = [r["times_s"]["assocopt"] / r["times_s"]["scipy"] for r in rows if r["n"] >= 100]
    lapjv = [r["times_s"]["scipy"] / r["times_s"]["lapjv"] for r in rows
             if r["n"] >= 2000 and "lapjv" in r["times_s"]]
    out = []
    if small:
        out.append(f"At n = 10 `solve` costs at most {max(small) * 1e6:.1f} us more than "
                   "scipy")
    if large:
        out.append(f"from n = 100 up at most {max(large):.2f} times scipy's time")
    if lapjv:
        out.append(f"with lapx (`solver=\"lapjv\"`) at n = 2000 at least "
                   f"{min(lapjv):.1f} times faster than scipy")
    return ["", "; ".join(out) + "."] if out else []


def render(data: dict) -> str:
    """The Markdown page, from the JSON only."""
    env = data["environment"]
    lines = ["# 2-D assignment: speed against scipy, k-best, marginals", "",
             "Written by `python benchmarks/twod.py` (numbers from "
             "[benchmarks-2d.json](benchmarks-2d.json); a test re-renders this page from "
             "it).  One process, best of several repeats, the sides interleaved; "
             f"Python {env['python']}, numpy {env['numpy']}, scipy {env['scipy']}, "
             f"lapx {env['lapx'] or 'not installed'}, {env['machine']}"
             + (f", load average {env['load_average']} at the start of the last run (a "
                "shared machine: timings at that load vary by a factor of up to 2 "
                "between runs; the ratios, taken with both sides interleaved, less so)"
                if env.get("load_average") is not None else "") + ".", "",
             "## Dense", "",
             "`solve(AssignmentProblem.dense(C))` timed from the constructor on (validation, "
             "solve, the re-check of the answer, the `Solution`) against "
             "`linear_sum_assignment(C)`; *miss*: every row and column may stay "
             f"unassigned at {MISS} (costs uniform on [0, 1)), "
             "`solve(AssignmentProblem.two_d(C, rm, cm))` with `rm`, `cm` "
             f"arrays of {MISS} against scipy on the "
             "`(n1 + n2) x (n2 + n1)` augmented matrix built beforehand.  "
             "Times are CPU seconds of the calling thread (every side runs there), best "
             "of the repeats; *wall ratio* is the same ratio on wall-clock time, which "
             "on a shared machine also counts the waits for a core.  "
             "*ratio* = assocopt / scipy; *lapjv* = `solve(..., solver=\"lapjv\")`.", ""]
    has_lapx = any("lapjv" in r["times_s"] for r in data["dense"])
    head = "| n | case | scipy | assocopt | ratio | difference | wall ratio |"
    sep = "|---|---|---|---|---|---|---|"
    if has_lapx:
        head += " lapjv | scipy / lapjv | raw lapx |"
        sep += "---|---|---|"
    head += " same objective |"
    sep += "---|"
    lines += [head, sep]
    for r in data["dense"]:
        t = r["times_s"]
        row = (f"| {r['n']} | {r['case']} | {_us(t['scipy'])} | {_us(t['assocopt'])} | "
               f"{t['assocopt'] / t['scipy']:.2f} | {(t['assocopt'] - t['scipy']) * 1e6:+.1f} us |"
               f" {_wall_ratio(r)} |")
        if has_lapx:
            row += (f" {_us(t['lapjv'])} | {t['scipy'] / t['lapjv']:.2g} | "
                    f"{_us(t['lapx'])} |")
        row += f" {'yes' if r['equal'] else 'NO'} |"
        lines.append(row)
    lines += _dense_summary(data["dense"])
    lines += _sparse_lines(data["sparse"])
    lines += ["", "## k-best", "",
              "`kbest(p, k)`: Murty's ranking compiled (numba), each subproblem solved "
              "from its parent's solution and duals by one shortest augmenting path, "
              "children kept unsolved on the heap under a lower bound until they reach "
              "the top; *scipy per subproblem*: the generic path, "
              "`kbest(p, k, solver=\"scipy-lsa\")`, one `linear_sum_assignment` per "
              "subproblem solved; *enumerate + sort*: every feasible solution "
              "(`enumerate_solutions`), sorted.  Times are best of 15 (the generic path: "
              "best of 3, one run on the larger problems), compilation excluded "
              "(cached on disk after the first run).  *same*: the k objectives equal "
              "the k smallest enumerated ones or, where enumeration is out of reach, "
              "the generic path's (within 1e-9).  Costs uniform on [0, 1), misses at "
              f"{MISS}.", "",
              "| problem | feasible solutions | k | found | subproblems solved | kbest | "
              "kbest (scipy per subproblem) | speed-up | enumerate + sort | same |",
              "|---|---|---|---|---|---|---|---|---|---|"]
    for r in data["kbest"]:
        feas = "-" if r["feasible"] is None else str(r["feasible"])
        enum = "-" if r["enumerate_s"] is None else _us(r["enumerate_s"])
        lines.append(f"| {r['problem']} | {feas} | {r['k']} | {r['found']} | "
                     f"{r['subproblems']} | {_us(r['kbest_s'])} | {_us(r['generic_s'])} | "
                     f"{_ratio(r['generic_s'] / r['kbest_s'])} | {enum} | "
                     f"{'yes' if r['equal'] else 'NO'} |")
    lines += ["", "TCL's `kBest2DAssign` (Tracker Component Library): no published timing "
              "figures were found, so it is not compared here.", "",
              "## Marginals from the k best", "",
              f"6 x 6 with misses at {MISS} (random costs), "
              f"{data['marginals'][0]['hypotheses']} hypotheses each; error = largest "
              "absolute difference of a candidate's marginal from the exact one (full "
              "enumeration) over the problems; *mass* = the smallest share of the total "
              "weight the k best carry.", "",
              "| temperature | k | problems | max error | median error | min mass |",
              "|---|---|---|---|---|---|"]
    for r in data["marginals"]:
        lines.append(f"| {r['temperature']} | {r['k']} | {r['problems']} | "
                     f"{r['max_abs_error']:.2e} | {r['median_abs_error']:.2e} | "
                     f"{r['min_mass_covered']:.4f} |")
    return "\n".join(lines) + "\n"


def _sparse_lines(rows: list[dict]) -> list[str]:
    """The page's sparse section (from the JSON rows only)."""
    lines = ["", "## Sparse gated scans", "",
             "Two kinds of scan, both with every track and measurement allowed to stay "
             "unassigned.  *gated_2d*: `gated_2d(n, k)`, n tracks and n measurements, "
             "each track gated to k of the 4k measurements around its own index "
             "(chi-square(2) costs, misses at 6.0): a band, so the gated graph is one "
             "giant component -- the hard case for any path search.  *spatial*: "
             "`spatial_scan(n, k)` in `benchmarks/twod.py`, n tracks uniform in a "
             f"square, each detected with probability {SPATIAL_PD} (unit noise), "
             f"{SPATIAL_CLUTTER:g} n clutter points, a 99 % chi-square gate holding "
             "about k measurements on average, negative log-likelihood-ratio costs "
             "(`assocopt.tracking.costs.kinematic.build_problem`): at k = 2 many "
             "small clusters, at k = 8 a giant one.  *components*: connected "
             "components of the gated graph after dropping the pairs dearer than both "
             "misses (isolated indices count), *largest*: rows + columns in the "
             "largest.", "",
             "Timed: `solve(p)` on the problem built beforehand (*build*: its "
             "constructor, not timed) -- splitting the candidate list, dropping "
             "dominated pairs, the engine, the candidate positions of the answer and "
             "`solve`'s re-check of it -- against "
             "`min_weight_full_bipartite_matching` (LAPJVsp) alone, on the same graph "
             "plus miss edges in the classical `(n1 + n2)`-square augmentation built "
             "beforehand (not timed).  Best of 3 runs (1 at n = 10^5), the two sides "
             "interleaved, in one process, after one untimed call of each side "
             "(none at n = 10^5: those cases run after the others).  *first call*: `solve(p)` once in a fresh "
             "Python process, which also imports numba and loads the compiled engine "
             "from numba's disk cache (a one-off per process; a tracker pays it on its "
             "first scan only).  *same objective*: equal to 1e-9 relative.", "",
             "assocopt's engine is its own compiled shortest-augmenting-path LAP "
             "(`assocopt/solvers/kernels/sparse_lap.py`: Jonker-Volgenant's augmenting "
             "row reduction, then one Dijkstra per row still free, on a heap and "
             "stopped at the closest free column), on the clipped reduced-cost form "
             "(n1 rows, n2 + n1 columns: one private miss column per track) rather "
             "than the square augmentation; a path search only touches the part of "
             "the graph it reaches, so separate clusters cost what they would solved "
             "one by one.  LAPJVsp instead scans its whole list of candidate columns "
             "at each step of a path, which grows with the problem.", "",
             "| scan | n | k | sizes | candidates | components (largest) | build | "
             "mwfbm | assocopt | ratio | first call | form | same objective |",
             "|---|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        t = r["times_s"]
        lines.append(
            f"| {r['scan']} | {r['n']} | {r['k']} | {r['sizes'][0]} x {r['sizes'][1]} | "
            f"{r['candidates']} | {r['components']} ({r['largest_component']}) | "
            f"{_us(r['build_s'])} | {_us(t['mwfbm'])} | {_us(t['assocopt'])} | "
            f"{t['assocopt'] / t['mwfbm']:.3f} | {_us(r['first_call_s'])} | "
            f"{r['mode']} | {'yes' if r['equal'] else 'NO'} |")
    slower = [r for r in rows if r["times_s"]["assocopt"] >= r["times_s"]["mwfbm"]]
    first = [r for r in rows if r["first_call_s"] >= r["times_s"]["mwfbm"]]
    lines += [""]
    lines.append("Slower than mwfbm (best of runs): " + (", ".join(
        f"{r['scan']} n = {r['n']}, k = {r['k']}" for r in slower) if slower else
        "no case") + ".  ")
    if first:
        loads = [r["cache_load_s"] + r["compile_s"] for r in first]
        lines[-1] += (
            "On the first call of a process assocopt is slower than mwfbm in "
            + ", ".join(f"{r['scan']} n = {r['n']}, k = {r['k']}" for r in first)
            + f": that call imports numba and loads the engine ({_us(min(loads))} to "
            f"{_us(max(loads))} of loading alone in these runs), more than mwfbm "
            "needs for the whole of these scans; every later call runs at the speed "
            "of the *assocopt* column.")
    else:
        lines[-1] += "Nor on the first call of a process."
    return lines


def environment() -> dict:
    import scipy

    try:
        import importlib.metadata as md
        lapx = md.version("lapx")
    except Exception:
        lapx = None
    return {"python": platform.python_version(), "numpy": np.__version__,
            "scipy": scipy.__version__, "lapx": lapx,
            "machine": f"{platform.machine()}, {__import__('os').cpu_count()} cores",
            "load_average": round(__import__('os').getloadavg()[0], 1)}


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="small smoke run")
    ap.add_argument("--render", action="store_true", help="rewrite the page from the JSON")
    ap.add_argument("--out", type=Path, default=None, help="folder (default docs/)")
    ap.add_argument("--sections", default="dense,sparse,kbest,marginals",
                    help="comma-separated sections to (re)run; the others are kept from "
                         "the existing JSON")
    args = ap.parse_args(argv)
    json_path = JSON if args.out is None else args.out / JSON.name
    page_path = PAGE if args.out is None else args.out / PAGE.name
    if args.render:
        page_path.write_text(render(json.loads(json_path.read_text())))
        return 0
    dense_n = [10, 100] if args.quick else [10, 100, 1000, 2000]
    sparse = [("gated_2d", 2000, 5), ("spatial", 2000, 2)] if args.quick else \
        [(scan, n, k) for scan, ks in (("gated_2d", (5, 20)), ("spatial", (2, 8)))
         for n in (10_000, 100_000) for k in ks]
    ks = [1, 10, 100] if args.quick else [1, 10, 100, 1000]
    runs = {"dense": lambda: dense_rows(dense_n, args.quick),
            "sparse": lambda: sparse_rows(sparse, args.quick),
            "kbest": lambda: kbest_rows(ks, args.quick),
            "marginals": lambda: marginal_rows(ks, 2 if args.quick else 5)}
    wanted = [w.strip() for w in args.sections.split(",") if w.strip()]
    unknown = set(wanted) - set(runs)
    if unknown:
        ap.error(f"unknown sections {sorted(unknown)}; valid: {sorted(runs)}")
    data = json.loads(json_path.read_text()) if set(wanted) != set(runs) else {}
    data["environment"] = environment()
    for name in runs:
        if name in wanted:
            data[name] = runs[name]()
    json_path.parent.mkdir(parents=True, exist_ok=True)
    json_path.write_text(json.dumps(data, indent=1) + "\n")
    page_path.write_text(render(data))
    print(f"wrote {json_path} and {page_path}")
    return 0


if __name__ == "__main__":
    # steady-state speed: the kernels compiled in the warm-up (by default a small
    # problem runs them as plain Python for its first seconds: first_use.py)
    os.environ.setdefault("ASSOCOPT_JIT", "compiled")
    sys.exit(main())
