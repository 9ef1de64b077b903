"""The command line (assocopt.cli): output, JSON, exit codes, one-line errors."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import assocopt
from assocopt import Solution, Status
from assocopt.cli import (EXIT_BAD_INPUT, EXIT_INFEASIBLE, EXIT_INTERNAL, EXIT_INTERRUPTED,
                          EXIT_LIMIT, EXIT_OK, exit_code, main)

ROOT = Path(__file__).resolve().parents[1]
EXAMPLES = ROOT / "instances"
SHARED = Path(__file__).resolve().parents[2] / "shared" / "ap_instances"


def write_json(path: Path, doc: dict) -> Path:
    doc = {"format": "assocopt-instance", "version": 1, **doc}
    path.write_text(json.dumps(doc))
    return path


@pytest.fixture
def infeasible(tmp_path):
    # column 2 (index 2 of axis 1) is covered by no candidate
    return write_json(tmp_path / "infeasible.json",
                      {"kind": "sparse", "sizes": [2, 2], "tuples": [[1, 1], [2, 1]],
                       "costs": [1, 2]})


@pytest.fixture
def truncated(tmp_path):
    p = tmp_path / "ap3.3.1.txt"
    p.write_text("3\n3 3 3\n" + "1\n" * 25)
    return p


def one_error_line(err: str) -> str:
    lines = err.strip().splitlines()
    assert len(lines) == 1, err
    assert lines[0].startswith("assocopt: error: ")
    assert "Traceback" not in err
    return lines[0]


# ------------------------------------------------------------------ solve: success
def test_solve_human_3d(capsys):
    assert main(["solve", str(EXAMPLES / "example-3d.json"), "--solver", "highs"]) == EXIT_OK
    out, err = capsys.readouterr()
    assert err == ""
    assert "example-3d" in out and "3 x 3 x 3" in out
    assert "status     optimal" in out
    assert "objective  5" in out
    assert "recorded   optimum 5  (matches)" in out
    assert "highs" in out
    assert "(1, 2, 1)" in out and "(3, 3, 3)" in out
    assert "axis 0: [0 1 2]" in out and "axis 1: [1 0 2]" in out


def test_solve_json(capsys):
    assert main(["solve", str(EXAMPLES / "example-sd.json"), "--solver", "highs",
                 "--json"]) == EXIT_OK
    out, err = capsys.readouterr()
    d = json.loads(out)                     # exactly one JSON object, nothing else
    for key in ("status", "objective", "bound", "gap", "solver", "tuples", "time_s"):
        assert key in d
    assert d["status"] == "optimal" and d["solver"] == "highs"
    assert d["instance"] == "example-sd"
    assert d["optimum"] == -6.75 and d["objective"] == -6.75
    assert d["matches_recorded_optimum"] is True
    assert sorted(map(tuple, d["tuples"])) == [(0, 2, 0), (1, 1, 1), (2, 3, 2)]


def test_solve_json_without_recorded_optimum(tmp_path, capsys):
    f = write_json(tmp_path / "plain.json", {"kind": "dense", "costs": [[4, 1], [2, 3]]})
    assert main(["solve", str(f), "--solver", "highs", "--json"]) == EXIT_OK
    d = json.loads(capsys.readouterr().out)
    assert d["optimum"] is None and "matches_recorded_optimum" not in d
    assert d["objective"] == 3.0 and d["instance"] == "plain"


def test_solve_two_d_miss_and_out_file(tmp_path, capsys):
    out_file = tmp_path / "sol.json"
    assert main(["solve", str(EXAMPLES / "example-2d-miss.json"), "--solver", "highs",
                 "--out", str(out_file)]) == EXIT_OK
    out = capsys.readouterr().out
    assert "(4, 0)" in out and "(0, 5)" in out              # a missed row, a free column
    assert "axis 0: [0 1 2]" in out and "axis 1: [0 1 3]" in out
    d = json.loads(out_file.read_text())
    assert d["objective"] == -6.0 and d["instance"] == "example-2d-miss"
    assert d["matches_recorded_optimum"] is True


def test_solve_relax_lp_and_options(capsys):
    assert main(["solve", str(EXAMPLES / "example-3d.json"), "--solver", "highs",
                 "--relax", "lp", "--time-limit", "60", "--gap", "0", "--threads", "1",
                 "--json"]) == EXIT_OK
    d = json.loads(capsys.readouterr().out)
    assert d["relaxation"] == "lp" and d["objective"] <= 5.0 + 1e-9


def test_long_tuple_list_is_truncated(tmp_path, capsys):
    n = 30
    C = (np.arange(n * n).reshape(n, n) % 7).tolist()
    f = write_json(tmp_path / "big.json", {"kind": "dense", "costs": C})
    assert main(["solve", str(f), "--solver", "highs"]) == EXIT_OK
    out = capsys.readouterr().out
    assert "30 chosen" in out and "... and 10 more" in out
    assert "(10 more)]" in out


def test_solve_balas_saltzman_instance_option(tmp_path, capsys):
    text = "AP3 Test Driver\n\n"
    for p in (1, 2):
        text += f"N = 2   PROBLEM = {p}\n" + "=" * 20 + "\n" + "\n".join(str(v + p) for v in range(8)) + "\n"
    f = tmp_path / "bs.txt"
    f.write_text(text)
    assert main(["solve", str(f), "--solver", "highs", "--instance", "N2_P2", "--json"]) == EXIT_OK
    d = json.loads(capsys.readouterr().out)
    assert d["instance"] == "bs:N2_P2"
    assert main(["solve", str(f), "--solver", "highs"]) == EXIT_BAD_INPUT
    line = one_error_line(capsys.readouterr().err)
    assert "holds 2 instances" in line


def test_solve_explicit_format(tmp_path, capsys):
    f = tmp_path / "lap.dat"
    f.write_text("2\n4 1\n2 3\n")
    assert main(["solve", str(f), "--format", "orlib", "--solver", "highs", "--json"]) == EXIT_OK
    assert json.loads(capsys.readouterr().out)["objective"] == 3.0


# ------------------------------------------------------------------ solve: failures
def test_infeasible_exit_1_names_index(infeasible, capsys):
    assert main(["solve", str(infeasible), "--solver", "highs"]) == EXIT_INFEASIBLE
    out, err = capsys.readouterr()
    assert "infeasible" in out
    assert "index 2" in out and "axis 1" in out and "covered by no candidate" in out
    assert main(["solve", str(infeasible), "--solver", "highs", "--json"]) == EXIT_INFEASIBLE
    d = json.loads(capsys.readouterr().out)
    assert d["status"] == "infeasible" and d["tuples"] is None
    assert "index 2" in d["message"] and "axis 1" in d["message"]


def test_truncated_exit_2(truncated, capsys):
    assert main(["solve", str(truncated), "--solver", "highs"]) == EXIT_BAD_INPUT
    out, err = capsys.readouterr()
    assert out == ""
    line = one_error_line(err)
    assert "ap3.3.1.txt" in line and "expected 27 costs, found 25" in line


@pytest.mark.parametrize("argv, fragment", [
    (["solve", "/nonexistent/file.json"], "No such file or directory"),
    (["solve", "{examples}/example-3d.json", "--solver", "no-such-solver"], "unknown solver 'no-such-solver'"),
    (["solve", "{examples}/example-3d.json", "--solver", "highs", "--time-limit", "-1"], "time_limit must be a positive number"),
    (["solve", "{examples}/example-3d.json", "--gap", "abc"], "argument --gap: invalid float value: 'abc'"),
    (["solve", "{examples}/example-3d.json", "--relax", "sdp"], "argument --relax: invalid choice"),
    (["solve", "{examples}/example-3d.json", "--format", "csv"], "argument --format: invalid choice"),
    (["solve"], "the following arguments are required: FILE"),
    ([], "the following arguments are required: COMMAND"),
    (["frobnicate"], "invalid choice: 'frobnicate'"),
    (["solve", "{examples}/example-3d.json", "--instance", "3"], "holds one instance per file"),
])
def test_bad_input_exit_2_one_line(argv, fragment, capsys):
    argv = [a.replace("{examples}", str(EXAMPLES)) for a in argv]
    assert main(argv) == EXIT_BAD_INPUT
    out, err = capsys.readouterr()
    assert out == ""
    assert fragment in one_error_line(err)


def test_directory_argument(tmp_path, capsys):
    assert main(["solve", str(tmp_path)]) == EXIT_BAD_INPUT
    assert "is a directory" in one_error_line(capsys.readouterr().err)


def test_help_and_version(capsys):
    assert main(["--help"]) == 0
    assert "solve" in capsys.readouterr().out
    assert main(["solve", "--help"]) == 0
    assert "--time-limit" in capsys.readouterr().out
    assert main(["--version"]) == 0
    assert assocopt.__version__ in capsys.readouterr().out


# ------------------------------------------------------------------ exit code mapping
@pytest.mark.parametrize("sol, code", [
    (Solution(Status.OPTIMAL, objective=1.0, selected=np.array([0])), EXIT_OK),
    (Solution(Status.FEASIBLE, objective=1.0, selected=np.array([0])), EXIT_OK),
    (Solution(Status.TIME_LIMIT, objective=1.0, selected=np.array([0])), EXIT_OK),
    (Solution(Status.TIME_LIMIT, relaxation="lp", x=np.array([0.5, 0.5])), EXIT_OK),
    (Solution(Status.TIME_LIMIT), EXIT_LIMIT),
    (Solution(Status.NODE_LIMIT, objective=1.0, selected=np.array([0])), EXIT_OK),
    (Solution(Status.NODE_LIMIT), EXIT_LIMIT),
    (Solution(Status.INFEASIBLE, message="infeasible"), EXIT_INFEASIBLE),
    (Solution(Status.ERROR, message="boom"), EXIT_INTERNAL),
])
def test_exit_code_mapping(sol, code):
    assert exit_code(sol) == code


def _fake_solve(result):
    def fake(problem, solver="auto", **kw):
        if isinstance(result, BaseException):
            raise result
        return result
    return fake


def test_limit_without_solution_exit_3(monkeypatch, capsys):
    monkeypatch.setattr("assocopt.solving.api.solve",
                        _fake_solve(Solution(Status.TIME_LIMIT, solver="highs",
                                             message="HiGHS: Time limit reached")))
    assert main(["solve", str(EXAMPLES / "example-3d.json")]) == EXIT_LIMIT
    out, err = capsys.readouterr()
    assert "time_limit" in out
    assert "limit" in one_error_line(err)


def test_solver_error_status_exit_4(monkeypatch, capsys):
    monkeypatch.setattr("assocopt.solving.api.solve",
                        _fake_solve(Solution(Status.ERROR, solver="highs",
                                             message="back end returned\nan infeasible assignment")))
    assert main(["solve", str(EXAMPLES / "example-3d.json"), "--json"]) == EXIT_INTERNAL
    out, err = capsys.readouterr()
    assert json.loads(out)["status"] == "error"
    line = one_error_line(err)
    assert "internal error" in line and "infeasible assignment" in line


def test_unexpected_exception_exit_4(monkeypatch, capsys):
    monkeypatch.setattr("assocopt.solving.api.solve", _fake_solve(RuntimeError("kaboom\nsecond line")))
    assert main(["solve", str(EXAMPLES / "example-3d.json")]) == EXIT_INTERNAL
    line = one_error_line(capsys.readouterr().err)
    assert "internal error" in line and "RuntimeError" in line and "kaboom" in line


def test_keyboard_interrupt_exit_130(monkeypatch, capsys):
    monkeypatch.setattr("assocopt.solving.api.solve", _fake_solve(KeyboardInterrupt()))
    assert main(["solve", str(EXAMPLES / "example-3d.json")]) == EXIT_INTERRUPTED
    assert "Traceback" not in capsys.readouterr().err


# ------------------------------------------------------------------ solvers
def test_solvers_human(capsys):
    assert main(["solvers"]) == EXIT_OK
    out = capsys.readouterr().out
    header = out.splitlines()[0]
    for col in ("name", "installed", "version", "ILP", "LP", "exact", "max N", "description"):
        assert col in header
    assert any(line.startswith("highs ") for line in out.splitlines())


def test_solvers_json_lists_every_registered(capsys):
    assert main(["solvers", "--json"]) == EXIT_OK
    rows = json.loads(capsys.readouterr().out)
    names = {r["name"] for r in rows}
    assert names == set(assocopt.solvers.registered())
    highs = next(r for r in rows if r["name"] == "highs")
    assert highs["installed"] is True and highs["version"]
    assert highs["ilp"] is True and highs["lp"] is True and highs["exact"] is True
    for r in rows:
        assert set(r) >= {"name", "installed", "version", "ilp", "lp", "exact", "max_ndim",
                          "description"}


# ------------------------------------------------------------------ python -m assocopt
def _run(*args: str) -> subprocess.CompletedProcess:
    env = dict(os.environ)
    env["PYTHONPATH"] = str(ROOT) + os.pathsep + env.get("PYTHONPATH", "")
    return subprocess.run([sys.executable, "-m", "assocopt", *args], capture_output=True,
                          text=True, env=env, cwd=str(ROOT), timeout=300)


def test_subprocess_truncated_file_exit_2(truncated):
    r = _run("solve", str(truncated))
    assert r.returncode == 2
    assert "Traceback" not in r.stderr
    assert r.stdout == ""
    assert "expected 27 costs, found 25" in one_error_line(r.stderr)


def test_subprocess_solve_json():
    r = _run("solve", str(EXAMPLES / "example-3d.json"), "--solver", "highs", "--json")
    assert r.returncode == 0, r.stderr
    assert "Traceback" not in r.stderr
    d = json.loads(r.stdout)
    assert d["objective"] == 5.0 and d["matches_recorded_optimum"] is True


def test_subprocess_infeasible_exit_1(infeasible):
    r = _run("solve", str(infeasible), "--solver", "highs")
    assert r.returncode == 1
    assert "Traceback" not in r.stderr
    assert "index 2" in r.stdout and "axis 1" in r.stdout


# ------------------------------------------------------------------ public benchmark files
def test_cli_on_shared_grundel(capsys):
    f = SHARED / "grundel_ap3" / "ap3.10.1.txt"
    if not f.is_file():
        pytest.skip(f"public benchmark instances not present at {SHARED}")
    assert main(["solve", str(f), "--solver", "highs", "--json"]) == EXIT_OK
    d = json.loads(capsys.readouterr().out)
    assert d["instance"] == "ap3.10.1"
    assert d["optimum"] == d["objective"] and d["matches_recorded_optimum"] is True


# ------------------------------------------------------------------ stored instance names
@pytest.mark.parametrize("argv", [
    ["solve", "example-3d", "--kbest", "2", "--solver", "bruteforce"],
    ["validate", "example-3d"],
    ["compare", "example-3d", "--solvers", "highs"],
    ["export", "example-3d", "--to", "{tmp}/m.lp"],
    ["convert", "example-3d", "{tmp}/copy.json"],
])
def test_stored_instance_names_in_every_command(argv, tmp_path, capsys, monkeypatch):
    """A stored instance's name works wherever a FILE is taken, from any folder."""
    monkeypatch.chdir(tmp_path)
    code = main([a.replace("{tmp}", str(tmp_path)) for a in argv])
    out, err = capsys.readouterr()
    assert code == EXIT_OK, err
    assert "No such file" not in err and "example-3d" in out + "".join(
        f.read_text() for f in tmp_path.iterdir() if f.suffix == ".json")


def test_bruteforce_node_cap_is_its_own_status():
    """No time limit was given: a node cap is ``node_limit``, not ``time_limit``."""
    from assocopt.io import read_instance

    p = read_instance(EXAMPLES / "example-3d.json")
    sol = assocopt.solve(p, "bruteforce", max_nodes=1)
    assert sol.status is Status.NODE_LIMIT and "nodes" in sol.message
    assert exit_code(sol) == EXIT_LIMIT
    assert assocopt.solve(p, "bruteforce", time_limit=1e-9).status is Status.TIME_LIMIT
