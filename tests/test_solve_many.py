"""``assocopt.solve_many``: one Solution per problem, the answers of ``solve``.

The small S-D problems go to ``bnb``'s batch kernel together and are checked in bulk;
every other problem goes to ``solve``.  Checked against ``solve`` one by one (and so,
through the conformance suite, against brute force) on random lists of problems of
every family, maximisation included.
"""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings, strategies as st

from assocopt import AssignmentProblem, InvalidProblemError, Status, solve, solve_many
from assocopt.testing import assert_optimal, problems


def _flip(p: AssignmentProblem) -> AssignmentProblem:
    """The same candidates as a maximisation of the negated costs."""
    return AssignmentProblem.sparse(p.sizes, p.tuples, -p.costs, maximize=True)


def _same(a, b, p):
    assert a.status is b.status, (a.message, b.message)
    if a.objective is None:
        assert b.objective is None
        return
    assert a.objective == pytest.approx(b.objective, rel=1e-9, abs=1e-9)
    assert a.maximize == b.maximize
    if a.status is Status.OPTIMAL:
        assert_optimal(p, a)
        assert a.tuples is not None and a.selected is not None


@settings(max_examples=40, deadline=None)
@given(st.lists(problems(), min_size=0, max_size=12), st.booleans())
def test_same_answers_as_solve(ps, flip):
    ps = [_flip(p) if flip and p.ndim >= 3 else p for p in ps]
    many = solve_many(ps)
    assert len(many) == len(ps)
    for p, a in zip(ps, many):
        _same(a, solve(p), p)


@settings(max_examples=15, deadline=None)
@given(st.lists(problems(("axial3", "axial4", "sd")), min_size=2, max_size=8))
def test_bnb_asked_for_and_options_go_the_same_way(ps):
    for a, p in zip(solve_many(ps, "bnb"), ps):
        _same(a, solve(p, "bnb"), p)
    for a, p in zip(solve_many(ps, "highs", time_limit=60.0), ps):
        _same(a, solve(p, "highs", time_limit=60.0), p)


def test_small_sd_problems_share_one_kernel_call():
    pytest.importorskip("numba")
    rng = np.random.default_rng(0)
    ps = [AssignmentProblem.dense(rng.random((3, 4, 3))) for _ in range(50)]
    ps.append(AssignmentProblem.dense(rng.random((3, 3))))            # 2-D: solve()
    ps.append(AssignmentProblem.sparse((2, 2, 2), [[1, 1, 1]], [1.0]))  # uncovered
    many = solve_many(ps)
    assert [s.info.get("batch", {}).get("problems") for s in many[:50]] == [50] * 50
    assert "batch" not in many[50].info and "batch" not in many[51].info
    assert many[51].status is Status.INFEASIBLE
    for p, a in zip(ps, many):
        _same(a, solve(p), p)


def test_not_a_problem_is_named():
    with pytest.raises(InvalidProblemError, match=r"problems\[1\] must be an "
                                                   "AssignmentProblem, got list"):
        solve_many([AssignmentProblem.dense([[1.0]]), [[1.0]]])


def test_one_shot_page_and_readme_agree_with_the_committed_run():
    """docs/benchmarks-one-shot.md is what benchmarks/one_shot.py renders from its
    committed JSON; the README quotes its summary; the run's own checks held."""
    import json
    from pathlib import Path

    from conftest import load_script, page_block

    root = Path(__file__).resolve().parents[1]
    bench = load_script("benchmarks/one_shot.py", "bench_one_shot")
    js = json.loads((root / "docs" / "benchmarks-one-shot.json").read_text())
    page = (root / "docs" / "benchmarks-one-shot.md").read_text()
    assert page_block(page, "one-shot") == bench.render(js).strip()
    readme = " ".join((root / "README.md").read_text().split())
    assert bench.summary_sentence(js) in readme
    assert all(r["same_answers"] for r in js["batch"])
    assert {r["instance"] for r in js["one_shot"]} == set(bench.INSTANCES)
