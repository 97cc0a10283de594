"""``python -m rigidkit ...``: the same command line as the ``rigidkit`` script."""

import sys

from .applications.cli import main

if __name__ == "__main__":
    sys.exit(main())
