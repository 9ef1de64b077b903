"""The shape of the library: layers import only downwards, no module imports itself
through others, modules stay small, and the project cites no file it does not ship.

Layers, lowest first: the core (everything under ``assocopt/`` not named below),
``assocopt.tracking`` (may import the core), ``assocopt.experiments`` (the core only),
``assocopt.reproduce`` (anything).  Inside the core each package imports only the
packages :data:`CORE` lists for it (its ``__init__`` says the same).  Imports are read
with :mod:`ast`, relative ones resolved, so the check covers ``from ..tracking import
x`` as well, and imports inside functions count like those at the top.
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
#: The core's packages (and top-level modules), lowest first, each with the core
#: packages it may import besides itself; each package's ``__init__`` docstring has a
#: "May import:" line naming the same.  Every module may read ``assocopt._version``
#: (a leaf); the package's own ``__init__`` / ``__main__`` (``"assocopt"``) may import
#: all of them.
_BASE = ("assocopt.runtime", "assocopt.problems", "assocopt.model", "assocopt.solvers")
CORE: dict[str, tuple[str, ...]] = {
    "assocopt.runtime": (),
    "assocopt.problems": _BASE[:1],
    "assocopt.model": _BASE[:2],
    "assocopt.solvers": _BASE[:3],
    "assocopt.solving": _BASE,
    "assocopt.ranking": _BASE + ("assocopt.solving",),
    "assocopt.io": _BASE,
    "assocopt.workflow": _BASE + ("assocopt.solving", "assocopt.ranking", "assocopt.io"),
    "assocopt.testing": _BASE + ("assocopt.solving", "assocopt.ranking", "assocopt.io",
                                 "assocopt.workflow"),
    "assocopt.cli": _BASE + ("assocopt.solving", "assocopt.ranking", "assocopt.io",
                             "assocopt.workflow"),
}
#: Inside ``assocopt.solvers``: the shared top-level modules, and the parts, each with
#: what it may import of the package besides itself (its ``__init__`` says the same).
SOLVERS_TOP = tuple(f"assocopt.solvers.{m}" for m in
                    ("base", "options", "status", "scaling", "interruptible"))
SOLVERS_PARTS: dict[str, tuple[str, ...]] = {
    "assocopt.solvers.kernels": (),
    "assocopt.solvers.twod": ("assocopt.solvers.base", "assocopt.solvers.scaling",
                              "assocopt.solvers.kernels"),
    "assocopt.solvers.milp": ("assocopt.solvers.base", "assocopt.solvers.status",
                              "assocopt.solvers.interruptible"),
    "assocopt.solvers.bnb": ("assocopt.solvers.base", "assocopt.solvers.interruptible",
                             "assocopt.solvers.kernels"),
    "assocopt.solvers.baseline": ("assocopt.solvers.base",),
    "assocopt.solvers.lagrangian": SOLVERS_TOP + (
        "assocopt.solvers.kernels", "assocopt.solvers.twod", "assocopt.solvers.milp",
        "assocopt.solvers.bnb", "assocopt.solvers.baseline"),
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


def _resolved(name: str, path: Path) -> list[tuple[int, str, tuple[str, ...]]]:
    """Every import statement of module ``name`` anywhere in its file (top level, inside
    functions, under ``TYPE_CHECKING``): ``(line, absolute module, names imported from
    it)``; ``import a.b`` gives ``(line, "a.b", ())``."""
    tree = ast.parse(path.read_text(encoding="utf-8"))
    package = name if path.name == "__init__.py" else name.rpartition(".")[0]
    out = []
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            out += [(node.lineno, a.name, ()) for a in node.names]
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                base = package.split(".")
                base = base[:len(base) - node.level + 1]
                mod = ".".join(base + ([node.module] if node.module else []))
            else:
                mod = node.module or ""
            out.append((node.lineno, mod, tuple(a.name for a in node.names)))
    return out


def _imports(name: str, path: Path) -> list[tuple[int, str]]:
    """Every module ``name`` imports (absolute dotted names), with the line."""
    out = []
    for line, mod, names in _resolved(name, path):
        out.append((line, mod))
        out += [(line, f"{mod}.{n}") for n in names]      # from pkg import sub
    return out


def _import_graph(modules: dict[str, Path]) -> dict[str, set[str]]:
    """Module -> the project modules it imports.  ``from X import n`` counts ``X.n`` when
    that is a module, else ``X``; ``import a.b`` counts ``a.b``.  Not counted: the
    parent packages' ``__init__`` that Python runs before a submodule (a package that
    re-exports its own modules would otherwise be a loop with each of them, and reading
    a module never needs its package's ``__init__``)."""
    graph: dict[str, set[str]] = {}
    for name, path in modules.items():
        out = set()
        for _, mod, names in _resolved(name, path):
            subs = {f"{mod}.{n}" for n in names} & modules.keys()
            out |= subs
            if len(subs) < len(names) or not names:
                while mod and mod not in modules:
                    mod = mod.rpartition(".")[0]
                out |= {mod} if mod else set()
        graph[name] = out - {name}
    return graph


def _cycles(graph: dict[str, set[str]]) -> list[list[str]]:
    """The groups of modules that import each other in a loop (strongly connected
    components of more than one module, Tarjan's algorithm), each sorted."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on_stack: set[str] = set()
    found = []

    def visit(v: str) -> None:
        index[v] = low[v] = len(index)
        stack.append(v)
        on_stack.add(v)
        for w in sorted(graph[v]):
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on_stack:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            group = []
            while True:
                w = stack.pop()
                on_stack.discard(w)
                group.append(w)
                if w == v:
                    break
            if len(group) > 1:
                found.append(sorted(group))

    for v in sorted(graph):
        if v not in index:
            visit(v)
    return sorted(found)


def _part(name: str) -> str:
    """The core package (or top-level module) ``name`` belongs to; ``"assocopt"`` for the
    package's own ``__init__`` / ``__main__``."""
    for part in tuple(CORE) + ("assocopt._version",):
        if name == part or name.startswith(part + "."):
            return part
    return "assocopt"


def _hits(mod: str, prefixes: tuple[str, ...]) -> bool:
    return any(mod == p or mod.startswith(p + ".") for p in prefixes)


def test_the_import_resolver_sees_relative_and_absolute_imports(tmp_path):
    """The checker itself can fail: it flags each kind of import of a forbidden layer."""
    pkg = tmp_path / "assocopt" / "solvers"
    pkg.mkdir(parents=True)
    f = pkg / "bad.py"
    f.write_text("from ..tracking.costs import COSTS\nimport assocopt.reproduce.lu2013\n"
                 "from .. import experiments\ndef f():\n"
                 "    from ..tracking.localisation import angles\n")
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


def test_core_packages_import_only_the_packages_below_them():
    bad = []
    for name, path in _modules().items():
        part = _part(name)
        if _layer(name) != "core" or part in ("assocopt", "assocopt._version"):
            continue
        allowed = (part, "assocopt._version") + CORE[part]
        for line, mod in _imports(name, path):
            if _hits(mod, ("assocopt",)) and not _hits(mod, UPPER) \
                    and _part(mod) not in allowed:
                bad.append(f"{path.relative_to(ROOT)}:{line} imports {mod} "
                           f"({part} may import {', '.join(CORE[part]) or 'nothing'})")
    assert not bad, "imports against the core's layering:\n" + "\n".join(bad)


def test_each_core_package_says_what_it_may_import():
    """The ``May import:`` line of each package's docstring names what :data:`CORE` does."""
    for part, allowed in CORE.items():
        init = ROOT / part.replace(".", "/") / "__init__.py"
        if not init.is_file():           # a top-level module (assocopt.testing)
            continue
        doc = ast.get_docstring(ast.parse(init.read_text(encoding="utf-8"))) or ""
        assert "May import:" in doc, f"{part}: its docstring does not say what it may import"
        said = doc.split("May import:", 1)[1].split("\n\n", 1)[0]
        named = set(re.findall(r"assocopt\.\w+", said))
        assert named == set(allowed), (part, sorted(named), sorted(allowed))
        if not allowed:
            assert "nothing of assocopt" in said, part


def _solvers_part(mod: str) -> str | None:
    """The part of ``assocopt.solvers`` that ``mod`` belongs to, the top-level module it
    is, or None outside the package."""
    for part in tuple(SOLVERS_PARTS) + SOLVERS_TOP + ("assocopt.solvers",):
        if _hits(mod, (part,)):
            return part
    return None


def test_solver_parts_import_only_the_shared_modules_and_the_parts_they_name():
    """A back end's part reads the shared top-level modules (and the kernels), not
    another part, except where the table says so; the top-level modules import no part."""
    bad = []
    for name, path in _modules().items():
        part = _solvers_part(name)
        if part is None or part == "assocopt.solvers":
            continue
        allowed = (part,) + SOLVERS_PARTS.get(part, SOLVERS_TOP)
        for line, mod in _imports(name, path):
            other = _solvers_part(mod)
            if other is not None and other != "assocopt.solvers" and other not in allowed:
                bad.append(f"{path.relative_to(ROOT)}:{line} imports {mod} "
                           f"({part} may import {', '.join(allowed[1:]) or 'nothing'})")
    assert not bad, "imports across the parts of assocopt.solvers:\n" + "\n".join(bad)


def test_each_solver_part_says_what_it_may_import():
    """Each part's ``__init__`` docstring has a ``May import:`` line naming the core
    packages that :data:`CORE` gives ``assocopt.solvers`` and, of the solvers' own
    modules, exactly those :data:`SOLVERS_PARTS` gives the part."""
    for part, allowed in SOLVERS_PARTS.items():
        init = ROOT / part.replace(".", "/") / "__init__.py"
        doc = ast.get_docstring(ast.parse(init.read_text(encoding="utf-8"))) or ""
        assert "May import:" in doc, f"{part}: its docstring does not say what it may import"
        said = doc.split("May import:", 1)[1].split("\n\n", 1)[0]
        named = set(re.findall(r"assocopt\.[\w.]+\w", said)) - {"assocopt.solvers"}
        core = {m for m in named if not m.startswith("assocopt.solvers")}
        assert core == set(CORE["assocopt.solvers"]) or not allowed, (part, sorted(core))
        assert named - core == set(allowed), (part, sorted(named - core), sorted(allowed))


def _forwards_only(path: Path) -> bool:
    """Whether a module's body is nothing but imports (and ``__all__``): a forwarding
    shim that keeps an old path alive instead of holding code."""
    body = ast.parse(path.read_text(encoding="utf-8")).body
    if body and isinstance(body[0], ast.Expr) and isinstance(body[0].value, ast.Constant):
        body = body[1:]
    def forwarding(node: ast.stmt) -> bool:
        if isinstance(node, (ast.Import, ast.ImportFrom)):
            return True
        return isinstance(node, ast.Assign) and all(
            isinstance(t, ast.Name) and t.id == "__all__" for t in node.targets)
    return bool(body) and all(forwarding(n) for n in body) and \
        any(isinstance(n, ast.ImportFrom) and n.module != "__future__" for n in body)


def test_no_forwarding_shims():
    """Only a package's ``__init__`` re-exports; no module exists just to forward
    names from where the code moved (import the code from where it lives)."""
    shims = [str(p.relative_to(ROOT)) for p in _modules().values()
             if p.name != "__init__.py" and _forwards_only(p)]
    assert not shims, f"modules that only forward imports: {shims}"


def test_the_shim_check_can_fail(tmp_path):
    shim = tmp_path / "old.py"
    shim.write_text('"""Moved."""\nfrom __future__ import annotations\n'
                    'from .new import f, g  # noqa: F401\n__all__ = ["f", "g"]\n')
    assert _forwards_only(shim)
    shim.write_text("from .new import f\n\ndef g():\n    return f()\n")
    assert not _forwards_only(shim)


def test_no_import_cycles():
    """No group of the project's modules imports each other in a loop, counting imports
    inside functions too: each module can be read and changed with only what is below
    it in mind."""
    cycles = _cycles(_import_graph(_modules()))
    graph = _import_graph(_modules())
    report = ["  " + ", ".join(f"{m} -> {sorted(graph[m] & set(group))}" for m in group)
              for group in cycles]
    assert not cycles, "modules that import each other in a loop:\n" + "\n".join(report)


def test_the_cycle_finder_finds_a_loop_through_a_function_level_import(tmp_path):
    """The cycle check can fail: a loop closed by a lazy import inside a function, and
    one through ``from package import module``, are both found; a package that imports
    its own submodules is not a loop."""
    pkg = tmp_path / "assocopt"
    (pkg / "sub").mkdir(parents=True)
    files = {"__init__.py": "from .sub import a\n",
             "sub/__init__.py": "from .a import f\nfrom .b import g\n",
             "sub/a.py": "from .b import g\ndef f():\n    return g()\n",
             "sub/b.py": "def g():\n    from . import a\n    return a\n",
             "c.py": "from .d import h\n", "d.py": "def h():\n    from .c import x\n",
             "e.py": "from .sub.a import f\n"}
    for rel, text in files.items():
        (pkg / rel).write_text(text)
    modules = {}
    for p in pkg.rglob("*.py"):
        parts = list(p.relative_to(tmp_path).with_suffix("").parts)
        modules[".".join(parts[:-1] if parts[-1] == "__init__" else parts)] = p
    graph = _import_graph(modules)
    assert graph["assocopt.sub.b"] == {"assocopt.sub.a"}          # from . import a
    assert _cycles(graph) == [["assocopt.c", "assocopt.d"], ["assocopt.sub.a", "assocopt.sub.b"]]
    (pkg / "sub/b.py").write_text("def g():\n    return 1\n")
    (pkg / "d.py").write_text("def h():\n    return 2\n")
    assert _cycles(_import_graph(modules)) == []


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


#: What a newcomer looks for, and the file that holds it; the README's Layout section
#: names each file and the folders on its way.
CONCEPTS = {
    "the S-D formulation": "model/formulation.py",
    "the S-D problem": "problems/problem.py",
    "the 2-D LAP": "solvers/twod/lap.py",
    "the HiGHS back end": "solvers/milp/highs.py",
    "solve": "solving/api.py",
    "the KLD cost": "tracking/costs/kld.py",
    "the dong2015 scenario": "tracking/scenarios/dong2015.py",
    "the lu2013 scenario": "tracking/scenarios/lu2013.py",
    "exact S-D solves by LP fixing": "solving/lp_fixing.py",
    "model files": "io/mps_lp.py",
    "localisation": "tracking/localisation/estimate.py",
    "the experiments' store": "experiments/store.py",
}


def test_each_concept_is_found_by_file_name():
    layout = (ROOT / "README.md").read_text(encoding="utf-8").split("## Layout", 1)[1]
    layout = layout.split("\n## ", 1)[0]
    for what, rel in CONCEPTS.items():
        assert (PKG / rel).is_file(), rel
        *folders, name = rel.split("/")
        assert f"`{name}`" in layout and all(f"{d}/`" in layout for d in folders), \
            f"README's Layout does not lead to {what} ({rel})"
    for rel in ("reproduce/lu2013/__init__.py", "reproduce/zhang2009/__init__.py"):
        assert (PKG / rel).is_file(), rel


def test_every_package_is_on_the_layout_page():
    """The README's Layout (also the site's layout page) names every package, at every
    depth (``solvers/twod/``, ``tracking/stonesoup/``), so a moved room shows there."""
    layout = (ROOT / "README.md").read_text(encoding="utf-8").split("## Layout", 1)[1]
    layout = layout.split("\n## ", 1)[0]
    packages = sorted(p.parent.relative_to(PKG).as_posix() for p in PKG.rglob("__init__.py")
                      if p.parent != PKG and "__pycache__" not in p.parts)
    missing = [rel for rel in packages if f"{rel.rsplit('/', 1)[-1]}/`" not in layout]
    assert not missing, f"packages the README's Layout does not name: {missing}"
    page = (ROOT / "docs" / "layout.md").read_text(encoding="utf-8")
    assert '"## Layout"' in page and "{include} ../README.md" in page


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
