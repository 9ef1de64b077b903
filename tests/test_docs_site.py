"""The documentation site builds without a warning and holds together.

One build (a copy of ``docs/`` in a scratch folder, so the repository is left as it
was) with ``python -m sphinx -W --keep-going -b html``, then: every internal link and
image of every page resolves (fragments included), every public name has an API page,
every back end and declared option is on the back-ends page, the gallery's figures and
the notebooks' outputs are in the site, and no Markdown is left unrendered.

Marked ``docs`` (a few minutes: it runs the notebooks and the gallery); the default run
skips it and CI runs it with ``python -m pytest -m docs``.
"""

from __future__ import annotations

import importlib
import os
import re
import shutil
import subprocess
import sys
from html.parser import HTMLParser
from pathlib import Path
from urllib.parse import unquote, urlsplit

import pytest

pytest.importorskip("sphinx")
pytest.importorskip("myst_nb")
pytest.importorskip("sphinx_gallery")
pytest.importorskip("numpydoc")
pytest.importorskip("pydata_sphinx_theme")

pytestmark = pytest.mark.docs

ROOT = Path(__file__).resolve().parents[1]
DOCS = ROOT / "docs"
#: What the build writes into its source folder (ignored by git).
GENERATED = ("_build", "auto_examples", "api/generated", "sg_execution_times.rst")


def _sources_only(folder: str, names: list[str]) -> list[str]:
    """copytree's filter: leave out what a build generated and caches."""
    rel = Path(folder).relative_to(DOCS)
    skip = {"__pycache__", ".ipynb_checkpoints"}
    skip |= {Path(g).name for g in GENERATED if Path(g).parent == rel}
    return [n for n in names if n in skip]


@pytest.fixture(scope="module")
def site(tmp_path_factory) -> Path:
    """Build the site from a copy of docs/; returns the HTML folder."""
    work = tmp_path_factory.mktemp("site")
    src = work / "docs"
    shutil.copytree(DOCS, src, ignore=_sources_only)
    shutil.copy(ROOT / "README.md", work / "README.md")     # docs/layout.md includes it
    out = work / "html"
    env = {k: v for k, v in os.environ.items() if k != "MPLBACKEND"}   # notebooks: inline
    env["PYTHONPATH"] = str(ROOT) + os.pathsep + os.environ.get("PYTHONPATH", "")
    run = subprocess.run([sys.executable, "-m", "sphinx", "-W", "--keep-going", "-q",
                          "-b", "html", str(src), str(out)],
                         cwd=work, env=env, capture_output=True, text=True)
    assert run.returncode == 0, f"the site did not build cleanly:\n{run.stderr[-6000:]}"
    return out


class _Page(HTMLParser):
    """The links, images and ids of one HTML page, and its text outside code."""

    def __init__(self) -> None:
        super().__init__()
        self.links: list[str] = []
        self.images: list[str] = []
        self.ids: set[str] = set()
        self.dead: list[str] = []          # references Sphinx left pointing nowhere
        self.text: list[str] = []
        self._code = 0

    def handle_starttag(self, tag, attrs):
        a = dict(attrs)
        if a.get("id"):
            self.ids.add(a["id"])
        if tag == "a" and a.get("href"):
            self.links.append(a["href"])
            cls = (a.get("class") or "").split()
            if a["href"] == "#" and "reference" in cls and not {"current", "nav-link"} & set(cls):
                self.dead.append(a["href"])
        if tag == "img" and a.get("src"):
            self.images.append(a["src"])
        if tag in ("pre", "code", "script", "style", "textarea"):
            self._code += 1

    def handle_endtag(self, tag):
        if tag in ("pre", "code", "script", "style", "textarea") and self._code:
            self._code -= 1

    def handle_data(self, data):
        if not self._code:
            self.text.append(data)


def _pages(site: Path) -> dict[Path, _Page]:
    pages = {}
    for f in sorted(site.rglob("*.html")):
        p = _Page()
        p.feed(f.read_text(encoding="utf-8"))
        pages[f] = p
    return pages


@pytest.fixture(scope="module")
def pages(site) -> dict[Path, _Page]:
    return _pages(site)


def _internal(url: str) -> bool:
    parts = urlsplit(url)
    return not parts.scheme and not parts.netloc and not url.startswith(("mailto:", "javascript:"))


def test_every_internal_link_and_image_resolves(site, pages):
    broken = []
    for f, page in pages.items():
        broken += [f"{f.relative_to(site)}: a reference to nowhere (href='#')"] * len(page.dead)
        for kind, urls in (("link", page.links), ("image", page.images)):
            for url in urls:
                if not _internal(url):
                    continue
                parts = urlsplit(url)
                target = (f.parent / unquote(parts.path)).resolve() if parts.path else f
                if target.is_dir():
                    target = target / "index.html"
                rel = f.relative_to(site)
                if not target.is_file():
                    broken.append(f"{rel}: {kind} {url} (no such file)")
                elif parts.fragment and target.suffix == ".html" and target in pages \
                        and unquote(parts.fragment) not in pages[target].ids:
                    broken.append(f"{rel}: {kind} {url} (no anchor #{parts.fragment})")
    assert not broken, "\n".join(broken[:50])


def test_the_checker_sees_a_broken_link(tmp_path):
    (tmp_path / "a.html").write_text('<a href="b.html#x">b</a><img src="gone.png">'
                                     '<a href="a.html#top">me</a><p id="top"></p>'
                                     '<a class="reference internal" href="#">x</a>')
    (tmp_path / "b.html").write_text('<p id="y"></p>')
    pages = _pages(tmp_path)
    page = pages[tmp_path / "a.html"]
    assert page.images == ["gone.png"]
    assert page.links == ["b.html#x", "a.html#top", "#"] and page.dead == ["#"]
    assert "x" not in pages[tmp_path / "b.html"].ids and "top" in page.ids


def _public_api():
    sys.path.insert(0, str(DOCS / "_ext"))
    try:
        return importlib.import_module("assocopt_api").public_api()
    finally:
        sys.path.remove(str(DOCS / "_ext"))


def test_every_public_name_has_a_page(site):
    api = _public_api()
    # the list itself covers the core's __all__ and every public tracking module
    for module in ("assocopt", "assocopt.solvers", "assocopt.io", "assocopt.testing",
                   "assocopt.experiments"):
        names = set(importlib.import_module(module).__all__) - {"__version__", "solvers"}
        assert {n for n, _ in api[module]} == names, module
    for module in ("assocopt.tracking.stonesoup", "assocopt.tracking.gating",
                   "assocopt.tracking.costs.kinematic", "assocopt.tracking.scenarios.simulate"):
        assert {n for n, _ in api[module]} == set(importlib.import_module(module).__all__)
    gen = site / "api" / "generated"
    missing = [m for m in api if not (gen / f"{m}.html").is_file()]
    missing += [f"{home}.{n}" for entries in api.values() for n, home in entries
                if not (gen / f"{home}.{n}.html").is_file()]
    assert not missing, f"no page for: {missing[:40]}"
    for name in ("assocopt.solve", "assocopt.AssignmentProblem", "assocopt.Solution",
                 "assocopt.kbest", "assocopt.marginals", "assocopt.io.read_instance",
                 "assocopt.testing.assert_optimal", "assocopt.experiments.run_experiment",
                 "assocopt.tracking.stonesoup.AssocoptGNN",
                 "assocopt.tracking.stonesoup.AssocoptKBest"):
        assert (gen / f"{name}.html").is_file(), name


def test_the_solve_page_shows_its_docstring(pages, site):
    page = pages[site / "api" / "generated" / "assocopt.solve.html"]
    text = " ".join(page.text)
    assert "Parameters" in text and "Returns" in text
    assert "solver" in text and "relax" in text


def test_every_back_end_and_option_is_on_the_backends_page(pages, site):
    from assocopt.solvers import options, registered

    html = (site / "api" / "backends.html").read_text(encoding="utf-8")
    literal = '<span class="pre">{}</span>'.format
    for name, cls in registered().items():
        assert f'<h2><code class="docutils literal notranslate">{literal(name)}' in html, name
        for o in cls.options:
            assert literal(o.name) in html, (name, o.name)
    for o in options.COMMON_OPTIONS:
        assert literal(o.name) in html


def test_the_gallery_figures_are_in_the_site(site, pages):
    examples = sorted((DOCS / "gallery").rglob("plot_*.py"))
    assert len(examples) >= 9
    for ex in examples:
        rel = ex.relative_to(DOCS / "gallery").with_suffix(".html")
        html = site / "auto_examples" / rel
        figs = [src for src in pages[html].images if "sphx_glr_" + ex.stem in src]
        assert figs, f"{rel}: no figure"
        for src in figs:
            assert (html.parent / src).resolve().stat().st_size > 5000, src


def test_the_notebooks_render_with_their_outputs(site, pages):
    for name in ("first-solve", "compare-backends"):
        html = site / "notebooks" / f"{name}.html"
        source = html.read_text(encoding="utf-8")
        assert "cell_output" in source, f"{name}: no outputs"
    plot = [s for s in pages[site / "notebooks" / "compare-backends.html"].images
            if s.endswith(".png")]
    assert plot, "compare-backends: the plot is missing"


_RAW_MARKDOWN = re.compile(r"\]\([^)\s]+\)|^#{1,6} |^```|!\[", re.M)


def test_no_markdown_left_unrendered(site, pages):
    md_pages = [p.relative_to(DOCS).with_suffix(".html")
                for p in DOCS.rglob("*.md") if "_build" not in p.parts and p.name != "README.md"]
    assert len(md_pages) >= 15
    raw = []
    for rel in md_pages:
        text = "".join(pages[site / rel].text)
        raw += [f"{rel}: {m.group(0)!r}" for m in _RAW_MARKDOWN.finditer(text)]
    assert not raw, "\n".join(raw[:30])
    home = " ".join(pages[site / "index.html"].text)
    assert "User guide" in home and "zhang2009" in home    # docs/README.md included


def test_the_raw_markdown_pattern_can_fail():
    for text in ("see [guide](guide.md)", "## Heading", "```python", "![fig](a.png)"):
        assert _RAW_MARKDOWN.search(text), text
    for text in ("a (b) [c]", "x # y", "f(x)[0]"):
        assert not _RAW_MARKDOWN.search(text), text


def test_constants_do_not_show_the_docstring_of_their_type(site, pages):
    """A tuple or dict constant without a ``#:`` comment shows no text rather than
    ``tuple``'s or ``dict``'s own docstring."""
    typed = [f.relative_to(site) for f, page in pages.items()
             if any(s in " ".join(page.text) for s in ("Built-in immutable sequence",
                                                       "new empty dictionary"))]
    assert not typed, typed[:20]
