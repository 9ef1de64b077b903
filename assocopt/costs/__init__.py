"""Moved: the S-D cost builders (Pattipati, KLD/SKLD) live in :mod:`assocopt.tracking.costs`.

This module only keeps the old import path ``assocopt.costs`` working (for users' code);
the project itself imports from the new place.
"""

from .._moved import reexport

__getattr__ = reexport(globals(), "assocopt.tracking.costs", {"divergence": "kld"})
