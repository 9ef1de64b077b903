"""Paper 004's tables, parameter table and key numbers (the page
``docs/papers/dong2015.md`` embeds them verbatim)."""

from __future__ import annotations

from typing import Any, Mapping

from .._report import mean_ci, wall_time_line
from .experiment import LABELS

__all__ = ["lookup", "render_tables", "render_parameters", "render_headline",
           "render_comparison", "steps_of"]

_FIG = {1: "Fig. 5", 2: "Fig. 6", 3: "Fig. 7"}


def lookup(records, part: str, metric: str) -> dict[tuple, tuple]:
    """{(method, env, coef, n_targets): (value, runs, stderr)}."""
    return {(r["method"], r["setting"]["env"], r["setting"]["coef"],
             r["setting"]["n_targets"]): (r["value"], r["runs"], r.get("stderr"))
            for r in records if r["experiment"] == part and r["metric"] == metric}


def steps_of(records, part: str) -> list[int]:
    ks = {int(r["metric"][4:]) for r in records
          if r["experiment"] == part and r["metric"].startswith("ec_k")}
    return sorted(ks)


def _ci(v, digits: int = 2) -> str:
    return mean_ci(v, digits)


def _methods(tab) -> list[str]:
    seen = []
    for k in tab:
        if k[0] not in seen:
            seen.append(k[0])
    order = list(LABELS)
    return sorted(seen, key=lambda m: order.index(m) if m in order else len(order))


def _one(tab, method, env=None):
    return next((v for k, v in tab.items() if k[0] == method and (env is None or k[1] == env)),
                None)


def _env_tables(recs) -> list[str]:
    L: list[str] = []
    ks = steps_of(recs, "main")
    for env in (1, 2, 3):
        tabs = {k: lookup(recs, "main", f"ec_k{k:02d}") for k in ks}
        if not any(key[1] == env for key in tabs[ks[0]]):
            continue
        runs = max(v[1] for key, v in tabs[ks[0]].items() if key[1] == env)
        L += [f"### Environment {env} ({_FIG[env]}): correct association rate E_c per step "
              f"({runs} runs; mean ± 95 % half-width)", "",
              "| method | " + " | ".join(f"k={k}" for k in ks) + " |",
              "|---|" + "---|" * len(ks)]
        for m in _methods(tabs[ks[0]]):
            L.append(f"| {LABELS.get(m, m)} | " +
                     " | ".join(_ci(_one(tabs[k], m, env)) for k in ks) + " |")
        L.append("")
    return L


def _glance_table(recs) -> list[str]:
    """E_c at steps 1, 4 and the last, every method and environment."""
    ks = steps_of(recs, "main")
    pick = [k for k in (1, 4, ks[-1]) if k in ks] if ks else []
    tabs = {k: lookup(recs, "main", f"ec_k{k:02d}") for k in pick}
    if not pick or not tabs[pick[0]]:
        return []
    envs = sorted({key[1] for key in tabs[pick[0]]})
    head = [f"env {e} k={k}" for e in envs for k in pick]
    L = ["### Every reading at a glance: E_c at steps " + ", ".join(map(str, pick))
         + " (mean ± 95 % half-width)", "",
         "| method | " + " | ".join(head) + " |", "|---|" + "---|" * len(head)]
    for m in _methods(tabs[pick[0]]):
        L.append(f"| {LABELS.get(m, m)} | " + " | ".join(
            _ci(_one(tabs[k], m, e)) for e in envs for k in pick) + " |")
    return L + [""]


def _calibration_table(recs) -> list[str]:
    """Mean gamma of the true neighbour pairs and the share under the gate."""
    ks = steps_of(recs, "main")
    pick = [k for k in (1, 4, ks[-1]) if k in ks] if ks else []
    g = {k: lookup(recs, "main", f"cg_k{k:02d}") for k in pick}
    q = {k: lookup(recs, "main", f"cp_k{k:02d}") for k in pick}
    if not pick or not g[pick[0]]:
        return []
    envs = sorted({key[1] for key in g[pick[0]]})
    head = [f"env {e} k={k}" for e in envs for k in pick]
    L = ["### Calibration: mean gamma of the true neighbour pairs under the true "
         "reference pair / share under the gate 13.2767 (chi-square, 4 degrees of "
         "freedom: 4.00 / 0.99)", "",
         "| distance | " + " | ".join(head) + " |", "|---|" + "---|" * len(head)]
    for m in _methods(g[pick[0]]):
        cells = []
        for e in envs:
            for k in pick:
                a, b = _one(g[k], m, e), _one(q[k], m, e)
                cells.append("—" if a is None else f"{a[0]:.2f} / {b[0]:.3f}")
        L.append(f"| {LABELS.get(m, m)} | " + " | ".join(cells) + " |")
    return L + [""]


def _slot_table(recs) -> list[str]:
    """Environment 1: the trial partner true / 1-2 slots off, the decided one 1-2 off."""
    ks = steps_of(recs, "main")
    pick = [k for k in (1, 4, ks[-1]) if k in ks] if ks else []
    tabs = {(c, k): lookup(recs, "main", f"{c}_k{k:02d}")
            for c in ("tr0", "tr12", "dec12") for k in pick}
    if not pick or not tabs[("tr0", pick[0])]:
        return []
    head = [f"{t} k={k}" for t in ("trial true", "trial 1-2 off", "decided 1-2 off")
            for k in pick]
    L = ["### Environment 1, the shifted formation: share of common radar-1 tracks whose "
         "trial partner (smallest lambda of the row) is the true one or 1-2 formation "
         "slots from it, and whose decided partner is 1-2 slots off", "",
         "| method | " + " | ".join(head) + " |", "|---|" + "---|" * len(head)]
    for m in _methods(tabs[("tr0", pick[0])]):
        L.append(f"| {LABELS.get(m, m)} | " + " | ".join(
            _ci(_one(tabs[(c, k)], m, 1)) for c in ("tr0", "tr12", "dec12")
            for k in pick) + " |")
    return L + [""]


def _wrong_table(recs) -> list[str]:
    ks = steps_of(recs, "main")
    pick = [k for k in (1, 4, ks[-1]) if k in ks] if ks else []
    tabs = {k: lookup(recs, "main", f"fp_k{k:02d}") for k in pick}
    if not pick or not tabs[pick[0]]:
        return []
    envs = sorted({key[1] for key in tabs[pick[0]]})
    head = [f"env {e} k={k}" for e in envs for k in pick]
    L = ["### Wrong pairs per common target (same runs; mean ± 95 % half-width)", "",
         "| method | " + " | ".join(head) + " |", "|---|" + "---|" * len(head)]
    for m in _methods(tabs[pick[0]]):
        L.append(f"| {LABELS.get(m, m)} | " + " | ".join(
            _ci(_one(tabs[k], m, e)) for e in envs for k in pick) + " |")
    return L + [""]


def _heading_table(recs) -> list[str]:
    ks = steps_of(recs, "main")
    cols = [("hd1", "sensor 1, all targets"), ("hd2", "sensor 2, all targets"),
            ("hd1t0", "sensor 1, one target"), ("hd2t0", "sensor 2, one target")]
    tabs = {(c, k): lookup(recs, "main", f"{c}_k{k:02d}") for c, _ in cols for k in ks}
    if not ks or not tabs[(cols[0][0], ks[0])]:
        return []
    L = ["### Heading error, environment 2 (Fig. 2): mean absolute error in rad "
         "(mean ± 95 % half-width over the runs)", "",
         "| step | " + " | ".join(t for _, t in cols) + " |", "|---|" + "---|" * len(cols)]
    for k in ks:
        L.append(f"| {k} | " + " | ".join(_ci(_one(tabs[(c, k)], "tsd", 2), 3)
                                          for c, _ in cols) + " |")
    return L + [""]


def _coef_table(recs) -> list[str]:
    ks = steps_of(recs, "coef")
    if not ks:
        return []
    tabs = {k: lookup(recs, "coef", f"ec_k{k:02d}") for k in ks}
    runs = max(v[1] for v in tabs[ks[0]].values())
    coefs = sorted({key[2] for key in tabs[ks[0]]})
    L = [f"### Threshold coefficient (Figs. 3-4; our substitute for T_1, on the paper's "
         f"reading and on the dummy reading), environment 2: E_c per step ({runs} runs "
         "per point)", "",
         "| method | coefficient | " + " | ".join(f"k={k}" for k in ks) + " |",
         "|---|---|" + "---|" * len(ks)]
    for m in _methods(tabs[ks[0]]):
        for c in coefs:
            L.append(f"| {LABELS.get(m, m)} | {c:g} | " + " | ".join(
                _ci(tabs[k].get((m, 2, c, _n(tabs[k])))) for k in ks) + " |")
    return L + [""]


def _n(tab) -> int:
    return next(iter(tab))[3]


def _timing_tables(summary) -> list[str]:
    recs = summary["records"]
    L: list[str] = []
    t = lookup(recs, "main", "t_step_ms")
    if t:
        envs = sorted({k[1] for k in t})
        ld = summary.get("load")
        load = f", 1-minute load average {ld['start']:.1f} at the start, " \
               f"{ld['end']:.1f} at the end" if ld else ""
        L += ["### Time per step (ms) in place of the lost Table 1 (30 targets; "
              f"mean ± 95 % half-width; shared 2-core machine{load}; readings that share "
              "one assignment are each charged its full time)", "",
              "| method | " + " | ".join(f"env {e}" for e in envs) + " |",
              "|---|" + "---|" * len(envs)]
        for m in _methods(t):
            L.append(f"| {LABELS.get(m, m)} | " + " | ".join(_ci(_one(t, m, e), 1)
                                                           for e in envs) + " |")
        L.append("")
    t = lookup(recs, "timing", "t_step_ms")
    pf = lookup(recs, "timing", "pairs_frac")
    if t:
        ns = sorted({k[3] for k in t})
        ms = _methods(t)
        L += ["### Growth with the number of targets (environment 2 geometry; time per "
              "step in ms; pre-gate: fraction of reference pairs kept)", "",
              "| targets | " + " | ".join(LABELS.get(m, m) for m in ms)
              + " | pre-gate keeps |", "|---|" + "---|" * (len(ms) + 1)]
        for n in ns:
            cells = [_ci(next((v for k, v in t.items() if k[0] == m and k[3] == n), None), 1)
                     for m in ms]
            keep = next((v for k, v in pf.items() if k[0] == "tsd-c-pregate" and k[3] == n),
                        None)
            L.append(f"| {n} | " + " | ".join(cells) + f" | {_ci(keep)} |")
        L.append("")
    lp = summary.get("lap_paths")
    if lp:
        names = [("paper", "paper's reading"), ("paper_plain", "paper's reading, before"),
                 ("paper_noself", "neighbour pairs only"),
                 ("paper_noself_plain", "neighbour pairs only, before"),
                 ("rect_c", "paper's reading + all three"),
                 ("compiled", "dummy reading + all three")]
        L += ["### One step's Phi at n targets a side: the compiled loop for each reading "
              "(ms, environment 2, first step / last step; *before*: the scalar loop the "
              "batched kernel replaced), against `assocopt.solve` one "
              "pair at a time (dummy reading + all three, last step)", "",
              "| targets | load avg | " + " | ".join(t for _, t in names)
              + " | through solve | of which the assignments in solve | the same "
              "assignments in scipy lsa | same Phi |",
              "|---|---|" + "---|" * len(names) + "---|---|---|---|"]
        for r in lp:
            f = lambda key: f"{r[key]:.1f}" if key in r else "—"
            agree = ("yes" if r["agree"] else "NO") if "agree" in r else "—"
            L.append(f"| {r['n_targets']} | {r['load']:.1f}–{r['load_end']:.1f} | "
                     + " | ".join(f"{f(k + '_first_ms')} / {f(k + '_ms')}" for k, _ in names)
                     + f" | {f('solve_ms')} | {f('solve_only_ms')} | {f('lsa_only_ms')} | "
                     f"{agree} |")
        L.append("")
        mean = [(k, t) for k, t in names if any(f"{k}_mean_ms" in r for r in lp)]
        if mean:
            L += ["### One step of the paper's reading, averaged over the 12 steps of one "
                  "run (ms, environment 2; inputs prepared included; wall / CPU time of the "
                  "process; *before*: the scalar loop; otherwise batched, each step "
                  "warm-started from the previous one)", "",
                  "| targets | load avg | " + " | ".join(t for _, t in mean) + " |",
                  "|---|---|" + "---|" * len(mean)]
            for r in lp:
                L.append(f"| {r['n_targets']} | {r['load']:.1f}–{r['load_end']:.1f} | "
                         + " | ".join(f"{r[k + '_mean_ms']:.1f} / {r[k + '_mean_cpu_ms']:.1f}"
                                      for k, _ in mean) + " |")
            L.append("")
    return L


def render_tables(summary: Mapping[str, Any]) -> str:
    """Markdown tables of the summary (the page embeds them verbatim)."""
    recs = summary["records"]
    L = (_glance_table(recs) + _env_tables(recs) + _wrong_table(recs)
         + _calibration_table(recs) + _slot_table(recs) + _heading_table(recs)
         + _coef_table(recs) + _timing_tables(summary))
    return "\n".join(L + wall_time_line(summary))


def render_parameters(summary: Mapping[str, Any]) -> str:
    """The parameter table: the paper's values beside ours."""
    p = summary["parameters"]["paper"]
    o = summary["parameters"]["ours"]
    sc = o["scenario"]
    rows = [
        ("sensors", f"{p['sensors_km']} km", "same"),
        ("range / azimuth noise", f"{p['sigma_r_m']} m / {p['sigma_az_deg']} deg",
         f"{sc['sigma_r']:g} m / {sc['sigma_az_deg']:g} deg"),
        ("range / azimuth bias", f"{p['bias_r_m']} m / {p['bias_az_deg']} deg",
         f"{sc['bias_r']} m / {sc['bias_az_deg']} deg"),
        ("period, steps, runs", f"{p['T_s']} s, {p['steps']}, {p['runs']}",
         f"{sc['T']:g} s, {sc['n_steps']}, {summary['runs']}"),
        ("targets", f"{p['targets']}", f"{sc['n_targets']}"),
        ("alpha, n_x, gate", f"{p['alpha']}, {p['n_x']}, not printed",
         f"{p['alpha']}, 4, {o['gate']:.4f} (scipy.stats.chi2)"),
        ("heading convention", "not given", "atan2(vx, vy): clockwise from north"),
        ("local trackers", "not given",
         f"Kalman CV on converted measurements, q = {sc['q']:g} m²/s³, two-point start"),
        ("P_c = 0.5 (env. 3)", "not given",
         f"{sc['missed']} targets missed by each sensor, {sc['false_tracks']} false "
         "tracks per sensor: 20 common of 40 observed"),
        ("threshold T_1, coefficient C_1", f"formula lost, C_1 = {p['C_1']}",
         f"substitute (ours): {o['t1_substitute']}, coef = {o['coef']:g}; "
         f"sweep {o['coef_grid']}"),
        ("Euclidean method's gate", "coefficient lost",
         f"{o['euclid_gate_m']:g} m on the position distance (ours)"),
        ("I/R criterion", "examples 1/1, 2/2, 2/3, 3/4, 3/5, 4/5, 4/6, 5/7, 6/8",
         f"{o['ir']['schedule']}: 1/1, 2/2, 2/3, 3/4, then 3/4 sliding "
         f"(R_max = {o['ir']['R_max']})"),
        ("coarse pre-gate", "suggested (speed, turn rate)",
         f"speed, chi-square(1) at 1 - {o['pregate_alpha']:g} (turn rate: straight "
         "targets, not used)"),
        ("fuzzy method (ref. [10], 16 quadrants)", "compared", o["fuzzy_method"]),
    ]
    return "\n".join(["| parameter | paper | ours |", "|---|---|---|"] +
                     [f"| {a} | {b} | {c} |" for a, b, c in rows])


#: The two comparisons run on both readings: (row, paper's reading self pair in, self
#: pair out, dummy reading).
COMPARISON = (("none: row-wise trial pairs, chi-square gate (the paper's reading)",
               "tsd-rect", "tsd-rect-noself", "tsd"),
              ("global trial pairs (2-D assignment on Phi)", "tsd-rect-global",
               "tsd-rect-noself-global", "tsd-global"),
              ("T_1 stand-in, C_1 = {coef:g}", "tsd-rect-t1", "tsd-rect-noself-t1", "tsd-t1"))


def render_comparison(summary: Mapping[str, Any]) -> str:
    """E_c at the last step, environments 1 / 2 / 3, of the global trial pairs and the
    T_1 stand-in on the paper's reading (self pair in and out) and on the dummy one."""
    recs = summary["records"]
    ks = steps_of(recs, "main")
    if not ks:
        return ""
    ec = lookup(recs, "main", f"ec_k{ks[-1]:02d}")

    def cell(m):
        v = [_one(ec, m, e) for e in (1, 2, 3)]
        return "—" if None in v else " / ".join(f"{x[0]:.2f}" for x in v)
    L = [f"| comparison (each a change of ours), E_c at step {ks[-1]}, env 1 / 2 / 3 | "
         "paper's reading, self pair in λ | paper's reading, neighbour pairs only | "
         "dummy reading (ours) |", "|---|---|---|---|"]
    coef = summary["parameters"]["ours"]["coef"]
    L += [f"| {name.format(coef=coef)} | {cell(a)} | {cell(b)} | {cell(c)} |"
          for name, a, b, c in COMPARISON]
    return "\n".join(L)


def render_headline(summary: Mapping[str, Any]) -> str:
    """The key numbers quoted in the page's text: the paper's reading first."""
    recs = summary["records"]
    ks = steps_of(recs, "main")
    last = ks[-1] if ks else 12
    ec = lookup(recs, "main", f"ec_k{last:02d}")
    mean = lookup(recs, "main", "ec_mean")
    L = []
    for m in ("tsd-rect", "tsd-rect-noself", "ted-rect", "ted-rect-noself",
              "tsd-rect-global", "tsd-rect-noself-global", "tsd-rect-t1",
              "tsd-rect-noself-t1", "tsd-rect-obj", "tsd-rect-refcov", "tsd-rect-inflate",
              "tsd-rect-c", "tsd", "tsd-global", "tsd-t1", "tsd-c", "tsd-c-global", "gnn"):
        cells = [f"env {e}: {_ci(_one(ec, m, e))} (mean over steps {_ci(_one(mean, m, e))})"
                 for e in (1, 2, 3) if _one(ec, m, e) is not None]
        if cells:
            L.append(f"- {LABELS[m]}, E_c at step {last}: " + "; ".join(cells))
    g = lookup(recs, "main", f"cg_k{last:02d}")
    q = lookup(recs, "main", f"cp_k{last:02d}")
    cal = [f"{LABELS[m]} {_one(g, m, 2)[0]:.2f} / {_one(q, m, 2)[0]:.3f}"
           for m in ("tsd-rect", "tsd-rect-refcov", "tsd-rect-inflate", "tsd-rect-c")
           if _one(g, m, 2) is not None]
    if cal:
        L.append(f"- calibration at step {last}, env 2 (mean gamma of true neighbour pairs / "
                 "share under 13.2767; chi-square: 4 / 0.99): " + "; ".join(cal))
    t0 = lookup(recs, "main", f"tr0_k{last:02d}")
    t12 = lookup(recs, "main", f"tr12_k{last:02d}")
    if _one(t0, "tsd-rect", 1) is not None:
        L.append(f"- env 1, paper's reading, step {last}: the row's smallest lambda is the true "
                 f"partner for {_ci(_one(t0, 'tsd-rect', 1))} of the tracks and 1-2 formation "
                 f"slots off for {_ci(_one(t12, 'tsd-rect', 1))}")
    hd = lookup(recs, "main", "hd1t0_k04")
    hd2 = lookup(recs, "main", "hd2t0_k04")
    if hd:
        L.append(f"- heading error of one target at step 4 (env 2): sensor 1 "
                 f"{_ci(_one(hd, 'tsd', 2), 3)} rad, sensor 2 {_ci(_one(hd2, 'tsd', 2), 3)} rad")
    t = lookup(recs, "main", "t_step_ms")
    cells = [f"{LABELS[m]} {_ci(_one(t, m, 2), 1)} ms"
             for m in ("tsd-rect", "tsd-rect-noself", "tsd-rect-t1", "tsd-rect-c", "tsd-c")
             if _one(t, m, 2) is not None]
    if cells:
        ld = summary.get("load")
        L.append("- time per step, 30 targets, env 2, mean over the steps: " + "; ".join(cells)
                 + (f" (load average {ld['start']:.1f} to {ld['end']:.1f})" if ld else ""))
    lp = {r["n_targets"]: r for r in summary.get("lap_paths", [])}
    if 30 in lp:
        r = lp[30]
        L.append(f"- one step, 30 targets, env 2, first / last step: paper's reading "
                 f"{r['paper_first_ms']:.1f} / {r['paper_ms']:.1f} ms, neighbour pairs only "
                 f"{r['paper_noself_first_ms']:.1f} / {r['paper_noself_ms']:.1f} ms, dummy "
                 f"reading + all three {r['compiled_first_ms']:.1f} / {r['compiled_ms']:.1f} "
                 f"ms; before (the scalar loop): paper's reading {r['paper_plain_first_ms']:.1f}"
                 f" / {r['paper_plain_ms']:.1f} ms; mean over the 12 steps (wall / CPU): "
                 f"paper's reading {r['paper_mean_ms']:.1f} / {r['paper_mean_cpu_ms']:.1f} ms "
                 f"(before {r['paper_plain_mean_ms']:.1f} / "
                 f"{r['paper_plain_mean_cpu_ms']:.1f}), neighbour pairs only "
                 f"{r['paper_noself_mean_ms']:.1f} / {r['paper_noself_mean_cpu_ms']:.1f} ms "
                 f"(before {r['paper_noself_plain_mean_ms']:.1f} / "
                 f"{r['paper_noself_plain_mean_cpu_ms']:.1f}) (load average {r['load']:.1f}); "
                 f"{r.get('solve_ms', float('nan')):.0f} ms through `assocopt.solve`")
    if "wall_s" in summary:
        L.append(f"- wall time of the full run: {summary['wall_s']:.0f} s with "
                 f"{summary['workers']} worker process(es)")
    return "\n".join(L)
