"""Random instances, proven optima, and the catalogue of stored instances.

Three seeded generators (:data:`GENERATORS`), each returning an
:class:`~assocopt.AssignmentProblem`; the same seed always gives the same instance:

``"dense"``
    Axial N-D assignment on a full cost array, integer costs uniform in
    ``low..high`` (Balas & Saltzman's 0..100 by default).
``"sparse"``
    S-D assignment with dummies from a synthetic multi-sensor scan: targets in a
    square, each of N sensors detects each target with probability ``pd`` and adds
    uniform false alarms up to its size; a tuple of m >= 2 measurements is a
    candidate when its spread passes a chi-square gate, costing
    ``chi2 / 2 - (m - 1) * gain`` (a negative log-likelihood ratio against "all
    false alarms"); single measurements cost 0, so every instance is feasible.
``"planted"``
    Grundel-like planted optimum: every cost uniform in ``low..high`` except one
    planted assignment whose costs are drawn below ``low``.  Every feasible solution
    has the same number of real tuples, so any other solution swaps a planted tuple
    for one costing at least ``low``: the planted assignment is the unique optimum
    by construction (:func:`generate` also verifies it with HiGHS).  Easy for greedy
    by design; use it to test scale and correctness, not heuristics.

:func:`prove_optimum` proves an optimum with HiGHS (and brute force when tiny) and
says how; :func:`catalogue` lists a folder of instances (``assocopt instances``) and
:func:`write_index` writes its ``index.csv``.

>>> p = generate("planted", seed=1, sizes=(4, 4, 4))
>>> p.optimum == solve(p, "highs").objective
True
"""

from __future__ import annotations

import math
import os
from pathlib import Path
from typing import Any, Sequence

import numpy as np

from ..solving.api import solve
from ..runtime.errors import InvalidProblemError
from ..problems.problem import AssignmentProblem
from ..model.solution import Status

__all__ = ["GENERATORS", "DEFAULT_SIZES", "generate", "generate_dense", "generate_sparse",
           "generate_planted", "prove_optimum", "feasibility", "catalogue", "write_index",
           "default_instances_dir", "find_stored_instance", "INDEX_NAME",
           "PACKAGED_INSTANCES", "gated_2d"]

#: Generator names accepted by :func:`generate`.
GENERATORS = ("dense", "sparse", "planted")
#: Sizes used when none are given.
DEFAULT_SIZES = {"dense": (5, 5, 5), "sparse": (4, 4, 4), "planted": (6, 6, 6)}
#: Largest candidate count :func:`prove_optimum` also checks by brute force.
BRUTE_FORCE_LIMIT = 400
#: File name of the catalogue written by :func:`write_index`.
INDEX_NAME = "index.csv"


def _check_sizes(sizes: Sequence[int] | None, kind: str) -> tuple[int, ...]:
    if sizes is None:
        return DEFAULT_SIZES[kind]
    try:
        out = tuple(int(n) for n in sizes)
    except (TypeError, ValueError):
        raise InvalidProblemError(f"sizes must be integers, got {sizes!r}") from None
    if any(int(n) != n for n in sizes):
        raise InvalidProblemError(f"sizes must be integers, got {list(sizes)}")
    if len(out) < 2:
        raise InvalidProblemError(f"sizes must list at least 2 axes, got {list(out)}")
    if any(n < 1 for n in out):
        raise InvalidProblemError(f"sizes must be positive, got {list(out)}")
    return out


def _check_range(low: float, high: float) -> None:
    if not (math.isfinite(low) and math.isfinite(high) and low <= high):
        raise InvalidProblemError(f"need finite low <= high, got low={low}, high={high}")


def generate_dense(rng: np.random.Generator, sizes: Sequence[int] = (5, 5, 5), *,
                   low: int = 0, high: int = 100) -> AssignmentProblem:
    """Axial assignment with integer costs uniform in ``low..high`` (both included)."""
    sizes = _check_sizes(sizes, "dense")
    _check_range(low, high)
    if math.prod(sizes) > 5_000_000:
        raise InvalidProblemError(f"sizes {list(sizes)} give {math.prod(sizes)} costs; at "
                                  "most 5,000,000 for a dense instance")
    C = rng.integers(int(low), int(high) + 1, size=sizes).astype(np.float64)
    return AssignmentProblem.dense(C)


def generate_planted(rng: np.random.Generator, sizes: Sequence[int] = (6, 6, 6), *,
                     low: int = 20, high: int = 100) -> AssignmentProblem:
    """Axial assignment with a planted optimum (costs below ``low``, others ``low..high``).

    The planted assignment covers the smallest axis; its tuples map index ``i`` of
    that axis to a random distinct index of every other axis.  ``problem.optimum`` is
    its cost (the unique optimum, see the module docstring).
    """
    sizes = _check_sizes(sizes, "planted")
    _check_range(low, high)
    if low < 1:
        raise InvalidProblemError(f"low must be >= 1 so planted costs 0..low-1 exist, got {low}")
    if math.prod(sizes) > 5_000_000:
        raise InvalidProblemError(f"sizes {list(sizes)} give {math.prod(sizes)} costs; at "
                                  "most 5,000,000 for a dense instance")
    C = rng.integers(int(low), int(high) + 1, size=sizes).astype(np.float64)
    m = min(sizes)
    planted = tuple(rng.permutation(n)[:m] for n in sizes)
    C[planted] = rng.integers(0, int(low), size=m)
    return AssignmentProblem.dense(C, optimum=float(C[planted].sum()))


def generate_sparse(rng: np.random.Generator, sizes: Sequence[int] = (4, 4, 4), *,
                    targets: int | None = None, pd: float = 0.9, sigma: float = 1.0,
                    area: float = 100.0, gate: float = 0.999,
                    decimals: int | None = 4) -> AssignmentProblem:
    """S-D assignment with dummies from a synthetic scan of ``len(sizes)`` sensors.

    ``sizes[s]`` is the number of measurements of sensor s (detections first, false
    alarms fill the rest); ``targets`` defaults to ``min(sizes)``.  Positions are 2-D
    in ``[0, area]^2`` with Gaussian noise ``sigma``; ``gate`` is the chi-square
    probability of the gate; costs are rounded to ``decimals`` (None: keep all).
    """
    from scipy.special import chdtri

    sizes = _check_sizes(sizes, "sparse")
    N = len(sizes)
    if not 0 < pd <= 1:
        raise InvalidProblemError(f"pd must lie in (0, 1], got {pd}")
    if not (sigma > 0 and area > 0 and 0 < gate < 1):
        raise InvalidProblemError("need sigma > 0, area > 0 and 0 < gate < 1")
    if math.prod(n + 1 for n in sizes) > 2_000_000:
        raise InvalidProblemError(f"sizes {list(sizes)} give more than 2,000,000 candidate "
                                  "tuples before gating; use fewer or smaller sensors")
    M = min(sizes) if targets is None else int(targets)
    if M < 0:
        raise InvalidProblemError(f"targets must be >= 0, got {targets}")
    X = rng.uniform(0.0, area, size=(M, 2))
    meas = []
    for n in sizes:
        det = np.flatnonzero(rng.random(M) < pd)[:n]
        z = np.concatenate([X[det] + rng.normal(0.0, sigma, size=(len(det), 2)),
                            rng.uniform(0.0, area, size=(n - len(det), 2))])
        meas.append(z[rng.permutation(n)])
    grids = np.meshgrid(*[np.arange(n + 1) for n in sizes], indexing="ij")
    T = np.stack([g.ravel() for g in grids], axis=1)
    real = T > 0
    m = real.sum(axis=1)
    T, real, m = T[m > 0], real[m > 0], m[m > 0]
    # positions of the tuple's measurements, NaN for dummies
    P = np.full((len(T), N, 2), np.nan)
    for s in range(N):
        rows = real[:, s]
        P[rows, s] = meas[s][T[rows, s] - 1]
    centre = np.nanmean(P, axis=1)
    spread = np.nansum((P - centre[:, None, :]) ** 2, axis=(1, 2)) / sigma ** 2
    gain = math.log(area ** 2 / (2 * math.pi * sigma ** 2)) + math.log(pd / max(1 - pd, 1e-12))
    cost = 0.5 * spread - (m - 1) * gain
    dof = np.maximum(2 * (m - 1), 1)
    keep = (m == 1) | (spread <= chdtri(dof, 1.0 - gate))   # chi-square quantile
    cost = np.where(m == 1, 0.0, cost)
    if decimals is not None:
        cost = np.round(cost, int(decimals)) + 0.0
    return AssignmentProblem.sparse(sizes, T[keep], cost[keep])


_FUNCS = {"dense": generate_dense, "sparse": generate_sparse, "planted": generate_planted}


def generate(kind: str, *, seed: int, sizes: Sequence[int] | None = None,
             verify: bool = True, **params: Any) -> AssignmentProblem:
    """A seeded random instance of generator ``kind`` (see :data:`GENERATORS`).

    ``params`` go to the generator (:func:`generate_dense`, :func:`generate_sparse`,
    :func:`generate_planted`).  The problem's ``name`` records kind, sizes and seed,
    its ``meta["description"]`` the command that re-creates it.  For ``"planted"``
    the optimum is recorded; with ``verify`` it is also checked with HiGHS.
    """
    if kind not in _FUNCS:
        raise InvalidProblemError(f"unknown generator {kind!r}; valid: {', '.join(GENERATORS)}")
    if isinstance(seed, bool) or not isinstance(seed, (int, np.integer)) or seed < 0:
        raise InvalidProblemError(f"seed must be a non-negative integer, got {seed!r}")
    sizes_t = _check_sizes(sizes, kind)
    p = _FUNCS[kind](np.random.default_rng(int(seed)), sizes_t, **params)
    dims = "x".join(map(str, sizes_t))
    name = f"{kind}-{dims}-s{int(seed)}"
    extra = "".join(f" {k}={v}" for k, v in sorted(params.items()))
    cmd = f"assocopt generate {kind} --seed {int(seed)} --sizes {','.join(map(str, sizes_t))}"
    desc = {"dense": "random dense axial assignment",
            "sparse": "random sparse S-D assignment with dummies (synthetic 2-D scan, "
                      "chi-square gate)",
            "planted": "random axial assignment with a planted optimum (Grundel-like)"}[kind]
    meta = {"description": f"{desc}, sizes {dims}, seed {int(seed)}{extra}; re-create "
                           f"with: {cmd}" + (f" (parameters{extra} from Python)" if extra else "")}
    optimum, source = p.optimum, None
    if kind == "planted":
        source = ("planted by construction (every planted cost is below every other cost, "
                  "so the planted assignment is the unique optimum)")
        if verify:
            sol = solve(p, "highs")
            if sol.status is not Status.OPTIMAL or \
                    not math.isclose(sol.objective, optimum, rel_tol=1e-12, abs_tol=1e-9):
                raise AssertionError(f"planted optimum {optimum} not confirmed by HiGHS: "
                                     f"{sol.status} {sol.objective}")  # a bug, not bad input
            source += f"; verified by HiGHS {sol.solver_version} MILP (gap 0)"
    q = _rebuild(p, name=name, optimum=optimum)
    q.meta.update(meta)
    if source:
        q.meta["optimum_source"] = source
    return q


def _rebuild(p: AssignmentProblem, *, name: str | None, optimum: float | None
             ) -> AssignmentProblem:
    """The same problem with another name / optimum (problems are frozen)."""
    if p.kind == "dense":
        return AssignmentProblem.dense(p.to_cost_matrix(), name=name, optimum=optimum)
    if p.kind == "two_d":
        rm, cm = p.miss_costs()
        return AssignmentProblem.two_d(p.to_cost_matrix(), rm, cm, name=name, optimum=optimum)
    return AssignmentProblem.sparse(p.sizes, p.tuples, p.costs, name=name, optimum=optimum)


def prove_optimum(problem: AssignmentProblem, *, time_limit: float | None = None
                  ) -> tuple[float, str]:
    """The optimum of ``problem`` proven by HiGHS (gap 0), and a sentence saying how.

    Problems with at most :data:`BRUTE_FORCE_LIMIT` candidates are also enumerated
    exhaustively and must agree.  Raises :class:`InvalidProblemError` when HiGHS
    finds the problem infeasible or cannot prove optimality within ``time_limit``.
    """
    sol = solve(problem, "highs", time_limit=time_limit)
    if sol.status is not Status.OPTIMAL:
        raise InvalidProblemError(f"HiGHS could not prove an optimum: status {sol.status} "
                                  f"({sol.message})")
    how = f"proved by HiGHS {sol.solver_version} MILP (gap 0)"
    if problem.n_candidates <= BRUTE_FORCE_LIMIT:
        bf = solve(problem, "bruteforce")
        if bf.status is Status.OPTIMAL:
            if not math.isclose(bf.objective, sol.objective, rel_tol=1e-12, abs_tol=1e-9):
                raise AssertionError(f"HiGHS {sol.objective} != brute force {bf.objective}")
            how += " and exhaustive enumeration"
    return float(sol.objective), how


def feasibility(problem: AssignmentProblem, *, time_limit: float | None = 60.0
                ) -> tuple[bool | None, str]:
    """Whether ``problem`` has a feasible assignment, and why: ``(True|False|None, reason)``.

    Decided from the structure when possible (an uncovered index; a single-index
    dummy candidate for every real index; a full dense array), else by HiGHS within
    ``time_limit`` seconds (None: undecided when the limit is reached).
    """
    from ..problems.problem import index_label

    n_missing = problem.n_uncovered
    if n_missing:
        a, i = problem.uncovered(limit=1)[0]
        more = f" (and {n_missing - 1} more)" if n_missing > 1 else ""
        return False, f"{index_label(a, i)} is covered by no candidate{more}"
    R = problem.entry_rows[(problem.tuples > 0).sum(axis=1) == 1]
    hit = np.zeros(problem.n_rows, dtype=bool)
    hit[R[R >= 0]] = True
    if hit.all():
        return True, "every real index has a single-index (dummy) candidate"
    if problem.kind == "dense" and int((~problem.slack).sum()) == math.prod(problem.sizes):
        return True, "full dense cost array, nothing forbidden"
    sol = solve(problem, "highs", time_limit=time_limit)
    if sol.has_solution:
        return True, "HiGHS found a feasible assignment"
    if sol.status is Status.INFEASIBLE:
        return False, "HiGHS proves that no feasible assignment exists"
    return None, f"undecided: HiGHS stopped ({sol.status}) before finding an assignment"


# ----------------------------------------------------------------------- catalogue
#: Copies of the stored instances shipped inside the package, so an installed
#: assocopt has them without the source checkout (tests/test_instances_shipped.py
#: checks that they equal ``instances/``).
PACKAGED_INSTANCES = Path(__file__).resolve().parents[1] / "data" / "instances"


def default_instances_dir() -> Path:
    """``./instances`` when it exists, else the source checkout's ``instances/``
    folder, else the copies installed with the package (``assocopt/data/instances``)."""
    here = Path.cwd() / "instances"
    if here.is_dir():
        return here
    project = Path(__file__).resolve().parents[2] / "instances"
    if (project / INDEX_NAME).is_file():
        return project
    return PACKAGED_INSTANCES


def find_stored_instance(name: str) -> Path | None:
    """The stored instance file called ``name`` (``example-sd`` or ``example-sd.json``)
    in :func:`default_instances_dir`, or None."""
    if not name or Path(name).name != name:
        return None
    folder = default_instances_dir()
    for candidate in (name, f"{name}.json"):
        path = folder / candidate
        if path.suffix == ".json" and path.is_file():
            return path
    return None


def catalogue(directory: str | os.PathLike[str]) -> list[dict[str, Any]]:
    """One record per instance file (``*.json``) in ``directory``.

    Records: ``file`` (name relative to the folder), ``name``, ``kind``, ``ndim``,
    ``sizes``, ``candidates``, ``optimum``, ``optimum_source``, ``description``.
    Files are read (and so validated) with :func:`assocopt.io.read_instance`.
    """
    from ..io import read_instance

    folder = Path(directory)
    if not folder.is_dir():
        raise InvalidProblemError(f"{folder}: not a folder of instances")
    out = []
    for f in sorted(folder.glob("*.json")):
        p = read_instance(f)
        out.append({"file": f.name, "name": p.name, "kind": p.kind, "ndim": p.ndim,
                    "sizes": list(p.sizes), "candidates": int((~p.slack).sum()),
                    "optimum": p.optimum, "optimum_source": p.meta.get("optimum_source"),
                    "description": p.meta.get("description")})
    return out


def write_index(directory: str | os.PathLike[str]) -> Path:
    """Write ``directory/index.csv``, one row per instance (a CSV so that a shell glob
    such as ``instances/*.json`` still means "the instances"; GitHub shows it as a table).
    """
    import csv

    folder = Path(directory)
    records = catalogue(folder)
    path = folder / INDEX_NAME
    cols = ["file", "name", "kind", "ndim", "sizes", "candidates", "optimum",
            "optimum_source", "description"]
    with open(path, "w", newline="", encoding="utf-8") as fh:
        w = csv.DictWriter(fh, fieldnames=cols, lineterminator="\n")
        w.writeheader()
        for r in records:
            w.writerow({**r, "sizes": "x".join(map(str, r["sizes"])),
                        "optimum": "" if r["optimum"] is None else f"{r['optimum']:.17g}"})
    return path


def gated_2d(n: int, k: int, *, seed: int, miss: float = 6.0,
             n_cols: int | None = None) -> AssignmentProblem:
    """A gated 2-D tracking scan: ``n`` tracks, ``n_cols`` (default ``n``) measurements,
    each track gated to ``k`` distinct nearby measurements at chi-square(2) costs (squared
    normalised distances), every track and measurement may stay unassigned at ``miss``.

    Built as a candidate list (``AssignmentProblem.sparse``), never as a matrix, so
    ``n = 10^5`` is cheap.
    """
    m = n if n_cols is None else int(n_cols)
    if n < 0 or m < 0 or not 1 <= k <= m:
        raise InvalidProblemError(f"gated_2d needs n >= 0 and 1 <= k <= n_cols, "
                                  f"got n={n}, k={k}, n_cols={m}")
    rng = np.random.default_rng(seed)
    width = min(m, 4 * k)
    off = np.argsort(rng.random((n, width)), axis=1)[:, :k]
    centre = (np.arange(n) * m) // max(n, 1)
    cols = (centre[:, None] + off - width // 2) % m
    rows = np.repeat(np.arange(n), k)
    pairs = np.stack([rows + 1, cols.ravel() + 1], axis=1)
    misses_r = np.stack([np.arange(1, n + 1), np.zeros(n, np.int64)], axis=1)
    misses_c = np.stack([np.zeros(m, np.int64), np.arange(1, m + 1)], axis=1)
    costs = np.concatenate([rng.chisquare(2, n * k), np.full(n + m, float(miss))])
    return AssignmentProblem.sparse((n, m), np.concatenate([pairs, misses_r, misses_c]),
                                    costs, name=f"gated-2d-n{n}-k{k}-s{seed}")
