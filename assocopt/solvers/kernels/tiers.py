"""Compiled or plain Python: each kernel call takes the route that costs less.

A numba kernel costs seconds to compile on first use (tens of seconds for the branch
and bound) and a fraction of a second to load from the disk cache, while the same
function run as plain Python answers a small problem in milliseconds: the problems of
a first CLI run, of a pytest optimality check or of a notebook's first cell.  So a
call that asks for a kernel (:func:`assocopt.solvers.kernels.pick`) with a measure of
its ``work`` runs the kernel *interpreted* (the same source, loaded a second time as
plain Python, numba not involved: :func:`plain`) while

* the kernel has no machine code in this process yet,
* the work is at most the kernel's :data:`LIMITS` entry (problems where the plain
  function answers within about a tenth of a second), and
* the interpreted calls of this kernel have cost less than the budget so far:
  :data:`BUDGET_COLD` seconds when the kernel would have to be compiled,
  :data:`BUDGET_CACHED` when numba's disk cache holds it (loading is cheaper), and
  :data:`BUDGET_WARM` when the disk cache holds it and this process has loaded or
  compiled a kernel already (numba and LLVM are up: a load costs milliseconds);

otherwise it is compiled (or loaded) and runs compiled from then on.  That is the
ski-rental rule: a process that keeps calling pays at most its budget before it
compiles, one that calls a few times never compiles.  Kernels with a stop flag (the
searches) are also given the rest of the budget as a deadline
(:func:`assocopt.solvers.bnb.kernels.run_tiered`): a hard small problem that runs
past it is solved again compiled.  Both routes give the same answers (the kernels are
written so that they run as plain Python: ``NUMBA_DISABLE_JIT=1`` is tested).

``ASSOCOPT_JIT`` (environment, read at each decision) or :func:`set_mode` choose:
``auto`` (the rule above, default), ``compiled`` (always compile) or ``interpreted``
(never compile).  The experiment runner's trials run compiled (:func:`reproducible`):
their numbers then never depend on which route a trial happened to take.

May import: the standard library; the kernel modules (numpy; the compiled ones numba)
only when a kernel is asked for.
"""

from __future__ import annotations

import contextlib
import importlib
import os
import sys
import threading
import time
import types
from typing import Any, Callable, Iterator

__all__ = ["MODES", "LIMITS", "BUDGET_COLD", "BUDGET_CACHED", "BUDGET_WARM", "mode",
           "set_mode", "warmed", "interpret", "plain", "compiled", "interpreted_seconds",
           "exhaust", "charge", "reproducible"]

MODES = ("auto", "compiled", "interpreted")

#: Interpreted seconds a kernel may cost in one process before it is compiled anyway,
#: when numba would compile it (cold) and when its disk cache holds it (cached).
BUDGET_COLD = 2.0
BUDGET_CACHED = 0.3
#: The cached budget once this process holds machine code of some kernel: loading one
#: more from the disk cache then took 3-40 ms (the first load of a process 160 ms, most
#: of it numba's code generator starting), so a kernel whose numpy or plain route
#: stands in at 0.5 ms a call is loaded after about 60 calls, not 600.
BUDGET_WARM = 0.03

#: Largest ``work`` of an interpreted call, per kernel (``module.function``); the unit
#: is the one its call site passes.  Set where the plain function takes about a second
#: on 2 cores, half the cold budget (measured per unit, interpreted: the batched scan
#: about 25 us a candidate, the sparse LAP about 3 us an edge, the ranking about 1.5 us
#: a solution x entry; the exact net grows faster than its candidates); the searches,
#: whose time no size bounds, also stop at the budget.  A kernel missing here always
#: runs compiled.
LIMITS: dict[str, float] = {
    "relaxation.prepare": 100_000,        # candidates
    "relaxation.improve_limit": 100_000,
    "relaxation.sort_lists": 100_000,
    "driver.solve": 20_000,               # candidates; stops at the budget
    "search.dfs": 20_000,                 # candidates; stops at the budget
    "forcing.window_lists": 100_000,      # candidates
    "batch.solve_batch": 40_000,          # candidates of all components; stops too
    "dominance.dominated_kernel": 300_000,  # candidates
    "dominance.dominated_all": 300_000,
    # candidates; below, the numpy route of ``problems.components`` stands in for the
    # plain twin (numpy: about 0.15 us a candidate; the twin would be 100x that)
    "components.split_rows": 100_000,
    "components.local_rows": 100_000,
    "components.scan_parts": 100_000,
    "components.gather_parts": 100_000,
    "components.plan_parts": 100_000,
    "sparse_lap.lap_edges": 300_000,      # edges
    "murty2d.murty": 200_000,             # solutions x matrix entries
    # candidates; a net grows with its cluster's width (dense 8 x 9: 0.11 s,
    # 10 x 10: 1 s, 12 x 12: 39 s interpreted)
    "ehm_exact.exact_marginals": 100,
    # grid entries of a dense 3-AP; below, the Lagrangian relaxation's numpy route
    # (no plain twin: numpy is quicker than the kernel interpreted)
    "grid.grid_eval": 1_000,
    # candidates of a gated S-D relaxation (lagrangian.compiled_sparse); below, its
    # numpy route, as for the grid (numpy is quicker than the kernels interpreted:
    # about 1.6 us a candidate an evaluation, 2.5 us a recovery; numpy 0.35 ms and
    # 1.2 ms at 22 000 candidates, where a cold compile costs 10 s, a load 0.4 s)
    "sparse_relax.sparse_eval": 20_000,
    "sparse_relax.sparse_recover": 20_000,
    # candidates of the same relaxation: the ascent between its events; below, the
    # Python loop (lagrangian.sparse_ascent)
    "sparse_ascent.ascent_run": 20_000,
}

_MODE: list[str | None] = [None]
#: Whether this process has compiled or loaded a kernel (:func:`warmed`).
_WARM = [False]
_SPENT: dict[str, float] = {}
_LOCK = threading.Lock()
_HOME = __name__.rsplit(".", 1)[0]
_PKG = _HOME + "._plain"


def mode() -> str:
    """The route rule now: :func:`set_mode`'s, else ``ASSOCOPT_JIT``, else ``auto``."""
    m = _MODE[0] or os.environ.get("ASSOCOPT_JIT", "").strip().lower() or "auto"
    if m not in MODES:
        raise ValueError(f"ASSOCOPT_JIT={m!r}: expected one of {', '.join(MODES)}")
    return m


def set_mode(value: str | None) -> None:
    """Fix the route rule for this process (``None``: back to ``ASSOCOPT_JIT``)."""
    if value is not None and value not in MODES:
        raise ValueError(f"mode {value!r}: expected one of {', '.join(MODES)} or None")
    _MODE[0] = value


@contextlib.contextmanager
def reproducible() -> Iterator[None]:
    """Within: every kernel compiled, unless ``ASSOCOPT_JIT`` or :func:`set_mode` chose
    otherwise.  For Monte Carlo runs: a trial's answers then never depend on how much of
    the process's interpreted budget earlier trials spent (both routes agree, but a
    floating-point tie may be decided by the order of a sum)."""
    chosen = _MODE[0] is not None or os.environ.get("ASSOCOPT_JIT", "").strip()
    if not chosen:
        _MODE[0] = "compiled"
    try:
        yield
    finally:
        if not chosen:
            _MODE[0] = None


def key(kernel: Any) -> str:
    """``"driver.solve"``: the kernel's module (last part) and name (a name is kept)."""
    if isinstance(kernel, str):
        return kernel
    fn = getattr(kernel, "py_func", kernel)
    return f"{fn.__module__.rsplit('.', 1)[-1]}.{fn.__name__}"


def loaded(name: str) -> Any:
    """The compiled kernel ``name`` if its module is imported already, else None."""
    module, func = name.rsplit(".", 1)
    mod = sys.modules.get(f"{_HOME}.{module}")
    return None if mod is None else getattr(mod, func)


def compiled(name: str) -> Any:
    """The compiled kernel ``name`` (its module imported, and numba with it)."""
    module, func = name.rsplit(".", 1)
    return getattr(importlib.import_module(f"{_HOME}.{module}"), func)


def warmed() -> None:
    """Record that this process holds machine code of a kernel (called by
    :func:`assocopt.solvers.kernels.ensure` after a compile or a load)."""
    _WARM[0] = True


def interpret(name: str, work: float, cached: Callable[[], bool]) -> bool:
    """Whether a call of kernel ``name`` with ``work`` runs interpreted (module doc);
    ``cached()`` tells whether numba's disk cache holds it (asked only if it matters)."""
    m = mode()
    if m != "auto":
        return m == "interpreted"
    if getattr(loaded(name), "overloads", None):     # machine code in this process
        return False
    if work > LIMITS.get(name, -1.0):
        return False
    spent = _SPENT.get(name, 0.0)
    if spent < BUDGET_WARM:
        return True
    return spent < BUDGET_COLD and ((spent < BUDGET_CACHED and not _WARM[0])
                                    or not cached())


def budget_left(name: str) -> float:
    """Seconds the interpreted route of kernel ``name`` may still cost (cold budget)."""
    return max(BUDGET_COLD - _SPENT.get(name, 0.0), 0.0)


def exhaust(name: str) -> None:
    """Close the interpreted route of kernel ``name`` for this process (a call ran
    past its budget): it is compiled from the next call on."""
    with _LOCK:
        _SPENT[name] = max(_SPENT.get(name, 0.0), BUDGET_COLD)


def charge(name: str, seconds: float) -> None:
    """Count ``seconds`` of a numpy route that stood in for kernel ``name`` (see
    :func:`assocopt.solvers.kernels.routed`) into its interpreted budget."""
    with _LOCK:
        _SPENT[name] = _SPENT.get(name, 0.0) + seconds


def interpreted_seconds() -> dict[str, float]:
    """Seconds spent in interpreted kernels so far, per kernel."""
    return dict(_SPENT)


def plain(name: str) -> Callable:
    """Kernel ``name`` as plain Python, its callees plain too, timed into its budget."""
    module, func = name.rsplit(".", 1)
    twin = getattr(_twin(module), func)

    def timed(*args: Any) -> Any:
        t0 = time.perf_counter()
        try:
            return twin(*args)
        finally:
            with _LOCK:
                _SPENT[name] = _SPENT.get(name, 0.0) + time.perf_counter() - t0

    timed.__name__ = func
    timed.__wrapped__ = twin                         # type: ignore[attr-defined]
    timed.interpreted = True                         # type: ignore[attr-defined]
    return timed


def _twin(name: str) -> types.ModuleType:
    """The kernel module ``name`` loaded again, as plain Python, under ``_plain``: a
    package whose path is this folder, so that the twin's relative imports load twins
    and its ``njit`` (``_plain.jit``) returns the functions unchanged."""
    with _LOCK:
        if _PKG not in sys.modules:
            pkg = types.ModuleType(_PKG, "plain-Python twins of the kernels")
            pkg.__path__ = [os.path.dirname(os.path.abspath(__file__))]
            pkg.__package__ = _PKG
            sys.modules[_PKG] = pkg
    return importlib.import_module(f"{_PKG}.{name}")
