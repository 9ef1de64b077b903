"""S-D assignment at scale: Lagrangian relaxation against MILP and CP solvers, one run.

    python benchmarks/sd_scaling.py --reference-all   # full run: docs/benchmarks-sd.json,
                                                      # .md and .png
    python benchmarks/sd_scaling.py --quick    # smoke run (small instances only)
    python benchmarks/sd_scaling.py --render   # page and figure from the committed JSON

The run writes the raw results with the environment (versions, cores, load average at
start and end, date, command line, options) to ``docs/benchmarks-sd.json``; the page
and the figure are drawn from that JSON only (``benchmarks/sd_page.py``), and
``tests/test_benchmarks_sd.py`` re-renders the page and checks it.

Families (every instance is solved by every method in this one process):

* the 120 axial 3-AP instances of ../shared/ap_instances (Grundel n = 5..50,
  Balas-Saltzman n = 4..26), with proven optima;
* 3-AP with costs ``d_ij + d_ik + d_jk`` (Crama-Spieksma-style, random integer d in
  0..8, redrawn until the ILP optimum exceeds the LP bound by at least one cost
  unit): integrality gaps 2.3..5.7% (see :func:`crama_spieksma`);
* random S-D tracking instances with dummies: N = 3..6 sensors, 10..50 targets,
  P_D = 0.8, Poisson false alarms, gated tuples, negative log-likelihood-ratio costs;
* paper 002's scenario (``assocopt.tracking.scenarios.lu2013``) when that package is present:
  the small problems a Monte Carlo study solves by the thousand.

Methods: ``lagrangian`` (bound + heuristic), ``lagrangian-exact``, ``auto`` (``bnb``,
the compiled branch and bound, on small problems, else ``lagrangian-exact``: the rule
of :func:`assocopt.solving.choice.choose_solver`),
``highs`` (HiGHS through highspy), ``scipy`` (scipy.optimize.milp), ``ortools-cpsat``.  Reported: time
to a proven optimum (per-solve time limit), the gap after a fixed time, the plain
Lagrangian's gap after 100 iterations, the in-process latency of ``solver="auto"`` on
small problems, and the 2-D LAP engines at n = 2000.  Peers run on a subset of the
large 3-AP instances (20% of each size above n = 10) to keep the whole run under 15
minutes on 2 cores (``--reference-all`` adds scipy on all 120, about 18 minutes);
ratios are taken on the instances both sides ran.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import platform
import statistics
import sys
import time
from dataclasses import asdict, dataclass, field
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "benchmarks"))

import sd_page  # noqa: E402  (the page and figure, from the JSON)

from assocopt import AssignmentProblem, Status, solve  # noqa: E402
from assocopt.io import write_text_atomically  # noqa: E402
from assocopt.solvers import registered  # noqa: E402
from assocopt.testing import random_scans  # noqa: E402

PEERS = ("highs", "scipy", "ortools-cpsat")
#: our exact methods, run on every instance: the one the user gets by default
#: (``auto``: ``bnb`` on small problems, else ``lagrangian-exact``) and the
#: Lagrangian exact method alone
OURS = ("auto", "lagrangian-exact")
EXACT = OURS + PEERS


# ----------------------------------------------------------------------- instances
@dataclass
class Instance:
    family: str
    name: str
    size: int                 # n (3-AP) or number of targets
    problem: AssignmentProblem
    optimum: float | None = None
    peers: bool = True        # run the MILP/CP peers on it


def ap_instances(ap_dir: Path, quick: bool) -> list[Instance]:
    if not ap_dir.is_dir():
        return []
    sys.path.insert(0, str(ap_dir))
    from load import known_value, load   # the shared folder's own loader
    out = []
    files = sorted((ap_dir / "grundel_ap3").glob("ap3.*.txt"),
                   key=lambda p: tuple(int(x) for x in p.stem.split(".")[1:]))
    files += sorted((ap_dir / "balas_saltzman" / "split").glob("balas-n*.txt"),
                    key=lambda p: (int(p.stem.split("-")[1][1:]), p.stem))
    for path in files:
        grundel = path.name.startswith("ap3")
        n = int(path.stem.split(".")[1]) if grundel else int(path.stem.split("-")[1][1:])
        inst = int(path.stem.split(".")[2]) if grundel else int(path.stem[-2:])
        if quick and n > 20:
            continue
        C, _ = load(str(path))
        out.append(Instance("grundel" if grundel else "balas-saltzman", path.stem, n,
                            AssignmentProblem.dense(C.astype(float), name=path.stem),
                            float(known_value(str(path))),
                            # peers: every n <= 10, and 20% of each larger size (Grundel
                            # 2 of 10, Balas-Saltzman 1 of 5) to stay under 15 minutes
                            peers=n <= 10 or inst <= (2 if grundel else 1)))
    return out


def crama_spieksma(rng: np.random.Generator, n: int, hi: int = 8,
                   min_gap: float = 1.0, max_draws: int = 200) -> AssignmentProblem:
    """3-AP with c_ijk = d_ij + d_ik + d_jk (Crama-Spieksma cost structure), the three
    n x n matrices d i.i.d. uniform integers in 0..hi (not metric: the triangle
    inequality of Crama-Spieksma's T-instances is not imposed).

    Draws are repeated until ILP optimum - LP optimum >= ``min_gap`` cost units (both
    by HiGHS, scipy's if highspy is missing; ``min_gap=0`` keeps the first draw; after
    ``max_draws`` the last draw is kept).  With integer costs a gap under 1 unit is
    closed by rounding the bound up, so min_gap = 1 keeps only instances whose LP
    bound, even rounded, does not prove the optimum.  Unconditioned, the LP is
    integral on most small draws (hi = 8: 81% at n = 10, 44% at n = 15 and 20, 17% at
    n = 25) and 0 < gap < 1 unit on most of the rest; ILP - LP >= 1 held on 8% of
    draws at n = 10, 12% at n = 15, 30% at n = 20..25 (so about 12, 8, 3 draws).

    Measured gap (ILP - LP) / ILP of the kept instances, hi = 8, min_gap = 1: 51
    instances at n = 10..25, all inside 2.3..5.7% (median 3.1% at n = 10, 4.2% at
    n = 25): a gap of 1 to 2 units on optima of about 20..45.  For comparison
    (unconditioned, 5 seeds per n): d in 1..100 gives 0..2.5%, rounded Euclidean
    distances between random points in the plane 0..0.4%.
    """
    cls = registered().get("highs")
    checker = "highs" if cls is not None and cls.is_available() else "scipy"
    for _ in range(max_draws):
        dij, dik, djk = (rng.integers(0, hi + 1, size=(n, n)).astype(float)
                         for _ in range(3))
        p = AssignmentProblem.dense(dij[:, :, None] + dik[:, None, :] + djk[None, :, :])
        if min_gap <= 0:
            break
        lp = solve(p, checker, relax="lp").objective
        ilp = solve(p, checker).objective
        if ilp - lp >= min_gap - 1e-6:
            break
    return p


def tracking(rng: np.random.Generator, N: int, n_targets: int, pd: float = 0.8,
             clutter: float = 5.0, sigma: float = 0.02, gate_sigmas: float = 4.0
             ) -> AssignmentProblem:
    """N sensors see targets in the unit square (P_D, Gaussian noise sigma) plus
    Poisson(clutter) false alarms; tuples gated on the distance to their centroid;
    cost = -log likelihood ratio against "all false alarms" (single-measurement
    tuples cost 0)."""
    meas = random_scans(rng, N, n_targets, pd=pd, clutter=clutter, sigma=sigma)
    sizes = tuple(len(z) for z in meas)
    gate = gate_sigmas * sigma * math.sqrt(2)
    parts, psum, pcnt = np.zeros((1, 0), np.int64), np.zeros((1, 2)), np.zeros(1)
    for s in range(N):
        Z = meas[s]
        cen = psum / np.maximum(pcnt, 1)[:, None]
        d = np.linalg.norm(cen[:, None, :] - Z[None, :, :], axis=2)
        pi, zi = np.nonzero((pcnt[:, None] == 0) | (d <= gate))
        parts = np.concatenate([np.concatenate([parts, np.zeros((len(parts), 1), np.int64)], 1),
                                np.concatenate([parts[pi], (zi + 1)[:, None]], 1)])
        psum = np.concatenate([psum, psum[pi] + Z[zi]])
        pcnt = np.concatenate([pcnt, pcnt[pi] + 1])
    keep = pcnt > 0
    T, psum, pcnt = parts[keep], psum[keep], pcnt[keep]
    cen = psum / pcnt[:, None]
    resid = np.zeros(len(T))
    for s in range(N):
        real = T[:, s] > 0
        resid[real] += ((meas[s][T[real, s] - 1] - cen[real]) ** 2).sum(1) / sigma ** 2
    cost = 0.5 * resid - pcnt * math.log(pd / (2 * math.pi * sigma ** 2 * clutter)) \
        - (N - pcnt) * math.log(1 - pd)
    cost[pcnt < 2] = 0.0
    return AssignmentProblem.sparse(sizes, T, cost)


def lu2013_problems(rng, M: int, pd: float, clutter: float, count: int):
    try:
        from assocopt.tracking.costs.sd_builder import build_problem
        from assocopt.tracking.scenarios.lu2013 import Lu2013
    except ImportError:
        return None
    sc = Lu2013(n_targets=M, d=0.5, sigma_mrad=5.0, pd=pd, clutter_rate=clutter)
    return [build_problem(sc.simulate(rng)[0], "pattipati") for _ in range(count)]


# ----------------------------------------------------------------------- running
@dataclass
class Run:
    solver: str
    time: float
    status: str
    objective: float | None
    bound: float | None
    gap: float | None
    info: dict = field(default_factory=dict)

    @property
    def proven(self) -> bool:
        return self.status == "optimal"


# Back ends that, under a time limit, solve in a child process by default (``isolate``):
# run here in this process, under their own limits, like the in-process peers and
# ``auto`` (the child's start, about 0.5 s, would otherwise be charged to every solve).
IN_PROCESS = {"isolate": False}
ISOLATING = ("highs", "scipy", "ortools-cpsat", "ortools-mip", "cvxpy")


def run(problem: AssignmentProblem, solver: str, **kw) -> Run:
    if solver in ISOLATING and kw.get("time_limit") is not None:
        kw = kw | IN_PROCESS
    t0 = time.perf_counter()
    try:
        sol = solve(problem, solver, **kw)
    except Exception as exc:   # a peer failing must not end the benchmark
        return Run(solver, time.perf_counter() - t0, f"error: {exc}"[:80], None, None, None)
    dt = time.perf_counter() - t0
    keep = {k: sol.info.get(k) for k in ("iterations", "stop", "proof") if k in sol.info}
    return Run(solver, dt, sol.status.value, sol.objective, sol.bound, sol.gap, keep)


def available(name: str) -> bool:
    if name == "auto":
        return True
    cls = registered().get(name)
    return cls is not None and cls.is_available()


def warm_up(solvers) -> None:
    p = AssignmentProblem.dense(np.random.default_rng(0).random((4, 4, 4)))
    for s in solvers:
        run(p, s)
        run(p, s)


def agrees(a: float | None, b: float | None) -> bool:
    return a is not None and b is not None and \
        abs(a - b) <= 1e-6 * max(1.0, abs(a), abs(b))


# ----------------------------------------------------------------------- sections
def record(inst: Instance) -> dict:
    """What the page needs to know about an instance (JSON)."""
    return {"family": inst.family, "name": inst.name, "size": inst.size,
            "sizes": list(inst.problem.sizes), "K": int(inst.problem.n_candidates),
            "optimum": inst.optimum, "peers": inst.peers}


def exact_section(instances, solvers, limit, cpsat_limit, log, ref_all=False) -> list:
    """Time to proven optimum, every solver on its instances."""
    rows = []
    for inst in instances:
        res = {}
        for s in solvers:
            if s not in OURS and not inst.peers and not (ref_all and s == "scipy"):
                continue
            res[s] = run(inst.problem, s,
                         time_limit=cpsat_limit if s == "ortools-cpsat" else limit)
        ref = inst.optimum
        if ref is None:
            proven = [r.objective for r in res.values() if r.proven]
            ref = proven[0] if proven else None
        for r in res.values():
            r.info["correct"] = (not r.proven) or ref is None or agrees(r.objective, ref)
        rows.append(record(inst) | {"reference": ref,
                                    "results": {s: asdict(r) for s, r in res.items()}})
        log(f"{inst.family:15s} {inst.name:24s} K={inst.problem.n_candidates:7d} " +
            " ".join(f"{s}={r.time:7.3f}s{'' if r.proven else '*'}"
                     f"{'' if r.info['correct'] else '!WRONG'}" for s, r in res.items()))
    return rows


def fixed_time_section(instances, solvers, t_fixed, log) -> list:
    out = []
    for inst in instances:
        res = {s: run(inst.problem, s, time_limit=t_fixed) for s in solvers}
        out.append(record(inst) | {"results": {s: asdict(r) for s, r in res.items()}})
        log(f"gap after {t_fixed:g}s on {inst.name}: " +
            " ".join(f"{s}={_pct(r.gap)}" for s, r in res.items()))
    return out


def plain_section(instances, log) -> list:
    """Plain lagrangian, 100 iterations; with the integrality gap of the LP relaxation
    (``(optimum - LP) / |optimum|``), a floor for any Lagrangian duality gap."""
    out = []
    for inst in instances:
        r = run(inst.problem, "lagrangian", max_iter=100, gap_tol=0.0)
        it = r.info.get("iterations") or 1
        lp = run(inst.problem, "highs", relax="lp").objective
        opt = run(inst.problem, "auto").objective
        if lp is not None and np.all(inst.problem.costs == np.round(inst.problem.costs)):
            lp = math.ceil(lp - 1e-6)      # integer costs: bounds are rounded up
        r.info["lp_gap"] = (None if lp is None or opt is None
                            else (opt - lp) / max(abs(opt), 1e-12))
        out.append(record(inst) | {"run": asdict(r), "lp_bound": lp, "optimum_found": opt,
                                   "per_iteration_s": r.time / it})
        log(f"lagrangian 100 it on {inst.name}: gap {_pct(r.gap)} in {it} it, "
            f"{1e3 * r.time / it:.2f} ms/it, LP gap {_pct(r.info['lp_gap'])}")
    return out


def latency_section(groups, solvers, log) -> list:
    out = []
    for label, probs in groups:
        row = {}
        for s in solvers:
            for p in probs[:3]:
                run(p, s)          # warm caches for this size
            times, ok = [], 0
            for p in probs:
                t0 = time.perf_counter()
                sol = solve(p, s)
                times.append(time.perf_counter() - t0)
                ok += sol.status is Status.OPTIMAL
            row[s] = {"median_s": statistics.median(times), "max_s": max(times),
                      "optimal": ok, "count": len(probs), "times_s": times}
        out.append({"label": label, "K": int(probs[0].n_candidates), "results": row})
        log(f"latency {label}: " + " ".join(
            f"{s}={1e3 * v['median_s']:.2f}ms" for s, v in row.items()))
    return out


_LAP_CODE = r"""
import json, sys, time
import numpy as np
from scipy.optimize import linear_sum_assignment
from assocopt.solvers.twod.lap import assign_with_misses, lapx_available, linear_assignment
quick = sys.argv[1] == "1"
rng = np.random.default_rng(0)
n = 500 if quick else 2000
def best_of(fs, k=7):
    # interleaved repeats, minimum of each: robust to load from other processes
    ts = [[] for _ in fs]
    for _ in range(k):
        for t, f in zip(ts, fs):
            t0 = time.perf_counter(); f(); t.append(time.perf_counter() - t0)
    return [min(t) for t in ts]
rows = []
for kind, C in (("uniform [0,1)", rng.random((n, n))),
                ("integers 0..999", rng.integers(0, 1000, (n, n)).astype(float))):
    fs = [lambda: linear_sum_assignment(C), lambda: linear_assignment(C, "scipy")]
    if lapx_available():
        fs.append(lambda: linear_assignment(C, "lapx"))
    t = best_of(fs)
    rows.append([f"dense n={n}, {kind}", t[0], t[1], t[2] if len(t) > 2 else None])
m = 2000 if quick else 20000
r = np.repeat(np.arange(m), 10)
c = (r + rng.integers(-20, 21, size=len(r))) % m
key = np.unique(r * m + c)
r, c = key // m, key % m
w = rng.random(len(r))
miss = np.full(m, 0.8)
t_sp = best_of([lambda: assign_with_misses(m, m, r, c, w, miss, miss, method="sparse")], k=2)[0]
rows.append([f"gated sparse n={m} ({len(w)} edges) with miss costs, LAPJVsp", None, t_sp, None])
print(json.dumps(rows))
"""


def lap_section(quick, lapx_path, log) -> list:
    """2-D LAP engines, in a subprocess so that lapx (a side install given by
    ``--lapx-path``) never leaks into the S-D measurements above."""
    import subprocess
    env = dict(os.environ)
    paths = [str(ROOT)] + ([lapx_path] if lapx_path else [])
    env["PYTHONPATH"] = os.pathsep.join(paths + [env.get("PYTHONPATH", "")])
    out = subprocess.run([sys.executable, "-c", _LAP_CODE, "1" if quick else "0"],
                         env=env, capture_output=True, text=True, check=True)
    rows = [{"label": r[0], "scipy_s": r[1], "scipy_path_s": r[2], "lapx_s": r[3]}
            for r in json.loads(out.stdout)]
    for r in rows:
        log(f"LAP {r['label']}: scipy {r['scipy_s']} assocopt(scipy path) "
            f"{r['scipy_path_s']} lapx {r['lapx_s']}")
    return rows


# ----------------------------------------------------------------------- report
def _pct(g):
    return sd_page.pct(g)


def environment(argv: list[str]) -> dict:
    """Machine, versions, load average at the start, date and command line."""
    import importlib.metadata as md
    cpu = platform.processor() or "unknown"
    try:
        for line in open("/proc/cpuinfo"):
            if line.startswith("model name"):
                cpu = line.split(":", 1)[1].strip()
                break
    except OSError:
        pass
    vers = {}
    for d in ("numpy", "scipy", "highspy", "ortools", "lapx", "matplotlib", "numba"):
        try:
            vers[d] = md.version(d)
        except md.PackageNotFoundError:
            vers[d] = None
    return {"command": "python benchmarks/sd_scaling.py" + "".join(" " + a for a in argv),
            "date": time.strftime("%Y-%m-%d"), "cpu": cpu, "cores": os.cpu_count(),
            "platform": platform.platform(), "python": platform.python_version(),
            "versions": vers, "load_start": [round(x, 2) for x in os.getloadavg()]}


def write_outputs(data: dict, json_path: Path | None, page: Path) -> bool:
    """The JSON (unless None: --render), the figure and the page; True if plotted."""
    page.parent.mkdir(parents=True, exist_ok=True)
    if json_path is not None:
        write_text_atomically(json_path, json.dumps(data, indent=1, default=float) + "\n")
    png = page.with_suffix(".png")
    plotted = sd_page.plot(data, png)
    data = dict(data, figure=png.name if plotted else None)
    write_text_atomically(page, sd_page.render(data))
    return plotted


# ----------------------------------------------------------------------- main
def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--quick", action="store_true", help="small instances only (smoke run)")
    ap.add_argument("--out", default=str(ROOT / "docs" / "benchmarks-sd.md"),
                    help="the page; the JSON and the figure go beside it (.json, .png)")
    ap.add_argument("--render", action="store_true",
                    help="rewrite the page and the figure from the JSON, run nothing")
    ap.add_argument("--ap-dir", default=str(ROOT.parent / "shared" / "ap_instances"))
    ap.add_argument("--time-limit", type=float, default=60.0,
                    help="per-solve limit for the exact methods (s)")
    ap.add_argument("--cpsat-limit", type=float, default=20.0,
                    help="per-solve limit for OR-Tools CP-SAT (s), to keep the run short")
    ap.add_argument("--fixed-time", type=float, default=1.0,
                    help="time budget for the gap-after-fixed-time table (s)")
    ap.add_argument("--seed", type=int, default=2024)
    ap.add_argument("--lapx-path", default=None,
                    help="directory holding lapx (pip install --target DIR lapx) for the "
                         "2-D LAP table only")
    ap.add_argument("--all-peers", action="store_true",
                    help="run every peer on every 3-AP instance (an hour or more)")
    ap.add_argument("--reference-all", action="store_true",
                    help="run scipy (the reference) on all 120 3-AP instances, the other "
                         "peers on the subset (about 17 min instead of 8)")
    argv = sys.argv[1:] if argv is None else list(argv)
    args = ap.parse_args(argv)
    page = Path(args.out)
    json_path = page.with_suffix(".json")
    if args.render:
        write_outputs(json.loads(json_path.read_text()), None, page)
        return 0
    t_start = time.perf_counter()
    lines_log: list[str] = []

    def log(msg: str) -> None:
        lines_log.append(msg)
        print(msg, flush=True)

    solvers = [s for s in EXACT if available(s)]
    missing = [s for s in EXACT if s not in solvers]
    rng = np.random.default_rng(args.seed)
    env = environment(argv)
    warm_up(solvers + ["lagrangian"])

    # 1. shared 3-AP instances
    ap_list = ap_instances(Path(args.ap_dir), args.quick)
    if args.all_peers:
        for inst in ap_list:
            inst.peers = True
    ref_all = args.reference_all and not args.all_peers
    # 2. LP-gap 3-AP (Crama-Spieksma-style)
    cs = [Instance("crama-spieksma", f"cs-n{n}-{k}", n, crama_spieksma(rng, n))
          for n in ((10, 15) if args.quick else (10, 15, 20, 25)) for k in (1, 2)]
    # 3. tracking S-D with dummies
    trk = [Instance(f"tracking N={N}", f"trk-N{N}-t{t}", t, tracking(rng, N, t))
           for N in (3, 4, 5, 6) for t in ((10, 25) if args.quick else (10, 25, 50))]
    rows = exact_section(ap_list + cs + trk, solvers, args.time_limit, args.cpsat_limit, log,
                         ref_all)

    big = [i for i in ap_list if i.name in ("ap3.50.1", "balas-n26-instance01")]
    big += [cs[-1], trk[-1]]
    fixed = fixed_time_section(big, ["lagrangian"] + solvers, args.fixed_time, log)
    plain = plain_section(trk + cs, log)

    # 4. latency of small problems (auto)
    groups = []
    for M in (2, 5, 10):
        for pd, cl in ((1.0, 0.0), (0.9, 1.0)):
            probs = lu2013_problems(rng, M, pd, cl, 40 if not args.quick else 10)
            if probs is not None:
                groups.append((f"paper 002, M={M}, P_D={pd}, clutter {cl}", probs))
    for n in (5, 10):
        groups.append((f"3-AP n={n}, uniform random costs",
                       [AssignmentProblem.dense(rng.random((n, n, n))) for _ in range(20)]))
    lat = latency_section(groups, ["auto"] + [s for s in ("lagrangian-exact", "highs", "scipy")
                                              if s in solvers], log)
    lapres = lap_section(args.quick, args.lapx_path, log)

    env["minutes"] = (time.perf_counter() - t_start) / 60
    env["load_end"] = [round(x, 2) for x in os.getloadavg()]
    data = {"environment": env,
            "options": {k: v for k, v in vars(args).items() if k not in ("out", "render")}
            | {"in_process": True}
            | {"solvers": solvers, "missing": missing, "reference_all": ref_all},
            "exact": rows, "fixed": fixed, "plain": plain, "latency": lat, "lap": lapres,
            "log": lines_log}
    plotted = write_outputs(data, json_path, page)
    print(f"wrote {json_path}, {page}" + (f" and {page.with_suffix('.png')}" if plotted
                                            else ""), flush=True)
    return 0


if __name__ == "__main__":
    # steady-state speed: the kernels compiled in the warm-up (by default a small
    # problem runs them as plain Python for its first seconds: first_use.py)
    os.environ.setdefault("ASSOCOPT_JIT", "compiled")
    raise SystemExit(main())
