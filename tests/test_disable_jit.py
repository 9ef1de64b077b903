"""``NUMBA_DISABLE_JIT=1`` (numba's debugging switch: every kernel runs as the plain
Python function it is written as) works on every public compiled path and gives the
answers of the compiled kernels: the paths of ``benchmarks/first_use.py`` on small
problems, run in a fresh interpreter with the switch, against this process (compiled)."""

from __future__ import annotations

import json
import math
import os
import subprocess
import sys
from pathlib import Path

import pytest

from conftest import load_script

ROOT = Path(__file__).resolve().parents[1]
first_use = load_script("benchmarks/first_use.py", "first_use")
KEYS = [key for key, _what, _fn in first_use.PATHS]


@pytest.fixture(scope="module")
def without_jit() -> dict:
    """Every path's answer with ``NUMBA_DISABLE_JIT=1``, by key."""
    env = dict(os.environ, PYTHONPATH=str(ROOT), NUMBA_DISABLE_JIT="1")
    done = subprocess.run([sys.executable, "-W", "error::RuntimeWarning",
                           str(ROOT / "benchmarks" / "first_use.py"), "--one", *KEYS,
                           "--small"], env=env, capture_output=True, text=True,
                          timeout=600, cwd=ROOT)
    assert done.returncode == 0, done.stderr[-3000:]
    rows = json.loads(done.stdout.splitlines()[-1])
    assert [r["compile_s"] + r["cache_load_s"] for r in rows] == [0.0] * len(rows)
    return {r["key"]: r["answer"] for r in rows}


def _same(a, b, path: str = "") -> None:
    """Equal answers: structure, statuses and selections exactly, numbers to 1e-9."""
    if isinstance(a, float) or isinstance(b, float):
        assert isinstance(a, (int, float)) and isinstance(b, (int, float)), path
        assert math.isclose(a, b, rel_tol=1e-9, abs_tol=1e-12), (path, a, b)
    elif isinstance(a, dict):
        assert isinstance(b, dict) and a.keys() == b.keys(), path
        for k in a:
            _same(a[k], b[k], f"{path}.{k}")
    elif isinstance(a, list):
        assert isinstance(b, list) and len(a) == len(b), path
        for i, (x, y) in enumerate(zip(a, b)):
            _same(x, y, f"{path}[{i}]")
    else:
        assert a == b, (path, a, b)


@pytest.fixture
def compiled_mode():
    """This process runs every kernel compiled (not as its plain twin) meanwhile."""
    from assocopt.solvers.kernels import tiers
    tiers.set_mode("compiled")
    yield
    tiers.set_mode(None)


@pytest.mark.parametrize("key", KEYS)
def test_same_answer_without_jit(without_jit, compiled_mode, key):
    compiled = first_use.run_one(key, small=True)["answer"]
    _same(without_jit[key], compiled, key)
    assert without_jit[key]                           # the path answered something


def test_numba_is_really_off_in_the_subprocess():
    """The switch reaches the kernels: they are plain functions there."""
    env = dict(os.environ, PYTHONPATH=str(ROOT), NUMBA_DISABLE_JIT="1")
    code = ("import types\nfrom assocopt.solvers.kernels import murty2d, driver\n"
            "print(isinstance(murty2d.murty, types.FunctionType), "
            "isinstance(driver.solve, types.FunctionType))")
    out = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True,
                         text=True, check=True, timeout=120).stdout.split()
    assert out == ["True", "True"]
