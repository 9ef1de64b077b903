"""Back ends behind one interface (see :mod:`assocopt.solvers.base`).

Importing this package registers every back end; each module imports its own
optional package only inside ``solve``, so a missing package costs nothing until
that back end is asked for, and then fails with a message naming the package.
"""

from .base import (Backend, RawResult, SolveOptions, available, get_backend,
                   register, registered)
from .options import Option, OptionError
from . import highs, scipy_milp, scipy_lsa, bruteforce, greedy  # noqa: F401  (register)
from . import lap, lagrangian, bnb  # noqa: F401  (register)
from . import ortools_cpsat, ortools_mip, cvxpy_backend  # noqa: F401  (register)

__all__ = ["Backend", "RawResult", "SolveOptions", "Option", "OptionError", "available",
           "get_backend", "register", "registered"]
