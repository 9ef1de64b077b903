"""docs/benchmarks-stonesoup.md is the rendering of the committed benchmark output."""

from __future__ import annotations

import json
from pathlib import Path

from conftest import load_script

ROOT = Path(__file__).resolve().parents[1]


def _script():
    return load_script("benchmarks/stonesoup_assoc.py", "stonesoup_assoc")


def test_page_is_the_rendering_of_the_json():
    result = json.loads((ROOT / "docs" / "benchmarks-stonesoup.json").read_text())
    page = (ROOT / "docs" / "benchmarks-stonesoup.md").read_text()
    assert _script().render(result) == page


def test_benchmark_covers_10_100_1000_targets_with_equal_associations():
    result = json.loads((ROOT / "docs" / "benchmarks-stonesoup.json").read_text())
    rows = result["rows"]
    assert [r["targets"] for r in rows] == [10, 100, 1000]
    assert all(r["same_associations"] for r in rows)
    for r in rows:
        assert r["ratio"] == r["assocopt_s"] / r["stonesoup_s"]
