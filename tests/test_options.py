"""Declared back-end options: the parser, the CLI table, model files and the docs page."""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest

from assocopt import AssignmentProblem, solve
from assocopt.cli import main
from assocopt.solvers import Option, OptionError, get_backend, registered
from assocopt.solvers.base import options_page
from assocopt.solvers.options import COMMON_OPTIONS

DOCS = Path(__file__).resolve().parents[1] / "docs"


# ------------------------------------------------------------------ Option
@pytest.mark.parametrize("opt, good, bad", [
    (Option("n", "int", 1, "d", low=1), [1, 7, np.int64(3)], [0, -1, 1.0, True, "2", None]),
    (Option("n", "int", 0, "d", low=0), [0, 5], [-1, 2.5]),
    (Option("x", "float", 1.0, "d", low=0.0, low_open=True, high=2.0),
     [2.0, 1e-9, 1, np.float64(0.5)], [0.0, 2.0001, math.nan, True, "1", math.inf]),
    (Option("x", "float", 0.0, "d", low=0.0, high=1.0, high_open=True), [0.0, 0.99], [1.0, -0.0001]),
    (Option("g", "float", None, "d", nullable=True), [None, -math.inf, math.inf, 3], [math.nan, "x"]),
    (Option("s", "float", "auto", "d", low=0.0, low_open=True, high=math.inf, high_open=True,
            choices=("auto",)), ["auto", 10, 0.5], ["AUTO", 0, math.inf, -1]),
    (Option("b", "bool", True, "d"), [True, False, np.bool_(True)], [1, 0, "yes", None]),
    (Option("c", "choice", "a", "d", choices=("a", "b")), ["a", "b"], ["c", None, 1, [1]]),
    (Option("t", "str", "", "d"), ["", "x = 1"], [1, None]),
    (Option("d", "dict", {}, "d"), [{}, {"a": 1}], [[], "a", None]),
    (Option("k", "axes", None, "d", nullable=True), [None, (0, 2), [1, 0]],
     [(1, 1), (0,), (0, 1, 2), "01", (0.0, 1.0), (-1, 0), (True, False)]),
])
def test_option_accepts_and_rejects(opt, good, bad):
    for v in good:
        opt.check(v)
    for v in bad:
        with pytest.raises(ValueError, match=f"^must be {__import__('re').escape(opt.describe())}, got "):
            opt.check(v)


def test_option_normalises_values():
    assert Option("k", "axes", None, "d", nullable=True).check([2, 0]) == (2, 0)
    assert type(Option("n", "int", 1, "d").check(np.int32(4))) is int
    assert type(Option("x", "float", 1.0, "d").check(3)) is float


def test_option_kind_is_checked():
    with pytest.raises(ValueError, match="kind must be one of"):
        Option("n", "integer", 1, "d")


def test_bad_value_names_solver_option_and_value():
    p = AssignmentProblem.dense(np.ones((2, 2, 2)))
    with pytest.raises(OptionError, match=r"^solver 'bnb': option max_nodes must be a positive "
                                          r"integer, got 0$") as info:
        solve(p, "bnb", max_nodes=0)
    assert info.value.option == "max_nodes"
    with pytest.raises(OptionError, match=r"option init must be one of 'share', 'zero', got 'x'"):
        solve(p, "lagrangian", init="x")


def test_native_options_pass_through_and_unknown_names_do_not():
    p = AssignmentProblem.dense(np.array([[4.0, 1.0], [2.0, 3.0]]))
    sol = solve(p, "highs", presolve="off")
    assert sol.objective == 3.0 and sol.info["options"] == {"presolve": "off", "isolate": None}
    with pytest.raises(OptionError, match="it also takes any HiGHS option by name"):
        solve(p, "highs", presolv="off")
    if get_backend("ortools-cpsat").is_available():
        assert solve(p, "ortools-cpsat", max_number_of_conflicts=100).objective == 3.0
        with pytest.raises(OptionError, match="SatParameters"):
            solve(p, "ortools-cpsat", max_number_of_conflictz=100)


# ------------------------------------------------------------------ docs page
def test_docs_page_matches_the_declarations():
    page = (DOCS / "solver-options.md").read_text()
    assert page == options_page(), (
        "docs/solver-options.md is stale: python -m assocopt solvers --options all "
        "--markdown > docs/solver-options.md")


def test_docs_page_lists_every_option_of_every_back_end():
    page = options_page()
    sections = page.split("\n## ")
    for name, cls in registered().items():
        (section,) = [t for t in sections if t.startswith(f"`{name}`")]
        for o in cls.options:
            assert f"| `{o.name}` | {o.describe()} |" in section, (name, o.name)
    for o in COMMON_OPTIONS:
        assert f"| `{o.name}` | {o.describe()} |" in sections[1]


# ------------------------------------------------------------------ CLI
def test_cli_prints_a_back_ends_options(capsys):
    assert main(["solvers", "--options", "bruteforce"]) == 0
    out = capsys.readouterr().out.splitlines()
    assert out[0].startswith("options of solver 'bruteforce'")
    assert out[1].split()[:4] == ["option", "accepts", "default", "description"]
    assert out[2].split()[0] == "max_nodes" and "2000000" in out[2]


def test_cli_options_json_matches_the_declaration(capsys):
    assert main(["solvers", "--options", "lagrangian-exact", "--json"]) == 0
    d = json.loads(capsys.readouterr().out)
    cls = registered()["lagrangian-exact"]
    assert [o["name"] for o in d["options"]] == [o.name for o in cls.options]
    assert d["options"][0]["default"] == cls.options[0].default


def test_cli_markdown_is_the_docs_page(capsys):
    assert main(["solvers", "--options", "all", "--markdown"]) == 0
    assert capsys.readouterr().out == options_page()


def test_cli_unknown_back_end_for_options(capsys):
    assert main(["solvers", "--options", "nope"]) == 2
    assert "unknown solver 'nope'" in capsys.readouterr().err


# ------------------------------------------------------------------ models
def test_model_options_checked_without_a_trial_solve(tmp_path, monkeypatch):
    import assocopt.solving.api
    from assocopt.workflow.models import ModelError, load_model

    def no_solve(*a, **k):
        raise AssertionError("load_model ran a solve")
    monkeypatch.setattr(assocopt.solving.api, "solve", no_solve)
    good = tmp_path / "good.toml"
    good.write_text('formulation = "ilp"\nsolver = "bnb"\n[options]\nmax_nodes = 10\n')
    assert load_model(str(good)).options["max_nodes"] == 10
    bad = tmp_path / "bad.toml"
    bad.write_text('formulation = "ilp"\nsolver = "bnb"\n[options]\nfallback = 1\n')
    with pytest.raises(ModelError, match="options.fallback: rejected by back end 'bnb': "
                                         ".*must be True or False, got 1"):
        load_model(str(bad))


# ------------------------------------------------------------------ status rule
@pytest.mark.parametrize("status, gap, mip_gap, claim_tol, expected", [
    ("optimal", 0.0, 0.0, None, "optimal"),
    ("optimal", 0.5, 0.0, None, "optimal"),        # no tolerance asked: the claim stands
    ("optimal", 0.5, 0.0, 1e-6, "feasible"),       # ... unless its own bound says no
    ("optimal", 1e-7, 0.0, 1e-6, "optimal"),
    ("optimal", 1e-10, 0.1, None, "optimal"),      # reached gap is round-off
    ("optimal", 1e-3, 0.1, None, "feasible"),      # stopped at the requested gap
    ("optimal", None, 0.1, None, "feasible"),      # no bound: nothing proven
    ("time_limit", 0.0, 0.1, None, "time_limit"),
    ("infeasible", None, 0.0, 1e-6, "infeasible"),
])
def test_settle_optimal_is_the_one_rule(status, gap, mip_gap, claim_tol, expected):
    from assocopt import Status
    from assocopt.solvers.status import settle_optimal

    got, note = settle_optimal(Status(status), gap, mip_gap, claim_tol=claim_tol)
    assert got is Status(expected)
    assert (note != "") == (status == "optimal" and expected == "feasible")


def test_backends_map_statuses_through_tables():
    from assocopt.solvers.milp import cvxpy_backend, highs, ortools_cpsat, ortools_mip, scipy_milp

    for module in (highs, scipy_milp, ortools_cpsat, ortools_mip, cvxpy_backend):
        table = module._STATUS_TABLE
        assert table and all(isinstance(k, str) for k in table), module.__name__


# ------------------------------------------------------------------ no limit
@pytest.mark.parametrize("solver", sorted(n for n, c in registered().items()
                                          if c.supports_time_limit))
def test_infinite_time_limit_means_no_limit(solver):
    """``time_limit=inf`` is no limit (as in HiGHS), for every back end that takes one:
    the answer and the recorded options are those of ``time_limit=None``."""
    if not registered()[solver].is_available():
        pytest.skip(f"{solver} not installed")
    p = AssignmentProblem.dense(np.random.default_rng(3).random((3, 3, 3)))
    free = solve(p, solver)
    sol = solve(p, solver, time_limit=math.inf)
    assert sol.status is free.status and sol.status.value in ("optimal", "feasible")
    assert sol.objective == pytest.approx(free.objective)
    assert sol.info.get("options", {}).get("time_limit") is None
    assert sol.info.get("isolated") is None          # no child process without a limit


def test_infinite_time_limit_in_a_model_file_and_on_the_command_line(tmp_path, capsys):
    from assocopt.workflow.models import load_model

    f = tmp_path / "m.toml"
    f.write_text('formulation = "ilp"\nsolver = "highs"\n[options]\ntime_limit = inf\n')
    p = AssignmentProblem.dense(np.random.default_rng(3).random((3, 3, 3)))
    assert load_model(str(f)).solve(p).status.value == "optimal"
    inst = Path(__file__).resolve().parents[1] / "instances" / "example-3d.json"
    assert main(["solve", str(inst), "--solver", "highs", "--time-limit", "inf"]) == 0
    assert "optimal" in capsys.readouterr().out
