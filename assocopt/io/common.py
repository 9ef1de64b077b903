"""Shared helpers of the instance-file readers: errors, text and number parsing.

Every reader (:mod:`.grundel`, :mod:`.balas_saltzman`, :mod:`.orlib`,
:mod:`.json_format`) and the format detection (:mod:`.detect`) raise their errors
through :func:`_fail` and parse numbers with the helpers here, so that every
malformed file gives an :class:`~assocopt.runtime.errors.InstanceFormatError` that names
the file and, where it can, the line of the bad token.
"""

from __future__ import annotations

import functools
import os
import re
from pathlib import Path
from typing import Any, Callable, NamedTuple

import numpy as np

from ..runtime.errors import InstanceFormatError, InvalidProblemError
from ..problems.problem import AssignmentProblem

_NUMBER = re.compile(r"^[+-]?(\d+\.?\d*|\.\d+)([eE][+-]?\d+)?$")
_INTEGER = re.compile(r"^[+-]?\d+$")


def _fail(path: Path, message: str) -> InstanceFormatError:
    return InstanceFormatError(f"{path}: {message}")


#: Default cap on the bytes an instance file may have (1 GiB: a dense JSON file of the
#: largest accepted dense problem, 50 million costs, is about 0.5 GiB).  Override it with
#: the environment variable ``ASSOCOPT_MAX_BYTES`` or the CLI's ``--max-bytes``.
DEFAULT_MAX_BYTES = 2 ** 30
MAX_BYTES_ENV = "ASSOCOPT_MAX_BYTES"
#: Deepest nesting of JSON arrays / objects a file may have (an N-D cost array needs N
#: levels; deeper files are rejected before parsing, never a RecursionError).
MAX_JSON_DEPTH = 100


def max_bytes() -> int:
    """The current cap on an instance file's size (see :data:`DEFAULT_MAX_BYTES`)."""
    raw = os.environ.get(MAX_BYTES_ENV)
    if raw is None or not raw.strip():
        return DEFAULT_MAX_BYTES
    try:
        value = int(float(raw))
    except ValueError:
        raise InstanceFormatError(f"{MAX_BYTES_ENV}={raw!r} is not a number of bytes") from None
    if value < 1:
        raise InstanceFormatError(f"{MAX_BYTES_ENV}={raw!r} must be a positive number of bytes")
    return value


def _read_text(path: Path) -> str:
    limit = max_bytes()
    with open(path, "rb") as f:
        data = f.read(min(4096, limit + 1))
        if b"\x00" in data:
            raise _fail(path, "not a text file (contains NUL bytes)")
        if len(data) <= limit:
            data += f.read(limit + 1 - len(data))
    if len(data) > limit:
        raise _fail(path, f"the file is larger than the limit of {limit} bytes; raise it "
                          f"with --max-bytes or the environment variable {MAX_BYTES_ENV}")
    if b"\x00" in data[:4096]:
        raise _fail(path, "not a text file (contains NUL bytes)")
    try:
        text = data.decode("utf-8-sig")
    except UnicodeDecodeError as exc:
        raise _fail(path, f"not a UTF-8 text file (byte {exc.start}: {exc.reason})") from None
    if not text or text.isspace():       # (no stripped copy of a large file)
        raise _fail(path, "the file is empty")
    return text


def _lines(text: str) -> list[list[str]]:
    """Token lists of the non-blank lines."""
    return [ln.split() for ln in text.splitlines() if ln.strip()]


class Layout(NamedTuple):
    """The line structure the text formats' detection and readers look at."""

    n_lines: int              #: non-blank lines
    head: list[list[str]]     #: tokens of the first two non-blank lines
    one_per_line: bool        #: every non-blank line after the first holds one token


class TextFile:
    """A text instance file split into tokens and lines once, in bulk, for the
    detection and the reader to share (a per-line split costs far more than the
    numbers' conversion on files of one cost per line)."""

    def __init__(self, text: str) -> None:
        self.text = text

    @classmethod
    def of(cls, text: "str | TextFile") -> "TextFile":
        return text if isinstance(text, TextFile) else cls(text)

    @functools.cached_property
    def tokens(self) -> list[str]:
        """``text.split()``: every token, in order."""
        return self.text.split()

    @functools.cached_property
    def layout(self) -> Layout:
        """:class:`Layout` from C-level passes (line breaks are whitespace, so the
        tokens of the non-blank lines after the first are one each exactly when they
        number as many as those lines)."""
        lines = self.text.splitlines()
        n = len(lines) - lines.count("") - sum(map(str.isspace, lines))
        head: list[list[str]] = []
        for line in lines:
            if len(head) == 2:
                break
            if words := line.split():
                head.append(words)
        one = not head or len(self.tokens) - len(head[0]) == n - 1
        return Layout(n, head, one)


def _locate_token(text: str, k: int) -> int:
    """1-based line number of the k-th (0-based) whitespace-separated token."""
    seen = 0
    for lineno, line in enumerate(text.splitlines(), 1):
        n = len(line.split())
        if seen + n > k:
            return lineno
        seen += n
    return -1


def _floats(tokens: list[str]) -> np.ndarray | None:
    """The tokens as float64 when every one is a finite number, else None.

    Python's ``float()`` over the list (the syntax numpy's str -> float cast accepts,
    at several times its speed).
    """
    try:
        values = np.fromiter(map(float, tokens), dtype=np.float64, count=len(tokens))
    except ValueError:
        return None
    return values if np.isfinite(values).all() else None


def _numbers(path: Path, text: str, tokens: list[str],
             start_token: int | Callable[[], int] = 0) -> np.ndarray:
    """Parse cost tokens as float64, naming the first bad token and its line.

    ``start_token`` is the position of ``tokens[0]`` in the whole file (for the line
    number in messages), or a function computing it (called only on an error).  Integers and decimal numbers are accepted; ``nan``/``inf``
    spelled out are not numbers here.
    """
    values = _floats(tokens)
    if values is not None:
        return values
    for k, tok in enumerate(tokens):
        if not _NUMBER.match(tok):
            start = start_token() if callable(start_token) else start_token
            line = _locate_token(text, start + k)
            raise _fail(path, f"non-numeric token {tok!r} on line {line}")
    raise _fail(path, "costs could not be parsed as numbers")  # pragma: no cover


def _first_non_number(tokens: list[str]) -> int | None:
    """Position of the first token that is not a plain (finite) number, or None."""
    if _floats(tokens) is not None:
        return None
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


def _listed_optimum(table: Path, name: str) -> float | None:
    """The optimum the table ``table`` (lines ``NAME VALUE``) lists for ``name``, or
    ``None`` when it lists none (callers catch :class:`OSError`)."""
    if table.is_file():
        for line in table.read_text(encoding="utf-8", errors="replace").splitlines():
            parts = line.split()
            if len(parts) == 2 and parts[0] == name and _NUMBER.match(parts[1]):
                return float(parts[1])
    return None


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
