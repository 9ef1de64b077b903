"""Tables and figures of the paper-000 reproduction (Zhang et al. 2009), from its summary.

Pure functions of ``summary.json`` (:func:`render_tables`, :func:`make_figures`): the
committed ``tables.md`` can be checked against the committed summary.  Each section
of ``tables.md`` opens with ``<!-- section: NAME -->``; ``docs/papers/zhang2009.md``
includes the sections by name (:mod:`assocopt.reproduce.pages`).
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any, Mapping

import numpy as np

from .._plot import pyplot, save
from ..runlog import command, timing_lines  # noqa: F401  (command: re-exported)

__all__ = ["render_tables", "make_figures", "expected_matchings"]

MAIN_METHODS = ("tbm+nd", "ncr+nd", "ncr+2da", "ncr+2da-rect")
DECISIONS = ("ncr+nd", "ncr+2da", "ncr+2da-rect")
TABLE1_METHODS = ("ncr+nd", "ncr+2da", "ncr+2da-highs")


def _label(summary, m: str) -> str:
    return summary["methods"].get(m, {}).get("label", m)


def _lookup(records, experiment: str, metric: str, sweep: str | None = None):
    """{(method, x): record} with x = f, p_d or k depending on the sweep."""
    out = {}
    for r in records:
        s = r["setting"]
        if r["experiment"] != experiment or r["metric"] != metric:
            continue
        if sweep is not None and s.get("sweep") != sweep:
            continue
        x = {"f": s.get("f"), "p_d": s.get("p_d"), "k": s.get("k"),
             "table1": s.get("p_d"), "sensitivity": s.get("f")}[s["sweep"]]
        out[(r["method"], x)] = r
    return out


def _f(v, digits=3) -> str:
    return "—" if v is None or (isinstance(v, float) and math.isnan(v)) else f"{v:.{digits}f}"


def _section(name: str, title: str) -> list[str]:
    return [f"<!-- section: {name} -->", f"### {title}", ""]


def _sweep_table(summary, name, experiment, sweep, methods, metric, xname, title) -> list[str]:
    tab = _lookup(summary["records"], experiment, metric, sweep)
    if not tab:
        return []
    xs = sorted({x for (_, x) in tab})
    runs = max(r["runs"] for r in tab.values())
    se = max((r["stderr"] or 0.0) for r in tab.values())
    L = _section(name, f"{title} ({runs} runs per point; largest standard error {se:.3f})")
    L += [f"| {xname} | " + " | ".join(_label(summary, m) for m in methods) + " |",
          "|---" * (len(methods) + 1) + "|"]
    for x in xs:
        L.append(f"| {x:g} | " + " | ".join(_f(tab[(m, x)]["value"]) if (m, x) in tab else "—"
                                           for m in methods) + " |")
    return L + [""]


def _weights_table(summary) -> list[str]:
    tab = _lookup(summary["records"], "weights", "correct_rate", "k")
    if not tab:
        return []
    W, R = summary["parameters"]["paper"]["w"], summary["parameters"]["paper"]["r"]
    runs = max(r["runs"] for r in tab.values())
    L = _section("fig3", f"Exp. 1b / Fig. 3 — P_c versus k ({runs} runs per point)")
    L += ["| k | w_p | w_a | r_p | r_a | MM-WA | MM-NCR |", "|---|---|---|---|---|---|---|"]
    for k in range(1, 11):
        if ("wa+nd", k) not in tab:
            continue
        L.append(f"| {k} | {W[0][k-1]:g} | {W[1][k-1]:g} | {R[0][k-1]:g} | {R[1][k-1]:g} | "
                 f"{_f(tab[('wa+nd', k)]['value'])} | {_f(tab[('ncr+nd', k)]['value'])} |")
    L.append("")
    L.append("Spread over k (derived): " + "; ".join(
        f"{_label(summary, m)} {min(v):.3f}–{max(v):.3f} (range {max(v) - min(v):.3f})"
        for m in ("ncr+nd", "wa+nd")
        if (v := [tab[(m, k)]["value"] for k in range(1, 11) if (m, k) in tab])) + ".")
    return L + [""]


def expected_matchings(p_d: float, n: int = 9) -> tuple[float, float]:
    """Expected numbers of (a) feasible one-to-one matchings with non-assignment,
    ``sum_k C(N1, k) C(N2, k) k!``, and (b) complete assignments of ``min(N1, N2)``
    pairs, ``max! / (max - min)!``, for ``N1, N2 ~ Binomial(n, p_d)`` independent."""
    pmf = [math.comb(n, k) * p_d ** k * (1 - p_d) ** (n - k) for k in range(n + 1)]
    feas = comp = 0.0
    for a in range(n + 1):
        for b in range(n + 1):
            w = pmf[a] * pmf[b]
            if w == 0.0:
                continue
            feas += w * sum(math.comb(a, k) * math.comb(b, k) * math.factorial(k)
                            for k in range(min(a, b) + 1))
            comp += w * math.perm(max(a, b), min(a, b))
    return feas, comp


def _table1(summary) -> list[str]:
    recs = summary["records"]
    t = _lookup(recs, "table1", "t_decide", "table1")
    b = _lookup(recs, "table1", "t_backend", "table1")
    if not t:
        return []
    pds = summary["paper_values"]["table1_p_d"]
    paper = summary["paper_values"]["table1"]
    runs = max(r["runs"] for r in t.values())
    solver = summary["parameters"]["run"]["md2da_solver"]
    cols = " | ".join(f"{p:g}" for p in pds)
    L = _section("table1", f"Table 1 — decision time (s) versus P_d (f = "
                 f"{summary['parameters']['ours']['table1_f']}; ours: mean of {runs} runs "
                 "inside the worker processes)")
    L += [f"| method | {cols} |", "|---" * (len(pds) + 1) + "|"]
    for k, v in paper.items():
        L.append(f"| paper: {k} | " + " | ".join(f"{x:g}" for x in v) + " |")
    L.append("| paper: ratio MD-2DA / MD-ND (derived) | " + " | ".join(
        f"{a / n:.1f}" for a, n in zip(paper["MD-2DA"], paper["MD-ND"])) + " |")
    e_t = _lookup(recs, "table1-enum", "t_decide_finished", "table1")
    e_all = _lookup(recs, "table1-enum", "t_decide", "table1")
    e_stop = _lookup(recs, "table1-enum", "stopped", "table1")
    m_enum = "ncr+2da-enum"
    if e_all:
        nodes = summary["parameters"]["run"].get("enum_max_nodes")
        L.append("| ours: MD-2DA by enumeration, runs that finished: mean | " + " | ".join(
            f"{e_t[(m_enum, p)]['value']:.3g} ({e_t[(m_enum, p)]['runs']} runs)"
            if (m_enum, p) in e_t else "— (none finished)" for p in pds) + " |")
        L.append(f"| ours: MD-2DA by enumeration, runs stopped at {nodes:,} search nodes | " +
                 " | ".join(f"{round(e_stop[(m_enum, p)]['value'] * e_stop[(m_enum, p)]['runs'])}"
                            f" of {e_stop[(m_enum, p)]['runs']}" if (m_enum, p) in e_stop else "—"
                            for p in pds) + " |")
        L.append("| ours: MD-2DA by enumeration, all runs (stopped ones until the stop: a "
                 "lower bound) | " + " | ".join(
                     f"{e_all[(m_enum, p)]['value']:.3g}" if (m_enum, p) in e_all else "—"
                     for p in pds) + " |")
    rows = [("ours: MD-ND (truncation, Python)", t, "ncr+nd"),
            (f"ours: MD-2DA via solve(), {solver}", t, "ncr+2da"),
            (f"ours: MD-2DA, {solver} back end only", b, "ncr+2da"),
            ("ours: MD-2DA via solve(), highs (ILP)", t, "ncr+2da-highs"),
            ("ours: MD-2DA, highs back end only", b, "ncr+2da-highs")]
    for label, tab, m in rows:
        L.append(f"| {label} | " + " | ".join(
            f"{tab[(m, p)]['value']:.3g}" if (m, p) in tab else "—" for p in pds) + " |")
    L.append(f"| ours: ratio MD-2DA ({solver}, solve()) / MD-ND (derived) | " + " | ".join(
        f"{t[('ncr+2da', p)]['value'] / t[('ncr+nd', p)]['value']:.1f}"
        if ("ncr+2da", p) in t and ("ncr+nd", p) in t else "—" for p in pds) + " |")
    ex = [expected_matchings(p) for p in pds]
    L.append("| derived: expected number of feasible matchings (what enumeration visits) | " +
             " | ".join(f"{a:.3g}" for a, _ in ex) + " |")
    L.append("| derived: expected number of complete assignments of min(N1, N2) pairs | " +
             " | ".join(f"{c:.3g}" for _, c in ex) + " |")
    L.append("| derived: the same, relative to P_d = 0.5 | " + " | ".join(
        f"{c / ex[0][1]:.0f}" for _, c in ex) + " |")
    L.append("| derived: paper's MD-2DA time relative to P_d = 0.5 | " + " | ".join(
        f"{a / paper['MD-2DA'][0]:.0f}" for a in paper["MD-2DA"]) + " |")
    nf = _lookup(recs, "table1-enum", "n_feasible", "table1")
    if nf:
        L.append("| ours: feasible matchings enumerated, runs that finished: mean | " +
                 " | ".join(f"{nf[(m_enum, p)]['value']:.3g}" if (m_enum, p) in nf else "—"
                            for p in pds) + " |")
    pc = _lookup(recs, "table1", "correct_rate", "table1")
    for m in TABLE1_METHODS:
        L.append(f"| ours: P_c {_label(summary, m)} | " + " | ".join(
            _f(pc[(m, p)]["value"]) if (m, p) in pc else "—" for p in pds) + " |")
    epc = _lookup(recs, "table1-enum", "correct_rate", "table1")
    if epc:
        L.append(f"| ours: P_c {_label(summary, m_enum)}, runs that finished | " + " | ".join(
            _f(epc[(m_enum, p)]["value"]) if (m_enum, p) in epc else "—" for p in pds) + " |")
    return L + [""]


def _paired_table(summary) -> list[str]:
    rows = summary.get("paired", [])
    if not rows:
        return []
    L = _section("paired", "Paired differences of P_c (same simulated runs; mean ± "
                 "standard error)")
    L += ["| experiment | sweep | f | P_d | k | A - B | mean | s.e. |",
          "|---|---|---|---|---|---|---|---|"]
    for r in rows:
        s = r["setting"]
        L.append(f"| {r['experiment']} | {s['sweep']} | {s['f']:g} | {s['p_d']:g} | "
                 f"{s.get('k', '')} | {r['method']} | {r['value']:+.4f} | {r['stderr']:.4f} |")
    return L + [""]


def _paired_summary(summary) -> list[str]:
    """Per comparison and sweep: where A is ahead / behind / level, and the extremes."""
    rows = summary.get("paired", [])
    if not rows:
        return []
    groups: dict[tuple[str, str, str], list[dict]] = {}
    for r in rows:
        groups.setdefault((r["experiment"], r["setting"]["sweep"], r["method"]), []).append(r)
    L = _section("paired-summary", "Paired differences of P_c summarised (derived from the "
                 "table above): points where A - B is above +2 s.e., below -2 s.e., or within")
    L += ["| experiment | sweep | A - B | points | A ahead | A behind | within ± 2 s.e. | "
          "smallest | largest | z range |", "|---|---|---|---|---|---|---|---|---|---|"]
    for (e, sw, m), rs in groups.items():
        v = np.array([r["value"] for r in rs])
        se = np.array([r["stderr"] for r in rs])
        z = np.divide(v, se, out=np.zeros_like(v), where=se > 1e-9)
        L.append(f"| {e} | {sw} | {m} | {len(rs)} | {int((v > 2 * se).sum())} | "
                 f"{int((v < -2 * se).sum())} | {int((np.abs(v) <= 2 * se).sum())} | "
                 f"{v.min():+.4f} | {v.max():+.4f} | {z.min():+.1f} to {z.max():+.1f} |")
    return L + [""]


def _same_condition(summary) -> list[str]:
    """The condition f = 0.3, P_d = 0.8 appears in several experiments, each with its
    own seeds (the setting, sweep name included, enters every trial's seed)."""
    o = summary["parameters"]["ours"]
    f0, p0 = o["f_fixed"], o["p_d_fixed"]
    want = ("ncr+nd", "ncr+2da")
    found = []
    for r in summary["records"]:
        s = r["setting"]
        if (r["metric"] == "correct_rate" and r["method"] in want and s.get("f") == f0
                and s.get("p_d") == p0 and "k" not in s):
            found.append(r)
    if not found:
        return []
    L = _section("same-condition", f"The condition f = {f0:g}, P_d = {p0:g} in each "
                 "experiment that contains it (separate seeds per experiment)")
    L += ["| experiment / sweep | method | P_c | s.e. | runs |", "|---|---|---|---|---|"]
    for r in found:
        L.append(f"| {r['experiment']} / {r['setting']['sweep']} | {_label(summary, r['method'])} "
                 f"| {r['value']:.3f} | {r['stderr'] or 0:.3f} | {r['runs']} |")
    return L + [""]


def render_tables(summary: Mapping[str, Any]) -> str:
    """Markdown tables (named sections), the paper's Table 1 beside ours."""
    L: list[str] = []
    L += _sweep_table(summary, "fig1", "main", "f", ("tbm+nd", "ncr+nd"), "correct_rate", "f",
                      "Exp. 1a / Fig. 1 — P_c versus f (P_d fixed)")
    L += _sweep_table(summary, "fig2", "main", "p_d", ("tbm+nd", "ncr+nd"), "correct_rate",
                      "P_d", "Exp. 1a / Fig. 2 — P_c versus P_d (f fixed)")
    L += _weights_table(summary)
    L += _sweep_table(summary, "fig4", "main", "f", DECISIONS, "correct_rate", "f",
                      "Exp. 2 / Fig. 4 — P_c versus f (P_d fixed)")
    L += _sweep_table(summary, "fig5", "main", "p_d", DECISIONS, "correct_rate", "P_d",
                      "Exp. 2 / Fig. 5 — P_c versus P_d (f fixed)")
    L += _sweep_table(summary, "all-correct", "main", "f", MAIN_METHODS, "all_correct", "f",
                      "Fraction of runs entirely correct versus f")
    L += _table1(summary)
    L += _paired_summary(summary)
    L += _same_condition(summary)
    recs = summary["records"]
    if any(r["experiment"] == "sensitivity" for r in recs):
        ms = sorted({r["method"] for r in recs if r["experiment"] == "sensitivity"},
                    key=lambda m: (("2da" in m), m))
        L += _sweep_table(summary, "sensitivity", "sensitivity", "sensitivity", ms,
                          "correct_rate", "f", "Ours — sensitivity of MD-2DA to alpha (tau) "
                          "and of MD-ND to its readings (P_d fixed)")
    L += _paired_table(summary)
    L += timing_lines(summary, "zhang2009", _section(
        "timing", "Runs that computed trials (wall time of each invocation)"))
    return "\n".join(L)


# ----------------------------------------------------------------- figures
def make_figures(summary: Mapping[str, Any], out) -> list[str]:
    """Figs. 1-5, Table 1 and the sensitivity study as PNG; [] without matplotlib."""
    plt = pyplot()
    if plt is None:
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
            ys = np.array([tab[(m, x)]["value"] for x in xs])
            se = np.array([tab[(m, x)]["stderr"] or 0.0 for x in xs])
            ax.errorbar(xs, ys, yerr=1.96 * se, marker="o", ms=3, capsize=2,
                        label=_label(summary, m))
        runs = max(r["runs"] for r in tab.values())
        ax.set_xlabel(xlabel)
        ax.set_ylabel("correct matching rate P_c")
        ax.set_title(f"{title}\n(ours, {runs} runs per point, 95% CI)", fontsize=10)
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8)
        made.append(save(fig, out, fname))

    curve("fig1_pc_vs_f_measures.png", "main", "f", ("tbm+nd", "ncr+nd"), "noise factor f",
          "Fig. 1: MM-TBM vs MM-NCR (truncation)")
    curve("fig2_pc_vs_pd_measures.png", "main", "p_d", ("tbm+nd", "ncr+nd"),
          "detection probability P_d", "Fig. 2: MM-TBM vs MM-NCR (truncation)")
    curve("fig3_pc_vs_k.png", "weights", "k", ("wa+nd", "ncr+nd"), "k (w(:,k) for MM-WA, "
          "r(:,k) for MM-NCR)", "Fig. 3: MM-WA vs MM-NCR (truncation)")
    curve("fig4_pc_vs_f_decisions.png", "main", "f", DECISIONS, "noise factor f",
          "Fig. 4: MD-ND vs MD-2DA (MM-NCR)")
    curve("fig5_pc_vs_pd_decisions.png", "main", "p_d", DECISIONS,
          "detection probability P_d", "Fig. 5: MD-ND vs MD-2DA (MM-NCR)")
    sens = sorted({r["method"] for r in recs if r["experiment"] == "sensitivity"},
                  key=lambda m: (("2da" in m), m))
    curve("sensitivity.png", "sensitivity", "sensitivity", sens, "noise factor f",
          "Ours: MD-2DA gate level and MD-ND readings")

    t = _lookup(recs, "table1", "t_decide", "table1")
    if t:
        pds = summary["paper_values"]["table1_p_d"]
        paper = summary["paper_values"]["table1"]
        fig, ax = plt.subplots(figsize=(6.4, 4.4))
        ax.semilogy(pds, paper["MD-2DA"], "k--s", label="paper: MD-2DA")
        ax.semilogy(pds, paper["MD-ND"], "k--o", label="paper: MD-ND")
        solver = summary["parameters"]["run"]["md2da_solver"]
        for m, lab in (("ncr+nd", "ours: MD-ND"), ("ncr+2da", f"ours: MD-2DA ({solver})"),
                       ("ncr+2da-highs", "ours: MD-2DA (highs)")):
            xs = [p for p in pds if (m, p) in t]
            ax.semilogy(xs, [t[(m, p)]["value"] for p in xs], "-o", ms=3, label=lab)
        e = _lookup(recs, "table1-enum", "t_decide_finished", "table1")
        xs = [p for p in pds if ("ncr+2da-enum", p) in e]
        if xs:
            ax.semilogy(xs, [e[("ncr+2da-enum", p)]["value"] for p in xs], "-^", ms=4,
                        label="ours: MD-2DA by enumeration (runs that finished)")
        ax.set_xlabel("detection probability P_d")
        ax.set_ylabel("seconds per decision")
        ax.set_title("Table 1: decision time (paper's hardware not given)", fontsize=10)
        ax.grid(alpha=0.3, which="both")
        ax.legend(fontsize=7)
        made.append(save(fig, out, "table1_time.png"))
    return made
