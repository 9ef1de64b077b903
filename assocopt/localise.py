"""Moved: bearing geometry and least-squares localisation live in :mod:`assocopt.tracking.localisation`.

This module only keeps the old import path ``assocopt.localise`` working (for users' code);
the project itself imports from the new place.
"""

from ._moved import reexport

__getattr__ = reexport(globals(), "assocopt.tracking.localisation")
