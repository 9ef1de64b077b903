"""The S-D benchmark page and figure, drawn from ``docs/benchmarks-sd.json`` only.

``benchmarks/sd_scaling.py`` runs the measurements and writes the JSON; this module
turns that JSON into ``docs/benchmarks-sd.md`` and ``docs/benchmarks-sd.png``
(``python benchmarks/sd_scaling.py --render`` does both without running anything), and
``tests/test_benchmarks_sd.py`` re-renders the page from the committed JSON.
"""

from __future__ import annotations

import math
import statistics
from pathlib import Path

AP_FAMILIES = ("grundel", "balas-saltzman")
BASE = "scipy"


# ----------------------------------------------------------------------- helpers
def pct(g: float | None) -> str:
    return "n/a" if g is None else ("inf" if not math.isfinite(g) else f"{100 * g:.3g}%")


def proven(r: dict) -> bool:
    return r["status"] == "optimal"


def correct(r: dict) -> bool:
    return r["info"].get("correct", True)


def ap_rows(data: dict) -> list[dict]:
    """The shared 3-AP instances (Grundel, Balas-Saltzman) of the exact section."""
    return [r for r in data["exact"] if r["family"] in AP_FAMILIES]


def other_rows(data: dict) -> list[dict]:
    return [r for r in data["exact"] if r["family"] not in AP_FAMILIES]


def totals(rows: list[dict], method: str, base: str = BASE) -> tuple[int, float, float]:
    """(instances, method total s, base total s) over the rows both ran."""
    both = [r["results"] for r in rows if method in r["results"] and base in r["results"]]
    return (len(both), sum(r[method]["time"] for r in both),
            sum(r[base]["time"] for r in both))


def _load(v) -> str:
    return ", ".join(f"{x:.2f}" for x in v)


# ----------------------------------------------------------------------- tables
def family_table(rows: list[dict], solvers: list[str]) -> list[str]:
    fams: dict = {}
    for r in rows:
        fams.setdefault((r["family"], r["size"]), []).append(r["results"])
    lines = ["| family | n | instances | " + " | ".join(
        f"{s} total s (proven)" for s in solvers) + " |", "|" + "---|" * (3 + len(solvers))]
    for (fam, n), items in sorted(fams.items()):
        cells = []
        for s in solvers:
            rs = [res[s] for res in items if s in res]
            if not rs:
                cells.append("-")
                continue
            wrong = sum(not correct(r) for r in rs)
            cells.append(f"{sum(r['time'] for r in rs):.3f} ({sum(map(proven, rs))}/"
                         f"{len(rs)}){' WRONG ' + str(wrong) if wrong else ''}")
        lines.append(f"| {fam} | {n} | {len(items)} | " + " | ".join(cells) + " |")
    return lines


def ratio_lines(rows: list[dict], solvers: list[str], base: str = BASE) -> list[str]:
    common = [r for r in rows if base in r["results"] and "lagrangian-exact" in r["results"]]
    if not common:
        return ["(no instance ran both)"]
    out = []
    for s in solvers:
        if s == base:
            continue
        both = [r["results"] for r in common if s in r["results"]]
        if not both:
            continue
        t_s = sum(r[s]["time"] for r in both)
        t_b = sum(r[base]["time"] for r in both)
        ps = sum(proven(r[s]) for r in both)
        pb = sum(proven(r[base]) for r in both)
        out.append(f"| {s} | {len(both)} | {t_s:.2f} | {t_b:.2f} | {t_s / t_b:.4f} "
                   f"(1/{t_b / max(t_s, 1e-9):.1f}) | {ps} | {pb} |")
    return ["| method | instances | method total s | scipy total s | ratio | method proven "
            "| scipy proven |", "|---|---|---|---|---|---|---|"] + out


def targets(data: dict) -> list[str]:
    out = []
    aps = ap_rows(data)
    la = [r["results"]["lagrangian-exact"] for r in aps if "lagrangian-exact" in r["results"]]
    if la:
        k, t_l, t_s = totals(aps, "lagrangian-exact")
        out.append(f"- 3-AP, all {len(la)} instances proven by `lagrangian-exact`: "
                   f"{sum(proven(r) and correct(r) for r in la)}/{len(la)}; "
                   f"on the {k} instances scipy also ran, total "
                   f"{t_l:.2f} s vs {t_s:.2f} s = 1/{t_s / max(t_l, 1e-9):.1f} "
                   "(target: at most 1/10, goal 1/50).")
        _, t_a, t_s = totals(aps, "auto")
        if t_a:
            out.append(f"- Same instances with `auto` (what `solve` picks): {t_a:.2f} s vs "
                       f"{t_s:.2f} s = 1/{t_s / max(t_a, 1e-9):.1f}.")
    cs = [r for r in other_rows(data) if r["family"] == "crama-spieksma"]
    if cs:
        slower = [r["name"] for r in cs if "highs" in r["results"] and
                  r["results"]["lagrangian-exact"]["time"] > r["results"]["highs"]["time"]]
        out.append(f"- LP-gap 3-AP: {sum(proven(r['results']['lagrangian-exact']) for r in cs)}/"
                   f"{len(cs)} proven; slower than HiGHS alone on "
                   f"{len(slower)} ({', '.join(slower) or 'none'}).")
    trk = [r for r in data["plain"] if r["family"].startswith("tracking")]
    if trk:
        worst = max((r["run"]["gap"] or 0.0) for r in trk)
        out.append(f"- Plain `lagrangian`, S-D with dummies, 100 iterations: worst gap "
                   f"{pct(worst)} over {len(trk)} instances (target <= 1%).")
    small = [(g["label"], g["results"]["auto"]) for g in data["latency"]
             if "auto" in g["results"]]
    if small:
        out.append("- `auto` latency, n <= 10 (target <= 1 ms), median (max) over the "
                   "draws: " + "; ".join(f"{label}: {1e3 * v['median_s']:.2f} "
                                         f"({1e3 * v['max_s']:.1f}) ms" for label, v in small)
                   + f"; median at or below 1 ms in "
                   f"{sum(v['median_s'] <= 1e-3 for _, v in small)} of {len(small)} groups.")
    for r in data["lap"]:
        t_sp, t_fb, t_lx = r["scipy_s"], r["scipy_path_s"], r["lapx_s"]
        if t_sp and t_lx:
            out.append(f"- {r['label']}: lapx {t_sp / t_lx:.2f}x faster than scipy "
                       "(target >= 2x when installed).")
        if t_sp and t_fb:
            out.append(f"- {r['label']}: without lapx {t_fb / t_sp:.3f}x scipy's time "
                       "(target <= 1.1x).")
    out.append("- Memory: candidates only (tests/test_lagrangian.py::"
               "test_memory_follows_candidates_not_sizes solves sizes 3000^4 with "
               "~13,500 candidates).")
    return out


# ----------------------------------------------------------------------- figures
def readme_figures(data: dict) -> list[str]:
    """The phrases README.md's Speed section quotes from this page, as rounded here."""
    out = []
    aps = ap_rows(data)
    la = [r["results"]["lagrangian-exact"] for r in aps]
    if la and all(proven(r) and correct(r) for r in la):
        out.append(f"proves all {len(la)} public 3-AP instances optimal in "
                   f"{sum(r['time'] for r in la):.2f} s")
    k, t_l, t_s = totals(aps, "lagrangian-exact")
    if k:
        pb = sum(proven(r["results"][BASE]) for r in aps
                 if BASE in r["results"] and "lagrangian-exact" in r["results"])
        ratio = f"1/{t_s / max(t_l, 1e-9):.1f}" + \
            ("" if pb == k else f"; scipy milp proves {pb} of them")
        out.append(f"scipy milp takes {t_s:.2f} s on all of them ({ratio})" if k == len(aps)
                   else f"on the {k} that scipy milp also ran, {t_l:.2f} s where scipy milp "
                   f"takes {t_s:.2f} s ({ratio})")
    paper = [g for g in data["latency"] if g["label"].startswith("paper 002")
             and "auto" in g["results"] and BASE in g["results"]]
    if paper:
        auto = [1e3 * g["results"]["auto"]["median_s"] for g in paper]
        ref = [1e3 * g["results"][BASE]["median_s"] for g in paper]
        out.append(f"`solve(p)` answers the small S-D problems of a paper-002 Monte Carlo "
                   f"study in {min(auto):.2f}-{max(auto):.2f} ms (median), scipy milp in "
                   f"{min(ref):.2f}-{max(ref):.2f} ms")
    return out


def plot(data: dict, path: Path) -> bool:
    """Median time to proven optimum against n, one panel per shared 3-AP family."""
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        return False
    fig, axes = plt.subplots(1, 2, figsize=(11, 4.2))
    for ax, fam in zip(axes, AP_FAMILIES):
        for s in data["options"]["solvers"]:
            pts: dict = {}
            for r in data["exact"]:
                if r["family"] == fam and s in r["results"]:
                    pts.setdefault(r["size"], []).append(r["results"][s]["time"])
            if pts:
                xs = sorted(pts)
                ax.plot(xs, [statistics.median(pts[x]) for x in xs], marker="o", label=s)
        ax.set_yscale("log")
        ax.set_xlabel("n (3-AP size)")
        ax.set_ylabel("time to proven optimum, s (median)")
        ax.set_title(f"{fam} 3-AP")
        ax.grid(True, which="both", alpha=0.3)
    if axes[0].get_legend_handles_labels()[0]:
        axes[0].legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=110, metadata={"Software": None})
    plt.close(fig)
    return True


# ----------------------------------------------------------------------- page
def _grid_rules() -> str:
    """The dense-grid ascent defaults, in words (from the solver's own table)."""
    from assocopt.solvers.lagrangian.options import GRID_DEFAULTS as g
    return (f"step {g['step0']}, recovery every {g['recover_every']} iterations, "
            f"patience {g['patience']}, stall tolerance {g['stall_tol']}")


_GRID_RULES = _grid_rules()


def _nodes() -> dict[str, str]:
    """The window search's node budgets, in words (from the solver's own constants)."""
    from assocopt.solvers.lagrangian.policy import _OPEN_NODES, _SKIP_NODES
    from assocopt.solvers.lagrangian.window import _COMPILED_NODES
    return {"full": f"{_COMPILED_NODES:,}", "split": f"{_OPEN_NODES:,}",
            "skip": f"{_SKIP_NODES:,}"}


_NODES = _nodes()
_COMPARED = [
    "## What is compared", "",
    "- `lagrangian`: Lagrangian relaxation of N-2 axes to a 2-D assignment "
    "(Pattipati et al. 1992, Deb et al. 1997), Polyak subgradient steps, recursive "
    "2-D recovery plus axis-wise local search; reports bound, objective and gap, "
    "`OPTIMAL` only with a proof.",
    "- `lagrangian-exact`: the same ascent, then reduced-cost fixing with the LAP "
    "duals; the candidates whose bound lies below a threshold T form a *window* "
    "that holds every solution cheaper than T; windows grow until T reaches the "
    "incumbent and are solved by the compiled exact-cover search (numba, up to "
    + _NODES["full"] + " nodes; it stops at the first cover that reaches the bound "
    "the smaller windows proved), then CP-SAT (integer costs, <= 1,500 candidates, "
    "1 s budget) or HiGHS (stopped at the proven bound).  A window of a problem "
    "with dummies that splits into connected components is solved component by "
    "component (`bnb` on each) when a first search of " + _NODES["split"] + " nodes "
    "does not settle it; with integer costs the search may give up on the first "
    "window after " + _NODES["skip"] + " nodes "
    "when the next one holds at least twice its candidates (the larger window "
    "decides; if it gives up too, the first gets the full treatment, and a first "
    "window that comes back goes to CP-SAT or HiGHS directly).  On dense square "
    "axial problems (3-AP) the whole ascent is one compiled kernel (minimum over "
    "the relaxed axis on pre-sorted pair rows, Hungarian method warm-started from "
    "the last iteration's potentials, recovery, axis-wise local search, step and "
    "stall rules: " + _GRID_RULES + " there), as are the fixing bounds; on gated "
    "problems the "
    "evaluation and the recursive recovery are compiled.  Proven optimum, no "
    "tolerance beyond floating-point round-off.",
    "- `auto`: what `solve(p)` picks: `bnb` up to 10,000 candidates (3,000 on dense "
    "square 3-D grids; with dummies 2,000, or 700 where the gated relaxation runs "
    "compiled) and 100 kept-axes indices, else `lagrangian-exact`.  `bnb` runs in "
    "one compiled call: the same relaxation "
    "with a dense Hungarian method, N = 3 primal recovery each iteration, then a "
    "depth-first exact-cover branch and bound on the reduced costs (falls back "
    "to `lagrangian-exact` after 200,000 nodes).",
    "- `highs`: HiGHS MIP through highspy on the full ILP; `scipy`: "
    "scipy.optimize.milp (HiGHS inside scipy); `ortools-cpsat`: CP-SAT on the "
    "exact-cover model (float costs scaled to integers: `FEASIBLE` only; 8 workers, "
    "assocopt's default, on the cores listed below).  Long solves run in a worker "
    "thread that Ctrl-C and the clock can stop; every solve here is given a time "
    "limit, so HiGHS (`highs`, `scipy`) runs with presolve off, as assocopt does under "
    "any time limit (HiGHS presolve does not look at the clock).", "",
    "Why it is fast: the Lagrangian bound is the LP bound at the cost of a few "
    "hundred 2-D assignments, and it prices every candidate: the reduced costs cut "
    "almost every branch of an exact-cover search, which in compiled code visits a "
    "node in about a microsecond, so the windows that HiGHS needed seconds for are "
    "settled in milliseconds.  The MILP solvers spend most of their time in "
    "presolve, the root LP of the full model and heuristics.", ""]


def _machine(env: dict, opt: dict) -> list[str]:
    return ["## Machine", "",
            f"- CPU: {env['cpu']}, {env['cores']} logical cores; {env['platform']}",
            f"- Python {env['python']}; " + ", ".join(
                f"{d} {v or '(not installed)'}" for d, v in env["versions"].items()),
            f"- load average (1, 5, 15 min) at start: {_load(env['load_start'])}",
            f"- load average at end: {_load(env['load_end'])}",
            f"- per-solve time limit {opt['time_limit']:g} s (CP-SAT: "
            f"{opt['cpsat_limit']:g} s); runs stopped by it count with the limit as their "
            f"time; not installed / not registered: {', '.join(opt['missing']) or 'none'}"
            + ("; every back end runs in this process under its own limit "
               "(`isolate=False`: no child process)" if opt.get("in_process") else ""),
            ""]


def _exact(data: dict) -> list[str]:
    opt, solvers = data["options"], data["options"]["solvers"]
    aps = ap_rows(data)
    P = ["## Time to proven optimum", "",
         "Total seconds per family and size; `(p/k)`: proven optimal in p of k runs. "
         "Peers (HiGHS, scipy, CP-SAT) run on every 3-AP instance with n <= 10 and on "
         "20% of each larger size (Grundel instances 1-2 of 10, Balas-Saltzman 1 of 5)" +
         (" (scipy on all 120: `--reference-all`)" if opt["reference_all"] else "") +
         (" (every peer on every instance: `--all-peers`)" if opt["all_peers"] else "") +
         "; `auto` and `lagrangian-exact` on every instance.  Every "
         "proven objective is checked against the recorded optimum (or the other "
         "methods): a mismatch would be flagged WRONG.", ""]
    P += family_table(data["exact"], solvers) + [""]
    la = [r["results"]["lagrangian-exact"] for r in aps if "lagrangian-exact" in r["results"]]
    if la:
        P += [f"`lagrangian-exact` on all {len(la)} shared 3-AP instances: "
              f"{sum(map(proven, la))} proven optimal, "
              f"{sum(not correct(r) for r in la)} wrong, "
              f"total {sum(r['time'] for r in la):.2f} s, slowest "
              f"{max(r['time'] for r in la):.2f} s.", ""]
    P += ["### Ratios against scipy.optimize.milp (same instances, same run)", "",
          "Shared 3-AP instances:", ""] + ratio_lines(aps, solvers) + [""]
    P += ["LP-gap 3-AP and tracking S-D instances:", ""] + \
        ratio_lines(other_rows(data), solvers) + [""]
    if data.get("figure"):
        P += [f"![time to proven optimum versus n]({data['figure']})", ""]
    return P


def _fixed_and_plain(data: dict) -> list[str]:
    methods = ["lagrangian"] + data["options"]["solvers"]
    P = ["## Gap after a fixed time", "",
         f"Each method stopped after {data['options']['fixed_time']:g} s (`time_limit`); "
         "relative gap `(objective - bound) / |objective|` (n/a: no bound or no solution).",
         "", "| instance | K | " + " | ".join(methods) + " |",
         "|---|---|" + "---|" * len(methods)]
    for r in data["fixed"]:
        P.append(f"| {r['name']} | {r['K']} | " +
                 " | ".join(pct(r["results"][s]["gap"]) for s in methods) + " |")
    P += ["", "## Plain `lagrangian`: gap after 100 iterations", "",
          "`solve(p, 'lagrangian', max_iter=100, gap_tol=0)`; each iteration is one pass "
          "over the candidates, one 2-D assignment and the primal recovery.  `LP gap`: "
          "the integrality gap `(optimum - LP) / |optimum|`, with the LP bound rounded up "
          "for integer costs (as every bound is then).  The Lagrangian bound never "
          "exceeds the LP bound, so no Lagrangian method can certify a gap below it: the "
          "1% target is about S-D problems with dummies (tracking), where the LP is "
          "nearly integral; on the LP-gap 3-AP instances the gap shown is at least the "
          "LP gap by construction.", "",
          "| instance | sizes | K | gap | LP gap | iterations | ms / iteration |",
          "|---|---|---|---|---|---|---|"]
    for r in data["plain"]:
        run = r["run"]
        P.append(f"| {r['name']} | {tuple(r['sizes'])} | {r['K']} | {pct(run['gap'])} | "
                 f"{pct(run['info'].get('lp_gap'))} | {run['info'].get('iterations')} | "
                 f"{1e3 * r['per_iteration_s']:.2f} |")
    return P


def _latency_and_lap(data: dict) -> list[str]:
    lat = data["latency"]
    P = ["", "## Small problems: in-process latency of `solver=\"auto\"`", "",
         "Median (max) milliseconds per `solve()` call over the listed problems (distinct "
         "random draws), after warm-up; `auto` picks by the rule above (`bnb` for most "
         "of these small problems).", ""]
    if lat:
        names = list(lat[0]["results"])
        P += ["| problems | K (first) | " + " | ".join(names) + " |",
              "|---|---|" + "---|" * len(names)]
    for g in lat:
        P.append(f"| {g['label']} | {g['K']} | " + " | ".join(
            f"{1e3 * v['median_s']:.2f} ({1e3 * v['max_s']:.1f}), "
            f"{v['optimal']}/{v['count']} optimal" for v in g["results"].values()) + " |")
    P += ["", "## 2-D assignment engines", "",
          "Best of 7 interleaved repeats, in a separate process (lapx from `--lapx-path` "
          "only there, or the installed one).  "
          "`assocopt scipy path`: `linear_assignment(C, 'scipy')`, what runs when lapx "
          "is not installed; `lapx`: `linear_assignment(C, 'lapx')` (lapx's `lapjvh`), "
          "what `auto` and the `lapjv` back end use when it is.", "",
          "| problem | scipy LSA s | assocopt scipy path s | lapx s | scipy / lapx | "
          "scipy path / scipy |", "|---|---|---|---|---|---|"]
    for r in data["lap"]:
        t_sp, t_fb, t_lx = r["scipy_s"], r["scipy_path_s"], r["lapx_s"]
        cells = ["-" if v is None else f"{v:.4f}" for v in (t_sp, t_fb, t_lx)]
        r1 = f"{t_sp / t_lx:.2f}x" if t_sp and t_lx else "-"
        r2 = f"{t_fb / t_sp:.3f}" if t_sp and t_fb else "-"
        P.append(f"| {r['label']} | " + " | ".join(cells) + f" | {r1} | {r2} |")
    return P


def render(data: dict) -> str:
    """The Markdown page, from the JSON only."""
    env = data["environment"]
    P = ["# S-D assignment at scale: Lagrangian relaxation vs MILP/CP solvers", "",
         f"Generated by `{env['command']}` on {env['date']} (one process, "
         f"{env['minutes']:.1f} min; numbers from [benchmarks-sd.json](benchmarks-sd.json), "
         "a test re-renders this page and checks it against it).  "
         "Timings are in-process wall-clock seconds of `assocopt.solve` (model building "
         f"included).  This machine has {env['cores']} cores that other work shared "
         "during the run, so single timings are noisy and on the slow side (see the load "
         "averages below); ratios between methods measured side by side are the robust "
         "numbers.", ""]
    P += _COMPARED + _machine(env, data["options"]) + _exact(data) + _fixed_and_plain(data)
    P += _latency_and_lap(data)
    P += ["", "## Targets of the issue, as measured in this run", ""] + targets(data) + [""]
    P += ["", "## Log", "", "```"] + data["log"] + ["```"]
    return "\n".join(P) + "\n"
