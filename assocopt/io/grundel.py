"""Reader of the DecompLib / Grundel generator format (``ap3.<n>.<s>.txt``).

Line 1 ``d``, line 2 the ``d`` sizes, then the costs with the last index varying
fastest; the recorded optimum comes from a sibling ``ap3.<n>.<s>.sol`` (``OPT:``
line) or an ``ap3.opt`` table.  :data:`_MAX_D` is shared with :mod:`.detect`.
"""

from __future__ import annotations

import math
import re
from pathlib import Path

from ..problems.problem import AssignmentProblem
from .common import (_NUMBER, TextFile, _count_error, _dense, _fail, _header_int,
                     _listed_optimum, _numbers)

#: Largest dimension count accepted in a Grundel header.
_MAX_D = 16


def _read_grundel(path: Path, text: str | TextFile) -> AssignmentProblem:
    src = TextFile.of(text)
    text = src.text
    lines = src.layout.head
    if len(lines) < 2:
        raise _fail(path, "Grundel format needs a line 'd' and a line with the d sizes")
    if len(lines[0]) != 1:
        raise _fail(path, f"Grundel format: line 1 must hold only d, found {' '.join(lines[0][:5])!r}")
    d = _header_int(path, lines[0][0], "d (line 1)")
    if not 2 <= d <= _MAX_D:
        raise _fail(path, f"Grundel format: d = {d} on line 1 is not in 2..{_MAX_D}")
    tokens = src.tokens
    if len(tokens) < 1 + d:
        raise _fail(path, f"Grundel format: line 2 must give {d} sizes")
    sizes = tuple(_header_int(path, t, "a size (line 2)") for t in tokens[1:1 + d])
    if any(n < 1 for n in sizes):
        raise _fail(path, f"Grundel format: sizes must be positive, found {list(sizes)}")
    expected = math.prod(sizes)
    cost_tokens = tokens[1 + d:]
    if len(cost_tokens) != expected:
        raise _count_error(path, expected, len(cost_tokens),
                           f"Grundel {'x'.join(map(str, sizes))} instance")
    values = _numbers(path, text, cost_tokens, 1 + d)
    optimum, source = _grundel_optimum(path)
    meta = {"optimum_source": source} if source else {}
    return _dense(path, values, sizes, path.stem, optimum, "grundel", **meta)


def _grundel_optimum(path: Path) -> tuple[float | None, str | None]:
    sol = path.with_suffix(".sol")
    try:
        if sol.is_file():
            for line in sol.read_text(encoding="utf-8", errors="replace").splitlines():
                if line.strip():
                    m = re.match(r"^\s*OPT\s*:\s*(\S+)\s*$", line)
                    if m and _NUMBER.match(m.group(1)):
                        return float(m.group(1)), f"{sol.name} (OPT line)"
                    break
        listed = _listed_optimum(path.parent / "ap3.opt", path.stem)
        if listed is not None:
            return listed, "ap3.opt"
    except OSError:
        pass
    return None, None
