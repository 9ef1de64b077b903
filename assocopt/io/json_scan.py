"""One bulk pass over the text of a JSON instance file, before it is parsed.

What it proves lets :mod:`.json_format` refuse a too deeply nested file before
``json`` recurses, parse without a Python hook per float, and let
:mod:`.json_bulk` trust a numeric numpy array (no bool can hide in it).  It works
on bytes with ``re``, ``bytes.translate`` and substring searches: no recursion,
no per-character Python.
"""

from __future__ import annotations

import re
from dataclasses import dataclass

import numpy as np

_JSON_STRING = re.compile(r'"(?:[^"\\]|\\.)*"')
_INF_STRING = re.compile(r'"\s*\+?(?i:inf)')
#: Longest run of integer-part digits a number literal may have and still be proven
#: finite when its exponent has at most two digits (10**200 * 10**99 < 1.8e308).
_SAFE_DIGITS = 200


def _shape_char(c: int) -> str:
    ch = chr(c)
    if "0" <= ch <= "9":
        return "0"
    if ch in "eE":
        return "e"
    if ch in "trufalsn[]":          # the letters of true / false / null; brackets
        return ch
    return {"{": "[", "}": "]"}.get(ch, " ")


#: Digits -> ``0``, ``e``/``E`` -> ``e``, ``{``/``}`` -> ``[``/``]``; the letters of
#: the literals and ``[``/``]`` stay; signs are deleted; every other byte -> space.
_SHAPE = "".join(map(_shape_char, range(256))).encode("latin-1")
_NOT_BRACKETS = bytes(c for c in range(256) if c not in b"[]")
#: ``[`` -> +1 and ``]`` -> -1 (as int8).
_STEP = bytes.maketrans(b"[]", bytes([1, 255]))


@dataclass(frozen=True)
class JsonScan:
    """What the pass over JSON text (strings blanked out) proves about it.

    ``depth``: deepest nesting of ``[``/``{``.  ``literals``: a ``true``, ``false``
    or ``null`` may occur (``False`` proves no bool or None anywhere in the
    document).  ``big_numbers``: a number literal may overflow a float (``False``
    proves every literal parses to a finite float, so ``json`` needs no
    ``parse_float`` hook to catch ``1e999``).  ``inf_strings``: a string such as
    ``"inf"`` may occur (only a hint for speed: a numeric numpy conversion of an
    array holding strings is bound to fail, slowly).  ``True`` answers may be false
    alarms.
    """

    depth: int
    literals: bool
    big_numbers: bool
    inf_strings: bool = True


def scan_json(text: str) -> JsonScan:
    """The :class:`JsonScan` of ``text``."""
    bare, inf_strings = _blank_strings(text)
    shape = bare.translate(_SHAPE, b"+-")
    del bare                                # (a copy of the file fewer at the peak)
    steps = np.frombuffer(shape.translate(None, _NOT_BRACKETS).translate(_STEP), dtype=np.int8)
    depth = int(np.cumsum(steps, dtype=np.int64).max(initial=0))
    literals = ((b"t" in shape or b"f" in shape or b"n" in shape)        # memchr first
                and any(word in shape for word in (b"true", b"false", b"null")))
    return JsonScan(depth, literals, _may_overflow(shape), inf_strings)


def _blank_strings(text: str) -> tuple[bytes, bool]:
    """UTF-8 ``text`` with every JSON string replaced by ``""``, and whether one of
    them may spell ``inf``.  Without backslashes the quotes pair up in order, and a
    split at them does it at memchr speed; otherwise a regex that knows escapes."""
    raw = text.encode("utf-8", "replace")
    if b"\\" not in raw:
        pieces = raw.split(b'"')
        del raw
        if len(pieces) % 2:                 # every string is closed
            inside = pieces[1::2]
            return b'""'.join(pieces[::2]), any(s.strip().lower().lstrip(b"+")
                                                in (b"inf", b"infinity") for s in inside)
    return (_JSON_STRING.sub('""', text).encode("utf-8", "replace"),
            _INF_STRING.search(text) is not None)


def _may_overflow(shape: bytes) -> bool:
    """Whether a number literal may be too large for a float: an exponent of three or
    more digits, or a run of at least :data:`_SAFE_DIGITS` digits (in ``shape``, the
    text mapped by :data:`_SHAPE`: an exponent reads ``e000``, signs deleted)."""
    if _long_digit_run(shape):
        return True
    if b"e" not in shape:
        return False
    b = np.frombuffer(shape, dtype=np.uint8)
    e = np.flatnonzero(b[:-3] == ord("e"))
    zero = ord("0")
    return bool(((b[e + 1] == zero) & (b[e + 2] == zero) & (b[e + 3] == zero)).any())


def _long_digit_run(shape: bytes) -> bool:
    """A run of :data:`_SAFE_DIGITS` ``0`` bytes in ``shape``.  Such a run covers
    ``(_SAFE_DIGITS - 7) // 8`` consecutive aligned 8-byte words of zeros: look for
    those first (one numpy pass over an eighth as many items), search only then."""
    need = (_SAFE_DIGITS - 7) // 8
    n = len(shape) // 8 * 8
    words = np.flatnonzero(np.frombuffer(shape, dtype=np.uint64, count=n // 8)
                           == np.uint64(0x3030303030303030))
    if len(words) < need or not (words[need - 1:] - words[:len(words) - need + 1]
                                 == need - 1).any():
        return False
    return b"0" * _SAFE_DIGITS in shape


def json_depth(text: str) -> int:
    """Deepest nesting of ``[``/``{`` in JSON text (strings ignored), without recursion."""
    return scan_json(text).depth
