"""All back ends import and run in ONE process.

highspy 1.15.1 and ortools 9.15 cannot share a process (undefined HiGHS symbol in
libortools.so), in either import order.  pyproject pins a set that coexists; this
test runs in fresh interpreters, both import orders, so an upgrade that breaks the
pin fails CI rather than users.
"""

from __future__ import annotations

import subprocess
import sys

import pytest

SCRIPT = """
import importlib
for mod in {order!r}:
    importlib.import_module(mod)
import numpy as np
from assocopt import AssignmentProblem, solve
p = AssignmentProblem.dense(np.random.default_rng(0).random((4, 4, 4)))
objs = {{name: solve(p, name).objective for name in
        ["highs", "scipy", "ortools-cpsat", "ortools-mip", "cvxpy"]}}
assert len({{round(v, 9) for v in objs.values()}}) == 1, objs
print("OK", objs)
"""


@pytest.mark.parametrize("order", [("highspy", "ortools.sat.python.cp_model", "cvxpy"),
                                   ("cvxpy", "ortools.linear_solver.pywraplp", "highspy")])
def test_every_backend_in_one_process(order):
    out = subprocess.run([sys.executable, "-c", SCRIPT.format(order=list(order))],
                         capture_output=True, text=True, timeout=300)
    assert out.returncode == 0, out.stderr[-3000:]
    assert "OK" in out.stdout
