"""Tracking code built on the core: everything here may import the core, never the reverse.

* :mod:`.localisation` -- bearing geometry and least-squares localisation
  (:mod:`.localisation.azimuth`: azimuth-only sensors in the plane);
* :mod:`.costs` -- S-D cost builders (Pattipati's likelihood ratio, KLD/SKLD),
  :mod:`.costs.kinematic` (Mahalanobis and log-likelihood-ratio costs of gated pairs),
  :mod:`.costs.topology` (target reference frames, the topology statistical distance);
* :mod:`.belief` -- belief (mass) functions and combination rules
  (:mod:`.belief.group_matching`: matching measures between two sensors' groups);
* :mod:`.decide` -- decision rules (MD-ND truncation, MD-2DA);
* :mod:`.gating` -- chi-square gating of track-measurement pairs (KD-tree pre-filter)
  and S-D candidate tuples gated pairwise across sensors;
* :mod:`.scenarios` -- the simulated scenarios of the papers (Lu 2013, Zhang 2009, ...)
  and :mod:`.scenarios.simulate` (seeded constant-velocity and crossing scenarios);
* :mod:`.filters` -- Kalman filter steps;
* :mod:`.mfa` -- multi-frame assignment: a sliding window of scans as one S-D problem;
* :mod:`.stonesoup` -- assocopt inside Stone Soup (optional extra): data associators
  (GNN, k-best, MFA), batched MFA hypotheses, detections of simulated scans.

Nothing is imported here, so ``import assocopt.tracking.costs`` loads only what it needs
(and importing this package never imports Stone Soup).
"""
