"""The SQLite results store: one row per (setting, method, trial), resumable.

Written by the coordinating process only, one transaction per trial.
"""

from __future__ import annotations

import json
import sqlite3
from pathlib import Path
from typing import Any, Iterable, Mapping, Sequence

from ..io.writers import jsonable
from .design import SCHEMA_VERSION, Experiment, StoreMismatchError

__all__ = ["ResultStore"]


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
                 json.dumps(_metric_values(r), sort_keys=True, separators=(",", ":")), seconds)
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


def _metric_values(metrics: Mapping[str, Any]) -> dict[str, Any]:
    """Metrics as floats (booleans count as 0/1); NaN/inf stored as missing (null)."""
    return jsonable({k: None if v is None else float(v) for k, v in metrics.items()},
                    nonfinite="null")
