"""The kernels' ``njit`` (assocopt/solvers/kernels/jit.py) and the compile note of
:func:`assocopt.solvers.kernels.ensure`, on a one-line kernel (compiled in well under
a second) written into a temporary module, each case in a fresh interpreter."""

from __future__ import annotations

import json
import os
import subprocess
import sys
import tempfile
import textwrap
from pathlib import Path

from test_readonly_install import _read_only, _unprivileged

ROOT = Path(__file__).resolve().parents[1]

_KERNEL = textwrap.dedent("""
    from assocopt.solvers.kernels.jit import njit

    @njit(cache=True)
    def twice(x):
        return 2.0 * x
""")

_RUN = textwrap.dedent("""
    import json, logging, sys
    logging.basicConfig(level=logging.INFO, format="LOG %(levelname)s %(message)s")
    sys.path.insert(0, sys.argv[1])
    import tinykernel
    from assocopt.solvers.kernels import ensure, jit, spent
    ensure(tinykernel.twice, 1.5)
    print(json.dumps({"value": tinykernel.twice(1.5), "policy": jit.cache_policy().kind,
                      "folder": jit.cache_policy().folder,
                      "path": tinykernel.twice._cache._cache_path,
                      "spent": spent()}))
""")


def _run(folder: Path, env: dict, prefix: list[str] = ()) -> tuple[dict, list[str]]:
    done = subprocess.run([*prefix, sys.executable, "-c", _RUN, str(folder)], env=env,
                          capture_output=True, text=True, timeout=300, cwd=folder)
    assert done.returncode == 0, done.stderr[-3000:]
    logs = [ln for ln in done.stderr.splitlines() if ln.startswith("LOG ")]
    return json.loads(done.stdout.splitlines()[-1]), logs


def _env(**extra: str) -> dict:
    env = {k: v for k, v in os.environ.items() if not k.startswith("NUMBA_")}
    env.update(PYTHONPATH=str(ROOT), **extra)
    return env


def test_compile_note_once_when_cold_and_none_when_cached(tmp_path):
    """With an empty NUMBA_CACHE_DIR the first ensure() says one line before it
    compiles; a second process finds the kernel on disk, loads it and says nothing."""
    (tmp_path / "tinykernel.py").write_text(_KERNEL)
    env = _env(NUMBA_CACHE_DIR=str(tmp_path / "cache"))
    cold, logs = _run(tmp_path, env)
    assert cold["value"] == 3.0 and cold["policy"] == "numba"
    assert cold["path"].startswith(str(tmp_path / "cache"))
    notes = [ln for ln in logs if "compiling numba kernels" in ln]
    assert len(notes) == 1 and notes[0].startswith("LOG WARNING") and "twice" in notes[0]
    assert cold["spent"][0] > 0 and cold["spent"][1] == 0
    warm, logs = _run(tmp_path, env)
    assert warm["value"] == 3.0
    assert not [ln for ln in logs if "compiling" in ln]
    assert warm["spent"][0] == 0 and warm["spent"][1] > 0


def test_read_only_source_and_home_fall_back_to_the_user_cache():
    """The kernel's folder not writable, XDG_CACHE_HOME writable: the cache goes to
    $XDG_CACHE_HOME/assocopt/numba (decided before numba picked the locator), said
    once at INFO; the folder survives the process (unlike the temporary one)."""
    base = Path(tempfile.mkdtemp(prefix="assocopt-jit-"))
    try:
        base.chmod(0o755)
        src = base / "src"
        src.mkdir()
        (src / "tinykernel.py").write_text(_KERNEL)
        xdg = base / "xdg"
        xdg.mkdir()
        xdg.chmod(0o777)
        home = base / "home"
        home.mkdir()
        _read_only(src, home)
        prefix = _unprivileged(src)
        env = _env(HOME=str(home), XDG_CACHE_HOME=str(xdg), PYTHONDONTWRITEBYTECODE="1")
        out, logs = _run(src, env, prefix)
        assert out["value"] == 3.0 and out["policy"] == "numba"   # jit.py's folder is ours
        assert out["path"].startswith(str(xdg / "assocopt" / "numba"))
        said = [ln for ln in logs if "numba kernels are cached in" in ln]
        assert len(said) == 1 and said[0].startswith("LOG INFO")
        assert str(xdg / "assocopt" / "numba") in said[0]
        assert any((xdg / "assocopt" / "numba").rglob("*.nbi"))
    finally:
        for path in [base, *base.rglob("*")]:
            if not path.is_symlink():
                path.chmod(path.stat().st_mode | 0o700)
        import shutil
        shutil.rmtree(base, ignore_errors=True)
