"""Monte Carlo runner: determinism across workers, atomic per-trial store, resume."""

from __future__ import annotations

import concurrent.futures as cf
import os
import signal
import sqlite3
import subprocess
import sys
import textwrap
import time

import numpy as np
import pytest

from assocopt.runtime.errors import AssocoptError
from processes import started
from assocopt.experiments import (Experiment, PerMethod, ResultStore, StoreMismatchError,
                                  TrialError, _demo_trial, association_metrics,
                                  run_experiment, setting_key, summarise, trial_seed)

SETTINGS = [{"mu": 0.0}, {"mu": 5.0}, {"mu": -2.5}]


def _exp(runs=6, seed=3, trial=_demo_trial, settings=SETTINGS, methods=("a", "b")):
    return Experiment("demo", settings, list(methods), trial, runs=runs, seed=seed,
                      volatile=("t",))


def _table(path, exp):
    return [(r["setting"]["mu"], r["method"], r["metric"], r["value"], r["runs"])
            for r in summarise(path, exp)]


def _raw(path):
    with ResultStore(path) as st:
        return sorted((s, m, t, d["x"]) for s, m, t, d in st.rows())


def test_seed_depends_on_setting_and_trial_only():
    a = trial_seed(1, {"x": 1, "y": 2}, 4).generate_state(4)
    b = trial_seed(1, {"y": 2, "x": 1}, 4).generate_state(4)
    assert (a == b).all()
    assert (trial_seed(1, {"x": 1, "y": 2}, 5).generate_state(4) != a).any()
    assert (trial_seed(2, {"x": 1, "y": 2}, 4).generate_state(4) != a).any()
    assert setting_key({"y": 2, "x": 1}) == '{"x":1,"y":2}'


def test_methods_of_a_trial_share_the_seed(tmp_path):
    run_experiment(_exp(runs=4), tmp_path / "r.sqlite")
    rows = _raw(tmp_path / "r.sqlite")
    a = {(s, t): x for s, m, t, x in rows if m == "a"}
    b = {(s, t): x for s, m, t, x in rows if m == "b"}
    assert all(b[k] == pytest.approx(a[k] + 1.0) for k in a)


def test_one_worker_and_two_workers_give_identical_results(tmp_path):
    e = _exp(runs=10)
    run_experiment(e, tmp_path / "w1.sqlite", workers=1)
    stats = run_experiment(e, tmp_path / "w2.sqlite", workers=2, chunk_size=3)
    assert stats == {"done": 30, "skipped": 0, "total": 30}
    assert _raw(tmp_path / "w1.sqlite") == _raw(tmp_path / "w2.sqlite")
    assert _table(tmp_path / "w1.sqlite", e) == _table(tmp_path / "w2.sqlite", e)


class _Boom:
    """Trial function interrupted (Ctrl-C) at its 8th call."""

    def __init__(self):
        self.calls = 0

    def __call__(self, setting, methods, seed):
        self.calls += 1
        if self.calls == 8:
            raise KeyboardInterrupt      # like Ctrl-C in the middle of the run
        return _demo_trial(setting, methods, seed)


def test_interrupted_run_resumes_without_losing_or_repeating(tmp_path):
    e = _exp(runs=6)
    full = tmp_path / "full.sqlite"
    run_experiment(e, full)
    part = tmp_path / "part.sqlite"
    boom = _Boom()
    with pytest.raises(KeyboardInterrupt):
        run_experiment(_exp(runs=6, trial=boom), part)
    with ResultStore(part) as st:
        assert st.count() == 7 * 2          # 7 finished trials x 2 methods, all kept
    stats = run_experiment(e, part)
    assert stats == {"done": 18 - 7, "skipped": 7, "total": 18}
    assert _raw(part) == _raw(full)
    assert _table(part, e) == _table(full, e)
    with ResultStore(part) as st:
        assert st.count() == 36             # nothing repeated


def test_failing_trial_names_setting_and_trial(tmp_path):
    def bad(setting, methods, seed):
        raise ValueError("boom")
    with pytest.raises(TrialError, match=r'trial 0 of setting \{"mu":0.0\} failed: ValueError'):
        run_experiment(_exp(trial=bad), tmp_path / "r.sqlite")


_KILL_SCRIPT = textwrap.dedent("""
    import sys
    from assocopt.experiments import Experiment, run_experiment, _demo_trial
    settings = [{"mu": 1.0, "sleep": 0.05}, {"mu": 2.0, "sleep": 0.05}]
    exp = Experiment("demo", settings, ["a", "b"], _demo_trial, runs=40, seed=9,
                     volatile=("t",))
    run_experiment(exp, sys.argv[1], chunk_size=1)
""")


def test_killed_process_resumes_to_the_same_table(tmp_path):
    """SIGKILL a run midway; the store keeps whole trials; resuming gives the same table."""
    store = tmp_path / "k.sqlite"
    env = dict(os.environ, PYTHONPATH=os.pathsep.join(
        [os.path.dirname(os.path.dirname(os.path.abspath(__file__)))] + sys.path))
    with started([sys.executable, "-c", _KILL_SCRIPT, str(store)], env=env) as proc:
        deadline = time.monotonic() + 60
        while time.monotonic() < deadline and proc.poll() is None:
            time.sleep(0.05)
            try:
                with sqlite3.connect(store) as c:
                    if c.execute("SELECT COUNT(*) FROM trials").fetchone()[0] >= 6:
                        break
            except sqlite3.OperationalError:
                pass
        assert proc.poll() is None, "the run finished before it could be killed"
        proc.send_signal(signal.SIGKILL)
        proc.wait(10)
    with ResultStore(store) as st:
        kept = st.count()
    assert 6 <= kept < 160 and kept % 2 == 0              # whole trials (both methods) only
    e = Experiment("demo", [{"mu": 1.0, "sleep": 0.05}, {"mu": 2.0, "sleep": 0.05}],
                   ["a", "b"], _demo_trial, runs=40, seed=9, volatile=("t",))
    stats = run_experiment(e, store, workers=2, chunk_size=10)
    assert stats == {"done": 80 - kept // 2, "skipped": kept // 2, "total": 80}
    ref = tmp_path / "ref.sqlite"
    run_experiment(e, ref, workers=2, chunk_size=10)
    assert _raw(store) == _raw(ref)
    assert summarise(store, e) == summarise(ref, e)


def test_store_refuses_another_seed(tmp_path):
    run_experiment(_exp(runs=2, seed=1), tmp_path / "r.sqlite")
    with pytest.raises(StoreMismatchError, match="seed=1"):
        run_experiment(_exp(runs=2, seed=2), tmp_path / "r.sqlite")


def test_more_runs_only_adds_trials_and_summary_counts_requested_runs(tmp_path):
    p = tmp_path / "r.sqlite"
    run_experiment(_exp(runs=3), p)
    stats = run_experiment(_exp(runs=5), p)
    assert stats == {"done": 6, "skipped": 9, "total": 15}
    assert {r["runs"] for r in summarise(p, _exp(runs=3))} == {3}
    assert {r["runs"] for r in summarise(p, _exp(runs=5))} == {5}
    assert all(r["metric"] != "t" for r in summarise(p, _exp(runs=5)))


def test_any_executor_with_submit_works(tmp_path):
    e = _exp(runs=4)
    run_experiment(e, tmp_path / "a.sqlite")
    with cf.ThreadPoolExecutor(2) as ex:
        run_experiment(e, tmp_path / "b.sqlite", executor=ex)
    assert _raw(tmp_path / "a.sqlite") == _raw(tmp_path / "b.sqlite")

    class Fut:                    # a future that is not a concurrent.futures.Future
        def __init__(self, fn, args):
            self.value = fn(*args)

        def done(self):
            return True

        def result(self):
            return self.value

        def cancel(self):
            return False

    class Client:                 # the dask.distributed.Client interface we rely on
        def submit(self, fn, *args):
            return Fut(fn, args)

    run_experiment(e, tmp_path / "c.sqlite", executor=Client())
    assert _raw(tmp_path / "a.sqlite") == _raw(tmp_path / "c.sqlite")


def test_per_method_adapter_and_validation():
    f = PerMethod(lambda s, m, seed: {"v": float(len(m))})
    assert f({}, ["a", "bb"], None) == {"a": {"v": 1.0}, "bb": {"v": 2.0}}
    with pytest.raises(AssocoptError, match="runs must be a positive integer"):
        _exp(runs=0)
    with pytest.raises(AssocoptError, match="settings must be distinct"):
        _exp(settings=[{"mu": 1}, {"mu": 1}])
    with pytest.raises(AssocoptError, match="workers must be a positive integer"):
        run_experiment(_exp(), ":memory:", workers=0)


def test_association_metrics_definitions():
    truth = [(1, 2, 0), (2, 1, 1)]
    part = truth + [(0, 0, 2)]
    m = association_metrics([(1, 2, 0), (2, 1, 1), (0, 0, 2)], part, truth)
    assert m == {"partition_correct": 1.0, "tuple_rate": 1.0}
    m = association_metrics([(1, 2, 0), (2, 1, 2), (0, 0, 1)], part, truth)
    assert m == {"partition_correct": 0.0, "tuple_rate": 0.5}
    assert np.isclose(association_metrics([], [], [])["tuple_rate"], 1.0)


def test_paired_differences_use_the_same_trial(tmp_path):
    from assocopt.experiments import paired_differences
    e = _exp(runs=5)
    run_experiment(e, tmp_path / "r.sqlite")
    recs = paired_differences(tmp_path / "r.sqlite", e, "x", "a")
    assert [r["method"] for r in recs] == ["b"] * 3
    for r in recs:      # b = a + 1 in every trial: the paired difference has no spread
        assert r["value"] == pytest.approx(1.0) and r["stderr"] == pytest.approx(0.0, abs=1e-12)
        assert r["metric"] == "x - a" and r["runs"] == 5


def _fail_or_sleep(setting, methods, seed):
    import time as _t
    if setting["mu"] == 1.0:
        raise ValueError("bad trial")
    _t.sleep(120)
    return {m: {"x": 0.0} for m in methods}


def test_failure_in_a_worker_does_not_wait_for_long_running_trials(tmp_path):
    """A failing trial stops the run without waiting for a 120 s trial in the other worker
    (a behavioural check with a wide margin, not a performance assertion)."""
    e = Experiment("demo", [{"mu": 2.0}, {"mu": 1.0}], ["a"], _fail_or_sleep, runs=1)
    t0 = time.monotonic()
    with pytest.raises(TrialError, match="bad trial"):
        run_experiment(e, tmp_path / "r.sqlite", workers=2, chunk_size=1)
    assert time.monotonic() - t0 < 60


def test_progress_bar_on_stderr(tmp_path, capsys):
    run_experiment(_exp(runs=2), tmp_path / "r.sqlite", progress=True)
    err = capsys.readouterr().err
    assert "demo:" in err and "6/6" in err and "trial" in err
