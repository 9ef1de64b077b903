"""
Zhang et al. 2009: group member matching
========================================

Correct matching rate of two matching measures (MM-TBM with truncation, MM-NCR
with MD-ND) against the noise factor f (the paper's Fig. 1, our run).

Drawn by ``assocopt.reproduce.zhang2009.make_figures`` from the committed
``docs/papers/zhang2009/summary.json`` (the run behind :doc:`the paper's page
<../../papers/zhang2009>`), shown here as that code writes it (``fig1_pc_vs_f_measures.png``).
"""

import json
import tempfile
from pathlib import Path

import matplotlib.pyplot as plt

from assocopt.reproduce.zhang2009 import make_figures

# the committed run: docs/papers/zhang2009/summary.json (this script runs in docs/gallery/papers)
summary = json.loads(Path("../../papers/zhang2009/summary.json").read_text())
print(summary["title"])
print(f"{summary['runs']} Monte Carlo runs, master seed {summary['seed']}")

with tempfile.TemporaryDirectory() as out:
    written = make_figures(summary, out)
    image = plt.imread(Path(out) / "fig1_pc_vs_f_measures.png")
print("figures:", ", ".join(written))

h, w = image.shape[:2]
fig = plt.figure(figsize=(w / 100, h / 100), dpi=100)
fig.figimage(image)
plt.show()
