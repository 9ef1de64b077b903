"""docs/benchmarks-2d.md is exactly what benchmarks/twod.py renders from the committed JSON."""

from __future__ import annotations

import json
from pathlib import Path

from conftest import load_script

ROOT = Path(__file__).resolve().parents[1]


def _bench():
    return load_script("benchmarks/twod.py", "bench_twod")


def test_page_matches_the_committed_json():
    data = json.loads((ROOT / "docs" / "benchmarks-2d.json").read_text())
    page = (ROOT / "docs" / "benchmarks-2d.md").read_text()
    assert _bench().render(data) == page


def test_committed_results_agree_with_the_references():
    data = json.loads((ROOT / "docs" / "benchmarks-2d.json").read_text())
    assert {r["n"] for r in data["dense"]} >= {10, 100, 1000, 2000}
    assert all(r["equal"] for r in data["dense"] + data["sparse"] + data["kbest"])
    for r in data["marginals"]:
        assert 0.0 <= r["max_abs_error"] <= 1.0 and 0.0 < r["min_mass_covered"] <= 1.0


def test_kbest_rows_time_both_paths_on_tracker_sizes():
    rows = json.loads((ROOT / "docs" / "benchmarks-2d.json").read_text())["kbest"]
    assert {(r["problem"], r["k"]) for r in rows} >= {("miss 20x20", 100),
                                                      ("miss 50x50", 100)}
    for r in rows:
        assert r["kbest_s"] > 0 and r["generic_s"] > 0 and r["found"] <= r["k"]
        small = r["feasible"] is not None
        assert r["reference"] == ("enumeration" if small else "scipy-lsa path")
        assert (r["enumerate_s"] is not None) == small


def test_quick_run_writes_a_consistent_page(tmp_path):
    bench = _bench()
    assert bench.main(["--quick", "--out", str(tmp_path)]) == 0
    data = json.loads((tmp_path / "benchmarks-2d.json").read_text())
    assert bench.render(data) == (tmp_path / "benchmarks-2d.md").read_text()
    assert all(r["equal"] for r in data["dense"] + data["sparse"] + data["kbest"])
