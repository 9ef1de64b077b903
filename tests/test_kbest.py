"""kbest: the k best objectives equal the k smallest of the full enumeration."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings, strategies as st

from assocopt import AssignmentProblem, InvalidProblemError, kbest
from assocopt.solvers.baseline.bruteforce import enumerate_solutions
from assocopt.testing import problems, random_problem

from test_twod import two_d_cases


def _ranked_reference(p: AssignmentProblem) -> list[float]:
    return sorted(p.objective_of(s) for s in enumerate_solutions(p))


def _check(p: AssignmentProblem, k: int, solver: str = "auto") -> None:
    ref = _ranked_reference(p)
    r = kbest(p, k, solver)
    got = [s.objective for s in r]
    want = ref[:k]
    if p.maximize:
        want = [-v for v in want]
    assert got == pytest.approx(want, abs=1e-9)
    assert len(r) == min(k, len(ref))
    assert r.exhausted == (len(ref) <= k)
    seen = set()
    for rank, s in enumerate(r, 1):
        assert p.violations(s.selected) is None
        assert p.value_of(s.selected) == pytest.approx(s.objective)
        key = tuple(s.selected.tolist())
        assert key not in seen
        seen.add(key)
        assert s.info["rank"] == rank


@settings(max_examples=120, deadline=None)
@given(two_d_cases(), st.integers(1, 30))
def test_kbest_2d_equals_enumeration(case, k):
    C, rm, cm = case
    _check(AssignmentProblem.two_d(C, rm, cm), k)


@settings(max_examples=40, deadline=None)
@given(problems(("square", "rect", "miss")), st.integers(1, 12))
def test_kbest_2d_candidate_list_path_with_highs(p, k):
    _check(AssignmentProblem.sparse(p.sizes, p.tuples, p.costs), k, "highs")


@settings(max_examples=25, deadline=None)
@given(problems(("sd", "axial3")), st.integers(1, 15))
def test_kbest_sd_equals_enumeration(p, k):
    _check(p, k, "highs")


@pytest.mark.parametrize("seed", range(4))
def test_kbest_sd_auto_uses_the_exact_sd_back_end(seed):
    p = random_problem(np.random.default_rng(seed), "sd", sizes=(3, 3, 2))
    _check(p, 8, "auto")


def test_kbest_returns_all_when_k_exceeds_the_count_and_says_so():
    p = AssignmentProblem.dense(np.arange(9.0).reshape(3, 3))
    r = kbest(p, 100)
    assert len(r) == 6 and r.exhausted and r.to_dict()["found"] == 6
    assert not kbest(p, 3).exhausted
    assert kbest(p, 6).exhausted


def test_kbest_maximize_ranks_highest_score_first():
    S = np.random.default_rng(1).random((3, 4))
    r = kbest(AssignmentProblem.two_d(S, 0.2, 0.1, maximize=True), 5)
    assert r.objectives == sorted(r.objectives, reverse=True)
    _check(AssignmentProblem.two_d(S, 0.2, 0.1, maximize=True), 7)


def test_kbest_ties_are_deterministic():
    p = AssignmentProblem.dense(np.ones((3, 3)))
    a = [s.selected.tolist() for s in kbest(p, 6)]
    assert a == [s.selected.tolist() for s in kbest(p, 6)] and a == sorted(a)


def test_kbest_infeasible_and_bad_k():
    p = AssignmentProblem.dense([[1.0, np.inf], [np.inf, np.inf]])
    r = kbest(p, 3)
    assert len(r) == 0 and r.exhausted
    with pytest.raises(InvalidProblemError, match="k must be"):
        kbest(p, 0)


def test_cli_solve_kbest_text_and_json(capsys):
    import json
    from pathlib import Path

    from assocopt.cli import main
    from assocopt.io import read_instance

    f = Path(__file__).resolve().parents[1] / "instances" / "example-2d-miss.json"
    assert main(["solve", str(f), "--kbest", "3"]) == 0
    text = capsys.readouterr().out
    assert "kbest      3 of 3 requested" in text
    assert main(["solve", str(f), "--kbest", "3", "--json"]) == 0
    rec = json.loads(capsys.readouterr().out)
    want = _ranked_reference(read_instance(f))[:3]
    assert [s["objective"] for s in rec["solutions"]] == pytest.approx(want)
    assert rec["found"] == 3 and rec["exhausted"] is False
    assert main(["solve", str(f), "--kbest", "2", "--relax", "lp"]) == 2
