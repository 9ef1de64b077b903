"""Reader of the OR-Library linear assignment format (``assign100.txt`` ...).

``n``, then ``n*n`` costs row by row; the recorded optimum comes from a sibling
``assignopt.txt`` table.
"""

from __future__ import annotations

from pathlib import Path

from ..problem import AssignmentProblem
from .common import _NUMBER, _count_error, _dense, _fail, _header_int, _numbers


def _read_orlib(path: Path, text: str) -> AssignmentProblem:
    tokens = text.split()
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
    table = path.parent / "assignopt.txt"
    try:
        if table.is_file():
            for line in table.read_text(encoding="utf-8", errors="replace").splitlines():
                parts = line.split()
                if len(parts) == 2 and parts[0] == path.stem and _NUMBER.match(parts[1]):
                    return float(parts[1]), "assignopt.txt"
    except OSError:
        pass
    return None, None
