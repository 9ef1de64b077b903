"""Compiled kernels of the ``bnb`` back end (numba, nopython): a dense Hungarian
method with duals, the Lagrangian relaxation to a 2-D assignment with misses, and a
depth-first exact-cover branch and bound on reduced costs.

Importing this module imports numba; :mod:`assocopt.solvers.bnb.backend` does so only inside
``solve``.  Functions are compiled on first use and cached on disk (``cache=True``).

Notation (as in :mod:`assocopt.solvers.lagrangian`): ``K`` candidates, ``N`` axes,
``G[k, s]`` the global row of the real index of candidate ``k`` on axis ``s`` (-1 for
the dummy), ``E`` real indices in all.  Axes ``a, b`` are kept, the others relaxed
with multipliers ``y[e]``.  For *any* ``y`` and any exact cover ``X``:

    cost(X) = sum_e y[e] + sum_{k in X} r[k],   r[k] = c[k] - sum_{e in k} y[e],

so ``base + sum_{k in X} max(r[k], 0)`` with ``base = sum(y) + sum_k min(r[k], 0)``
bounds every solution from below: the bound is valid whatever the multipliers, and
the ascent only makes it tight.
"""

from typing import Any

from ..kernels import ensure, spent, uninterrupted  # noqa: F401  (compile clock; Ctrl-C)
from ..kernels.driver import (INFEASIBLE, PROVEN, STOPPED, recover3, solve,  # noqa: F401
                             tuple_index)
from ..kernels.hungarian import hungarian, hungarian_warm  # noqa: F401
from ..kernels.relaxation import (evaluate, full_reduced, improve_limit,  # noqa: F401
                                 prepare, raise_rows, reduced, sort_lists)
from ..kernels.search import BUDGET, COMPLETE, dfs  # noqa: F401


def cached(*kernels: Any) -> bool:
    """Whether compiled code of ``kernels`` (default: those ``bnb`` calls) is on disk,
    so the first call loads it instead of compiling for 15-30 s.  Reads numba's cache
    index paths, which are not public API: on any surprise it answers True (no note
    rather than a wrong one)."""
    import os
    try:
        return all(os.path.exists(f._cache._cache_file._index_path)
                   for f in (kernels or (solve, prepare)))
    except Exception:
        return True
