"""Reader for Iranian BHRC Volume 1 records (obspy waveform plug-in ``SHIPBLOCK_BHRC``).

The Iran Strong Motion Network of the Building and Housing Research Center (BHRC, now the Road,
Housing and Urban Development Research Center) distributes its records as ``*.V1`` text files [1]_.
No published description of the layout was used: what follows was read from the six files of the
USGS gmprocess test corpus (event usp000jq5p, 2012-08-11 Ahar-Varzaghan earthquake, SSA-2
recorders). A file holds one block per channel (three: ``L``, ``V``, ``T``), each made of

1. 13 text lines: ``* VOL1DS FILE:  5520/01`` (volume and record number), ``Inst Type = SSA-2``,
   ``Origin Time : 2012/08/11   12:23:16`` (the earthquake's origin time, not the record's start),
   a blank line, the component letter (``L``, ``V`` or ``T``), a blank line, ``COMP L1``, the
   station line ``Ahar  Station   38.474 N 47.059 E   Altitude 1360m   Azimuth L 352   T 82``,
   the epicentre line, ``INSTR PERIOD =  .019 SEC   DAMPING =  .640``,
   ``NO. OF POINTS =  15616      DURATION =  78.080``, ``UNITS ARE SECONDS AND G/10`` and a blank
   line;
2. 7 lines of integers (``14I5``, 88 values; Int(26), 1-based, repeats the number of points);
3. 7 lines of reals (``6E13.6``, the lines cut at column 70, so every sixth value is lost): Real(1)
   the instrument period [s] to more digits, Real(2) the damping, Real(3) the duration [s] and
   Real(7) the sampling rate [samples/s] (200 in every file);
4. the samples, ``10E13.6`` per line, then a line ``/&`` that closes the channel.

What the real files showed, and what this reader makes of it:

* **Sampling interval.** In every channel ``DURATION`` equals ``NO. OF POINTS`` / Real(7) exactly
  (15616 / 200 = 78.080 s), so the interval is 1/Real(7) = 0.005 s, and ``DURATION`` is
  npts x dt. gmprocess 2.8 takes dt = DURATION / (npts - 1) (0.005000320 s for 15616 points),
  which stretches the time axis by 1/(npts - 1); this reader uses the stated rate. If Real(7) is
  missing (zero), dt = DURATION / npts. A header whose rate and duration disagree by more than one
  sample is refused.
* **Start time.** The files state no record start time; ``Origin Time`` is the earthquake's
  (about 2 s before the USGS origin time, 12:23:18 UTC, so it is UTC). It is kept in
  ``stats.shipblock_bhrc.origin_time`` and ``stats.starttime`` stays obspy's default (the epoch,
  1970-01-01), which here means "not stated" (``stats.shipblock_bhrc.start_time_stated`` is
  ``False``).
* **Units.** ``G/10``: samples times g/10 give m/s^2 (0.980665 m/s^2 per unit). The samples move
  in whole multiples of one step per channel, 0.00488 to 0.00490 g/10 (about 2 g / 4096): they
  are the SSA-2's 12-bit counts times each channel's calibration, with no other processing.
* **Orientation.** ``Azimuth L 352   T 82``: the longitudinal component points at 352 deg and the
  transverse at 82 deg, clockwise from north; T = L + 90 deg in every file. ``V`` is taken as
  positive up (the file does not say). L gets channel index 1, T index 2 (``HN1``/``HN2`` unless
  the azimuth is within 1 deg of north or east).
* **Codes.** The file states no network or station code. The network is ``I1`` (the label
  gmprocess gives BHRC records); the station code is the record number of the ``FILE:`` field
  (``5520``), the station's name (``Ahar``) is in ``stats.shipblock_bhrc.station_name``.
* The files state no peak values.

References
----------
.. [1] Road, Housing and Urban Development Research Center, Iran Strong Motion Network,
   https://smd.bhrc.ac.ir.
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
    check_delta,
    check_plausible_samples,
    check_samples,
    check_sampling_interval,
    fixed_fields,
    make_trace,
    orientation_stats,
    parse_float,
    peek_text,
    read_text,
    source_name,
    utc_time,
)
from shipblock.units import STANDARD_GRAVITY, si_factor

__all__ = ["FORMAT", "is_bhrc", "read_bhrc"]

#: Name under which the reader is registered as an obspy waveform plug-in.
FORMAT = "SHIPBLOCK_BHRC"

#: Network code given to BHRC records (gmprocess's label; the files state none).
NETWORK = "I1"

#: Lines of each channel block's text, integer and real headers.
TEXT_LINES = 13
INT_LINES = 7
REAL_LINES = 7

#: Field widths of the integer header (I5), the real header (E13.6) and the samples (E13.6).
INT_WIDTH = 5
REAL_WIDTH = 13
REALS_PER_LINE = 6
SAMPLE_WIDTH = 13

#: 0-based positions of the number of points in the integer header and of the sampling rate
#: [samples/s] and duration [s] in the real header.
INT_NPTS = 25
REAL_DURATION_S = 2
REAL_RATE_HZ = 6

#: Line that closes each channel's samples.
END_MARKER = "/&"

#: m/s^2 per unit of ``G/10``.
G_OVER_10_SI = STANDARD_GRAVITY / 10.0

#: Printed precision of ``DURATION`` [s] (three decimals), for the consistency check.
DURATION_PRINT_STEP_S = 0.001

_VOLUME_RE = re.compile(r"^\*\s*(VOL\w*)\s+FILE\s*:\s*(\S+)")
_STATION_RE = re.compile(
    r"^(?P<name>.*?)\s*Station\s+(?P<lat>" + FLOAT_RE.pattern + r")\s*(?P<ns>[NS])\s+"
    r"(?P<lon>" + FLOAT_RE.pattern + r")\s*(?P<ew>[EW])"
    r"(?:\s+Altitude\s+(?P<alt>" + FLOAT_RE.pattern + r")\s*m)?"
    r"(?:\s+Azimuth\s+L\s+(?P<l>" + FLOAT_RE.pattern + r")\s+T\s+(?P<t>" + FLOAT_RE.pattern
    + r"))?",
    re.IGNORECASE,
)
_NPTS_RE = re.compile(
    r"NO\.?\s*OF\s*POINTS\s*=\s*(\d+)\s+DURATION\s*=\s*(" + FLOAT_RE.pattern + ")", re.IGNORECASE
)
_PERIOD_RE = re.compile(
    r"INSTR\s+PERIOD\s*=\s*(" + FLOAT_RE.pattern + r")\s*SEC\s+DAMPING\s*=\s*("
    + FLOAT_RE.pattern + ")", re.IGNORECASE
)
_UNITS_RE = re.compile(r"^\s*UNITS\s+ARE\s+SECONDS\s+AND\s+(\S+)", re.IGNORECASE)
_ORIGIN_RE = re.compile(r"Origin\s+Time\s*:\s*(\d{4})/(\d{1,2})/(\d{1,2})\s+(\d{1,2}):(\d{1,2}):"
                        r"(\d{1,2}(?:\.\d*)?)", re.IGNORECASE)


def is_bhrc(filename) -> bool:
    """Tell whether a file is a BHRC Volume 1 record (never raises).

    Parameters
    ----------
    filename : str, os.PathLike or file-like
        The file to check.

    Returns
    -------
    bool
        ``True`` if line 1 is ``* VOL... FILE: ...``, line 7 starts with ``COMP`` and the first
        block has the ``NO. OF POINTS`` and ``UNITS ARE SECONDS AND`` lines.
    """
    text = peek_text(filename)
    if text is None:
        return False
    lines = text.splitlines()[:TEXT_LINES]
    return (
        len(lines) == TEXT_LINES
        and _VOLUME_RE.match(lines[0]) is not None
        and lines[6].lstrip().upper().startswith("COMP")
        and any(_NPTS_RE.search(line) for line in lines)
        and any(_UNITS_RE.match(line) for line in lines)
    )


def _units(unit: str, name: str) -> float:
    """Return m/s^2 per unit of the samples (``G/10``, or any unit :func:`~shipblock.units.si_factor` knows)."""
    if unit.upper() == "G/10":
        return G_OVER_10_SI
    return si_factor(unit, name)


def _ints(lines, name, first_line):
    """Parse the I5 integer header."""
    values = []
    for offset, line in enumerate(lines):
        for field in fixed_fields(line.rstrip(), INT_WIDTH):
            field = field.strip()
            if not field:
                values.append(0)
                continue
            try:
                values.append(int(field))
            except ValueError:
                raise RecordError(name, f"line {first_line + offset}: integer header field"
                                        f" {field!r} is not an integer") from None
    return values


def _reals(lines, name, first_line):
    """Parse the E13.6 real header (six values a line; a cut last field reads as what is left)."""
    values = []
    for offset, line in enumerate(lines):
        row = line.rstrip("\r\n")
        for position, field in enumerate(fixed_fields(row, REAL_WIDTH, REALS_PER_LINE)):
            field = field.strip()
            if not field:
                values.append(0.0)
                continue
            try:
                values.append(parse_float(field))
            except ValueError:
                if position == REALS_PER_LINE - 1 and len(row) < REALS_PER_LINE * REAL_WIDTH:
                    values.append(math.nan)  # cut off at column 70: the value is lost
                    continue
                raise RecordError(name, f"line {first_line + offset}: real header field"
                                        f" {field!r} is not a number") from None
    return values


def _samples(lines, name, first_line):
    """Parse E13.6 sample lines."""
    values = []
    for offset, line in enumerate(lines):
        for field in fixed_fields(line.rstrip(), SAMPLE_WIDTH):
            field = field.strip()
            if not field:
                continue
            try:
                values.append(parse_float(field))
            except ValueError:
                raise RecordError(name, f"line {first_line + offset}: sample {field!r} is not"
                                        " a number") from None
    return np.asarray(values, dtype=np.float64)


def _float(match, group):
    value = match.group(group)
    return None if value is None else parse_float(value)


def _text_header(lines, name, first_line):
    """Parse a channel's 13 text lines into a dict of simple values."""
    volume = _VOLUME_RE.match(lines[0])
    if volume is None:
        raise RecordError(name, f"line {first_line}: expected a channel header '* VOL... FILE:'"
                                f" but found {lines[0].strip()[:40]!r}")
    header = {"volume": volume.group(1), "file_id": volume.group(2)}
    body = "\n".join(lines)
    instrument = re.search(r"Inst\s+Type\s*=\s*(.*)", body, re.IGNORECASE)
    header["instrument"] = instrument.group(1).strip() if instrument else ""
    origin = _ORIGIN_RE.search(body)
    if origin is not None:
        year, month, day, hour, minute = (int(g) for g in origin.groups()[:5])
        origin_time = utc_time(year, month, day, hour, minute, float(origin.group(6)))
        if origin_time is None:
            raise RecordError(name, f"Origin Time {origin.group(0)!r} is not a valid date and"
                                    " time")
        header["origin_time"] = str(origin_time)
    component = lines[4].strip().upper()
    comp = re.match(r"\s*COMP\s+(\S+)", lines[6], re.IGNORECASE)
    header["comp"] = comp.group(1) if comp else ""
    if not component and comp:
        component = comp.group(1)[:1].upper()
    if component not in ("L", "T", "V"):
        raise RecordError(name, f"line {first_line + 4}: component {component!r} is not L, T"
                                " or V")
    header["component"] = component
    station = _STATION_RE.search(lines[7])
    if station is not None:
        header["station_name"] = station.group("name").strip()
        header["latitude"] = _float(station, "lat") * (
            -1.0 if station.group("ns").upper() == "S" else 1.0)
        header["longitude"] = _float(station, "lon") * (
            -1.0 if station.group("ew").upper() == "W" else 1.0)
        if station.group("alt") is not None:
            header["altitude_m"] = _float(station, "alt")
        if station.group("l") is not None:
            header["azimuth_l_deg"] = _float(station, "l")
            header["azimuth_t_deg"] = _float(station, "t")
    period = _PERIOD_RE.search(body)
    if period is not None:
        header["instrument_period_s"] = _float(period, 1)
        header["instrument_damping"] = _float(period, 2)
    npts = _NPTS_RE.search(body)
    if npts is None:
        raise RecordError(name, f"channel {component} (line {first_line}): no 'NO. OF POINTS ="
                                " ... DURATION = ...' line")
    header["npts"] = int(npts.group(1))
    header["duration_s"] = _float(npts, 2)
    units = next((m for m in map(_UNITS_RE.match, lines) if m is not None), None)
    if units is None:
        raise UnitsError(name, f"channel {component}: no 'UNITS ARE SECONDS AND ...' line;"
                               " units unknown")
    header["units"] = units.group(1)
    return header


def _delta(header, name):
    """Sampling interval [s] from the stated rate, checked against the duration."""
    npts, duration, rate = header["npts"], header["duration_s"], header["sampling_rate_hz"]
    what = f"channel {header['component']}"
    if npts < 1:
        raise RecordError(name, f"{what}: NO. OF POINTS = {npts} is not a sample count")
    if math.isfinite(rate) and rate > 0:
        delta = 1.0 / rate
        mismatch = abs(npts * delta - duration)
        if not math.isfinite(duration) or mismatch > delta + DURATION_PRINT_STEP_S:
            raise RecordError(name, f"{what}: {npts} points at {rate:g} samples/s last"
                                    f" {npts * delta:g} s, but DURATION = {duration:g} s")
    elif rate == 0:
        delta = check_delta(duration / npts, name)
    else:
        raise RecordError(name, f"{what}: sampling rate {rate!r} is not a positive number")
    return check_sampling_interval(delta, name, f"{what}: sampling interval")


def read_bhrc(filename, headonly: bool = False, **kwargs) -> Stream:
    """Read a BHRC Volume 1 file into a Stream of one trace per channel, in m/s^2.

    Parameters
    ----------
    filename : str, os.PathLike or file-like
        The BHRC ``*.V1`` file.
    headonly : bool, optional
        Read only the headers; the traces then have no samples.
    **kwargs
        Ignored (obspy passes its own keywords to every plug-in).

    Returns
    -------
    obspy.Stream
        One trace per channel block (L, V, T in file order); ``stats.units == "m/s**2"``,
        ``stats.original_units`` the file's unit (``"G/10"``), ``stats.azimuth``/``stats.dip``,
        ``stats.coordinates`` and the channel's header in ``stats.shipblock_bhrc``. The start
        time is not stated by the file and stays at obspy's default.

    Raises
    ------
    RecordError
        If a header is incomplete or inconsistent, the file truncated (no ``/&`` after a
        channel's samples, or fewer samples than ``NO. OF POINTS``), or samples are NaN/inf or
        absurd.
    UnitsError
        If a channel states no unit, or one that is not an acceleration.
    """
    name = source_name(filename)
    lines = read_text(filename).splitlines()
    if not lines or _VOLUME_RE.match(lines[0]) is None:
        raise RecordError(name, "is not a BHRC file (line 1 is not '* VOL... FILE: ...')")
    stream = Stream()
    position = 0
    block_lines = TEXT_LINES + INT_LINES + REAL_LINES
    while position < len(lines):
        if not lines[position].strip():
            position += 1
            continue
        first_line = position + 1  # 1-based, for messages
        if position + block_lines > len(lines):
            raise RecordError(name, f"is truncated: the channel header starting at line"
                                    f" {first_line} is incomplete")
        header = _text_header(lines[position:position + TEXT_LINES], name, first_line)
        ints = _ints(lines[position + TEXT_LINES:position + TEXT_LINES + INT_LINES], name,
                     first_line + TEXT_LINES)
        reals = _reals(lines[position + TEXT_LINES + INT_LINES:position + block_lines], name,
                       first_line + TEXT_LINES + INT_LINES)
        what = f"channel {header['component']}"
        if len(ints) > INT_NPTS and ints[INT_NPTS] not in (0, header["npts"]):
            raise RecordError(name, f"{what}: NO. OF POINTS = {header['npts']} but the integer"
                                    f" header says {ints[INT_NPTS]}")
        header["sampling_rate_hz"] = reals[REAL_RATE_HZ] if len(reals) > REAL_RATE_HZ else 0.0
        delta = _delta(header, name)
        factor = _units(header["units"], name)
        header["start_time_stated"] = False
        data_start = position + block_lines
        try:
            end = next(i for i in range(data_start, len(lines))
                       if lines[i].strip() == END_MARKER)
        except StopIteration:
            raise RecordError(name, f"is truncated: {what} (header at line {first_line}) has no"
                                    f" closing {END_MARKER!r} line") from None
        horizontal_azimuth = None
        if header["component"] != "V":
            horizontal_azimuth = header.get(f"azimuth_{header['component'].lower()}_deg")
        stats = {
            "network": NETWORK,
            "station": header["file_id"].split("/")[0],
            "location": "",
            "units": "m/s**2",
            "original_units": header["units"],
            "shipblock_bhrc": AttribDict(header),
            **orientation_stats(1.0 / delta, vertical=header["component"] == "V",
                                azimuth_deg=horizontal_azimuth,
                                index=2 if header["component"] == "T" else 1),
        }
        if "latitude" in header:
            if not (abs(header["latitude"]) <= 90.0 and abs(header["longitude"]) <= 360.0):
                raise RecordError(name, f"{what}: station coordinates out of range")
            stats["coordinates"] = AttribDict(latitude=header["latitude"],
                                              longitude=header["longitude"],
                                              elevation=header.get("altitude_m", 0.0))
        # Counted also when only the header is read, so that headonly sees truncation too.
        count = sum(len(line.split()) for line in lines[data_start:end])
        if count != header["npts"]:
            problem = "truncated" if count < header["npts"] else "too long"
            raise RecordError(name, f"{what} is {problem}: NO. OF POINTS = {header['npts']}"
                                    f" but {count} samples were found")
        if headonly:
            trace = make_trace([], delta, stats)
            trace.stats.npts = header["npts"]
        else:
            samples = _samples(lines[data_start:end], name, data_start + 1)
            if samples.size != count:
                raise RecordError(name, f"{what}: samples run together (fixed-width fields"
                                        " without spaces); cannot tell them apart")
            trace = make_trace(samples, delta, stats)
            check_samples(trace.data, name, what)
            trace.data *= factor
            check_plausible_samples(trace.data, name, what)
        stream.append(trace)
        position = end + 1
    if not stream:
        raise RecordError(name, "holds no channel")
    return stream
