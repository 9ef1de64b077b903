"""``python -m assocopt``: the command line (see :mod:`assocopt.cli`)."""

import sys

from .cli import main

if __name__ == "__main__":
    sys.exit(main())
