"""Run a long compiled (numba ``nogil``) call so that Ctrl-C and a time limit stop it.

A compiled kernel never returns to the interpreter, so Python's SIGINT handler
cannot run until it ends (and numba then reports ``SystemError``).  Kernels that
take a one-element ``stop`` array and check it in their loops are run here in a
worker thread instead, while the calling thread keeps the clock: at the deadline,
or on ``KeyboardInterrupt``, it sets ``stop[0] = 1``, the kernel returns within a
chunk of work (one ascent iteration or 1024 search nodes) with what it has, and the
interrupt is re-raised.  Tiny calls run inline.  The worker threads are kept
between calls (:class:`_Worker`): starting a thread costs about 0.1 ms, handing a call
to a waiting one about a third of that, on solves that take 1-2 ms.
"""

from __future__ import annotations

import os
import queue
import threading
import time
from typing import Any, Callable

import numpy as np

__all__ = ["new_stop", "run_stoppable", "run_cancellable"]

#: Set once a Ctrl-C has stopped (or abandoned) a worker-thread solve: native solver
#: threads may still be winding down, and interpreter finalisation can then abort
#: (OR-tools: "terminate called"); the command line leaves with ``os._exit`` instead.
INTERRUPTED = threading.Event()

#: How often the waiting thread looks at the clock and at pending signals (seconds).
POLL = 0.05
#: How long Ctrl-C waits for a cancelled worker to return (seconds): compiled kernels
#: return within a chunk of work, but a library may run a phase without looking at its
#: interrupt hook (HiGHS in presolve or a long LP); then the interrupt is re-raised
#: anyway and the daemon thread is left to wind down on its own.
CANCEL_WAIT = 2.0


#: Idle worker threads kept for the next call (more are started when calls overlap:
#: several caller threads, or a worker left running after Ctrl-C).
MAX_IDLE = 4


class _Worker:
    """A daemon thread that runs the calls handed to it, one at a time, and goes back
    to the idle list after each (or ends, when that list is full)."""

    def __init__(self) -> None:
        self.jobs: queue.SimpleQueue = queue.SimpleQueue()
        threading.Thread(target=self._loop, name="assocopt-kernel", daemon=True).start()

    def _loop(self) -> None:
        while True:
            job = self.jobs.get()
            if job is None:
                return
            job()
            job = None                  # let the call's arrays go before waiting
            with _IDLE_LOCK:
                if len(_IDLE) >= MAX_IDLE:
                    return
                _IDLE.append(self)


_IDLE: list[_Worker] = []
_IDLE_LOCK = threading.Lock()


def _forget_workers() -> None:
    """In a forked child the parent's threads do not exist: never hand them a call."""
    global _IDLE_LOCK
    _IDLE.clear()
    _IDLE_LOCK = threading.Lock()


if hasattr(os, "register_at_fork"):
    os.register_at_fork(after_in_child=_forget_workers)


def _start(job: Callable[[], None]) -> None:
    """Run ``job`` in an idle worker thread (a new one if none is idle)."""
    with _IDLE_LOCK:
        worker = _IDLE.pop() if _IDLE else None
    (worker or _Worker()).jobs.put(job)


def new_stop() -> np.ndarray:
    """A fresh stop flag for a kernel (0 = run, non-zero = stop now)."""
    return np.zeros(1, np.int64)


def run_stoppable(fn: Callable[..., Any], args: tuple, stop: np.ndarray, *,
                  deadline: float | None = None, inline: bool = False) -> tuple[Any, bool]:
    """``(fn(*args), stopped_by_clock)``, ``args`` ending with ``stop``.

    ``deadline`` is a ``time.perf_counter()`` value; ``inline=True`` calls ``fn``
    directly (for calls known to be short, when no deadline is set).
    """
    if inline and deadline is None:
        return fn(*args), False

    def cancel() -> None:
        stop[0] = 1
    return run_cancellable(fn, args, cancel, deadline=deadline)


def run_cancellable(fn: Callable[..., Any], args: tuple, cancel: Callable[[], None] | None,
                    *, deadline: float | None = None,
                    kwargs: dict[str, Any] | None = None) -> tuple[Any, bool]:
    """``(fn(*args), stopped_by_clock)`` with ``fn`` in a worker thread; ``cancel()``
    asks it to stop (at ``deadline`` or on Ctrl-C), after which it is awaited (on
    Ctrl-C for at most :data:`CANCEL_WAIT` seconds).

    With ``cancel=None`` (a library without an interrupt hook) Ctrl-C is re-raised at
    once and the worker thread (a daemon) is left to finish on its own: the command
    line exits immediately, a Python caller gets its ``KeyboardInterrupt`` without
    waiting for the solve.
    """
    box: dict[str, Any] = {}
    finished = threading.Event()

    def work() -> None:
        try:
            box["result"] = fn(*args, **(kwargs or {}))
        except BaseException as exc:  # noqa: BLE001 - re-raised in the caller
            box["error"] = exc
        finally:
            finished.set()

    # Waiting on an Event, not Thread.join: the worker outlives the call (and in
    # Python 3.11 a Ctrl-C that interrupts join() marks a thread stopped while it
    # still runs, so the awaiting below would silently not happen).
    _start(work)
    by_clock = False
    try:
        while not finished.is_set():
            wait = POLL if deadline is None else min(POLL, max(deadline - time.perf_counter(), 0))
            finished.wait(wait)
            if deadline is not None and cancel is not None and not finished.is_set() \
                    and time.perf_counter() >= deadline:
                cancel()
                by_clock = True
                finished.wait()
    except BaseException:
        INTERRUPTED.set()
        if cancel is not None:    # Ctrl-C (or SIGTERM turned into it): stop, then re-raise
            cancel()
            finished.wait(CANCEL_WAIT)
        raise
    if "error" in box:
        raise box["error"]
    return box["result"], by_clock

