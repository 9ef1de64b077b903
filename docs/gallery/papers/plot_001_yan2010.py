"""
Yan et al. 2010: multi-feature D-S track-to-track association
=============================================================

Correct association rate over time of the D-S rules (the paper's and ours, with
the 2-D assignment) and the weighted chi-square test (the paper's Fig. 4, our run).

Drawn by ``assocopt.reproduce.yan2010.make_figures`` from the committed
``docs/papers/yan2010/summary.json`` (the run behind :doc:`the paper's page
<../../papers/yan2010>`), shown here as that code writes it (``fig4_correct_rate.png``).
"""

import json
import tempfile
from pathlib import Path

import matplotlib.pyplot as plt

from assocopt.reproduce.yan2010 import make_figures

# the committed run: docs/papers/yan2010/summary.json (this script runs in docs/gallery/papers)
summary = json.loads(Path("../../papers/yan2010/summary.json").read_text())
print(summary["title"])
print(f"{summary['runs']} Monte Carlo runs, master seed {summary['seed']}")

with tempfile.TemporaryDirectory() as out:
    written = make_figures(summary, out)
    image = plt.imread(Path(out) / "fig4_correct_rate.png")
print("figures:", ", ".join(written))

h, w = image.shape[:2]
fig = plt.figure(figsize=(w / 100, h / 100), dpi=100)
fig.figimage(image)
plt.show()
