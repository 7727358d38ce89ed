"""Reader for plain one- or two-column text/CSV records (obspy plug-in ``SHIPBLOCK_TEXT``).

A plain record is one column (acceleration, the sampling interval given by the caller or a
``dt = 0.01`` header line), two columns (time [s], acceleration), or four: time and three
components named in a header line (the SCEC broadband platform's ``.bbp``: ``# Time (s), NS
(cm/s/s), EW (cm/s/s), UD (cm/s/s)``; NS/N-S/N, EW/E-W/E, UD/U-D/UP/Z/V), separated by commas,
semicolons, tabs or spaces. Lines starting with ``#``, ``%``, ``!``, ``;`` or ``//`` are comments;
non-numeric lines before the first sample (a CSV header such as ``time,accel``) are header lines.
A blank line between the samples of a one-column record is refused (it may be a lost sample, and
one column has no time to tell); two-column records are checked by their time column.

Plain text carries no agreed unit, so the unit must be stated: either by the caller (``units="g"``,
``"m/s^2"``, ``"cm/s^2"``, ``"gal"``, ...) or in a header line, in brackets after the quantity (``#
Time (s),Acceleration (g's)``, ``accel [m/s^2]``) or as ``units: cm/s^2``. A file with neither is
refused with :class:`~shipblock.errors.UnitsError`; if both are given they must agree (in kind and
size: ``g`` and ``gal`` contradict each other, ``cm/s^2`` and ``gal`` do not), and so must all of a
header's statements (``accel (g)`` and ``units: cm/s^2`` are refused). A velocity unit (``cm/s``,
``m/s``) gives a velocity trace (``stats.units == "m/s"``) that :func:`shipblock.read_motion`
differentiates when asked to (``--differentiate``). A unit after a peak value's name (``PGV
(cm/s)``) is not a statement about the samples. A header that calls the samples one quantity and
gives the unit of another (``Acceleration ... in units of cm/s``) is refused unless the caller
states the unit, which then decides. For the same reason :func:`is_text` auto-detects only files
whose header states an acceleration unit; any other plain file is read with
``format="SHIPBLOCK_TEXT"`` and ``units=``, or through :func:`shipblock.read_motion` with
``units=``.
"""

from __future__ import annotations

import re

import numpy as np
from obspy import Stream, UTCDateTime
from obspy.core import AttribDict

from shipblock.checks import how_to_pass
from shipblock.errors import RecordError, UnitsError
from shipblock.io._common import (
    UNITS_GIVEN_KEY,
    check_plausible_samples,
    check_samples,
    check_sampling_interval,
    make_trace,
    parse_float,
    peek_text,
    read_text,
    source_name,
)
from shipblock.units import (
    ACCELERATION_UNITS_TO_SI,
    VELOCITY_UNITS_TO_SI,
    canonical_unit,
    canonical_velocity_unit,
    si_factor,
)

__all__ = ["FORMAT", "TIME_STEP_TOLERANCE", "is_text", "read_text_record"]

#: Name under which the reader is registered as an obspy waveform plug-in.
FORMAT = "SHIPBLOCK_TEXT"

#: Largest deviation of a time step from the median step, as a fraction of the step [-].
TIME_STEP_TOLERANCE = 0.01

_COMMENT_PREFIXES = ("#", "%", "!", ";", "//")
_SPLIT = re.compile(r"[,;\s]+")
_BRACKETED = re.compile(r"[\(\[\{]\s*([^\)\]\}]+?)\s*[\)\]\}]")
_UNITS_KEY = re.compile(r"\bunits?\s*[:=]\s*([^\s,;]+)", re.IGNORECASE)
#: Names of a peak value: a unit after one is the value's, not the samples' (``PGV (cm/s)``).
_PEAK_NAME = re.compile(r"^(?:PG[ADV]|PEAK|MAX(?:IMUM)?|MIN(?:IMUM)?)$", re.IGNORECASE)
_DT_KEY = re.compile(r"\b(?:dt|delta)\s*[:=]\s*([-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?)",
                     re.IGNORECASE)


def _is_comment(line: str) -> bool:
    return line.lstrip().startswith(_COMMENT_PREFIXES)


def _numbers(line: str) -> list[float] | None:
    """Return the numbers of a data line, or ``None`` if it is not all numbers."""
    tokens = [t for t in _SPLIT.split(line.strip()) if t]
    if not tokens:
        return None
    try:
        return [parse_float(t) for t in tokens]
    except ValueError:
        return None


def _split(lines, name: str, strict: bool):
    """Separate header lines from numeric rows.

    Returns
    -------
    header : list of str
    rows : list of list of float
    blanks : list of int
        Line numbers of blank lines between two numeric rows.
    """
    header, rows, blanks, pending = [], [], [], []
    for lineno, line in enumerate(lines, start=1):
        if not line.strip():
            if rows:
                pending.append(lineno)
            continue
        if _is_comment(line):
            header.append(line)
            continue
        values = _numbers(line)
        if values is None:
            if rows:
                if strict:
                    raise RecordError(name, f"line {lineno}: {line.strip()[:40]!r} is not numeric")
                break  # end of the peek window may cut a line
            header.append(line)
            continue
        rows.append(values)
        blanks += pending
        pending = []
    return header, rows, blanks


def _unit_kind(word: str) -> tuple[str, str] | None:
    """``(canonical unit, "acceleration" | "velocity")`` of a unit word, or ``None``."""
    key = canonical_unit(word)
    if key is not None:
        return key, "acceleration"
    key = canonical_velocity_unit(word)
    return (key, "velocity") if key is not None else None


def header_unit_statements(header_lines) -> list[tuple[str, str]]:
    """Every distinct unit of the samples the header lines state, in order of appearance.

    A statement is a word in brackets (``accel (g)``, ``[cm/s^2]``) or after ``units:``, that is
    an acceleration or a velocity unit (time units, ``(s)``, and other words are not); one after a
    peak value's name (``PGV (cm/s)``, ``peak (g)``) states the unit of that value, not of the
    samples, and is left out.

    Returns
    -------
    list of (str, str)
        ``(canonical unit, "acceleration" | "velocity")``.
    """
    found = []
    for line in header_lines:
        matches = [(m.start(), m.group(1)) for m in _BRACKETED.finditer(line)]
        matches += [(m.start(), m.group(1)) for m in _UNITS_KEY.finditer(line)]
        for start, candidate in sorted(matches):
            before = line[:start].split()
            if before and _PEAK_NAME.match(before[-1].strip(",;:=")):
                continue
            unit = _unit_kind(candidate)
            if unit is not None and unit not in found:
                found.append(unit)
    return found


def header_units(header_lines) -> str | None:
    """Find the unit of the samples stated in header lines.

    Parameters
    ----------
    header_lines : list of str
        Comment/header lines of a text record.

    Returns
    -------
    str or None
        The canonical unit key (acceleration, see :func:`shipblock.units.canonical_unit`, or
        velocity), ``None`` if none is stated, or the units joined by ``|`` if several are.
    """
    statements = header_unit_statements(header_lines)
    if len({_factor(*unit) for unit in statements}) == 1:
        return statements[0][0]  # one unit, perhaps spelled two ways (cm/s^2 and gal)
    return "|".join(unit for unit, _ in statements) or None


def _header_dt(header_lines) -> float | None:
    for line in header_lines:
        match = _DT_KEY.search(line)
        if match:
            return float(match.group(1))
    return None


def is_text(filename) -> bool:
    """Tell whether a file is a plain text record whose header states its unit (never raises).

    Parameters
    ----------
    filename : str, os.PathLike or file-like
        The file to check.

    Returns
    -------
    bool
        ``True`` only if the header states one acceleration unit and the data are one column with
        a ``dt`` header entry or two columns of numbers. Plain files without a stated unit are
        never claimed: their units cannot be known.
    """
    text = peek_text(filename)
    if text is None:
        return False
    try:
        lines = text.splitlines()
        if len(text) >= 8192 and lines:
            lines = lines[:-1]  # the last line may be cut by the peek window
        header, rows, _ = _split(lines, "", strict=False)
        if len(rows) < 2 or not header:
            return False
        unit = header_units(header)
        if unit is None or "|" in unit:
            return False
        ncols = {len(r) for r in rows}
        if ncols == {2}:
            return True
        return ncols == {1} and _header_dt(header) is not None
    except Exception:  # noqa: BLE001 - detection must never raise
        return False


def _resolve_units(stated: str | None, found: list[tuple[str, str]], name: str):
    """Combine the caller's unit with the header's; refuse unknown or contradictory units.

    Returns
    -------
    unit : str
        The canonical unit.
    kind : str
        ``"acceleration"`` or ``"velocity"``.
    factor : float
        Factor to SI (m/s^2 or m/s).
    """
    if len({_factor(*unit) for unit in found}) > 1:
        raise UnitsError(name, "header states contradictory units of the samples ("
                               + ", ".join(unit for unit, _ in found) + "); give the file one")
    if stated is None and not found:
        raise UnitsError(
            name,
            "units unknown: a plain text record needs a header such as '# time (s), accel (g)'"
            " or " + how_to_pass("units", "UNIT", placeholder=True) + ", UNIT for example g,"
            " m/s^2, cm/s^2, gal (or m/s, cm/s for velocity, with --differentiate)",
        )
    if stated is not None:
        given = _unit_kind(stated)
        if given is None:
            si_factor(stated, name)  # raises, naming the known units
        if found and _factor(*found[0]) != _factor(*given):
            raise UnitsError(name, f"units={stated!r} contradicts the header unit {found[0][0]!r}"
                                   f" ({found[0][1]})")
        unit, kind = given
    else:
        unit, kind = found[0]
    return unit, kind, _factor(unit, kind)


def _factor(unit: str, kind: str) -> tuple[str, float]:
    """The kind and SI factor of a canonical unit (compared to tell units apart)."""
    return kind, (ACCELERATION_UNITS_TO_SI[unit] if kind == "acceleration"
                  else VELOCITY_UNITS_TO_SI[unit])


def read_text_record(
    filename,
    headonly: bool = False,
    units: str | None = None,
    dt: float | None = None,
    starttime=None,
    network: str = "",
    station: str = "",
    location: str = "",
    channel: str = "",
    **kwargs,
) -> Stream:
    """Read a one- or two-column text/CSV record into a Stream of one trace in m/s^2.

    Parameters
    ----------
    filename : str, os.PathLike or file-like
        The text file.
    headonly : bool, optional
        Read only the header (the samples are parsed anyway to know their number).
    units : str, optional
        Unit of the acceleration column (``"g"``, ``"m/s^2"``, ``"cm/s^2"``, ``"gal"``, ...);
        required unless the header states it. A velocity unit (``"m/s"``, ``"cm/s"``) reads a
        velocity record: the trace is then in m/s (``stats.units == "m/s"``), to be
        differentiated (``read_motion(..., differentiate=True)``).
    dt : float, optional
        Sampling interval [s]; required for one-column files without a ``dt =`` header line;
        checked against the time column of two-column files.
    starttime : obspy.UTCDateTime or str, optional
        Time of the first sample; default the epoch plus the first time value.
    network, station, location, channel : str, optional
        SEED codes to put in the trace header.
    **kwargs
        Ignored (obspy passes its own keywords to every plug-in).

    Returns
    -------
    obspy.Stream
        One trace; ``stats.units == "m/s**2"``, ``stats.original_units`` the unit used and the
        header lines in ``stats.shipblock_text``.

    Raises
    ------
    RecordError
        If the file is not a one/two-column numeric record, the time step is not uniform, the
        sampling interval is unknown, or samples are NaN/inf.
    UnitsError
        If the units are unknown or contradictory.
    """
    name = source_name(filename)
    header, rows, blanks = _split(read_text(filename).splitlines(), name, strict=True)
    if not rows:
        raise RecordError(name, "holds no numeric samples (empty or not a text record)")
    ncols = {len(r) for r in rows}
    if len(ncols) != 1:
        raise RecordError(name, f"rows have different numbers of columns ({sorted(ncols)})")
    (ncol,) = ncols
    components = _components(header, name) if ncol == 4 else None
    if ncol not in (1, 2) and components is None:
        raise RecordError(name, f"has {ncol} columns; expected 1 (accel), 2 (time, accel) or 4"
                                " (time and three components named in a header line, such as"
                                " '# Time (s), NS (cm/s/s), EW (cm/s/s), UD (cm/s/s)')")
    statements = header_unit_statements(header)
    notes = _check_quantity_words(header, statements, units, name)
    unit, kind, (_, factor) = _resolve_units(units, [] if notes else statements, name)
    table = np.asarray(rows, dtype=np.float64)
    t0 = 0.0
    if ncol >= 2:
        times = table[:, 0]
        if times.size < 2:
            raise RecordError(name, "a two-column record needs at least two samples")
        if not np.all(np.isfinite(times)):
            raise RecordError(name, "the time column holds NaN/inf values")
        steps = np.diff(times)
        step = float(np.median(steps))
        if not step > 0 or np.max(np.abs(steps - step)) > TIME_STEP_TOLERANCE * step:
            raise RecordError(
                name, "the time column is not uniformly increasing (non-uniform sampling)"
            )
        if dt is not None and abs(dt - step) > TIME_STEP_TOLERANCE * step:
            raise RecordError(name, f"dt={dt} s contradicts the time column step {step:g} s")
        delta, t0 = step, float(times[0])
    else:
        if blanks:
            # One column has no time to tell a gap by: a blank line may be a lost sample, and
            # every later sample would move one interval earlier.
            raise RecordError(name, f"line {blanks[0]} is blank between samples of a one-column"
                                    f" record ({len(blanks)} such lines): a sample missing? Remove"
                                    " the blank lines if none is")
        delta = dt if dt is not None else _header_dt(header)
        if delta is None:
            raise RecordError(name, "one-column record: the sampling interval is unknown; "
                                    + how_to_pass("dt", "SECONDS", placeholder=True))
    delta = check_sampling_interval(delta, name)
    start = UTCDateTime(starttime) if starttime is not None else UTCDateTime(0) + t0
    traces = []
    for column, component in enumerate(components or [{"channel": channel}], start=1):
        stats = {
            "network": network,
            "station": station,
            "location": location,
            "starttime": start,
            "units": "m/s**2" if kind == "acceleration" else "m/s",
            "original_units": unit,
            "shipblock_text": AttribDict(
                {"header_lines": header, "columns": ncol, "units": unit, "units_stated_by":
                 "caller" if units is not None else "header", "notes": notes}
            ),
            # the caller's unit is the samples' unit: the file states none, or contradicts itself
            UNITS_GIVEN_KEY: units is not None and (not statements or bool(notes)),
            **component,
        }
        values = table[:, column if components else -1]
        if headonly:
            trace = make_trace([], delta, stats)
            trace.stats.npts = values.size
        else:
            trace = make_trace(values, delta, stats)
            what = f"the {kind} column{f' {column + 1}' if components else ''}"
            check_samples(trace.data, name, what)
            trace.data *= factor
            if kind == "acceleration":
                check_plausible_samples(trace.data, name, f"{what} (in {unit})")
        traces.append(trace)
    return Stream(traces)


#: Column names of the components of a multi-column record (SCEC broadband platform ``.bbp``)
#: -> (vertical, azimuth [deg]).
_COMPONENT_NAMES = {"NS": (False, 0.0), "N-S": (False, 0.0), "N": (False, 0.0),
                    "EW": (False, 90.0), "E-W": (False, 90.0), "E": (False, 90.0),
                    "UD": (True, None), "U-D": (True, None), "UP": (True, None),
                    "Z": (True, None), "V": (True, None)}


def _components(header, name: str):
    """Channel entries of the three component columns a header line names, or ``None``."""
    for line in reversed(header):
        fields = [f.strip() for f in line.lstrip("#%!;/ ").split(",")]
        if len(fields) != 4:
            continue
        words = [re.sub(r"[\(\[].*$", "", f).strip().upper() for f in fields[1:]]
        if not all(word in _COMPONENT_NAMES for word in words):
            continue
        found = [_COMPONENT_NAMES[word] for word in words]
        if sorted(vertical for vertical, _ in found) != [False, False, True] or len(
                {azimuth for _, azimuth in found}) != 3:
            raise RecordError(name, f"the columns {', '.join(words)} are not two horizontals"
                                    " and a vertical")
        return [{"channel": f"HN{'Z' if vertical else 'NE'[int(azimuth == 90.0)]}",
                 "dip": -90.0 if vertical else 0.0,
                 **({} if vertical else {"azimuth": azimuth})} for vertical, azimuth in found]
    return None


def _check_quantity_words(header, statements, units, name) -> list[str]:
    """Refuse a header that calls the samples one quantity and gives the unit of another.

    ``# Acceleration time series in units of cm/s`` (pyrotd's ``accel_ts.bbp``) names an
    acceleration and a velocity unit: one of them is wrong, and only the caller can say which
    (``units=``, which then decides; said in the returned notes).
    """
    text = " ".join(header).lower()
    says = {q for q, words in (("acceleration", ("acceleration", "accel")),
                               ("velocity", ("velocity",))) if any(w in text for w in words)}
    stated_kinds = {k for _, k in statements}
    if len(says) != 1 or not stated_kinds or says == stated_kinds:
        return []
    (word,) = says
    if units is None:
        raise UnitsError(name, f"the header calls the samples {word} but states the"
                               f" {'/'.join(sorted(stated_kinds))} unit"
                               f" {', '.join(u for u, _ in statements)}: contradictory; state the"
                               " unit: " + how_to_pass("units", "UNIT", placeholder=True))
    return [f"the header calls the samples {word} but states"
            f" {', '.join(u for u, _ in statements)}; units={units!r} given by the caller used"]
