"""Moved: the simulated scenarios of the papers live in :mod:`assocopt.tracking.scenarios`.

This module only keeps the old import path ``assocopt.scenarios`` working (for users' code);
the project itself imports from the new place.
"""

from .._moved import reexport

__getattr__ = reexport(globals(), "assocopt.tracking.scenarios")
