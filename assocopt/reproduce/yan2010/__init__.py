"""Reproduction of paper 001 (Yan et al. 2010): Table 1 and Fig. 4, and our extensions.

Four experiments, each with its own results store ``OUT/yan2010-*.sqlite``:

``table1``       correct association probability at t = 80 s for 10..100 targets: the
                 paper's rule (D-S degrees, maximum degree, counter), its pair-frame
                 reading, our 2-D assignment counterpart and the weighted test.
``fig4``         the correct rate at every scan for 60 targets, every method.
``sensitivity``  ours: 100 targets, one open parameter changed at a time.
``grid``         ours: 10..100 targets, single-node fraction x feature set, the paper's
                 rule against the 2-D assignment, counter or not, tolerance factor 2 or 1.
``confirm``      ours: one grid cell (option ``confirm``) rerun on fresh seeds.
``three_node``   ours: a third TDOA system and one S-D assignment over the three.

Every method of a trial decides on the same simulated run (paired comparison).  The
metric (``correct_T``) is defined in docs/papers/yan2010.md.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any, Mapping, Sequence

from ..runlog import run_and_collect
from .._report import write_report
from .experiment import (DEFAULTS, LABELS, METHODS, PAPER_CLAIMS, PAPER_METHODS,  # noqa: F401
                         PAPER_TABLE1, SENS_VARIANTS, TABLE1_N, experiments, parameters, trial)
from .report import make_figures, render_tables  # noqa: F401

__all__ = ["PAPER_TABLE1", "TABLE1_N", "DEFAULTS", "METHODS", "experiments", "trial",
           "parameters", "run", "render_tables", "make_figures"]

PARTS = ("table1", "fig4", "sensitivity", "grid", "confirm", "three_node")


def _kept(metric: str) -> bool:
    """The grid's metrics that go into ``summary.json``: those at 5 s and 80 s (the
    tables use no other time) and the final fixing counts."""
    return metric.endswith(("_5", "_80")) or metric in ("fixed_final", "wrong_fixed_final",
                                                        "t_decide")


def run(runs: int, workers: int, seed: int, out, *, progress: bool = False,
        executor: Any = None, options: Mapping[str, Any] | None = None,
        parts: Sequence[str] = PARTS, echo=print) -> dict[str, Any]:
    """Run (or resume) the reproduction into ``out`` and write its report files
    (:func:`assocopt.reproduce.reproduce`; stores ``out/yan2010-*.sqlite``)."""
    def flag(exp, r: dict[str, Any]) -> bool:
        r["method_is_ours"] = r["method"] not in PAPER_METHODS
        return exp.params["experiment"] not in ("grid", "confirm") or _kept(r["metric"])

    out = Path(out)
    timed, records = run_and_collect(experiments(runs, seed, options, parts), out,
                                     ("n", "variant", "features", "coverage"), runs=runs,
                                     workers=workers, seed=seed, options=options,
                                     executor=executor, progress=progress, flag=flag)
    methods = sorted({r["method"] for r in records})
    summary = {
        "paper": "yan2010",
        "title": "Multi-feature D-S track-to-track association for passive TDOA systems "
                 "(Yan et al. 2010, paper 001)",
        "runs": runs, "seed": seed, "workers": workers,
        "methods": {m: {**METHODS.get(m, {}), "label": LABELS.get(m, m)} for m in methods},
        "parameters": parameters(options),
        "paper_values": {"table1": list(PAPER_TABLE1), "table1_n": list(TABLE1_N),
                         "claims": PAPER_CLAIMS},
        "records": records,
        **timed,
    }
    return write_report(out, summary, render_tables, make_figures, echo)
