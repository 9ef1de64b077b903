"""Writing files atomically: instances (JSON v1), solutions, any text or JSON.

:func:`replace_atomically` writes through a temporary file and ``os.replace``, so
an interrupted write never leaves a partial file; :func:`write_text_atomically`,
:func:`write_json_atomically`, :func:`write_instance` and :func:`write_solution` use
it (the one atomic writer of the project).  :func:`jsonable` is the one JSON
sanitiser (numpy types to Python, non-finite floats to strings or ``null``).  The
JSON text of an instance comes from :func:`~.json_format.instance_to_json`.
"""

from __future__ import annotations

import errno
import json
import math
import os
import tempfile
from pathlib import Path
from typing import Any

import numpy as np

from ..problems.problem import AssignmentProblem
from ..model.solution import Solution
from .json_format import instance_to_json


def replace_atomically(path: str | os.PathLike[str], write: Any) -> None:
    """Call ``write(tmp_path)`` on a temporary file beside ``path``, then move it into
    place with ``os.replace``: an interrupted write never leaves a partial file.

    The temporary file is removed on any exception, Ctrl-C included (the CLI turns
    SIGTERM / SIGHUP into the same unwinding; only SIGKILL can leave it behind), and
    every error names ``path``, the user's own name, never the temporary one.
    """
    path = Path(path)
    directory = path.parent if str(path.parent) else Path(".")
    if not directory.is_dir():
        why = "is not a folder" if directory.exists() else "does not exist"
        raise FileNotFoundError(errno.ENOENT, f"cannot write here: the folder {directory} "
                                              f"{why}", str(path))
    if path.is_dir():
        raise IsADirectoryError(errno.EISDIR, "is a folder, not a file name", str(path))
    tmp = None
    try:
        fd, tmp = tempfile.mkstemp(dir=directory, prefix=f".{path.stem}.",
                                   suffix=path.suffix)
        os.close(fd)
        write(Path(tmp))
        umask = os.umask(0)
        os.umask(umask)
        os.chmod(tmp, 0o666 & ~umask)
        os.replace(tmp, path)
        tmp = None
    except OSError as exc:
        raise type(exc)(exc.errno, exc.strerror or str(exc), str(path)) from None
    finally:
        if tmp is not None:
            try:
                os.unlink(tmp)
            except OSError:
                pass


def write_text_atomically(path: str | os.PathLike[str], text: str) -> None:
    """Write ``text`` (UTF-8, ``\\n`` line ends) to ``path`` atomically, synced to disk."""
    def write(tmp: Path) -> None:
        with open(tmp, "w", encoding="utf-8", newline="\n") as f:
            f.write(text)
            f.flush()
            os.fsync(f.fileno())
    replace_atomically(path, write)


#: Old private name of :func:`write_text_atomically`.
_atomic_write = write_text_atomically


def write_json_atomically(path: str | os.PathLike[str], obj: Any, *, indent: int | None = 1,
                          nonfinite: str = "null") -> None:
    """Write ``obj`` as strict JSON (through :func:`jsonable`) to ``path`` atomically."""
    text = json.dumps(jsonable(obj, nonfinite=nonfinite), indent=indent, allow_nan=False)
    write_text_atomically(path, text)


def write_instance(problem: AssignmentProblem, path: str | os.PathLike[str], *,
                   optimum: float | None = None, optimum_source: str | None = None,
                   description: str | None = None) -> None:
    """Write ``problem`` as a JSON v1 instance file, atomically.

    Problems built with :meth:`~AssignmentProblem.dense` or
    :meth:`~AssignmentProblem.two_d` are written as kind ``"dense"`` (the full cost
    array with ``"inf"`` where forbidden, plus ``row_miss``/``col_miss`` for
    ``two_d``); sparse problems as kind ``"sparse"``.  ``optimum``,
    ``optimum_source`` and ``description`` default to the problem's own recorded
    values.  Reading the file back gives the same candidates and costs.
    """
    _atomic_write(Path(path), instance_to_json(problem, optimum=optimum,
                                               optimum_source=optimum_source,
                                               description=description))


def jsonable(v: Any, *, nonfinite: str = "string") -> Any:
    """Plain-JSON version of ``v``: numpy types and tuples converted, keys made strings.

    Non-finite floats become ``"nan"``/``"inf"``/``"-inf"`` (``nonfinite="string"``,
    the instance and solution files) or ``None`` (``nonfinite="null"``: a missing
    value, as the experiment store and the reproduction summaries record it).

    >>> jsonable({"a": np.float64("inf"), "b": (1, np.int64(2))})
    {'a': 'inf', 'b': [1, 2]}
    >>> jsonable([float("nan"), np.bool_(True)], nonfinite="null")
    [None, True]
    """
    if nonfinite not in ("string", "null"):
        raise ValueError(f"nonfinite must be 'string' or 'null', got {nonfinite!r}")
    if isinstance(v, dict):
        return {str(k): jsonable(x, nonfinite=nonfinite) for k, x in v.items()}
    if isinstance(v, (list, tuple)):
        return [jsonable(x, nonfinite=nonfinite) for x in v]
    if isinstance(v, np.ndarray):
        return jsonable(v.tolist(), nonfinite=nonfinite)
    if isinstance(v, (bool, np.bool_)):
        return bool(v)
    if isinstance(v, (int, np.integer)):
        return int(v)
    if isinstance(v, (float, np.floating)):
        f = float(v)
        if math.isfinite(f):
            return f
        if nonfinite == "null":
            return None
        return "nan" if math.isnan(f) else ("inf" if f > 0 else "-inf")
    if v is None or isinstance(v, str):
        return v
    return str(v)


#: Old private name of :func:`jsonable`.
_jsonable = jsonable


def solution_to_dict(solution: Solution, extra: dict[str, Any] | None = None) -> dict[str, Any]:
    """``solution.to_dict()`` made plain-JSON safe, with ``extra`` keys merged in."""
    d = dict(solution.to_dict())
    if extra:
        d.update(extra)
    return _jsonable(d)


def write_solution(solution: Solution, path: str | os.PathLike[str], *,
                   extra: dict[str, Any] | None = None) -> None:
    """Write ``solution.to_dict()`` (plus ``extra`` keys) as JSON, atomically."""
    text = json.dumps(solution_to_dict(solution, extra), indent=2, allow_nan=False)
    _atomic_write(Path(path), text + "\n")
