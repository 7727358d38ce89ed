"""Reader for Turkish NSMN/AFAD text records (obspy waveform plug-in ``SHIPBLOCK_NSMN``).

The National Strong-Motion Network of Turkey (TR-NSMN, FDSN network code ``TK``), run by the
Earthquake Department of the Disaster and Emergency Management Presidency (AFAD), distributes
uncorrected three-component records as text through its accelerometric database [1]_. No published
description of the text layout was used: the layout below was read from the files of the USGS
gmprocess test corpus (event us20009ynd, 2017-07-20 Bodrum-Kos earthquake, Mw 6.5):

1. the title ``STRONG GROUND MOTION RECORDS OF TURKIYE``;
2. ``KEY : value`` lines: ``PLACE``, ``EARTHQUAKE DATE``, ``EPICENTER COORDINATES``,
   ``STATION ID``, ``STATION COORDINATES`` (e.g. ``37.87470N-27.59223E``: the ``-`` separates the
   two numbers, the hemisphere letters give the signs), ``STATION ALTITUDE (m)``,
   ``RECORDER TYPE``, ``RECORD TIME`` (``dd/mm/yyyy hh:mm:ss.ffffff (GMT)``, the first sample),
   ``NUMBER OF DATA``, ``SAMPLING INTERVAL (sec)`` and ``RAW PGA VALUES (gal)``
   (``(N-S) 13.200332 (E-W) 12.163827 (U-D) 9.840572``);
3. two copyright lines, then a column title line ``N-S  E-W  U-D``;
4. one row per sample, the three components in the columns the title names.

What the real files showed:

* the only statement of the samples' unit is the one in the PGA key (``gal``); in all three files
  the largest absolute sample of each column equals the stated PGA to the printed digits, so the
  samples are in that unit. A file that states no unit there is refused (:class:`UnitsError`);
* the text is not UTF-8 but the Turkish Windows code page (cp1254): ``AYD\\xfdN`` is ``AYDıN``
  (byte 0xFD is the dotless i). Text that is not UTF-8 is decoded as cp1254; only free-text header
  values (``PLACE``) are affected;
* lines end in CRLF; the header is 18 lines, but this reader finds the keys by name and the data by
  the column title, not by line number.

The N-S column is taken as positive north (azimuth 0), E-W as positive east (azimuth 90) and U-D as
positive up, as their names say. The network code is ``TK``; the station code is ``STATION ID``.

References
----------
.. [1] AFAD, Turkish Accelerometric Database and Analysis System (TADAS),
   https://tadas.afad.gov.tr.
"""

from __future__ import annotations

import math
import re

import numpy as np
from obspy import Stream
from obspy.core import AttribDict

from shipblock.errors import RecordError, UnitsError
from shipblock.io._common import (
    FLOAT_RE,
    check_plausible_samples,
    check_samples,
    check_sampling_interval,
    make_trace,
    orientation_stats,
    parse_float,
    peek_text,
    read_text,
    source_name,
    utc_time,
)
from shipblock.units import si_factor

__all__ = ["FORMAT", "is_nsmn", "read_nsmn"]

#: Name under which the reader is registered as an obspy waveform plug-in.
FORMAT = "SHIPBLOCK_NSMN"

#: FDSN code of the National Strong-Motion Network of Turkey.
NETWORK = "TK"

#: First line of every NSMN file.
_TITLE = "STRONG GROUND MOTION RECORDS OF TURKIYE"

#: The column names and what they mean: (vertical, azimuth [deg], index of a horizontal).
_COLUMNS = {"N-S": (False, 0.0, 1), "E-W": (False, 90.0, 2), "U-D": (True, None, 1)}

_KEY_LINE = re.compile(r"^([A-Za-z][^:]*?)\s*:(.*)$")
_TIME_RE = re.compile(
    r"(\d{1,2})/(\d{1,2})/(\d{4})\s+(\d{1,2}):(\d{1,2}):(\d{1,2}(?:\.\d*)?)"
)
_COORD_RE = re.compile(
    r"(" + FLOAT_RE.pattern + r")\s*([NS])\W*(" + FLOAT_RE.pattern + r")\s*([EW])", re.IGNORECASE
)
_PGA_RE = re.compile(r"\(\s*([NSEWUD]-[NSEWUD])\s*\)\s*(" + FLOAT_RE.pattern + ")", re.IGNORECASE)


def is_nsmn(filename) -> bool:
    """Tell whether a file is an NSMN/AFAD text record (never raises).

    Parameters
    ----------
    filename : str, os.PathLike or file-like
        The file to check.

    Returns
    -------
    bool
        ``True`` if line 1 is ``STRONG GROUND MOTION RECORDS OF TURKIYE`` and the header has the
        ``NUMBER OF DATA`` and ``SAMPLING INTERVAL`` keys.
    """
    text = peek_text(filename)
    if text is None:
        return False
    first = text.lstrip("\ufeff").split("\n", 1)[0].strip().upper()
    upper = text.upper()
    return first == _TITLE and "NUMBER OF DATA" in upper and "SAMPLING INTERVAL" in upper


def _turkish(text: str) -> str:
    """Re-decode text that was read as Latin-1 with the Turkish code page cp1254."""
    try:
        raw = text.encode("latin-1")
    except UnicodeEncodeError:
        return text  # real UTF-8 (characters beyond Latin-1): keep it
    if max(raw, default=0) < 0x80:
        return text
    return raw.decode("cp1254", errors="replace")


def _key(raw: str) -> str:
    """``"SAMPLING INTERVAL (sec)"`` -> ``"sampling_interval_sec"``."""
    return re.sub(r"[^0-9a-z]+", "_", raw.lower()).strip("_")


def _header(lines, name):
    """Parse the header; return ``(keys, raw keys, index of the column title line)``."""
    header, raw_keys = {}, {}
    for index, line in enumerate(lines[1:], start=1):
        tokens = line.split()
        if tokens and all(t.upper() in _COLUMNS for t in tokens):
            return header, raw_keys, index
        match = _KEY_LINE.match(line.strip())
        if match is not None:
            key = _key(match.group(1))
            header[key] = match.group(2).strip()
            raw_keys[key] = match.group(1).strip()
        elif tokens and FLOAT_RE.fullmatch(tokens[0]):
            break  # numbers before any column title: the title line is missing
    raise RecordError(name, "has no column title line (N-S E-W U-D) before the samples")


def _number(header, key, name, what):
    """Return a required numeric header value."""
    raw = header.get(key, "")
    if not raw:
        raise RecordError(name, f"header line {what!r} is missing or empty")
    try:
        return parse_float(raw.split()[0])
    except ValueError:
        raise RecordError(name, f"header line {what!r} = {raw!r} is not a number") from None


def _start_time(raw: str, name: str):
    """Parse ``RECORD TIME`` (``dd/mm/yyyy hh:mm:ss.ffffff (GMT)``)."""
    match = _TIME_RE.search(raw)
    if match is None:
        raise RecordError(name, f"RECORD TIME {raw!r} is not dd/mm/yyyy hh:mm:ss")
    day, month, year, hour, minute = (int(g) for g in match.groups()[:5])
    second = float(match.group(6))
    start = utc_time(year, month, day, hour, minute, second)
    if start is None:
        raise RecordError(name, f"RECORD TIME {raw!r} is not a valid date and time")
    return start


def _coordinates(header, name):
    """Station coordinates as an AttribDict, or ``None`` if the header has none."""
    match = _COORD_RE.search(header.get("station_coordinates", ""))
    if match is None:
        return None
    latitude = parse_float(match.group(1)) * (-1.0 if match.group(2).upper() == "S" else 1.0)
    longitude = parse_float(match.group(3)) * (-1.0 if match.group(4).upper() == "W" else 1.0)
    if not (abs(latitude) <= 90.0 and abs(longitude) <= 360.0):
        raise RecordError(name, f"STATION COORDINATES {header['station_coordinates']!r} are"
                                " out of range")
    elevation = 0.0
    altitude = header.get("station_altitude_m", "")
    if altitude:
        try:
            elevation = parse_float(altitude.split()[0])
        except ValueError:
            raise RecordError(name, f"STATION ALTITUDE {altitude!r} is not a number") from None
    return AttribDict(latitude=latitude, longitude=longitude, elevation=elevation)


def _pga(header, raw_keys):
    """Return ``(unit, {column: stated PGA})`` from the ``RAW PGA VALUES (unit)`` line."""
    for key, value in header.items():
        if "pga" not in key:
            continue
        unit = re.search(r"\(([^)]*)\)", raw_keys[key])
        peaks = {}
        for column, number in _PGA_RE.findall(value):
            try:
                peaks[column.upper()] = abs(parse_float(number))
            except ValueError:
                continue
        return (unit.group(1).strip() if unit else ""), peaks
    return "", {}


def _samples(lines, first, ncols, name):
    """Parse the sample rows into an array of shape (rows, ncols)."""
    rows = lines[first:]
    while rows and not rows[-1].strip():
        rows = rows[:-1]
    values = []
    for offset, line in enumerate(rows):
        tokens = line.split()
        if len(tokens) != ncols:
            raise RecordError(
                name, f"line {first + offset + 1}: {len(tokens)} numbers where {ncols} columns"
                      " are expected (corrupt or truncated row)")
        try:
            values.extend(float(t) for t in tokens)
        except ValueError:
            raise RecordError(name, f"line {first + offset + 1}: {line.strip()[:40]!r} is not"
                                    " a row of numbers") from None
    return np.asarray(values, dtype=np.float64).reshape(-1, ncols)


def read_nsmn(filename, headonly: bool = False, **kwargs) -> Stream:
    """Read an NSMN/AFAD text record into a Stream of three traces in m/s^2.

    Parameters
    ----------
    filename : str, os.PathLike or file-like
        The NSMN file.
    headonly : bool, optional
        Read only the header; the traces then have no samples.
    **kwargs
        Ignored (obspy passes its own keywords to every plug-in).

    Returns
    -------
    obspy.Stream
        One trace per column (N-S, E-W, U-D: channels ``HNN``, ``HNE``, ``HNZ`` at 100 Hz);
        ``stats.units == "m/s**2"``, ``stats.original_units`` the unit of the PGA line,
        ``stats.starttime`` the ``RECORD TIME``, ``stats.coordinates``, ``stats.stated_peak_si``
        (the stated PGA [m/s^2]) and the header in ``stats.shipblock_nsmn``.

    Raises
    ------
    RecordError
        If the header is incomplete, the file truncated, or samples are NaN/inf or absurd.
    UnitsError
        If the header states no unit, or one that is not an acceleration.
    """
    name = source_name(filename)
    lines = _turkish(read_text(filename)).splitlines()
    if not lines or lines[0].lstrip("\ufeff").strip().upper() != _TITLE:
        raise RecordError(name, f"is not an NSMN file (line 1 is not {_TITLE!r})")
    header, raw_keys, title_index = _header(lines, name)
    columns = [t.upper() for t in lines[title_index].split()]
    if sorted(columns) != sorted(_COLUMNS):
        raise RecordError(name, f"column title {lines[title_index].strip()!r} does not name"
                                " N-S, E-W and U-D once each")
    unit, stated = _pga(header, raw_keys)
    if not unit:
        raise UnitsError(name, "the header states no unit (expected 'RAW PGA VALUES (gal)')")
    factor = si_factor(unit, name)
    npts = _number(header, "number_of_data", name, "NUMBER OF DATA")
    if not (math.isfinite(npts) and npts == int(npts) and npts >= 1):
        raise RecordError(name, f"NUMBER OF DATA = {header['number_of_data']!r} is not a"
                                " sample count")
    npts = int(npts)
    delta = check_sampling_interval(
        _number(header, "sampling_interval_sec", name, "SAMPLING INTERVAL (sec)"), name,
        "SAMPLING INTERVAL =")
    start = _start_time(header["record_time"], name) if "record_time" in header else None
    coordinates = _coordinates(header, name)
    station = header.get("station_id", "")

    rows = len(lines) - title_index - 1
    while rows > 0 and not lines[title_index + rows].strip():
        rows -= 1  # trailing blank lines
    if rows != npts:  # checked before parsing, and also when only the header is read
        what = "truncated" if rows < npts else "longer than its header says"
        raise RecordError(name, f"is {what}: NUMBER OF DATA = {npts} but {rows} rows were"
                                " found")
    if not headonly:
        data = _samples(lines, title_index + 1, len(columns), name)
    stream = Stream()
    for column_index, column in enumerate(columns):
        vertical, azimuth, index = _COLUMNS[column]
        stats = {
            "network": NETWORK,
            "station": station,
            "location": "",
            "units": "m/s**2",
            "original_units": unit,
            "shipblock_nsmn": AttribDict(dict(header, component=column)),
            **orientation_stats(1.0 / delta, vertical=vertical, azimuth_deg=azimuth,
                                index=index),
        }
        if coordinates is not None:
            stats["coordinates"] = AttribDict(coordinates)
        if column in stated:
            stats["stated_peak_si"] = stated[column] * factor
        if headonly:
            trace = make_trace([], delta, stats)
            trace.stats.npts = npts
        else:
            trace = make_trace(data[:, column_index], delta, stats)
            check_samples(trace.data, name, f"component {column}")
            trace.data *= factor
            check_plausible_samples(trace.data, name, f"component {column}")
        if start is not None:
            trace.stats.starttime = start
        stream.append(trace)
    return stream
