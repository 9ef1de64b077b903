"""Reader of the OR-Library linear assignment format (``assign100.txt`` ...).

``n``, then ``n*n`` costs row by row; the recorded optimum comes from a sibling
``assignopt.txt`` table.
"""

from __future__ import annotations

from pathlib import Path

from ..problems.problem import AssignmentProblem
from .common import (TextFile, _count_error, _dense, _fail, _header_int, _listed_optimum,
                     _numbers)


def _read_orlib(path: Path, text: str | TextFile) -> AssignmentProblem:
    src = TextFile.of(text)
    text, tokens = src.text, src.tokens
    n = _header_int(path, tokens[0], "n (the first number)")
    if n < 1:
        raise _fail(path, f"OR-Library format: n = {n} must be positive")
    if len(tokens) - 1 != n * n:
        raise _count_error(path, n * n, len(tokens) - 1, f"OR-Library {n}x{n} instance")
    values = _numbers(path, text, tokens[1:], 1)
    optimum, source = _orlib_optimum(path)
    meta = {"optimum_source": source} if source else {}
    return _dense(path, values, (n, n), path.stem, optimum, "orlib", **meta)


def _orlib_optimum(path: Path) -> tuple[float | None, str | None]:
    try:
        listed = _listed_optimum(path.parent / "assignopt.txt", path.stem)
    except OSError:
        listed = None
    return (listed, "assignopt.txt") if listed is not None else (None, None)
