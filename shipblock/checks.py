"""Checks of arguments where they enter shipblock, and the plausibility limits they apply.

Every public function checks its arguments with these helpers before any work, so that a wrong
value ends in a :class:`~shipblock.errors.ParameterError` that names the argument and says what
it expects (a :class:`~shipblock.errors.ParameterTypeError`, also a :class:`TypeError`, for a
value of the wrong type), never in a numba typing error, an ``OverflowError`` deep inside NumPy
or a NaN result.

Beyond the mathematical domain (a positive mass, a finite number) the inputs are held to
physical plausibility: a ground acceleration above :data:`MAX_ACCELERATION` (100 g; the largest
recorded are about 4 g) or a sampling interval outside :data:`MIN_TIME_STEP` ..
:data:`MAX_TIME_STEP` is a corrupt number or a unit mistake, not a record. The same limits are
applied by the record readers (:mod:`shipblock.io`), so whatever a reader accepts the solver
runs.

Paths are checked the same way: a value that is not a ``str`` or :class:`os.PathLike` is a
:class:`~shipblock.errors.ParameterTypeError` naming the argument (:func:`pathname`); a path that
names no file, or a folder where a file is needed, is a :class:`~shipblock.errors.RecordError`
that names the path and the argument (:func:`existing_file`).

Names a user gives that become labels, coordinates or file names (limit states, record ids)
hold printable characters only (:func:`label`): a NUL or another control character makes two
names print alike, or look alike once a C library (netCDF, the file system) cuts them. A TOML
document is read with :func:`toml_document`, which refuses nesting deeper than
:data:`MAX_TOML_DEPTH` by name instead of a ``RecursionError``. A keyword a function does not
take is refused with the closest one it does (:func:`keywords`).
"""

from __future__ import annotations

import difflib
import inspect
import math
import os
import re
import tomllib
from collections.abc import Callable, Collection, Iterable, Mapping

import numpy as np

from shipblock.errors import ParameterError, ParameterTypeError, RecordError, TomlNestingError
from shipblock.units import (
    ACCELERATION_UNITS_TO_SI,
    STANDARD_GRAVITY,
    VELOCITY_UNITS_TO_SI,
    canonical_unit,
    canonical_velocity_unit,
)

__all__ = [
    "MAX_ACCELERATION",
    "MAX_AZIMUTH",
    "MAX_DURATION",
    "MAX_PADDING",
    "MAX_PERIOD",
    "MAX_TIME_STEP",
    "MAX_TOML_DEPTH",
    "MIN_PERIOD",
    "MIN_TIME_STEP",
    "READ_OPTIONS",
    "acceleration",
    "azimuth",
    "choice",
    "existing_file",
    "flag",
    "closest",
    "how_to_leave_out",
    "how_to_pass",
    "is_real",
    "keyword_names",
    "keywords",
    "label",
    "pathname",
    "real",
    "text",
    "time_step",
    "toml_document",
    "toml_file",
    "toml_text",
    "unit",
    "whole",
]

#: Largest absolute ground acceleration accepted [m/s^2] (100 g), for records as given and as
#: scaled.
MAX_ACCELERATION = 100.0 * STANDARD_GRAVITY

#: Range of sampling intervals accepted [s] (10 kHz to 1 Hz).
MIN_TIME_STEP = 1e-4
MAX_TIME_STEP = 1.0

#: Range of oscillator periods of a response spectrum or a scaling measure [s] (a period of 0,
#: where a spectrum takes one, stands for PGA; below the finest sampling interval the
#: oscillator is rigid).
MIN_PERIOD = 1e-4
MAX_PERIOD = 100.0

#: Longest time a record is trimmed at [s] (a day; no earthquake record is longer).
MAX_DURATION = 86_400.0

#: Longest zero padding added to either end of a record [s].
MAX_PADDING = 600.0

#: Largest magnitude of an azimuth accepted [deg] (one turn either way; an azimuth of 1e300 deg
#: is a corrupt number, not a direction).
MAX_AZIMUTH = 360.0

#: Deepest nesting of arrays and tables read from a TOML file [levels]. A pipeline or catalogue
#: needs four; Python's TOML parser recurses once or twice a level and fails near 500
#: (``RecursionError``), and so do the readers that walk the document.
MAX_TOML_DEPTH = 32

_REAL_TYPES = (int, float, np.integer, np.floating)


def is_real(value) -> bool:
    """Whether ``value`` is a real number (a Python or NumPy int or float, not a bool)."""
    if isinstance(value, np.ndarray) and value.ndim == 0:
        value = value[()]
    return isinstance(value, _REAL_TYPES) and not isinstance(value, bool | np.bool_)


def _bound(value: float, low, high, low_open: bool, high_open: bool) -> bool:
    if low is not None and (value <= low if low_open else value < low):
        return False
    return not (high is not None and (value >= high if high_open else value > high))


def _describe(low, high, low_open: bool, high_open: bool, units: str) -> str:
    unit = f" [{units}]" if units else ""
    if low is not None and high is not None:
        return (f"a number in {'(' if low_open else '['}{low:g}, {high:g}"
                f"{')' if high_open else ']'}{unit}")
    if low is not None:
        return f"a finite number {'>' if low_open else '>='} {low:g}{unit}"
    if high is not None:
        return f"a finite number {'<' if high_open else '<='} {high:g}{unit}"
    return f"a finite number{unit}"


def real(value, name: str, *, low=None, high=None, low_open: bool = False,
         high_open: bool = False, units: str = "") -> float:
    """``value`` as a float, checked to be a finite number within the given bounds.

    Parameters
    ----------
    value : object
        The argument.
    name : str
        Its name, for the message.
    low, high : float, optional
        Bounds (inclusive unless ``low_open``/``high_open``).
    low_open, high_open : bool
        Whether the bound itself is excluded.
    units : str
        Units of the value, for the message.

    Returns
    -------
    float

    Raises
    ------
    ParameterTypeError
        If ``value`` is not a real number (a bool, a string, None, a sequence...).
    ParameterError
        If it is not finite or out of bounds.
    """
    expected = _describe(low, high, low_open, high_open, units)
    if not is_real(value):
        raise ParameterTypeError(f"{name} must be {expected}, got {type(value).__name__} "
                                 f"{value!r}")
    try:
        x = float(value)
    except OverflowError:  # an int beyond the float range
        x = math.inf
    if not (math.isfinite(x) and _bound(x, low, high, low_open, high_open)):
        raise ParameterError(f"{name} must be {expected}, got {value!r}")
    return x


def whole(value, name: str, *, low: int | None = None, high: int | None = None) -> int:
    """``value`` as an int, checked to be a whole number within ``[low, high]``.

    A float with a whole value (``3.0``) is accepted; a bool is not.

    Raises
    ------
    ParameterTypeError
        If ``value`` is not a real number.
    ParameterError
        If it is not finite, not whole, or out of bounds.
    """
    expected = "a whole number" + ("" if low is None else f" >= {low}") + (
        "" if high is None else f" and <= {high}")
    if not is_real(value):
        raise ParameterTypeError(f"{name} must be {expected}, got {type(value).__name__} "
                                 f"{value!r}")
    if isinstance(value, int | np.integer):
        n = int(value)
    else:
        x = float(value)
        if not (math.isfinite(x) and x == math.floor(x)):
            raise ParameterError(f"{name} must be {expected}, got {value!r}")
        n = int(x)
    if (low is not None and n < low) or (high is not None and n > high):
        raise ParameterError(f"{name} must be {expected}, got {value!r}")
    return n


def choice(value, name: str, choices: Collection[str]) -> str:
    """``value`` checked to be one of the strings ``choices``.

    Raises
    ------
    ParameterTypeError
        If ``value`` is not a string.
    ParameterError
        If it is not one of ``choices``.
    """
    listed = ", ".join(repr(c) for c in choices)
    if not isinstance(value, str):
        raise ParameterTypeError(f"{name} must be one of {listed}, got {type(value).__name__} "
                                 f"{value!r}")
    if value not in choices:
        raise ParameterError(f"{name} must be one of {listed}, got {value!r}")
    return value


def time_step(dt, name: str = "dt") -> float:
    """A sampling interval, checked to lie in [:data:`MIN_TIME_STEP`, :data:`MAX_TIME_STEP`] [s].

    Raises
    ------
    ParameterTypeError, ParameterError
        Naming ``name``.
    """
    # a relative slack of 1e-9: an interval computed as 1 / 10 kHz may round below 1e-4
    return real(dt, name, low=MIN_TIME_STEP * (1.0 - 1e-9), high=MAX_TIME_STEP * (1.0 + 1e-9),
                units="s")


def acceleration(values, name: str, *, limit: float = MAX_ACCELERATION,
                 min_samples: int = 2) -> np.ndarray:
    """A ground acceleration as a contiguous float array, checked sample by sample.

    Parameters
    ----------
    values : array_like
        The samples [m/s^2].
    name : str
        The argument's name, for the message.
    limit : float
        Largest absolute sample accepted [m/s^2]; :data:`MAX_ACCELERATION` by default.
    min_samples : int
        Fewest samples accepted.

    Returns
    -------
    numpy.ndarray
        One-dimensional, float64, C-contiguous.

    Raises
    ------
    ParameterTypeError
        If ``values`` is not an array of real numbers.
    ParameterError
        If it is not one-dimensional, is too short, or holds a non-finite sample or one above
        ``limit`` (the message gives the first such sample).
    """
    arr = as_real_array(values, name, "a one-dimensional array of accelerations [m/s^2]")
    if arr.ndim != 1:
        raise ParameterError(f"{name} must be a one-dimensional (1-D) array, got shape "
                             f"{arr.shape}")
    if arr.size < min_samples:
        raise ParameterError(f"{name} must have at least {min_samples} samples, got {arr.size}")
    check_samples(arr, name, limit)
    return np.ascontiguousarray(arr)


def as_real_array(values, name: str, what: str, kinds: str = "iuf") -> np.ndarray:
    """``values`` as a float64 array, or a :class:`ParameterTypeError` naming ``name``.

    ``kinds`` are the NumPy dtype kinds accepted (``"b"`` added for true/false arrays).
    """
    if type(values) is np.ndarray and values.dtype == np.float64:
        return values  # the common case, at no cost
    if values is None or isinstance(values, str | bytes | dict | set):
        raise ParameterTypeError(f"{name} must be {what}, got {type(values).__name__}")
    if isinstance(values, np.ma.MaskedArray):
        # np.asarray would drop the mask and compute with whatever the masked slots hold
        if np.ma.is_masked(values):
            first = int(np.flatnonzero(np.ma.getmaskarray(values))[0])
            raise ParameterError(
                f"{name} has {int(np.ma.count_masked(values))} masked samples (the first at index"
                f" {first}): fill them (values.filled(0.0) if the gap means no motion) or cut the"
                " record around them")
        values = values.data
    try:
        arr = np.asarray(values)
        if arr.dtype.kind not in kinds:
            raise TypeError(f"elements of type {arr.dtype}")
        return arr.astype(np.float64, copy=False)
    except (TypeError, ValueError) as exc:
        raise ParameterTypeError(f"{name} must be {what}, got {type(values).__name__} "
                                 f"({exc})") from None


def check_samples(arr: np.ndarray, name: str, limit: float = MAX_ACCELERATION) -> None:
    """Raise a :class:`ParameterError` naming the first non-finite sample or one above ``limit``.

    One pass over the samples (NaN fails the comparison, so it is found too).
    """
    if arr.size and arr.max() <= limit and arr.min() >= -limit:
        return
    bad = ~(np.abs(arr) <= limit)
    if bad.any():
        i = int(np.flatnonzero(bad)[0])
        what = "non-finite" if not np.isfinite(arr[i]) else f"above {limit / STANDARD_GRAVITY:g} g"
        raise ParameterError(
            f"{name} has {int(bad.sum())} sample(s) that are NaN, infinite or above the "
            f"plausibility limit {limit:g} m/s^2 ({limit / STANDARD_GRAVITY:g} g); the first is "
            f"{float(arr[i])!r} at index {i} ({what})")


def azimuth(value, name: str) -> float:
    """An azimuth [deg clockwise from north], checked to be a finite number within one turn.

    Raises
    ------
    ParameterTypeError, ParameterError
        Naming ``name``, if ``value`` is not a number in
        [-:data:`MAX_AZIMUTH`, :data:`MAX_AZIMUTH`].
    """
    return real(value, name, low=-MAX_AZIMUTH, high=MAX_AZIMUTH, units="deg")


def flag(value, name: str) -> bool:
    """``value`` checked to be ``True`` or ``False`` (a Python or NumPy bool, nothing else).

    Raises
    ------
    ParameterTypeError
        Naming ``name``, for anything else (a string ``"yes"`` is not true).
    """
    if isinstance(value, bool | np.bool_):
        return bool(value)
    raise ParameterTypeError(f"{name} must be True or False, got {type(value).__name__} "
                             f"{value!r}")


def text(value, name: str, *, optional: bool = False, what: str = "a non-empty string"):
    """``value`` checked to be a non-empty string (or ``None`` when ``optional``).

    Raises
    ------
    ParameterTypeError
        Naming ``name``, if ``value`` is not a string.
    ParameterError
        If it is empty (or only blanks).
    """
    if value is None and optional:
        return None
    if not isinstance(value, str):
        raise ParameterTypeError(f"{name} must be {what}"
                                 f"{' or None' if optional else ''}, got "
                                 f"{type(value).__name__} {value!r}")
    if not value.strip():
        raise ParameterError(f"{name} must be {what}, got {value!r}")
    return value


def pathname(value, name: str, what: str = "a file") -> str:
    """``value`` (a ``str`` or :class:`os.PathLike`) as a ``str``, without looking at the disk.

    Parameters
    ----------
    value : object
        The argument.
    name : str
        Its name, for the message.
    what : str
        What it must name, for the message (``"a record file"``).

    Raises
    ------
    ParameterTypeError
        Naming ``name``, if ``value`` is not a path (None, a number, bytes...).
    ParameterError
        If it is an empty string.
    """
    path = os.fspath(value) if isinstance(value, os.PathLike) else value
    if not isinstance(path, str):
        raise ParameterTypeError(f"{name} must be a path (str or os.PathLike) naming {what}, "
                                 f"got {type(value).__name__} {value!r}")
    if not path.strip():
        raise ParameterError(f"{name} must be a path naming {what}, got an empty string")
    return path


def existing_file(value, name: str, what: str = "a file", folder_hint: str = "") -> str:
    """``value`` as a ``str`` path to an existing file (not a folder).

    Parameters
    ----------
    value : object
        The argument.
    name : str
        Its name, for the message.
    what : str
        What it must name (``"a StationXML file"``).
    folder_hint : str
        Said when the path is a folder (``"; read a folder with read_motions()"``).

    Raises
    ------
    ParameterTypeError, ParameterError
        As :func:`pathname`.
    RecordError
        Naming the path and ``name``, if nothing or a folder is there.
    """
    path = pathname(value, name, what)
    if os.path.isdir(path):
        raise RecordError(path, f"is a folder, not a file ({name} must name {what}"
                                f"{folder_hint})")
    if not os.path.exists(path):
        raise RecordError(path, f"no such file ({name} must name {what})")
    if not os.path.isfile(path):
        raise RecordError(path, f"is not a regular file ({name} must name {what})")
    return path


def _unit_words(table) -> list[str]:
    """The spellings of a unit table worth listing (``"m/s^2"``, not also ``"m/s**2"``)."""
    return [u for u in table if "**" not in u and "/s/s" not in u]


def unit(value, name: str, *, velocity: bool = True) -> str:
    """``value`` checked to be a known unit of acceleration (or, if ``velocity``, of velocity).

    Any spelling the record readers accept (``"G"``, ``"cm/sec2"``, ``"gal"``, ``"cm/s"``) is
    accepted; it is returned unchanged.

    Raises
    ------
    ParameterTypeError
        Naming ``name``, if ``value`` is not a string.
    ParameterError
        If it is not a known unit; the message lists the known ones.
    """
    known = "an acceleration unit (" + ", ".join(_unit_words(ACCELERATION_UNITS_TO_SI)) + ")"
    if velocity:
        known += (" or a velocity unit (" + ", ".join(_unit_words(VELOCITY_UNITS_TO_SI))
                  + "; with differentiate=True)")
    if not isinstance(value, str):
        raise ParameterTypeError(f"{name} must be {known}, got {type(value).__name__} "
                                 f"{value!r}")
    if canonical_unit(value) is None and not (velocity and canonical_velocity_unit(value)):
        raise ParameterError(f"{name} must be {known}, got {value!r}")
    return value


#: Every option of reading a record, by its Python keyword (of
#: :func:`shipblock.read_motion` and the readers it passes ``**read_kwargs`` to): its
#: command-line flag (``shipblock simulate/info/process/catalogue``) and its key in a
#: catalogue entry (``[[record]]`` of a catalogue TOML, which pipelines read). Error messages
#: that ask for an option name all three (:func:`how_to_pass`).
READ_OPTIONS: dict[str, tuple[str, str]] = {
    "units": ("--units", "units"),
    "inventory": ("--inventory", "inventory"),
    "response": ("--response", "response"),
    "differentiate": ("--differentiate", "differentiate"),
    "channel_map": ("--channel-map", "components"),
    "sensor": ("--sensor", "sensor"),
    "align": ("--align", "align"),
    "gaps": ("--gaps", "gaps"),
    "event": ("--event", "event"),
    "format": ("--input-format", "format"),
    "dt": ("--dt", "dt"),
    "data_type": ("--data-type", "data_type"),
    "resample_rate": ("--resample-rate", "resample_rate"),
    "resample_interval": ("--resample-interval", "resample_interval"),
    "horizontal": ("--horizontal", "horizontal"),
    "azimuth": ("--azimuth", "azimuth"),
}


def how_to_pass(keyword: str, value, placeholder: bool = False) -> str:
    """How to give a read option, in the three places it can be given.

    Parameters
    ----------
    keyword : str
        A key of :data:`READ_OPTIONS` (the Python keyword).
    value : str, bool or float
        The value to suggest (``True`` for a switch such as ``differentiate``).
    placeholder : bool, optional
        ``value`` is a name standing for the user's value (``"SECONDS"``), written bare.

    Returns
    -------
    str
        E.g. ``pass --align resample (catalogue key align = "resample"; Python
        align='resample')``; for ``channel_map`` the catalogue's ``[record.components]`` table.

    Examples
    --------
    >>> how_to_pass("dt", "SECONDS", placeholder=True)
    'pass --dt SECONDS (catalogue key dt = SECONDS; Python dt=SECONDS)'
    """
    flag, key = READ_OPTIONS[keyword]
    if keyword == "channel_map":
        return ("pass --channel-map CHANNEL=H1 (CHANNEL a channel code, SEED id or file name;"
                " one per channel, H1, H2 or V, comma-separated or repeated;"
                " catalogue table [record.components] with CHANNEL = \"H1\"; Python"
                " channel_map={'CHANNEL': 'H1', ...})")
    if value is True:
        return f"pass {flag} (catalogue key {key} = true; Python {keyword}=True)"
    if placeholder:
        return f"pass {flag} {value} (catalogue key {key} = {value}; Python {keyword}={value})"
    toml = f'"{value}"' if isinstance(value, str) else f"{value!r}"
    return f"pass {flag} {value} (catalogue key {key} = {toml}; Python {keyword}={value!r})"


def how_to_leave_out(keyword: str) -> str:
    """How to stop giving a read option, in the three places it can be given.

    Parameters
    ----------
    keyword : str
        A key of :data:`READ_OPTIONS` (the Python keyword).

    Returns
    -------
    str

    Examples
    --------
    >>> how_to_leave_out("resample_rate")
    'leave out --resample-rate, catalogue key resample_rate, Python resample_rate='
    """
    flag, key = READ_OPTIONS[keyword]
    return f"leave out {flag}, catalogue key {key}, Python {keyword}="


def label(value, name: str, *, what: str = "a name") -> str:
    """``value`` checked to be a non-empty string of printable characters.

    For names that become labels, coordinates or file names. Printable is Python's
    :meth:`str.isprintable`: no control characters (Unicode category Cc: NUL, tab, newline,
    escape, DEL, the C1 controls), format characters (Cf: zero-width and direction marks),
    line or paragraph separators, surrogates, private-use or unassigned code points, and no
    space but the ASCII one. Such a character makes two names print alike, or alike once a C
    library (netCDF, the file system) cuts the name at a NUL.

    Raises
    ------
    ParameterTypeError
        Naming ``name``, if ``value`` is not a string.
    ParameterError
        Naming ``name``, the character (``U+0000``) and its position, if it is empty or holds a
        character that is not printable.
    """
    text(value, name, what=what)
    bad = next((i for i, ch in enumerate(value) if not ch.isprintable()), None)
    if bad is not None:
        raise ParameterError(f"{name} must be {what} of printable characters, got {value!r} "
                             f"(U+{ord(value[bad]):04X} at position {bad}: a control or "
                             "other non-printable character)")
    return value


def closest(word, choices: Iterable[str]) -> str:
    """``"; did you mean 'x'?"`` for the choice most like ``word`` (:mod:`difflib`), or ``""``."""
    found = difflib.get_close_matches(str(word), list(choices), n=1)
    return f"; did you mean {found[0]!r}?" if found else ""


def keyword_names(function, skip: int = 0) -> list[str]:
    """The names ``function`` takes as keyword arguments (its first ``skip`` left out)."""
    parameters = list(inspect.signature(function).parameters.values())[skip:]
    return [p.name for p in parameters if p.kind in (p.POSITIONAL_OR_KEYWORD, p.KEYWORD_ONLY)]


def keywords(given: Mapping, accepted: Collection[str], function: str,
             listed: Collection[str] | None = None, others: str = "") -> None:
    """Refuse a keyword argument that ``function`` does not take, suggesting the closest.

    For functions that pass ``**kwargs`` on: a misspelt keyword (``unit=`` for ``units=``)
    would otherwise be ignored.

    Parameters
    ----------
    given : mapping
        The keyword arguments.
    accepted : collection of str
        Every keyword ``function`` takes.
    function : str
        Its name, for the message.
    listed : collection of str, optional
        The keywords the message lists (default: ``accepted``); ``others`` says what else is
        accepted (``"a reader's keyword"``).

    Raises
    ------
    ParameterTypeError
        Naming the first unknown keyword, the closest accepted one and the accepted ones.
    """
    shown = ", ".join(sorted(accepted if listed is None else listed))
    for key in given:
        if key not in accepted:
            raise ParameterTypeError(
                f"{function}() got an unknown keyword argument {key!r}{closest(key, accepted)}"
                f" (accepted: {shown}{f'; or {others}' if others else ''})")


#: The tokens of TOML that can hold brackets without nesting anything, strings (multi-line
#: ones first, with the one or two quotes allowed before their closing delimiter) and
#: comments, and the brackets themselves.
_TOML_TOKENS = re.compile(r'''
      """(?:[^"\\]|\\.|"(?!""))*"{3,5}
    | \'\'\'.*?\'{3,5}
    | "(?:[^"\\\n]|\\.)*"
    | '[^'\n]*'
    | \#[^\n]*
    | [\[\]{}]
''', re.VERBOSE | re.DOTALL)


def _too_deep(where: str) -> TomlNestingError:
    where = where if len(where) <= 80 else where[:77] + "..."
    return TomlNestingError(f"is nested deeper than {MAX_TOML_DEPTH} levels of arrays and "
                            f"tables ({where}); shipblock reads at most {MAX_TOML_DEPTH}")


def toml_document(source: str) -> dict:
    """Parse TOML text (:func:`tomllib.loads`), refusing nesting deeper than :data:`MAX_TOML_DEPTH`.

    The brackets of inline arrays and tables are counted before parsing (outside strings and
    comments), since the parser recurses on them; the parsed document is then measured
    without recursion, since dotted keys and table headers nest too (``a.b.c = 1`` is three
    levels).

    Parameters
    ----------
    source : str
        The TOML document.

    Returns
    -------
    dict
        The document.

    Raises
    ------
    TomlNestingError
        Saying how deep and where (the line, or the key); the caller names the file.
    tomllib.TOMLDecodeError
        If the text is not TOML.
    """
    depth = 0
    for token in _TOML_TOKENS.finditer(source):
        bracket = token.group()
        if bracket in ("[", "{"):
            depth += 1
            if depth > MAX_TOML_DEPTH:
                raise _too_deep(f"line {source.count(chr(10), 0, token.start()) + 1}")
        elif bracket in ("]", "}"):
            depth = max(depth - 1, 0)
    document = tomllib.loads(source)
    stack = [(document, 0, "")]
    while stack:
        node, level, where = stack.pop()
        if level > MAX_TOML_DEPTH:
            raise _too_deep(f"at {where}")
        for key, child in (node.items() if isinstance(node, dict) else enumerate(node)):
            if isinstance(child, dict | list):
                inner = (f"{where}[{key}]" if isinstance(key, int)
                         else f"{where}.{key}" if where else str(key))
                stack.append((child, level + 1, inner))
    return document


def _parameter_error(path: str, problem: str) -> ParameterError:
    return ParameterError(f"{path}: {problem}")


def toml_text(path, what: str = "TOML file",
              error: Callable[[str, str], Exception] = _parameter_error) -> str:
    """The text of a TOML file, checked to be text; every failure an error naming the file.

    The one reader of shipblock's TOML files (pipelines, catalogues, system and processing
    chain files; :func:`toml_file` parses what it reads): each caller gets the same checks
    and messages, in its own error type.

    Parameters
    ----------
    path : str or os.PathLike
        The file.
    what : str
        What the file is, for the messages (``"system file"``).
    error : callable, optional
        ``error(path, problem)`` makes the exception raised for the file ``path`` (a str) and
        the ``problem`` (a message without the file name), e.g.
        :class:`~shipblock.errors.RecordError`; by default a
        :class:`~shipblock.errors.ParameterError` whose message is ``"<path>: <problem>"``.

    Returns
    -------
    str
        The file's text (not yet parsed).

    Raises
    ------
    ParameterTypeError
        If ``path`` is not a path.
    Exception
        Made by ``error``: the file is missing or unreadable (a folder), not UTF-8 text or
        binary (a NUL byte).
    """
    path = pathname(path, "path", f"a {what}")
    try:
        with open(path, "rb") as fh:
            data = fh.read()
    except FileNotFoundError:
        raise error(str(path), f"{what} not found (path must name a {what})") from None
    except OSError as exc:
        raise error(str(path), f"cannot read the {what} ({exc})") from None
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError as exc:
        raise error(str(path), f"is not a {what}: not UTF-8 text (byte 0x{data[exc.start]:02x} at "
                               f"offset {exc.start}); a {what} is a TOML text file") from None
    if "\x00" in text:
        raise error(str(path), f"is not a {what}: binary data (a NUL byte at offset "
                               f"{text.index(chr(0))}); a {what} is a TOML text file")
    return text


def toml_file(path, what: str = "TOML file",
              error: Callable[[str, str], Exception] = _parameter_error) -> dict:
    """Read a TOML file (:func:`toml_text`) and parse it (:func:`toml_document`); every failure
    an error naming the file.

    Parameters
    ----------
    path : str or os.PathLike
        The file.
    what : str
        What the file is, for the messages (``"system file"``).
    error : callable, optional
        Makes the exception, as in :func:`toml_text`.

    Returns
    -------
    dict
        The document.

    Raises
    ------
    ParameterTypeError
        If ``path`` is not a path.
    Exception
        Made by ``error``: as :func:`toml_text`, and the text is not TOML or is nested deeper
        than :data:`MAX_TOML_DEPTH` levels.
    """
    text = toml_text(path, what, error)
    try:
        return toml_document(text)
    except TomlNestingError as exc:
        raise error(str(path), exc.problem) from None
    except tomllib.TOMLDecodeError as exc:
        raise error(str(path), f"is not valid TOML: {exc}") from None
