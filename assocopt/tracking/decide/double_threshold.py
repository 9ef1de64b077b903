"""Double-threshold (I/R, "M out of N") confirmation of trial pairs over time steps,
with the two tie-breaks of Dong et al. 2015, eqs. (18)-(19).

Each step delivers the trial pairs (a sensor-2 partner per sensor-1 track, ``-1`` for
none) and the degree matrix Phi.  The association quality ``m_uv`` counts the steps of
the current window in which (u, v) was a trial pair; (u, v) is *confirmed* when
``m_uv >= I``.  When several v reach I for one u: the largest ``m_uv`` (18), then the
smallest mean of ``lambda_uv`` over the window (19: the paper's "average norm of the
association-measure vector", read as the 1-norm over R, i.e. the mean), then the
smallest index.

Criteria (:class:`IRRule`):

``"dynamic"``  (ours, from the paper's example list 1/1, 2/2, 2/3, 3/4, 3/5, 4/6, 5/7,
               6/8, ...): at step k the window is every step so far up to ``R_max``
               (R = min(k, R_max)) and I is the list's entry for that R (I = R - 2
               beyond the list); the window then slides.  Every step has a decision.
``"fixed"``    one I/R with a sliding window of the last R steps (whether the paper's
               window slides is not said); nothing is confirmed before step I.

``exclusive`` (ours) also gives each sensor-2 track at most one partner: confirmed
pairs are kept in the order of (18)-(19) and a pair whose v is taken is dropped.
Without it, each sensor-1 track has at most one partner (what the rule promises).

>>> dt = DoubleThreshold(2, 2, IRRule("fixed", I=2, R=3))
>>> phi = np.array([[1.0, 5.0], [5.0, 1.0]])
>>> dt.update(np.array([0, 1]), phi).tolist(), dt.update(np.array([0, 1]), phi).tolist()
([-1, -1], [0, 1])
"""

from __future__ import annotations

from dataclasses import asdict, dataclass
from typing import Any

import numpy as np

__all__ = ["IRRule", "DoubleThreshold", "DYNAMIC_SCHEDULE"]

#: (I, R) of the dynamic criterion for R = 1..8 (the paper's examples without 4/5).
DYNAMIC_SCHEDULE = ((1, 1), (2, 2), (2, 3), (3, 4), (3, 5), (4, 6), (5, 7), (6, 8))


@dataclass(frozen=True)
class IRRule:
    """The I/R criterion (see the module docstring)."""

    schedule: str = "dynamic"
    I: int = 2
    R: int = 3
    exclusive: bool = False
    R_max: int = 4

    def __post_init__(self) -> None:
        if self.schedule not in ("dynamic", "fixed"):
            raise ValueError(f"schedule must be 'dynamic' or 'fixed', got {self.schedule!r}")
        if not (isinstance(self.I, int) and isinstance(self.R, int) and 1 <= self.I <= self.R):
            raise ValueError(f"need integers 1 <= I <= R, got I={self.I!r}, R={self.R!r}")
        if not isinstance(self.R_max, int) or self.R_max < 1:
            raise ValueError(f"R_max must be a positive integer, got {self.R_max!r}")

    def criterion(self, k: int) -> tuple[int, int]:
        """(I, R) at step ``k`` (1-based)."""
        if self.schedule == "fixed":
            return self.I, self.R
        R = min(k, self.R_max)
        if R <= len(DYNAMIC_SCHEDULE):
            return DYNAMIC_SCHEDULE[R - 1]
        return R - 2, R

    def as_dict(self) -> dict[str, Any]:
        return asdict(self)


class DoubleThreshold:
    """The I/R state of one pair of sensors with fixed track index sets."""

    def __init__(self, n1: int, n2: int, rule: IRRule | None = None):
        self.n1, self.n2 = int(n1), int(n2)
        self.rule = rule or IRRule()
        self.trials: list[np.ndarray] = []
        self.phis: list[np.ndarray] = []

    def update(self, trial: np.ndarray, phi: np.ndarray) -> np.ndarray:
        """Add one step; the confirmed partner of each sensor-1 track (``-1``: none)."""
        trial = np.asarray(trial, dtype=np.int64)
        phi = np.asarray(phi, dtype=np.float64)
        if trial.shape != (self.n1,) or phi.shape != (self.n1, self.n2):
            raise ValueError(f"trial must have shape ({self.n1},) and phi "
                             f"({self.n1}, {self.n2}); got {trial.shape}, {phi.shape}")
        if ((trial < -1) | (trial >= self.n2)).any():
            raise ValueError("trial partners must be -1 or a sensor-2 index")
        hit = np.zeros((self.n1, self.n2), dtype=np.int64)
        ok = trial >= 0
        hit[np.flatnonzero(ok), trial[ok]] = 1
        self.trials.append(hit)
        self.phis.append(phi)
        I, R = self.rule.criterion(len(self.trials))
        m = np.sum(self.trials[-R:], axis=0)
        mean_lam = np.mean(self.phis[-R:], axis=0)
        return self._decide(m, mean_lam, I)

    def _decide(self, m: np.ndarray, mean_lam: np.ndarray, I: int) -> np.ndarray:
        out = np.full(self.n1, -1, dtype=np.int64)
        cand = m >= I
        rows = np.flatnonzero(cand.any(axis=1))
        # order every candidate by (18) largest m, (19) smallest mean lambda, index
        key_m = np.where(cand, m, -1)
        for u in rows:
            best = np.flatnonzero(key_m[u] == key_m[u].max())
            out[u] = best[np.argmin(mean_lam[u, best])]     # argmin: first on ties
        if self.rule.exclusive and len(rows):
            order = sorted(rows, key=lambda u: (-m[u, out[u]], mean_lam[u, out[u]], u))
            taken: set[int] = set()
            for u in order:
                if int(out[u]) in taken:
                    out[u] = -1
                else:
                    taken.add(int(out[u]))
        return out
