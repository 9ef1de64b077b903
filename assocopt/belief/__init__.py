"""Moved: belief (mass) functions and their combination rules live in :mod:`assocopt.tracking.belief`.

This module only keeps the old import path ``assocopt.belief`` working (for users' code);
the project itself imports from the new place.
"""

from .._moved import reexport

__getattr__ = reexport(globals(), "assocopt.tracking.belief")
