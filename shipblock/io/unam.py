"""Reader for Mexican ASA strong-motion records (obspy waveform plug-in ``SHIPBLOCK_UNAM``).

The Instituto de Ingenieria of UNAM (and the other members of the Mexican strong-motion database,
*Base Mexicana de Datos de Sismos Fuertes*, Sociedad Mexicana de Ingenieria Sismica) distribute
accelerograms as *Archivo Estandar de Aceleracion* (ASA) text files, format version 2.0 [1]_.
No published description of the layout was at hand; the layout below was read from the files of
the USGS gmprocess test corpus (us2000ar20, 2017-09-19 Puebla-Morelos Mw 7.1; usp000cgtd,
2004-01-01 Guerrero):

1. a banner, then the title ``ARCHIVO ESTANDAR DE ACELERACION:``;
2. ``KEY : value`` lines in Spanish, grouped in sections (station, instrument, earthquake, this
   record, quality, comments); a line with an empty key continues the key above it (the station
   coordinates are ``16.84851 LAT. N`` then ``: 99.85157 LONG. W``). Per-channel values are
   written ``/v1/v2/v3`` under two keys, one for channels 1-6 and one for channels 7-12:
   ``ORIENTACION`` (``V``, ``N00E``, ``N90E``, ``S45W`` ...), ``INTERVALO DE MUESTREO`` [s],
   ``VEL. DE MUESTREO`` [samples/s], ``NUM. TOTAL DE MUESTRAS``, ``DURACION DEL REGISTRO`` [s],
   ``ACEL. MAX.`` (the signed peak of each channel) and ``ACEL. MAX., ... EN LA MUESTRA``;
   ``UNIDADES DE LOS DATOS`` (``Gal (cm/s/s)``) and ``FORMATO DATOS`` (Fortran, ``3F10.4``);
3. after ``DATOS DE ACELERACION:``, a ruler line, the column titles (``CANAL-1 ...`` and the
   orientations), a second ruler, then one row per sample with one column per channel.

The record start is given only as a time of day (``HORA DE LA PRIMERA MUESTRA (GMT)``); the date
is that of the earthquake (``FECHA DEL SISMO [GMT]``), moved by one day when that brings the start
closer to the origin time (``HORA EPICENTRO (GMT)``): a record of an earthquake shortly before
midnight starts on the next day.

What the real files showed:

* the stated peaks equal the largest absolute samples to the printed digits in all four files;
  their sample numbers count from 1 in the 2017 files and from 0 in the 2004 file;
* the 2004 file (CUP50401.012) holds 17502 rows for 17500 stated samples: its last three rows are
  identical, i.e. the writer padded the record by repeating the last sample. Rows beyond the
  stated count are accepted only when they repeat the last sample (their number is kept in the
  header as ``padding_rows``); any other excess or any shortfall is an error;
* orientations are bearings (``N00E``, ``N90E``; one quadrant bearing ``N<a>W`` would be
  azimuth ``360 - a``), the vertical is ``V``. A horizontal is taken as positive towards its
  bearing and the vertical as positive up (the usual convention of these data; the files do not
  say);
* the text is ASCII in these files; non-UTF-8 text is decoded as Latin-1 (Spanish accents);
  ``CA&AS`` stands for ``CAÑAS`` in one station address.

The file names no network; the network code is left empty, the station code is
``CLAVE DE LA ESTACION``.

References
----------
.. [1] Sociedad Mexicana de Ingenieria Sismica (2000). Base Mexicana de Datos de Sismos Fuertes,
   vol. 2 (CD-ROM), Archivo Estandar de Aceleracion (ASA) version 2.0.
"""

from __future__ import annotations

import math
import re
import unicodedata

import numpy as np
from obspy import Stream
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
    utc_time,
)
from shipblock.units import si_factor

__all__ = ["FORMAT", "is_unam", "read_unam"]

#: Name under which the reader is registered as an obspy waveform plug-in.
FORMAT = "SHIPBLOCK_UNAM"

#: Title line of every ASA file.
_TITLE = "ARCHIVO ESTANDAR DE ACELERACION"

#: Marker of the data section.
_DATA_TITLE = "DATOS DE ACELERACION"

#: Largest distance [s] between the record start and the origin time for which the earthquake's
#: date is trusted without trying the day before and after (half a day).
_HALF_DAY_S = 43200.0

#: Largest relative disagreement between the stated sampling interval and rate.
_RATE_TOLERANCE = 1e-3

_KEY_LINE = re.compile(r"^([^:]*?)\s*:(.*)$")
_FORTRAN_FORMAT = re.compile(r"(\d*)\s*[FEGD]\s*(\d+)(?:\.(\d+))?", re.IGNORECASE)
_BEARING = re.compile(r"^([NS])\s*(\d+(?:\.\d*)?)\s*([EW])$")
_TIME_OF_DAY = re.compile(r"^(\d{1,2}):(\d{1,2}):(\d{1,2}(?:\.\d*)?)$")
_VERTICAL_NAMES = {"V", "Z", "UP", "VERT", "VERTICAL", "U"}


def _normalise_key(key: str) -> str:
    """Upper-case a header key and strip accents and repeated blanks."""
    key = unicodedata.normalize("NFKD", key)
    key = "".join(ch for ch in key if not unicodedata.combining(ch))
    return " ".join(key.upper().split())


def is_unam(filename) -> bool:
    """Tell whether a file is a Mexican ASA (UNAM) strong-motion record (never raises).

    Parameters
    ----------
    filename : str, os.PathLike or file-like
        The file to check.

    Returns
    -------
    bool
        ``True`` if one of the first 20 lines holds the title ``ARCHIVO ESTANDAR DE
        ACELERACION`` and the station key ``CLAVE DE LA ESTACION`` follows.
    """
    text = peek_text(filename)
    if text is None:
        return False
    head = [_normalise_key(line) for line in text.splitlines()[:20]]
    return any(line.startswith(_TITLE) for line in head) and "CLAVE DE LA ESTACION" in (
        _normalise_key(text)
    )


def _parse_header(lines, name):
    """Parse the ``KEY : value`` header; return it and the index of the data title line.

    Continuation lines (empty key) are appended to the previous key's list of values.
    """
    header: dict[str, list[str]] = {}
    last = None
    for index, line in enumerate(lines):
        key_text = _normalise_key(line)
        if key_text.startswith(_DATA_TITLE):
            return header, index
        match = _KEY_LINE.match(line)
        if match is None:
            continue
        key = _normalise_key(match.group(1))
        value = match.group(2).strip()
        if not key:
            if last is not None:
                header[last].append(value)
            continue
        header.setdefault(key, []).append(value)
        last = key
    raise RecordError(name, f"has no {_DATA_TITLE} section (truncated or not an ASA file)")


def _first(header, prefix, name=None, required=False):
    """The first value of the first key starting with ``prefix`` ('' if absent and optional)."""
    for key, values in header.items():
        if key.startswith(prefix):
            return values[0]
    if required:
        raise RecordError(name, f"header key {prefix!r} is missing")
    return ""


def _per_channel(header, prefix, exclude=None):
    """Per-channel values of ``/v1/v2/...`` keys starting with ``prefix`` (channels 1-6, 7-12)."""
    found = {}
    for key, values in header.items():
        if not key.startswith(prefix) or (exclude and exclude in key):
            continue
        group = "C7" if "C7" in key else "C1"
        found.setdefault(group, values[0])
    result = []
    for group in ("C1", "C7"):
        raw = found.get(group, "").strip()
        if not raw:
            continue
        parts = raw.split("/")
        if parts and not parts[0].strip():
            parts = parts[1:]
        result.extend(part.strip() for part in parts)
    return result


def _orientation(label):
    """``(vertical, azimuth [deg] or None)`` of an orientation label such as ``N90W`` or ``V``."""
    text = label.split(";")[0].strip().upper().replace(" ", "")
    if text in _VERTICAL_NAMES:
        return True, None
    match = _BEARING.match(text)
    if match is None:
        return False, None
    first, angle, second = match.group(1), float(match.group(2)), match.group(3)
    if angle > 90.0:
        return False, None
    if first == "N":
        azimuth = angle if second == "E" else 360.0 - angle
    else:
        azimuth = 180.0 - angle if second == "E" else 180.0 + angle
    return False, azimuth % 360.0


def _coordinates(header):
    """Station coordinates from ``COORDENADAS DE LA ESTACION`` and ``ALTITUD``, or ``None``."""
    values = None
    for key, found in header.items():
        if key.startswith("COORDENADAS DE LA ESTACION"):
            values = found
            break
    if not values:
        return None
    latitude = longitude = None
    for value in values:
        text = value.upper()
        match = FLOAT_RE.search(text)
        if match is None:
            continue
        try:
            number = abs(parse_float(match.group()))
        except ValueError:
            continue
        hemisphere = text.rstrip()[-1:] if text.strip() else ""
        if "LAT" in text:
            latitude = -number if hemisphere == "S" else number
        elif "LON" in text:
            longitude = -number if hemisphere == "W" else number
    if latitude is None or longitude is None or not (
        math.isfinite(latitude) and math.isfinite(longitude)
        and abs(latitude) <= 90.0 and abs(longitude) <= 360.0
    ):
        return None
    elevation = 0.0
    raw = _first(header, "ALTITUD")
    match = FLOAT_RE.search(raw)
    if match is not None:
        try:
            elevation = parse_float(match.group())
        except ValueError:
            elevation = 0.0
        if not math.isfinite(elevation):
            elevation = 0.0
    return AttribDict(latitude=latitude, longitude=longitude, elevation=elevation)


def _seconds_of_day(raw):
    """Seconds since midnight of ``hh:mm:ss[.fff]``, or ``None``."""
    match = _TIME_OF_DAY.match(raw.strip())
    if match is None:
        return None
    hour, minute, second = int(match.group(1)), int(match.group(2)), float(match.group(3))
    if hour > 23 or minute > 59 or second >= 61.0:
        return None
    return hour * 3600.0 + minute * 60.0 + second


def _date(raw):
    """``UTCDateTime`` of midnight of a ``yyyy/mm/dd`` or ``dd/mm/yyyy`` date, or ``None``."""
    parts = re.split(r"[/\-.]", raw.strip())
    if len(parts) != 3 or not all(part.isdigit() for part in parts):
        return None
    numbers = [int(part) for part in parts]
    year, month, day = numbers if len(parts[0]) == 4 else numbers[::-1]
    return utc_time(year, month, day)


def _start_time(header):
    """First-sample time: the earthquake's date, corrected across midnight; ``None`` if unknown."""
    first = _seconds_of_day(_first(header, "HORA DE LA PRIMERA MUESTRA"))
    day = _date(_first(header, "FECHA DEL SISMO"))
    if first is None or day is None:
        return None
    start = day + first
    origin_seconds = _seconds_of_day(_first(header, "HORA EPICENTRO"))
    if origin_seconds is None:
        return start
    origin = day + origin_seconds
    if abs(start - origin) <= _HALF_DAY_S:
        return start
    # The record crosses midnight relative to the origin: take the nearest of the three days.
    return min((start - 86400.0, start, start + 86400.0), key=lambda t: abs(t - origin))


def _data_format(raw):
    """``(fields per row, field width)`` of a Fortran format such as ``3F10.4``, or ``None``."""
    match = _FORTRAN_FORMAT.search(raw or "")
    if match is None:
        return None
    count = int(match.group(1)) if match.group(1) else 1
    width = int(match.group(2))
    return (count, width) if count > 0 and width > 0 else None


def _data_start(lines, title_index, name):
    """Index of the first sample row: after the second ruler line below the data title."""
    rulers = 0
    for index in range(title_index + 1, min(len(lines), title_index + 12)):
        if lines[index].lstrip().startswith("-----"):
            rulers += 1
            if rulers == 2:
                return index + 1
    raise RecordError(name, "the data section has no column titles between two ruler lines")


def _parse_rows(lines, nchan, fmt, name):
    """Parse sample rows into an array ``(rows, nchan)``; a blank field is NaN."""
    width = fmt[1] if fmt is not None else None
    rows = []
    for lineno, line in enumerate(lines, start=1):
        if not line.strip():
            continue
        tokens = line.split()
        if len(tokens) != nchan and width is not None:
            # Fixed-width fields can touch when a value fills its field (-1234.5678-123.4567).
            text = line.rstrip()
            tokens = [field.strip() for field in fixed_fields(text, width, nchan)]
            if len(text) > nchan * width:
                tokens.append(text[nchan * width:])
        if len(tokens) != nchan:
            raise RecordError(
                name, f"data row {lineno} has {len(tokens)} values, expected {nchan} channels")
        row = []
        for token in tokens:
            if not token:
                row.append(math.nan)
                continue
            try:
                row.append(parse_float(token))
            except ValueError:
                raise RecordError(
                    name, f"acceleration samples: {token!r} is not a number (data row {lineno})"
                ) from None
        rows.append(row)
    return np.asarray(rows, dtype=np.float64).reshape(-1, nchan)


def _samples(data, npts, name):
    """Cut the stated number of rows, accepting only rows that repeat the last sample."""
    if data.shape[0] < npts:
        raise RecordError(
            name, f"is truncated: {npts} samples stated but {data.shape[0]} rows were found")
    extra = data[npts:]
    if extra.shape[0] and not (npts > 0 and np.array_equal(
            extra, np.broadcast_to(data[npts - 1], extra.shape))):
        raise RecordError(
            name, f"is longer than its header says: {npts} samples stated but"
                  f" {data.shape[0]} rows were found")
    return data[:npts], int(extra.shape[0])


def read_unam(filename, headonly: bool = False, **kwargs) -> Stream:
    """Read a Mexican ASA (UNAM) record into a Stream of one trace per channel, in m/s^2.

    Parameters
    ----------
    filename : str, os.PathLike or file-like
        The ASA file.
    headonly : bool, optional
        Read only the header; the traces then have no samples.
    **kwargs
        Ignored (obspy passes its own keywords to every plug-in).

    Returns
    -------
    obspy.Stream
        One trace per channel; ``stats.units == "m/s**2"``, ``stats.original_units`` the file's
        unit, ``stats.stated_peak_si`` the stated peak [m/s^2], the header in
        ``stats.shipblock_unam``.

    Raises
    ------
    RecordError
        If the header is incomplete or inconsistent, the file truncated or padded with other
        values, or samples are NaN/inf/implausible.
    UnitsError
        If the data unit is missing or not an acceleration.
    """
    name = source_name(filename)
    lines = read_text(filename).splitlines()
    if not any(_normalise_key(line).startswith(_TITLE) for line in lines[:20]):
        raise RecordError(name, f"is not an ASA file (no {_TITLE!r} title)")
    header, title_index = _parse_header(lines, name)

    unit_text = _first(header, "UNIDADES DE LOS DATOS")
    if not unit_text:
        raise UnitsError(name, "header key UNIDADES DE LOS DATOS is missing or empty")
    unit = unit_text.split("(")[0].strip()
    try:
        factor = si_factor(unit, name)
    except UnitsError:
        inner = re.search(r"\(([^)]*)\)", unit_text)
        if inner is None:
            raise
        unit = inner.group(1).strip()
        factor = si_factor(unit, name)

    orientations = _per_channel(header, "ORIENTACION")
    count_text = _first(header, "NUMERO DE CANALES")
    nchan = int(parse_number(count_text, name, "NUMERO DE CANALES")) if count_text else len(
        orientations)
    if not 1 <= nchan <= 12:
        raise RecordError(name, f"NUMERO DE CANALES={count_text!r} is not 1 to 12")
    if len(orientations) < nchan:
        raise RecordError(name, f"ORIENTACION gives {len(orientations)} orientations for"
                                f" {nchan} channels")
    npts_text = _per_channel(header, "NUM. TOTAL DE MUESTRAS")
    deltas_text = _per_channel(header, "INTERVALO DE MUESTREO")
    rates_text = _per_channel(header, "VEL. DE MUESTREO")
    peaks_text = _per_channel(header, "ACEL. MAX.", exclude="MUESTRA")
    if len(npts_text) < nchan:
        raise RecordError(name, "NUM. TOTAL DE MUESTRAS does not give every channel's count")
    npts = []
    for value in npts_text[:nchan]:
        count = parse_number(value, name, "NUM. TOTAL DE MUESTRAS")
        if count != int(count) or count <= 0:
            raise RecordError(name, f"NUM. TOTAL DE MUESTRAS {value!r} is not a sample count")
        npts.append(int(count))
    deltas = []
    for channel in range(nchan):
        delta_raw = deltas_text[channel] if channel < len(deltas_text) else ""
        rate_raw = rates_text[channel] if channel < len(rates_text) else ""
        rate = parse_number(rate_raw, name, "VEL. DE MUESTREO") if rate_raw else None
        if delta_raw:
            delta = check_sampling_interval(parse_number(delta_raw, name, "INTERVALO DE MUESTREO"), name)
            if rate is not None and abs(rate * delta - 1.0) > _RATE_TOLERANCE:
                raise RecordError(name, f"channel {channel + 1}: sampling interval {delta} s"
                                        f" and sampling rate {rate} /s disagree")
        elif rate is not None and rate > 0:
            delta = check_sampling_interval(1.0 / rate, name)
        else:
            raise RecordError(name, f"channel {channel + 1} has no sampling interval or rate")
        deltas.append(delta)

    fmt = _data_format(_first(header, "FORMATO DATOS"))
    start = _start_time(header)
    coordinates = _coordinates(header)
    station = _first(header, "CLAVE DE LA ESTACION").strip()
    simple = {key.lower(): " ".join(values).strip() for key, values in header.items()}

    data = None
    padding = 0
    if not headonly:
        first_row = _data_start(lines, title_index, name)
        rows = _parse_rows(lines[first_row:], nchan, fmt, name)
        data, padding = _samples(rows, max(npts), name)

    stream = Stream()
    horizontal = 0
    for channel in range(nchan):
        label = orientations[channel]
        vertical, azimuth = _orientation(label)
        if not vertical:
            horizontal += 1
        what = f"channel {channel + 1} ({label})"
        stats = {
            "network": "",
            "station": station,
            "location": "",
            "units": "m/s**2",
            "original_units": unit_text,
            "shipblock_unam": AttribDict(dict(simple, channel_number=channel + 1,
                                              orientation=label, padding_rows=padding)),
            **orientation_stats(1.0 / deltas[channel], vertical=vertical, azimuth_deg=azimuth,
                                positive_up=True, index=min(horizontal, 2) or 1),
        }
        if coordinates is not None:
            stats["coordinates"] = AttribDict(coordinates)
        if channel < len(peaks_text) and peaks_text[channel]:
            try:
                stated = abs(parse_float(peaks_text[channel]))
            except ValueError:
                stated = math.nan
            if math.isfinite(stated):
                stats["stated_peak_si"] = stated * factor
        if headonly:
            trace = make_trace([], deltas[channel], stats)
            trace.stats.npts = npts[channel]
        else:
            column = data[:, channel]
            tail = column[npts[channel]:]
            if tail.size and not np.all(np.isnan(tail)):
                raise RecordError(name, f"{what} has values beyond its {npts[channel]} samples")
            trace = make_trace(column[:npts[channel]], deltas[channel], stats)
            check_samples(trace.data, name, what)
            trace.data *= factor
            check_plausible_samples(trace.data, name, what)
        if start is not None:
            trace.stats.starttime = start
        stream.append(trace)
    return stream
