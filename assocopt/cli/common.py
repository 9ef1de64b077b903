"""Shared pieces of the command line: exit codes, error lines and output formatting.

Every subcommand module and :func:`assocopt.cli.app.main` import from here, so the exit
codes, the one-line ``assocopt: error: ...`` format and the readable solve summary are
defined once.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any, Sequence, TextIO

from ..model.solution import Solution, Status

EXIT_OK = 0
EXIT_INFEASIBLE = 1
EXIT_BAD_INPUT = 2
EXIT_LIMIT = 3
EXIT_INTERNAL = 4
EXIT_INTERRUPTED = 130
EXIT_BROKEN_PIPE = 141   # as a shell reports a process stopped by SIGPIPE

#: How many chosen tuples the human-readable output shows before "... and k more".
MAX_SHOWN = 20


class _UsageError(Exception):
    """An argparse usage error, turned into one line on stderr and exit code 2."""


def exit_code(solution: Solution) -> int:
    """The process exit code for a finished solve (see :mod:`assocopt.cli`)."""
    status = solution.status
    if status in (Status.OPTIMAL, Status.FEASIBLE):
        return EXIT_OK
    if status is Status.INFEASIBLE:
        return EXIT_INFEASIBLE
    if status.is_limit:
        has = solution.has_solution or solution.x is not None
        return EXIT_OK if has else EXIT_LIMIT
    return EXIT_INTERNAL


def _instance_path(text: str) -> str:
    """``text``, or the stored instance of that name when no such file exists
    (``assocopt solve example-sd`` works from any folder, installed or not); every
    command that reads an instance file resolves its argument through this."""
    if Path(text).exists():
        return text
    from ..workflow.generate import find_stored_instance

    stored = find_stored_instance(text)
    return str(stored) if stored is not None else text


# ------------------------------------------------------------------ errors
def _error(err: TextIO, message: str) -> None:
    print(f"assocopt: error: {_one_line(message)}", file=err)


def _os_message(exc: OSError) -> str:
    what = exc.strerror or str(exc)
    name = exc.filename
    return f"{name}: {what}" if name else what


def _one_line(text: str) -> str:
    return " ".join(str(text).split())


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
    from ..problems.problem import OPT_TOL      # imported here: the CLI starts without scipy
    return abs(objective - optimum) <= OPT_TOL * max(1.0, abs(optimum))


def _short_list(values: Sequence[int], limit: int = MAX_SHOWN) -> str:
    vals = [str(int(v)) for v in values]
    if len(vals) > limit:
        return "[" + " ".join(vals[:limit]) + f" ... ({len(vals) - limit} more)]"
    return "[" + " ".join(vals) + "]"


def _table(rows: list[Sequence[str]], out: TextIO) -> None:
    """Print ``rows`` (first = header) in aligned columns; the last column is free text."""
    widths = [max(len(r[i]) for r in rows) for i in range(len(rows[0]) - 1)]
    for r in rows:
        cells = [c.ljust(w) for c, w in zip(r[:-1], widths)] + [r[-1]]
        print("  ".join(cells).rstrip(), file=out)


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
    detail = ", ".join(f"{k.replace('_', ' ')} {t[k]:.3g} s"
                       for k in ("import", "build", "solve", "compile", "cache_load")
                       if t.get(k) is not None)
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
    from ..io import solution_to_dict

    extra: dict[str, Any] = {"instance": problem.name, "sizes": list(problem.sizes),
                             "optimum": problem.optimum}
    if problem.optimum is not None:
        extra["matches_recorded_optimum"] = _matches(sol.objective, problem.optimum)
    return solution_to_dict(sol, extra)

