"""A complete install: the stored instances ship inside the package, a non-editable
install of the wheel works from outside the checkout (whatever the base Python has),
and optional test helpers name the package to install."""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
import venv
from pathlib import Path

import pytest

from conftest import fresh_python

ROOT = Path(__file__).resolve().parents[1]
INSTANCES = ROOT / "instances"
PACKAGED = ROOT / "assocopt" / "data" / "instances"


def test_packaged_instances_equal_the_instances_folder():
    """assocopt/data/instances ships the stored instances to installed users: it must
    equal instances/ (json files and index.csv).

    Fix a failure with:  cp instances/*.json instances/index.csv assocopt/data/instances/
    """
    def files(folder: Path) -> dict[str, bytes]:
        return {p.name: p.read_bytes() for p in sorted(folder.iterdir())
                if p.suffix == ".json" or p.name == "index.csv"}
    canonical = files(INSTANCES)
    assert "index.csv" in canonical and len(canonical) > 5
    assert files(PACKAGED) == canonical


def test_package_data_globs_cover_the_shipped_files():
    """pyproject.toml's package-data patterns match every packaged instance file."""
    import fnmatch
    import tomllib

    patterns = tomllib.loads((ROOT / "pyproject.toml").read_text())["tool"]["setuptools"][
        "package-data"]["assocopt"]
    for p in PACKAGED.iterdir():
        rel = p.relative_to(ROOT / "assocopt").as_posix()
        assert any(fnmatch.fnmatch(rel, pat) for pat in patterns), rel


def test_installed_copies_are_found_without_a_checkout(monkeypatch, tmp_path):
    """Outside the checkout (no ./instances, no project folder) the default instance
    folder is the packaged one."""
    import assocopt.workflow.generate as gen
    from assocopt.testing import stored_instances

    monkeypatch.chdir(tmp_path)
    fake_module = tmp_path / "site" / "assocopt" / "workflow" / "generate.py"
    monkeypatch.setattr(gen, "__file__", str(fake_module))
    assert gen.default_instances_dir() == gen.PACKAGED_INSTANCES
    names = [p.name for p in stored_instances()]
    assert names == sorted(p.name for p in INSTANCES.glob("*.json"))
    assert gen.find_stored_instance("example-sd") == gen.PACKAGED_INSTANCES / "example-sd.json"
    assert gen.find_stored_instance("no-such") is None
    assert gen.find_stored_instance("../example-sd.json") is None


def test_problems_without_hypothesis_names_the_install():
    """Without hypothesis, the strategies raise an error that says what to install
    (simulated in a fresh interpreter by blocking the import)."""
    code = ("import sys\nsys.modules['hypothesis'] = None\n"
            "import assocopt.testing as t\n"
            "from assocopt.runtime.errors import MissingDependencyError\n"
            "for f in (t.problems, t.generated_problems):\n"
            "    try:\n        f()\n"
            "    except MissingDependencyError as exc:\n        print(exc)\n"
            "    else:\n        raise SystemExit('no error')\n"
            "print(t.random_problem.__name__)\n")
    out = fresh_python(code).splitlines()
    assert len(out) == 3
    for line in out[:2]:
        assert "pip install hypothesis" in line and "assocopt[dev]" in line
    assert out[0].startswith("assocopt.testing.problems()")
    assert out[1].startswith("assocopt.testing.generated_problems()")
    assert out[2] == "random_problem"           # the rest of the module works


def test_missing_dependency_error_is_an_import_error():
    from assocopt.runtime.errors import AssocoptError, MissingDependencyError
    assert issubclass(MissingDependencyError, ImportError)
    assert issubclass(MissingDependencyError, AssocoptError)


# ------------------------------------------------------------------ a real install
def _copy_source(dest: Path) -> Path:
    """The files a build needs, so pip's build never writes into the checkout."""
    src = dest / "src"
    shutil.copytree(ROOT / "assocopt", src / "assocopt",
                    ignore=shutil.ignore_patterns("__pycache__", "*.nbi", "*.nbc"))
    for name in ("pyproject.toml", "README.md"):
        shutil.copy2(ROOT / name, src / name)
    return src


def _notebook_script(path: Path) -> str:
    """The code cells of a notebook as one script (no magics in these notebooks)."""
    cells = json.loads(path.read_text())["cells"]
    return "\n\n".join("".join(c["source"]) for c in cells if c["cell_type"] == "code")


def _site_dirs() -> list[str]:
    """The running environment's site-packages folders, as this interpreter sees them."""
    import site

    dirs = list(site.getsitepackages())
    if site.ENABLE_USER_SITE:
        dirs.append(site.getusersitepackages())
    return [d for d in dirs if d in sys.path and os.path.isdir(d)]


def _build_wheel(src: Path, dest: Path, env: dict[str, str]) -> Path:
    """assocopt's wheel, built by the running interpreter from ``src`` with its own
    setuptools and wheel (the dev extra), without build isolation or downloads."""
    import importlib.util

    import setuptools
    if importlib.util.find_spec("wheel") is None or \
            tuple(int(v) for v in setuptools.__version__.split(".")[:2]) < (68, 0):
        pytest.skip("building the wheel needs setuptools>=68 and wheel: "
                    "pip install -e '.[dev]'")
    done = subprocess.run([sys.executable, "-m", "pip", "wheel", "--no-deps",
                           "--no-build-isolation", "--no-index", "--quiet",
                           "--wheel-dir", str(dest), str(src)],
                          env=env, capture_output=True, text=True, timeout=600)
    if done.returncode != 0 and "No module named pip" in done.stderr:
        pytest.skip("pip is not available to the test interpreter")
    assert done.returncode == 0, done.stderr[-2000:]
    (wheel,) = dest.glob("assocopt-*.whl")
    return wheel


@pytest.fixture(scope="module")
def installed(tmp_path_factory) -> dict[str, Path]:
    """A fresh venv with assocopt installed non-editable from a wheel of a copy of this
    checkout.  The venv sees the running environment's site-packages through a
    ``.pth`` file (numpy & co. and pip need no download), never the base
    interpreter's, so the test passes whatever the base Python has."""
    base = tmp_path_factory.mktemp("install")
    src = _copy_source(base)
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "PYTHONHOME")}
    env["PIP_DISABLE_PIP_VERSION_CHECK"] = "1"
    wheel = _build_wheel(src, base / "dist", env)
    env_dir = base / "venv"
    try:
        venv.EnvBuilder(with_pip=False).create(env_dir)
    except Exception as exc:  # pragma: no cover - platform without venv
        pytest.skip(f"cannot create a venv: {exc}")
    python = env_dir / ("Scripts" if os.name == "nt" else "bin") / "python"
    purelib = subprocess.run([str(python), "-c", "import sysconfig; "
                              "print(sysconfig.get_paths()['purelib'])"], env=env,
                             capture_output=True, text=True, check=True).stdout.strip()
    Path(purelib, "_assocopt_test_env.pth").write_text("\n".join(_site_dirs()) + "\n")
    done = subprocess.run([str(python), "-m", "pip", "install", "--no-deps", "--no-index",
                           "--ignore-installed", "--quiet", str(wheel)],
                          env=env, capture_output=True, text=True, timeout=600)
    assert done.returncode == 0, done.stderr[-2000:]
    work = base / "elsewhere"
    work.mkdir()
    script = python.parent / ("assocopt.exe" if os.name == "nt" else "assocopt")
    return {"python": python, "script": script, "work": work, "env": env,
            "venv": env_dir}


def _run(installed: dict, *argv: str) -> subprocess.CompletedProcess:
    return subprocess.run([str(a) for a in argv], cwd=installed["work"],
                          env=installed["env"], capture_output=True, text=True,
                          timeout=600)


def test_installed_package_is_the_one_imported(installed):
    """The venv's assocopt is the installed copy, not the editable checkout."""
    done = _run(installed, installed["python"], "-c",
                "import assocopt, assocopt.workflow.generate as g; print(assocopt.__file__); "
                "print(g.default_instances_dir())")
    assert done.returncode == 0, done.stderr
    where, folder = done.stdout.splitlines()
    venv_dir = str(installed["venv"].resolve())
    assert where.startswith(venv_dir) and "site-packages" in where
    assert folder.startswith(venv_dir) and folder.endswith(os.path.join("data",
                                                                        "instances"))


def test_installed_cli_lists_and_solves_stored_instances(installed):
    done = _run(installed, installed["script"], "instances")
    assert done.returncode == 0, done.stderr
    listed = {line.split()[0] for line in done.stdout.splitlines()[1:]}
    assert listed == {p.name for p in INSTANCES.glob("*.json")}
    done = _run(installed, installed["script"], "solve", "example-sd", "--json")
    assert done.returncode == 0, done.stderr
    rec = json.loads(done.stdout)
    assert rec["status"] == "optimal" and rec["matches_recorded_optimum"] is True
    path = installed["venv"].resolve()
    stored = next(path.glob("lib*/python*/site-packages/assocopt/data/instances/"
                            "example-2d-miss.json"), None) or \
        next(path.rglob("assocopt/data/instances/example-2d-miss.json"))
    done = _run(installed, installed["script"], "solve", stored)
    assert done.returncode == 0, done.stderr
    assert "(matches)" in done.stdout


def test_installed_stored_instances_helper(installed):
    done = _run(installed, installed["python"], "-c",
                "from assocopt.testing import stored_instances; "
                "print(len(stored_instances()))")
    assert done.returncode == 0, done.stderr
    assert int(done.stdout) == len(list(INSTANCES.glob("*.json")))


@pytest.mark.parametrize("name", ["first-solve", "compare-backends"])
def test_notebooks_run_from_the_install(installed, name):
    """Both notebooks' code runs with the installed package, outside the checkout."""
    pytest.importorskip("matplotlib")
    script = installed["work"] / f"{name}.py"
    script.write_text(_notebook_script(ROOT / "docs" / "notebooks" / f"{name}.ipynb"))
    env = dict(installed["env"], MPLBACKEND="Agg")
    done = subprocess.run([str(installed["python"]), str(script)], cwd=installed["work"],
                          env=env, capture_output=True, text=True, timeout=600)
    assert done.returncode == 0, done.stderr[-3000:]
