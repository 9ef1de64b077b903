"""Reading and writing instance files, and writing solutions.

:func:`read_instance` reads the project's own JSON format (``"assocopt"``, see
``docs/instance-format.md``) and four public benchmark formats, detected from the
file's content:

``"grundel"``
    DecompLib / Grundel generator ``ap3.<n>.<s>.txt``: line 1 ``d``, line 2 the
    ``d`` sizes, then the costs with the last index varying fastest.  A sibling
    ``ap3.<n>.<s>.sol`` whose first non-empty line is ``OPT: <value>`` (or an
    ``ap3.opt`` table) gives the recorded optimum.
``"balas-saltzman"``
    The original multi-instance "AP3 Test Driver" file of Balas & Saltzman (1991):
    blocks ``N = n   PROBLEM = p`` / a line of ``=`` / ``n**3`` costs.  Pick one
    with ``instance="N20_P5"``, ``instance=(20, 5)`` or a 1-based position.
``"balas-saltzman-split"``
    One such instance per file: ``n**3`` costs, optionally after a ``3 n`` header.
``"orlib"``
    OR-Library linear assignment (``assign100.txt`` ...): ``n``, then ``n*n``
    costs row by row.  A sibling ``assignopt.txt`` gives the recorded optimum.

Public-format costs are integers; they are stored as float64.  Every problem in a
public file is a dense (axial) minimisation problem: :meth:`AssignmentProblem.dense`.

Every malformed file raises :class:`~assocopt.errors.InstanceFormatError` with the
file name and what is wrong in the message.
"""

from __future__ import annotations

import json
import math
import os
import re
import tempfile
from pathlib import Path
from typing import Any, Iterable

import numpy as np

from .errors import InstanceFormatError, InvalidProblemError
from .problem import AssignmentProblem
from .solution import Solution

__all__ = ["read_instance", "write_instance", "write_solution", "detect_format",
           "instance_to_json", "solution_to_dict", "FORMATS", "FORMAT_NAME",
           "FORMAT_VERSION"]

#: Value of the ``"format"`` key of the project's JSON instance files.
FORMAT_NAME = "assocopt-instance"
#: Newest version of the JSON instance format this module reads and writes.
FORMAT_VERSION = 1
#: Accepted values of ``read_instance(..., format=...)``.
FORMATS = ("auto", "assocopt", "grundel", "balas-saltzman", "balas-saltzman-split", "orlib")

_COMMON_KEYS = {"format", "version", "kind", "name", "optimum", "optimum_source",
                "description"}
_KIND_KEYS = {"dense": ({"costs"}, {"row_miss", "col_miss"}),
              "sparse": ({"sizes", "tuples", "costs"}, set())}

_BS_BLOCK = re.compile(r"^[ \t]*N[ \t]*=[ \t]*(\d+)[ \t]+PROBLEM[ \t]*=[ \t]*(\d+)[ \t]*\r?\n"
                       r"[ \t]*=+[ \t]*\r?$", re.MULTILINE)
_BS_INSTANCE = re.compile(r"^\s*N\s*(\d+)\s*[_\-\s,:]?\s*P(?:ROBLEM)?\s*(\d+)\s*$", re.I)
_PAIR = re.compile(r"^\s*\(?\s*(\d+)\s*[,:/ ]\s*(\d+)\s*\)?\s*$")
_NUMBER = re.compile(r"^[+-]?(\d+\.?\d*|\.\d+)([eE][+-]?\d+)?$")
_INTEGER = re.compile(r"^[+-]?\d+$")

#: Largest dimension count accepted in a Grundel header.
_MAX_D = 16


# =============================================================== reading: helpers
def _fail(path: Path, message: str) -> InstanceFormatError:
    return InstanceFormatError(f"{path}: {message}")


def _read_text(path: Path) -> str:
    with open(path, "rb") as f:
        data = f.read()
    if b"\x00" in data[:4096]:
        raise _fail(path, "not a text file (contains NUL bytes)")
    try:
        text = data.decode("utf-8-sig")
    except UnicodeDecodeError as exc:
        raise _fail(path, f"not a UTF-8 text file (byte {exc.start}: {exc.reason})") from None
    if not text.strip():
        raise _fail(path, "the file is empty")
    return text


def _lines(text: str) -> list[list[str]]:
    """Token lists of the non-blank lines."""
    return [ln.split() for ln in text.splitlines() if ln.strip()]


def _locate_token(text: str, k: int) -> int:
    """1-based line number of the k-th (0-based) whitespace-separated token."""
    seen = 0
    for lineno, line in enumerate(text.splitlines(), 1):
        n = len(line.split())
        if seen + n > k:
            return lineno
        seen += n
    return -1


def _numbers(path: Path, text: str, tokens: list[str], start_token: int = 0) -> np.ndarray:
    """Parse cost tokens as float64, naming the first bad token and its line.

    ``start_token`` is the position of ``tokens[0]`` in the whole file (for the line
    number in messages).  Integers and decimal numbers are accepted; ``nan``/``inf``
    spelled out are not numbers here.
    """
    try:
        values = np.array(tokens, dtype=np.str_).astype(np.float64)
        ok = bool(np.isfinite(values).all())
    except ValueError:
        ok = False
    if ok:
        return values
    for k, tok in enumerate(tokens):
        if not _NUMBER.match(tok):
            line = _locate_token(text, start_token + k)
            raise _fail(path, f"non-numeric token {tok!r} on line {line}")
    raise _fail(path, "costs could not be parsed as numbers")  # pragma: no cover


def _first_non_number(tokens: list[str]) -> int | None:
    """Position of the first token that is not a plain (finite) number, or None."""
    try:
        if np.isfinite(np.array(tokens, dtype=np.str_).astype(np.float64)).all():
            return None
    except ValueError:
        pass
    return next((k for k, t in enumerate(tokens) if not _NUMBER.match(t)), None)


def _header_int(path: Path, tok: str, what: str) -> int:
    if not _INTEGER.match(tok):
        raise _fail(path, f"{what} must be an integer, found {tok!r}")
    return int(tok)


def _dense(path: Path, values: np.ndarray, shape: tuple[int, ...], name: str,
           optimum: float | None, fmt: str, **meta: Any) -> AssignmentProblem:
    try:
        p = AssignmentProblem.dense(values.reshape(shape), name=name, optimum=optimum)
    except InvalidProblemError as exc:
        raise _fail(path, str(exc)) from exc
    p.meta.update({"format": fmt, "path": str(path), **meta})
    return p


def _count_error(path: Path, expected: int, found: int, what: str = "") -> InstanceFormatError:
    where = f"{what}: " if what else ""
    more = "truncated file?" if found < expected else "extra numbers at the end?"
    return _fail(path, f"{where}expected {expected} costs, found {found} ({more})")


def _cube_root(m: int) -> int | None:
    if m <= 0:
        return None
    r = int(round(m ** (1.0 / 3.0)))
    for c in (r - 1, r, r + 1):
        if c > 0 and c ** 3 == m:
            return c
    return None


# =============================================================== public formats
def _read_grundel(path: Path, text: str) -> AssignmentProblem:
    lines = _lines(text)
    if len(lines) < 2:
        raise _fail(path, "Grundel format needs a line 'd' and a line with the d sizes")
    if len(lines[0]) != 1:
        raise _fail(path, f"Grundel format: line 1 must hold only d, found {' '.join(lines[0][:5])!r}")
    d = _header_int(path, lines[0][0], "d (line 1)")
    if not 2 <= d <= _MAX_D:
        raise _fail(path, f"Grundel format: d = {d} on line 1 is not in 2..{_MAX_D}")
    tokens = text.split()
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
        table = path.parent / "ap3.opt"
        if table.is_file():
            for line in table.read_text(encoding="utf-8", errors="replace").splitlines():
                parts = line.split()
                if len(parts) == 2 and parts[0] == path.stem and _NUMBER.match(parts[1]):
                    return float(parts[1]), "ap3.opt"
    except OSError:
        pass
    return None, None


def _bs_blocks(text: str) -> list[tuple[int, int, int, int]]:
    """``(n, p, start, end)`` of each block's cost text in the driver file."""
    marks = list(_BS_BLOCK.finditer(text))
    out = []
    for k, m in enumerate(marks):
        end = marks[k + 1].start() if k + 1 < len(marks) else len(text)
        out.append((int(m.group(1)), int(m.group(2)), m.end(), end))
    return out


def _parse_bs_instance(instance: Any, blocks: list[tuple[int, int, int, int]],
                       path: Path) -> int:
    """Position in ``blocks`` of the requested instance."""
    count = len(blocks)
    labels = [f"N{n}_P{p}" for n, p, _, _ in blocks]
    hint = (f"the file holds {count} instances ({labels[0]} .. {labels[-1]}); choose one "
            f"as 'N<n>_P<p>' (e.g. {labels[-1]!r}), an (N, PROBLEM) pair such as "
            f"'{blocks[-1][0]},{blocks[-1][1]}', or a position 1..{count} "
            "(CLI: --instance)")
    if instance is None:
        raise _fail(path, f"no instance chosen: {hint}")
    pair: tuple[int, int] | None = None
    pos: int | None = None
    if isinstance(instance, bool):
        raise _fail(path, f"instance must not be a bool: {hint}")
    if isinstance(instance, (int, np.integer)):
        pos = int(instance)
    elif isinstance(instance, (tuple, list)) and len(instance) == 2:
        try:
            pair = (int(instance[0]), int(instance[1]))
        except (TypeError, ValueError):
            raise _fail(path, f"instance {instance!r} not understood: {hint}") from None
    elif isinstance(instance, str):
        s = instance.strip()
        if s.isdigit():
            pos = int(s)
        elif (m := _BS_INSTANCE.match(s)) or (m := _PAIR.match(s)):
            pair = (int(m.group(1)), int(m.group(2)))
        else:
            raise _fail(path, f"instance {instance!r} not understood: {hint}")
    else:
        raise _fail(path, f"instance {instance!r} not understood: {hint}")
    if pos is not None:
        if not 1 <= pos <= count:
            raise _fail(path, f"instance position {pos} out of range: {hint}")
        return pos - 1
    assert pair is not None
    for k, (n, p, _, _) in enumerate(blocks):
        if (n, p) == pair:
            return k
    raise _fail(path, f"no instance N{pair[0]}_P{pair[1]} in the file: {hint}")


def _read_bs_driver(path: Path, text: str, instance: Any) -> AssignmentProblem:
    blocks = _bs_blocks(text)
    if not blocks:
        raise _fail(path, "no 'N = n   PROBLEM = p' block followed by a line of '=' found "
                          "(expected the Balas-Saltzman 'AP3 Test Driver' format)")
    k = _parse_bs_instance(instance, blocks, path)
    n, p, start, end = blocks[k]
    label = f"N{n}_P{p}"
    tokens = text[start:end].split()
    if len(tokens) != n ** 3:
        raise _count_error(path, n ** 3, len(tokens), f"instance {label}")
    first_token = len(text[:start].split())
    values = _numbers(path, text, tokens, first_token)
    return _dense(path, values, (n, n, n), f"{path.stem}:{label}", None,
                  "balas-saltzman", instance=label)


def _read_bs_split(path: Path, text: str) -> AssignmentProblem:
    tokens = text.split()
    start = 0
    if _cube_root(len(tokens)) is None:
        # optional "3 n" header (d, n)
        if (len(tokens) >= 2 and tokens[0] == "3" and _INTEGER.match(tokens[1])
                and _lines(text)[0] == tokens[:2]):
            n = int(tokens[1])
            if len(tokens) - 2 != n ** 3:
                raise _count_error(path, n ** 3, len(tokens) - 2,
                                   f"header '3 {n}' announces a {n}x{n}x{n} instance")
            start = 2
        else:
            named = re.match(r"^balas(?:3D)?-n(\d+)-instance\d+$", path.stem, re.I)
            if named:
                n = int(named.group(1))
                raise _count_error(path, n ** 3, len(tokens),
                                   f"file name announces a {n}x{n}x{n} instance")
            lo = _cube_root_floor(len(tokens))
            raise _fail(path, f"expected n**3 costs (one instance of the Balas-Saltzman "
                              f"split format), found {len(tokens)}, which is not a cube "
                              f"(nearest: {lo ** 3} = {lo}**3, {(lo + 1) ** 3} = {lo + 1}**3)")
    n = _cube_root(len(tokens) - start)
    assert n is not None
    m = re.match(r"^balas(?:3D)?-n(\d+)-instance(\d+)$", path.stem, re.I)
    if m and int(m.group(1)) != n:
        raise _fail(path, f"file name says n = {int(m.group(1))} but the file holds "
                          f"{len(tokens) - start} = {n}**3 costs")
    values = _numbers(path, text, tokens[start:], start)
    meta = {"instance": f"N{int(m.group(1))}_P{int(m.group(2))}"} if m else {}
    return _dense(path, values, (n, n, n), path.stem, None, "balas-saltzman-split", **meta)


def _cube_root_floor(m: int) -> int:
    r = max(int(round(m ** (1.0 / 3.0))), 1)
    while r ** 3 > m and r > 1:
        r -= 1
    while (r + 1) ** 3 <= m:
        r += 1
    return r


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


# =============================================================== detection
def _looks_grundel(lines: list[list[str]]) -> bool:
    if len(lines) < 2 or len(lines[0]) != 1 or not _INTEGER.match(lines[0][0]):
        return False
    d = int(lines[0][0])
    return (2 <= d <= _MAX_D and len(lines[1]) == d
            and all(_INTEGER.match(t) and int(t) > 0 for t in lines[1]))


def _matches(text: str) -> tuple[dict[str, tuple[bool, int, bool]], str]:
    """Which public text formats fit the file.

    Returns ``{format: (count_fits, expected_count, strong)}`` for every format whose
    layout fits (``count_fits`` False: a damaged file of that format; ``strong``: the
    layout alone is distinctive), and a short description of what was seen.
    """
    tokens = text.split()
    lines = _lines(text)
    L = len(tokens)
    seen = (f"{len(lines)} non-blank lines, {L} numbers, first line "
            f"{' '.join(lines[0][:6])[:60]!r}")
    found: dict[str, tuple[bool, int, bool]] = {}
    # Grundel: "d" / "n1 .. nd" / costs; a square header "n n n" is distinctive
    if _looks_grundel(lines):
        d = int(lines[0][0])
        sizes = [int(t) for t in lines[1]]
        expected = math.prod(sizes)
        found["grundel"] = (L - 1 - d == expected, expected, len(set(sizes)) == 1)
    # Balas-Saltzman split: n^3 numbers (one per line), or a "3 n" header first
    one_per_line = all(len(ln) == 1 for ln in lines[1:])
    if one_per_line and len(lines[0]) == 2 and lines[0][0] == "3" \
            and _INTEGER.match(lines[0][1]):
        n = int(lines[0][1])
        found["balas-saltzman-split"] = (L - 2 == n ** 3, n ** 3, True)
    elif one_per_line and len(lines[0]) == 1:
        found["balas-saltzman-split"] = (_cube_root(L) is not None, L, False)
    # OR-Library: n alone on line 1, then n*n costs (several per line in practice)
    if len(lines[0]) == 1 and _INTEGER.match(lines[0][0]) and int(lines[0][0]) > 0:
        n = int(lines[0][0])
        exact = L - 1 == n * n
        if exact or not one_per_line or len(lines) < 3:
            found["orlib"] = (exact, n * n, False)
    if not found and _cube_root(L) is not None:
        # n**3 numbers laid out otherwise than one per line
        found["balas-saltzman-split"] = (True, L, False)
    return found, seen


def detect_format(path: str | os.PathLike[str], text: str | None = None) -> str:
    """The format name :func:`read_instance` would use for ``path`` with ``format="auto"``.

    Raises :class:`InstanceFormatError` when the content fits no format, or several.
    """
    path = Path(path)
    if text is None:
        text = _read_text(path)
    head = text.lstrip()
    if head.startswith(("{", "[")):
        return "assocopt"
    if _BS_BLOCK.search(text) or "AP3 Test Driver" in text[:2000]:
        return "balas-saltzman"
    found, seen = _matches(text)
    hint = _name_hint(path)
    exact = [f for f, (ok, _, _) in found.items() if ok]
    if len(exact) == 1:
        return exact[0]
    if len(exact) > 1:
        if hint in exact:
            return hint
        raise _fail(path, f"ambiguous format: the content fits {' and '.join(exact)} "
                          f"({seen}); pass format=... (CLI: --format)")
    # no count fits: a damaged file; let the reader of the right format say what is wrong
    strong = [f for f, (_, _, st) in found.items() if st]
    if len(strong) == 1:
        return strong[0]
    if len(found) == 1:
        return next(iter(found))
    if hint in found:
        return hint
    tokens = text.split()
    bad = _first_non_number(tokens)
    if bad is not None:
        raise _fail(path, f"unknown format: non-numeric token {tokens[bad][:40]!r} on line "
                          f"{_locate_token(text, bad)} (not JSON, not a Balas-Saltzman "
                          "driver file, and the numeric formats hold numbers only)")
    if found:
        fits = ", ".join(f"{f} (would need {_need(f, exp)})" for f, (_, exp, _) in found.items())
        raise _fail(path, f"cannot tell the format: the layout fits {fits} but the number "
                          f"count fits none ({seen}); truncated file? pass format=... "
                          "(CLI: --format) for a precise message")
    raise _fail(path, f"unknown format ({seen}): not assocopt JSON, Grundel "
                      "('d' / sizes / costs), Balas-Saltzman (n**3 costs), nor OR-Library "
                      "(n then n*n costs)")


def _need(fmt: str, expected: int) -> str:
    if fmt == "balas-saltzman-split":
        return "n**3 costs"
    return f"{expected} costs after the header"


def _name_hint(path: Path) -> str | None:
    name = path.name.lower()
    if re.match(r"^ap\d+\.\d+\.\d+\.txt$", name):
        return "grundel"
    if name.startswith("balas"):
        return "balas-saltzman-split"
    if re.match(r"^assign\d+\.txt$", name):
        return "orlib"
    return None


# =============================================================== JSON format
def _no_duplicates(pairs: list[tuple[str, Any]]) -> dict[str, Any]:
    out: dict[str, Any] = {}
    for k, v in pairs:
        if k in out:
            raise ValueError(f"duplicate key {k!r}")
        out[k] = v
    return out


_CONSTANTS = {"Infinity": math.inf, "-Infinity": -math.inf, "NaN": math.nan}


def _parse_constant(name: str) -> float:
    # Python's json writes Infinity/NaN; accept them here and reject NaN and -inf
    # where they are used, with their position.
    return _CONSTANTS[name]


def _cost_value(v: Any, where: str, path: Path) -> float:
    if isinstance(v, bool) or v is None:
        raise _fail(path, f"{where} must be a number or \"inf\", found {json.dumps(v)}")
    if isinstance(v, (int, float)):
        f = float(v)
        if math.isnan(f):
            raise _fail(path, f"{where} is NaN")
        if f == -math.inf:
            raise _fail(path, f"{where} is -inf (only +inf, \"inf\", is allowed: forbidden)")
        return f
    if isinstance(v, str):
        if v.strip().lower() in ("inf", "+inf", "infinity", "+infinity"):
            return math.inf
        raise _fail(path, f"{where} must be a number or \"inf\", found the string {v!r}")
    raise _fail(path, f"{where} must be a number or \"inf\", found {type(v).__name__}")


def _cost_array(v: Any, where: str, path: Path, min_ndim: int = 0) -> np.ndarray:
    """Nested lists of costs -> float64 array, naming the position of any bad entry."""
    shape: list[int] = []
    node = v
    while isinstance(node, list):
        shape.append(len(node))
        if not node:
            break
        node = node[0]
    if len(shape) < min_ndim:
        raise _fail(path, f"{where} must be a nested list of at least {min_ndim} levels "
                          f"(one per axis), found {len(shape)} level(s)")
    if not shape:
        return np.array(_cost_value(v, where, path), dtype=np.float64)

    def here(idx: list[int]) -> str:
        return where + "".join(f"[{i}]" for i in idx)

    flat: list[Any] = []
    last = len(shape) - 1

    def walk(node: Any, depth: int, idx: list[int]) -> None:
        if not isinstance(node, list):
            raise _fail(path, f"ragged {where}: {here(idx)} is a single value, expected a "
                              f"list of {shape[depth]} (shape {shape})")
        if len(node) != shape[depth]:
            raise _fail(path, f"ragged {where}: {here(idx)} has {len(node)} entries, "
                              f"expected {shape[depth]} like the first one (shape {shape})")
        if depth < last:
            for i, item in enumerate(node):
                walk(item, depth + 1, idx + [i])
            return
        for i, x in enumerate(node):
            t = type(x)
            if t is int or t is float:
                flat.append(x)
            elif isinstance(x, list):
                raise _fail(path, f"ragged {where}: {here(idx + [i])} is a list, expected a "
                                  f"cost (shape {shape})")
            else:
                flat.append(_cost_value(x, here(idx + [i]), path))

    walk(v, 0, [])
    arr = np.array(flat, dtype=np.float64).reshape(shape)
    bad = np.isnan(arr) | np.isneginf(arr)
    if bad.any():
        first = [int(i) for i in np.argwhere(bad)[0]]
        _cost_value(float(arr[tuple(first)]), here(first), path)   # raises with the position
    return arr


def _int_list(v: Any, where: str, path: Path) -> list[int]:
    if not isinstance(v, list):
        raise _fail(path, f"{where} must be a list of integers, found {type(v).__name__}")
    out = []
    for i, x in enumerate(v):
        if isinstance(x, bool) or not isinstance(x, int):
            if isinstance(x, float) and x.is_integer():
                x = int(x)
            else:
                raise _fail(path, f"{where}[{i}] must be an integer, found {json.dumps(x)}")
        out.append(x)
    return out


def _read_json(path: Path, text: str) -> AssignmentProblem:
    try:
        doc = json.loads(text, object_pairs_hook=_no_duplicates,
                         parse_constant=_parse_constant)
    except json.JSONDecodeError as exc:
        raise _fail(path, f"invalid JSON: {exc.msg} at line {exc.lineno} column {exc.colno}") from None
    except ValueError as exc:
        raise _fail(path, f"invalid JSON: {exc}") from None
    if not isinstance(doc, dict):
        raise _fail(path, f"expected a JSON object at the top level, found {type(doc).__name__}")
    fmt = doc.get("format")
    if fmt != FORMAT_NAME:
        what = "no \"format\" key" if "format" not in doc else f"\"format\": {json.dumps(fmt)}"
        raise _fail(path, f"not an assocopt instance file ({what}; expected "
                          f"\"format\": \"{FORMAT_NAME}\")")
    if "version" not in doc:
        raise _fail(path, "missing key \"version\"")
    version = doc["version"]
    if isinstance(version, bool) or not isinstance(version, int):
        raise _fail(path, f"\"version\" must be an integer, found {json.dumps(version)}")
    if version > FORMAT_VERSION:
        raise _fail(path, f"version {version} is newer than this assocopt reads "
                          f"({FORMAT_VERSION}); upgrade assocopt")
    if version < 1:
        raise _fail(path, f"unsupported version {version} (this assocopt reads 1..{FORMAT_VERSION})")
    if "kind" not in doc:
        raise _fail(path, "missing key \"kind\" (\"dense\" or \"sparse\")")
    kind = doc["kind"]
    if kind not in _KIND_KEYS:
        raise _fail(path, f"unknown kind {json.dumps(kind)}; expected \"dense\" or \"sparse\"")
    required, optional = _KIND_KEYS[kind]
    for key in sorted(required):
        if key not in doc:
            raise _fail(path, f"missing key \"{key}\" (required for kind \"{kind}\")")
    for key in doc:
        if key.startswith("x-") or key in _COMMON_KEYS or key in required or key in optional:
            continue
        other = [k for k, (r, o) in _KIND_KEYS.items() if key in r | o]
        why = f" (used by kind \"{other[0]}\", not \"{kind}\")" if other else ""
        raise _fail(path, f"unknown key \"{key}\"{why}; user extensions must start with \"x-\"")

    name = doc.get("name", path.stem)
    if not isinstance(name, str):
        raise _fail(path, f"\"name\" must be a string, found {json.dumps(name)}")
    optimum = doc.get("optimum")
    if optimum is not None:
        if isinstance(optimum, bool) or not isinstance(optimum, (int, float)) \
                or not math.isfinite(optimum):
            raise _fail(path, f"\"optimum\" must be a finite number, found {json.dumps(optimum)}")
        optimum = float(optimum)
    meta: dict[str, Any] = {"format": "assocopt", "path": str(path), "version": version}
    for key in ("optimum_source", "description"):
        if key in doc and doc[key] is not None:
            if not isinstance(doc[key], str):
                raise _fail(path, f"\"{key}\" must be a string, found {json.dumps(doc[key])}")
            meta[key] = doc[key]
    meta.update({k: v for k, v in doc.items() if k.startswith("x-")})

    try:
        if kind == "dense":
            C = _cost_array(doc["costs"], "costs", path, min_ndim=2)
            rm = doc.get("row_miss")
            cm = doc.get("col_miss")
            if rm is not None or cm is not None:
                if C.ndim != 2:
                    raise _fail(path, f"\"row_miss\"/\"col_miss\" need a 2-D cost matrix, "
                                      f"\"costs\" has {C.ndim} axes")
                rma = None if rm is None else _cost_array(rm, "row_miss", path)
                cma = None if cm is None else _cost_array(cm, "col_miss", path)
                p = AssignmentProblem.two_d(C, rma, cma, name=name, optimum=optimum)
            else:
                p = AssignmentProblem.dense(C, name=name, optimum=optimum)
        else:
            sizes = _int_list(doc["sizes"], "sizes", path)
            tuples = doc["tuples"]
            if not isinstance(tuples, list):
                raise _fail(path, f"\"tuples\" must be a list of index lists, found "
                                  f"{type(tuples).__name__}")
            T = [_int_list(t, f"tuples[{k}]", path) for k, t in enumerate(tuples)]
            for k, t in enumerate(T):
                if len(t) != len(sizes):
                    raise _fail(path, f"tuples[{k}] has {len(t)} indices, expected one per "
                                      f"axis ({len(sizes)})")
            costs = doc["costs"]
            if not isinstance(costs, list):
                raise _fail(path, f"\"costs\" must be a list of numbers, found "
                                  f"{type(costs).__name__}")
            if len(costs) != len(T):
                raise _fail(path, f"\"costs\" has {len(costs)} entries but \"tuples\" has "
                                  f"{len(T)}")
            c = np.array([_cost_value(v, f"costs[{k}]", path) for k, v in enumerate(costs)],
                         dtype=np.float64)
            Ta = np.array(T, dtype=np.int64).reshape(len(T), len(sizes))
            p = AssignmentProblem.sparse(sizes, Ta, c, name=name, optimum=optimum)
    except InvalidProblemError as exc:
        raise _fail(path, f"invalid problem: {exc}") from exc
    p.meta.update(meta)
    return p


# =============================================================== read_instance
def read_instance(path: str | os.PathLike[str], *, format: str = "auto",
                  instance: Any = None) -> AssignmentProblem:
    """Read an instance file into an :class:`AssignmentProblem`.

    Parameters
    ----------
    path : str or path-like
    format : str
        One of :data:`FORMATS`; ``"auto"`` detects it from the content.
    instance : str, (int, int) or int, optional
        For the multi-instance Balas-Saltzman file only: ``"N20_P5"``, ``(20, 5)``
        or a 1-based position.

    The problem's ``name`` is the JSON ``"name"`` or else the file stem (with
    ``":N20_P5"`` for a block of the Balas-Saltzman file); ``optimum`` is the
    recorded optimum when the file (or its sibling ``.sol`` / ``ap3.opt`` /
    ``assignopt.txt``) records one.  ``meta`` holds ``format``, ``path`` and the
    optional ``optimum_source``, ``description`` and ``x-`` keys.

    Raises
    ------
    InstanceFormatError
        Malformed, truncated, ambiguous or unknown content (the message names the
        file); OSError when the file cannot be read.
    """
    path = Path(path)
    if format not in FORMATS:
        raise InstanceFormatError(f"unknown format {format!r}; valid: {', '.join(FORMATS)}")
    if os.path.isdir(path):
        raise _fail(path, "is a directory, not an instance file")
    text = _read_text(path)
    fmt = detect_format(path, text) if format == "auto" else format
    if instance is not None and fmt != "balas-saltzman":
        raise _fail(path, f"an instance was chosen ({instance!r}) but the {fmt} format holds "
                          "one instance per file")
    if fmt == "assocopt":
        return _read_json(path, text)
    if fmt == "balas-saltzman":
        return _read_bs_driver(path, text, instance)
    if fmt == "grundel":
        return _read_grundel(path, text)
    if fmt == "balas-saltzman-split":
        return _read_bs_split(path, text)
    return _read_orlib(path, text)


# =============================================================== writing
def _json_cost(v: float) -> Any:
    if math.isinf(v):
        if v > 0:
            return "inf"
        raise InvalidProblemError("cannot write a -inf cost")
    if math.isnan(v):
        raise InvalidProblemError("cannot write a NaN cost")
    if v.is_integer() and abs(v) < 1e15:
        return int(v)
    return v


def _dump_nested(a: np.ndarray, indent: int) -> str:
    """Nested list text: innermost lists on one line, outer levels one item per line."""
    if a.ndim == 1:
        return "[" + ", ".join(json.dumps(_json_cost(float(v))) for v in a) + "]"
    pad = " " * (indent + 2)
    inner = (",\n" + pad).join(_dump_nested(sub, indent + 2) for sub in a)
    return "[\n" + pad + inner + "\n" + " " * indent + "]"


def _dump_rows(rows: Iterable[str], indent: int) -> str:
    rows = list(rows)
    if not rows:
        return "[]"
    pad = " " * (indent + 2)
    return "[\n" + pad + (",\n" + pad).join(rows) + "\n" + " " * indent + "]"


def replace_atomically(path: str | os.PathLike[str], write: Any) -> None:
    """Call ``write(tmp_path)`` on a temporary file beside ``path``, then move it into
    place with ``os.replace``: an interrupted write never leaves a partial file."""
    path = Path(path)
    directory = path.parent if str(path.parent) else Path(".")
    fd, tmp = tempfile.mkstemp(dir=directory, prefix=f".{path.stem}.", suffix=path.suffix)
    os.close(fd)
    try:
        write(Path(tmp))
        umask = os.umask(0)
        os.umask(umask)
        os.chmod(tmp, 0o666 & ~umask)
        os.replace(tmp, path)
    except BaseException:
        try:
            os.unlink(tmp)
        except OSError:
            pass
        raise


def _atomic_write(path: Path, text: str) -> None:
    def write(tmp: Path) -> None:
        with open(tmp, "w", encoding="utf-8", newline="\n") as f:
            f.write(text)
            f.flush()
            os.fsync(f.fileno())
    replace_atomically(path, write)


def instance_to_json(problem: AssignmentProblem, *, optimum: float | None = None,
                     optimum_source: str | None = None,
                     description: str | None = None) -> str:
    """The JSON v1 text :func:`write_instance` writes."""
    if not isinstance(problem, AssignmentProblem):
        raise InvalidProblemError(
            f"problem must be an AssignmentProblem, got {type(problem).__name__}")
    if optimum is None:
        optimum = problem.optimum
        if optimum_source is None and optimum is not None:
            optimum_source = problem.meta.get("optimum_source")
    if description is None:
        description = problem.meta.get("description")
    head: list[tuple[str, str]] = [("format", json.dumps(FORMAT_NAME)),
                                   ("version", json.dumps(FORMAT_VERSION))]
    if problem.name is not None:
        head.append(("name", json.dumps(problem.name)))
    if description is not None:
        head.append(("description", json.dumps(str(description))))
    if optimum is not None:
        opt = float(optimum)
        if not math.isfinite(opt):
            raise InvalidProblemError(f"optimum must be finite, got {optimum!r}")
        head.append(("optimum", json.dumps(_json_cost(opt))))
        if optimum_source is not None:
            head.append(("optimum_source", json.dumps(str(optimum_source))))
    body: list[tuple[str, str]] = []
    if problem.kind in ("dense", "two_d"):
        if 0 in problem.sizes:
            raise InvalidProblemError(
                f"a dense problem with an empty axis (sizes {list(problem.sizes)}) cannot be "
                "written as nested lists; build it with AssignmentProblem.sparse")
        head.append(("kind", json.dumps("dense")))
        body.append(("costs", _dump_nested(problem.to_cost_matrix(), 2)))
        if problem.kind == "two_d":
            rm, cm = problem.miss_costs()
            body.append(("row_miss", _dump_nested(rm, 2)))
            body.append(("col_miss", _dump_nested(cm, 2)))
    elif problem.kind == "sparse":
        head.append(("kind", json.dumps("sparse")))
        if problem.slack.any():  # pragma: no cover - sparse problems never have slack
            raise InvalidProblemError("a sparse problem with slack candidates cannot be written")
        body.append(("sizes", json.dumps(list(problem.sizes))))
        body.append(("tuples", _dump_rows((json.dumps(t) for t in problem.tuples.tolist()), 2)))
        costs = [json.dumps(_json_cost(c)) for c in problem.costs.tolist()]
        per_line = 10
        body.append(("costs", _dump_rows((", ".join(costs[k:k + per_line])
                                          for k in range(0, len(costs), per_line)), 2)))
    else:
        raise InvalidProblemError(f"cannot write a problem of kind {problem.kind!r}")
    items = [f"  {json.dumps(k)}: {v}" for k, v in head + body]
    return "{\n" + ",\n".join(items) + "\n}\n"


def write_instance(problem: AssignmentProblem, path: str | os.PathLike[str], *,
                   optimum: float | None = None, optimum_source: str | None = None,
                   description: str | None = None) -> None:
    """Write ``problem`` as a JSON v1 instance file, atomically.

    Problems built with :meth:`~AssignmentProblem.dense` or
    :meth:`~AssignmentProblem.two_d` are written as kind ``"dense"`` (the full cost
    array with ``"inf"`` where forbidden, plus ``row_miss``/``col_miss`` for
    ``two_d``); sparse problems as kind ``"sparse"``.  ``optimum``,
    ``optimum_source`` and ``description`` default to the problem's own recorded
    values.  Reading the file back gives the same candidates and costs.
    """
    _atomic_write(Path(path), instance_to_json(problem, optimum=optimum,
                                               optimum_source=optimum_source,
                                               description=description))


def _jsonable(v: Any) -> Any:
    """Plain-JSON version of ``v``: numpy types converted, non-finite floats as strings."""
    if isinstance(v, dict):
        return {str(k): _jsonable(x) for k, x in v.items()}
    if isinstance(v, (list, tuple)):
        return [_jsonable(x) for x in v]
    if isinstance(v, np.ndarray):
        return _jsonable(v.tolist())
    if isinstance(v, (bool, np.bool_)):
        return bool(v)
    if isinstance(v, (int, np.integer)):
        return int(v)
    if isinstance(v, (float, np.floating)):
        f = float(v)
        if math.isnan(f):
            return "nan"
        if math.isinf(f):
            return "inf" if f > 0 else "-inf"
        return f
    if v is None or isinstance(v, str):
        return v
    return str(v)


def solution_to_dict(solution: Solution, extra: dict[str, Any] | None = None) -> dict[str, Any]:
    """``solution.to_dict()`` made plain-JSON safe, with ``extra`` keys merged in."""
    d = dict(solution.to_dict())
    if extra:
        d.update(extra)
    return _jsonable(d)


def write_solution(solution: Solution, path: str | os.PathLike[str], *,
                   extra: dict[str, Any] | None = None) -> None:
    """Write ``solution.to_dict()`` (plus ``extra`` keys) as JSON, atomically."""
    text = json.dumps(solution_to_dict(solution, extra), indent=2, allow_nan=False)
    _atomic_write(Path(path), text + "\n")
