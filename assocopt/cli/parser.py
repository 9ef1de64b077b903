"""The argparse parser of ``assocopt``: every subcommand and its options.

Kept apart from the command implementations so that the option surface can be read (and
tested via :func:`_build_parser`) in one place; usage errors raise
:class:`~assocopt.cli.common._UsageError` instead of exiting.
"""

from __future__ import annotations

import argparse
from typing import Any, Sequence

from .common import _UsageError


class _Parser(argparse.ArgumentParser):
    def error(self, message: str) -> None:  # type: ignore[override]
        raise _UsageError(message)


def _build_parser() -> argparse.ArgumentParser:
    from ..io import FORMATS

    parser = _Parser(
        prog="assocopt",
        description="Data association / assignment problems as optimisation models.",
        epilog="exit codes: 0 solved, 1 infeasible, 2 bad input, 3 limit reached without "
               "a solution, 4 solver or internal error, 130 interrupted")
    from .._version import __version__
    parser.add_argument("--version", action="version", version=f"assocopt {__version__}")
    parser.add_argument("--max-bytes", type=_max_bytes, metavar="N", default=None,
                        help="largest instance file read, in bytes (default 1 GiB; also "
                             "the environment variable ASSOCOPT_MAX_BYTES)")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND")
    sub.required = True

    ps = sub.add_parser("solve", help="solve an instance file",
                        description="Solve an instance file (assocopt JSON, Grundel, "
                                    "Balas-Saltzman or OR-Library format).")
    ps.add_argument("file", metavar="FILE",
                    help="instance file, or the name of a stored instance (see "
                         "'assocopt instances')")
    ps.add_argument("--solver", type=_solver_name, default=None,
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
    ps.add_argument("--kbest", type=int, metavar="K", default=None,
                    help="the K best solutions, best first (Murty's ranking); "
                         "--solver must name an exact back end; not with --model, "
                         "--relax, --time-limit, --gap, --threads or --out")

    pl = sub.add_parser("solvers", help="list the back ends and their capabilities",
                        description="List every registered back end, installed or not.")
    pl.add_argument("--json", action="store_true", help="print JSON")
    pl.add_argument("--options", metavar="NAME", default=None,
                    help="print the options back end NAME takes ('all': every back end)")
    pl.add_argument("--markdown", action="store_true",
                    help="with --options all: print the page docs/solver-options.md")
    _add_more_parsers(sub, FORMATS)
    return parser


def _max_bytes(text: str) -> int:
    try:
        value = int(float(text))
    except (ValueError, OverflowError):
        raise argparse.ArgumentTypeError(f"expected a number of bytes, got {text!r}") from None
    if value < 1:
        raise argparse.ArgumentTypeError(f"must be a positive number of bytes, got {text!r}")
    return value


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
    parts = [t.strip() for t in text.split(",")]
    if not any(parts):
        raise argparse.ArgumentTypeError("expected comma-separated names")
    if not all(parts):
        raise argparse.ArgumentTypeError(f"empty name in {text!r}")
    return parts


def _solver_name(text: str) -> str:
    """A back end name: an empty one is an error, not a silent ``auto``."""
    if not text.strip():
        raise argparse.ArgumentTypeError("empty solver name (give a name from "
                                         "'assocopt solvers', or auto)")
    return text.strip()


def _add_input_args(p: argparse.ArgumentParser, formats: Sequence[str]) -> None:
    p.add_argument("--format", choices=list(formats), default="auto",
                   help="instance file format (default: detected from the content)")
    p.add_argument("--instance", metavar="I", default=None,
                   help="instance in a multi-instance file: N20_P5, 20,5 or a 1-based position")


def _add_prove_args(p: argparse.ArgumentParser) -> None:
    """``--prove`` and its ``--time-limit`` (``generate`` and ``convert``)."""
    p.add_argument("--prove", action="store_true",
                   help="prove the optimum with HiGHS and record it")
    p.add_argument("--time-limit", type=float, metavar="S", default=None,
                   help="seconds for --prove")


def _add_more_parsers(sub: Any, formats: Sequence[str]) -> None:
    from ..io.convert import CONVERT_FORMATS
    from ..workflow.generate import GENERATORS

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
    _add_prove_args(pg)

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
    _add_prove_args(pk)

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
    pr.add_argument("--scheduler", default=None, metavar="ADDRESS",
                    help="run the trials on a dask.distributed cluster (e.g. "
                         "tcp://10.0.0.5:8786; needs pip install 'assocopt[distributed]')")
    pr.add_argument("--seed", type=int, default=None, metavar="S", help="random seed")
    pr.add_argument("--out", default=None, metavar="DIR", help="output folder")
    pr.add_argument("--progress", action=argparse.BooleanOptionalAction, default=None,
                    help="progress bar on stderr (default: when stderr is a terminal)")

