"""Convert an instance between formats: read any supported one, write any writable one."""

from __future__ import annotations

import math
import os
import re
from pathlib import Path
from typing import Any, Callable

from ..runtime.errors import AssocoptError
from ..problems.problem import AssignmentProblem
from .public_writers import PUBLIC_WRITERS, write_public

__all__ = ["CONVERT_FORMATS", "convert", "output_format"]

#: Formats :func:`convert` writes (the project's JSON first).
CONVERT_FORMATS = ("assocopt",) + PUBLIC_WRITERS


def output_format(path: str | os.PathLike[str]) -> str | None:
    """The format :func:`convert` infers from an output file name (None: cannot tell)."""
    name = Path(path).name.lower()
    if name.endswith(".json"):
        return "assocopt"
    if re.match(r"^ap3\..*\.txt$", name):
        return "grundel"
    if re.match(r"^assign.*\.txt$", name):
        return "orlib"
    if name.startswith("balas"):
        return "balas-saltzman-split"
    return None


def convert(src: str | os.PathLike[str], dst: str | os.PathLike[str], *,
            from_format: str = "auto", to_format: str | None = None, instance: Any = None,
            prove: Callable[[AssignmentProblem], tuple[float, str]] | None = None
            ) -> dict[str, Any]:
    """Read ``src`` in any supported format and write ``dst``.

    ``to_format`` defaults to the one :func:`output_format` infers from ``dst``.
    Converting to JSON keeps the recorded optimum and its source and adds a
    description naming the source file.  ``prove``, when given, proves the optimum of
    the problem read and returns it with how it was proven (``assocopt convert
    --prove`` passes :func:`assocopt.workflow.generate.prove_optimum`, HiGHS); the result is
    checked against a recorded optimum and recorded.  Returns a summary.
    """
    from .detect import read_instance
    from .writers import write_instance

    fmt = to_format or output_format(dst)
    if fmt is None:
        raise AssocoptError(f"{dst}: cannot tell the output format from the name; pass "
                            f"--to-format ({', '.join(CONVERT_FORMATS)})")
    if fmt not in CONVERT_FORMATS:
        raise AssocoptError(f"unknown output format {fmt!r}; valid: {', '.join(CONVERT_FORMATS)}")
    problem = read_instance(src, format=from_format, instance=instance)
    optimum = problem.optimum
    source = problem.meta.get("optimum_source")
    if prove is not None:
        proven, how = prove(problem)
        if optimum is not None and not math.isclose(proven, optimum, rel_tol=1e-9,
                                                    abs_tol=1e-9):
            raise AssocoptError(f"{src}: recorded optimum {optimum:g} but {how} gives "
                                f"{proven:g}")
        source = how if optimum is None else f"{source or 'recorded'}; re-{how}"
        optimum = proven
    if fmt == "assocopt":
        read_fmt = problem.meta.get("format", from_format)
        label = f" ({problem.meta['instance']})" if "instance" in problem.meta else ""
        desc = problem.meta.get("description") or \
            f"converted from {Path(src).name}{label} ({read_fmt} format) by assocopt convert"
        write_instance(problem, dst, optimum=optimum,
                       optimum_source=source if optimum is not None else None,
                       description=desc)
        written = [Path(dst)]
    else:
        if optimum is not None and optimum != problem.optimum:
            problem = AssignmentProblem.dense(problem.to_cost_matrix(), name=problem.name,
                                              optimum=optimum) \
                if problem.kind == "dense" else problem
        written = write_public(problem, dst, fmt)
    return {"source": str(src), "written": [str(p) for p in written], "format": fmt,
            "name": problem.name, "sizes": list(problem.sizes), "optimum": optimum,
            "optimum_source": source if optimum is not None else None}
