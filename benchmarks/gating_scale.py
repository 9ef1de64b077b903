"""Gating at scale: time and peak memory of gate, tuples, costs and solve against n.

Two pipelines, each size in a fresh Python process (``--worker``) so that its peak
resident memory (``resource.getrusage(...).ru_maxrss``) is its own:

* **position reports** (``benchmarks/tracking_scans.py``'s scans: 3 sensors in the
  plane, ``n`` targets at a mean spacing of 4 gate radii, P_D 0.9, 0.2 n false
  alarms per sensor, sigma 1): :func:`assocopt.tracking.gating.position_pair_gate`
  (chi-square 2 dof at 99.9 %), :func:`assocopt.tracking.gating.gated_tuples`,
  :func:`assocopt.tracking.costs.position.position_tuple_costs`,
  ``AssignmentProblem.sparse`` and ``solve`` (``auto``, to a proven optimum);
* **bearing scans** (3 azimuth-elevation sensors, 1.5 mrad noise, ``n`` targets
  uniform in one fixed volume of 250 x 160 x 14 km, so the scan gets denser with
  ``n``): :func:`assocopt.tracking.gating.bearing_pair_gate` (99 %),
  ``gated_tuples``, the Pattipati costs (``tuple_costs_in_chunks``),
  ``AssignmentProblem.sparse`` -- what ``build_gated_problem`` does, stage by stage;
* **bearing scans in a sector** (``bearing-sector``): the same, the targets at
  80-200 km in a sector of azimuths that widens with ``n`` (as many per degree at
  every size, so the scan does not get denser).

Each worker first solves a small scan (numba's kernels loaded from their cache,
not timed).  ``python benchmarks/gating_scale.py`` writes
``docs/benchmarks-gating.json``, ``docs/gating-scale.png`` and
``docs/benchmarks-gating.md``; ``--render`` redraws the page (and the plot) from the
JSON; ``--quick`` runs small sizes only.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import resource
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "benchmarks"))

POSITION_SIZES = (1_000, 3_000, 10_000, 30_000, 100_000)
BEARING_SIZES = (100, 200, 500, 1_000, 2_000)
KINDS = ("position", "bearing", "bearing-sector")
SIZES = {"position": POSITION_SIZES, "bearing": BEARING_SIZES,
         "bearing-sector": BEARING_SIZES}
QUICK = {"position": (1_000, 3_000), "bearing": (100, 200), "bearing-sector": (100, 200)}
#: Slopes are fitted on the sizes from these on (below, fixed costs dominate).
FIT_FROM = {"position": 10_000, "bearing": 500, "bearing-sector": 500}
STAGES = {"position": ("gate", "tuples", "costs", "problem", "solve"),
          "bearing": ("gate", "tuples", "costs", "problem"),
          "bearing-sector": ("gate", "tuples", "costs", "problem")}
#: The issue's targets, checked on the page.
TARGETS = {"position_n": 100_000, "position_s": 30.0, "position_gb": 3.0,
           "bearing_n": 1_000, "bearing_s": 20.0, "bearing_gb": 1.5,
           "gate_over_solve": 2.0, "memory_slope": 1.2}


def _rss_gb() -> float:
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024 / 1e9


class _Clock:
    """CPU and wall time of each stage, and the peak RSS after it."""

    def __init__(self) -> None:
        self.out: dict[str, dict] = {}

    def run(self, name: str, fn, *a, **kw):
        c0, w0 = time.process_time(), time.perf_counter()
        r = fn(*a, **kw)
        self.out[name] = {"cpu": time.process_time() - c0, "wall": time.perf_counter() - w0,
                          "rss_gb": _rss_gb()}
        return r


def bearing_scan(n: int, seed: int = 0, sigma: float = 1.5e-3, sector: bool = False):
    """Three sensors at different heights; targets uniform in a fixed volume (or,
    with ``sector``, at 80-200 km from the sensors' centre in a sector of azimuths
    ``360 * n / 2000`` degrees wide: as many targets per degree at every n); each
    sensor's measurements in random order."""
    from assocopt.tracking.costs.sd_builder import Scan
    from assocopt.tracking.localisation import angles
    rng = np.random.default_rng(seed)
    S = np.array([[0.0, 0.0, 0.0], [60.0, 0.0, 0.5], [30.0, -50.0, 1.0]])
    if sector:
        phi = np.pi / 2 + rng.uniform(-1.0, 1.0, n) * min(np.pi, np.pi * n / 2000)
        r = rng.uniform(80.0, 200.0, n)
        X = np.column_stack([30.0 + r * np.cos(phi), -15.0 + r * np.sin(phi),
                             rng.uniform(1, 15, n)])
    else:
        X = np.column_stack([rng.uniform(-100, 150, n), rng.uniform(40, 200, n),
                             rng.uniform(1, 15, n)])
    th = angles(X, S)
    meas = [th[rng.permutation(n), s] + rng.normal(0, sigma, (n, 2)) for s in range(3)]
    return Scan.create(S, meas, np.eye(2) * sigma ** 2)


def _position(n: int, seed: int, clock: _Clock) -> dict:
    from tracking_scans import ScanSpec, draw_scan
    from assocopt import AssignmentProblem, solve
    from assocopt.tracking.costs.position import position_tuple_costs
    from assocopt.tracking.gating import gated_tuples, position_pair_gate
    spec = ScanSpec(N=3, n=n, spacing=4.0, seed=seed)
    meas = draw_scan(spec)
    lam = max(spec.clutter * spec.n, 1.0) / spec.side ** 2
    R = np.eye(2) * spec.sigma ** 2
    sizes = [len(z) for z in meas]
    ok = clock.run("gate", position_pair_gate, meas, R, probability=spec.gate)
    T = clock.run("tuples", gated_tuples, sizes, ok, spec.pd, lam)
    c = clock.run("costs", position_tuple_costs, meas, R, T, spec.pd, lam)
    p = clock.run("problem", AssignmentProblem.sparse, sizes, T, c)
    sol = clock.run("solve", solve, p)
    dec = (sol.info or {}).get("decomposition", {})
    return {"sizes": sizes, "pairs": int(sum(M.nnz for M in ok.values())),
            "candidates": int(p.n_candidates), "status": sol.status.value,
            "objective": float(sol.objective), "bound": None if sol.bound is None
            else float(sol.bound), "components": dec.get("components"),
            "largest": dec.get("largest")}


def _bearing(n: int, seed: int, clock: _Clock, sector: bool = False) -> dict:
    from assocopt import AssignmentProblem
    from assocopt.tracking.costs.sd_builder import tuple_costs_in_chunks
    from assocopt.tracking.gating import bearing_pair_gate, gated_tuples
    scan = bearing_scan(n, seed, sector=sector)
    ok = clock.run("gate", bearing_pair_gate, scan, probability=0.99)
    T = clock.run("tuples", gated_tuples, scan.sizes, ok, scan.pd, scan.clutter_density)
    c = clock.run("costs", tuple_costs_in_chunks, scan, T, "pattipati")
    keep = np.isfinite(c)
    p = clock.run("problem", AssignmentProblem.sparse, scan.sizes, T[keep], c[keep])
    return {"sizes": list(scan.sizes), "pairs": int(sum(M.nnz for M in ok.values())),
            "candidates": int(p.n_candidates)}


def worker(kind: str, n: int, seed: int) -> dict:
    """One size of one pipeline, in this (fresh) process."""
    import assocopt  # noqa: F401  (imports before the baseline)
    from assocopt import solve
    from assocopt.tracking.gating import position_pair_gate  # noqa: F401
    from tracking_scans import ScanSpec, build_problem
    w0 = time.perf_counter()
    solve(build_problem(ScanSpec(N=3, n=300, spacing=2.0, seed=99))[0])
    warm = time.perf_counter() - w0
    base = _rss_gb()
    clock = _Clock()
    if kind == "position":
        info = _position(n, seed, clock)
    else:
        info = _bearing(n, seed, clock, sector=kind == "bearing-sector")
    st = clock.out
    return {"kind": kind, "n": n, "seed": seed, "warmup_s": warm, "rss_base_gb": base,
            "rss_peak_gb": _rss_gb(), "stages": st,
            "total_cpu": sum(v["cpu"] for v in st.values()),
            "total_wall": sum(v["wall"] for v in st.values()), **info}


def slope(xs, ys) -> float | None:
    """Least-squares slope of log y against log x (None with fewer than 2 points)."""
    pts = [(math.log(x), math.log(y)) for x, y in zip(xs, ys) if y and y > 0]
    if len(pts) < 2:
        return None
    a = np.array(pts)
    return float(np.polyfit(a[:, 0], a[:, 1], 1)[0])


def fits(rows: list[dict], kind: str) -> dict:
    """Fitted slopes (sizes from FIT_FROM on) of each stage's CPU time, the total,
    and the peak memory above the process's baseline."""
    sel = [r for r in rows if r["kind"] == kind and r["n"] >= FIT_FROM[kind]]
    ns = [r["n"] for r in sel]
    out = {s: slope(ns, [r["stages"][s]["cpu"] for r in sel]) for s in STAGES[kind]}
    out["total"] = slope(ns, [r["total_cpu"] for r in sel])
    out["memory"] = slope(ns, [r["rss_peak_gb"] - r["rss_base_gb"] for r in sel])
    return out


def environment(argv: list[str]) -> dict:
    from sd_scaling import environment as env0
    env = env0(argv)
    env["command"] = "python benchmarks/gating_scale.py" + "".join(" " + a for a in argv)
    try:
        env["uptime_start"] = subprocess.run(["uptime"], capture_output=True, text=True,
                                             check=False).stdout.strip()
    except OSError:
        env["uptime_start"] = None
    return env


def plot(data: dict, path: Path) -> None:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, axes = plt.subplots(1, 4, figsize=(20, 4.6))
    for ax, kind in zip(axes[:3], KINDS):
        rows = [r for r in data["rows"] if r["kind"] == kind]
        if not rows:
            continue
        ns = [r["n"] for r in rows]
        f = data["fits"][kind]
        for s in STAGES[kind] + ("total",):
            ys = [r["total_cpu"] if s == "total" else r["stages"][s]["cpu"] for r in rows]
            lab = f"{s} (slope {f[s]:.2f})" if f.get(s) is not None else s
            ax.loglog(ns, ys, "o-" if s != "total" else "k^-", label=lab)
        ax.set_title(f"{kind}: CPU time per stage")
        ax.set_xlabel("targets n")
        ax.set_ylabel("CPU s")
        ax.legend(fontsize=8)
        ax.grid(True, which="both", alpha=0.3)
    ax = axes[3]
    for kind, mark in zip(KINDS, ("o-", "s-", "d-")):
        rows = [r for r in data["rows"] if r["kind"] == kind]
        if rows:
            f = data["fits"][kind]["memory"]
            ax.loglog([r["n"] for r in rows], [r["rss_peak_gb"] - r["rss_base_gb"]
                                               for r in rows], mark,
                      label=f"{kind} (slope {f:.2f})" if f is not None else kind)
    ax.set_title("peak RSS above the process baseline")
    ax.set_xlabel("targets n")
    ax.set_ylabel("GB")
    ax.legend(fontsize=8)
    ax.grid(True, which="both", alpha=0.3)
    fig.tight_layout()
    fig.savefig(path, dpi=90)
    plt.close(fig)


def main(argv: list[str] | None = None) -> int:
    argv = sys.argv[1:] if argv is None else list(argv)
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--worker", nargs=3, metavar=("KIND", "N", "SEED"), help=argparse.SUPPRESS)
    ap.add_argument("--quick", action="store_true", help="small sizes only (smoke run)")
    ap.add_argument("--render", action="store_true", help="page and plot from the JSON only")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--out", default=str(ROOT / "docs" / "benchmarks-gating.md"))
    args = ap.parse_args(argv)
    if args.worker:
        kind, n, seed = args.worker
        print(json.dumps(worker(kind, int(n), int(seed))))
        return 0
    import gating_page
    from assocopt.io import write_text_atomically
    page = Path(args.out)
    json_path = page.with_suffix(".json")
    png = page.parent / "gating-scale.png"
    page.parent.mkdir(parents=True, exist_ok=True)
    if args.render:
        data = json.loads(json_path.read_text())
        plot(data, png)
        write_text_atomically(page, gating_page.render(data))
        return 0
    t0 = time.perf_counter()
    env = environment(argv)
    rows = []
    plan = [(k, n) for k in KINDS for n in (QUICK if args.quick else SIZES)[k]]
    for kind, n in plan:
        cmd = [sys.executable, str(Path(__file__).resolve()), "--worker", kind, str(n),
               str(args.seed)]
        proc = subprocess.run(cmd, capture_output=True, text=True, check=False,
                              env=dict(os.environ, PYTHONPATH=str(ROOT)))
        if proc.returncode != 0:
            print(proc.stderr, file=sys.stderr)
            raise SystemExit(f"worker {kind} {n} failed")
        r = json.loads(proc.stdout.strip().splitlines()[-1])
        rows.append(r)
        print(f"{kind:8s} n={n:>7d}  total {r['total_cpu']:7.2f} CPU s "
              f"({r['total_wall']:7.2f} wall)  peak {r['rss_peak_gb']:.3f} GB  "
              f"candidates {r['candidates']}", flush=True)
    env["minutes"] = (time.perf_counter() - t0) / 60
    env["load_end"] = [round(x, 2) for x in os.getloadavg()]
    data = {"environment": env, "options": {"quick": args.quick, "seed": args.seed},
            "targets": TARGETS, "fits_from": FIT_FROM, "rows": rows,
            "fits": {k: fits(rows, k) for k in KINDS}}
    write_text_atomically(json_path, json.dumps(data, indent=1) + "\n")
    plot(data, png)
    write_text_atomically(page, gating_page.render(data))
    print(f"wrote {json_path}, {png} and {page}", flush=True)
    return 0


if __name__ == "__main__":
    # steady-state speed: the kernels compiled in the warm-up (by default a small
    # problem runs them as plain Python for its first seconds: first_use.py)
    os.environ.setdefault("ASSOCOPT_JIT", "compiled")
    raise SystemExit(main())
