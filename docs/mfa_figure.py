"""Draw docs/mfa-example.png: the guide's Stone Soup MFA tracker both ways.

Runs the python block of the guide's section "Multi-frame assignment in Stone Soup"
(so the figure shows exactly what the guide computes), then plots the truth, the
detections and clutter, and the most probable track positions of the tracker with
Stone Soup's ``MFADataAssociator`` and with ``AssocoptMFA``.

Usage::

    python docs/mfa_figure.py [--out docs/mfa-example.png]
"""

from __future__ import annotations

import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "docs"))

import tracking_figure  # noqa: E402
from tracking_figure import figure_main, plot_scans, save, section_blocks  # noqa: E402,F401

SECTION = "## Multi-frame assignment in Stone Soup"


def run_section() -> dict:
    return tracking_figure.run_section(SECTION)


def draw(ns: dict, out: Path) -> None:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    run, sc = ns["run"], ns["crossing"]
    fig, ax = plt.subplots(figsize=(8.5, 6))
    plot_scans(ax, run.meas, run.labels)
    for i in range(run.truth.shape[1]):
        ax.plot(run.truth[:, i, 0], run.truth[:, i, 2], "k--", lw=1,
                label="truth" if i == 0 else None)
        ax.plot(ns["stone_soup"][i, :, 0], ns["stone_soup"][i, :, 1], "-", c="tab:blue",
                lw=1.8, label="MFADataAssociator" if i == 0 else None)
        ax.plot(ns["exact"][i, :, 0], ns["exact"][i, :, 1], ":", c="tab:orange", lw=2.2,
                label="AssocoptMFA (proven optimal windows)" if i == 0 else None)
    save(fig, ax, f"{run.truth.shape[1]} targets crossing in pairs, {len(run.meas)} "
         f"scans, window 3, P_D = {sc.pd}, clutter {sc.clutter_rate:g} per scan", out)


def main(argv=None) -> Path:
    return figure_main(__doc__, "mfa-example.png", run_section, draw, argv)


if __name__ == "__main__":
    main()
