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
