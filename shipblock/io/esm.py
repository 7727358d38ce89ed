"""Reader for ESM ASCII records (obspy waveform plug-in ``SHIPBLOCK_ESM``).

The Engineering Strong-Motion database (ESM, ORFEUS) distributes one component per file [1]_: a
header of ``KEY: value`` lines (64 in current files, ``HEADER_FORMAT: DYNA 1.2``, starting with
``EVENT_NAME:`` and ``EVENT_ID:``), then one sample per line. Keys used here: ``NETWORK``,
``STATION_CODE``, ``LOCATION``, ``STREAM`` (the SEED channel code, e.g. ``HNE``),
``SAMPLING_INTERVAL_S`` [s], ``NDATA``, ``DATE_TIME_FIRST_SAMPLE_YYYYMMDD_HHMMSS``, ``DATA_TYPE``
(must be an acceleration time series), ``UNITS`` (e.g. ``cm/s^2``), ``PGA_CM/S^2`` and
``TIME_PGA_S`` (the file's own peak, signed, and its time after the first sample),
``STATION_LATITUDE_DEGREE``/``STATION_LONGITUDE_DEGREE``/``STATION_ELEVATION_M``.

What the real files (HI.ARS1 and HL.DLFA, 2019-07-28 M4.6 Greece, from ESM via the gmprocess
test corpus) showed:

* **Keys hold** ``/`` **and** ``^``: ``VS30_M/S``, ``INSTRUMENT_ANALOG/DIGITAL``, ``PGA_CM/S^2``,
  ``LATE/NORMAL_TRIGGERED``. (The reader's first version took ``VS30_M/S:`` for the first sample
  line, so it never saw ``UNITS`` nor the samples' true start.)
* ``UNITS: cm/s^2`` is present; ``LOCATION:`` is written empty (the empty SEED location, which
  gmprocess calls ``--``); ``DATE_TIME_FIRST_SAMPLE_YYYYMMDD_HHMMSS: 20190728_160919.870`` with
  ``DATE_TIME_FIRST_SAMPLE_PRECISION: milliseconds``; ``DATA_TYPE: ACCELERATION``;
  ``PROCESSING: manual (Paolucci et al., 2011)`` (the ``.C.`` of the file name: corrected).
* ``PGA_CM/S^2`` equals the largest sample in absolute value to the printed 6 decimals, with its
  sign, and ``TIME_PGA_S`` is that sample's index times ``SAMPLING_INTERVAL_S``.

AFAD (Turkey) exports records in this layout with differences: the first sample's time written
``2023/02/06 01:17:32.000000`` (read; a time in no known layout is refused, never put at 1970), and
a place name under ``LOCATION`` (not a SEED location code of up to two letters or digits: the code
is left empty and the name kept in the header, with a note).

Cross-check: ``DURATION_S`` is ``NDATA`` x ``SAMPLING_INTERVAL_S`` in every real file; an interval
or count that disagrees by more than one sample (a damaged number) is refused.

Units: ``UNITS`` is honoured (converted to m/s^2; an unknown unit is refused). gmprocess ignores
the key and always assumes cm/s^2. A file without ``UNITS`` is read only if its own
``PGA_CM/S^2`` (a value the key names in cm/s^2) equals the samples' peak read as cm/s^2: the file
then proves its unit and ``stats.units_source`` says so; otherwise it is refused, since guessing
would be silent. ``stats.stated_peak_si`` holds ``|PGA_CM/S^2|`` in m/s^2.

References
----------
.. [1] Luzi, L., Puglia, R., Russo, E., and ORFEUS WG5 (2016). Engineering Strong Motion Database,
   version 1.0. Istituto Nazionale di Geofisica e Vulcanologia, Observatories & Research
   Facilities for European Seismology. doi:10.13127/ESM.
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
    check_plausible_samples,
    check_samples,
    check_sampling_interval,
    make_trace,
    parse_float,
    parse_free_floats,
    peek_text,
    read_text,
    source_name,
)
from shipblock.units import si_factor

__all__ = ["FORMAT", "is_esm", "read_esm"]

#: Name under which the reader is registered as an obspy waveform plug-in.
FORMAT = "SHIPBLOCK_ESM"

#: Header key of the file's own peak acceleration; the key itself names the unit (cm/s^2).
PGA_KEY = "PGA_CM/S^2"

#: Factor from the unit of :data:`PGA_KEY` (cm/s^2) to m/s^2.
PGA_KEY_TO_SI = 0.01

#: Relative tolerance for a stated peak to agree with the samples' peak. The values are printed
#: to 6 decimals; units that could be confused differ by factors of 100 (m/s^2) or ~981 (g).
PEAK_MATCH_RTOL = 0.01

#: Absolute tolerance of that comparison [file units]: one unit of the 6th printed decimal.
PEAK_MATCH_ATOL = 1e-6

#: Resolution of ``DURATION_S`` as printed [s].
DURATION_RESOLUTION_S = 0.001

#: ``stats.units_source`` values.
UNITS_FROM_HEADER = "UNITS header"
UNITS_FROM_PGA = "no UNITS key; PGA_CM/S^2 agrees with the samples read as cm/s^2"

_KEY_LINE = re.compile(r"^\s*([A-Z][A-Z0-9_/^.-]*)\s*:(.*)$")
_TIME_FORMATS = ("%Y%m%d_%H%M%S.%f", "%Y%m%d_%H%M%S", "%Y-%m-%dT%H:%M:%S.%f", "%Y-%m-%dT%H:%M:%S",
                 "%Y/%m/%d %H:%M:%S.%f", "%Y/%m/%d %H:%M:%S")

#: Header key of the time of the first sample.
START_KEY = "DATE_TIME_FIRST_SAMPLE_YYYYMMDD_HHMMSS"

#: A SEED location code: up to two letters or digits (``--`` is the empty one).
_SEED_LOCATION = re.compile(r"^(?:[A-Za-z0-9]{0,2}|--)$")


def is_esm(filename) -> bool:
    """Tell whether a file is an ESM ASCII record (never raises).

    Parameters
    ----------
    filename : str, os.PathLike or file-like
        The file to check.

    Returns
    -------
    bool
        ``True`` if the first two lines are ``EVENT_NAME:`` and ``EVENT_ID:`` and a
        ``SAMPLING_INTERVAL_S:`` key follows.
    """
    text = peek_text(filename)
    if text is None:
        return False
    lines = text.splitlines()
    return (
        len(lines) > 2
        and lines[0].startswith("EVENT_NAME:")
        and lines[1].startswith("EVENT_ID:")
        and "SAMPLING_INTERVAL_S:" in text
    )


def _header(lines) -> tuple[dict, int]:
    """Parse the ``KEY: value`` header; return it and the index of the first data line."""
    header = {}
    for index, line in enumerate(lines):
        match = _KEY_LINE.match(line)
        if match is not None:
            header[match.group(1)] = match.group(2).strip()
        elif line.strip():
            return header, index
    return header, len(lines)


def _float(header, key, name, required=True):
    """Return a float header value, ``None`` if absent and optional."""
    raw = header.get(key, "")
    if not raw:
        if required:
            raise RecordError(name, f"header key {key} is missing or empty")
        return None
    try:
        value = parse_float(raw)
    except ValueError:
        value = math.nan
    if not math.isfinite(value):
        if required:
            raise RecordError(name, f"header key {key}={raw!r} is not a finite number")
        return None
    return value


def _start_time(raw: str, name: str) -> UTCDateTime | None:
    """Parse ``DATE_TIME_FIRST_SAMPLE_YYYYMMDD_HHMMSS``; ``None`` if empty, refused if unreadable."""
    text = raw.strip()
    if not text:
        return None
    for fmt in _TIME_FORMATS:
        try:
            return UTCDateTime.strptime(text[:26], fmt)
        except Exception:  # noqa: BLE001 - try the next layout
            continue
    raise RecordError(name, f"header key {START_KEY}={raw.strip()!r} is not a time in a known"
                            " layout (YYYYMMDD_hhmmss.fff, YYYY-MM-DDThh:mm:ss.f or"
                            " YYYY/MM/DD hh:mm:ss.ffffff)")


def _check_duration(header, delta: float, ndata: int, name: str) -> None:
    """Refuse an interval that contradicts ``DURATION_S`` (ESM writes NDATA x interval)."""
    duration = _float(header, "DURATION_S", name, required=False)
    if duration is None or ndata == 0:
        return
    # The duration is printed to 1 ms; NDATA x interval or (NDATA - 1) x interval is meant.
    if abs(duration - ndata * delta) > delta + DURATION_RESOLUTION_S:
        raise RecordError(
            name, f"header key SAMPLING_INTERVAL_S={header['SAMPLING_INTERVAL_S']} with"
            f" NDATA={ndata} spans {ndata * delta:g} s, but DURATION_S={header['DURATION_S']}"
            " (a damaged interval or count)")


def _location(header, notes) -> str:
    """The SEED location code of ``LOCATION``; a place name there (AFAD) is kept as a note."""
    location = header.get("LOCATION", "")
    if _SEED_LOCATION.match(location):
        return "" if location == "--" else location
    notes.append(f"LOCATION {location!r} is not a SEED location code (a place name?); the"
                 " location code is left empty")
    return ""


def _peaks_agree(samples_peak: float, stated: float) -> bool:
    """Whether two absolute peaks (same unit) agree within the printed precision."""
    return abs(samples_peak - stated) <= PEAK_MATCH_ATOL + PEAK_MATCH_RTOL * stated


def _units(header, samples, name) -> tuple[str, float, str]:
    """Return the file's unit, its factor to m/s^2 and where the unit came from."""
    unit = header.get("UNITS", "")
    if unit:
        return unit, si_factor(unit, name), UNITS_FROM_HEADER
    pga = _float(header, PGA_KEY, name, required=False)
    if pga is None:
        raise UnitsError(
            name, f"header key UNITS is missing or empty and there is no {PGA_KEY} to check"
            " the samples against; units unknown"
        )
    peak = float(np.max(np.abs(samples))) if samples.size else float("nan")
    if not _peaks_agree(peak, abs(pga)):
        raise UnitsError(
            name, f"header key UNITS is missing or empty and the samples' peak {peak:g} is not"
            f" {PGA_KEY}={pga:g}: the samples are not in cm/s^2; units unknown"
        )
    return "cm/s^2", si_factor("cm/s^2", name), UNITS_FROM_PGA


def read_esm(filename, headonly: bool = False, **kwargs) -> Stream:
    """Read an ESM ASCII record into a Stream of one trace in m/s^2.

    Parameters
    ----------
    filename : str, os.PathLike or file-like
        The ESM file.
    headonly : bool, optional
        Read only the header; the trace then has no samples (the samples are still parsed when
        the file has no ``UNITS`` key, to prove its unit).
    **kwargs
        Ignored (obspy passes its own keywords to every plug-in).

    Returns
    -------
    obspy.Stream
        One trace; ``stats.units == "m/s**2"``, ``stats.original_units`` the file's unit,
        ``stats.units_source`` where that unit came from, ``stats.stated_peak_si`` the file's
        ``PGA_CM/S^2`` in m/s^2 (absolute), the SEED codes from the header, and the header in
        ``stats.shipblock_esm``.

    Raises
    ------
    RecordError
        If the header is incomplete, the file truncated, or samples are NaN/inf.
    UnitsError
        If ``UNITS`` is unknown, or missing without a matching ``PGA_CM/S^2``, or ``DATA_TYPE``
        is not an acceleration time series.
    """
    name = source_name(filename)
    lines = read_text(filename).splitlines()
    if not (len(lines) > 1 and lines[0].startswith("EVENT_NAME:")):
        raise RecordError(name, "is not an ESM ASCII file (no EVENT_NAME: header)")
    header, first_data = _header(lines)
    data_type = header.get("DATA_TYPE", "")
    if data_type and ("ACC" not in data_type.upper() or "SPECTR" in data_type.upper()):
        raise UnitsError(name, f"DATA_TYPE is {data_type!r}, not an acceleration time series")
    delta = check_sampling_interval(_float(header, "SAMPLING_INTERVAL_S", name), name)
    ndata = _float(header, "NDATA", name)
    if ndata != int(ndata) or ndata < 0:
        raise RecordError(name, f"NDATA={header['NDATA']!r} is not a sample count")
    ndata = int(ndata)
    _check_duration(header, delta, ndata, name)
    start = _start_time(header.get(START_KEY, ""), name)
    samples = None
    if not headonly or not header.get("UNITS", ""):
        samples = parse_free_floats(lines[first_data:], name, "acceleration samples")
        if samples.size != ndata:
            what = "truncated" if samples.size < ndata else "longer than its header says"
            raise RecordError(
                name, f"is {what}: NDATA={ndata} but {samples.size} samples were found"
            )
        check_samples(samples, name, f"channel {header.get('STREAM') or '?'}")
    unit, factor, units_source = _units(header, samples, name)
    esm = AttribDict(header)
    esm["notes"] = []
    location = _location(header, esm["notes"])
    if units_source != UNITS_FROM_HEADER:
        esm["notes"].append(units_source)
    stats = {
        "network": header.get("NETWORK", ""),
        "station": header.get("STATION_CODE", ""),
        "location": location,
        "channel": header.get("STREAM", ""),
        "units": "m/s**2",
        "original_units": unit,
        "units_source": units_source,
        "shipblock_esm": esm,
    }
    pga = _float(header, PGA_KEY, name, required=False)
    if pga is not None:
        stats["stated_peak_si"] = abs(pga) * PGA_KEY_TO_SI
    latitude = _float(header, "STATION_LATITUDE_DEGREE", name, required=False)
    longitude = _float(header, "STATION_LONGITUDE_DEGREE", name, required=False)
    if latitude is not None and longitude is not None:
        elevation = _float(header, "STATION_ELEVATION_M", name, required=False)
        stats["coordinates"] = AttribDict(
            latitude=latitude, longitude=longitude, elevation=elevation or 0.0
        )
    if headonly:
        trace = make_trace([], delta, stats)
        trace.stats.npts = ndata
    else:
        trace = make_trace(samples, delta, stats)
        trace.data *= factor
        check_plausible_samples(trace.data, name, f"channel {stats['channel'] or '?'}")
        if pga is not None and not _peaks_agree(float(np.max(np.abs(trace.data))),
                                                abs(pga) * PGA_KEY_TO_SI):
            note = (f"{PGA_KEY}={pga:g} disagrees with the samples' peak"
                    f" {np.max(np.abs(trace.data)) / PGA_KEY_TO_SI:g} cm/s^2 (UNITS={unit!r})")
            esm["notes"].append(note)
            warnings.warn(f"{name}: {note}", stacklevel=2)
    if start is not None:
        trace.stats.starttime = start
    return Stream([trace])
