"""Fast start: what ``import assocopt``, the registry and a CLI solve load, and the
start-up benchmark's docs page.  No timing is asserted here (the benchmark measures
it, benchmarks/startup.py); these tests check which modules get imported, in a fresh
interpreter each."""

from __future__ import annotations

import importlib.util
import json
from pathlib import Path

import pytest

from conftest import fresh_python, load_script

ROOT = Path(__file__).resolve().parents[1]
HEAVY = ("scipy.sparse", "scipy.optimize", "numba", "highspy", "ortools", "cvxpy",
         "matplotlib")


def _loaded(code: str, cwd: Path = ROOT) -> set[str]:
    """Module names loaded after running ``code`` in a fresh interpreter."""
    out = fresh_python(code + "\nimport sys, json\nprint(json.dumps(sorted(sys.modules)))",
                       cwd=cwd)
    return set(json.loads(out.splitlines()[-1]))


def _heavy(mods: set[str]) -> list[str]:
    return sorted(m for m in HEAVY if m in mods)


def test_import_assocopt_loads_no_heavy_package():
    mods = _loaded("import assocopt")
    assert _heavy(mods) == []
    from assocopt.solvers import BACKEND_MODULES
    assert not {f"assocopt.solvers.{m}" for m in BACKEND_MODULES.values()} & mods
    assert "assocopt.solvers.bnb.kernels" not in mods


def test_listing_back_ends_imports_none_of_their_packages():
    mods = _loaded("import assocopt.solvers as s\nnames = sorted(s.registered())\n"
                   "s.available()\nassert 'highs' in names and 'bnb' in names")
    assert _heavy(mods) == []


def test_cli_parser_and_solvers_listing_stay_light(tmp_path):
    mods = _loaded("from assocopt.cli import main\nassert main(['solvers']) == 0\n"
                   "assert main(['--help']) == 0", cwd=tmp_path)
    assert _heavy(mods) == []


def test_2d_solve_loads_only_its_back_end():
    mods = _loaded("from assocopt.cli import main\n"
                   "assert main(['solve', 'instances/example-2d-miss.json', '--solver', "
                   "'scipy-lsa']) == 0")
    assert "scipy.optimize" in mods          # linear_sum_assignment
    assert set(_heavy(mods)) <= {"scipy.optimize", "scipy.sparse"}  # scipy's own imports
    from assocopt.solvers import BACKEND_MODULES
    backends = {f"assocopt.solvers.{m}" for m in BACKEND_MODULES.values()}
    # lap.py holds the LAP engine the dense 2-D path shares with `lapjv` (numpy only;
    # lapx itself is imported only when that engine is chosen)
    assert backends & mods <= {"assocopt.solvers.twod.scipy_lsa",
                               "assocopt.solvers.twod.lap"}
    assert "assocopt.solvers.twod.scipy_lsa" in mods and "lap" not in mods


@pytest.mark.skipif(importlib.util.find_spec("numba") is None, reason="needs numba")
def test_bnb_solve_loads_numba_but_not_the_other_back_ends():
    """Compiled (``ASSOCOPT_JIT=compiled``), bnb loads numba and its kernels only."""
    mods = _loaded("import os; os.environ['ASSOCOPT_JIT'] = 'compiled'\n"
                   "from assocopt.cli import main\n"
                   "assert main(['solve', 'instances/sd-bearing-3s.json', '--solver', "
                   "'bnb']) == 0")
    assert "numba" in mods and "assocopt.solvers.kernels.driver" in mods
    for other in ("highspy", "ortools", "cvxpy", "assocopt.solvers.milp.highs",
                  "assocopt.solvers.lagrangian"):
        assert other not in mods, other


def test_a_small_bnb_solve_runs_interpreted_without_numba():
    """By default a small problem in a fresh process runs bnb's kernels as plain Python
    (kernels.tiers): numba is not even imported."""
    mods = _loaded("from assocopt.cli import main\n"
                   "assert main(['solve', 'instances/sd-bearing-3s.json', '--solver', "
                   "'bnb']) == 0")
    assert "numba" not in mods and "assocopt.solvers.kernels._plain.driver" in mods
    assert "assocopt.solvers.kernels.driver" not in mods


def test_tiny_sd_solve_from_the_cli_loads_no_compiled_kernels(capsys):
    """One small S-D problem per process: enumerated exactly, numba not imported."""
    mods = _loaded("from assocopt.cli import main\n"
                   "assert main(['solve', 'instances/example-sd.json']) == 0")
    assert _heavy(mods) == []
    assert "assocopt.solvers.baseline.bruteforce" in mods


def test_small_sd_solve_from_the_cli_loads_neither_highs_nor_numba():
    """One S-D problem above the enumeration's size in a fresh process: auto's bnb with
    its kernels interpreted (cheaper than HiGHS's import, and no numba)."""
    mods = _loaded("from assocopt.cli import main\n"
                   "assert main(['solve', 'instances/sd-bearing-3s.json']) == 0")
    assert "highspy" not in mods and "numba" not in mods
    assert "assocopt.solvers.kernels._plain.driver" in mods


def test_small_sd_solve_from_the_cli_goes_to_highs_when_compiled():
    """Compiled (``ASSOCOPT_JIT=compiled``), the one-shot route takes HiGHS: its import
    and solve are cheaper than numba's import and bnb's kernels' load."""
    if importlib.util.find_spec("highspy") is None:
        pytest.skip("needs highspy")
    mods = _loaded("import os; os.environ['ASSOCOPT_JIT'] = 'compiled'\n"
                   "from assocopt.cli import main\n"
                   "assert main(['solve', 'instances/sd-bearing-3s.json']) == 0")
    assert "highspy" in mods and "numba" not in mods
    assert "assocopt.solvers.bnb.kernels" not in mods


def test_one_shot_highs_answer_equals_auto_in_the_library(capsys):
    from assocopt import solve
    from assocopt.cli import main
    from assocopt.io import read_instance
    import assocopt.cli.one_shot as sc

    if importlib.util.find_spec("highspy") is None:
        pytest.skip("needs highspy")
    for name in ("sd-bearing-3s", "planted-3d-8", "grundel-ap3.10.1", "axial-4d-4x4x4x4",
                 "example-2d-miss", "rect-2d-5x8"):
        path = ROOT / "instances" / f"{name}.json"
        p = read_instance(path)
        interpreted = p.ndim >= 3 and sc._interpreted(p.n_candidates)
        assert main(["solve", str(path), "--json"]) == 0
        rec = json.loads(capsys.readouterr().out)
        small = p.n_candidates > sc.ONE_SHOT_CANDIDATES or p.ndim == 2
        want = "highs" if small and p.n_candidates <= sc.ONE_SHOT_HIGHS \
            and not interpreted else None
        if want:
            assert rec["solver"] == want and "HiGHS rather than" in rec["message"], name
            assert rec["info"]["one_shot"] is True
        assert rec["status"] == "optimal"
        assert rec["objective"] == pytest.approx(solve(p).objective, abs=1e-9)


def test_the_first_solve_labels_its_imports():
    """An import is no solve time: the first 2-D solve (scipy) and the first HiGHS
    solve (highspy, scipy.sparse) report it as times["import"], later ones do not."""
    code = ("import json, numpy as np, assocopt\n"
            "p = assocopt.AssignmentProblem.dense(np.arange(9.0).reshape(3, 3))\n"
            "q = assocopt.AssignmentProblem.dense(np.arange(27.0).reshape(3, 3, 3))\n"
            "t = [assocopt.solve(p).times, assocopt.solve(p).times]\n"
            "if __import__('importlib').util.find_spec('highspy'):\n"
            "    t += [assocopt.solve(q, 'highs').times, assocopt.solve(q, 'highs').times]\n"
            "print(json.dumps(t))")
    times = json.loads(fresh_python(code).splitlines()[-1])
    for first, later in zip(times[::2], times[1::2]):
        assert first["import"] > 0 and "import" not in later
        assert first["total"] >= first["import"] + first["build"] + first["solve"]


def test_one_shot_answer_equals_auto_in_the_library(capsys):
    """The CLI's enumeration of a tiny problem gives the same optimum as auto."""
    from assocopt import solve
    from assocopt.cli import main
    from assocopt.io import read_instance

    for name in ("example-sd", "example-3d"):
        path = ROOT / "instances" / f"{name}.json"
        assert main(["solve", str(path), "--json"]) == 0
        rec = json.loads(capsys.readouterr().out)
        ref = solve(read_instance(path))
        assert rec["solver"] == "bruteforce" and rec["status"] == "optimal"
        assert rec["objective"] == pytest.approx(ref.objective, abs=1e-9)
        assert "enumerated" in rec["message"]
        assert rec["info"]["requested"] == "auto" and rec["info"]["one_shot"] is True


def test_one_shot_falls_back_when_enumeration_is_too_long(capsys, monkeypatch):
    """A search that runs out of nodes goes to auto's back end as before."""
    import assocopt.cli.one_shot as sc
    from assocopt.cli import main

    monkeypatch.setattr(sc, "ONE_SHOT_NODES", 3)
    assert main(["solve", str(ROOT / "instances" / "example-sd.json"), "--json"]) == 0
    rec = json.loads(capsys.readouterr().out)
    assert rec["solver"] != "bruteforce" and rec["status"] == "optimal"
    # --solver always means that back end
    monkeypatch.undo()
    assert main(["solve", str(ROOT / "instances" / "example-sd.json"), "--json",
                 "--solver", "highs"]) == 0
    assert json.loads(capsys.readouterr().out)["solver"] == "highs"


def test_solvers_are_reachable_as_attributes():
    """The parts of ``assocopt.solvers`` (``s.milp``, ``s.bnb``, ...) work as attribute
    paths, imported on first access."""
    import assocopt.solvers as s
    assert s.milp.__name__ == "assocopt.solvers.milp" and s.twod.__doc__
    assert s.get_backend("bnb").__module__ == "assocopt.solvers.bnb.backend"
    assert s.get_backend("scipy-lsa").__module__ == "assocopt.solvers.twod.scipy_lsa"
    with pytest.raises(AttributeError):
        s.no_such_module  # noqa: B018
    from assocopt import UnknownSolverError
    with pytest.raises(UnknownSolverError, match="valid names: bnb, bruteforce"):
        s.get_backend("nope")


# ------------------------------------------------------------------ the docs page
def _bench():
    return load_script("benchmarks/startup.py", "startup_bench")


def test_startup_page_is_rendered_from_the_committed_measurements():
    """docs/benchmarks-startup.md is exactly what benchmarks/startup.py renders from
    the json the same run wrote.  Refresh both: python benchmarks/startup.py"""
    bench = _bench()
    data = json.loads(bench.DATA.read_text())
    assert bench.PAGE.read_text() == bench.render(data)


def test_startup_measurements_are_consistent():
    """Each ratio is the best time over the baseline's best time; best is the minimum
    of the rounds; met says whether the ratio is within the target."""
    bench = _bench()
    data = json.loads(bench.DATA.read_text())
    rows = {r["key"]: r for r in data["rows"]}
    assert set(rows) == {key for key, *_ in bench.COMMANDS}
    base = rows["baseline"]["best_s"]
    for r in rows.values():
        assert len(r["all_s"]) == data["rounds"]
        assert r["best_s"] == pytest.approx(min(r["all_s"]), abs=1e-4)
        assert r["ratio"] == pytest.approx(r["best_s"] / base, abs=2e-3)
        assert r["cpu_ratio"] == pytest.approx(r["cpu_best_s"] / rows["baseline"][
            "cpu_best_s"], abs=2e-3)
        if r["target"] is not None:
            assert r["met"] == (r["ratio"] <= r["target"])
    targets = {key: target for key, _, _, target in bench.COMMANDS}
    assert {k: r["target"] for k, r in rows.items()} == targets


def test_every_back_end_module_is_declared():
    """A back end registered by any module under assocopt/solvers is declared in
    BACKEND_MODULES (else the lazy registry would not list it until imported)."""
    code = ("import importlib, pkgutil, json\n"
            "import assocopt.solvers as s\n"
            "declared = s.names()\n"
            "for m in pkgutil.walk_packages(s.__path__, 'assocopt.solvers.'):\n"
            "    if 'kernels' not in m.name:\n"
            "        importlib.import_module(m.name)\n"
            "print(json.dumps([declared, sorted(s.registered())]))\n")
    out = fresh_python(code)
    declared, registered = json.loads(out.splitlines()[-1])
    assert declared == registered and len(declared) >= 12
