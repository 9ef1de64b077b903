"""docs/benchmarks-marginals.md is the rendering of the committed benchmarks/marginals.py
output, and what it records holds: every exact method agrees with ours to 1e-9, the
kbest error never exceeds its certified bound, the S-D exact marginals equal
enumeration, and the scenes cover what the page says."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from conftest import load_script

ROOT = Path(__file__).resolve().parents[1]
RESULT = json.loads((ROOT / "docs" / "benchmarks-marginals.json").read_text())
EXACT = ("ours_ss", "JPDA", "JPDAwithEHM", "JPDAwithEHM2", "pyehm", "pyehm_engine")


def _bench():
    return load_script("benchmarks/marginals.py", "bench_marginals")


def test_page_is_the_rendering_of_the_json():
    page = (ROOT / "docs" / "benchmarks-marginals.md").read_text()
    assert _bench().render(RESULT) == page


def test_the_run_covers_3_to_20_tracks_a_100_track_scene_and_sd_scans():
    clusters = [r for r in RESULT["scenes"] if r["scene"].startswith("cluster")]
    assert {r["tracks"] for r in clusters} >= {3, 5, 8, 12, 16, 20}
    assert all(r["largest_cluster"] == r["tracks"] for r in clusters)    # one entangled cluster
    scene = [r for r in RESULT["scenes"] if r["scene"] == "scene"]
    assert len(scene) == 1 and scene[0]["tracks"] >= 90 and scene[0]["clusters"] >= 20
    assert {r["targets"] for r in RESULT["sd"]} >= {3, 6, 9, 12}


@pytest.mark.parametrize("row", RESULT["scenes"], ids=lambda r: r["scene"])
def test_exact_methods_agree_and_kbest_stays_within_its_bound(row):
    e = row["errors"]
    assert e["ours"] <= 1e-12                       # our rows sum to 1
    for name in EXACT:
        if name in e:
            assert e[name] <= 1e-9, name
    assert {"ours", "ours_ss", "JPDAwithLBP", "kbest", "lbp"} <= set(row["times"])
    assert e["kbest"] <= row["kbest_bound"] + 1e-12
    assert row["lbp_iterations"] >= 1


@pytest.mark.parametrize("row", RESULT["sd"], ids=lambda r: str(r["targets"]))
def test_sd_exact_equals_enumeration_and_covers_each_measurement_once(row):
    assert row["coverage_error"] <= 1e-9
    if "enumerate_error" in row:
        assert row["enumerate_error"] <= 1e-9
    assert row["kbest_error"] <= row["kbest_bound"] + 1e-12


def test_quick_run_writes_a_consistent_page(tmp_path):
    pytest.importorskip("stonesoup")
    bench = _bench()
    out = tmp_path / "m"
    bench.main(["--sizes", "3", "--scene", "4", "--sd", "3", "--out", str(out)])
    data = json.loads(out.with_suffix(".json").read_text())
    assert bench.render(data) == out.with_suffix(".md").read_text()
    for row in data["scenes"]:
        assert all(row["errors"][n] <= 1e-9 for n in EXACT if n in row["errors"])
