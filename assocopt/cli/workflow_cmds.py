"""The instance / model workflow subcommands: ``export``, ``generate``, ``convert``,
``instances``, ``models`` and ``reproduce``.

Each ``_cmd_*`` takes the parsed arguments and the output / error streams and returns an
exit code; library modules (and the optional :mod:`assocopt.reproduce`) are imported inside
the functions, as before the split.
"""

from __future__ import annotations

import argparse
import functools
import json
import sys
from pathlib import Path
from typing import Any, Sequence, TextIO

from ..runtime.errors import AssocoptError
from .common import EXIT_OK, _instance_path, _num, _one_line, _table, _UsageError


def _cmd_models(args: argparse.Namespace, out: TextIO, err: TextIO) -> int:
    from ..workflow.models import list_models

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


def _cmd_export(args: argparse.Namespace, out: TextIO, err: TextIO) -> int:
    from ..io.mps_lp import export_model
    from ..io import read_instance

    problem = read_instance(_instance_path(args.file), format=args.format,
                            instance=args.instance)
    info = export_model(problem, args.to, relax=args.relax, names=not args.no_names)
    what = "LP relaxation" if args.relax else "ILP"
    print(f"wrote {info['path']}: {what} of {problem.name}, {info['columns']} "
          f"{'continuous' if args.relax else 'binary'} variables, {info['rows']} equality "
          f"rows ({info['format'].upper()} format)", file=out)
    return EXIT_OK


def _cmd_generate(args: argparse.Namespace, out: TextIO, err: TextIO) -> int:
    from ..workflow.generate import generate, prove_optimum
    from ..io import write_instance

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
    from ..workflow.generate import prove_optimum
    from ..io.convert import convert

    prove = functools.partial(prove_optimum, time_limit=args.time_limit) if args.prove \
        else None
    info = convert(_instance_path(args.src), args.dst, from_format=args.format,
                   to_format=args.to_format,
                   instance=args.instance, prove=prove)
    opt = "" if info["optimum"] is None else f"; optimum {_num(info['optimum'])}"
    print(f"wrote {', '.join(info['written'])} ({info['format']} format): {info['name']}, "
          f"sizes {'x'.join(map(str, info['sizes']))}{opt}", file=out)
    return EXIT_OK


def _cmd_instances(args: argparse.Namespace, out: TextIO, err: TextIO) -> int:
    from ..workflow.generate import catalogue, default_instances_dir, write_index

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


#: Seconds to wait for a dask scheduler to answer.
SCHEDULER_TIMEOUT = 20.0


def _dask_client(address: str) -> Any:
    """A ``dask.distributed.Client`` connected to ``address``, or a clear error."""
    try:
        from distributed import Client
    except ImportError:
        raise AssocoptError("--scheduler needs dask.distributed: pip install "
                            "'assocopt[distributed]'") from None
    try:
        return Client(address, timeout=SCHEDULER_TIMEOUT, set_as_default=False)
    except (OSError, TimeoutError, ValueError) as exc:
        raise AssocoptError(f"cannot connect to the dask scheduler {address!r}: "
                            f"{_one_line(str(exc))}") from None


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
    if args.scheduler is not None:
        if args.workers is not None:
            raise AssocoptError("give --workers or --scheduler, not both (the cluster's "
                                "workers run the trials)")
        with _dask_client(args.scheduler) as client:
            result = mod.reproduce(args.name, executor=client, **kwargs)
    else:
        result = mod.reproduce(args.name, **kwargs)
    where = args.out or (result.get("out") if isinstance(result, dict) else None)
    print(f"reproduced {args.name}" + (f": results in {where}" if where else ""), file=out)
    return EXIT_OK

