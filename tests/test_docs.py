"""docs/guide.md is executable: every command in it runs, in order, and does what it says.

The guide's fenced blocks are run in document order in a scratch folder holding a
copy of ``instances/``:

* ```` ```bash ````: each line is a command.  ``assocopt ...`` runs through
  :func:`assocopt.cli.main` (shell globs expanded); ``pip install`` and
  ``python -m pytest`` lines are skipped; a trailing ``# exit N`` comment is the
  expected exit code (default 0).  Anything else fails the test, so the guide only
  shows commands this test can run.
* ```` ```python ````: executed in one namespace.
* ```` ```toml ```` preceded by ``<!-- guide-test: write NAME -->``: written to NAME
  (and checked to be a valid model when it looks like one).
"""

from __future__ import annotations

import glob
import re
import shlex
import shutil
from pathlib import Path

import pytest

from assocopt.cli import _build_parser, main

ROOT = Path(__file__).resolve().parents[1]
GUIDE = ROOT / "docs" / "guide.md"
README = ROOT / "README.md"

_FENCE = re.compile(r"(?:<!--\s*guide-test:\s*write\s+(?P<target>\S+)\s*-->\s*\n)?"
                    r"^```(?P<lang>[\w-]*)[ \t]*\n(?P<body>.*?)^```[ \t]*$",
                    re.MULTILINE | re.DOTALL)
_EXIT = re.compile(r"#\s*exit\s+(\d+)\s*$")
_SKIP = ("pip install", "python -m pytest")


def blocks(page: Path = GUIDE) -> list[tuple[str, str, str | None, int]]:
    """``(language, body, write-target, line number)`` of every fenced block of a page."""
    text = page.read_text(encoding="utf-8")
    return [(m["lang"], m["body"], m["target"], text.count("\n", 0, m.start("body")) + 1)
            for m in _FENCE.finditer(text)]


def commands() -> list[tuple[str, int]]:
    out = []
    for lang, body, _, line in blocks():
        if lang == "bash":
            out += [(ln.strip(), line + k) for k, ln in enumerate(body.splitlines())
                    if ln.strip() and not ln.strip().startswith("#")]
    return out


def _argv(command: str, cwd: Path) -> list[str]:
    words = shlex.split(command, comments=True)
    argv: list[str] = []
    for w in words[1:]:
        if any(ch in w for ch in "*?["):
            hits = sorted(glob.glob(w, root_dir=cwd))
            assert hits, f"glob {w!r} matches nothing"
            argv += hits
        else:
            argv.append(w)
    return argv


def _run_command(command: str, line: int, cwd: Path, capsys) -> None:
    if command.startswith(_SKIP):
        return
    assert command.startswith("assocopt "), (
        f"guide.md line {line}: {command!r} is not an assocopt command; the guide's bash "
        "blocks may hold only assocopt, pip install and python -m pytest lines")
    assert not re.search(r"[|<>;&`$]", command.split("#")[0]), (
        f"guide.md line {line}: shell syntax is not run by this test: {command!r}")
    m = _EXIT.search(command)
    expected = int(m.group(1)) if m else 0
    code = main(_argv(command, cwd))
    out, err = capsys.readouterr()
    assert code == expected, (f"guide.md line {line}: {command!r} exited {code}, expected "
                              f"{expected}\nstdout:\n{out[-2000:]}\nstderr:\n{err[-2000:]}")
    if expected == 2:
        assert len(err.strip().splitlines()) == 1 and "Traceback" not in err, err


@pytest.fixture
def workspace(tmp_path, monkeypatch):
    shutil.copytree(ROOT / "instances", tmp_path / "instances")
    monkeypatch.chdir(tmp_path)
    return tmp_path


def test_guide_runs_in_order(workspace, capsys):
    namespace: dict = {"__name__": "guide"}
    for lang, body, target, line in blocks():
        if target is not None:
            (workspace / target).write_text(body, encoding="utf-8")
        if lang == "bash":
            for k, raw in enumerate(body.splitlines()):
                if raw.strip() and not raw.strip().startswith("#"):
                    _run_command(raw.strip(), line + k, workspace, capsys)
        elif lang == "python":
            try:
                exec(compile(body, f"guide.md:{line}", "exec"), namespace)
            except Exception as exc:  # noqa: BLE001 - report which block failed
                pytest.fail(f"guide.md python block at line {line} failed: "
                            f"{type(exc).__name__}: {exc}")
            capsys.readouterr()


def test_guide_toml_models_are_valid(tmp_path):
    from assocopt.workflow.models import load_model

    written = [(t, body) for lang, body, t, _ in blocks() if lang == "toml" and t]
    assert written, "the guide shows how to write a model"
    for target, body in written:
        path = tmp_path / target
        path.write_text(body, encoding="utf-8")
        assert load_model(str(path)).name == path.stem


def test_guide_shows_every_command():
    parser = _build_parser()
    sub = next(a for a in parser._actions if a.dest == "command")
    shown = {c.split()[1] for c, _ in commands() if c.startswith("assocopt ") and
             len(c.split()) > 1}
    text = GUIDE.read_text(encoding="utf-8")
    for verb in sub.choices:
        assert f"assocopt {verb}" in text, f"the command reference misses {verb!r}"
    missing = set(sub.choices) - shown                    # and each one is run

    assert not missing, f"no runnable example of: {sorted(missing)}"


def test_guide_examples_of_errors_are_checked():
    codes = [int(m.group(1)) for c, _ in commands() if (m := _EXIT.search(c))]
    assert 2 in codes


def test_command_parser_rejects_shell_syntax(tmp_path, capsys):
    with pytest.raises(AssertionError, match="not an assocopt command"):
        _run_command("ls instances", 1, tmp_path, capsys)
    with pytest.raises(AssertionError, match="shell syntax"):
        _run_command("assocopt solvers | head", 1, tmp_path, capsys)
    with pytest.raises(AssertionError, match="exited 0, expected 2"):
        _run_command("assocopt solvers  # exit 2", 1, tmp_path, capsys)


def test_sample_output_in_the_guide_is_real(capsys):
    sample = next(body for lang, body, _, _ in blocks()
                  if lang == "text" and body.startswith("instance   example-3d"))
    shown = [ln for ln in sample.splitlines() if ln.strip() != "..."]
    assert main(["solve", str(ROOT / "instances" / "example-3d.json")]) == 0
    real = capsys.readouterr().out.splitlines()
    assert real[:len(shown)] == shown


def test_readme_first_commands_and_python_run(workspace, capsys):
    """README's "Set up and run" block prints what the README says; its Python runs."""
    setup = next(body for lang, body, _, _ in blocks(README) if lang == "bash")
    commands = [ln.strip() for ln in setup.splitlines() if ln.strip()]
    assert commands[0].startswith("pip install") and len(commands) == 2
    assert main(_argv(commands[1], workspace)) == 0
    out = capsys.readouterr().out
    for field in ("status", "objective", "bound", "gap", "solver", "tuples"):
        assert re.search(rf"^{field}\b", out, re.MULTILINE), (field, out)
    assert main(["instances"]) == 0 and "example-3d" in capsys.readouterr().out
    assert main(["solve", "example-3d"]) == 0 and "optimal" in capsys.readouterr().out
    python = [(body, line) for lang, body, _, line in blocks(README) if lang == "python"]
    assert python, "README shows the Python API"
    namespace: dict = {"__name__": "readme"}
    for body, line in python:
        exec(compile(body, f"README.md:{line}", "exec"), namespace)
    sol, lp, ranked, m = (namespace[k] for k in ("sol", "lp", "ranked", "m"))
    assert (sol.status, sol.gap) == ("optimal", 0.0) and sol.bound == sol.objective
    assert lp.objective <= sol.objective + 1e-9
    assert namespace["solve"](namespace["p3"]).tuples.tolist() == [[1, 1, 1], [2, 2, 2]]
    assert len(ranked) == 10 and list(ranked.objectives) == sorted(ranked.objectives)
    assert abs(m.pairs.sum(axis=1) + m.row_miss - 1).max() < 1e-9
