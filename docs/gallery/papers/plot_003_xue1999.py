"""
Xue et al. 1999: distributed inference decision on crossing targets
===================================================================

Where each method breaks: correct association rate of DID (as printed, and with
our correction), GNN and nearest neighbour against the noise scale, for three
clutter levels.

Drawn by ``assocopt.reproduce.xue1999.make_figures`` from the committed
``docs/papers/xue1999/summary.json`` (the run behind :doc:`the paper's page
<../../papers/xue1999>`), shown here as that code writes it (``fig_sweep.png``).
"""

import json
import tempfile
from pathlib import Path

import matplotlib.pyplot as plt

from assocopt.reproduce.xue1999 import DEFAULTS, make_figures

# the committed run: docs/papers/xue1999/summary.json (this script runs in docs/gallery/papers)
summary = json.loads(Path("../../papers/xue1999/summary.json").read_text())
print(summary["title"])
print(f"{summary['runs']} Monte Carlo runs, master seed {summary['seed']}")

with tempfile.TemporaryDirectory() as out:
    written = make_figures(summary, out, DEFAULTS)
    image = plt.imread(Path(out) / "fig_sweep.png")
print("figures:", ", ".join(written))

h, w = image.shape[:2]
fig = plt.figure(figsize=(w / 100, h / 100), dpi=100)
fig.figimage(image)
plt.show()
