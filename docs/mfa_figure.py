"""Draw docs/mfa-example.png: the guide's Stone Soup MFA tracker both ways.

Runs the python block of the guide's section "Multi-frame assignment in Stone Soup"
(so the figure shows exactly what the guide computes), then plots the truth, the
detections and clutter, and the most probable track positions of the tracker with
Stone Soup's ``MFADataAssociator`` and with ``AssocoptMFA``.

Usage::

    python docs/mfa_figure.py [--out docs/mfa-example.png]
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "docs"))

from tracking_figure import section_blocks  # noqa: E402

SECTION = "## Multi-frame assignment in Stone Soup"


def run_section() -> dict:
    namespace: dict = {"__name__": "guide"}
    for block in section_blocks(section=SECTION):
        exec(compile(block, "guide.md", "exec"), namespace)
    return namespace


def draw(ns: dict, out: Path) -> None:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import numpy as np

    run, sc = ns["run"], ns["crossing"]
    fig, ax = plt.subplots(figsize=(8.5, 6))
    z = np.concatenate(run.meas)
    lab = np.concatenate(run.labels)
    ax.scatter(z[lab >= 0, 0], z[lab >= 0, 1], s=8, c="0.55", label="detections")
    ax.scatter(z[lab < 0, 0], z[lab < 0, 1], s=8, marker="x", c="0.75", label="clutter")
    for i in range(run.truth.shape[1]):
        ax.plot(run.truth[:, i, 0], run.truth[:, i, 2], "k--", lw=1,
                label="truth" if i == 0 else None)
        ax.plot(ns["stone_soup"][i, :, 0], ns["stone_soup"][i, :, 1], "-", c="tab:blue",
                lw=1.8, label="MFADataAssociator" if i == 0 else None)
        ax.plot(ns["exact"][i, :, 0], ns["exact"][i, :, 1], ":", c="tab:orange", lw=2.2,
                label="AssocoptMFA (proven optimal windows)" if i == 0 else None)
    ax.set_xlabel("x")
    ax.set_ylabel("y")
    ax.set_aspect("equal")
    ax.set_title(f"{run.truth.shape[1]} targets crossing in pairs, {len(run.meas)} scans, "
                 f"window 3, P_D = {sc.pd}, clutter {sc.clutter_rate:g} per scan")
    ax.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize=8)
    fig.tight_layout()
    fig.savefig(out, dpi=110)
    plt.close(fig)


def main(argv=None) -> Path:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", default=str(ROOT / "docs" / "mfa-example.png"))
    args = ap.parse_args(argv)
    sys.path.insert(0, str(ROOT))
    out = Path(args.out)
    draw(run_section(), out)
    print(f"wrote {out}")
    return out


if __name__ == "__main__":
    main()
