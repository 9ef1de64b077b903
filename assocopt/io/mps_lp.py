"""Export the ILP / LP of a problem as an MPS or LP file, and solve such a file back.

:func:`export_model` writes the model of :mod:`assocopt.model.formulation` through highspy
(``Highs.writeModel``), so any MILP solver can read it.  Columns are named after
their candidate tuple, ``x_<i1>_<i2>_..`` (S-D convention: 0 = dummy, real indices
1-based); rows ``cover_<axis>_<index>`` (axis 0-based, index 1-based), one per real
index.  HiGHS writes costs with 15 significant digits, so a model re-read from the
file has the same optimum to about 1e-14 relative (exactly, for integer costs):
:func:`solve_model_file` checks that round trip.
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import Any

import numpy as np

from ..runtime.errors import AssocoptError, InvalidProblemError
from ..problems.problem import AssignmentProblem
from .writers import replace_atomically

__all__ = ["MODEL_FORMATS", "export_model", "solve_model_file"]

#: File suffix -> model format written by :func:`export_model`.
MODEL_FORMATS = {".mps": "mps", ".lp": "lp"}


def _model_format(path: Path) -> str:
    fmt = MODEL_FORMATS.get(path.suffix.lower())
    if fmt is None:
        raise AssocoptError(f"{path}: cannot tell the model format from the suffix "
                            f"{path.suffix or '(none)'!r}; use .mps or .lp")
    return fmt


def export_model(problem: AssignmentProblem, path: str | os.PathLike[str], *,
                 relax: str | None = None, names: bool = True) -> dict[str, Any]:
    """Write the ILP (or with ``relax="lp"`` its LP relaxation) of ``problem``.

    The format follows the suffix: ``.mps`` (free MPS) or ``.lp`` (CPLEX LP).
    ``names=False`` leaves HiGHS's default names ``c0..``, ``r0..``.  The file is
    written atomically.  Returns a summary: path, format, columns, rows, integer.

    Examples
    --------
    >>> import tempfile, os
    >>> p = AssignmentProblem.dense([[4.0, 1.0], [2.0, 3.0]])
    >>> f = os.path.join(tempfile.mkdtemp(), "m.lp")
    >>> export_model(p, f)["columns"], solve_model_file(f)
    (4, 3.0)
    """
    import highspy

    from ..model.formulation import build_model
    from ..solvers.milp.highs import highs_from_model

    path = Path(path)
    fmt = _model_format(path)
    if not isinstance(problem, AssignmentProblem):
        raise InvalidProblemError(
            f"problem must be an AssignmentProblem, got {type(problem).__name__}")
    if problem.n_candidates == 0 or problem.n_rows == 0:
        raise InvalidProblemError("the problem has no candidates or no real index: "
                                  "nothing to export")
    model = build_model(problem, relax)
    h = highs_from_model(model)
    if names:
        T = problem.tuples
        for k in range(problem.n_candidates):       # export only: one call per name
            h.passColName(k, "x_" + "_".join(map(str, T[k].tolist())))
        for r in range(problem.n_rows):
            a = int(np.searchsorted(problem.row_offsets, r, side="right") - 1)
            h.passRowName(r, f"cover_{a}_{int(r - problem.row_offsets[a] + 1)}")

    def write(tmp: Path) -> None:
        status = h.writeModel(str(tmp))
        if status == highspy.HighsStatus.kError:
            raise AssocoptError(f"{path}: HiGHS could not write the model")

    replace_atomically(path, write)
    return {"path": str(path), "format": fmt, "columns": int(model.A.shape[1]),
            "rows": int(model.A.shape[0]), "integer": model.is_mip,
            "relaxation": relax}


def solve_model_file(path: str | os.PathLike[str], *, time_limit: float | None = None
                     ) -> float | None:
    """Read an MPS / LP file with HiGHS, solve it, return the optimum (None if not optimal)."""
    import highspy

    path = Path(path)
    if not path.is_file():
        raise AssocoptError(f"{path}: no such model file")
    h = highspy.Highs()
    h.setOptionValue("output_flag", False)
    if time_limit is not None:
        h.setOptionValue("time_limit", float(time_limit))
    if h.readModel(str(path)) == highspy.HighsStatus.kError:
        raise AssocoptError(f"{path}: HiGHS could not read the model")
    h.run()
    if h.getModelStatus() != highspy.HighsModelStatus.kOptimal:
        return None
    return float(h.getInfo().objective_function_value)
