"""The API reference of the documentation site, generated from the package itself.

Sphinx extension (``docs/conf.py`` loads it).  When the configuration is read it writes
one page per public module under ``docs/api/generated/`` (ignored by git), whose
autosummary tables make one page per public name, all through the public import paths:

* the core (:data:`CORE`): ``assocopt``, ``assocopt.solvers``, ``assocopt.io``,
  ``assocopt.testing``, ``assocopt.experiments``; each documents its ``__all__`` at
  that path (``assocopt.solve``, never the module that happens to define it);
* ``assocopt.tracking`` and every public module under it (walked, so a new module gets
  a page): each documents its ``__all__``; a name a package only re-exports from one of
  its public submodules is documented once, at the submodule, and listed by the package.

Markdown links to a folder lose their link (there is no page to point to).  The
directive ``.. assocopt-backends::`` writes the back ends' capabilities and declared
options from the declarations (:func:`assocopt.solvers.registered` and each back end's
``options``), the same source as the page ``solver-options.md``.

:func:`public_api` is the list the site's test checks: every name in it has a page.
"""

from __future__ import annotations

import importlib
import inspect
import pkgutil
import re
from pathlib import Path
from types import ModuleType

#: Core modules documented at their public path, with a one-line title each.
CORE = {
    "assocopt": "Problems, solutions, solve, k-best and marginals",
    "assocopt.solvers": "Back-end registry and options",
    "assocopt.io": "Reading and writing instances and solutions",
    "assocopt.testing": "Checks and problem generators for your own tests",
    "assocopt.experiments": "Monte Carlo experiment runner",
}
#: Names of a core ``__all__`` that are not documented as objects.
SKIP = {"__version__", "solvers"}
TRACKING = "assocopt.tracking"
OUT = "api/generated"


def tracking_modules() -> list[str]:
    """``assocopt.tracking`` and every public module under it, sorted."""
    pkg = importlib.import_module(TRACKING)
    found = [TRACKING]
    for info in pkgutil.walk_packages(pkg.__path__, TRACKING + "."):
        if not any(part.startswith("_") for part in info.name.split(".")):
            found.append(info.name)
    return sorted(found)


def _public(mod: ModuleType) -> list[str]:
    if hasattr(mod, "__all__"):
        return [n for n in mod.__all__ if n not in SKIP]
    return sorted(n for n, v in vars(mod).items()
                  if not n.startswith("_") and getattr(v, "__module__", None) == mod.__name__
                  and (inspect.isclass(v) or inspect.isfunction(v)))


def _home(modname: str, name: str, modules: list[str]) -> str:
    """Where ``modname.name`` is documented: the shallowest public module that lists the
    very same object in its ``__all__`` (a package's ``__all__`` is its public face, so
    ``assocopt.tracking.stonesoup.AssocoptGNN`` is documented there, not in the module
    that happens to define it), else ``modname`` itself."""
    mod = importlib.import_module(modname)
    obj = getattr(mod, name)
    for parent in modules:
        if modname.startswith(parent + "."):
            pmod = importlib.import_module(parent)
            if name in getattr(pmod, "__all__", ()) and getattr(pmod, name, None) is obj:
                return parent
    if name in getattr(mod, "__all__", ()) and hasattr(mod, "__path__"):
        return modname
    for sub in modules:
        if sub.startswith(modname + ".") and sub != modname:
            submod = importlib.import_module(sub)
            if name in _public(submod) and getattr(submod, name, None) is obj:
                return _home(sub, name, modules)
    return modname


def public_api() -> dict[str, list[tuple[str, str]]]:
    """module -> [(name, home module)] for every documented module."""
    api = {m: [(n, m) for n in _public(importlib.import_module(m))] for m in CORE}
    modules = tracking_modules()
    for m in modules:
        api[m] = [(n, _home(m, n, modules)) for n in _public(importlib.import_module(m))]
    return api


def _relative(module: str, home: str) -> str:
    """``home`` as autosummary resolves it from ``module``: relative below, absolute
    above."""
    return home[len(module) + 1:] if home.startswith(module + ".") else home


def _title(text: str, char: str = "=") -> list[str]:
    return [text, char * len(text), ""]


def _module_page(module: str, entries: list[tuple[str, str]], title: str | None,
                 submodules: list[str]) -> str:
    head = f"``{module}``" + (f": {title}" if title else "")
    lines = _title(head) + [f".. automodule:: {module}", "   :no-members:", "",
                            f".. currentmodule:: {module}", ""]
    own = [n for n, home in entries if home == module]
    moved = [(n, home) for n, home in entries if home != module]
    if own:
        lines += [".. autosummary::", f"   :toctree: .", ""]
        lines += [f"   {n}" for n in own] + [""]
    if moved:
        lines += ["Also importable from here (documented at the path shown):", "",
                  ".. autosummary::", ""]
        lines += [f"   {_relative(module, home)}.{n}" for n, home in moved] + [""]
    if submodules:
        lines += _title("Submodules", "-") + [".. toctree::", "   :maxdepth: 1", ""]
        lines += [f"   {s}" for s in submodules] + [""]
    return "\n".join(lines)


def write_pages(srcdir: Path) -> list[str]:
    """Write one page per public module (autosummary writes the stubs of its names
    from ``docs/_templates/autosummary``); returns the module names."""
    out = srcdir / OUT
    out.mkdir(parents=True, exist_ok=True)
    api = public_api()
    for module, entries in api.items():
        children = [m for m in api if m.startswith(module + ".")
                    and "." not in m[len(module) + 1:]] if module.startswith(TRACKING) else []
        text = _module_page(module, entries, CORE.get(module), children)
        path = out / f"{module}.rst"
        if not path.exists() or path.read_text() != text:   # unchanged pages stay cached
            path.write_text(text)
    return list(api)


# ---------------------------------------------------------------- back ends
def _row(cells: list[str]) -> list[str]:
    first, *rest = cells
    return [f"   * - {first}"] + [f"     - {c}" for c in rest]


def _table(header: list[str], rows: list[list[str]]) -> list[str]:
    lines = [".. list-table::", "   :header-rows: 1", ""]
    for r in [header] + rows:
        lines += _row([c.replace("\n", " ") or " " for c in r])
    return lines + [""]


def _lit(text: str) -> str:
    return f"``{text}``" if text else " "


def backends_rst() -> list[str]:
    """reStructuredText of every registered back end: capabilities and options."""
    from assocopt.solvers import options, registered

    yes = {True: "yes", False: "no"}
    caps = [[f"``{name}``", yes[c.integer], yes[c.lp], str(c.max_ndim or "any"),
             yes[c.exact], yes[c.gives_bound], yes[c.supports_time_limit],
             c.distribution or c.module or "(numpy / own)"]
            for name, c in sorted(registered().items())]
    lines = _title("Capabilities", "-") + _table(
        ["back end", "integer solution", "LP relaxation", "axes", "exact", "bound",
         "time limit", "package"], caps)
    opt_head = ["option", "accepts", "default", "description"]
    lines += _title("Common options (every back end)", "-") + _table(
        opt_head, [[_lit(o.name), o.describe(), _lit(o.default_text()), o.doc]
                   for o in options.COMMON_OPTIONS])
    for name, cls in sorted(registered().items()):
        lines += _title(f"``{name}``", "-") + [cls.description or "", ""]
        rows = [[_lit(n), a, _lit(d), doc] for n, a, d, doc in options.options_table(cls)]
        lines += _table(opt_head, rows) if rows else ["No options of its own.", ""]
        if cls.native_options:
            lines += [f"Also accepts {cls.native_options}, passed through by name.", ""]
    return lines


def _directive():
    from docutils import nodes
    from docutils.statemachine import StringList
    from sphinx.util.docutils import SphinxDirective
    from sphinx.util.nodes import nested_parse_with_titles

    class BackendsDirective(SphinxDirective):
        """``.. assocopt-backends::``: the back ends and their declared options."""

        def run(self) -> list:
            node = nodes.section()
            node.document = self.state.document
            nested_parse_with_titles(self.state, StringList(backends_rst(), "<backends>"),
                                     node)
            return node.children

    return BackendsDirective


def _on_config(app, config) -> None:
    write_pages(Path(app.srcdir))


def _no_type_doc(app, what, name, obj, options, lines) -> None:
    """A constant without a ``#:`` comment has no docstring of its own: drop the one of
    its type (``dict() -> new empty dictionary``) that autodoc would show."""
    doc = getattr(type(obj), "__doc__", None)
    if what in ("data", "attribute") and not inspect.isclass(obj) and lines \
            and isinstance(doc, str):
        own = inspect.cleandoc(doc).splitlines()
        def body(text: list[str]) -> list[str]:
            return [ln.rstrip() for ln in text if ln.strip()]
        if body(lines) == body(own):
            lines.clear()


_DIR_LINK = re.compile(r"\[([^\]]+)\]\(([\w.-]+/)\)")


def _folder_links(app, docname: str, source: list[str]) -> None:
    """A Markdown link to a folder (``[`lu2013/`](lu2013/)``, which GitHub lists) has no
    page on the site: keep its text, drop the link."""
    base = (Path(app.srcdir) / docname).parent

    def plain(m: re.Match) -> str:
        return m.group(1) if (base / m.group(2)).is_dir() else m.group(0)

    if str(app.env.doc2path(docname)).endswith(".md"):
        source[0] = _DIR_LINK.sub(plain, source[0])


def setup(app):
    app.connect("config-inited", _on_config)
    app.connect("autodoc-process-docstring", _no_type_doc, priority=100)   # before numpydoc
    app.connect("source-read", _folder_links)
    app.add_directive("assocopt-backends", _directive())
    return {"parallel_read_safe": True, "parallel_write_safe": True}
