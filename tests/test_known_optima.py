"""Every exact back end against the proven optima of the public benchmark instances.

Grundel and Balas-Saltzman 3-AP instances with n <= 10 and OR-Library assign100 run
by default; every other instance in ../shared/ap_instances is marked ``slow``
(``pytest -m slow``).  Skipped cleanly when ../shared is absent.
"""

from __future__ import annotations

import csv

import pytest

from assocopt import Status, solve
from assocopt.io import read_instance
from assocopt.solvers import registered

from conftest import AP_INSTANCES, EXACT, installed

DEFAULT_MAX_N = 10


def _rows() -> list[dict[str, str]]:
    path = AP_INSTANCES / "known_values.csv"
    if not path.is_file():
        return []
    with open(path, newline="") as fh:
        return [r for r in csv.DictReader(fh) if r["file"] != "balas_saltzman/BalasAndSaltzman.txt"]


#: (back end, file suffix) pairs too slow for the default run: CP-SAT needs more than
#: 90 s on the dense 100 x 100 LAP on 2 cores.
SLOW_PAIRS = {("ortools-cpsat", "assign100.txt")}


def _cases():
    for r in _rows():
        n = int(r["n"])
        default = n <= DEFAULT_MAX_N or r["file"].endswith("assign100.txt")
        for name in EXACT:
            marks = list(installed(name).marks)
            if not default or any(name == b and r["file"].endswith(f) for b, f in SLOW_PAIRS):
                marks.append(pytest.mark.slow)
            yield pytest.param(name, r["file"], float(r["value"]), marks=marks,
                               id=f"{name}-{r['file'].split('/')[-1]}")


CASES = list(_cases()) or [pytest.param(None, None, None, marks=pytest.mark.skip(
    reason="../shared/ap_instances not present"))]


@pytest.mark.parametrize("name, rel, optimum", CASES)
def test_known_optimum(name, rel, optimum, ap_instances):
    p = read_instance(ap_instances / rel)
    if registered()[name].max_ndim is not None and p.ndim > registered()[name].max_ndim:
        pytest.skip(f"{name} is 2-D only")
    sol = solve(p, name)
    assert sol.status is Status.OPTIMAL, f"{name}: {sol.status} {sol.message}"
    assert sol.objective == optimum, f"{name}: {sol.objective} != proven {optimum}"
    assert p.violations(sol.selected) is None


@pytest.mark.parametrize("n, k", [(4, 1), (10, 5), (26, 5)])
def test_combined_balas_saltzman_file_matches_split_files(ap_instances, n, k):
    combined = read_instance(ap_instances / "balas_saltzman/BalasAndSaltzman.txt",
                             instance=f"N{n}_P{k}")
    split = read_instance(ap_instances / f"balas_saltzman/split/balas-n{n}-instance{k:02d}.txt")
    assert combined.sizes == split.sizes == (n, n, n)
    assert (combined.costs == split.costs).all()
