"""Monte Carlo experiment runner shared by every paper's reproduction.

An :class:`Experiment` is a grid of *settings* (JSON-ready dicts) x *methods* x
``runs`` Monte Carlo *trials*.  A trial function computes the metrics of one
(setting, trial) for one or several methods::

    trial(setting: dict, methods: list[str], seed: numpy.random.SeedSequence)
        -> {method: {metric: float}}

Every method of a trial gets the **same seed**, so the same simulated data are
costed by every method and the comparison between methods is paired.  (Wrap a
per-method function ``f(setting, method, seed) -> {metric: float}`` with
:class:`PerMethod`.)

Determinism.  The seed of trial ``t`` of a setting is derived from the master seed,
a hash of the setting's canonical JSON and ``t`` (:func:`trial_seed`): it does not
depend on the grid order, the number of workers or the scheduling, so 1 worker or
16 give identical numbers.

Store.  Results go to an embedded SQLite file, one transaction per trial (all of
its methods at once), written by the coordinating process only.  A run that is
interrupted (Ctrl-C, killed, a failing trial) keeps every finished trial; running
the same experiment on the same store again computes only the missing
(setting, method, trial) keys, so nothing is lost or repeated.  A store created with
another master seed or other parameters is refused rather than mixed.

Execution.  ``workers=1`` runs in-process.  ``workers > 1`` uses a
:class:`concurrent.futures.ProcessPoolExecutor` (spawned processes).  Any object
with ``submit(fn, *args)`` returning a future with ``result()`` and ``done()``
works as ``executor`` -- a ``dask.distributed.Client`` does, so a cluster can run
the trials (dask is not a dependency).  The trial function must be picklable (a
module-level function).

Progress.  ``progress=True`` shows a tqdm bar when tqdm is installed, otherwise a
counter on stderr.
"""

from __future__ import annotations

import concurrent.futures as cf
import hashlib
import json
import math
import multiprocessing
import sqlite3
import sys
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Callable, Iterable, Mapping, Sequence

import numpy as np

from .errors import AssocoptError

__all__ = ["Experiment", "PerMethod", "ResultStore", "run_experiment", "trial_seed",
           "setting_key", "summarise", "paired_differences", "StoreMismatchError",
           "TrialError", "run_all", "report_records",
           "association_metrics"]

SCHEMA_VERSION = 2


class StoreMismatchError(AssocoptError, ValueError):
    """The results store belongs to another experiment, seed or parameter set."""


class TrialError(AssocoptError, RuntimeError):
    """A trial function raised; the message names the setting and trial."""


# --------------------------------------------------------------------------- seeds
def setting_key(setting: Mapping[str, Any]) -> str:
    """Canonical JSON of a setting (sorted keys): its identity in the store.

    >>> setting_key({"b": 1, "a": 0.5})
    '{"a":0.5,"b":1}'
    """
    try:
        return json.dumps(setting, sort_keys=True, separators=(",", ":"), allow_nan=False)
    except (TypeError, ValueError) as exc:
        raise AssocoptError(f"setting {setting!r} is not JSON-serialisable: {exc}") from exc


def trial_seed(master: int, setting: Mapping[str, Any] | str, trial: int) -> np.random.SeedSequence:
    """The seed of one trial: independent of workers, scheduling and grid order.

    ``SeedSequence(master, spawn_key=(h0, h1, h2, h3, trial))`` where ``h`` are four
    32-bit words of the SHA-256 of the setting's canonical JSON.

    >>> s1 = trial_seed(7, {"d": 0.5}, 3).generate_state(2).tolist()
    >>> s1 == trial_seed(7, '{"d":0.5}', 3).generate_state(2).tolist()
    True
    """
    key = setting if isinstance(setting, str) else setting_key(setting)
    digest = hashlib.sha256(key.encode("utf-8")).digest()
    words = tuple(int.from_bytes(digest[4 * i:4 * i + 4], "little") for i in range(4))
    return np.random.SeedSequence(int(master), spawn_key=words + (int(trial),))


# ---------------------------------------------------------------------- experiment
@dataclass(frozen=True)
class Experiment:
    """A settings x methods x trials grid and the function that runs one trial.

    Attributes
    ----------
    name : str
        Identifies the experiment in the store (one store, one experiment).
    settings : list of dict
        JSON-ready settings; each must be distinct.
    methods : list of str
    trial : callable
        ``trial(setting, methods, seed) -> {method: {metric: value}}``, picklable.
    runs : int
        Monte Carlo trials per setting.
    seed : int
        Master seed.
    params : dict
        Parameters recorded in the store; a store written with other params is refused.
    volatile : tuple of str
        Metrics that are not deterministic (timings); excluded from :func:`summarise`
        unless asked for, and never compared between runs.
    """

    name: str
    settings: Sequence[Mapping[str, Any]]
    methods: Sequence[str]
    trial: Callable[..., Mapping[str, Mapping[str, float]]]
    runs: int
    seed: int = 0
    params: Mapping[str, Any] = field(default_factory=dict)
    volatile: tuple[str, ...] = ()

    def __post_init__(self) -> None:
        if not isinstance(self.runs, int) or self.runs < 1:
            raise AssocoptError(f"runs must be a positive integer, got {self.runs!r}")
        keys = [setting_key(s) for s in self.settings]
        if len(set(keys)) != len(keys):
            raise AssocoptError("settings must be distinct")
        if not self.methods or len(set(self.methods)) != len(self.methods):
            raise AssocoptError(f"methods must be a non-empty list of distinct names, "
                                f"got {list(self.methods)}")


class PerMethod:
    """Adapt ``f(setting, method, seed) -> metrics`` to the batched trial signature.

    Each method still receives the same seed (paired comparison).
    """

    def __init__(self, fn: Callable[[Mapping, str, np.random.SeedSequence], Mapping[str, float]]):
        self.fn = fn

    def __call__(self, setting, methods, seed):
        return {m: self.fn(setting, m, seed) for m in methods}


# --------------------------------------------------------------------------- store
class ResultStore:
    """SQLite store of trial results: one row per (setting, method, trial).

    Use as a context manager, or call :meth:`close`.
    """

    def __init__(self, path: str | Path):
        self.path = Path(path)
        self.path.parent.mkdir(parents=True, exist_ok=True)
        self.conn = sqlite3.connect(str(self.path), isolation_level=None)  # explicit txns
        self.conn.execute("PRAGMA journal_mode=WAL")
        self.conn.execute("PRAGMA synchronous=NORMAL")
        self.conn.executescript("""
            CREATE TABLE IF NOT EXISTS meta (key TEXT PRIMARY KEY, value TEXT NOT NULL);
            CREATE TABLE IF NOT EXISTS settings (
                id INTEGER PRIMARY KEY, setting TEXT NOT NULL UNIQUE,
                position INTEGER NOT NULL);
            CREATE TABLE IF NOT EXISTS trials (
                setting_id INTEGER NOT NULL REFERENCES settings(id),
                method TEXT NOT NULL, trial INTEGER NOT NULL,
                metrics TEXT NOT NULL, seconds REAL,
                PRIMARY KEY (setting_id, method, trial)) WITHOUT ROWID;
        """)
        self._ids: dict[str, int] = {}

    def close(self) -> None:
        self.conn.close()

    def __enter__(self) -> "ResultStore":
        return self

    def __exit__(self, *exc) -> None:
        self.close()

    # meta ------------------------------------------------------------------
    def meta(self) -> dict[str, Any]:
        return {k: json.loads(v) for k, v in self.conn.execute("SELECT key, value FROM meta")}

    def bind(self, exp: Experiment) -> None:
        """Record the experiment's identity, or check it against what is stored."""
        want = {"schema": SCHEMA_VERSION, "name": exp.name, "seed": int(exp.seed),
                "params": json.loads(json.dumps(exp.params, sort_keys=True, default=str))}
        have = self.meta()
        if have:
            for k, v in want.items():
                if have.get(k) != v:
                    raise StoreMismatchError(
                        f"results store {self.path} was written with {k}={have.get(k)!r}, "
                        f"this run has {k}={v!r}; use another output directory or delete "
                        "the store to start afresh")
            return
        self.conn.execute("BEGIN IMMEDIATE")
        for k, v in want.items():
            self.conn.execute("INSERT INTO meta VALUES (?, ?)", (k, json.dumps(v, sort_keys=True)))
        self.conn.execute("COMMIT")

    def register_settings(self, keys: Sequence[str]) -> None:
        self.conn.execute("BEGIN IMMEDIATE")
        self.conn.executemany("INSERT OR IGNORE INTO settings (setting, position) VALUES (?, ?)",
                              [(k, i) for i, k in enumerate(keys)])
        self.conn.execute("COMMIT")
        self._ids = {k: int(i) for i, k in self.conn.execute("SELECT id, setting FROM settings")}

    # trials ----------------------------------------------------------------
    def done_keys(self) -> set[tuple[str, str, int]]:
        return {(s, m, int(t)) for s, m, t in self.conn.execute(
            "SELECT s.setting, t.method, t.trial FROM trials t JOIN settings s "
            "ON s.id = t.setting_id")}

    def write_trial(self, skey: str, trial: int, results: Mapping[str, Mapping[str, float]],
                    seconds: float) -> None:
        """All methods of one trial in one transaction (atomic)."""
        if skey not in self._ids:
            self.register_settings([skey])
        sid = self._ids[skey]
        rows = [(sid, m, int(trial),
                 json.dumps(_jsonable(r), sort_keys=True, separators=(",", ":")), seconds)
                for m, r in results.items()]
        self.conn.execute("BEGIN IMMEDIATE")
        try:
            self.conn.executemany("INSERT OR IGNORE INTO trials VALUES (?, ?, ?, ?, ?)", rows)
        except BaseException:
            self.conn.execute("ROLLBACK")
            raise
        self.conn.execute("COMMIT")

    def rows(self) -> Iterable[tuple[str, str, int, dict]]:
        for s, m, t, js in self.conn.execute(
                "SELECT s.setting, t.method, t.trial, t.metrics FROM trials t JOIN settings s "
                "ON s.id = t.setting_id ORDER BY s.position, t.method, t.trial"):
            yield s, m, int(t), json.loads(js)

    def count(self) -> int:
        return int(self.conn.execute("SELECT COUNT(*) FROM trials").fetchone()[0])


def _jsonable(metrics: Mapping[str, Any]) -> dict[str, Any]:
    out = {}
    for k, v in metrics.items():
        if isinstance(v, (bool, np.bool_)):
            out[k] = float(v)
        elif v is None:
            out[k] = None
        else:
            f = float(v)
            out[k] = f if math.isfinite(f) else None   # NaN/inf stored as missing
    return out


# -------------------------------------------------------------------------- runner
def _run_chunk(trial_fn, setting: Mapping, skey: str, methods: list[str],
               trials: list[int], master: int, on_result: Callable | None = None
               ) -> list[tuple[int, dict, float]]:
    """Run several trials of one setting (module-level: picklable for workers).

    In-process, ``on_result`` stores each trial as soon as it is finished.
    """
    out = []
    for t in trials:
        t0 = time.perf_counter()
        try:
            res = trial_fn(setting, list(methods), trial_seed(master, skey, t))
        except Exception as exc:
            raise TrialError(f"trial {t} of setting {skey} failed: "
                             f"{type(exc).__name__}: {exc}") from exc
        missing = set(methods) - set(res)
        if missing:
            raise TrialError(f"trial {t} of setting {skey} returned no metrics for "
                             f"{sorted(missing)}")
        item = (t, {m: dict(res[m]) for m in methods}, time.perf_counter() - t0)
        if on_result is not None:
            on_result(*item)
        else:
            out.append(item)
    return out


class _Progress:
    def __init__(self, total: int, done: int, enabled: bool, label: str):
        self.total, self.n, self.enabled = total, done, enabled
        self.bar = None
        self.last = 0.0
        self.t0 = time.perf_counter()
        if not enabled:
            return
        try:
            from tqdm import tqdm  # optional
            self.bar = tqdm(total=total, initial=done, desc=label, unit="trial",
                            file=sys.stderr, dynamic_ncols=True)
        except ImportError:
            self.label = label
            self._print(force=True)

    def update(self, k: int = 1) -> None:
        self.n += k
        if self.bar is not None:
            self.bar.update(k)
        elif self.enabled:
            self._print()

    def _print(self, force: bool = False) -> None:
        now = time.perf_counter()
        if force or now - self.last > 0.5 or self.n == self.total:
            self.last = now
            print(f"\r{self.label}: {self.n}/{self.total} trials "
                  f"({now - self.t0:.0f} s)", end="", file=sys.stderr, flush=True)

    def close(self) -> None:
        if self.bar is not None:
            self.bar.close()
        elif self.enabled:
            print(file=sys.stderr)


def _wait_any(pending: set) -> set:
    """Futures of ``pending`` that are done (blocks until at least one is)."""
    if all(isinstance(f, cf.Future) for f in pending):
        done, _ = cf.wait(pending, return_when=cf.FIRST_COMPLETED)
        return set(done)
    while True:                       # foreign futures (dask): poll
        done = {f for f in pending if f.done()}
        if done:
            return done
        time.sleep(0.005)


def run_experiment(exp: Experiment, store: str | Path | ResultStore, *, workers: int = 1,
                   executor: Any = None, progress: bool = False,
                   chunk_size: int | None = None) -> dict[str, int]:
    """Run every missing (setting, method, trial) of ``exp`` into ``store``.

    Parameters
    ----------
    exp : Experiment
    store : path or ResultStore
        SQLite file (created if absent).  Finished trials already in it are skipped.
    workers : int
        Processes of the default local pool (1: run in this process).
    executor : object with ``submit``, optional
        A ``concurrent.futures`` executor or a ``dask.distributed.Client``; used
        instead of the local pool (not shut down here).
    progress : bool
        Show a progress bar (tqdm) or counter (stderr).
    chunk_size : int, optional
        Trials per submitted task (default: chosen from the work left and workers).

    Returns
    -------
    dict with ``done`` (trials run now), ``skipped`` (already stored) and ``total``.

    Examples
    --------
    >>> import tempfile, os
    >>> exp = Experiment("demo", [{"mu": 0.0}], ["a"], _demo_trial, runs=3, seed=1)
    >>> with tempfile.TemporaryDirectory() as d:
    ...     run_experiment(exp, os.path.join(d, "r.sqlite"))
    {'done': 3, 'skipped': 0, 'total': 3}
    """
    if not isinstance(workers, int) or workers < 1:
        raise AssocoptError(f"workers must be a positive integer, got {workers!r}")
    own_store = not isinstance(store, ResultStore)
    st = ResultStore(store) if own_store else store
    try:
        st.bind(exp)
        keys = [setting_key(s) for s in exp.settings]
        st.register_settings(keys)
        done = st.done_keys()
        todo: list[tuple[int, list[int], list[str]]] = []   # (setting idx, trials, methods)
        by_methods: dict[tuple[int, tuple[str, ...]], list[int]] = {}
        n_skip = 0
        for i, k in enumerate(keys):
            for t in range(exp.runs):
                missing = tuple(m for m in exp.methods if (k, m, t) not in done)
                if not missing:
                    n_skip += 1
                    continue
                by_methods.setdefault((i, missing), []).append(t)
        n_todo = sum(len(v) for v in by_methods.values())
        total = n_todo + n_skip
        if chunk_size is None:
            chunk_size = max(1, min(32, math.ceil(n_todo / max(1, 8 * workers))))
        for (i, ms), ts in by_methods.items():
            for j in range(0, len(ts), chunk_size):
                todo.append((i, ts[j:j + chunk_size], list(ms)))
        bar = _Progress(total, n_skip, progress, exp.name)
        try:
            if executor is None and workers == 1:
                for i, ts, ms in todo:
                    def store_now(t, res, sec, _k=keys[i]):
                        st.write_trial(_k, t, res, sec)
                        bar.update()
                    _run_chunk(exp.trial, exp.settings[i], keys[i], ms, ts, exp.seed, store_now)
            else:
                _run_parallel(exp, st, keys, todo, workers, executor, bar)
        finally:
            bar.close()
        return {"done": n_todo, "skipped": n_skip, "total": total}
    finally:
        if own_store:
            st.close()


def _run_parallel(exp, st, keys, todo, workers, executor, bar) -> None:
    own = executor is None
    if own:
        executor = cf.ProcessPoolExecutor(max_workers=workers,
                                          mp_context=multiprocessing.get_context("spawn"))
    max_pending = 4 * workers if own else 64
    queue = list(reversed(todo))
    pending: dict[Any, int] = {}
    try:
        while queue or pending:
            while queue and len(pending) < max_pending:
                i, ts, ms = queue.pop()
                fut = executor.submit(_run_chunk, exp.trial, exp.settings[i], keys[i], ms, ts,
                                      exp.seed)
                pending[fut] = i
            for fut in _wait_any(set(pending)):
                i = pending.pop(fut)
                for t, res, sec in fut.result():
                    st.write_trial(keys[i], t, res, sec)
                    bar.update()
    except BaseException:
        for fut in pending:
            fut.cancel()
        if own:
            # do not wait for trials still running in the workers (they may be long):
            # finished trials are stored, the rest is redone on resume
            for proc in list(getattr(executor, "_processes", {}).values()):
                proc.terminate()
            executor.shutdown(wait=False, cancel_futures=True)
            own = False
        raise
    finally:
        if own:
            executor.shutdown(wait=True, cancel_futures=True)


# ------------------------------------------------------------------------ summaries
def summarise(store: str | Path | ResultStore, exp: Experiment | None = None, *,
              include_volatile: bool = False) -> list[dict[str, Any]]:
    """Mean of every metric per (setting, method) as records.

    Each record: ``setting`` (dict), ``method``, ``metric``, ``value`` (mean over the
    trials where it is defined), ``runs`` (that count), ``stderr`` (standard error).
    With ``exp``, only its settings, methods and trials ``0 .. runs-1`` are counted
    (a store may hold more, e.g. from an earlier run with more trials) and its
    ``volatile`` metrics are left out unless ``include_volatile``.  Ordered by the
    settings' position in the experiment, then method, then metric.
    """
    own = not isinstance(store, ResultStore)
    st = ResultStore(store) if own else store
    volatile = set(exp.volatile) if exp is not None else set()
    try:
        if exp is not None:
            keys = [setting_key(s) for s in exp.settings]
            pos = {k: i for i, k in enumerate(keys)}
            methods = set(exp.methods)
        else:
            pos = dict(st.conn.execute("SELECT setting, position FROM settings"))
        acc: dict[tuple[str, str], dict[str, list[float]]] = {}
        for s, m, t, metrics in st.rows():
            if exp is not None and (s not in pos or m not in methods or t >= exp.runs):
                continue
            d = acc.setdefault((s, m), {})
            for k, v in metrics.items():
                if v is not None and (include_volatile or k not in volatile):
                    d.setdefault(k, []).append(v)
        out = []
        for (s, m) in sorted(acc, key=lambda sm: (pos.get(sm[0], 1 << 30), sm[1])):
            for k in sorted(acc[(s, m)]):
                v = np.asarray(acc[(s, m)][k], dtype=np.float64)
                se = float(v.std(ddof=1) / math.sqrt(len(v))) if len(v) > 1 else None
                out.append({"setting": json.loads(s), "method": m, "metric": k,
                            "value": float(v.mean()), "runs": int(len(v)), "stderr": se})
        return out
    finally:
        if own:
            st.close()


def paired_differences(store: str | Path | ResultStore, exp: Experiment, metric: str,
                       baseline: str) -> list[dict[str, Any]]:
    """Mean and standard error of ``metric(method) - metric(baseline)`` over the trials
    of each setting (paired: the methods of a trial saw the same data).

    Records as :func:`summarise`, with ``metric`` = ``"<metric> - <baseline>"``.
    """
    own = not isinstance(store, ResultStore)
    st = ResultStore(store) if own else store
    try:
        keys = [setting_key(s) for s in exp.settings]
        pos = {k: i for i, k in enumerate(keys)}
        per: dict[tuple[str, int], dict[str, float]] = {}
        for s, m, t, metrics in st.rows():
            if s in pos and t < exp.runs and metrics.get(metric) is not None:
                per.setdefault((s, t), {})[m] = metrics[metric]
        acc: dict[tuple[str, str], list[float]] = {}
        for (s, _), by in per.items():
            if baseline not in by:
                continue
            for m, v in by.items():
                if m != baseline:
                    acc.setdefault((s, m), []).append(v - by[baseline])
        out = []
        for (s, m) in sorted(acc, key=lambda sm: (pos[sm[0]], list(exp.methods).index(sm[1]))):
            v = np.asarray(acc[(s, m)])
            se = float(v.std(ddof=1) / math.sqrt(len(v))) if len(v) > 1 else None
            out.append({"setting": json.loads(s), "method": m,
                        "metric": f"{metric} - {baseline}", "value": float(v.mean()),
                        "runs": int(len(v)), "stderr": se})
        return out
    finally:
        if own:
            st.close()


# ------------------------------------------------------------------------- metrics
def run_all(exps: Sequence[Experiment], out: str | Path, *, workers: int = 1,
            executor: Any = None, progress: bool = False) -> dict[str, dict[str, Any]]:
    """Run (or resume) every experiment into ``out/<name>.sqlite``: the loop each paper
    reproduction shares.  Returns each experiment's wall time and run statistics."""
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    timing: dict[str, dict[str, Any]] = {}
    for exp in exps:
        t0 = time.perf_counter()
        stats = run_experiment(exp, out / f"{exp.name}.sqlite", workers=workers,
                               executor=executor, progress=progress)
        timing[exp.name] = {"wall_s": time.perf_counter() - t0, **stats}
    return timing


def report_records(rows: Iterable[dict[str, Any]], exp: Experiment,
                   setting_keys: Sequence[str]) -> list[dict[str, Any]]:
    """Summary rows shaped for a report: tagged with the experiment's part, the
    setting cut to ``setting_keys``, and whether the metric is volatile (timing)."""
    out = []
    for r in rows:
        r["experiment"] = exp.params["experiment"]
        r["setting"] = {k: v for k, v in r["setting"].items() if k in setting_keys}
        r["volatile"] = r["metric"] in exp.volatile
        out.append(r)
    return out


def association_metrics(chosen: Iterable[Sequence[int]], true_partition: Iterable[Sequence[int]],
                        true_targets: Iterable[Sequence[int]]) -> dict[str, float]:
    """The two correct-association rates (SPEC.md 5; defined once, used everywhere).

    ``partition_correct``: 1 if the chosen tuples are exactly the true partition
    (targets and false-alarm singletons), else 0.
    ``tuple_rate``: fraction of the true target tuples found among the chosen ones.

    >>> association_metrics([(1, 2), (2, 1)], [(1, 2), (2, 1)], [(1, 2), (2, 1)])
    {'partition_correct': 1.0, 'tuple_rate': 1.0}
    >>> association_metrics([(1, 1), (2, 2)], [(1, 2), (2, 1)], [(1, 2), (2, 1)])
    {'partition_correct': 0.0, 'tuple_rate': 0.0}
    """
    ch = {tuple(int(v) for v in t) for t in chosen}
    part = {tuple(int(v) for v in t) for t in true_partition}
    targ = {tuple(int(v) for v in t) for t in true_targets}
    rate = len(ch & targ) / len(targ) if targ else 1.0
    return {"partition_correct": float(ch == part), "tuple_rate": float(rate)}


def _demo_trial(setting, methods, seed):
    """Tiny trial for examples and tests: ``x ~ N(mu, 1)`` per trial, shared by the
    methods (method ``"b"`` reports ``x + 1``); ``setting["sleep"]`` seconds of delay."""
    if setting.get("sleep"):
        time.sleep(float(setting["sleep"]))
    x = float(np.random.default_rng(seed).normal(setting["mu"]))
    return {m: {"x": x + (1.0 if m == "b" else 0.0), "t": time.perf_counter()} for m in methods}
