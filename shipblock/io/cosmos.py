"""Reader for COSMOS V1/V2 strong-motion text files (obspy waveform plug-in ``SHIPBLOCK_COSMOS``).

Written from the COSMOS Strong Motion Data Format, version 1.20 (2001) [1]_, the format CSMIP/CESMD
and the USGS NSMP distribute their V1 (uncorrected) and V2 (corrected) records in. A file holds one
or more channel blocks; each block has

* a text header (the first line says ``(Format v01.20 with 13 text lines)``; line 5 holds
  ``Code:<network>-<station>``; line 13 the values used for unknown parameters);
* ``N Integer-header values follow on M lines, Format= (10I8)`` and the integers;
* ``N Real-header values follow on M lines, Format= (6E13.6)`` and the reals;
* ``N Comment line(s) follow, each starting with a "|":`` and the comments;
* one data section per quantity, each introduced by a line such as
  ``8000 acceleration pts, approx 40 secs, units=cm/sec2 (04), Format=(8F10.5)``: V1 files have
  acceleration only, V2 files acceleration, velocity and displacement;
* an ``End-of-data for Chan 1 ...`` line.

Header entries used (1-based, as numbered in the specification): Int(1) processing stage, Int(2)
kind of quantity (1 = acceleration), Int(3) physical-units code (Table 2), Int(40), Int(42)-Int(45)
start year, month, day, hour, minute, Int(54) sensor orientation (0-360 deg azimuth, 400 up, 401
down, 402 vertical of unknown sense, 500/501 radial/transverse, 600/601 longitudinal/tangential,
700/701 horizontal of unknown azimuth), Int(55) orientation relative to the structure (used only
to tell vertical from horizontal when Int(54) is unknown), Real(1)-Real(3) station latitude,
longitude [deg] and elevation [m], Real(30) start second [s], Real(62) sampling interval [ms].

The channel and location codes come from a ``|<SCNL>STA.CHA.NET.LOC`` comment when the file has one
(the USGS NSMP and CESMD write it; ``--`` is the empty location), else the channel is ``HN`` plus
the orientation letter of Int(54). Real files can contradict themselves: the USGS copy of AK.BMR
``BNZ`` (2018 Anchorage) has Int(54)=0 (north) on a vertical channel whose text header says
"Other". When the SCNL channel's orientation (Z vs horizontal) contradicts Int(54), the reader
warns and keeps the channel code, dropping the Int(54) azimuth/dip, so a vertical record is never
silently taken as a horizontal one.

Only the acceleration sections are read. Their unit code (from the data line, checked against
Int(3)) is honoured: the samples are converted to m/s^2, ``stats.units`` is ``"m/s**2"`` and
``stats.original_units`` the file's unit. Raw counts (code 50, V0 files) are kept as counts with
``stats.units == "counts"``, for conversion with a StationXML inventory.

References
----------
.. [1] COSMOS Strong Motion Programs Board, "COSMOS Strong Motion Data Format", version 1.20,
   15 August 2001, Consortium of Organizations for Strong-Motion Observation Systems.
"""

from __future__ import annotations

import math
import re
import warnings

from obspy import Stream, UTCDateTime
from obspy.core import AttribDict

from shipblock.errors import RecordError, UnitsError
from shipblock.io._common import (
    check_delta,
    check_samples,
    make_trace,
    parse_float,
    peek_text,
    read_text,
    source_name,
)
from shipblock.units import INCH, STANDARD_GRAVITY

__all__ = ["FORMAT", "UNIT_CODES", "is_cosmos", "read_cosmos"]

#: Name under which the reader is registered as an obspy waveform plug-in.
FORMAT = "SHIPBLOCK_COSMOS"

#: The international inch [m] (exact), for the in/s^2 unit code.

#: COSMOS Table 2 physical-unit codes of acceleration: code -> (name, factor to m/s^2).
#: ``None`` marks raw counts, which need an instrument response.
UNIT_CODES: dict[int, tuple[str, float | None]] = {
    2: ("g", STANDARD_GRAVITY),
    4: ("cm/s^2", 0.01),
    7: ("in/s^2", INCH),
    10: ("gal", 0.01),
    11: ("mg", STANDARD_GRAVITY * 1e-3),
    12: ("micro-g", STANDARD_GRAVITY * 1e-6),
    50: ("counts", None),
}

#: COSMOS unit codes of quantities that are not accelerations (velocity, displacement, ...).
_NON_ACCELERATION_CODES = {1, 3, 5, 6, 8, 9, 22, 23, 24, 25, 51, 60, 80}

#: Value the specification uses for unknown parameters when the header does not say otherwise.
DEFAULT_NULL = -999

_FIRST_LINE = re.compile(r"\(\s*Format\s+v\s*[\d.]+", re.IGNORECASE)
_TEXT_LINES = re.compile(r"with\s+(\d+)\s+text\s+lines", re.IGNORECASE)
_INT_HEADER = re.compile(
    r"^\s*(\d+)\s+Integer-header\s+values\s+follow\s+on\s+(\d+)\s+lines?\s*,?\s*"
    r"Format\s*=\s*\(\s*(\d+)\s*I\s*(\d+)\s*\)",
    re.IGNORECASE,
)
_REAL_HEADER = re.compile(
    r"^\s*(\d+)\s+Real-header\s+values\s+follow\s+on\s+(\d+)\s+lines?\s*,?\s*"
    r"Format\s*=\s*\(\s*(\d+)\s*[EFGD]\s*(\d+)(?:\.\d+)?\s*\)",
    re.IGNORECASE,
)
_COMMENTS = re.compile(r"^\s*(\d+)\s+Comment\s+line", re.IGNORECASE)
_DATA_HEADER = re.compile(
    r"^\s*(\d+)\s+(.*?)\s*pts\b(.*?)Format\s*=\s*\(\s*(\d+)\s*[EFGDI]\s*(\d+)(?:\.\d+)?\s*\)",
    re.IGNORECASE,
)
_DATA_UNITS = re.compile(r"units\s*=\s*([^(,]*?)\s*\(\s*(\d+)\s*\)", re.IGNORECASE)
_STATION_CODE = re.compile(r"Code\s*:\s*([A-Za-z0-9]{1,2})\s*-\s*([A-Za-z0-9]+)")
#: USGS/CESMD comment naming the SEED channel: ``|<SCNL>8040.HNZ.NP.03`` (station.channel.net.loc).
_SCNL = re.compile(
    r"<SCNL>\s*([A-Za-z0-9]+)\.([A-Za-z0-9]{3})\.([A-Za-z0-9]{1,2})\.([A-Za-z0-9]{2}|--)?"
)
_NULLS = re.compile(r"unknown.*?(-?\d+)\s*,\s*(-?\d+\.?\d*)", re.IGNORECASE)


def is_cosmos(filename) -> bool:
    """Tell whether a file is a COSMOS V0/V1/V2 text file (never raises).

    Parameters
    ----------
    filename : str, os.PathLike or file-like
        The file to check.

    Returns
    -------
    bool
        ``True`` if line 1 carries ``(Format v...`` and an integer-header line follows.
    """
    text = peek_text(filename)
    if text is None:
        return False
    lines = text.splitlines()
    if not lines or not _FIRST_LINE.search(lines[0]):
        return False
    return any(_INT_HEADER.match(line) for line in lines[1:60])


def _fixed_width(lines, count: int, per_line: int, width: int, name: str, what: str):
    """Parse ``count`` Fortran fixed-width numbers from ``lines``."""
    values = []
    for lineno, line in lines:
        for k in range(per_line):
            field = line[k * width : (k + 1) * width]
            if not field.strip():
                continue
            try:
                values.append(parse_float(field))
            except ValueError:
                raise RecordError(
                    name, f"line {lineno}: {field.strip()!r} in the {what} is not a number"
                ) from None
    if len(values) != count:
        raise RecordError(
            name, f"the {what} should hold {count} values but {len(values)} were found"
            " (truncated or corrupt file)"
        )
    return values


class _Lines:
    """A cursor over the numbered lines of a file (private helper)."""

    def __init__(self, lines, name):
        self.lines = lines
        self.index = 0
        self.name = name

    def skip_blank(self):
        while self.index < len(self.lines) and not self.lines[self.index].strip():
            self.index += 1

    def at_end(self) -> bool:
        self.skip_blank()
        return self.index >= len(self.lines)

    def peek(self) -> str:
        return self.lines[self.index] if self.index < len(self.lines) else ""

    def take(self, count: int, what: str):
        if count < 0 or self.index + count > len(self.lines):
            raise RecordError(self.name, f"ends inside the {what} (truncated file)")
        block = [(self.index + 1 + k, self.lines[self.index + k]) for k in range(count)]
        self.index += count
        return block

    def expect(self, pattern, what: str):
        self.skip_blank()
        line = self.peek()
        match = pattern.match(line)
        if match is None:
            raise RecordError(
                self.name, f"line {self.index + 1}: expected the {what} line, found {line[:60]!r}"
            )
        self.index += 1
        return match


def _value(values, number: int, null: float):
    """Return header value ``number`` (1-based), or ``None`` if absent or unknown."""
    if number > len(values):
        return None
    value = values[number - 1]
    if value == null or (isinstance(value, float) and not math.isfinite(value)):
        return None
    return value


def _orientation(code, null_note: list) -> tuple[dict, str]:
    """Map COSMOS Int(54) to ``azimuth``/``dip`` [deg] entries and a channel orientation letter."""
    if code is None:
        return {}, "X"
    code = int(code)
    if 0 <= code <= 360:
        azimuth = float(code % 360)
        letter = {0.0: "N", 90.0: "E"}.get(azimuth, "H")
        return {"azimuth": azimuth, "dip": 0.0}, letter
    if code == 400:
        return {"dip": -90.0}, "Z"
    if code == 401:
        return {"dip": 90.0}, "Z"
    if code == 402:
        null_note.append("vertical sense not indicated in the file (code 402); taken positive up")
        return {"dip": -90.0}, "Z"
    if code in (500, 600, 700):
        return {"dip": 0.0}, "1"
    if code in (501, 601, 701):
        return {"dip": 0.0}, "2"
    return {}, "X"


def _scnl(comments) -> tuple[str, str, str, str] | None:
    """Return ``(station, channel, network, location)`` from a ``<SCNL>`` comment, if any."""
    for line in comments:
        if (m := _SCNL.search(line)) is not None:
            station, channel, network, location = m.groups()
            location = "" if location in (None, "--") else location
            return station, channel.upper(), network.upper(), location
    return None


def _data_units(data_line: str, int_code, name: str) -> tuple[int, str]:
    """Return the unit code of a data section, cross-checked with Int(3)."""
    match = _DATA_UNITS.search(data_line)
    line_code = int(match.group(2)) if match else None
    line_text = match.group(1).strip() if match else ""
    if line_code is not None and int_code is not None and int(int_code) != line_code:
        raise UnitsError(
            name,
            f"data line says unit code {line_code:02d} ({line_text}) but Int(3) says"
            f" {int(int_code):02d}",
        )
    code = line_code if line_code is not None else (None if int_code is None else int(int_code))
    if code is None:
        raise UnitsError(name, "the acceleration data carry no unit code (data line nor Int(3))")
    if code not in UNIT_CODES:
        raise UnitsError(name, f"unit code {code:02d} ({line_text or '?'}) is not an acceleration")
    return code, line_text


def _start_time(ints, reals, null) -> UTCDateTime | None:
    """Return the record start time from Int(40), Int(42)-Int(45) and Real(30), if known."""
    parts = [_value(ints, k, null) for k in (40, 42, 43, 44, 45)]
    second = _value(reals, 30, null)
    if any(p is None for p in parts):
        return None
    try:
        year, month, day, hour, minute = (int(p) for p in parts)
        return UTCDateTime(year, month, day, hour, minute) + (second or 0.0)
    except Exception:  # noqa: BLE001 - an impossible date means "unknown"
        return None


def _read_block(cursor: _Lines, name: str, headonly: bool):
    """Read one channel block; return its acceleration trace (or ``None``)."""
    first = cursor.peek()
    if not _FIRST_LINE.search(first):
        raise RecordError(
            name, f"line {cursor.index + 1}: expected a COSMOS text header, found {first[:60]!r}"
        )
    n_text = int(m.group(1)) if (m := _TEXT_LINES.search(first)) else 13
    text = [line for _, line in cursor.take(n_text, "text header")]
    nulls = _NULLS.search(text[12]) if len(text) > 12 else None
    int_null = int(nulls.group(1)) if nulls else DEFAULT_NULL
    real_null = float(nulls.group(2)) if nulls else float(DEFAULT_NULL)

    m = cursor.expect(_INT_HEADER, "integer-header")
    count, n_lines, per_line, width = (int(g) for g in m.groups())
    ints = [int(v) for v in _fixed_width(cursor.take(n_lines, "integer header"), count,
                                         per_line, width, name, "integer header")]
    m = cursor.expect(_REAL_HEADER, "real-header")
    count, n_lines, per_line, width = (int(g) for g in m.groups())
    reals = _fixed_width(cursor.take(n_lines, "real header"), count, per_line, width, name,
                         "real header")
    m = cursor.expect(_COMMENTS, "comment-count")
    comments = [line for _, line in cursor.take(int(m.group(1)), "comments")]

    trace = None
    while not cursor.at_end() and (m := _DATA_HEADER.match(cursor.peek())):
        data_line = cursor.peek()
        cursor.index += 1
        npts, kind, per_line, width = int(m.group(1)), m.group(2), int(m.group(4)), int(m.group(5))
        n_lines = math.ceil(npts / per_line) if per_line > 0 else -1
        block = cursor.take(n_lines, f"{kind} data")
        if "acc" not in kind.lower() or trace is not None:
            continue  # velocity and displacement sections of V2 files
        code, unit_text = _data_units(data_line, _value(ints, 3, int_null), name)
        trace = _make_trace(name, text, ints, reals, comments, (int_null, real_null),
                            data_line, code, unit_text, npts)
        if not headonly:
            samples = _fixed_width(block, npts, per_line, width, name, f"{kind} data")
            trace.data = make_trace(samples, trace.stats.delta, {}).data
            check_samples(trace.data, name, f"channel {trace.stats.channel}")
            factor = UNIT_CODES[code][1]
            if factor is not None:
                trace.data *= factor
    while not cursor.at_end() and cursor.peek().strip().lower().startswith("end-of-data"):
        cursor.index += 1
    return trace


def _make_trace(name, text, ints, reals, comments, nulls, data_line, code, unit_text, npts):
    """Build the (still empty) trace of an acceleration section with its header."""
    int_null, real_null = nulls
    kind = _value(ints, 2, int_null)
    if kind is not None and int(kind) != 1:
        raise UnitsError(name, f"Int(2)={int(kind)}: the record is not an acceleration")
    delta_ms = _value(reals, 62, real_null)
    if delta_ms is None:
        raise RecordError(name, "the sampling interval Real(62) is unknown")
    delta = check_delta(delta_ms / 1000.0, name)
    notes: list[str] = []
    sensor, source = _value(ints, 54, int_null), "Int(54)"
    relative = _value(ints, 55, int_null)
    if sensor is None and relative is not None:
        # USGS NSMP structure arrays (e.g. NP.8040) leave Int(54) unknown and give the orientation
        # relative to the structure in Int(55): enough to tell vertical from horizontal, not the
        # azimuth (700 = horizontal of unknown azimuth).
        sensor, source = (relative if int(relative) in (400, 401, 402) else 700), "Int(55)"
    orientation, letter = _orientation(sensor, notes)
    for note in notes:
        warnings.warn(f"{name}: {note}", stacklevel=4)
    channel, location = "HN" + letter, ""
    scnl = _scnl(comments)
    if scnl is not None:
        channel, location = scnl[1], scnl[3]
        vertical_by_code = channel[-1] == "Z"
        if letter != "X" and (letter == "Z") != vertical_by_code:
            kinds = ("horizontal", "vertical")
            note = (
                f"{source}={int(sensor)} says {kinds[letter == 'Z']} but the <SCNL> channel code"
                f" {channel} says {kinds[vertical_by_code]}; {source} ignored, orientation taken"
                " from the channel code"
            )
            notes.append(note)
            warnings.warn(f"{name}: {note}", stacklevel=4)
            orientation = {}
    station_match = _STATION_CODE.search(text[4]) if len(text) > 4 else None
    start = _start_time(ints, reals, int_null)
    unit_name, factor = UNIT_CODES[code]
    header = AttribDict(
        {
            "text_header": text,
            "integer_header": ints,
            "real_header": reals,
            "comments": comments,
            "data_line": data_line.strip(),
            "unit_code": code,
            "unit_text": unit_text,
            "processing_stage": _value(ints, 1, int_null),
            "orientation_code": _value(ints, 54, int_null),
            "scnl": scnl,
            "notes": notes,
            "start_time_known": start is not None,
        }
    )
    stats = {
        "network": station_match.group(1).upper() if station_match else "",
        "station": station_match.group(2) if station_match else "",
        "location": location,
        "channel": channel,
        "units": "counts" if factor is None else "m/s**2",
        "original_units": unit_name,
        "shipblock_cosmos": header,
        **orientation,
    }
    coordinates = [_value(reals, k, real_null) for k in (1, 2, 3)]
    if coordinates[0] is not None and coordinates[1] is not None:
        stats["coordinates"] = AttribDict(
            latitude=coordinates[0], longitude=coordinates[1], elevation=coordinates[2] or 0.0
        )
    trace = make_trace([], delta, stats)
    trace.stats.npts = npts
    if start is not None:
        trace.stats.starttime = start
    return trace


def read_cosmos(filename, headonly: bool = False, **kwargs) -> Stream:
    """Read a COSMOS V1/V2 file into a Stream of acceleration traces.

    Parameters
    ----------
    filename : str, os.PathLike or file-like
        The COSMOS file (one or more channels).
    headonly : bool, optional
        Read only the headers; the traces then have no samples.
    **kwargs
        Ignored (obspy passes its own keywords to every plug-in).

    Returns
    -------
    obspy.Stream
        One trace per channel, in m/s^2 (``stats.units == "m/s**2"``) or raw counts
        (``stats.units == "counts"``); ``stats.azimuth``/``stats.dip`` [deg] from Int(54), and the
        original header in ``stats.shipblock_cosmos``.

    Raises
    ------
    RecordError
        If the file is not COSMOS, is truncated or corrupt, or holds NaN/inf samples.
    UnitsError
        If a unit code is missing, inconsistent or not an acceleration.
    """
    name = source_name(filename)
    cursor = _Lines(read_text(filename).splitlines(), name)
    if cursor.at_end():
        raise RecordError(name, "is empty")
    traces = []
    while not cursor.at_end():
        trace = _read_block(cursor, name, headonly)
        if trace is not None:
            traces.append(trace)
    if not traces:
        raise RecordError(name, "holds no acceleration data section")
    return Stream(traces)
