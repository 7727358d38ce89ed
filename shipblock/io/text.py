"""Reader for plain one- or two-column text/CSV records (obspy plug-in ``SHIPBLOCK_TEXT``).

A plain record is either one column (acceleration, the sampling interval given by the caller or a
``dt = 0.01`` header line) or two columns (time [s], acceleration), separated by commas,
semicolons, tabs or spaces. Lines starting with ``#``, ``%``, ``!``, ``;`` or ``//`` are comments;
non-numeric lines before the first sample (a CSV header such as ``time,accel``) are header lines.

Plain text carries no agreed unit, so the unit must be stated: either by the caller
(``units="g"``, ``"m/s^2"``, ``"cm/s^2"``, ``"gal"``, ...) or in a header line, in brackets after
the quantity (``# Time (s),Acceleration (g's)``, ``accel [m/s^2]``) or as ``units: cm/s^2``. A
file with neither is refused with :class:`~shipblock.errors.UnitsError`; if both are given they
must agree. For the same reason :func:`is_text` auto-detects only files whose header states an
acceleration unit; any other plain file is read with ``format="SHIPBLOCK_TEXT"`` and ``units=``,
or through :func:`shipblock.read_motion` with ``units=``.
"""

from __future__ import annotations

import re

import numpy as np
from obspy import Stream, UTCDateTime
from obspy.core import AttribDict

from shipblock.errors import RecordError, UnitsError
from shipblock.checks import how_to_pass
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
from shipblock.units import VELOCITY_UNITS_TO_SI, canonical_unit, canonical_velocity_unit, si_factor

__all__ = ["FORMAT", "TIME_STEP_TOLERANCE", "is_text", "read_text_record"]

#: Name under which the reader is registered as an obspy waveform plug-in.
FORMAT = "SHIPBLOCK_TEXT"

#: Largest deviation of a time step from the median step, as a fraction of the step [-].
TIME_STEP_TOLERANCE = 0.01

_COMMENT_PREFIXES = ("#", "%", "!", ";", "//")
_SPLIT = re.compile(r"[,;\s]+")
_BRACKETED = re.compile(r"[\(\[\{]\s*([^\)\]\}]+?)\s*[\)\]\}]")
_UNITS_KEY = re.compile(r"\bunits?\s*[:=]\s*([^\s,;]+)", re.IGNORECASE)
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
    """
    header, rows = [], []
    for lineno, line in enumerate(lines, start=1):
        if not line.strip():
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
    return header, rows


def header_units(header_lines) -> str | None:
    """Find an acceleration unit stated in header lines.

    Parameters
    ----------
    header_lines : list of str
        Comment/header lines of a text record.

    Returns
    -------
    str or None
        The canonical unit key (see :func:`shipblock.units.canonical_unit`), or ``None``.

    Raises
    ------
    UnitsError
        Never raised here; conflicting statements are resolved by the caller.
    """
    found = []
    for line in header_lines:
        candidates = _BRACKETED.findall(line) + _UNITS_KEY.findall(line)
        for candidate in candidates:
            key = canonical_unit(candidate)
            if key is not None and key not in found:
                found.append(key)
    return found[0] if len(found) == 1 else (None if not found else "|".join(found))


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
        header, rows = _split(lines, "", strict=False)
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


def _resolve_units(stated: str | None, found: str | None, name: str) -> str:
    """Combine the caller's unit with the header's; refuse unknown or conflicting units."""
    if found is not None and "|" in found:
        raise UnitsError(name, f"header states several units ({found.replace('|', ', ')})")
    if stated is None and found is None:
        raise UnitsError(
            name,
            "units unknown: a plain text record needs a header such as '# time (s), accel (g)'"
            " or " + how_to_pass("units", "UNIT", placeholder=True) + ", UNIT for example g,"
            " m/s^2, cm/s^2, gal (or m/s, cm/s for velocity, with --differentiate)",
        )
    if stated is not None and canonical_velocity_unit(stated) is not None:
        if found is not None:
            raise UnitsError(name, f"units={stated!r} (a velocity) contradicts the header unit"
                                   f" {found!r}")
        return canonical_velocity_unit(stated)
    if stated is not None:
        si_factor(stated, name)
        if found is not None and si_factor(stated, name) != si_factor(found, name):
            raise UnitsError(name, f"units={stated!r} contradicts the header unit {found!r}")
        return canonical_unit(stated)
    return found


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
    header, rows = _split(read_text(filename).splitlines(), name, strict=True)
    if not rows:
        raise RecordError(name, "holds no numeric samples (empty or not a text record)")
    ncols = {len(r) for r in rows}
    if len(ncols) != 1:
        raise RecordError(name, f"rows have different numbers of columns ({sorted(ncols)})")
    (ncol,) = ncols
    if ncol not in (1, 2):
        raise RecordError(name, f"has {ncol} columns; expected 1 (accel) or 2 (time, accel)")
    stated_by_header = header_units(header)
    unit = _resolve_units(units, stated_by_header, name)
    velocity = canonical_velocity_unit(unit) is not None
    factor = VELOCITY_UNITS_TO_SI[unit] if velocity else si_factor(unit, name)
    table = np.asarray(rows, dtype=np.float64)
    accel = table[:, -1]
    t0 = 0.0
    if ncol == 2:
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
        delta = dt if dt is not None else _header_dt(header)
        if delta is None:
            raise RecordError(name, "one-column record: the sampling interval is unknown; "
                                    + how_to_pass("dt", "SECONDS", placeholder=True))
    delta = check_sampling_interval(delta, name)
    start = UTCDateTime(starttime) if starttime is not None else UTCDateTime(0) + t0
    stats = {
        "network": network,
        "station": station,
        "location": location,
        "channel": channel,
        "starttime": start,
        "units": "m/s" if velocity else "m/s**2",
        "original_units": unit,
        UNITS_GIVEN_KEY: stated_by_header is None,
        "shipblock_text": AttribDict(
            {"header_lines": header, "columns": ncol, "units": unit, "units_stated_by":
             "caller" if units is not None else "header"}
        ),
    }
    if headonly:
        trace = make_trace([], delta, stats)
        trace.stats.npts = accel.size
        return Stream([trace])
    trace = make_trace(accel, delta, stats)
    check_samples(trace.data, name, "the acceleration column")
    trace.data *= factor
    if not velocity:
        check_plausible_samples(trace.data, name, f"the acceleration column (in {unit})")
    return Stream([trace])
