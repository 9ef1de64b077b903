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

from ...experiments import report_records, summarise
from ..runlog import run_timed
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
    """Run (or resume) the reproduction into ``out`` and write its report files.

    Writes ``out/summary.json``, ``out/tables.md``, PNG figures (when matplotlib is
    installed) and the stores ``out/yan2010-*.sqlite``; prints the tables with
    ``echo``.  ``summary.json`` keeps, under ``timing_history``, the wall time of every
    invocation into ``out`` that computed trials.  Returns the summary dict.
    """
    out = Path(out)
    exps = experiments(runs, seed, options, parts)
    timed = run_timed(exps, out, runs=runs, workers=workers, seed=seed, options=options,
                      executor=executor, progress=progress)
    records: list[dict[str, Any]] = []
    for exp in exps:
        rows = summarise(out / f"{exp.name}.sqlite", exp, include_volatile=True)
        for r in report_records(rows, exp, ("n", "variant", "features", "coverage")):
            if exp.params["experiment"] in ("grid", "confirm") and not _kept(r["metric"]):
                continue                    # in the stores, not in summary.json
            r["method_is_ours"] = r["method"] not in PAPER_METHODS
            records.append(r)
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
