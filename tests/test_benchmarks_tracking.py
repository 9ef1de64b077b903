"""docs/benchmarks-tracking.md is what benchmarks/tracking_page.py draws from the
committed docs/benchmarks-tracking.json, and its numbers hold together: every proven
objective agrees with the scan's reference, the totals are sums of the scan times, the
ratios are ratios of the totals shown, the scans are the ones the generator draws;
README.md's tracking figures are the ones in the JSON."""

from __future__ import annotations

import json
import re

from conftest import ROOT, agrees, load_script

JSON = ROOT / "docs" / "benchmarks-tracking.json"
PAGE = ROOT / "docs" / "benchmarks-tracking.md"


def _page_mod():
    return load_script("benchmarks/tracking_page.py", "bench_tracking_page")


def _data() -> dict:
    return json.loads(JSON.read_text())


def test_page_matches_the_committed_json():
    assert _page_mod().render(_data()) == PAGE.read_text()


def test_json_records_the_environment_and_the_command():
    env = _data()["environment"]
    assert env["command"].startswith("python benchmarks/sd_tracking.py")
    assert len(env["load_start"]) == len(env["load_end"]) == 3
    assert env["minutes"] > 0 and re.fullmatch(r"\d{4}-\d\d-\d\d", env["date"])


def test_every_proven_objectiveagrees():
    scans = _data()["scans"]
    assert scans
    for row in scans:
        for name, r in row["results"].items():
            ok = r["status"] != "optimal" or agrees(r["objective"], row["reference"])
            assert r["correct"] == ok, (row["spec"], name)
            if name != "milp":                 # our solves prove every scan
                assert r["status"] == "optimal" and ok, (row["spec"], name)


def test_totals_and_ratios_are_those_of_the_scan_times():
    data = _data()
    mod = _page_mod()
    methods = data["options"]["methods"]
    lines = PAGE.read_text().splitlines()
    i = next(k for k, ln in enumerate(lines) if ln.startswith("| N | n | spacing |"))
    rows = []
    for ln in lines[i + 2:]:
        if not ln.startswith("|"):
            break
        rows.append([c.strip() for c in ln.strip("|").split("|")])
    g = mod.groups(data)
    assert len(rows) == len(g)
    for cells, (key, scans) in zip(rows, g.items()):
        assert (int(cells[0]), int(cells[1]), float(cells[2]), float(cells[3]),
                float(cells[4])) == key
        assert int(cells[5]) == len(scans)
        times = {}
        for m, cell in zip(methods, cells[10:10 + len(methods)]):
            if cell == "-":
                assert any(m not in s["results"] for s in scans)
                continue
            t = float(cell.split()[0])
            assert abs(t - sum(s["results"][m]["time"] for s in scans)) <= 5e-4
            times[m] = t
        for cell, num in ((cells[-2], "highs"), (cells[-1], "milp")):
            if cell == "-":
                continue
            r = float(cell.rstrip("x"))
            lo = (times[num] - 5e-4) / (times["auto"] + 5e-4)
            hi = (times[num] + 5e-4) / max(times["auto"] - 5e-4, 1e-12)
            assert lo - 0.05 <= r <= hi + 0.05, (key, num)


def test_scans_are_the_generators():
    """The committed scans' sizes are what benchmarks/tracking_scans.py draws today
    (a changed generator would make the page describe other scans)."""
    gen = load_script("benchmarks/tracking_scans.py", "bench_tracking_scans", register=True)
    small = sorted(_data()["scans"], key=lambda r: r["K"])[:3]
    for row in small:
        p, _ = gen.build_problem(gen.ScanSpec(**row["spec"]))
        assert list(p.sizes) == row["sizes"] and p.n_candidates == row["K"]


def test_readme_quotes_the_committed_tracking_figures():
    readme = " ".join((ROOT / "README.md").read_text().split())
    figures = _page_mod().readme_figures(_data())
    assert len(figures) == 3
    for phrase in figures:
        assert phrase in readme
