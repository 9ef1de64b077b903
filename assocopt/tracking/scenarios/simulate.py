"""A seeded constant-velocity multi-target scenario in the plane, with clutter.

The scenario of the guide's tracking loops, the Stone Soup comparison and its
benchmark: ``n_targets`` targets with nearly constant velocity (white-noise
acceleration of intensity ``q``), position measurements with noise ``sigma``,
detected with probability ``pd``, and a Poisson number of false alarms (mean
``clutter_rate`` per scan) uniform over ``region``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ...runtime.errors import InvalidProblemError

__all__ = ["CVScenario", "CrossingScenario", "Scans"]


@dataclass(frozen=True)
class Scans:
    """What :meth:`CVScenario.simulate` returns.

    Attributes
    ----------
    truth : ndarray (n_steps + 1, n_targets, 4)
        ``[x, vx, y, vy]`` of every target at every time (index 0 = the start).
    meas : list of n_steps arrays (M_t, 2)
        Position measurements of scans 1 .. n_steps, in random order.
    labels : list of n_steps arrays (M_t,)
        Target of each measurement, -1 for a false alarm.
    """

    truth: np.ndarray
    meas: list
    labels: list


@dataclass(frozen=True)
class CVScenario:
    """Constant-velocity targets seen by a position sensor with clutter.

    Examples
    --------
    >>> sc = CVScenario(n_targets=3, n_steps=5)
    >>> out = sc.simulate(np.random.default_rng(0))
    >>> out.truth.shape, len(out.meas)
    ((6, 3, 4), 5)
    """

    n_targets: int = 4
    n_steps: int = 20
    dt: float = 1.0
    q: float = 0.05
    sigma: float = 0.5
    pd: float = 0.95
    clutter_rate: float = 3.0
    region: tuple = ((-30.0, 30.0), (-30.0, 30.0))
    speed: float = 1.0

    def __post_init__(self) -> None:
        if int(self.n_targets) != self.n_targets or self.n_targets < 0:
            raise InvalidProblemError(f"n_targets must be an integer >= 0, got {self.n_targets}")
        if not 0 < self.pd <= 1:
            raise InvalidProblemError(f"pd must lie in (0, 1], got {self.pd}")
        if not (self.sigma > 0 and self.q >= 0 and self.clutter_rate >= 0 and self.dt > 0):
            raise InvalidProblemError("sigma and dt must be > 0, q and clutter_rate >= 0")

    @property
    def F(self) -> np.ndarray:
        """Transition matrix of ``[x, vx, y, vy]``."""
        f = np.array([[1.0, self.dt], [0.0, 1.0]])
        return np.kron(np.eye(2), f)

    @property
    def Q(self) -> np.ndarray:
        """Process noise (continuous white-noise acceleration, per axis)."""
        dt = self.dt
        q = self.q * np.array([[dt ** 3 / 3, dt ** 2 / 2], [dt ** 2 / 2, dt]])
        return np.kron(np.eye(2), q)

    @property
    def H(self) -> np.ndarray:
        """Position measurement matrix."""
        return np.array([[1.0, 0.0, 0.0, 0.0], [0.0, 0.0, 1.0, 0.0]])

    @property
    def R(self) -> np.ndarray:
        return np.eye(2) * self.sigma ** 2

    @property
    def area(self) -> float:
        (x0, x1), (y0, y1) = self.region
        return (x1 - x0) * (y1 - y0)

    @property
    def clutter_density(self) -> float:
        """False alarms per unit area (the lambda of the likelihood-ratio cost)."""
        return self.clutter_rate / self.area

    def initial_states(self, rng: np.random.Generator) -> np.ndarray:
        (x0, x1), (y0, y1) = self.region
        pos = np.stack([rng.uniform(x0, x1, self.n_targets) * 0.6,
                        rng.uniform(y0, y1, self.n_targets) * 0.6], axis=1)
        heading = rng.uniform(-np.pi, np.pi, self.n_targets)
        vel = self.speed * np.stack([np.cos(heading), np.sin(heading)], axis=1)
        return np.stack([pos[:, 0], vel[:, 0], pos[:, 1], vel[:, 1]], axis=1)

    def simulate(self, rng: np.random.Generator) -> Scans:
        """Truth and scans; ``rng`` (a ``numpy.random.Generator``) fixes every draw."""
        if not isinstance(rng, np.random.Generator):
            raise TypeError("rng must be a numpy.random.Generator")
        X = self.initial_states(rng)
        truth = [X]
        meas, labels = [], []
        Lq = np.linalg.cholesky(self.Q + 1e-12 * np.eye(4))
        (x0, x1), (y0, y1) = self.region
        for _ in range(self.n_steps):
            X = X @ self.F.T + rng.normal(size=X.shape) @ Lq.T
            truth.append(X)
            seen = np.flatnonzero(rng.random(self.n_targets) < self.pd)
            z = X[seen][:, [0, 2]] + rng.normal(scale=self.sigma, size=(len(seen), 2))
            n_fa = int(rng.poisson(self.clutter_rate))
            fa = np.stack([rng.uniform(x0, x1, n_fa), rng.uniform(y0, y1, n_fa)], axis=1)
            z = np.concatenate([z, fa])
            lab = np.concatenate([seen, -np.ones(n_fa, dtype=np.int64)])
            order = rng.permutation(len(z))
            meas.append(z[order])
            labels.append(lab[order])
        return Scans(np.stack(truth), meas, labels)


@dataclass(frozen=True)
class CrossingScenario(CVScenario):
    """Targets that cross in pairs: the two of pair ``j`` meet at one point, at a time
    drawn in the middle half of the run, with headings ``crossing_angle`` apart
    (radians); a last unpaired target flies alone.  Meeting points are spread over the
    middle 60 % of ``region``.

    Examples
    --------
    >>> sc = CrossingScenario(n_targets=4, n_steps=10, clutter_rate=0.0, q=0.0)
    >>> x = sc.initial_states(np.random.default_rng(0))
    >>> t = sc.crossing_times(np.random.default_rng(0))
    >>> bool(np.allclose(x[0, [0, 2]] + t[0] * x[0, [1, 3]], x[1, [0, 2]] + t[0] * x[1, [1, 3]]))
    True
    """

    crossing_angle: float = np.pi / 4

    def crossing_times(self, rng: np.random.Generator) -> np.ndarray:
        """Meeting time of each pair (the first draws of ``rng``)."""
        T = self.n_steps * self.dt
        return rng.uniform(0.25 * T, 0.75 * T, self.n_targets // 2)

    def initial_states(self, rng: np.random.Generator) -> np.ndarray:
        t_meet = self.crossing_times(rng)
        (x0, x1), (y0, y1) = self.region
        n = self.n_targets
        meet = np.stack([rng.uniform(x0, x1, (n + 1) // 2) * 0.6,
                         rng.uniform(y0, y1, (n + 1) // 2) * 0.6], axis=1)
        heading = rng.uniform(-np.pi, np.pi, (n + 1) // 2)
        heading = np.stack([heading, heading + self.crossing_angle], axis=1).ravel()[:n]
        vel = self.speed * np.stack([np.cos(heading), np.sin(heading)], axis=1)
        t = np.repeat(np.concatenate([t_meet, [0.0] * (n % 2)]), 2)[:n]
        pos = np.repeat(meet, 2, axis=0)[:n] - vel * t[:, None]
        return np.stack([pos[:, 0], vel[:, 0], pos[:, 1], vel[:, 1]], axis=1)
