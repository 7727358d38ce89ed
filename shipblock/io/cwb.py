"""Reader for Central Weather Bureau (Taiwan) ``.dat`` records (plug-in ``SHIPBLOCK_CWB``).

The Central Weather Bureau (CWB, now the Central Weather Administration) distributes the records
of the Taiwan Strong Motion Instrumentation Program as text files of one station each: a header
of ``#Key: value`` lines, then one line per sample holding the time and the three components. No
public specification of the layout was found; this reader follows what the files state about
themselves (the gmprocess test corpus, event us1000chhc of 2018-02-06):

.. code-block:: text

    #Earthquake Information
    #Origin Time(GMT+08): 2018/02/06-23:50:42
    ...
    #StationCode: EAS
    #StationLongitude(E): 120.857
    #StationLatitude(N): 22.381
    #InstrumentKind: FBA
    #StartTime(GMT+08): 2018/02/06-23:50:29.000
    #RecordLength(sec): 120
    #SampleRate(Hz): 50
    #AmplitudeUnit:  gal. DCoffset(corr)
    #AmplitudeMAX. U:    0.658~   -0.837
    #AmplitudeMAX. N:    1.256~   -2.273
    #AmplitudeMAX. E:    1.017~   -0.778
    #DataSequence: Time U(+); N(+); E(+)
    #Data: 4F10.3
         0.000     0.000     0.000     0.000

* The times are local (the key says ``GMT+08``); ``stats.starttime`` is converted to UTC.
* ``#DataSequence`` names the columns after the time: ``U`` (vertical, positive up), ``N``
  (north) and ``E`` (east), each with the sign of its positive direction; a ``(-)`` component is
  read as pointing the other way (``D``, south or west).
* ``#AmplitudeUnit`` is ``gal`` (cm/s^2); the DC offset has been removed.
* ``#AmplitudeMAX. X: max~min`` gives each component's largest and smallest sample (checked
  against the samples in the tests; the peak is the larger magnitude of the two), kept as
  ``stats.stated_peak_si``.
* ``#Data: 4F10.3`` is the Fortran format of the rows (the fields are cut by column); the number
  of rows equals ``RecordLength x SampleRate`` and the time column counts ``i / SampleRate``.
* The files use CR-LF line ends.

Traces are in m/s^2 (``stats.units == "m/s**2"``, ``stats.original_units`` the stated unit),
network ``TW``, the channel from ``orientation_stats`` (``BNZ``, ``BNN``, ``BNE`` at 50 Hz), the
coordinates of the header (no elevation is stated: 0) and the header in ``stats.shipblock_cwb``.
"""

from __future__ import annotations

import re

import numpy as np
from obspy import Stream, UTCDateTime
from obspy.core import AttribDict

from shipblock.errors import RecordError, UnitsError
from shipblock.io._common import (
    FLOAT_RE,
    check_plausible_samples,
    check_samples,
    check_sampling_interval,
    fixed_fields,
    make_trace,
    orientation_stats,
    parse_float,
    parse_number,
    peek_text,
    read_text,
    source_name,
)
from shipblock.units import si_factor

__all__ = ["FORMAT", "is_cwb", "read_cwb"]

#: Name under which the reader is registered as an obspy waveform plug-in.
FORMAT = "SHIPBLOCK_CWB"

#: SEED network code of the Taiwan strong-motion network.
NETWORK = "TW"

#: First line of every CWB file.
FIRST_LINE = "#Earthquake Information"

#: Tolerance of the time column against ``i / SampleRate``, in units of its last printed digit.
TIME_COLUMN_TOLERANCE_DIGITS = 0.6

_KEY_RE = re.compile(r"^#\s*([^:]+?)\s*:(.*)$")
_FORTRAN_RE = re.compile(r"^\s*(\d+)\s*[FEGD]\s*(\d+)(?:\.(\d+))?", re.IGNORECASE)
_GMT_RE = re.compile(r"GMT\s*([+-])\s*(\d{1,2})(?::?(\d{2}))?", re.IGNORECASE)
_COLUMN_RE = re.compile(r"^([A-Za-z]+)\s*\(\s*([+-])\s*\)$")
_TIME_FORMATS = ("%Y/%m/%d-%H:%M:%S.%f", "%Y/%m/%d-%H:%M:%S")
#: Column letter -> (vertical, azimuth of the positive direction [deg]) for a ``(+)`` column.
_DIRECTIONS = {
    "U": (True, None), "Z": (True, None), "D": (True, None),
    "N": (False, 0.0), "E": (False, 90.0), "S": (False, 180.0), "W": (False, 270.0),
}


def is_cwb(filename) -> bool:
    """Tell whether a file is a CWB (Taiwan) strong-motion ``.dat`` file (never raises).

    Parameters
    ----------
    filename : str, os.PathLike or file-like
        The file to check.

    Returns
    -------
    bool
        ``True`` if the first line is ``#Earthquake Information`` and the header has the
        ``#StationCode:``, ``#SampleRate`` and ``#DataSequence:`` keys.
    """
    text = peek_text(filename)
    if text is None:
        return False
    lines = text.splitlines()
    return (
        bool(lines)
        and lines[0].strip() == FIRST_LINE
        and "#StationCode:" in text
        and "#SampleRate" in text
        and "#DataSequence:" in text
    )


def _header(lines, name):
    """Parse the ``#Key: value`` lines; return ``(header, index of the first data line)``."""
    header = {}
    for index, line in enumerate(lines):
        stripped = line.strip()
        if not stripped:
            continue
        if not stripped.startswith("#"):
            return header, index
        match = _KEY_RE.match(stripped)
        if match is not None:
            header[match.group(1)] = match.group(2).strip()
    raise RecordError(name, "has a header but no data lines")


def _find(header, prefix):
    """Return ``(key, value)`` of the key ``prefix`` or ``prefix(...)``, or ``(None, "")``.

    Keys carry their unit or time zone in parentheses (``SampleRate(Hz)``).
    """
    wanted = prefix.lower()
    for key, value in header.items():
        lower = key.lower()
        if lower == wanted or (lower.startswith(wanted) and lower[len(wanted):].lstrip()[:1] == "("):
            return key, value
    return None, ""


def _number(header, prefix, name, required=True):
    """A float header value; ``None`` when absent and optional."""
    key, raw = _find(header, prefix)
    if not raw:
        if required:
            raise RecordError(name, f"header key #{prefix} is missing or empty")
        return None
    return parse_number(raw, name, f"header key #{key}:")


def _local_time(header, prefix, name):
    """Parse a ``<prefix>(GMT+08): yyyy/mm/dd-hh:mm:ss.sss`` time into UTC; ``None`` if absent."""
    key, raw = _find(header, prefix)
    if not raw:
        return None
    zone = _GMT_RE.search(key)
    if zone is None:
        raise RecordError(name, f"header key #{key} does not state its time zone (GMT+hh)")
    sign = 1 if zone.group(1) == "+" else -1
    offset_s = sign * (int(zone.group(2)) * 3600 + int(zone.group(3) or 0) * 60)
    for fmt in _TIME_FORMATS:
        try:
            return UTCDateTime.strptime(raw, fmt) - offset_s
        except Exception:  # noqa: BLE001 - try the next layout
            continue
    raise RecordError(name, f"header key #{key}: {raw!r} is not a yyyy/mm/dd-hh:mm:ss time")


def _columns(header, name):
    """The components after the time column, from ``#DataSequence``."""
    key, raw = _find(header, "DataSequence")
    if not raw:
        raise RecordError(name, "header key #DataSequence (the column order) is missing")
    tokens = [t.strip() for t in re.split(r"[;,]", raw) if t.strip()]
    if not tokens or not tokens[0].lower().startswith("time"):
        raise RecordError(name, f"#DataSequence {raw!r} does not start with the time column")
    tokens[0] = tokens[0][4:].strip()
    columns = []
    for token in tokens:
        match = _COLUMN_RE.match(token)
        letter = match.group(1).upper() if match else ""
        if letter not in _DIRECTIONS:
            raise RecordError(name, f"#DataSequence column {token!r} is not U/N/E(+/-)")
        vertical, azimuth = _DIRECTIONS[letter]
        positive = match.group(2) == "+"
        if vertical:
            positive_up = positive == (letter != "D")
            columns.append((letter, True, positive_up, None))
        else:
            columns.append((letter, False, True, azimuth if positive else (azimuth + 180.0) % 360))
    if len(columns) != 3 or sum(col[1] for col in columns) != 1:
        raise RecordError(
            name, f"#DataSequence {raw!r} does not name one vertical and two horizontals"
        )
    return columns


def _rows(lines, ncols, width, name):
    """Parse data rows of ``ncols`` numbers (fixed ``width`` if given, else blank-separated)."""
    values = np.empty((len(lines), ncols), dtype=np.float64)
    for row, line in enumerate(lines):
        line = line.rstrip()
        if width:
            # Fortran fields are right-aligned: a shifted field changes the row's length.
            if len(line) != ncols * width:
                raise RecordError(
                    name,
                    f"data row {row + 1} is {len(line)} characters long; {ncols} fields of "
                    f"{width} characters were expected",
                )
            fields = fixed_fields(line, width, ncols)
        else:
            fields = line.split()
            if len(fields) != ncols:
                raise RecordError(
                    name, f"data row {row + 1} has {len(fields)} numbers, expected {ncols}"
                )
        for col, field in enumerate(fields):
            try:
                values[row, col] = float(field)
            except ValueError:
                raise RecordError(
                    name,
                    f"data row {row + 1}: {field.strip() or 'a blank field'!r} is not a number",
                ) from None
    return values


def _stated_peak(header, letter, factor, name):
    """Peak magnitude [m/s^2] from ``#AmplitudeMAX. X: max~min``; ``None`` if absent."""
    key, raw = _find(header, f"AmplitudeMAX. {letter}")
    numbers = re.findall(FLOAT_RE.pattern, raw)
    if key is None or len(numbers) != 2:
        return None
    return max(abs(parse_float(numbers[0])), abs(parse_float(numbers[1]))) * factor


def read_cwb(filename, headonly: bool = False, **kwargs) -> Stream:
    """Read a CWB (Taiwan) ``.dat`` file into a Stream of three traces in m/s^2.

    Parameters
    ----------
    filename : str, os.PathLike or file-like
        The CWB file.
    headonly : bool, optional
        Read only the header; the traces then have no samples (their length is still checked).
    **kwargs
        Ignored (obspy passes its own keywords to every plug-in).

    Returns
    -------
    obspy.Stream
        Three traces in the file's column order (vertical first in CWB files), in m/s^2.

    Raises
    ------
    RecordError
        If the header lacks a needed key, the rows disagree with the record length or sampling
        rate, or a sample is not a finite number.
    UnitsError
        If ``#AmplitudeUnit`` is missing or not an acceleration unit.
    """
    name = source_name(filename)
    lines = read_text(filename).splitlines()
    if not lines or lines[0].strip() != FIRST_LINE:
        raise RecordError(name, f"is not a CWB file (first line is not {FIRST_LINE!r})")
    header, first_data = _header(lines, name)

    _, unit_raw = _find(header, "AmplitudeUnit")
    unit_tokens = unit_raw.replace(".", " ").split()
    if not unit_tokens:
        raise UnitsError(name, "header key #AmplitudeUnit is missing or empty; units unknown")
    unit = unit_tokens[0]
    factor = si_factor(unit, name)

    rate = _number(header, "SampleRate", name)
    if rate <= 0:
        raise RecordError(name, f"#SampleRate {rate:g} Hz is not positive")
    delta = check_sampling_interval(1.0 / rate, name,
                                    f"#SampleRate {rate:g} Hz: sampling interval")
    length = _number(header, "RecordLength", name, required=False)
    columns = _columns(header, name)

    ncols = 1 + len(columns)
    width = 0
    decimals = 3
    _, data_format = _find(header, "Data")
    fortran = _FORTRAN_RE.match(data_format)
    if fortran is not None:
        if int(fortran.group(1)) != ncols:
            raise RecordError(
                name, f"#Data format {data_format!r} has {fortran.group(1)} columns, not {ncols}"
            )
        width = int(fortran.group(2))
        decimals = int(fortran.group(3) or 0)

    data_lines = lines[first_data:]
    while data_lines and not data_lines[-1].strip():
        data_lines.pop()
    npts = len(data_lines)
    if npts == 0:
        raise RecordError(name, "has no data rows")
    if length is not None and npts != round(length * rate):
        raise RecordError(
            name,
            f"has {npts} data rows but #RecordLength x #SampleRate = {length:g} s x {rate:g} Hz "
            f"= {round(length * rate)} samples (truncated or padded)",
        )

    station = _find(header, "StationCode")[1]
    latitude = _number(header, "StationLatitude", name, required=False)
    longitude = _number(header, "StationLongitude", name, required=False)
    start = _local_time(header, "StartTime", name)

    table = None
    first_time = 0.0
    if not headonly:
        table = _rows(data_lines, ncols, width, name)
        check_samples(table[:, 0], name, "the time column")
        first_time = float(table[0, 0])
        expected = first_time + np.arange(npts) * delta
        worst = float(np.max(np.abs(table[:, 0] - expected)))
        if worst > TIME_COLUMN_TOLERANCE_DIGITS * 10.0 ** -decimals:
            row = int(np.argmax(np.abs(table[:, 0] - expected)))
            raise RecordError(
                name,
                f"the time column is not evenly spaced at 1/#SampleRate = {delta} s (row "
                f"{row + 1}: {table[row, 0]} s, expected {expected[row]:.6f} s); rows are missing "
                "or duplicated",
            )

    traces = []
    horizontals = 0
    for index, (letter, vertical, positive_up, azimuth) in enumerate(columns, start=1):
        trace_stats = {
            "network": NETWORK,
            "station": station,
            "location": "",
            "units": "m/s**2",
            "original_units": unit,
            "shipblock_cwb": AttribDict(header),
        }
        if latitude is not None and longitude is not None:
            trace_stats["coordinates"] = AttribDict(
                latitude=latitude, longitude=longitude, elevation=0.0
            )
        if not vertical:
            horizontals += 1
        trace_stats.update(orientation_stats(
            rate, vertical=vertical, azimuth_deg=azimuth, positive_up=positive_up,
            index=horizontals or 1,
        ))
        peak = _stated_peak(header, letter, factor, name)
        if peak is not None:
            trace_stats["stated_peak_si"] = peak
        if headonly:
            trace = make_trace([], delta, trace_stats)
            trace.stats.npts = npts
        else:
            samples = table[:, index]
            check_samples(samples, name, f"component {letter}")
            trace = make_trace(samples * factor, delta, trace_stats)
            check_plausible_samples(trace.data, name, f"component {letter}")
        if start is not None:
            trace.stats.starttime = start + first_time
        traces.append(trace)
    return Stream(traces)
