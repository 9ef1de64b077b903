"""Where eq. (27) of paper 002, as printed, is negative: over the reproduction's region.

Printed (27) per component is ``((s~^2 - s^2) + (mu~ - mu)^2) / (2 s^2 s~^2)``: negative
whenever the pseudo-measurement spread ``s~`` is below the measurement noise ``s`` and
the mean difference is small -- so it is not a divergence.  How often that happens
depends on the geometry: :func:`printed_kld_over_region` localises true (correctly
associated) 3-sensor tuples of targets drawn uniformly in the region, and returns the
spread ratios ``s~ / s`` and the values of (27) at the true association.  The
reproduction puts their range into ``summary.json`` (``derived.printed_kld``).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from ...tracking.costs import kld as dv
from ...tracking.localisation import angles, localise, pseudo_measurements, wrap_angle
from ...tracking.scenarios.lu2013 import PAPER_SENSORS_KM, REPRODUCTION_REGION_KM

__all__ = ["printed_kld_over_region", "printed_kld_summary"]


def printed_kld_over_region(sigma_mrad: float, *, region_km=REPRODUCTION_REGION_KM,
                            n: int = 2000, seed: int = 0) -> dict[str, np.ndarray]:
    """Per target (n of them, uniform in ``region_km``) and per sensor and angle:
    ``ratio`` = s~ / s and ``kld27`` = printed (27) of the true tuple (rad^-2).

    Returns arrays of shape (n, 3, 2) (targets, sensors, [elevation, azimuth]), and
    the targets ``x_true``, the measurements ``meas``, the LS estimates ``x`` and
    their covariances ``P`` (for checks).
    """
    rng = np.random.default_rng(seed)
    reg = np.asarray(region_km, dtype=float)
    S = np.asarray(PAPER_SENSORS_KM, dtype=float)
    X = reg[:, 0] + (reg[:, 1] - reg[:, 0]) * rng.random((n, 3))
    s = sigma_mrad * 1e-3
    meas = angles(X, S) + rng.normal(0.0, s, size=(n, len(S), 2))
    meas[..., 1] = wrap_angle(meas[..., 1])
    R = np.eye(2) * s * s
    loc = localise(meas, S, R)
    pm = pseudo_measurements(loc.x, loc.P, S)
    var_t = np.stack([pm.cov[..., 0, 0], pm.cov[..., 1, 1]], axis=-1)
    diff = pm.mean - meas
    diff[..., 1] = wrap_angle(diff[..., 1])
    return {"ratio": np.sqrt(var_t) / s,
            "kld27": dv.kld_printed(diff, var_t, 0.0, s * s),
            "valid": np.broadcast_to(loc.valid[:, None, None], var_t.shape),
            "x_true": X, "meas": meas, "x": loc.x, "P": loc.P}


def printed_kld_summary(sigmas=(1.5, 5.0), **kw: Any) -> list[dict[str, float]]:
    """Range of s~ / s and of printed (27), and the fraction of negative (27) values,
    per sigma (JSON-ready rows)."""
    rows = []
    for sg in sigmas:
        r = printed_kld_over_region(sg, **kw)
        ok = r["valid"]
        ratio, k27 = r["ratio"][ok], r["kld27"][ok]
        rows.append({"sigma_mrad": float(sg), "targets": int(ok[:, 0, 0].sum()),
                     "ratio_min": float(ratio.min()), "ratio_max": float(ratio.max()),
                     "ratio_p05": float(np.quantile(ratio, 0.05)),
                     "ratio_median": float(np.median(ratio)),
                     "ratio_p95": float(np.quantile(ratio, 0.95)),
                     "ratio_below_1": float((ratio < 1).mean()),
                     "kld27_min": float(k27.min()), "kld27_max": float(k27.max()),
                     "kld27_negative": float((k27 < 0).mean())})
    return rows
