"""Reproduction of paper 002 (Lu et al. 2013): Fig. 1, Fig. 2 and Tables 1-4.

Experiments, one results store each (``OUT/lu2013-*.sqlite``):

``fig``     two targets at distance d (§4.1), d = 0:0.05:1.5, sigma = 1.5 and 5 mrad.
            All 4 feasible partitions are enumerated (as the paper does); per trial
            we record whether the best one is the truth, and the solution
            discrimination r (29) under two conventions (``r_data``: constants
            dropped; ``r_full``: the costs as printed).
``tables``  M = 5, 10, 15, 20 targets on a line, sigma = 1.5 and 5 mrad,
            d = 0.5, 1, 1.5 (Tables 1-4).  Each S-D problem is solved through
            :func:`assocopt.solve`: first its LP relaxation (HiGHS, the paper's
            LP_SOLVE method); when the LP optimum is integral it is a proven ILP
            optimum.  Otherwise (``ilp_strategy="lp-fixing"``, default) LP
            reduced-cost fixing leaves a few hundred candidates and the ILP on them
            is solved exactly with ``solver`` (:func:`solve_with_fixing`); with
            ``ilp_strategy="full"`` the full ILP is solved with ``solver``.  We
            record both correct rates, whether the LP was integral, whether
            rounding the LP (x > 0.5) would be infeasible or wrong, and the gap of
            the solution used.

``region``  ours: ref. [2] at M = 5, sigma = 1.5, d = 0.5 in the regions [0, L]^2 x
            [1, 10] km (how the correct rate depends on the unknown region).

Tables 1-4 run in every line geometry of ``line_directions`` (one store each).  Every
method of a trial costs the same simulated scan (paired comparison).  The report
(:mod:`.report`) is a pure function of ``summary.json``.
"""

from __future__ import annotations

from typing import Any, Mapping, Sequence

from ...tracking.costs.sd_builder import COSTS
from .._report import write_report
from ..runlog import run_and_collect
from .divergence import printed_kld_summary
from .experiment import (D_GRID, DEFAULTS, DISAGREEMENT_PAIRS, METHODS,  # noqa: F401
                         OURS_PARAMS, PAPER_FIG2_GAIN, PAPER_LABELS, PAPER_TABLES, PRINTED,
                         SIGMAS, TABLE_COLUMNS, TABLE_GRID, _cost_opts, _options, _problems,
                         _ratio, _scenario, _solve_metrics, experiments, fig_trial,
                         outcome_disagreements, parameters, table_experiment_name,
                         table_trial)
from .figures import make_figures  # noqa: F401
from .report import render_tables  # noqa: F401

__all__ = ["METHODS", "PAPER_TABLES", "PAPER_FIG2_GAIN", "DEFAULTS", "experiments",
           "fig_trial", "table_trial", "D_GRID", "TABLE_GRID", "run", "render_tables",
           "make_figures", "parameters", "outcome_disagreements"]


def run(runs: int, workers: int, seed: int, out, *, progress: bool = False,
        executor: Any = None, options: Mapping[str, Any] | None = None,
        parts: Sequence[str] = ("fig", "tables", "region"), echo=print) -> dict[str, Any]:
    """Run (or resume) the reproduction into ``out`` and write its report files
    (:func:`assocopt.reproduce.reproduce`; stores ``out/lu2013-*.sqlite``)."""
    from pathlib import Path

    from ...experiments import paired_differences
    from ...io.writers import jsonable

    def paired(store, exp) -> list:
        return [r for metric in ("tuple_rate", "partition_correct")
                for r in paired_differences(store, exp, metric, "pattipati")]

    def flag(exp, r: dict[str, Any]) -> bool:
        r["paired"] = " - " in r["metric"]
        return True

    out = Path(out)
    exps = experiments(runs, seed, options, parts)
    timed, records = run_and_collect(exps, out, ("sigma_mrad", "d", "M", "line_direction", "L"),
                                     runs=runs, workers=workers, seed=seed, options=options,
                                     executor=executor, progress=progress,
                                     extra_rows=paired, flag=flag)
    disagreements = []
    for exp in exps:
        if exp.params["experiment"] == "tables":
            store, ld = out / f"{exp.name}.sqlite", exp.settings[0]["line_direction"]
            for a, b in DISAGREEMENT_PAIRS:
                if {a, b} <= set(exp.methods):
                    disagreements.append({"line_direction": ld, "a": a, "b": b,
                                          **outcome_disagreements(store, exp, a, b)})
    summary = {
        "paper": "lu2013",
        "title": "Multi-passive-sensor data association with KL / symmetric KL costs "
                 "(Lu et al. 2013)",
        "runs": runs, "seed": seed, "workers": workers,
        "methods": {m: COSTS[m] for m in METHODS},
        "paper_labels": PAPER_LABELS,
        "parameters": parameters(options),
        "paper_values": {"tables": {str(M): {k: list(v) for k, v in t.items()}
                                    for M, t in PAPER_TABLES.items()},
                         "table_columns": [{"sigma_mrad": s, "d": d} for s, d in TABLE_COLUMNS],
                         "fig2_mean_gain_over_ref2": PAPER_FIG2_GAIN},
        "records": records,
        "derived": {"disagreements": disagreements,
                    "printed_kld": printed_kld_summary(
                        SIGMAS, region_km=_options(options)["region_km"])},
        **timed,
    }
    summary = jsonable(summary, nonfinite="null")        # as summary.json stores it
    return write_report(out, summary, render_tables, make_figures, echo)
