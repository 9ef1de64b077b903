"""docs/benchmarks.md is what benchmarks/backends.py renders from the committed
docs/benchmarks.json, and its numbers hold together: every proven objective is the
recorded optimum, every ratio is the ratio of the times shown, every geometric mean is
that of the ratios; README.md's Grundel n = 50 figure is the one in the JSON."""

from __future__ import annotations

import csv
import json
import math
import re
import statistics

import pytest

from conftest import ROOT, load_script

JSON = ROOT / "docs" / "benchmarks.json"
PAGE = ROOT / "docs" / "benchmarks.md"


def _bench():
    return load_script("benchmarks/backends.py", "bench_backends")


def _data() -> dict:
    return json.loads(JSON.read_text())


def _cells() -> list[tuple[str, str, str]]:
    """(instance, back end, cell text) of every filled cell of the page's table."""
    rows = [ln for ln in PAGE.read_text().splitlines() if ln.startswith("| ")]
    head = [c.strip() for c in rows[0].strip("|").split("|")]
    out = []
    for ln in rows[1:]:
        cells = [c.strip() for c in ln.strip("|").split("|")]
        out += [(cells[0], h, c) for h, c in zip(head[4:], cells[4:]) if c]
    return out


def test_page_matches_the_committed_json():
    assert _bench().render(_data()) == PAGE.read_text()


def test_json_records_the_environment_and_the_command():
    env = _data()["environment"]
    assert env["command"].startswith("python benchmarks/backends.py")
    assert len(env["load_start"]) == len(env["load_end"]) == 3
    assert env["cores"] >= 1 and re.fullmatch(r"\d{4}-\d\d-\d\d", env["date"])


def test_every_proven_objective_is_the_recorded_optimum():
    data = _data()
    assert data["records"]
    for row in data["records"]:
        for name, res in row["results"].items():
            proven = res["status"] == "optimal"
            assert res["correct"] == (proven and res["objective"] == row["optimum"]), \
                (row["instance"], name)
            if proven:
                assert res["objective"] == row["optimum"], (row["instance"], name)
            assert res["time"] == statistics.median(res["times"])


def test_the_default_and_the_lagrangian_exact_method_prove_every_instance():
    """What README.md and the S-D page say of them (``bnb`` alone may hit the limit)."""
    for row in _data()["records"]:
        for name in ("lagrangian-exact", "auto"):
            if name in row["results"]:
                assert row["results"][name]["correct"], (row["instance"], name)


def _shown(cell: str) -> tuple[float, float | None]:
    m = re.match(r"([0-9.]+) s(?: \(([0-9.e+-]+)\))?", cell)
    return float(m.group(1)), (float(m.group(2)) if m.group(2) else None)


def _ratio_fits(t: float, ref: float, shown: float, dt: float = 5e-5) -> bool:
    """Can ``shown`` (3 significant digits) be t_true / ref_true for times that round to
    ``t`` and ``ref`` (4 decimals)?"""
    lo = max(t - dt, 0.0) / (ref + dt)
    hi = math.inf if ref <= dt else (t + dt) / (ref - dt)
    return lo * (1 - 5e-3) <= shown <= hi * (1 + 5e-3)


def test_every_ratio_on_the_page_is_the_ratio_of_the_times_shown():
    cells = _cells()
    ref = {inst: _shown(c)[0] for inst, name, c in cells if name == "scipy"}
    checked = 0
    for inst, name, c in cells:
        t, r = _shown(c)
        if r is not None:
            assert _ratio_fits(t, ref[inst], r), (inst, name, c)
            checked += 1
    assert checked >= len(ref)


def test_geometric_means_are_those_of_the_ratios():
    data = _data()
    page = PAGE.read_text()
    for name in data["options"]["solvers"]:
        ratios = [row["results"][name]["time"] / row["results"]["scipy"]["time"]
                  for row in data["records"]
                  if name in row["results"] and row["results"].get("scipy", {}).get("correct")]
        if ratios:
            gm = math.exp(sum(map(math.log, ratios)) / len(ratios))
            assert f"* `{name}`: {gm:.3g} over {len(ratios)} instances" in page


def test_readme_quotes_the_committed_grundel_n50_figure():
    readme = " ".join((ROOT / "README.md").read_text().split())
    assert _bench().readme_figure(_data()) in readme
    row = next(r for r in _data()["records"] if r["instance"].endswith("ap3.50.1.txt"))
    assert row["results"]["lagrangian-exact"]["correct"]


def test_recorded_optima_are_the_shared_known_values(ap_instances):
    with open(ap_instances / "known_values.csv", newline="") as fh:
        known = {r["file"]: float(r["value"]) for r in csv.DictReader(fh)}
    for row in _data()["records"]:
        if row["instance"] not in known:
            pytest.skip(f"{row['instance']} not in this copy of the shared instances")
        assert row["optimum"] == known[row["instance"]]


def test_small_run_writes_a_page_rendered_from_its_json(ap_instances, tmp_path):
    bench = _bench()
    assert bench.main(["--max-n", "10", "--solvers", "scipy,auto", "--time-limit", "60",
                       "--out", str(tmp_path)]) == 0
    data = json.loads((tmp_path / "benchmarks.json").read_text())
    assert data["options"]["max_n"] == 10 and data["environment"]["load_end"]
    assert all(r["results"]["auto"]["correct"] for r in data["records"])
    assert bench.render(data) == (tmp_path / "benchmarks.md").read_text()
    (tmp_path / "benchmarks.md").unlink()
    assert bench.main(["--render", "--out", str(tmp_path)]) == 0
    assert bench.render(data) == (tmp_path / "benchmarks.md").read_text()
