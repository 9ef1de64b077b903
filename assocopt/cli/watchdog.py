"""A last resort for Ctrl-C at the command line: leave within seconds even when the
interrupt is lost.

Python delivers SIGINT as a ``KeyboardInterrupt`` at the next bytecode of the main
thread; when that bytecode belongs to a finaliser (``__del__``, a weakref callback run
by the garbage collector) the exception is printed as "ignored" and the solve goes on.
:func:`arm` installs a handler that raises ``KeyboardInterrupt`` as usual (so the stack
unwinds and temporary files are removed) and also starts a daemon thread that ends the
process with exit code 130 if it is still running :data:`GRACE` seconds later.  Only
the program (``assocopt ...``) arms it, never a caller of :func:`assocopt.cli.main`.
"""

from __future__ import annotations

import os
import signal
import sys
import threading
from typing import Any, Callable

__all__ = ["arm", "interrupted", "GRACE"]

#: Seconds between the first Ctrl-C and the forced exit.
GRACE = 5.0

#: Set by the armed handler on the first Ctrl-C: an exception that follows it (an
#: extension module whose import was interrupted raises ``ImportError`` instead of
#: ``KeyboardInterrupt``) is then reported as an interruption, not as a bug.
_FIRED = threading.Event()


def interrupted() -> bool:
    """Whether the armed handler has seen a Ctrl-C in this process."""
    return _FIRED.is_set()


def arm(exit_code: int) -> Callable[[], None]:
    """Install the SIGINT handler (main thread only); returns the function that puts
    the previous handler back."""
    if threading.current_thread() is not threading.main_thread() or \
            signal.getsignal(signal.SIGINT) is not signal.default_int_handler:
        return lambda: None       # a thread, or SIGINT ignored / taken over by the caller
    fired = _FIRED
    fired.clear()

    def leave_later() -> None:
        threading.Event().wait(GRACE)
        for stream in (sys.stdout, sys.stderr):
            try:
                stream.flush()
            except (OSError, ValueError):
                pass
        try:
            os.write(2, b"assocopt: interrupted\n")
        except OSError:
            pass
        os._exit(exit_code)

    def on_sigint(signum: int, frame: Any) -> None:
        if not fired.is_set():
            fired.set()
            threading.Thread(target=leave_later, name="assocopt-watchdog",
                             daemon=True).start()
        kernels = sys.modules.get("assocopt.solvers.kernels")   # not imported: not busy
        if kernels is not None and kernels.defer_interrupt():
            return                     # inside numba's compiler: raised when it is done
        raise KeyboardInterrupt

    old_hook = sys.unraisablehook

    def quiet_lost_interrupt(unraisable: Any) -> None:
        """A Ctrl-C raised inside a callback (numba's LLVM cache notifier, a
        finaliser) is lost there: the watchdog ends the program, and the user sees
        'assocopt: interrupted' instead of an 'Exception ignored' traceback."""
        if not (fired.is_set() and isinstance(unraisable.exc_value, KeyboardInterrupt)):
            old_hook(unraisable)

    def disarm() -> None:
        signal.signal(signal.SIGINT, old)
        sys.unraisablehook = old_hook

    old = signal.signal(signal.SIGINT, on_sigint)
    sys.unraisablehook = quiet_lost_interrupt
    return disarm
