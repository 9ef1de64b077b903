"""docs/benchmarks-mfa-components.md is the rendering of the committed
benchmarks/mfa_components.py output, and what it records holds: every component and
window proven optimal by `auto` with HiGHS's objective, components of the sizes the
target speaks of present, and the script's split gives the problem's components."""

from __future__ import annotations

import json

import numpy as np
import pytest

from conftest import ROOT, load_script

RESULT = json.loads((ROOT / "docs" / "benchmarks-mfa-components.json").read_text())


def _mod():
    pytest.importorskip("stonesoup")
    return load_script("benchmarks/mfa_components.py", "bench_mfa_components")


def test_page_is_the_rendering_of_the_json():
    page = (ROOT / "docs" / "benchmarks-mfa-components.md").read_text()
    assert _mod().render(RESULT) == page


def test_every_problem_proven_with_highs_objective():
    for cfg in RESULT["configs"]:
        for s in cfg["steps"]:
            for r in s["components"] + [s["window"]]:
                assert r["auto_status"] == r["highs_status"] == "optimal"
                ok = abs(r["auto_objective"] - r["highs_objective"]) <= 1e-9 * max(
                    1.0, abs(r["highs_objective"]))
                assert r["agree"] == ok and ok


def test_the_run_has_components_of_the_target_size():
    mod = _mod()
    comps = mod.all_components(RESULT)
    assert all(c["candidates"] >= RESULT["min_candidates"] for c in comps)
    assert sum(c["candidates"] >= mod.TARGET_K for c in comps) >= 5
    assert {cfg["window"] for cfg in RESULT["configs"]} >= {4, 5, 6}


def test_components_are_the_problems_connected_parts():
    from assocopt import AssignmentProblem, solve
    # two blocks that share no index: indices 1-2 of every axis, and index 3
    T = np.array([[1, 1, 1], [1, 2, 0], [2, 1, 1], [2, 2, 2], [0, 1, 2],
                  [3, 3, 3], [3, 0, 3], [0, 3, 3]])
    c = np.array([-3.0, -1.0, -2.0, -4.0, 0.5, -1.0, -0.5, -0.2])
    p = AssignmentProblem.sparse((3, 3, 3), T, c)
    parts = _mod().components(p, 2)
    assert sorted(q.n_candidates for q in parts) == [3, 5]
    whole = solve(p).objective
    assert abs(sum(solve(q).objective for q in parts) - whole) <= 1e-12
