"""Decision stages: turn matching measures into association relations.

* :mod:`.truncation` -- paper 000's observation-sequence truncation ("MD-ND");
* :mod:`.md2da` -- paper 000's 2-D assignment baseline ("MD-2DA") as an
  optimisation model solved by any back end;
* :mod:`.did` -- paper 003's distributed inference decision (DID), both stages;
* :mod:`.nearest` -- report-to-track GNN (a 2-D assignment through ``solve``) and
  nearest neighbour;
* :mod:`.max_degree` -- paper 001's maximum-degree rule, association-quality counter,
  its 2-D assignment counterpart and the weighted chi-square baseline;
* :mod:`.topology` -- paper 004's 2-D assignment per reference pair, the degree
  matrix Phi and the trial pairs; :mod:`.double_threshold` -- its I/R confirmation.
"""

from .md2da import MD2DAResult, gate_threshold, md_2da, md_2da_problem
from .truncation import (TruncationOptions, TruncationResult, coarse_truncation,
                         fine_truncation, md_nd, single_linkage_order, truncate)

__all__ = ["TruncationOptions", "TruncationResult", "single_linkage_order",
           "coarse_truncation", "fine_truncation", "truncate", "md_nd",
           "MD2DAResult", "md_2da", "md_2da_problem", "gate_threshold"]
