"""assocopt inside Stone Soup (optional extra: ``pip install assocopt[stonesoup]``).

* :mod:`.associators` -- assocopt as Stone Soup data associators: GNN
  (:class:`AssocoptGNN`), ranked joint hypotheses (:class:`AssocoptKBest`) and
  multi-frame assignment (:class:`AssocoptMFA`), with :func:`hypotheses_problem` and
  :func:`mfa_reference_cost`;
* :mod:`.jpda` -- exact joint probabilistic data association
  (:class:`AssocoptJPDA`, a drop-in for Stone Soup's ``JPDAwithEHM2``);
* :mod:`.problems` -- hypotheses read once into arrays and the JPDA problem built from
  them in bulk (:func:`probability_problem`);
* :mod:`.hypothesiser` -- Stone Soup's MFA hypotheses for linear-Gaussian models,
  batched (:class:`~.hypothesiser.LinearGaussianMFAHypothesiser`);
* :mod:`.scenario` -- Stone Soup detections and tracks of assocopt's simulated scans.

Importing this package imports Stone Soup (a clear error names the extra when it is
missing); the hypothesiser and the scenario helpers load when imported themselves.

May import: the core (:mod:`assocopt.solving`, :mod:`assocopt.ranking`,
:mod:`assocopt.problems`, :mod:`assocopt.model`, :mod:`assocopt.runtime`) and, in
the tracking layer, :mod:`assocopt.tracking.mfa`.
"""

from .associators import (AssocoptGNN, AssocoptKBest, AssocoptMFA, hypotheses_problem,
                          mfa_reference_cost)
from .jpda import AssocoptJPDA
from .problems import ProbabilityProblem, probability_problem

__all__ = ["AssocoptGNN", "AssocoptJPDA", "AssocoptKBest", "AssocoptMFA",
           "ProbabilityProblem", "hypotheses_problem", "mfa_reference_cost",
           "probability_problem"]
