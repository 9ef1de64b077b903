"""
Dong et al. 2015: anti-bias track association by topology
=========================================================

Correct association rate per step of the topology statistical distance (as
reconstructed and with our corrections), the Euclidean topology distance and GNN on
biased tracks, in the paper's three environments (its Figs. 5-7, our run).

Drawn by ``assocopt.reproduce.dong2015.make_figures`` from the committed
``docs/papers/dong2015/summary.json`` (the run behind :doc:`the paper's page
<../../papers/dong2015>`), shown here as that code writes it (``fig_ec_per_step.png``).
"""

import json
import tempfile
from pathlib import Path

import matplotlib.pyplot as plt

from assocopt.reproduce.dong2015 import make_figures

# the committed run: docs/papers/dong2015/summary.json (this script runs in docs/gallery/papers)
summary = json.loads(Path("../../papers/dong2015/summary.json").read_text())
print(summary["title"])
print(f"{summary['runs']} Monte Carlo runs, master seed {summary['seed']}")

with tempfile.TemporaryDirectory() as out:
    written = make_figures(summary, out)
    image = plt.imread(Path(out) / "fig_ec_per_step.png")
print("figures:", ", ".join(written))

h, w = image.shape[:2]
fig = plt.figure(figsize=(w / 100, h / 100), dpi=100)
fig.figimage(image)
plt.show()
