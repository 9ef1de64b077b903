"""docs/benchmarks-mfa.md is the rendering of the committed benchmarks/mfa.py output, and
what it records holds: every window proven optimal, our cost never above Stone Soup's,
the same pruned hypotheses where Stone Soup's answer is optimal, the same hypotheses
from the batched hypothesiser as from Stone Soup's chain."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from conftest import load_script

ROOT = Path(__file__).resolve().parents[1]
RESULT = json.loads((ROOT / "docs" / "benchmarks-mfa.json").read_text())


def test_page_is_the_rendering_of_the_json():
    page = (ROOT / "docs" / "benchmarks-mfa.md").read_text()
    assert load_script("benchmarks/mfa.py", "bench_mfa").render(RESULT) == page


def test_the_run_covers_windows_2_to_6_and_5_to_50_targets():
    cfgs = RESULT["configs"]
    assert {c["window"] for c in cfgs} >= {2, 3, 4, 5, 6}
    assert min(c["targets"] for c in cfgs) == 5 and max(c["targets"] for c in cfgs) == 50
    assert all(len(c["steps"]) == RESULT["steps"] for c in cfgs)


@pytest.mark.parametrize("cfg", RESULT["configs"], ids=lambda c: f"{c['targets']}x{c['window']}")
def test_every_window_proven_and_never_above_stone_soup(cfg):
    for r in cfg["steps"]:
        assert r["status"] == "optimal" and r["gap"] <= 1e-12
        assert r["bound"] <= r["ours_cost"] + 1e-9
        assert r["ours_cost"] <= r["stonesoup_cost"] + 1e-9 * max(1.0, abs(r["ours_cost"]))
        assert r["theirs_optimal"] == (abs(r["stonesoup_cost"] - r["ours_cost"]) <= 1e-9 * max(
            1.0, abs(r["ours_cost"])))
        if r["theirs_optimal"]:
            assert r["same_pruned"] is True
        assert r["axes"] == cfg["window"] + 1
        # leaving dominated hypotheses out kept the optimum
        assert abs(r["drop_cost"] - r["ours_cost"]) <= 1e-9 * max(1.0, abs(r["ours_cost"]))


def test_generation_rows_have_stone_soups_hypotheses():
    gen = [c for c in RESULT["configs"] if "gen_stonesoup_s" in c["steps"][0]]
    assert gen, "the run compares hypothesis generation on at least one scene"
    assert all(r["same_hypotheses"] for c in gen for r in c["steps"])
