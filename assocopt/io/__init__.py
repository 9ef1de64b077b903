"""Reading and writing instance files, and writing solutions.

:func:`read_instance` reads the project's own JSON format (``"assocopt"``, see
``docs/instance-format.md``) and four public benchmark formats, detected from the
file's content:

``"grundel"``
    DecompLib / Grundel generator ``ap3.<n>.<s>.txt``: line 1 ``d``, line 2 the
    ``d`` sizes, then the costs with the last index varying fastest.  A sibling
    ``ap3.<n>.<s>.sol`` whose first non-empty line is ``OPT: <value>`` (or an
    ``ap3.opt`` table) gives the recorded optimum.
``"balas-saltzman"``
    The original multi-instance "AP3 Test Driver" file of Balas & Saltzman (1991):
    blocks ``N = n   PROBLEM = p`` / a line of ``=`` / ``n**3`` costs.  Pick one
    with ``instance="N20_P5"``, ``instance=(20, 5)`` or a 1-based position.
``"balas-saltzman-split"``
    One such instance per file: ``n**3`` costs, optionally after a ``3 n`` header.
``"orlib"``
    OR-Library linear assignment (``assign100.txt`` ...): ``n``, then ``n*n``
    costs row by row.  A sibling ``assignopt.txt`` gives the recorded optimum.

Public-format costs are integers; they are stored as float64.  Every problem in a
public file is a dense (axial) minimisation problem: :meth:`AssignmentProblem.dense`.

Every malformed file raises :class:`~assocopt.runtime.errors.InstanceFormatError` with the
file name and what is wrong in the message.

The package has one module per concept; this ``__init__`` re-exports every name
other code uses (and every name the former single-module ``assocopt/io.py`` had),
so ``from assocopt.io import X`` works as before:

:mod:`.common`
    ``_fail`` and the text / number parsing helpers shared by every reader
    (``TextFile``: a text file's tokens and line layout, computed once).
:mod:`.grundel`, :mod:`.balas_saltzman`, :mod:`.orlib`
    Readers of the public benchmark formats.
:mod:`.json_format`
    The JSON v1 format: reader, :func:`instance_to_json`, ``FORMAT_NAME``,
    ``FORMAT_VERSION``.
:mod:`.json_scan`, :mod:`.json_bulk`
    The JSON reader's fast route: one pass over the text before parsing, and the
    bulk conversion of the parsed arrays (the strict per-entry walks stay the
    fallback that names a bad entry).
:mod:`.detect`
    :data:`FORMATS`, :func:`detect_format` and :func:`read_instance`.
:mod:`.mps_lp`
    :func:`export_model` (the ILP / LP as an MPS or LP file), :func:`solve_model_file`.
:mod:`.public_writers`
    :func:`write_public`: the Grundel, OR-Library and Balas-Saltzman formats.
:mod:`.convert`
    :func:`convert` between formats, :func:`output_format`.
:mod:`.writers`
    Atomic writes: :func:`replace_atomically`, :func:`write_text_atomically`,
    :func:`write_json_atomically`, :func:`write_instance`, :func:`write_solution`,
    :func:`solution_to_dict`; the JSON sanitiser :func:`jsonable`.

May import: :mod:`assocopt.runtime`, :mod:`assocopt.problems`, :mod:`assocopt.model`,
:mod:`assocopt.solvers` (a model file is solved by a back end).
"""

from __future__ import annotations

from ..runtime.errors import InstanceFormatError, InvalidProblemError  # noqa: F401
from ..problems.problem import AssignmentProblem  # noqa: F401
from ..model.solution import Solution  # noqa: F401
from .balas_saltzman import (_BS_BLOCK, _BS_INSTANCE, _PAIR, _bs_blocks,  # noqa: F401
                             _cube_root_floor, _parse_bs_instance, _read_bs_driver,
                             _read_bs_split)
from .common import (_INTEGER, _NUMBER, _count_error, _cube_root, _dense,  # noqa: F401
                     _fail, _first_non_number, _header_int, _lines, _locate_token,
                     _numbers, _read_text)
from .detect import (FORMATS, _looks_grundel, _matches, _name_hint, _need,  # noqa: F401
                     detect_format, read_instance)
from .grundel import _MAX_D, _grundel_optimum, _read_grundel  # noqa: F401
from .json_format import (FORMAT_NAME, FORMAT_VERSION, _COMMON_KEYS,  # noqa: F401
                          _CONSTANTS, _KIND_KEYS, _cost_array, _cost_value,
                          _dump_nested, _dump_rows, _int_list, _json_cost,
                          _no_duplicates, _parse_constant, _read_json,
                          instance_to_json)
from .orlib import _orlib_optimum, _read_orlib  # noqa: F401
from .writers import (_atomic_write, _jsonable, jsonable, replace_atomically,  # noqa: F401
                      solution_to_dict, write_instance, write_json_atomically,
                      write_solution, write_text_atomically)

from .convert import CONVERT_FORMATS, convert, output_format  # noqa: F401,E402
from .mps_lp import MODEL_FORMATS, export_model, solve_model_file  # noqa: F401,E402
from .public_writers import PUBLIC_WRITERS, write_public  # noqa: F401,E402

__all__ = ["read_instance", "write_instance", "write_solution", "detect_format",
           "instance_to_json", "solution_to_dict", "FORMATS", "FORMAT_NAME",
           "FORMAT_VERSION", "export_model", "solve_model_file", "write_public", "convert",
           "output_format", "jsonable", "write_text_atomically", "write_json_atomically"]
