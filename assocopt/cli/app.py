"""The entry point :func:`main`: parse, dispatch to a subcommand, map errors to exit codes.

Every failure ends here as one ``assocopt: error: ...`` line on stderr and an exit code
(see :mod:`assocopt.cli`), never a traceback.
"""

from __future__ import annotations

import argparse
import sys
from typing import Sequence, TextIO

from ..runtime.errors import AssocoptError
from .common import (EXIT_BAD_INPUT, EXIT_BROKEN_PIPE, EXIT_INTERNAL, EXIT_INTERRUPTED,
                     _error, _one_line, _os_message, _UsageError)
from .parser import _build_parser
from .watchdog import arm, interrupted
from .solve_cmds import _cmd_compare, _cmd_solve, _cmd_solvers, _cmd_validate
from .workflow_cmds import (_cmd_convert, _cmd_export, _cmd_generate, _cmd_instances,
                            _cmd_models, _cmd_reproduce)


_COMMANDS = {"solve": _cmd_solve, "solvers": _cmd_solvers, "models": _cmd_models,
             "compare": _cmd_compare, "validate": _cmd_validate,
             "export": _cmd_export, "generate": _cmd_generate,
             "convert": _cmd_convert, "instances": _cmd_instances,
             "reproduce": _cmd_reproduce}


def _terminate(signum: int, frame: object) -> None:
    """SIGTERM / SIGHUP: unwind like Ctrl-C, so temporary files are removed."""
    raise KeyboardInterrupt


def _run(args: argparse.Namespace, out: TextIO, err: TextIO) -> int:
    """Run one subcommand, with ``--max-bytes`` in force and termination signals
    unwinding the stack (cleanup in ``finally`` blocks) instead of killing at once."""
    import os
    import signal
    import threading

    from ..io.common import MAX_BYTES_ENV

    saved_env = os.environ.get(MAX_BYTES_ENV)
    saved_sig = {}
    if threading.current_thread() is threading.main_thread():
        for sig in (signal.SIGTERM, getattr(signal, "SIGHUP", None)):
            if sig is not None and signal.getsignal(sig) in (signal.SIG_DFL, None):
                saved_sig[sig] = signal.signal(sig, _terminate)
    try:
        if args.max_bytes is not None:
            os.environ[MAX_BYTES_ENV] = str(args.max_bytes)
        return _COMMANDS[args.command](args, out, err)
    finally:
        for sig, old in saved_sig.items():
            signal.signal(sig, old)
        if args.max_bytes is not None:
            if saved_env is None:
                os.environ.pop(MAX_BYTES_ENV, None)
            else:
                os.environ[MAX_BYTES_ENV] = saved_env


def _exit_now_if_solver_threads(as_program: bool) -> None:
    """After a Ctrl-C, leave at once when run as the program (``main()`` without
    ``argv``), never inside a caller's process: native solver threads still winding
    down, or a compiler (numba/LLVM) interrupted half-way, can make interpreter
    finalisation crash (SIGABRT or SIGSEGV instead of exit 130).  Files being written
    were already cleaned up while the interrupt unwound to here."""
    if not as_program:
        return
    import os
    for stream in (sys.stdout, sys.stderr):
        try:
            stream.flush()
        except (OSError, ValueError):
            pass
    os._exit(EXIT_INTERRUPTED)


def _interrupted(err: TextIO, as_program: bool) -> int:
    print("assocopt: interrupted", file=err)
    _exit_now_if_solver_threads(as_program)
    return EXIT_INTERRUPTED


def _caused_by_interrupt(exc: BaseException) -> bool:
    """An error raised because of a Ctrl-C: one with a ``KeyboardInterrupt`` in its
    chain, or any error after the program's handler saw a Ctrl-C (a native extension
    interrupted while importing reports ``ImportError: initialization failed``)."""
    seen: set[int] = set()
    e: BaseException | None = exc
    while e is not None and id(e) not in seen:
        if isinstance(e, KeyboardInterrupt):
            return True
        seen.add(id(e))
        e = e.__cause__ or e.__context__
    return interrupted()


def main(argv: Sequence[str] | None = None) -> int:
    """Run the command line; returns the exit code (see :mod:`assocopt.cli`)."""
    out, err = sys.stdout, sys.stderr
    disarm = arm(EXIT_INTERRUPTED) if argv is None else (lambda: None)
    try:
        parser = _build_parser()
        args = parser.parse_args(list(sys.argv[1:] if argv is None else argv))
        return _run(args, out, err)
    except SystemExit as exc:        # --help / --version
        code = exc.code
        return code if isinstance(code, int) else (0 if code is None else EXIT_BAD_INPUT)
    except _UsageError as exc:
        _error(err, f"{exc} (see 'assocopt --help')")
        return EXIT_BAD_INPUT
    except AssocoptError as exc:
        _error(err, str(exc))
        return EXIT_BAD_INPUT
    except BrokenPipeError:          # output piped into `head` and closed: stop quietly
        try:
            import os
            os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        except (OSError, ValueError):
            pass
        return EXIT_BROKEN_PIPE
    except OSError as exc:
        _error(err, _os_message(exc))
        return EXIT_BAD_INPUT
    except KeyboardInterrupt:
        return _interrupted(err, argv is None)
    except Exception as exc:  # noqa: BLE001 - the CLI never shows a traceback
        if _caused_by_interrupt(exc):
            return _interrupted(err, argv is None)
        _error(err, f"internal error ({type(exc).__name__}: {_one_line(str(exc))}); "
                    "this is a bug in assocopt or a back end, please report it")
        return EXIT_INTERNAL
    finally:
        disarm()

