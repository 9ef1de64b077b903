"""Tracking code built on the core: everything here may import the core, never the reverse.

* :mod:`.localisation` -- bearing geometry and least-squares localisation;
* :mod:`.costs` -- S-D cost builders (Pattipati's likelihood ratio, KLD/SKLD);
* :mod:`.belief` -- belief (mass) functions and combination rules;
* :mod:`.group_matching` -- matching measures between two sensors' group observations;
* :mod:`.topology` -- target reference frames and the topology statistical distance;
* :mod:`.decide` -- decision rules (MD-ND truncation, MD-2DA);
* :mod:`.scenarios` -- the simulated scenarios of the papers (Lu 2013, Zhang 2009);
* :mod:`.gating` -- chi-square gating of track-measurement pairs (KD-tree pre-filter);
* :mod:`.costs.kinematic` -- Mahalanobis and log-likelihood-ratio costs of gated pairs;
* :mod:`.sd_gating` -- S-D candidate tuples gated pairwise across sensors;
* :mod:`.azimuth` -- azimuth-only sensors in the plane;
* :mod:`.simulate` -- seeded constant-velocity and crossing scenarios with clutter;
* :mod:`.mfa` -- multi-frame assignment: a sliding window of scans as one S-D problem;
* :mod:`.stonesoup` -- assocopt as Stone Soup data associators, GNN, k-best and MFA
  (optional extra);
* :mod:`.stonesoup_hypothesiser` -- Stone Soup's MFA hypotheses, batched (optional extra).

Nothing is imported here, so ``import assocopt.tracking.costs`` loads only what it needs
(and importing this package never imports Stone Soup).
"""
