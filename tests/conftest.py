"""Shared fixtures: the back ends under test and the public benchmark folder."""

from __future__ import annotations

from pathlib import Path

import pytest

from assocopt.solvers import registered

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
