"""Writing files atomically: instances (JSON v1) and solutions.

:func:`replace_atomically` writes through a temporary file and ``os.replace``, so
an interrupted write never leaves a partial file; :func:`write_instance` and
:func:`write_solution` use it (through :func:`_atomic_write`).  The JSON text of
an instance comes from :func:`~.json_format.instance_to_json`.
"""

from __future__ import annotations

import json
import math
import os
import tempfile
from pathlib import Path
from typing import Any

import numpy as np

from ..problem import AssignmentProblem
from ..solution import Solution
from .json_format import instance_to_json


def replace_atomically(path: str | os.PathLike[str], write: Any) -> None:
    """Call ``write(tmp_path)`` on a temporary file beside ``path``, then move it into
    place with ``os.replace``: an interrupted write never leaves a partial file."""
    path = Path(path)
    directory = path.parent if str(path.parent) else Path(".")
    fd, tmp = tempfile.mkstemp(dir=directory, prefix=f".{path.stem}.", suffix=path.suffix)
    os.close(fd)
    try:
        write(Path(tmp))
        umask = os.umask(0)
        os.umask(umask)
        os.chmod(tmp, 0o666 & ~umask)
        os.replace(tmp, path)
    except BaseException:
        try:
            os.unlink(tmp)
        except OSError:
            pass
        raise


def _atomic_write(path: Path, text: str) -> None:
    def write(tmp: Path) -> None:
        with open(tmp, "w", encoding="utf-8", newline="\n") as f:
            f.write(text)
            f.flush()
            os.fsync(f.fileno())
    replace_atomically(path, write)


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


def _jsonable(v: Any) -> Any:
    """Plain-JSON version of ``v``: numpy types converted, non-finite floats as strings."""
    if isinstance(v, dict):
        return {str(k): _jsonable(x) for k, x in v.items()}
    if isinstance(v, (list, tuple)):
        return [_jsonable(x) for x in v]
    if isinstance(v, np.ndarray):
        return _jsonable(v.tolist())
    if isinstance(v, (bool, np.bool_)):
        return bool(v)
    if isinstance(v, (int, np.integer)):
        return int(v)
    if isinstance(v, (float, np.floating)):
        f = float(v)
        if math.isnan(f):
            return "nan"
        if math.isinf(f):
            return "inf" if f > 0 else "-inf"
        return f
    if v is None or isinstance(v, str):
        return v
    return str(v)


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
