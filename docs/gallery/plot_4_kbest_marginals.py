"""
Ranked assignments and association probabilities
================================================

:func:`~assocopt.kbest` ranks the assignments of a problem, best first (Murty's
method); :func:`~assocopt.marginals` turns them into association probabilities
``P(track i <- measurement j)``, weighting each assignment by
``exp(-cost / temperature)`` (with negative log-likelihood costs and temperature 1,
the probabilities of joint probabilistic data association).
"""

import matplotlib.pyplot as plt
import numpy as np

from assocopt import AssignmentProblem, kbest, marginals

rng = np.random.default_rng(3)
C = rng.normal(size=(4, 5))                     # 4 tracks, 5 measurements
problem = AssignmentProblem.two_d(C, row_miss=1.0, col_miss=0.5)

ranked = kbest(problem, 8)
for rank, sol in enumerate(ranked, start=1):
    rows, cols = sol.assignment()
    print(f"{rank}: cost {sol.objective:7.3f}  pairs {list(zip(rows.tolist(), cols.tolist()))}")
print("every assignment ranked:", ranked.exhausted)

# %%
m = marginals(problem, k=200, temperature=1.0, method="kbest")
print("each track's probabilities (pairs + miss) sum to",
      np.round(m.pairs.sum(axis=1) + m.row_miss, 6))

fig, ax = plt.subplots(figsize=(6.5, 3.8))
P = np.column_stack([m.pairs, m.row_miss])
im = ax.imshow(P, vmin=0, vmax=1, cmap="magma")
for (i, j), v in np.ndenumerate(P):
    ax.text(j, i, f"{v:.2f}", ha="center", va="center",
            color="white" if v < 0.5 else "black", fontsize=9)
ax.set_xticks(range(P.shape[1]), [f"z{j}" for j in range(C.shape[1])] + ["miss"])
ax.set_yticks(range(P.shape[0]), [f"track {i}" for i in range(C.shape[0])])
ax.set_title("association probabilities from the 200 best assignments")
fig.colorbar(im, ax=ax)
plt.show()
