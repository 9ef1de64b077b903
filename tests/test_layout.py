"""The shape of the library: the core never imports tracking or paper code, modules stay
small, and the project cites no file it does not ship.

Layers, lowest first: the core (everything under ``assocopt/`` not named below),
``assocopt.tracking`` (may import the core), ``assocopt.experiments`` (the core only),
``assocopt.reproduce`` (anything).  Imports are read with :mod:`ast`, relative ones
resolved, so the check covers ``from ..tracking import x`` as well.
"""

from __future__ import annotations

import ast
import re
from pathlib import Path

import pytest

from conftest import fresh_python

ROOT = Path(__file__).resolve().parents[1]
PKG = ROOT / "assocopt"

#: Upper layers, each with the layers it must not import.
UPPER = ("assocopt.tracking", "assocopt.experiments", "assocopt.reproduce")
FORBIDDEN = {
    "core": UPPER,
    "assocopt.tracking": ("assocopt.experiments", "assocopt.reproduce"),
    "assocopt.experiments": ("assocopt.tracking", "assocopt.reproduce"),
}
#: The one place the core names the tracking layer: the cost builders of scenario
#: models, looked up by name like a plug-in (assocopt/workflow/models.py, COST_LAYER).
PLUGIN_POINTS = {"assocopt.workflow.models": {"assocopt.tracking.costs"},
                 "assocopt.cli.workflow_cmds": {"assocopt.reproduce"}}   # `assocopt reproduce`
MAX_LINES = 400
#: Modules allowed over MAX_LINES, with the reason (keep this empty if possible).
LONG_ALLOWED: dict[str, str] = {}


def _module_name(path: Path) -> str:
    parts = list(path.relative_to(ROOT).with_suffix("").parts)
    if parts[-1] == "__init__":
        parts.pop()
    return ".".join(parts)


def _modules() -> dict[str, Path]:
    return {_module_name(p): p for p in sorted(PKG.rglob("*.py"))}


def _layer(name: str) -> str:
    for top in UPPER:
        if name == top or name.startswith(top + "."):
            return top
    return "core"


def _imports(name: str, path: Path) -> list[tuple[int, str]]:
    """Every module ``name`` imports (absolute dotted names), with the line."""
    tree = ast.parse(path.read_text(encoding="utf-8"))
    package = name if path.name == "__init__.py" else name.rpartition(".")[0]
    out = []
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            out += [(node.lineno, a.name) for a in node.names]
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                base = package.split(".")
                base = base[:len(base) - node.level + 1]
                mod = ".".join(base + ([node.module] if node.module else []))
            else:
                mod = node.module or ""
            out.append((node.lineno, mod))
            out += [(node.lineno, f"{mod}.{a.name}") for a in node.names]  # from pkg import sub
    return out


def _hits(mod: str, prefixes: tuple[str, ...]) -> bool:
    return any(mod == p or mod.startswith(p + ".") for p in prefixes)


def test_the_import_resolver_sees_relative_and_absolute_imports(tmp_path):
    """The checker itself can fail: it flags each kind of import of a forbidden layer."""
    pkg = tmp_path / "assocopt" / "solvers"
    pkg.mkdir(parents=True)
    f = pkg / "bad.py"
    f.write_text("from ..tracking.costs import COSTS\nimport assocopt.reproduce.lu2013\n"
                 "from .. import experiments\ndef f():\n    from ..tracking.localisation import angles\n")
    found = [m for _, m in _imports("assocopt.solvers.bad", f)]
    assert _hits(found[0], FORBIDDEN["core"])
    assert "assocopt.reproduce.lu2013" in found
    assert "assocopt.experiments" in found
    assert "assocopt.tracking.localisation" in found


def test_layers_import_only_downwards():
    bad = []
    for name, path in _modules().items():
        forbidden = FORBIDDEN.get(_layer(name), ())
        for line, mod in _imports(name, path):
            if _hits(mod, forbidden):
                bad.append(f"{path.relative_to(ROOT)}:{line} imports {mod}")
    assert not bad, "imports against the layering:\n" + "\n".join(bad)


def test_the_core_names_upper_layers_only_at_declared_plugin_points():
    """No importlib-by-string detour around the layering except the declared one."""
    pattern = re.compile(r"[\"']assocopt\.(tracking|experiments|reproduce)[\w.]*[\"']")
    bad = []
    for name, path in _modules().items():
        if _layer(name) != "core":
            continue
        for m in pattern.finditer(path.read_text(encoding="utf-8")):
            if m.group(0).strip("'\"") not in PLUGIN_POINTS.get(name, set()):
                bad.append(f"{path.relative_to(ROOT)}: {m.group(0)}")
    assert not bad, "\n".join(bad)
    from assocopt.workflow import models
    assert models.COST_LAYER in PLUGIN_POINTS["assocopt.workflow.models"]


def test_no_module_is_over_the_size_limit():
    long = {}
    for name, path in _modules().items():
        n = len(path.read_text(encoding="utf-8").splitlines())
        if n > MAX_LINES and name not in LONG_ALLOWED:
            long[name] = n
    assert not long, f"modules over {MAX_LINES} lines (split them by concept): {long}"


def test_each_concept_is_found_by_file_name():
    for rel in ("model/formulation.py", "solvers/highs.py", "tracking/costs/kld.py",
                "tracking/scenarios/lu2013.py", "solving/lp_fixing.py", "io/mps_lp.py",
                "tracking/localisation/estimate.py", "experiments/store.py",
                "reproduce/lu2013/__init__.py", "reproduce/zhang2009/__init__.py"):
        assert (PKG / rel).is_file(), rel


# ----------------------------------------------------------------- self-contained docs
#: Files a user does not have, and the section / erratum ids of those files.
_CITES = re.compile("|".join([
    r"SPEC" + r"(_TRAPS)?\.md", r"shared/" + r"SPEC", r"SPEC" + r"_TRAPS", r"\bSPEC\b",
    r"\[IMPL\]",
    r"(?<![\w.])[ERD]\d{1,2}\.\d{1,2}(?![\w.])",      # erratum / derivation ids: E2.11, R0.1
    r"(?<![\w.])00\d\.\d(?![\w.])",                   # spec sections: 002.2
]))
_SCANNED = ("assocopt", "docs", "models", "benchmarks", "tests", "README.md")
_TEXT = {".py", ".md", ".toml", ".json", ".ipynb", ".txt", ".cfg", ".rst"}


def _scanned_files():
    for top in _SCANNED:
        p = ROOT / top
        files = [p] if p.is_file() else sorted(p.rglob("*"))
        for f in files:
            if f.is_file() and f.suffix in _TEXT and "__pycache__" not in f.parts \
                    and f != Path(__file__).resolve():       # this file spells the patterns
                yield f


def test_the_citation_pattern_can_fail():
    for text in ("see SP" "EC.md 002.2", "(E" "2.11)", "R0" ".1", "SPEC_TR" "APS.md point 1",
                 "[IM" "PL]", "shared/SP" "EC"):
        assert _CITES.search(text), text
    for text in ("eq. (27)", "1e-9", "v2.2", "x = 1.5", "scipy 1.11.0", "E2E", "0.002"):
        assert not _CITES.search(text), text


def test_no_reference_to_files_the_project_does_not_ship():
    bad = []
    for f in _scanned_files():
        for i, line in enumerate(f.read_text(encoding="utf-8", errors="replace").splitlines(), 1):
            m = _CITES.search(line)
            if m:
                bad.append(f"{f.relative_to(ROOT)}:{i}: {m.group(0)!r}")
    assert not bad, ("state the equation or correction in words and point to "
                     "docs/papers/NAME.md instead:\n" + "\n".join(bad[:60]))


def test_a_plain_model_does_not_load_the_tracking_layer():
    """The cost layer is looked up only for models with a [cost] table."""
    code = ("import sys, assocopt.workflow.models as m; m.load_model('highs-ilp');"
            "print(any(k.startswith('assocopt.tracking') for k in sys.modules));"
            "m.load_model('lu2013-pattipati');"
            "print(any(k.startswith('assocopt.tracking') for k in sys.modules))")
    out = fresh_python(code, cwd=ROOT).split()
    assert out == ["False", "True"]
