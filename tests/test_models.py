"""Named models (assocopt.workflow.models): the shipped TOML files, lookup, strict validation."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from assocopt import AssignmentProblem, Status
from assocopt.cli import EXIT_BAD_INPUT, EXIT_OK, main
from assocopt.io import read_instance
from assocopt.workflow.models import (FORMULATIONS, MODEL_PATH_ENV, Model, ModelError, find_model,
                                      list_models, load_model, model_dirs)
from assocopt.solvers import registered
from assocopt.testing import assert_optimal, assert_valid_bound

ROOT = Path(__file__).resolve().parents[1]
MODELS = ROOT / "models"
PACKAGED = ROOT / "assocopt" / "data" / "models"
INSTANCES = ROOT / "instances"

REQUIRED = {"highs-ilp", "highs-lp", "scipy-milp", "scipy-lsa", "ortools-cpsat", "ortools-mip",
            "cvxpy-highs", "greedy", "bruteforce"}


def _installed(m: Model) -> bool:
    return registered()[m.solver].is_available()


def _model_param(name: str):
    m = load_model(name, check_options=False)
    return pytest.param(name, id=name, marks=pytest.mark.skipif(
        not _installed(m), reason=f"{m.solver} not installed"))


SHIPPED = sorted(p.stem for p in MODELS.glob("*.toml"))


# ------------------------------------------------------------------ the shipped files
def test_required_models_are_shipped():
    assert REQUIRED <= set(SHIPPED)
    for name in ("lagrangian", "lagrangian-exact"):
        assert (name in registered()) == (name in SHIPPED), name


def test_packaged_copies_equal_models_folder():
    """assocopt/data/models ships the models to installed users: it must equal models/.

    Fix a failure with:  cp models/*.toml assocopt/data/models/
    """
    canonical = {p.name: p.read_bytes() for p in MODELS.glob("*.toml")}
    packaged = {p.name: p.read_bytes() for p in PACKAGED.glob("*.toml")}
    assert packaged == canonical


@pytest.mark.parametrize("name", SHIPPED)
def test_shipped_model_loads_strictly(name):
    m = load_model(name)                  # back-end options checked by the back end itself
    assert m.name == name and m.formulation in FORMULATIONS
    assert m.description
    assert m.path is not None and m.path.stem == name
    json.dumps(m.to_dict())


def test_list_models_finds_every_file():
    assert [m.name for m in list_models()] == SHIPPED
    assert MODELS.resolve() in [d.resolve() for d in model_dirs()]


# ------------------------------------------------------------------ solving with models
def _instance_for(m: Model) -> AssignmentProblem:
    two_d = registered()[m.solver].max_ndim == 2
    return read_instance(INSTANCES / ("example-2d-miss.json" if two_d else "example-sd.json"))


@pytest.mark.parametrize("name", [_model_param(n) for n in SHIPPED
                                  if load_model(n, check_options=False).formulation
                                  in ("ilp", "bruteforce", "lagrangian-exact")
                                  and load_model(n, check_options=False).cost is None])
def test_exact_models_reach_the_recorded_optimum(name):
    m = load_model(name)
    p = _instance_for(m)
    sol = m.solve(p)
    assert sol.info["model"] == name and sol.solver == m.solver
    assert_optimal(p, sol)


def test_lp_and_heuristic_models():
    p = read_instance(INSTANCES / "axial-4d-4x4x4x4.json")
    lp = load_model("highs-lp").solve(p)
    assert lp.relaxation == "lp"
    assert_valid_bound(p, lp)
    g = load_model("greedy").solve(p)
    assert g.status is Status.FEASIBLE and g.objective >= p.optimum


def test_overrides_win_over_the_file_and_none_keeps_it():
    m = load_model("ortools-cpsat")
    kw = m.solve_kwargs(time_limit=5.0, mip_gap=None)
    assert kw["time_limit"] == 5.0 and kw["mip_gap"] == 0.0 and kw["scale"] == "auto"
    assert kw["relax"] is None
    assert load_model("highs-lp").solve_kwargs()["relax"] == "lp"


def test_options_are_read_only():
    m = load_model("ortools-cpsat")
    with pytest.raises(TypeError):
        m.options["scale"] = 2          # type: ignore[index]


def test_scenario_model_builds_and_solves_a_scan():
    from assocopt.tracking.scenarios.lu2013 import Lu2013

    m = load_model("lu2013-pattipati")
    assert m.cost["builder"] == "pattipati"
    scan, truth = Lu2013(n_targets=3, d=1.0).simulate(np.random.default_rng(0))
    p = m.build_problem(scan)
    sol = m.solve(p)
    assert sol.status is Status.OPTIMAL and p.ndim == 3
    with pytest.raises(ModelError, match="no \\[cost\\] table"):
        load_model("highs-ilp").build_problem(scan)


# ------------------------------------------------------------------ lookup
def test_lookup_by_path_and_by_stem_on_the_search_path(tmp_path, monkeypatch):
    f = tmp_path / "my-model.toml"
    f.write_text('formulation = "ilp"\nsolver = "highs"\n[options]\ntime_limit = 30\n')
    m = load_model(str(f))
    assert m.name == "my-model" and m.options["time_limit"] == 30.0
    with pytest.raises(ModelError, match="unknown model 'my-model'"):
        load_model("my-model")
    monkeypatch.setenv(MODEL_PATH_ENV, str(tmp_path))
    assert find_model("my-model") == f
    # the user's folder comes first: a file there shadows a shipped model
    (tmp_path / "greedy.toml").write_text('formulation = "ilp"\nsolver = "highs"\n')
    assert load_model("greedy").solver == "highs"


def test_unknown_model_lists_the_available_ones():
    with pytest.raises(ModelError, match=r"unknown model 'nope'; available: .*highs-ilp"):
        load_model("nope")
    with pytest.raises(ModelError, match=r"model file .*missing\.toml not found"):
        load_model("missing.toml")
    assert load_model("highs-ilp.toml").path == load_model("highs-ilp").path


# ------------------------------------------------------------------ strict validation
BAD = [
    ('formulation = "ilp"\nsolver = "highs"\ncolour = "red"\n', "colour: unknown key"),
    ('solver = "highs"\n', "formulation: missing"),
    ('formulation = "sdp"\nsolver = "highs"\n', "formulation: unknown value 'sdp'"),
    ('formulation = "ilp"\n', "solver: missing"),
    ('formulation = "ilp"\nsolver = 3\n', "solver: must be a string"),
    ('formulation = "ilp"\nsolver = "gurobi-direct"\n', "solver: unknown solver 'gurobi-direct'"),
    ('formulation = "lp"\nsolver = "ortools-cpsat"\n', "solver: 'ortools-cpsat' cannot solve LP"),
    ('formulation = "heuristic"\nsolver = "highs"\n', "solver: 'highs' is exact"),
    ('formulation = "ilp"\nsolver = "greedy"\n', "solver: 'greedy' is a heuristic"),
    ('formulation = "ilp"\nsolver = "bruteforce"\n', "solver: use formulation 'bruteforce'"),
    ('formulation = "ilp"\nsolver = "highs"\ndescription = 5\n', "description: must be a string"),
    ('formulation = "ilp"\nsolver = "highs"\noptions = 3\n', "options: must be a table"),
    ('formulation = "ilp"\nsolver = "highs"\n[options]\ntime_limit = -1\n',
     "options.time_limit: must be a positive number"),
    ('formulation = "ilp"\nsolver = "highs"\n[options]\ntime_limit = "fast"\n',
     "options.time_limit: must be a positive number"),
    ('formulation = "ilp"\nsolver = "highs"\n[options]\nmip_gap = 1.0\n',
     "options.mip_gap: must be a number in [0, 1)"),
    ('formulation = "ilp"\nsolver = "bnb"\n[options]\nmax_nodes = 0\n',
     "options.max_nodes: rejected by back end 'bnb'"),
    ('formulation = "ilp"\nsolver = "highs"\n[options]\nmip_gap = -0.1\n',
     "options.mip_gap: must be a number in [0, 1)"),
    ('formulation = "ilp"\nsolver = "highs"\n[options]\nthreads = 1.5\n',
     "options.threads: must be a positive integer"),
    ('formulation = "ilp"\nsolver = "highs"\n[options]\nverbose = 1\n',
     "options.verbose: must be True or False"),
    ('formulation = "ilp"\nsolver = "highs"\n[options]\nno_such_option = 1\n',
     "options.no_such_option: rejected by back end 'highs'"),
    ('formulation = "ilp"\nsolver = "ortools-cpsat"\n[options]\nscale = -3\n',
     "options.scale: rejected by back end 'ortools-cpsat'"),
    ('formulation = "ilp"\nsolver = "scipy"\n[options]\npresolve = true\nwarp = 9\n',
     "options.warp: rejected by back end 'scipy'"),
    ('formulation = "ilp"\nsolver = "highs"\n[options]\nlist = [1, 2]\n',
     "options.list: back-end options must be"),
    ('formulation = "ilp"\nsolver = "highs"\n[cost]\nbuilder = "telepathy"\n',
     "cost.builder: unknown cost builder 'telepathy'"),
    ('formulation = "ilp"\nsolver = "highs"\n[cost]\nparams = {}\n', "cost.builder: must name"),
    ('formulation = "ilp"\nsolver = "highs"\n[cost]\nbuilder = "pattipati"\nextra = 1\n',
     "cost.extra: unknown key"),
    ('formulation = "ilp"\nsolver = "highs"\n[cost]\nbuilder = "pattipati"\n'
     '[cost.params]\nsmoothing = 2\n', "cost.params.smoothing: unknown parameter"),
    ('formulation = "ilp"\nsolver = "highs"\nsolver = "scipy"\n', "invalid TOML"),
    ('formulation = "ilp\n', "invalid TOML"),
]


@pytest.mark.parametrize("text, fragment", BAD, ids=[f for _, f in BAD])
def test_bad_model_files_name_the_file_and_the_key(tmp_path, text, fragment):
    f = tmp_path / "bad-model.toml"
    f.write_text(text)
    with pytest.raises(ModelError) as info:
        load_model(str(f))
    msg = str(info.value)
    assert str(f) in msg and fragment in msg, msg
    assert "\n" not in msg


def test_option_checks_can_be_deferred(tmp_path):
    f = tmp_path / "lazy.toml"
    f.write_text('formulation = "ilp"\nsolver = "highs"\n[options]\nno_such_option = 1\n')
    m = load_model(str(f), check_options=False)       # listing stays cheap
    with pytest.raises(Exception, match="no_such_option"):
        m.solve(AssignmentProblem.dense([[1.0, 2.0], [3.0, 4.0]]))


# ------------------------------------------------------------------ CLI
def _one_line(err: str) -> str:
    lines = err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("assocopt: error: "), err
    assert "Traceback" not in err
    return lines[0]


def test_cli_solve_with_model(capsys):
    assert main(["solve", str(INSTANCES / "sd-bearing-3s.json"), "--model", "ortools-cpsat",
                 "--json"]) == EXIT_OK
    d = json.loads(capsys.readouterr().out)
    assert d["solver"] == "ortools-cpsat" and d["matches_recorded_optimum"] is True
    assert d["info"]["model"] == "ortools-cpsat"


def test_cli_model_lp_and_time_limit_override(capsys):
    assert main(["solve", str(INSTANCES / "example-3d.json"), "--model", "highs-lp",
                 "--time-limit", "30", "--json"]) == EXIT_OK
    d = json.loads(capsys.readouterr().out)
    assert d["relaxation"] == "lp" and d["objective"] <= 5 + 1e-9


def test_cli_model_by_path(tmp_path, capsys):
    f = tmp_path / "mine.toml"
    f.write_text('formulation = "ilp"\nsolver = "scipy"\n')
    assert main(["solve", str(INSTANCES / "example-3d.json"), "--model", str(f),
                 "--json"]) == EXIT_OK
    assert json.loads(capsys.readouterr().out)["solver"] == "scipy"


@pytest.mark.parametrize("argv, fragment", [
    (["--model", "no-such-model"], "unknown model 'no-such-model'"),
    (["--model", "highs-ilp", "--solver", "highs"], "give --solver or --model, not both"),
    (["--model", "highs-ilp", "--relax", "lp"], "conflicts with model 'highs-ilp'"),
    (["--model", "nowhere/x.toml"], "model file nowhere/x.toml not found"),
])
def test_cli_model_errors(argv, fragment, capsys):
    assert main(["solve", str(INSTANCES / "example-3d.json"), *argv]) == EXIT_BAD_INPUT
    out, err = capsys.readouterr()
    assert out == "" and fragment in _one_line(err)


def test_cli_bad_model_file_one_line(tmp_path, capsys):
    f = tmp_path / "broken.toml"
    f.write_text('formulation = "ilp"\nsolver = "highs"\n[options]\nthreads = 0\n')
    assert main(["solve", str(INSTANCES / "example-3d.json"), "--model", str(f)]) \
        == EXIT_BAD_INPUT
    line = _one_line(capsys.readouterr().err)
    assert "broken.toml" in line and "options.threads" in line


def test_cli_models_listing(capsys):
    assert main(["models"]) == EXIT_OK
    out = capsys.readouterr().out
    assert out.splitlines()[0].split()[:3] == ["name", "formulation", "solver"]
    assert any(line.startswith("highs-ilp ") for line in out.splitlines())
    assert main(["models", "--json"]) == EXIT_OK
    rows = json.loads(capsys.readouterr().out)
    assert {r["name"] for r in rows} == set(SHIPPED)
    scen = next(r for r in rows if r["name"] == "lu2013-pattipati")
    assert scen["cost"]["builder"] == "pattipati"
