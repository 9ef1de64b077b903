"""Every docstring example in the package runs, one test per module that has any.

Equivalent to ``pytest --doctest-modules assocopt`` but part of the default run
(``python -m pytest``), so an example that goes stale fails the suite.
"""

from __future__ import annotations

import doctest
import importlib
import pkgutil

import pytest

import assocopt

#: Modules that cannot be imported here (none today); named so that the list of
#: modules checked below is complete by construction.
_SKIP: tuple[str, ...] = ()


def _modules() -> list[str]:
    names = [assocopt.__name__]
    names += [m.name for m in pkgutil.walk_packages(assocopt.__path__, "assocopt.")]
    return sorted(n for n in names if n not in _SKIP and not n.endswith("__main__"))


def _with_examples() -> list[str]:
    finder = doctest.DocTestFinder(exclude_empty=True)
    out = []
    for name in _modules():
        module = importlib.import_module(name)
        if any(t.examples for t in finder.find(module, name)):
            out.append(name)
    return out


MODULES = _with_examples()


def test_examples_are_found():
    # the package documents its main entry points by example: if the walk above
    # stopped finding them, the parametrised test below would silently shrink
    assert {"assocopt.solving.api", "assocopt.problems.problem", "assocopt.testing",
            "assocopt.solvers.options"} <= set(MODULES)
    assert sum(len(t.examples) for m in MODULES
               for t in doctest.DocTestFinder().find(importlib.import_module(m), m)) >= 48


@pytest.mark.parametrize("name", MODULES)
def test_docstring_examples_run(name, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)     # examples that write files write them here
    module = importlib.import_module(name)
    flags = doctest.ELLIPSIS | doctest.NORMALIZE_WHITESPACE
    runner = doctest.DocTestRunner(optionflags=flags)
    for test in doctest.DocTestFinder().find(module, name):
        runner.run(test, out=lambda text: None)
    result = runner.summarize(verbose=False)
    if result.failed:
        report = []
        r2 = doctest.DocTestRunner(optionflags=flags)
        for test in doctest.DocTestFinder().find(module, name):
            r2.run(test, out=report.append)
        pytest.fail(f"{result.failed} of {result.attempted} examples failed in {name}:\n"
                    + "".join(report))
