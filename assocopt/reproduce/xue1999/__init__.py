"""Reproduction of paper 003 (Xue et al. 1999): DID against GNN and nearest neighbour.

The paper shows four crossing targets (Figs. 2-3) and claims correct associations
despite many crossings and strong noise; it gives no parameter and no number.  Three
experiments, each with its own store ``OUT/xue1999-*.sqlite``, run in this order:

``tune``   the base scene on seeds apart from the reported ones, ``runs //
           tune_divisor`` runs: every method of ``tune_methods`` at every (B, M') of
           ``tune_B`` x ``tune_M_prime``; the best pair of each by correct rate
           (:func:`.experiment.best_pairs`) joins the two other parts.
``main``   the base scene (noise scale 1, clutter mean ``clutter_mean``): every method
           of :data:`~assocopt.tracking.scenarios.xue1999_tracker.METHODS` and the
           tuned ones; per-scan correct association rate, decision precision, track
           swaps, false tracks, targets held at the end, DID's stage-2,
           non-convergence and conflict rates.
``sweep``  noise scale x clutter mean grid (``noise_grid`` x ``clutter_grid``) with
           ``sweep_methods`` and their tuned versions, ``runs // sweep_divisor`` runs
           per point.

Every method of a trial tracks the same simulated run (paired comparison).  All
parameters are ours and recorded in ``summary.json``; the page is
``docs/papers/xue1999.md``.  Modules: :mod:`.experiment` (options, trial, grid),
:mod:`.report` (tables), :mod:`.figures`.
"""

from __future__ import annotations

import time
from pathlib import Path
from typing import Any, Mapping, Sequence

from ...experiments import report_records, run_all, summarise
from ...tracking.scenarios.xue1999_tracker import METHODS
from .._report import write_report
from ...tracking.scenarios.xue1999_tracker import method_options, split_method
from .experiment import (DEFAULTS, LABELS, PAPER_CLAIMS, _options, _scenario,  # noqa: F401
                         _tracker, best_pairs, experiments, label, parameters, trial)
from .figures import make_figures
from .report import (lookup, render_example, render_headline,  # noqa: F401
                     render_parameters, render_run, render_tables)

__all__ = ["DEFAULTS", "PAPER_CLAIMS", "LABELS", "METHODS", "experiments", "trial",
           "parameters", "run", "render_tables", "render_parameters", "render_headline",
           "render_run", "render_example", "make_figures", "label", "best_pairs"]

_PARTS = ("tune", "main", "sweep")


def run(runs: int, workers: int, seed: int, out, *, progress: bool = False,
        executor: Any = None, options: Mapping[str, Any] | None = None,
        parts: Sequence[str] = _PARTS, echo=print) -> dict[str, Any]:
    """Run (or resume) the reproduction into ``out`` and write its report files.

    Writes ``out/summary.json``, ``out/tables.md``, PNG figures (with matplotlib) and
    the stores ``out/xue1999-*.sqlite``; prints the tables with ``echo``.  The tuning
    part runs first: its best pairs join ``main`` and ``sweep``.
    """
    out = Path(out)
    t0 = time.perf_counter()
    records: list[dict[str, Any]] = []
    timing: dict[str, Any] = {}
    tuned: dict[str, Any] = {}
    for part in (p for p in _PARTS if p in parts):
        names = {m: v["method"] for m, v in tuned.items()}
        exps = experiments(runs, seed, options, (part,), tuned=names)
        timing.update(run_all(exps, out, workers=workers, executor=executor,
                              progress=progress))
        for exp in exps:
            rows = summarise(out / f"{exp.name}.sqlite", exp, include_volatile=True)
            for r in report_records(rows, exp, ("part", "noise_scale", "clutter_mean")):
                if part != "main" and r["metric"].startswith("car_k"):
                    continue                    # per-scan curves: base scene only
                r["method_is_ours"] = True
                records.append(r)
        if part == "tune":
            tuned = best_pairs(records, options)
    o = _options(options)
    summary = {
        "paper": "xue1999",
        "title": "Target data association by distributed inference decision (Xue et al. 1999)",
        "runs": runs, "sweep_runs": max(1, runs // o["sweep_divisor"]),
        "tune_runs": max(1, runs // o["tune_divisor"]), "seed": seed,
        "workers": workers,
        "methods": {m: {**method_options(m), **split_method(m)[1], "label": label(m)}
                    for m in sorted({r["method"] for r in records})},
        "tuned": tuned,
        "parameters": parameters(options),
        "paper_values": {"claims": PAPER_CLAIMS},
        "records": records,
        "timing": timing,
    }
    summary["wall_s"] = time.perf_counter() - t0
    return write_report(out, summary, render_tables,
                        lambda s, d: make_figures(s, d, o), echo)
