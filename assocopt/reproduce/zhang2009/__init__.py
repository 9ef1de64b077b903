"""Reproduction of paper 000 (Zhang et al. 2009): Figs. 1-5 and Table 1.

Five experiments (:data:`PARTS`), each with its own results store ``OUT/zhang2009-*.sqlite``:

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
``table1-enum``  the same by the brute-force enumeration (``enum_runs`` runs per P_d).
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
                         PARTS, PAPER_CLAIMS, PAPER_METHODS, PAPER_TABLE1, R, TABLE1_METHODS,
                         TABLE1_PD, VOLATILE, W, _measure_params, _options, experiments,
                         paired_differences, parameters, trial)
from .report import make_figures, render_tables  # noqa: F401

__all__ = ["W", "R", "PAPER_TABLE1", "PAPER_CLAIMS", "DEFAULTS", "METHODS", "experiments",
           "trial", "parameters", "run", "render_tables", "make_figures"]


def run(runs: int, workers: int, seed: int, out, *, progress: bool = False,
        executor: Any = None, options: Mapping[str, Any] | None = None,
        parts: Sequence[str] = PARTS, echo=print) -> dict[str, Any]:
    """Run (or resume) the reproduction into ``out`` and write its report files
    (:func:`assocopt.reproduce.reproduce`; stores ``out/zhang2009-*.sqlite``).

    ``parts`` (a subset of :data:`PARTS`) runs only those parts.  When ``out`` holds a
    ``summary.json``, the records of the other parts are kept from it (so a part whose
    code did not change need not be recomputed when another one did); it must then
    come from a run with the same run count, seed and parameters."""
    def flag(exp, r: dict[str, Any]) -> bool:
        r["method_is_ours"] = r["method"] not in PAPER_METHODS
        return True

    out = Path(out)
    kept = [p for p in PARTS if p not in parts]
    previous = (_previous(out / "summary.json", runs, seed, options)
                if kept and (out / "summary.json").exists() else None)
    exps = experiments(runs, seed, options, parts)
    timed, records = run_and_collect(exps, out, ("sweep", "f", "p_d", "k"), runs=runs,
                                     workers=workers, seed=seed, options=options,
                                     executor=executor, progress=progress, flag=flag)
    paired = []
    for exp in exps:
        paired += paired_differences(out / f"{exp.name}.sqlite", exp)
    if previous is not None:
        records = _in_part_order([r for r in previous["records"] if r["experiment"] in kept]
                                 + records)
        paired = _in_part_order([r for r in previous["paired"] if r["experiment"] in kept]
                                + paired)
        seconds = {**previous.get("trial_seconds", {}), **timed["trial_seconds"]}
        timed["trial_seconds"] = {f"zhang2009-{p}": seconds[f"zhang2009-{p}"]
                                  for p in PARTS if f"zhang2009-{p}" in seconds}
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
    if previous is not None:
        summary["kept_parts"] = kept
    summary = jsonable(summary, nonfinite="null")        # as summary.json stores it
    return write_report(out, summary, render_tables, make_figures, echo)


def _previous(path: Path, runs: int, seed: int,
              options: Mapping[str, Any] | None) -> dict[str, Any]:
    """The summary whose parts a partial run keeps; an error unless it was written with
    the same run count, seed and parameters."""
    import json
    try:
        prev = json.loads(path.read_text())
    except (OSError, ValueError) as exc:
        raise ValueError(f"a run of only some parts keeps the others from {path}, which "
                         f"cannot be read ({exc}); run every part") from None
    want = jsonable(parameters(options), nonfinite="null")
    if prev.get("runs") != runs or prev.get("seed") != seed or prev.get("parameters") != want:
        raise ValueError(f"{path} was written with other runs, seed or parameters "
                         f"(runs {prev.get('runs')}, seed {prev.get('seed')}); a run of "
                         "only some parts cannot keep its other parts")
    return prev


def _in_part_order(records: list[dict[str, Any]]) -> list[dict[str, Any]]:
    """``records`` ordered by part (:data:`PARTS`), in their order within a part."""
    rank = {p: i for i, p in enumerate(PARTS)}
    return sorted(records, key=lambda r: rank[r["experiment"]])
