"""Shared helpers of the instance-file readers: errors, text and number parsing.

Every reader (:mod:`.grundel`, :mod:`.balas_saltzman`, :mod:`.orlib`,
:mod:`.json_format`) and the format detection (:mod:`.detect`) raise their errors
through :func:`_fail` and parse numbers with the helpers here, so that every
malformed file gives an :class:`~assocopt.errors.InstanceFormatError` that names
the file and, where it can, the line of the bad token.
"""

from __future__ import annotations

import re
from pathlib import Path
from typing import Any

import numpy as np

from ..errors import InstanceFormatError, InvalidProblemError
from ..problem import AssignmentProblem

_NUMBER = re.compile(r"^[+-]?(\d+\.?\d*|\.\d+)([eE][+-]?\d+)?$")
_INTEGER = re.compile(r"^[+-]?\d+$")


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
