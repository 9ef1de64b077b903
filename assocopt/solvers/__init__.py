"""Back ends behind one interface (see :mod:`assocopt.solvers.base`).

Every back end is declared here by name and module; its module is imported the first
time it is asked for (:func:`get_backend`, or :func:`registered` for the listing), so a
solve loads only the chosen back end.  Each module imports its optional package only
inside ``solve``: a missing package costs nothing until that back end is asked for,
and then fails with a message naming the package.  Submodules are also reachable as
attributes (``assocopt.solvers.bnb``), imported on first access.

May import: :mod:`assocopt.runtime`, :mod:`assocopt.problems`, :mod:`assocopt.model`.
"""

from __future__ import annotations

import importlib
from typing import Any

from .base import (Backend, RawResult, SolveOptions, available, declare, get_backend,
                   names, register, registered)
from .options import Option, OptionError

#: name -> module, in the order of the listing (the registry's order).
BACKEND_MODULES: dict[str, str] = {
    "highs": "highs", "scipy": "scipy_milp", "scipy-lsa": "scipy_lsa",
    "bruteforce": "bruteforce", "greedy": "greedy", "lapjv": "lapjv",
    "lagrangian": "lagrangian", "lagrangian-exact": "lagrangian", "bnb": "bnb",
    "ortools-cpsat": "ortools_cpsat", "ortools-mip": "ortools_mip",
    "cvxpy": "cvxpy_backend",
}
for _name, _module in BACKEND_MODULES.items():
    declare(_name, f"{__name__}.{_module}")
del _name, _module

_SUBMODULES = frozenset(BACKEND_MODULES.values()) | {"base", "bnb_kernels", "kernels"}


def __getattr__(name: str) -> Any:
    """Import a submodule on first attribute access (PEP 562)."""
    if name in _SUBMODULES:
        return importlib.import_module(f"{__name__}.{name}")
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


__all__ = ["Backend", "RawResult", "SolveOptions", "Option", "OptionError", "available",
           "get_backend", "register", "registered", "declare", "names", "BACKEND_MODULES"]
