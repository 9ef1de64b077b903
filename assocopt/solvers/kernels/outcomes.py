"""The outcome codes the search kernels return, importable without numba (a caller
that runs a kernel interpreted, :mod:`.tiers`, never loads numba for them).

May import: nothing.
"""

__all__ = ["PROVEN", "STOPPED", "INFEASIBLE", "COMPLETE", "BUDGET"]

# driver.solve() / batch.solve_batch() outcomes
PROVEN = 0         # incumbent optimal (or infeasible if there is none)
STOPPED = 1        # budget spent: incumbent (if any) and a bound
INFEASIBLE = 2     # the kept axes admit no assignment

# search.dfs() outcomes
COMPLETE = 0       # search exhausted: the incumbent (if any) is optimal
BUDGET = 1         # node budget spent
