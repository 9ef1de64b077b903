"""Command line: ``assocopt COMMAND ...``.

Commands: ``solve`` (one instance), ``compare`` (instances x back ends or models),
``validate`` (check instance files), ``export`` (MPS / LP model file), ``generate``
(random instance), ``convert`` (between instance formats), ``instances`` (list stored
instances), ``models`` (list named models), ``solvers`` (list back ends) and
``reproduce`` (a paper's experiments, when :mod:`assocopt.reproduce` is installed).
``assocopt COMMAND --help`` describes each.

Exit codes
----------
0  solved: status optimal or feasible, or stopped by a limit with a solution
   (other commands: done)
1  proven infeasible (the message names an uncovered index when that is the cause)
2  bad input: unreadable or malformed file, invalid option, unknown or missing solver
   or model; ``validate``: some file failed a check
3  stopped by a time/iteration limit without a solution
4  the solver reported an error, or an internal error (a bug: please report it);
   ``compare --check``: an answer claimed optimal differs from a recorded optimum, a
   bound exceeds it, or a back end failed
130  interrupted (Ctrl-C); 141: the output pipe was closed (e.g. ``| head``)

Errors are one line on stderr, ``assocopt: error: <message>``, never a traceback.

May import: :mod:`assocopt.runtime`, :mod:`assocopt.problems`, :mod:`assocopt.model`,
:mod:`assocopt.solvers`, :mod:`assocopt.solving`, :mod:`assocopt.ranking`,
:mod:`assocopt.io`, :mod:`assocopt.workflow`.

``assocopt reproduce`` loads the paper reproductions by name, the one plug-in point
into that layer.
"""
# Package layout (split from the former single module ``cli.py``; names unchanged):
#   common.py         exit codes, exit_code(), one-line errors, output formatting
#   parser.py         the argparse parser (_build_parser) for every subcommand
#   solve_cmds.py     solve, solvers, compare, validate
#   workflow_cmds.py  export, generate, convert, instances, models, reproduce
#   app.py            main(): parse, dispatch, map exceptions to exit codes
# ``assocopt = "assocopt.cli:main"`` (pyproject.toml) and ``python -m assocopt`` use main.

from __future__ import annotations

from .app import main
from .common import (EXIT_BAD_INPUT, EXIT_INFEASIBLE, EXIT_INTERNAL, EXIT_INTERRUPTED,
                     EXIT_LIMIT, EXIT_OK, exit_code)
# also importable from here, as before the split, though not in __all__
from .common import EXIT_BROKEN_PIPE, MAX_SHOWN  # noqa: F401
from .parser import _build_parser  # noqa: F401  (tests/test_docs.py)

__all__ = ["main", "exit_code", "EXIT_OK", "EXIT_INFEASIBLE", "EXIT_BAD_INPUT",
           "EXIT_LIMIT", "EXIT_INTERNAL", "EXIT_INTERRUPTED"]
