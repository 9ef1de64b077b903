"""Three-baseline TDOA location in the plane: measurements, a linear closed-form fix with
its covariance, and the Jacobian an EKF needs (paper 001's sensors; docs/papers/yan2010.md).

A system has a main station ``s0`` and three auxiliary stations ``s_k = s0 + L u_k``
(baseline length ``L``, unit vectors ``u_k`` 120 degrees apart).  It measures the three
time differences ``tau_k = (|x - s_k| - |x - s0|) / c + noise`` (independent noise of
standard deviation ``sigma`` per baseline), i.e. the range differences
``d_k = c tau_k``.

**Fix** (:meth:`TdoaSystem.fix`): with ``u = x - s0``, ``b_k = s_k - s0`` and the
unknown main-station range ``r0 = |u|``, squaring ``|u - b_k| = r0 + d_k`` and
subtracting ``|u|^2 = r0^2`` gives three equations linear in ``(u, r0)``::

    b_k . u + d_k r0 = (|b_k|^2 - d_k^2) / 2,   k = 1, 2, 3

-- the first stage of Chan's method (the spherical-interpolation equations), exactly
determined with three baselines in the plane, so solved directly.  **Covariance**:
differentiating ``A(d) theta = y(d)`` gives ``d theta / d d_k = -A^-1 e_k (r0 + d_k)``,
so ``J = -A^-1 diag(r0 + d_k)`` and ``P = J_u (c sigma)^2 J_u^T`` (``J_u``: the two
position rows), evaluated at the estimate: first order, tested by Monte Carlo (NEES).

>>> import numpy as np
>>> s = TdoaSystem(main=(0.0, 0.0), baseline=25e3, sigma=30e-9)
>>> x = np.array([[40e3, 60e3]])
>>> bool(np.allclose(s.fix(s.tdoa(x)).position, x))
True
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property
from typing import NamedTuple

import numpy as np
from numpy.typing import ArrayLike

__all__ = ["C_LIGHT", "TdoaSystem", "TdoaFix", "range_differences", "range_jacobian"]

#: Speed of light (m/s).
C_LIGHT = 299_792_458.0


class TdoaFix(NamedTuple):
    """Positions ``(N, 2)`` and their first-order covariances ``(N, 2, 2)``."""

    position: np.ndarray
    covariance: np.ndarray


@dataclass(frozen=True)
class TdoaSystem:
    """A main station and three baselines (lengths in m, angles in degrees, sigma in s)."""

    main: tuple[float, float]
    baseline: float
    sigma: float
    angles_deg: tuple[float, float, float] = (90.0, 210.0, 330.0)

    def __post_init__(self) -> None:
        if not (self.baseline > 0 and self.sigma >= 0 and len(self.angles_deg) == 3):
            raise ValueError(f"need baseline > 0, sigma >= 0 and three baseline angles, got "
                             f"{self.baseline!r}, {self.sigma!r}, {self.angles_deg!r}")

    @cached_property
    def stations(self) -> np.ndarray:
        """``(4, 2)``: the main station, then the three auxiliary stations (computed once,
        read-only: a tracker asks for them at every scan)."""
        a = np.radians(np.asarray(self.angles_deg, dtype=float))
        s0 = np.asarray(self.main, dtype=float)
        st = np.vstack([s0, s0 + self.baseline * np.stack([np.cos(a), np.sin(a)], axis=1)])
        st.flags.writeable = False
        return st

    @property
    def range_sigma(self) -> float:
        """Standard deviation of a range difference (m)."""
        return C_LIGHT * self.sigma

    def range_differences(self, x: ArrayLike) -> np.ndarray:
        """``|x - s_k| - |x - s0|`` for ``x`` ``(..., 2)`` -> ``(..., 3)`` (m)."""
        return range_differences(x, self.stations)

    def jacobian(self, x: ArrayLike) -> np.ndarray:
        """Jacobian of :meth:`range_differences` with respect to position, ``(..., 3, 2)``."""
        return range_jacobian(x, self.stations)

    def tdoa(self, x: ArrayLike, rng: np.random.Generator | None = None) -> np.ndarray:
        """Time differences (s) ``(..., 3)`` of emitters at ``x`` ``(..., 2)``; noisy when ``rng``
        is given (one draw per difference, in the order of ``x``)."""
        t = self.range_differences(x) / C_LIGHT
        if rng is not None:
            t = t + rng.normal(0.0, self.sigma, size=t.shape)
        return t

    def fix(self, tdoa: ArrayLike) -> TdoaFix:
        """The linear closed-form fix and its covariance (module docstring)."""
        d = C_LIGHT * np.atleast_2d(np.asarray(tdoa, dtype=float))
        if d.shape[-1] != 3:
            raise ValueError(f"need three time differences per emitter, got shape {d.shape}")
        st = self.stations
        b = st[1:] - st[0]                                         # (3, 2)
        A = np.concatenate([np.broadcast_to(b, d.shape + (2,)), d[..., None]], axis=-1)
        y = 0.5 * ((b ** 2).sum(axis=1) - d ** 2)
        Ainv = np.linalg.pinv(A)                                   # (N, 3, 3); exact if regular
        theta = (Ainv @ y[..., None])[..., 0]
        J = -Ainv * (theta[..., 2:3] + d)[..., None, :]            # columns scaled by r0 + d_k
        Ju = J[..., :2, :]
        P = self.range_sigma ** 2 * Ju @ np.swapaxes(Ju, -1, -2)
        return TdoaFix(theta[..., :2] + st[0], P)


def range_differences(x: ArrayLike, stations: np.ndarray) -> np.ndarray:
    """``|x - s_k| - |x - s0|`` for ``x`` ``(..., 2)`` and ``stations`` ``(4, 2)``, or one
    set of stations per point ``(..., 4, 2)`` (several systems' tracks in one batch)
    -> ``(..., 3)`` (m)."""
    x = np.asarray(x, dtype=float)
    r = np.linalg.norm(x[..., None, :] - stations, axis=-1)
    return r[..., 1:] - r[..., :1]


def range_jacobian(x: ArrayLike, stations: np.ndarray) -> np.ndarray:
    """Jacobian of :func:`range_differences` with respect to position, ``(..., 3, 2)``."""
    x = np.asarray(x, dtype=float)
    d = x[..., None, :] - stations
    u = d / np.linalg.norm(d, axis=-1, keepdims=True)
    return u[..., 1:, :] - u[..., :1, :]
