"""Ctrl-C during a worker-thread solve: the interrupt reaches the caller even when the
library ignores its cancel hook for a while (HiGHS in a phase without callbacks).

``_thread.interrupt_main()`` does nothing where SIGINT is ignored (pytest started in
the background): the ``sigint_python`` fixture installs Python's handler for each test,
and every wait has a deadline, so a lost interrupt fails the test instead of hanging.
"""

from __future__ import annotations

import _thread
import threading
import time

import numpy as np
import pytest

from assocopt.solvers import interruptible

#: Seconds after which a lost interrupt lets the waits below return (and the test fail).
DEADLINE = 60.0

pytestmark = pytest.mark.usefixtures("sigint_python")


def _interrupt_soon() -> threading.Timer:
    timer = threading.Timer(0.1, _thread.interrupt_main)
    timer.start()
    return timer


def test_interrupt_is_raised_although_the_worker_ignores_cancel(monkeypatch):
    monkeypatch.setattr(interruptible, "CANCEL_WAIT", 0.05)
    release = threading.Event()
    backstop = threading.Timer(DEADLINE, release.set)   # never leave a thread behind
    backstop.start()
    cancelled = []
    try:
        _interrupt_soon()
        with pytest.raises(KeyboardInterrupt):
            interruptible.run_cancellable(release.wait, (), lambda: cancelled.append(1))
        assert cancelled == [1]
        assert not release.is_set()                  # the worker was still running
        assert interruptible.INTERRUPTED.is_set()
    finally:
        release.set()
        backstop.cancel()
        interruptible.INTERRUPTED.clear()


def test_a_kernel_honouring_the_stop_flag_is_awaited():
    """A compiled-style worker that checks its stop flag returns what it has before the
    interrupt is re-raised: the flag is set and the worker has finished."""
    stop = interruptible.new_stop()
    done = threading.Event()

    def kernel(stop: np.ndarray) -> int:
        while not stop[0]:
            threading.Event().wait(0.01)
        done.set()
        return 1

    try:
        _interrupt_soon()
        with pytest.raises(KeyboardInterrupt):
            interruptible.run_stoppable(kernel, (stop,), stop,
                                        deadline=time.perf_counter() + DEADLINE)
        assert stop[0] == 1 and done.is_set()
    finally:
        interruptible.INTERRUPTED.clear()
