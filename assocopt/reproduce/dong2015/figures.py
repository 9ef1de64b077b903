"""Figures of the paper-004 reproduction: E_c per step per environment (Figs. 5-7), the
heading error (Fig. 2), E_c against the threshold coefficient (Figs. 3-4) and the
growth of the time per step; 95 % bands everywhere."""

from __future__ import annotations

from typing import Any, Mapping

import numpy as np

from .._plot import draw_all, save
from .experiment import LABELS
from .report import lookup, steps_of

__all__ = ["make_figures", "FIG_METHODS"]

#: Methods drawn in the per-environment figures (all are in the tables).
FIG_METHODS = ("tsd-rect", "tsd-rect-noself", "ted-rect", "tsd-rect-c", "tsd", "tsd-c", "gnn")


def make_figures(summary: Mapping[str, Any], out) -> list[str]:
    """Write the PNG figures into ``out``; [] without matplotlib."""
    return draw_all(summary, out, (_per_env, _heading, _coef, _timing))


def _curve(recs, part, prefix, method, env, coef=None):
    ks = steps_of(recs, part)
    vals, ses = [], []
    for k in ks:
        tab = lookup(recs, part, f"{prefix}_k{k:02d}")
        v = next((v for key, v in tab.items() if key[0] == method and key[1] == env
                  and (coef is None or key[2] == coef)), None)
        vals.append(np.nan if v is None else v[0])
        ses.append(np.nan if v is None or v[2] is None else v[2])
    return np.array(ks), np.array(vals), np.array(ses)


def _band(ax, k, v, se, label, **kw):
    line, = ax.plot(k, v, marker="o", ms=3, label=label, **kw)
    ax.fill_between(k, v - 1.96 * se, v + 1.96 * se, color=line.get_color(), alpha=0.15)


def _per_env(plt, summary, out) -> str | None:
    recs = summary["records"]
    if not steps_of(recs, "main"):
        return None
    fig, axes = plt.subplots(1, 3, figsize=(15, 4.4), sharey=True)
    for ax, env in zip(axes, (1, 2, 3)):
        for m in FIG_METHODS:
            k, v, se = _curve(recs, "main", "ec", m, env)
            if np.isfinite(v).any():
                _band(ax, k, v, se, LABELS.get(m, m))
        ax.set_title(f"environment {env} (paper's Fig. {4 + env})")
        ax.set_xlabel("step")
        ax.set_ylim(-0.02, 1.02)
        ax.grid(alpha=0.3)
    axes[0].set_ylabel("correct association rate E_c")
    axes[-1].legend(fontsize=7, loc="lower right")
    return save(fig, out, "fig_ec_per_step.png")


def _heading(plt, summary, out) -> str | None:
    recs = summary["records"]
    k, v, _ = _curve(recs, "main", "hd1t0", "tsd", 2)
    if not np.isfinite(v).any():
        return None
    fig, ax = plt.subplots(figsize=(6, 4))
    for c, lab in (("hd1t0", "sensor 1, one target"), ("hd2t0", "sensor 2, one target"),
                   ("hd1", "sensor 1, all targets"), ("hd2", "sensor 2, all targets")):
        k, v, se = _curve(recs, "main", c, "tsd", 2)
        _band(ax, k, v, se, lab, ls="-" if "t0" in c else "--")
    ax.axhline(0.1, color="0.5", lw=0.8, ls=":")
    ax.set_xlabel("step")
    ax.set_ylabel("mean |heading error| (rad)")
    ax.set_title("heading error, environment 2 (paper's Fig. 2)")
    ax.legend(fontsize=8)
    ax.grid(alpha=0.3)
    return save(fig, out, "fig_heading.png")


def _coef(plt, summary, out) -> str | None:
    recs = summary["records"]
    ks = steps_of(recs, "coef")
    if not ks:
        return None
    tab = lookup(recs, "coef", f"ec_k{ks[0]:02d}")
    methods = sorted({key[0] for key in tab}, key=lambda m: list(LABELS).index(m))
    coefs = sorted({key[2] for key in tab})
    fig, axes = plt.subplots(1, len(methods), figsize=(4.2 * len(methods), 4), sharey=True)
    for ax, m in zip(np.atleast_1d(axes), methods):
        for c in coefs:
            k, v, se = _curve(recs, "coef", "ec", m, 2, c)
            _band(ax, k, v, se, f"coef {c:g}")
        ax.set_title(LABELS.get(m, m), fontsize=9)
        ax.set_xlabel("step")
        ax.grid(alpha=0.3)
    np.atleast_1d(axes)[0].set_ylabel("E_c (environment 2)")
    np.atleast_1d(axes)[-1].legend(fontsize=7)
    fig.suptitle("threshold coefficient of our T_1 substitute (paper's Figs. 3-4)", fontsize=10)
    return save(fig, out, "fig_coef.png")


def _timing(plt, summary, out) -> str | None:
    t = lookup(summary["records"], "timing", "t_step_ms")
    if not t:
        return None
    fig, ax = plt.subplots(figsize=(6, 4))
    for m in sorted({k[0] for k in t}, key=lambda m: list(LABELS).index(m)):
        pts = sorted((k[3], v) for k, v in t.items() if k[0] == m)
        n = np.array([p[0] for p in pts])
        ax.loglog(n, [p[1][0] for p in pts], marker="o", label=LABELS.get(m, m))
    n = np.array(sorted({k[3] for k in t}), dtype=float)
    ref = next(v[0] for k, v in t.items() if k[0] == "tsd-c" and k[3] == n[0]) \
        if any(k[0] == "tsd-c" for k in t) else None
    if ref:
        ax.loglog(n, ref * (n / n[0]) ** 4, color="0.6", ls=":", label="~ n^4")
    ax.set_xlabel("targets per sensor")
    ax.set_ylabel("time per step (ms)")
    ax.legend(fontsize=8)
    ax.grid(alpha=0.3, which="both")
    return save(fig, out, "fig_timing.png")
