"""Reproduction of paper 004 (Dong et al. 2015): anti-bias track association by the
topology statistical distance, against the topology Euclidean distance and nearest
neighbour / 2-D assignment on the biased tracks.

Experiments (:mod:`.experiment`): ``main`` (environments 1-3: Figs. 2, 5-7 and the
time per step in place of the lost Table 1), ``coef`` (Figs. 3-4 with our substitute
for the lost threshold T_1) and ``timing`` (10 to 100 targets, the coarse pre-gate);
plus one step's assignments timed by the compiled loop and through ``assocopt.solve``.
The page is ``docs/papers/dong2015.md``.  Modules: :mod:`.experiment`, :mod:`.report`,
:mod:`.figures`.
"""

from __future__ import annotations

import os
import time
from pathlib import Path
from typing import Any, Mapping, Sequence

from ...experiments import report_records, run_all, summarise
from ...tracking.scenarios.dong2015_assoc import METHODS
from .._report import write_report
from .experiment import (DEFAULTS, LABELS, PAPER, _options, experiments, lap_paths,  # noqa: F401
                         parameters, trial)
from .figures import make_figures

#: Methods that are readings of the paper itself (the rest carry a change of ours).
PAPER_READINGS = ("tsd-rect", "tsd-rect-noself", "ted-rect", "ted-rect-noself", "nn", "gnn")
from .report import (lookup, render_comparison, render_headline,  # noqa: F401
                     render_parameters, render_tables)

__all__ = ["DEFAULTS", "PAPER", "LABELS", "METHODS", "experiments", "trial", "parameters",
           "run", "render_tables", "render_parameters", "render_headline", "render_comparison",
           "make_figures",
           "lap_paths"]


def run(runs: int, workers: int, seed: int, out, *, progress: bool = False,
        executor: Any = None, options: Mapping[str, Any] | None = None,
        parts: Sequence[str] = ("main", "coef", "timing"), echo=print,
        lap_sizes: Sequence[int] = (10, 30, 50)) -> dict[str, Any]:
    """Run (or resume) the reproduction into ``out`` and write its report files
    (``summary.json``, ``tables.md``, PNG figures, stores ``dong2015-*.sqlite``)."""
    out = Path(out)
    t0 = time.perf_counter()
    load0 = os.getloadavg()[0]
    o = _options(options)
    exps = experiments(runs, seed, options, parts)
    timing = run_all(exps, out, workers=workers, executor=executor, progress=progress)
    records: list[dict[str, Any]] = []
    for exp in exps:
        rows = summarise(out / f"{exp.name}.sqlite", exp, include_volatile=True)
        for r in report_records(rows, exp, ("part", "env", "coef", "n_targets")):
            if r["metric"].startswith("hd") and not (exp.params["experiment"] == "main"
                                                     and r["setting"]["env"] == 2):
                continue                        # heading errors: Fig. 2 is env 2
            r["method_is_ours"] = r["method"] not in PAPER_READINGS
            records.append(r)
    summary = {
        "paper": "dong2015",
        "title": "Anti-bias track association by topology statistical distance "
                 "(Dong et al. 2015)",
        "runs": runs, "coef_runs": max(1, runs // o["coef_divisor"]), "seed": seed,
        "workers": workers,
        "methods": {m: {**METHODS[m], "label": LABELS.get(m, m)}
                    for m in sorted({r["method"] for r in records})},
        "parameters": parameters(options),
        "paper_values": {"claims": PAPER["claims"], "lost": PAPER["lost"]},
        "records": records,
        "lap_paths": lap_paths(seed, lap_sizes) if lap_sizes else [],
        "timing": timing,
    }
    summary["load"] = {"start": load0, "end": os.getloadavg()[0]}
    summary["wall_s"] = time.perf_counter() - t0
    return write_report(out, summary, render_tables, make_figures, echo)
