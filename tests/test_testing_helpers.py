"""assocopt.testing: the helpers users import into their own test suites must catch errors."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings

from assocopt import AssignmentProblem, Solution, Status, solve
from assocopt.io import read_instance
from assocopt.testing import (KINDS, assert_feasible, assert_optimal, assert_valid_bound,
                              generated_problems, problems, random_problem,
                              reference_optimum, stored_instances)

ROOT = Path(__file__).resolve().parents[1]


def _problem() -> AssignmentProblem:
    # greedy takes 1 first and is then forced to 4: total 5, optimum 2 + 2 = 4
    return AssignmentProblem.dense([[1.0, 2.0], [2.0, 4.0]])


def test_assert_optimal_accepts_an_optimal_solution():
    p = _problem()
    assert_optimal(p, solve(p, "highs"))
    assert_optimal(p, solve(p, "scipy-lsa"), reference=4.0)


def test_assert_optimal_rejects_a_suboptimal_solution_named_optimal():
    p = _problem()
    greedy = solve(p, "greedy")
    assert greedy.objective == 5.0
    with pytest.raises(AssertionError, match="greedy: status feasible"):
        assert_optimal(p, greedy)
    fake = replace(greedy, status=Status.OPTIMAL)
    with pytest.raises(AssertionError, match=r"greedy: objective 5\.0 != brute force 4\.0"):
        assert_optimal(p, fake)
    with pytest.raises(AssertionError, match="the given reference"):
        assert_optimal(p, solve(p, "highs"), reference=3.0)


def test_assert_optimal_uses_the_recorded_optimum():
    p = read_instance(ROOT / "instances" / "example-3d.json")
    assert reference_optimum(p) == (5.0, "recorded optimum")
    wrong = AssignmentProblem.dense(p.to_cost_matrix(), optimum=4.0)
    with pytest.raises(AssertionError, match="recorded optimum 4.0"):
        assert_optimal(wrong, solve(wrong, "highs"))


def test_reference_optimum_sources():
    assert reference_optimum(_problem()) == (4.0, "brute force")
    big = random_problem(np.random.default_rng(0), "axial3", sizes=(8, 8, 8))
    value, how = reference_optimum(big)
    assert how == "HiGHS" and value == solve(big, "scipy").objective


def test_assert_feasible_catches_a_broken_solution():
    p = _problem()
    sol = solve(p, "highs")
    broken = replace(sol, selected=sol.selected[:1])
    with pytest.raises(AssertionError, match="covered 0 times"):
        assert_feasible(p, broken)
    lying = replace(sol, objective=sol.objective - 1)
    with pytest.raises(AssertionError, match="!= sum of chosen costs"):
        assert_feasible(p, lying)
    with pytest.raises(AssertionError, match="no solution attached"):
        assert_feasible(p, Solution(Status.TIME_LIMIT, message="stopped"))


def test_assert_valid_bound():
    p = read_instance(ROOT / "instances" / "axial-4d-4x4x4x4.json")
    assert_valid_bound(p, solve(p, "highs", relax="lp"))
    assert_valid_bound(p, solve(p, "highs"))
    too_high = replace(solve(p, "highs"), bound=p.optimum + 1)
    with pytest.raises(AssertionError, match="exceeds the recorded optimum"):
        assert_valid_bound(p, too_high)
    with pytest.raises(AssertionError, match="no bound reported"):
        assert_valid_bound(p, solve(p, "greedy"))


def test_stored_instances_are_the_curated_set(monkeypatch, tmp_path):
    files = stored_instances()
    assert files == sorted((ROOT / "instances").glob("*.json")) and len(files) >= 12
    assert stored_instances(tmp_path) == []
    monkeypatch.chdir(tmp_path)                    # outside the checkout: the project's set
    assert stored_instances() == files


@pytest.mark.parametrize("path", stored_instances(), ids=lambda p: p.stem)
def test_every_stored_optimum_is_right(path):
    p = read_instance(path)
    assert p.optimum is not None and p.meta.get("optimum_source")
    assert_optimal(p, solve(p, "highs"))
    assert_valid_bound(p, solve(p, "highs", relax="lp"))


@settings(max_examples=25, deadline=None)
@given(generated_problems(max_axes=3, max_size=3))
def test_generated_problems_strategy(p):
    assert_optimal(p, solve(p, "highs"))


@settings(max_examples=10, deadline=None)
@given(generated_problems(kinds=("planted",), max_axes=4, max_size=4))
def test_planted_problems_carry_their_optimum(p):
    assert p.optimum is not None
    assert_optimal(p, solve(p, "ortools-cpsat"))


@settings(max_examples=20, deadline=None)
@given(problems())
def test_problems_strategy_still_works(p):
    assert p.kind in ("dense", "two_d", "sparse")
    assert_optimal(p, solve(p, "highs"))


def test_generated_problems_rejects_unknown_kinds():
    with pytest.raises(ValueError, match="kinds must be among"):
        generated_problems(kinds=("cubic",))
    assert "sd" in KINDS
