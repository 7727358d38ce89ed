"""Fixed-width fields and header values of CSMIP/CDMG ("DMG") text records.

The column-exact parsing of the integer and real headers and of the data series, and the
values the text and numeric headers state (units, orientation, start time, channel count,
station coordinates), for :mod:`shipblock.io.dmg`, whose module notes describe the format and
what the real files showed. Split from it to keep each module to one concern (issue 28).
"""

from __future__ import annotations

import math
import re

import numpy as np
from obspy import UTCDateTime

from shipblock.errors import RecordError, UnitsError
from shipblock.io._common import fixed_fields, parse_float
from shipblock.units import STANDARD_GRAVITY, canonical_unit, si_factor

#: Value of an integer or real header field that is not known.
_NULL = -999

# Positions (0-based) in the integer and real headers.
_INT_CHANNEL_NUMBER = 2
_INT_CHANNELS = 3
_INT_YEAR = 23
_REAL_LATITUDE = 28
_REAL_LONGITUDE = 29

#: Orientation codes of the integer header other than an azimuth.
_VERTICAL_UP_CODE = 500
#: Values per line tried, in this order, when a data line states no format.
_PER_LINE_GUESSES = (8, 10, 5, 6, 4)

_CHANNELS_RE = re.compile(r"\(\s*(\d+)\s+CHNS\s+OF\s+(\d+)\s+AT\s+STA\s*\)", re.IGNORECASE)
_COMPASS_DEG = {"N": 0.0, "E": 90.0, "S": 180.0, "W": 270.0}
_FORMAT_RE = re.compile(r"\(\s*(\d+)\s*[FEG]\s*(\d+)(?:\.\d+)?\s*\)", re.IGNORECASE)
_LATLON_RE = re.compile(r"(\d+(?:\.\d*)?)\s*([NS])\s*,?\s*(\d+(?:\.\d*)?)\s*([EW])\b")
_PROCESSED_RE = re.compile(r"PROCESSED\s*:\s*(\d{1,2})/(\d{1,2})/(\d{4}|\d{2})\b", re.IGNORECASE)
_START_RE = re.compile(
    r"(START|TRIGGER)\s+TIME\s*:\s*(\d{1,2})[/-](\d{1,2})[/-](\d{4}|\d{2})\s*,?\s*"
    r"(\d{1,2})\s*:\s*(\d{1,2})\s*:\s*(\d{1,2}(?:\.\d*)?)\s*([A-Z]{1,3})?",
    re.IGNORECASE,
)
_TIME_ZONES_H = {"UTC": 0, "GMT": 0, "Z": 0, "PST": 8, "PDT": 7}

# --------------------------------------------------------------------------------------------
# Fixed-width parsing
# --------------------------------------------------------------------------------------------

def _header_numbers(lines, first, count, width, parse, name, what):
    """Cut ``count`` numbers of ``width`` columns from ``lines``; ``None`` for blank/overflow."""
    values = []
    per_line = 80 // width
    for offset, line in enumerate(lines):
        text = line.rstrip()
        expected = min(per_line, count - len(values))
        # Numbers are right-justified in full fields: any other length means shifted columns.
        if len(text) != expected * width:
            raise RecordError(name, f"line {first + offset + 1}: {what} line has {len(text)}"
                                    f" characters, not {expected} fields of {width}")
        for field in fixed_fields(text, width, expected):
            field = field.strip()
            if not field or set(field) == {"*"}:
                values.append(None)  # blank, or a Fortran field overflow
                continue
            try:
                values.append(parse(field))
            except ValueError:
                raise RecordError(name, f"line {first + offset + 1}: {what} field {field!r} is"
                                        " not a number") from None
    return values


def _layout(start_line: str, first_data: str | None, total: int, name: str, lineno: int):
    """Values per line and field width of a data series, from its format or its first line."""
    match = _FORMAT_RE.search(start_line)
    if match is not None:
        per_line, width = int(match.group(1)), int(match.group(2))
        if per_line < 1 or width < 2:
            raise RecordError(name, f"line {lineno}: data format {match.group(0)!r} is invalid")
        return per_line, width
    if first_data is None:
        raise RecordError(name, f"is truncated after line {lineno}: no data follow")
    text = first_data.rstrip()
    for per_line in _PER_LINE_GUESSES:
        count = min(per_line, total)
        if count < 1 or len(text) % count:
            continue
        width = len(text) // count
        fields = fixed_fields(text, width, count)
        if width >= 2 and all(_clean_field(f) for f in fields):
            return per_line, width
    raise RecordError(name, f"line {lineno + 1}: cannot tell the column layout of the data (no"
                            " format stated and the line is not evenly divided into numbers)")


def _clean_field(field: str) -> bool:
    """Whether a fixed-width field holds exactly one number."""
    token = field.strip()
    if not token or " " in token:
        return False
    try:
        parse_float(token)
    except ValueError:
        return False
    return True


def _series(lines, first, total, per_line, width, name, what):
    """Parse ``total`` fixed-width values from ``lines[first:]``; return them and the next index."""
    rows = -(-total // per_line)
    if first + rows > len(lines):
        found = len(lines) - first
        raise RecordError(name, f"{what}: truncated: {total} values need {rows} lines but only"
                                f" {max(found, 0)} follow line {first}")
    values = np.empty(total, dtype=np.float64)
    position = 0
    for row in range(rows):
        index = first + row
        text = lines[index].rstrip()
        count = min(per_line, total - position)
        if len(text) > count * width or len(text) <= (count - 1) * width:
            raise RecordError(name, f"line {index + 1}: {what}: expected {count} values of"
                                    f" {width} characters, found {len(text)} characters")
        for k, field in enumerate(fixed_fields(text, width, count)):
            field = field.strip()
            if not field or " " in field:
                raise RecordError(name, f"line {index + 1}: {what}: field {k + 1} {field!r} is"
                                        " not one number")
            try:
                values[position] = parse_float(field)
            except ValueError:
                raise RecordError(name, f"line {index + 1}: {what}: {field!r} is not a number"
                                  ) from None
            position += 1
    return values, first + rows


def _skip_series(lines, first, total, per_line, name, what):
    """Index after a series that is not read (checks only that its lines exist)."""
    rows = -(-total // per_line)
    if first + rows > len(lines):
        raise RecordError(name, f"{what}: truncated: {total} values need {rows} lines but only"
                                f" {max(len(lines) - first, 0)} follow line {first}")
    for index in range(first, first + rows):
        if re.search(r"[A-CF-Za-cf-z]", lines[index]):
            raise RecordError(name, f"line {index + 1}: {what}: text {lines[index].strip()!r}"
                                    " where numbers were expected")
    return first + rows


# --------------------------------------------------------------------------------------------
# Header values
# --------------------------------------------------------------------------------------------

def _search(regex, lines):
    for line in lines:
        match = regex.search(line)
        if match is not None:
            return match
    return None


def _unit(raw: str, name: str) -> tuple[str, float | None]:
    """Canonical unit and factor to m/s^2 (``None`` for counts) of a stated unit."""
    token = raw.strip().rstrip(".,;)").strip().lower()
    if token in ("g/10", "g/10."):
        return "g/10", 0.1 * STANDARD_GRAVITY
    if token in ("count", "counts"):
        return "counts", None
    if token in ("cm/sec", "cm/s", "cm", "in/s", "in/sec", "in"):
        raise UnitsError(name, f"the samples are in {raw.strip()!r}: velocity or displacement,"
                               " not acceleration")
    key = canonical_unit(token)
    return (key or token), si_factor(token, name)


def _orientation_text(text: str):
    """Orientation stated by the ``CHAN n:`` line: a dict, or ``None`` if it says nothing."""
    token = text.strip().upper()
    match = re.match(r"^(-?\d{1,3}(?:\.\d*)?)\s*(?:DEG|DEGREES?)?\b", token)
    if match is not None:
        azimuth = float(match.group(1))
        if 0.0 <= azimuth <= 360.0:
            return {"vertical": False, "azimuth": azimuth % 360.0}
        return None
    word = token.split()[0] if token.split() else ""
    if word in ("UP", "VERT", "VERTICAL", "V", "Z", "UP-DOWN"):
        return {"vertical": True, "positive_up": True}
    if word in ("DOWN", "DWN", "DN"):
        return {"vertical": True, "positive_up": False}
    match = re.fullmatch(r"H(\d)", word)
    if match is not None:
        return {"vertical": False, "azimuth": None, "index": int(match.group(1))}
    if word in _COMPASS_DEG:
        return {"vertical": False, "azimuth": _COMPASS_DEG[word]}
    match = re.fullmatch(r"([NS])(\d{1,2}(?:\.\d*)?)([EW])", word)
    if match is not None:
        angle = float(match.group(2))
        base = 0.0 if match.group(1) == "N" else 180.0
        clockwise = (match.group(1) == "N") == (match.group(3) == "E")
        return {"vertical": False, "azimuth": (base + (angle if clockwise else -angle)) % 360.0}
    return None


def _orientation_code(code):
    """Orientation stated by integer-header value 27, or ``None``."""
    if code is None:
        return None
    if 0 <= code <= 360:
        return {"vertical": False, "azimuth": float(code % 360)}
    if code == _VERTICAL_UP_CODE:
        return {"vertical": True, "positive_up": True}
    return None


def _same_orientation(a: dict, b: dict) -> bool:
    if a["vertical"] != b["vertical"]:
        return False
    if a["vertical"]:
        return a["positive_up"] == b["positive_up"]
    if a.get("azimuth") is None or b.get("azimuth") is None:
        return True
    difference = abs(a["azimuth"] - b["azimuth"]) % 360.0
    return min(difference, 360.0 - difference) < 0.5


def _full_year(two_digits: int, ints, processed_year, notes) -> int:
    """Complete a two-digit year (see the module notes)."""
    year = ints[_INT_YEAR] if len(ints) > _INT_YEAR else None
    if year is not None and 1900 <= year <= 2100 and year % 100 == two_digits:
        return year
    if processed_year is not None:
        candidate = 2000 + two_digits
        return candidate if candidate <= processed_year else 1900 + two_digits
    notes.append("two-digit year completed with the pivot 70 (no processing date)")
    return 2000 + two_digits if two_digits < 70 else 1900 + two_digits


def _processed_year(header_lines):
    match = _search(_PROCESSED_RE, header_lines[:2])
    if match is None:
        return None
    year = int(match.group(3))
    return year if year >= 100 else (2000 + year if year < 70 else 1900 + year)


def _start_time(header_lines, ints, name, notes):
    """Start time (UTC) of a channel and the text it was read from, or ``(None, text)``."""
    match = _search(_START_RE, header_lines)
    if match is None:
        notes.append("the header states no start or trigger time")
        return None, ""
    month, day, year = int(match.group(2)), int(match.group(3)), int(match.group(4))
    hour, minute, second = int(match.group(5)), int(match.group(6)), float(match.group(7))
    zone = (match.group(8) or "").upper()
    if year < 100:
        year = _full_year(year, ints, _processed_year(header_lines), notes)
    if zone not in _TIME_ZONES_H:
        notes.append(f"start time {match.group(0).strip()!r} has no known time zone; not used")
        return None, match.group(0).strip()
    try:
        start = UTCDateTime(year, month, day, hour, minute) + second
    except (ValueError, TypeError):
        raise RecordError(name, f"start time {match.group(0).strip()!r} is not a valid date and"
                                " time") from None
    if not 0.0 <= second < 61.0:
        raise RecordError(name, f"start time {match.group(0).strip()!r} has {second} seconds")
    return start + 3600.0 * _TIME_ZONES_H[zone], match.group(0).strip()


def _channels_stated(header_lines, ints, number: int) -> tuple[int, str] | None:
    """How many channels the record holds, as the header states it, and where.

    The text's ``(3 Chns of  3 at Sta)`` (channels of this recorder, of the station), else
    integer-header value 4 where value 3 is the channel's own number (the layout of every real
    file: ``1  100    1    3    3``), else ``None``.
    """
    match = _search(_CHANNELS_RE, header_lines)
    if match is not None and match.group(1).isdigit() and int(match.group(1)) > 0:
        return int(match.group(1)), f"the text {match.group(0)!r}"
    if (len(ints) > _INT_CHANNELS and ints[_INT_CHANNEL_NUMBER] == number
            and ints[_INT_CHANNELS] is not None and 0 < ints[_INT_CHANNELS] < 100):
        return ints[_INT_CHANNELS], f"integer-header value {_INT_CHANNELS + 1}"
    return None


def _check_all_channels(traces, name: str) -> None:
    """Refuse a file cut at a channel boundary: more than one channel but fewer than stated.

    A file of one channel is a channel file of its own (CESMD ships some so) and is read.
    """
    if len(traces) < 2:
        return
    dmg = traces[0].stats.shipblock_dmg
    stated = dmg.get("channels_stated")
    if stated is None or len(traces) >= stated[0]:
        return
    numbers = ", ".join(str(tr.stats.shipblock_dmg.channel_number) for tr in traces)
    raise RecordError(
        name, f"holds {len(traces)} channels ({numbers}) but {stated[1]} states {stated[0]}: the"
        " file is cut at a channel boundary (truncated?)")


def _coordinates(station_line: str, reals, notes):
    """Latitude and longitude [deg] of the station, or ``None``."""
    text = None
    match = _LATLON_RE.search(station_line)
    if match is not None:
        latitude = float(match.group(1)) * (-1.0 if match.group(2) == "S" else 1.0)
        longitude = float(match.group(3)) * (-1.0 if match.group(4) == "W" else 1.0)
        if abs(latitude) <= 90.0 and abs(longitude) <= 180.0:
            text = (latitude, longitude)
    real = None
    if len(reals) > _REAL_LONGITUDE:
        latitude, longitude = reals[_REAL_LATITUDE], reals[_REAL_LONGITUDE]
        if (latitude is not None and longitude is not None
                and math.isfinite(latitude) and math.isfinite(longitude)
                and abs(latitude) <= 90.0 and abs(longitude) <= 180.0
                and (latitude, longitude) != (0.0, 0.0) and _NULL not in (latitude, longitude)):
            real = (latitude, longitude)
    if real is not None and text is not None and (
            abs(real[0] - text[0]) > 0.01 or abs(real[1] - text[1]) > 0.01):
        notes.append(f"text coordinates {text} disagree with the real header {real}; the real"
                     " header's are used")
    return real or text
