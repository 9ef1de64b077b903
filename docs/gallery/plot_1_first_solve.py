"""
From a cost tensor to a solution
================================

An association decision is an assignment problem: here, which of five measurements
continues which of five tracks.  Build the problem from a cost matrix, solve it, read
the answer, then let a track go unassigned (missed detection) and a measurement be
left over (clutter) at a price, and finally the same for three sensors (S-D).
"""

import matplotlib.pyplot as plt
import numpy as np

from assocopt import AssignmentProblem, solve

rng = np.random.default_rng(0)
C = rng.random((5, 5))                     # C[i, j]: cost of track i <- measurement j

# %%
# A square 2-D problem: every track takes exactly one measurement.
sol = solve(AssignmentProblem.dense(C))
print(sol.status, sol.objective, sol.bound, sol.solver)
rows, cols = sol.assignment()              # 0-based, like linear_sum_assignment
print(list(zip(rows.tolist(), cols.tolist())))

# %%
# With non-assignment costs: leaving track ``i`` without a measurement costs
# ``row_miss[i]``, leaving measurement ``j`` unused costs ``col_miss[j]``.  Pairs that
# cost more than the two misses together are then better left apart.
p2 = AssignmentProblem.two_d(C, row_miss=0.3, col_miss=0.3)
sol2 = solve(p2)
rows2, cols2 = sol2.assignment()
print(sol2.objective, "pairs:", list(zip(rows2.tolist(), cols2.tolist())))

fig, axes = plt.subplots(1, 2, figsize=(8, 3.8), sharey=True)
for ax, (r, c), title in zip(axes, [(rows, cols), (rows2, cols2)],
                             ["every track assigned", "misses cost 0.3 each"]):
    im = ax.imshow(C, cmap="viridis")
    ax.scatter(c, r, marker="o", s=180, facecolors="none", edgecolors="red", linewidths=2)
    ax.set_title(title)
    ax.set_xlabel("measurement j")
axes[0].set_ylabel("track i")
fig.colorbar(im, ax=axes, label="cost C[i, j]")
plt.show()

# %%
# Three sensors (S-D assignment): index 0 of each axis is the dummy (not seen by that
# sensor), real indices are 1..n.  A candidate tuple lists one index per sensor.
p3 = AssignmentProblem.sparse(sizes=(2, 2, 2),
                              tuples=[[1, 1, 1], [2, 2, 2], [1, 2, 1], [1, 0, 0],
                                      [2, 0, 0], [0, 1, 0], [0, 2, 0], [0, 0, 1],
                                      [0, 0, 2]],
                              costs=[-3.0, -2.5, -2.9, 0, 0, 0, 0, 0, 0])
sol3 = solve(p3)
print(sol3.status, sol3.objective, sol3.tuples.tolist())

# %%
# The LP relaxation gives a bound and a fractional solution; ``integral`` says whether
# the relaxation happened to be integral (then it is the optimum).
lp = solve(p3, solver="highs", relax="lp")
print(lp.objective, lp.integral)
