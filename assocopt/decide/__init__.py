"""Moved: the decision rules (MD-ND truncation, MD-2DA) live in :mod:`assocopt.tracking.decide`.

This module only keeps the old import path ``assocopt.decide`` working (for users' code);
the project itself imports from the new place.
"""

from .._moved import reexport

__getattr__ = reexport(globals(), "assocopt.tracking.decide")
