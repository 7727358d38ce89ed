"""Reader for COSMOS V0/V1/V2 strong-motion text files (obspy plug-in ``SHIPBLOCK_COSMOS``).

Written from the COSMOS Strong Motion Data Format, version 1.20 (2001) [1]_, the format CSMIP/CESMD
and the USGS NSMP distribute their V0 (raw counts), V1 (uncorrected) and V2 (corrected) records in.
A file holds one or more channel blocks; each block has

* a text header (the first line names the data, e.g. ``Corrected acceleration``, and says
  ``(Format v01.20 with 13 text lines)``; line 5 holds ``Code:<network>-<station>``; line 8 the
  record start time; line 11 the peak; line 13 the values used for unknown parameters);
* ``N Integer-header values follow on M lines, Format= (10I8)`` and the integers;
* ``N Real-header values follow on M lines, Format= (6E13.6)`` and the reals;
* ``N Comment line(s) follow, each starting with a "|":`` and the comments;
* one data section per quantity, each introduced by a line such as
  ``8000 acceleration pts, approx 40 secs, units=cm/sec2 (04), Format=(8F10.5)``: V0/V1 files have
  acceleration only, V2 files acceleration, velocity and displacement; its ``approx N secs`` is
  checked against the samples x Real(62) (1 s + 1 %: a damaged interval is refused);
* an end-of-data line.

Header entries used (1-based, as numbered in the specification): Int(1) processing stage, Int(2)
kind of quantity (1 = acceleration), Int(3) physical-units code (Table 2), Int(40), Int(42)-Int(45)
start year, month, day, hour, minute, Int(54) sensor orientation (0-360 deg azimuth, 400 up, 401
down, 402 vertical of unknown sense, 500/501 radial/transverse, 600/601 longitudinal/tangential,
700/701 horizontal of unknown azimuth, 2000 other), Int(55) orientation relative to the structure
(used only to tell vertical from horizontal when Int(54) is unknown), Real(1)-Real(3) station
latitude, longitude [deg] and elevation [m], Real(30) start second [s], Real(62) sampling interval
[ms], Real(63) record length [s], Real(64)/Real(65) the peak of the data (file units, signed) and
its time [s].

What the real files (USGS NSMP, AK via USGS, and the CESMD-style test files of the gmprocess
corpus) showed beyond the specification:

* **End-of-data lines** are written as ``End-of-data for ChanHNE``, ``End-of-data for
  1795.HNE.NP.-- acceleration`` or ``/&  ----------  End of data for channel  1  ----------``
  (all three are accepted; a block without one, or anything else between blocks, is an error:
  it is how a file cut at a line boundary shows).
* **Fixed-width samples run together**: ``(10I8)`` counts such as ``-1341626-1341627`` have no
  blank between them, so the data are cut by the format's field width, not split on blanks. A
  data line must end on a field boundary: a file cut inside the last field (``-2378631`` cut to
  ``-237863``) would otherwise still parse.
* **Unknown values** (``-999``) where readers expect a value: Int(1) (processing stage) and Int(2)
  unknown in a CESMD-style file whose line 1 says ``Corrected acceleration`` and whose data line
  says ``acceleration pts, units=cm/sec2(04)``. Neither is needed to read the samples: the stage is
  then taken from line 1 (``Raw acceleration counts`` 0, ``Uncorrected`` 1, ``Corrected`` 2) and
  noted. Real(30) (start second) unknown: the start time is taken from text line 8
  (``Rcrd start time:06/16/2005, 20:53:04.400 UTC``, printed to 1 ms); with neither, the start
  time is left unset rather than rounded to the minute. Line 13 may list no null values at all
  (the specification's ``-999`` is then used).
* **Station code with no network**: ``Code:---J2236`` (network ``--``, i.e. unknown).
* **Self-contradicting orientation**: the USGS copy of AK.BMR ``BNZ`` (2018 Anchorage) has
  Int(54)=0 (north) on a channel that the ``|<SCNL>BMR.BNZ.AK.--`` comment, the RcrdId and the file
  name call vertical and whose text line 9 says "Other". When the SCNL channel's orientation (Z vs
  horizontal, or N vs E) contradicts Int(54), the reader warns and keeps the channel code, dropping
  the Int(54) azimuth/dip, so a vertical record is never silently taken as a horizontal one.
* **Structure arrays** (NP.8040, R B Atwood building) leave Int(54) unknown and give the
  orientation relative to the structure in Int(55) (400 = up, 90 = a horizontal): enough to tell
  vertical from horizontal, not a geographic azimuth.
* **Self-contradicting units**: a data line ``units=cm/sec2(04)`` under Int(3)=25 (degrees) is
  refused (:class:`~shipblock.errors.UnitsError` naming the channel block), since either could be
  the wrong one.

The channel and location codes come from a ``|<SCNL>STA.CHA.NET.LOC`` comment when the file has one
(the USGS NSMP writes it; ``--`` is the empty location), else from
:func:`~shipblock.io._common.orientation_stats` (``HNZ``, ``HNN``, ``HNE``, ``HN1``/``HN2`` for
other or unknown azimuths, numbered in file order; ``HNX`` when nothing says whether the channel is
vertical).

Only the acceleration sections are read. Their unit code (from the data line, checked against
Int(3)) is honoured: the samples are converted to m/s^2, ``stats.units`` is ``"m/s**2"`` and
``stats.original_units`` the file's unit. Raw counts (code 50, V0 files) are kept as counts with
``stats.units == "counts"``, for conversion with a StationXML inventory. The stated peak
Real(64) is kept in ``stats.shipblock_cosmos.stated_peak`` (file units) and, for accelerations,
``stats.stated_peak_si`` (m/s^2, absolute value).

References
----------
.. [1] COSMOS Strong Motion Programs Board, "COSMOS Strong Motion Data Format", version 1.20,
   15 August 2001, Consortium of Organizations for Strong-Motion Observation Systems.
"""

from __future__ import annotations

import math
import re
import warnings

import numpy as np
from obspy import Stream, UTCDateTime
from obspy.core import AttribDict

from shipblock.errors import RecordError, UnitsError
from shipblock.io._common import (
    CARDINAL_TOLERANCE_DEG,
    band_code,
    check_plausible_samples,
    check_samples,
    check_sampling_interval,
    fixed_fields,
    horizontal_index,
    make_trace,
    orientation_stats,
    parse_float,
    peek_text,
    read_text,
    source_name,
)
from shipblock.units import INCH, STANDARD_GRAVITY

__all__ = ["FORMAT", "UNIT_CODES", "is_cosmos", "read_cosmos"]

#: Name under which the reader is registered as an obspy waveform plug-in.
FORMAT = "SHIPBLOCK_COSMOS"

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

#: COSMOS Table 2 codes of quantities that are not accelerations, named for error messages.
_OTHER_UNIT_NAMES = {
    1: "s", 3: "s and g", 5: "cm/s", 6: "cm", 8: "in/s", 9: "in", 22: "mV", 23: "deg/s^2",
    24: "deg/s", 25: "deg", 51: "V", 60: "psi", 80: "micro-strain",
}

#: Value the specification uses for unknown parameters when the header does not say otherwise.
DEFAULT_NULL = -999

#: Precision of the start time printed on text line 8 [s] (milliseconds, rounded).
TEXT_START_PRECISION_S = 0.5e-3

#: Processing stage (Int(1)) named by the first words of text line 1, when Int(1) is unknown.
_STAGE_WORDS = (("raw", 0), ("uncorrected", 1), ("corrected", 2))

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
_APPROX_SECS = re.compile(r"approx\.?\s*(\d+(?:\.\d*)?)\s*sec", re.IGNORECASE)
#: Tolerance of a data line's ``approx N secs`` against samples x interval: the printed
#: rounding (whole seconds) and one per cent.
APPROX_DURATION_ATOL_S = 1.0
APPROX_DURATION_RTOL = 0.01
_DATA_UNITS = re.compile(r"units\s*=\s*([^(,]*?)\s*\(\s*(\d+)\s*\)", re.IGNORECASE)
#: ``Code:CE-J2236``; ``--`` (written ``---J2236``) is an unknown network.
_STATION_CODE = re.compile(r"Code\s*:\s*([A-Za-z0-9]{1,2}|--)\s*-\s*([A-Za-z0-9]+)")
#: USGS/CESMD comment naming the SEED channel: ``|<SCNL>8040.HNZ.NP.03`` (station.channel.net.loc).
_SCNL = re.compile(
    r"<SCNL>\s*([A-Za-z0-9]+)\.([A-Za-z0-9]{3})\.([A-Za-z0-9]{1,2})\.([A-Za-z0-9]{2}|--)?"
)
_NULLS = re.compile(r"unknown.*?(-?\d+)\s*,\s*(-?\d+\.?\d*)", re.IGNORECASE)
#: End of a channel block: ``End-of-data for ChanHNE`` or ``/&  ---  End of data for channel 1``.
_END_OF_DATA = re.compile(r"^\s*(/&|end[\s-]*of[\s-]*data)", re.IGNORECASE)
#: Text line 8: ``Rcrd start time: 2018/11/30 17:29:39.137 UTC`` or ``...:06/16/2005, 20:53:04.4``.
_TEXT_START = re.compile(
    r"start\s+time\s*:\s*(\d{1,4})[/-](\d{1,2})[/-](\d{1,4})\s*,?\s*"
    r"(\d{1,2}):(\d{1,2}):(\d{1,2}(?:\.\d*)?)",
    re.IGNORECASE,
)
#: Text line 11: ``Max =  -161.962 cm/sec2  at  27.850 sec`` or ``Max =   1033406 counts, at ...``.
_TEXT_PEAK = re.compile(
    r"Max\s*=\s*([-+]?(?:\d+\.?\d*|\.\d+))\s*([^\s,]*)\s*,?\s*at\s*([-+]?(?:\d+\.?\d*|\.\d+))",
    re.IGNORECASE,
)


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


def _fixed_width(lines, count: int, per_line: int, width: int, name: str, what: str,
                 aligned: bool = False):
    """Parse ``count`` Fortran fixed-width numbers from ``lines``.

    With ``aligned``, each line must end on a field boundary: Fortran right-justifies numbers,
    so a line ending inside a field was cut (``-2378631`` cut to ``-237863`` is still a number).
    """
    values = []
    for lineno, line in lines:
        if aligned and len(line.rstrip()) % width:
            raise RecordError(
                name, f"line {lineno}: the {what} line ends inside a {width}-character field"
                " (truncated or corrupt file)"
            )
        for field in fixed_fields(line, width, per_line):
            if not field.strip():
                continue
            try:
                values.append(parse_float(field))
            except ValueError:
                raise RecordError(
                    name, f"line {lineno}: {field.strip()!r} in the {what} is not a number"
                ) from None
        if len(line.rstrip()) > per_line * width:
            raise RecordError(
                name, f"line {lineno}: the {what} line is longer than its format"
                f" ({per_line} fields of {width} characters)"
            )
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


def _orientation(code) -> dict | None:
    """Interpret an Int(54)/Int(55) orientation code.

    Returns ``None`` for an unknown or unrecognised code, else a dict with ``vertical`` (bool),
    ``azimuth`` [deg] or ``None``, ``positive_up`` (bool), ``index`` (1/2 for the horizontals that
    COSMOS numbers, else ``None``) and ``note`` (a caveat, or ``None``).
    """
    if code is None:
        return None
    code = int(code)
    result = {"vertical": False, "azimuth": None, "positive_up": True, "index": None, "note": None}
    if 0 <= code <= 360:
        result["azimuth"] = float(code % 360)
    elif code in (400, 401, 402):
        result.update(vertical=True, positive_up=code != 401)
        if code == 402:
            result["note"] = ("vertical sense not indicated in the file (code 402); taken"
                              " positive up")
    elif code in (500, 600, 700):
        result["index"] = 1
    elif code in (501, 601, 701):
        result["index"] = 2
    else:
        return None  # 2000 "other" and codes the specification does not define
    return result


def _scnl(comments) -> tuple[str, str, str, str] | None:
    """Return ``(station, channel, network, location)`` from a ``<SCNL>`` comment, if any."""
    for line in comments:
        if (m := _SCNL.search(line)) is not None:
            station, channel, network, location = m.groups()
            location = "" if location in (None, "--") else location
            return station, channel.upper(), network.upper(), location
    return None


def _unit_label(code: int) -> str:
    """Name of a COSMOS Table 2 unit code, for messages."""
    if code in UNIT_CODES:
        return UNIT_CODES[code][0]
    return _OTHER_UNIT_NAMES.get(code, "not in COSMOS Table 2")


def _data_units(data_line: str, int_code, name: str, where: str) -> tuple[int, str]:
    """Return the unit code of a data section, cross-checked with Int(3)."""
    match = _DATA_UNITS.search(data_line)
    line_code = int(match.group(2)) if match else None
    line_text = match.group(1).strip() if match else ""
    if line_code is not None and int_code is not None and int(int_code) != line_code:
        raise UnitsError(
            name,
            f"{where}: data line says unit code {line_code:02d} ({line_text}) but Int(3) says"
            f" {int(int_code):02d} ({_unit_label(int(int_code))}); the units are contradictory",
        )
    code = line_code if line_code is not None else (None if int_code is None else int(int_code))
    if code is None:
        raise UnitsError(
            name, f"{where}: the acceleration data carry no unit code (data line nor Int(3))"
        )
    if code not in UNIT_CODES:
        raise UnitsError(
            name, f"{where}: unit code {code:02d} ({line_text or _unit_label(code)}) is not an"
            " acceleration"
        )
    return code, line_text


def _text_start(line: str) -> UTCDateTime | None:
    """Parse the start time of text line 8 (``yyyy/mm/dd`` or ``mm/dd/yyyy``), or ``None``."""
    match = _TEXT_START.search(line)
    if match is None:
        return None
    a, b, c, hour, minute, second = match.groups()
    year, month, day = (a, b, c) if len(a) == 4 else (c, a, b)
    try:
        return UTCDateTime(int(year), int(month), int(day), int(hour), int(minute)) + float(second)
    except Exception:  # noqa: BLE001 - an impossible date means "not stated"
        return None


def _start_time(ints, reals, null, text, notes) -> UTCDateTime | None:
    """Record start from Int(40), Int(42)-Int(45) and Real(30), else from text line 8."""
    line8 = _text_start(text[7]) if len(text) > 7 else None
    parts = [_value(ints, k, null[0]) for k in (40, 42, 43, 44, 45)]
    second = _value(reals, 30, null[1])
    start = None
    if all(p is not None for p in parts) and second is not None:
        try:
            year, month, day, hour, minute = (int(p) for p in parts)
            start = UTCDateTime(year, month, day, hour, minute) + float(second)
        except Exception:  # noqa: BLE001 - an impossible date means "unknown"
            start = None
    if start is None:
        if line8 is not None:
            notes.append("start time from text line 8 (integer/real header incomplete)")
        return line8
    if line8 is not None and abs(line8 - start) > TEXT_START_PRECISION_S + 1e-9:
        notes.append(f"text line 8 start time {line8} differs from the header's {start}")
    return start


def _processing_stage(ints, null: int, first_line: str, notes) -> int | None:
    """Int(1), or the stage named by text line 1 when Int(1) is unknown."""
    stage = _value(ints, 1, null)
    if stage is not None:
        return int(stage)
    words = first_line.split("(")[0].strip().lower()
    for word, value in _STAGE_WORDS:
        if words.startswith(word):
            notes.append(f"Int(1) unknown; processing stage {value} from text line 1")
            return value
    return None


def _read_block(cursor: _Lines, name: str, headonly: bool, horizontals: list):
    """Read one channel block; return its acceleration trace (or ``None``)."""
    first = cursor.peek()
    block_line = cursor.index + 1
    if not _FIRST_LINE.search(first):
        raise RecordError(
            name, f"line {block_line}: expected a COSMOS text header, found {first[:60]!r}"
        )
    n_text = int(m.group(1)) if (m := _TEXT_LINES.search(first)) else 13
    text = [line for _, line in cursor.take(n_text, "text header")]
    nulls = _NULLS.search(text[12]) if len(text) > 12 else None
    int_null = int(nulls.group(1)) if nulls else DEFAULT_NULL
    real_null = float(nulls.group(2)) if nulls else float(DEFAULT_NULL)

    m = cursor.expect(_INT_HEADER, "integer-header")
    count, n_lines, per_line, width = (int(g) for g in m.groups())
    ints = _fixed_width(cursor.take(n_lines, "integer header"), count, per_line, width, name,
                        "integer header")
    if not all(math.isfinite(v) for v in ints):
        raise RecordError(name, f"line {block_line}: the integer header holds NaN/inf")
    ints = [int(v) for v in ints]
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
        where = f"channel block at line {block_line}"
        code, unit_text = _data_units(data_line, _value(ints, 3, int_null), name, where)
        trace = _make_trace(name, text, ints, reals, comments, (int_null, real_null),
                            data_line, code, unit_text, npts, horizontals)
        _check_approx_duration(data_line, npts, trace.stats.delta, name, block_line)
        if not headonly:
            samples = _fixed_width(block, npts, per_line, width, name, f"{kind} data",
                                   aligned=True)
            trace.data = make_trace(samples, trace.stats.delta, {}).data
            check_samples(trace.data, name, f"channel {trace.stats.channel}")
            factor = UNIT_CODES[code][1]
            if factor is not None:
                trace.data *= factor
                check_plausible_samples(trace.data, name, f"channel {trace.stats.channel}")
    if cursor.at_end() or not _END_OF_DATA.match(cursor.peek()):
        found = repr(cursor.peek()[:60]) if not cursor.at_end() else "the end of the file"
        raise RecordError(
            name, f"line {cursor.index + 1}: expected the end-of-data line of the channel block at"
            f" line {block_line}, found {found} (truncated file or wrong sample count)"
        )
    while not cursor.at_end() and _END_OF_DATA.match(cursor.peek()):
        cursor.index += 1
    return trace


def _channel(name, orientation, scnl, sampling_rate, horizontals, notes) -> tuple[str, dict]:
    """SEED channel code and ``azimuth``/``dip`` entries of one block."""
    if scnl is None:
        if orientation is None:
            return f"{band_code(sampling_rate)}NX", {}
        index = orientation["index"]
        if not orientation["vertical"] and index is None:
            # A stated azimuth names the axis (1 nearer north-south, 2 nearer east-west), so the
            # horizontals of a station split into one file a channel never share a code; an
            # unknown azimuth goes by file order.
            index = (min(len(horizontals) + 1, 2) if orientation["azimuth"] is None
                     else horizontal_index(orientation["azimuth"]))
        if not orientation["vertical"]:
            horizontals.append(index)
        stats = orientation_stats(
            sampling_rate, vertical=orientation["vertical"], azimuth_deg=orientation["azimuth"],
            positive_up=orientation["positive_up"], index=index or 1,
        )
        return stats.pop("channel"), stats
    channel = scnl[1]
    if orientation is None:
        return channel, {}
    stats = orientation_stats(
        sampling_rate, vertical=orientation["vertical"], azimuth_deg=orientation["azimuth"],
        positive_up=orientation["positive_up"], index=orientation["index"] or 1,
    )
    by_code = {"Z": "vertical", "N": "north", "E": "east"}.get(channel[-1])
    by_header = "vertical" if orientation["vertical"] else "horizontal"
    conflict = by_code is not None and (by_code == "vertical") != orientation["vertical"]
    if not conflict and by_code in ("north", "east") and orientation["azimuth"] is not None:
        target = 0.0 if by_code == "north" else 90.0
        gap = abs(orientation["azimuth"] - target) % 360.0
        if min(gap, 360.0 - gap) > CARDINAL_TOLERANCE_DEG:
            conflict, by_header = True, f"azimuth {orientation['azimuth']:g} deg"
    if conflict:
        note = (
            f"{orientation['source']}={orientation['code']} says {by_header} but the <SCNL>"
            f" channel code {channel} says {by_code}; {orientation['source']} ignored, orientation"
            " taken from the channel code"
        )
        notes.append(note)
        warnings.warn(f"{name}: {note}", stacklevel=5)
        return channel, {}
    stats.pop("channel")
    return channel, stats


def _check_approx_duration(data_line: str, npts: int, delta: float, name: str, block_line: int):
    """Refuse an interval Real(62) that contradicts the data line's ``approx N secs``.

    The duration is printed in whole seconds (``42000 ... pts, approx  210 secs`` at 0.005 s);
    :data:`APPROX_DURATION_ATOL_S` plus :data:`APPROX_DURATION_RTOL` of it is allowed.
    """
    match = _APPROX_SECS.search(data_line)
    if match is None or npts == 0:
        return
    stated = float(match.group(1))
    if abs(npts * delta - stated) > APPROX_DURATION_ATOL_S + APPROX_DURATION_RTOL * stated:
        raise RecordError(
            name, f"channel block at line {block_line}: {npts} samples of Real(62)"
            f" {delta * 1000.0:g} ms span {npts * delta:g} s, but the data line says"
            f" 'approx {match.group(1)} secs' (a damaged interval or count)")


def _make_trace(name, text, ints, reals, comments, nulls, data_line, code, unit_text, npts,
                horizontals):
    """Build the (still empty) trace of an acceleration section with its header."""
    int_null, real_null = nulls
    notes: list[str] = []
    kind = _value(ints, 2, int_null)
    if kind is not None and int(kind) != 1:
        raise UnitsError(name, f"Int(2)={int(kind)}: the record is not an acceleration")
    if kind is None:
        notes.append("Int(2) unknown; the data line names the section an acceleration")
    delta_ms = _value(reals, 62, real_null)
    if delta_ms is None:
        raise RecordError(name, "the sampling interval Real(62) is unknown")
    delta = check_sampling_interval(delta_ms / 1000.0, name)
    length = _value(reals, 63, real_null)
    if length is not None and abs(length / delta - npts) > 1.0:
        notes.append(f"Real(63) record length {length:g} s is not {npts} samples of {delta:g} s")

    sensor, source = _value(ints, 54, int_null), "Int(54)"
    orientation = _orientation(sensor)
    relative = _value(ints, 55, int_null)
    if orientation is None and relative is not None:
        # USGS NSMP structure arrays (e.g. NP.8040) leave Int(54) unknown and give the orientation
        # relative to the structure in Int(55): enough to tell vertical from horizontal, not the
        # geographic azimuth.
        orientation, sensor, source = _orientation(relative), relative, "Int(55)"
        if orientation is not None:
            orientation.update(azimuth=None)
    if orientation is not None:
        orientation.update(source=source, code=int(sensor))
        if orientation["note"]:
            notes.append(orientation["note"])
            warnings.warn(f"{name}: {orientation['note']}", stacklevel=4)
    scnl = _scnl(comments)
    channel, orientation_entries = _channel(name, orientation, scnl, 1.0 / delta, horizontals,
                                            notes)

    station_match = _STATION_CODE.search(text[4]) if len(text) > 4 else None
    network = station_match.group(1).upper() if station_match else ""
    station = station_match.group(2) if station_match else ""
    network = "" if network == "--" else network
    location = ""
    if scnl is not None:
        station, network, location = scnl[0], scnl[2], scnl[3]

    start = _start_time(ints, reals, nulls, text, notes)
    stage = _processing_stage(ints, int_null, text[0] if text else "", notes)
    unit_name, factor = UNIT_CODES[code]
    peak, peak_time = _value(reals, 64, real_null), _value(reals, 65, real_null)
    text_peak = _TEXT_PEAK.search(text[10]) if len(text) > 10 else None
    header = AttribDict(
        {
            "text_header": text,
            "integer_header": ints,
            "real_header": reals,
            "comments": comments,
            "data_line": data_line.strip(),
            "unit_code": code,
            "unit_text": unit_text,
            "processing_stage": stage,
            "orientation_code": _value(ints, 54, int_null),
            "relative_orientation_code": relative,
            "scnl": scnl,
            "notes": notes,
            "start_time_known": start is not None,
            "stated_peak": peak,
            "stated_peak_time": peak_time,
            "text_peak": float(text_peak.group(1)) if text_peak else None,
            "text_peak_unit": text_peak.group(2) if text_peak else None,
            "text_peak_time": float(text_peak.group(3)) if text_peak else None,
        }
    )
    stats = {
        "network": network,
        "station": station,
        "location": location,
        "channel": channel,
        "units": "counts" if factor is None else "m/s**2",
        "original_units": unit_name,
        "shipblock_cosmos": header,
        **orientation_entries,
    }
    if peak is not None and factor is not None:
        stats["stated_peak_si"] = abs(peak) * factor
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
    """Read a COSMOS V0/V1/V2 file into a Stream of acceleration traces.

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
        (``stats.units == "counts"``); ``stats.azimuth``/``stats.dip`` [deg] from Int(54), the
        stated peak in ``stats.stated_peak_si`` [m/s^2] and the original header in
        ``stats.shipblock_cosmos``.

    Raises
    ------
    RecordError
        If the file is not COSMOS, is truncated or corrupt, holds NaN/inf samples, or a channel
        block repeats an earlier one (same SEED id or the same samples).
    UnitsError
        If a unit code is missing, inconsistent or not an acceleration.
    """
    name = source_name(filename)
    cursor = _Lines(read_text(filename).splitlines(), name)
    if cursor.at_end():
        raise RecordError(name, "is empty")
    traces, horizontals, lines = [], [], []
    while not cursor.at_end():
        line = cursor.index + 1
        trace = _read_block(cursor, name, headonly, horizontals)
        if trace is not None:
            _check_not_repeated(trace, line, traces, lines, name)
            traces.append(trace)
            lines.append(line)
    if not traces:
        raise RecordError(name, "holds no acceleration data section")
    return Stream(traces)


def _check_not_repeated(trace, line: int, traces, lines, name: str) -> None:
    """Refuse a channel block that repeats an earlier one (a duplicated block, not a channel).

    A block repeats another if it has the same SEED id, or the same samples (not constant: two
    dead channels may both be zero).
    """
    data = np.asarray(trace.data)
    for other, other_line in zip(traces, lines, strict=True):
        same_id = other.id == trace.id
        same_samples = (data.size > 0 and other.data.shape == data.shape
                        and np.ptp(data) > 0 and np.array_equal(other.data, data))
        if same_id or same_samples:
            what = f"channel {trace.id}" if same_id else f"the samples of {other.id}"
            raise RecordError(
                name, f"channel block at line {line} repeats {what} of the block at line"
                f" {other_line} (a duplicated block: one channel cannot be two)")
