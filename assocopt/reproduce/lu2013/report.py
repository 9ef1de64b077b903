"""Paper 002's report: the Markdown tables (ours beside the paper's) and the figures.
"""

from __future__ import annotations

import math
from typing import Any, Mapping

import numpy as np

from .experiment import (D_GRID, METHODS, PAPER_LABELS, PAPER_TABLES, PRINTED, SIGMAS,
                         TABLE_COLUMNS)

__all__ = ["render_tables", "make_figures"]


def _lookup(records, experiment: str, metric: str, include_volatile=False):
    """{(method, sigma, d[, M]): (value, runs)} for one metric."""
    out = {}
    for r in records:
        if r["experiment"] != experiment or r["metric"] != metric:
            continue
        s = r["setting"]
        key = (r["method"], s["sigma_mrad"], s["d"]) if experiment == "fig" else \
            (r["method"], s["M"], s["sigma_mrad"], s["d"])
        out[key] = (r["value"], r["runs"])
    return out


def _fmt(v) -> str:
    return "—" if v is None or (isinstance(v, float) and math.isnan(v)) else f"{v:.4f}"


def render_tables(summary: Mapping[str, Any]) -> str:
    """Markdown tables: ours beside the paper's, LP statistics, Fig. 2 gains."""
    recs = summary["records"]
    lines: list[str] = []
    cols = " | ".join(f"σ={s:g}, d={d:g}" for s, d in TABLE_COLUMNS)
    tr = _lookup(recs, "tables", "tuple_rate")
    pc = _lookup(recs, "tables", "partition_correct")
    if tr:
        runs = max(v[1] for v in tr.values())
        for k, M in enumerate((5, 10, 15, 20), start=1):
            lines += [f"### Table {k} — M = {M} (correct rate; ours: tuple rate "
                      f"[whole-partition rate], {runs} runs)", "",
                      f"| method | {cols} |", "|---" * 7 + "|"]
            for label, name in PAPER_LABELS.items():
                lines.append(f"| paper: {label} | " + " | ".join(
                    f"{v:.4f}" for v in PAPER_TABLES[M][label]) + " |")
            for m in METHODS:
                cells = []
                for s, d in TABLE_COLUMNS:
                    a = tr.get((m, M, s, d), (None, 0))[0]
                    b = pc.get((m, M, s, d), (None, 0))[0]
                    cells.append(f"{_fmt(a)} [{_fmt(b)}]")
                lines.append(f"| ours: {m} | " + " | ".join(cells) + " |")
            lines.append("")
        lines += _paired_table(recs)
        lines += _lp_table(recs)
    fig = _lookup(recs, "fig", "partition_correct")
    if fig:
        lines += _fig_gain_table(recs)
    return "\n".join(lines)


def _paired_table(recs) -> list[str]:
    """Paired difference of the tuple rate against ref. [2] (pattipati), +- 2 SE."""
    tab = {}
    for r in recs:
        if r["experiment"] == "tables" and r["metric"] == "tuple_rate - pattipati":
            st = r["setting"]
            tab[(r["method"], st["M"], st["sigma_mrad"], st["d"])] = (r["value"], r["stderr"])
    if not tab:
        return []
    cols = " | ".join(f"σ={s:g}, d={d:g}" for s, d in TABLE_COLUMNS)
    lines = ["### Tuple rate minus ref. [2] (pattipati), paired, ± 2 standard errors "
             "(percentage points)", "", f"| M | method | {cols} |", "|---|---" + "|---" * 6 + "|"]
    for M in (5, 10, 15, 20):
        for m in METHODS[1:]:
            cells = []
            for s, d in TABLE_COLUMNS:
                v = tab.get((m, M, s, d))
                cells.append("—" if v is None else
                             f"{100 * v[0]:+.2f} ± {200 * (v[1] or 0):.2f}")
            lines.append(f"| {M} | {m} | " + " | ".join(cells) + " |")
    paper = ["", "Paper, same difference (points): "]
    for M in (5, 10, 15, 20):
        k = [f"{100 * (a - b):+.2f}" for a, b in zip(PAPER_TABLES[M]["KLD"],
                                                       PAPER_TABLES[M]["ref. [2]"])]
        sk = [f"{100 * (a - b):+.2f}" for a, b in zip(PAPER_TABLES[M]["SKLD"],
                                                        PAPER_TABLES[M]["ref. [2]"])]
        paper.append(f"M={M}: KLD {' '.join(k)}; SKLD {' '.join(sk)}.")
    return lines + paper + [""]


def _lp_table(recs) -> list[str]:
    li = _lookup(recs, "tables", "lp_integral")
    rw = _lookup(recs, "tables", "lp_round_wrong")
    ri = _lookup(recs, "tables", "lp_round_infeasible")
    gap = _lookup(recs, "tables", "gap")
    lines = ["### LP relaxation (the paper's LP_SOLVE method), all 24 settings pooled", "",
             "| method | LP integral | rounding infeasible | rounding wrong | max gap of "
             "solution used |", "|---|---|---|---|---|"]
    for m in METHODS:
        keys = [k for k in li if k[0] == m]
        if not keys:
            continue
        n = sum(li[k][1] for k in keys)
        f = lambda tab: sum(tab[k][0] * tab[k][1] for k in keys if k in tab) / n  # noqa: E731
        g = max((gap[k][0] for k in keys if k in gap), default=math.nan)
        lines.append(f"| {m} | {f(li):.4f} | {f(ri):.4f} | {f(rw):.4f} | {g:.2e} |")
    lines += ["", "LP integral, by setting (all methods and d pooled):", "",
              "| M | σ=1.5 | σ=5 |", "|---|---|---|"]
    for M in (5, 10, 15, 20):
        cells = []
        for sg in SIGMAS:
            keys = [k for k in li if k[1] == M and k[2] == sg]
            n = sum(li[k][1] for k in keys)
            cells.append(f"{sum(li[k][0] * li[k][1] for k in keys) / n:.4f}" if n else "—")
        lines.append(f"| {M} | " + " | ".join(cells) + " |")
    lines.append("")
    return lines


def _fig_gain_table(recs) -> list[str]:
    pc = _lookup(recs, "fig", "partition_correct")
    lines = ["### Fig. 2 — mean correct rate over d = 0:0.05:1.5, and gain over ref. [2] "
             "(percentage points)", "",
             "| method | σ=1.5 rate | σ=1.5 gain | σ=5 rate | σ=5 gain |", "|---|---|---|---|---|"]
    base = {s: np.mean([pc[("pattipati", s, d)][0] for d in D_GRID if ("pattipati", s, d) in pc])
            for s in SIGMAS}
    for m in METHODS:
        row = [m]
        for s in SIGMAS:
            vals = [pc[(m, s, d)][0] for d in D_GRID if (m, s, d) in pc]
            if not vals:
                row += ["—", "—"]
                continue
            mean = float(np.mean(vals))
            row += [f"{mean:.4f}", f"{100 * (mean - base[s]):+.2f}"]
        lines.append("| " + " | ".join(row) + " |")
    lines += ["", "Paper (Fig. 2 text): KLD +0.23 (σ=1.5), +0.2 (σ=5); SKLD +0.78 (σ=1.5), "
              "+1.4 (σ=5); '%', unit (points or relative) not given.", ""]
    return lines


def make_figures(summary: Mapping[str, Any], out) -> list[str]:
    """Fig. 1 (r versus d) and Fig. 2 (correct rate versus d) as PNG; [] without matplotlib."""
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        return []
    recs = summary["records"]
    made = []
    specs = [("fig1_r.png", "r_data", "r = C_best / C_ave, constants dropped",
              (-0.05, 1.05)),
             ("fig1_r_full.png", "r_full", "r on the costs as printed (radians)", None),
             ("fig2_correct.png", "partition_correct", "correct association rate", None)]
    for fname, metric, ylabel, ylim in specs:
        tab = _lookup(recs, "fig", metric)
        if not tab:
            continue
        fig, axes = plt.subplots(1, 2, figsize=(11, 4.2), sharex=True)
        for ax, s in zip(axes, SIGMAS):
            for m in METHODS:
                ds = [d for d in D_GRID if (m, s, d) in tab]
                ys = [tab[(m, s, d)][0] for d in ds]
                style = "-" if m in PRINTED else "--"
                label = m
                if ylim is not None and any(not (ylim[0] <= y <= ylim[1]) for y in ys):
                    label += " (leaves the axis)"
                ax.plot(ds, ys, style, label=label, lw=1.4)
            if ylim is not None:
                ax.set_ylim(*ylim)
            ax.set_title(f"σ = {s:g} mrad")
            ax.set_xlabel("target spacing d (km, unit ours)")
            ax.set_ylabel(ylabel)
            ax.grid(alpha=0.3)
        runs = max(v[1] for v in tab.values())
        axes[0].legend(fontsize=7)
        fig.suptitle(f"lu2013 {fname.split('_')[0]}: {metric}, {runs} runs per point")
        fig.tight_layout()
        fig.savefig(out / fname, dpi=110)
        plt.close(fig)
        made.append(fname)
    return made
