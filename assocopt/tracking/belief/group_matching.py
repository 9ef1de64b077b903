"""Matching measures between two sensors' observations of one group (paper 000).

Every observation ``z = {p, a}`` has a 2-D position ``p`` with its noise covariance
and an attribute BBA ``a`` on the type frame (a mass vector of length ``2**T``,
see :mod:`assocopt.tracking.belief`).  For every pair of observations the pipeline is

1. position belief on ``{M, Mbar}`` (eqs. 1-2, the chi-square(2) p-value):
   ``m^p(M) = exp(-d^2 / 2)`` with ``d^2`` the squared Mahalanobis distance under
   ``Sigma_a + Sigma_b`` (ours: not given; ``c = 2``, valid for 2-D positions only);
2. attribute belief (eqs. 5-6): ``m^a(M) = 1 - K``, ``m^a(Mbar) = K`` with ``K`` the
   new conflict (4) or, for MM-TBM, the traditional conflict (3);
3. discounting by ``r_p``, ``r_a`` (eqs. 7-9);
4. combination: the new rule (10)-(11) for **MM-NCR**, Smets' conjunctive rule for
   **MM-TBM**; ``pi = m(M)`` (eq. 12).  **MM-WA** (formula not printed) is
   ``pi = w_p m^p(M) + w_a m^a(M)`` on the undiscounted (1) and (5).

Everything is computed for all pairs at once with the stacked-vector operations of
:mod:`assocopt.tracking.belief` (closed forms on the 2-element frame are the tests' oracle).

This module also holds the relation bookkeeping shared by the decision rules
(:class:`Relations`) and the paper's metric, :func:`correct_match_rate`.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass
from typing import Any, Iterable, Sequence

import numpy as np
from numpy.typing import ArrayLike

from .combination import conflict_matrix, conjunctive_vectors, discount_vectors
from .mass import InvalidMassError, check_vectors
from .zhang import zhang_combination_vectors, zhang_conflict_matrix
from ...runtime.errors import AssocoptError
from ...problems.validation import finite_floats

__all__ = [
    "MATCH_FRAME", "MEASURES", "SAME_SENSOR_READINGS", "MeasureParams", "Observations",
    "squared_mahalanobis", "position_belief", "attribute_conflict", "match_masses",
    "combined_masses", "mm_ncr", "mm_tbm", "mm_wa", "pair_measure", "pair_components",
    "matching_matrix",
    "Relations", "true_relations", "correct_match_rate", "InvalidObservationsError",
]

#: The pair frame ``Theta = {M, Mbar}``: bit 0 = M (match), bit 1 = Mbar; 3 = Theta.
MATCH_FRAME = ("M", "Mbar")
_M, _MBAR, _THETA = 1, 2, 3

#: Matching measures: new conflict + new rule, traditional conflict + Smets' rule,
#: weighted average.
MEASURES = ("ncr", "tbm", "wa")

#: How pi is filled for two observations of the same sensor (paper: cross-sensor only):
#: ``"formula"`` applies the cross-sensor formulas (our default);
#: ``"zero"`` sets pi = 0 (same-sensor observations never look alike).
SAME_SENSOR_READINGS = ("formula", "zero")


class InvalidObservationsError(AssocoptError, ValueError):
    """Observation arrays of the wrong shape, non-finite values, or bad sensor labels."""


@dataclass(frozen=True)
class MeasureParams:
    """Which matching measure, and its parameters.

    Attributes
    ----------
    measure : {"ncr", "tbm", "wa"}
        MM-NCR (paper's), MM-TBM (paper's baseline), MM-WA (formula not printed).
    r_p, r_a : float
        Reliability factors of eqs. (7)-(9) (ncr, tbm).  Paper: 1 and 0.6 in
        Experiment 1a; ``r(1,k)``, ``r(2,k)`` in 1b; not given in Experiment 2.
    w_p, w_a : float
        MM-WA weights (paper: ``w(1,k)``, ``w(2,k)`` in 1b).
    wa_conflict : {"new", "traditional"}
        Conflict inside MM-WA's ``m^a`` ("new": eq. (5) with K^a of (4), as §3.3
        defines it).
    same_sensor : {"formula", "zero"}
        See :data:`SAME_SENSOR_READINGS`.
    """

    measure: str = "ncr"
    r_p: float = 1.0
    r_a: float = 0.6
    w_p: float = 0.5
    w_a: float = 0.5
    wa_conflict: str = "new"
    same_sensor: str = "formula"

    def __post_init__(self) -> None:
        if self.measure not in MEASURES:
            raise ValueError(f"measure must be one of {MEASURES}, got {self.measure!r}")
        if self.wa_conflict not in ("new", "traditional"):
            raise ValueError("wa_conflict must be 'new' or 'traditional', "
                             f"got {self.wa_conflict!r}")
        if self.same_sensor not in SAME_SENSOR_READINGS:
            raise ValueError(f"same_sensor must be one of {SAME_SENSOR_READINGS}, "
                             f"got {self.same_sensor!r}")
        for name in ("r_p", "r_a", "w_p", "w_a"):
            v = getattr(self, name)
            if not (isinstance(v, (int, float)) and 0.0 <= v <= 1.0):
                raise ValueError(f"{name} must be a number in [0, 1], got {v!r}")

    def as_dict(self) -> dict[str, Any]:
        return asdict(self)


@dataclass(frozen=True, eq=False)
class Observations:
    """The pooled observations ``Z = Z_1 then Z_2`` of two sensors (paper 000 §4).

    Attributes
    ----------
    positions : ndarray (N, 2)
    covariances : ndarray (N, 2, 2)
        Position-noise covariance of each measurement (symmetric positive definite).
    attributes : ndarray (N, 2**T)
        Attribute BBAs as mass vectors on the type frame.
    sensor : ndarray (N,) of int
        1 or 2.  The paper pools sensor 1 first; any order is accepted.
    types : tuple
        Names of the type frame's elements (bit order of ``attributes``).
    """

    positions: np.ndarray
    covariances: np.ndarray
    attributes: np.ndarray
    sensor: np.ndarray
    types: tuple

    def __post_init__(self) -> None:
        P = finite_floats(self.positions, "positions", InvalidObservationsError, plural=True)
        if P.ndim != 2 or P.shape[1] != 2:
            raise InvalidObservationsError(f"positions must have shape (N, 2), got {P.shape}")
        n = len(P)
        C = finite_floats(self.covariances, "covariances", InvalidObservationsError,
                          plural=True)
        if C.shape != (n, 2, 2):
            raise InvalidObservationsError(
                f"covariances must have shape ({n}, 2, 2), got {C.shape}")
        if n and (not np.allclose(C, C.transpose(0, 2, 1))
                  or (np.linalg.eigvalsh(C)[:, 0] <= 0).any()):
            raise InvalidObservationsError("covariances must be symmetric positive definite")
        types = tuple(self.types)
        try:
            A = check_vectors(self.attributes, "attributes")
        except InvalidMassError as exc:
            raise InvalidObservationsError(str(exc)) from exc
        if A.shape != (n, 1 << len(types)):
            raise InvalidObservationsError(
                f"attributes must have shape ({n}, {1 << len(types)}) for {len(types)} types, "
                f"got {A.shape}")
        s = np.asarray(self.sensor)
        if s.shape != (n,) or not np.isin(s, (1, 2)).all():
            raise InvalidObservationsError(f"sensor must be {n} labels in {{1, 2}}, got {s!r}")
        for name, arr in (("positions", P), ("covariances", C), ("attributes", A),
                          ("sensor", s.astype(np.int64))):
            arr = np.array(arr)
            arr.setflags(write=False)
            object.__setattr__(self, name, arr)
        object.__setattr__(self, "types", types)

    @classmethod
    def from_sensors(cls, positions1: ArrayLike, attributes1: ArrayLike,
                     positions2: ArrayLike, attributes2: ArrayLike, *,
                     covariances1: ArrayLike, covariances2: ArrayLike,
                     types: Sequence) -> "Observations":
        """Pool ``Z_1`` and ``Z_2`` (sensor 1 first), as the paper does."""
        P1 = np.asarray(positions1, dtype=np.float64).reshape(-1, 2)
        P2 = np.asarray(positions2, dtype=np.float64).reshape(-1, 2)
        size = 1 << len(tuple(types))
        A1 = np.asarray(attributes1, dtype=np.float64).reshape(-1, size)
        A2 = np.asarray(attributes2, dtype=np.float64).reshape(-1, size)
        C1 = np.asarray(covariances1, dtype=np.float64).reshape(-1, 2, 2)
        C2 = np.asarray(covariances2, dtype=np.float64).reshape(-1, 2, 2)
        return cls(np.concatenate([P1, P2]), np.concatenate([C1, C2]),
                   np.concatenate([A1, A2]),
                   np.concatenate([np.ones(len(P1), np.int64), np.full(len(P2), 2)]),
                   tuple(types))

    @property
    def n(self) -> int:
        """N_Sigma, the number of pooled observations."""
        return len(self.positions)

    def of_sensor(self, s: int) -> np.ndarray:
        """Pooled indices of sensor ``s``'s observations, in pooled order."""
        return np.flatnonzero(self.sensor == s)


# ------------------------------------------------------------- components
def squared_mahalanobis(pa: ArrayLike, ca: ArrayLike, pb: ArrayLike, cb: ArrayLike) -> np.ndarray:
    """``d^2[i, j] = (pa_i - pb_j)^T (ca_i + cb_j)^{-1} (pa_i - pb_j)``, in bulk.

    ``pa`` (Na, 2), ``ca`` (Na, 2, 2), ``pb`` (Nb, 2), ``cb`` (Nb, 2, 2).
    """
    pa, pb = np.asarray(pa, np.float64), np.asarray(pb, np.float64)
    ca, cb = np.asarray(ca, np.float64), np.asarray(cb, np.float64)
    diff = pa[:, None, :] - pb[None, :, :]
    S = ca[:, None] + cb[None, :]
    a, b, d = S[..., 0, 0], S[..., 0, 1], S[..., 1, 1]     # symmetric 2x2: closed-form inverse
    det = a * d - b * b
    x, y = diff[..., 0], diff[..., 1]
    return (d * x * x - 2.0 * b * x * y + a * y * y) / det


def position_belief(d2: ArrayLike) -> np.ndarray:
    """``m^p(M) = c / (2 Gamma(1)) exp(-d^2/2)`` with ``c = 2`` (eq. 1), i.e. ``exp(-d^2/2)``.

    It is the chi-square(2) survival function of ``d^2``.  Only valid for
    2-D positions (for 1-D the density is unbounded at 0, for 3-D it is 0 there).
    """
    return np.exp(-0.5 * np.asarray(d2, dtype=np.float64))


def attribute_conflict(aa: ArrayLike, ab: ArrayLike, kind: str = "new") -> np.ndarray:
    """Attribute conflict matrix between rows of ``aa`` and ``ab``: eq. (4) or eq. (3)."""
    if kind == "new":
        return np.clip(zhang_conflict_matrix(aa, ab), 0.0, 1.0)
    if kind == "traditional":
        return np.clip(conflict_matrix(aa, ab), 0.0, 1.0)
    raise ValueError(f"kind must be 'new' or 'traditional', got {kind!r}")


def match_masses(belief_match: ArrayLike) -> np.ndarray:
    """Stacked vectors on ``{M, Mbar}`` with ``m(M) = x``, ``m(Mbar) = 1 - x`` (eqs. 2, 5-6)."""
    x = np.asarray(belief_match, dtype=np.float64)
    out = np.zeros(x.shape + (4,))
    out[..., _M] = x
    out[..., _MBAR] = 1.0 - x
    return out


def combined_masses(mp_match: ArrayLike, conflict: ArrayLike, *, r_p: float, r_a: float,
                    rule: str) -> np.ndarray:
    """Combined mass vectors ``(..., 4)`` on ``{M, Mbar}`` for every pair.

    ``mp_match``: ``m^p(M)``; ``conflict``: the attribute conflict K (eq. 4 for the
    new rule, eq. 3 for Smets'); both discounted first (eqs. 7-9), then combined by
    ``rule`` = ``"zhang"`` (10)-(11) or ``"conjunctive"`` (Smets).
    """
    mp = discount_vectors(match_masses(mp_match), r_p)
    ma = discount_vectors(match_masses(1.0 - np.asarray(conflict, dtype=np.float64)), r_a)
    if rule == "zhang":
        return zhang_combination_vectors(mp, ma)
    if rule == "conjunctive":
        return conjunctive_vectors(mp, ma)
    raise ValueError(f"rule must be 'zhang' or 'conjunctive', got {rule!r}")


def mm_ncr(mp_match: ArrayLike, k_new: ArrayLike, r_p: float, r_a: float) -> np.ndarray:
    """MM-NCR: ``pi = m(M)`` of the new rule on the discounted m^p and m^a (K from eq. 4)."""
    return combined_masses(mp_match, k_new, r_p=r_p, r_a=r_a, rule="zhang")[..., _M]


def mm_tbm(mp_match: ArrayLike, k_traditional: ArrayLike, r_p: float, r_a: float) -> np.ndarray:
    """MM-TBM: ``pi = m(M)`` of Smets' rule on the discounted m^p and m^a (K0 from eq. 3)."""
    return combined_masses(mp_match, k_traditional, r_p=r_p, r_a=r_a,
                           rule="conjunctive")[..., _M]


def mm_wa(mp_match: ArrayLike, k_new: ArrayLike, w_p: float, w_a: float) -> np.ndarray:
    """MM-WA (ours, formula not printed): ``pi = w_p m^p(M) + w_a m^a(M)``, undiscounted."""
    return w_p * np.asarray(mp_match, np.float64) + w_a * (1.0 - np.asarray(k_new, np.float64))


def pair_measure(mp_match: ArrayLike, k_new: ArrayLike, k_traditional: ArrayLike,
                 params: MeasureParams) -> np.ndarray:
    """``pi`` for the measure named in ``params`` from precomputed components."""
    if params.measure == "ncr":
        return mm_ncr(mp_match, k_new, params.r_p, params.r_a)
    if params.measure == "tbm":
        return mm_tbm(mp_match, k_traditional, params.r_p, params.r_a)
    k = k_new if params.wa_conflict == "new" else k_traditional
    return mm_wa(mp_match, k, params.w_p, params.w_a)


def matching_matrix(obs: Observations, params: MeasureParams | None = None, *,
                    components: tuple[np.ndarray, np.ndarray, np.ndarray] | None = None,
                    **overrides: Any) -> np.ndarray:
    """The pooled ``N_Sigma x N_Sigma`` matrix ``pi`` (paper §4), diagonal NaN (never used).

    Same-sensor entries follow ``params.same_sensor``.  Keyword overrides
    replace fields of ``params`` (default :class:`MeasureParams`).  ``components``:
    the output of :func:`pair_components` for ``obs``, to share it between measures.

    Examples
    --------
    >>> import numpy as np
    >>> obs = Observations.from_sensors([[0, 0]], np.eye(4)[[3]], [[0, 0]], np.eye(4)[[3]],
    ...                                 covariances1=[np.eye(2)], covariances2=[np.eye(2)],
    ...                                 types=("t1", "t2"))
    >>> float(matching_matrix(obs, measure="ncr", r_p=1.0, r_a=1.0)[0, 1])   # K^a = 1/2
    0.5
    """
    params = MeasureParams(**{**(params.as_dict() if params else {}), **overrides})
    if components is None:
        components = pair_components(obs)
    pi = pair_measure(*components, params=params)
    if params.same_sensor == "zero":
        pi = np.where(obs.sensor[:, None] == obs.sensor[None, :], 0.0, pi)
    np.fill_diagonal(pi, np.nan)
    return pi


def pair_components(obs: Observations) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(m^p(M), K^a (4), K^a0 (3))`` for all pooled pairs: the measure-independent part."""
    d2 = squared_mahalanobis(obs.positions, obs.covariances, obs.positions, obs.covariances)
    return (position_belief(d2), attribute_conflict(obs.attributes, obs.attributes, "new"),
            attribute_conflict(obs.attributes, obs.attributes, "traditional"))


# --------------------------------------------------------------- relations
@dataclass(frozen=True)
class Relations:
    """A partition of the pooled observations into matched pairs and isolated points.

    ``pairs``: ``(i, j)`` pooled indices, ``i`` from sensor 1 and ``j`` from sensor 2
    (relation ``z_1i <-> z_2j``), sorted; ``isolated``: pooled indices of
    observations with no partner (``z_1i <-> *`` or ``* <-> z_2j``), sorted.
    Construction checks that every observation is in exactly one relation and
    that each pair joins the two sensors.
    """

    n: int
    pairs: tuple[tuple[int, int], ...]
    isolated: tuple[int, ...]

    @classmethod
    def from_clusters(cls, clusters: Iterable[Iterable[int]], sensor: ArrayLike) -> "Relations":
        """From clusters of one or two pooled indices; raises AssertionError if not a partition."""
        s = np.asarray(sensor)
        n = len(s)
        pairs, isolated = [], []
        for c in clusters:
            c = tuple(int(i) for i in c)
            if len(c) == 1:
                isolated.append(c[0])
            elif len(c) == 2:
                if s[c[0]] == s[c[1]]:
                    raise AssertionError(f"cluster {c} joins two observations of sensor {s[c[0]]}")
                pairs.append(c if s[c[0]] == 1 else (c[1], c[0]))
            else:
                raise AssertionError(f"cluster {c} has {len(c)} observations, not 1 or 2")
        rel = cls(n, tuple(sorted(pairs)), tuple(sorted(isolated)))
        rel.check()
        return rel

    def check(self) -> None:
        """Raise AssertionError unless every observation is in exactly one relation."""
        count = np.zeros(self.n, dtype=np.int64)
        members = [i for p in self.pairs for i in p] + list(self.isolated)
        if any(not 0 <= i < self.n for i in members):
            raise AssertionError(f"relation index out of range 0..{self.n - 1}")
        np.add.at(count, np.asarray(members, dtype=np.int64), 1)
        bad = np.flatnonzero(count != 1)
        if len(bad):
            raise AssertionError(
                f"observation {int(bad[0])} is in {int(count[bad[0]])} relations, not exactly one")

    def as_set(self) -> frozenset:
        """The relations as a set of frozensets (one or two pooled indices each)."""
        return frozenset([frozenset(p) for p in self.pairs] +
                         [frozenset((i,)) for i in self.isolated])

    def __len__(self) -> int:
        return len(self.pairs) + len(self.isolated)


def true_relations(target: ArrayLike, sensor: ArrayLike) -> Relations:
    """Ground-truth relations: observations of the same target by the two sensors pair up."""
    t = np.asarray(target)
    s = np.asarray(sensor)
    clusters: dict[Any, list[int]] = {}
    for i, tid in enumerate(t.tolist()):
        clusters.setdefault(tid, []).append(i)
    return Relations.from_clusters(clusters.values(), s)


def correct_match_rate(decided: Relations, truth: Relations) -> float:
    """Paper 000's correct matching rate P_c for one run (ours: the paper does not define it).

    Correct decided relations (matched pairs and isolated observations that are
    also true relations) divided by the number of true relations.  A run with no
    observations has rate 1 (nothing to get wrong).
    """
    if decided.n != truth.n:
        raise ValueError(f"decided relations cover {decided.n} observations, truth {truth.n}")
    if len(truth) == 0:
        return 1.0
    return len(decided.as_set() & truth.as_set()) / len(truth)
