"""Child processes in tests: started so that signals behave the same however pytest
itself was started, and never left running.

A process started in the background (``nohup ... &``, a CI runner, a batch job)
inherits SIGINT as *ignored*, and so does every process it starts: a Ctrl-C test that
sends SIGINT to such a child waits for nothing, and ``_thread.interrupt_main()`` does
nothing in such a process.  :func:`sigint_handled` installs Python's SIGINT handler
for a block; :func:`started` starts a child with SIGINT at its default action (exec
resets a *handled* signal to the default but keeps an *ignored* one ignored) in a
process group of its own, and kills that group when the block ends, however it ends
(failure, pytest-timeout).  :func:`leftover_children` is the check behind the
autouse fixture of ``conftest.py``: no child of the test process outlives its test.
"""

from __future__ import annotations

import contextlib
import os
import signal
import subprocess
from typing import Any, Iterator, Sequence

import psutil

__all__ = ["sigint_handled", "started", "kill_group", "leftover_children", "kill_tree"]

#: Long-lived helpers of multiprocessing, started once per process by design.
PERSISTENT = ("multiprocessing.resource_tracker", "multiprocessing.forkserver")
#: Process groups started by :func:`started` in this process (checked after each test).
GROUPS: set[int] = set()


@contextlib.contextmanager
def sigint_handled() -> Iterator[None]:
    """SIGINT raises KeyboardInterrupt in this process for the block, whatever
    disposition pytest inherited; children started inside get SIGINT's default."""
    old = signal.signal(signal.SIGINT, signal.default_int_handler)
    try:
        yield
    finally:
        signal.signal(signal.SIGINT, old)


def kill_group(pgid: int) -> None:
    """SIGKILL every process of group ``pgid`` (none left is fine)."""
    with contextlib.suppress(ProcessLookupError, PermissionError):
        os.killpg(pgid, signal.SIGKILL)


@contextlib.contextmanager
def started(argv: Sequence[Any], **popen: Any) -> Iterator[subprocess.Popen]:
    """``subprocess.Popen(argv, **popen)`` with SIGINT at its default action, in a new
    process group; when the block ends the group is killed and the child reaped."""
    with sigint_handled():
        proc = subprocess.Popen([str(a) for a in argv], process_group=0, **popen)
    GROUPS.add(proc.pid)
    try:
        yield proc
    finally:
        kill_group(proc.pid)
        for stream in (proc.stdin, proc.stdout, proc.stderr):
            if stream is not None:
                with contextlib.suppress(OSError):
                    stream.close()
        proc.wait()


def _persistent(p: psutil.Process) -> bool:
    try:
        return any(tag in " ".join(p.cmdline()) for tag in PERSISTENT)
    except psutil.Error:
        return True


def _running(p: psutil.Process) -> bool:
    try:
        return p.status() not in (psutil.STATUS_ZOMBIE, psutil.STATUS_DEAD)
    except psutil.Error:
        return False


def _owned_by(p: psutil.Process, before: set[int], me: int) -> bool:
    """Whether ``p`` descends from one of the processes in ``before`` (a child that
    a longer-lived fixture started: its workers may come and go)."""
    try:
        for parent in p.parents():
            if parent.pid == me:
                return False
            if parent.pid in before:
                return True
    except psutil.Error:
        return True
    return False


def children_now() -> set[int]:
    """Pids of the running descendants of this process."""
    return {p.pid for p in psutil.Process().children(recursive=True) if _running(p)}


def leftover_children(before: set[int], grace: float) -> list[psutil.Process]:
    """Descendants of this process (and members of the groups :func:`started`
    started) that are still running, were not running ``before`` the test, do not
    belong to a fixture's process, and do not end within ``grace`` seconds."""
    me = os.getpid()
    found: dict[int, psutil.Process] = {}
    for p in psutil.Process().children(recursive=True):
        if p.pid not in before and _running(p) and not _persistent(p) \
                and not _owned_by(p, before, me):
            found[p.pid] = p
    for pgid in list(GROUPS):
        GROUPS.discard(pgid)
        for p in psutil.process_iter():
            with contextlib.suppress(psutil.Error):
                if p.pid != me and os.getpgid(p.pid) == pgid and _running(p):
                    found.setdefault(p.pid, p)
    if not found:
        return []
    try:
        _, alive = psutil.wait_procs(list(found.values()), timeout=grace)
    except BaseException:              # pytest-timeout while waiting: kill, then re-raise
        kill_tree(list(found.values()))
        raise
    return [p for p in alive if _running(p)]


def kill_tree(procs: list[psutil.Process]) -> list[str]:
    """SIGKILL ``procs`` and their descendants; their command lines, for the report."""
    names = []
    for p in procs:
        with contextlib.suppress(psutil.Error):
            names.append(f"{p.pid}: {' '.join(p.cmdline())[:200]}")
            for kid in p.children(recursive=True):
                with contextlib.suppress(psutil.Error):
                    kid.kill()
            p.kill()
    psutil.wait_procs(procs, timeout=5)
    return names
