"""Reader for GeoNet (GNS Science, New Zealand) ``.V1A``/``.V2A`` records (plug-in ``SHIPBLOCK_GEONET``).

GeoNet distributes its strong-motion accelerograms in the GNS block format [1]_ [2]_: ``.V1A``
files hold the uncorrected record, ``.V2A`` files the corrected one. A file holds three
orthogonal components, one after the other; each component is a block of

A. 16 text lines (line 1 ``Uncorrected accelerogram <id> GNS Science`` or ``Corrected
   accelerogram <id> ...``; line 2 ``Site <code> ...``; the ``Component`` line, e.g. ``N28W``,
   ``S90E`` or ``Up``; the ``Acceleration: peak <value> mm/s/s at <time>`` line);
B. 40 integers, 4 lines of Fortran ``10I8``;
C. 60 reals, 6 lines of Fortran ``10F8.0``;
D. the accelerations, 10 per line in ``F8`` fields, then (``.V2A`` only) as many lines of
   velocities [mm/s] and of displacements [mm], which this reader skips.

Header values used (1-based positions of [1]_): integers 9, 10, 19, 20, 39, 40 (buffer start
time: year, month, day, hour, minute, seconds x 1000, UT), 21-26 (site latitude S and longitude
E, degrees-minutes-seconds), 28 (component direction, deg east of north), 34-36 (numbers of
acceleration, velocity and displacement samples); reals 22 (the time [s] prepended to a
corrected record) and 26 (the sampling interval of the accelerations [s]).

What the real files (the gmprocess test corpus) showed beyond the format description:

* the accelerations are in mm/s^2 (the documented unit; ``.V1A`` files say ``Raw readings in
  units of 1.00 mm/s/s``, which this reader honours, scale included);
* a ``.V2A`` record starts *before* the buffer start time by the prepended duration (real 22,
  5 s in the corpus): the stated time of the peak (``at 44.88 sec``) is counted from the buffer
  start, and the largest sample is 5 s later in the series. ``stats.starttime`` is therefore the
  buffer start minus the prepended time; a ``.V1A`` record starts at the buffer start;
* the seconds of the buffer start carry milliseconds (``19715`` = 19.715 s);
* in the velocity and displacement sections, ``F8`` fields touch (``0.00000-0.00000``), so fields
  are cut by column, never split on blanks;
* the record identifier ends in the SEED location code (``20161113_110256_WTMC_20`` -> ``20``;
  ``..._INHS_21`` -> ``21``), as in GeoNet's station metadata where the strong-motion sensors are
  at locations 20, 21, ...;
* the vertical is ``Up`` (positive up); its integer 28 is 0, so the azimuth comes from the text.

Samples are converted to m/s^2 (``stats.units == "m/s**2"``, ``stats.original_units`` the
file's unit). Each trace gets ``stats.stated_peak_si`` (the file's own peak, m/s^2) and the parsed
header in ``stats.shipblock_geonet``. The channel is named from the sampling rate and the
orientation (``HN1``/``HN2`` for horizontals off north/east, ``BN?`` for 50 Hz corrected records).

References
----------
.. [1] GeoNet, "Strong motion file formats: accelerogram data filenames and formats",
   https://www.geonet.org.nz/data/supplementary/strong_motion_file_formats (accessed 2024).
.. [2] Cousins, W. J. (2008). GNS accelerogram data files, standard format. GNS Science.
"""

from __future__ import annotations

import math
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
    peek_text,
    read_text,
    source_name,
    utc_time,
)
from shipblock.units import canonical_unit, si_factor

__all__ = ["FORMAT", "is_geonet", "read_geonet"]

#: Name under which the reader is registered as an obspy waveform plug-in.
FORMAT = "SHIPBLOCK_GEONET"

#: SEED network code of GeoNet.
NETWORK = "NZ"

#: Components a GeoNet file holds.
COMPONENTS_PER_FILE = 3

TEXT_LINES = 16
INT_LINES = 4
REAL_LINES = 6
#: Values per line and the width [characters] of every field (Fortran 10I8, 10F8.0, 10F8.x).
VALUES_PER_LINE = 10
FIELD_WIDTH = 8

#: Unit of the samples when the block does not state one (the format's documented unit).
DEFAULT_UNIT = "mm/s/s"

#: Tolerance [s] between the header's sampling interval and the one printed in the text lines
#: (printed with three decimals).
TEXT_DELTA_TOLERANCE_S = 6e-4

# 0-based positions in the integer and real headers (the documentation counts from 1).
_I_BUFFER_YEAR, _I_BUFFER_MONTH, _I_BUFFER_DAY, _I_BUFFER_HOUR = 8, 9, 18, 19
_I_BUFFER_MINUTE, _I_BUFFER_MILLISECONDS = 38, 39
_I_SITE_LAT, _I_SITE_LON = 20, 23
_I_COMPONENT_DIRECTION = 27
_I_N_ACC, _I_N_VEL, _I_N_DIS = 33, 34, 35
_R_PREPENDED_S, _R_DELTA_S, _R_GRAVITY = 21, 25, 29

_TITLE_RE = re.compile(r"^\s*(un)?corrected\s+accelerogram\s+(\S+)", re.IGNORECASE)
_SITE_RE = re.compile(r"^\s*Site\s+(\S+)", re.IGNORECASE)
_COMPONENT_RE = re.compile(r"^\s*Component\s+(\S+)(.*)$", re.IGNORECASE)
_BEARING_RE = re.compile(r"^([NS])(\d+(?:\.\d*)?)([EW])$", re.IGNORECASE)
_NPOINTS_RE = re.compile(r"Number\s+of\s+points\s+(\d+)", re.IGNORECASE)
_RAW_UNITS_RE = re.compile(
    r"units\s+of\s+(" + FLOAT_RE.pattern + r")\s+(\S+)", re.IGNORECASE
)
_TEXT_DELTA_RE = re.compile(
    r"(?:intervals\s+of|data\s+at)\s+(" + FLOAT_RE.pattern + r")\s*s", re.IGNORECASE
)
_PEAK_RE = re.compile(
    r"^\s*Acceleration:\s+peak\s+(" + FLOAT_RE.pattern + r")\s+(\S+)\s+at\s+("
    + FLOAT_RE.pattern + ")",
    re.IGNORECASE,
)
_CARDINAL_AZIMUTH_DEG = {"N": 0.0, "E": 90.0, "S": 180.0, "W": 270.0}
_UP = {"UP", "U", "Z", "VERT", "VERTICAL"}
_DOWN = {"DOWN", "DN", "DWN", "D"}


def _fixed_fields(line: str, count: int):
    """Cut a line into ``count`` fields of :data:`FIELD_WIDTH`; ``None`` if it holds more."""
    line = line.rstrip()
    if len(line) > count * FIELD_WIDTH:
        return None
    return fixed_fields(line, FIELD_WIDTH, count)


def _header_numbers(lines, kind):
    """Parse header lines of 10 fixed-width numbers; return a list, or ``None`` if malformed.

    An all-blank field is 0, as in Fortran formatted ``I8``/``F8.0`` input.
    """
    convert = int if kind == "int" else float
    values = []
    for line in lines:
        fields = _fixed_fields(line, VALUES_PER_LINE)
        if fields is None:
            return None
        for field in fields:
            field = field.strip()
            try:
                values.append(convert(field) if field else convert(0))
            except ValueError:
                return None
    return values


def _looks_like_block(lines, start: int) -> bool:
    """Whether a component block (title, site line, 4 integer and 6 real lines) starts here."""
    end = start + TEXT_LINES + INT_LINES + REAL_LINES
    if len(lines) < end or _TITLE_RE.match(lines[start]) is None:
        return False
    if _SITE_RE.match(lines[start + 1]) is None:
        return False
    ints = _header_numbers(lines[start + TEXT_LINES:start + TEXT_LINES + INT_LINES], "int")
    reals = _header_numbers(lines[start + TEXT_LINES + INT_LINES:end], "real")
    return ints is not None and reals is not None


def is_geonet(filename) -> bool:
    """Tell whether a file is a GeoNet ``.V1A``/``.V2A`` accelerogram (never raises).

    Parameters
    ----------
    filename : str, os.PathLike or file-like
        The file to check.

    Returns
    -------
    bool
        ``True`` if the file starts with a GNS component block: an ``(Un)corrected accelerogram``
        title, a ``Site`` line, and after 16 text lines four lines of ``10I8`` integers and six
        of ``10F8.0`` reals.
    """
    text = peek_text(filename)
    if text is None:
        return False
    try:
        return _looks_like_block(text.splitlines(), 0)
    except Exception:  # noqa: BLE001 - detection must never raise
        return False


def _azimuth(component: str):
    """Return ``(vertical, positive_up, azimuth_deg)`` of a component token, or ``None``."""
    token = component.strip().upper()
    if token in _UP:
        return True, True, None
    if token in _DOWN:
        return True, False, None
    if token in _CARDINAL_AZIMUTH_DEG:
        return False, True, _CARDINAL_AZIMUTH_DEG[token]
    match = _BEARING_RE.match(token)
    if match is None:
        return None
    start, angle, end = match.group(1), float(match.group(2)), match.group(3)
    if angle > 90.0:
        return None
    # N28W = 28 deg from north towards west; S62W = 62 deg from south towards west.
    base = 0.0 if start == "N" else 180.0
    sign = 1.0 if (start == "N") == (end == "E") else -1.0
    return False, True, (base + sign * angle) % 360.0


def _start_time(ints, name: str, what: str) -> UTCDateTime:
    """Buffer start time (UT) from the integer header."""
    start = utc_time(
        ints[_I_BUFFER_YEAR], ints[_I_BUFFER_MONTH], ints[_I_BUFFER_DAY],
        ints[_I_BUFFER_HOUR], ints[_I_BUFFER_MINUTE],
    )
    if start is None:
        raise RecordError(
            name,
            f"{what}: the buffer start time in the integer header "
            f"({ints[_I_BUFFER_YEAR]}-{ints[_I_BUFFER_MONTH]}-{ints[_I_BUFFER_DAY]} "
            f"{ints[_I_BUFFER_HOUR]}:{ints[_I_BUFFER_MINUTE]}) is not a valid date",
        )
    milliseconds = ints[_I_BUFFER_MILLISECONDS]
    if not 0 <= milliseconds < 61000:
        raise RecordError(
            name, f"{what}: buffer start seconds x 1000 = {milliseconds} is out of range"
        )
    return start + milliseconds / 1000.0


def _dms(values, name: str, what: str) -> float:
    """Degrees from degrees, minutes, seconds."""
    degrees, minutes, seconds = values
    if not (0 <= minutes < 60 and 0 <= seconds < 60 and 0 <= degrees <= 180):
        raise RecordError(name, f"{what}: site coordinate {degrees} {minutes} {seconds} is invalid")
    return degrees + minutes / 60.0 + seconds / 3600.0


def _parse_samples(lines, start: int, count: int, name: str, what: str) -> np.ndarray:
    """Parse ``count`` samples, 10 per line in 8-character fields, from ``lines[start:]``."""
    values = np.empty(count, dtype=np.float64)
    done = 0
    for offset in range((count + VALUES_PER_LINE - 1) // VALUES_PER_LINE):
        lineno = start + offset
        expected = min(VALUES_PER_LINE, count - done)
        line = lines[lineno].rstrip()
        # Fortran F8 fields are right-aligned: a row of n values is exactly 8n characters long,
        # so a lost or added character (fields shifted) is caught here.
        if len(line) != expected * FIELD_WIDTH:
            raise RecordError(
                name,
                f"{what}: line {lineno + 1} is {len(line)} characters long; {expected} values "
                f"of {FIELD_WIDTH} characters were expected",
            )
        fields = _fixed_fields(line, expected)
        for field in fields:
            try:
                values[done] = float(field)
            except ValueError:
                raise RecordError(
                    name,
                    f"{what}: line {lineno + 1}: {field.strip() or 'a blank field'!r} is not a "
                    "number",
                ) from None
            done += 1
    return values


def _block(lines, start: int, name: str, number: int, horizontal_index: int, headonly: bool):
    """Read one component block; return ``(trace, index of the line after the block)``.

    ``horizontal_index`` (1 or 2) names a horizontal that is not along north or east.
    """
    what = f"component {number}"
    if not _looks_like_block(lines, start):
        if start >= len(lines) or not lines[start].strip():
            raise RecordError(
                name, f"is truncated: component {number} of {COMPONENTS_PER_FILE} is missing"
            )
        raise RecordError(
            name,
            f"{what} (line {start + 1}) does not start with a GNS header block (an "
            "'(Un)corrected accelerogram' title, a 'Site' line, 4 lines of 10I8 integers and 6 "
            "lines of 10F8.0 reals); the file is damaged or a line count is wrong",
        )
    text = lines[start:start + TEXT_LINES]
    ints = _header_numbers(lines[start + TEXT_LINES:start + TEXT_LINES + INT_LINES], "int")
    reals = _header_numbers(
        lines[start + TEXT_LINES + INT_LINES:start + TEXT_LINES + INT_LINES + REAL_LINES], "real"
    )
    title = _TITLE_RE.match(text[0])
    corrected = title.group(1) is None
    record_id = title.group(2)
    station = _SITE_RE.match(text[1]).group(1)
    id_parts = record_id.split("_")
    location = id_parts[-1] if len(id_parts) >= 4 and re.fullmatch(r"\d\d", id_parts[-1]) else ""

    component_line = next((ln for ln in text if _COMPONENT_RE.match(ln)), None)
    if component_line is None:
        raise RecordError(name, f"{what}: no 'Component' line in the text header")
    component_match = _COMPONENT_RE.match(component_line)
    component = component_match.group(1)
    orientation = _azimuth(component)
    if orientation is None:
        raise RecordError(name, f"{what}: component {component!r} is not a direction or Up/Down")
    vertical, positive_up, azimuth = orientation

    npts = ints[_I_N_ACC]
    if npts <= 0:
        raise RecordError(name, f"{what}: the number of acceleration samples is {npts}")
    stated_points = next((m for m in map(_NPOINTS_RE.search, text) if m), None)
    if stated_points is not None and int(stated_points.group(1)) != npts:
        raise RecordError(
            name,
            f"{what}: the text says {stated_points.group(1)} points but the integer header says "
            f"{npts} acceleration samples",
        )
    delta = check_sampling_interval(reals[_R_DELTA_S], name, f"{what}: sampling interval")
    stated_delta = next((m for m in map(_TEXT_DELTA_RE.search, text) if m), None)
    if stated_delta is not None and abs(float(stated_delta.group(1)) - delta) > TEXT_DELTA_TOLERANCE_S:
        raise RecordError(
            name,
            f"{what}: the text says samples every {stated_delta.group(1)} s but the real header "
            f"says {delta} s",
        )

    # Unit: V1A 'Raw readings in units of 1.00 mm/s/s' (a scale and a unit); else the unit of
    # the stated peak; else the format's documented mm/s^2.
    raw_units = next((m for m in map(_RAW_UNITS_RE.search, text) if m), None)
    peak = next((m for m in map(_PEAK_RE.match, text) if m), None)
    scale = 1.0
    if raw_units is not None:
        unit = raw_units.group(2)
        scale = float(raw_units.group(1))
        if not (math.isfinite(scale) and scale > 0):
            raise UnitsError(name, f"{what}: raw readings in units of {raw_units.group(1)} {unit}")
    elif peak is not None and canonical_unit(peak.group(2)) is not None:
        unit = peak.group(2)
    else:
        unit = DEFAULT_UNIT
    factor = si_factor(unit, name) * scale

    prepended = reals[_R_PREPENDED_S] if corrected else 0.0
    if not (math.isfinite(prepended) and 0.0 <= prepended < npts * delta):
        raise RecordError(name, f"{what}: prepended time {prepended!r} s is invalid")
    buffer_start = _start_time(ints, name, what)
    latitude = -_dms(ints[_I_SITE_LAT:_I_SITE_LAT + 3], name, what)
    longitude = _dms(ints[_I_SITE_LON:_I_SITE_LON + 3], name, what)

    n_rows = (npts + VALUES_PER_LINE - 1) // VALUES_PER_LINE
    data_start = start + TEXT_LINES + INT_LINES + REAL_LINES
    end = data_start + n_rows
    if corrected:
        for extra, label in ((ints[_I_N_VEL], "velocity"), (ints[_I_N_DIS], "displacement")):
            if extra < 0:
                raise RecordError(name, f"{what}: the number of {label} samples is {extra}")
            end += (extra + VALUES_PER_LINE - 1) // VALUES_PER_LINE
    if end > len(lines):
        raise RecordError(
            name,
            f"is truncated: {what} needs {end - data_start} data lines after line {data_start} "
            f"but the file ends at line {len(lines)}",
        )

    header = AttribDict(
        record_id=record_id,
        processing="corrected" if corrected else "uncorrected",
        site_name=text[2].strip(),
        instrument=text[3].split()[1] if len(text[3].split()) > 1 else "",
        component=component,
        component_note=component_match.group(2).strip(),
        component_direction_deg=ints[_I_COMPONENT_DIRECTION],
        buffer_start=str(buffer_start),
        prepended_s=prepended,
        gravity_in_file_units=reals[_R_GRAVITY],
        unit=unit,
        unit_scale=scale,
    )
    stats = {
        "network": NETWORK,
        "station": station,
        "location": location,
        "units": "m/s**2",
        "original_units": unit,
        "coordinates": AttribDict(latitude=latitude, longitude=longitude, elevation=0.0),
        "shipblock_geonet": header,
    }
    stats.update(orientation_stats(
        1.0 / delta, vertical=vertical, azimuth_deg=azimuth, positive_up=positive_up,
        index=horizontal_index,
    ))
    if peak is not None:
        peak_unit = canonical_unit(peak.group(2))
        if peak_unit is not None:
            stats["stated_peak_si"] = abs(float(peak.group(1))) * si_factor(peak_unit, name)
            header["stated_peak"] = float(peak.group(1))
            header["stated_peak_time_s"] = float(peak.group(3))

    if headonly:
        trace = make_trace([], delta, stats)
        trace.stats.npts = npts
    else:
        samples = _parse_samples(lines, data_start, npts, name, what)
        check_samples(samples, name, what)
        trace = make_trace(samples * factor, delta, stats)
        check_plausible_samples(trace.data, name, what)
    trace.stats.starttime = buffer_start - prepended
    return trace, end


def read_geonet(filename, headonly: bool = False, **kwargs) -> Stream:
    """Read a GeoNet ``.V1A`` or ``.V2A`` file into a Stream of three traces in m/s^2.

    Parameters
    ----------
    filename : str, os.PathLike or file-like
        The GeoNet file.
    headonly : bool, optional
        Read only the headers; the traces then have no samples.
    **kwargs
        Ignored (obspy passes its own keywords to every plug-in).

    Returns
    -------
    obspy.Stream
        Three traces (the file's order); ``stats.units == "m/s**2"``, ``stats.original_units``
        the file's unit, network ``NZ``, the location code from the record identifier, the
        channel from ``orientation_stats``, ``stats.starttime`` the first sample (UT),
        ``stats.coordinates``, ``stats.stated_peak_si`` and ``stats.shipblock_geonet``.

    Raises
    ------
    RecordError
        If a header block is malformed, counts disagree, the file is truncated or carries extra
        lines, or a sample is not a finite number.
    UnitsError
        If a block states a unit that is not an acceleration.
    """
    name = source_name(filename)
    lines = read_text(filename).splitlines()
    if not lines or _TITLE_RE.match(lines[0]) is None:
        raise RecordError(
            name, "is not a GeoNet V1A/V2A file (no '(Un)corrected accelerogram' first line)"
        )
    traces = []
    start = 0
    for number in range(1, COMPONENTS_PER_FILE + 1):
        horizontals = sum(abs(tr.stats.dip) < 45.0 for tr in traces)
        trace, start = _block(lines, start, name, number, min(horizontals + 1, 2), headonly)
        traces.append(trace)
    levels = {tr.stats.shipblock_geonet.processing for tr in traces}
    if len(levels) != 1:
        raise RecordError(name, "mixes corrected and uncorrected component blocks")
    leftover = next((i for i in range(start, len(lines)) if lines[i].strip()), None)
    if leftover is not None:
        raise RecordError(
            name,
            f"has unexpected content after the third component (line {leftover + 1}); a line "
            "count in a header is wrong or lines were added",
        )
    return Stream(traces)
