"""Draw docs/tracking-example.png: the guide's two tracking loops on one scenario.

Runs the python blocks of the guide's section "From measurements to a decision"
(so the figure shows exactly what the guide computes), then plots the truth, the
measurements (clutter included) and the tracks of the numpy + assocopt loop and of
the Stone Soup + assocopt loop.

Usage::

    python docs/tracking_figure.py [--out docs/tracking-example.png]
"""

from __future__ import annotations

import argparse
import re
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
SECTION = "## From measurements to a decision"


def section_blocks(guide: Path = ROOT / "docs" / "guide.md",
                   section: str = SECTION) -> list[str]:
    """The python blocks of one section of the guide (the tracking one), in order."""
    text = guide.read_text(encoding="utf-8")
    start = text.index(section)
    end = text.find("\n## ", start + len(section))
    body = text[start:end if end > 0 else None]
    return re.findall(r"^```python\n(.*?)^```", body, re.MULTILINE | re.DOTALL)


def run_section(section: str = SECTION) -> dict:
    """The namespace after running the section's python blocks in order."""
    namespace: dict = {"__name__": "guide"}
    for block in section_blocks(section=section):
        exec(compile(block, "guide.md", "exec"), namespace)
    return namespace


def draw(ns: dict, out: Path) -> None:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    scans, est, ss = ns["scans"], ns["estimates"], ns["ss"]
    fig, ax = plt.subplots(figsize=(8.5, 6))
    plot_scans(ax, scans.meas, scans.labels)
    for i in range(est.shape[1]):
        ax.plot(scans.truth[:, i, 0], scans.truth[:, i, 2], "k--", lw=1,
                label="truth" if i == 0 else None)
        ax.plot(est[:, i, 0], est[:, i, 2], "-", c="tab:blue", lw=1.8,
                label="numpy + assocopt" if i == 0 else None)
        ax.plot(ss[i, :, 0], ss[i, :, 1], ":", c="tab:orange", lw=2.2,
                label="Stone Soup + AssocoptGNN" if i == 0 else None)
    save(fig, ax, f"{est.shape[1]} targets, {len(scans.meas)} scans, "
         f"P_D = {ns['sc'].pd}, clutter {ns['sc'].clutter_rate:g} per scan", out)


def plot_scans(ax, meas: list, labels: list) -> None:
    """All scans' measurements: detections grey dots, clutter light crosses."""
    import numpy as np
    z = np.concatenate(meas)
    lab = np.concatenate(labels)
    ax.scatter(z[lab >= 0, 0], z[lab >= 0, 1], s=8, c="0.55", label="detections")
    ax.scatter(z[lab < 0, 0], z[lab < 0, 1], s=8, marker="x", c="0.75", label="clutter")


def save(fig, ax, title: str, out: Path) -> None:
    """Axes labelled, equal aspect, the legend outside, written to ``out``."""
    import matplotlib.pyplot as plt
    ax.set_xlabel("x")
    ax.set_ylabel("y")
    ax.set_aspect("equal")
    ax.set_title(title)
    ax.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize=8)
    fig.tight_layout()
    fig.savefig(out, dpi=110)
    plt.close(fig)


def figure_main(doc: str, default: str, run, draw_figure, argv=None) -> Path:
    """The command line of a guide figure script: ``--out`` (default ``default``
    under docs/), run the section, draw, say where."""
    ap = argparse.ArgumentParser(description=doc.splitlines()[0])
    ap.add_argument("--out", default=str(ROOT / "docs" / default))
    args = ap.parse_args(argv)
    sys.path.insert(0, str(ROOT))
    out = Path(args.out)
    draw_figure(run(), out)
    print(f"wrote {out}")
    return out


def main(argv=None) -> Path:
    return figure_main(__doc__, "tracking-example.png", run_section, draw, argv)


if __name__ == "__main__":
    main()
