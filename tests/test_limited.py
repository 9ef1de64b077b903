"""Time limits that hold: under a limit, HiGHS, scipy's milp, cvxpy and OR-tools solve in
a warm worker process (``assocopt.solvers.milp.limited``), reused across calls, that is
killed at the deadline or on Ctrl-C and started afresh by the next call.

No wall-clock assertions: a killed child is recognised by ``info["isolated"]`` and the
autouse fixture of conftest.py checks that no child process outlives its test.
"""

from __future__ import annotations

import signal
import subprocess
import threading
from types import SimpleNamespace

import numpy as np
import pytest

from assocopt import AssignmentProblem, solve
from assocopt.runtime.errors import InvalidProblemError
from assocopt.workflow.generate import generate_dense
from assocopt.model.solution import Status
from assocopt.solvers.milp import limited
from assocopt.solvers import registered

ISOLATED = [n for n in ("highs", "scipy", "cvxpy", "ortools-cpsat", "ortools-mip")
            if registered()[n].is_available()]


@pytest.fixture(scope="module")
def hard():
    """Dense 3-D n = 30: far more than half a second for HiGHS under a limit."""
    return generate_dense(np.random.default_rng(5), (30, 30, 30), low=1000, high=2000)


@pytest.mark.parametrize("relax", [None, "lp"])
@pytest.mark.parametrize("solver", ISOLATED)
def test_the_child_gives_the_same_answer(solver, relax):
    if relax is not None and not registered()[solver].lp:
        pytest.skip(f"{solver} solves no LP relaxation")
    costs = np.random.default_rng(1).random((4, 4, 4))
    if solver == "ortools-cpsat":          # integer costs: an exact optimum there too
        costs = np.round(100 * costs)
    p = AssignmentProblem.dense(costs)
    inside = solve(p, solver, relax=relax, time_limit=60.0, isolate=False)
    child = solve(p, solver, relax=relax, time_limit=60.0)
    assert "isolated" not in inside.info and isinstance(child.info["isolated"], float)
    assert child.status is inside.status is Status.OPTIMAL
    assert child.objective == pytest.approx(inside.objective)
    if relax is None:
        assert sorted(map(tuple, child.tuples)) == sorted(map(tuple, inside.tuples))
    else:
        np.testing.assert_allclose(child.x, inside.x, atol=1e-9)


@pytest.mark.parametrize("solver", ISOLATED)
def test_no_child_without_a_limit(solver):
    p = AssignmentProblem.dense(np.random.default_rng(1).random((3, 3)))
    assert "isolated" not in solve(p, solver).info


@pytest.mark.parametrize("solver", ISOLATED)
def test_a_child_still_running_at_the_deadline_is_killed(solver, hard, monkeypatch):
    """The kill deadline moved to half a second after the start, far before the
    solver's own limit: the child is killed and the run reports time_limit."""
    monkeypatch.setattr(limited, "kill_slack", lambda limit: 0.5 - limit)
    sol = solve(hard, solver, time_limit=60.0)
    assert sol.info["isolated"] == "killed"
    assert sol.status is Status.TIME_LIMIT and not sol.has_solution
    assert "time limit" in sol.message


@pytest.mark.parametrize("solver", ISOLATED)
def test_ctrl_c_kills_the_child(solver, hard, sigint_python, monkeypatch):
    """A real SIGINT to the main thread (what Ctrl-C sends) half a second after the
    child started: the parent stops waiting at once and kills the child, which was
    still solving (exit status -SIGKILL, not 0 after an answer).

    ``_thread.interrupt_main()`` would not do: it interrupts no system call, so the
    parent raised only once the child had finished the solve (minutes, under load)."""
    children: list[subprocess.Popen] = []
    timers: list[threading.Timer] = []

    def popen(*args, **kwargs) -> subprocess.Popen:
        proc = subprocess.Popen(*args, **kwargs)
        children.append(proc)
        timers.append(threading.Timer(0.5, signal.pthread_kill,
                                      (threading.main_thread().ident, signal.SIGINT)))
        timers[-1].start()
        return proc

    monkeypatch.setattr(limited, "subprocess", SimpleNamespace(
        Popen=popen, PIPE=subprocess.PIPE, TimeoutExpired=subprocess.TimeoutExpired))
    limited.shutdown()                    # no warm worker: this call starts one
    try:
        with pytest.raises(KeyboardInterrupt):
            solve(hard, solver, time_limit=600.0)
    finally:
        for timer in timers:
            timer.cancel()
    assert len(children) == 1 and children[0].returncode == -signal.SIGKILL


@pytest.mark.parametrize("solver", ISOLATED)
def test_the_worker_is_reused_and_restarted_after_a_kill(solver, hard, monkeypatch):
    """Calls under a limit share one warm worker (no process start per call); one
    killed at the deadline is replaced by a new one on the next call."""
    p = AssignmentProblem.dense(np.round(100 * np.random.default_rng(2).random((4, 4, 4))))
    limited.shutdown()
    started: list[subprocess.Popen] = []
    real = subprocess.Popen

    def popen(*args, **kwargs):
        started.append(real(*args, **kwargs))
        return started[-1]

    monkeypatch.setattr(limited, "subprocess", SimpleNamespace(
        Popen=popen, PIPE=subprocess.PIPE, TimeoutExpired=subprocess.TimeoutExpired))
    first = solve(p, solver, time_limit=60.0)
    again = [solve(p, solver, time_limit=1e300) for _ in range(3)]
    assert len(started) == 1
    assert first.info["isolated"] >= 0 and all(s.info["isolated"] >= 0 for s in again)
    assert {s.objective for s in again} == {first.objective}
    monkeypatch.setattr(limited, "kill_slack", lambda limit: 0.5 - limit)
    assert solve(hard, solver, time_limit=60.0).info["isolated"] == "killed"
    assert started[0].returncode == -signal.SIGKILL
    monkeypatch.undo()
    monkeypatch.setattr(limited, "subprocess", SimpleNamespace(
        Popen=popen, PIPE=subprocess.PIPE, TimeoutExpired=subprocess.TimeoutExpired))
    assert solve(p, solver, time_limit=60.0).objective == first.objective
    assert len(started) == 2 and started[1].poll() is None


def test_a_dead_idle_worker_is_replaced():
    """A warm worker that died while idle (killed from outside) is noticed and a new
    one answers: the call does not fail."""
    if "highs" not in ISOLATED:
        pytest.skip("highspy not installed")
    p = AssignmentProblem.dense(np.random.default_rng(1).random((3, 3)))
    limited.shutdown()
    ref = solve(p, "highs", time_limit=60.0).objective
    (worker,) = limited._IDLE["assocopt.solvers.milp.highs"]
    worker.proc.kill()
    worker.proc.wait()
    assert solve(p, "highs", time_limit=60.0).objective == ref


def test_a_forked_child_does_not_share_the_warm_workers():
    """A fork (a process pool) must not write to, or end, its parent's workers."""
    import os

    if "highs" not in ISOLATED:
        pytest.skip("highspy not installed")
    p = AssignmentProblem.dense(np.random.default_rng(1).random((3, 3)))
    ref = solve(p, "highs", time_limit=60.0).objective
    (worker,) = limited._IDLE["assocopt.solvers.milp.highs"]
    pid = os.fork()
    if pid == 0:                                   # the child: nothing inherited
        os._exit(0 if not limited._IDLE else 1)
    _, status = os.waitpid(pid, 0)
    assert os.waitstatus_to_exitcode(status) == 0
    assert worker.alive() and limited._IDLE["assocopt.solvers.milp.highs"] == [worker]
    assert solve(p, "highs", time_limit=60.0).objective == ref


@pytest.mark.parametrize("solver", [n for n, cls in sorted(registered().items())
                                    if cls.supports_time_limit and cls.is_available()])
def test_any_time_limit_up_to_inf_is_accepted(solver):
    costs = np.round(100 * np.random.default_rng(3).random((3, 3, 3)))
    p = AssignmentProblem.dense(costs if registered()[solver].max_ndim is None
                                else costs[0])
    ref = solve(p, "bruteforce")
    for limit in (1e300, float("inf"), 1e9):
        sol = solve(p, solver, time_limit=limit)
        assert sol.status in (Status.OPTIMAL, Status.FEASIBLE), (limit, sol.message)
        assert sol.objective == pytest.approx(ref.objective)


def test_an_error_in_the_child_is_raised_here():
    p = AssignmentProblem.dense(np.random.default_rng(1).random((3, 3)))
    if "highs" not in ISOLATED:
        pytest.skip("highspy not installed")
    with pytest.raises(InvalidProblemError, match="mip_heuristic_effort"):
        solve(p, "highs", time_limit=60.0, mip_heuristic_effort="lots")


def test_kill_slack_fits_the_tolerance():
    for limit in (0.1, 1.0, 10.0, 100.0):
        assert 0 < limit.__class__(limited.kill_slack(limit)) < max(1.0, 0.1 * limit)


def test_limits_page_and_docs_agree_with_the_committed_run():
    """docs/benchmarks-limits.md is what benchmarks/time_limits.py renders from its
    committed JSON, and the README and the guide quote its start-up figures."""
    import json
    from pathlib import Path

    from conftest import load_script, page_block

    root = Path(__file__).resolve().parents[1]
    bench = load_script("benchmarks/time_limits.py", "bench_time_limits")
    js = json.loads((root / "docs" / "benchmarks-limits.json").read_text())
    page = (root / "docs" / "benchmarks-limits.md").read_text()
    assert page_block(page, "limits") == bench.render(js).strip()
    sentence = bench.startup_sentence(js)
    for doc in ("README.md", "docs/guide.md"):
        text = " ".join((root / doc).read_text().split())
        assert sentence in text, doc
    assert {r["solver"] for r in js["runs"]} >= set(ISOLATED)


def test_the_child_exits_when_its_parent_is_killed(hard, tmp_path):
    """SIGKILL of a process solving under a limit: its solver child notices (it watches
    its parent, assocopt.runtime.parent_watch) and exits."""
    import os
    import subprocess
    import sys
    import time
    from pathlib import Path

    import psutil

    from assocopt.io import write_instance
    from processes import started

    if "highs" not in ISOLATED:
        pytest.skip("highspy not installed")
    path = tmp_path / "hard.json"
    write_instance(hard, path)
    root = Path(__file__).resolve().parents[1]
    code = ("import sys; from assocopt import solve; from assocopt.io import read_instance; "
            "p = read_instance(sys.argv[1]); print('ready', flush=True); "
            "solve(p, 'highs', time_limit=600.0)")
    env = dict(os.environ, PYTHONPATH=str(root))
    with started([sys.executable, "-c", code, path], env=env, text=True,
                 stdout=subprocess.PIPE) as proc:
        assert proc.stdout.readline().strip() == "ready"
        kids: list[psutil.Process] = []
        for _ in range(1200):                 # until the solver's child is up
            kids = psutil.Process(proc.pid).children()
            if kids or proc.poll() is not None:
                break
            time.sleep(0.05)
        assert kids, "no solver child process started"
        proc.kill()
        proc.wait()
        _, alive = psutil.wait_procs(kids, timeout=60)
        assert alive == [], "the solver's child outlived its killed parent"
