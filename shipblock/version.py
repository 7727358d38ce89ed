"""The version of the installed shipblock, written into every result file.

At the bottom of the package's layers with :mod:`shipblock.units` and :mod:`shipblock.errors`:
modules that record the version (:mod:`shipblock.result`, the studies) import it from here, not
from the top-level package, which imports them.
"""

from __future__ import annotations

from importlib.metadata import PackageNotFoundError, version

__all__ = ["__version__"]

try:
    __version__ = version("shipblock")
except PackageNotFoundError:  # running from a source tree that is not installed
    __version__ = "0+unknown"
