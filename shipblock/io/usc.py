"""Reader for USC strong-motion volumes (obspy waveform plug-in ``SHIPBLOCK_USC``).

The University of Southern California's Los Angeles strong-motion network distributed its film
records (1994 Northridge and others) in Fortran fixed-width volumes modelled on the Caltech/CDMG
"Volume I/II" layout [1]_ [2]_, one channel per block (blocks may follow each other in a file):

Volume I (uncorrected, ``FILE  n OF UNCORRECTED ACCELEROGRAM DATA OF VOLUME I:``)
    13 text lines (event, ``STATION USC# nnnn  dd mm ssN, ddd mm ssW``, station name,
    ``COMP N08W``/``COMP  UP``, ``NO. OF POINTS``, ``UNITS ARE SEC AND G/10``,
    ``RMS ACCLN. OF COMPLETE RECORD``), 100 integers ``16I5`` (7 lines), 50 reals ``8F10.3``
    (7 lines), then the digitized (time [s], acceleration) pairs, five pairs a line
    (``F8.3`` then ``F7.3`` fields).
Volume II (corrected, first line ``CORRECTED ACCELEROGRAM``)
    the Volume I text header after that first line plus processing lines (25 text lines in all),
    100 integers (7 lines), 100 reals (13 lines), then
    ``n POINTS OF ACC DATA EQUALLY SPACED AT dt SEC. IN UNITS CM/SEC/SEC`` and ``8F10.3``
    samples, followed by velocity and displacement blocks (not read).

Integers used (0-based, both volumes): 8 station number; 9-14 station latitude and longitude in
degrees, minutes, seconds; 21-24 month, day, year and ``hhmm`` (GMT); 26 orientation: an azimuth
0-360 [deg clockwise from north], 400 vertical, 500 up, 600 down, 700 longitudinal, 800
transverse; 27 number of digitized pairs. Reals of Volume I: 2 duration [s], 4 the unit as a
fraction of g (0.1 for ``G/10``).

What the real files (gmprocess test corpus, Northridge 1994) show:

* Volume I samples are uneven (about 237 points/s, times printed to 1 ms); they are linearly
  interpolated onto an even grid at ``resample_rate`` (200 samples/s by default, as gmprocess
  does, so the two agree sample for sample; the option is refused for a file of Volume II
  channels only, which are evenly sampled and read as stored). The unit is g/10 (``UNITS ARE SEC AND G/10`` and
  real 4 = 0.100 agree); the stated RMS acceleration matches the record's to 1.5 %.
* ``017m30bt.s0a``, which gmprocess refuses as "not a supported volume", is a valid Volume II:
  1887 instrument- and baseline-corrected samples at 0.02 s in cm/s^2, band-passed 0.225-0.325 to
  25-27 Hz, with its peak (-242.39450 cm/s^2) stated in the header. It is read (acceleration
  block only); the stated peak's magnitude and time match the samples.
* In ``017m30bt.s0a`` every stated extreme has the opposite sign of the samples: peak
  acceleration -242.39450 cm/s^2 at 4.58 s where the sample is +242.395, peak velocity +12.05681
  where the velocity block holds -12.057, displacement and initial velocity and displacement
  likewise. One of the two was negated after the other was computed (a polarity change to report
  the component as N08W, probably); the file does not say which. The samples are returned as
  stored and ``stats.shipblock_usc.stated_peak_sign_matches_samples`` is ``False``.
* ``017m30lw.s0?`` state the longitude as ``118 26 05N``; a longitude hemisphere other than ``E``
  is taken as west (the network lies in Los Angeles), and the text kept in the header.
* The date and ``hhmm`` of the header are the earthquake's minute (``1230 GMT`` for an origin at
  12:30:55): film records carry no absolute time, so the start time is nominal
  (``stats.shipblock_usc.start_time_nominal``).

No public description of the USC files was found; the field positions above were read from the
real files (text and numbers agree field by field) and compared with gmprocess 2.8's reader, whose
numbers this reader reproduces.

References
----------
.. [1] Trifunac, M. D., and Lee, V. W. (1973). Routine computer processing of strong-motion
   accelerograms. Report EERL 73-03, California Institute of Technology (the Volume I/II scheme).
.. [2] California Strong Motion Instrumentation Program, CSMIP/CDMG Volume 1 and 2 ASCII formats
   (25 text lines, ``16I5`` integer and ``8F10.3`` real headers), as used by
   :mod:`shipblock.io.dmg`.
"""

from __future__ import annotations

import math
import re

import numpy as np
from obspy import Stream, UTCDateTime
from obspy.core import AttribDict

from shipblock.errors import RecordError, UnitsError
from shipblock.io._common import (
    DEFAULT_RESAMPLE_RATE_HZ,
    FLOAT_RE,
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
from shipblock.units import STANDARD_GRAVITY, canonical_unit, si_factor

__all__ = ["FORMAT", "is_usc", "read_usc"]

#: Name under which the reader is registered as an obspy waveform plug-in.
FORMAT = "SHIPBLOCK_USC"

_V1_FIRST = re.compile(r"^\s*FILE\s+\d+\s+OF UNCORRECTED ACCELEROGRAM DATA OF VOLUME I\b")
_V2_FIRST = "CORRECTED ACCELEROGRAM"
_STATION = re.compile(
    r"STATION USC#\s*(\d+)\s+(\d+)\s+(\d+)\s+(\d+)\s*([NS])\s*,\s*(\d+)\s+(\d+)\s+(\d+)\s*([A-Z]?)"
)
_UNITS_V1 = re.compile(r"UNITS ARE SEC AND\s+(\S+)")
_RMS = re.compile(r"RMS ACCLN\. OF COMPLETE RECORD\s*=\s*(" + FLOAT_RE.pattern + r")\s*(\S+)")
_NPOINTS_V1 = re.compile(r"NO\. OF POINTS\s*=\s*(\d+)")
_ACC_LINE = re.compile(
    r"^\s*(\d+)\s+POINTS OF ACC\w* DATA EQUALLY SPACED AT\s+(" + FLOAT_RE.pattern
    + r")\s*SEC\.?,?\s+IN UNITS(?: OF)?\s+(\S+)"
)
_PEAK_V2 = re.compile(r"PEAK ACCELERATION\s*=\s*(" + FLOAT_RE.pattern + r")\s*(\S+)")
_SPACING_V2 = re.compile(r"AT EQUALLY-SPACED INTERVALS OF\s+(" + FLOAT_RE.pattern + r")\s*SEC")
_BEARING = re.compile(r"^([NS])\s*(\d{1,2}(?:\.\d*)?)\s*([EW])$")

_V1_TEXT, _V2_TEXT = 13, 25
#: Text width of a header line; columns 73-74 of Volume I lines hold the text's length.
_TEXT_COLUMNS = 72
_INT_LINES, _INT_COUNT, _INT_WIDTH = 7, 100, 5
_V1_REAL_LINES, _V1_REAL_COUNT = 7, 50
_V2_REAL_LINES, _V2_REAL_COUNT = 13, 100
_REAL_WIDTH = 10
#: Volume I data fields: an 8-wide time, then 7-wide values, ten fields (five pairs) a line.
_V1_FIELDS_PER_LINE = 10
_V2_PER_LINE = 8

#: Orientation codes of integer 26 other than an azimuth.
_VERTICAL_CODES = {400: True, 500: True, 600: False}  # code -> positive up
_STRUCTURE_AXES = {700: ("longitudinal", 1), 800: ("transverse", 2)}

#: Units spelled as fractions or multiples of g in USC headers [g].
_G_MULTIPLES = {"G": 1.0, "G/10": 0.1, "G*10": 10.0, "10G": 10.0, "G/100": 0.01}


def _is_v1_start(line: str) -> bool:
    return _V1_FIRST.match(line) is not None


def _is_v2_start(line: str) -> bool:
    return line.lstrip().upper().startswith(_V2_FIRST)


def is_usc(filename) -> bool:
    """Tell whether a file is a USC Volume I or II record (never raises).

    Parameters
    ----------
    filename : str, os.PathLike or file-like
        The file to check.

    Returns
    -------
    bool
        ``True`` if the file starts with ``FILE n OF UNCORRECTED ACCELEROGRAM DATA OF VOLUME I``
        (Volume I), or with ``CORRECTED ACCELEROGRAM`` followed by that line (Volume II), and
        its header names a ``STATION USC#``.
    """
    text = peek_text(filename)
    if text is None:
        return False
    try:
        lines = text.splitlines()[:_V2_TEXT]
        if not lines:
            return False
        if _is_v1_start(lines[0]):
            header = lines[:_V1_TEXT]
        elif _is_v2_start(lines[0]) and len(lines) > 1 and _is_v1_start(lines[1]):
            header = lines[1 : _V1_TEXT + 1]
        else:
            return False
        return any("STATION USC#" in line for line in header)
    except Exception:  # noqa: BLE001 - detection must never raise
        return False


def _fixed(lines, width, count, what, first_lineno, name, cast):
    """Parse ``count`` fixed-width numbers from ``lines``; raise :class:`RecordError` if bad."""
    values = []
    for offset, line in enumerate(lines):
        for field in fixed_fields(line.rstrip(), width):
            try:
                values.append(cast(field))
            except ValueError:
                raise RecordError(
                    name, f"{what}, line {first_lineno + offset}: {field.strip()!r} is not a"
                    " number"
                ) from None
    if len(values) != count:
        raise RecordError(name, f"{what} holds {len(values)} numbers, not {count}")
    return values


def _float_field(field: str) -> float:
    value = parse_float(field)
    if not math.isfinite(value):
        raise ValueError(field)
    return value


def _coordinates(header_lines, name):
    """Station latitude/longitude from the ``STATION USC#`` line (``None`` if absent)."""
    for line in header_lines:
        match = _STATION.search(line)
        if match is None:
            continue
        number, lat_d, lat_m, lat_s, lat_h, lon_d, lon_m, lon_s, lon_h = match.groups()
        lat = (int(lat_d), int(lat_m), int(lat_s))
        lon = (int(lon_d), int(lon_m), int(lon_s))
        if lat[0] > 90 or lon[0] > 180 or max(lat[1:] + lon[1:]) >= 60:
            raise RecordError(name, f"station coordinates {match.group(0)!r} are not valid")
        latitude = (lat[0] + lat[1] / 60 + lat[2] / 3600) * (-1 if lat_h == "S" else 1)
        # The network lies in Los Angeles; a longitude marked other than E (a few files print
        # "118 26 05N") is west.
        longitude = (lon[0] + lon[1] / 60 + lon[2] / 3600) * (1 if lon_h == "E" else -1)
        return number, latitude, longitude, lon_h
    return None


def _start_time(ints, name):
    """Nominal start time from integers 21-24 (month, day, year, hhmm)."""
    month, day, year, hhmm = ints[21:25]
    if year < 100:
        year += 1900
    hour, minute = divmod(hhmm, 100)
    try:
        if not (1900 <= year <= 2100 and 0 <= hour <= 23 and 0 <= minute <= 59):
            raise ValueError
        return UTCDateTime(year, month, day, hour, minute)
    except Exception:  # noqa: BLE001 - obspy raises several types for bad dates
        raise RecordError(
            name, f"header date month={month} day={day} year={year} hhmm={hhmm:04d} is not"
            " valid"
        ) from None


def _bearing(component: str):
    """Azimuth [deg] of a quadrant bearing (``N08W`` -> 352), ``"up"``/``"down"``, or ``None``."""
    token = component.replace(" ", "").upper()
    if token in ("UP", "VERT", "V"):
        return "up"
    if token in ("DOWN", "DN"):
        return "down"
    match = _BEARING.match(token)
    if match is None:
        return None
    base, angle, side = match.group(1), float(match.group(2)), match.group(3)
    if angle > 90:
        return None
    if base == "N":
        return angle if side == "E" else (360.0 - angle) % 360.0
    return 180.0 - angle if side == "E" else 180.0 + angle


def _orientation(code, component, rate, name) -> dict:
    """Channel, azimuth and dip from integer 26, checked against the ``COMP`` text."""
    text = _bearing(component) if component else None
    if code in _VERTICAL_CODES:
        if text is not None and not isinstance(text, str):
            raise RecordError(
                name, f"orientation code {code} says vertical but the text says COMP {component}"
            )
        up = _VERTICAL_CODES[code] if text is None else (text == "up")
        return orientation_stats(rate, vertical=True, positive_up=up)
    if code in _STRUCTURE_AXES:
        return orientation_stats(rate, vertical=False, index=_STRUCTURE_AXES[code][1])
    if not 0 <= code <= 360:
        raise RecordError(name, f"orientation code {code} is neither an azimuth nor a known code")
    if isinstance(text, str) or (
        text is not None and min(abs(text - code) % 360, 360 - abs(text - code) % 360) > 1.0
    ):
        raise RecordError(
            name, f"orientation code {code} deg disagrees with the text COMP {component}"
        )
    return orientation_stats(
        rate, vertical=False, azimuth_deg=float(code), index=horizontal_index(code)
    )


def _units_factor(unit: str, name: str) -> float:
    """Factor to m/s^2 of a USC unit (``G/10``, ``G``, ``CM/SEC/SEC``, ``CMS/SEC/SEC``, ...).

    Raises
    ------
    UnitsError
        If the unit is not an acceleration unit (``CM/SEC``, ``CMS`` ...).
    """
    key = unit.strip().upper().rstrip(".")
    if key in _G_MULTIPLES:
        return _G_MULTIPLES[key] * STANDARD_GRAVITY
    return si_factor(re.sub(r"^CMS/", "CM/", key).lower(), name)


def _component(header_lines) -> str:
    """The ``COMP`` text (columns 73 onwards hold a line length, not text)."""
    for line in header_lines:
        if line.startswith("COMP "):
            return line[5:_TEXT_COLUMNS].strip()
    return ""


def _v1_pairs(lines, start, npairs, name):
    """Parse the (time, value) pairs of a Volume I block; return them and the next line index."""
    nvalues = 2 * npairs
    nlines = -(-nvalues // _V1_FIELDS_PER_LINE)
    block = lines[start : start + nlines]
    if len(block) < nlines:
        raise RecordError(
            name, f"is truncated: {npairs} digitized points stated, the file ends after"
            f" {len(block)} of their {nlines} lines"
        )
    values = []
    for offset, line in enumerate(block):
        line = line.rstrip()
        fields = [line[:8]] + fixed_fields(line[8:], 7)
        for field in fields:
            try:
                values.append(_float_field(field))
            except ValueError:
                raise RecordError(
                    name, f"data line {start + offset + 1}: {field.strip()!r} is not a number"
                ) from None
    if len(values) != nvalues:
        raise RecordError(
            name, f"{npairs} digitized points stated but {len(values) // 2} found in"
            f" {nlines} data lines"
        )
    data = np.asarray(values, dtype=np.float64)
    return data[0::2], data[1::2], start + nlines


def _read_v1(lines, start, name, resample_rate, headonly):
    """Read one Volume I channel starting at line ``start``; return the trace and next line."""
    text = lines[start : start + _V1_TEXT]
    ints_at = start + _V1_TEXT
    reals_at = ints_at + _INT_LINES
    data_at = reals_at + _V1_REAL_LINES
    if len(lines) < data_at:
        raise RecordError(name, "is truncated inside the Volume I header")
    ints = _fixed(lines[ints_at:reals_at], _INT_WIDTH, _INT_COUNT, "integer header",
                  ints_at + 1, name, int)
    reals = _fixed(lines[reals_at:data_at], _REAL_WIDTH, _V1_REAL_COUNT, "real header",
                   reals_at + 1, name, _float_field)
    npairs = ints[27]
    stated = _NPOINTS_V1.search("\n".join(text))
    if npairs <= 1 or (stated is not None and int(stated.group(1)) != npairs):
        raise RecordError(
            name, f"point count {npairs} (integer 28) is invalid or disagrees with the text"
            f" {stated.group(0) if stated else ''!r}"
        )
    unit_match = _UNITS_V1.search("\n".join(text))
    fraction = reals[4]
    if unit_match is not None:
        unit = unit_match.group(1).rstrip(".")
        factor = _units_factor(unit, name)
        if unit.upper() in _G_MULTIPLES and fraction > 0 and not math.isclose(
                fraction, _G_MULTIPLES[unit.upper()], rel_tol=1e-3):
            raise UnitsError(
                name, f"text says units {unit} but real 5 gives {fraction:g} g per unit"
            )
    elif fraction > 0:
        unit, factor = f"{fraction:g} g", fraction * STANDARD_GRAVITY
    else:
        raise UnitsError(name, "states no unit (no 'UNITS ARE SEC AND ...' line, real 5 is 0)")
    times, values, end = _v1_pairs(lines, data_at, npairs, name)
    check_samples(values, name, "the digitized acceleration")
    samples, first_time, merged = resample_pairs(times, values, resample_rate, name)
    header = _header(text, ints, "I")
    rms = _RMS.search("\n".join(text))
    header.update(
        dict(
            unit=unit,
            npts_digitized=npairs,
            duration_s=reals[2],
            resample_rate_hz=resample_rate,
            first_digitized_time_s=first_time,
            merged_repeated_times=merged,
            digitized_peak_si=float(np.max(np.abs(values))) * factor,
            stated_rms_si=parse_float(rms.group(1)) * factor if rms else None,
        )
    )
    trace = _trace(samples, 1.0 / resample_rate, factor, unit, header, ints, text, name, headonly)
    trace.stats.starttime += first_time
    return trace, end


def _read_v2(lines, start, name, headonly):
    """Read one Volume II channel (acceleration block); return the trace and the next line."""
    text = lines[start : start + _V2_TEXT]
    ints_at = start + _V2_TEXT
    reals_at = ints_at + _INT_LINES
    acc_at = reals_at + _V2_REAL_LINES
    if len(lines) <= acc_at:
        raise RecordError(name, "is truncated inside the Volume II header")
    ints = _fixed(lines[ints_at:reals_at], _INT_WIDTH, _INT_COUNT, "integer header",
                  ints_at + 1, name, int)
    _fixed(lines[reals_at:acc_at], _REAL_WIDTH, _V2_REAL_COUNT, "real header", reals_at + 1,
           name, _float_field)
    match = _ACC_LINE.match(lines[acc_at])
    if match is None:
        raise RecordError(
            name, f"line {acc_at + 1} is not the 'n POINTS OF ACC DATA EQUALLY SPACED AT dt SEC."
            " IN UNITS ...' line"
        )
    npts, dt, unit = int(match.group(1)), parse_float(match.group(2)), match.group(3).rstrip(".")
    delta = check_sampling_interval(dt, name)
    factor = _units_factor(unit, name)
    if npts <= 0:
        raise RecordError(name, f"acceleration block states {npts} points")
    nlines = -(-npts // _V2_PER_LINE)
    block = lines[acc_at + 1 : acc_at + 1 + nlines]
    if len(block) < nlines:
        raise RecordError(name, f"is truncated: {npts} acceleration samples stated, the file"
                                f" ends after {len(block)} of their {nlines} lines")
    values = []
    for offset, line in enumerate(block):
        for field in fixed_fields(line.rstrip(), _REAL_WIDTH):
            try:
                values.append(_float_field(field))
            except ValueError:
                raise RecordError(
                    name, f"data line {acc_at + 2 + offset}: {field.strip()!r} is not a number"
                ) from None
    if len(values) != npts:
        raise RecordError(name, f"{npts} acceleration samples stated but {len(values)} found in"
                                f" {nlines} lines")
    samples = np.asarray(values, dtype=np.float64)
    check_samples(samples, name, "the acceleration record")
    header = _header(text[1:], ints, "II")
    header["title"] = text[0][:_TEXT_COLUMNS].strip()
    joined = "\n".join(text)
    spacing = _SPACING_V2.search(joined)
    if spacing is not None and not math.isclose(parse_float(spacing.group(1)), dt, rel_tol=1e-6):
        raise RecordError(name, f"text says samples {spacing.group(0).strip()!r} but the"
                                f" acceleration block says {dt:g} s")
    peak = _PEAK_V2.search(joined)
    header.update(dict(unit=unit, npts=npts, dt=dt, processing=" ".join(
        line.strip() for line in text[_V1_TEXT + 1 : _V1_TEXT + 4])))
    trace = _trace(samples, delta, factor, unit, header, ints, text[1:], name, headonly)
    if peak is not None:
        signed = parse_float(peak.group(1)) * _units_factor(peak.group(2), name)
        trace.stats.stated_peak_si = abs(signed)
        if not headonly:
            # The real file's samples are the negative of its stated peaks (see module notes);
            # the samples are kept as stored and the disagreement is reported.
            extreme = float(trace.data[int(np.argmax(np.abs(trace.data)))])
            header["stated_peak_sign_matches_samples"] = bool(np.sign(extreme) == np.sign(signed))
    # Velocity and displacement blocks follow; the next channel (if any) starts with its title.
    end = acc_at + 1 + nlines
    while end < len(lines) and not _is_v2_start(lines[end]):
        end += 1
    return trace, end


def _header(text, ints, volume) -> AttribDict:
    """The header fields common to both volumes (``text`` is the Volume I text header)."""
    return AttribDict(
        volume=volume,
        title=text[0][:_TEXT_COLUMNS].strip(),
        event=text[1][:_TEXT_COLUMNS].strip() if len(text) > 1 else "",
        record_id=text[3][:_TEXT_COLUMNS].strip() if len(text) > 3 else "",
        station_name=text[5][:_TEXT_COLUMNS].strip() if len(text) > 5 else "",
        component=_component(text),
        orientation_code=ints[26],
        station_number=ints[8],
        start_time_nominal=True,
    )


def _trace(samples, delta, factor, unit, header, ints, text, name, headonly):
    """Build the trace of one channel."""
    rate = 1.0 / delta
    found = _coordinates(text, name)
    stats = {
        "network": "LA",
        "station": str(ints[8]),
        "location": "",
        "units": "m/s**2",
        "original_units": canonical_unit(unit.replace("CMS/", "CM/")) or unit.lower(),
        "shipblock_usc": header,
        **_orientation(ints[26], header["component"], rate, name),
    }
    if found is not None:
        header["longitude_hemisphere_text"] = found[3]
        stats["coordinates"] = AttribDict(latitude=found[1], longitude=found[2], elevation=0.0)
    trace = make_trace([] if headonly else samples, delta, stats)
    if headonly:
        trace.stats.npts = len(samples)
    else:
        trace.data *= factor
        check_plausible_samples(trace.data, name, f"channel {trace.stats.channel}")
    trace.stats.starttime = _start_time(ints, name)
    return trace


def read_usc(filename, headonly: bool = False, resample_rate: float | None = None,
             **kwargs) -> Stream:
    """Read a USC Volume I or II file into a Stream of acceleration traces in m/s^2.

    Parameters
    ----------
    filename : str, os.PathLike or file-like
        The USC file.
    headonly : bool, optional
        Return traces without samples (``stats.npts`` still set).
    resample_rate : float, optional
        Sampling rate [samples/s] onto which Volume I's uneven digitized points are linearly
        interpolated; by default :data:`~shipblock.io._common.DEFAULT_RESAMPLE_RATE_HZ` (200).
        Volume II is evenly sampled and returned as stored, so the option is refused for a file
        without a Volume I channel (a :class:`RecordError`) rather than ignored.
    **kwargs
        Ignored (obspy passes its own keywords to every plug-in).

    Returns
    -------
    obspy.Stream
        One trace a channel: network ``LA``, station the USC station number, channel, azimuth and
        dip from the orientation code, ``stats.original_units`` the file's unit (``G/10`` for
        Volume I, ``CM/SEC/SEC`` for Volume II), ``stats.stated_peak_si`` [m/s^2] for Volume II,
        ``stats.coordinates`` and the header in ``stats.shipblock_usc``.

    Raises
    ------
    RecordError
        If the file is not a USC Volume I/II, a header is broken, the data are truncated or longer
        than stated, digitized times go backwards, samples are not finite, or ``resample_rate``
        is given for a file of Volume II channels only.
    UnitsError
        If the unit is missing, unknown or contradicted by the header.
    """
    name = source_name(filename)
    lines = read_text(filename).splitlines()
    if not lines:
        raise RecordError(name, "is empty")
    first = lines[0].lstrip().upper()
    if first.startswith("RESPONSE"):
        raise RecordError(name, "is a USC Volume III (response spectra), not a time series")
    traces = []
    index = 0
    rate = DEFAULT_RESAMPLE_RATE_HZ if resample_rate is None else resample_rate
    while index < len(lines):
        line = lines[index]
        if not line.strip():
            index += 1
            continue
        if _is_v2_start(line) and index + 1 < len(lines) and _is_v1_start(lines[index + 1]):
            trace, index = _read_v2(lines, index, name, headonly)
        elif _is_v1_start(line):
            trace, index = _read_v1(lines, index, name, rate, headonly)
        else:
            where = "does not start" if not traces else f"line {index + 1} does not start"
            raise RecordError(
                name, f"{where} a USC Volume I or II channel ({line.strip()[:40]!r})"
            )
        traces.append(trace)
    rates = sorted({f"{trace.stats.sampling_rate:g}" for trace in traces})
    check_resampling_applies(
        name, "resample_rate", resample_rate,
        any(trace.stats.shipblock_usc.volume == "I" for trace in traces),
        f"a Volume II, evenly sampled at {' and '.join(rates)} samples/s")
    return Stream(traces)
