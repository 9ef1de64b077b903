"""Paper pages whose tables come from the reproduction's own output.

A reproduction writes ``tables.md`` as named sections, each opened by a line
``<!-- section: NAME -->``.  A docs page includes a section between
``<!-- BEGIN GENERATED NAME -->`` and ``<!-- END GENERATED NAME -->``;
:func:`fill` copies the sections in, :func:`check` reports every block that differs
from its section and every table outside a block that is not marked
``<!-- static table: why -->`` (a table of parameters or definitions, no run output).
``tests/test_paper_pages.py`` runs :func:`check` on the committed pages, so a page
cannot drift from the run it reports.

Regenerate a page after a run::

    python -m assocopt.reproduce.pages docs/papers/lu2013.md docs/papers/lu2013/tables.md
"""

from __future__ import annotations

import re
import sys
from pathlib import Path

__all__ = ["sections", "fill", "check", "update_page", "main"]

_SECTION = re.compile(r"^<!-- section: ([\w.-]+) -->$", re.M)
_BLOCK = re.compile(r"<!-- BEGIN GENERATED ([\w.-]+) -->\n(.*?)<!-- END GENERATED \1 -->",
                    re.S)
_STATIC = "<!-- static table:"


def sections(tables_md: str) -> dict[str, str]:
    """``{name: text}`` of every section of a ``tables.md`` (marker line excluded)."""
    marks = list(_SECTION.finditer(tables_md))
    out = {}
    for i, m in enumerate(marks):
        end = marks[i + 1].start() if i + 1 < len(marks) else len(tables_md)
        out[m.group(1)] = tables_md[m.end():end].strip("\n") + "\n"
    return out


def fill(page: str, secs: dict[str, str]) -> str:
    """``page`` with every generated block replaced by its section.

    Raises
    ------
    KeyError
        A block names a section that ``secs`` lacks.
    """
    def repl(m: re.Match) -> str:
        name = m.group(1)
        if name not in secs:
            raise KeyError(f"page includes section {name!r}, which tables.md lacks "
                           f"(it has: {', '.join(sorted(secs))})")
        return f"<!-- BEGIN GENERATED {name} -->\n{secs[name]}<!-- END GENERATED {name} -->"
    return _BLOCK.sub(repl, page)


def check(page: str, secs: dict[str, str]) -> list[str]:
    """Problems of ``page`` against the sections (empty list: the page is in sync)."""
    problems = []
    for m in _BLOCK.finditer(page):
        name, body = m.group(1), m.group(2)
        if name not in secs:
            problems.append(f"block {name!r}: no such section in tables.md")
        elif body != secs[name]:
            problems.append(f"block {name!r} differs from tables.md (regenerate the page)")
    opened = len(re.findall(r"<!-- BEGIN GENERATED ", page))
    if opened != len(_BLOCK.findall(page)):
        problems.append("a BEGIN GENERATED marker has no matching END marker")
    outside = _BLOCK.sub("", page)
    outside = re.sub(r"```.*?```", "", outside, flags=re.S)       # code blocks
    lines = outside.splitlines()
    for i, line in enumerate(lines):
        if not re.match(r"^\|[\s:]*-{3,}", line):                 # a table's rule line
            continue
        j = i - 2                                                 # line above the header
        while j >= 0 and not lines[j].strip():
            j -= 1
        if j < 0 or not lines[j].lstrip().startswith(_STATIC):
            problems.append(f"table {lines[i - 1][:60]!r} is outside a generated block and "
                            "not marked static")
    return problems


def update_page(page_path: str | Path, tables_path: str | Path) -> bool:
    """Rewrite ``page_path`` from ``tables_path``; True if it changed."""
    page_path = Path(page_path)
    old = page_path.read_text()
    new = fill(old, sections(Path(tables_path).read_text()))
    if new != old:
        page_path.write_text(new)
    return new != old


def main(argv: list[str] | None = None) -> int:
    args = sys.argv[1:] if argv is None else argv
    if len(args) != 2:
        print("usage: python -m assocopt.reproduce.pages PAGE.md TABLES.md", file=sys.stderr)
        return 2
    changed = update_page(*args)
    page = Path(args[0]).read_text()
    problems = check(page, sections(Path(args[1]).read_text()))
    for p in problems:
        print(p, file=sys.stderr)
    print(f"{args[0]}: {'updated' if changed else 'unchanged'}"
          f"{'' if not problems else f', {len(problems)} problem(s)'}")
    return 1 if problems else 0


if __name__ == "__main__":
    raise SystemExit(main())
