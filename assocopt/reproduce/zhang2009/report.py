"""Paper 000's report: paired differences, the Markdown tables (ours beside the
paper's Table 1) and the figures.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any, Mapping

import numpy as np

from ...experiments import Experiment
from .experiment import LABELS, MAIN_METHODS, PAPER_TABLE1, R, TABLE1_METHODS, TABLE1_PD, W

__all__ = ["paired_differences", "render_tables", "make_figures", "PAIRS"]


#: Paired comparisons (same simulated runs): (experiment, method A, method B).
PAIRS = (("main", "ncr+nd", "tbm+nd"), ("weights", "ncr+nd", "wa+nd"),
         ("main", "ncr+2da", "ncr+nd"), ("main", "ncr+2da-rect", "ncr+nd"))


def paired_differences(store: Path, exp: Experiment,
                       metric: str = "correct_rate") -> list[dict[str, Any]]:
    """Mean and standard error of the per-run difference A - B of ``metric``.

    Both methods decide on the same simulated runs, so the paired standard error is
    much smaller than the two curves' own.
    """
    from ...experiments import ResultStore, setting_key
    part = exp.params["experiment"]
    wanted = [(a, b) for e, a, b in PAIRS if e == part and {a, b} <= set(exp.methods)]
    if not wanted:
        return []
    keys = {setting_key(s): s for s in exp.settings}
    vals: dict[tuple[str, str], dict[int, float]] = {}
    with ResultStore(store) as st:
        for s, m, t, metrics in st.rows():
            if s in keys and t < exp.runs and metrics.get(metric) is not None:
                vals.setdefault((s, m), {})[t] = metrics[metric]
    out = []
    for k, setting in keys.items():
        for a, b in wanted:
            va, vb = vals.get((k, a), {}), vals.get((k, b), {})
            common = sorted(set(va) & set(vb))
            if len(common) < 2:
                continue
            d = np.array([va[t] - vb[t] for t in common])
            out.append({"experiment": part, "setting": {x: setting[x] for x in
                                                       ("sweep", "f", "p_d", "k") if x in setting},
                        "method": f"{a} - {b}", "metric": metric, "value": float(d.mean()),
                        "stderr": float(d.std(ddof=1) / math.sqrt(len(d))), "runs": len(d)})
    return out


def _paired_table(summary) -> list[str]:
    rows = summary.get("paired", [])
    if not rows:
        return []
    lines = ["### Paired differences of P_c (same simulated runs; mean ± standard error)", "",
             "| experiment | sweep | f | P_d | k | A - B | mean | s.e. |",
             "|---|---|---|---|---|---|---|---|"]
    for r in rows:
        s = r["setting"]
        lines.append(f"| {r['experiment']} | {s['sweep']} | {s['f']:g} | {s['p_d']:g} | "
                     f"{s.get('k', '')} | {r['method']} | {r['value']:+.4f} | {r['stderr']:.4f} |")
    return lines + [""]


def _lookup(records, experiment: str, metric: str, sweep: str | None = None):
    """{(method, x): (value, runs, stderr)} with x = f, p_d or k depending on the sweep."""
    out = {}
    for r in records:
        s = r["setting"]
        if r["experiment"] != experiment or r["metric"] != metric:
            continue
        if sweep is not None and s.get("sweep") != sweep:
            continue
        x = {"f": s.get("f"), "p_d": s.get("p_d"), "k": s.get("k"),
             "table1": s.get("p_d"), "sensitivity": s.get("f")}[s["sweep"]]
        out[(r["method"], x)] = (r["value"], r["runs"], r.get("stderr"))
    return out


def _f(v, digits=3) -> str:
    return "—" if v is None or (isinstance(v, float) and math.isnan(v)) else f"{v:.{digits}f}"


def _sweep_table(recs, experiment, sweep, methods, metric, xname, title) -> list[str]:
    tab = _lookup(recs, experiment, metric, sweep)
    if not tab:
        return []
    xs = sorted({x for (_, x) in tab})
    runs = max(v[1] for v in tab.values())
    se = max((v[2] or 0.0) for v in tab.values())
    lines = [f"### {title} ({runs} runs per point; largest standard error {se:.3f})", "",
             f"| {xname} | " + " | ".join(LABELS.get(m, m) for m in methods) + " |",
             "|---" * (len(methods) + 1) + "|"]
    for x in xs:
        lines.append(f"| {x:g} | " + " | ".join(_f(tab.get((m, x), (None,))[0])
                                               for m in methods) + " |")
    return lines + [""]


def render_tables(summary: Mapping[str, Any]) -> str:
    """Markdown tables: ours, with the paper's Table 1 beside ours."""
    recs = summary["records"]
    L: list[str] = []
    L += _sweep_table(recs, "main", "f", ("tbm+nd", "ncr+nd"), "correct_rate", "f",
                      "Exp. 1a / Fig. 1 — P_c versus f (P_d fixed)")
    L += _sweep_table(recs, "main", "p_d", ("tbm+nd", "ncr+nd"), "correct_rate", "P_d",
                      "Exp. 1a / Fig. 2 — P_c versus P_d (f fixed)")
    L += _weights_table(recs)
    L += _sweep_table(recs, "main", "f", ("ncr+nd", "ncr+2da", "ncr+2da-rect"),
                      "correct_rate", "f", "Exp. 2 / Fig. 4 — P_c versus f (P_d fixed)")
    L += _sweep_table(recs, "main", "p_d", ("ncr+nd", "ncr+2da", "ncr+2da-rect"),
                      "correct_rate", "P_d", "Exp. 2 / Fig. 5 — P_c versus P_d (f fixed)")
    L += _sweep_table(recs, "main", "f", MAIN_METHODS, "all_correct", "f",
                      "Fraction of runs entirely correct versus f")
    L += _table1(summary)
    L += _paired_table(summary)
    if any(r["experiment"] == "sensitivity" for r in recs):
        ms = [m for m in summary["methods"] if any(
            r["experiment"] == "sensitivity" and r["method"] == m for r in recs)]
        ms = sorted(ms, key=lambda m: (("2da" in m), m))
        L += _sweep_table(recs, "sensitivity", "sensitivity", ms, "correct_rate", "f",
                          "Ours — sensitivity of MD-2DA to alpha (tau) and of MD-ND to "
                          "its readings (P_d fixed)")
    return "\n".join(L)


def _weights_table(recs) -> list[str]:
    tab = _lookup(recs, "weights", "correct_rate", "k")
    if not tab:
        return []
    runs = max(v[1] for v in tab.values())
    lines = [f"### Exp. 1b / Fig. 3 — P_c versus k ({runs} runs per point)", "",
             "| k | w_p | w_a | r_p | r_a | MM-WA | MM-NCR |", "|---|---|---|---|---|---|---|"]
    for k in range(1, 11):
        if ("wa+nd", k) not in tab:
            continue
        lines.append(f"| {k} | {W[0][k-1]:g} | {W[1][k-1]:g} | {R[0][k-1]:g} | {R[1][k-1]:g} | "
                     f"{_f(tab[('wa+nd', k)][0])} | {_f(tab[('ncr+nd', k)][0])} |")
    return lines + [""]


def _table1(summary) -> list[str]:
    recs = summary["records"]
    t = _lookup(recs, "table1", "t_decide", "table1")
    b = _lookup(recs, "table1", "t_backend", "table1")
    if not t:
        return []
    runs = max(v[1] for v in t.values())
    solver = summary["parameters"]["run"]["md2da_solver"]
    cols = " | ".join(f"{p:g}" for p in TABLE1_PD)
    lines = [f"### Table 1 — decision time (s) versus P_d (f = "
             f"{summary['parameters']['ours']['table1_f']}; ours: mean of {runs} runs)", "",
             f"| method | {cols} |", "|---" * (len(TABLE1_PD) + 1) + "|"]
    for k, v in PAPER_TABLE1.items():
        lines.append(f"| paper: {k} | " + " | ".join(f"{x:.3g}" for x in v) + " |")
    lines.append("| paper: ratio 2DA/ND | " + " | ".join(
        f"{a / n:.1f}" for a, n in zip(PAPER_TABLE1["MD-2DA"], PAPER_TABLE1["MD-ND"])) + " |")
    rows = [("ours: MD-ND (truncation, Python)", t, "ncr+nd"),
            (f"ours: MD-2DA via solve(), {solver}", t, "ncr+2da"),
            (f"ours: MD-2DA, {solver} back end only", b, "ncr+2da"),
            ("ours: MD-2DA via solve(), highs (ILP)", t, "ncr+2da-highs"),
            ("ours: MD-2DA, highs back end only", b, "ncr+2da-highs")]
    for label, tab, m in rows:
        lines.append(f"| {label} | " + " | ".join(
            f"{tab[(m, p)][0]:.3g}" if (m, p) in tab else "—" for p in TABLE1_PD) + " |")
    lines.append(f"| ours: ratio 2DA ({solver}, solve())/ND | " + " | ".join(
        f"{t[('ncr+2da', p)][0] / t[('ncr+nd', p)][0]:.1f}"
        if ("ncr+2da", p) in t and ("ncr+nd", p) in t else "—" for p in TABLE1_PD) + " |")
    pc = _lookup(recs, "table1", "correct_rate", "table1")
    for m in TABLE1_METHODS:
        lines.append(f"| ours: P_c {LABELS.get(m, m)} | " + " | ".join(
            _f(pc.get((m, p), (None,))[0]) for p in TABLE1_PD) + " |")
    return lines + [""]


# ----------------------------------------------------------------- figures
def make_figures(summary: Mapping[str, Any], out) -> list[str]:
    """Figs. 1-5, Table 1 and the sensitivity study as PNG; [] without matplotlib."""
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        return []
    out = Path(out)
    recs = summary["records"]
    made: list[str] = []

    def curve(fname, experiment, sweep, methods, xlabel, title, metric="correct_rate"):
        tab = _lookup(recs, experiment, metric, sweep)
        if not tab:
            return
        fig, ax = plt.subplots(figsize=(6, 4.2))
        for m in methods:
            xs = sorted(x for (mm, x) in tab if mm == m)
            ys = np.array([tab[(m, x)][0] for x in xs])
            se = np.array([tab[(m, x)][2] or 0.0 for x in xs])
            ax.errorbar(xs, ys, yerr=1.96 * se, marker="o", ms=3, capsize=2,
                        label=LABELS.get(m, m))
        runs = max(v[1] for v in tab.values())
        ax.set_xlabel(xlabel)
        ax.set_ylabel("correct matching rate P_c" if metric == "correct_rate" else metric)
        ax.set_title(f"{title}\n(ours, {runs} runs per point, 95% CI)", fontsize=10)
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8)
        fig.tight_layout()
        fig.savefig(out / fname, dpi=110)
        plt.close(fig)
        made.append(fname)

    curve("fig1_pc_vs_f_measures.png", "main", "f", ("tbm+nd", "ncr+nd"), "noise factor f",
          "Fig. 1: MM-TBM vs MM-NCR (truncation)")
    curve("fig2_pc_vs_pd_measures.png", "main", "p_d", ("tbm+nd", "ncr+nd"),
          "detection probability P_d", "Fig. 2: MM-TBM vs MM-NCR (truncation)")
    curve("fig3_pc_vs_k.png", "weights", "k", ("wa+nd", "ncr+nd"), "k (w(:,k) for MM-WA, "
          "r(:,k) for MM-NCR)", "Fig. 3: MM-WA vs MM-NCR (truncation)")
    curve("fig4_pc_vs_f_decisions.png", "main", "f", ("ncr+nd", "ncr+2da", "ncr+2da-rect"),
          "noise factor f", "Fig. 4: MD-ND vs MD-2DA (MM-NCR)")
    curve("fig5_pc_vs_pd_decisions.png", "main", "p_d", ("ncr+nd", "ncr+2da", "ncr+2da-rect"),
          "detection probability P_d", "Fig. 5: MD-ND vs MD-2DA (MM-NCR)")
    sens = sorted({r["method"] for r in recs if r["experiment"] == "sensitivity"},
                  key=lambda m: (("2da" in m), m))
    curve("sensitivity.png", "sensitivity", "sensitivity", sens, "noise factor f",
          "Ours: MD-2DA gate level and MD-ND readings")

    t = _lookup(recs, "table1", "t_decide", "table1")
    if t:
        fig, ax = plt.subplots(figsize=(6, 4.2))
        ax.semilogy(TABLE1_PD, PAPER_TABLE1["MD-2DA"], "k--s", label="paper: MD-2DA")
        ax.semilogy(TABLE1_PD, PAPER_TABLE1["MD-ND"], "k--o", label="paper: MD-ND")
        solver = summary["parameters"]["run"]["md2da_solver"]
        for m, lab in (("ncr+nd", "ours: MD-ND"), ("ncr+2da", f"ours: MD-2DA ({solver})"),
                       ("ncr+2da-highs", "ours: MD-2DA (highs)")):
            xs = [p for p in TABLE1_PD if (m, p) in t]
            ax.semilogy(xs, [t[(m, p)][0] for p in xs], "-o", ms=3, label=lab)
        ax.set_xlabel("detection probability P_d")
        ax.set_ylabel("seconds per decision")
        ax.set_title("Table 1: decision time (paper's hardware not given)", fontsize=10)
        ax.grid(alpha=0.3, which="both")
        ax.legend(fontsize=8)
        fig.tight_layout()
        fig.savefig(out / "table1_time.png", dpi=110)
        plt.close(fig)
        made.append("table1_time.png")
    return made
