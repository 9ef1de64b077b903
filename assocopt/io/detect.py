"""Format detection and :func:`read_instance`, the entry point of all readers.

:func:`detect_format` tells the format from the file's content (with the file
name as a tie-breaker) and :func:`read_instance` dispatches to the reader of
:mod:`.json_format`, :mod:`.grundel`, :mod:`.balas_saltzman` or :mod:`.orlib`.
"""

from __future__ import annotations

import math
import os
import re
from pathlib import Path
from typing import Any

from ..runtime.errors import InstanceFormatError
from ..problems.problem import AssignmentProblem
from .balas_saltzman import _BS_BLOCK, _read_bs_driver, _read_bs_split
from .common import (_INTEGER, TextFile, _cube_root, _fail, _first_non_number,
                     _locate_token, _read_text)
from .grundel import _MAX_D, _read_grundel
from .json_format import _read_json
from .orlib import _read_orlib

#: Accepted values of ``read_instance(..., format=...)``.
FORMATS = ("auto", "assocopt", "grundel", "balas-saltzman", "balas-saltzman-split", "orlib")


# =============================================================== detection
def _looks_grundel(lines: list[list[str]]) -> bool:
    if len(lines) < 2 or len(lines[0]) != 1 or not _INTEGER.match(lines[0][0]):
        return False
    d = int(lines[0][0])
    return (2 <= d <= _MAX_D and len(lines[1]) == d
            and all(_INTEGER.match(t) and int(t) > 0 for t in lines[1]))


def _matches(text: str | TextFile) -> tuple[dict[str, tuple[bool, int, bool]], str]:
    """Which public text formats fit the file.

    Returns ``{format: (count_fits, expected_count, strong)}`` for every format whose
    layout fits (``count_fits`` False: a damaged file of that format; ``strong``: the
    layout alone is distinctive), and a short description of what was seen.
    """
    src = TextFile.of(text)
    n_lines, lines, one_per_line = src.layout      # lines: the first two only
    L = len(src.tokens)
    seen = (f"{n_lines} non-blank lines, {L} numbers, first line "
            f"{' '.join(lines[0][:6])[:60]!r}")
    found: dict[str, tuple[bool, int, bool]] = {}
    # Grundel: "d" / "n1 .. nd" / costs; a square header "n n n" is distinctive
    if _looks_grundel(lines):
        d = int(lines[0][0])
        sizes = [int(t) for t in lines[1]]
        expected = math.prod(sizes)
        found["grundel"] = (L - 1 - d == expected, expected, len(set(sizes)) == 1)
    # Balas-Saltzman split: n^3 numbers (one per line), or a "3 n" header first
    if one_per_line and len(lines[0]) == 2 and lines[0][0] == "3" \
            and _INTEGER.match(lines[0][1]):
        n = int(lines[0][1])
        found["balas-saltzman-split"] = (L - 2 == n ** 3, n ** 3, True)
    elif one_per_line and len(lines[0]) == 1:
        # headerless: n**3 numbers with n >= 2 (a lone number is no 1x1x1 problem)
        found["balas-saltzman-split"] = (_cube_root(L) is not None and L >= 8, L, False)
    # OR-Library: n alone on line 1, then n*n costs (several per line in practice)
    if len(lines[0]) == 1 and _INTEGER.match(lines[0][0]) and int(lines[0][0]) > 0:
        n = int(lines[0][0])
        exact = L - 1 == n * n
        if exact or not one_per_line or n_lines < 3:
            found["orlib"] = (exact, n * n, False)
    if not found and L >= 8 and _cube_root(L) is not None:
        # n**3 numbers laid out otherwise than one per line
        found["balas-saltzman-split"] = (True, L, False)
    return found, seen


def detect_format(path: str | os.PathLike[str], text: str | None = None) -> str:
    """The format name :func:`read_instance` would use for ``path`` with ``format="auto"``.

    Raises :class:`InstanceFormatError` when the content fits no format, or several.
    """
    path = Path(path)
    return _detect(path, TextFile(_read_text(path) if text is None else text))


def _detect(path: Path, src: TextFile) -> str:
    text = src.text
    head = text.lstrip()
    if head.startswith(("{", "[")):
        return "assocopt"
    if path.suffix.lower() == ".json":
        raise _fail(path, f"invalid assocopt instance: expected a JSON object at the top "
                          f"level, found {head[:40].split(chr(10))[0]!r}")
    # ("PROBLEM" first: a substring search is far cheaper than the regex)
    if ("PROBLEM" in text and _BS_BLOCK.search(text)) or "AP3 Test Driver" in text[:2000]:
        return "balas-saltzman"
    found, seen = _matches(src)
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
    tokens = src.tokens
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
    src = TextFile(_read_text(path))
    fmt = _detect(path, src) if format == "auto" else format
    if instance is not None and fmt != "balas-saltzman":
        raise _fail(path, f"an instance was chosen ({instance!r}) but the {fmt} format holds "
                          "one instance per file")
    if fmt == "assocopt":
        return _read_json(path, src.text)
    if fmt == "balas-saltzman":
        return _read_bs_driver(path, src.text, instance)
    if fmt == "grundel":
        return _read_grundel(path, src)
    if fmt == "balas-saltzman-split":
        return _read_bs_split(path, src)
    return _read_orlib(path, src)
