"""assocopt: data association for multi-sensor tracking as optimisation models.

>>> from assocopt import AssignmentProblem, solve
>>> sol = solve(AssignmentProblem.dense([[4.0, 1.0], [2.0, 3.0]]))
>>> sol.objective
3.0
"""

from ._version import __version__
from .runtime.errors import (AssocoptError, InstanceFormatError, InvalidProblemError,
                             ProblemTooLargeError, SolverCapabilityError,
                             SolverNotInstalledError, UnknownSolverError)
from .problems.problem import AssignmentProblem
from .model.solution import Solution, Status
from . import solvers
from .solving.api import choose_solver, solve
from .solving.many import solve_many
from .ranking.kbest import Ranked, kbest
from .ranking.marginals import Marginals, marginals

__all__ = ["AssignmentProblem", "Solution", "Status", "solve", "solve_many", "choose_solver",
           "solvers",
           "kbest", "Ranked", "marginals", "Marginals",
           "AssocoptError", "InvalidProblemError", "InstanceFormatError",
           "UnknownSolverError", "SolverNotInstalledError", "SolverCapabilityError",
           "ProblemTooLargeError", "__version__"]
