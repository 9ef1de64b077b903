"""Moved: the group matching measures live in :mod:`assocopt.tracking.group_matching`.

This module only keeps the old import path ``assocopt.group_matching`` working (for users' code);
the project itself imports from the new place.
"""

from ._moved import reexport

__getattr__ = reexport(globals(), "assocopt.tracking.group_matching")
