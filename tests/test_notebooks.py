"""The notebooks in docs/notebooks are executed, so they cannot rot.

Each runs in a fresh Jupyter kernel (nbclient) from a scratch folder, finds the
stored instances through the installed package, and must not write into the repository.
"""

from __future__ import annotations

import os
from pathlib import Path

import pytest

nbformat = pytest.importorskip("nbformat")
nbclient = pytest.importorskip("nbclient")
pytest.importorskip("ipykernel")

ROOT = Path(__file__).resolve().parents[1]
NOTEBOOKS = sorted((ROOT / "docs" / "notebooks").glob("*.ipynb"))
_IGNORED = {"__pycache__", ".pytest_cache", ".hypothesis", ".git", ".ipynb_checkpoints"}


def _snapshot() -> dict[str, int]:
    files = {}
    for dirpath, dirnames, filenames in os.walk(ROOT):
        dirnames[:] = [d for d in dirnames if d not in _IGNORED]
        for f in filenames:
            p = os.path.join(dirpath, f)
            files[p] = os.stat(p).st_mtime_ns
    return files


def test_the_two_notebooks_exist():
    assert {p.name for p in NOTEBOOKS} >= {"first-solve.ipynb", "compare-backends.ipynb"}


@pytest.mark.parametrize("path", NOTEBOOKS, ids=lambda p: p.stem)
def test_notebook_is_stored_clean(path):
    nb = nbformat.read(path, as_version=4)
    nbformat.validate(nb)
    for cell in nb.cells:
        if cell.cell_type == "code":
            assert cell.outputs == [] and cell.execution_count is None, (
                f"{path.name}: store notebooks without outputs (clear them before saving)")


@pytest.mark.parametrize("path", NOTEBOOKS, ids=lambda p: p.stem)
def test_notebook_executes(path, tmp_path, monkeypatch):
    monkeypatch.setenv("PYTHONPATH", str(ROOT) + os.pathsep + os.environ.get("PYTHONPATH", ""))
    monkeypatch.setenv("MPLBACKEND", "module://matplotlib_inline.backend_inline")
    before = _snapshot()
    nb = nbformat.read(path, as_version=4)
    client = nbclient.NotebookClient(nb, timeout=300, kernel_name="python3",
                                     resources={"metadata": {"path": str(tmp_path)}})
    client.execute()                 # raises CellExecutionError naming the failing cell
    outputs = [o for c in nb.cells if c.cell_type == "code" for o in c.outputs]
    assert not [o for o in outputs if o.output_type == "error"]
    if path.stem == "compare-backends":
        assert any("image/png" in o.get("data", {}) for o in outputs), "no plot was drawn"
        text = "".join(o.get("text", "") for o in outputs)
        assert "all equal to the recorded optimum" in text
    assert _snapshot() == before, "executing the notebook changed files in the repository"
