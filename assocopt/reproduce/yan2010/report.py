"""Paper 001's report: the Markdown tables (ours beside the paper's) and the figures.

Every band is a 95 % normal interval of the mean over runs: ``value +- 1.96 stderr``.
"""

from __future__ import annotations

from typing import Any, Mapping

from .._plot import pyplot, save
from ..runlog import timing_lines
from .experiment import (FIG4_METHODS, LABELS, PAPER_TABLE1, SENS_METHODS, SENS_VARIANTS,
                         TABLE1_METHODS, TABLE1_N)
from .report_grid import (_grid, _variants, confirm_table, grid_tables, section,
                          three_node_tables)

__all__ = ["render_tables", "make_figures", "lookup", "FIG4_TIMES"]

#: Times (s) of the Fig. 4 table.
FIG4_TIMES = (1, 2, 3, 5, 10, 20, 40, 80)
Z95 = 1.96


def lookup(records, experiment: str, metric: str, key: str = "n") -> dict:
    """``{(method, setting[key]): (value, half-width of the 95 % band, runs)}``."""
    out = {}
    for r in records:
        if r["experiment"] == experiment and r["metric"] == metric:
            out[(r["method"], r["setting"].get(key))] = (
                r["value"], Z95 * (r["stderr"] or 0.0), r["runs"])
    return out


def _cell(v, band: bool = True) -> str:
    if v is None:
        return "—"
    return f"{v[0]:.4f} ± {v[1]:.4f}" if band else f"{v[0]:.4f}"


def render_tables(summary: Mapping[str, Any]) -> str:
    """Markdown tables: Table 1 beside the paper's, Fig. 4 as a table, the extras."""
    recs = summary["records"]
    lines: list[str] = []
    c80 = lookup(recs, "table1", "correct_80")
    if c80:
        runs = max(v[2] for v in c80.values())
        lines += section("table1", f"Table 1 — correct association probability at t = 80 s "
                         f"({runs} runs per point; ours ± 95 % band; full coverage)")
        lines += ["| targets | " + " | ".join(str(n) for n in TABLE1_N) + " |",
                  "|---" * (len(TABLE1_N) + 1) + "|",
                  "| paper | " + " | ".join(f"{v:.4f}" for v in PAPER_TABLE1) + " |"]
        for m in TABLE1_METHODS:
            lines.append(f"| ours: {m} | " + " | ".join(_cell(c80.get((m, n)))
                                                        for n in TABLE1_N) + " |")
        diff = [c80[("ds-max", n)][0] - p if ("ds-max", n) in c80 else None
                for n, p in zip(TABLE1_N, PAPER_TABLE1)]
        lines += ["| ds-max − paper | " + " | ".join("—" if d is None else f"{d:+.4f}"
                                                     for d in diff) + " |", ""]
        lines += _extras_table(recs)
    lines += _fig4_table(recs)
    lines += _sensitivity_table(recs)
    lines += grid_tables(summary)
    lines += confirm_table(summary)
    lines += three_node_tables(summary)
    lines += timing_lines(summary, "yan2010", section(
        "timing", "Runs that computed trials (wall time of each invocation)"))
    return "\n".join(lines)


def _extras_table(recs) -> list[str]:
    rows = [("shared_steps", "ds-max", "paper's rule: fraction of scans with a node-2 track "
             "given to two node-1 tracks"),
            ("shared_steps", "ds-assign", "assignment: the same fraction"),
            ("shared_cols", "ds-max", "paper's rule: node-2 tracks shared per scan / n"),
            ("wrong_fixed_final", "ds-max", "paper's rule: tracks fixed to a wrong partner "
             "at 80 s / n"),
            ("fixed_final", "ds-max", "paper's rule: tracks fixed at 80 s / n"),
            ("correct_5", "ds-max", "paper's rule: correct rate at 5 s"),
            ("correct_5", "weighted", "weighted test: correct rate at 5 s")]
    lines = section("table1-extras", "Table 1 settings — what else happens (means over runs)")
    lines += ["| quantity | " + " | ".join(str(n) for n in TABLE1_N) + " |",
             "|---" * (len(TABLE1_N) + 1) + "|"]
    for metric, method, label in rows:
        tab = lookup(recs, "table1", metric)
        if not tab:
            continue
        lines.append(f"| {label} | " + " | ".join(_cell(tab.get((method, n)), band=False)
                                                  for n in TABLE1_N) + " |")
    return lines + [""]


def _fig4_table(recs) -> list[str]:
    tabs = {t: lookup(recs, "fig4", f"correct_{t}") for t in FIG4_TIMES}
    times = [t for t in FIG4_TIMES if tabs[t]]
    if not times:
        return []
    (m0, n), v = next(iter(tabs[times[-1]].items()))
    lines = section("fig4", f"Fig. 4 — correct rate over time, {n} targets ({v[2]} runs; "
                    "± 95 % band)")
    lines += ["| method | " + " | ".join(f"t = {t} s" for t in times) + " |",
             "|---" * (len(times) + 1) + "|"]
    for m in FIG4_METHODS:
        lines.append(f"| {m} | " + " | ".join(_cell(tabs[t].get((m, n))) for t in times)
                     + " |")
    return lines + [""]


def _sensitivity_table(recs) -> list[str]:
    c80 = lookup(recs, "sensitivity", "correct_80", "variant")
    c5 = lookup(recs, "sensitivity", "correct_5", "variant")
    sh = lookup(recs, "sensitivity", "shared_steps", "variant")
    if not c80:
        return []
    runs = max(v[2] for v in c80.values())
    n = next(r["setting"]["n"] for r in recs if r["experiment"] == "sensitivity")
    lines = section("sensitivity", f"Sensitivity (ours) — one open parameter changed at a "
                    f"time, {n} targets ({runs} runs): correct rate at 80 s [at 5 s]")
    lines += ["| variant | " + " | ".join(SENS_METHODS) + " | ds-max shared scans |",
             "|---" * (len(SENS_METHODS) + 2) + "|"]
    for v in SENS_VARIANTS:
        cells = [f"{_cell(c80.get((m, v)), False)} [{_cell(c5.get((m, v)), False)}]"
                 for m in SENS_METHODS]
        lines.append(f"| {v} | " + " | ".join(cells) + f" | {_cell(sh.get(('ds-max', v)), False)} |")
    return lines + [""]


def make_figures(summary: Mapping[str, Any], out) -> list[str]:
    """Fig. 4 (correct rate over time with 95 % bands) and Table 1 as a plot; [] without
    matplotlib."""
    plt = pyplot()
    if plt is None:
        return []
    recs = summary["records"]
    made = []
    series: dict[str, list[tuple[int, float, float]]] = {}
    for r in recs:
        if r["experiment"] == "fig4" and r["metric"].startswith("correct_") and \
                r["metric"][8:].isdigit():
            series.setdefault(r["method"], []).append(
                (int(r["metric"][8:]), r["value"], Z95 * (r["stderr"] or 0.0)))
    if series:
        fig, ax = plt.subplots(figsize=(8, 4.5))
        for m in ("ds-max", "ds-assign", "weighted", "ds-max-pair", "weighted-counter"):
            if m not in series:
                continue
            pts = sorted(series[m])
            t = [p[0] for p in pts]
            y = [p[1] for p in pts]
            h = [p[2] for p in pts]
            line, = ax.plot(t, y, "-" if m in ("ds-max", "weighted") else "--",
                            label=LABELS.get(m, m), lw=1.4)
            ax.fill_between(t, [a - b for a, b in zip(y, h)], [min(1.0, a + b) for a, b in zip(y, h)],
                            color=line.get_color(), alpha=0.2)
        ax.set_xlabel("time (s)")
        ax.set_ylabel("correct association rate")
        ax.grid(alpha=0.3)
        ax.legend(fontsize=7, loc="lower left")
        ax.set_title("yan2010 Fig. 4: correct rate over time (95 % bands)")
        made.append(save(fig, out, "fig4_correct_rate.png"))
    c80 = lookup(recs, "table1", "correct_80")
    if c80:
        fig, ax = plt.subplots(figsize=(7, 4))
        ax.plot(TABLE1_N, PAPER_TABLE1, "ko-", label="paper, Table 1")
        for m in TABLE1_METHODS:
            ns = [n for n in TABLE1_N if (m, n) in c80]
            ax.errorbar(ns, [c80[(m, n)][0] for n in ns], yerr=[c80[(m, n)][1] for n in ns],
                        marker=".", capsize=2, label=f"ours: {LABELS.get(m, m)}")
        ax.set_xlabel("number of targets")
        ax.set_ylabel("correct association probability at t = 80 s")
        ax.grid(alpha=0.3)
        ax.legend(fontsize=7)
        made.append(save(fig, out, "table1_correct_rate.png"))
    made += _grid_figure(plt, recs, out)
    return made


def _grid_figure(plt, recs, out) -> list[str]:
    """The paper's rule (all-track rate at 80 s, no counter and counter) against n for
    every grid setting, with Table 1."""
    tab = _grid(recs)
    if not tab:
        return []
    fig, axes = plt.subplots(1, 2, figsize=(11, 4.2), sharey=True)
    for ax, m, title in ((axes[0], "ds-max", "counter"), (axes[1], "ds-max-nocounter",
                                                           "no counter")):
        ax.plot(TABLE1_N, PAPER_TABLE1, "ko-", label="paper, Table 1", lw=2)
        for v in _variants(recs):
            ns = [n for n in TABLE1_N if (m, v, "all_80", n) in tab]
            ax.plot(ns, [tab[(m, v, "all_80", n)][0] for n in ns], ".-", label=v, lw=1)
        ax.set_title(f"paper's rule, {title}: all-track rate at 80 s")
        ax.set_xlabel("number of targets")
        ax.grid(alpha=0.3)
    axes[0].set_ylabel("correct association rate")
    axes[1].legend(fontsize=6, loc="lower left")
    return [save(fig, out, "grid_rule_all80.png")]
