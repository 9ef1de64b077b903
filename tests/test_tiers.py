"""The route of a kernel call (assocopt/solvers/kernels/tiers.py): a small problem
runs the kernels as plain Python, a large one or a busy process compiles them, and
both routes give the same answers."""

from __future__ import annotations

import numpy as np
import pytest

from conftest import load_script
from assocopt import AssignmentProblem, solve
from assocopt.solvers import kernels
from assocopt.solvers.kernels import tiers
from assocopt.testing import random_problem

first_use = load_script("benchmarks/first_use.py", "first_use")
KEYS = [key for key, _what, _fn in first_use.PATHS]


@pytest.fixture
def fresh(monkeypatch):
    """A process state without interpreted seconds and with the default rule."""
    monkeypatch.setattr(tiers, "_SPENT", {})
    monkeypatch.setattr(tiers, "_WARM", [False])
    monkeypatch.delenv("ASSOCOPT_JIT", raising=False)
    tiers.set_mode(None)
    yield
    tiers.set_mode(None)


def _answers(key: str, mode: str) -> dict:
    tiers.set_mode(mode)
    try:
        return first_use.run_one(key, small=True)["answer"]
    finally:
        tiers.set_mode(None)


@pytest.mark.parametrize("key", KEYS)
def test_interpreted_and_compiled_answer_alike(fresh, key):
    """Every public compiled path, its kernels interpreted and compiled."""
    from test_disable_jit import _same
    plain = _answers(key, "interpreted")
    assert plain
    _same(plain, _answers(key, "compiled"), key)


def test_small_work_runs_interpreted_large_work_compiled(fresh, monkeypatch):
    import assocopt.solvers.kernels.relaxation as rel
    if not rel.prepare.overloads:            # nothing of it compiled in this process
        assert tiers.interpret("relaxation.prepare", 10, lambda: False)
    monkeypatch.setattr(tiers, "LIMITS", {"relaxation.prepare": 5})
    assert not tiers.interpret("relaxation.prepare", 10, lambda: False)
    assert not tiers.interpret("no_such.kernel", 0, lambda: False)   # no limit: compiled


def test_the_budget_closes_the_interpreted_route(fresh, monkeypatch):
    """Interpreted calls cost up to the budget; past it (cold) or past the smaller
    cached budget (when the disk cache holds the kernel) the kernel is compiled."""
    monkeypatch.setattr(tiers, "LIMITS", {"x.y": 100})
    assert tiers.interpret("x.y", 1, lambda: True)
    tiers._SPENT["x.y"] = tiers.BUDGET_CACHED + 0.01
    assert tiers.interpret("x.y", 1, lambda: False)          # cold: still interpreted
    assert not tiers.interpret("x.y", 1, lambda: True)       # cached: load it now
    tiers.exhaust("x.y")
    assert not tiers.interpret("x.y", 1, lambda: False)
    assert tiers.budget_left("x.y") == 0.0


def test_a_warm_process_loads_a_cached_kernel_sooner(fresh, monkeypatch):
    """Once the process holds machine code of some kernel, a cached kernel is loaded
    after the small warm budget; a kernel that must be compiled keeps the cold one."""
    monkeypatch.setattr(tiers, "LIMITS", {"x.y": 100})
    tiers._SPENT["x.y"] = tiers.BUDGET_WARM + 0.001
    assert tiers.interpret("x.y", 1, lambda: True)           # nothing loaded yet
    tiers.warmed()
    assert not tiers.interpret("x.y", 1, lambda: True)       # cached: load it now
    assert tiers.interpret("x.y", 1, lambda: False)          # cold: still interpreted
    tiers._SPENT["x.y"] = tiers.BUDGET_WARM / 2
    assert tiers.interpret("x.y", 1, lambda: True)


def test_loading_a_kernel_marks_the_process_warm(fresh):
    """:func:`kernels.ensure` records the load (or compile) it times."""
    p = random_problem(np.random.default_rng(3), "sd", sizes=(4, 4, 3), keep=0.5)
    tiers.set_mode("compiled")
    kernels._SEEN.clear()
    solve(p, "bnb")
    assert tiers._WARM[0]


def test_interpreted_time_is_counted(fresh):
    p = random_problem(np.random.default_rng(5), "sd", sizes=(4, 4, 3), keep=0.5)
    tiers.set_mode("interpreted")
    sol = solve(p, "bnb")
    assert sol.status.value == "optimal"
    assert tiers.interpreted_seconds().get("driver.solve", 0.0) > 0.0


def test_a_search_past_its_budget_is_solved_again_compiled(fresh, monkeypatch):
    """An interpreted bnb search stopped by the budget (made tiny here) hands over to
    the compiled kernel: same proven answer as a compiled solve, route closed."""
    p = random_problem(np.random.default_rng(11), "sd", sizes=(7, 7, 6), keep=0.6)
    tiers.set_mode("compiled")
    want = solve(p, "bnb")
    tiers.set_mode(None)
    monkeypatch.setattr(tiers, "_SPENT", {})
    monkeypatch.setattr(tiers, "BUDGET_COLD", 1e-6)
    monkeypatch.setattr(tiers, "budget_left", lambda name: 1e-6)
    monkeypatch.setattr(tiers, "interpret", lambda name, work, cached:
                        not tiers._SPENT.get(name) and name == "driver.solve")
    import assocopt.solvers.interruptible as intr
    real, calls = intr.run_stoppable, []

    def recorded(fn, args, stop, **kw):
        out = real(fn, args, stop, **kw)
        plain = getattr(fn, "interpreted", False)
        if plain:                      # as if the budget's clock had stopped it: a
            out = (out[0], True)       # tiny problem may end before looking at it
        calls.append((plain, out[1]))
        return out
    monkeypatch.setattr(intr, "run_stoppable", recorded)
    got = solve(p, "bnb")
    assert calls == [(True, True), (False, False)]     # stopped by the budget, redone
    assert got.status == want.status and got.objective == pytest.approx(want.objective)
    assert np.array_equal(got.selected, want.selected)


def test_mode_is_checked(fresh, monkeypatch):
    monkeypatch.setenv("ASSOCOPT_JIT", "sometimes")
    with pytest.raises(ValueError, match="ASSOCOPT_JIT='sometimes'"):
        tiers.mode()
    with pytest.raises(ValueError, match="expected one of auto, compiled, interpreted"):
        tiers.set_mode("fast")
    monkeypatch.setenv("ASSOCOPT_JIT", "Interpreted")
    assert tiers.mode() == "interpreted"


def test_twins_are_plain_python_and_distinct(fresh):
    import types
    f = tiers.plain("driver.solve")
    assert isinstance(f.__wrapped__, types.FunctionType)
    assert f.__wrapped__.__module__ == "assocopt.solvers.kernels._plain.driver"
    import assocopt.solvers.kernels._plain.jit as plain_jit
    assert plain_jit.PLAIN and not kernels.jit.PLAIN
