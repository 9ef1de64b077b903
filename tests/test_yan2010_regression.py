"""Paper 001's trials give the same records after the speed-up of the trial loop.

``tests/data/yan2010_trials.json`` was written by the code BEFORE the speed-up
(commit e333ed2, ``python tests/test_yan2010_regression.py --write`` run against that
tree): every metric of a few trials of every part -- grid cells (sparse scans), the
table-1 and Fig.-4 settings (every scan, the pair frame and the weighted test), the
sensitivity variants with another tracker or initialisation, and three nodes -- at
small ``n``.  The current code must give the same numbers (to 1e-12; the decisions,
hence the rates, exactly).
"""

from __future__ import annotations

import json
import math
import shutil
import subprocess
import sys
from functools import lru_cache
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings, strategies as st

from assocopt.experiments.design import setting_key, trial_seed
from assocopt.reproduce.yan2010.experiment import (FIG4_METHODS, GRID_METHODS, SENS_METHODS,
                                                   TABLE1_METHODS, THREE_NODE_METHODS,
                                                   experiments, trial)
from assocopt.tracking.decide.max_degree import COUNTER_SEMANTICS, QualityCounter
from conftest import load_script

FIXTURE = Path(__file__).resolve().parent / "data" / "yan2010_trials.json"
SKIP = ("t_decide",)                        # compute time, not a result


@lru_cache(maxsize=1)
def _cases() -> list[tuple[dict, list[str], int]]:
    """(setting, methods, trial index) of the pinned trials: the experiments' own
    settings, with ``n`` cut to keep the test fast."""
    exps = {e.params["experiment"]: e for e in experiments(
        2, 0, {"confirm": ("per-emitter", 0.2), "grid_n": (10, 20)},
        ("table1", "fig4", "sensitivity", "grid", "confirm", "three_node"))}
    out: list[tuple[dict, list[str], int]] = []
    for s in exps["grid"].settings:
        if s["features"] in ("types10", "per-emitter") and s["coverage"] in (0.0, 0.2) \
                or s["features"] == "one-type":
            out += [(s, list(GRID_METHODS), t) for t in (0, 1)]
    out += [(exps["confirm"].settings[1], list(GRID_METHODS), 0)]
    out += [({**exps["table1"].settings[0]}, list(TABLE1_METHODS), t) for t in (0, 1)]
    out += [({**exps["fig4"].settings[0], "n": 12}, list(FIG4_METHODS), 0)]
    for s in exps["sensitivity"].settings:
        if s["variant"] in ("kf-on-fixes", "one-point-init", "unique-features", "tdoa-x3"):
            out += [({**s, "n": 15}, list(SENS_METHODS), 0)]
    out += [(s, list(THREE_NODE_METHODS), 0) for s in exps["three_node"].settings
            if s["n"] == 10]
    return out


def _run(case: tuple[dict, list[str], int]) -> dict[str, dict[str, float]]:
    s, methods, t = case
    res = trial(s, methods, trial_seed(0, s, t))
    return {m: {k: v for k, v in r.items() if k not in SKIP} for m, r in res.items()}


def _same(a: float, b: float) -> bool:
    return (math.isnan(a) and math.isnan(b)) or abs(a - b) <= 1e-12


def test_fixture_covers_every_case():
    stored = json.loads(FIXTURE.read_text())
    assert [c["key"] for c in stored["cases"]] == \
        [setting_key(s) + f"#{t}" for s, _, t in _cases()]


#: The code before the speed-up, which wrote the fixture.
OLD_REVISION = "e333ed2"


def _differences(got: dict, want: dict) -> dict:
    """Metric by metric where ``got`` and the records ``want`` differ (beyond 1e-12)."""
    assert sorted(got) == sorted(want)
    out = {}
    for m, rec in want.items():
        assert sorted(got[m]) == sorted(rec), m
        bad = {k: (got[m][k], v) for k, v in rec.items()
               if not _same(got[m][k], float("nan") if v is None else v)}
        if bad:
            out[m] = bad
    return out


@lru_cache(maxsize=1)
def _old_tree() -> Path | None:
    """The package as it was at :data:`OLD_REVISION`, unpacked from git (None: no git
    history here)."""
    root = Path(__file__).resolve().parents[1]
    if shutil.which("git") is None:
        return None
    import tempfile
    dest = Path(tempfile.mkdtemp(prefix="assocopt-old-"))
    import atexit
    atexit.register(shutil.rmtree, dest, ignore_errors=True)
    archive = subprocess.run(["git", "-C", str(root), "archive", OLD_REVISION, "assocopt"],
                             capture_output=True)
    if archive.returncode:
        return None
    subprocess.run(["tar", "-x", "-C", str(dest)], input=archive.stdout, check=True)
    return dest


def _run_old(case: tuple[dict, list[str], int]) -> dict | None:
    """``_run(case)`` by the old code on this machine, in a child process."""
    tree = _old_tree()
    if tree is None:
        return None
    s, methods, t = case
    code = ("import json, sys\n"
            "from assocopt.experiments.design import trial_seed\n"
            "from assocopt.reproduce.yan2010.experiment import trial\n"
            "s, methods, t = json.loads(sys.stdin.read())\n"
            "res = trial(s, methods, trial_seed(0, s, t))\n"
            "print(json.dumps({m: {k: (None if v != v else v) for k, v in r.items()}"
            " for m, r in res.items()}))\n")
    out = subprocess.run([sys.executable, "-c", code], input=json.dumps([s, methods, t]),
                         capture_output=True, text=True, cwd=tree,
                         env={**__import__("os").environ, "PYTHONPATH": str(tree)})
    assert out.returncode == 0, out.stderr[-2000:]
    res = json.loads(out.stdout)
    return {m: {k: v for k, v in r.items() if k not in SKIP} for m, r in res.items()}


@pytest.mark.parametrize("i", range(len(_cases())))
def test_trial_records_equal_the_old_codes(i):
    """The fixture was written on one machine; a decision at a floating-point tie may
    go the other way on a processor with other vector instructions (seen: one grid
    trial on an AVX2-only machine; the old code gives the same there as the new).
    Where this machine disagrees with the fixture, the old code itself is run here
    (from git) and the new code must agree with it."""
    case = _cases()[i]
    want = json.loads(FIXTURE.read_text())["cases"][i]
    assert want["key"] == setting_key(case[0]) + f"#{case[2]}"
    got = _run(case)
    bad = _differences(got, want["records"])
    if bad:
        old = _run_old(case)
        assert old is not None, ("differs from the fixture and no git history to run "
                                 f"{OLD_REVISION} here", bad)
        assert not _differences(got, old), ("differs from the old code on this machine",
                                            _differences(got, old))


def _old_update(c: QualityCounter, partner: np.ndarray) -> None:
    """The counter update before the speed-up (every pair of the matrix), kept as the
    reference of :meth:`QualityCounter.update` (which works on the open block)."""
    if c.semantics == "off":
        return
    rows, cols = c.open_rows, c.open_cols
    assoc = np.zeros(c.delta.shape, dtype=bool)
    i = np.flatnonzero(rows & (partner >= 0))
    assoc[i, partner[i]] = True
    live = rows[:, None] & cols[None, :]
    dec = live & ~assoc
    if c.semantics == "seen":
        dec &= c.seen
    c.delta += assoc.astype(np.int64) - dec.astype(np.int64)
    if c.semantics == "floor":
        np.maximum(c.delta, 0, out=c.delta)
    c.seen |= assoc
    cand = np.argwhere(live & (c.delta >= c.fix_at))
    if len(cand):
        order = np.lexsort((cand[:, 0], -c.delta[cand[:, 0], cand[:, 1]]))
        for a, b in cand[order]:
            if c.fixed[a] < 0 and not c.col_fixed[b]:
                c.fixed[a] = b
                c.col_fixed[b] = True


@given(st.integers(0, 6), st.integers(0, 6), st.integers(0, 2 ** 32 - 1),
       st.sampled_from(COUNTER_SEMANTICS), st.integers(1, 3))
@settings(max_examples=60, deadline=None)
def test_counter_update_equals_the_full_matrix_reference(n1, n2, seed, semantics, fix_at):
    """Random decisions, some in closed columns, with ties in the counts: the same
    counts, seen pairs and fixed pairs as the old update, scan after scan."""
    rng = np.random.default_rng(seed)
    new, old = (QualityCounter(n1, n2, semantics, fix_at) for _ in range(2))
    for _ in range(10):
        partner = rng.integers(-1, n2, size=n1) if n2 else np.full(n1, -1)
        if n2 and rng.random() < 0.5:                 # mostly a fixed pattern: pairs fix
            partner = np.where(rng.random(n1) < 0.8, np.arange(n1) % n2, partner)
        new.update(partner)
        _old_update(old, partner)
        for a in ("delta", "seen", "fixed", "col_fixed"):
            assert np.array_equal(getattr(new, a), getattr(old, a)), a
    if semantics != "off":
        with pytest.raises(ValueError, match="partner must have shape"):
            new.update(np.full(n1 + 1, -1))


def test_speed_benchmark_compares_with_a_revision(capsys, monkeypatch):
    """``benchmarks/yan2010_trial.py`` against HEAD: both codes give the same records."""
    root = Path(__file__).resolve().parents[1]
    if shutil.which("git") is None or subprocess.run(
            ["git", "-C", str(root), "rev-parse", "HEAD"], capture_output=True).returncode:
        pytest.skip("not a git checkout")
    monkeypatch.chdir(root)
    res = load_script("benchmarks/yan2010_trial.py", "bench_yan2010_trial").main(
        ["--base", "HEAD", "--n", "10", "--reps", "1"])
    assert res["trials"] == 7 and res["base_s"] > 0 and res["this_s"] > 0
    assert "CPU s per trial" in capsys.readouterr().out


if __name__ == "__main__" and "--write" in sys.argv:
    cases = [{"key": setting_key(c[0]) + f"#{c[2]}",
              "records": {m: {k: (None if isinstance(v, float) and np.isnan(v) else v)
                              for k, v in r.items()} for m, r in _run(c).items()}}
             for c in _cases()]
    FIXTURE.write_text(json.dumps({"written_by": sys.argv[sys.argv.index("--write") + 1],
                                   "cases": cases}, indent=None, sort_keys=True) + "\n")
    print(len(cases), "cases written to", FIXTURE)
