"""Benchmark: the components of multi-frame window problems, `auto` against HiGHS.

The scenes of ``benchmarks/mfa.py`` (a Stone Soup MFA tracker on targets crossing in
pairs, hypotheses by :class:`~assocopt.tracking.stonesoup.hypothesiser.
LinearGaussianMFAHypothesiser`, the tracks advanced with AssocoptMFA's pruned
hypotheses), with larger windows.  At every step the window's S-D problem is split
into its connected components (:func:`assocopt.problems.components.split`); each
component of at least ``--min-candidates`` candidates is solved as a problem of its
own, ``solve(component)`` (``auto``) and ``solve(component, "highs")``, interleaved,
best of ``--repeat`` (wall clock and process CPU time); the whole window is timed the
same way (``solve(window)`` against ``solve(window, "highs")``, each with its default
decomposition).  Every proven objective is checked against the other's.

Usage::

    python benchmarks/mfa_components.py [--configs 10x5,...] [--steps 8] [--repeat 3]
        [--min-candidates 1000] [--seed 0] [--out docs/benchmarks-mfa-components]
    python benchmarks/mfa_components.py --render   # the page from the committed JSON

writes ``OUT.json`` and ``OUT.md`` (``tests/test_benchmarks_mfa_components.py``
re-renders the page and checks it against the JSON).
"""

from __future__ import annotations

import json
import os
import sys
import time
from datetime import timedelta
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "benchmarks"))

from mfa import advance, cached_hypothesiser, scene, scene_arguments  # noqa: E402
from stonesoup_assoc import command, machine, write_pages  # noqa: E402

CONFIGS = "5x6,10x5,10x6,20x5,50x4,50x5"
#: the component size at and above which `auto` must never be slower than HiGHS
TARGET_K = 3000


def timed_pair(problem, repeat: int) -> dict:
    """``auto`` and ``highs`` on ``problem``, interleaved, best of ``repeat``."""
    from assocopt import solve
    best = {m: [np.inf, np.inf] for m in ("auto", "highs")}
    sols = {}
    for _ in range(repeat):
        for m in best:
            t0, c0 = time.perf_counter(), time.process_time()
            sols[m] = solve(problem) if m == "auto" else solve(problem, "highs")
            best[m][0] = min(best[m][0], time.perf_counter() - t0)
            best[m][1] = min(best[m][1], time.process_time() - c0)
    a, h = sols["auto"], sols["highs"]
    return {"auto_s": best["auto"][0], "auto_cpu_s": best["auto"][1],
            "highs_s": best["highs"][0], "highs_cpu_s": best["highs"][1],
            "auto_solver": a.solver, "auto_status": a.status.value,
            "highs_status": h.status.value, "auto_objective": float(a.objective),
            "highs_objective": float(h.objective),
            "agree": abs(a.objective - h.objective) <= 1e-9 * max(1.0, abs(h.objective))}


def components(problem, min_k: int):
    """The components of ``problem`` with at least ``min_k`` candidates, as problems."""
    from assocopt.problems.components import local_tuples, split, subproblem
    sp = split(problem)
    big = np.flatnonzero(sp.sizes >= min_k)
    if not len(big):
        return []
    T, sizes = local_tuples(problem, sp.of_row, sp.n)
    return [subproblem(problem, T, sizes[c], sp.order[sp.ptr[c]:sp.ptr[c + 1]])
            for c in big]


def run_config(n: int, window: int, steps: int, seed: int, repeat: int, min_k: int,
               log) -> dict:
    """One scene: the whole window and its large components at every step."""
    from assocopt.tracking.stonesoup import AssocoptMFA
    from assocopt.tracking.stonesoup.scenario import scan_detections

    parts = scene(n, window, steps, seed)
    sc, out, mm = parts["scenario"], parts["sim"], parts["mm"]
    cached = cached_hypothesiser()
    ours = AssocoptMFA(cached, slide_window=window)
    tracks = parts["tracks"]
    rows = []
    for k, (zs, lab) in enumerate(zip(out.meas, out.labels), start=1):
        t = parts["start"] + timedelta(seconds=k * sc.dt)
        dets = scan_detections(zs, lab, t, mm)
        dtup = tuple(dets)
        cached.table = {tr: parts["fast"].hypothesise(tr, dets, t, dtup) for tr in tracks}
        assoc = ours.associate(set(tracks), dets, t)
        p = ours.last_window.problem
        row = {"step": k, "candidates": int(p.n_candidates), "axes": int(p.ndim),
               "window": timed_pair(p, repeat), "components": []}
        for q in components(p, min_k):
            r = {"candidates": int(q.n_candidates), "sizes": [int(v) for v in q.sizes]}
            r.update(timed_pair(q, repeat))
            row["components"].append(r)
            log(f"{n}x{window} step {k}: component K={r['candidates']} auto "
                f"{r['auto_s'] * 1e3:.1f} ms ({r['auto_solver']}) highs "
                f"{r['highs_s'] * 1e3:.1f} ms")
        rows.append(row)
        advance(assoc, parts["updater"])
    return {"targets": n, "window": window, "steps": rows}


def all_components(result: dict) -> list[dict]:
    return [c for cfg in result["configs"] for s in cfg["steps"] for c in s["components"]]


def _ratio(r: dict) -> float:
    return r["highs_s"] / r["auto_s"]


def targets(result: dict) -> str:
    """The target line: at and above ``TARGET_K`` candidates, never slower than HiGHS."""
    comps = all_components(result)
    big = [c for c in comps if c["candidates"] >= TARGET_K]
    if not big:
        return f"Target: no component of {TARGET_K} candidates or more in this run."
    slower = [c for c in big if c["auto_s"] > c["highs_s"]]
    worst = min(big, key=_ratio)
    return (f"Target: `auto` never slower than HiGHS on a component of at least "
            f"{TARGET_K} candidates: slower on {len(slower)} of {len(big)} "
            f"({'met' if not slower else 'NOT met'}); the smallest ratio HiGHS / `auto` "
            f"there is {_ratio(worst):.1f}x (K = {worst['candidates']}, "
            f"{worst['auto_solver']}); over all {len(comps)} components of at least "
            f"{result['min_candidates']} candidates it is "
            f"{min(_ratio(c) for c in comps):.1f}x, slower on "
            f"{sum(c['auto_s'] > c['highs_s'] for c in comps)}.")


def _checks(result: dict) -> str:
    comps = all_components(result)
    wins = [s["window"] for cfg in result["configs"] for s in cfg["steps"]]
    solved = comps + wins
    proven = sum(r["auto_status"] == "optimal" for r in solved)
    agree = sum(r["agree"] for r in solved)
    return (f"`auto` proved {proven} of {len(solved)} problems optimal (components and "
            f"whole windows); its objective agreed with HiGHS's on {agree} of "
            f"{len(solved)}.")


def render(result: dict) -> str:
    """The markdown page of a result."""
    m = result["machine"]
    lines = [
        "# Multi-frame window components: `auto` beside HiGHS", "",
        f"Generated by `{result['command']}` (the script's docstring says what is "
        f"measured).  The scenes of the multi-frame benchmark (targets crossing in "
        f"pairs, P_D = 0.9, clutter n/2 a scan, {result['steps']} steps, seed "
        f"{result['seed']}), windows of 4-6 scans.  Each window problem is split into "
        f"its connected components; every component of at least "
        f"{result['min_candidates']} candidates is solved on its own by "
        "`solve(component)` and `solve(component, \"highs\")`, interleaved, best of "
        f"{result['repeat']} (milliseconds of wall clock; CPU in brackets).  The "
        "whole window is timed the same way, each solver with its default "
        "decomposition.", "",
        f"Machine: {m['cpu_count']} logical cores, {m['platform']}; Python {m['python']}, "
        f"numpy {m['numpy']}, highspy {m['highspy']}, stonesoup {m['stonesoup']}; load "
        f"average {m['load_start']} at start, {m['load_end']} at end (shared cores: "
        "single timings are upper bounds; ratios are measured side by side).", "",
        targets(result), "", _checks(result), "",
        "## Components", "",
        "| scene | step | candidates | axes | sizes | `auto` route | `auto` ms (CPU) | "
        "HiGHS ms (CPU) | HiGHS / `auto` | same objective |", "|" + "---|" * 10]
    for cfg in result["configs"]:
        for s in cfg["steps"]:
            for c in s["components"]:
                lines.append(
                    f"| {cfg['targets']}x{cfg['window']} | {s['step']} | {c['candidates']} "
                    f"| {len(c['sizes'])} | {tuple(c['sizes'])} | {c['auto_solver']} | "
                    f"{c['auto_s'] * 1e3:.1f} ({c['auto_cpu_s'] * 1e3:.1f}) | "
                    f"{c['highs_s'] * 1e3:.1f} ({c['highs_cpu_s'] * 1e3:.1f}) | "
                    f"{_ratio(c):.1f}x | {'yes' if c['agree'] else 'NO'} |")
    lines += ["", "## Whole windows", "",
              "| scene | steps | candidates (max) | `auto` s (sum) | HiGHS s (sum) | "
              "HiGHS / `auto` | slowest `auto` step s |", "|" + "---|" * 7]
    for cfg in result["configs"]:
        w = [s["window"] for s in cfg["steps"]]
        ta, th = sum(r["auto_s"] for r in w), sum(r["highs_s"] for r in w)
        lines.append(f"| {cfg['targets']}x{cfg['window']} | {len(w)} | "
                     f"{max(s['candidates'] for s in cfg['steps'])} | {ta:.3f} | "
                     f"{th:.3f} | {th / ta:.1f}x | {max(r['auto_s'] for r in w):.3f} |")
    lines.append("")
    return "\n".join(lines)


def main(argv=None) -> dict:
    ap = scene_arguments(__doc__, CONFIGS, 3, "benchmarks-mfa-components")
    ap.add_argument("--min-candidates", type=int, default=1000)
    ap.add_argument("--render", action="store_true", help="only redraw OUT.md from OUT.json")
    args = ap.parse_args(argv)
    out = Path(args.out)
    if args.render:
        out.with_suffix(".md").write_text(render(json.loads(out.with_suffix(".json")
                                                            .read_text())))
        return {}
    import stonesoup
    from importlib.metadata import version

    from mfa import _warm_up
    _warm_up()
    load_start = [round(v, 2) for v in os.getloadavg()]
    configs = []
    for c in args.configs.split(","):
        n, w = (int(v) for v in c.split("x"))
        configs.append(run_config(n, w, args.steps, args.seed, args.repeat,
                                  args.min_candidates, lambda s: print(s, flush=True)))
    result = {"command": command("python benchmarks/mfa_components.py", argv),
              "configs": configs, "repeat": args.repeat, "steps": args.steps,
              "seed": args.seed, "min_candidates": args.min_candidates,
              "machine": machine(load_start, stonesoup=stonesoup.__version__,
                                 highspy=version("highspy"))}
    write_pages(out, result, render)
    return result


if __name__ == "__main__":
    # steady-state speed: kernels compiled in the warm-up (first_use.py measures cold)
    os.environ.setdefault("ASSOCOPT_JIT", "compiled")
    main()
