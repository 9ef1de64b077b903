"""Moved: model export and format conversion live in :mod:`assocopt.io`.

:mod:`assocopt.io.mps_lp` (MPS / LP model files), :mod:`assocopt.io.public_writers`
(Grundel, OR-Library, Balas-Saltzman) and :mod:`assocopt.io.convert`.  This module
only keeps the old import path ``assocopt.export`` working (for users' code); the
project itself imports from the new places.
"""

from .io.convert import CONVERT_FORMATS, convert, output_format  # noqa: F401
from .io.mps_lp import MODEL_FORMATS, _model_format, export_model, solve_model_file  # noqa: F401
from .io.public_writers import PUBLIC_WRITERS, _dense_costs, _number, write_public  # noqa: F401

__all__ = ["MODEL_FORMATS", "PUBLIC_WRITERS", "export_model", "solve_model_file",
           "write_public", "convert", "output_format"]
