"""Readers of the Balas & Saltzman (1991) 3-D assignment formats.

``"balas-saltzman"``: the multi-instance "AP3 Test Driver" file (blocks
``N = n   PROBLEM = p`` / a line of ``=`` / ``n**3`` costs), one block chosen with
``instance=``; ``"balas-saltzman-split"``: one instance per file, ``n**3`` costs,
optionally after a ``3 n`` header.  :data:`_BS_BLOCK` is shared with :mod:`.detect`.
"""

from __future__ import annotations

import re
from pathlib import Path
from typing import Any

import numpy as np

from ..problems.problem import AssignmentProblem
from .common import (_INTEGER, TextFile, _count_error, _cube_root, _dense, _fail,
                     _numbers)

_BS_BLOCK = re.compile(r"^[ \t]*N[ \t]*=[ \t]*(\d+)[ \t]+PROBLEM[ \t]*=[ \t]*(\d+)[ \t]*\r?\n"
                       r"[ \t]*=+[ \t]*\r?$", re.MULTILINE)
_BS_INSTANCE = re.compile(r"^\s*N\s*(\d+)\s*[_\-\s,:]?\s*P(?:ROBLEM)?\s*(\d+)\s*$", re.I)
_PAIR = re.compile(r"^\s*\(?\s*(\d+)\s*[,:/ ]\s*(\d+)\s*\)?\s*$")


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
    values = _numbers(path, text, tokens, lambda: len(text[:start].split()))
    return _dense(path, values, (n, n, n), f"{path.stem}:{label}", None,
                  "balas-saltzman", instance=label)


def _read_bs_split(path: Path, text: str | TextFile) -> AssignmentProblem:
    src = TextFile.of(text)
    text, tokens = src.text, src.tokens
    start = 0
    if _cube_root(len(tokens)) is None:
        # optional "3 n" header (d, n)
        if (len(tokens) >= 2 and tokens[0] == "3" and _INTEGER.match(tokens[1])
                and src.layout.head[0] == tokens[:2]):
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
