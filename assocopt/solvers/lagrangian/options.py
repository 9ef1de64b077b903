"""Options of the Lagrangian back ends: defaults, validation, and the kept axes.

Kept apart from the algorithm so that the option set (documented in the package
docstring) and its checks can be read in one place; :data:`OPT_TOL` lives here
because both the ascent and the window search use it.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from ...errors import InvalidProblemError, SolverNotInstalledError
from ..lap import LAP_METHODS, lapx_available

#: Relative tolerance for "bound meets objective" with non-integer costs (round-off).
OPT_TOL = 1e-9

_COMMON = {
    "max_iter": 1000, "gap_tol": 1e-4, "step0": 1.0, "step_decay": 0.5, "patience": 10,
    "step_min": 1e-4, "deflect": 0.5, "recover_every": 1, "keep_axes": None,
    "lap": "auto", "reduce": True, "gate": None, "return_history": False,
    "stall_iter": 60, "stall_tol": 1e-3, "local_search": True, "init": "share",
}
_EXACT = dict(_COMMON, max_iter=500, gap_tol=0.0, window_solver="auto")


def _parse(extra: dict[str, Any], exact: bool, name: str) -> dict[str, Any]:
    """Defaults merged with ``extra`` (the solve options), each option checked."""
    defaults = _EXACT if exact else _COMMON
    unknown = sorted(set(extra) - set(defaults))
    if unknown:
        raise InvalidProblemError(f"unknown option(s) for solver {name!r}: {unknown}; "
                                  f"valid: {sorted(defaults)}")
    p = dict(defaults)
    p.update(extra)
    for key in ("max_iter", "patience", "stall_iter", "recover_every"):
        v = p[key]
        if isinstance(v, bool) or not isinstance(v, (int, np.integer)) or v < 0 or \
                (key in ("patience", "stall_iter") and v < 1):
            raise InvalidProblemError(f"option {key} must be a non-negative integer"
                                      f"{' >= 1' if key in ('patience', 'stall_iter') else ''}"
                                      f", got {v!r}")
        p[key] = int(v)
    for key, lo, hi in (("gap_tol", 0.0, math.inf), ("step0", 0.0, 2.0), ("deflect", 0.0, 0.99),
                        ("step_decay", 0.0, 1.0), ("step_min", 0.0, math.inf),
                        ("stall_tol", 0.0, math.inf)):
        v = p[key]
        ok = isinstance(v, (int, float, np.floating)) and not isinstance(v, bool) and \
            lo <= float(v) <= hi and not (key in ("step0", "step_decay") and float(v) == 0)
        if not ok:
            raise InvalidProblemError(f"option {key} must be a number in "
                                      f"{'(' if key in ('step0', 'step_decay') else '['}"
                                      f"{lo}, {hi}], got {v!r}")
        p[key] = float(v)
    if exact and p["window_solver"] not in ("auto", "highs", "cpsat"):
        raise InvalidProblemError(f"option window_solver must be 'auto', 'highs' or 'cpsat', "
                                  f"got {p['window_solver']!r}")
    if p["init"] not in ("share", "zero"):
        raise InvalidProblemError(f"option init must be 'share' or 'zero', got {p['init']!r}")
    if p["lap"] not in LAP_METHODS:
        raise InvalidProblemError(f"option lap must be one of {LAP_METHODS}, got {p['lap']!r}")
    if p["lap"] == "lapx" and not lapx_available():
        raise SolverNotInstalledError("option lap='lapx' needs the Python package 'lapx': "
                                      "pip install lapx")
    if p["gate"] is not None:
        g = p["gate"]
        if isinstance(g, bool) or not isinstance(g, (int, float, np.floating)) or math.isnan(g):
            raise InvalidProblemError(f"option gate must be a number or None, got {g!r}")
        p["gate"] = float(g)
    for key in ("reduce", "return_history", "local_search"):
        if not isinstance(p[key], (bool, np.bool_)):
            raise InvalidProblemError(f"option {key} must be True or False, got {p[key]!r}")
        p[key] = bool(p[key])
    return p


def _keep_axes(sizes: tuple[int, ...], keep: Any) -> tuple[int, int]:
    """The two kept axes, sorted: ``keep`` checked, or by default the two largest."""
    N = len(sizes)
    if keep is None:
        order = sorted(range(N), key=lambda s: (-sizes[s], s))
        return tuple(sorted(order[:2]))    # type: ignore[return-value]
    try:
        a, b = (int(v) for v in keep)
    except (TypeError, ValueError) as exc:
        raise InvalidProblemError(f"keep_axes must be two axis numbers, got {keep!r}") from exc
    if not (0 <= a < N and 0 <= b < N and a != b):
        raise InvalidProblemError(f"keep_axes must be two different axes in 0..{N - 1}, "
                                  f"got {keep!r}")
    return (min(a, b), max(a, b))

