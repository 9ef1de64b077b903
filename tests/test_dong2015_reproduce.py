"""Paper 004's reproduction: a small run writes its summary and figures and resumes,
options are checked, and the page shows exactly what the committed summary gives."""

from __future__ import annotations

import json
import re
from pathlib import Path

import pytest

from conftest import check_page_against_summary

ROOT = Path(__file__).resolve().parents[1]
SMALL = {"n_targets": 10, "missed": 2, "false_tracks": 2, "n_steps": 3,
         "timing_n": (6,), "timing_steps": 2, "timing_runs": 1, "coef_grid": (0.0, 20.0),
         "coef_divisor": 1, "main_methods": ("tsd-rect", "tsd-rect-noself", "tsd-rect-global", "tsd-rect-c",
                          "tsd", "tsd-c", "ted", "gnn"),
         "coef_methods": ("tsd-t1", "tsd-rect-t1"), "timing_methods": ("tsd-c", "tsd-c-pregate")}


def test_reproduction_writes_summary_figures_and_resumes(tmp_path):
    from assocopt.reproduce import dong2015 as repro
    printed = []
    s = repro.run(2, 1, 3, tmp_path, options=SMALL, echo=printed.append, lap_sizes=(6,))
    data = json.loads((tmp_path / "summary.json").read_text())
    assert data["paper"] == "dong2015" and data["runs"] == 2
    assert {r["experiment"] for r in data["records"]} == {"main", "coef", "timing"}
    assert {r["setting"]["env"] for r in data["records"] if r["experiment"] == "main"} == {1, 2, 3}
    assert all(r["runs"] == 2 for r in data["records"]
               if r["experiment"] == "main" and r["metric"] == "ec_k01")
    assert data["lap_paths"][0]["agree"] is True
    assert "Environment 3 (Fig. 7)" in printed[0] and "Threshold coefficient" in printed[0]
    for f in s["figures"]:
        assert (tmp_path / f).stat().st_size > 0
    again = repro.run(2, 1, 3, tmp_path, options=SMALL, echo=lambda t: None, lap_sizes=())
    assert all(v["done"] == 0 for v in again["timing"].values())
    stable = lambda recs: sorted((json.dumps(r["setting"], sort_keys=True), r["method"],
                                  r["metric"], r["value"]) for r in recs if not r["volatile"])
    assert stable(again["records"]) == stable(s["records"])


def test_reproduction_rejects_unknown_options_and_methods():
    from assocopt.reproduce import dong2015 as repro
    with pytest.raises(ValueError, match="unknown dong2015 option"):
        repro.experiments(2, 0, {"bogus": 1})
    with pytest.raises(ValueError, match="unknown dong2015 method"):
        repro.experiments(2, 0, {"main_methods": ("fuzzy",)})


def test_registered_as_a_paper():
    from assocopt.reproduce import PAPERS
    assert PAPERS["dong2015"].default_runs == 50 and PAPERS["dong2015"].spec == "004"


# ------------------------------------------------------------- the page
PAGE = ROOT / "docs" / "papers" / "dong2015.md"
SUMMARY = ROOT / "docs" / "papers" / "dong2015" / "summary.json"


def test_page_tables_match_the_committed_summary():
    from assocopt.reproduce import dong2015 as repro
    summary = check_page_against_summary(repro, "dong2015", PAGE, SUMMARY)
    assert summary["seed"] == 0
    stated = re.search(r"\*\*(\d+) runs\s+x\s+(\d+) steps\*\*", PAGE.read_text(encoding="utf-8"))
    assert stated and int(stated.group(1)) == summary["runs"]
    assert int(stated.group(2)) == summary["parameters"]["ours"]["scenario"]["n_steps"]
    labels = {r["method"] for r in summary["records"] if r["experiment"] == "main"}
    assert {"tsd-rect", "tsd-rect-noself", "tsd", "tsd-rect-obj", "tsd-rect-refcov",
            "tsd-rect-inflate"} <= labels
    assert all(r["agree"] for r in summary["lap_paths"] if "agree" in r)
    tables = (SUMMARY.parent / "tables.md").read_text(encoding="utf-8")
    assert tables == repro.render_tables(summary)



def _val(summary, part, metric, method, env=2, coef=None) -> float:
    from assocopt.reproduce.dong2015 import lookup
    return next(v[0] for k, v in lookup(summary["records"], part, metric).items()
                if k[0] == method and k[1] == env and (coef is None or k[2] == coef))


def _ec3(summary, method, step=12) -> str:
    """E_c at ``step`` in environments 1 / 2 / 3, as the page's prose writes it."""
    return " / ".join(f"{_val(summary, 'main', f'ec_k{step:02d}', method, e):.2f}"
                      for e in (1, 2, 3))


def _prose_fragments(summary) -> list[str]:
    """What the prose says about the two comparisons run on both readings (global trial
    pairs; the T_1 stand-in), the coefficient sweep and the time per step."""
    m = lambda metric, meth, env=2: f"{_val(summary, 'main', metric, meth, env):.2f}"
    c = lambda meth, coef, k: f"{_val(summary, 'coef', f'ec_k{k:02d}', meth, 2, coef):.2f}"
    span = lambda meth: "–".join(f"{f(_val(summary, 'coef', 'ec_k12', meth, 2, x) for x in grid):.2f}"
                                 for f in (min, max))
    grid = summary["parameters"]["ours"]["coef_grid"]
    hi = max(grid)
    r = next(r for r in summary["lap_paths"] if r["n_targets"] == 30)
    from assocopt.reproduce.dong2015 import lookup
    g = lambda n: next(v[0] for k, v in lookup(summary["records"], "timing", "t_step_ms").items()
                       if k[0] == "tsd-rect" and k[3] == n)
    keep = [v[0] for k, v in lookup(summary["records"], "timing", "pairs_frac").items()
            if k[0] == "tsd-c-pregate"]
    return [
        f"global trial pairs on the paper's reading: {_ec3(summary, 'tsd-rect-global')} with "
        f"the self pair in, {_ec3(summary, 'tsd-rect-noself-global')} with the neighbour "
        f"pairs only, against {_ec3(summary, 'tsd-rect')} and "
        f"{_ec3(summary, 'tsd-rect-noself')} row-wise",
        f"t_1 stand-in on the paper's reading: {_ec3(summary, 'tsd-rect-t1')} with the self "
        f"pair in, {_ec3(summary, 'tsd-rect-noself-t1')} with the neighbour pairs only",
        f"global trial pairs on the dummy reading: {_ec3(summary, 'tsd-global')}",
        f"t_1 stand-in on the dummy reading: {_ec3(summary, 'tsd-t1')}",
        f"environment 1 ends at {m('ec_k12', 'tsd-rect-global', 1)} (self pair in) and "
        f"{m('ec_k12', 'tsd-rect-noself-global', 1)} (neighbour pairs only)",
        f"the trial partner is the true one for {m('tr0_k12', 'tsd-rect-global', 1)} of the "
        f"tracks at step 12 (row-wise {m('tr0_k12', 'tsd-rect', 1)}) and the wrong pairs "
        f"fall from {m('fp_k12', 'tsd-rect', 1)} to {m('fp_k12', 'tsd-rect-global', 1)}",
        f"environment 2 rises from {m('ec_k12', 'tsd-rect')} to {m('ec_k12', 'tsd-rect-global')}"
        f" (wrong pairs {m('fp_k12', 'tsd-rect')} to {m('fp_k12', 'tsd-rect-global')}), "
        f"environment 3, with its 10 non-common tracks per radar, only from "
        f"{m('ec_k12', 'tsd-rect', 3)} to {m('ec_k12', 'tsd-rect-global', 3)}",
        f"2 rises from {m('ec_k01', 'tsd-rect')} to {m('ec_k01', 'tsd-rect-t1')} with the self "
        f"pair in and from {m('ec_k01', 'tsd-rect-noself')} to "
        f"{m('ec_k01', 'tsd-rect-noself-t1')} with the neighbour pairs only",
        f"first step (environment 2: {m('ec_k01', 'tsd-t1')})",
        f"step 1 goes from {c('tsd-rect-t1', 0.0, 1)} at coefficient 0 to "
        f"{c('tsd-rect-t1', hi, 1)} at {hi:g} and step 4 from {c('tsd-rect-t1', 0.0, 4)} to "
        f"{c('tsd-rect-t1', hi, 4)}, and at step 12 every coefficient gives "
        f"{span('tsd-rect-t1')}",
        f"step 1 goes from {c('tsd-rect-noself-t1', 0.0, 1)} to {c('tsd-rect-noself-t1', hi, 1)}"
        f" and step 12 is {span('tsd-rect-noself-t1')}",
        f"{r['paper_plain_mean_cpu_ms']:.1f} ms of cpu per step before, "
        f"{r['paper_mean_cpu_ms']:.1f} ms after (wall {r['paper_plain_mean_ms']:.1f} and "
        f"{r['paper_mean_ms']:.1f} ms)",
        f"{r['paper_noself_plain_mean_cpu_ms']:.1f} and {r['paper_noself_mean_cpu_ms']:.1f} ms "
        f"of cpu (wall {r['paper_noself_plain_mean_ms']:.1f} and "
        f"{r['paper_noself_mean_ms']:.1f} ms)",
        f"load average {r['load']:.1f} at the start and {r['load_end']:.1f} at the end, on the",
        f"takes {g(10):.0f} ms per step at 10 targets and {g(50) / 1e3:.1f} s at 50, "
        f"{g(50) / g(10):.0f} times as long",
        f"keeps {min(keep):.2f}–{max(keep):.2f} of the reference pairs",
        f"{summary['wall_s']:.0f} s.",
    ]


def test_page_prose_quotes_the_committed_run():
    """Every number the prose gives for the two comparisons run on both readings, the
    coefficient sweep on the paper's reading and the time per step is the committed
    run's, and the comparison block is what ``render_comparison`` gives."""
    from assocopt.reproduce import dong2015 as repro
    from conftest import page_block
    summary = json.loads(SUMMARY.read_text())
    raw = PAGE.read_text(encoding="utf-8")
    assert page_block(raw, "comparison") == repro.render_comparison(summary).strip()
    text = " ".join(raw.split()).lower()
    for frag in _prose_fragments(summary):
        assert frag.lower() in text, frag
