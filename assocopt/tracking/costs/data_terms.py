"""The data term of every named S-D cost (paper 002): per tuple, the sum over its real
measurements of 1/2 (statistical distance or divergence) between the measurement and
the pseudo-measurement of the tuple's estimated position, read from a
:class:`TupleGeometry`.  :mod:`assocopt.tracking.costs.sd_builder` builds the geometry
and adds the constant terms.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..localisation import wrap_angle
from . import kld as dv

__all__ = ["TupleGeometry", "data_term"]


@dataclass(frozen=True)
class TupleGeometry:
    """Per-tuple measurements, localisation and pseudo-measurements (shared by all costs)."""

    tuples: np.ndarray            # (K, N)
    mask: np.ndarray              # (K, N) real measurements
    meas: np.ndarray              # (K, N, 2)
    R: np.ndarray                 # (K, N, 2, 2)
    x: np.ndarray                 # (K, 3)
    P: np.ndarray                 # (K, 3, 3)
    valid: np.ndarray             # (K,) localised
    pm_mean: np.ndarray           # (K, N, 2)
    pm_cov: np.ndarray            # (K, N, 2, 2)
    options: dict = field(default_factory=dict)
    cache: dict = field(default_factory=dict, repr=False, compare=False)

    @property
    def n_real(self) -> np.ndarray:
        return self.mask.sum(axis=1)


def _components(g: TupleGeometry) -> dict[str, np.ndarray]:
    """(K, N) component arrays shared by every data term (computed once per geometry)."""
    cached = g.cache.get("components")
    if cached is not None:
        return cached
    delta = g.pm_mean - g.meas
    if delta.shape[-1] == 1:
        # azimuth only: a neutral elevation slot (zero difference, unit variances, no
        # correlation) contributes exactly 0 to every data term below
        zero, one = np.zeros(delta.shape[:-1]), np.ones(delta.shape[:-1])
        comp = dict(da=zero, db=wrap_angle(delta[..., 0]), ra=one, rb=g.R[..., 0, 0],
                    rab=zero, ta=one, tb=g.pm_cov[..., 0, 0], tab=zero)
        g.cache["components"] = comp
        return comp
    da = delta[..., 0]
    db = wrap_angle(delta[..., 1])
    comp = dict(da=da, db=db, ra=g.R[..., 0, 0], rb=g.R[..., 1, 1], rab=g.R[..., 0, 1],
                ta=g.pm_cov[..., 0, 0], tb=g.pm_cov[..., 1, 1], tab=g.pm_cov[..., 0, 1])
    g.cache["components"] = comp
    return comp


def data_term(g: TupleGeometry, method: str) -> np.ndarray:
    """Per tuple: sum over real sensors of 1/2 (statistical distance or divergence)."""
    c = _components(g)
    da, db, ra, rb, rab = c["da"], c["db"], c["ra"], c["rb"], c["rab"]
    with np.errstate(invalid="ignore", divide="ignore", over="ignore"):
        if method in ("pattipati", "pattipati-ml"):
            det_r = ra * rb - rab * rab
            per = (rb * da * da - 2.0 * rab * da * db + ra * db * db) / det_r
        elif method.endswith("-joint"):
            ta, tb, tab = c["ta"], c["tb"], c["tab"]
            det_r = ra * rb - rab * rab
            det_t = ta * tb - tab * tab
            tr_rt = (rb * ta - 2.0 * rab * tab + ra * tb) / det_r       # tr(R^-1 S~)
            maha_r = (rb * da * da - 2.0 * rab * da * db + ra * db * db) / det_r
            if method == "kld-joint":
                per = 0.5 * (tr_rt + maha_r - 2.0 + np.log(det_r / det_t))
            else:
                tr_tr = (tb * ra - 2.0 * tab * rab + ta * rb) / det_t   # tr(S~^-1 R)
                maha_t = (tb * da * da - 2.0 * tab * da * db + ta * db * db) / det_t
                per = 0.5 * (tr_rt + tr_tr - 4.0 + maha_r + maha_t)
        else:
            fn = {"kld-printed": dv.kld_printed, "skld-printed": dv.skld_printed,
                  "kld-exact": dv.kld_exact, "skld-exact": dv.skld_exact}.get(method)
            # (26): elevation and azimuth treated as independent scalar Gaussians
            if fn is not None:
                per = fn(da, c["ta"], 0.0, ra) + fn(db, c["tb"], 0.0, rb)
            else:                       # kld-reversed: KL(measurement || pseudo-measurement)
                per = (dv.kld_exact(0.0, ra, da, c["ta"]) +
                       dv.kld_exact(0.0, rb, db, c["tb"]))
    return 0.5 * np.where(g.mask, per, 0.0).sum(axis=1)
