"""Paper 001 end to end: the three-node S-D model, a pinned seeded run, the reproduction
(summary, resume, registry) and the page's tables against the committed summary.json."""

from __future__ import annotations

import json
import re
from pathlib import Path

import numpy as np
import pytest

from assocopt import solve
from assocopt.runtime.errors import AssocoptError
from assocopt.reproduce import PAPERS, list_papers, reproduce
from assocopt.tracking.decide.max_degree import assignment_rule
from assocopt.tracking.decide.multi_node import three_node_decision, three_node_problem

ROOT = Path(__file__).resolve().parents[1]
PAGE = ROOT / "docs" / "papers" / "yan2010.md"
COMMITTED = ROOT / "docs" / "papers" / "yan2010" / "summary.json"


# ------------------------------------------------------------------ three nodes
def test_three_node_model_against_brute_force():
    rng = np.random.default_rng(4)
    for _ in range(5):
        m = [rng.uniform(0, 1, size=(3, 3)) for _ in range(3)]
        prob = three_node_problem(*m, eps=0.5)
        a, b = solve(prob, solver="bruteforce"), solve(prob, solver="highs")
        assert a.objective == pytest.approx(b.objective)
        tup = three_node_decision(*m, eps=0.5, solver="highs")
        for ax in range(3):
            used = tup[:, ax][tup[:, ax] >= 0]
            assert len(set(used.tolist())) == len(used)         # one-to-one on every node


def test_three_node_model_reduces_to_the_2d_rule_without_a_third_node():
    rng = np.random.default_rng(5)
    m12 = rng.uniform(0, 1, size=(4, 5))
    none13, none23 = np.zeros((4, 2)), np.zeros((5, 2))
    tup = three_node_decision(m12, none13, none23, 0.5, solver="highs")
    assert tup[:, 1].tolist() == assignment_rule(m12, 0.5).tolist()
    assert np.all(tup[:, 2] == -1)
    with pytest.raises(ValueError, match="degree matrices"):
        three_node_problem(m12, none13, np.zeros((4, 2)), 0.5)


# ------------------------------------------------------------------ pinned run
def test_pinned_small_seeded_run():
    from assocopt.reproduce.yan2010.experiment import DEFAULTS, _common, trial
    common = _common({**DEFAULTS, "q_filter": 1.0, "duration": 30.0})
    r = trial({"part": "pin", "n": 12, **common},
              ["ds-max", "ds-assign", "weighted", "ds-max-nocounter"], np.random.SeedSequence(2024))
    assert r["ds-max"]["correct_mean"] == pytest.approx(359 / 360)
    assert r["ds-max"]["shared_steps"] == pytest.approx(1 / 30)      # one scan shared a track
    assert r["ds-assign"]["shared_steps"] == 0.0
    assert r["ds-assign"]["correct_mean"] == pytest.approx(359 / 360)
    assert r["weighted"]["correct_mean"] == pytest.approx(355 / 360)
    assert r["ds-max"]["fixed_final"] == 1.0 and r["weighted"]["fixed_final"] == 0.0
    assert r["ds-max-nocounter"]["fixed_final"] == 0.0


# ------------------------------------------------------------------ reproduction
def test_registry_and_option_errors():
    assert "yan2010" in [p["name"] for p in list_papers()]
    assert PAPERS["yan2010"].page == "docs/papers/yan2010.md"
    with pytest.raises(AssocoptError, match="unknown yan2010 option"):
        reproduce("yan2010", runs=1, out="x", options={"epss": 0.5})
    with pytest.raises(AssocoptError, match="tracker"):
        reproduce("yan2010", runs=1, out="x", options={"tracker": "imm"})


def test_reproduction_writes_summary_tables_and_resumes(tmp_path):
    from assocopt.reproduce import yan2010 as repro
    opts = {"fig4_n": 6, "sensitivity_n": 6, "three_node_n": (5,), "grid_n": (6,),
            "three_node_coverage": (0.2,), "three_node_features": ("per-emitter",)}
    parts = ("fig4", "sensitivity", "grid", "three_node")
    printed = []
    s = repro.run(2, 1, 3, tmp_path, options=opts, parts=parts, echo=printed.append)
    data = json.loads((tmp_path / "summary.json").read_text())
    assert data["paper"] == "yan2010" and data["runs"] == 2
    assert data["paper_values"]["table1"][0] == 0.9980
    assert "emitter_types" in data["parameters"]["ours"]["scenario_ours"]
    assert data["parameters"]["ours"]["tolerances_f_pw_pri"][0] == pytest.approx(
        2 * np.hypot(2.0, 3.0))
    exps = {r["experiment"] for r in data["records"]}
    assert exps == {"fig4", "sensitivity", "grid", "three_node"}
    assert {r["runs"] for r in data["records"] if r["metric"] == "correct_20"} == {2}
    assert "Fig. 4" in printed[0] and "Three nodes" in printed[0]
    for name in ("grid-rule", "grid-rule-k1", "grid-closest", "grid-versus", "grid-shared",
                 "features-matter", "three-node"):
        assert f"<!-- section: {name} -->" in printed[0], name
    grid = [r for r in data["records"] if r["experiment"] == "grid"]
    assert {r["setting"]["variant"] for r in grid} == {
        "types10, 0 % single", "types10, 10 % single", "types10, 20 % single",
        "per-emitter, 0 % single", "per-emitter, 10 % single", "per-emitter, 20 % single",
        "one-type, 0 % single"}
    assert {r["metric"] for r in grid if r["method"] == "ds-assign"} >= {"dall_80", "all_5"}
    for f in s["figures"]:
        assert (tmp_path / f).stat().st_size > 0
    again = repro.run(2, 1, 3, tmp_path, options=opts, parts=parts, echo=lambda t: None)
    assert all(v["done"] == 0 for v in again["timing"].values())
    key = lambda r: (r["experiment"], json.dumps(r["setting"], sort_keys=True),  # noqa: E731
                     r["method"], r["metric"])
    stable = lambda recs: sorted((key(r), r["value"]) for r in recs if not r["volatile"])  # noqa
    assert stable(again["records"]) == stable(s["records"])


# ------------------------------------------------------------------ the page
def _page_table_rows(text: str) -> list[str]:
    return [ln.strip() for ln in text.splitlines()
            if ln.startswith("|") and not re.match(r"^\|(\s*-+\s*\|)+$", ln.strip().replace("---", "-"))]


@pytest.mark.skipif(not COMMITTED.is_file(), reason="no committed yan2010 summary")
def test_every_table_on_the_page_comes_from_the_committed_summary():
    from assocopt.reproduce.yan2010 import PAPER_TABLE1, render_tables
    summary = json.loads(COMMITTED.read_text())
    generated = set(_page_table_rows(render_tables(summary)))
    page = PAGE.read_text(encoding="utf-8")
    rows = _page_table_rows(page)
    tol = next(r for r in rows if r.startswith("| tolerances |"))
    f, pw, pri = summary["parameters"]["ours"]["tolerances_f_pw_pri"]
    assert f"{f:.2f} MHz, {pw:.4f} µs, {pri:.4f} µs" in tol
    numeric = [r for r in rows if re.search(r"\d\.\d{4}", r) and r is not tol]
    assert len(numeric) >= 20, "the page shows the reproduction's tables"
    missing = [r for r in numeric if r not in generated]
    assert not missing, "page rows not produced from summary.json:\n" + "\n".join(missing[:10])
    paper_row = "| paper | " + " | ".join(f"{v:.4f}" for v in PAPER_TABLE1) + " |"
    assert paper_row in rows and "0.9428" in paper_row
    assert (ROOT / "docs" / "papers" / "yan2010" / "tables.md").read_text().strip() == \
        render_tables(summary).strip()


@pytest.mark.skipif(not COMMITTED.is_file(), reason="no committed yan2010 summary")
def test_the_page_states_the_run_behind_it():
    summary = json.loads(COMMITTED.read_text())
    page = PAGE.read_text(encoding="utf-8")
    assert f"**{summary['runs']} runs per point**" in page
    grid_runs = summary["parameters"]["ours"]["grid"]["runs"] or summary["runs"]
    assert f"**{grid_runs} runs per point**" in page
    assert "<!-- BEGIN GENERATED timing -->" in page
    done = {name for h in summary["timing_history"] for name, t in h["experiments"].items()
            if t["done"]}
    assert done <= {f"yan2010-{p}" for p in ("table1", "fig4", "sensitivity", "grid",
                                             "confirm", "three_node")}
    assert {t["trials"] for t in summary["trial_seconds"].values()} and all(
        t["trials"] > 0 for t in summary["trial_seconds"].values())
