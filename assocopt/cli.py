"""Command line: ``assocopt solve FILE`` and ``assocopt solvers``.

Exit codes
----------
0  solved: status optimal or feasible, or stopped by a limit with a solution
1  proven infeasible (the message names an uncovered index when that is the cause)
2  bad input: unreadable or malformed file, invalid option, unknown or missing solver
3  stopped by a time/iteration limit without a solution
4  the solver reported an error, or an internal error (a bug: please report it)
130  interrupted (Ctrl-C)

Errors are one line on stderr, ``assocopt: error: <message>``, never a traceback.
"""

from __future__ import annotations

import argparse
import json
import math
import sys
from typing import Any, Sequence, TextIO

from .errors import AssocoptError
from .solution import Solution, Status

__all__ = ["main", "exit_code", "EXIT_OK", "EXIT_INFEASIBLE", "EXIT_BAD_INPUT",
           "EXIT_LIMIT", "EXIT_INTERNAL", "EXIT_INTERRUPTED"]

EXIT_OK = 0
EXIT_INFEASIBLE = 1
EXIT_BAD_INPUT = 2
EXIT_LIMIT = 3
EXIT_INTERNAL = 4
EXIT_INTERRUPTED = 130

#: How many chosen tuples the human-readable output shows before "... and k more".
MAX_SHOWN = 20


class _UsageError(Exception):
    """An argparse usage error, turned into one line on stderr and exit code 2."""


class _Parser(argparse.ArgumentParser):
    def error(self, message: str) -> None:  # type: ignore[override]
        raise _UsageError(message)


def exit_code(solution: Solution) -> int:
    """The process exit code for a finished solve (see the module docstring)."""
    status = solution.status
    if status in (Status.OPTIMAL, Status.FEASIBLE):
        return EXIT_OK
    if status is Status.INFEASIBLE:
        return EXIT_INFEASIBLE
    if status is Status.TIME_LIMIT:
        has = solution.has_solution or solution.x is not None
        return EXIT_OK if has else EXIT_LIMIT
    return EXIT_INTERNAL


# ------------------------------------------------------------------ parser
def _build_parser() -> argparse.ArgumentParser:
    from .io import FORMATS

    parser = _Parser(
        prog="assocopt",
        description="Data association / assignment problems as optimisation models.",
        epilog="exit codes: 0 solved, 1 infeasible, 2 bad input, 3 limit reached without "
               "a solution, 4 solver or internal error, 130 interrupted")
    from . import __version__
    parser.add_argument("--version", action="version", version=f"assocopt {__version__}")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND")
    sub.required = True

    ps = sub.add_parser("solve", help="solve an instance file",
                        description="Solve an instance file (assocopt JSON, Grundel, "
                                    "Balas-Saltzman or OR-Library format).")
    ps.add_argument("file", metavar="FILE", help="instance file")
    ps.add_argument("--solver", default="auto",
                    help="back end name (see 'assocopt solvers'); default: auto")
    ps.add_argument("--relax", choices=["lp"], default=None,
                    help="solve the LP relaxation instead of the ILP")
    ps.add_argument("--time-limit", type=float, metavar="S", default=None,
                    help="time limit in seconds")
    ps.add_argument("--gap", type=float, metavar="G", default=0.0,
                    help="relative MIP gap at which to stop (default 0: prove optimality)")
    ps.add_argument("--threads", type=int, metavar="T", default=None,
                    help="solver threads")
    ps.add_argument("--format", choices=list(FORMATS), default="auto",
                    help="instance file format (default: detected from the content)")
    ps.add_argument("--instance", metavar="I", default=None,
                    help="instance in a multi-instance file: N20_P5, 20,5 or a 1-based "
                         "position")
    ps.add_argument("--json", action="store_true",
                    help="print one JSON object instead of the readable summary")
    ps.add_argument("--out", metavar="SOLUTION.json", default=None,
                    help="also write the solution as JSON to this file")

    pl = sub.add_parser("solvers", help="list the back ends and their capabilities",
                        description="List every registered back end, installed or not.")
    pl.add_argument("--json", action="store_true", help="print JSON")
    return parser


# ------------------------------------------------------------------ formatting
def _num(v: float | None) -> str:
    if v is None:
        return "-"
    if isinstance(v, float) and math.isinf(v):
        return "inf" if v > 0 else "-inf"
    return f"{v:.10g}"


def _gap_text(g: float | None) -> str:
    if g is None:
        return "-"
    if math.isinf(g):
        return "inf"
    return "0" if g == 0 else f"{g:.3g} ({100 * g:.3g} %)"


def _matches(objective: float | None, optimum: float | None) -> bool | None:
    if optimum is None or objective is None:
        return None
    return abs(objective - optimum) <= 1e-9 * max(1.0, abs(optimum))


def _short_list(values: Sequence[int], limit: int = MAX_SHOWN) -> str:
    vals = [str(int(v)) for v in values]
    if len(vals) > limit:
        return "[" + " ".join(vals[:limit]) + f" ... ({len(vals) - limit} more)]"
    return "[" + " ".join(vals) + "]"


def _one_line(text: str) -> str:
    return " ".join(str(text).split())


def _human(problem: Any, sol: Solution, out: TextIO) -> None:
    w = 10
    sizes = " x ".join(str(n) for n in problem.sizes)
    kind = {"two_d": "2-D with miss costs"}.get(problem.kind, problem.kind)
    rows = [("instance", f"{problem.name}  ({problem.ndim} axes, sizes {sizes}, "
                         f"{problem.n_candidates} candidates, {kind})")]
    status = sol.status.value + (f" (LP relaxation{', integral' if sol.integral else ''})"
                                 if sol.relaxation else "")
    rows.append(("status", status))
    rows.append(("objective", _num(sol.objective)))
    rows.append(("bound", _num(sol.bound)))
    rows.append(("gap", _gap_text(sol.gap)))
    if problem.optimum is not None:
        m = _matches(sol.objective, problem.optimum)
        verdict = "" if m is None else ("  (matches)" if m else "  (DIFFERS)")
        rows.append(("recorded", f"optimum {_num(problem.optimum)}{verdict}"))
    ver = f" {sol.solver_version}" if sol.solver_version else ""
    rows.append(("solver", f"{sol.solver}{ver}"))
    t = sol.times
    detail = ", ".join(f"{k} {t[k]:.3g} s" for k in ("build", "solve") if t.get(k) is not None)
    total = t.get("total")
    rows.append(("time", (f"{total:.3g} s" if total is not None else "-")
                 + (f" ({detail})" if detail else "")))
    if sol.message:
        rows.append(("message", _one_line(sol.message)))
    for key, val in rows:
        print(f"{key:<{w}} {val}", file=out)
    if sol.tuples is not None:
        T = sol.tuples.tolist()
        print(f"{'tuples':<{w}} {len(T)} chosen (index 0 = dummy, real indices 1-based)",
              file=out)
        for tup in T[:MAX_SHOWN]:
            print(" " * (w + 3) + "(" + ", ".join(str(i) for i in tup) + ")", file=out)
        if len(T) > MAX_SHOWN:
            print(" " * (w + 3) + f"... and {len(T) - MAX_SHOWN} more "
                                  "(--json or --out for all)", file=out)
        if problem.kind in ("dense", "two_d"):
            arrays = sol.assignment()
            print(f"{'assignment':<{w}} 0-based index arrays (as scipy's "
                  "linear_sum_assignment)", file=out)
            for s, arr in enumerate(arrays):
                print(" " * (w + 3) + f"axis {s}: {_short_list(arr.tolist())}", file=out)


def _solve_record(problem: Any, sol: Solution) -> dict[str, Any]:
    from .io import solution_to_dict

    extra: dict[str, Any] = {"instance": problem.name, "sizes": list(problem.sizes),
                             "optimum": problem.optimum}
    if problem.optimum is not None:
        extra["matches_recorded_optimum"] = _matches(sol.objective, problem.optimum)
    return solution_to_dict(sol, extra)


# ------------------------------------------------------------------ commands
def _cmd_solve(args: argparse.Namespace, out: TextIO, err: TextIO) -> int:
    from .api import solve
    from .io import read_instance, write_solution

    problem = read_instance(args.file, format=args.format, instance=args.instance)
    sol = solve(problem, args.solver, relax=args.relax, time_limit=args.time_limit,
                mip_gap=args.gap, threads=args.threads)
    record = _solve_record(problem, sol)
    if args.out:
        write_solution(sol, args.out, extra={k: record[k] for k in
                                            ("instance", "sizes", "optimum",
                                             "matches_recorded_optimum") if k in record})
    if args.json:
        print(json.dumps(record, allow_nan=False), file=out)
    else:
        _human(problem, sol, out)
    code = exit_code(sol)
    if code == EXIT_INTERNAL:
        print(f"assocopt: error: solver {sol.solver!r} failed (internal error): "
              f"{_one_line(sol.message) or 'no message'}", file=err)
    elif code == EXIT_LIMIT:
        print("assocopt: error: stopped by a limit before any solution was found", file=err)
    return code


def _solver_rows() -> list[dict[str, Any]]:
    from .solvers import registered

    rows = []
    for name, cls in sorted(registered().items()):
        try:
            installed = bool(cls.is_available())
        except Exception:  # a broken back end must not break the listing
            installed = False
        try:
            version = cls.version() if installed else ""
        except Exception:
            version = ""
        rows.append({
            "name": name,
            "installed": installed,
            "version": version or None,
            "package": cls.distribution,
            "ilp": bool(cls.integer),
            "lp": bool(cls.lp),
            "exact": bool(cls.exact),
            "gives_bound": bool(cls.gives_bound),
            "max_ndim": cls.max_ndim,
            "time_limit": bool(cls.supports_time_limit),
            "description": cls.description,
        })
    return rows


def _cmd_solvers(args: argparse.Namespace, out: TextIO, err: TextIO) -> int:
    rows = _solver_rows()
    if args.json:
        print(json.dumps(rows, indent=2), file=out)
        return EXIT_OK
    if not rows:
        print("no back ends registered", file=out)
        return EXIT_OK
    yes = {True: "yes", False: "-"}
    table = [("name", "installed", "version", "ILP", "LP", "exact", "max N", "description")]
    for r in rows:
        table.append((r["name"], "yes" if r["installed"] else "no",
                      r["version"] or "-", yes[r["ilp"]], yes[r["lp"]], yes[r["exact"]],
                      "any" if r["max_ndim"] is None else str(r["max_ndim"]),
                      r["description"] or ""))
    widths = [max(len(row[i]) for row in table) for i in range(len(table[0]) - 1)]
    for row in table:
        cells = [c.ljust(wd) for c, wd in zip(row[:-1], widths)]
        print("  ".join(cells + [row[-1]]).rstrip(), file=out)
    return EXIT_OK


# ------------------------------------------------------------------ main
def _error(err: TextIO, message: str) -> None:
    print(f"assocopt: error: {_one_line(message)}", file=err)


def _os_message(exc: OSError) -> str:
    what = exc.strerror or str(exc)
    name = exc.filename
    return f"{name}: {what}" if name else what


def main(argv: Sequence[str] | None = None) -> int:
    """Run the command line; returns the exit code (see the module docstring)."""
    out, err = sys.stdout, sys.stderr
    try:
        parser = _build_parser()
        args = parser.parse_args(list(sys.argv[1:] if argv is None else argv))
        if args.command == "solve":
            return _cmd_solve(args, out, err)
        return _cmd_solvers(args, out, err)
    except SystemExit as exc:        # --help / --version
        code = exc.code
        return code if isinstance(code, int) else (0 if code is None else EXIT_BAD_INPUT)
    except _UsageError as exc:
        _error(err, f"{exc} (see 'assocopt --help')")
        return EXIT_BAD_INPUT
    except AssocoptError as exc:
        _error(err, str(exc))
        return EXIT_BAD_INPUT
    except OSError as exc:
        _error(err, _os_message(exc))
        return EXIT_BAD_INPUT
    except KeyboardInterrupt:
        print("assocopt: interrupted", file=err)
        return EXIT_INTERRUPTED
    except Exception as exc:  # noqa: BLE001 - the CLI never shows a traceback
        _error(err, f"internal error ({type(exc).__name__}: {_one_line(str(exc))}); "
                    "this is a bug in assocopt or a back end, please report it")
        return EXIT_INTERNAL


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
