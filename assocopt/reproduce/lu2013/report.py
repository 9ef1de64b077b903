"""Tables and figures of the paper-002 reproduction (Lu et al. 2013), from its summary.

Everything here is a pure function of ``summary.json`` (:func:`render_tables`; the
figures, :mod:`.figures`, likewise), so the committed ``tables.md`` and figures can be checked
against the committed summary.  Each section of ``tables.md`` starts with a
``<!-- section: NAME -->`` marker; ``docs/papers/lu2013.md`` includes the sections by
name (:mod:`assocopt.reproduce.pages`).
"""

from __future__ import annotations

import math
from typing import Any, Iterable, Mapping, Sequence

import numpy as np

from ..runlog import command, timing_lines  # noqa: F401  (command: re-exported)

__all__ = ["render_tables", "index_records", "GEOMETRY_LABELS", "command"]

SIGMAS = (1.5, 5.0)
TABLE_M = (5, 10, 15, 20)
TABLE_COLUMNS = tuple((s, d) for s in SIGMAS for d in (0.5, 1.0, 1.5))
D_GRID = tuple(round(0.05 * i, 2) for i in range(31))
GEOMETRY_LABELS = {"x": "line along +x", "horizontal": "line in a random horizontal direction",
                   "3d": "line in a random 3-D direction"}
REFERENCE = "pattipati"


def index_records(records: Iterable[Mapping[str, Any]]) -> dict[tuple, Mapping[str, Any]]:
    """Records keyed by (experiment, line_direction, M, sigma, d, L, method, metric)."""
    out = {}
    for r in records:
        s = r["setting"]
        out[(r["experiment"], s.get("line_direction", "x"), s.get("M"), s.get("sigma_mrad"),
             s.get("d"), s.get("L"), r["method"], r["metric"])] = r
    return out


def _f4(v) -> str:
    return "—" if v is None or (isinstance(v, float) and math.isnan(v)) else f"{v:.4f}"


def _section(name: str, title: str) -> list[str]:
    return [f"<!-- section: {name} -->", f"### {title}", ""]


def _methods(summary) -> list[str]:
    return list(summary["methods"])


def _geometries(summary) -> list[str]:
    return list(summary["parameters"]["ours"]["line_directions"])


def _runs_of(ix, experiment, ld) -> int:
    return max((r["runs"] for k, r in ix.items() if k[0] == experiment and k[1] == ld
                and k[7] == "tuple_rate"), default=0)


# ----------------------------------------------------------------- Tables 1-4
def _tables(summary, ix, ld) -> list[str]:
    paper = summary["paper_values"]["tables"]
    labels = summary["paper_labels"]
    runs = _runs_of(ix, "tables", ld)
    if not runs:
        return []
    cols = " | ".join(f"σ={s:g}, d={d:g}" for s, d in TABLE_COLUMNS)
    L = _section(f"tables-{ld}", f"Tables 1–4, {GEOMETRY_LABELS.get(ld, ld)} (correct rate; "
                 f"ours: tuple rate [whole-partition rate], {runs} runs per cell)")
    for k, M in enumerate(TABLE_M, start=1):
        L += [f"**Table {k} — M = {M}**", "", f"| method | {cols} |", "|---" * 7 + "|"]
        for label in labels:
            L.append(f"| paper: {label} | " + " | ".join(f"{v:.4f}" for v in paper[str(M)][label])
                     + " |")
        for m in _methods(summary):
            cells = []
            for s, d in TABLE_COLUMNS:
                a = ix.get(("tables", ld, M, s, d, None, m, "tuple_rate"))
                b = ix.get(("tables", ld, M, s, d, None, m, "partition_correct"))
                cells.append(f"{_f4(a and a['value'])} [{_f4(b and b['value'])}]")
            L.append(f"| ours: {m} | " + " | ".join(cells) + " |")
        L.append("")
    return L


def _paired(summary, ix, ld) -> list[str]:
    if not _runs_of(ix, "tables", ld):
        return []
    cols = " | ".join(f"σ={s:g}, d={d:g}" for s, d in TABLE_COLUMNS)
    L = _section(f"paired-{ld}", f"Tuple rate minus ref. [2] ({REFERENCE}), paired, ± 2 "
                 f"standard errors, percentage points — {GEOMETRY_LABELS.get(ld, ld)}")
    L += [f"| M | method | {cols} |", "|---|---" + "|---" * 6 + "|"]
    paper = summary["paper_values"]["tables"]
    for M in TABLE_M:
        for label in ("KLD", "SKLD"):
            L.append(f"| {M} | paper: {label} (derived: paper's {label} − paper's ref. [2]) | " +
                     " | ".join(f"{100 * (a - b):+.2f}" for a, b in
                                zip(paper[str(M)][label], paper[str(M)]["ref. [2]"])) + " |")
        for m in _methods(summary)[1:]:
            cells = []
            for s, d in TABLE_COLUMNS:
                r = ix.get(("tables", ld, M, s, d, None, m, f"tuple_rate - {REFERENCE}"))
                cells.append("—" if r is None else
                             f"{100 * r['value']:+.2f} ± {200 * (r['stderr'] or 0):.2f}")
            L.append(f"| {M} | {m} | " + " | ".join(cells) + " |")
    return L + [""]


def _gains(summary, ix) -> list[str]:
    """Mean over the 24 cells of each cost's paired gain over ref. [2], beside the paper's."""
    geos = [g for g in _geometries(summary) if _runs_of(ix, "tables", g)]
    if not geos:
        return []
    paper = summary["paper_values"]["tables"]
    L = _section("gains", "Mean gain over ref. [2] across the 24 cells of Tables 1–4 "
                 "(tuple rate, percentage points, ± 2 standard errors; cells where the paired "
                 "difference is more than 2 standard errors above / below zero)")
    L += ["| method | " + " | ".join(f"{GEOMETRY_LABELS.get(g, g)}: mean | cells above / below"
                                      for g in geos) + " |",
          "|---" + "|---|---" * len(geos) + "|"]
    for label in ("KLD", "SKLD"):
        diffs = [100 * (a - b) for M in TABLE_M
                 for a, b in zip(paper[str(M)][label], paper[str(M)]["ref. [2]"])]
        above = sum(x > 0 for x in diffs)
        below = sum(x < 0 for x in diffs)
        cell = f"{np.mean(diffs):+.2f} | {above} / {below} (sign only)"
        L.append(f"| paper: {label} (derived from its tables) | " +
                 " | ".join(cell for _ in geos) + " |")
    for m in _methods(summary)[1:]:
        row = []
        for g in geos:
            rs = [ix.get(("tables", g, M, s, d, None, m, f"tuple_rate - {REFERENCE}"))
                  for M in TABLE_M for s, d in TABLE_COLUMNS]
            rs = [r for r in rs if r is not None]
            if not rs:
                row += ["—", "—"]
                continue
            v = np.array([r["value"] for r in rs])
            se = np.array([r["stderr"] or 0.0 for r in rs])
            mean_se = math.sqrt(float((se ** 2).sum())) / len(rs)
            row += [f"{100 * v.mean():+.2f} ± {200 * mean_se:.2f}",
                    f"{int((v > 2 * se).sum())} / {int((v < -2 * se).sum())}"]
        L.append(f"| ours: {m} | " + " | ".join(row) + " |")
    return L + [""]


def _geometry_fit(summary, ix) -> list[str]:
    """How far ref. [2]'s tuple rate is from the paper's, per geometry."""
    geos = [g for g in _geometries(summary) if _runs_of(ix, "tables", g)]
    if not geos:
        return []
    paper = summary["paper_values"]["tables"]
    L = _section("geometry", "Line geometry: ours (ref. [2], tuple rate) minus the paper's "
                 "ref. [2], over the cells of Tables 1–4 (derived)")
    L += ["| geometry | runs | mean difference | RMS difference | largest absolute difference | "
          "mean, σ = 1.5 | mean, σ = 5 | M = 20 minus M = 5, ours (paper) |",
          "|---|---|---|---|---|---|---|---|"]
    pdrop = np.mean([paper["20"]["ref. [2]"][j] - paper["5"]["ref. [2]"][j] for j in range(6)])
    for g in geos:
        diff, by_s, ours = [], {s: [] for s in SIGMAS}, {}
        for M in TABLE_M:
            for j, (s, d) in enumerate(TABLE_COLUMNS):
                r = ix.get(("tables", g, M, s, d, None, REFERENCE, "tuple_rate"))
                if r is None:
                    continue
                ours[(M, j)] = r["value"]
                x = r["value"] - paper[str(M)]["ref. [2]"][j]
                diff.append(x)
                by_s[s].append(x)
        if not diff:
            continue
        dv = np.array(diff)
        drop = np.mean([ours[(20, j)] - ours[(5, j)] for j in range(6)
                        if (20, j) in ours and (5, j) in ours])
        L.append(f"| {GEOMETRY_LABELS.get(g, g)} | {_runs_of(ix, 'tables', g)} | "
                 f"{dv.mean():+.4f} | {math.sqrt(float((dv ** 2).mean())):.4f} | "
                 f"{np.abs(dv).max():.4f} | {np.mean(by_s[1.5]):+.4f} | {np.mean(by_s[5.0]):+.4f} | "
                 f"{drop:+.4f} ({pdrop:+.4f}) |")
    return L + [""]


def _lp_table(summary, ix) -> list[str]:
    geos = [g for g in _geometries(summary) if _runs_of(ix, "tables", g)]
    if not geos:
        return []
    L = _section("lp", "LP relaxation (the paper's LP_SOLVE method), the 24 cells of each "
                 "geometry pooled")
    L += ["| geometry | method | LP integral | rounding infeasible | rounding wrong | "
          "largest gap of the solution used |", "|---|---|---|---|---|---|"]
    for g in geos:
        for m in _methods(summary):
            def pooled(metric):
                rs = [ix.get(("tables", g, M, s, d, None, m, metric))
                      for M in TABLE_M for s, d in TABLE_COLUMNS]
                rs = [r for r in rs if r is not None]
                n = sum(r["runs"] for r in rs)
                return sum(r["value"] * r["runs"] for r in rs) / n if n else math.nan
            gaps = [ix.get(("tables", g, M, s, d, None, m, "gap"))
                    for M in TABLE_M for s, d in TABLE_COLUMNS]
            gmax = max((r["value"] for r in gaps if r is not None), default=math.nan)
            L.append(f"| {g} | {m} | {pooled('lp_integral'):.4f} | "
                     f"{pooled('lp_round_infeasible'):.4f} | {pooled('lp_round_wrong'):.4f} | "
                     f"{gmax:.2e} |")
    L += ["", "LP integral by M and σ (all methods and d pooled):", "",
          "| geometry | M | σ=1.5 | σ=5 |", "|---|---|---|---|"]
    for g in geos:
        for M in TABLE_M:
            cells = []
            for s in SIGMAS:
                rs = [ix.get(("tables", g, M, s, d, None, m, "lp_integral"))
                      for m in _methods(summary) for d in (0.5, 1.0, 1.5)]
                rs = [r for r in rs if r is not None]
                n = sum(r["runs"] for r in rs)
                cells.append(f"{sum(r['value'] * r['runs'] for r in rs) / n:.4f}" if n else "—")
            L.append(f"| {g} | {M} | " + " | ".join(cells) + " |")
    return L + [""]


def _fig2_gains(summary, ix) -> list[str]:
    rs = [k for k in ix if k[0] == "fig" and k[7] == "partition_correct"]
    if not rs:
        return []
    L = _section("fig2", "Fig. 2 — mean correct rate over d = 0:0.05:1.5 and mean paired "
                 "difference to ref. [2] (percentage points, ± 2 standard errors)")
    L += ["| method | σ=1.5 rate | σ=1.5 difference | σ=5 rate | σ=5 difference |",
          "|---|---|---|---|---|"]
    for m in _methods(summary):
        row = [m]
        for s in SIGMAS:
            v = [ix[k]["value"] for d in D_GRID
                 if (k := ("fig", "x", None, s, d, None, m, "partition_correct")) in ix]
            if not v:
                row += ["—", "—"]
                continue
            row.append(f"{np.mean(v):.4f}")
            if m == REFERENCE:
                row.append("(reference)")
                continue
            ds = [ix[k] for d in D_GRID if (k := ("fig", "x", None, s, d, None, m,
                                                  f"partition_correct - {REFERENCE}")) in ix]
            mean = float(np.mean([r["value"] for r in ds]))
            se = math.sqrt(sum((r["stderr"] or 0.0) ** 2 for r in ds)) / len(ds)
            row.append(f"{100 * mean:+.2f} ± {200 * se:.2f}")
        L.append("| " + " | ".join(row) + " |")
    g = summary["paper_values"]["fig2_mean_gain_over_ref2"]
    L += ["", f"Paper (Fig. 2 text, '%', points or relative not said): KLD {g['KLD']['1.5']:+g} "
          f"(σ=1.5), {g['KLD']['5.0']:+g} (σ=5); SKLD {g['SKLD']['1.5']:+g} (σ=1.5), "
          f"{g['SKLD']['5.0']:+g} (σ=5).", ""]
    return L


def _region(summary, ix) -> list[str]:
    rs = sorted((k[5], r) for k, r in ix.items() if k[0] == "region" and k[7] == "tuple_rate")
    if not rs:
        return []
    cell = summary["paper_values"]["tables"]["5"]["ref. [2]"][0]
    L = _section("region", "Region scan: ref. [2]'s tuple rate at M = 5, σ = 1.5 mrad, "
                 "d = 0.5 (line along +x) in the region [0, L] × [0, L] × [1, 10] km")
    L += ["| L (km) | runs | tuple rate | standard error | paper |", "|---|---|---|---|---|"]
    for Lkm, r in rs:
        L.append(f"| {Lkm:g} | {r['runs']} | {r['value']:.4f} | {r['stderr'] or 0:.4f} | "
                 f"{cell:.4f} |")
    return L + [""]


def _disagreements(summary) -> list[str]:
    rows = summary.get("derived", {}).get("disagreements", [])
    if not rows:
        return []
    L = _section("disagreements", "Trials of Tables 1–4 in which two costs give a different "
                 "outcome (tuple rate or whole-partition correctness)")
    L += ["| geometry | cost A | cost B | trials that differ | trials | fraction |",
          "|---|---|---|---|---|---|"]
    for r in rows:
        L.append(f"| {r['line_direction']} | {r['a']} | {r['b']} | {r['differ']} | "
                 f"{r['trials']} | {r['differ'] / r['trials']:.4%} |")
    return L + [""]


def _printed_kld(summary) -> list[str]:
    rows = summary.get("derived", {}).get("printed_kld", [])
    if not rows:
        return []
    L = _section("kld27", "Printed (27) at the true association, targets uniform in the "
                 "reproduction's region (per sensor and angle; s~ = pseudo-measurement "
                 "spread, s = measurement noise)")
    L += ["| σ (mrad) | targets | s~/s: min | 5 % | median | 95 % | max | share s~ < s | "
          "(27): min (rad⁻²) | max (rad⁻²) | share (27) < 0 |",
          "|---|---|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        L.append(f"| {r['sigma_mrad']:g} | {r['targets']} | {r['ratio_min']:.2f} | "
                 f"{r['ratio_p05']:.2f} | {r['ratio_median']:.2f} | {r['ratio_p95']:.2f} | "
                 f"{r['ratio_max']:.1f} | {r['ratio_below_1']:.1%} | {r['kld27_min']:.3g} | "
                 f"{r['kld27_max']:.3g} | {r['kld27_negative']:.1%} |")
    return L + [""]


def render_tables(summary: Mapping[str, Any]) -> str:
    """Markdown of every table of the reproduction (sections marked for the page)."""
    ix = index_records(summary["records"])
    L: list[str] = []
    for g in _geometries(summary):
        L += _tables(summary, ix, g)
    L += _geometry_fit(summary, ix)
    L += _gains(summary, ix)
    for g in _geometries(summary):
        L += _paired(summary, ix, g)
    L += _disagreements(summary)
    L += _lp_table(summary, ix)
    L += _fig2_gains(summary, ix)
    L += _region(summary, ix)
    L += _printed_kld(summary)
    L += timing_lines(summary, "lu2013", _section(
        "timing", "Runs that computed trials (wall time of each invocation)"))
    return "\n".join(L)
