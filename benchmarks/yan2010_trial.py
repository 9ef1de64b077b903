"""CPU time of paper 001's grid trial: this tree against an earlier revision, in one process.

The earlier revision's ``assocopt`` is extracted with ``git archive`` into a temporary
folder and imported as ``assocopt_base`` (the package imports itself relatively), so
both codes run interleaved, on the same settings and seeds, under the same load; the
records of every trial must agree (compute time aside).  Prints the mean CPU seconds
per trial (all eight grid methods) of both and their ratio, with the load average::

    python benchmarks/yan2010_trial.py --base e333ed2 --n 10,50,100 --reps 2
"""

from __future__ import annotations

import argparse
import importlib
import io
import json
import os
import subprocess
import sys
import tarfile
import tempfile
import time

from assocopt.experiments.design import trial_seed
from assocopt.reproduce.yan2010 import experiment as NEW


def _base_module(rev: str, where: str):
    """``assocopt.reproduce.yan2010.experiment`` of revision ``rev``, as ``assocopt_base``."""
    blob = subprocess.run(["git", "archive", rev, "assocopt"], check=True,
                          capture_output=True).stdout
    with tarfile.open(fileobj=io.BytesIO(blob)) as tar:
        tar.extractall(where, filter="data")
    os.rename(os.path.join(where, "assocopt"), os.path.join(where, "assocopt_base"))
    sys.path.insert(0, where)
    return importlib.import_module("assocopt_base.reproduce.yan2010.experiment")


def _strip(res: dict) -> str:
    return json.dumps({m: {k: v for k, v in r.items() if k != "t_decide"}
                       for m, r in res.items()}, sort_keys=True)


def main(argv: list[str] | None = None) -> dict:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--base", required=True, help="git revision to compare with")
    ap.add_argument("--n", default="10,50,100", help="target counts of the grid to time")
    ap.add_argument("--reps", type=int, default=2, help="trials per grid setting")
    a = ap.parse_args(argv)
    ns = {int(x) for x in a.n.split(",")}
    with tempfile.TemporaryDirectory() as tmp:
        old = _base_module(a.base, tmp)
        settings = [s for s in NEW.experiments(a.reps, 0, None, parts=("grid",))[0].settings
                    if s["n"] in ns]
        cpu = {"base": 0.0, "this": 0.0}
        for r in range(a.reps):
            for s in settings:
                seed, out = trial_seed(0, s, r), {}
                order = [("base", old), ("this", NEW)]
                for name, mod in (order if r % 2 == 0 else order[::-1]):
                    t = time.process_time()
                    out[name] = mod.trial(s, NEW.GRID_METHODS, seed)
                    cpu[name] += time.process_time() - t
                if _strip(out["base"]) != _strip(out["this"]):
                    raise SystemExit(f"records differ: {s['variant']}, n = {s['n']}, trial {r}")
        sys.path.remove(tmp)                        # forget the base code again
        for name in [m for m in sys.modules if m.split(".")[0] == "assocopt_base"]:
            del sys.modules[name]
    k = a.reps * len(settings)
    res = {"trials": k, "base_s": cpu["base"] / k, "this_s": cpu["this"] / k,
           "ratio": cpu["this"] / cpu["base"], "loadavg": os.getloadavg()}
    print(f"{k} trials (n in {sorted(ns)}), CPU s per trial: {a.base} {res['base_s']:.4f}, "
          f"this tree {res['this_s']:.4f}, ratio {res['ratio']:.3f}; load average "
          f"{' '.join(f'{x:.2f}' for x in res['loadavg'])}")
    return res


if __name__ == "__main__":
    main()
