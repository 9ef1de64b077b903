"""The solving subcommands: ``solve``, ``solvers``, ``compare`` and ``validate``.

Each ``_cmd_*`` takes the parsed arguments and the output / error streams and returns an
exit code; library modules are imported inside the functions (as before the split) so that
``assocopt --help`` stays fast and tests can patch e.g. ``assocopt.solving.api.solve``.
"""

from __future__ import annotations

import argparse
import io
import json
from pathlib import Path
from typing import Any, TextIO

from ..runtime.errors import AssocoptError
from .common import (EXIT_BAD_INPUT, EXIT_INFEASIBLE, EXIT_INTERNAL, EXIT_LIMIT, EXIT_OK, _error, _human,
                     _matches, _num, _instance_path,
                     _one_line, _os_message, _solve_record, _table, exit_code)
from .one_shot import one_shot


def _compile_note(problem: Any, solver: str, relax: str | None, err: TextIO) -> bool:
    """Start a line on stderr before ``bnb``'s numba kernels are compiled (first run
    only); :func:`_compile_done` ends it with the time taken.  True if begun."""
    from ..solving.api import choose_solver
    from ..solvers import get_backend

    name = choose_solver(problem, relax) if solver == "auto" else solver
    if relax is not None or name != "bnb" or not get_backend("bnb").is_available():
        return False
    if not _will_compile("driver.solve", problem.n_candidates):
        return False
    from ..solvers.bnb import kernels as bnb_kernels
    if bnb_kernels.cached():
        return False
    return _say_compiling(err)


def _will_compile(kernel: str, work: float) -> bool:
    """Whether the kernel would be compiled rather than run interpreted (a small
    problem in a fresh process: :mod:`assocopt.solvers.kernels.tiers`)."""
    from ..solvers.kernels import tiers
    return not tiers.interpret(kernel, work, lambda: False)


def _kbest_note(problem: Any, solver: str, err: TextIO, k: int = 1) -> bool:
    """:func:`_compile_note` for the compiled 2-D ranking of ``--kbest``."""
    from ..ranking import kbest2d

    if problem.ndim != 2 or solver not in ("auto", kbest2d.NAME) or not kbest2d.available():
        return False
    n1, n2 = problem.sizes
    if not _will_compile("murty2d.murty", k * n1 * (n1 + n2)):
        return False
    from ..solvers.bnb import kernels as bnb_kernels
    from ..solvers.kernels.murty2d import murty
    if bnb_kernels.cached(murty):
        return False
    return _say_compiling(err)


def _say_compiling(err: TextIO) -> bool:
    """Start the compile note, and tell the kernels it is given (else the API says it
    again)."""
    from ..solvers.kernels import announced

    print("assocopt: compiling the numba kernels (first run only, about 15-30 s; "
          "cached afterwards) ...", end="", file=err, flush=True)
    announced(now=True)
    return True


def _compile_done(sol: Any, begun: bool, err: TextIO) -> None:
    """One line on stderr with the compilation time, when the solve compiled kernels."""
    if sol is None:              # the solve raised: end the begun line, say no more
        if begun:
            print(file=err)
        return
    took = sol.times.get("compile", 0.0)
    if begun:
        print(f" done in {took:.1f} s" if took > 0 else " not needed (already compiled)",
              file=err)
    elif took > 0:
        print(f"assocopt: compiled the numba kernels in {took:.1f} s (first run only; "
              "cached afterwards)", file=err)


def _cmd_kbest(args: argparse.Namespace, out: TextIO, err: TextIO) -> int:
    """``solve --kbest K``: the K best solutions, as a table or one JSON object."""
    from ..io import read_instance
    from ..ranking.kbest import kbest

    for flag in ("model", "relax", "out", "time_limit", "gap", "threads"):
        if getattr(args, flag, None) is not None:
            raise AssocoptError(f"--kbest does not combine with --{flag.replace('_', '-')}")
    if args.kbest < 1:
        raise AssocoptError(f"--kbest must be a positive integer, got {args.kbest}")
    problem = read_instance(_instance_path(args.file), format=args.format,
                            instance=args.instance)
    solver = args.solver or "auto"
    begun = _compile_note(problem, solver, None, err) or \
        _kbest_note(problem, solver, err, args.kbest)
    ranked = None
    try:
        ranked = kbest(problem, args.kbest, solver)
    finally:
        _compile_done(ranked, begun, err)
    if args.json:
        rec = {"instance": problem.name, "sizes": list(problem.sizes), **ranked.to_dict()}
        print(json.dumps(rec, allow_nan=False), file=out)
    else:
        note = " (all feasible solutions)" if ranked.exhausted else ""
        print(f"instance   {problem.name}  (sizes {' x '.join(map(str, problem.sizes))})",
              file=out)
        print(f"kbest      {len(ranked)} of {ranked.k} requested{note}, solver "
              f"{ranked.solver}, {ranked.subproblems} subproblems, "
              f"{ranked.times['total']:.3g} s", file=out)
        for s in ranked:
            tup = " ".join("(" + ",".join(map(str, t)) + ")" for t in s.tuples.tolist())
            print(f"{s.info['rank']:>4}  {_num(s.objective):>14}  {tup}", file=out)
    return EXIT_OK if len(ranked) else 1
def _check_options(time_limit: Any = None, mip_gap: Any = None, threads: Any = None) -> None:
    """Validate the common solve options before any file is read or row is run: every
    bad value is one ``assocopt: error:`` line and exit 2, for solve and compare alike."""
    from ..solvers.options import check_common

    try:
        check_common(time_limit, 0.0 if mip_gap is None else mip_gap, threads, False)
    except AssocoptError:
        raise
    except ValueError as exc:
        raise AssocoptError(str(exc)) from None


def _cmd_solve(args: argparse.Namespace, out: TextIO, err: TextIO) -> int:
    from ..solving.api import solve
    from ..io import read_instance, write_solution

    if getattr(args, "kbest", None) is not None:
        return _cmd_kbest(args, out, err)
    _check_options(args.time_limit, args.gap, args.threads)

    if args.model is not None:
        from ..workflow.models import load_model

        if args.solver is not None:
            raise AssocoptError("give --solver or --model, not both")
        model = load_model(args.model)
        if args.relax is not None and args.relax != model.relax:
            raise AssocoptError(f"--relax {args.relax} conflicts with model {model.name!r} "
                                f"(formulation {model.formulation!r})")
        problem = read_instance(_instance_path(args.file), format=args.format,
                                instance=args.instance)
        begun, sol = _compile_note(problem, model.solver, model.relax, err), None
        try:
            sol = model.solve(problem, time_limit=args.time_limit, mip_gap=args.gap,
                              threads=args.threads)
        finally:
            _compile_done(sol, begun, err)
    else:
        problem = read_instance(_instance_path(args.file), format=args.format,
                                instance=args.instance)
        sol = None
        if args.solver is None and args.time_limit is None and not args.gap:
            sol = one_shot(problem, args.relax)
        if sol is None:
            begun = _compile_note(problem, args.solver or "auto", args.relax, err)
            try:
                sol = solve(problem, args.solver or "auto", relax=args.relax,
                            time_limit=args.time_limit,
                            mip_gap=0.0 if args.gap is None else args.gap,
                            threads=args.threads)
            finally:
                _compile_done(sol, begun, err)
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
    elif code == EXIT_INFEASIBLE:
        why = _one_line(sol.message) or "no assignment covers every real index once"
        if not why.startswith("infeasible"):
            why = f"infeasible ({why})"
        print(f"assocopt: {args.file}: {why}", file=err)
    elif code == EXIT_LIMIT:
        print("assocopt: error: stopped by a limit before any solution was found", file=err)
    return code


def _solver_rows() -> list[dict[str, Any]]:
    from ..solvers import registered

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


def _option_rows(name: str) -> dict[str, Any]:
    from ..solvers import get_backend

    cls = get_backend(name)
    return {"name": cls.name, "native_options": cls.native_options or None,
            "options": [{"name": o.name, "kind": o.kind, "accepts": o.describe(),
                         "default": o.default, "description": o.doc}
                        for o in cls.options]}


def _cmd_options(args: argparse.Namespace, out: TextIO) -> int:
    """``assocopt solvers --options NAME``: the declared options, as a table."""
    from ..solvers import registered
    from ..solvers.base import options_page
    from ..solvers.options import COMMON_NAMES, options_table

    if args.markdown:
        if args.options != "all":
            raise AssocoptError("--markdown prints the page of every back end: "
                                "use --options all --markdown")
        print(options_page(), end="", file=out)
        return EXIT_OK
    names = sorted(registered()) if args.options == "all" else [args.options]
    docs = [_option_rows(n) for n in names]
    if args.json:
        print(json.dumps(docs if args.options == "all" else docs[0], indent=2), file=out)
        return EXIT_OK
    for i, name in enumerate(names):
        cls = registered()[name]
        if i:
            print(file=out)
        print(f"options of solver {name!r} (besides the common "
              f"{', '.join(COMMON_NAMES)}):", file=out)
        rows = options_table(cls)
        if rows:
            _table([("option", "accepts", "default", "description"), *rows], out)
        else:
            print("  none of its own", file=out)
        if cls.native_options:
            print(f"also: {cls.native_options}", file=out)
    return EXIT_OK


def _cmd_solvers(args: argparse.Namespace, out: TextIO, err: TextIO) -> int:
    if args.options is not None or args.markdown:
        if args.options is None:
            raise AssocoptError("--markdown needs --options all")
        return _cmd_options(args, out)
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


def _cmd_compare(args: argparse.Namespace, out: TextIO, err: TextIO) -> int:
    from ..workflow.compare import compare

    _check_options(args.time_limit)
    res = compare([_instance_path(f) for f in args.files], solvers=args.solvers,
                  models=args.models,
                  time_limit=args.time_limit, relax=args.relax, repeat=args.repeat,
                  format=args.format, instance=args.instance, progress=args.progress)
    fmt = "json" if args.json else "csv" if args.csv else "text"
    if args.out:
        from ..io import write_text_atomically
        buf = io.StringIO()
        res.write(buf, fmt)
        write_text_atomically(Path(args.out), buf.getvalue())
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
    from ..workflow.generate import feasibility, prove_optimum
    from ..io import read_instance

    rec: dict[str, Any] = {"file": path, "ok": False}
    try:
        p = read_instance(_instance_path(path), format=args.format, instance=args.instance)
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

