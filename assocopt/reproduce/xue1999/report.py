"""Paper 003's tables: the base scene, the sweep, the parameters and the key numbers
(the page ``docs/papers/xue1999.md`` embeds them verbatim)."""

from __future__ import annotations

from typing import Any, Mapping

from ...tracking.scenarios.xue1999_tracker import METHODS
from .._report import mean_ci, wall_time_line
from .experiment import LABELS, METRICS

__all__ = ["lookup", "render_tables", "render_parameters", "render_headline"]


def lookup(records, part: str, metric: str) -> dict[tuple, tuple]:
    """{(method, noise_scale, clutter_mean): (value, runs, stderr)}."""
    return {(r["method"], r["setting"]["noise_scale"], r["setting"]["clutter_mean"]):
            (r["value"], r["runs"], r.get("stderr"))
            for r in records if r["experiment"] == part and r["metric"] == metric}


def _ci(v) -> str:
    return mean_ci(v, 3)


def render_tables(summary: Mapping[str, Any]) -> str:
    """Markdown tables of the summary (the page embeds them verbatim)."""
    recs = summary["records"]
    L: list[str] = []
    main = {m: lookup(recs, "main", m) for m in METRICS}
    if main["correct_rate"]:
        (_, f, c) = next(iter(main["correct_rate"]))
        runs = max(v[1] for v in main["correct_rate"].values())
        methods = [m for m in METHODS if (m, f, c) in main["correct_rate"]]
        L += [f"### Base scene (noise scale {f:g}, clutter mean {c:g} per scan; {runs} runs; "
              "mean ± 95 % half-width)", "",
              "| method | correct association rate | track swaps | false tracks | "
              "targets held at end | stage-2 rate | non-converged rate |",
              "|---|---|---|---|---|---|---|"]
        for m in methods:
            L.append(f"| {LABELS[m]} | " + " | ".join(_ci(main[k].get((m, f, c)))
                                                       for k in METRICS) + " |")
        L.append("")
    for metric, title in (("correct_rate", "correct association rate"),
                          ("swaps", "track swaps per run"),
                          ("false_tracks", "false tracks per run")):
        tab = lookup(recs, "sweep", metric)
        if not tab:
            continue
        runs = max(v[1] for v in tab.values())
        methods = [m for m in METHODS if any(k[0] == m for k in tab)]
        cells = sorted({(k[2], k[1]) for k in tab})
        L += [f"### Sweep: {title} ({runs} runs per point; mean ± 95 % half-width)", "",
              "| clutter mean | noise scale | " + " | ".join(LABELS[m] for m in methods) + " |",
              "|---|---|" + "---|" * len(methods)]
        for c, f in cells:
            L.append(f"| {c:g} | {f:g} | " + " | ".join(_ci(tab.get((m, f, c)))
                                                       for m in methods) + " |")
        L.append("")
    return "\n".join(L + wall_time_line(summary))


def render_parameters(summary: Mapping[str, Any]) -> str:
    """The parameter table of the page (every value ours; the paper gives none)."""
    o = summary["parameters"]["ours"]
    sc, tp = o["scenario"], o["tracker"]
    rows = [
        ("scans, period", f"{sc['n_scans']} scans, T = {sc['T']:g} s"),
        ("region", f"{sc['region'][0] / 1e3:g} km x {sc['region'][1] / 1e3:g} km"),
        ("targets (start m, velocity m/s, IFF)", "; ".join(
            f"({p[0]:g}, {p[1]:g}), ({v[0]:g}, {v[1]:g}), {'friend' if i else 'foe'}"
            for p, v, i in zip(sc["starts"], sc["velocities"], sc["iff"]))),
        ("detection probability", f"{sc['p_d']:g}"),
        ("report noise (noise scale 1)", f"sigma_p = {sc['sigma_p']:g} m, "
                                         f"sigma_v = {sc['sigma_v']:g} m/s"),
        ("IFF reported wrong", f"p_iff = {sc['p_iff']:g}"),
        ("clutter", f"Poisson, mean {sc['clutter_mean']:g} per scan (base), uniform in the "
                    f"region, velocity uniform in ±{sc['clutter_v']:g} m/s, IFF random"),
        ("tracker", f"Kalman CV, q = {tp['q']:g} m²/s³; confirm after {tp['confirm_hits']} "
                    f"hits in a row, tentative deleted at 1 miss, confirmed after "
                    f"{tp['delete_misses']}"),
        ("new-target cost c_new", f"chi-square(4) at 1 - {tp['gate_alpha']:g} = "
                                  f"{o['c_new']:.3f}"),
        ("IFF mismatch cost", f"2 ln((1 - p_iff) / p_iff) = {o['iff_mismatch_cost']:.3f}"),
        ("DID M, M', B, iteration cap", f"M = {tp['did_M']:g}, M' = {tp['did_M_prime']:g}, "
                                        f"B = {tp['did_B']:g} (all pairs), "
                                        f"{tp['did_max_iter']} updates per record"),
        ("DID origin-dependent reading", f"M = {tp['did_origin_M']:g}, floors "
                                         f"{tp['did_origin_floor']} (x, y, vx, vy, IFF)"),
        ("sweep", f"noise scale {o['noise_grid']} x clutter mean {o['clutter_grid']}, "
                  f"{summary['sweep_runs']} runs per point"),
        ("2-D assignment back end", f"{tp['solver']} (through assocopt.solve)"),
    ]
    return "\n".join(["| parameter (paper: not given) | ours |", "|---|---|"] +
                     [f"| {a} | {b} |" for a, b in rows])


def render_headline(summary: Mapping[str, Any]) -> str:
    """The key numbers quoted in the page's text."""
    main = lookup(summary["records"], "main", "correct_rate")
    swaps = lookup(summary["records"], "main", "swaps")
    false = lookup(summary["records"], "main", "false_tracks")
    L = []
    for m in METHODS:
        k = next((k for k in main if k[0] == m), None)
        if k is not None:
            L.append(f"- {LABELS[m]}: correct association rate {_ci(main[k])}, "
                     f"{swaps[k][0]:.2f} track swaps and {false[k][0]:.2f} false tracks "
                     "per run")
    t = summary["timing"]
    L.append(f"- wall time of the full run: {summary['wall_s']:.0f} s with "
             f"{summary['workers']} worker processes (main {t['xue1999-main']['wall_s']:.0f} s "
             f"for {summary['runs']} runs, sweep {t['xue1999-sweep']['wall_s']:.0f} s)"
             if {"xue1999-main", "xue1999-sweep"} <= set(t) else
             f"- wall time: {summary['wall_s']:.0f} s")
    return "\n".join(L)
