"""Cost builders: paper 002's Pattipati, KLD and SKLD costs (printed, exact, joint).

See :mod:`assocopt.tracking.costs.sd_builder` for the pipeline and :data:`COSTS` for the names;
:mod:`.kinematic` has the Mahalanobis and log-likelihood-ratio costs of gated
track-measurement pairs.
"""

from .sd_builder import (COSTS, PRINTED_COSTS, Scan, SDCosts, build_costs, build_problem,
                         candidate_tuples, tuple_costs, tuple_geometry)

__all__ = ["COSTS", "PRINTED_COSTS", "Scan", "SDCosts", "build_costs", "build_problem",
           "candidate_tuples", "tuple_costs", "tuple_geometry"]
