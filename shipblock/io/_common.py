"""Helpers shared by the text-format readers (private).

The readers accept what :func:`obspy.read` hands to a plug-in: a path (``str`` or
:class:`pathlib.Path`) or an open binary/text file object. Detection (``is_*``) functions must never
raise, so they go through :func:`peek_text`, which returns ``None`` for anything that is not a
readable text file.
"""

from __future__ import annotations

import math
import os
import re
import warnings

import numpy as np
from obspy import Trace, UTCDateTime

from shipblock.checks import MAX_ACCELERATION, MAX_TIME_STEP, MIN_TIME_STEP, how_to_leave_out
from shipblock.errors import RecordError

#: Number of bytes read by the format-detection functions [bytes].
PEEK_BYTES = 8192

#: Largest text record a reader accepts [bytes]; guards against feeding a huge binary file to a
#: text parser (the largest real accelerogram text files are a few tens of MB).
MAX_TEXT_BYTES = 512 * 1024 * 1024

# The plausibility limits are the solver's (one home, :mod:`shipblock.checks`), so that whatever a
# reader accepts the solver runs: 100 g, and sampling intervals of 1e-4..1 s.
MAX_ACCELERATION_SI = MAX_ACCELERATION
MIN_SAMPLING_INTERVAL_S = MIN_TIME_STEP
MAX_SAMPLING_INTERVAL_S = MAX_TIME_STEP

#: Range of times a record may start in (UTC). The oldest strong-motion records are of 1933 (Long
#: Beach); files that state no start time are put at the epoch, 1970. A start outside comes from a
#: damaged time field (a MiniSEED year, a SAC ``B`` of 1e30), not from an earthquake.
EARLIEST_START = UTCDateTime(1900, 1, 1)
LATEST_START = UTCDateTime(2200, 1, 1)

#: Range of the acceleration (or velocity) that one count of raw data stands for [m/s^2 or m/s per
#: count], from a StationXML sensitivity (its inverse), a SAC ``SCALE`` or a K-NET/EVT
#: calibration. Real instruments lie between 4e-10 (a broadband seismometer, 2.5e9 counts/(m/s))
#: and 7e-6 (a strong-motion accelerometer, 1.3e5 counts/(m/s^2)); data already in physical units
#: have 1 (SI) or 9.8 (g). The range leaves two orders of margin on each side; beyond it the
#: factor is a damaged number (a sensitivity of 1e300 or 1e-300), not an instrument.
MIN_COUNT_VALUE_SI = 1e-12
MAX_COUNT_VALUE_SI = 1e3

#: Sampling rate onto which unevenly digitized (time, value) records are interpolated
#: [samples/s].
DEFAULT_RESAMPLE_RATE_HZ = 200.0

#: Longest gap between two digitized points bridged by interpolation [s]. The real files'
#: largest gap is 0.037 s (SMC) and 0.013 s (USC); a quarter second without a point would hide
#: the 1-25 Hz motion of the record, so a longer gap is taken for a corrupt time column.
MAX_DIGITIZATION_GAP_S = 0.25

#: Key of ``trace.stats`` a reader sets to ``True`` when the unit of the samples is the one the
#: caller gave (``units=``, command line ``--units``) because the file states none, so that the
#: provenance says "given with --units", not "from the file header".
UNITS_GIVEN_KEY = "units_given"

#: A floating-point number as written by Fortran or C (``1.0``, ``-.25E-03``, ``3``, ``1.2D+01``).
FLOAT_RE = re.compile(r"[-+]?(?:\d+\.?\d*|\.\d+)(?:[EeDd][-+]?\d+)?")

def source_name(source) -> str:
    """Return a printable name for a path or file object.

    Parameters
    ----------
    source : str, os.PathLike or file-like
        What a reader was given.

    Returns
    -------
    str
        The path, the file object's ``name`` attribute, or ``"<file object>"``.
    """
    if isinstance(source, (str, os.PathLike)):
        return os.fspath(source)
    name = getattr(source, "name", None)
    return str(name) if isinstance(name, (str, os.PathLike)) else "<file object>"


def _decode(raw: bytes) -> str | None:
    """Decode bytes as text, or return ``None`` if they look binary."""
    if b"\x00" in raw:
        return None
    try:
        return raw.decode("utf-8")
    except UnicodeDecodeError:
        pass
    text = raw.decode("latin-1")
    # Latin-1 decodes anything; insist on mostly printable characters.
    printable = sum(ch.isprintable() or ch in "\r\n\t" for ch in text)
    return text if printable >= 0.98 * max(len(text), 1) else None


def _read_bytes(source, limit: int | None) -> bytes:
    """Read up to ``limit`` bytes from a path or file object, restoring the file position."""
    if isinstance(source, (str, os.PathLike)):
        with open(source, "rb") as fh:
            return fh.read(-1 if limit is None else limit)
    position = source.tell() if hasattr(source, "tell") else None
    try:
        raw = source.read(-1 if limit is None else limit)
    finally:
        if position is not None and hasattr(source, "seek"):
            source.seek(position)
    if isinstance(raw, str):
        raw = raw.encode("utf-8", errors="replace")
    return raw


def peek_text(source) -> str | None:
    """Return the first :data:`PEEK_BYTES` of a file as text, or ``None`` (never raises).

    Parameters
    ----------
    source : str, os.PathLike or file-like
        A path or an open file.

    Returns
    -------
    str or None
        The beginning of the file as text; ``None`` if it cannot be read or looks binary.
    """
    try:
        raw = _read_bytes(source, PEEK_BYTES)
    except Exception:  # noqa: BLE001 - detection must never raise
        return None
    if not raw:
        return None
    # A multi-byte UTF-8 character may be cut at the end of the peek window.
    for cut in range(4):
        text = _decode(raw[: len(raw) - cut] if cut else raw)
        if text is not None:
            return text
    return None


def read_text(source) -> str:
    """Read a whole text file.

    Parameters
    ----------
    source : str, os.PathLike or file-like
        A path or an open file.

    Returns
    -------
    str
        The file's text.

    Raises
    ------
    RecordError
        If the file cannot be opened, is too large, or is not text.
    """
    name = source_name(source)
    try:
        raw = _read_bytes(source, MAX_TEXT_BYTES + 1)
    except OSError as exc:
        raise RecordError(name, f"cannot be opened: {exc}") from exc
    if len(raw) > MAX_TEXT_BYTES:
        raise RecordError(name, f"is larger than {MAX_TEXT_BYTES} bytes; not a text record")
    text = _decode(raw)
    if text is None:
        raise RecordError(name, "is not a text file (binary content)")
    return text


def parse_float(token: str) -> float:
    """Parse one Fortran/C number, accepting the ``D`` exponent; raise ``ValueError`` if bad."""
    return float(token.strip().replace("D", "E").replace("d", "e"))


def parse_number(raw: str, name: str, what: str) -> float:
    """Parse one finite header number, or raise a :class:`RecordError` naming it.

    Parameters
    ----------
    raw : str
        The number as written (Fortran ``D`` exponents accepted).
    name : str
        File name, for error messages.
    what : str
        What the number is, put before it in error messages (e.g. ``"NO. OF POINTS"``).

    Returns
    -------
    float
        The value.

    Raises
    ------
    RecordError
        If ``raw`` is not a number, or is NaN or infinite.
    """
    try:
        value = parse_float(raw)
    except ValueError:
        raise RecordError(name, f"{what} {raw!r} is not a number") from None
    if not math.isfinite(value):
        raise RecordError(name, f"{what} {raw!r} is not a finite number")
    return value


def fixed_fields(line: str, width: int, count: int | None = None) -> list[str]:
    """Cut a line into Fortran fixed-width fields (not stripped).

    Parameters
    ----------
    line : str
        The line (strip its end first if trailing blanks must not make fields).
    width : int
        Field width [characters].
    count : int, optional
        Number of fields to cut, whatever the line's length (fields beyond its end are ``""``);
        by default as many as the line holds, the last one possibly shorter.

    Returns
    -------
    list of str
        The fields.
    """
    if count is None:
        return [line[i : i + width] for i in range(0, len(line), width)]
    return [line[k * width : (k + 1) * width] for k in range(count)]


def parse_free_floats(lines, name: str, what: str) -> np.ndarray:
    """Parse whitespace-separated numbers from lines of text.

    Parameters
    ----------
    lines : iterable of str
        Lines holding only numbers.
    name : str
        File name, for error messages.
    what : str
        What the numbers are (for error messages), e.g. ``"acceleration samples"``.

    Returns
    -------
    numpy.ndarray
        The numbers, float64.

    Raises
    ------
    RecordError
        If a token is not a number.
    """
    values = []
    for lineno, line in enumerate(lines, start=1):
        for token in line.replace(",", " ").split():
            try:
                values.append(parse_float(token))
            except ValueError:
                raise RecordError(
                    name, f"{what}: {token!r} is not a number (data line {lineno})"
                ) from None
    return np.asarray(values, dtype=np.float64)


def check_samples(data: np.ndarray, name: str, what: str) -> None:
    """Refuse empty records and non-finite samples.

    Parameters
    ----------
    data : numpy.ndarray
        Samples.
    name : str
        File name, for the error message.
    what : str
        Which record or channel (for the error message).

    Raises
    ------
    RecordError
        If there are no samples, or any sample is NaN or infinite.
    """
    if data.size == 0:
        raise RecordError(name, f"{what} has no samples (zero-length record)")
    bad = ~np.isfinite(data)
    if bad.any():
        first = int(np.flatnonzero(bad)[0])
        raise RecordError(
            name, f"{what} has {int(bad.sum())} NaN/inf samples (first at index {first})"
        )


def check_delta(delta: float, name: str) -> float:
    """Validate a sampling interval [s] and return it as a float.

    Raises
    ------
    RecordError
        If the interval is not a finite positive number.
    """
    if not (isinstance(delta, (int, float)) and math.isfinite(delta) and delta > 0):
        raise RecordError(name, f"sampling interval {delta!r} s is not a positive number")
    return float(delta)


def check_sampling_interval(delta: float, name: str, what: str = "sampling interval") -> float:
    """Validate a sampling interval [s] against the plausible range and return it as a float.

    Parameters
    ----------
    delta : float
        Sampling interval [s].
    name : str
        File name, for the error message.
    what : str, optional
        Words put before the interval in the error message.

    Returns
    -------
    float
        The interval [s].

    Raises
    ------
    RecordError
        If the interval is not a finite positive number, or lies outside
        [:data:`MIN_SAMPLING_INTERVAL_S`, :data:`MAX_SAMPLING_INTERVAL_S`].
    """
    delta = check_delta(delta, name)
    if not MIN_SAMPLING_INTERVAL_S <= delta <= MAX_SAMPLING_INTERVAL_S:
        raise RecordError(name, f"{what} {delta:g} s is outside"
                                f" [{MIN_SAMPLING_INTERVAL_S:g}, {MAX_SAMPLING_INTERVAL_S:g}] s")
    return delta


def check_start_time(starttime, name: str, what: str = "the record") -> None:
    """Refuse a start time outside [:data:`EARLIEST_START`, :data:`LATEST_START`).

    Parameters
    ----------
    starttime : obspy.UTCDateTime
        Time of the first sample.
    name : str
        File name, for the error message.
    what : str, optional
        Which record or channel (for the error message).

    Raises
    ------
    RecordError
        If the time lies outside the range (a damaged time field).
    """
    if not EARLIEST_START <= starttime < LATEST_START:
        # str() of such a time may overflow Python's datetime: say it in seconds.
        raise RecordError(
            name, f"{what} starts {float(starttime.ns) / 1e9:.6g} s from 1970-01-01, outside"
            f" {EARLIEST_START.year}-{LATEST_START.year} (a damaged time field)"
        )


def check_count_value(value_si: float, name: str, what: str) -> float:
    """Check what one count of raw data stands for, in SI units per count.

    Parameters
    ----------
    value_si : float
        Acceleration [m/s^2] (or velocity [m/s]) of one count; negative for a channel of reversed
        polarity.
    name : str
        File name, for the error message.
    what : str
        Where the value comes from, e.g. ``"StationXML x.xml: sensitivity 4.2e5 counts/(M/S**2)"``.

    Returns
    -------
    float
        The value.

    Raises
    ------
    RecordError
        If the value is not finite, is zero, or its magnitude lies outside
        [:data:`MIN_COUNT_VALUE_SI`, :data:`MAX_COUNT_VALUE_SI`].
    """
    if not (math.isfinite(value_si) and MIN_COUNT_VALUE_SI <= abs(value_si) <= MAX_COUNT_VALUE_SI):
        raise RecordError(
            name, f"{what} makes one count {value_si:.3g} in SI units, outside"
            f" [{MIN_COUNT_VALUE_SI:g}, {MAX_COUNT_VALUE_SI:g}] (a damaged number, not an"
            " instrument)"
        )
    return float(value_si)


def check_plausible_samples(data_si: np.ndarray, name: str, what: str) -> float:
    """Refuse accelerations larger than :data:`MAX_ACCELERATION_SI`; return the peak.

    Parameters
    ----------
    data_si : numpy.ndarray
        Finite, non-empty samples [m/s^2].
    name : str
        File name, for the error message.
    what : str
        Which record or channel (for the error message).

    Returns
    -------
    float
        The largest absolute sample [m/s^2].

    Raises
    ------
    RecordError
        If a sample exceeds :data:`MAX_ACCELERATION_SI` in magnitude.
    """
    peak = float(np.max(np.abs(data_si)))
    if peak > MAX_ACCELERATION_SI:
        raise RecordError(name, f"{what} has a sample of {peak:.3g} m/s^2, not a ground"
                                " acceleration (corrupt number or wrong unit?)")
    return peak


def utc_time(year: int, month: int, day: int, hour: int = 0, minute: int = 0,
             second: float = 0.0) -> UTCDateTime | None:
    """The UTC time of calendar fields, or ``None`` if they name no valid time.

    Parameters
    ----------
    year, month, day, hour, minute : int
        Calendar fields.
    second : float, optional
        Seconds [s] added after the minute (may hold a fraction).

    Returns
    -------
    obspy.UTCDateTime or None
        The time; ``None`` for an impossible date (the caller words the error).
    """
    try:
        return UTCDateTime(year, month, day, hour, minute) + second
    except Exception:  # noqa: BLE001 - obspy raises several types for impossible dates
        return None


def resample_pairs(times, values, rate_hz: float, name: str):
    """Interpolate unevenly digitized (time, value) pairs onto an even grid.

    Parameters
    ----------
    times : numpy.ndarray
        Digitized times [s], non-decreasing.
    values : numpy.ndarray
        Values at those times (any unit).
    rate_hz : float
        Sampling rate of the grid [samples/s].
    name : str
        File name, for error messages.

    Returns
    -------
    tuple
        ``(samples, first_time_s, merged)``: the samples at ``first_time_s + k / rate_hz`` up to
        the last digitized time, the first digitized time [s], and how many repeated times were
        merged (their values averaged).

    Raises
    ------
    RecordError
        If times go backwards, jump by more than :data:`MAX_DIGITIZATION_GAP_S`, are not finite,
        or span no time.
    """
    times = np.asarray(times, dtype=np.float64)
    values = np.asarray(values, dtype=np.float64)
    if not (isinstance(rate_hz, (int, float)) and math.isfinite(rate_hz) and rate_hz > 0):
        raise RecordError(name, f"resample rate {rate_hz!r} Hz is not a positive number")
    if times.size < 2 or not np.all(np.isfinite(times)):
        raise RecordError(name, "digitized times are missing or not finite")
    steps = np.diff(times)
    back = np.flatnonzero(steps < 0)
    if back.size:
        i = int(back[0])
        raise RecordError(
            name, f"digitized times go backwards at pair {i + 2} ({times[i]:g} s then"
            f" {times[i + 1]:g} s)"
        )
    if steps.max() > MAX_DIGITIZATION_GAP_S:
        i = int(np.argmax(steps))
        raise RecordError(
            name, f"digitized times jump by {steps[i]:g} s at pair {i + 2} (more than"
            f" {MAX_DIGITIZATION_GAP_S:g} s; corrupt time column)"
        )
    unique, inverse = np.unique(times, return_inverse=True)
    if unique.size < 2:
        raise RecordError(name, "digitized times span no time")
    merged = times.size - unique.size
    if merged:
        values = np.bincount(inverse, weights=values) / np.bincount(inverse)
    span = unique[-1] - unique[0]
    # The small allowance keeps a last digitized time that falls on the grid.
    count = int(math.floor(span * rate_hz + 1e-6)) + 1
    grid = unique[0] + np.arange(count) / rate_hz
    return np.interp(grid, unique, values), float(unique[0]), merged


def check_resampling_applies(name: str, keyword: str, value, uneven: bool, stored: str) -> None:
    """Refuse a resampling read option given for a file that holds no uneven samples.

    ``resample_rate`` (SMC, USC) and ``resample_interval`` (DMG) set the even grid onto which
    unevenly digitized (time, value) pairs are interpolated, as gmprocess's read option
    ``resample_rate`` does (its readers interpolate only the samples that are not evenly spaced).
    A record sampled evenly as stored is returned as stored: resampling it needs an anti-alias
    filter, which is a processing step, not a reader's. Given for such a file the option would
    have no effect and the caller would believe the record resampled, so it is refused.

    Parameters
    ----------
    name : str
        The file, for the message.
    keyword : str
        The option (a key of :data:`shipblock.checks.READ_OPTIONS`).
    value : float or None
        Its value; ``None`` (not given) is always accepted.
    uneven : bool
        Whether the file held uneven pairs, interpolated at ``value``.
    stored : str
        How the file is sampled, for the message (``"evenly sampled at 200 samples/s"``).

    Raises
    ------
    RecordError
        Naming the file, the option, why it does not apply and how to resample instead.
    """
    if value is None or uneven:
        return
    raise RecordError(
        name, f"{keyword}={value!r} cannot apply: the record is {stored} as stored, with no"
        f" unevenly digitized (time, value) pairs, and {keyword} only sets the grid such pairs"
        f" are interpolated onto (the samples would be returned unchanged). To change an even"
        f" record's rate use the anti-aliased processing step 'resample' (or align='resample'"
        f" across components); {how_to_leave_out(keyword)}")


def make_trace(data, delta: float, stats: dict) -> Trace:
    """Build an obspy Trace of float64 samples.

    Parameters
    ----------
    data : array_like
        Samples (already in the unit given in ``stats["units"]``).
    delta : float
        Sampling interval [s].
    stats : dict
        Extra header entries (network, station, channel, units, format header, ...).

    Returns
    -------
    obspy.Trace
        The trace.
    """
    trace = Trace(data=np.ascontiguousarray(data, dtype=np.float64))
    trace.stats.delta = delta
    for key, value in stats.items():
        trace.stats[key] = value
    return trace


#: Largest departure from north or east [deg] for which a horizontal is named N or E.
CARDINAL_TOLERANCE_DEG = 1.0


def code_from_name(text: str) -> str:
    """A code made of a name: each run of anything but letters, digits and ``_`` becomes one
    ``-``, none at either end.

    For a station a file names in words only (PEER AT2) and for record ids: such a code holds no
    ``.`` (the separator of a SEED id ``NET.STA.LOC.CHA``), no space and nothing a file name
    would have to quote, and different names stay different.

    Examples
    --------
    >>> code_from_name("Anaheim - Lakeview & Riverdale")
    'Anaheim-Lakeview-Riverdale'
    >>> code_from_name("Mt. Wilson - CIT Seis Sta")
    'Mt-Wilson-CIT-Seis-Sta'
    """
    return re.sub(r"[^A-Za-z0-9_]+", "-", text).strip("-")


def band_code(sampling_rate: float) -> str:
    """SEED band code of an accelerometer channel for its sampling rate [Hz].

    ``"H"`` at 80 Hz or more, ``"B"`` from 10 Hz, ``"M"`` from 1 Hz, ``"L"`` below (SEED manual,
    appendix A, for the broadband codes accelerometers share with seismometers).
    """
    if sampling_rate >= 80.0:
        return "H"
    if sampling_rate >= 10.0:
        return "B"
    if sampling_rate > 1.0:
        return "M"
    return "L"


def horizontal_index(azimuth_deg: float) -> int:
    """SEED orientation digit of a horizontal that is not along north or east.

    ``1`` for an axis nearer north-south (or exactly on a diagonal through the north-east
    quadrant), ``2`` for one nearer east-west.

    Parameters
    ----------
    azimuth_deg : float
        Azimuth of the positive direction [deg clockwise from north].

    Returns
    -------
    int
        ``1`` or ``2``.
    """
    axis = azimuth_deg % 180.0
    return 1 if axis <= 45.0 or axis > 135.0 else 2


def orientation_stats(sampling_rate: float, *, vertical: bool, azimuth_deg: float | None = None,
                      positive_up: bool = True, index: int = 1) -> dict:
    """Channel code, azimuth and dip of an accelerometer component, as ``trace.stats`` entries.

    Parameters
    ----------
    sampling_rate : float
        Samples per second [Hz] (chooses the band code).
    vertical : bool
        Whether the component is vertical.
    azimuth_deg : float, optional
        Azimuth of a horizontal's positive direction [deg clockwise from north]; ``None`` if the
        file does not state it.
    positive_up : bool, optional
        For a vertical: whether positive samples mean up (``dip = -90``) or down (``dip = 90``).
    index : int, optional
        ``1`` or ``2``: the digit a horizontal gets when it is not along north or east.

    Returns
    -------
    dict
        ``channel`` (``HNZ``, ``HNN``, ``HNE``, ``HN1``/``HN2``; band letter by rate), ``dip``
        [deg, SEED: positive down] and, for a horizontal of known azimuth, ``azimuth`` [deg].
    """
    band = band_code(sampling_rate)
    if vertical:
        return {"channel": f"{band}NZ", "dip": -90.0 if positive_up else 90.0}
    stats = {"dip": 0.0}
    letter = str(index)
    if azimuth_deg is not None and math.isfinite(azimuth_deg):
        azimuth = float(azimuth_deg) % 360.0
        stats["azimuth"] = azimuth
        for cardinal, target in (("N", 0.0), ("E", 90.0)):
            if min(abs(azimuth - target), 360.0 - abs(azimuth - target)) <= CARDINAL_TOLERANCE_DEG:
                letter = cardinal
    stats["channel"] = f"{band}N{letter}"
    return stats


class PolarityReversalWarning(RecordError, UserWarning):
    """A channel read as wired with reversed polarity on the word of its sensitivity alone.

    It is a warning (the record is read, its sign restored) and a :class:`RecordError`: turned
    into an error by a warnings filter (``warnings.simplefilter("error",
    PolarityReversalWarning)``; ``python -W error::shipblock.io._common.PolarityReversalWarning``),
    it refuses the record by name in :func:`shipblock.read_motion`.
    """


def sensitivity_sign(response, name: str, what: str) -> str:
    """Check the sign of a response's overall sensitivity against its stages; return a note.

    A negative overall sensitivity states a channel wired with reversed polarity: dividing by it
    restores the ground's sign (BK.VALB's HN1-HN3 in real BK metadata, whose first stage gain is
    -1.02038). The overall sensitivity is the product of the stage gains (at the normalisation
    frequency), so its sign must be theirs:

    * stages whose gains multiply to a negative number confirm the reversal (a note says so);
    * stages whose gains multiply to a positive number contradict it: a damaged sign, refused;
    * no stage gains: nothing confirms it. It is read as a reversal and said loudly with a
      :class:`PolarityReversalWarning`, which a user can turn into an error to refuse it.

    Parameters
    ----------
    response : obspy.core.inventory.Response
        The channel's response, with a finite non-zero overall sensitivity.
    name : str
        Source of the response (file), for messages.
    what : str
        The channel, for messages.

    Returns
    -------
    str
        ``""`` for a positive sensitivity, else a note for the conversion's description.

    Raises
    ------
    RecordError
        If the sensitivity is negative and the stage gains positive.
    """
    value = response.instrument_sensitivity.value
    if value >= 0:
        return ""
    gains = [stage.stage_gain for stage in (response.response_stages or [])
             if stage.stage_gain is not None and math.isfinite(stage.stage_gain)
             and stage.stage_gain != 0]
    if gains:
        negative = sum(1 for gain in gains if gain < 0) % 2 == 1
        if not negative:
            raise RecordError(
                name, f"{what}: overall sensitivity {value:.6g} is negative but its"
                f" {len(gains)} stage gains multiply to a positive number: a damaged sign, not a"
                " channel of reversed polarity")
        return (" (negative, as the product of its stage gains: the channel's polarity is reversed"
                " and is restored)")
    warnings.warn(PolarityReversalWarning(
        name, f"{what}: overall sensitivity {value:.6g} is negative and no stage gain confirms it;"
        " read as a channel of reversed polarity and its sign restored. If the sign is a damaged"
        " number, refuse such channels by turning PolarityReversalWarning into an error (python"
        " -W error::shipblock.io._common.PolarityReversalWarning)"), stacklevel=4)
    return " (negative, no stage gains to confirm it: polarity taken as reversed and restored)"
