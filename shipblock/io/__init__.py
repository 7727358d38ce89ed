"""Reading ground-motion records into obspy Streams.

Formats obspy already reads (MiniSEED, SAC, K-NET, Kinemetrics EVT, ...) go straight to
:func:`obspy.read`. Formats obspy lacks are obspy waveform plug-ins registered through entry points
by shipblock's ``pyproject.toml`` (so ``obspy.read("x.AT2")`` works once shipblock is installed):

==================  =================================  ==========================================
format              module                             what
==================  =================================  ==========================================
SHIPBLOCK_AT2       :mod:`shipblock.io.at2`            PEER NGA ``.AT2`` (g)
SHIPBLOCK_COSMOS    :mod:`shipblock.io.cosmos`         COSMOS / CSMIP V1 and V2 (unit codes)
SHIPBLOCK_ESM       :mod:`shipblock.io.esm`            ESM ASCII (``UNITS`` key)
SHIPBLOCK_DMG       :mod:`shipblock.io.dmg`            CSMIP/CDMG V1, V2 and RAW (CESMD)
SHIPBLOCK_GEONET    :mod:`shipblock.io.geonet`         GeoNet V1A/V2A (New Zealand)
SHIPBLOCK_CWB       :mod:`shipblock.io.cwb`            CWB (Taiwan) ``.dat``
SHIPBLOCK_NSMN      :mod:`shipblock.io.nsmn`           AFAD/NSMN text (Turkey)
SHIPBLOCK_BHRC      :mod:`shipblock.io.bhrc`           BHRC V1 (Iran)
SHIPBLOCK_UNAM      :mod:`shipblock.io.unam`           UNAM ASA (Mexico)
SHIPBLOCK_RENADIC   :mod:`shipblock.io.renadic`        RENADIC ``.v1`` (Chile)
SHIPBLOCK_USC       :mod:`shipblock.io.usc`            USC volumes (Los Angeles)
SHIPBLOCK_SMC       :mod:`shipblock.io.smc`            USGS SMC
SHIPBLOCK_TEXT      :mod:`shipblock.io.text`           one/two-column text or CSV (stated units)
==================  =================================  ==========================================

K-NET and KiK-net files are read by obspy, renamed the SEED way, freed of the digitiser's offset
(NIED's mean of the record) and checked against their header's duration and ``Max. Acc.`` by
:func:`shipblock.io.knet.normalise_knet`.

:func:`read_record` wraps :func:`obspy.read` so that every failure becomes a
:class:`~shipblock.errors.RecordError` naming the file, so that a damaged file (a warning of
libmseed, a MiniSEED record cut short, an implausible interval, start time or sample) is refused
rather than read, and so that plain text files (which obspy cannot auto-detect, their units being
unknown) are read with the caller's ``units``. Its arguments are checked before the file is
opened (:mod:`shipblock.checks`, :func:`check_format`): a wrong one is a
:class:`~shipblock.errors.ParameterError` that names it.
"""

from __future__ import annotations

import os
import warnings
from importlib.metadata import entry_points

import numpy as np
import obspy
from obspy.core import AttribDict
from obspy.core.util.base import ENTRY_POINTS

from shipblock import checks
from shipblock.errors import ParameterError, ParameterTypeError, RecordError, ShipblockError
from shipblock.io import at2, bhrc, cosmos, cwb, dmg, esm, geonet, nsmn, renadic, screen, smc, text, unam, usc
from shipblock.io import mseed as mseed_checks
from shipblock.io._common import (
    MAX_DIGITIZATION_GAP_S,
    UNITS_GIVEN_KEY,
    PolarityReversalWarning,
    check_count_value,
    check_plausible_samples,
    check_sampling_interval,
    check_start_time,
    code_from_name,
    peek_text,
    sensitivity_sign,
)
from shipblock.io.knet import normalise_knet

# The reader entry points, and the checks of a record's numbers that the readers share and
# shipblock.records applies to the traces it converts.
__all__ = [
    "FORMATS",
    "MAX_DIGITIZATION_GAP_S",
    "PolarityReversalWarning",
    "UNITS_GIVEN_KEY",
    "check_count_value",
    "check_format",
    "check_reader_keywords",
    "check_plausible_samples",
    "check_sampling_interval",
    "code_from_name",
    "known_formats",
    "read_record",
    "reader_keywords",
    "sensitivity_sign",
]

#: Words of a reader's warning that mean the file is damaged: libmseed's reports (truncated
#: records, Steim integrity checks) and truncation notices. A damaged file is refused rather than
#: read with samples changed or missing.
DAMAGE_WORDS = ("end of file", "truncated", "integrity check", "last record only has",
                "not a seed record", "not enough to constitute")

#: The formats shipblock adds to obspy: name -> (detector, reader).
FORMATS = {
    at2.FORMAT: (at2.is_at2, at2.read_at2),
    cosmos.FORMAT: (cosmos.is_cosmos, cosmos.read_cosmos),
    esm.FORMAT: (esm.is_esm, esm.read_esm),
    dmg.FORMAT: (dmg.is_dmg, dmg.read_dmg),
    geonet.FORMAT: (geonet.is_geonet, geonet.read_geonet),
    cwb.FORMAT: (cwb.is_cwb, cwb.read_cwb),
    nsmn.FORMAT: (nsmn.is_nsmn, nsmn.read_nsmn),
    bhrc.FORMAT: (bhrc.is_bhrc, bhrc.read_bhrc),
    unam.FORMAT: (unam.is_unam, unam.read_unam),
    renadic.FORMAT: (renadic.is_renadic, renadic.read_renadic),
    usc.FORMAT: (usc.is_usc, usc.read_usc),
    smc.FORMAT: (smc.is_smc, smc.read_smc),
    text.FORMAT: (text.is_text, text.read_text_record),
}


#: Reader keywords of shipblock's own formats that are numbers, and how each is checked:
#: ``dt`` of a one-column text file [s], the rate [Hz] uneven SMC/USC pairs are interpolated
#: onto, the interval [s] of a DMG resampling.
_NUMERIC_KEYWORDS = {
    "dt": checks.time_step,
    "resample_interval": checks.time_step,
    "resample_rate": lambda value, name: checks.real(
        value, name, low=1.0 / checks.MAX_TIME_STEP, high=1.0 / checks.MIN_TIME_STEP,
        units="Hz"),
}


#: Keywords that only some of shipblock's readers take: given for a file of another format they
#: would be ignored without a word (``dt`` for an AT2 file, which states its own interval).
_FORMAT_KEYWORDS = ("dt", "resample_rate", "resample_interval", "data_type")


#: Keywords of :func:`obspy.read` and of shipblock's own readers: known without loading the
#: other plug-ins.
_OWN_READER_KEYWORDS = frozenset(set(checks.keyword_names(obspy.read, 1)).union(
    *(checks.keyword_names(reader, 1) for _, reader in FORMATS.values())))


def reader_keywords() -> frozenset[str]:
    """The keywords a record read passes on to a reader: those of :func:`obspy.read` and of
    the reader of every installed obspy waveform plug-in (obspy's formats and shipblock's).

    Loads every plug-in's reader (about half a second): :func:`check_reader_keywords` calls it
    only for a keyword that is not one of obspy.read's or shipblock's readers'.
    """
    names = set(_OWN_READER_KEYWORDS)
    installed = entry_points()  # one scan of the installed packages' metadata
    for name in ENTRY_POINTS.get("waveform", {}):
        for point in installed.select(group=f"obspy.plugin.waveform.{name}", name="readFormat"):
            try:
                names.update(checks.keyword_names(point.load(), 1))
            except (ImportError, AttributeError):  # a broken plug-in has no keywords to offer
                continue
    return frozenset(names)


def check_reader_keywords(given, function: str, own=()) -> None:
    """Refuse a keyword that no reader takes (a misspelling: ``unit=`` for ``units=``).

    Parameters
    ----------
    given : mapping
        The keywords passed on to the readers.
    function : str
        The public function they were given to, for the message.
    own : iterable of str
        That function's own parameters (accepted, and offered as the closest match).

    Raises
    ------
    ParameterTypeError
        Naming the keyword and the closest accepted one (:func:`shipblock.checks.keywords`).
    """
    accepted = _OWN_READER_KEYWORDS.union(own)
    if not set(given) <= accepted:
        checks.keywords(given, accepted | reader_keywords(), function, listed=set(own) or None,
                        others="a keyword of obspy.read or of a format's reader "
                               "(shipblock.io.reader_keywords())" if own else "")


def known_formats() -> list[str]:
    """The waveform format names :func:`obspy.read` knows, with shipblock's own (sorted)."""
    return sorted(set(ENTRY_POINTS.get("waveform", {})) | set(FORMATS))


def check_format(value, name: str = "format") -> str | None:
    """``value`` checked to be ``None`` (detect the format) or a waveform format obspy knows.

    Parameters
    ----------
    value : object
        The argument; case-insensitive (``"mseed"`` is ``"MSEED"``).
    name : str
        Its name, for the message.

    Returns
    -------
    str or None
        The format name in upper case.

    Raises
    ------
    ParameterTypeError, ParameterError
        Naming ``name`` and listing the known formats.
    """
    if value is None:
        return None
    formats = known_formats()
    listed = "None (detect it) or one of " + ", ".join(formats)
    if not isinstance(value, str):
        raise ParameterTypeError(f"{name} must be {listed}, got {type(value).__name__}"
                                 f" {value!r}")
    if value.upper() not in formats:
        raise ParameterError(f"{name} must be {listed}, got {value!r}")
    return value.upper()


def _looks_like_plain_text(path) -> bool:
    """Tell whether a file is text whose non-comment lines are mostly numbers."""
    content = peek_text(path)
    if content is None:
        return False
    lines = [ln for ln in content.splitlines()[:50] if ln.strip()]
    numeric = 0
    for line in lines:
        tokens = line.replace(",", " ").replace(";", " ").split()
        try:
            [float(t) for t in tokens]
        except ValueError:
            continue
        numeric += 1
    return numeric >= max(1, len(lines) // 2)


def _is_damage(warning) -> bool:
    """Whether a warning caught while reading says the file is damaged."""
    if type(warning.message).__name__ == "InternalMSEEDWarning":
        return True  # every libmseed diagnostic is about a record it could not decode as stored
    message = str(warning.message).lower()
    return any(word in message for word in DAMAGE_WORDS)


def _check_mseed(stream, name: str) -> None:
    """Refuse a MiniSEED file whose bytes are not all in the records obspy read, or whose
    encoding byte hides Steim frames; attach a full SEED volume's own responses.

    libmseed skips a record cut short at the end of the file without a word when too little of
    it is left to parse; the records read then cover fewer bytes than the file holds. The control
    headers of a full SEED volume (its dataless part) are counted as read
    (:mod:`shipblock.io.mseed`).
    """
    mseed = [tr.stats.mseed for tr in stream if tr.stats.get("_format") == "MSEED"
             and "mseed" in tr.stats]
    if not mseed or "filesize" not in mseed[0]:
        return
    with open(name, "rb") as fh:
        raw = fh.read()  # every record's encoding byte: obspy reports only the first record's
    control = mseed_checks.control_header_bytes(raw)
    mseed_checks.check_encodings(raw, name)
    used = control + sum(int(m.number_of_records) * int(m.record_length) for m in mseed)
    size = int(mseed[0].filesize)
    if used != size:
        what = ("left over: a record cut short (truncated file?)" if size > used
                else "missing")
        raise RecordError(
            name, f"is damaged: its records hold {used} bytes but the file has {size}"
            f" ({abs(size - used)} bytes {what})"
        )
    if control:
        notes: list[str] = []
        mseed_checks.attach_volume_responses(stream, name, notes)
        for trace in stream:
            trace.stats.seed_volume = AttribDict(control_header_bytes=control, notes=notes)
        for note in notes:
            warnings.warn(f"{name}: full SEED volume: {note}", stacklevel=3)


def _check_trace(trace, name: str) -> None:
    """Refuse a trace with an implausible sampling interval, start time or acceleration."""
    what = f"channel {trace.id}"
    fmt = trace.stats.get("_format", "")
    check_sampling_interval(trace.stats.delta, name,
                            f"{what}: sampling interval{' (SAC DELTA)' if fmt == 'SAC' else ''}")
    check_start_time(trace.stats.starttime, name, what)
    if np.issubdtype(trace.data.dtype, np.floating):
        bad = ~np.isfinite(trace.data)
        if bad.any():
            raise RecordError(name, f"{what} has {int(bad.sum())} NaN/inf samples (first at"
                                    f" index {int(np.flatnonzero(bad)[0])})")
        if trace.stats.get("units") == "m/s**2":
            check_plausible_samples(trace.data, name, what)


def _check_format_keywords(stream, name: str, kwargs) -> None:
    """Refuse a format's own keyword (:data:`_FORMAT_KEYWORDS`) given for a file of a format
    whose reader does not take it, naming the keyword and the formats that do (a
    :class:`RecordError`, as a unit that contradicts the file's: the value is good, the file is
    not one it suits)."""
    fmt = getattr(stream[0].stats, "_format", None)
    reader = FORMATS[fmt][1] if fmt in FORMATS else None
    takes = set(checks.keyword_names(reader, 1)) if reader is not None else set()
    for key in _FORMAT_KEYWORDS:
        if kwargs.get(key) is None or key in takes:
            continue
        which = [f for f, (_, r) in FORMATS.items() if key in checks.keyword_names(r, 1)]
        raise RecordError(
            name, f"{key}={kwargs[key]!r} applies to {' and '.join(which)} files only; this "
            f"file is {fmt or 'of another format'}, whose reader does not use it"
            f" ({checks.how_to_leave_out(key)})")


def read_record(path, format: str | None = None, units: str | None = None, **kwargs):
    """Read one record file into an obspy Stream.

    Parameters
    ----------
    path : str or os.PathLike
        The file.
    format : str, optional
        An obspy format name (``"MSEED"``, ``"SAC"``, ``"KNET"``, ``"SHIPBLOCK_AT2"``,
        ``"SHIPBLOCK_TEXT"``, ...; case-insensitive); auto-detected when omitted.
    units : str, optional
        Acceleration unit of a plain text file (passed to the ``SHIPBLOCK_TEXT`` reader only);
        any unit :func:`shipblock.checks.unit` knows.
    **kwargs
        Passed to the reader: ``dt`` [s] for a one-column text file, ``data_type``
        (``"acceleration"``) for an SMC file whose header says ``0 UNKNOWN``, ``resample_rate`` [Hz] for
        SMC and USC files, ``resample_interval`` [s] for DMG files (each checked: an interval
        within 1e-4..1 s, a rate within 1..1e4 Hz; the grid of a record digitized at uneven
        times, refused for an evenly sampled file, which it would leave as stored), or obspy's own keywords (those of
        :func:`obspy.read` and of its format readers; any other is refused, see
        :func:`check_reader_keywords`).

    Returns
    -------
    obspy.Stream
        The traces as the file holds them (each tagged with ``stats.source_file``). Traces of
        shipblock's own formats are already in m/s^2 (``stats.units``); others are as stored
        (counts, or whatever the file holds).

    Raises
    ------
    ParameterError
        If an argument is of the wrong type or value (also a :class:`TypeError` for a wrong
        type): a keyword no reader takes (the closest named), a path that is not a ``str`` or
        :class:`os.PathLike`, a format obspy does not
        know, an unknown unit, a ``dt``, ``resample_rate`` or ``resample_interval`` out of range.
    RecordError
        If the file does not exist or is a folder, its format is unknown (a file over 16 MB whose
        start shows no record format is refused before obspy's sniffing, unless ``format`` is
        given: :mod:`shipblock.io.screen`), or it is corrupt or
        truncated: any libmseed diagnostic (a Steim integrity check, a record cut short),
        MiniSEED records that do not account for every byte of the file (a full SEED volume's
        control headers count), a record whose plain encoding hides Steim frames; a format's own
        option (``dt``, ``resample_rate``, ``resample_interval``, ``data_type``) given for a file
        whose reader does not take it, or ``resample_rate``/``resample_interval`` given for an
        evenly sampled file; NaN/inf samples; a
        sampling interval outside 1e-4..1 s; a start time outside 1900-2200; samples in m/s^2
        above 100 g.
    """
    check_reader_keywords(kwargs, "read_record", ("path", "format", "units"))
    if isinstance(path, (str, os.PathLike)) and os.path.islink(path) and not os.path.exists(path):
        raise RecordError(os.fspath(path), f"is a broken symbolic link (to"
                                           f" {os.readlink(path)!r}, which does not exist)")
    name = checks.existing_file(path, "path", "a record file",
                                "; read_motions() reads a folder of records")
    format = check_format(format)  # noqa: A001 - obspy's name for it
    if units is not None:
        checks.unit(units, "units")
    for key, check in _NUMERIC_KEYWORDS.items():
        if kwargs.get(key) is not None:
            kwargs[key] = check(kwargs[key], key)
    if kwargs.get("data_type") is not None:
        checks.choice(kwargs["data_type"], "data_type", smc.STATED_DATA_TYPES)
    if format == text.FORMAT:
        kwargs["units"] = units
    if format is None:
        screen.screen_large_file(name)  # before obspy's sniffing, which reads a large file whole
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        try:
            stream = obspy.read(name, format=format, **kwargs)
        except ShipblockError:
            raise
        except TypeError as exc:
            if "Unknown format" not in str(exc) and "not supported" not in str(exc):
                raise RecordError(name, f"cannot be read: {exc}") from exc
            if format is None and _looks_like_plain_text(name):
                stream = text.read_text_record(name, units=units, **kwargs)
                for trace in stream:
                    trace.stats._format = text.FORMAT
            else:
                raise RecordError(
                    name,
                    f"unknown format ({exc}); known formats: obspy's and "
                    + ", ".join(FORMATS),
                ) from exc
        except Exception as exc:  # noqa: BLE001 - obspy readers raise anything on corrupt files
            raise RecordError(name, f"cannot be read (corrupt or truncated?): {exc}") from exc
    for warning in caught:
        message = str(warning.message)
        if _is_damage(warning):
            raise RecordError(name, f"is damaged (truncated or corrupt): {message.strip()}")
        warnings.warn_explicit(warning.message, warning.category, warning.filename, warning.lineno)
    if len(stream) == 0:
        raise RecordError(name, "holds no traces")
    _check_format_keywords(stream, name, kwargs)
    empty = [tr.id for tr in stream if tr.stats.npts == 0 or len(tr.data) == 0]
    if empty:
        raise RecordError(name, f"channel {empty[0]} has no samples (corrupt or truncated file?)")
    _check_mseed(stream, name)
    for trace in stream:
        _check_trace(trace, name)
    normalise_knet(stream, name)
    for trace in stream:
        trace.stats.source_file = name
    return stream
