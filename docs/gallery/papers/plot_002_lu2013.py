"""
Lu et al. 2013: passive-sensor S-D association with KLD / SKLD costs
====================================================================

Correct association rate of the S-D assignment with Pattipati's, KLD and SKLD
costs against the target spacing d, for two bearing noises (the paper's Fig. 2,
our run).

Drawn by ``assocopt.reproduce.lu2013.make_figures`` from the committed
``docs/papers/lu2013/summary.json`` (the run behind :doc:`the paper's page
<../../papers/lu2013>`), shown here as that code writes it (``fig2_correct.png``).
"""

import json
import tempfile
from pathlib import Path

import matplotlib.pyplot as plt

from assocopt.reproduce.lu2013 import make_figures

# the committed run: docs/papers/lu2013/summary.json (this script runs in docs/gallery/papers)
summary = json.loads(Path("../../papers/lu2013/summary.json").read_text())
print(summary["title"])
print(f"{summary['runs']} Monte Carlo runs, master seed {summary['seed']}")

with tempfile.TemporaryDirectory() as out:
    written = make_figures(summary, out)
    image = plt.imread(Path(out) / "fig2_correct.png")
print("figures:", ", ".join(written))

h, w = image.shape[:2]
fig = plt.figure(figsize=(w / 100, h / 100), dpi=100)
fig.figimage(image)
plt.show()
