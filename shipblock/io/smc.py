"""Reader for USGS SMC strong-motion files (obspy waveform plug-in ``SHIPBLOCK_SMC``).

The SMC format is the ASCII format of the USGS National Strong-Motion Project (NSMP) [1]_, one
component per file (``.smc``):

1. 11 text lines. Line 1 names the data type: ``1 UNCORRECTED ACCELEROGRAM``,
   ``2 CORRECTED ACCELEROGRAM``, ``3 VELOCITY``, ``4 DISPLACEMENT``, ``5 RESPONSE SPECTRA``,
   ``6 FOURIER AMPLITUDE SPECTRA ...`` (``0 UNKNOWN``); line 3 starts with the station code, line 4
   holds the event date and name, line 6 the station name and ``component=``, line 7 the peak,
   line 8 the instrument and data source.
2. 48 integers, ``8I10`` (6 lines). Used here, 0-based: 0 the null value (``-32768``); 1-6 start
   year, day of year, hour, minute, second, millisecond; 8 channel number; 12 vertical orientation
   [deg from up: 0 up, 180 down, 90 horizontal]; 13 horizontal orientation [deg clockwise from
   north]; 14 sensor type code; 15 number of comment lines; 16 number of data values; 17 problem
   flag; 18 structure type (null: not a structure, 1 building, 2 bridge, 3 dam, 4 other);
   24 building floor; 26 transducer location on a bridge, 27 on a dam (0 = free field);
   29 station number.
3. 50 reals, ``5E15.7`` (10 lines). 0 the null value (``1.7E+38``); 1 sampling rate [samples/s];
   10-12 station latitude, longitude, elevation; 16 epicentral distance [km]; 28-31 time and
   value of the maximum and of the minimum of the record.
4. The comment lines (``|`` in column 1), then the data values, ``8E10.4``.

Accelerations are in cm/s^2: the format defines them so and states no unit code; the data type
of line 1 is checked (velocity and displacement files raise :class:`UnitsError`, spectra
:class:`RecordError`). The field layout above is the NSMP documentation's as implemented by D. M.
Boore's ``SMCWrite`` (which writes ``int_head(17) = npts``, ``real_head(2) = sps``, null values
``-32768`` and ``1.7E+38``).

What the real files (Loma Prieta 1989, gmprocess test corpus) show beyond that description:

* Analog (film) records digitized unevenly have a null sampling rate; their data are then
  (time [s], acceleration) pairs, and the integer header counts values, not pairs. These are read
  and linearly interpolated onto an even grid at ``resample_rate`` (200 samples/s by default, the
  rate of the corrected files of the same event); times that repeat (the ``E10.4`` time field
  rounds to 1 ms after 10 s) are merged by averaging their values. The interpolated peak is within
  0.5 % of the digitized one on these files. ``resample_rate`` means only this, as gmprocess's
  read option of that name: given for an evenly sampled file (the corrected ``0111a/b/c.smc``, 200
  samples/s) it is refused (:class:`RecordError`), not silently ignored.
* Each of these pair files ends with one extra line of four pairs after the counted values. It
  does not continue the record: its times jump back (by up to 0.1 s) or forward (by 0.012 to
  1.6 s), and its values jump too (from -1.2 to -19.8 cm/s^2 in 12 ms in ``cra-1.0210g``). The
  header's count is taken as right, the line is ignored, and its size is kept in
  ``stats.shipblock_smc.ignored_trailing_values``. Any other surplus is an error.
* The start time of these analog records (all fifteen files) is the event's minute
  (``1989-10-18 00:04:00`` for an origin at 00:04:15, seconds 0, milliseconds null): film records
  have no absolute timing. A time stated to the minute only is flagged
  ``stats.shipblock_smc.start_time_nominal``.
* Sensors in structures (a 42-storey building, a dam crest) are ordinary records here; the site
  is reported in ``stats.sensor_site`` (``"free-field"`` or ``"structure"``) with the location
  in words in ``stats.shipblock_smc.sensor_location``, so that a caller can refuse them for a
  ground-motion analysis. No error is raised for them.

References
----------
.. [1] U.S. Geological Survey National Strong-Motion Project, "SMC- and BBF-format data files"
   (smcfmt), https://escweb.wr.usgs.gov/nsmp-data/smcfmt.html (accessed 2024).
"""

from __future__ import annotations

import math
import re

import numpy as np
from obspy import Stream, UTCDateTime
from obspy.core import AttribDict

from shipblock.checks import how_to_pass
from shipblock.errors import RecordError, UnitsError
from shipblock.io._common import (
    DEFAULT_RESAMPLE_RATE_HZ,
    FLOAT_RE,
    band_code,
    check_plausible_samples,
    check_resampling_applies,
    check_samples,
    check_sampling_interval,
    fixed_fields,
    horizontal_index,
    make_trace,
    orientation_stats,
    parse_float,
    peek_text,
    read_text,
    resample_pairs,
    source_name,
)
from shipblock.units import si_factor

__all__ = ["FORMAT", "is_smc", "read_smc"]

#: Name under which the reader is registered as an obspy waveform plug-in.
FORMAT = "SHIPBLOCK_SMC"

#: What a caller may state an SMC file of data type ``0 UNKNOWN`` holds (``data_type=``).
STATED_DATA_TYPES = ("acceleration",)

#: Unit of SMC accelerations (the format's own; the header states no unit code).
SMC_UNIT = "cm/s^2"

#: Highest credible sampling rate [samples/s] (some files hold nonsense there).
MAX_SAMPLING_RATE_HZ = 1.0e5

_TEXT_LINES = 11
_INT_LINES = 6
_INT_PER_LINE = 8
_INT_WIDTH = 10
_REAL_LINES = 10
_REAL_PER_LINE = 5
_REAL_WIDTH = 15
_DATA_WIDTH = 10
_HEADER_LINES = _TEXT_LINES + _INT_LINES + _REAL_LINES

#: Integer-header flag (0-based index 46) that Boore's SMCWrite sets to 8 for high-precision
#: data lines (``5ES14.7``), which are read as free-format numbers.
_HIGH_PRECISION_FLAG = 8

_TYPE_LINE = re.compile(
    r"^\s*([0-6])\s+(UNKNOWN|UNCORRECTED ACCELEROGRAM|CORRECTED ACCELEROGRAM|VELOCITY"
    r"|DISPLACEMENT|RESPONSE SPECTRA|FOURIER AMPLITUDE SPECTRA.*)\s*$",
    re.IGNORECASE,
)
_STRUCTURES = {1: "building", 2: "bridge", 3: "dam", 4: "other structure"}
_BRIDGE_LOCATIONS = {
    0: "free field",
    1: "at the base of a pier or abutment",
    2: "on an abutment",
    3: "on the deck at the top of a pier",
    4: "on the deck between piers or between an abutment and a pier",
}
_DAM_LOCATIONS = {
    0: "upstream or downstream free field",
    1: "at the base of the dam",
    2: "on the crest of the dam",
    3: "on the abutment of the dam",
}
_PEAK_TEXT = re.compile(r"pk\s*(?:acc|mtn)?\s*=\s*(" + FLOAT_RE.pattern + ")", re.IGNORECASE)
_COMPONENT_TEXT = re.compile(r"component\s*=\s*(\S+)", re.IGNORECASE)


def _fixed_fields(line: str, width: int, count: int) -> list[str]:
    """Split a Fortran fixed-width line into at most ``count`` non-blank fields."""
    fields = fixed_fields(line[: width * count], width)
    while fields and not fields[-1].strip():
        fields.pop()
    return fields


def _ints(lines, name: str) -> list[int]:
    """Parse the integer header (``8I10``); raise :class:`RecordError` if a field is bad."""
    values = []
    for offset, line in enumerate(lines):
        fields = _fixed_fields(line, _INT_WIDTH, _INT_PER_LINE)
        if len(fields) != _INT_PER_LINE:
            raise RecordError(
                name, f"integer header line {_TEXT_LINES + offset + 1} has {len(fields)} of"
                f" {_INT_PER_LINE} fields"
            )
        for field in fields:
            try:
                values.append(int(field))
            except ValueError:
                raise RecordError(
                    name, f"integer header line {_TEXT_LINES + offset + 1}: {field.strip()!r}"
                    " is not an integer"
                ) from None
    return values


def _reals(lines, name: str) -> list[float]:
    """Parse the real header (``5E15.7``); raise :class:`RecordError` if a field is bad."""
    values = []
    first = _TEXT_LINES + _INT_LINES + 1
    for offset, line in enumerate(lines):
        fields = _fixed_fields(line, _REAL_WIDTH, _REAL_PER_LINE)
        if len(fields) != _REAL_PER_LINE:
            raise RecordError(
                name, f"real header line {first + offset} has {len(fields)} of {_REAL_PER_LINE}"
                " fields"
            )
        for field in fields:
            try:
                value = parse_float(field)
            except ValueError:
                raise RecordError(
                    name, f"real header line {first + offset}: {field.strip()!r} is not a number"
                ) from None
            if not math.isfinite(value):
                raise RecordError(name, f"real header line {first + offset} holds {value}")
            values.append(value)
    return values


def _looks_like_smc(lines) -> bool:
    """Structural check shared by detection: type line, 6 integer and 10 real header lines."""
    if len(lines) < _HEADER_LINES:
        return False
    first = lines[0].strip()
    if _TYPE_LINE.match(first) is None and first != "*":
        return False
    try:
        ints = _ints(lines[_TEXT_LINES : _TEXT_LINES + _INT_LINES], "")
        _reals(lines[_TEXT_LINES + _INT_LINES : _HEADER_LINES], "")
    except RecordError:
        return False
    return 0 <= ints[15] < 10000 and ints[16] >= 0


def is_smc(filename) -> bool:
    """Tell whether a file is a USGS SMC file (never raises).

    Parameters
    ----------
    filename : str, os.PathLike or file-like
        The file to check.

    Returns
    -------
    bool
        ``True`` if line 1 names an SMC data type (or is ``*``) and lines 12-17 and 18-27 are an
        ``8I10`` integer header and a ``5E15.7`` real header.
    """
    text = peek_text(filename)
    if text is None:
        return False
    try:
        return _looks_like_smc(text.splitlines()[:_HEADER_LINES])
    except Exception:  # noqa: BLE001 - detection must never raise
        return False


def _null(value, null) -> bool:
    return value == null


def _start_time(ints, null, event_line, name):
    """Start time from integer header fields 1-6, or ``None`` if year/day/hour/minute are null.

    Some files hold 0 for the year; the year of text line 4 (the event date) is used then.
    """
    year, jday, hour, minute, second, msec = ints[1:7]
    if year == 0:
        found = re.match(r"\s*(\d{4})\b", event_line)
        year = int(found.group(1)) if found else null
    if null in (year, jday, hour, minute):
        return None
    second = 0 if second == null else second
    msec = 0 if msec == null else msec
    if not (1800 <= year <= 2200 and 1 <= jday <= 366 and 0 <= hour <= 23 and 0 <= minute <= 59
            and 0 <= second <= 60 and 0 <= msec <= 999):
        raise RecordError(
            name, f"integer header start time year={year} day={jday} {hour}:{minute}:{second}"
            f" +{msec} ms is not a valid date"
        )
    try:
        return UTCDateTime(year=year, julday=jday, hour=hour, minute=minute) + second + msec / 1e3
    except Exception:  # noqa: BLE001 - obspy raises several types for bad dates
        raise RecordError(name, f"year {year} has no day {jday}") from None


def _site(ints, null) -> tuple[str, str]:
    """``(sensor_site, sensor_location)`` from the structure fields of the integer header."""
    kind = ints[18]
    if kind == null:
        return "free-field", "not a structure"
    words = _STRUCTURES.get(kind, f"structure type code {kind}")
    if kind == 1:
        floor = ints[24]
        return "structure", words + ("" if floor == null else f", floor {floor}")
    table, code = (_BRIDGE_LOCATIONS, ints[26]) if kind == 2 else (_DAM_LOCATIONS, ints[27])
    if kind in (2, 3) and code != null:
        where = table.get(code, f"location code {code}")
        return ("free-field" if code == 0 else "structure"), f"{words}, {where}"
    # A structure whose transducer location is not stated is not taken for free field.
    return "structure", words


def _orientation(ints, null, component_text, rate, name, unknown_type=False) -> dict:
    """Channel code, azimuth and dip from the orientation fields (text ``component=`` if null)."""
    vertical, azimuth = ints[12], ints[13]
    token = component_text.strip().lower()
    # Line 6 repeats the orientation in words; a header that contradicts itself is refused.
    if token in ("up", "down") and vertical not in (null, 0, 180):
        raise RecordError(name, f"line 6 says component={token} but the vertical orientation"
                                f" field is {vertical} deg from up")
    if (re.fullmatch(r"\d{1,3}", token) and vertical == 90 and azimuth != null
            and int(token) % 360 != azimuth % 360):
        raise RecordError(name, f"line 6 says component={token} but the horizontal"
                                f" orientation field is {azimuth} deg")
    if vertical == null:
        if token in ("up", "vert", "v", "z"):
            vertical = 0
        elif token in ("down", "dn"):
            vertical = 180
        elif re.fullmatch(r"\d{1,3}", token):
            vertical, azimuth = 90, int(token)
    if vertical in (0, 180):
        return orientation_stats(rate, vertical=True, positive_up=vertical == 0)
    if vertical == 90:
        if azimuth == null:
            return orientation_stats(rate, vertical=False, index=1)
        if not 0 <= azimuth <= 360:
            raise RecordError(name, f"horizontal orientation {azimuth} deg is not an azimuth")
        return orientation_stats(
            rate, vertical=False, azimuth_deg=float(azimuth), index=horizontal_index(azimuth)
        )
    if vertical == null and unknown_type:
        # A "0 UNKNOWN" file (PEER's conversions) states nothing but its samples: the component
        # is the caller's to give (channel_map, by file name).
        return {}
    if vertical == null:
        # Nothing says vertical or horizontal (pyrotd's PEER copies): an unknown component that
        # read_motion refuses unless the caller names it (channel_map).
        return {"channel": f"{band_code(rate)}NX"}
    raise RecordError(
        name, f"vertical orientation {vertical} deg from up is neither vertical (0/180) nor"
        " horizontal (90)"
    )


def _data_values(lines, high_precision: bool, name: str) -> tuple[list[float], list[int]]:
    """Parse data lines; return the values and the value count of each line."""
    values: list[float] = []
    per_line: list[int] = []
    for lineno, line in enumerate(lines, start=1):
        if high_precision:
            tokens = FLOAT_RE.findall(line)
            if FLOAT_RE.sub("", line).strip():
                raise RecordError(name, f"data line {lineno}: unreadable characters")
        else:
            tokens = _fixed_fields(line.rstrip(), _DATA_WIDTH, 10**6)
        for token in tokens:
            try:
                values.append(parse_float(token))
            except ValueError:
                raise RecordError(
                    name, f"data line {lineno}: {token.strip()!r} is not a number"
                ) from None
        per_line.append(len(tokens))
    return values, per_line


def _trim_pair_tail(values, per_line, npts, name) -> tuple[list[float], int]:
    """Drop the one extra line that follows the counted values of a (time, value) pair file.

    Exactly one line of whole pairs after the line holding the last counted value is dropped;
    any other surplus means the file holds more data than its header says.
    """
    if len(values) <= npts:
        return values, 0
    used = 0
    extra: list[int] = []
    for index, count in enumerate(per_line):
        used += count
        if used >= npts:
            extra = per_line[index + 1 :]
            break
    if used == npts and len(extra) == 1 and extra[0] % 2 == 0:
        return values[:npts], extra[0]
    raise RecordError(
        name, f"is longer than its header says: {npts} values stated, {len(values)} found"
    )


def read_smc(filename, headonly: bool = False, resample_rate: float | None = None,
             data_type: str | None = None, **kwargs) -> Stream:
    """Read a USGS SMC acceleration file into a Stream of one trace in m/s^2.

    Parameters
    ----------
    filename : str, os.PathLike or file-like
        The SMC file.
    headonly : bool, optional
        Return the trace without samples (``stats.npts`` still set).
    resample_rate : float, optional
        Sampling rate [samples/s] onto which an unevenly digitized record (time, value pairs) is
        linearly interpolated; by default :data:`~shipblock.io._common.DEFAULT_RESAMPLE_RATE_HZ`
        (200). An evenly sampled record is returned as stored, so the option is refused for it
        (a :class:`RecordError`) rather than ignored: its rate is changed by the processing step
        ``resample``, which filters against aliasing.
    data_type : {"acceleration"}, optional
        What the file holds when line 1 says ``0 UNKNOWN`` (PEER's ``.AT2.smc`` conversions are
        written so): ``"acceleration"`` reads it as an accelerogram in the format's cm/s^2 (the
        provenance says the type was stated by the caller). Ignored for files that state a type.
    **kwargs
        Ignored (obspy passes its own keywords to every plug-in).

    Returns
    -------
    obspy.Stream
        One trace: ``stats.units == "m/s**2"``, ``stats.original_units == "cm/s^2"``, channel,
        azimuth and dip from the orientation fields, ``stats.sensor_site`` (``"free-field"`` or
        ``"structure"``), ``stats.stated_peak_si`` [m/s^2] from the header's maximum and minimum,
        ``stats.coordinates`` and the parsed header in ``stats.shipblock_smc``.

    Raises
    ------
    RecordError
        If the file is not SMC, its header is broken, it holds spectra, its data count differs
        from the header's, samples are not finite, or ``resample_rate`` is given for an evenly
        sampled record.
    UnitsError
        If it holds velocity, displacement or an unknown data type.
    """
    name = source_name(filename)
    lines = read_text(filename).splitlines()
    if len(lines) < _HEADER_LINES:
        raise RecordError(name, f"is not an SMC file or is truncated: {len(lines)} lines, the"
                                f" headers alone take {_HEADER_LINES}")
    type_line = lines[0].strip()
    match = _TYPE_LINE.match(type_line)
    if match is None:
        if type_line == "*":
            raise UnitsError(name, "line 1 is '*': the SMC file does not state its data type")
        raise RecordError(name, f"line 1 {type_line[:40]!r} is not an SMC data type")
    code = int(match.group(1))
    if code in (3, 4):
        raise UnitsError(name, f"holds {match.group(2).lower()}, not acceleration")
    if code in (5, 6):
        raise RecordError(name, f"holds {match.group(2).lower()}, not a time series")
    if code == 0 and data_type != "acceleration":
        raise UnitsError(name, "data type is '0 UNKNOWN'; not known to be an acceleration; if"
                               " it is one (in cm/s^2, as SMC defines), "
                               + how_to_pass("data_type", "acceleration"))
    ints = _ints(lines[_TEXT_LINES : _TEXT_LINES + _INT_LINES], name)
    reals = _reals(lines[_TEXT_LINES + _INT_LINES : _HEADER_LINES], name)
    inull, rnull = ints[0], reals[0]

    ncomments, npts = ints[15], ints[16]
    if ncomments == inull or not 0 <= ncomments < 10000:
        raise RecordError(name, f"comment line count {ncomments} is invalid")
    if npts == inull or npts <= 0:
        raise RecordError(name, f"data value count {npts} is invalid")
    comments = lines[_HEADER_LINES : _HEADER_LINES + ncomments]
    if len(comments) < ncomments:
        raise RecordError(name, f"is truncated inside its {ncomments} comment lines")

    rate = reals[1]
    pairs = _null(rate, rnull) or rate >= 1e37
    if not pairs and not (0 < rate <= MAX_SAMPLING_RATE_HZ):
        raise RecordError(name, f"sampling rate {rate:g} samples/s is not credible")
    if pairs and npts % 2:
        raise RecordError(name, f"holds (time, value) pairs but an odd value count {npts}")
    check_resampling_applies(name, "resample_rate", resample_rate, pairs,
                             f"evenly sampled at {rate:g} samples/s")
    if resample_rate is None:
        resample_rate = DEFAULT_RESAMPLE_RATE_HZ

    text = [line.rstrip() for line in lines[:_TEXT_LINES]]
    component = _COMPONENT_TEXT.search(text[5])
    component_text = component.group(1) if component else ""
    factor = si_factor(SMC_UNIT, name)
    high_precision = len(ints) > 46 and ints[46] == _HIGH_PRECISION_FLAG
    values, per_line = _data_values(lines[_HEADER_LINES + ncomments :], high_precision, name)
    ignored = 0
    if pairs:
        values, ignored = _trim_pair_tail(values, per_line, npts, name)
    if len(values) != npts:
        what = "truncated" if len(values) < npts else "longer than its header says"
        raise RecordError(name, f"is {what}: {npts} data values stated, {len(values)} found")
    data = np.asarray(values, dtype=np.float64)
    check_samples(data, name, "the record")

    merged = 0
    first_time = 0.0
    if pairs:
        samples, first_time, merged = resample_pairs(data[0::2], data[1::2], resample_rate, name)
        delta = 1.0 / resample_rate
        raw_peak = float(np.max(np.abs(data[1::2])))
    else:
        samples = data
        delta = check_sampling_interval(1.0 / rate, name)
        raw_peak = float(np.max(np.abs(data)))
    sampling_rate = 1.0 / delta

    site, location_words = _site(ints, inull)
    peak_text = _PEAK_TEXT.search(text[6])
    header = AttribDict(
        {
            "data_type": match.group(2).upper(),
            # "0 UNKNOWN" read as an accelerogram because the caller said so (data_type=)
            "data_type_stated_by_caller": code == 0,
            "station_code": text[2][:5].strip(),
            "event": text[3].strip(),
            "station_name": text[5].split("component")[0].replace("station =", "").strip(" ,"),
            "component": component_text,
            "instrument": text[7].split("data source")[0].replace("inst type=", "").strip(),
            "data_source": text[7].split("=")[-1].strip() if "data source" in text[7] else "",
            "text_peak_cm_s2": parse_float(peak_text.group(1)) if peak_text else None,
            "channel_number": None if ints[8] == inull else ints[8],
            "vertical_orientation_deg": None if ints[12] == inull else ints[12],
            "horizontal_orientation_deg": None if ints[13] == inull else ints[13],
            "sensor_type_code": None if ints[14] == inull else ints[14],
            "problem_flag": ints[17] == 1,
            "structure_type_code": None if ints[18] == inull else ints[18],
            "sensor_site": site,
            "sensor_location": location_words,
            "station_number": None if ints[29] == inull else ints[29],
            "npts_file": npts,
            "time_value_pairs": pairs,
            "resample_rate_hz": resample_rate if pairs else None,
            "first_digitized_time_s": first_time if pairs else None,
            "merged_repeated_times": merged,
            "ignored_trailing_values": ignored,
            "digitized_peak_cm_s2": raw_peak,
            "comments": " ".join(c.strip().lstrip("|").strip() for c in comments).strip(),
            # A time stated to the minute only (seconds 0, milliseconds null) is the event's
            # minute on the analog records seen, not a trigger time.
            "start_time_nominal": ints[5] in (0, inull) and ints[6] == inull,
        }
    )
    floor = ints[24]
    stats = {
        "network": "US" if "USGS" in header["data_source"].upper() else "",
        "station": text[2][:4].strip().strip("*"),  # "*": not stated
        "location": f"{floor:02d}" if ints[18] == 1 and floor != inull and 0 <= floor < 100
        else "",
        "units": "m/s**2",
        "original_units": SMC_UNIT,
        "sensor_site": site,
        "shipblock_smc": header,
        **_orientation(ints, inull, component_text, sampling_rate, name, unknown_type=code == 0),
    }
    peaks = [abs(reals[i]) for i in (29, 31) if not _null(reals[i], rnull)]
    if peaks:
        stats["stated_peak_si"] = max(peaks) * factor
    latitude, longitude, elevation = reals[10:13]
    if not (_null(latitude, rnull) or _null(longitude, rnull)):
        stats["coordinates"] = AttribDict(
            latitude=latitude,
            longitude=longitude,
            elevation=0.0 if _null(elevation, rnull) else elevation,
        )
    start = _start_time(ints, inull, text[3], name)
    trace = make_trace([] if headonly else samples, delta, stats)
    if headonly:
        trace.stats.npts = len(samples)
    else:
        trace.data *= factor
        check_plausible_samples(trace.data, name, "the record")
    if start is not None:
        trace.stats.starttime = start + first_time
    return Stream([trace])
