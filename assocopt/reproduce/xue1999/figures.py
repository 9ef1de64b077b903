"""Figures of the paper-003 reproduction: a scene like the paper's Figs. 2-3, the
per-scan correct association rate with 95 % bands, and the noise x clutter sweep."""

from __future__ import annotations

from typing import Any, Mapping

import numpy as np

from ...tracking.scenarios.xue1999_tracker import run_tracker, split_method
from .._plot import draw_all, save
from . import experiment as exp
from .experiment import label
from .report import lookup, ordered

__all__ = ["make_figures"]

_COLOURS = ("tab:blue", "tab:orange", "tab:green", "tab:red")
#: One colour per method in every figure (a tuned method: its base's, dashed).
_METHOD_COLOURS = {"did-printed": "tab:blue", "did-dowhile": "tab:cyan",
                   "did-zscore": "tab:orange", "did-movable": "tab:green",
                   "did-printed-q0": "tab:olive", "did-majority": "gold",
                   "did-conflict-q0": "tab:pink",
                   "did-conflict-new": "tab:gray", "did-zm": "black", "did-q0": "tab:red",
                   "gnn": "tab:purple", "nn": "tab:brown"}
#: The methods of the per-scan figure (and their tuned versions).
_PER_SCAN = ("did-printed", "did-dowhile", "did-majority", "did-zm", "did-q0", "gnn", "nn")


def _style(m: str) -> dict:
    base, over = split_method(m)
    return {"color": _METHOD_COLOURS.get(base), "ls": "--" if over else "-",
            "label": label(m)}


def make_figures(summary: Mapping[str, Any], out, options: Mapping[str, Any]) -> list[str]:
    """Write the PNG figures into ``out``; [] without matplotlib."""
    return draw_all(summary, out, (_scene, _per_scan, _sweep), options)


def _scene(plt, summary, out, o) -> str | None:
    sc = exp._scenario(o)
    tp = exp._tracker(o)
    scans = sc.simulate(np.random.default_rng(int(o["example_seed"])))
    X = sc.truth()
    methods = ["did-printed", "did-q0", "gnn"]
    fig, axes = plt.subplots(1, 1 + len(methods), figsize=(4.2 * (1 + len(methods)), 4.7),
                             sharex=True, sharey=True)
    ax = axes[0]
    for s in scans:
        clutter = s.source < 0
        ax.plot(s.reports[clutter, 0] / 1e3, s.reports[clutter, 1] / 1e3, ".", ms=2,
                color="0.6")
        for t in range(sc.n_targets):
            sel = s.source == t
            ax.plot(s.reports[sel, 0] / 1e3, s.reports[sel, 1] / 1e3, ".", ms=3,
                    color=_COLOURS[t % 4])
    for t in range(sc.n_targets):
        ax.plot(X[:, t, 0] / 1e3, X[:, t, 1] / 1e3, "-", lw=0.8, color=_COLOURS[t % 4],
                label=f"target {t} ({'friend' if sc.iff[t] else 'foe'})")
    ax.set_title("true tracks and reports\n(like the paper's Fig. 2)", fontsize=9)
    ax.legend(fontsize=7, loc="upper left")
    for ax, m in zip(axes[1:], methods):
        log = run_tracker(scans, m, sc, tp)
        for t in range(sc.n_targets):
            ax.plot(X[:, t, 0] / 1e3, X[:, t, 1] / 1e3, "-", lw=3, color=_COLOURS[t % 4],
                    alpha=0.15)
        for tid, path in log.path.items():
            if not log.confirmed.get(tid) or len(path) < 2:
                continue
            p = np.array([(x, y) for _, x, y in path]) / 1e3
            own = log.owner[tid]
            ax.plot(p[:, 0], p[:, 1], "-", lw=0.9,
                    color=_COLOURS[own % 4] if own >= 0 else "k")
        ax.set_title(f"confirmed tracks: {label(m)}\n(like the paper's Fig. 3)",
                     fontsize=7)
    for ax in axes:
        ax.set_xlabel("x (km)")
        ax.set_aspect("equal")
        ax.grid(alpha=0.3)
    axes[0].set_ylabel("y (km)")
    fig.suptitle(f"one run (seed {o['example_seed']}), noise scale {sc.noise_scale:g}, "
                 f"clutter mean {sc.clutter_mean:g} per scan (ours); track colour = the "
                 "target whose report started it, black = started by clutter", fontsize=9)
    return save(fig, out, "fig_scene.png", rect=(0, 0, 1, 0.93), bbox_inches="tight")


def _per_scan(plt, summary, out, o) -> str | None:
    recs = [r for r in summary["records"] if r["experiment"] == "main"
            and r["metric"].startswith("car_k")]
    if not recs:
        return None
    fig, ax = plt.subplots(figsize=(8, 5))
    for m in ordered({r["method"] for r in recs}):
        if split_method(m)[0] not in _PER_SCAN:
            continue
        rows = sorted((int(r["metric"][5:]), r["value"], r["stderr"] or 0.0)
                      for r in recs if r["method"] == m)
        k, v, se = map(np.array, zip(*rows))
        line, = ax.plot(k, v, lw=1.2, **_style(m))
        ax.fill_between(k, v - 1.96 * se, v + 1.96 * se, color=line.get_color(), alpha=0.15)
    for k in (20, 30):
        ax.axvline(k, color="0.5", ls=":", lw=0.8)
    runs = max(r["runs"] for r in recs)
    ax.set_xlabel("scan k (crossings at k = 20: targets 0/1, k = 30: targets 2/3)")
    ax.set_ylabel("correct association rate")
    ax.set_title(f"per-scan correct association rate, base scene ({runs} runs, 95 % bands)",
                 fontsize=9)
    ax.set_ylim(0, 1.02)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=6, loc="lower left")
    return save(fig, out, "fig_per_scan.png")


def _sweep(plt, summary, out, o) -> str | None:
    tab = lookup(summary["records"], "sweep", "correct_rate")
    if not tab:
        return None
    clutter = sorted({k[2] for k in tab})
    fig, axes = plt.subplots(1, len(clutter), figsize=(4 * len(clutter), 3.8), sharey=True)
    axes = np.atleast_1d(axes)
    for ax, c in zip(axes, clutter):
        for m in ordered({k[0] for k in tab}):
            pts = sorted((k[1], *v) for k, v in tab.items() if k[0] == m and k[2] == c)
            if not pts:
                continue
            f, v, _, se = zip(*pts)
            ax.errorbar(f, v, yerr=1.96 * np.array([s or 0.0 for s in se]), marker="o",
                        ms=3, capsize=2, **_style(m))
        ax.set_title(f"clutter mean {c:g} per scan", fontsize=9)
        ax.set_xlabel("noise scale (x sigma_p, sigma_v)")
        ax.grid(alpha=0.3)
    axes[0].set_ylabel("correct association rate")
    axes[0].legend(fontsize=6)
    runs = max(v[1] for v in tab.values())
    fig.suptitle(f"where each method breaks ({runs} runs per point, 95 % CI)", fontsize=9)
    return save(fig, out, "fig_sweep.png", rect=(0, 0, 1, 0.93), bbox_inches="tight")
