"""Shared fixtures: the back ends under test, the public benchmark folder, and the
small random S-D problems the Lagrangian and branch-and-bound tests draw."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from hypothesis import strategies as st

from assocopt import AssignmentProblem
from assocopt.solvers import registered
from assocopt.testing import random_problem

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


@pytest.fixture
def ap_instances() -> Path:
    if not AP_INSTANCES.is_dir():
        pytest.skip("../shared/ap_instances not present (only in the development checkout)")
    return AP_INSTANCES


# No wall-clock limits in unit tests: hypothesis's per-example deadline is one.
from hypothesis import HealthCheck, settings  # noqa: E402

settings.register_profile("assocopt", deadline=None, max_examples=40,
                          suppress_health_check=[HealthCheck.too_slow])
settings.register_profile("thorough", deadline=None, max_examples=500,
                          suppress_health_check=[HealthCheck.too_slow])
settings.load_profile("assocopt")


def _sd(rng: np.random.Generator, N: int, dummies: bool, integer: bool) -> AssignmentProblem:
    """A small random S-D problem that brute force settles quickly."""
    if dummies:
        hi = {3: 4, 4: 3, 5: 3}[N]
        sizes = tuple(int(v) for v in rng.integers(1, hi, size=N))
        return random_problem(rng, "sd", sizes=sizes, integer=integer,
                              keep=float(rng.choice([0.3, 0.6, 1.0])))
    if rng.random() < 0.25:                       # rectangular: zero-cost slack
        shape = tuple(int(v) for v in rng.integers(1, 4, size=N))
    else:
        n = int(rng.integers(1, {3: 5, 4: 4, 5: 3}[N]))
        shape = (n,) * N
    C = rng.integers(-5, 20, size=shape).astype(float) if integer else rng.normal(size=shape)
    return AssignmentProblem.dense(C)


@st.composite
def sd_problems(draw, dummies=None):
    N = draw(st.integers(3, 5))
    seed = draw(st.integers(0, 2 ** 32 - 1))
    use_dummies = draw(st.booleans()) if dummies is None else dummies
    return _sd(np.random.default_rng(seed), N, use_dummies, draw(st.booleans()))
