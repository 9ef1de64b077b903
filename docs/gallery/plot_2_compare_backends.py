"""
Comparing back ends
===================

Every back end answers the same problem with the same :class:`~assocopt.Solution`, so
comparing them is a loop.  Random axial 3-D problems of growing size (integer costs,
which CP-SAT solves without scaling) are solved by the general MILP solvers and by
assocopt's own Lagrangian solvers; all proven optima agree, and the plot shows the time each took (build + solve, one run on the machine that
built this page, so only the trend means anything; ``benchmarks/`` has the measured
comparisons).
"""

import matplotlib.pyplot as plt
import numpy as np

from assocopt import solve
from assocopt.solvers import available
from assocopt.testing import random_problem

SOLVERS = [s for s in ("highs", "scipy", "ortools-cpsat", "lagrangian-exact", "bnb")
           if s in available()]
SIZES = [4, 6, 8, 10, 12]

solve(random_problem(np.random.default_rng(0), "axial3", (4, 4, 4)), solver="bnb")  # compile once

times = {s: [] for s in SOLVERS}
for n in SIZES:
    problem = random_problem(np.random.default_rng(n), "axial3", (n, n, n), integer=True)
    answers = {s: solve(problem, solver=s) for s in SOLVERS}
    optimum = answers[SOLVERS[0]].objective
    for s, sol in answers.items():
        assert sol.status == "optimal" and abs(sol.objective - optimum) < 1e-9, (s, sol)
        times[s].append(sol.times["build"] + sol.times["solve"])
    print(f"n = {n:2d}: optimum {optimum:.4f}, agreed by {len(answers)} back ends")

# %%
fig, ax = plt.subplots(figsize=(6, 4))
for s, ts in times.items():
    ax.plot([n ** 3 for n in SIZES], ts, marker="o", label=s)
ax.set_xscale("log")
ax.set_yscale("log")
ax.set_xlabel("candidates (n^3)")
ax.set_ylabel("build + solve, s")
ax.set_title("Random n x n x n axial assignment, integer costs")
ax.legend()
plt.show()
