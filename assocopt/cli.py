"""Command line: ``assocopt COMMAND ...``.

Commands: ``solve`` (one instance), ``compare`` (instances x back ends or models),
``validate`` (check instance files), ``export`` (MPS / LP model file), ``generate``
(random instance), ``convert`` (between instance formats), ``instances`` (list stored
instances), ``models`` (list named models), ``solvers`` (list back ends) and
``reproduce`` (a paper's experiments, when :mod:`assocopt.reproduce` is installed).
``assocopt COMMAND --help`` describes each.

Exit codes
----------
0  solved: status optimal or feasible, or stopped by a limit with a solution
   (other commands: done)
1  proven infeasible (the message names an uncovered index when that is the cause)
2  bad input: unreadable or malformed file, invalid option, unknown or missing solver
   or model; ``validate``: some file failed a check
3  stopped by a time/iteration limit without a solution
4  the solver reported an error, or an internal error (a bug: please report it);
   ``compare --check``: an answer claimed optimal differs from a recorded optimum, a
   bound exceeds it, or a back end failed
130  interrupted (Ctrl-C); 141: the output pipe was closed (e.g. ``| head``)

Errors are one line on stderr, ``assocopt: error: <message>``, never a traceback.
"""

from __future__ import annotations

import argparse
import io
import json
import math
import sys
from pathlib import Path
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
EXIT_BROKEN_PIPE = 141   # as a shell reports a process stopped by SIGPIPE

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
    ps.add_argument("--solver", default=None,
                    help="back end name (see 'assocopt solvers'); default: auto")
    ps.add_argument("--model", metavar="MODEL", default=None,
                    help="named model (file stem, see 'assocopt models', or a .toml path) "
                         "instead of --solver")
    ps.add_argument("--relax", choices=["lp"], default=None,
                    help="solve the LP relaxation instead of the ILP")
    ps.add_argument("--time-limit", type=float, metavar="S", default=None,
                    help="time limit in seconds")
    ps.add_argument("--gap", type=float, metavar="G", default=None,
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
    _add_more_parsers(sub, FORMATS)
    return parser


def _sizes(text: str) -> tuple[int, ...]:
    parts = [t for t in text.replace("x", ",").split(",") if t.strip()]
    try:
        sizes = tuple(int(t) for t in parts)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected integers such as 5,5,5, got {text!r}") \
            from None
    if len(sizes) < 2:
        raise argparse.ArgumentTypeError(f"give at least 2 sizes, got {text!r}")
    if any(n < 1 for n in sizes):
        raise argparse.ArgumentTypeError(f"sizes must be positive, got {text!r}")
    return sizes


def _names(text: str) -> list[str]:
    names = [t.strip() for t in text.split(",") if t.strip()]
    if not names:
        raise argparse.ArgumentTypeError("expected comma-separated names")
    return names


def _add_input_args(p: argparse.ArgumentParser, formats: Sequence[str]) -> None:
    p.add_argument("--format", choices=list(formats), default="auto",
                   help="instance file format (default: detected from the content)")
    p.add_argument("--instance", metavar="I", default=None,
                   help="instance in a multi-instance file: N20_P5, 20,5 or a 1-based position")


def _add_more_parsers(sub: Any, formats: Sequence[str]) -> None:
    from .export import CONVERT_FORMATS
    from .generate import GENERATORS

    pm = sub.add_parser("models", help="list the named models",
                        description="List the named models (TOML files) found by stem.")
    pm.add_argument("--json", action="store_true", help="print JSON")
    pm.add_argument("--check", action="store_true",
                    help="also let each back end check its options (slower)")

    pc = sub.add_parser("compare", help="compare back ends or models on instances",
                        description="Solve every FILE with every back end (--solvers) and/or "
                                    "named model (--models); print one row per pair.")
    pc.add_argument("files", nargs="+", metavar="FILE", help="instance files")
    pc.add_argument("--solvers", type=_names, metavar="A,B", default=None,
                    help="comma-separated back end names")
    pc.add_argument("--models", type=_names, metavar="M1,M2", default=None,
                    help="comma-separated model names or .toml paths")
    pc.add_argument("--relax", choices=["lp"], default=None,
                    help="--solvers solve the LP relaxation")
    pc.add_argument("--time-limit", type=float, metavar="S", default=None,
                    help="time limit per solve, seconds")
    pc.add_argument("--repeat", type=int, metavar="R", default=1,
                    help="solve each pair R times, keep the fastest (for timings)")
    fmt = pc.add_mutually_exclusive_group()
    fmt.add_argument("--json", action="store_true", help="print the rows as JSON")
    fmt.add_argument("--csv", action="store_true", help="print the rows as CSV")
    pc.add_argument("--out", metavar="FILE", default=None,
                    help="write the table to FILE instead of stdout")
    pc.add_argument("--progress", action=argparse.BooleanOptionalAction, default=None,
                    help="progress bar on stderr (default: when stderr is a terminal)")
    pc.add_argument("--check", action="store_true",
                    help="exit 4 when an answer disagrees with a recorded optimum or a "
                         "back end fails")
    _add_input_args(pc, formats)

    pv = sub.add_parser("validate", help="check instance files",
                        description="Check each FILE: format, values and feasibility "
                                    "(exit 0 all good, 2 otherwise).")
    pv.add_argument("files", nargs="+", metavar="FILE", help="instance files")
    pv.add_argument("--check-optimum", action="store_true",
                    help="also prove the optimum with HiGHS and compare it with the "
                         "recorded one")
    pv.add_argument("--time-limit", type=float, metavar="S", default=60.0,
                    help="seconds for HiGHS when a check needs a solve (default 60)")
    pv.add_argument("--json", action="store_true", help="print one JSON record per file")
    _add_input_args(pv, formats)

    pe = sub.add_parser("export", help="write the ILP or LP as an MPS or LP file",
                        description="Write the model of FILE for any MILP solver (via "
                                    "HiGHS); the format follows the suffix of --to.")
    pe.add_argument("file", metavar="FILE", help="instance file")
    pe.add_argument("--to", required=True, metavar="MODEL.mps|MODEL.lp",
                    help="output model file (.mps or .lp)")
    pe.add_argument("--relax", choices=["lp"], default=None,
                    help="write the LP relaxation instead of the ILP")
    pe.add_argument("--no-names", action="store_true",
                    help="keep HiGHS's default names c0.., r0.. (default: x_<tuple>, "
                         "cover_<axis>_<index>)")
    _add_input_args(pe, formats)

    pg = sub.add_parser("generate", help="write a random instance",
                        description="Write a seeded random instance in the assocopt JSON "
                                    "format: dense axial, sparse S-D with dummies, or "
                                    "planted (Grundel-like, optimum known).")
    pg.add_argument("kind", choices=list(GENERATORS), help="generator")
    pg.add_argument("--seed", type=int, required=True, metavar="S", help="random seed")
    pg.add_argument("--sizes", type=_sizes, default=None, metavar="N1,N2,...",
                    help="axis sizes (default: dense 5,5,5; sparse 4,4,4; planted 6,6,6)")
    pg.add_argument("--out", required=True, metavar="FILE", help="output .json file")
    pg.add_argument("--low", type=int, default=None, help="dense/planted: lowest cost")
    pg.add_argument("--high", type=int, default=None, help="dense/planted: highest cost")
    pg.add_argument("--pd", type=float, default=None,
                    help="sparse: detection probability (default 0.9)")
    pg.add_argument("--targets", type=int, default=None,
                    help="sparse: number of targets (default: the smallest size)")
    pg.add_argument("--prove", action="store_true",
                    help="prove the optimum with HiGHS and record it")
    pg.add_argument("--time-limit", type=float, metavar="S", default=None,
                    help="seconds for --prove")

    pk = sub.add_parser("convert", help="convert between instance formats",
                        description="Read IN (any supported format) and write OUT: the "
                                    "assocopt JSON (.json) or a public format.")
    pk.add_argument("src", metavar="IN", help="input instance file")
    pk.add_argument("dst", metavar="OUT", help="output file")
    pk.add_argument("--from", dest="format", choices=list(formats), default="auto",
                    help="input format (default: detected from the content)")
    pk.add_argument("--to-format", choices=list(CONVERT_FORMATS), default=None,
                    help="output format (default: from the name: .json, ap3.*.txt, "
                         "assign*.txt, balas*)")
    pk.add_argument("--instance", metavar="I", default=None,
                    help="instance in a multi-instance file: N20_P5, 20,5 or a position")
    pk.add_argument("--prove", action="store_true",
                    help="prove the optimum with HiGHS and record it")
    pk.add_argument("--time-limit", type=float, metavar="S", default=None,
                    help="seconds for --prove")

    pi = sub.add_parser("instances", help="list stored instances",
                        description="List the instance files of DIR (default: ./instances, "
                                    "else the project's instances/) with their proven optima.")
    pi.add_argument("dir", nargs="?", default=None, metavar="DIR", help="folder")
    pi.add_argument("--json", action="store_true", help="print JSON")
    pi.add_argument("--write-index", action="store_true",
                    help="(re)write DIR/index.csv from the files")

    pr = sub.add_parser("reproduce", help="reproduce a paper's experiments",
                        description="Run a paper's experiments and write DIR/summary.json "
                                    "and figures (needs assocopt.reproduce).")
    pr.add_argument("name", nargs="?", default=None, metavar="NAME",
                    help="paper name (see --list)")
    pr.add_argument("--list", action="store_true", help="list the papers")
    pr.add_argument("--runs", type=int, default=None, metavar="N", help="Monte Carlo runs")
    pr.add_argument("--workers", type=int, default=None, metavar="W", help="worker processes")
    pr.add_argument("--seed", type=int, default=None, metavar="S", help="random seed")
    pr.add_argument("--out", default=None, metavar="DIR", help="output folder")
    pr.add_argument("--progress", action=argparse.BooleanOptionalAction, default=None,
                    help="progress bar on stderr (default: when stderr is a terminal)")


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
def _compile_note(problem: Any, solver: str, relax: str | None, err: TextIO) -> None:
    """One line on stderr before the numba kernels are compiled (first run only)."""
    from .api import choose_solver
    from .solvers import get_backend

    name = choose_solver(problem, relax) if solver == "auto" else solver
    if relax is not None or name not in ("bnb", "lagrangian-exact") or \
            not get_backend("bnb").is_available():
        return
    from .solvers import bnb_kernels
    if not bnb_kernels.cached():
        print("assocopt: compiling the numba kernels (first run only, about 15-30 s; "
              "cached afterwards)", file=err)


def _cmd_solve(args: argparse.Namespace, out: TextIO, err: TextIO) -> int:
    from .api import solve
    from .io import read_instance, write_solution

    if args.model is not None:
        from .models import load_model

        if args.solver is not None:
            raise AssocoptError("give --solver or --model, not both")
        model = load_model(args.model)
        if args.relax is not None and args.relax != model.relax:
            raise AssocoptError(f"--relax {args.relax} conflicts with model {model.name!r} "
                                f"(formulation {model.formulation!r})")
        problem = read_instance(args.file, format=args.format, instance=args.instance)
        _compile_note(problem, model.solver, model.relax, err)
        sol = model.solve(problem, time_limit=args.time_limit, mip_gap=args.gap,
                          threads=args.threads)
    else:
        problem = read_instance(args.file, format=args.format, instance=args.instance)
        _compile_note(problem, args.solver or "auto", args.relax, err)
        sol = solve(problem, args.solver or "auto", relax=args.relax,
                    time_limit=args.time_limit,
                    mip_gap=0.0 if args.gap is None else args.gap, threads=args.threads)
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
    _table(table, out)
    return EXIT_OK


def _table(rows: list[Sequence[str]], out: TextIO) -> None:
    """Print ``rows`` (first = header) in aligned columns; the last column is free text."""
    widths = [max(len(r[i]) for r in rows) for i in range(len(rows[0]) - 1)]
    for r in rows:
        cells = [c.ljust(w) for c, w in zip(r[:-1], widths)] + [r[-1]]
        print("  ".join(cells).rstrip(), file=out)


def _cmd_models(args: argparse.Namespace, out: TextIO, err: TextIO) -> int:
    from .models import list_models

    models = list_models(check_options=args.check)
    if args.json:
        print(json.dumps([m.to_dict() for m in models], indent=2), file=out)
        return EXIT_OK
    rows: list[Sequence[str]] = [("name", "formulation", "solver", "options", "description")]
    for m in models:
        opts = " ".join(f"{k}={v}" for k, v in m.options.items()) or "-"
        cost = f" [cost: {m.cost['builder']}]" if m.cost else ""
        rows.append((m.name, m.formulation, m.solver, opts, m.description + cost))
    _table(rows, out)
    return EXIT_OK


def _cmd_compare(args: argparse.Namespace, out: TextIO, err: TextIO) -> int:
    from .compare import compare

    res = compare(args.files, solvers=args.solvers, models=args.models,
                  time_limit=args.time_limit, relax=args.relax, repeat=args.repeat,
                  format=args.format, instance=args.instance, progress=args.progress)
    fmt = "json" if args.json else "csv" if args.csv else "text"
    if args.out:
        from .io import _atomic_write
        buf = io.StringIO()
        res.write(buf, fmt)
        _atomic_write(Path(args.out), buf.getvalue())
        print(f"wrote {args.out}: {len(res.rows)} rows ({fmt})", file=out)
    else:
        res.write(out, fmt)
    if args.check:
        bad = res.disagreements() + res.errors()
        if bad:
            r = bad[0]
            _error(err, f"{len(bad)} run(s) failed the check; first: {r['instance']} / "
                        f"{r['method']}: status {r['status']}, objective "
                        f"{_num(r['objective'])}, recorded optimum {_num(r['optimum'])}"
                        + (f" ({r['message']})" if r["message"] else ""))
            return EXIT_INTERNAL
    return EXIT_OK


def _validate_one(path: str, args: argparse.Namespace) -> dict[str, Any]:
    from .generate import feasibility, prove_optimum
    from .io import read_instance

    rec: dict[str, Any] = {"file": path, "ok": False}
    try:
        p = read_instance(path, format=args.format, instance=args.instance)
    except (AssocoptError, OSError) as exc:
        rec["error"] = _os_message(exc) if isinstance(exc, OSError) else str(exc)
        return rec
    rec.update(name=p.name, kind=p.kind, sizes=list(p.sizes),
               candidates=int((~p.slack).sum()), optimum=p.optimum)
    feasible, why = feasibility(p, time_limit=args.time_limit)
    rec.update(feasible=feasible, feasibility=why)
    if feasible is False:
        rec["error"] = f"{path}: infeasible: {why}"
        return rec
    if args.check_optimum:
        try:
            proven, how = prove_optimum(p, time_limit=args.time_limit)
        except AssocoptError as exc:
            rec["error"] = f"{path}: {exc}"
            return rec
        rec["proven_optimum"] = proven
        if p.optimum is not None and not _matches(proven, p.optimum):
            rec["error"] = (f"{path}: recorded optimum {_num(p.optimum)} but {how} gives "
                            f"{_num(proven)}")
            return rec
    rec["ok"] = True
    return rec


def _cmd_validate(args: argparse.Namespace, out: TextIO, err: TextIO) -> int:
    code = EXIT_OK
    for path in args.files:
        rec = _validate_one(path, args)
        if args.json:
            print(json.dumps(rec, allow_nan=False), file=out)
        elif rec["ok"]:
            sizes = "x".join(map(str, rec["sizes"]))
            opt = "no recorded optimum" if rec["optimum"] is None else \
                f"recorded optimum {_num(rec['optimum'])}" + \
                (" (confirmed by HiGHS)" if "proven_optimum" in rec else "")
            feas = "feasible" if rec["feasible"] else "feasibility undecided"
            print(f"ok  {path}: {rec['kind']}, sizes {sizes}, {rec['candidates']} "
                  f"candidates; {feas} ({rec['feasibility']}); {opt}", file=out)
        if not rec["ok"]:
            _error(err, rec["error"])
            code = EXIT_BAD_INPUT
    return code


def _cmd_export(args: argparse.Namespace, out: TextIO, err: TextIO) -> int:
    from .export import export_model
    from .io import read_instance

    problem = read_instance(args.file, format=args.format, instance=args.instance)
    info = export_model(problem, args.to, relax=args.relax, names=not args.no_names)
    what = "LP relaxation" if args.relax else "ILP"
    print(f"wrote {info['path']}: {what} of {problem.name}, {info['columns']} "
          f"{'continuous' if args.relax else 'binary'} variables, {info['rows']} equality "
          f"rows ({info['format'].upper()} format)", file=out)
    return EXIT_OK


def _cmd_generate(args: argparse.Namespace, out: TextIO, err: TextIO) -> int:
    from .generate import generate, prove_optimum
    from .io import write_instance

    params: dict[str, Any] = {}
    allowed = {"dense": ("low", "high"), "planted": ("low", "high"),
               "sparse": ("pd", "targets")}[args.kind]
    for key in ("low", "high", "pd", "targets"):
        value = getattr(args, key)
        if value is not None:
            if key not in allowed:
                raise AssocoptError(f"--{key} does not apply to the {args.kind} generator "
                                    f"(it takes {', '.join('--' + a for a in allowed)})")
            params[key] = value
    problem = generate(args.kind, seed=args.seed, sizes=args.sizes, **params)
    optimum, source = problem.optimum, problem.meta.get("optimum_source")
    if args.prove and args.kind != "planted":
        optimum, source = prove_optimum(problem, time_limit=args.time_limit)
    write_instance(problem, args.out, optimum=optimum, optimum_source=source)
    sizes = "x".join(map(str, problem.sizes))
    opt = "no optimum recorded (--prove records one)" if optimum is None else \
        f"optimum {_num(optimum)} ({source})"
    print(f"wrote {args.out}: {problem.name}, sizes {sizes}, "
          f"{int((~problem.slack).sum())} candidates; {opt}", file=out)
    return EXIT_OK


def _cmd_convert(args: argparse.Namespace, out: TextIO, err: TextIO) -> int:
    from .export import convert

    info = convert(args.src, args.dst, from_format=args.format, to_format=args.to_format,
                   instance=args.instance, prove=args.prove, time_limit=args.time_limit)
    opt = "" if info["optimum"] is None else f"; optimum {_num(info['optimum'])}"
    print(f"wrote {', '.join(info['written'])} ({info['format']} format): {info['name']}, "
          f"sizes {'x'.join(map(str, info['sizes']))}{opt}", file=out)
    return EXIT_OK


def _cmd_instances(args: argparse.Namespace, out: TextIO, err: TextIO) -> int:
    from .generate import catalogue, default_instances_dir, write_index

    folder = Path(args.dir) if args.dir else default_instances_dir()
    if args.write_index:
        path = write_index(folder)
        print(f"wrote {path}", file=out)
        return EXIT_OK
    records = catalogue(folder)
    if args.json:
        print(json.dumps(records, indent=2), file=out)
        return EXIT_OK
    rows: list[Sequence[str]] = [("file", "kind", "sizes", "candidates", "optimum",
                                  "how the optimum was proven")]
    for r in records:
        rows.append((r["file"], r["kind"], "x".join(map(str, r["sizes"])), str(r["candidates"]),
                     _num(r["optimum"]), r["optimum_source"] or "-"))
    _table(rows, out)
    return EXIT_OK


def _cmd_reproduce(args: argparse.Namespace, out: TextIO, err: TextIO) -> int:
    import importlib
    import importlib.util
    import inspect

    try:
        found = importlib.util.find_spec("assocopt.reproduce") is not None
    except (ImportError, ValueError):
        found = False
    if not found:
        raise AssocoptError("paper reproduction is not available in this installation "
                            "(module assocopt.reproduce is missing)")
    mod = importlib.import_module("assocopt.reproduce")
    if args.list:
        papers = mod.list_papers()
        if isinstance(papers, dict):
            papers = [{"name": k, "title": v} for k, v in papers.items()]
        for paper in papers:
            if isinstance(paper, str):
                print(paper, file=out)
                continue
            get = paper.get if isinstance(paper, dict) else \
                (lambda key, default=None, _p=paper: getattr(_p, key, default))
            runs = get("default_runs")
            more = f" (default {runs} runs)" if runs else ""
            print(f"{get('name')}  {get('title', '') or ''}{more}".rstrip(), file=out)
        return EXIT_OK
    if args.name is None:
        raise _UsageError("reproduce needs a NAME (or --list)")
    progress = args.progress if args.progress is not None else \
        bool(getattr(sys.stderr, "isatty", lambda: False)())
    wanted = {"runs": args.runs, "workers": args.workers, "seed": args.seed,
              "out": args.out, "progress": progress}
    params = inspect.signature(mod.reproduce).parameters
    takes_any = any(p.kind is inspect.Parameter.VAR_KEYWORD for p in params.values())
    kwargs = {k: v for k, v in wanted.items()
              if v is not None and (takes_any or k in params)}
    result = mod.reproduce(args.name, **kwargs)
    where = args.out or (result.get("out") if isinstance(result, dict) else None)
    print(f"reproduced {args.name}" + (f": results in {where}" if where else ""), file=out)
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
        commands = {"solve": _cmd_solve, "solvers": _cmd_solvers, "models": _cmd_models,
                    "compare": _cmd_compare, "validate": _cmd_validate,
                    "export": _cmd_export, "generate": _cmd_generate,
                    "convert": _cmd_convert, "instances": _cmd_instances,
                    "reproduce": _cmd_reproduce}
        return commands[args.command](args, out, err)
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
        print("assocopt: interrupted", file=err)
        return EXIT_INTERRUPTED
    except Exception as exc:  # noqa: BLE001 - the CLI never shows a traceback
        _error(err, f"internal error ({type(exc).__name__}: {_one_line(str(exc))}); "
                    "this is a bug in assocopt or a back end, please report it")
        return EXIT_INTERNAL


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
