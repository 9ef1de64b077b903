"""docs/benchmarks-read.md is exactly what benchmarks/read.py renders from the committed
JSON, and a quick run of the script writes a consistent page.  No timing is asserted."""

from __future__ import annotations

import json
from pathlib import Path

from conftest import load_script

ROOT = Path(__file__).resolve().parents[1]


def _bench():
    return load_script("benchmarks/read.py", "bench_read")


def test_page_matches_the_committed_json():
    data = json.loads((ROOT / "docs" / "benchmarks-read.json").read_text())
    page = (ROOT / "docs" / "benchmarks-read.md").read_text()
    assert _bench().render(data) == page


def test_committed_run_covers_the_sizes():
    data = json.loads((ROOT / "docs" / "benchmarks-read.json").read_text())
    assert not data["quick"]
    keys = {r["key"] for r in data["rows"]}
    assert {"dense3-int", "dense3-big", "dense2", "sparse3"} <= keys
    for r in data["rows"]:
        assert r["floor_s"] > 0 and r["read_s"] > 0
        assert r["ratio_to_floor"] == round(r["read_s"] / r["floor_s"], 2)
        if r["before_s"] is not None:
            assert r["speedup"] == round(r["before_s"] / r["read_s"], 1)


def test_quick_run_writes_a_consistent_page(tmp_path):
    bench = _bench()
    assert bench.main(["--quick", "--out", str(tmp_path)]) == 0
    data = json.loads((tmp_path / "benchmarks-read.json").read_text())
    assert bench.render(data) == (tmp_path / "benchmarks-read.md").read_text()
    assert data["quick"] and len(data["rows"]) == len(bench.cases(True))
