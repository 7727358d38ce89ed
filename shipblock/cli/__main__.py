"""``python -m shipblock.cli``: the ``shipblock`` command."""

import sys

from shipblock.cli import main

if __name__ == "__main__":
    sys.exit(main())
