"""Bearing geometry and least-squares localisation from angle-only sensors (paper 002).

One module per concept: :mod:`.geometry` (angles, Jacobians, line-of-sight system),
:mod:`.estimate` (the estimators), :mod:`.pseudo` (pseudo-measurements).

Conventions (docs/papers/lu2013.md)
-----------------------------------
* Angles are in **radians** everywhere inside the library; positions in any length
  unit (the paper's scenarios use km).  Only scenario files and reports use mrad.
* A sensor measures ``theta = [alpha, beta]``: **elevation first**, then azimuth.
  ``beta = atan2(dy, dx)`` (four-quadrant), ``alpha = atan2(dz, rho)`` with
  ``rho = hypot(dx, dy)``, ``d = x - x*_s``.
* Batches: ``K`` candidate tuples of ``N`` sensors.  ``meas`` has shape ``(K, N, 2)``;
  ``mask`` (``(K, N)`` bool) marks the sensors that contribute a real measurement
  (``False`` = dummy).  Dummy sensors get zero rows in ``H`` and ``Y``, so tuples with
  different numbers of real measurements are solved in one batched call.  A tuple needs
  at least 2 real measurements (4 equations, 3 unknowns) to be localised.

Estimators (``method=``)
------------------------
``"ls"``
    The paper's linear least squares (14) on the line-of-sight equations (9)-(13).
``"ils"``
    Iterated (Gauss-Newton, weighted) least squares on the angle residuals, started
    at the LS solution: the maximum-likelihood estimate under Gaussian angle noise.
``"tls"``
    Total least squares of ``[H | Y]`` (H holds noisy angles too), unweighted.

Covariance (15)-(16) uses, by default, the Jacobian of the equation *residual*
``e(m) = H(m) x - Y(m)`` with respect to the measured angles (not Y alone as (16) does,
``covariance="residual"``); ``covariance="printed"`` is the literal ``dY/dm`` of (16),
kept only to show that it is wrong (it depends on the origin and is 0 for a sensor at
the origin).  For ``"ils"`` the covariance is ``(G^T R^-1 G)^-1`` at the estimate.
For ``"tls"`` the residual sandwich is evaluated at the TLS estimate (first order).
"""

from .estimate import (COVARIANCES, METHODS, RCOND_MIN, Localisation, localise,  # noqa: F401
                       localise_indexed)
from .geometry import angle_jacobian, angles, los_system, residual_jacobian, wrap_angle
from .pseudo import PseudoMeasurements, pseudo_measurements

__all__ = ["angles", "angle_jacobian", "wrap_angle", "los_system", "localise",
           "Localisation", "pseudo_measurements", "PseudoMeasurements",
           "residual_jacobian", "localise_indexed", "METHODS", "COVARIANCES"]
