"""What a setting of the paper-001 experiments means: its scenario and its degree parameters.

Shared by the two-node trials (:mod:`.experiment`) and our three-node extension
(:mod:`.three_node`).
"""

from __future__ import annotations

from typing import Any, Mapping

from ...tracking.costs.association_degree import DegreeParams, tolerance
from ...tracking.scenarios.yan2010 import Yan2010

__all__ = ["SCENARIO_KEYS", "scenario_of", "degree_params"]

#: Keys of a setting that configure the scenario (the rest configure the decision).
SCENARIO_KEYS = ("tracker", "init", "q_true", "q_filter", "period", "duration", "freq_range",
                  "pw_range", "pri_range", "emitter_types", "region_scale",
                  "single_node_fraction", "tdoa_sigma_scale")


def scenario_of(setting: Mapping[str, Any], nodes: int = 2) -> Yan2010:
    """The scenario of a setting."""
    kw = {k: (tuple(setting[k]) if isinstance(setting[k], list) else setting[k])
          for k in SCENARIO_KEYS if k in setting}
    return Yan2010(n_targets=int(setting["n"]), nodes=nodes, **kw)


def degree_params(setting: Mapping[str, Any], sc: Yan2010, fusion: str = "candidate",
                  a: int = 0, b: int = 1, k_tol: float | None = None) -> DegreeParams:
    """Weights and tolerances of the degrees between nodes ``a`` and ``b`` (tolerance
    factor ``k_tol``, default the setting's)."""
    sig = sc.feature_sigmas()
    k = float(setting["k_tol"] if k_tol is None else k_tol)
    tols = tuple(tolerance(sig[a, i], sig[b, i], k) for i in range(3))
    return DegreeParams(weights=tuple(setting["weights"]), tolerances=tols, fusion=fusion)
