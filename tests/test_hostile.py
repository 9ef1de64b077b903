"""Hostile input, limits that hold, interrupts, dying parents and a real dask cluster.

One class per kind of attack.  Every command-line case asserts the exit code and that
stderr is ONE line naming the problem and the user's own path (never a hidden
temporary file, never a traceback).  No wall-clock assertions: a stopped solve is
recognised by its status, an interrupt by its exit code.
"""

from __future__ import annotations

import functools
import json
import math
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

from assocopt import AssignmentProblem, solve
from assocopt.cli import main
from assocopt.runtime.errors import InvalidProblemError, ProblemTooLargeError
from assocopt.workflow.generate import generate_dense
from assocopt.io import read_instance, write_instance
from assocopt.model.solution import Status
from assocopt.solvers import registered
from processes import started

ROOT = Path(__file__).resolve().parents[1]
ENV = {**os.environ, "PYTHONPATH": str(ROOT) + os.pathsep + os.environ.get("PYTHONPATH", "")}


# ------------------------------------------------------------------ helpers
def cli(capsys, *argv: str) -> tuple[int, str, str]:
    """Run the CLI in-process: ``(exit code, stdout, stderr)``."""
    code = main([str(a) for a in argv])
    out, err = capsys.readouterr()
    return code, out, err


def one_line(err: str, *words: str) -> str:
    """Assert ``err`` is one ``assocopt:`` line containing every word; return it."""
    lines = err.strip().splitlines()
    assert len(lines) == 1, f"expected one line on stderr, got {lines!r}"
    line = lines[0]
    assert line.startswith("assocopt:"), line
    assert "Traceback" not in line and "internal error" not in line, line
    for w in words:
        assert str(w) in line, f"{w!r} not in {line!r}"
    return line


def bad_input(capsys, path, *argv, words=()) -> str:
    """The CLI rejects the input: exit 2, one line naming ``path`` and ``words``."""
    code, _, err = cli(capsys, *argv)
    assert code == 2, err
    return one_line(err, str(path), *words)


def bad_file(capsys, path: Path, content: str | bytes, command: str,
             words: tuple[str, ...]) -> Path:
    """``path`` written with ``content``: ``assocopt COMMAND path`` rejects it
    (:func:`bad_input`)."""
    if isinstance(content, bytes):
        path.write_bytes(content)
    else:
        path.write_text(content)
    bad_input(capsys, path, command, path, words=words)
    return path


def json_instance(path: Path, **doc) -> Path:
    path.write_text(json.dumps({"format": "assocopt-instance", "version": 1, **doc}))
    return path


def dense_json(path: Path, costs_text: str) -> Path:
    """A dense instance whose cost array is given as raw JSON text (any literal)."""
    path.write_text('{"format": "assocopt-instance", "version": 1, "kind": "dense", '
                    f'"costs": {costs_text}}}')
    return path


@pytest.fixture(scope="module")
def hard_problem() -> AssignmentProblem:
    """Dense 3-D n = 50 with costs 1000..2000: every exact back end needs far longer
    than a fraction of a second to prove it (no cheap zero-cost optimum)."""
    return generate_dense(np.random.default_rng(5), (50, 50, 50), low=1000, high=2000)


@pytest.fixture(scope="module")
def hard_file(tmp_path_factory, hard_problem) -> Path:
    path = tmp_path_factory.mktemp("hard") / "hard50.json"
    write_instance(hard_problem, path)
    return path


# ------------------------------------------------------------------ costs
class TestCostRange:
    """|cost| <= 1e300 is accepted and solves everywhere; beyond is an error naming
    the first offending entry; non-real data is rejected."""

    def test_beyond_range_names_entry(self):
        C = np.ones((3, 3))
        C[1, 2] = 1e308
        with pytest.raises(InvalidProblemError, match=r"entry \(1, 2\) = 1e\+308.*1e\+300"):
            AssignmentProblem.dense(C)
        with pytest.raises(InvalidProblemError, match=r"costs entry 1 = -1e\+301"):
            AssignmentProblem.sparse((1, 1), [[1, 1], [1, 0]], [0.0, -1e301])

    def test_huge_python_integer(self):
        with pytest.raises(InvalidProblemError, match=r"entry \(0, 1\).*401 characters"):
            AssignmentProblem.dense([[1, 10 ** 400], [1, 1]])

    @pytest.mark.parametrize("costs, match", [
        (np.array([[1 + 2j, 1], [1, 1]]), "complex"),
        ([["1", "2"], ["3", "4"]], "strings"),
        (np.ones((2, 2), dtype=bool), "boolean"),
        ([[1, "2"], [3, 4]], "strings"),
    ])
    def test_non_real_costs(self, costs, match):
        with pytest.raises(InvalidProblemError, match=match):
            AssignmentProblem.dense(costs)

    @pytest.mark.parametrize("solver", ["highs", "scipy", "ortools-cpsat", "ortools-mip",
                                        "cvxpy", "bnb", "lagrangian-exact", "scipy-lsa",
                                        "bruteforce"])
    def test_inside_range_solves(self, solver):
        cls = registered()[solver]
        if not cls.is_available():
            pytest.skip(f"{solver} not installed")
        C = np.full((3, 3), 1e300)
        np.fill_diagonal(C, 1.0)
        sol = solve(AssignmentProblem.dense(C), solver)
        assert sol.status in (Status.OPTIMAL, Status.FEASIBLE), sol.message
        assert sol.objective == 3.0
        if sol.bound is not None:
            assert sol.bound <= 3.0
        big = solve(AssignmentProblem.dense(np.full((3, 3), 1e300)), solver)
        assert big.objective == pytest.approx(3e300, rel=1e-12)

    def test_three_d_near_range(self):
        C = np.full((3, 3, 3), 1e300)
        for i in range(3):
            C[i, i, i] = 1.0
        assert solve(AssignmentProblem.dense(C), "highs").objective == 3.0

    def test_cli_400_digit_literal(self, tmp_path, capsys):
        f = dense_json(tmp_path / "big.json", "[[1, " + "9" * 400 + "], [1, 1]]")
        bad_input(capsys, f, "solve", f, words=("costs[0][1]", "400 digits", "1e+300"))

    def test_cli_float_overflow_literal(self, tmp_path, capsys):
        f = dense_json(tmp_path / "ovf.json", "[[1, 1e999], [1, 1]]")
        bad_input(capsys, f, "solve", f, words=("1e999", "float range"))

    def test_cli_1e308(self, tmp_path, capsys):
        f = dense_json(tmp_path / "e308.json", "[[1e308, 1e308], [1e308, 1e308]]")
        bad_input(capsys, f, "solve", f, words=("1e+308", "1e+300"))


# ------------------------------------------------------------------ indices and sizes
class TestIndicesAndSizes:
    """Beyond int64, wrapped unsigned values and bookkeeping too large for memory."""

    def test_index_beyond_int64(self):
        with pytest.raises(InvalidProblemError, match=str(2 ** 70)):
            AssignmentProblem.sparse((2, 2), [[2 ** 70, 1]], [1.0])

    def test_uint64_shown_as_itself(self):
        T = np.array([[2 ** 64 - 1, 1]], dtype=np.uint64)
        with pytest.raises(InvalidProblemError, match=str(2 ** 64 - 1)) as info:
            AssignmentProblem.sparse((2, 2), T, [1.0])
        assert "-1" not in str(info.value)

    @pytest.mark.parametrize("size", [2 ** 63, 2 ** 70])
    def test_size_beyond_int64(self, size):
        with pytest.raises(InvalidProblemError, match=f"size {size} of axis 0"):
            AssignmentProblem.sparse((size, 2), [[1, 1]], [1.0])

    def test_huge_sizes_few_candidates_sparse_bookkeeping(self):
        p = AssignmentProblem.sparse((10 ** 12, 10 ** 12), [[1, 1]], [1.0])
        assert p.n_uncovered == 2 * 10 ** 12 - 2
        assert p.uncovered(limit=3) == [(0, 2), (0, 3), (0, 4)]
        sol = solve(p)
        assert sol.status is Status.INFEASIBLE and "1999999999997 more" in sol.message
        assert p.violations([0]) is not None

    def test_memory_needed_is_said(self):
        p = AssignmentProblem.sparse((10 ** 12, 10 ** 12), [[1, 1]], [1.0])
        with pytest.raises(ProblemTooLargeError, match=r"would need .* PiB of memory"):
            p.to_cost_matrix()
        with pytest.raises(ProblemTooLargeError, match=r"constraint matrix .* would need"):
            p.coverage_matrix()

    def test_cli_index_beyond_int64(self, tmp_path, capsys):
        f = json_instance(tmp_path / "idx.json", kind="sparse", sizes=[2, 2],
                          tuples=[[1, 2 ** 70]], costs=[1])
        bad_input(capsys, f, "solve", f, words=(str(2 ** 70), "out of range"))

    def test_cli_size_beyond_int64(self, tmp_path, capsys):
        f = json_instance(tmp_path / "size.json", kind="sparse", sizes=[2 ** 63, 2],
                          tuples=[[1, 1]], costs=[1])
        bad_input(capsys, f, "validate", f, words=(str(2 ** 63), "2**62"))

    def test_cli_huge_sizes_infeasible(self, tmp_path, capsys):
        f = json_instance(tmp_path / "huge.json", kind="sparse", sizes=[1e12, 1e12],
                          tuples=[[1, 1]], costs=[1])
        code, _, err = cli(capsys, "solve", f)
        assert code == 1
        one_line(err, str(f), "infeasible", "covered by no candidate")


# ------------------------------------------------------------------ deep JSON
class TestDeepJson:
    """100,000 levels of nesting anywhere: a clear error, no RecursionError."""

    @pytest.mark.parametrize("where", ["costs", "x-extension", "top"])
    def test_deep(self, tmp_path, capsys, where):
        deep = "[" * 100_000 + "]" * 100_000
        head = '{"format": "assocopt-instance", "version": 1, "kind": "dense"'
        text = {"costs": head + f', "costs": {deep}}}',
                "x-extension": head + f', "costs": [[1]], "x-mine": {{"a": {deep}}}}}',
                "top": deep}[where]
        f = tmp_path / "deep.json"
        f.write_text(text)
        bad_input(capsys, f, "validate", f, words=("nested", "100 levels"))


# ------------------------------------------------------------------ unbounded reads
class TestReadCap:
    """What is read is capped (1 GiB by default, --max-bytes or ASSOCOPT_MAX_BYTES)."""

    def test_dev_zero(self, capsys):
        if not os.path.exists("/dev/zero"):
            pytest.skip("no /dev/zero")
        bad_input(capsys, "/dev/zero", "validate", "/dev/zero", words=("not a text file",))

    def test_max_bytes_option(self, tmp_path, capsys):
        f = dense_json(tmp_path / "ok.json", "[[1, 2], [3, 4]]")
        assert cli(capsys, "validate", f)[0] == 0
        bad_input(capsys, f, "--max-bytes", "20", "validate", f,
                  words=("larger than the limit of 20 bytes", "--max-bytes",
                         "ASSOCOPT_MAX_BYTES"))
        assert "ASSOCOPT_MAX_BYTES" not in os.environ      # the option does not leak
        assert cli(capsys, "validate", f)[0] == 0

    def test_env_var(self, tmp_path, capsys, monkeypatch):
        f = dense_json(tmp_path / "ok.json", "[[1, 2], [3, 4]]")
        monkeypatch.setenv("ASSOCOPT_MAX_BYTES", "10")
        bad_input(capsys, f, "solve", f, words=("limit of 10 bytes",))

    def test_endless_text_stream(self, tmp_path, capsys):
        if not os.path.exists("/dev/zero"):
            pytest.skip("no /dev/zero")
        fifo = tmp_path / "endless.txt"
        os.mkfifo(fifo)
        with started(["sh", "-c", f"yes 1 > '{fifo}'"], stderr=subprocess.DEVNULL):
            bad_input(capsys, fifo, "--max-bytes", "100000", "validate", fifo,
                      words=("larger than the limit",))


# ------------------------------------------------------------------ detection
class TestDetection:
    """A lone number is no 1x1x1 problem."""

    def test_truncated_orlib(self, tmp_path, capsys):
        f = bad_file(capsys, tmp_path / "assign100.txt", "100\n", "validate", ("10000",))
        with pytest.raises(Exception, match="10000"):
            read_instance(f)

    def test_lone_number(self, tmp_path, capsys):
        bad_file(capsys, tmp_path / "numbers.txt", "100\n", "solve",
                 ("cannot tell the format",))

    def test_json_scalar(self, tmp_path, capsys):
        bad_file(capsys, tmp_path / "answer.json", "42\n", "validate", ("JSON object", "42"))

    def test_real_cube_still_detected(self, tmp_path):
        f = tmp_path / "cube.txt"
        f.write_text("\n".join(str(v) for v in range(8)) + "\n")
        assert read_instance(f).sizes == (2, 2, 2)


# ------------------------------------------------------------------ CLI options
class TestCliOptions:
    """Bad option values are exit 2 with one line, for solve and compare alike."""

    @pytest.fixture()
    def inst(self, tmp_path):
        return dense_json(tmp_path / "i.json", "[[1, 2], [3, 4]]")

    def test_empty_solver(self, inst, capsys):
        code, _, err = cli(capsys, "solve", inst, "--solver", "")
        assert code == 2
        one_line(err, "empty solver name")

    def test_empty_name_in_list(self, inst, capsys):
        code, _, err = cli(capsys, "compare", inst, "--solvers", "highs,")
        assert code == 2
        one_line(err, "empty name")

    @pytest.mark.parametrize("cmd", ["solve", "compare"])
    def test_negative_time_limit(self, inst, capsys, cmd):
        extra = ["--solvers", "highs"] if cmd == "compare" else []
        code, out, err = cli(capsys, cmd, inst, *extra, "--time-limit", "-1")
        assert code == 2 and out == ""
        one_line(err, "time_limit", "-1")

    def test_gap_outside_unit_interval(self, inst, capsys):
        code, _, err = cli(capsys, "solve", inst, "--gap", "2")
        assert code == 2
        one_line(err, "gap", "2")


# ------------------------------------------------------------------ user paths
class TestUserPaths:
    """Errors name the path the user gave; no temporary file survives."""

    @pytest.fixture()
    def inst(self, tmp_path):
        return dense_json(tmp_path / "i.json", "[[1, 2], [3, 4]]")

    @pytest.mark.parametrize("target", ["/nonexistent-dir/x", "/proc/x"])
    def test_write_errors_name_user_path(self, inst, capsys, target):
        cases = [("export", inst, "--to", target + ".mps"),
                 ("generate", "dense", "--seed", "1", "--out", target + ".json"),
                 ("convert", inst, target + ".json"),
                 ("solve", inst, "--out", target + ".json")]
        for argv in cases:
            code, _, err = cli(capsys, *argv)
            assert code == 2, (argv, err)
            line = one_line(err, target)
            assert "/." not in line, line          # no hidden temporary name

    def test_interrupted_export_leaves_no_temporary(self, tmp_path, hard_file):
        out_dir = tmp_path / "out"
        out_dir.mkdir()
        target = out_dir / "x.mps"
        for delay in (1.0, 2.5):
            with started([sys.executable, "-m", "assocopt", "export", hard_file,
                          "--to", target], env=ENV, stdout=subprocess.PIPE,
                         stderr=subprocess.PIPE, text=True) as proc:
                time.sleep(delay)
                proc.send_signal(signal.SIGTERM)
                _, err = proc.communicate(timeout=120)
            assert proc.returncode in (0, 130, -signal.SIGTERM, -signal.SIGINT), \
                (proc.returncode, err)
            leftovers = [p.name for p in out_dir.iterdir() if p.name.startswith(".")]
            assert leftovers == [], leftovers


# ------------------------------------------------------------------ interrupts
def _interrupt(path: Path, solver: str, after: float = 2.0) -> tuple[int, str]:
    """Start ``assocopt solve`` in a child, SIGINT it ``after`` s into the solve (the
    child gets SIGINT at its default action even if pytest runs with it ignored, and
    is killed with its process group whatever happens)."""
    code = ("import sys; from assocopt.cli import main; print('ready', flush=True); "
            f"sys.argv = ['assocopt', 'solve', {str(path)!r}, '--solver', {solver!r}]; "
            "sys.exit(main())")
    with started([sys.executable, "-c", code], env=ENV, text=True,
                 stdout=subprocess.PIPE, stderr=subprocess.PIPE) as proc:
        assert proc.stdout.readline().strip() == "ready"
        time.sleep(after)
        proc.send_signal(signal.SIGINT)
        _, err = proc.communicate(timeout=300)
    return proc.returncode, err


class TestInterrupts:
    """Ctrl-C during a long solve: exit 130, one line, never SystemError / exit 4."""

    @pytest.mark.parametrize("solver", ["bnb", "highs", "scipy", "lagrangian-exact",
                                        "ortools-cpsat"])
    def test_ctrl_c(self, hard_file, solver):
        if not registered()[solver].is_available():
            pytest.skip(f"{solver} not installed")
        code, err = _interrupt(hard_file, solver, after=1.0)
        if code == 0:
            pytest.skip(f"{solver} solved the instance before the interrupt arrived")
        lines = [ln for ln in err.strip().splitlines()
                 if not ln.startswith("assocopt: compiling")]
        assert code == 130, err
        assert lines == ["assocopt: interrupted"], err


# ------------------------------------------------------------------ limits
def _limited_backends() -> list[str]:
    return sorted(n for n, c in registered().items() if c.supports_time_limit)


class TestTimeLimits:
    """Every back end that advertises a time limit stops at it, on an instance that
    takes far longer, and returns instead of proving optimality; what it returns
    (incumbent, bound) has passed the common feasibility and bound checks."""

    @pytest.mark.parametrize("solver", _limited_backends())
    def test_stops(self, hard_problem, solver):
        if not registered()[solver].is_available():
            pytest.skip(f"{solver} not installed")
        sol = solve(hard_problem, solver, time_limit=0.2)
        assert sol.status is not Status.OPTIMAL, sol.message
        assert sol.status in (Status.TIME_LIMIT, Status.FEASIBLE), sol.message
        if sol.has_solution:
            assert hard_problem.violations(sol.selected) is None
        if sol.bound is not None and sol.objective is not None:
            assert sol.bound <= sol.objective

    def test_highs_presolve_off_under_a_limit(self, hard_problem, monkeypatch):
        """HiGHS presolve does not look at the clock (11 s under a 0.5 s limit on
        Grundel n = 50): the HiGHS-based back ends switch it off under a limit only."""
        import scipy.optimize

        seen = []
        real = scipy.optimize.milp

        def spy(*args, options=None, **kw):
            seen.append(dict(options or {}))
            return real(*args, options=options, **kw)

        monkeypatch.setattr(scipy.optimize, "milp", spy)
        small = AssignmentProblem.dense(np.arange(9.0).reshape(3, 3))
        solve(small, "scipy", time_limit=5.0, isolate=False)    # spied in this process
        solve(small, "scipy")
        solve(small, "scipy", time_limit=5.0, presolve=True, isolate=False)
        assert seen[0]["presolve"] is False and "presolve" not in seen[1]
        assert seen[2]["presolve"] is True
        assert solve(small, "highs", time_limit=5.0).info["presolve"] == "off"
        assert solve(small, "highs").info["presolve"] != "off"

    def test_bruteforce_advertises_and_honours(self, hard_problem):
        assert registered()["bruteforce"].supports_time_limit
        sol = solve(hard_problem, "bruteforce", time_limit=0.2)
        assert sol.status is Status.TIME_LIMIT and "time limit" in sol.message

    def test_cpsat_workers_recorded(self):
        if not registered()["ortools-cpsat"].is_available():
            pytest.skip("ortools not installed")
        from assocopt.solvers.milp.ortools_cpsat import DEFAULT_WORKERS

        p = AssignmentProblem.dense(np.random.default_rng(1).integers(0, 9, (4, 4)))
        sol = solve(p, "ortools-cpsat")
        assert sol.info["num_workers"] == DEFAULT_WORKERS
        assert "default" in sol.info["num_workers_source"]
        assert solve(p, "ortools-cpsat", threads=1).info["num_workers"] == 1

    def test_cli_limit_without_solution_is_exit_3_or_0(self, hard_file, capsys):
        code, out, err = cli(capsys, "solve", hard_file, "--solver", "highs",
                             "--time-limit", "0.2")
        assert code in (0, 3)
        assert "time_limit" in out
        if code == 3:
            one_line(err, "stopped by a limit")


# ------------------------------------------------------------------ processes
def _children(pid: int) -> list[int]:
    kids = []
    for entry in Path("/proc").iterdir():
        if not entry.name.isdigit():
            continue
        try:
            stat = (entry / "stat").read_text()
        except OSError:
            continue
        fields = stat[stat.rindex(")") + 2:].split()
        if int(fields[1]) == pid:
            kids.append(int(entry.name))
    return kids


def _alive(pid: int) -> bool:
    try:
        stat = Path(f"/proc/{pid}/stat").read_text()
    except OSError:
        return False
    return stat[stat.rindex(")") + 2:].split()[0] not in ("Z", "X")


@pytest.mark.skipif(not Path("/proc/self/stat").exists(), reason="needs Linux /proc")
class TestProcesses:
    """SIGKILL of ``assocopt reproduce``: its pool workers and the resource tracker exit."""

    def test_workers_exit_with_parent(self, tmp_path):
        with started([sys.executable, "-m", "assocopt", "reproduce", "zhang2009",
                      "--runs", "1000", "--workers", "2", "--out", tmp_path / "r"],
                     env=ENV, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL) as proc:
            kids: list[int] = []
            for _ in range(600):                       # until the pool is up
                kids = _children(proc.pid)
                if len(kids) >= 3 or proc.poll() is not None:
                    break
                time.sleep(0.1)
            assert len(kids) >= 3, "pool workers and resource tracker did not start"
            proc.kill()
            proc.wait()
            for _ in range(300):
                if not any(_alive(k) for k in kids):
                    break
                time.sleep(0.1)
            left = [k for k in kids if _alive(k)]
        assert left == [], "children outlived their killed parent"


# ------------------------------------------------------------------ dask
@pytest.fixture(scope="module")
def dask_cluster():
    distributed = pytest.importorskip(
        "distributed", reason="dask.distributed not installed: "
                              "pip install 'assocopt[distributed]'")
    cluster = distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                                       dashboard_address=None, silence_logs=40,
                                       env={"PYTHONPATH": ENV["PYTHONPATH"]})
    client = distributed.Client(cluster)
    try:
        yield cluster, client
    finally:
        client.close()
        cluster.close()


def _trial_numbers(folder: Path) -> dict[str, list]:
    from assocopt.experiments import ResultStore

    out = {}
    for db in sorted(folder.glob("*.sqlite")):
        with ResultStore(db) as st:
            # timings (t_*, *time*) differ between any two runs; every number else agrees
            rows = sorted((s, m, t, {k: v for k, v in r.items()
                                     if not k.startswith("t_") and "time" not in k})
                          for s, m, t, r in st.rows())
        out[db.name] = [json.dumps(r, sort_keys=True) for r in rows]
    return out


class TestDistributed:
    """A real ``LocalCluster`` (2 worker processes) runs the trials."""

    def test_reproduce_on_dask_equals_one_worker(self, dask_cluster, tmp_path, capsys,
                                                 monkeypatch):
        """Both runs with zhang2009's Table 1 enumeration capped at 100000 nodes (the
        settings carry the cap to the workers; the default 2 million cost 11 s a run)."""
        from assocopt.reproduce.zhang2009 import experiment
        monkeypatch.setitem(experiment.DEFAULTS, "enum_max_nodes", 100_000)
        cluster, _ = dask_cluster
        local, remote = tmp_path / "local", tmp_path / "dask"
        assert cli(capsys, "reproduce", "zhang2009", "--runs", "1", "--workers", "1",
                   "--out", local)[0] == 0
        assert cli(capsys, "reproduce", "zhang2009", "--runs", "1", "--scheduler",
                   cluster.scheduler_address, "--out", remote)[0] == 0
        a, b = _trial_numbers(local), _trial_numbers(remote)
        assert a and a == b

    @pytest.mark.fixture_children
    def test_killed_worker_loses_no_trial(self, dask_cluster, tmp_path):
        from assocopt.experiments import Experiment, ResultStore, _demo_trial, run_experiment

        _, client = dask_cluster
        exp = Experiment("kill", [{"mu": 0.0, "sleep": 0.05}, {"mu": 1.0, "sleep": 0.05}],
                         ["a", "b"], _demo_trial, runs=30, seed=3)
        ref = tmp_path / "ref.sqlite"
        run_experiment(exp, ref)
        pids = client.run(os.getpid)
        victim = sorted(pids.values())[0]

        import threading

        killed_at: list[float] = []

        def kill_later():
            time.sleep(0.8)
            os.kill(victim, signal.SIGKILL)
            killed_at.append(time.perf_counter())

        killer = threading.Thread(target=kill_later)
        killer.start()
        out = tmp_path / "dask.sqlite"
        res = run_experiment(exp, out, executor=client, chunk_size=1)
        finished = time.perf_counter()
        killer.join()
        assert killed_at and killed_at[0] < finished, "the worker was not killed mid-run"
        assert victim not in client.run(os.getpid).values()
        assert res["total"] == 60
        with ResultStore(out) as a, ResultStore(ref) as b:
            ra = sorted((s, m, t, r["x"]) for s, m, t, r in a.rows())
            rb = sorted((s, m, t, r["x"]) for s, m, t, r in b.rows())
        assert ra == rb and len(ra) == 120

    def test_scheduler_unreachable(self, capsys, tmp_path, monkeypatch):
        pytest.importorskip("distributed", reason="dask.distributed not installed")
        monkeypatch.setattr("assocopt.cli.workflow_cmds.SCHEDULER_TIMEOUT", 1.0)
        code, _, err = cli(capsys, "reproduce", "zhang2009", "--runs", "1", "--scheduler",
                           "tcp://127.0.0.1:9", "--out", tmp_path / "x")
        assert code == 2
        one_line(err, "tcp://127.0.0.1:9")


# ------------------------------------------------------------------ already handled
class TestAlreadyHandled:
    """The classes of bad input handled before this module: still one line each."""

    def test_truncated(self, tmp_path, capsys):
        bad_file(capsys, tmp_path / "ap3.2.1.txt", "3\n2 2 2\n1 2 3\n", "solve",
                 ("expected 8 costs, found 3",))

    def test_garbled(self, tmp_path, capsys):
        bad_file(capsys, tmp_path / "garbled.txt", b"\x89PNG\r\n\x1a junk \xff\xfe", "solve",
                 ("not a UTF-8 text file",))

    def test_garbled_token(self, tmp_path, capsys):
        bad_file(capsys, tmp_path / "tok.txt", "3\n2 2 2\n1 2 3 4 5 6 seven 8\n", "validate",
                 ("seven",))

    def test_wrong_version(self, tmp_path, capsys):
        f = json_instance(tmp_path / "v.json", kind="dense", costs=[[1]])
        f.write_text(f.read_text().replace('"version": 1', '"version": 99'))
        bad_input(capsys, f, "solve", f, words=("version 99",))

    def test_nan(self, tmp_path, capsys):
        f = dense_json(tmp_path / "nan.json", "[[1, NaN], [1, 1]]")
        bad_input(capsys, f, "solve", f, words=("costs[0][1] is NaN",))

    def test_bad_indices(self, tmp_path, capsys):
        f = json_instance(tmp_path / "bad.json", kind="sparse", sizes=[2, 2],
                          tuples=[[3, 1]], costs=[1])
        bad_input(capsys, f, "solve", f, words=("out of range",))

    def test_infeasible(self, tmp_path, capsys):
        f = json_instance(tmp_path / "inf.json", kind="sparse", sizes=[2, 2],
                          tuples=[[1, 1]], costs=[1])
        code, _, err = cli(capsys, "solve", f)
        assert code == 1
        one_line(err, str(f), "infeasible")
        bad_input(capsys, f, "validate", f, words=("infeasible",))

    def test_unknown_names(self, tmp_path, capsys):
        f = dense_json(tmp_path / "i.json", "[[1, 2], [3, 4]]")
        for argv, word in ((("--solver", "nope"), "unknown solver 'nope'"),
                           (("--model", "nope"), "unknown model 'nope'")):
            code, _, err = cli(capsys, "solve", f, *argv)
            assert code == 2
            one_line(err, word)

    def test_bad_toml(self, tmp_path, capsys):
        f = dense_json(tmp_path / "i.json", "[[1, 2], [3, 4]]")
        m = tmp_path / "broken.toml"
        m.write_text("name = [unclosed\n")
        code, _, err = cli(capsys, "solve", f, "--model", m)
        assert code == 2
        one_line(err, str(m), "TOML")


def test_math_is_exact_for_power_of_two_scaling():
    """Scaling huge costs by a power of two keeps the optimum's objective exact."""
    rng = np.random.default_rng(0)
    C = rng.integers(1, 100, (4, 4)).astype(float) * 2.0 ** 900
    p = AssignmentProblem.dense(C)
    sol = solve(p, "highs")
    ref = solve(AssignmentProblem.dense(C / 2.0 ** 900), "scipy-lsa")
    assert sol.objective == ref.objective * 2.0 ** 900
    assert math.isfinite(sol.bound) and sol.bound <= sol.objective
    assert sol.info["cost_scale"] > 1


# ------------------------------------------------------------------ API edge inputs
class TestRankingEdgeInputs:
    """kbest / marginals on awkward but legal inputs: a right answer or a clear error."""

    def test_kbest_rejects_relax_by_name(self):
        from assocopt import kbest

        p = AssignmentProblem.dense(np.random.default_rng(3).random((3, 3, 3)))
        with pytest.raises(InvalidProblemError, match="relax='lp' is not supported"):
            kbest(p, 2, solver="highs", relax="lp")

    def test_marginals_temperature_numpy_scalar_and_bool(self):
        from assocopt import marginals

        p = AssignmentProblem.two_d([[0.0, 5.0]], 1.0, 1.0)
        a = marginals(p, k=5, temperature=np.float32(0.5))
        b = marginals(p, k=5, temperature=0.5)
        assert np.allclose(a.candidate, b.candidate)
        for bad in (True, "1", 0.0, -1.0, math.inf, math.nan):
            with pytest.raises(InvalidProblemError, match="temperature must be a positive"):
                marginals(p, temperature=bad)

    @pytest.mark.parametrize("k", [0, -1, 1.5, True, math.inf])
    def test_kbest_bad_k(self, k):
        from assocopt import kbest

        with pytest.raises(InvalidProblemError, match="k must be a positive integer"):
            kbest(AssignmentProblem.dense([[1.0]]), k)

    def test_kbest_degenerate_shapes(self):
        from assocopt import kbest

        one = kbest(AssignmentProblem.dense([[3.0]]), 10**30)
        assert one.objectives == [3.0] and one.exhausted
        empty = kbest(AssignmentProblem.two_d(np.zeros((0, 3)), 1.0, 2.0), 3)
        assert empty.objectives == [6.0] and empty.exhausted
        row = kbest(AssignmentProblem.dense(np.arange(50.0)[None, :]), 5)
        assert row.objectives == [0.0, 1.0, 2.0, 3.0, 4.0]
        col = kbest(AssignmentProblem.dense(np.arange(50, dtype=np.int32)[:, None]), 60)
        assert col.objectives == [float(v) for v in range(50)] and col.exhausted
        none = kbest(AssignmentProblem.dense([[math.inf, 1.0], [math.inf, 2.0]]), 3)
        assert len(none) == 0 and none.exhausted

    def test_kbest_takes_the_name_it_reports(self, capsys):
        from assocopt import kbest
        from assocopt.runtime.errors import SolverCapabilityError

        p = AssignmentProblem.two_d([[1.0, 2.0], [3.0, 1.0]], 2.0, 2.0)
        r = kbest(p, 4)
        assert r.solver == "murty2d"
        assert kbest(p, 4, solver="murty2d").objectives == r.objectives
        with pytest.raises(SolverCapabilityError, match="2-D problems only"):
            kbest(AssignmentProblem.dense(np.ones((2, 2, 2))), 2, solver="murty2d")
        code, out, err = cli(capsys, "solve", ROOT / "instances" / "example-3d.json",
                             "--kbest", "2", "--solver", "murty2d")
        assert code == 2 and len(err.strip().splitlines()) == 1 and "2-D" in err

    def test_marginals_enumerate_too_large_points_to_kbest(self, monkeypatch):
        """The node cap lowered to 20000 (the default 2 million costs 15 s of search
        to reach; the error path is the same)."""
        from assocopt import marginals
        from assocopt.solvers.baseline import bruteforce

        capped = functools.partial(bruteforce.enumerate_solutions, max_nodes=20_000)
        monkeypatch.setattr(bruteforce, "enumerate_solutions", capped)
        p = AssignmentProblem.dense(np.random.default_rng(0).random((30, 30)))
        with pytest.raises(ProblemTooLargeError, match="use method='kbest'"):
            marginals(p, method="enumerate")

    @pytest.mark.parametrize("extra, needle", [
        (["--kbest", "0"], "--kbest must be a positive integer, got 0"),
        (["--kbest", "-3"], "--kbest must be a positive integer, got -3"),
        (["--kbest", "x"], "--kbest: invalid int value"),
        (["--kbest", "2", "--solver", "greedy"], "kbest needs an exact solver"),
        (["--kbest", "2", "--solver", "no-such"], "unknown solver 'no-such'"),
        (["--kbest", "2", "--time-limit", "5"], "--kbest does not combine with --time-limit"),
        (["--kbest", "2", "--model", "highs-ilp"], "--kbest does not combine with --model"),
    ])
    def test_cli_kbest_bad_arguments(self, capsys, extra, needle):
        code, out, err = cli(capsys, "solve", ROOT / "instances" / "example-2d-miss.json",
                             *extra)
        assert code == 2 and len(err.strip().splitlines()) == 1, err
        assert needle in err and "Traceback" not in err

    def test_cli_kbest_huge_k_lists_every_solution(self, capsys):
        code, out, _ = cli(capsys, "solve", ROOT / "instances" / "example-2d-miss.json",
                           "--kbest", str(10**25), "--json")
        rec = json.loads(out)
        assert code == 0 and rec["exhausted"] and rec["found"] == len(rec["solutions"])
        objs = [s["objective"] for s in rec["solutions"]]
        assert objs == sorted(objs) and objs[0] == -6
        from assocopt.solvers.baseline.bruteforce import enumerate_solutions

        problem = read_instance(ROOT / "instances" / "example-2d-miss.json")
        assert rec["found"] == sum(1 for _ in enumerate_solutions(problem))

    def test_cli_kbest_help_lists_exactly_the_refused_options(self, capsys):
        import re

        code, out, _ = cli(capsys, "solve", "--help")
        assert code == 0
        text = " ".join(out.split())
        listed = re.search(r"--kbest K .*?not with (.*?--out)", text).group(1)
        flags = re.findall(r"--[a-z-]+", listed)
        assert len(flags) == 6
        values = {"--model": "highs-ilp", "--relax": "lp", "--time-limit": "5",
                  "--gap": "0.1", "--threads": "1", "--out": "x.json"}
        for flag in flags:
            code, _, err = cli(capsys, "solve", ROOT / "instances" / "example-3d.json",
                               "--kbest", "2", flag, values[flag])
            assert code == 2 and f"--kbest does not combine with {flag}" in err


@pytest.mark.parametrize("solver", ["highs", "scipy", "cvxpy", "ortools-mip"])
def test_big_m_cost_keeps_highs_optimal_and_bound_valid(solver):
    """A big-M "forbidden" cost no longer drowns the ordinary ones (tests/test_scaling.py
    has the general check)."""
    C = np.random.default_rng(0).integers(0, 10, (4, 4)).astype(float)
    C[0, 0] = 1e20                                    # "forbidden" written as big-M
    p = AssignmentProblem.dense(C)
    best = solve(p, "bruteforce").objective
    sol = solve(p, solver)
    assert sol.bound is None or sol.bound <= best + 1e-9
    assert sol.status is not Status.OPTIMAL or sol.objective == best
