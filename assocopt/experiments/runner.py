"""Running an experiment: every missing trial, in-process or on any executor.

See :mod:`assocopt.experiments` for the execution model.
"""

from __future__ import annotations

import concurrent.futures as cf
import math
import multiprocessing
import os
import time
from pathlib import Path
from typing import Any, Callable, Mapping, Sequence

from ..runtime.errors import AssocoptError
from ..runtime.progress import Progress
from .design import Experiment, TrialError, setting_key, trial_seed
from .store import ResultStore

__all__ = ["run_experiment", "run_all"]


def _run_chunk(trial_fn, setting: Mapping, skey: str, methods: list[str],
               trials: list[int], master: int, on_result: Callable | None = None
               ) -> list[tuple[int, dict, float]]:
    """Run several trials of one setting (module-level: picklable for workers).

    In-process, ``on_result`` stores each trial as soon as it is finished.
    """
    from ..solvers.kernels.tiers import reproducible
    with reproducible():              # the kernels compiled: same route in every worker
        return _run_trials(trial_fn, setting, skey, methods, trials, master, on_result)


def _run_trials(trial_fn, setting: Mapping, skey: str, methods: list[str],
                trials: list[int], master: int, on_result: Callable | None
                ) -> list[tuple[int, dict, float]]:
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
        Show a progress bar (tqdm, on stderr).
    chunk_size : int, optional
        Trials per submitted task (default: chosen from the work left and workers).

    Returns
    -------
    dict with ``done`` (trials run now), ``skipped`` (already stored) and ``total``.

    Examples
    --------
    >>> import tempfile, os
    >>> from assocopt.experiments import _demo_trial
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
        bar = Progress(total, progress, exp.name, unit="trial", initial=n_skip)
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
        from ..runtime.parent_watch import watch_parent
        # workers exit when this process dies, even by SIGKILL (see parent_watch)
        executor = cf.ProcessPoolExecutor(max_workers=workers,
                                          mp_context=multiprocessing.get_context("spawn"),
                                          initializer=watch_parent, initargs=(os.getpid(),))
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
