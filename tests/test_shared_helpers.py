"""The one JSON sanitiser, the one atomic writer and the one progress display that every
part of the project uses (io.jsonable, io.write_*_atomically, progress.Progress)."""

from __future__ import annotations

import io
import json
import math
import sys
from pathlib import Path

import numpy as np
import pytest

from assocopt.io import jsonable, write_json_atomically, write_text_atomically
from assocopt.runtime.progress import Progress

ROOT = Path(__file__).resolve().parents[1]


def test_jsonable_converts_numpy_tuples_and_keys():
    out = jsonable({1: (np.int64(2), np.float32(0.5)), "a": np.array([[1, 2]]),
                    "b": np.bool_(False), "c": None, "d": "x", "e": Path("p")})
    assert out == {"1": [2, 0.5], "a": [[1, 2]], "b": False, "c": None, "d": "x", "e": "p"}
    assert type(out["1"][0]) is int and type(out["b"]) is bool
    json.dumps(out, allow_nan=False)


@pytest.mark.parametrize("mode,expect", [("string", ["nan", "inf", "-inf", 1.5]),
                                         ("null", [None, None, None, 1.5])])
def test_jsonable_nonfinite_modes(mode, expect):
    v = [float("nan"), np.float64("inf"), -math.inf, 1.5]
    assert jsonable(v, nonfinite=mode) == expect


def test_jsonable_rejects_an_unknown_mode():
    with pytest.raises(ValueError, match="nonfinite"):
        jsonable(1.0, nonfinite="zero")


def test_write_json_atomically_is_strict_json_and_leaves_no_temporary(tmp_path):
    f = tmp_path / "s.json"
    write_json_atomically(f, {"x": float("nan"), "t": (1, 2)})
    assert json.loads(f.read_text()) == {"x": None, "t": [1, 2]}
    assert "NaN" not in f.read_text()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["s.json"]


def test_an_interrupted_write_keeps_the_old_file(tmp_path, monkeypatch):
    f = tmp_path / "t.md"
    write_text_atomically(f, "old\n")
    import assocopt.io.writers as w

    def boom(*a, **k):
        raise KeyboardInterrupt

    monkeypatch.setattr(w.os, "replace", boom)
    with pytest.raises(KeyboardInterrupt):
        write_text_atomically(f, "new\n")
    assert f.read_text() == "old\n"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["t.md"]


def test_progress_bar_on_its_stream():
    s = io.StringIO()
    bar = Progress(3, True, "demo", unit="trial", initial=1, stream=s)
    bar.update()
    bar.update(1, "last one")
    bar.close()
    text = s.getvalue()
    assert "demo:" in text and "1/3" in text and "3/3" in text and "trial" in text
    assert "last one" in text and text.endswith("\n")


def test_progress_disabled_writes_nothing(monkeypatch):
    monkeypatch.setitem(sys.modules, "tqdm", None)
    s = io.StringIO()
    bar = Progress(2, False, "demo", stream=s)
    bar.update(2, "x")
    bar.close()
    assert s.getvalue() == "" and bar.n == 2


def test_no_other_atomic_writer_json_sanitiser_or_progress_bar():
    """Nothing outside the shared helpers rolls its own (tmp file + os.replace, a
    json default= hook, a tqdm import)."""
    own = {ROOT / "assocopt" / "io" / "writers.py", ROOT / "assocopt" / "runtime" / "progress.py"}
    bad = []
    for top in ("assocopt", "benchmarks"):
        for f in sorted((ROOT / top).rglob("*.py")):
            if f in own:
                continue
            text = f.read_text(encoding="utf-8")
            for needle in ("os.replace(", "mkstemp(", "default=_json", "from tqdm import"):
                if needle in text:
                    bad.append(f"{f.relative_to(ROOT)}: {needle}")
    assert not bad, "\n".join(bad)


@pytest.mark.parametrize("paper", ["dong2015", "lu2013", "xue1999", "yan2010", "zhang2009"])
def test_reproduction_figures_without_matplotlib_are_none(paper, tmp_path, monkeypatch):
    import importlib
    from assocopt.reproduce._plot import pyplot
    repro = importlib.import_module(f"assocopt.reproduce.{paper}")
    summary = json.loads((ROOT / "docs" / "papers" / paper / "summary.json").read_text())
    monkeypatch.setitem(sys.modules, "matplotlib", None)
    monkeypatch.setitem(sys.modules, "matplotlib.pyplot", None)
    assert pyplot() is None
    extra = (repro.experiment._options(None),) if paper == "xue1999" else ()
    assert repro.make_figures(summary, tmp_path, *extra) == []
    assert list(tmp_path.iterdir()) == []


def test_plot_save_writes_closes_and_names_the_figure(tmp_path):
    from assocopt.reproduce._plot import draw_all, pyplot, save
    plt = pyplot()
    if plt is None:
        pytest.skip("matplotlib not installed")

    def one(plt, summary, out, title):
        fig, ax = plt.subplots()
        ax.set_title(title)
        return save(fig, out, "one.png", rect=(0, 0, 1, 0.9))

    before = set(plt.get_fignums())
    assert draw_all({}, tmp_path, (one, lambda *a: None), "t") == ["one.png"]
    assert (tmp_path / "one.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert set(plt.get_fignums()) == before


def test_no_other_figure_writer_in_the_reproductions():
    """The reproductions draw through reproduce/_plot.py (one back end, one resolution)."""
    own = ROOT / "assocopt" / "reproduce" / "_plot.py"
    bad = [f"{f.relative_to(ROOT)}: {needle}"
           for f in sorted((ROOT / "assocopt" / "reproduce").rglob("*.py")) if f != own
           for needle in ("matplotlib.use(", ".savefig(", "plt.close(")
           if needle in f.read_text(encoding="utf-8")]
    assert not bad, "\n".join(bad)


def test_finite_floats_names_the_input_and_raises_the_callers_error():
    from assocopt.runtime.errors import InvalidProblemError
    from assocopt.tracking.belief.group_matching import InvalidObservationsError, Observations
    from assocopt.tracking.gating import gate
    from assocopt.problems.validation import finite_floats
    out = finite_floats([[1, 2]], "x")
    assert out.dtype == np.float64 and out.tolist() == [[1.0, 2.0]]
    with pytest.raises(InvalidProblemError, match="^x contains NaN or inf$"):
        finite_floats([1.0, math.nan], "x")
    with pytest.raises(KeyError, match="positions contain NaN or inf"):
        finite_floats([math.inf], "positions", KeyError, plural=True)
    with pytest.raises(InvalidProblemError, match="^z must be numeric"):
        finite_floats(["a"], "z")
    with pytest.raises(InvalidProblemError, match="z_pred contains NaN"):
        gate([[math.nan]], [[[1.0]]], [[0.0]])
    with pytest.raises(InvalidObservationsError, match="positions contain NaN"):
        Observations([[math.nan, 0.0]], [np.eye(2)], [[1.0]], [1], ("a",))
