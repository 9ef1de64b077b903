"""``python -m assocopt.cli``: the command line, as ``python -m assocopt``."""

import sys

from .app import main

if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
