"""Moved: the LP relaxation and exact solve by reduced-cost fixing live in :mod:`assocopt.lp_fixing`.

This module only keeps the old import path ``assocopt.reproduce.sdlp`` working (for
users' code); the project itself imports from the new place.
"""

from .._moved import reexport

__getattr__ = reexport(globals(), "assocopt.lp_fixing")
