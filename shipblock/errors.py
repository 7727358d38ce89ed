"""Error types of shipblock.

Every error that shipblock raises on purpose derives from :class:`ShipblockError`, so callers can
catch the project's own failures with one ``except`` clause. Errors in parameters and records
also derive from :class:`ValueError`, the type that Python code conventionally raises for bad
input data.
"""

from __future__ import annotations

__all__ = ["ParameterError", "ParameterTypeError", "RecordError", "ShipblockError", "TomlNestingError",
           "UnitsError"]


class ShipblockError(Exception):
    """Base class of every error raised on purpose by shipblock."""


class ParameterError(ShipblockError, ValueError):
    """A parameter, option or input array is invalid; the message names it and its value."""


class ParameterTypeError(ParameterError, TypeError):
    """A parameter has the wrong type (a string for a number, a bare array for a pair...).

    Also a :class:`TypeError`, the type Python code conventionally raises for it; the message
    names the parameter and what it expects.
    """


class TomlNestingError(ParameterError):
    """A TOML document nests arrays and tables deeper than shipblock reads.

    Raised by :func:`shipblock.checks.toml_document` before the parser recurses that deep (a
    ``RecursionError`` otherwise); each reader of a TOML file turns it into its own error naming
    the file.

    Parameters
    ----------
    problem : str
        What is wrong and where (the line), without the file name.
    """

    def __init__(self, problem: str):
        self.problem = problem
        super().__init__(problem)

    def __reduce__(self):
        """Keep the error picklable."""
        return (type(self), (self.problem,))


class RecordError(ShipblockError, ValueError):
    """A ground-motion record cannot be read or used.

    The message always names the file (or ``"<stream>"`` for an in-memory stream) and says what is
    wrong with it.

    Parameters
    ----------
    source : str or os.PathLike
        The file (or a label for the in-memory data) the problem was found in.
    problem : str
        What is wrong, in words a user can act on.
    """

    def __init__(self, source, problem: str):
        self.source = str(source)
        self.problem = problem
        super().__init__(f"{self.source}: {problem}")

    def __reduce__(self):
        """Keep the error picklable (for example across Dask workers)."""
        return (type(self), (self.source, self.problem))


class UnitsError(RecordError):
    """The physical units of a record are unknown, inconsistent or not an acceleration."""
