"""Build the sparse S-D assignment problem of one passive-sensor scan (paper 002).

Pipeline, all vectorised over the K candidate tuples at once (no loop per tuple):

1. :func:`candidate_tuples` -- every index combination (0 = dummy) allowed by the
   detection and false-alarm model (docs/papers/lu2013.md):

   * the all-dummy tuple is never a candidate;
   * a tuple with a dummy in sensor s needs ``P_Ds < 1`` (with ``P_D = 1`` it is
     dropped, never given an inf/NaN cost);
   * a tuple with one real measurement (false alarm, or a target seen once) is a
     candidate only if that measurement can be a false alarm (clutter density > 0) or
     every other sensor may miss; its cost is 0 by convention (it cannot be localised);
2. :func:`tuple_geometry` -- LS position (14) and covariance (15) of every tuple with
   >= 2 real measurements, and its pseudo-measurement statistics (22)-(23);
3. :func:`tuple_costs` -- the cost of each tuple for one named method (:data:`COSTS`);
4. :func:`build_problem` -- an :class:`~assocopt.problems.problem.AssignmentProblem`.

:func:`build_costs` does steps 1-3 for several methods sharing one geometry.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Sequence

import numpy as np
from numpy.typing import ArrayLike

from ...runtime.errors import InvalidProblemError
from ..localisation import localise_indexed, pseudo_measurements
from ...problems.problem import AssignmentProblem
from .data_terms import TupleGeometry, data_term
from .pattipati import NORMALISATIONS, constant_terms

__all__ = ["Scan", "COSTS", "PRINTED_COSTS", "candidate_tuples", "TupleGeometry",
           "tuple_geometry", "SDCosts", "tuple_costs", "tuple_costs_in_chunks", "build_costs",
           "build_problem"]

#: The named cost builders: name -> what it is.  "printed" = exactly as printed in
#: paper 002 (not true divergences); "exact" = the exact 1-D Gaussian forms with the
#: independence step (26); "joint" = the exact 2-D Gaussian divergence of each
#: sensor's [alpha, beta] pair, without (26).
COSTS: dict[str, str] = {
    "pattipati": "eq. (7): 1/2 Delta^T R^-1 Delta with the LS position (ref. [2] of paper 002)",
    "kld-printed": "eqs. (24)+(26)+(27) exactly as printed (not a KL divergence: negative "
                   "when s~ < s)",
    "skld-printed": "eqs. (25)+(26)+(28) exactly as printed (not the symmetric KL: no "
                    "variance term)",
    "kld-exact": "eqs. (24)+(26) with the exact 1-D Gaussian KL divergence "
                 "KL(pseudo-measurement || measurement)",
    "skld-exact": "eqs. (25)+(26) with the exact 1-D symmetric KL (Jeffreys) divergence",
    "kld-joint": "eq. (24) with the exact 2-D Gaussian KL of each sensor's (alpha, beta)",
    "skld-joint": "eq. (25) with the exact 2-D Gaussian symmetric KL of each sensor's "
                  "(alpha, beta)",
    "pattipati-ml": "eq. (7) with the maximum-likelihood position (iterated LS, Gauss-Newton) "
                    "instead of the one-step LS (14)",
    "kld-reversed": "eqs. (24)+(26) with the exact 1-D KL divergence, arguments swapped: "
                    "KL(measurement || pseudo-measurement), mean difference weighted by "
                    "1/s~^2",
}
#: Costs that localise with their own method, whatever the run's ``localiser``.
COST_LOCALISER: dict[str, str] = {"pattipati-ml": "ils"}
#: The costs as the paper prints them (what its tables report).
PRINTED_COSTS = ("pattipati", "kld-printed", "skld-printed")


@dataclass(frozen=True)
class Scan:
    """One scan of N angle-only sensors: azimuth-elevation in space, or azimuth-only
    in the plane (chosen by the sensors' dimension).

    Attributes
    ----------
    sensors : (N, 3) positions, or (N, 2) for azimuth-only sensors in the plane (same
        length unit as the targets; km in paper 002)
    meas : list of N arrays (n_s, 2) or, in the plane, (n_s, 1)
        ``[alpha, beta]`` (elevation, azimuth) of each measurement, or the azimuth
        ``[beta]`` alone, **rad**.
    R : list of N arrays (n_s, 2, 2) or (n_s, 1, 1)
        Noise covariance of each measurement, rad^2.
    pd : (N,) detection probabilities, in (0, 1].
    clutter_density : (N,) false alarms per rad^2 (per rad in the plane) of the field
        of view (0 = none).
    """

    sensors: np.ndarray
    meas: tuple
    R: tuple
    pd: np.ndarray
    clutter_density: np.ndarray

    @classmethod
    def create(cls, sensors: ArrayLike, meas: Sequence[ArrayLike],
               R: Sequence[ArrayLike] | ArrayLike, pd: ArrayLike = 1.0,
               clutter_density: ArrayLike = 0.0) -> "Scan":
        """Validate and normalise.  ``R`` may be one 2x2 matrix, one per sensor
        ``(N, 2, 2)``, or one per measurement (a list of ``(n_s, 2, 2)``); for
        azimuth-only sensors (``sensors`` of shape ``(N, 2)``) a variance, one per
        sensor ``(N,)``, or a list of ``(n_s,)``.

        >>> s = Scan.create([[0, 0, 0], [1, 0, 0]], [[[0.1, 0.2]], [[0.1, 2.0]]],
        ...                 np.eye(2) * 1e-6)
        >>> s.sizes, s.pd.tolist()
        ((1, 1), [1.0, 1.0])
        >>> Scan.create([[0, 0], [1, 0]], [[0.2, 0.5], [2.0]], 1e-6).sizes
        (2, 1)
        """
        S = np.asarray(sensors, dtype=np.float64)
        if S.ndim != 2 or S.shape[1] not in (2, 3) or len(S) < 2:
            raise InvalidProblemError("sensors must have shape (N, 3) (azimuth-elevation) or "
                                      f"(N, 2) (azimuth only), N >= 2; got {S.shape}")
        N, width = len(S), S.shape[1] - 1           # angles per measurement
        if len(meas) != N:
            raise InvalidProblemError(f"meas must list {N} arrays (one per sensor), got {len(meas)}")
        ms = []
        for s, m in enumerate(meas):
            a = np.asarray(m, dtype=np.float64).reshape(-1, width) if np.size(m) \
                else np.zeros((0, width))
            if not np.isfinite(a).all():
                raise InvalidProblemError(f"measurements of sensor {s} contain NaN or inf")
            ms.append(a)
        Rs = _per_measurement_R(R, [len(a) for a in ms], width)
        pd_a = np.broadcast_to(np.asarray(pd, dtype=np.float64), (N,)).copy()
        if not ((pd_a > 0) & (pd_a <= 1)).all():
            raise InvalidProblemError(f"pd must lie in (0, 1], got {pd_a.tolist()}")
        cd = np.broadcast_to(np.asarray(clutter_density, dtype=np.float64), (N,)).copy()
        if not (np.isfinite(cd).all() and (cd >= 0).all()):
            raise InvalidProblemError(f"clutter_density must be >= 0, got {cd.tolist()}")
        return cls(S, tuple(ms), tuple(Rs), pd_a, cd)

    @property
    def sizes(self) -> tuple[int, ...]:
        return tuple(len(m) for m in self.meas)

    @property
    def planar(self) -> bool:
        """Azimuth-only sensors in the plane (else azimuth-elevation in space)."""
        return self.sensors.shape[1] == 2


def _per_measurement_R(R, counts: list[int], w: int = 2) -> list[np.ndarray]:
    """One ``(n_s, w, w)`` covariance per measurement (``w`` angles per measurement)."""
    N = len(counts)
    if isinstance(R, (list, tuple)) and len(R) == N and all(
            np.ndim(r) == 3 or (w == 1 and np.ndim(r) == 1) for r in R):
        out = [np.asarray(r, dtype=np.float64).reshape(-1, w, w) for r in R]
    else:
        Ra = np.asarray(R, dtype=np.float64)
        if w == 1 and Ra.ndim <= 1 and Ra.size in (1, N):
            Ra = Ra.reshape(-1, 1, 1)
        if Ra.shape in ((w, w), (1, w, w)):
            Ra = np.broadcast_to(Ra.reshape(w, w), (N, w, w))
        if Ra.shape != (N, w, w):
            forms = ("a variance, (N,) or a list of (n_s,)" if w == 1 else
                     "(2, 2), (N, 2, 2) or a list of (n_s, 2, 2)")
            raise InvalidProblemError(f"R must be {forms}; got {Ra.shape}")
        out = [np.broadcast_to(Ra[s], (n, w, w)).copy() for s, n in enumerate(counts)]
    for s, (r, n) in enumerate(zip(out, counts)):
        if r.shape != (n, w, w):
            raise InvalidProblemError(f"R of sensor {s} must have shape ({n}, {w}, {w}), "
                                      f"got {r.shape}")
        if n and not (np.isfinite(r).all() and (r[:, 0, 0] > 0).all()
                      and (np.linalg.det(r) > 0).all()):
            raise InvalidProblemError(f"R of sensor {s} must be positive definite")
    return out


def candidate_tuples(sizes: Sequence[int], pd: ArrayLike,
                     clutter_density: ArrayLike | None = None) -> np.ndarray:
    """All candidate tuples (index 0 = dummy) allowed by the detection/false-alarm model.

    >>> candidate_tuples((2, 2), [1.0, 1.0]).tolist()
    [[1, 1], [1, 2], [2, 1], [2, 2]]
    >>> len(candidate_tuples((2, 2), [0.9, 0.9]))      # + (i,0), (0,j), no (0,0)
    8
    """
    sizes = tuple(int(n) for n in sizes)
    N = len(sizes)
    pd_a = np.broadcast_to(np.asarray(pd, float), (N,))
    cd = np.zeros(N) if clutter_density is None else \
        np.broadcast_to(np.asarray(clutter_density, float), (N,))
    can_miss = pd_a < 1.0
    if not can_miss.any() and not (cd > 0).any():
        # the paper's case: only fully real tuples
        grids = np.meshgrid(*[np.arange(1, n + 1) for n in sizes], indexing="ij")
        return np.stack([g.ravel() for g in grids], axis=1).astype(np.int64).reshape(-1, N)
    grids = np.meshgrid(*[np.arange(0, n + 1) for n in sizes], indexing="ij")
    T = np.stack([g.ravel() for g in grids], axis=1).astype(np.int64)
    real = T > 0
    n_real = real.sum(axis=1)
    ok = n_real >= 2
    # dummy at s allowed only if sensor s may miss
    ok &= ((~real) & ~can_miss[None, :]).sum(axis=1) == 0
    # singleton: a false alarm at its sensor, or a target missed by every other sensor
    single = n_real == 1
    if single.any():
        s_of = np.argmax(real, axis=1)
        fa_ok = cd[s_of] > 0
        others_miss = ((~real) & ~can_miss[None, :]).sum(axis=1) == 0
        ok |= single & (fa_ok | others_miss)
    return T[ok]


def tuple_geometry(scan: Scan, tuples: np.ndarray | None = None, *, localiser: str = "ls",
                   covariance: str = "residual") -> TupleGeometry:
    """Gather each tuple's measurements and localise every tuple with >= 2 real ones."""
    if tuples is None:
        tuples = candidate_tuples(scan.sizes, scan.pd, scan.clutter_density)
    T = np.asarray(tuples, dtype=np.int64)
    K, N = T.shape
    mask = T > 0
    w = 1 if scan.planar else 2
    # gather each tuple's measurements and covariances (index 0 = dummy -> padding)
    meas = np.stack([np.concatenate([np.zeros((1, w)), scan.meas[s]])[T[:, s]]
                     for s in range(N)], axis=1).reshape(K, N, w)
    R = np.stack([np.concatenate([np.eye(w)[None], scan.R[s]])[T[:, s]]
                  for s in range(N)], axis=1).reshape(K, N, w, w)
    if scan.planar:
        from ..localisation.azimuth import planar_tuple_geometry
        x, P, valid, pm_mean, pm_cov = planar_tuple_geometry(scan, T, localiser, covariance)
        return TupleGeometry(T, mask, meas, R, x, P, valid, pm_mean, pm_cov,
                             {"localiser": localiser, "covariance": covariance})
    loc_rows = mask.sum(axis=1) >= 2
    if loc_rows.all():
        loc = localise_indexed(scan.meas, scan.R, scan.sensors, T, method=localiser,
                               covariance=covariance)
        x, P, valid = loc.x, loc.P, loc.valid
    else:
        x = np.full((K, 3), np.nan)
        P = np.full((K, 3, 3), np.nan)
        valid = np.zeros(K, dtype=bool)
        sub = np.flatnonzero(loc_rows)
        if len(sub):
            loc = localise_indexed(scan.meas, scan.R, scan.sensors, T[sub],
                                   method=localiser, covariance=covariance)
            x[sub], P[sub], valid[sub] = loc.x, loc.P, loc.valid
    pm_mean = np.zeros((K, N, 2))
    pm_cov = np.broadcast_to(np.eye(2), (K, N, 2, 2)).copy()
    if valid.all():
        pm = pseudo_measurements(x, P, scan.sensors)
        pm_mean, pm_cov = pm.mean, pm.cov
    elif valid.any():
        good = np.flatnonzero(valid)
        pm = pseudo_measurements(x[good], P[good], scan.sensors)
        pm_mean[good], pm_cov[good] = pm.mean, pm.cov
    return TupleGeometry(T, mask, meas, R, x, P, valid, pm_mean, pm_cov,
                         {"localiser": localiser, "covariance": covariance})


@dataclass(frozen=True)
class SDCosts:
    """Costs of every candidate tuple for one method.

    ``total = const + data``; ``+inf`` where a tuple with >= 2 real measurements could
    not be localised (it is then forbidden).  Single-measurement tuples cost 0.
    """

    method: str
    tuples: np.ndarray
    total: np.ndarray
    data: np.ndarray
    const: np.ndarray
    options: dict = field(default_factory=dict)


def tuple_costs(scan: Scan, geometry: TupleGeometry, method: str, *,
                normalisation: str = "printed", const: np.ndarray | None = None) -> SDCosts:
    """Cost of every tuple of ``geometry`` for the named ``method`` (see :data:`COSTS`).

    ``const`` may pass the constant terms already computed for this geometry and
    ``normalisation`` (they do not depend on the method).
    """
    if method not in COSTS:
        raise InvalidProblemError(f"unknown cost {method!r}; valid: {', '.join(COSTS)}")
    g = geometry
    if const is None:
        const = _constants(scan, g, normalisation)
    n_real = g.n_real
    data = data_term(g, method)
    bad = ((n_real >= 2) & ~g.valid) | ~np.isfinite(data)
    data = np.where(n_real == 1, 0.0, data)        # false-alarm tuple: cost 0 (our convention)
    data = np.where(bad, np.inf, data)
    total = const + data
    return SDCosts(method, g.tuples, total, data, const,
                   {"normalisation": normalisation, **g.options})


def tuple_costs_in_chunks(scan: Scan, tuples: np.ndarray, method: str = "pattipati", *,
                          localiser: str = "ls", covariance: str = "residual",
                          normalisation: str = "printed", chunk: int = 1 << 16
                          ) -> np.ndarray:
    """Total cost of every tuple (``+inf``: forbidden), its geometry built ``chunk``
    tuples at a time: the same numbers as :func:`tuple_geometry` and
    :func:`tuple_costs` on all of them, in memory bounded by the chunk (a tuple's
    geometry takes about 1 KB) rather than by the number of tuples."""
    T = np.asarray(tuples, dtype=np.int64)
    out = np.empty(len(T))
    loc = COST_LOCALISER.get(method, localiser)
    for a in range(0, len(T), chunk):
        g = tuple_geometry(scan, T[a:a + chunk], localiser=loc, covariance=covariance)
        out[a:a + chunk] = tuple_costs(scan, g, method, normalisation=normalisation).total
    return out


def _constants(scan: Scan, g: TupleGeometry, normalisation: str) -> np.ndarray:
    if normalisation not in NORMALISATIONS:
        raise InvalidProblemError(
            f"normalisation must be one of {NORMALISATIONS}, got {normalisation!r}")
    const = constant_terms(g.mask, g.R, scan.pd, normalisation, scan.clutter_density)
    return np.where(g.n_real == 1, 0.0, const)


def build_costs(scan: Scan, methods: Sequence[str] = tuple(COSTS), *, localiser: str = "ls",
                covariance: str = "residual", normalisation: str = "printed"
                ) -> dict[str, SDCosts]:
    """Costs of all candidate tuples for several methods, sharing one localisation.

    Examples
    --------
    >>> from assocopt.tracking.scenarios.lu2013 import Lu2013
    >>> scan, truth = Lu2013(n_targets=2, d=1.0).simulate(np.random.default_rng(0))
    >>> c = build_costs(scan, ["pattipati", "skld-exact"])
    >>> c["pattipati"].tuples.shape, bool(np.isfinite(c["skld-exact"].total).all())
    ((8, 3), True)
    """
    for m in methods:
        if m not in COSTS:
            raise InvalidProblemError(f"unknown cost {m!r}; valid: {', '.join(COSTS)}")
    geoms: dict[str, TupleGeometry] = {}
    out: dict[str, SDCosts] = {}
    const = None
    for m in methods:
        loc = COST_LOCALISER.get(m, localiser)
        if loc not in geoms:
            geoms[loc] = tuple_geometry(scan, localiser=loc, covariance=covariance)
        g = geoms[loc]
        if const is None:                  # the constants depend on the tuples and R only
            const = _constants(scan, g, normalisation)
        out[m] = tuple_costs(scan, g, m, normalisation=normalisation, const=const)
    return out


def build_problem(scan: Scan, method: str = "pattipati", *, costs: SDCosts | None = None,
                  name: str | None = None, **options) -> AssignmentProblem:
    """The S-D :class:`AssignmentProblem` of ``scan`` with the named cost.

    Forbidden tuples (``+inf``) are dropped here, so the problem's candidates are the
    finite entries of ``costs`` in the same order.  ``name`` names the problem
    (default ``"bearing-METHOD"``).
    """
    c = costs if costs is not None else build_costs(scan, [method], **options)[method]
    keep = np.isfinite(c.total)
    return AssignmentProblem.sparse(scan.sizes, c.tuples[keep], c.total[keep],
                                    name=name or f"bearing-{c.method}")
