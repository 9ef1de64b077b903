"""Summaries of a results store: means with standard errors, paired differences,
report rows, and the association metrics the paper trials report.
"""

from __future__ import annotations

import json
import math
import time
from pathlib import Path
from typing import Any, Iterable, Sequence

import numpy as np

from .design import Experiment, setting_key
from .store import ResultStore

__all__ = ["summarise", "paired_differences", "report_records", "association_metrics"]


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
    """The two correct-association rates (defined once, used everywhere; docs/papers/lu2013.md).

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
