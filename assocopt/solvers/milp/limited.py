"""Time limits that hold: a solve under a limit in a child process that can be ended.

HiGHS (through highspy, scipy's ``milp`` or cvxpy) does not look at the clock in some
phases (the root LP, cut rounds, symmetry detection): under load a 0.5 s limit was
overshot to 3-5 s, cvxpy's compilation knows no clock at all, and scipy and cvxpy have
no hook to stop a solve, so an abandoned one kept a thread busy until it ended.  Under
a time limit these back ends (``highs``, ``scipy``, ``cvxpy``) therefore run their
solve in a child interpreter (``isolate`` option, on by default only when a limit is
given): the model goes to it in bulk (one pickle of its arrays through a pipe), the
child solves with the library's own limit and sends back what it found, and the parent
kills it if it is still running at ``limit + KILL_SLACK(limit)`` (a run then returns
``time_limit`` without a solution).  Ctrl-C kills the child at once; a child whose
parent dies exits too (:mod:`assocopt.runtime.parent_watch`).  No thread outlives the solve.

The child costs an interpreter start and the solver's import (``info["isolated"]``
records the seconds until the child was ready; see the back-end section of the
README).  Without a time limit nothing changes: the solve runs in this process.
"""

from __future__ import annotations

import importlib
import os
import pickle
import signal
import subprocess
import sys
import time
from pathlib import Path
from typing import Any, Callable

from ...model.solution import Status
from ..base import Option, RawResult, SolveOptions, remaining

__all__ = ["ISOLATE", "run_limited", "solve_isolated_or_here", "kill_slack",
           "killed_at_limit", "child_main"]

#: The option of the back ends that use this module.
ISOLATE = Option("isolate", "bool", None,
                 "solve in a child process that is killed at the time limit (None: "
                 "when a time limit is given; False: in this process, where the library "
                 "may overshoot the limit)", nullable=True)

#: The package's parent folder, put first on the child's path (the same assocopt).
_ROOT = str(Path(__file__).resolve().parents[3])
_BOOT = ("import sys; sys.path.insert(0, sys.argv[1]); "
         "from assocopt.solvers.milp.limited import child_main; child_main()")


def kill_slack(limit: float) -> float:
    """Seconds past the limit at which a child still running is killed: half of the
    tolerance max(1 s, 10 %) a limit is held to, so that killing and reaping it fit."""
    return 0.5 * max(1.0, 0.1 * limit)


def run_limited(target: str, args: tuple, limit: float, start: float) -> dict[str, Any] | None:
    """``target(*args, time_limit=left)`` (``target`` = ``"module:function"``, returning
    a picklable dict) run in a child process; ``limit`` seconds count from ``start``
    (a ``time.monotonic()`` value, the same clock in every process).

    Returns the function's dict with ``"startup"`` (seconds from here until the child
    had read the model) added, or None when the child was killed at the deadline.  An
    exception in the child is raised here.
    """
    payload = pickle.dumps((target, args, start + limit), protocol=pickle.HIGHEST_PROTOCOL)
    kill_at = start + limit + kill_slack(limit)
    spawned = time.monotonic()
    env = {k: v for k, v in os.environ.items() if k != "PYTHONSTARTUP"}
    proc = None
    try:                           # Popen inside: a Ctrl-C just after it still ends the child
        proc = subprocess.Popen([sys.executable, "-c", _BOOT, _ROOT, str(os.getpid())],
                                stdin=subprocess.PIPE, stdout=subprocess.PIPE, env=env)
        out, _ = proc.communicate(payload, timeout=max(kill_at - time.monotonic(), 0.0))
    except subprocess.TimeoutExpired:
        _end(proc)
        return None
    except BaseException:          # Ctrl-C (or SIGTERM turned into it): end the child
        if proc is not None:
            _end(proc)
        raise
    try:
        kind, value, ready = pickle.loads(out)
    except Exception:  # noqa: BLE001 - the child died without an answer
        raise RuntimeError(f"the solver's child process ended with exit code "
                           f"{proc.returncode} and no answer") from None
    if kind == "error":
        raise value
    value["startup"] = ready - spawned
    return value


def solve_isolated_or_here(solver: str, fn: Callable[..., dict[str, Any]], args: tuple,
                           options: SolveOptions, isolate: bool | None,
                           start: float, t0: float, t1: float) -> dict[str, Any] | RawResult:
    """``fn(*args, time_limit=...)`` (a module-level function of a back end) run under
    the back end's ``isolate`` option: in a child process when a time limit is given
    and ``isolate`` is not False (:func:`run_limited`; limit counted from ``start``, a
    ``time.monotonic()`` value), else in this process with the limit less what has
    passed since ``t0`` (``time.perf_counter()``, the start of building).

    Returns ``fn``'s dict, or the :func:`killed_at_limit` answer (build time
    ``t1 - t0``, ``t1`` the end of building) when the child was killed at the limit.
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
    """The answer of a solve whose child was killed at the time limit: no solution."""
    return RawResult(status=Status.TIME_LIMIT, build_time=build_time,
                     solve_time=solve_time, info={"isolated": "killed"},
                     message=f"{solver}: stopped at the time limit of {limit:g} s (the "
                             "solver's process was ended; no solution found by then)")


def _end(proc: subprocess.Popen) -> None:
    proc.kill()
    proc.communicate()


def child_main() -> None:
    """The child: read ``(target, args, limit_at)`` from stdin, run it, write
    ``(kind, value, ready)`` to the original stdout (the solver's own output goes to
    stderr, so it cannot corrupt the answer)."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)      # the parent handles Ctrl-C
    from ...runtime.parent_watch import watch_parent
    watch_parent(int(sys.argv[2]))
    answer = os.fdopen(os.dup(1), "wb")
    os.dup2(2, 1)
    target, args, limit_at = pickle.loads(sys.stdin.buffer.read())
    module, name = target.split(":")
    fn: Callable[..., dict[str, Any]] = getattr(importlib.import_module(module), name)
    ready = time.monotonic()
    try:
        result: tuple = ("ok", fn(*args, time_limit=max(limit_at - ready, 1e-3)), ready)
    except BaseException as exc:  # noqa: BLE001 - re-raised in the parent
        result = ("error", exc, ready)
    try:
        data = pickle.dumps(result, protocol=pickle.HIGHEST_PROTOCOL)
    except Exception:  # noqa: BLE001 - an exception that cannot be pickled
        data = pickle.dumps(("error", RuntimeError(repr(result[1])), ready))
    answer.write(data)
    answer.flush()
    os._exit(0)        # no interpreter finalisation with native solver threads around
