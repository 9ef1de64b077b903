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


def _kernel_threads() -> list[threading.Thread]:
    return [t for t in threading.enumerate() if t.name == "assocopt-kernel"]


def test_worker_threads_are_reused_between_calls():
    """A call hands its work to an idle worker: a run of calls starts no new threads,
    and each still gets its own answer (and its own exception)."""
    interruptible.run_cancellable(int, ("1",), None)
    before = {t.ident for t in _kernel_threads()}
    answers = [interruptible.run_cancellable(int, (str(i),), None)[0] for i in range(50)]
    assert answers == list(range(50))
    with pytest.raises(ValueError):
        interruptible.run_cancellable(int, ("x",), None)
    assert interruptible.run_cancellable(int, ("7",), None) == (7, False)
    assert {t.ident for t in _kernel_threads()} <= before | {None}
    assert len(_kernel_threads()) <= interruptible.MAX_IDLE + 1


def test_a_busy_worker_is_not_handed_another_call():
    """While one call runs (a worker left going after Ctrl-C, or another caller's),
    a second call gets a worker of its own and does not wait for the first."""
    release = threading.Event()
    backstop = threading.Timer(DEADLINE, release.set)
    backstop.start()
    box = {}
    first = threading.Thread(
        target=lambda: box.setdefault("r", interruptible.run_cancellable(
            release.wait, (DEADLINE,), None)))
    try:
        first.start()
        while not any(t.is_alive() for t in _kernel_threads()):
            time.sleep(0.01)
        t0 = time.perf_counter()
        assert interruptible.run_cancellable(int, ("3",), None) == (3, False)
        assert time.perf_counter() - t0 < DEADLINE / 2 and not release.is_set()
    finally:
        release.set()
        backstop.cancel()
        first.join(DEADLINE)
    assert box["r"] == (True, False)


@pytest.mark.skipif(not hasattr(__import__("os"), "fork"), reason="needs os.fork")
def test_a_forked_child_starts_its_own_workers():
    """The parent's idle workers do not exist in a forked child (multiprocessing's
    fork start): the child's call must not be handed to one of them and hang."""
    import multiprocessing as mp
    interruptible.run_cancellable(int, ("1",), None)      # an idle worker to inherit
    ctx = mp.get_context("fork")
    with ctx.Pool(1) as pool:
        assert pool.apply_async(interruptible.run_cancellable, (int, ("5",), None)
                                ).get(DEADLINE) == (5, False)
