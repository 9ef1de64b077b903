"""The user's workflow on the command line: compare, validate, export, generate, convert,
instances, reproduce -- output, exit codes, and one-line errors on bad input."""

from __future__ import annotations

import csv
import io
import json
import math
import sys
import types
from pathlib import Path

import numpy as np
import pytest

from assocopt import AssignmentProblem, solve
from assocopt.cli import (EXIT_BAD_INPUT, EXIT_INFEASIBLE, EXIT_INTERNAL, EXIT_OK, main)
from assocopt.io import export_model, solve_model_file, write_public
from assocopt.workflow.generate import catalogue, generate, write_index
from assocopt.io import read_instance, write_instance
from assocopt.solvers import registered

ROOT = Path(__file__).resolve().parents[1]
INSTANCES = ROOT / "instances"
STORED = sorted(INSTANCES.glob("*.json"))
SHARED = Path(__file__).resolve().parents[2] / "shared" / "ap_instances"

HEADER = '{"format": "assocopt-instance", '
BAD_FILES = {
    "truncated": HEADER + '"version": 1, "kind": "dense", "costs": [[1, 2], [3',
    "wrong-version": HEADER + '"version": 2, "kind": "dense", "costs": [[1, 2], [3, 4]]}',
    "nan-cost": HEADER + '"version": 1, "kind": "dense", "costs": [[NaN, 2], [3, 4]]}',
    "negative-size": HEADER + '"version": 1, "kind": "sparse", "sizes": [2, -1], '
                              '"tuples": [[1, 0]], "costs": [1]}',
}
BAD_FRAGMENTS = {"truncated": "invalid JSON", "wrong-version": "version 2 is newer",
                 "nan-cost": "costs[0][0] is NaN",
                 "negative-size": "sizes must be non-negative"}
INFEASIBLE = HEADER + ('"version": 1, "kind": "sparse", "sizes": [2, 2], '
                       '"tuples": [[1, 1], [2, 1]], "costs": [1, 2]}')


def one_error_line(err: str) -> str:
    lines = err.strip().splitlines()
    assert len(lines) == 1, err
    assert lines[0].startswith("assocopt: error: ") and "Traceback" not in err
    return lines[0]


def run(capsys, *argv: str) -> tuple[int, str, str]:
    code = main([str(a) for a in argv])
    out, err = capsys.readouterr()
    return code, out, err


@pytest.fixture
def bad_file(request, tmp_path):
    f = tmp_path / f"{request.param}.json"
    f.write_text(BAD_FILES[request.param])
    return request.param, f


@pytest.fixture
def infeasible(tmp_path):
    f = tmp_path / "infeasible.json"
    f.write_text(INFEASIBLE)
    return f


# ------------------------------------------------------------------ bad input, every verb
VERBS = {
    "solve": lambda f, d: ["solve", f],
    "validate": lambda f, d: ["validate", f],
    "compare": lambda f, d: ["compare", f, "--solvers", "highs"],
    "export": lambda f, d: ["export", f, "--to", d / "m.mps"],
    "convert": lambda f, d: ["convert", f, d / "out.json"],
}


@pytest.mark.parametrize("bad_file", list(BAD_FILES), indirect=True)
@pytest.mark.parametrize("verb", list(VERBS))
def test_bad_files_exit_2_with_one_line(verb, bad_file, tmp_path, capsys):
    kind, f = bad_file
    code, out, err = run(capsys, *VERBS[verb](f, tmp_path))
    assert code == EXIT_BAD_INPUT
    assert out == ""
    line = one_error_line(err)
    assert f.name in line and BAD_FRAGMENTS[kind] in line
    assert not (tmp_path / "m.mps").exists() and not (tmp_path / "out.json").exists()


@pytest.mark.parametrize("argv, fragment", [
    (["compare", "{3d}", "--solvers", "highs,nope"], "unknown solver 'nope'"),
    (["compare", "{3d}", "--models", "highs-ilp,nope"], "unknown model 'nope'"),
    (["compare", "{3d}"], "nothing to compare"),
    (["compare", "{3d}", "--solvers", "highs", "--repeat", "0"], "repeat must be a positive"),
    (["compare", "{3d}", "--solvers", "highs,highs"], "method 'highs' given twice"),
    (["compare", "{3d}", "/no/such.json", "--solvers", "highs"], "No such file"),
    (["compare", "{3d}", "--solvers", "highs", "--json", "--csv"], "not allowed with"),
    (["validate"], "the following arguments are required: FILE"),
    (["export", "{3d}", "--to", "model.txt"], "use .mps or .lp"),
    (["export", "{3d}"], "the following arguments are required: --to"),
    (["generate", "cubic", "--seed", "1", "--out", "x.json"], "invalid choice: 'cubic'"),
    (["generate", "dense", "--out", "x.json"], "required: --seed"),
    (["generate", "dense", "--seed", "1", "--sizes=3,-2", "--out", "x.json"],
     "sizes must be positive"),
    (["generate", "dense", "--seed", "1", "--sizes", "4", "--out", "x.json"],
     "give at least 2 sizes"),
    (["generate", "dense", "--seed", "1", "--sizes", "4,a", "--out", "x.json"],
     "expected integers"),
    (["generate", "sparse", "--seed", "1", "--low", "3", "--out", "x.json"],
     "--low does not apply to the sparse generator"),
    (["generate", "dense", "--seed", "-1", "--out", "x.json"], "seed must be a non-negative"),
    (["generate", "sparse", "--seed", "1", "--pd", "1.5", "--out", "x.json"],
     "pd must lie in (0, 1]"),
    (["convert", "{3d}", "out.dat"], "cannot tell the output format"),
    (["convert", "{3d}", "assign3.txt"], "orlib format holds square 2-D"),
    (["convert", "{sd}", "ap3.x.txt"], "dense axial problems only"),
    (["instances", "/no/such/folder"], "not a folder of instances"),
    (["reproduce"], "reproduce needs a NAME"),
])
def test_usage_errors_exit_2(argv, fragment, tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    argv = [a.replace("{3d}", str(INSTANCES / "example-3d.json"))
             .replace("{sd}", str(INSTANCES / "example-sd.json")) for a in argv]
    if argv[0] == "reproduce":
        _fake_reproduce(monkeypatch)
    code, out, err = run(capsys, *argv)
    assert code == EXIT_BAD_INPUT
    assert fragment in one_error_line(err)
    assert list(tmp_path.iterdir()) == []           # nothing written on bad input


def test_subprocess_new_verbs_never_show_a_traceback(tmp_path):
    import os
    import subprocess

    bad = tmp_path / "trunc.json"
    bad.write_text(BAD_FILES["truncated"])
    env = dict(os.environ, PYTHONPATH=str(ROOT) + os.pathsep + os.environ.get("PYTHONPATH", ""))
    r = subprocess.run([sys.executable, "-m", "assocopt", "validate", str(bad),
                        str(INSTANCES / "example-3d.json")],
                       capture_output=True, text=True, env=env, timeout=300)
    assert r.returncode == EXIT_BAD_INPUT and "Traceback" not in r.stderr
    assert "invalid JSON" in one_error_line(r.stderr) and r.stdout.startswith("ok  ")


def test_infeasible_solve_exit_1_validate_exit_2(infeasible, capsys):
    code, out, err = run(capsys, "solve", infeasible, "--solver", "highs")
    assert code == EXIT_INFEASIBLE and "covered by no candidate" in out
    code, out, err = run(capsys, "validate", infeasible)
    assert code == EXIT_BAD_INPUT
    assert "infeasible" in one_error_line(err) and "index 2" in err


# ------------------------------------------------------------------ compare
def test_compare_agrees_with_every_recorded_optimum(capsys):
    """The acceptance check: highs, scipy, CP-SAT and cvxpy on every stored instance."""
    solvers = [s for s in ("highs", "scipy", "ortools-cpsat", "cvxpy")
               if registered()[s].is_available()]
    code, out, err = run(capsys, "compare", *STORED, "--solvers", ",".join(solvers),
                         "--json", "--check")
    assert code == EXIT_OK, err
    rows = json.loads(out)
    assert len(rows) == len(STORED) * len(solvers)
    for r in rows:
        assert r["optimum"] is not None, r["instance"]
        assert r["status"] == "optimal" and r["agrees"] is True, r
        assert r["bound_ok"] is True and r["total_s"] >= 0


def test_compare_text_csv_and_models(tmp_path, capsys):
    files = [INSTANCES / "example-3d.json", INSTANCES / "rect-2d-miss-6x9.json"]
    code, out, err = run(capsys, "compare", *files, "--solvers", "highs,scipy-lsa,greedy",
                         "--no-progress")
    assert code == EXIT_OK and err == ""
    lines = out.splitlines()
    assert lines[0].split()[:4] == ["instance", "sizes", "method", "status"]
    assert "skipped" in out and "at most 2 axes" in out          # scipy-lsa on 3-D
    assert "match" in out and "6 runs, 6 with a recorded optimum" in out
    code, out, _ = run(capsys, "compare", *files, "--models", "highs-ilp,highs-lp",
                       "--csv", "--out", tmp_path / "t.csv")
    assert code == EXIT_OK and out == f"wrote {tmp_path / 't.csv'}: 4 rows (csv)\n"
    rows = list(csv.DictReader(io.StringIO((tmp_path / "t.csv").read_text())))
    assert [r["method"] for r in rows] == ["highs-ilp", "highs-lp"] * 2
    lp = [r for r in rows if r["method"] == "highs-lp"]
    assert all(r["formulation"] == "lp" and r["bound_ok"] == "True" for r in lp)


def test_compare_check_flags_a_wrong_record(tmp_path, capsys):
    p = read_instance(INSTANCES / "example-3d.json")
    f = tmp_path / "wrong.json"
    write_instance(p, f, optimum=4.0, optimum_source="a typo")
    code, out, err = run(capsys, "compare", f, "--solvers", "highs")
    assert code == EXIT_OK and "DIFFERS" in out and "BOUND" not in out
    code, out, err = run(capsys, "compare", f, "--solvers", "highs", "--check")
    assert code == EXIT_INTERNAL
    line = one_error_line(err)
    assert "example-3d / highs" in line and "recorded optimum 4" in line


def test_compare_keeps_going_when_a_back_end_raises(monkeypatch, capsys):
    from assocopt.solvers.baseline.greedy import GreedyBackend

    def boom(self, problem, options):
        raise RuntimeError("kaboom")
    monkeypatch.setattr(GreedyBackend, "solve", boom)
    code, out, err = run(capsys, "compare", INSTANCES / "example-3d.json", "--solvers",
                         "greedy,highs", "--json")
    assert code == EXIT_OK
    rows = {r["method"]: r for r in json.loads(out)}
    assert rows["greedy"]["status"] == "error" and "kaboom" in rows["greedy"]["message"]
    assert rows["highs"]["agrees"] is True
    code, _, err = run(capsys, "compare", INSTANCES / "example-3d.json", "--solvers",
                       "greedy", "--check")
    assert code == EXIT_INTERNAL and "kaboom" in one_error_line(err)


def test_compare_progress_bar_shows_each_run():
    from assocopt.runtime.progress import Progress

    stream = io.StringIO()
    bar = Progress(2, True, "compare", unit="run", stream=stream)
    bar.update(1, "a highs")
    bar.update(1, "b highs")
    bar.close()
    assert "compare:" in stream.getvalue() and "1/2" in stream.getvalue()
    assert "a highs" in stream.getvalue()
    assert "2/2" in stream.getvalue() and "b highs" in stream.getvalue()
    quiet = io.StringIO()
    off = Progress(2, False, "compare", stream=quiet)
    off.update(1, "x")
    off.close()
    assert quiet.getvalue() == ""


def test_compare_uses_the_shared_progress_helper(monkeypatch):
    """compare() reports through assocopt.runtime.progress.Progress, one step per run."""
    from assocopt.workflow import compare as cmp

    seen = []

    class Spy(cmp.Progress):
        def update(self, k=1, note=""):
            seen.append(note)
            super().update(k, note)

    monkeypatch.setattr(cmp, "Progress", Spy)
    p = read_instance(INSTANCES / "example-3d.json")
    cmp.compare([p], solvers=["greedy", "highs"], progress=False)
    assert len(seen) == 2 and all(n.startswith("example-3d ") for n in seen)


def test_compare_repeat_keeps_the_fastest_and_python_api():
    from assocopt.workflow.compare import compare

    p = read_instance(INSTANCES / "example-sd.json")
    res = compare([p], solvers=["highs"], repeat=3, progress=False)
    assert len(res.rows) == 1 and res.rows[0]["agrees"] is True
    assert res.to_records()[0]["instance"] == "example-sd"
    assert json.loads(res.to_json())[0]["method"] == "highs"


# ------------------------------------------------------------------ validate
def test_validate_every_stored_instance(capsys):
    code, out, err = run(capsys, "validate", *STORED)
    assert code == EXIT_OK and err == ""
    assert len(out.splitlines()) == len(STORED)
    assert all(line.startswith("ok  ") for line in out.splitlines())


def test_validate_check_optimum_and_json(tmp_path, capsys):
    p = read_instance(INSTANCES / "example-sd.json")
    wrong = tmp_path / "wrong.json"
    write_instance(p, wrong, optimum=-7.0)
    code, out, err = run(capsys, "validate", INSTANCES / "example-sd.json", wrong,
                         "--check-optimum", "--json")
    assert code == EXIT_BAD_INPUT
    good, bad = [json.loads(line) for line in out.splitlines()]
    assert good["ok"] is True and good["proven_optimum"] == -6.75
    assert bad["ok"] is False and "recorded optimum -7" in bad["error"]
    assert "wrong.json" in one_error_line(err)


def test_validate_decides_feasibility_with_highs(tmp_path, capsys):
    # every index covered, but no exact cover: rows 1 and 2 both need column 1
    f = tmp_path / "no-cover.json"
    f.write_text(HEADER + '"version": 1, "kind": "sparse", "sizes": [3, 3], '
                          '"tuples": [[1, 1], [2, 1], [3, 2], [3, 3]], "costs": [1, 2, 3, 4]}')
    g = tmp_path / "cover.json"
    g.write_text(HEADER + '"version": 1, "kind": "sparse", "sizes": [2, 2], '
                          '"tuples": [[1, 1], [2, 2], [1, 2]], "costs": [1, 2, 3]}')
    code, out, err = run(capsys, "validate", f, g)
    assert code == EXIT_BAD_INPUT
    assert "no feasible assignment" in one_error_line(err)
    assert "HiGHS found a feasible assignment" in out


# ------------------------------------------------------------------ export
ROUND_TRIP = ["example-3d.json", "example-2d-miss.json", "rect-2d-5x8.json",
              "axial-4d-4x4x4x4.json", "sd-bearing-3s.json", "sparse-4d-5x6x4x5.json"]


@pytest.mark.parametrize("suffix", [".mps", ".lp"])
@pytest.mark.parametrize("name", ROUND_TRIP)
def test_export_round_trip_through_highs(name, suffix, tmp_path, capsys):
    p = read_instance(INSTANCES / name)
    out_file = tmp_path / f"model{suffix}"
    code, out, err = run(capsys, "export", INSTANCES / name, "--to", out_file)
    assert code == EXIT_OK and err == "" and f"wrote {out_file}" in out
    assert math.isclose(solve_model_file(out_file), p.optimum, rel_tol=1e-12, abs_tol=1e-9)
    relaxed = tmp_path / f"relaxed{suffix}"
    assert run(capsys, "export", INSTANCES / name, "--to", relaxed, "--relax", "lp")[0] == 0
    lp = solve(p, "highs", relax="lp").objective
    assert math.isclose(solve_model_file(relaxed), lp, rel_tol=1e-9, abs_tol=1e-9)


def test_export_names_columns_after_tuples(tmp_path):
    p = read_instance(INSTANCES / "example-sd.json")
    info = export_model(p, tmp_path / "m.lp")
    text = (tmp_path / "m.lp").read_text()
    assert info == {"path": str(tmp_path / "m.lp"), "format": "lp", "columns": 14,
                    "rows": 7, "integer": True, "relaxation": None}
    assert "x_1_1_1" in text and "x_0_3_2" in text and "cover_1_3" in text
    export_model(p, tmp_path / "plain.mps", names=False)
    plain = (tmp_path / "plain.mps").read_text()
    assert "x_1_1_1" not in plain and " c0 " in f" {plain} ".replace("\n", " ")
    assert list(tmp_path.glob(".*")) == []          # no temporary file left behind


def test_export_refuses_an_empty_problem(tmp_path):
    from assocopt.runtime.errors import InvalidProblemError

    empty = AssignmentProblem.sparse([0, 0], np.zeros((0, 2), int), [])
    with pytest.raises(InvalidProblemError, match="nothing to export"):
        export_model(empty, tmp_path / "e.mps")


# ------------------------------------------------------------------ generate
@pytest.mark.parametrize("kind, sizes", [("dense", "4,4,4"), ("sparse", "3,4,3"),
                                         ("planted", "5,4,6")])
def test_generate_is_seeded_and_readable(kind, sizes, tmp_path, capsys):
    a, b, c = tmp_path / "a.json", tmp_path / "b.json", tmp_path / "c.json"
    for f, seed in ((a, 1), (b, 1), (c, 2)):
        code, out, err = run(capsys, "generate", kind, "--seed", seed, "--sizes", sizes,
                             "--out", f, "--prove")
        assert code == EXIT_OK and err == "" and f"wrote {f}" in out
    assert a.read_bytes() == b.read_bytes()
    assert a.read_bytes() != c.read_bytes()
    p = read_instance(a)
    assert p.sizes == tuple(int(n) for n in sizes.split(","))
    assert p.optimum == solve(p, "highs").objective
    assert "assocopt generate" in p.meta["description"]
    source = p.meta["optimum_source"]
    assert ("planted by construction" in source) == (kind == "planted")
    if kind == "sparse":
        assert (p.tuples == 0).any()                # dummies
        singles = (p.tuples > 0).sum(axis=1) == 1
        assert (p.costs[singles] == 0).all()


def test_generate_without_prove_records_no_optimum(tmp_path, capsys):
    f = tmp_path / "d.json"
    code, out, _ = run(capsys, "generate", "dense", "--seed", "3", "--out", f, "--low", "5",
                       "--high", "9")
    assert code == EXIT_OK and "no optimum recorded" in out
    p = read_instance(f)
    assert p.optimum is None and p.sizes == (5, 5, 5)
    assert p.costs.min() >= 5 and p.costs.max() <= 9


def test_planted_optimum_is_unique_by_construction():
    p = generate("planted", seed=11, sizes=(4, 4, 4), low=10, high=12)
    planted = p.costs < 10
    assert planted.sum() == 4 and p.optimum == p.costs[planted].sum()
    sol = solve(p, "bruteforce")
    assert sol.objective == p.optimum
    assert sorted(sol.selected.tolist()) == sorted(np.flatnonzero(planted).tolist())


# ------------------------------------------------------------------ convert
def test_convert_json_to_grundel_and_back(tmp_path, capsys):
    src = INSTANCES / "planted-3d-8.json"
    txt = tmp_path / "ap3.8.1.txt"
    code, out, _ = run(capsys, "convert", src, txt)
    assert code == EXIT_OK and "ap3.8.1.sol" in out
    assert (tmp_path / "ap3.8.1.sol").read_text() == "OPT: 81\n"
    back = tmp_path / "back.json"
    assert run(capsys, "convert", txt, back, "--prove")[0] == EXIT_OK
    p, q = read_instance(src), read_instance(back)
    assert np.array_equal(p.to_cost_matrix(), q.to_cost_matrix())
    assert q.optimum == 81 and "re-proved by HiGHS" in q.meta["optimum_source"]
    assert "converted from ap3.8.1.txt" in q.meta["description"]


def test_convert_public_writers_round_trip(tmp_path):
    C2 = np.array([[4.0, 1.0, 3.0], [2.0, 0.0, 5.0], [3.0, 2.0, 2.0]])
    p2 = AssignmentProblem.dense(C2)
    write_public(p2, tmp_path / "assign3.txt", "orlib")
    assert np.array_equal(read_instance(tmp_path / "assign3.txt").to_cost_matrix(), C2)
    C3 = np.arange(27, dtype=float).reshape(3, 3, 3) % 7
    write_public(AssignmentProblem.dense(C3), tmp_path / "balas-n3-instance01.txt",
                 "balas-saltzman-split")
    assert np.array_equal(read_instance(tmp_path / "balas-n3-instance01.txt")
                          .to_cost_matrix(), C3)


def test_convert_balas_saltzman_driver_file(tmp_path, capsys):
    src = SHARED / "balas_saltzman" / "BalasAndSaltzman.txt"
    if not src.is_file():
        pytest.skip("../shared/ap_instances not present")
    out_file = tmp_path / "bs.json"
    code, out, err = run(capsys, "convert", src, out_file, "--instance", "N4_P1", "--prove")
    assert code == EXIT_OK, err
    p = read_instance(out_file)
    stored = read_instance(INSTANCES / "balas-saltzman-n4-p1.json")
    assert np.array_equal(p.to_cost_matrix(), stored.to_cost_matrix())
    assert p.optimum == stored.optimum == 46


def test_convert_prove_detects_a_wrong_record(tmp_path, capsys):
    p = read_instance(INSTANCES / "example-3d.json")
    f = tmp_path / "typo.json"
    write_instance(p, f, optimum=6)
    code, out, err = run(capsys, "convert", f, tmp_path / "ap3.3.1.txt", "--prove")
    assert code == EXIT_BAD_INPUT and "recorded optimum 6" in one_error_line(err)


# ------------------------------------------------------------------ instances
def test_instances_listing_and_index_match_the_files(capsys):
    code, out, err = run(capsys, "instances", INSTANCES, "--json")
    assert code == EXIT_OK
    records = json.loads(out)
    assert [r["file"] for r in records] == [f.name for f in STORED]
    assert all(r["optimum"] is not None and r["optimum_source"] for r in records)
    with open(INSTANCES / "index.csv", newline="") as fh:
        index = list(csv.DictReader(fh))
    assert [r["file"] for r in index] == [r["file"] for r in records], \
        "instances/index.csv is stale: run  assocopt instances instances --write-index"
    for i, r in zip(index, records):
        assert float(i["optimum"]) == r["optimum"] and i["sizes"] == "x".join(map(str, r["sizes"]))
        assert i["optimum_source"] == r["optimum_source"]
    code, out, _ = run(capsys, "instances", INSTANCES)
    assert out.splitlines()[0].split()[:3] == ["file", "kind", "sizes"]
    assert "sd-bearing-3s.json" in out


def test_curated_set_covers_the_families():
    recs = {r["name"]: r for r in catalogue(INSTANCES)}
    kinds = {(r["kind"], r["ndim"]) for r in recs.values()}
    assert ("two_d", 2) in kinds and ("dense", 2) in kinds       # 2-D, with and without misses
    assert ("dense", 3) in kinds and ("dense", 4) in kinds       # axial 3-D and 4-D
    assert ("sparse", 3) in kinds                                # S-D with dummies
    assert "bearing-only" in recs["sd-bearing-3s"]["description"]
    converted = [r for r in recs.values() if "converted from" in (r["description"] or "")]
    assert len(converted) >= 2


def test_write_index(tmp_path, capsys):
    write_instance(read_instance(INSTANCES / "example-3d.json"), tmp_path / "a.json")
    code, out, _ = run(capsys, "instances", tmp_path, "--write-index")
    assert code == EXIT_OK and (tmp_path / "index.csv").is_file()
    assert write_index(tmp_path).read_text().splitlines()[1].startswith("a.json,example-3d")


# ------------------------------------------------------------------ reproduce
def _fake_reproduce(monkeypatch, calls=None):
    mod = types.ModuleType("assocopt.reproduce")

    def reproduce(name, *, runs=None, workers=None, seed=None, out=None):
        calls.append((name, runs, workers, seed, out))
        return {"out": out}
    mod.reproduce = reproduce
    mod.list_papers = lambda: [{"name": "lu2013", "title": "Lu et al. 2013", "default_runs": 1000},
                               {"name": "zhang2009", "title": "Zhang et al. 2009"}]
    monkeypatch.setitem(sys.modules, "assocopt.reproduce", mod)
    import importlib.util
    real = importlib.util.find_spec
    monkeypatch.setattr(importlib.util, "find_spec",
                        lambda n, *a: object() if n == "assocopt.reproduce" else real(n, *a))


def test_reproduce_delegates_with_the_parameters_it_accepts(monkeypatch, tmp_path, capsys):
    calls: list = []
    _fake_reproduce(monkeypatch, calls)
    code, out, err = run(capsys, "reproduce", "lu2013", "--runs", "3", "--workers", "2",
                         "--seed", "5", "--out", tmp_path, "--progress")
    assert code == EXIT_OK, err
    assert calls == [("lu2013", 3, 2, 5, str(tmp_path))]     # progress= not in its signature
    assert str(tmp_path) in out
    code, out, _ = run(capsys, "reproduce", "--list")
    assert code == EXIT_OK and out.splitlines() == ["lu2013  Lu et al. 2013 (default 1000 runs)",
                                                    "zhang2009  Zhang et al. 2009"]


def test_reproduce_list_with_the_real_module(capsys):
    pytest.importorskip("assocopt.reproduce")
    from assocopt.reproduce import list_papers

    code, out, err = run(capsys, "reproduce", "--list")
    assert code == EXIT_OK, err
    names = [line.split()[0] for line in out.splitlines()]
    assert names == [p["name"] for p in list_papers()]


def test_reproduce_without_the_module_is_one_line_exit_2(monkeypatch, capsys):
    import importlib.util
    real = importlib.util.find_spec
    monkeypatch.setattr(importlib.util, "find_spec",
                        lambda n, *a: None if n == "assocopt.reproduce" else real(n, *a))
    for argv in (["reproduce", "--list"], ["reproduce", "lu2013"]):
        code, out, err = run(capsys, *argv)
        assert code == EXIT_BAD_INPUT and out == ""
        assert "assocopt.reproduce is missing" in one_error_line(err)
