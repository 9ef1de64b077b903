"""Ctrl-C at the command line ends the process even when the KeyboardInterrupt is lost
(raised inside a finaliser and printed as "ignored"): the watchdog exits with 130."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
from pathlib import Path

from processes import started

ROOT = Path(__file__).resolve().parents[1]

CHILD = """
import sys, time
from assocopt.cli import watchdog
watchdog.GRACE = 0.3
watchdog.arm(130)
try:                          # "ready" inside: the interrupt may come at once
    print("ready", flush=True)
    time.sleep(30)
except KeyboardInterrupt:
    pass                      # the interrupt lost, as in a finaliser
time.sleep(60)
print("still running", flush=True)
"""


def _run_child(code: str):
    """The child running ``code`` (SIGINT at its default, killed at the block's end)."""
    env = dict(os.environ, PYTHONPATH=str(ROOT))
    return started([sys.executable, "-c", code], env=env, text=True,
                   stdout=subprocess.PIPE, stderr=subprocess.PIPE)


def test_a_lost_interrupt_still_ends_the_program():
    with _run_child(CHILD) as proc:
        assert proc.stdout.readline().strip() == "ready"
        proc.send_signal(signal.SIGINT)
        out, err = proc.communicate(timeout=50)
        assert proc.returncode == 130, (out, err)
        assert "still running" not in out and "assocopt: interrupted" in err


def test_an_ignored_sigint_is_left_alone():
    """Started with SIGINT ignored (a background job), the program keeps it ignored."""
    code = ("import signal; signal.signal(signal.SIGINT, signal.SIG_IGN)\n"
            "from assocopt.cli import watchdog\n"
            "watchdog.arm(130)\n"
            "print(signal.getsignal(signal.SIGINT) is signal.SIG_IGN)")
    with _run_child(code) as proc:
        out, _ = proc.communicate(timeout=50)
    assert out.strip() == "True"


def test_an_error_caused_by_ctrl_c_is_an_interruption_not_a_bug():
    """A native module whose import is interrupted raises ImportError with the
    KeyboardInterrupt in its chain: the program reports exit 130, not an internal
    error; an unrelated error stays an internal error."""
    from assocopt.cli.app import _caused_by_interrupt
    try:
        try:
            raise KeyboardInterrupt
        except KeyboardInterrupt:
            raise ImportError("initialization failed")
    except ImportError as exc:
        assert _caused_by_interrupt(exc)
    assert not _caused_by_interrupt(ValueError("a real bug"))


LOST = """
import os, signal, time
from assocopt.cli import watchdog
watchdog.GRACE = 0.3
watchdog.arm(130)
class Finaliser:
    def __del__(self):
        os.kill(os.getpid(), signal.SIGINT)
        time.sleep(0.5)           # the KeyboardInterrupt is raised here, and lost
Finaliser()
time.sleep(30)                    # the watchdog ends the process first
print("still running", flush=True)
"""


def test_a_lost_interrupt_prints_no_traceback():
    """A Ctrl-C raised inside a callback that cannot propagate it (here a finaliser;
    in practice numba's LLVM cache notifier while compiling) is not shown as an
    'Exception ignored' traceback: the program says 'assocopt: interrupted' and
    exits with 130."""
    with _run_child(LOST) as proc:
        out, err = proc.communicate(timeout=50)
    assert proc.returncode == 130, (out, err)
    assert err.strip() == "assocopt: interrupted", err
