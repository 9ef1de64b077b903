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
* k-best: ``kbest(problem, k)`` against enumerating every feasible solution and sorting.
* marginals: how close the k-best marginals get to the exact ones (full enumeration).
"""

from __future__ import annotations

import argparse
import json
import math
import platform
import sys
import time
from pathlib import Path
from typing import Any, Callable

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from assocopt import AssignmentProblem, kbest, marginals, solve  # noqa: E402
from assocopt.generate import gated_2d  # noqa: E402
from assocopt.solvers.bruteforce import enumerate_solutions  # noqa: E402
from assocopt.solvers.lap import augmented_edges, lapx_available  # noqa: E402
from assocopt.solvers.scipy_lsa import augmented_matrix  # noqa: E402

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
            t = best_of(fns, repeats, inner)
            r, c = lsa(C if case == "plain" else M)
            ref = float((C if case == "plain" else M)[r, c].sum())
            p = AssignmentProblem.dense(C) if case == "plain" else \
                AssignmentProblem.two_d(C, rm, cm)
            objs = {"assocopt": solve(p).objective}
            if lapx_available():
                objs["lapjv"] = solve(p, "lapjv").objective
            rows.append({"n": n, "case": case, "times_s": t, "scipy_objective": ref,
                         "objectives": objs,
                         "equal": all(abs(v - ref) <= 1e-9 * max(1.0, abs(ref))
                                      for v in objs.values())})
            print(f"dense n={n} {case}: " + ", ".join(f"{k} {v * 1e6:.1f} us"
                                                   for k, v in t.items()), flush=True)
    return rows


def sparse_rows(cases: list[tuple[int, int]], quick: bool) -> list[dict]:
    import scipy.sparse as sp
    from scipy.sparse.csgraph import min_weight_full_bipartite_matching as mwfbm

    rows = []
    for n, k in cases:
        t0 = time.perf_counter()
        p = gated_2d(n, k, seed=0)
        build = time.perf_counter() - t0
        T, c = p.tuples, p.costs
        both = (T[:, 0] > 0) & (T[:, 1] > 0)
        rm, cm = p.miss_costs()
        ar, ac, aw = augmented_edges(n, n, T[both, 0] - 1, T[both, 1] - 1, c[both], rm, cm)
        shift = 1.0 - min(0.0, float(aw.min()))
        G = sp.csr_matrix((aw + shift, (ar, ac)), shape=(2 * n, 2 * n))
        out: dict[str, Any] = {}
        fns = {"mwfbm": lambda: out.__setitem__("m", mwfbm(G)),
               "assocopt": lambda: out.__setitem__("s", solve(p))}
        t = best_of(fns, 1 if quick or n >= 100_000 else 2, 1)
        r, cc = out["m"]
        ref = float(np.asarray(G[r, cc]).sum() - shift * 2 * n)
        obj = out["s"].objective
        rows.append({"n": n, "k": k, "candidates": p.n_candidates, "build_s": build,
                     "times_s": t, "mwfbm_objective": ref, "objective": obj,
                     "mode": out["s"].info.get("lsa_mode"),
                     "equal": abs(obj - ref) <= 1e-9 * max(1.0, abs(ref))})
        print(f"sparse n={n} k={k}: " + ", ".join(f"{a} {v:.3f} s" for a, v in t.items()),
              flush=True)
    return rows


def _small_problems(seed: int) -> list[tuple[str, AssignmentProblem]]:
    rng = np.random.default_rng(seed)
    C = rng.random((6, 6))
    C[rng.random(C.shape) < 0.3] = np.inf
    return [("dense 7x7", AssignmentProblem.dense(rng.random((7, 7)))),
            ("miss 5x5, 30% forbidden", AssignmentProblem.two_d(C[:5, :5], 0.3, 0.3)),
            ("miss 6x6", AssignmentProblem.two_d(rng.random((6, 6)), 0.3, 0.3))]


def kbest_rows(ks: list[int], quick: bool) -> list[dict]:
    rows = []
    for label, p in _small_problems(1):
        t0 = time.perf_counter()
        objs = sorted(p.objective_of(s) for s in enumerate_solutions(p, max_nodes=10**8))
        t_enum = time.perf_counter() - t0
        for k in ks:
            t0 = time.perf_counter()
            r = kbest(p, k)
            t_k = time.perf_counter() - t0
            rows.append({"problem": label, "feasible": len(objs), "k": k,
                         "found": len(r), "kbest_s": t_k, "enumerate_s": t_enum,
                         "subproblems": r.subproblems,
                         "equal": [float(v) for v in r.objectives] == objs[:k]})
            print(f"kbest {label} k={k}: {t_k:.4f} s vs enumeration {t_enum:.3f} s",
                  flush=True)
    return rows


def marginal_rows(ks: list[int], seeds: int) -> list[dict]:
    rows = []
    for T in (0.02, 0.05, 0.1):
        for k in ks:
            errs, masses = [], []
            for seed in range(seeds):
                p = AssignmentProblem.two_d(np.random.default_rng(100 + seed).random((6, 6)),
                                            MISS, MISS)
                exact = marginals(p, temperature=T, method="enumerate")
                approx = marginals(p, k=k, temperature=T)
                errs.append(float(np.abs(approx.candidate - exact.candidate).max()))
                masses.append(float(math.exp(approx.log_partition - exact.log_partition)))
            rows.append({"temperature": T, "k": k, "problems": seeds,
                         "hypotheses": _count(), "max_abs_error": max(errs),
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
             "*ratio* = assocopt / scipy; *lapjv* = `solve(..., solver=\"lapjv\")`.", ""]
    has_lapx = any("lapjv" in r["times_s"] for r in data["dense"])
    head = "| n | case | scipy | assocopt | ratio | difference |"
    sep = "|---|---|---|---|---|---|"
    if has_lapx:
        head += " lapjv | scipy / lapjv | raw lapx |"
        sep += "---|---|---|"
    head += " same objective |"
    sep += "---|"
    lines += [head, sep]
    for r in data["dense"]:
        t = r["times_s"]
        row = (f"| {r['n']} | {r['case']} | {_us(t['scipy'])} | {_us(t['assocopt'])} | "
               f"{t['assocopt'] / t['scipy']:.2f} | {(t['assocopt'] - t['scipy']) * 1e6:+.1f} us |")
        if has_lapx:
            row += (f" {_us(t['lapjv'])} | {t['scipy'] / t['lapjv']:.2g} | "
                    f"{_us(t['lapx'])} |")
        row += f" {'yes' if r['equal'] else 'NO'} |"
        lines.append(row)
    lines += ["", "## Sparse gated scans", "",
              "`gated_2d(n, k)`: n tracks, n measurements, each track gated to k "
              "measurements (chi-square(2) costs), every track and measurement may stay "
              "unassigned at 6.0.  `solve(p)` (problem built beforehand; *build* is "
              "`gated_2d`'s constructor) against `min_weight_full_bipartite_matching` "
              "on the same graph plus miss edges (the classical augmentation, built "
              "beforehand).  assocopt drops the pairs dearer than both misses, then runs "
              "the same LAPJVsp on the same augmentation.", "",
              "| n | k | candidates | build | mwfbm | assocopt | ratio | same objective |",
              "|---|---|---|---|---|---|---|---|"]
    for r in data["sparse"]:
        t = r["times_s"]
        lines.append(f"| {r['n']} | {r['k']} | {r['candidates']} | {_us(r['build_s'])} | "
                     f"{_us(t['mwfbm'])} | {_us(t['assocopt'])} | "
                     f"{t['assocopt'] / t['mwfbm']:.2f} | {'yes' if r['equal'] else 'NO'} |")
    lines += ["", "## k-best", "",
              "`kbest(p, k)` (lazy Murty on the dense matrix) against enumerating every "
              "feasible solution (`enumerate_solutions`) and sorting; *same* = the k "
              "objectives equal the k smallest enumerated ones.", "",
              "| problem | feasible solutions | k | found | subproblems solved | kbest | "
              "enumerate + sort | same |", "|---|---|---|---|---|---|---|---|"]
    for r in data["kbest"]:
        lines.append(f"| {r['problem']} | {r['feasible']} | {r['k']} | {r['found']} | "
                     f"{r['subproblems']} | {_us(r['kbest_s'])} | {_us(r['enumerate_s'])} | "
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
    sparse = [(2000, 5)] if args.quick else [(10_000, 5), (10_000, 20), (100_000, 5),
                                             (100_000, 20)]
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
    sys.exit(main())
