"""Figures of the paper-002 reproduction, drawn from ``summary.json`` alone."""

from __future__ import annotations

from typing import Any, Mapping, Sequence

import numpy as np

from .._plot import pyplot, save
from .report import D_GRID, REFERENCE, SIGMAS, _methods, index_records

__all__ = ["make_figures"]


def make_figures(summary: Mapping[str, Any], out) -> list[str]:
    """Fig. 1 (r versus d), Fig. 2 (difference to ref. [2] with 95 % bands, and the
    rates themselves) as PNG; [] without matplotlib."""
    plt = pyplot()
    if plt is None:
        return []
    from pathlib import Path
    out = Path(out)
    ix = index_records(summary["records"])
    methods = _methods(summary)
    if not any(k[0] == "fig" for k in ix):
        return []
    made = []
    colours = {m: plt.get_cmap("tab10")(i % 10) for i, m in enumerate(methods)}

    def curves(metric, s, m):
        ds = [d for d in D_GRID if ("fig", "x", None, s, d, None, m, metric) in ix]
        rs = [ix[("fig", "x", None, s, d, None, m, metric)] for d in ds]
        return (np.array(ds), np.array([r["value"] for r in rs]),
                np.array([r["stderr"] or 0.0 for r in rs]), max((r["runs"] for r in rs), default=0))

    specs = [("fig1_r.png", "r_data", "r = C_best / C_ave (cost constants dropped)",
              (-0.05, 1.05)),
             ("fig1_r_full.png", "r_full", "r = C_best / C_ave (costs as printed, radians)", None)]
    for fname, metric, ylabel, ylim in specs:
        fig, axes = plt.subplots(1, 2, figsize=(11, 4.4), sharex=True)
        runs = 0
        for ax, s in zip(axes, SIGMAS):
            for m in methods:
                ds, ys, _, runs = curves(metric, s, m)
                label = m
                if ylim is not None and any(not (ylim[0] <= y <= ylim[1]) for y in ys):
                    label += " (leaves the axis)"
                ax.plot(ds, ys, "-" if m in summary["paper_labels"].values() else "--",
                        color=colours[m], label=label, lw=1.3)
            if ylim is not None:
                ax.set_ylim(*ylim)
            ax.set_title(f"σ = {s:g} mrad")
            ax.set_xlabel("target spacing d (km)")
            ax.set_ylabel(ylabel)
            ax.grid(alpha=0.3)
        _shared_legend(fig, axes)
        fig.suptitle(f"Fig. 1: solution discrimination r versus d (ours, {runs} runs per point)")
        made.append(save(fig, out, fname, rect=(0, 0.1, 1, 1)))

    # Fig. 2, differences to the reference (the comparison the paper is about): one row
    # for the paper's costs as printed (and the reversed KL, which decides like them),
    # one for the exact divergences and the ML position; a legend in every panel
    rows = [[m for m in methods if m in ("kld-printed", "skld-printed", "kld-reversed")],
            [m for m in methods[1:] if m not in ("kld-printed", "skld-printed",
                                                  "kld-reversed")]]
    rows = [r for r in rows if r]
    fig, axes = plt.subplots(len(rows), 2, figsize=(11, 4.0 * len(rows)), sharex=True,
                             squeeze=False)
    runs = 0
    g = summary["paper_values"]["fig2_mean_gain_over_ref2"]
    for i, row in enumerate(rows):
        for ax, s in zip(axes[i], SIGMAS):
            ax.axhline(0.0, color="k", lw=0.8)
            for m in row:
                ds, ys, se, runs = curves(f"partition_correct - {REFERENCE}", s, m)
                ax.plot(ds, 100 * ys, color=colours[m], lw=1.3, label=m)
                ax.fill_between(ds, 100 * (ys - 1.96 * se), 100 * (ys + 1.96 * se),
                                color=colours[m], alpha=0.15, lw=0)
            for lab, ls in (("KLD", ":"), ("SKLD", "-.")):
                ax.axhline(g[lab][f"{s:.1f}"], color="0.3", ls=ls, lw=1.0,
                           label=f"paper: mean gain of {lab} (text)")
            ax.set_title(f"σ = {s:g} mrad")
            ax.set_xlabel("target spacing d (km)")
            ax.set_ylabel("correct rate minus ref. [2]'s\n(percentage points)")
            ax.grid(alpha=0.3)
            ax.legend(fontsize=7, loc="lower right", ncol=2)
    fig.suptitle(f"Fig. 2: each cost's correct association rate minus ref. [2]'s, paired, "
                 f"95 % bands (ours, {runs} runs per point)")
    made.append(save(fig, out, "fig2_difference.png"))

    # Fig. 2, the rates themselves (ref. [2] with its band; the others are within it)
    fig, axes = plt.subplots(1, 2, figsize=(11, 4.4), sharex=True)
    for ax, s in zip(axes, SIGMAS):
        for m in methods:
            ds, ys, se, runs = curves("partition_correct", s, m)
            ax.plot(ds, ys, color=colours[m], lw=1.2, label=m)
            if m == REFERENCE:
                ax.fill_between(ds, ys - 1.96 * se, ys + 1.96 * se, color=colours[m],
                                alpha=0.2, lw=0, label="ref. [2], 95 % band")
        ax.set_title(f"σ = {s:g} mrad")
        ax.set_xlabel("target spacing d (km)")
        ax.set_ylabel("correct association rate")
        ax.grid(alpha=0.3)
    _shared_legend(fig, axes)
    fig.suptitle(f"Fig. 2: correct association rate versus d (ours, {runs} runs per point)")
    made.append(save(fig, out, "fig2_correct.png", rect=(0, 0.1, 1, 1)))
    return made


def _shared_legend(fig, axes: Sequence) -> None:
    """One legend below both panels (every curve of both panels, once)."""
    handles, labels = {}, []
    for ax in axes:
        for h, lab in zip(*ax.get_legend_handles_labels()):
            if lab not in handles:
                handles[lab] = h
                labels.append(lab)
    fig.legend([handles[lab] for lab in labels], labels, loc="lower center",
               ncol=min(5, len(labels)), fontsize=8, frameon=False)
