"""Gating: which track-measurement pairs, and which S-D tuples, may belong together.

* :mod:`.chi2` -- chi-square gating of track-measurement pairs with a KD-tree
  pre-filter (:func:`gate`, :class:`Gate`, :func:`chi2_threshold`,
  :func:`predict_measurements`, :func:`pair_statistics`);
* :mod:`.position` -- the pairwise gate of position-like reports across sensors
  (:func:`position_pair_gate`: chi-square(d), KD-tree candidates, sparse result);
* :mod:`.tuples` -- S-D candidate tuples gated pairwise across sensors
  (:func:`gated_tuples`, for any pairwise compatibility);
* :mod:`.bearing` -- the pairwise gate of bearing measurements and the gated S-D
  problem of a bearing scan (:func:`bearing_pair_gate`, :func:`build_gated_problem`).

Importing this package loads numpy and the S-D cost builders, never Stone Soup or
numba (scipy's chi-square and KD-tree are imported when a gate is computed).

May import: :mod:`assocopt.runtime`, :mod:`assocopt.problems`, and in the tracking
layer :mod:`assocopt.tracking.costs` (with what it imports).
"""

from .bearing import bearing_pair_gate, build_gated_problem
from .chi2 import Gate, chi2_threshold, gate, pair_statistics, predict_measurements
from .position import position_pair_gate
from .tuples import gated_tuples

__all__ = ["Gate", "chi2_threshold", "predict_measurements", "gate", "pair_statistics",
           "position_pair_gate", "gated_tuples", "bearing_pair_gate", "build_gated_problem"]
