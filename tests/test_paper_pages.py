"""The paper pages regenerate what they say.

For each reproduced paper: the committed ``tables.md`` is exactly what the report
code renders from the committed ``summary.json``; every generated block of the page
is exactly its ``tables.md`` section (so every number in the page's result tables
comes from ``summary.json``); every other table on the page is marked static; the
figures the run wrote exist and are shown.  (That no page cites a file the project
does not ship is checked for every file by ``tests/test_layout.py``.)
"""

from __future__ import annotations

import json
import re
from pathlib import Path

import pytest

from assocopt.reproduce import lu2013, pages, yan2010, zhang2009

DOCS = Path(__file__).resolve().parents[1] / "docs" / "papers"
PAPERS = {"lu2013": lu2013, "yan2010": yan2010, "zhang2009": zhang2009}


def _load(name):
    summary = json.loads((DOCS / name / "summary.json").read_text())
    tables = (DOCS / name / "tables.md").read_text()
    page = (DOCS / f"{name}.md").read_text()
    return summary, tables, page


@pytest.mark.parametrize("name", sorted(PAPERS))
def test_tables_md_is_rendered_from_the_committed_summary(name):
    summary, tables, _ = _load(name)
    assert PAPERS[name].render_tables(summary) == tables


@pytest.mark.parametrize("name", sorted(PAPERS))
def test_page_tables_equal_the_runs_tables(name):
    summary, tables, page = _load(name)
    secs = pages.sections(tables)
    assert pages.check(page, secs) == []
    used = re.findall(r"<!-- BEGIN GENERATED ([\w.-]+) -->", page)
    assert len(used) >= 5 and set(used) <= set(secs)


@pytest.mark.parametrize("name", sorted(PAPERS))
def test_figures_exist_and_are_shown(name):
    summary, _, page = _load(name)
    assert summary["figures"]
    for f in summary["figures"]:
        assert (DOCS / name / f).stat().st_size > 1000
        assert f"({name}/{f})" in page, f


def test_check_finds_a_stale_block_and_an_unmarked_table():
    secs = pages.sections("<!-- section: a -->\n### A\n\n| x | y |\n|---|---|\n| 1 | 2 |\n")
    good = "intro\n<!-- BEGIN GENERATED a -->\nold\n<!-- END GENERATED a -->\n"
    filled = pages.fill(good, secs)
    assert pages.check(filled, secs) == []
    assert "| 1 | 2 |" in filled
    stale = filled.replace("| 1 | 2 |", "| 1 | 3 |")
    assert any("differs" in p for p in pages.check(stale, secs))
    loose = filled + "\n| p | q |\n|---|---|\n| 5 | 6 |\n"
    assert any("not marked static" in p for p in pages.check(loose, secs))
    marked = filled + "\n<!-- static table: definitions -->\n| p | q |\n|---|---|\n| 5 | 6 |\n"
    assert pages.check(marked, secs) == []
    with pytest.raises(KeyError, match="lacks"):
        pages.fill("<!-- BEGIN GENERATED b -->\n<!-- END GENERATED b -->", secs)
