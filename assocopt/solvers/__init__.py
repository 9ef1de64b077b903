"""Back ends behind one interface (see :mod:`assocopt.solvers.base`).

The shared pieces are top-level modules: :mod:`.base` (the interface and the
registry), :mod:`.options` (declared options), :mod:`.status` (solver statuses to
ours), :mod:`.scaling` (float costs to integers), :mod:`.interruptible` (Ctrl-C and
time limits around long calls).  The back ends live in named parts:

* :mod:`.twod` -- 2-D assignment (LAP engines, ``scipy-lsa``, ``lapjv``);
* :mod:`.milp` -- the MILP back ends (``highs``, ``scipy``, ``ortools-cpsat``,
  ``ortools-mip``, ``cvxpy``) and their child-process time limits;
* :mod:`.bnb` -- the compiled branch and bound (``bnb``);
* :mod:`.lagrangian` -- Lagrangian relaxation (``lagrangian``, ``lagrangian-exact``);
* :mod:`.baseline` -- ``bruteforce`` (the test oracle) and ``greedy``;
* :mod:`.kernels` -- every compiled (numba) kernel, under one cache policy.

Inside this package the parts import the top-level modules and :mod:`.kernels`;
only :mod:`.lagrangian` imports other parts (the 2-D engines, HiGHS, the ``bnb``
kernels and ``greedy``).

Every back end is declared here by name and module; its module is imported the first
time it is asked for (:func:`get_backend`, or :func:`registered` for the listing), so a
solve loads only the chosen back end.  Each module imports its optional package only
inside ``solve``: a missing package costs nothing until that back end is asked for,
and then fails with a message naming the package.  Submodules are also reachable as
attributes (``assocopt.solvers.milp``), imported on first access.

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
    "highs": "milp.highs", "scipy": "milp.scipy_milp", "scipy-lsa": "twod.scipy_lsa",
    "bruteforce": "baseline.bruteforce", "greedy": "baseline.greedy",
    "lapjv": "twod.lapjv", "lagrangian": "lagrangian", "lagrangian-exact": "lagrangian",
    "bnb": "bnb.backend", "ortools-cpsat": "milp.ortools_cpsat",
    "ortools-mip": "milp.ortools_mip", "cvxpy": "milp.cvxpy_backend",
}
for _name, _module in BACKEND_MODULES.items():
    declare(_name, f"{__name__}.{_module}")
del _name, _module

#: Submodules reachable as attributes: the parts and the top-level modules.
_SUBMODULES = frozenset({"twod", "milp", "bnb", "lagrangian", "baseline", "kernels", "base",
                         "options", "status", "scaling", "interruptible"})


def __getattr__(name: str) -> Any:
    """Import a submodule on first attribute access (PEP 562)."""
    if name in _SUBMODULES:
        return importlib.import_module(f"{__name__}.{name}")
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


__all__ = ["Backend", "RawResult", "SolveOptions", "Option", "OptionError", "available",
           "get_backend", "register", "registered", "declare", "names", "BACKEND_MODULES"]
