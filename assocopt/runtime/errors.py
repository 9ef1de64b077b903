"""Exception types.

Every error that bad user input can cause derives from :class:`AssocoptError`; the
CLI turns these into a one-line message and exit code 2, never a traceback.
"""

from __future__ import annotations


class AssocoptError(Exception):
    """Base class of every error assocopt raises on purpose."""


class InvalidProblemError(AssocoptError, ValueError):
    """The cost data do not describe a valid assignment problem (shape, NaN, indices...)."""


class InstanceFormatError(AssocoptError, ValueError):
    """A stored instance file is malformed or of an unknown format."""


class UnknownSolverError(AssocoptError, KeyError):
    """The requested back end is not registered; the message lists the valid names."""

    def __str__(self) -> str:  # KeyError would quote the message
        return str(self.args[0]) if self.args else ""


class SolverNotInstalledError(AssocoptError, ImportError):
    """The back end is registered but its Python package is missing."""


class SolverCapabilityError(AssocoptError, ValueError):
    """The back end cannot solve this kind of problem (e.g. N-D with a 2-D method)."""


class ProblemTooLargeError(AssocoptError, ValueError):
    """An exhaustive method (brute force) was asked to solve an instance that is too big."""


class MissingDependencyError(AssocoptError, ImportError):
    """An optional Python package (not a back end's) is missing; the message says
    what to ``pip install``."""
