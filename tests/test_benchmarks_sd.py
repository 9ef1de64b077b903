"""docs/benchmarks-sd.md (and its figure) is what benchmarks/sd_page.py draws from the
committed docs/benchmarks-sd.json, and its numbers hold together: every proven
objective is the recorded optimum, totals are sums of the instance times, ratios are
ratios of the totals shown; README.md's S-D figures are the ones in the JSON."""

from __future__ import annotations

import json
import math
import re

import numpy as np
import pytest

from conftest import ROOT, agrees, load_script

JSON = ROOT / "docs" / "benchmarks-sd.json"
PAGE = ROOT / "docs" / "benchmarks-sd.md"
PNG = ROOT / "docs" / "benchmarks-sd.png"


def _page_mod():
    return load_script("benchmarks/sd_page.py", "bench_sd_page")


def _scaling_mod():
    """benchmarks/sd_scaling.py as a module (registered: its dataclasses need that)."""
    return load_script("benchmarks/sd_scaling.py", "bench_sd_scaling", register=True)


def _data() -> dict:
    return json.loads(JSON.read_text())


def test_page_matches_the_committed_json():
    assert _page_mod().render(dict(_data(), figure=PNG.name)) == PAGE.read_text()
    assert f"]({PNG.name})" in PAGE.read_text()


def test_json_records_the_environment_and_the_command():
    data = _data()
    env = data["environment"]
    assert env["command"].startswith("python benchmarks/sd_scaling.py")
    assert len(env["load_start"]) == len(env["load_end"]) == 3
    assert env["minutes"] > 0 and re.fullmatch(r"\d{4}-\d\d-\d\d", env["date"])
    assert data["options"]["reference_all"] == ("--reference-all" in env["command"])


def test_every_proven_objective_is_the_recorded_optimum():
    rows = _data()["exact"]
    assert rows
    for row in rows:
        ref = row["optimum"] if row["optimum"] is not None else row["reference"]
        for name, r in row["results"].items():
            if r["status"] == "optimal":
                assert ref is not None and agrees(r["objective"], ref), (row["name"], name)
            assert r["info"]["correct"] == (r["status"] != "optimal" or ref is None
                                            or agrees(r["objective"], ref))


def test_our_exact_methods_prove_every_instance():
    for row in _data()["exact"]:
        for name in ("auto", "lagrangian-exact"):
            r = row["results"][name]
            assert r["status"] == "optimal" and r["info"]["correct"], (row["name"], name)


def _table(page: str, header_start: str) -> list[list[str]]:
    lines = page.splitlines()
    i = next(k for k, ln in enumerate(lines) if ln.startswith(header_start))
    out = []
    for ln in lines[i + 2:]:
        if not ln.startswith("|"):
            break
        out.append([c.strip() for c in ln.strip("|").split("|")])
    return out


def test_family_totals_are_sums_of_the_instance_times():
    data = _data()
    solvers = data["options"]["solvers"]
    rows = _table(PAGE.read_text(), "| family | n | instances |")
    assert len(rows) == len({(r["family"], r["size"]) for r in data["exact"]})
    for fam, n, count, *cells in rows:
        items = [r for r in data["exact"] if r["family"] == fam and r["size"] == int(n)]
        assert len(items) == int(count)
        for s, cell in zip(solvers, cells):
            rs = [r["results"][s] for r in items if s in r["results"]]
            if not rs:
                assert cell == "-"
                continue
            total = float(cell.split()[0])
            assert abs(total - sum(r["time"] for r in rs)) <= 5e-4, (fam, n, s)
            proven = sum(r["status"] == "optimal" for r in rs)
            assert f"({proven}/{len(rs)})" in cell


def _fits(t: float, b: float, shown: float, dt: float = 5e-3, dr: float = 5e-5) -> bool:
    """Can ``shown`` (4 decimals) be t_true / b_true for totals that round to t, b?"""
    lo = max(t - dt, 0.0) / (b + dt)
    hi = math.inf if b <= dt else (t + dt) / (b - dt)
    return lo - dr <= shown <= hi + dr


def test_ratios_are_the_ratios_of_the_totals_shown():
    page = PAGE.read_text()
    checked = 0
    for block in page.split("| method | instances | method total s | scipy total s |")[1:]:
        for ln in block.splitlines()[2:]:
            if not ln.startswith("|"):
                break
            _, _, t, b, ratio, *_ = [c.strip() for c in ln.strip("|").split("|")]
            r, inv = re.fullmatch(r"([0-9.]+) \(1/([0-9.]+)\)", ratio).groups()
            assert _fits(float(t), float(b), float(r)), ln
            assert _fits(float(b), float(t), float(inv), dr=0.05) or float(t) < 5e-3, ln
            checked += 1
    assert checked >= 2


def test_latency_medians_are_those_of_the_recorded_times():
    for g in _data()["latency"]:
        for name, v in g["results"].items():
            assert v["count"] == len(v["times_s"])
            assert v["median_s"] == pytest.approx(float(np.median(v["times_s"])))
            assert v["max_s"] == max(v["times_s"])
            assert 0 <= v["optimal"] <= v["count"]


def test_readme_quotes_the_committed_sd_figures():
    readme = " ".join((ROOT / "README.md").read_text().split())
    figures = _page_mod().readme_figures(_data())
    assert len(figures) == 3
    for phrase in figures:
        assert phrase in readme


def test_figure_is_drawn_from_the_json(tmp_path):
    pytest.importorskip("matplotlib")
    assert PNG.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    out = tmp_path / "fig.png"
    assert _page_mod().plot(_data(), out)
    import matplotlib
    if matplotlib.__version__ != _data()["environment"]["versions"].get("matplotlib"):
        pytest.skip("another matplotlib version than the one that drew the committed figure")
    assert out.read_bytes() == PNG.read_bytes()


def test_a_small_run_writes_json_page_and_figure(tmp_path):
    """The measuring code on a few tiny problems, its JSON rendered back (no ../shared)."""
    sd = _scaling_mod()
    rng = np.random.default_rng(3)
    insts = [sd.Instance("crama-spieksma", "cs-n5-1", 5, sd.crama_spieksma(rng, 5, min_gap=0)),
             sd.Instance("tracking N=3", "trk-N3-t5", 5, sd.tracking(rng, 3, 5))]
    solvers = [s for s in ("auto", "lagrangian-exact", "scipy") if sd.available(s)]
    log: list[str] = []
    data = {"environment": sd.environment(["--tiny"]) | {"minutes": 0.1,
                                                           "load_end": [0.0, 0.0, 0.0]},
            "options": {"time_limit": 60.0, "cpsat_limit": 20.0, "fixed_time": 0.5,
                        "solvers": solvers, "missing": [], "reference_all": False,
                        "all_peers": False},
            "exact": sd.exact_section(insts, solvers, 60.0, 20.0, log.append),
            "fixed": sd.fixed_time_section(insts[:1], ["lagrangian"] + solvers, 0.5,
                                           log.append),
            "plain": sd.plain_section(insts[1:], log.append) if sd.available("highs") else [],
            "latency": sd.latency_section(
                [("3-AP n=4", [sd.AssignmentProblem.dense(rng.random((4, 4, 4)))
                               for _ in range(4)])], solvers, log.append),
            "lap": [], "log": log}
    page = tmp_path / "benchmarks-sd.md"
    sd.write_outputs(data, page.with_suffix(".json"), page)
    back = json.loads(page.with_suffix(".json").read_text())
    figure = page.with_suffix(".png").name if page.with_suffix(".png").exists() else None
    assert _page_mod().render(dict(back, figure=figure)) == page.read_text()
    assert all(r["results"]["auto"]["info"]["correct"] for r in back["exact"])
    page.unlink()
    assert sd.main(["--render", "--out", str(page)]) == 0
    assert page.read_text() == _page_mod().render(dict(back, figure=figure))


@pytest.mark.slow
def test_quick_run_writes_a_consistent_page(ap_instances, tmp_path):
    sd = _scaling_mod()
    page = tmp_path / "benchmarks-sd.md"
    assert sd.main(["--quick", "--out", str(page)]) == 0
    data = json.loads(page.with_suffix(".json").read_text())
    assert _page_mod().render(dict(data, figure="benchmarks-sd.png")) == page.read_text()
    assert all(r["results"]["lagrangian-exact"]["info"]["correct"] for r in data["exact"])
