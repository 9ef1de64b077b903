"""docs/benchmarks-first-use.md against the JSON that benchmarks/first_use.py wrote in
the same run (no timing is asserted: the benchmark measures it)."""

from __future__ import annotations

import json

import pytest

from conftest import load_script


@pytest.fixture(scope="module")
def bench():
    return load_script("benchmarks/first_use.py", "first_use_page")


def test_first_use_page_is_rendered_from_the_committed_measurements(bench):
    """The page is exactly what the benchmark renders from the committed json.
    Refresh both: python benchmarks/first_use.py"""
    data = json.loads(bench.DATA.read_text())
    assert bench.PAGE.read_text() == bench.render(data)


def test_first_use_measurements_cover_every_timed_path(bench):
    """Every public path the benchmark times has a row (and only those), in order;
    the targets and the rule are the benchmark's; all-together covers the same paths."""
    from assocopt.solvers.kernels import tiers
    data = json.loads(bench.DATA.read_text())
    keys = [k for k, _w, _f in bench.PATHS if k not in bench.NOT_TIMED]
    assert [r["key"] for r in data["rows"]] == keys
    for mode in ("auto", "compiled"):
        assert list(data["together"][mode]["per_path"]) == keys
    assert data["targets"] == {"cold_s": bench.COLD_TARGET, "all_s": bench.ALL_TARGET,
                               "warm_s": bench.WARM_TARGET}
    assert data["rule"] == {"budget_cold_s": tiers.BUDGET_COLD,
                            "budget_cached_s": tiers.BUDGET_CACHED,
                            "budget_warm_s": tiers.BUDGET_WARM,
                            "limits": tiers.LIMITS}
    assert len(data["load_before"]) == len(data["load_after"]) == 3


def test_first_use_measurements_are_consistent(bench):
    """Compile and cache-load times are parts of the call's time; a compiled warm
    process compiles nothing and says nothing; a process that compiled said so first;
    an interpreted first call imported no numba; the totals are the per-path sums."""
    data = json.loads(bench.DATA.read_text())
    for r in data["rows"]:
        for run in ("auto", "cold", "warm"):
            t = r[run]
            assert 0 <= t["compile_s"] + t["cache_load_s"] <= t["wall_s"] + 1e-3
            assert (r[f"{run}_notes"] == 1) == (t["compile_s"] > 0)
        assert r["warm"]["compile_s"] == 0 and r["warm_notes"] == 0
        assert r["cold"]["interpreted_s"] == r["warm"]["interpreted_s"] == 0
        if bench.route(r["auto"]) == "interpreted":
            assert not r["auto"]["numba"]
    for mode in ("auto", "compiled"):
        tg = data["together"][mode]
        per = tg["per_path"].values()
        assert tg["wall_s"] == pytest.approx(sum(p["wall_s"] for p in per), abs=5e-3)
        assert tg["cpu_s"] == pytest.approx(sum(p["cpu_s"] for p in per), abs=5e-3)
        assert tg["notes"] == (1 if tg["compile_s"] > 0 else 0)
