"""Reproduction of paper 000 (Zhang et al. 2009): Figs. 1-5 and Table 1.

Four experiments, each with its own results store ``OUT/zhang2009-*.sqlite``:

``main``         P_c versus the noise factor f (P_d fixed) and versus P_d (f fixed)
                 for MM-TBM and MM-NCR decided by truncation (Experiment 1a, Figs.
                 1-2) and for MM-NCR decided by truncation (MD-ND), by our gated 2-D
                 assignment (MD-2DA) and by the plain rectangular assignment (tau = 0)
                 (Experiment 2, Figs. 4-5).  r_p = 1, r_a = 0.6 (the paper's values
                 for 1a; not given for 2, presumably the same).
``weights``      MM-WA versus MM-NCR over k = 1..10 with the paper's w and r
                 matrices, truncation decision (Experiment 1b, Fig. 3).
``table1``       decision time versus P_d: MD-ND, MD-2DA solved by the default back
                 end (``auto``, which picks scipy's linear_sum_assignment for these
                 2-D problems) and by HiGHS (ILP).
``sensitivity``  ours: MD-2DA's gate level alpha, tau = 0, and the alternative
                 readings of truncation (dendrogram ordering, same-sensor
                 pi = 0) at three noise levels.

Every method of a trial decides on the same simulated run (paired comparison).
The metric is :func:`~assocopt.tracking.belief.group_matching.correct_match_rate` (P_c: correct relations / true relations per run, averaged)
and ``all_correct`` (the run's relations entirely right); timings are volatile
metrics (seconds per decision, the matching measures excluded).
"""

from __future__ import annotations

from pathlib import Path
from typing import Any, Mapping, Sequence

from ...io.writers import jsonable
from .._report import write_report
from ..runlog import run_and_collect
from .experiment import (DEFAULTS, LABELS, MAIN_METHODS, METHODS, PAIRS,  # noqa: F401
                         PAPER_CLAIMS, PAPER_METHODS, PAPER_TABLE1, R, TABLE1_METHODS,
                         TABLE1_PD, VOLATILE, W, _measure_params, _options, experiments,
                         paired_differences, parameters, trial)
from .report import make_figures, render_tables  # noqa: F401

__all__ = ["W", "R", "PAPER_TABLE1", "PAPER_CLAIMS", "DEFAULTS", "METHODS", "experiments",
           "trial", "parameters", "run", "render_tables", "make_figures"]


def run(runs: int, workers: int, seed: int, out, *, progress: bool = False,
        executor: Any = None, options: Mapping[str, Any] | None = None,
        parts: Sequence[str] = ("main", "weights", "table1", "sensitivity"),
        echo=print) -> dict[str, Any]:
    """Run (or resume) the reproduction into ``out`` and write its report files
    (:func:`assocopt.reproduce.reproduce`; stores ``out/zhang2009-*.sqlite``)."""
    def flag(exp, r: dict[str, Any]) -> bool:
        r["method_is_ours"] = r["method"] not in PAPER_METHODS
        return True

    out = Path(out)
    exps = experiments(runs, seed, options, parts)
    timed, records = run_and_collect(exps, out, ("sweep", "f", "p_d", "k"), runs=runs,
                                     workers=workers, seed=seed, options=options,
                                     executor=executor, progress=progress, flag=flag)
    paired = []
    for exp in exps:
        paired += paired_differences(out / f"{exp.name}.sqlite", exp)
    summary = {
        "paper": "zhang2009",
        "title": "Group member matching with position + attribute belief functions "
                 "(Zhang et al. 2009)",
        "runs": runs, "seed": seed, "workers": workers,
        "methods": {m: {"measure": METHODS[m][0], "decision": METHODS[m][1],
                        "options": METHODS[m][2], "label": LABELS.get(m, m)}
                    for m in sorted({r["method"] for r in records})},
        "parameters": parameters(options),
        "paper_values": {"table1": {k: list(v) for k, v in PAPER_TABLE1.items()},
                         "table1_p_d": list(TABLE1_PD), "claims": PAPER_CLAIMS},
        "records": records,
        "paired": paired,
        **timed,
    }
    summary = jsonable(summary, nonfinite="null")        # as summary.json stores it
    return write_report(out, summary, render_tables, make_figures, echo)
