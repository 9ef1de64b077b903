"""Shared fixtures: the back ends under test, the public benchmark folder, the
small random S-D problems the Lagrangian and branch-and-bound tests draw, the
check that a paper page's generated blocks match its committed summary (and the rerun
of one of its cells), loading the repository's scripts (benchmarks/, docs/) as
modules, running code in a fresh interpreter (import checks), and the check that no
child process outlives its test (helpers in ``processes.py``)."""

from __future__ import annotations

import faulthandler
import importlib.util
import json
import os
import re
import subprocess
import sys
from pathlib import Path
from typing import Any, Callable

import numpy as np
import pytest
from hypothesis import strategies as st

from assocopt import AssignmentProblem
from assocopt.solvers import registered
from assocopt.testing import draw_costs, draw_sd
from processes import children_now, kill_tree, leftover_children, sigint_handled

ROOT = Path(__file__).resolve().parents[1]
#: ../shared/ap_instances beside the project checkout (absent for installed users).
AP_INSTANCES = Path(__file__).resolve().parents[2] / "shared" / "ap_instances"

EXACT = sorted(n for n, cls in registered().items()
               if cls.exact and cls.integer and n != "bruteforce")
EXACT_ND = [n for n in EXACT if registered()[n].max_ndim is None]
LP = sorted(n for n, cls in registered().items() if cls.lp)


def installed(name: str):
    """pytest.param for a back end, skipped (naming the package) when not installed."""
    cls = registered()[name]
    return pytest.param(name, id=name, marks=pytest.mark.skipif(
        not cls.is_available(), reason=f"{cls.distribution} not installed"))


#: Seconds a child may take to end after its test (a killed child being reaped).
CHILD_GRACE = 5.0


#: Seconds beyond pytest-timeout's limit after which a test stuck in C code (where
#: SIGALRM cannot raise) ends the run with the tracebacks of all threads (the
#: environment variable ASSOCOPT_TEST_BACKSTOP sets it, to check the backstop).
BACKSTOP = 60.0 if "ASSOCOPT_TEST_BACKSTOP" not in os.environ else \
    float(os.environ["ASSOCOPT_TEST_BACKSTOP"])


def _timeout(config: pytest.Config) -> float:
    try:
        return float(config.getini("timeout") or 0)
    except (ValueError, TypeError):          # pytest-timeout not installed
        return 0.0


def _stderr_fd(config: pytest.Config) -> int:
    """The real standard error (pytest's copy of it, as its own faulthandler uses)."""
    try:
        from _pytest.faulthandler import fault_handler_stderr_fd_key
        return config.stash[fault_handler_stderr_fd_key]
    except (ImportError, KeyError):
        return sys.__stderr__.fileno()


@pytest.fixture(autouse=True)
def no_process_left_behind(request):
    """Fail (and kill) any child process of the test process that outlives its test:
    a test that starts a process must end it on every path (``processes.started``)."""
    limit = _timeout(request.config)
    if limit > 0:
        faulthandler.dump_traceback_later(limit + BACKSTOP, exit=True,
                                          file=_stderr_fd(request.config))
    before = children_now()
    yield
    if limit > 0:
        faulthandler.cancel_dump_traceback_later()
    if request.node.get_closest_marker("fixture_children"):
        return                  # children a longer-lived fixture owns and ends itself
    # the warm time-limit workers are kept by design between solves: ended here, so
    # that what is checked below is every other child, and that shutdown() ends them
    from assocopt.solvers.milp.limited import shutdown
    shutdown()
    left = leftover_children(before, CHILD_GRACE)
    if left:
        pytest.fail("child processes outlived the test (killed now): "
                    + "; ".join(kill_tree(left)), pytrace=False)


@pytest.fixture
def sigint_python():
    """SIGINT raises KeyboardInterrupt for the test's duration, also when pytest was
    started with SIGINT ignored (``nohup ... &``): what ``_thread.interrupt_main()``
    and children started inside (SIGINT at its default) rely on."""
    with sigint_handled():
        yield


@pytest.fixture
def ap_instances() -> Path:
    if not AP_INSTANCES.is_dir():
        pytest.skip("../shared/ap_instances not present (only in the development checkout)")
    return AP_INSTANCES


# No wall-clock limits in unit tests: hypothesis's per-example deadline is one.
from hypothesis import HealthCheck, settings  # noqa: E402

# The default run draws the same examples every time (derandomize: a seed from each
# test's own code), so a clean clone passes or fails the same way on every machine;
# `pytest --hypothesis-profile=explore` draws afresh (and keeps failures in the local
# example database), `thorough` draws afresh and many more.
settings.register_profile("assocopt", deadline=None, max_examples=40, derandomize=True,
                          suppress_health_check=[HealthCheck.too_slow])
settings.register_profile("explore", deadline=None, max_examples=40,
                          suppress_health_check=[HealthCheck.too_slow])
settings.register_profile("thorough", deadline=None, max_examples=500,
                          suppress_health_check=[HealthCheck.too_slow])
settings.load_profile("assocopt")


@st.composite
def sd_problems(draw, dummies=None):
    """Small S-D problems (N = 3..5) that brute force settles quickly, drawn
    structurally (sizes, tuples, costs) so failures shrink: with dummies, a drawn
    subset of the multi-index tuples; without, a full dense cost array (a quarter
    of them rectangular, with zero-cost slack)."""
    N = draw(st.integers(3, 5))
    use_dummies = draw(st.booleans()) if dummies is None else dummies
    integer = draw(st.booleans())
    if use_dummies:
        hi = {3: 3, 4: 2, 5: 2}[N]
        sizes = tuple(draw(st.lists(st.integers(1, hi), min_size=N, max_size=N)))
        return draw_sd(draw, sizes, integer)
    if draw(st.integers(0, 3)) == 0:
        shape = tuple(draw(st.lists(st.integers(1, 3), min_size=N, max_size=N)))
    else:
        shape = (draw(st.integers(1, {3: 4, 4: 3, 5: 2}[N])),) * N
    return AssignmentProblem.dense(draw_costs(draw, shape, integer))


def draw_misses(draw, rng: np.random.Generator, n: int, none: Any) -> Any:
    """Miss costs of ``n`` rows or columns of a drawn 2-D problem, of a drawn kind:
    ``none`` (returned as given: no misses), finite, some forbidden (inf) or all zero."""
    kind = draw(st.sampled_from(["none", "finite", "some-inf", "zero"]))
    if kind == "none":
        return none
    m = rng.integers(-3, 8, size=n).astype(float)
    if kind == "zero":
        m[:] = 0.0
    if kind == "some-inf" and n:
        m[rng.random(n) < 0.5] = np.inf
    return m


def page_block(text: str, name: str) -> str:
    """The generated block ``name`` of a docs page (between its begin/end markers)."""
    m = re.search(rf"<!-- {name}:begin -->\n(.*?)\n<!-- {name}:end -->", text, re.DOTALL)
    assert m, f"the page has no generated block {name!r}"
    return m.group(1).strip()


def check_page_against_summary(repro, paper: str, page: Path, summary_path: Path) -> dict:
    """Assert a paper page's tables, parameters and headline blocks are what ``repro``
    renders from the committed summary, that the summary was run with the current
    default parameters, and that every figure it lists is committed and shown on the
    page; returns the summary for paper-specific checks."""
    summary = json.loads(summary_path.read_text())
    text = page.read_text(encoding="utf-8")
    assert page_block(text, "tables") == repro.render_tables(summary).strip()
    assert page_block(text, "parameters") == repro.render_parameters(summary).strip()
    assert page_block(text, "headline") == repro.render_headline(summary).strip()
    assert summary["parameters"] == json.loads(json.dumps(repro.parameters()))
    for f in summary["figures"]:
        assert (summary_path.parent / f).is_file() and f"{paper}/{f}" in text
    return summary


def load_script(path: str, name: str, register: bool = False):
    """The repository script ``path`` (relative to the checkout, e.g.
    ``"benchmarks/twod.py"``) executed as a fresh module called ``name``; ``register``:
    entered in ``sys.modules`` first (a script defining dataclasses needs that)."""
    spec = importlib.util.spec_from_file_location(name, ROOT / path)
    mod = importlib.util.module_from_spec(spec)
    if register:
        sys.modules[name] = mod
    spec.loader.exec_module(mod)
    return mod


def agrees(a: float, b: float) -> bool:
    """``a`` and ``b`` equal to a relative 1e-6 (numbers read back from a page or JSON)."""
    return abs(a - b) <= 1e-6 * max(1.0, abs(a), abs(b))


def rerun_committed(repro, paper: str, part: str, where: Callable[[dict], bool],
                    store: Path) -> tuple[list[dict[str, Any]], list[dict[str, Any]]]:
    """Recompute from scratch, into ``store``, the settings of experiment ``part`` of the
    committed run of ``paper`` that ``where(setting)`` selects (with that run's run
    count and seed); returns the summarised rows and the committed records of the
    same settings, to compare."""
    from assocopt.experiments import Experiment, run_experiment, summarise
    js = json.loads((ROOT / "docs" / "papers" / paper / "summary.json").read_text())
    exp = repro.experiments(js["runs"], js["seed"], parts=(part,))[0]
    one = Experiment(exp.name, [s for s in exp.settings if where(s)], exp.methods,
                     exp.trial, exp.runs, exp.seed, exp.params, exp.volatile)
    run_experiment(one, store)
    committed = [r for r in js["records"] if r["experiment"] == part and where(r["setting"])]
    return summarise(store, one), committed


def fresh_python(code: str, *, cwd: Path | None = None) -> str:
    """The standard output of ``code`` run by a fresh interpreter on this checkout
    (``PYTHONPATH`` = the checkout); a non-zero exit fails the test."""
    env = dict(os.environ, PYTHONPATH=str(ROOT))
    return subprocess.run([sys.executable, "-c", code], cwd=cwd, env=env, check=True,
                          capture_output=True, text=True).stdout
