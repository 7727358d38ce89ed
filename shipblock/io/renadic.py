"""Reader for Chilean RENADIC ``.v1`` records (obspy waveform plug-in ``SHIPBLOCK_RENADIC``).

RENADIC, the national accelerograph network of the Department of Civil Engineering of the
Universidad de Chile, distributes uncorrected records in the Volume 1 layout of the California
strong-motion program (CDMG/CSMIP "uncorrected accelerogram data") [1]_, one block per channel:

1. 13 text lines: ``UNCORRECTED ACCELEROGRAM DATA  PROCESSED: <date>``; the event name; the time
   of the first sample (``mm/dd/yyyy h:mm:ss (GMT)  (ORIGIN: mm/dd/yyyy h:mm:ss GMT)``);
   ``TRIGGER TIME: m/d/yyyy h:mm:ss.sss GMT``; ``STATION NO.`` with the coordinates (``0.000N
   0.000E`` when unknown), the recorder model and serial number; the station name and
   ``S/N <number>``; ``CHAN n: <orientation>``; ``UNIVERSIDAD DE CHILE - RENADIC``; the
   hypocentre; ``INSTR PERIOD``, ``DAMPING``, ``SENSITIVITY``; ``NO. OF POINTS``,
   ``RECORD LENGTH`` [s]; ``UNITS OF UNCOR ACCEL ARE SEC AND G/10.  MAX = <peak> G, AT <t> SEC``;
   ``RMS ACCEL OF COMPLETE RECORD``;
2. 100 integers (16I5) and 50 reals (8F10.3), mostly the same values again;
3. ``(time [s], acceleration [g/10])`` pairs, five pairs a line in fields of 7 characters
   (10F7.3: from 100 s on the time fields touch, ``100.000 -0.145100.005``);
4. the line ``/&  ----------  END OF DATA FOR CHANNEL n  ----------``.

What the real files (2010 Maule and 2009 Tarapaca earthquakes, gmprocess test corpus) showed:

* the sampling interval is ``RECORD LENGTH / NO. OF POINTS`` (0.01 s or 0.005 s): the time column
  runs from 0 to ``(n - 1) * dt`` (``99.990`` for 10000 points over 100 s). gmprocess divides by
  ``n - 1`` (0.0100010001 s), which stretches the record by one sample. This reader checks every
  time of the column against ``i * dt``;
* the time on the third line (``ORIGIN``) is the first sample; the trigger time is a pre-event
  memory later (20 s on the QDR recorders, 10 s, 14.84 s, 20.8 s, 40.7 s, 50.6 s on others): the
  stated time of each peak (``AT ... SEC``) is counted from the trigger, and is exactly the
  data time of the largest sample minus that difference, in all 28 files. gmprocess starts the
  traces at the trigger time, a pre-event memory too late;
* several QDR files of the Maule earthquake state "GMT" times between 02:45 and 03:56 for an
  earthquake at 06:34 UTC (03:34 local): their clocks were not synchronised. The reader keeps
  the stated time (it cannot know the error);
* the digitised analogue records (SMA-1) carry the placeholder date 1/1/1980 0:00:00; it is not a
  start time and is not used (the traces then start at obspy's default epoch);
* the samples are in g/10: the stated ``MAX`` [g] equals the largest absolute sample / 10 to the
  printed three decimals in every channel. g is the standard gravity 9.80665 m/s^2 (gmprocess
  uses 980 cm/s^2, 0.07 % less);
* orientations are ``EW``, ``NS`` (taken as positive east and north), ``V``/``Z`` (taken as
  positive up), ``L``/``T`` (longitudinal and transverse of the analogue instruments: horizontal,
  azimuth not stated) and once ``NZ`` for a horizontal beside ``EW`` and ``Z`` (kept as a
  horizontal of unstated azimuth). Curico has a fourth channel ``INTC`` that is all zeros (not a
  sensor); it is skipped and named in the header (``skipped_channels``);
* records longer than the recorder's 100 s were split in ``parte1``/``parte2`` files (QDR): the
  recorder triggered again when the first file was full, so the pre-event memory of ``parte2``
  repeats the end of ``parte1``: the first sample of ``parte2`` is sample 8001 of ``parte1``,
  counted from 0 (9002 with a 10 s memory; correlation above 0.99 on every channel). Their stated times
  disagree with that by 10 to 13 s (``parte2`` stated 90 to 100 s after ``parte1`` instead of
  80.01 s or 90.02 s). Each file is read as its own record with its stated times; to join the
  two, drop the first pre-event memory of ``parte2`` and append it to ``parte1``;
* the text is Latin-1 (``PE\\xd1ALOLEN``); lines end in CRLF.

The file names no network; the network code is left empty. The station code is the recorder's
serial number (``S/N`` after the station name), the station name is kept in the header.

References
----------
.. [1] Shakal, A. F., and Huang, M. J. (1985). Standard tape format for CSMIP strong-motion data
   tapes. California Division of Mines and Geology, Office of Strong Motion Studies, Report
   OSMS 85-03.
"""

from __future__ import annotations

import contextlib
import re

import numpy as np
from obspy import Stream, UTCDateTime
from obspy.core import AttribDict

from shipblock.errors import RecordError, UnitsError
from shipblock.io._common import (
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
    utc_time,
)
from shipblock.units import si_factor

__all__ = ["FORMAT", "is_renadic", "read_renadic"]

#: Name under which the reader is registered as an obspy waveform plug-in.
FORMAT = "SHIPBLOCK_RENADIC"

#: First line of every channel block.
_TITLE = "UNCORRECTED ACCELEROGRAM DATA"

#: Agency line of RENADIC files (line 8 of a block).
_MARKER = "RENADIC"

#: Lines of a block before the samples: text, integer header (100 x I5), real header (50 x F10.3).
TEXT_LINES = 13
INTEGER_LINES = 7
REAL_LINES = 7

#: Width of a data field [characters] (10F7.3).
FIELD_WIDTH = 7

#: Largest difference between a stated sample time and ``i * dt`` [s]: the times are printed
#: with three decimals.
TIME_TOLERANCE_S = 1.5e-3

#: Orientation labels: ``(vertical, azimuth [deg] or None)``.
_ORIENTATIONS = {
    "NS": (False, 0.0), "N": (False, 0.0), "SN": (False, 0.0),
    "EW": (False, 90.0), "E": (False, 90.0), "WE": (False, 90.0),
    "V": (True, None), "Z": (True, None), "UP": (True, None), "UD": (True, None),
    "L": (False, None), "T": (False, None), "NZ": (False, None),
}

#: Channels that are not sensors (an internal calibration or time-code trace).
_NON_SENSOR = {"INTC"}

#: Placeholder date of records without absolute time.
_NO_TIME = UTCDateTime(1980, 1, 1)

_DATE_TIME = r"(\d{1,2})/(\d{1,2})/(\d{4})\s+(\d{1,2}):(\d{1,2}):(\d{1,2}(?:\.\d*)?)"
_ORIGIN_RE = re.compile(r"ORIGIN:\s*" + _DATE_TIME)
_FIRST_RE = re.compile(r"^\s*" + _DATE_TIME + r"\s*\(GMT\)")
_TRIGGER_RE = re.compile(r"TRIGGER TIME:\s*" + _DATE_TIME)
_NPTS_RE = re.compile(r"NO\. OF POINTS\s*=\s*(\S+)\s+RECORD LENGTH\s*=\s*(\S+)\s*SEC")
_UNITS_RE = re.compile(r"UNITS OF UNCOR ACCEL ARE SEC AND\s+(\S+?)\.?\s+MAX")
_MAX_RE = re.compile(r"MAX\s*=\s*(\S+)\s*G\s*,\s*AT\s*(\S+)\s*SEC")
_RMS_RE = re.compile(r"RMS ACCEL OF COMPLETE RECORD\s*=\s*(\S+)\s*G")
_CHAN_RE = re.compile(r"^CHAN\s*(\d+)\s*:\s*(\S+)")
_SERIAL_RE = re.compile(r"S/N\s*(\d+)")
_COORD_RE = re.compile(r"(\d+(?:\.\d*)?)\s*([NS])\s+(\d+(?:\.\d*)?)\s*([EW])")
_RECORDER_RE = re.compile(r"[EW]\s+(\S+)\s+S/N")
_INSTRUMENT_RE = re.compile(
    r"INSTR PERIOD\s*=\s*(\S+)\s*SEC,\s*DAMPING\s*=\s*(\S+?),\s*SENSITIVITY\s*=\s*(\S+)")


def is_renadic(filename) -> bool:
    """Tell whether a file is a RENADIC ``.v1`` record (never raises).

    Parameters
    ----------
    filename : str, os.PathLike or file-like
        The file to check.

    Returns
    -------
    bool
        ``True`` if the first line is ``UNCORRECTED ACCELEROGRAM DATA`` and the agency line
        ``UNIVERSIDAD DE CHILE - RENADIC`` is among the block's 13 text lines. (The same
        Volume 1 layout without that line is a CDMG/CSMIP or USC file.)
    """
    text = peek_text(filename)
    if text is None:
        return False
    lines = text.splitlines()[:TEXT_LINES]
    return bool(lines) and lines[0].lstrip().startswith(_TITLE) and any(
        _MARKER in line.upper() for line in lines[1:])


def _time(match):
    """``UTCDateTime`` of a ``_DATE_TIME`` match, or ``None`` if absent or impossible."""
    if match is None:
        return None
    month, day, year, hour, minute = (int(match.group(i)) for i in range(1, 6))
    return utc_time(year, month, day, hour, minute, float(match.group(6)))


def _unit_factor(unit, name):
    """Factor to m/s^2 of a unit such as ``G/10``."""
    match = re.fullmatch(r"G\s*/\s*(\d+)", unit.strip().upper())
    if match is not None and int(match.group(1)) > 0:
        return si_factor("g", name) / int(match.group(1))
    return si_factor(unit, name)


def _block_header(text, name, number):
    """Parse the 13 text lines of channel block ``number``."""
    where = f"channel block {number}"
    if _MARKER not in " ".join(text).upper():
        raise RecordError(name, f"{where}: no 'UNIVERSIDAD DE CHILE - RENADIC' line")
    header = {"processed": text[0].partition("PROCESSED:")[2].strip(),
              "event": text[1].strip()}
    chan = _CHAN_RE.match(text[6].strip())
    if chan is None:
        raise RecordError(name, f"{where}: line 7 {text[6].strip()!r} is not 'CHAN n: <name>'")
    header["channel_number"] = int(chan.group(1))
    header["orientation"] = chan.group(2).upper()
    counts = _NPTS_RE.search(text[10])
    if counts is None:
        raise RecordError(name, f"{where}: no 'NO. OF POINTS = n RECORD LENGTH = t SEC' line")
    npts = parse_number(counts.group(1), name, f"{where}: NO. OF POINTS")
    if npts != int(npts) or npts <= 1:
        raise RecordError(name, f"{where}: NO. OF POINTS {counts.group(1)!r} is not a count")
    header["npts"] = int(npts)
    header["record_length_s"] = parse_number(counts.group(2), name,
                                             f"{where}: RECORD LENGTH")
    units = _UNITS_RE.search(text[11])
    if units is None:
        raise UnitsError(name, f"{where}: the units line {text[11].strip()!r} is not understood")
    header["units"] = units.group(1)
    peak = _MAX_RE.search(text[11])
    if peak is not None:
        header["stated_max_g"] = parse_number(peak.group(1), name, f"{where}: MAX")
        header["stated_max_time_s"] = parse_number(peak.group(2), name,
                                                   f"{where}: MAX time")
    rms = _RMS_RE.search(text[12])
    if rms is not None:
        header["stated_rms_g"] = parse_number(rms.group(1), name, f"{where}: RMS")
    instrument = _INSTRUMENT_RE.search(text[9])
    if instrument is not None:
        for key, value in zip(("instrument_period_s", "instrument_damping",
                               "sensitivity_v_per_g"), instrument.groups(), strict=True):
            with contextlib.suppress(ValueError):  # instrument constants are optional
                header[key] = parse_float(value)
    station_line = text[5].strip()
    serial = _SERIAL_RE.search(station_line) or _SERIAL_RE.search(text[4])
    header["station_name"] = station_line.split("S/N")[0].strip()
    header["serial_number"] = serial.group(1) if serial else ""
    recorder = _RECORDER_RE.search(text[4])
    header["recorder"] = recorder.group(1) if recorder else ""
    coords = _COORD_RE.search(text[4])
    if coords is not None:
        latitude = float(coords.group(1)) * (-1.0 if coords.group(2) == "S" else 1.0)
        longitude = float(coords.group(3)) * (-1.0 if coords.group(4) == "W" else 1.0)
        if (latitude, longitude) != (0.0, 0.0) and abs(latitude) <= 90 and abs(longitude) <= 180:
            header["latitude"] = latitude
            header["longitude"] = longitude
    first = _time(_ORIGIN_RE.search(text[2])) or _time(_FIRST_RE.search(text[2]))
    trigger = _time(_TRIGGER_RE.search(text[3]))
    header["time_stated"] = first is not None and first != _NO_TIME
    if header["time_stated"]:
        header["first_sample_time"] = str(first)
    if trigger is not None and trigger != _NO_TIME:
        header["trigger_time"] = str(trigger)
        if header["time_stated"]:
            header["pre_event_s"] = round(trigger - first, 6)
    return header, (first if header["time_stated"] else None)


def _parse_pairs(lines, name, where):
    """Parse the fixed-width ``(time, value)`` fields of a block's data lines."""
    fields = []
    for line in lines:
        text = line.rstrip()
        fields.extend(fixed_fields(text, FIELD_WIDTH))
    try:
        values = np.array(fields, dtype=np.float64) if fields else np.empty(0)
    except ValueError:
        for token in fields:
            try:
                float(token)
            except ValueError:
                raise RecordError(name, f"{where}: {token.strip()!r} is not a number") from None
        raise RecordError(name, f"{where}: the samples are not numbers") from None
    return values


def _read_block(lines, start, name, number, headonly):
    """Read the channel block starting at ``lines[start]``; return (header, start, data, next)."""
    where = f"channel block {number}"
    data_start = start + TEXT_LINES + INTEGER_LINES + REAL_LINES
    if data_start > len(lines):
        raise RecordError(name, f"{where} is truncated inside its header")
    header, first = _block_header(lines[start:start + TEXT_LINES], name, number)
    end = data_start
    while end < len(lines) and not lines[end].lstrip().startswith("/&"):
        if lines[end].lstrip().startswith(_TITLE):
            break
        end += 1
    if end >= len(lines) or not lines[end].lstrip().startswith("/&"):
        raise RecordError(name, f"{where} is truncated: no '/& END OF DATA' line")
    npts = header["npts"]
    delta = check_sampling_interval(header["record_length_s"] / npts, name)
    data = None
    if not headonly:
        values = _parse_pairs(lines[data_start:end], name, where)
        if values.size != 2 * npts:
            what = "truncated" if values.size < 2 * npts else "longer than its header says"
            raise RecordError(name, f"{where} is {what}: NO. OF POINTS={npts} but"
                                    f" {values.size / 2:g} (time, value) pairs were found")
        times, data = values[0::2], values[1::2]
        expected = np.arange(npts) * delta
        if not np.all(np.isfinite(times)):
            raise RecordError(name, f"{where}: the time column has NaN/inf values")
        worst = int(np.argmax(np.abs(times - expected)))
        if abs(times[worst] - expected[worst]) > TIME_TOLERANCE_S:
            raise RecordError(
                name, f"{where}: sample {worst} is at {times[worst]} s, not at"
                      f" {expected[worst]:.3f} s (RECORD LENGTH/NO. OF POINTS = {delta} s):"
                      " samples missing or repeated")
    return header, first, delta, data, end + 1


def read_renadic(filename, headonly: bool = False, **kwargs) -> Stream:
    """Read a RENADIC ``.v1`` record into a Stream of one trace per sensor channel, in m/s^2.

    Parameters
    ----------
    filename : str, os.PathLike or file-like
        The ``.v1`` file.
    headonly : bool, optional
        Read only the headers; the traces then have no samples.
    **kwargs
        Ignored (obspy passes its own keywords to every plug-in).

    Returns
    -------
    obspy.Stream
        One trace per sensor channel; ``stats.units == "m/s**2"``, ``stats.original_units`` the
        file's unit (``G/10``), ``stats.stated_peak_si`` the stated ``MAX`` [m/s^2], the header in
        ``stats.shipblock_renadic``.

    Raises
    ------
    RecordError
        If a header is incomplete, a block truncated, the time column irregular, or samples are
        NaN/inf/implausible.
    UnitsError
        If the unit is missing or not an acceleration.
    """
    name = source_name(filename)
    lines = read_text(filename).splitlines()
    if not lines or not lines[0].lstrip().startswith(_TITLE):
        raise RecordError(name, f"is not a RENADIC .v1 file (first line is not {_TITLE!r})")
    blocks = []
    position = 0
    while position < len(lines):
        if not lines[position].strip():
            position += 1
            continue
        if not lines[position].lstrip().startswith(_TITLE):
            raise RecordError(name, f"line {position + 1}: expected a new channel block"
                                    f" ({_TITLE!r}), found {lines[position].strip()[:40]!r}")
        block = _read_block(lines, position, name, len(blocks) + 1, headonly)
        blocks.append(block[:4])
        position = block[4]

    skipped = [header["orientation"] for header, *_ in blocks
               if header["orientation"] in _NON_SENSOR]
    stream = Stream()
    horizontal = 0
    for header, first, delta, data in blocks:
        label = header["orientation"]
        if label in _NON_SENSOR:
            continue
        where = f"channel {header['channel_number']} ({label})"
        if label not in _ORIENTATIONS:
            raise RecordError(name, f"{where}: unknown orientation {label!r}")
        vertical, azimuth = _ORIENTATIONS[label]
        if not vertical:
            horizontal += 1
        factor = _unit_factor(header["units"], name)
        stats = {
            "network": "",
            "station": header["serial_number"],
            "location": "",
            "units": "m/s**2",
            "original_units": header["units"],
            "shipblock_renadic": AttribDict(dict(header, skipped_channels=",".join(skipped))),
            **orientation_stats(1.0 / delta, vertical=vertical, azimuth_deg=azimuth,
                                positive_up=True, index=min(horizontal, 2)),
        }
        if "latitude" in header:
            stats["coordinates"] = AttribDict(latitude=header["latitude"],
                                              longitude=header["longitude"], elevation=0.0)
        if "stated_max_g" in header:
            stats["stated_peak_si"] = abs(header["stated_max_g"]) * si_factor("g", name)
        if headonly:
            trace = make_trace([], delta, stats)
            trace.stats.npts = header["npts"]
        else:
            trace = make_trace(data, delta, stats)
            check_samples(trace.data, name, where)
            trace.data *= factor
            check_plausible_samples(trace.data, name, where)
        if first is not None:
            trace.stats.starttime = first
        stream.append(trace)
    if not stream:
        raise RecordError(name, "has no sensor channel")
    return stream
