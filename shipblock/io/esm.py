"""Reader for ESM ASCII records (obspy waveform plug-in ``SHIPBLOCK_ESM``).

The Engineering Strong-Motion database (ESM, ORFEUS) distributes one component per file: a header
of ``KEY: value`` lines (64 in current files, starting with ``EVENT_NAME:`` and ``EVENT_ID:``),
then one sample per line [1]_. Keys used here: ``NETWORK``, ``STATION_CODE``, ``LOCATION``,
``STREAM`` (the SEED channel code, e.g. ``HGE``), ``SAMPLING_INTERVAL_S`` [s], ``NDATA``,
``DATE_TIME_FIRST_SAMPLE_YYYYMMDD_HHMMSS``, ``DATA_TYPE`` (must be an acceleration), ``UNITS``
(e.g. ``cm/s^2``) and ``STATION_LATITUDE_DEGREE``/``STATION_LONGITUDE_DEGREE``/
``STATION_ELEVATION_M``. ``UNITS`` is honoured (converted to m/s^2); a file without it is refused,
since guessing would be silent.

References
----------
.. [1] Luzi, L., Puglia, R., Russo, E., and ORFEUS WG5 (2016). Engineering Strong Motion Database,
   version 1.0. Istituto Nazionale di Geofisica e Vulcanologia, Observatories & Research
   Facilities for European Seismology. doi:10.13127/ESM.
"""

from __future__ import annotations

import re

from obspy import Stream, UTCDateTime
from obspy.core import AttribDict

from shipblock.errors import RecordError, UnitsError
from shipblock.io._common import (
    check_delta,
    check_samples,
    make_trace,
    parse_float,
    parse_free_floats,
    peek_text,
    read_text,
    si_factor,
    source_name,
)

__all__ = ["FORMAT", "is_esm", "read_esm"]

#: Name under which the reader is registered as an obspy waveform plug-in.
FORMAT = "SHIPBLOCK_ESM"

_KEY_LINE = re.compile(r"^\s*([A-Z][A-Z0-9_]*)\s*:(.*)$")
_TIME_FORMATS = ("%Y%m%d_%H%M%S.%f", "%Y%m%d_%H%M%S", "%Y-%m-%dT%H:%M:%S.%f", "%Y-%m-%dT%H:%M:%S")


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
        return parse_float(raw)
    except ValueError:
        if required:
            raise RecordError(name, f"header key {key}={raw!r} is not a number") from None
        return None


def _start_time(raw: str) -> UTCDateTime | None:
    """Parse ``DATE_TIME_FIRST_SAMPLE_YYYYMMDD_HHMMSS``, or return ``None``."""
    for fmt in _TIME_FORMATS:
        try:
            return UTCDateTime.strptime(raw.strip()[:26], fmt)
        except Exception:  # noqa: BLE001 - try the next layout
            continue
    return None


def read_esm(filename, headonly: bool = False, **kwargs) -> Stream:
    """Read an ESM ASCII record into a Stream of one trace in m/s^2.

    Parameters
    ----------
    filename : str, os.PathLike or file-like
        The ESM file.
    headonly : bool, optional
        Read only the header; the trace then has no samples.
    **kwargs
        Ignored (obspy passes its own keywords to every plug-in).

    Returns
    -------
    obspy.Stream
        One trace; ``stats.units == "m/s**2"``, ``stats.original_units`` the file's ``UNITS``,
        the SEED codes from the header, and the header in ``stats.shipblock_esm``.

    Raises
    ------
    RecordError
        If the header is incomplete, the file truncated, or samples are NaN/inf.
    UnitsError
        If ``UNITS`` is missing or unknown, or ``DATA_TYPE`` is not an acceleration.
    """
    name = source_name(filename)
    lines = read_text(filename).splitlines()
    if not (len(lines) > 1 and lines[0].startswith("EVENT_NAME:")):
        raise RecordError(name, "is not an ESM ASCII file (no EVENT_NAME: header)")
    header, first_data = _header(lines)
    data_type = header.get("DATA_TYPE", "")
    if data_type and "ACC" not in data_type.upper():
        raise UnitsError(name, f"DATA_TYPE is {data_type!r}, not an acceleration")
    unit = header.get("UNITS", "")
    if not unit:
        raise UnitsError(name, "header key UNITS is missing or empty; units unknown")
    factor = si_factor(unit, name)
    delta = check_delta(_float(header, "SAMPLING_INTERVAL_S", name), name)
    ndata = _float(header, "NDATA", name)
    if ndata != int(ndata) or ndata < 0:
        raise RecordError(name, f"NDATA={header['NDATA']!r} is not a sample count")
    stats = {
        "network": header.get("NETWORK", ""),
        "station": header.get("STATION_CODE", ""),
        "location": header.get("LOCATION", ""),
        "channel": header.get("STREAM", ""),
        "units": "m/s**2",
        "original_units": unit,
        "shipblock_esm": AttribDict(header),
    }
    latitude = _float(header, "STATION_LATITUDE_DEGREE", name, required=False)
    longitude = _float(header, "STATION_LONGITUDE_DEGREE", name, required=False)
    if latitude is not None and longitude is not None:
        elevation = _float(header, "STATION_ELEVATION_M", name, required=False)
        stats["coordinates"] = AttribDict(
            latitude=latitude, longitude=longitude, elevation=elevation or 0.0
        )
    start = _start_time(header.get("DATE_TIME_FIRST_SAMPLE_YYYYMMDD_HHMMSS", ""))
    if headonly:
        trace = make_trace([], delta, stats)
        trace.stats.npts = int(ndata)
    else:
        samples = parse_free_floats(lines[first_data:], name, "acceleration samples")
        if samples.size != int(ndata):
            what = "truncated" if samples.size < ndata else "longer than its header says"
            raise RecordError(
                name, f"is {what}: NDATA={int(ndata)} but {samples.size} samples were found"
            )
        trace = make_trace(samples, delta, stats)
        check_samples(trace.data, name, f"channel {stats['channel'] or '?'}")
        trace.data *= factor
    if start is not None:
        trace.stats.starttime = start
    return Stream([trace])
