"""Worker processes that exit when the process that started them dies.

A ``ProcessPoolExecutor`` worker blocks on its call queue; when the main process is
killed with SIGKILL nothing tells it, and it (and multiprocessing's resource tracker,
which waits for every holder of its pipe) stays alive for ever.  :func:`watch_parent`,
run as the pool's ``initializer``, starts a daemon thread that polls ``os.getppid()``
and ends the worker with ``os._exit`` as soon as its parent is gone (the worker is
re-parented, so the parent id changes); the tracker then sees its pipe close and exits
too.  On Linux ``prctl(PR_SET_PDEATHSIG)`` is not used: it fires when the parent
*thread* that forked exits, which is not the parent process's death.
"""

from __future__ import annotations

import os
import threading
import time

__all__ = ["watch_parent", "POLL_SECONDS"]

#: How often a worker checks that its parent is alive.
POLL_SECONDS = 0.5


def watch_parent(parent_pid: int | None = None, poll: float = POLL_SECONDS) -> None:
    """Start the watchdog thread in this (worker) process; ``parent_pid`` defaults
    to the current parent."""
    parent = os.getppid() if parent_pid is None else int(parent_pid)

    def watch() -> None:
        while True:
            if os.getppid() != parent:
                os._exit(1)
            time.sleep(poll)

    threading.Thread(target=watch, name="assocopt-parent-watch", daemon=True).start()
