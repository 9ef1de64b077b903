"""Time limits that hold: a solve under a limit in a warm worker process that can be ended.

HiGHS (through highspy, scipy's ``milp`` or cvxpy) does not look at the clock in some
phases (the root LP, cut rounds, symmetry detection): under load a 0.5 s limit was
overshot to 3-5 s, cvxpy's compilation knows no clock at all, and scipy and cvxpy have
no hook to stop a solve, so an abandoned one kept a thread busy until it ended.  Under
a time limit these back ends (``highs``, ``scipy``, ``cvxpy``, ``ortools-cpsat``,
``ortools-mip``) therefore run their solve in a worker process (``isolate`` option, on
by default only when a limit is given): the model goes to it in bulk (one pickle of its
arrays through a pipe), the worker solves with the library's own limit and sends back
what it found, and the parent kills it if it is still running at
``limit + KILL_SLACK(limit)`` (a run then returns ``time_limit`` without a solution).
Ctrl-C kills the worker at once; a worker whose parent dies exits too (its pipe closes,
and :mod:`assocopt.runtime.parent_watch`).  No thread outlives the solve.

The worker is *warm*: one per back end, started by the first solve under a limit (an
interpreter start and the solver's import, about 0.4 s) and reused by every later one,
so a limit costs a pickle and a pipe round trip per call (``info["isolated"]`` records
the seconds from the call until the worker had read the model).  Only a worker that was
killed (at the deadline, on Ctrl-C) or that died is started afresh, by the next call;
:func:`shutdown` ends the idle ones (run at interpreter exit).  Without a time limit
nothing changes: the solve runs in this process.
"""

from __future__ import annotations

import atexit
import importlib
import os
import pickle
import select
import signal
import struct
import subprocess
import sys
import threading
import time
from pathlib import Path
from typing import Any, Callable

from ...model.solution import Status
from ..base import Option, RawResult, SolveOptions, remaining

__all__ = ["ISOLATE", "run_limited", "solve_isolated_or_here", "kill_slack",
           "killed_at_limit", "child_main", "shutdown", "WORKER_FLAG"]

#: The option of the back ends that use this module.
ISOLATE = Option("isolate", "bool", None,
                 "solve in a worker process that is killed at the time limit (None: "
                 "when a time limit is given; False: in this process, where the library "
                 "may overshoot the limit)", nullable=True)

#: The package's parent folder, put first on the worker's path (the same assocopt).
_ROOT = str(Path(__file__).resolve().parents[3])
_BOOT = ("import sys; sys.path.insert(0, sys.argv[1]); "
         "from assocopt.solvers.milp.limited import child_main; child_main()")
#: The worker's command line carries this word (so a process listing can tell them).
WORKER_FLAG = "assocopt-limit-worker"
#: How often the waiting parent looks at the clock and lets signals in (seconds).
POLL = 0.05
#: Idle workers kept per back end (more only while solves run side by side in threads).
MAX_IDLE = 2
_HEADER = struct.Struct("!Q")


def kill_slack(limit: float) -> float:
    """Seconds past the limit at which a worker still running is killed: half of the
    tolerance max(1 s, 10 %) a limit is held to, so that killing and reaping it fit."""
    return 0.5 * max(1.0, 0.1 * limit)


class _Dead(Exception):
    """The worker ended (or its pipe broke) without an answer."""


class _Worker:
    """One worker process and its two pipes; used by one call at a time."""

    def __init__(self) -> None:
        env = {k: v for k, v in os.environ.items() if k != "PYTHONSTARTUP"}
        self.proc = subprocess.Popen(
            [sys.executable, "-c", _BOOT, _ROOT, str(os.getpid()), WORKER_FLAG],
            stdin=subprocess.PIPE, stdout=subprocess.PIPE, env=env, bufsize=0)
        self.calls = 0

    def alive(self) -> bool:
        return self.proc.poll() is None

    def send(self, data: bytes) -> None:
        try:
            self.proc.stdin.write(_HEADER.pack(len(data)) + data)
            self.proc.stdin.flush()
        except (BrokenPipeError, OSError) as exc:
            raise _Dead(str(exc)) from None

    def receive(self, until: float) -> bytes | None:
        """The answer's bytes, or None at ``until`` (a ``time.monotonic()`` value);
        signal handlers run every :data:`POLL` seconds (Ctrl-C raises here)."""
        fd = self.proc.stdout.fileno()
        buf = bytearray()
        size: int | None = None            # the answer's length, once its header is in
        while True:
            left = until - time.monotonic()
            if left <= 0:
                return None
            ready, _, _ = select.select([fd], [], [], min(POLL, left))
            if not ready:
                continue
            want = _HEADER.size if size is None else size
            chunk = os.read(fd, max(want - len(buf), 1))
            if not chunk:
                raise _Dead("end of file")
            buf += chunk
            if size is None and len(buf) >= _HEADER.size:
                size = _HEADER.unpack(bytes(buf[:_HEADER.size]))[0]
                del buf[:_HEADER.size]
            if size is not None and len(buf) >= size:
                return bytes(buf)

    def kill(self) -> None:
        """End the process and reap it (nothing is left running)."""
        try:
            self.proc.kill()
        except OSError:
            pass
        for stream in (self.proc.stdin, self.proc.stdout):
            try:
                stream.close()
            except OSError:
                pass
        self.proc.wait()

    def close(self) -> None:
        """Ask an idle worker to leave (end of its input), kill it if it lingers."""
        try:
            self.proc.stdin.close()
        except OSError:
            pass
        try:
            self.proc.wait(timeout=2.0)
        except subprocess.TimeoutExpired:
            pass
        self.kill()


_LOCK = threading.Lock()
_IDLE: dict[str, list[_Worker]] = {}


def _checkout(key: str) -> tuple[_Worker, bool]:
    """An idle live worker for ``key`` (True: warm) or a newly started one."""
    with _LOCK:
        idle = _IDLE.get(key, [])
        while idle:
            w = idle.pop()
            if w.alive():
                return w, True
            w.kill()
    return _Worker(), False


def _checkin(key: str, w: _Worker) -> None:
    with _LOCK:
        idle = _IDLE.setdefault(key, [])
        if len(idle) < MAX_IDLE:
            idle.append(w)
            return
    w.close()


def shutdown() -> None:
    """End every idle worker (run at interpreter exit; a later solve under a limit
    starts a new one)."""
    with _LOCK:
        workers = [w for ws in _IDLE.values() for w in ws]
        _IDLE.clear()
    for w in workers:
        w.close()


def _forget_after_fork() -> None:
    """In a forked child: the parent's workers are not this process's to use or end."""
    global _LOCK
    _LOCK = threading.Lock()
    _IDLE.clear()


atexit.register(shutdown)
os.register_at_fork(after_in_child=_forget_after_fork)


def run_limited(target: str, args: tuple, limit: float, start: float) -> dict[str, Any] | None:
    """``target(*args, time_limit=left)`` (``target`` = ``"module:function"``, returning
    a picklable dict) run in a warm worker process; ``limit`` seconds count from
    ``start`` (a ``time.monotonic()`` value, the same clock in every process).

    Returns the function's dict with ``"startup"`` (seconds from here until the worker
    had read the model; a new worker's start included) and ``"warm"`` added, or None
    when the worker was killed at the deadline.  An exception in the worker is raised
    here.
    """
    payload = pickle.dumps((target, args, start + limit), protocol=pickle.HIGHEST_PROTOCOL)
    kill_at = start + limit + kill_slack(limit)
    key = target.split(":")[0]
    for attempt in (0, 1):
        called = time.monotonic()
        worker = None
        try:                       # inside: a Ctrl-C just after the start still ends it
            worker, warm = _checkout(key)
            worker.send(payload)
            out = worker.receive(kill_at)
        except _Dead:
            code = worker.proc.poll() if worker is not None else None
            if worker is not None:
                worker.kill()
            if attempt == 0 and warm:      # an idle worker that had died: start anew
                continue
            raise RuntimeError(f"the solver's worker process ended with exit code "
                               f"{code} and no answer") from None
        except BaseException:      # Ctrl-C (or SIGTERM turned into it): end the worker
            if worker is not None:
                worker.kill()
            raise
        if out is None:            # still solving at the kill deadline
            worker.kill()
            return None
        break
    try:
        kind, value, ready = pickle.loads(out)
    except Exception:  # noqa: BLE001 - a garbled answer: the worker is not trusted again
        worker.kill()
        raise RuntimeError("the solver's worker process sent an unreadable answer") \
            from None
    worker.calls += 1
    _checkin(key, worker)
    if kind == "error":
        raise value
    value["startup"] = max(ready - called, 0.0)
    value["warm"] = warm
    return value


def solve_isolated_or_here(solver: str, fn: Callable[..., dict[str, Any]], args: tuple,
                           options: SolveOptions, isolate: bool | None,
                           start: float, t0: float, t1: float) -> dict[str, Any] | RawResult:
    """``fn(*args, time_limit=...)`` (a module-level function of a back end) run under
    the back end's ``isolate`` option: in a worker process when a time limit is given
    and ``isolate`` is not False (:func:`run_limited`; limit counted from ``start``, a
    ``time.monotonic()`` value), else in this process with the limit less what has
    passed since ``t0`` (``time.perf_counter()``, the start of building).

    Returns ``fn``'s dict, or the :func:`killed_at_limit` answer (build time
    ``t1 - t0``, ``t1`` the end of building) when the worker was killed at the limit.
    """
    if options.time_limit is not None and isolate is not False:
        out = run_limited(f"{fn.__module__}:{fn.__name__}", args, options.time_limit, start)
        if out is None:
            return killed_at_limit(solver, options.time_limit, t1 - t0,
                                   time.perf_counter() - t1)
        return out
    return fn(*args, time_limit=remaining(options, t0).time_limit)


def killed_at_limit(solver: str, limit: float, build_time: float,
                    solve_time: float) -> RawResult:
    """The answer of a solve whose worker was killed at the time limit: no solution."""
    return RawResult(status=Status.TIME_LIMIT, build_time=build_time,
                     solve_time=solve_time, info={"isolated": "killed"},
                     message=f"{solver}: stopped at the time limit of {limit:g} s (the "
                             "solver's process was ended; no solution found by then)")


def _read_exactly(stream: Any, n: int) -> bytes | None:
    data = b""
    while len(data) < n:
        chunk = stream.read(n - len(data))
        if not chunk:
            return None
        data += chunk
    return data


def child_main() -> None:
    """The worker: read ``(target, args, limit_at)`` requests from stdin, one after
    the other, run each and write ``(kind, value, ready)`` to the original stdout (the
    solver's own output goes to stderr, so it cannot corrupt the answer); leave at the
    end of the input."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)      # the parent handles Ctrl-C
    from ...runtime.parent_watch import watch_parent
    watch_parent(int(sys.argv[2]))
    answer = os.fdopen(os.dup(1), "wb")
    os.dup2(2, 1)
    source = sys.stdin.buffer
    while True:
        head = _read_exactly(source, _HEADER.size)
        if head is None:
            break
        body = _read_exactly(source, _HEADER.unpack(head)[0])
        if body is None:
            break
        try:
            target, args, limit_at = pickle.loads(body)
            module, name = target.split(":")
            fn: Callable[..., dict[str, Any]] = getattr(importlib.import_module(module), name)
            ready = time.monotonic()       # the solver's import (first call) included
            result: tuple = ("ok", fn(*args, time_limit=max(limit_at - ready, 1e-3)), ready)
        except BaseException as exc:  # noqa: BLE001 - re-raised in the parent
            result = ("error", exc, time.monotonic())
        try:
            data = pickle.dumps(result, protocol=pickle.HIGHEST_PROTOCOL)
        except Exception:  # noqa: BLE001 - an exception that cannot be pickled
            data = pickle.dumps(("error", RuntimeError(repr(result[1])), ready))
        answer.write(_HEADER.pack(len(data)) + data)
        answer.flush()
    os._exit(0)        # no interpreter finalisation with native solver threads around
