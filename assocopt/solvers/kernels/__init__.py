"""numba kernels of the ``bnb`` back end (its N = 3 recovery on gated problems:
:mod:`.recovery`), the compiled window search of ``lagrangian-exact`` (its forced
candidates first: :mod:`.forcing`), the dominance rule of both Lagrangian back ends
(:mod:`.dominance`), their relaxation of a gated problem (:mod:`.sparse_relax`, wired
by :mod:`assocopt.solvers.lagrangian.compiled_sparse`) and its ascent
(:mod:`.sparse_ascent`, with numpy's sums: :mod:`.sums`; the relaxed dense grid:
:mod:`.grid`), the sparse 2-D LAP
(:mod:`.sparse_lap`, imported by :mod:`assocopt.solvers.twod.sparse`) and the 2-D ranking
of :func:`assocopt.kbest` (:mod:`.sap`: a warm-startable shortest-augmenting-path LAP
on dense matrices, :mod:`.murty2d`: Murty's method on it, imported by
:mod:`assocopt.ranking.kbest2d`) and the exact marginals' hypothesis net
(:mod:`.ehm_net`, imported by :mod:`assocopt.ranking.hypothesis_net`); imported only when one of them runs (importing numba
costs half a second). :mod:`assocopt.solvers.bnb.kernels` is the import point of the
``bnb`` kernels.

Every kernel is decorated by :func:`.jit.njit` (numba's, with the disk cache placed so
that a read-only install never fails: see :mod:`.jit`).  Callers ask for a kernel
through :func:`pick`, which on a small problem hands back its plain-Python twin instead
of compiling it (:mod:`.tiers`).

numba's disk cache does not notice a change in a kernel another file calls: after
editing ``sap.py``, delete ``__pycache__/murty2d.*.nb[ic]`` (the same holds for
``driver.py`` and the kernels it calls, for ``sparse_lap.py`` and ``sums.py``, which
``sparse_relax.py`` calls, for ``sparse_relax.py`` and ``grid_ascent.py``, which
``sparse_ascent.py`` calls, for ``relaxation.py``, which ``forcing.py`` calls, and for
``grid.py`` and ``hungarian.py``, which ``grid_ascent.py`` calls).  A kernel that calls itself does
not link from the cache at all: write recursions as loops (:func:`.sums.np_sum`).

This package file itself imports no numba: it holds the clock of compilation and
cache loading (:func:`ensure`, :func:`spent`), which :func:`assocopt.solve` reads
without loading the kernels.

May import: nothing of assocopt (numba and numpy only): every part of
:mod:`assocopt.solvers` may call a kernel, so the kernels call none of them.
"""

from __future__ import annotations

import contextlib
import logging
import time
from typing import Any, Iterator

import numpy as np

__all__ = ["ensure", "pick", "pick_fixed", "routed", "spent", "announced", "defer_interrupt",
           "uninterrupted"]

_LOG = logging.getLogger("assocopt")

#: Whether this process has said that kernels are being compiled (once a process).
_ANNOUNCED = [False]


#: Compiles or cache loads in progress (:func:`ensure`), and whether a Ctrl-C arrived
#: during one.  A ``KeyboardInterrupt`` raised inside numba's LLVM code is lost in a
#: callback there and can leave a half-loaded kernel that crashes when called, so a
#: SIGINT handler asks :func:`defer_interrupt` first, and the interrupt is raised
#: when the compile is done (:func:`uninterrupted`).  A kernel called in the main thread
#: is such a section too: a ``KeyboardInterrupt`` raised while numba unboxes its
#: arguments or boxes its results crashed the process (SIGSEGV, seen about once in 15
#: Ctrl-C's during ``bnb``'s set-up).
_BUSY = [0]
_DEFERRED = [False]


def defer_interrupt() -> bool:
    """Whether a kernel is being compiled or loaded now; if so, the interrupt is raised
    as ``KeyboardInterrupt`` when that is done (for a SIGINT handler)."""
    if _BUSY[0] > 0:
        _DEFERRED[0] = True
        return True
    return False


@contextlib.contextmanager
def uninterrupted() -> Iterator[None]:
    """A section (a compile, a kernel call in the main thread) in which a Ctrl-C is
    held back by :func:`defer_interrupt` and raised when the section ends."""
    _BUSY[0] += 1
    try:
        yield
    finally:
        _BUSY[0] -= 1
    if _BUSY[0] == 0 and _DEFERRED[0]:
        _DEFERRED[0] = False
        raise KeyboardInterrupt


def announced(now: bool = False) -> bool:
    """Whether the compile note of this process has been given; ``now=True`` records
    that the caller gives it itself (the command line prints its own)."""
    if now:
        _ANNOUNCED[0] = True
    return _ANNOUNCED[0]


#: Seconds this process spent compiling kernels and loading them from numba's disk
#: cache (:func:`ensure`); :func:`assocopt.solve` reports the part spent during a
#: solve as ``times["compile"]`` and ``times["cache_load"]``, apart from build/solve.
_SPENT = {"compile": 0.0, "cache_load": 0.0}


def spent() -> tuple[float, float]:
    """``(compile, cache_load)`` seconds spent so far in this process."""
    return _SPENT["compile"], _SPENT["cache_load"]


def ensure(kernel: Any, *args: Any) -> None:
    """Make sure ``kernel`` has machine code for the types of ``args`` (only that
    specialisation, and the kernels it calls), timing the compilation or the load
    from the disk cache apart from the call itself.

    Hot loops call this before every kernel call (the Lagrangian ascent: once per
    2-D solve), where numba's own typing of the arguments cost more than a small
    LAP (0.37 ms against 0.17 ms per call on a gated scan): a signature seen before,
    keyed cheaply by argument kind, dtype, rank and layout, returns at once.  A key
    that misses a distinction numba makes only moves a compilation into the call's
    own time, never changes a result."""
    key = (id(kernel),) + tuple(_kind(a) for a in args)
    if key in _SEEN:
        return
    try:
        sig = tuple(kernel.typeof_pyval(a) for a in args)
    except Exception:          # not a numba dispatcher: nothing to prepare
        return
    from . import tiers
    if sig in kernel.overloads:
        _SEEN.add(key)
        tiers.warmed()
        return
    if not _ANNOUNCED[0] and not _on_disk(kernel, sig):
        _ANNOUNCED[0] = True
        _LOG.warning("assocopt: compiling numba kernels for %s (first use with an empty "
                     "cache: seconds; cached on disk afterwards)", kernel.__name__)
    hits = sum(kernel.stats.cache_hits.values())
    t0 = time.perf_counter()
    with uninterrupted():
        kernel.compile(sig)
    dt = time.perf_counter() - t0
    _SPENT["cache_load" if sum(kernel.stats.cache_hits.values()) > hits else "compile"] += dt
    _SEEN.add(key)
    tiers.warmed()


def pick(kernel: Any, *args: Any, work: float) -> Any:
    """The function to call for ``kernel(*args)`` (a kernel or its name,
    ``"driver.solve"``: a name imports neither the kernel nor numba unless needed):
    the kernel itself, compiled (or loaded) for these arguments by :func:`ensure`, or
    its plain-Python twin where that costs less (:mod:`.tiers`: small ``work``, no
    machine code in this process, the interpreted budget not spent)."""
    from . import tiers

    name = tiers.key(kernel)
    if tiers.interpret(name, work, lambda: _cached(_compiled(name), args)):
        return tiers.plain(name)
    kernel = _compiled(name)
    if hasattr(kernel, "py_func"):               # (NUMBA_DISABLE_JIT: a plain function)
        ensure(kernel, *args)
    return kernel


def pick_fixed(kernel: str, *args: Any, work: float) -> Any:
    """:func:`pick` for a call site whose argument types never change (arrays it builds
    itself, with fixed dtypes): once the compiled kernel has been handed out there, it
    is returned at once under the same route rule (:func:`.tiers.mode`), without
    typing the arguments again (a window search asked for four kernels at 5-14 us
    each; a gated scan's solve makes about 80 such asks)."""
    from . import tiers

    key = (kernel, tiers.mode())
    fn = _FIXED.get(key)
    if fn is None:
        fn = pick(kernel, *args, work=work)
        if getattr(fn, "overloads", None):           # compiled (not a plain twin)
            _FIXED[key] = fn
    return fn


#: Compiled kernels :func:`pick_fixed` has handed out, by (name, route rule).
_FIXED: dict[tuple[str, str], Any] = {}


def routed(kernel: str, fallback: Any, *args: Any, work: float) -> Any:
    """``kernel(*args)`` compiled where :mod:`.tiers` chooses the compiled route, else
    ``fallback(*args)``: for a kernel whose caller has a numpy route quicker than the
    kernel's plain twin.  The fallback's time is charged to the kernel's interpreted
    budget, so a process that keeps calling compiles it in the end (the ski rental of
    :mod:`.tiers`)."""
    from . import tiers

    name = tiers.key(kernel)
    if tiers.interpret(name, work, lambda: _cached(_compiled(name), args)):
        t0 = time.perf_counter()
        try:
            return fallback(*args)
        finally:
            tiers.charge(name, time.perf_counter() - t0)
    fn = _compiled(name)
    if hasattr(fn, "py_func"):                   # (NUMBA_DISABLE_JIT: a plain function)
        ensure(fn, *args)
    return fn(*args)


def _compiled(name: str) -> Any:
    """The compiled kernel ``name``; importing its module (and numba, the first time:
    about half a second) is timed as loading kernels (``times["cache_load"]``)."""
    from . import tiers

    if tiers.loaded(name) is not None:
        return tiers.loaded(name)
    t0 = time.perf_counter()
    kernel = tiers.compiled(name)
    if hasattr(kernel, "py_func"):                # not NUMBA_DISABLE_JIT's plain function
        _SPENT["cache_load"] += time.perf_counter() - t0
    return kernel


def _cached(kernel: Any, args: tuple) -> bool:
    """Whether numba's disk cache holds ``kernel`` for the types of ``args``."""
    try:
        sig = tuple(kernel.typeof_pyval(a) for a in args)
    except Exception:
        return False
    return _on_disk(kernel, sig)


def _on_disk(kernel: Any, sig: tuple) -> bool:
    """Whether numba's disk cache holds ``kernel`` for ``sig`` (its index read as
    numba's own ``load_overload`` does: not public API, so any surprise answers True,
    no note rather than a wrong one).  A kernel without a disk cache answers False."""
    try:
        cache = kernel._cache
        if not hasattr(cache, "_cache_file"):          # NullCache: compiled every time
            return False
        key = cache._index_key(sig, kernel.targetctx.codegen())
        return key in cache._cache_file._load_index()
    except Exception:
        return True


#: Cheap keys of the signatures :func:`ensure` has seen compiled.
_SEEN: set = set()


def _kind(a: Any) -> Any:
    """What numba's dispatch depends on, cheaply: arrays by type, dtype, rank and flag
    bits (layout, writability, alignment; the owner bit too, which only splits a key),
    scalars by Python type.  About 0.2 us an array (reading the flags one by one
    cost 0.5 us, and a gated scan's solve asks about 900 of them)."""
    if isinstance(a, np.ndarray):
        return (type(a), a.dtype.num, a.ndim, a.flags.num)
    return type(a)

