"""Reader for CSMIP/CDMG ("DMG") volume 1 and volume 2 text records (obspy plug-in ``SHIPBLOCK_DMG``).

The California Strong Motion Instrumentation Program (CSMIP, of the California Geological Survey,
formerly the California Division of Mines and Geology, CDMG; FDSN network code ``CE``) distributes
its records through CESMD in fixed-width Fortran text files [1]_ [2]_. One file holds several
channels; each channel is one block:

1. a text header: 13 lines in volume 1 (uncorrected acceleration: ``.V1`` and most ``.RAW``
   files), 25 lines in volume 2 (instrument- and baseline-corrected: ``.V2``);
2. an integer header, 100 values written ``16I5`` (7 lines);
3. a real header written ``8F10``: 50 values (7 lines) in volume 1, 100 values (13 lines) in
   volume 2. Numbers fill their fields and may abut (``  .4738048-999.00000``), so every header and
   data line is cut by column, never split on blanks; ``-999`` means "not known";
4. the samples: volume 2 has three series (acceleration, velocity, displacement), each after a line
   such as ``15050 points of accel data equally spaced at  .020 sec, in cm/sec2. (8f10.6)``;
   newer volume 1 files have ``13200 Accelerogram points at 200 pts/sec in units of g .  Format:
   (8f9.6)`` and older ones ``12001 POINTS OF ACCEL DATA EQUALLY SPACED AT .005 SEC. (UNITS: G)``;
   the oldest volume 1 files (digitised film) have no such line but (time, acceleration) pairs,
   ``10F7.3``, at uneven times;
5. an end line ``/&  ----------  End of data for channel  1  ----------``.

Only the acceleration is read (the velocity and displacement of volume 2 are checked for
completeness and skipped). Volume 3 files (``.V3``: response and Fourier spectra) hold no time
series and are refused with :class:`RecordError`.

What is read from where:

* orientation: the ``Chan  1:  90 Deg`` line of the text header (``NNN Deg`` is the azimuth of the
  positive direction, ``Up``/``Down`` a vertical; ``H1``/``H2`` a horizontal whose azimuth the file
  does not state); when the text does not say, integer-header value 27 (azimuth 0-360, 500 for
  Up). Two definite statements that disagree are refused;
* units: the data line (``in cm/sec2``, ``in units of g``, ``(UNITS: G)``) or, for time/value
  pairs, the header line ``UNITS OF UNCOR ACCEL ARE SEC AND G/10.``;
* start time: ``Start time:`` or ``TRIGGER TIME:`` in the text header, in UTC (``PDT`` and ``PST``
  times are converted); the fields may be blank-padded (``10:34: 1.0 UTC`` in CESMD's 2022 files).
  Two-digit years are completed with the year of integer-header value 24, else so that the record
  is not later than its processing date;
* station: ``Station No. 89146`` / ``Station Id. WLT`` and the ``40.941N, 123.633W`` beside it; real
  header values 29-30 give the coordinates to more digits in newer files and are preferred. A
  ``<event>.<net>.<sta>.<loc>.<cha>`` record id (``15481673.CI.WLT.--.HN``) gives network and
  station; otherwise the network is ``CE`` (the five-digit station numbers are CSMIP's);
* stated peak (``stats.stated_peak_si``): ``Peak acceleration = 77.280 cm/sec/sec at ...`` in
  volume 2, ``Max = .079 g , at ...`` in volume 1. The samples' peak must agree with it within a
  factor 2, which catches a misread unit (``g`` against ``g/10`` is a factor 10).

* channel count: ``(3 Chns of  3 at Sta)`` in the text, else integer-header value 4. A file of
  several channels but fewer than that (cut at a channel boundary) is refused; a file of one
  channel is read (a channel file of its own).

What the real files (USGS gmprocess test corpus) showed that a format description does not:

* ``G/10`` (the SMA-1 film records of 1992-1994) means samples in tenths of g: the largest value
  of NEWPORT.RAW channel 1 is ``.549`` and its header says ``MAX = -.055 G``;
* the time/value pairs of digitised records are printed to 0.001 s around a nominal 0.005 s, so
  their steps are 0.004, 0.005 and 0.006 s: they are interpolated linearly onto an even grid whose
  step is their median step (0.005 s; ``resample_interval`` overrides it), from the first time to
  the last. The original count is kept in the header (``original_npts``), and ``interpolated``
  says whether a channel was. ``resample_interval`` given for a file with no uneven channel (a
  V2, or pairs already evenly spaced) is refused (:class:`RecordError`): it would have no
  effect;
* the digit count of the data format changes between channels of one file (``8f10.6`` and
  ``8f10.5`` in CIWLT.V2) to make room for larger values, and some files omit the format: it is
  then inferred from the width of the first data line;
* CE58667.V2 names its horizontals ``H1`` and ``H2`` (integer code 1100 and 1200): they are read as
  horizontals of unknown azimuth (``HN1``/``HN2``, dip 0, no ``azimuth``); gmprocess refuses the
  file. BadHeader.V2 is CE89146.V2 with a damaged header (integer orientation code 900, dashes in
  the date, latitude ``40.941S``, no data format): the text says ``360 Deg``, which is used, and
  the real header gives the latitude 40.9406 N;
* RENADIC (Chile) ``.v1`` files copy volume 1 line for line; they name ``RENADIC`` in their header
  and are not taken for CSMIP files;
* lines end in CRLF in some files and trailing blanks are stripped in others; the 1983 file
  ce36456p_CE36456.V2 is padded after its last channel with DOS end-of-file characters (Ctrl-Z),
  which are ignored.

Channel codes follow :func:`shipblock.io._common.orientation_stats` (``HNE``, ``BNZ``, ...); a
horizontal of stated azimuth off north and east is ``HN1`` nearer north-south and ``HN2`` nearer
east-west (:func:`~shipblock.io._common.horizontal_index`), whichever file it is in, so the two
horizontals of a station split into one file a channel never share a code. If a
file has several channels with the same code (structure arrays), every trace gets the channel
number as its location code.

The column-exact parsing and the header values are in :mod:`shipblock.io._dmg_header`.

References
----------
.. [1] CESMD, "Strong-motion data formats: CSMIP Volume 1 and Volume 2",
   https://www.strongmotioncenter.org/ (accessed 2024).
.. [2] QuakeManager help, "CSMIP file format",
   https://quakemanager.eqsols.com/topics/idh-csmip-file-format.htm (element list of a volume 2
   channel: text, integer and real headers, three data series each after a start line, end flag).
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
    check_resampling_applies,
    check_samples,
    check_sampling_interval,
    horizontal_index,
    make_trace,
    orientation_stats,
    parse_float,
    peek_text,
    read_text,
    source_name,
)
from shipblock.io._dmg_header import (
    _channels_stated,
    _check_all_channels,
    _coordinates,
    _header_numbers,
    _layout,
    _orientation_code,
    _orientation_text,
    _same_orientation,
    _search,
    _series,
    _skip_series,
    _start_time,
    _unit,
)

__all__ = ["FORMAT", "is_dmg", "read_dmg"]

#: Name under which the reader is registered as an obspy waveform plug-in.
FORMAT = "SHIPBLOCK_DMG"

#: FDSN code of the California Strong Motion Instrumentation Program.
NETWORK = "CE"

#: Largest ratio of samples after and before interpolating time/value pairs onto an even grid.
MAX_RESAMPLE_FACTOR = 100

#: Resolution of the times of time/value pairs (``F7.3``) [s].
PAIR_TIME_RESOLUTION_S = 0.001

_V1_TITLE = "UNCORRECTED ACCELEROGRAM DATA"
_V2_TITLE = "CORRECTED ACCELEROGRAM"
_V3_TITLE = "RESPONSE AND FOURIER AMPLITUDE SPECTRA"

#: Lines of (text header, integer header, real header) and number of reals, per volume.
_LAYOUT = {"V1": (13, 7, 7, 50), "V2": (25, 7, 13, 100)}
_INT_COUNT = 100
_INT_WIDTH = 5
_REAL_WIDTH = 10

# Positions (0-based) in the integer and real headers.
_INT_ORIENTATION = 26

_REAL_V1_MAX_G = 6
_REAL_V2_PEAK = 65

_END_MARKER = "/&"
#: DOS end-of-file character; old files are padded with it after the last channel.
_DOS_EOF = "\x1a"
_RENADIC_WORDS = ("RENADIC", "UNIVERSIDAD DE CHILE")

_NUMBER = FLOAT_RE.pattern
_CHAN_RE = re.compile(r"^\s*CHAN\s+(\d+)\s*:\s*(.*?)\s*$", re.IGNORECASE)
_STATION_RE = re.compile(r"STATION\s+(?:NO|ID)\.?\s+(\S+)", re.IGNORECASE)
_RECORD_ID_RE = re.compile(
    r"\b\d+\.([A-Z0-9]{1,2})\.([A-Z0-9]{1,5})\.([A-Z0-9-]{2})\.([A-Z0-9]{2,3})\b"
)
_V2_PEAK_RE = re.compile(
    rf"PEAK\s+ACCELERATION\s*=\s*({_NUMBER})\s+(\S+)\s+AT\s+({_NUMBER})", re.IGNORECASE
)
_V1_PEAK_RE = re.compile(
    rf"(?<!UNCOR )\bMAX\s*=\s*({_NUMBER})\s*([A-Z][A-Z0-9/*^]*)\s*,?\s*AT\s+({_NUMBER})",
    re.IGNORECASE,
)
_V1_NPTS_RE = re.compile(r"NO\.\s*OF\s+POINTS\s*=\s*(\d+)", re.IGNORECASE)
_HEADER_UNIT_RE = re.compile(
    r"UNITS\s+OF\s+UNCOR\w*\s+\w+\s+(?:ARE\s+SEC\s+AND|ARE|IS)\s+([A-Z0-9/*^]+)", re.IGNORECASE
)
_DATA_UNIT_RES = (
    re.compile(r"UNITS\s*:\s*([A-Z0-9/*^]+)", re.IGNORECASE),
    re.compile(r"\bIN\s+UNITS\s+OF\s+([A-Z0-9/*^]+)", re.IGNORECASE),
    re.compile(r"\bIN\s+([A-Z][A-Z0-9/*^]*)", re.IGNORECASE),
)
_SPACED_RE = re.compile(
    rf"^\s*(\d+)\s+POINTS\s+OF\s+(ACCEL|VELOC|DISPL)\w*\s+DATA\s+EQUALLY\s+SPACED\s+AT\s+"
    rf"({_NUMBER})\s*SEC",
    re.IGNORECASE,
)
_RATE_RE = re.compile(
    rf"^\s*(\d+)\s+ACCELEROGRAM\s+POINTS\s+AT\s+({_NUMBER})\s*PTS\s*/\s*SEC", re.IGNORECASE
)


# --------------------------------------------------------------------------------------------
# Detection
# --------------------------------------------------------------------------------------------

def _volume(lines) -> str | None:
    """``"V1"``, ``"V2"``, ``"V3"`` from the first lines of a CSMIP file, else ``None``."""
    top = [line.upper() for line in lines[:3]]
    while len(top) < 3:
        top.append("")
    if top[0].startswith(_V1_TITLE):
        return "V1"
    if top[0].startswith(_V2_TITLE) and top[1].startswith(_V1_TITLE):
        return "V2"
    if (top[0].startswith(_V3_TITLE) and top[1].startswith(_V2_TITLE)
            and top[2].startswith(_V1_TITLE)):
        return "V3"
    return None


def _is_renadic(header_lines) -> bool:
    text = " ".join(header_lines).upper()
    return any(word in text for word in _RENADIC_WORDS)


def _int_row(line: str) -> bool:
    """Whether a line is a row of ``I5`` integers (the first integer-header line)."""
    fields = [line[k:k + _INT_WIDTH] for k in range(0, len(line.rstrip()), _INT_WIDTH)]
    return len(fields) == 16 and all(re.fullmatch(r"\s*-?\d+", f) for f in fields)


def is_dmg(filename) -> bool:
    """Tell whether a file is a CSMIP/CDMG volume 1, 2 or 3 text file (never raises).

    Parameters
    ----------
    filename : str, os.PathLike or file-like
        The file to check.

    Returns
    -------
    bool
        ``True`` for a CSMIP volume 1 or 2 file (the title lines, a ``CHAN n:`` line in the text
        header and the integer header where the volume puts it) and for a volume 3 file (which
        :func:`read_dmg` refuses with a clear message); ``False`` for RENADIC and USC files, which
        share the titles.
    """
    text = peek_text(filename)
    if text is None:
        return False
    try:
        lines = text.splitlines()
        volume = _volume(lines)
        if volume == "V3":
            return True
        if volume is None:
            return False
        n_text = _LAYOUT[volume][0]
        if len(lines) <= n_text or _is_renadic(lines[:n_text]):
            return False
        if not any(_CHAN_RE.match(line) for line in lines[:n_text]):
            return False
        return _int_row(lines[n_text])
    except Exception:  # noqa: BLE001 - detection must never raise
        return False


# --------------------------------------------------------------------------------------------
# Channels
# --------------------------------------------------------------------------------------------

def _channel_blocks(lines, volume, name):
    """Split the file into channel blocks: lists of ``(first line index, lines)``."""
    title = _V1_TITLE if volume == "V1" else _V2_TITLE
    starts = [i for i, line in enumerate(lines) if line.upper().startswith(title)]
    if not starts or any(line.strip() for line in lines[:starts[0]]):
        raise RecordError(name, "text before the first channel header")
    blocks = []
    for number, start in enumerate(starts):
        end = starts[number + 1] if number + 1 < len(starts) else len(lines)
        block = lines[start:end]
        marker = next((k for k, line in enumerate(block) if line.startswith(_END_MARKER)), None)
        if marker is not None:
            rest = block[marker + 1:]
            if any(line.strip() for line in rest):
                raise RecordError(name, f"line {start + marker + 2}: text after the end-of-data"
                                        " line of a channel")
            block = block[:marker]
        blocks.append((start, block, marker is not None))
    return blocks


def _data_start(volume, block, index, name, start):
    """Parse the line that opens the acceleration series: ``(npts, dt, unit)``, ``None`` for pairs.
    """
    if index >= len(block):
        raise RecordError(name, f"is truncated: channel at line {start + 1} ends before its data")
    line = block[index]
    lineno = start + index + 1
    if not re.search(r"[A-Za-z]", line):
        if volume == "V2":
            raise RecordError(name, f"line {lineno}: expected the line that opens the"
                                    " acceleration data, found numbers")
        return None  # time/value pairs
    match = _SPACED_RE.match(line)
    if match is not None:
        if match.group(2).upper() != "ACCEL":
            raise RecordError(name, f"line {lineno}: the first series is"
                                    f" {match.group(2).lower()}, not acceleration")
        npts, dt = int(match.group(1)), parse_float(match.group(3))
    else:
        match = _RATE_RE.match(line)
        if match is None:
            raise RecordError(name, f"line {lineno}: {line.strip()!r} does not state the number of"
                                    " points and their spacing")
        rate = parse_float(match.group(2))
        if not (math.isfinite(rate) and rate > 0):
            raise RecordError(name, f"line {lineno}: sampling rate {rate} is not positive")
        npts, dt = int(match.group(1)), 1.0 / rate
    unit = next((m.group(1) for m in (r.search(line) for r in _DATA_UNIT_RES) if m), None)
    return npts, dt, unit


def _v2_tail(block, index, name, start):
    """Check the velocity and displacement series of a volume 2 channel; return the next index."""
    for quantity in ("VELOC", "DISPL"):
        if index >= len(block):
            raise RecordError(name, f"is truncated: the {quantity.lower()} series of the channel"
                                    f" at line {start + 1} is missing")
        line = block[index]
        match = _SPACED_RE.match(line)
        if match is None or match.group(2).upper() != quantity:
            raise RecordError(name, f"line {start + index + 1}: expected the line that opens the"
                                    f" {quantity.lower()} data, found {line.strip()[:40]!r}")
        total = int(match.group(1))
        first_data = block[index + 1] if index + 1 < len(block) else None
        per_line, _ = _layout(line, first_data, total, name, start + index + 1)
        index = _skip_series(block, index + 1, total, per_line, name,
                             f"{quantity.lower()} series at line {start + index + 1}")
    return index


def _read_channel(volume, start, block, has_marker, name, headonly, resample_interval):
    """Read one channel block.

    Returns
    -------
    tuple
        ``(orientation, delta, npts, stats, data)``: the orientation (``vertical``, ``azimuth``,
        ``positive_up``, ``index``) or, if unknown, the ``channel`` entry; sampling interval [s];
        number of samples; the other ``trace.stats`` entries; the samples in m/s^2 (or counts).
    """
    n_text, n_int, n_real, real_count = _LAYOUT[volume]
    notes: list[str] = []
    if len(block) < n_text + n_int + n_real:
        raise RecordError(name, f"is truncated: the channel header at line {start + 1} is"
                                " incomplete")
    header = block[:n_text]
    if _is_renadic(header):
        raise RecordError(name, "is a RENADIC (Chile) file, not a CSMIP file")
    ints = _header_numbers(block[n_text:n_text + n_int], start + n_text, _INT_COUNT,
                           _INT_WIDTH, int, name, "integer header")
    first_real = n_text + n_int
    reals = _header_numbers(block[first_real:first_real + n_real], start + first_real,
                            real_count, _REAL_WIDTH, parse_float, name, "real header")

    chan = _search(_CHAN_RE, header[1:])
    if chan is None:
        raise RecordError(name, f"channel at line {start + 1}: no 'Chan n:' line in the header")
    number = int(chan.group(1))
    orientation_text = chan.group(2)
    from_text = _orientation_text(orientation_text)
    code = ints[_INT_ORIENTATION]
    from_code = _orientation_code(code)
    if from_text is not None and from_code is not None and not _same_orientation(from_text,
                                                                                  from_code):
        raise RecordError(name, f"channel {number}: the text says {orientation_text!r} but the"
                                f" integer header's orientation code is {code}")
    if from_text is None and from_code is not None:
        notes.append(f"orientation taken from the integer header code {code}")
    elif from_text is not None and from_code is None and code is not None and not (
            1000 <= code < 2000 and from_text.get("index") is not None):
        notes.append(f"integer header orientation code {code} is not a known code; the text"
                     f" {orientation_text!r} is used")
    orientation = from_text or from_code
    channels_stated = _channels_stated(header, ints, number)
    if orientation is not None and not orientation["vertical"] and orientation["azimuth"] is None:
        notes.append(f"horizontal {orientation_text!r} of unstated azimuth: azimuth left unset")
    if orientation is None:
        notes.append(f"orientation {orientation_text!r} (code {code}) is not stated in a known"
                     " way: azimuth and dip left unset")

    # The samples.
    data_index = n_text + n_int + n_real
    opened = _data_start(volume, block, data_index, name, start)
    header_npts = _search(_V1_NPTS_RE, header)
    pairs = opened is None
    if pairs:
        if header_npts is None:
            raise RecordError(name, f"channel {number}: no 'NO. OF POINTS' in the header")
        npts, dt, unit = int(header_npts.group(1)), None, None
        first, total = data_index, 2 * npts
        start_line = ""
    else:
        npts, dt, unit = opened
        if header_npts is not None and int(header_npts.group(1)) != npts:
            raise RecordError(name, f"channel {number}: the header says"
                                    f" {header_npts.group(1)} points, the data line {npts}")
        first, total = data_index + 1, npts
        start_line = block[data_index]
    if npts < 1:
        raise RecordError(name, f"channel {number} has {npts} points")
    if unit is None:
        unit_match = _search(_HEADER_UNIT_RE, header)
        if unit_match is None:
            raise UnitsError(name, f"channel {number}: the header states no unit for the samples")
        unit = unit_match.group(1)
    original_unit, factor = _unit(unit, name)

    first_data = block[first] if first < len(block) else None
    per_line, width = _layout(start_line, first_data, total, name, start + first)
    values, after = _series(block, first, total, per_line, width, name,
                            f"channel {number} acceleration")
    if volume == "V2":
        after = _v2_tail(block, after, name, start)
    if any(line.strip() for line in block[after:]):
        raise RecordError(name, f"line {start + after + 1}: unexpected text after the data of"
                                f" channel {number}")
    if not has_marker:
        notes.append("no end-of-data line after this channel")

    offset = 0.0
    original_npts = npts
    interpolated = False
    if pairs:
        times, data = values[0::2], values[1::2]
        check_samples(times, name, f"the times of channel {number}")
        steps = np.diff(times)
        if steps.size == 0 or np.any(steps < 0) or times[-1] <= times[0]:
            raise RecordError(name, f"channel {number}: the times of the time/value pairs do"
                                    " not increase")
        offset = float(times[0])
        if np.ptp(steps) < 1e-9:
            dt = float(steps[0])
        else:
            if resample_interval is None:
                dt = round(float(np.median(steps)) / PAIR_TIME_RESOLUTION_S)
                dt *= PAIR_TIME_RESOLUTION_S
            else:
                dt = float(resample_interval)
            dt = check_sampling_interval(dt, name)
            count = int(math.floor((times[-1] - times[0]) / dt + 1e-6)) + 1
            if count > MAX_RESAMPLE_FACTOR * npts:
                raise RecordError(name, f"channel {number}: resampling {npts} pairs at {dt} s"
                                        f" would make {count} samples; choose a larger interval")
            grid = times[0] + dt * np.arange(count)
            check_samples(data, name, f"channel {number} acceleration")
            data = np.interp(grid, times, data)
            interpolated = True
            notes.append(f"{npts} time/value pairs at uneven times interpolated linearly onto"
                         f" {count} samples {dt} s apart")
            npts = count
    else:
        data = values
    delta = check_sampling_interval(dt, name)
    check_samples(data, name, f"channel {number} acceleration")

    # Stated peak, checked against the samples.
    peak_re = _V2_PEAK_RE if volume == "V2" else _V1_PEAK_RE
    stated = _search(peak_re, header)
    stated_peak_si = None
    units = "counts" if factor is None else "m/s**2"
    if factor is not None:
        data = data * factor
        peak = check_plausible_samples(data, name, f"channel {number} acceleration")
        if stated is not None:
            _, peak_factor = _unit(stated.group(2), name)
            value = parse_float(stated.group(1))
            if peak_factor is not None and math.isfinite(value):
                stated_peak_si = abs(value) * peak_factor
                digits = len(stated.group(1).split(".")[1]) if "." in stated.group(1) else 0
                resolution = 10.0 ** -digits * peak_factor
                if stated_peak_si >= 20.0 * resolution and not (
                        0.5 * stated_peak_si <= peak <= 2.0 * stated_peak_si):
                    raise UnitsError(name, f"channel {number}: the header states a peak of"
                                           f" {stated.group(1)} {stated.group(2)} but the samples,"
                                           f" read in {unit!r}, peak at {peak:.4g} m/s^2")

    starttime, start_text = _start_time(header, ints, name, notes)
    station_line_index = 4 if volume == "V1" else 5
    station_line = next((line for line in header if _STATION_RE.search(line)),
                        header[station_line_index])
    station_match = _STATION_RE.search(station_line)
    record_id = _search(_RECORD_ID_RE, header)
    coordinates = _coordinates(station_line, reals, notes)
    band_rate = 1.0 / delta
    if orientation is None:
        channel_stats = {"channel": orientation_stats(band_rate, vertical=False)["channel"][:2]
                         + str(number % 10)}
    else:
        channel_stats = dict(orientation)

    name_line = header[station_line_index + 1] if len(header) > station_line_index + 1 else ""
    stats = {
        "network": record_id.group(1) if record_id else NETWORK,
        "station": (record_id.group(2) if record_id
                    else (station_match.group(1) if station_match else "")),
        "location": "",
        "units": units,
        "original_units": original_unit,
        "shipblock_dmg": AttribDict({
            "volume": volume,
            "channel_number": number,
            "channels_stated": channels_stated,
            "orientation_text": orientation_text,
            "orientation_code": code,
            "station_line": station_line.strip(),
            "station_name": name_line[:40].strip(),
            "record_id": record_id.group(0) if record_id else "",
            "start_time_text": start_text,
            "units": unit.strip(),
            "npts": original_npts,
            "dt": dt,
            "time_value_pairs": pairs,
            "original_npts": original_npts,
            "interpolated": interpolated,
            "stated_peak_text": stated.group(0) if stated else "",
            # The same peak to more digits (signed): V1 in g, V2 in the unit of the samples.
            "real_header_peak": reals[_REAL_V1_MAX_G if volume == "V1" else _REAL_V2_PEAK],
            "notes": notes,
            "text_header": [line.rstrip() for line in header],
        }),
    }
    if starttime is not None:
        stats["starttime"] = starttime + offset
    if coordinates is not None:
        stats["coordinates"] = AttribDict(latitude=coordinates[0], longitude=coordinates[1],
                                          elevation=0.0)
    if stated_peak_si is not None:
        stats["stated_peak_si"] = stated_peak_si
    if headonly:
        data = np.empty(0)
    return channel_stats, delta, npts, stats, data


def read_dmg(filename, headonly: bool = False, resample_interval=None, **kwargs) -> Stream:
    """Read a CSMIP/CDMG volume 1 or 2 file into a Stream of acceleration traces in m/s^2.

    Parameters
    ----------
    filename : str, os.PathLike or file-like
        The ``.V1``, ``.V2`` or ``.RAW`` file.
    headonly : bool, optional
        Read only the headers; the traces then have no samples (``stats.npts`` is set).
    resample_interval : float, optional
        Sampling interval [s] onto which time/value pairs at uneven times are interpolated; by
        default their median time step, rounded to 0.001 s. Evenly sampled channels are returned
        as stored, so the option is refused for a file without an uneven channel (a
        :class:`RecordError`) rather than ignored.
    **kwargs
        Ignored (obspy passes its own keywords to every plug-in).

    Returns
    -------
    obspy.Stream
        One trace per channel, in the file's order: ``stats.units == "m/s**2"`` (``"counts"`` if
        the file says counts), ``stats.original_units`` the file's unit (``"g"``, ``"g/10"``,
        ``"cm/s^2"``), channel code, ``azimuth``/``dip`` [deg] where the file states them,
        ``starttime`` (UTC), ``coordinates``, ``stated_peak_si`` [m/s^2] and the parsed header in
        ``stats.shipblock_dmg`` (with ``notes`` on anything the reader had to decide).

    Raises
    ------
    RecordError
        If the file is not a CSMIP volume 1 or 2 file (a volume 3 file holds spectra), a header
        is broken or contradicts itself, the data are truncated, too long, not numbers, NaN/inf or
        implausibly large, or ``resample_interval`` is given for a file with no uneven channel.
    UnitsError
        If the unit of the samples is not stated, not an acceleration, or disagrees with the
        stated peak.
    """
    name = source_name(filename)
    text = read_text(filename)
    head, eof, tail = text.partition(_DOS_EOF)
    if eof and not tail.strip(_DOS_EOF + " \r\n"):
        text = head  # DOS end-of-file padding (Ctrl-Z) after the last channel
    lines = text.splitlines()
    volume = _volume(lines)
    if volume == "V3":
        raise RecordError(name, "V3 holds response spectra, not a time series; use the V2 file")
    if volume is None:
        raise RecordError(name, "is not a CSMIP/DMG file (no 'Uncorrected accelerogram data' or"
                                " 'Corrected accelerogram' title on line 1)")
    traces = []
    horizontals = 0
    for start, block, has_marker in _channel_blocks(lines, volume, name):
        orientation, delta, npts, stats, data = _read_channel(
            volume, start, block, has_marker, name, headonly, resample_interval)
        rate = 1.0 / delta
        if "vertical" in orientation:
            index = orientation.get("index")
            if not orientation["vertical"] and index is None:
                horizontals += 1
                azimuth = orientation.get("azimuth")
                # By the azimuth, not the file order: a set of one-channel files (CESMD's
                # free-field sets at 110 and 20 deg) then names its horizontals 2 and 1.
                index = horizontals if azimuth is None else horizontal_index(azimuth)
            stats.update(orientation_stats(
                rate, vertical=orientation["vertical"], azimuth_deg=orientation.get("azimuth"),
                positive_up=orientation.get("positive_up", True), index=index or 1))
        else:
            stats.update(orientation)
        trace = make_trace(data, delta, stats)
        if headonly:
            trace.stats.npts = npts
        traces.append(trace)
    _check_all_channels(traces, name)
    intervals = sorted({f"{trace.stats.delta:g}" for trace in traces})
    check_resampling_applies(
        name, "resample_interval", resample_interval,
        any(trace.stats.shipblock_dmg.interpolated for trace in traces),
        f"evenly sampled at {' and '.join(intervals)} s intervals")
    codes = [trace.stats.channel for trace in traces]
    if len(set(codes)) < len(codes):
        for trace in traces:
            trace.stats.location = f"{trace.stats.shipblock_dmg.channel_number % 100:02d}"
    return Stream(traces)
