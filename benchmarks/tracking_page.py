"""The tracker-scan benchmark page, drawn from ``docs/benchmarks-tracking.json`` only.

``benchmarks/sd_tracking.py`` runs the measurements and writes the JSON;
``python benchmarks/sd_tracking.py --render`` redraws ``docs/benchmarks-tracking.md``
from it, and ``tests/test_benchmarks_tracking.py`` checks the committed page.
"""

from __future__ import annotations

#: Scans with a spacing at most this many gate radii are one dense component.
DENSE = 1.0

NAMES = {"auto": "`auto`", "highs": "`highs`", "highs-whole": "`highs`, whole",
         "scipy": "`scipy`", "milp": "plain milp"}


def setting(row: dict) -> tuple:
    s = row["spec"]
    return s["N"], s["n"], s["spacing"], s["clutter"], s["pd"]


def groups(data: dict) -> dict[tuple, list[dict]]:
    """Rows by scan setting (N, n, spacing, clutter), in run order."""
    out: dict[tuple, list[dict]] = {}
    for r in data["scans"]:
        out.setdefault(setting(r), []).append(r)
    return out


def total(rows: list[dict], m: str) -> float | None:
    """Summed time of ``m`` over ``rows`` (None if it did not run on all of them)."""
    if not all(m in r["results"] for r in rows):
        return None
    return sum(r["results"][m]["time"] for r in rows)


def proven(rows: list[dict], m: str) -> int:
    return sum(r["results"][m]["status"] == "optimal" for r in rows if m in r["results"])


def ratio(a: float | None, b: float | None) -> float | None:
    return None if a is None or b is None or b <= 0 else a / b


def _x(v: float | None) -> str:
    return "-" if v is None else f"{v:.1f}x"


def _load(v) -> str:
    return ", ".join(f"{x:.2f}" for x in v)


def summary_table(data: dict) -> list[str]:
    methods = data["options"]["methods"]
    P = ["| N | n | spacing | clutter | P_D | scans | K (mean) | components (largest K) | "
         "gate s | tuples s | " + " | ".join(f"{NAMES[m]} s" for m in methods) +
         " | `highs` / `auto` | plain milp / `auto` |",
         "|" + "---|" * (12 + len(methods))]
    for (N, n, sp, cl, pd), rows in groups(data).items():
        K = sum(r["K"] for r in rows) / len(rows)
        comps = "; ".join(f"{r['results']['auto']['info'].get('components', 1)} "
                          f"({r['results']['auto']['info'].get('largest', r['K'])})"
                          for r in rows)
        cells = []
        for m in methods:
            t = total(rows, m)
            cells.append("-" if t is None else
                         f"{t:.3f} ({proven(rows, m)}/{len(rows)})")
        t_a = total(rows, "auto")
        P.append(f"| {N} | {n} | {sp:g} | {cl:g} | {pd:g} | {len(rows)} | {K:.0f} | {comps} | "
                 f"{sum(r['build'].get('gate_s', 0.0) for r in rows):.3f} | "
                 f"{sum(r['build']['tuples_s'] for r in rows):.3f} | " + " | ".join(cells) +
                 f" | {_x(ratio(total(rows, 'highs'), t_a))} | "
                 f"{_x(ratio(total(rows, 'milp'), t_a))} |")
    return P


def targets(data: dict) -> list[str]:
    """The issue's targets, each with what this run measured."""
    g = groups(data)
    scans = data["scans"]
    ok_all = [r for r in scans if r["results"]["auto"]["status"] == "optimal"
              and r["results"]["auto"]["correct"]]
    slower = [r for r in scans if "highs" in r["results"] and
              r["results"]["auto"]["time"] > r["results"]["highs"]["time"]]
    wrong = [r for r in scans for v in r["results"].values() if not v["correct"]]
    out = [f"- `auto` proves the optimum: {len(ok_all)} of {len(scans)} scans; proven "
           f"objectives that disagree (any method): {len(wrong)}.",
           f"- `auto` never slower than `solver=\"highs\"` on a scan: slower on "
           f"{len(slower)} of {len(scans)}" +
           ("" if not slower else " (" + ", ".join(
               f"N={r['spec']['N']} n={r['spec']['n']} seed {r['spec']['seed']}"
               for r in slower) + ")") + "."]

    def worst(keys, what, num="highs") -> str:
        rs = [(ratio(total(g[k], num), total(g[k], "auto")), k) for k in keys]
        rs = [(v, k) for v, k in rs if v is not None]
        if not rs:
            return f"{what}: no scan"
        v, k = min(rs)
        met = sum(r >= target(what) for r, _ in rs)
        return (f"{what}: {NAMES[num]} / `auto` at least {v:.1f}x (N={k[0]} n={k[1]} "
                f"spacing {k[2]:g}); met on {met} of {len(rs)} settings")
    out.append("- " + worst([k for k in g if k[0] == 3 and k[1] >= 100],
                            "N = 3, n >= 100 (target 5x)"))
    n4 = [k for k in g if k[0] >= 4]
    out.append("- " + worst(n4, "every scan at N >= 4 (target 10x)"))
    out.append("- " + worst(n4, "every scan at N >= 4 (target 50x)", "milp"))
    out.append("- " + worst([k for k in g if k[2] <= DENSE],
                            "one dense component, spacing at or below the gate "
                            "(target 3x)"))
    slow_build = [r for r in scans if r["build"]["tuples_s"] > r["results"]["auto"]["time"]]
    out.append(f"- `gated_tuples` takes longer than `auto`'s solve on {len(slow_build)} of "
               f"{len(scans)} scans" + ("" if not slow_build else " (" + ", ".join(
                   f"N={r['spec']['N']} n={r['spec']['n']} seed {r['spec']['seed']}: "
                   f"{r['build']['tuples_s']:.3f} s against {r['results']['auto']['time']:.3f} s"
                   for r in slow_build) + ")") + ".")
    return out


def target(what: str) -> float:
    """The ratio a target line asks for (read from its ``(target Nx)``)."""
    return float(what.split("(target ")[1].split("x")[0])


def readme_figures(data: dict) -> list[str]:
    """The phrases README.md's Speed section quotes, as rounded here."""
    g = groups(data)
    out = []
    for key in ((3, 1000, 2.0, 0.2, 0.9), (6, 100, 2.0, 0.2, 0.9)):
        if key in g:
            rows = g[key]
            t_a, t_h, t_m = (total(rows, m) for m in ("auto", "highs", "milp"))
            phrase = (f"N = {key[0]} sensors, {key[1]} targets: `solve(p)` "
                      f"{1e3 * t_a / len(rows):.0f} ms per scan, `solver=\"highs\"` "
                      f"{1e3 * t_h / len(rows):.0f} ms")
            if t_m is not None:
                phrase += f", plain `scipy.optimize.milp` {1e3 * t_m / len(rows):.0f} ms"
            out.append(phrase)
    n4 = [k for k in g if k[0] >= 4]
    vh = [v for v in (ratio(total(g[k], "highs"), total(g[k], "auto")) for k in n4)
          if v is not None]
    vm = [v for v in (ratio(total(g[k], "milp"), total(g[k], "auto")) for k in n4)
          if v is not None]
    if vh and vm:
        out.append(f"N >= 4 at 10x: at least {min(vh):.1f}x), "
                   f"50x the plain milp model at N >= 4 on {sum(v >= 50 for v in vm)} of "
                   f"the {len(vm)} settings")
    return out


#: Why the plain model is level with ``highs`` here (no numbers of this run in it).
PLAIN_MILP = (
    "The issues that asked for this benchmark measured their plain "
    "`scipy.optimize.milp` model 3-14 times slower than `solver=\"highs\"`, and set 50x "
    "the plain model as a target, first at N >= 5, then for every scan at N >= 4 "
    "beside 10x against `highs` (on their scans the two asked for about the same).  "
    "Here the plain model (sparse `A`, `mip_rel_gap=0`) runs about as fast as "
    "`highs` through our formulation: both hand HiGHS the same set-partitioning "
    "program.  Variants of the plain model that a first attempt "
    "might write (HiGHS's default gap, a dense `A`, presolve off, `A x = 1` as two "
    "inequalities) did not make it slower than `highs` on our N = 4-5 scans either "
    "(checked by hand; not part of this run).  Their generator is not in the "
    "repository; their scans had many more candidates per target (110k at N = 5, "
    "n = 50, where ours have a few thousand at spacing 2), which is the likeliest "
    "reason their plain model fell behind.  So on these scans the 50x target against "
    "the plain model is in effect a 50x target against HiGHS itself.")


def render(data: dict) -> str:
    env, opt = data["environment"], data["options"]
    P = ["# S-D assignment on tracker scans", "",
         f"Generated by `{env['command']}` on {env['date']} (one process, "
         f"{env['minutes']:.1f} min; numbers from "
         "[benchmarks-tracking.json](benchmarks-tracking.json), a test re-renders this "
         "page and checks it against it).  This machine has "
         f"{env['cores']} cores that other work shared during the run (load averages "
         "below), so single timings are on the slow side; ratios measured side by side "
         "are the robust numbers.", "",
         "## What is measured", "",
         "Scans of `benchmarks/tracking_scans.py`: N position sensors in the plane, n "
         "targets in a square whose side makes the mean target spacing `spacing` gate "
         "radii (4: well separated; below 1: closer than the gate, one dense component), "
         "P_D 0.9 (0.8 to 0.95 in the unseen settings), `clutter * n` false alarms per "
         "sensor, tuples gated pairwise at 99.9 % "
         "(chi-square, 2 dof) and enumerated by `assocopt.tracking.gating.gated_tuples`, "
         "negative log-likelihood-ratio costs.  Each method is timed from the candidate "
         "arrays on: `solve(AssignmentProblem.sparse(sizes, T, c), solver)`; "
         "`highs`, whole: the same with `decompose=False`; plain milp: the binary program "
         "`A x = 1` built from the same arrays and passed to `scipy.optimize.milp` "
         "(`mip_rel_gap=0`, so that its optimum is proven like the others).  "
         f"Solves under 0.5 s are repeated {opt['repeats']} times, interleaved, the "
         f"fastest kept; `solve` runs without a time limit (as a user calls it), plain "
         f"milp with a limit of {opt['time_limit']:g} s; plain milp and `scipy` "
         f"are left out of scans with more than {opt['milp_max']} candidates.  Times are "
         "summed over the scans of a setting; `(p/k)`: proven optimal in p of k.  "
         "The settings with seeds from 31 on (the last ones) were not used while tuning "
         "in the first round; in the second round their settings (not those seeds) were "
         "profiled and tuned on, on seeds 51-53, so they are unseen scans, no longer "
         "unseen settings.  The settings with seeds from 71 on were found after that by "
         "probing for weak spots on seed 41 (large components at spacings 0.8-1.5, "
         "where `auto` had fallen to 4-9x of `highs`) and tuned on seeds 41-42; seeds "
         "71 on were not used for either.  "
         "`components (largest K)`: how `auto` split each scan; `gate s`: the pairwise "
         "gate (KD-trees), `tuples s`: `gated_tuples` (both summed over the scans).  "
         f"The targets count scans with spacing above {DENSE:g} as sparse, the others as "
         "one dense component.", "",
         "## Machine", "",
         f"- CPU: {env['cpu']}, {env['cores']} logical cores; {env['platform']}",
         f"- Python {env['python']}; " + ", ".join(
             f"{d} {v or '(not installed)'}" for d, v in env["versions"].items()),
         f"- load average (1, 5, 15 min) at start: {_load(env['load_start'])}",
         f"- load average at end: {_load(env['load_end'])}", "",
         "## Time to proven optimum", ""]
    P += summary_table(data)
    P += ["", "## Targets of the issue, as measured in this run", ""] + targets(data)
    P += ["", "## Plain milp against `highs`", "", PLAIN_MILP]
    P += ["", "## Log", "", "```"] + data["log"] + ["```"]
    return "\n".join(P) + "\n"
