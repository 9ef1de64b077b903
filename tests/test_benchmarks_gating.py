"""docs/benchmarks-gating.md is what benchmarks/gating_page.py draws from the committed
docs/benchmarks-gating.json, and its numbers hold together: the slopes are the fits of
the recorded points, the totals the sums of the stages, every position scan was solved
to a proven optimum, the sizes are the script's."""

from __future__ import annotations

import json
import re

import pytest

from conftest import ROOT, load_script

JSON = ROOT / "docs" / "benchmarks-gating.json"
PAGE = ROOT / "docs" / "benchmarks-gating.md"


def _mod(path: str, name: str):
    return load_script(path, name)


def _data() -> dict:
    return json.loads(JSON.read_text())


def test_page_matches_the_committed_json():
    page = _mod("benchmarks/gating_page.py", "bench_gating_page")
    assert page.render(_data()) == PAGE.read_text()
    assert (ROOT / "docs" / "gating-scale.png").stat().st_size > 10_000


def test_json_records_the_environment_and_the_command():
    env = _data()["environment"]
    assert env["command"].startswith("python benchmarks/gating_scale.py")
    assert len(env["load_start"]) == len(env["load_end"]) == 3
    assert "load average" in env["uptime_start"]
    assert env["minutes"] > 0 and re.fullmatch(r"\d{4}-\d\d-\d\d", env["date"])


def test_slopes_totals_and_sizes_are_those_of_the_rows():
    bench = _mod("benchmarks/gating_scale.py", "bench_gating_scale")
    data = _data()
    assert data["targets"] == bench.TARGETS and data["fits_from"] == bench.FIT_FROM
    assert set(data["fits"]) == set(bench.KINDS)
    for kind, sizes in bench.SIZES.items():
        rows = [r for r in data["rows"] if r["kind"] == kind]
        assert [r["n"] for r in rows] == list(sizes)
        got, want = data["fits"][kind], bench.fits(data["rows"], kind)
        assert got.keys() == want.keys()
        for k in want:
            assert got[k] == pytest.approx(want[k], rel=1e-12)
        for r in rows:
            assert r["total_cpu"] == pytest.approx(sum(v["cpu"] for v in r["stages"].values()))
            assert r["rss_peak_gb"] >= r["rss_base_gb"] > 0
            assert list(r["stages"]) == list(bench.STAGES[kind])
            assert r["candidates"] > r["n"]


def test_every_position_scan_is_proven_optimal():
    for r in _data()["rows"]:
        if r["kind"] == "position":
            assert r["status"] == "optimal"
            assert r["bound"] == pytest.approx(r["objective"], abs=1e-6 * max(1, abs(r["objective"])))


def test_the_slope_helper_recovers_a_power_law():
    bench = _mod("benchmarks/gating_scale.py", "bench_gating_scale")
    assert bench.slope([10, 100, 1000], [3e-3, 3e-2 * 10 ** 0.5, 3e-1 * 10]) == pytest.approx(1.5)
