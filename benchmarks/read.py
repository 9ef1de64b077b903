"""Time to read a stored instance (``read_instance``), against a parse-only floor.

    python benchmarks/read.py                        # writes docs/benchmarks-read.{md,json}
    python benchmarks/read.py --before-tree DIR      # and times another checkout too
    python benchmarks/read.py --quick --out DIR      # small files, one round (the tests)

The instance files are written (``write_instance`` / ``write_public``) into a
temporary folder from seeded generators, plus a Grundel ``ap3.50.1`` and the
OR-Library ``assign700`` file when ``../shared/ap_instances`` exists (skipped
otherwise).  Each reader runs in a fresh subprocess of this interpreter with the
checkout first on ``PYTHONPATH`` (the current tree, and ``--before-tree`` when
given, e.g. a ``git worktree`` of an older commit); each file is read once
unmeasured, then ``--rounds`` times, best kept.  The floor is what parsing alone
costs in the same process: ``json.load`` and ``np.array(costs, dtype=float)``
(plus ``np.array(tuples)`` for a sparse file) for JSON, ``str.split`` and
``float()`` over the tokens for the text formats.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
PAGE = ROOT / "docs" / "benchmarks-read.md"
DATA = ROOT / "docs" / "benchmarks-read.json"
SHARED = ROOT.parent / "shared" / "ap_instances"


# ------------------------------------------------------------------ the files
def _dense(sizes: tuple[int, ...], seed: int, kind: str) -> Any:
    from assocopt import AssignmentProblem
    from assocopt.workflow.generate import generate_dense
    rng = np.random.default_rng(seed)
    if kind == "int":
        return generate_dense(rng, sizes, low=1000, high=2000)
    C = rng.random(sizes)
    if kind == "forbidden":
        C[rng.random(sizes) < 0.1] = np.inf
    return AssignmentProblem.dense(C)


def _sparse(n: int, k: int, seed: int) -> Any:
    from assocopt import AssignmentProblem
    rng = np.random.default_rng(seed)
    T = np.unique(rng.integers(0, n + 1, size=(k, 3)), axis=0)
    T = T[T.any(axis=1)]
    return AssignmentProblem.sparse((n, n, n), T, rng.normal(size=len(T)).round(6))


def cases(quick: bool) -> list[tuple[str, str, Any]]:
    """``(key, description, problem builder)`` of each generated JSON file."""
    m, big, two, sp = (10, 20, 100, 2000) if quick else (50, 100, 2000, 200_000)
    return [
        ("dense3-int", f"dense 3-D {m}^3, integer costs 1000..2000 (`generate_dense`, seed 5)",
         lambda: _dense((m, m, m), 5, "int")),
        ("dense3-float", f"dense 3-D {m}^3, float costs (uniform, 17 digits)",
         lambda: _dense((m, m, m), 6, "float")),
        ("dense3-inf", f"dense 3-D {m}^3, float costs, 10% forbidden (`\"inf\"`)",
         lambda: _dense((m, m, m), 7, "forbidden")),
        ("dense3-big", f"dense 3-D {big}^3, integer costs 1000..2000",
         lambda: _dense((big, big, big), 8, "int")),
        ("dense2", f"dense 2-D {two}x{two}, integer costs 1000..2000",
         lambda: _dense((two, two), 9, "int")),
        ("sparse3", f"sparse 3-D, {sp:,} random candidates with dummies, 6-decimal costs",
         lambda: _sparse(100, sp, 10)),
    ]


def shared_files(quick: bool) -> list[tuple[str, str, Path]]:
    """The public instances read when ``../shared/ap_instances`` exists."""
    if quick or not SHARED.is_dir():
        return []
    out = [("grundel", "Grundel `ap3.50.1.txt` (50^3, one cost per line)",
            SHARED / "grundel_ap3" / "ap3.50.1.txt"),
           ("orlib", "OR-Library `assign700.txt` (700x700)",
            SHARED / "orlib_lap" / "assign700.txt")]
    return [c for c in out if c[2].is_file()]


def write_files(folder: Path, quick: bool) -> list[dict[str, Any]]:
    from assocopt.io import write_instance
    rows = []
    for key, what, build in cases(quick):
        path = folder / f"{key}.json"
        write_instance(build(), path)
        rows.append({"key": key, "what": what, "path": str(path), "format": "json"})
    for key, what, path in shared_files(quick):
        rows.append({"key": key, "what": what, "path": str(path), "format": "text"})
    for r in rows:
        r["bytes"] = os.path.getsize(r["path"])
    return rows


# ------------------------------------------------------------------ timing
def best_of(fn, rounds: int) -> float:
    fn()
    best = float("inf")
    for _ in range(rounds):
        t0 = time.perf_counter()
        fn()
        best = min(best, time.perf_counter() - t0)
    return best


def floor(path: str, fmt: str) -> None:
    """Parsing alone: the least any reader must do."""
    if fmt == "json":
        with open(path, encoding="utf-8") as f:
            doc = json.load(f)
        np.array(doc["costs"], dtype=float)
        if doc["kind"] == "sparse":
            np.array(doc["tuples"])
        return
    with open(path, encoding="utf-8") as f:
        tokens = f.read().split()
    np.fromiter(map(float, tokens), dtype=float, count=len(tokens))


_CHILD = """
import json, sys, time
sys.path.insert(0, {tree!r})
from assocopt.io import read_instance
paths, rounds = json.loads(sys.argv[1]), int(sys.argv[2])
out = []
for p in paths:
    read_instance(p)
    best = float("inf")
    for _ in range(rounds):
        t0 = time.perf_counter(); read_instance(p); best = min(best, time.perf_counter() - t0)
    out.append(best)
print(json.dumps(out))
"""


def time_tree(tree: Path, paths: list[str], rounds: int) -> list[float]:
    """Best ``read_instance`` time of each file with the assocopt of checkout ``tree``."""
    env = dict(os.environ)
    env["PYTHONPATH"] = str(tree)
    done = subprocess.run([sys.executable, "-c", _CHILD.format(tree=str(tree)),
                           json.dumps(paths), str(rounds)], env=env, cwd=tree,
                          capture_output=True, text=True)
    if done.returncode != 0:
        raise RuntimeError(f"timing in {tree} failed: {done.stderr[-800:]}")
    return json.loads(done.stdout.splitlines()[-1])


def measure(rounds: int, quick: bool, before: Path | None,
            before_label: str | None = None) -> dict[str, Any]:
    with tempfile.TemporaryDirectory() as tmp:
        rows = write_files(Path(tmp), quick)
        paths = [r["path"] for r in rows]
        now = time_tree(ROOT, paths, rounds)
        old = time_tree(before, paths, rounds) if before is not None else None
        for k, r in enumerate(rows):
            r["floor_s"] = round(best_of(lambda: floor(r["path"], r["format"]), rounds), 4)
            r["read_s"] = round(now[k], 4)
            r["before_s"] = None if old is None else round(old[k], 4)
            r["ratio_to_floor"] = round(r["read_s"] / r["floor_s"], 2)
            r["speedup"] = None if old is None else round(r["before_s"] / r["read_s"], 1)
            del r["path"]
    return {"rounds": rounds, "quick": quick,
            "before_tree": None if before is None else before_label or _describe(before),
            "machine": {"python": platform.python_version(), "system": platform.system(),
                        "machine": platform.machine(), "cpus": os.cpu_count(),
                        "numpy": np.__version__},
            "rows": rows}


def _describe(tree: Path) -> str:
    """The commit a checkout is at (its short hash and subject), else its path."""
    done = subprocess.run(["git", "-C", str(tree), "log", "-1", "--format=%h %s"],
                          capture_output=True, text=True)
    return done.stdout.strip()[:72] if done.returncode == 0 else str(tree)


# ------------------------------------------------------------------ the page
def _s(v: float | None) -> str:
    return "-" if v is None else f"{v:.3f}"


def render(data: dict[str, Any]) -> str:
    """The docs page for ``data`` (tests/test_benchmarks_read.py checks that the
    committed page is this function of the committed json)."""
    m = data["machine"]
    before = data["before_tree"]
    lines = [
        "# Reading stored instances",
        "",
        "Measured by `python benchmarks/read.py"
        + (" --before-tree DIR" if before else "") + "` (numbers below from "
        "`docs/benchmarks-read.json`, written by the same run). Each file is read by "
        "`read_instance` in a fresh process, once unmeasured, then best of "
        f"{data['rounds']} rounds. The floor is parsing alone in the same way: "
        "`json.load` plus `np.array(costs, dtype=float)` (and `np.array(tuples)`) for "
        "JSON, `str.split` plus `float()` over the tokens for the text formats; "
        "`read_instance` does that and also validates every entry (shape, type, range, "
        "NaN, bools), builds the problem, and for a text file detects the format.",
        "",
        f"Machine: Python {m['python']}, {m['system']} {m['machine']}, {m['cpus']} CPUs "
        f"(shared with other work: times are best-of), numpy {m['numpy']}.",
        "",
    ]
    if before:
        lines += [f"The `before` column is the same run's reading with the checkout at "
                  f"`{before}`, the reader before the bulk routes (such a tree: "
                  "`git archive COMMIT | tar -x -C DIR`).", ""]
    lines += ["| file | size (MB) | floor (s) | read_instance (s) | ratio to floor | "
              "before (s) | speed-up |",
              "|---|---|---|---|---|---|---|"]
    for r in data["rows"]:
        up = "-" if r["speedup"] is None else f"{r['speedup']:.1f}x"
        lines.append(f"| {r['what']} | {r['bytes'] / 1e6:.1f} | {_s(r['floor_s'])} | "
                     f"{_s(r['read_s'])} | {r['ratio_to_floor']:.2f}x | "
                     f"{_s(r['before_s'])} | {up} |")
    lines += [
        "",
        "How: a JSON cost array is converted by one `np.array` call and checked in bulk "
        "(dtype and shape against the first entries' shape, range by one min and one "
        "max); a single scan of the text beforehand proves that no `true`/`false`/"
        "`null` occurs (numpy would turn `True` into `1.0`) and that no number literal "
        "can overflow (so `json` needs no per-float hook to refuse `1e999`). When a "
        "proof fails the entries' types are checked with C-level passes, and when "
        "those fail too the reader walks the entries one by one, which is what names "
        "the bad entry's position in the error; every error message is the walk's. "
        "Text files are split into tokens once (format detection and reader share "
        "them) and converted with `float()` over the list. A dense N-D problem whose "
        "costs are all finite gets its candidate tuples as a broadcast index grid.",
        "",
    ]
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--rounds", type=int, default=3, help="timed rounds (best kept)")
    ap.add_argument("--before-tree", type=Path, default=None,
                    help="another checkout to time as the 'before' column")
    ap.add_argument("--before-label", default=None,
                    help="how the page names --before-tree (default: its git commit)")
    ap.add_argument("--quick", action="store_true", help="small files, one round")
    ap.add_argument("--out", type=Path, default=None, help="folder for the page and json")
    ap.add_argument("--no-write", action="store_true", help="print only")
    args = ap.parse_args(argv)
    data = measure(1 if args.quick else args.rounds, args.quick, args.before_tree,
                   args.before_label)
    for r in data["rows"]:
        print(f"{r['key']:<14} floor {r['floor_s']:.3f} s  read {r['read_s']:.3f} s  "
              f"{r['ratio_to_floor']:.2f}x" + ("" if r["before_s"] is None else
                                               f"  before {r['before_s']:.3f} s"))
    if not args.no_write:
        page, datafile = ((PAGE, DATA) if args.out is None else
                          (args.out / PAGE.name, args.out / DATA.name))
        datafile.write_text(json.dumps(data, indent=2) + "\n")
        page.write_text(render(data))
        print(f"wrote {page} and {datafile}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
