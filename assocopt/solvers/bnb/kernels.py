"""Compiled kernels of the ``bnb`` back end (numba, nopython): a dense Hungarian
method with duals, the Lagrangian relaxation to a 2-D assignment with misses, and a
depth-first exact-cover branch and bound on reduced costs.

The kernels are imported (and numba with them) on first access; :mod:`assocopt.solvers.bnb.backend`
asks for them by name (:func:`name`) where a small problem may run them interpreted.  Functions are compiled on first use and cached on disk (``cache=True``).

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

from ..kernels import ensure, pick, pick_fixed, spent, uninterrupted  # noqa: F401  (clock; Ctrl-C)
from ..kernels.outcomes import BUDGET, COMPLETE, INFEASIBLE, PROVEN, STOPPED  # noqa: F401

#: The kernels, by the module of :mod:`assocopt.solvers.kernels` that holds them:
#: imported (with numba) on first access, so that a caller that runs them
#: interpreted (:func:`assocopt.solvers.kernels.pick` given a name) never loads numba.
_WHERE = {"recover3": "driver", "solve": "driver", "tuple_index": "driver",
          "hungarian": "hungarian", "hungarian_warm": "hungarian",
          "evaluate": "relaxation", "full_reduced": "relaxation",
          "improve_limit": "relaxation", "prepare": "relaxation",
          "raise_rows": "relaxation", "reduced": "relaxation",
          "sort_lists": "relaxation", "dfs": "search"}


def name(kernel: str) -> str:
    """``"relaxation.prepare"``: the name :func:`pick` takes for a ``bnb`` kernel."""
    return f"{_WHERE[kernel]}.{kernel}"


def __getattr__(attr: str) -> Any:
    if attr in _WHERE:
        from ..kernels import tiers
        return tiers.compiled(name(attr))
    raise AttributeError(f"module {__name__!r} has no attribute {attr!r}")


def cached(*kernels: Any) -> bool:
    """Whether compiled code of ``kernels`` (default: those ``bnb`` calls) is on disk,
    so the first call loads it instead of compiling for 15-30 s.  Reads numba's cache
    index paths, which are not public API: on any surprise it answers True (no note
    rather than a wrong one)."""
    import os
    try:
        return all(os.path.exists(f._cache._cache_file._index_path)
                   for f in (kernels or (__getattr__("solve"), __getattr__("prepare"))))
    except Exception:
        return True


def run_tiered(kernel: str, args: tuple, stop: Any, *, work: float,
               deadline: float | None = None, inline: bool = False,
               fixed: bool = False) -> tuple[Any, bool]:
    """:func:`assocopt.solvers.interruptible.run_stoppable` of the kernel named ``kernel`` (``"driver.solve"``) by
    the route :func:`assocopt.solvers.kernels.pick` chooses for ``work``.

    Interpreted, the call works on copies of the array arguments (copied back when it
    ends: a kernel may write its answer into one) and gets the rest of the kernel's
    interpreted budget as a deadline of its own: a small problem that turns out hard
    runs past it, and is then solved again compiled, from the original arguments, the
    compilation not counted against ``deadline``.  ``fixed``: the call site's argument
    types never change (:func:`assocopt.solvers.kernels.pick_fixed`)."""
    import time

    import numpy as np

    from ..interruptible import run_stoppable
    from ..kernels import tiers

    fn = (pick_fixed if fixed else pick)(kernel, *args, work=work)
    if not getattr(fn, "interpreted", False):               # compiled
        return run_stoppable(fn, args, stop, deadline=deadline, inline=inline)
    cap = time.perf_counter() + tiers.budget_left(kernel)
    ours = deadline is None or cap < deadline
    copies = tuple(a.copy() if isinstance(a, np.ndarray) and a is not stop else a
                   for a in args)
    result, by_clock = run_stoppable(fn, copies, stop, deadline=cap if ours else deadline)
    if not (by_clock and ours):
        for a, b in zip(args, copies):       # what the kernel wrote into its arguments
            if b is not a and a.flags.writeable:
                a[...] = b
        return result, by_clock
    stop[0] = 0
    tiers.exhaust(kernel)
    k0 = sum(spent())
    fn = pick(kernel, *args, work=work)
    if deadline is not None:
        deadline += sum(spent()) - k0
    return run_stoppable(fn, args, stop, deadline=deadline, inline=inline)
