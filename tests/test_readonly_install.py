"""A read-only install: a non-editable copy of assocopt whose folders, and whose user's
home, the user running it cannot write.  numba then finds no place for its disk cache
next to the kernels nor in the home; the CLI and the API must still solve (the kernels
cache in a private temporary folder, said once on stderr), with the right answers.

Root ignores file permissions, so as root the programs run with the capabilities that
let root do so (``CAP_DAC_OVERRIDE``, ``CAP_DAC_READ_SEARCH``, ``CAP_FOWNER``) removed
by ``setpriv``: the files are root's own, their write bits cleared, so they are then as
read-only to the program as to any other user; failing that, as the user ``nobody``.
Not root: clearing the write bits is enough.
"""

from __future__ import annotations

import json
import os
import shutil
import stat
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]

#: Capabilities that let root read and write whatever the permissions say.
_CAPS = "-dac_override,-dac_read_search,-fowner"


def _install(base: Path) -> Path:
    """``pip install --target`` of a copy of this checkout (no build isolation, no
    downloads): the folder to put on PYTHONPATH."""
    src = base / "src"
    shutil.copytree(ROOT / "assocopt", src / "assocopt",
                    ignore=shutil.ignore_patterns("__pycache__", "*.nbi", "*.nbc"))
    for name in ("pyproject.toml", "README.md"):
        shutil.copy2(ROOT / name, src / name)
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "PYTHONHOME")}
    env["PIP_DISABLE_PIP_VERSION_CHECK"] = "1"
    site = base / "site"
    done = subprocess.run([sys.executable, "-m", "pip", "install", "--no-deps",
                           "--no-build-isolation", "--no-index", "--quiet",
                           "--target", str(site), str(src)],
                          env=env, capture_output=True, text=True, timeout=600)
    if done.returncode != 0 and "No module named pip" in done.stderr:
        pytest.skip("pip is not available to the test interpreter")
    assert done.returncode == 0, done.stderr[-2000:]
    shutil.rmtree(src)
    return site


def _read_only(*folders: Path) -> None:
    """Clear every write bit under ``folders`` (readable and searchable by all)."""
    for folder in folders:
        for path in [folder, *folder.rglob("*")]:
            mode = path.lstat().st_mode
            if stat.S_ISLNK(mode):
                continue
            keep = stat.S_IMODE(mode) & ~0o222 | 0o444
            if stat.S_ISDIR(mode) or mode & 0o111:
                keep |= 0o111
            path.chmod(keep)


def _unprivileged(probe: Path) -> list[str]:
    """The command prefix that runs a program unable to write into the read-only
    folder ``probe`` (see the module docstring); skips when there is none."""
    def cannot_write(prefix: list[str]) -> bool:
        code = (f"import os\ntry:\n    open(os.path.join({str(probe)!r}, 'x'), 'w')\n"
                "except PermissionError:\n    print('denied')\n")
        try:
            done = subprocess.run(prefix + [sys.executable, "-c", code],
                                  capture_output=True, text=True, timeout=60)
        except OSError:
            return False
        return done.returncode == 0 and done.stdout.strip() == "denied"

    if os.geteuid() != 0:
        if cannot_write([]):
            return []
        pytest.skip("the folders stay writable after chmod (a file system without "
                    "permissions?)")
    setpriv = shutil.which("setpriv")
    candidates = []
    if setpriv:
        candidates.append([setpriv, "--inh-caps=-all", f"--bounding-set={_CAPS}", "--"])
        candidates.append([setpriv, "--reuid=nobody", "--regid=nogroup", "--clear-groups",
                           "--"])
    runuser = shutil.which("runuser")
    if runuser:
        candidates.append([runuser, "-u", "nobody", "--"])
    for prefix in candidates:
        if cannot_write(prefix):
            return prefix
    pytest.skip("running as root, and neither setpriv (dropping the capabilities that "
                "bypass file permissions, or switching to nobody) nor runuser can run "
                "this interpreter without them")


@pytest.fixture(scope="module")
def readonly() -> dict:
    """The read-only install, its read-only home and the command prefix to use (in a
    folder of the system's temporary folder that every user can search: pytest's own
    may be private to its user)."""
    import tempfile

    base = Path(tempfile.mkdtemp(prefix="assocopt-readonly-"))
    try:
        base.chmod(0o755)
        site = _install(base)
        home = base / "home"
        (home / "work").mkdir(parents=True)
        _read_only(site, home)
        prefix = _unprivileged(site)
        env = {k: v for k, v in os.environ.items()
               if not k.startswith("NUMBA_") and k not in ("PYTHONPATH", "PYTHONHOME",
                                                            "XDG_CACHE_HOME")}
        # compiled: the point is numba's cache (a small problem would run interpreted)
        env.update(HOME=str(home), PYTHONPATH=str(site), PYTHONDONTWRITEBYTECODE="1",
                   ASSOCOPT_JIT="compiled")
        yield {"site": site, "home": home, "prefix": prefix, "env": env}
    finally:
        for path in [base, *base.rglob("*")]:
            if not path.is_symlink():
                path.chmod(path.stat().st_mode | 0o700)
        shutil.rmtree(base, ignore_errors=True)


def _run(ro: dict, *argv: str) -> subprocess.CompletedProcess:
    return subprocess.run(ro["prefix"] + [sys.executable, *argv], cwd=ro["home"] / "work",
                          env=ro["env"], capture_output=True, text=True, timeout=600)


def _said_once(stderr: str) -> None:
    """The fallback cache is named once, and no error is printed."""
    lines = [ln for ln in stderr.splitlines() if "numba kernels are cached in" in ln]
    assert len(lines) == 1, stderr
    assert "not writable" in lines[0] and "for this process only" in lines[0]
    assert "error" not in stderr.lower(), stderr


def test_the_install_and_the_home_are_read_only(readonly):
    """The setting itself: the program cannot write into the package nor the home."""
    code = ("import os, sys\n"
            "for d in sys.argv[1:]:\n"
            "    print(os.access(d, os.W_OK), end=' ')\n")
    kernels = readonly["site"] / "assocopt" / "solvers" / "kernels"
    done = _run(readonly, "-c", code, str(kernels), str(readonly["home"]))
    assert done.returncode == 0, done.stderr
    assert done.stdout.split() == ["False", "False"]


@pytest.mark.parametrize("solver", [
    None, "lagrangian-exact",
    pytest.param("bnb", marks=pytest.mark.slow)])     # bnb compiles for ~40 s CPU cold
def test_cli_solves_a_stored_instance(readonly, solver):
    """``python -m assocopt solve sd-bearing-3s`` (the default path and compiled back
    ends) exits 0 with the recorded optimum (numba raised 'no locator available' at the
    kernels' import: exit 4).  Any compiled back end imports every kernel module it
    uses; ``lagrangian-exact`` compiles in seconds, ``bnb`` (slow run) in tens."""
    argv = ["-m", "assocopt", "solve", "sd-bearing-3s", "--json"]
    if solver:
        argv += ["--solver", solver]
    done = _run(readonly, *argv)
    assert done.returncode == 0, done.stderr[-3000:]
    rec = json.loads(done.stdout)
    assert rec["status"] == "optimal" and rec["matches_recorded_optimum"] is True
    if solver:
        assert rec["solver"] == solver
        _said_once(done.stderr)


def test_a_small_problem_needs_no_cache_at_all(readonly):
    """By default (``ASSOCOPT_JIT`` unset) a small ``bnb`` solve in the read-only
    install runs its kernels interpreted: no cache is looked for, nothing is said."""
    env = {k: v for k, v in readonly["env"].items() if k != "ASSOCOPT_JIT"}
    done = subprocess.run(readonly["prefix"] + [
        sys.executable, "-m", "assocopt", "solve", "sd-bearing-3s", "--json", "--solver",
        "bnb"], cwd=readonly["home"] / "work", env=env, capture_output=True, text=True,
        timeout=600)
    assert done.returncode == 0, done.stderr[-3000:]
    rec = json.loads(done.stdout)
    assert rec["status"] == "optimal" and rec["matches_recorded_optimum"] is True
    assert done.stderr == ""


_API = textwrap.dedent("""
    import json, sys
    import numpy as np
    import assocopt
    from assocopt import AssignmentProblem, kbest, marginals, solve
    from assocopt.testing import random_problem

    out = {"file": assocopt.__file__}
    rng = np.random.default_rng(3)
    # a gated S-D problem: sparse, every real index covered by its single
    sd = random_problem(rng, "sd", sizes=(4, 3, 4), keep=0.3)
    full = sys.argv[1] == "full"
    sol = solve(sd, "auto" if full else "lagrangian-exact")
    ref = solve(sd, "highs")
    out["sd"] = [sol.status.value, sol.objective, ref.objective, sol.solver]
    if full:
        p2 = AssignmentProblem.two_d(rng.random((4, 5)), row_miss=0.6, col_miss=0.4)
        ranked = kbest(p2, 6)
        out["kbest"] = [s.objective for s in ranked]
        out["kbest_solver"] = ranked[0].solver
        out["best"] = solve(p2, "bruteforce").objective
        m = marginals(p2, method="exact")
        e = marginals(p2, method="enumerate")
        out["marginals"] = [bool(m.exhaustive),
                            float(np.abs(m.candidate - e.candidate).max())]
    from assocopt.solvers.kernels import hungarian, jit
    out["policy"] = jit.cache_policy().kind
    out["cache_path"] = hungarian.hungarian._cache._cache_path
    out["folder"] = jit.cache_policy().folder
    print(json.dumps(out))
""")


@pytest.mark.parametrize("paths", ["short", pytest.param("full", marks=pytest.mark.slow)])
def test_api_solves_ranks_and_marginalises(readonly, paths):
    """The API in the read-only setting: a gated S-D solve (a compiled path, against
    HiGHS; the slow run also ``auto``'s route, ``kbest`` against brute force and exact
    ``marginals`` against enumeration, each compiling for tens of seconds cold); the
    kernels cache in the private temporary folder, chosen before numba picked their
    locator."""
    done = _run(readonly, "-c", _API, paths)
    assert done.returncode == 0, done.stderr[-3000:]
    out = json.loads(done.stdout.splitlines()[-1])
    assert out["file"].startswith(str(readonly["site"]))
    status, obj, ref, solver = out["sd"]
    assert status == "optimal" and abs(obj - ref) <= 1e-9 * max(1.0, abs(ref))
    assert solver != "highs"
    if paths == "full":
        objs = out["kbest"]
        assert len(objs) == 6 and objs == sorted(objs) and out["kbest_solver"] == "murty2d"
        assert abs(objs[0] - out["best"]) <= 1e-12
        exhaustive, diff = out["marginals"]
        assert exhaustive and diff <= 1e-12
    assert out["policy"] == "temporary"
    assert out["cache_path"].startswith(out["folder"])
    assert not Path(out["folder"]).exists()          # removed at exit
    _said_once(done.stderr)
