"""docs/benchmarks-jpda.md is the rendering of the committed benchmarks/stonesoup_jpda.py
output, and what it records holds: AssocoptJPDA's probabilities equal JPDAwithEHM2's
on every scan it answered, the speed-ups are the recorded times' ratios."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from conftest import load_script

ROOT = Path(__file__).resolve().parents[1]
RESULT = json.loads((ROOT / "docs" / "benchmarks-jpda.json").read_text())


def _script():
    return load_script("benchmarks/stonesoup_jpda.py", "stonesoup_jpda")


def test_page_is_the_rendering_of_the_json():
    page = (ROOT / "docs" / "benchmarks-jpda.md").read_text()
    assert _script().render(RESULT) == page


def test_the_run_covers_clusters_of_3_to_8_and_a_100_track_scene():
    rows = RESULT["rows"]
    assert {r["cluster_size"] for r in rows} >= {3, 5, 8}
    assert max(r["tracks"] for r in rows) >= 100
    assert RESULT["engine"] == "exact"
    assert all(r["tracks"] == r["cluster_size"] * r["clusters"] for r in rows)


@pytest.mark.parametrize("row", RESULT["rows"], ids=lambda r: f"{r['cluster_size']}x{r['clusters']}")
def test_same_probabilities_and_consistent_ratios(row):
    answered = row["scans"] - row["refused_scans"]
    if RESULT["engine"] == "exact":
        assert answered == row["scans"]           # the exact engine refuses nothing here
    if answered:
        assert row["max_error"] <= 1e-9
        assert row["speedup"] == row["ehm2_cpu_s"] / row["assocopt_cpu_s"]
    else:
        assert row["assocopt_cpu_s"] is None and row["max_error"] is None
