"""Running a paper's experiments and what a reproduction records about its own runs:
the report records of every store (:func:`run_and_collect`), the wall time of every
invocation that computed trials, and the compute time stored with the trials themselves.

Both go into ``summary.json``, so the wall times a paper page quotes come from the
command's output, not from a note taken by hand.
"""

from __future__ import annotations

import json
import sqlite3
from pathlib import Path
from typing import Any, Callable, Mapping, Sequence

from ..experiments import report_records, run_all, summarise

__all__ = ["run_timed", "run_and_collect", "timing_history", "trial_seconds"]


def run_timed(exps: Sequence[Any], out: Path, *, runs: int, workers: int, seed: int,
              options: Mapping[str, Any] | None = None, executor: Any = None,
              progress: bool = False) -> dict[str, Any]:
    """Run (or resume) ``exps`` into ``out`` and return the summary's three timing
    entries, in the order the summaries store them: ``timing`` (this invocation),
    ``timing_history`` (:func:`timing_history`) and ``trial_seconds``."""
    timing = run_all(exps, out, workers=workers, executor=executor, progress=progress)
    history = timing_history(Path(out) / "summary.json", timing, runs=runs,
                             workers=workers, seed=seed, options=options)
    return {"timing": timing, "timing_history": history,
            "trial_seconds": trial_seconds(out, [e.name for e in exps])}


def run_and_collect(exps: Sequence[Any], out: Path, by: Sequence[str], *, runs: int,
                    workers: int, seed: int, options: Mapping[str, Any] | None = None,
                    executor: Any = None, progress: bool = False,
                    extra_rows: Callable[[Path, Any], list] | None = None,
                    flag: Callable[[Any, dict], bool] | None = None
                    ) -> tuple[dict[str, Any], list[dict[str, Any]]]:
    """Run (or resume) ``exps`` into ``out`` (:func:`run_timed`) and gather the report
    records of every store ``out/NAME.sqlite``, settings keyed by ``by``.

    ``extra_rows(store, exp)`` gives more rows reported with the store's own (paired
    differences); ``flag(exp, record)`` sets a record's flags in place and says whether
    it goes into ``summary.json``.  Returns the timing entries and the records.
    """
    timed = run_timed(exps, out, runs=runs, workers=workers, seed=seed, options=options,
                      executor=executor, progress=progress)
    records: list[dict[str, Any]] = []
    for exp in exps:
        store = Path(out) / f"{exp.name}.sqlite"
        rows = summarise(store, exp, include_volatile=True)
        if extra_rows is not None:
            rows = rows + extra_rows(store, exp)
        records += [r for r in report_records(rows, exp, by) if flag is None or flag(exp, r)]
    return timed, records


def timing_history(previous_summary: Path, timing: Mapping[str, Mapping[str, Any]], *,
                   runs: int, workers: int, seed: int,
                   options: Mapping[str, Any] | None = None) -> list[dict[str, Any]]:
    """The invocations into one output folder that computed trials, oldest first.

    ``previous_summary`` is the folder's ``summary.json`` before this invocation (its
    ``timing_history`` is kept; an older summary without one contributes its
    ``timing``); this invocation's ``timing`` is appended when it ran any trial.
    """
    hist: list[dict[str, Any]] = []
    try:
        old = json.loads(Path(previous_summary).read_text())
    except (OSError, ValueError):
        old = None
    if old is not None:
        if "timing_history" in old:
            hist = list(old["timing_history"])
        elif isinstance(old.get("timing"), dict) and any(
                t.get("done") for t in old["timing"].values()):
            hist = [{"runs": old.get("runs"), "workers": old.get("workers"),
                     "seed": old.get("seed"), "options": {}, "experiments": old["timing"]}]
    if any(t.get("done") for t in timing.values()):
        hist.append({"runs": runs, "workers": workers, "seed": seed,
                     "options": dict(options or {}),
                     "experiments": {k: dict(v) for k, v in timing.items()}})
    return hist


def trial_seconds(out: Path, names: Sequence[str]) -> dict[str, dict[str, float]]:
    """Per experiment store ``out/NAME.sqlite``: trials stored and the sum of their
    compute seconds (measured in the worker around each trial; one value per trial,
    shared by its methods)."""
    res = {}
    for name in names:
        path = Path(out) / f"{name}.sqlite"
        if not path.exists():
            continue
        con = sqlite3.connect(f"file:{path}?mode=ro", uri=True)
        try:
            n, s = con.execute(
                "SELECT COUNT(*), SUM(sec) FROM (SELECT MAX(seconds) AS sec FROM trials "
                "GROUP BY setting_id, trial)").fetchone()
        finally:
            con.close()
        res[name] = {"trials": int(n or 0), "seconds": float(s or 0.0)}
    return res


def duration(seconds: float) -> str:
    """Seconds as the pages print them: ``"42 s"``, or ``"3.5 min (210 s)"`` from 2 min."""
    return f"{seconds:.0f} s" if seconds < 120 else f"{seconds / 60:.1f} min ({seconds:.0f} s)"


def command(entry: Mapping[str, Any], paper: str) -> str:
    """The command of one ``timing_history`` entry (the CLI form when it has no options)."""
    if entry.get("options"):
        return (f"`reproduce({paper!r}, runs={entry['runs']}, workers={entry['workers']}, "
                f"seed={entry['seed']}, options={entry['options']!r})`")
    return (f"`assocopt reproduce {paper} --runs {entry['runs']} --workers {entry['workers']} "
            f"--seed {entry['seed']}`")


def timing_lines(summary: Mapping[str, Any], paper: str, heading: list[str]) -> list[str]:
    """The page's timing table: wall time of each invocation that ran trials, and the
    compute time stored with the trials (which also counts interrupted invocations).
    ``heading`` is the section's first lines; nothing when no invocation is recorded."""
    hist = summary.get("timing_history", [])
    if not hist:
        return []
    L = list(heading)
    L += ["| invocation | command | experiment | trials run | wall time |", "|---|---|---|---|---|"]
    for i, h in enumerate(hist, start=1):
        cmd = command(h, paper)
        done = [(name, t) for name, t in h["experiments"].items() if t["done"]]
        for name, t in done:
            L.append(f"| {i} | {cmd} | {name} | {t['done']} | {duration(t['wall_s'])} |")
        tot = sum(t["wall_s"] for _, t in done)
        L.append(f"| {i} | {cmd} | **all** | {sum(t['done'] for _, t in done)} | "
                 f"**{duration(tot)}** |")
    ts = summary.get("trial_seconds", {})
    if ts:
        L += ["", "Compute time stored with the trials (sum over the trials of the seconds "
              "each took in its worker process; 2 workers share the wall time):", "",
              "| experiment | trials stored | compute time |", "|---|---|---|"]
        for name, t in ts.items():
            L.append(f"| {name} | {t['trials']} | {duration(t['seconds'])} |")
    return L + [""]
