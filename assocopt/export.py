"""Export the ILP / LP as MPS or LP files, and convert between instance formats.

:func:`export_model` writes the model of :mod:`assocopt.formulation` through highspy
(``Highs.writeModel``), so any MILP solver can read it.  Columns are named after
their candidate tuple, ``x_<i1>_<i2>_..`` (S-D convention: 0 = dummy, real indices
1-based); rows ``cover_<axis>_<index>`` (axis 0-based, index 1-based), one per real
index.  HiGHS writes costs with 15 significant digits, so a model re-read from the
file has the same optimum to about 1e-14 relative (exactly, for integer costs):
:func:`solve_model_file` checks that round trip.

:func:`write_public` writes the public benchmark formats that
:func:`assocopt.io.read_instance` reads (Grundel, OR-Library, Balas-Saltzman split),
and :func:`convert` reads any supported format and writes any of them.
"""

from __future__ import annotations

import math
import os
import re
from pathlib import Path
from typing import Any

import numpy as np

from .errors import AssocoptError, InvalidProblemError
from .io import replace_atomically
from .problem import AssignmentProblem

__all__ = ["MODEL_FORMATS", "PUBLIC_WRITERS", "export_model", "solve_model_file",
           "write_public", "convert", "output_format"]

#: File suffix -> model format written by :func:`export_model`.
MODEL_FORMATS = {".mps": "mps", ".lp": "lp"}
#: Formats :func:`write_public` writes.
PUBLIC_WRITERS = ("grundel", "orlib", "balas-saltzman-split")
#: Formats :func:`convert` writes (the project's JSON first).
CONVERT_FORMATS = ("assocopt",) + PUBLIC_WRITERS


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

    from .formulation import build_model
    from .solvers.highs import highs_from_model

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


# ----------------------------------------------------------------------- public formats
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


def output_format(path: str | os.PathLike[str]) -> str | None:
    """The format :func:`convert` infers from an output file name (None: cannot tell)."""
    name = Path(path).name.lower()
    if name.endswith(".json"):
        return "assocopt"
    if re.match(r"^ap3\..*\.txt$", name):
        return "grundel"
    if re.match(r"^assign.*\.txt$", name):
        return "orlib"
    if name.startswith("balas"):
        return "balas-saltzman-split"
    return None


def convert(src: str | os.PathLike[str], dst: str | os.PathLike[str], *,
            from_format: str = "auto", to_format: str | None = None, instance: Any = None,
            prove: bool = False, time_limit: float | None = None) -> dict[str, Any]:
    """Read ``src`` in any supported format and write ``dst``.

    ``to_format`` defaults to the one :func:`output_format` infers from ``dst``.
    Converting to JSON keeps the recorded optimum and its source and adds a
    description naming the source file; ``prove=True`` proves the optimum with HiGHS
    (:func:`assocopt.generate.prove_optimum`) and records it.  Returns a summary.
    """
    from .generate import prove_optimum
    from .io import read_instance, write_instance

    fmt = to_format or output_format(dst)
    if fmt is None:
        raise AssocoptError(f"{dst}: cannot tell the output format from the name; pass "
                            f"--to-format ({', '.join(CONVERT_FORMATS)})")
    if fmt not in CONVERT_FORMATS:
        raise AssocoptError(f"unknown output format {fmt!r}; valid: {', '.join(CONVERT_FORMATS)}")
    problem = read_instance(src, format=from_format, instance=instance)
    optimum = problem.optimum
    source = problem.meta.get("optimum_source")
    if prove:
        proven, how = prove_optimum(problem, time_limit=time_limit)
        if optimum is not None and not math.isclose(proven, optimum, rel_tol=1e-9,
                                                    abs_tol=1e-9):
            raise AssocoptError(f"{src}: recorded optimum {optimum:g} but {how} gives "
                                f"{proven:g}")
        source = how if optimum is None else f"{source or 'recorded'}; re-{how}"
        optimum = proven
    if fmt == "assocopt":
        read_fmt = problem.meta.get("format", from_format)
        label = f" ({problem.meta['instance']})" if "instance" in problem.meta else ""
        desc = problem.meta.get("description") or \
            f"converted from {Path(src).name}{label} ({read_fmt} format) by assocopt convert"
        write_instance(problem, dst, optimum=optimum,
                       optimum_source=source if optimum is not None else None,
                       description=desc)
        written = [Path(dst)]
    else:
        if optimum is not None and optimum != problem.optimum:
            problem = AssignmentProblem.dense(problem.to_cost_matrix(), name=problem.name,
                                              optimum=optimum) \
                if problem.kind == "dense" else problem
        written = write_public(problem, dst, fmt)
    return {"source": str(src), "written": [str(p) for p in written], "format": fmt,
            "name": problem.name, "sizes": list(problem.sizes), "optimum": optimum,
            "optimum_source": source if optimum is not None else None}
