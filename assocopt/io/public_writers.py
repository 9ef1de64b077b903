"""Write the public benchmark formats that :func:`assocopt.io.read_instance` reads.

Grundel (with its ``.sol`` optimum file), OR-Library (square 2-D) and the
Balas-Saltzman split format (cubic 3-D); each holds dense problems without
forbidden or miss costs.
"""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np

from ..runtime.errors import AssocoptError, InvalidProblemError
from ..problems.problem import AssignmentProblem
from .writers import replace_atomically

__all__ = ["PUBLIC_WRITERS", "write_public"]

#: Formats :func:`write_public` writes.
PUBLIC_WRITERS = ("grundel", "orlib", "balas-saltzman-split")


def _number(v: float) -> str:
    return str(int(v)) if float(v).is_integer() and abs(v) < 1e15 else repr(float(v))


def _dense_costs(problem: AssignmentProblem, fmt: str) -> np.ndarray:
    if problem.kind != "dense":
        raise InvalidProblemError(
            f"the {fmt} format holds dense axial problems only; this one is "
            f"{'2-D with miss costs' if problem.kind == 'two_d' else 'sparse (S-D with dummies)'}"
            "; keep it in the assocopt JSON format")
    C = problem.to_cost_matrix()
    if not np.isfinite(C).all():
        raise InvalidProblemError(f"the {fmt} format has no forbidden (inf) costs; this "
                                  "problem has some")
    return C


def write_public(problem: AssignmentProblem, path: str | os.PathLike[str], format: str
                 ) -> list[Path]:
    """Write ``problem`` in a public benchmark format; returns the files written.

    ``"grundel"``: ``d``, the sizes, then the costs (last index fastest); a recorded
    optimum also goes to the sibling ``.sol`` file (``OPT: value``), which the reader
    picks up.  ``"orlib"``: square 2-D, ``n`` then the ``n*n`` costs.
    ``"balas-saltzman-split"``: cubic 3-D, ``n**3`` costs one per line.  All need a
    dense problem without forbidden costs or miss costs.
    """
    if format not in PUBLIC_WRITERS:
        raise AssocoptError(f"unknown output format {format!r}; valid: "
                            f"{', '.join(PUBLIC_WRITERS)}")
    path = Path(path)
    C = _dense_costs(problem, format)
    values = "\n".join(_number(v) for v in C.ravel())
    written = [path]
    if format == "grundel":
        text = f"{C.ndim}\n{' '.join(map(str, C.shape))}\n{values}\n"
    elif format == "orlib":
        if C.ndim != 2 or C.shape[0] != C.shape[1]:
            raise InvalidProblemError(f"the orlib format holds square 2-D problems; this "
                                      f"one has sizes {list(C.shape)}")
        rows = "\n".join(" ".join(_number(v) for v in row) for row in C)
        text = f"{C.shape[0]}\n{rows}\n"
    else:
        if C.ndim != 3 or len(set(C.shape)) != 1:
            raise InvalidProblemError(f"the balas-saltzman-split format holds n x n x n "
                                      f"problems; this one has sizes {list(C.shape)}")
        text = values + "\n"
    replace_atomically(path, lambda tmp: tmp.write_text(text, encoding="utf-8"))
    if format == "grundel" and problem.optimum is not None:
        sol = path.with_suffix(".sol")
        body = f"OPT: {_number(problem.optimum)}\n"
        replace_atomically(sol, lambda tmp: tmp.write_text(body, encoding="utf-8"))
        written.append(sol)
    return written
