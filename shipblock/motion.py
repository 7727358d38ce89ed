"""Ground motions: from record files to the (horizontal, vertical) pair the solver takes.

:func:`read_motion` reads one or more record files (or takes an obspy Stream), converts every
trace to m/s^2, identifies the components H1, H2 and V, brings them to one time window and one
sampling rate, and returns a :class:`GroundMotion`. All conversions are recorded in
``GroundMotion.metadata``; nothing about units is guessed:

* traces of formats that carry units (PEER AT2, COSMOS, ESM, text files with a stated unit) are
  converted by their readers (:mod:`shipblock.io`);
* K-NET and Kinemetrics EVT counts are scaled with the calibration obspy reads from their headers
  (``stats.calib``, m/s^2 per count for both formats);
* raw counts are converted with a StationXML inventory: the overall sensitivity
  (:meth:`obspy.core.trace.Trace.remove_sensitivity`, the default) or the full response to
  acceleration (``response="full"``);
* otherwise the caller states the unit (``units="m/s^2"``, ``"cm/s^2"``, ``"gal"``, ``"g"``);
  SAC files are multiplied by their ``scale`` header (``stats.calib``) first;
* a trace whose unit stays unknown raises :class:`~shipblock.errors.UnitsError` naming the file.

Component conventions: H1 and H2 are the horizontals (``H2`` normally 90 deg clockwise from
``H1``), V the vertical, positive up (a vertical recorded positive down is flipped). Azimuths are
in degrees clockwise from north.
"""

from __future__ import annotations

import copy
import logging
import math
import os
import warnings
from collections.abc import Iterable, Mapping

import numpy as np
import obspy
from obspy import Stream, Trace, UTCDateTime

from shipblock import checks
from shipblock.errors import ParameterError, ParameterTypeError, RecordError, UnitsError
from shipblock.io import check_format, read_record
from shipblock.io._common import (
    MAX_DIGITIZATION_GAP_S,
    canonical_unit,
    canonical_velocity_unit,
    check_count_value,
    check_plausible_samples,
    check_sampling_interval,
    si_factor,
)
from shipblock.units import ACCELERATION_UNITS_TO_SI, STANDARD_GRAVITY, VELOCITY_UNITS_TO_SI

__all__ = [
    "COMPONENTS",
    "COMPONENT_KEY",
    "GroundMotion",
    "check_read_arguments",
    "read_motion",
    "rotate_to_azimuth",
]

logger = logging.getLogger(__name__)

#: Component names, in order.
COMPONENTS = ("H1", "H2", "V")

#: Key of ``trace.stats`` that tags each trace with its component name. (obspy reserves
#: ``stats.motion_component``: it is the last letter of the channel code, and setting it renames the
#: channel, so the tag lives under its own key.)
COMPONENT_KEY = "motion_component"

#: Largest departure from a right angle accepted between two horizontals, and from exact
#: vertical/horizontal accepted for a sensor axis [deg].
ORIENTATION_TOLERANCE = 1.0

#: Anti-alias low-pass corner as a fraction of the new Nyquist frequency when down-sampling [-].
ANTI_ALIAS_FRACTION = 0.8

#: Order of the zero-phase Butterworth anti-alias filter [-].
ANTI_ALIAS_CORNERS = 8

#: Half-width of the Lanczos interpolation kernel, in samples [-].
LANCZOS_HALF_WIDTH = 20

#: Time offsets smaller than this fraction of a sample are treated as zero [-].
SAMPLE_FRACTION_TOLERANCE = 1e-3

#: Longest gap inside a channel that ``gaps="interpolate"`` fills by a straight line [s]: as for
#: digitized records (:data:`shipblock.io._common.MAX_DIGITIZATION_GAP_S`), a longer hole would
#: replace the 1-25 Hz motion the ship responds to by a line. Any gap is refused by default.
MAX_INTERPOLATED_GAP_S = MAX_DIGITIZATION_GAP_S

#: Largest share of a record's span (from the earliest start to the latest end of its components)
#: that trimming the components to their common window may drop [-]. Real records' components
#: differ by up to 3.1 % (CI.MPM, gmprocess corpus: ends at 66.05-68.19 s); a component with much
#: less than the others is damaged (a truncated file, a lost record) and is refused.
WINDOW_TOLERANCE_FRACTION = 0.05

#: Formats whose ``stats.calib`` (set by obspy from the file header) is m/s^2 per count.
CALIB_IN_SI_FORMATS = {
    "KNET": "K-NET scale factor",
    "KINEMETRICS_EVT": "Kinemetrics EVT full scale and sensitivity",
}

#: SAC's dependent-variable codes (IDEP) that state a unit, and the unit (SAC manual: IACC is
#: nm/s^2, IVEL nm/s).
SAC_IDEP_UNITS = {8: "nm/s^2", 7: "nm/s"}
SAC_IDEP_NAMES = {8: "IACC", 7: "IVEL"}

#: What read_motion says of a record whose sensor (``stats.sensor_site``) is not at the free
#: surface: neither is the motion at a dock's floor.
SITE_NOTES = {
    "structure": "the sensor is in a structure (a building, dam or bridge), not free-field:"
                 " its record is the structure's response, not the ground motion",
    "borehole": "the sensor is in a borehole below the surface (KiK-net 01): its record is the"
                " motion at depth, not at the surface",
}

#: Mean of a vertical above which read_motion notes gravity or an offset in it [m/s^2].
GRAVITY_NOTE_THRESHOLD = 0.5 * STANDARD_GRAVITY

#: How close to 1 the mean of a vertical may be to be taken for gravity in g [-].
GRAVITY_MEAN_TOLERANCE = 0.05

_SI_UNITS = "m/s**2"


# --------------------------------------------------------------------------------------------
# Pure helpers
# --------------------------------------------------------------------------------------------


def rotate_to_azimuth(h1, h2, azimuth_h1: float, azimuth_h2: float, azimuth: float) -> np.ndarray:
    """Project two orthogonal horizontal accelerations onto one direction.

    .. math:: a_\\theta(t) = a_1(t)\\cos(\\theta - \\alpha_1) + a_2(t)\\cos(\\theta - \\alpha_2)

    which holds for any two orthogonal axes (either handedness).

    Parameters
    ----------
    h1, h2 : array_like
        Accelerations along the two horizontals [m/s^2], same length.
    azimuth_h1, azimuth_h2 : float
        Azimuths of the positive directions of ``h1`` and ``h2`` [deg clockwise from north].
    azimuth : float
        Azimuth of the direction to project on, e.g. the dock's transverse axis
        [deg clockwise from north].

    Returns
    -------
    numpy.ndarray
        Acceleration along ``azimuth`` [m/s^2].

    Raises
    ------
    ParameterError
        Naming the argument: ``h1`` or ``h2`` not a one-dimensional array of finite
        accelerations within 100 g (:func:`shipblock.checks.acceleration`), of different lengths;
        an azimuth that is not a number within +-360 deg; or horizontals that are not orthogonal
        within :data:`ORIENTATION_TOLERANCE` (``azimuth_h2``). A wrong type is also a
        :class:`TypeError`.
    """
    azimuth_h1 = checks.azimuth(azimuth_h1, "azimuth_h1")
    azimuth_h2 = checks.azimuth(azimuth_h2, "azimuth_h2")
    azimuth = checks.azimuth(azimuth, "azimuth")
    separation = (azimuth_h2 - azimuth_h1) % 360.0
    if min(abs(separation - 90.0), abs(separation - 270.0)) > ORIENTATION_TOLERANCE:
        raise ParameterError(
            f"azimuth_h2 must be 90 deg from azimuth_h1 (within {ORIENTATION_TOLERANCE:g} deg):"
            f" horizontals at {azimuth_h1:g} and {azimuth_h2:g} deg are not orthogonal"
        )
    h1 = checks.acceleration(h1, "h1", min_samples=1)
    h2 = checks.acceleration(h2, "h2", min_samples=1)
    if h2.size != h1.size:
        raise ParameterError(f"h2 must have as many samples as h1 ({h1.size}), got {h2.size}")
    return h1 * math.cos(math.radians(azimuth - azimuth_h1)) + h2 * math.cos(
        math.radians(azimuth - azimuth_h2)
    )


def _source(trace: Trace) -> str:
    return str(trace.stats.get("source_file", "<stream>"))


def _check_finite(trace: Trace) -> None:
    name = _source(trace)
    if trace.stats.npts == 0 or len(trace.data) == 0:
        raise RecordError(name, f"channel {trace.id} has no samples (zero-length trace)")
    data = np.asarray(trace.data)
    if np.issubdtype(data.dtype, np.floating):
        bad = ~np.isfinite(data)
        if bad.any():
            raise RecordError(name, f"channel {trace.id} has {int(bad.sum())} NaN/inf samples")


# --------------------------------------------------------------------------------------------
# Arguments
# --------------------------------------------------------------------------------------------

#: Choices of read_motion's options.
RESPONSES = ("sensitivity", "full")
GAPS = ("refuse", "interpolate")
ALIGNS = ("trim", "resample", "strict")


def check_read_arguments(*, inventory=None, units=None, response="sensitivity",
                         differentiate=False, align="trim", gaps="refuse", event=None,
                         format=None) -> dict:  # noqa: A002 - obspy's name for it
    """Check the options :func:`read_motion` and :func:`shipblock.collection.read_motions` share.

    Called before any file is read, so that a wrong option is one error naming it, not a
    failure of every record (``read_motions`` lists failures per record).

    Parameters
    ----------
    inventory, units, response, differentiate, align, gaps, event, format
        As in :func:`read_motion`.

    Returns
    -------
    dict
        The arguments, paths as ``str`` and ``format`` in upper case.

    Raises
    ------
    ParameterError
        Naming the argument and what it expects (a :class:`~shipblock.errors.ParameterTypeError`,
        also a :class:`TypeError`, for a wrong type): an unknown unit, response, alignment, gap
        rule or format; ``differentiate`` not a bool; an empty event Catalog.
    RecordError
        Naming the file and the argument, if an inventory or event path names no file or a
        folder.
    """
    if inventory is not None and not isinstance(inventory, obspy.Inventory):
        if not isinstance(inventory, str | os.PathLike):
            raise ParameterTypeError(
                "inventory must be a StationXML file (str or os.PathLike), an obspy Inventory"
                f" or None, got {type(inventory).__name__} {inventory!r}")
        inventory = checks.existing_file(inventory, "inventory", "a StationXML file")
    if units is not None:
        checks.unit(units, "units")
    checks.choice(response, "response", RESPONSES)
    differentiate = checks.flag(differentiate, "differentiate")
    checks.choice(align, "align", ALIGNS)
    checks.choice(gaps, "gaps", GAPS)
    if isinstance(event, obspy.Catalog):
        if len(event) == 0:
            raise ParameterError("event must hold an earthquake, got an empty obspy Catalog")
    elif isinstance(event, str | os.PathLike):
        event = checks.existing_file(event, "event", "a QuakeML event file")
    elif not (event is None or isinstance(event, Mapping | obspy.core.event.Event)):
        raise ParameterTypeError(
            "event must be a QuakeML file (str or os.PathLike), an obspy Event or Catalog, a dict"
            f" or None, got {type(event).__name__} {event!r}")
    return dict(inventory=inventory, units=units, response=response,
                differentiate=differentiate, align=align, gaps=gaps, event=event,
                format=check_format(format))


def _check_sources(paths_or_stream):
    """``paths_or_stream`` of :func:`read_motion` checked: a Stream or Trace as given, a path
    (file, folder or glob pattern) as a ``str``, or a non-empty list of existing files."""
    if isinstance(paths_or_stream, Stream | Trace):
        return paths_or_stream
    expected = ("a record file, folder or glob pattern (str or os.PathLike), a list of record"
                " files, or an obspy Stream or Trace")
    if isinstance(paths_or_stream, str | os.PathLike):
        path = checks.pathname(paths_or_stream, "paths_or_stream",
                               "a record file, folder or glob pattern")
        if _names_many(path):
            return path
        return checks.existing_file(path, "paths_or_stream", "a record file, folder or glob"
                                    " pattern")
    if (isinstance(paths_or_stream, bytes | Mapping | np.ndarray)
            or not isinstance(paths_or_stream, Iterable)):
        raise ParameterTypeError(f"paths_or_stream must be {expected}, got "
                                 f"{type(paths_or_stream).__name__} {paths_or_stream!r}")
    paths = list(paths_or_stream)
    if not paths:
        raise ParameterError(f"paths_or_stream must be {expected}, got an empty list")
    return [checks.existing_file(p, f"paths_or_stream[{i}]", "a record file")
            for i, p in enumerate(paths)]


def _check_channel_map(channel_map):
    """``channel_map`` checked: ``None`` or a mapping of strings to component names."""
    if channel_map is None:
        return None
    if not isinstance(channel_map, Mapping):
        raise ParameterTypeError(
            "channel_map must be a dict {channel code, SEED id or file name: 'H1' | 'H2' | 'V'},"
            f" got {type(channel_map).__name__} {channel_map!r}")
    for key, value in channel_map.items():
        if not isinstance(key, str):
            raise ParameterTypeError(f"channel_map keys must be channel codes, SEED ids or file"
                                     f" names (str), got {type(key).__name__} {key!r}")
        checks.choice(value, f"channel_map[{key!r}]", COMPONENTS)
    return dict(channel_map)


# --------------------------------------------------------------------------------------------
# Loading
# --------------------------------------------------------------------------------------------


def _load_stream(paths_or_stream, units, fmt, read_kwargs) -> Stream:
    if isinstance(paths_or_stream, Stream):
        stream = paths_or_stream.copy()
        for trace in stream:
            trace.stats.setdefault("source_file", "<stream>")
        return stream
    if isinstance(paths_or_stream, Trace):
        return _load_stream(Stream([paths_or_stream]), units, fmt, read_kwargs)
    single = isinstance(paths_or_stream, (str, os.PathLike))
    paths = [paths_or_stream] if single else list(paths_or_stream)
    stream = Stream()
    for path in paths:
        stream += read_record(path, format=fmt, units=units, **read_kwargs)
    return stream


def _load_inventory(inventory):
    if inventory is None or isinstance(inventory, obspy.Inventory):
        return inventory, ("<inventory>" if inventory is not None else None)
    name = os.fspath(inventory)  # an existing file: check_read_arguments
    try:
        return obspy.read_inventory(name), name
    except Exception as exc:  # noqa: BLE001 - any parser failure means a bad inventory file
        raise RecordError(name, f"cannot be read as a StationXML inventory: {exc}") from exc


def _load_event(event):
    """Summarise an event (QuakeML path, Catalog or Event) as a plain dict."""
    if event is None:
        return None
    if isinstance(event, Mapping):
        return dict(event)
    if isinstance(event, (str, os.PathLike)):
        name = os.fspath(event)
        try:
            catalog = obspy.read_events(name)
        except Exception as exc:  # noqa: BLE001
            raise RecordError(name, f"cannot be read as an event file (QuakeML): {exc}") from exc
        if len(catalog) == 0:
            raise RecordError(name, "holds no event")
        event = catalog[0]
    elif isinstance(event, obspy.Catalog):
        event = event[0]  # not empty: check_read_arguments
    origin = event.preferred_origin() or (event.origins[0] if event.origins else None)
    magnitude = event.preferred_magnitude() or (event.magnitudes[0] if event.magnitudes else None)
    summary = {"id": str(event.resource_id)}
    if origin is not None:
        summary.update(
            time=str(origin.time),
            latitude=origin.latitude,
            longitude=origin.longitude,
            depth_m=origin.depth,
        )
    if magnitude is not None:
        summary.update(magnitude=magnitude.mag, magnitude_type=magnitude.magnitude_type)
    return summary


def _seconds(duration_s: float) -> str:
    """A duration in words a reader can judge: seconds, or days/years when it is that long."""
    if abs(duration_s) >= 2 * 86400.0 * 365.25:
        return f"{duration_s:.6g} s ({duration_s / (86400.0 * 365.25):.3g} years)"
    if abs(duration_s) >= 2 * 86400.0:
        return f"{duration_s:.6g} s ({duration_s / 86400.0:.3g} days)"
    return f"{duration_s:.6g} s"


def _segments(group: Stream, name: str, seed_id: str):
    """Gaps and overlaps between the traces of one channel, found from their headers alone.

    Returns
    -------
    list of (obspy.UTCDateTime, float)
        ``(end of the data before the gap, gap length [s])``: time without samples, beyond half
        a sample.

    Raises
    ------
    RecordError
        If two traces overlap with different samples (two versions of the same time: a damaged
        time field, or two different recordings under one channel code).
    """
    delta = group[0].stats.delta
    ordered = sorted(group, key=lambda tr: tr.stats.starttime)
    found = []
    covered = ordered[0]
    for trace in ordered[1:]:
        missing = trace.stats.starttime - covered.stats.endtime - delta  # [s]
        if missing > 0.5 * delta:
            found.append((covered.stats.endtime, missing))
        elif missing < -0.5 * delta:
            for earlier in ordered:
                if earlier is trace:
                    break
                _check_overlap(earlier, trace, name, seed_id)
        if trace.stats.endtime > covered.stats.endtime:
            covered = trace
    return found


def _check_overlap(first: Trace, second: Trace, name: str, seed_id: str) -> None:
    """Refuse two traces of one channel whose common time holds different samples."""
    delta = first.stats.delta
    start = max(first.stats.starttime, second.stats.starttime)
    end = min(first.stats.endtime, second.stats.endtime)
    if end < start:
        return
    offset_a = (start - first.stats.starttime) / delta
    offset_b = (start - second.stats.starttime) / delta
    count = int(round((end - start) / delta)) + 1
    aligned = max(abs(offset_a - round(offset_a)), abs(offset_b - round(offset_b)))
    a = np.asarray(first.data[int(round(offset_a)):int(round(offset_a)) + count])
    b = np.asarray(second.data[int(round(offset_b)):int(round(offset_b)) + count])
    if aligned <= SAMPLE_FRACTION_TOLERANCE and a.shape == b.shape and np.array_equal(a, b):
        return  # the same samples twice (a repeated record): merged as one
    raise RecordError(
        name,
        f"channel {seed_id} holds two different recordings of {_seconds(end - start)} from"
        f" {start} (overlapping records with different samples: a damaged record time?)",
    )


def _merge_gaps(stream: Stream, gaps: str) -> Stream:
    """Merge traces of the same channel; refuse or fill gaps.

    Gaps and overlaps are found from the traces' headers before anything is merged, so that a
    damaged record time (a MiniSEED record put years away) is refused at once, without
    allocating the span it would make.
    """
    if gaps not in ("refuse", "interpolate"):
        raise ParameterError(f"gaps must be 'refuse' or 'interpolate', not {gaps!r}")
    merged = Stream()
    for seed_id in dict.fromkeys(tr.id for tr in stream):
        group = Stream([tr for tr in stream if tr.id == seed_id])
        if len(group) == 1:
            merged += group
            continue
        name = _source(group[0])
        if len({_source(tr) for tr in group}) > 1:
            raise RecordError(
                name, f"channel {seed_id} appears in several files: "
                + ", ".join(sorted({_source(tr) for tr in group}))
            )
        rates = {tr.stats.sampling_rate for tr in group}
        if len(rates) > 1:
            raise RecordError(name, f"channel {seed_id} changes sampling rate ({sorted(rates)} Hz)")
        gap_list = _segments(group, name, seed_id)
        if gap_list:
            first_end, first_gap = gap_list[0]
            longest = max(length for _, length in gap_list)
            where = (f"{len(gap_list)} gap(s), the first of {_seconds(first_gap)} after {first_end}"
                     + (f", the longest {_seconds(longest)}" if len(gap_list) > 1 else ""))
            if gaps == "refuse":
                raise RecordError(
                    name, f"channel {seed_id} has {where}; pass gaps='interpolate' to fill gaps"
                    f" of up to {MAX_INTERPOLATED_GAP_S:g} s",
                )
            if longest > MAX_INTERPOLATED_GAP_S:
                raise RecordError(
                    name, f"channel {seed_id} has {where}: longer than the"
                    f" {MAX_INTERPOLATED_GAP_S:g} s gaps='interpolate' fills (a damaged record"
                    " time, or a recording with a hole in it)",
                )
        try:
            joined = group.copy().merge(method=1, fill_value="interpolate" if gap_list else None)
        except Exception as exc:  # noqa: BLE001
            raise RecordError(name, f"channel {seed_id} cannot be merged: {exc}") from exc
        trace = joined[0]
        if np.ma.isMaskedArray(trace.data):
            if np.ma.count_masked(trace.data):
                raise RecordError(name, f"channel {seed_id} has masked samples after merging")
            trace.data = np.ma.getdata(trace.data)
        if gap_list:
            trace.stats.shipblock_gaps_filled = len(gap_list)
        merged += joined
    return merged


# --------------------------------------------------------------------------------------------
# Units
# --------------------------------------------------------------------------------------------


def _select_channel(trace: Trace, inventory, inventory_name):
    """The inventory's channel of a trace in force at the trace's start (its epoch)."""
    stats = trace.stats
    selected = inventory.select(
        network=stats.network,
        station=stats.station,
        location=stats.location,
        channel=stats.channel,
        time=stats.starttime,
    )
    channels = [ch for net in selected for sta in net for ch in sta]
    if not channels:
        raise RecordError(
            _source(trace),
            f"StationXML {inventory_name} has no channel {trace.id} at {stats.starttime}"
            " (inventory does not match the record)",
        )
    return channels[0]


def _input_unit(unit: str | None):
    """``(quantity, factor to SI)`` of a StationXML/SAC input unit, or ``(None, None)``."""
    acceleration = canonical_unit(unit or "")
    if acceleration is not None:
        return "acceleration", ACCELERATION_UNITS_TO_SI[acceleration]
    velocity = canonical_velocity_unit(unit)
    if velocity is not None:
        return "velocity", VELOCITY_UNITS_TO_SI[velocity]
    return None, None


def _differentiate(trace: Trace, how: str, differentiate: bool, name: str, what: str) -> str:
    """Differentiate a velocity trace [m/s] to acceleration [m/s^2] in place, if asked to."""
    if not differentiate:
        raise UnitsError(
            name,
            f"channel {trace.id} is a velocity record ({what}); pass differentiate=True"
            " (command line: --differentiate) to differentiate it to acceleration",
        )
    # Central differences inside, one-sided at the ends (obspy's Trace.differentiate).
    trace.data = np.gradient(np.asarray(trace.data, dtype=np.float64), trace.stats.delta)
    return how + "; velocity differentiated to acceleration (central differences)"


def _by_sensitivity(trace, response, source_label, differentiate, name, note=""):
    """Divide counts by a response's overall sensitivity; convert its input unit to SI."""
    sensitivity = response.instrument_sensitivity if response is not None else None
    value = None if sensitivity is None else sensitivity.value
    if value is None or not (math.isfinite(value) and value != 0):
        raise RecordError(
            name, f"{source_label} has no usable sensitivity for channel {trace.id}"
            f" (value {value!r}; a finite, non-zero number of counts per input unit is needed)"
        )
    input_units = sensitivity.input_units or ""
    quantity, factor = _input_unit(input_units)
    if quantity is not None:
        check_count_value(factor / value, name, f"{source_label}: channel {trace.id}'s sensitivity"
                                                f" {value:.6g} counts/({input_units})")
    if value < 0:
        # A negative sensitivity states a channel wired with reversed polarity (BK.VALB HN3 in
        # real BK metadata): dividing by it restores the ground's sign.
        note += " (negative: the channel's polarity is reversed and is restored)"
    if quantity is None:
        raise UnitsError(
            name, f"{source_label}: channel {trace.id} senses {input_units or 'unknown units'},"
            " which is neither an acceleration nor a velocity; use response='full'"
            " (command line: --response full)",
        )
    trace.data = np.asarray(trace.data, dtype=np.float64) * (factor / value)
    how = (f"counts -> {'m/s**2' if quantity == 'acceleration' else 'm/s'} by the overall"
           f" sensitivity {value:.6g} counts/({input_units}) of {source_label}{note}")
    if quantity == "velocity":
        how = _differentiate(trace, how, differentiate, name, f"{source_label} senses {input_units}")
    return how


def _by_response(trace, inventory, inventory_name, response, differentiate) -> str:
    """Counts to m/s^2 with an inventory, or with the response attached to the trace."""
    name = _source(trace)
    if inventory is not None:
        channel = _select_channel(trace, inventory, inventory_name)
        resp, label = channel.response, f"StationXML {inventory_name}"
    else:
        resp, label = trace.stats.response, "the response attached to the stream"
    if response == "sensitivity":
        return _by_sensitivity(trace, resp, label, differentiate, name)
    if response != "full":
        raise ParameterError(f"response must be 'sensitivity' or 'full', not {response!r}")
    if resp is None or not resp.response_stages:
        # Strong-motion StationXML often holds the overall sensitivity only: with no stages there
        # is no frequency response to remove, and the sensitivity is all there is.
        return _by_sensitivity(
            trace, resp, label, differentiate, name,
            note=" (response='full' asked, but the response has no stages)",
        )
    trace.data = np.asarray(trace.data, dtype=np.float64)
    try:
        with warnings.catch_warnings():
            warnings.filterwarnings("ignore", message="Found more than one matching")
            if inventory is not None:
                # The channel of the record's epoch, not whichever epoch obspy finds first.
                trace.stats.response = resp
            trace.remove_response(output="ACC")
    except Exception as exc:  # noqa: BLE001 - obspy raises many kinds on bad responses
        raise RecordError(name, f"response of {trace.id} from {label} failed: {exc}") from exc
    return f"counts -> m/s**2 by the full response of {label} (obspy remove_response, output ACC)"


def _sac_unit(trace: Trace) -> tuple[str | None, str]:
    """The unit a SAC file states (KUSER0-2 unit word, else IDEP), and where it came from."""
    sac = trace.stats.get("sac") or {}
    for key in ("kuser0", "kuser1", "kuser2"):
        word = str(sac.get(key, "") or "").strip()
        if word and word != "-12345" and (canonical_unit(word) or canonical_velocity_unit(word)):
            return word, f"SAC {key.upper()}={word!r}"
    idep = sac.get("idep")
    if idep in SAC_IDEP_UNITS:
        return SAC_IDEP_UNITS[idep], f"SAC IDEP={idep} ({SAC_IDEP_NAMES[idep]})"
    return None, ""


def _check_gravity(trace: Trace, unit: str, origin: str, name: str) -> None:
    """Refuse a vertical whose mean is 1 in a unit where 1 g would be absurdly small."""
    letter = _orientation_letter(trace.stats.channel)
    if letter != "Z" or unit != "nm/s^2":
        return
    mean = float(np.mean(np.asarray(trace.data, dtype=np.float64)))
    if abs(abs(mean) - 1.0) <= GRAVITY_MEAN_TOLERANCE:
        raise UnitsError(
            name,
            f"{origin} says the samples are in nm/s^2, but vertical channel {trace.id} averages"
            f" {mean:.4g}: that is gravity in g, not 1 nm/s^2 (Community Seismic Network files"
            " are written so); give units='g' (command line: --units g)",
        )


def _to_si(trace: Trace, inventory, inventory_name, units, response, differentiate=False) -> str:
    """Convert one trace to m/s^2 in place; return how it was done."""
    name = _source(trace)
    stats = trace.stats
    fmt = stats.get("_format", "")
    current = stats.get("units")
    if current == _SI_UNITS:
        original = stats.get("original_units", _SI_UNITS)
        key = canonical_unit(str(original))
        if units is not None and (key is None or si_factor(units, name)
                                  != ACCELERATION_UNITS_TO_SI[key]):
            raise UnitsError(name, f"units={units!r} contradicts the file's own unit {original!r}")
        return f"{original} -> m/s**2 from the file header ({fmt or 'stream'})"
    if current == "m/s" and units is None:
        how = f"{stats.get('original_units', 'm/s')} -> m/s from the file header ({fmt})"
        how = _differentiate(trace, how, differentiate, name, "the file states velocity")
        stats.units = _SI_UNITS
        return how
    if current not in (None, "counts"):
        raise UnitsError(name, f"channel {trace.id} has unsupported units {current!r}")

    has_response = inventory is not None or stats.get("response") is not None
    if has_response and fmt not in CALIB_IN_SI_FORMATS and units is None:
        how = _by_response(trace, inventory, inventory_name, response, differentiate)
        original = "counts"
    elif has_response and inventory is not None and units is not None:
        raise UnitsError(
            name, "both an inventory and units= were given for raw data; give one of them"
        )
    elif fmt in CALIB_IN_SI_FORMATS:
        if units is not None:
            raise UnitsError(
                name, f"{fmt} records carry their own calibration; do not give units="
            )
        check_count_value(stats.calib, name, f"the {CALIB_IN_SI_FORMATS[fmt]} (calibration"
                                             f" {stats.calib!r} m/s^2 per count)")
        trace.data = np.asarray(trace.data, dtype=np.float64) * stats.calib
        how = f"counts -> m/s**2 by stats.calib={stats.calib:.6g} ({CALIB_IN_SI_FORMATS[fmt]})"
        stats.calib = 1.0
        original = "counts"
    else:
        origin = "the caller's units="
        if units is None and fmt == "SAC":
            units, origin = _sac_unit(trace)
            if units is not None:
                _check_gravity(trace, units, origin, name)
        if units is None:
            raise UnitsError(
                name,
                f"units of channel {trace.id} are unknown ({fmt or 'stream'} data"
                f"{', raw counts' if current == 'counts' else ''}): give inventory= (StationXML;"
                " command line: --inventory FILE) for raw counts, or units= ('m/s^2', 'cm/s^2',"
                " 'gal', 'g', or a velocity unit 'm/s', 'cm/s' with differentiate=True; command"
                " line: --units)",
            )
        data = np.asarray(trace.data, dtype=np.float64)
        prefix = ""
        if stats.calib != 1.0:
            velocity = canonical_velocity_unit(units)
            unit_si = (VELOCITY_UNITS_TO_SI[velocity] if velocity is not None
                       else si_factor(units, name))
            check_count_value(stats.calib * unit_si, name,
                              f"the {'SAC SCALE' if fmt == 'SAC' else 'calibration'}"
                              f" {stats.calib!r} ({units} per count)")
            data = data * stats.calib
            prefix = f"calib {stats.calib:g} from the {fmt or 'stream'} header, then "
            stats.calib = 1.0
        velocity = canonical_velocity_unit(units)
        if velocity is not None:
            factor = VELOCITY_UNITS_TO_SI[velocity]
            trace.data = data * factor
            how = prefix + f"{units} -> m/s as stated by {origin} (x{factor:g})"
            how = _differentiate(trace, how, differentiate, name, f"{origin} gives {units}")
        else:
            factor = si_factor(units, name)
            trace.data = data * factor
            how = prefix + f"{units} -> m/s**2 as stated by {origin} (x{factor:g})"
        original = units
    stats.units = _SI_UNITS
    stats.original_units = stats.get("original_units", original)
    return how


# --------------------------------------------------------------------------------------------
# Components
# --------------------------------------------------------------------------------------------

_TWO_LETTER = {"NS": "N", "EW": "E", "UD": "Z"}


def _orientation_letter(channel: str) -> str:
    code = channel.strip().upper()
    if code in _TWO_LETTER:
        return _TWO_LETTER[code]
    return code[-1] if code else ""


def _orientation(trace: Trace, inventory):
    """Return ``(kind, azimuth, dip, note)`` with kind in {"V", "H", None}."""
    stats = trace.stats
    azimuth = stats.get("azimuth")
    dip = stats.get("dip")
    note = None
    sac = stats.get("sac")
    if sac is not None:
        if dip is None and sac.get("cmpinc") is not None and sac.get("cmpinc") != -12345.0:
            dip = float(sac["cmpinc"]) - 90.0  # SAC: 0 = up, 90 = horizontal, 180 = down
        if azimuth is None and sac.get("cmpaz") is not None and sac.get("cmpaz") != -12345.0:
            azimuth = float(sac["cmpaz"])
    if inventory is not None and (azimuth is None or dip is None):
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                found = inventory.get_orientation(trace.id, stats.starttime)
        except Exception:  # noqa: BLE001 - the channel may simply be absent
            found = {}
        if azimuth is None and found.get("azimuth") is not None:
            azimuth = float(found["azimuth"])
        if dip is None and found.get("dip") is not None:
            dip = float(found["dip"])
    letter = _orientation_letter(stats.channel)
    if dip is not None:
        if abs(abs(dip) - 90.0) <= ORIENTATION_TOLERANCE:
            return "V", None, float(math.copysign(90.0, dip)), note
        if abs(dip) <= ORIENTATION_TOLERANCE:
            if azimuth is None:
                azimuth = {"N": 0.0, "E": 90.0}.get(letter)
            return "H", azimuth, 0.0, note
        raise RecordError(
            _source(trace), f"channel {trace.id} is tilted (dip {dip:g} deg); cannot use it"
        )
    if letter in ("Z", "U"):
        note = f"{trace.id}: vertical polarity not stated; taken positive up (SEED convention)"
        return "V", None, -90.0, note
    if letter in ("N", "E", "1", "2"):
        if azimuth is None:
            azimuth = {"N": 0.0, "E": 90.0}.get(letter)
        return "H", azimuth, 0.0, note
    return None, azimuth, dip, note


def sensor_code(trace: Trace) -> str:
    """``"<location>.<band+instrument>"`` of a trace, e.g. ``"02.HN"``: one sensor of a station.

    Only SEED channel codes (three characters, band and instrument letters first) name a sensor;
    other codes (an AT2 file's ``"180"``, an EVT file's ``"0"``) leave it empty.
    """
    channel = trace.stats.channel
    code = channel[:2] if len(channel) == 3 and channel[:2].isalpha() else ""
    return f"{trace.stats.location}.{code}"


def _select_sensor(stream: Stream, sensor: str | None, channel_map, strict: bool = True) -> Stream:
    """Keep the traces of one sensor; refuse a choice between several that nobody made.

    With ``strict=False`` a sensor that matches nothing gives an empty Stream, not an error.
    """
    sensors = dict.fromkeys(sensor_code(tr) for tr in stream)
    if sensor is None:
        if len(sensors) <= 1 or channel_map:
            return stream
        stations = {(tr.stats.network, tr.stats.station) for tr in stream}
        if len(stations) > 1:
            return stream  # several stations: _assign_components says so
        label = _source(stream[0])
        raise RecordError(
            label,
            "the files hold several sensors of one station: "
            + ", ".join(f"{code} ({', '.join(tr.stats.channel for tr in stream if sensor_code(tr) == code)})"
                        for code in sensors)
            + "; choose one with sensor='<location>.<code>' (command line: --sensor)",
        )
    wanted = sensor.strip().upper()
    chosen = Stream([tr for tr in stream if sensor_code(tr).upper() == wanted
                     or ("." not in wanted and tr.stats.channel[:2].upper() == wanted)])
    if not chosen and strict:
        raise ParameterError(
            f"sensor={sensor!r} matches none of the record's sensors: {', '.join(sensors)}"
        )
    return chosen


def _match_map(trace: Trace, channel_map: Mapping[str, str]):
    source = _source(trace)
    for key in (trace.id, trace.stats.channel, os.path.basename(source), source):
        if key in channel_map:
            return channel_map[key]
    return None


def _assign_components(
    stream: Stream, inventory, channel_map, notes, processing
) -> dict[str, Trace]:
    """Tag each trace with ``stats.motion_component``; return the component -> trace mapping."""
    assigned: dict[str, Trace] = {}
    info = {}
    for trace in stream:
        info[id(trace)] = _orientation(trace, inventory)
        if info[id(trace)][3]:
            notes.append(info[id(trace)][3])
    label = _source(stream[0])
    if channel_map:
        for trace in stream:
            component = _match_map(trace, channel_map)
            if component is None:
                notes.append(f"{trace.id} not in the component mapping; left out")
                continue
            if component not in COMPONENTS:
                raise ParameterError(f"channel_map values must be one of {COMPONENTS}: {component!r}")
            if component in assigned:
                raise RecordError(label, f"two channels are mapped to {component}")
            assigned[component] = trace
        absent = sorted({c for c in channel_map.values() if c in COMPONENTS} - set(assigned),
                        key=COMPONENTS.index)
        if absent:
            raise RecordError(
                label, "the component mapping names "
                + ", ".join(f"{c} ({', '.join(k for k, v in channel_map.items() if v == c)})"
                            for c in absent)
                + " but the files hold no such channel (a missing or damaged file?); they hold "
                + ", ".join(tr.id for tr in stream),
            )
    else:
        stations = {(tr.stats.network.upper(), tr.stats.station.upper(), tr.stats.location.upper())
                        for tr in stream}
        if len(stations) > 1:
            raise RecordError(
                label,
                "traces of several stations/locations: "
                + ", ".join(".".join(s) for s in sorted(stations))
                + "; pass channel_map= to choose",
            )
        verticals = [tr for tr in stream if info[id(tr)][0] == "V"]
        horizontals = [tr for tr in stream if info[id(tr)][0] == "H"]
        unknown = [tr for tr in stream if info[id(tr)][0] is None]
        if unknown:
            if len(stream) == 1:
                horizontals = unknown
                notes.append(
                    f"{unknown[0].id.strip('.') or _source(unknown[0])}: orientation unknown;"
                    " the single"
                    " record is taken as horizontal H1"
                )
            else:
                raise RecordError(
                    label,
                    "cannot tell the component of "
                    + ", ".join(f"{tr.id} ({_source(tr)})" for tr in unknown)
                    + "; pass channel_map={'<channel or file>': 'H1'|'H2'|'V'}",
                )
        if len(verticals) > 1:
            raise RecordError(label, f"{len(verticals)} vertical channels; pass channel_map=")
        if len(horizontals) > 2:
            raise RecordError(label, f"{len(horizontals)} horizontal channels; pass channel_map=")
        if len(horizontals) == 2:
            horizontals = _order_horizontals(horizontals, info)
        for component, trace in zip(("H1", "H2"), horizontals, strict=False):
            assigned[component] = trace
        if verticals:
            assigned["V"] = verticals[0]
    if "H1" not in assigned and "H2" not in assigned:
        if "V" in assigned:
            raise RecordError(
                label, f"holds only a vertical component ({assigned['V'].id}); the model needs a"
                " horizontal one"
            )
        raise RecordError(label, "no horizontal component found")
    for component, trace in assigned.items():
        kind, azimuth, dip, _ = info[id(trace)]
        trace.stats[COMPONENT_KEY] = component
        if component == "V":
            if kind == "H":
                raise RecordError(_source(trace), f"{trace.id} is horizontal but mapped to V")
            dip = -90.0 if dip is None else dip
            if dip > 0:
                trace.data = -np.asarray(trace.data)
                processing.append(
                    f"{trace.id}: vertical recorded positive down; flipped to positive up"
                )
                dip = -90.0
            trace.stats.dip = dip
        else:
            if kind == "V":
                raise RecordError(
                    _source(trace), f"{trace.id} is vertical but mapped to {component}"
                )
            trace.stats.dip = 0.0
            if azimuth is not None:
                trace.stats.azimuth = float(azimuth) % 360.0
    return assigned


def _order_horizontals(horizontals, info):
    letters = [_orientation_letter(tr.stats.channel) for tr in horizontals]
    for first, second in (("N", "E"), ("1", "2")):
        if set(letters) == {first, second}:
            return sorted(
                horizontals, key=lambda tr: _orientation_letter(tr.stats.channel) != first
            )
    az = [info[id(tr)][1] for tr in horizontals]
    if None not in az:
        separation = (az[1] - az[0]) % 360.0
        if abs(separation - 270.0) <= ORIENTATION_TOLERANCE:
            return [horizontals[1], horizontals[0]]
    return list(horizontals)


# --------------------------------------------------------------------------------------------
# Alignment
# --------------------------------------------------------------------------------------------


def _describe(traces: list[Trace], origin) -> str:
    """Each component's rate, window (from ``origin``) and sample count, for error messages."""
    return "; ".join(
        f"{tr.stats[COMPONENT_KEY]} ({tr.id}) {tr.stats.sampling_rate:g} Hz,"
        f" {tr.stats.starttime - origin:.6g}-{tr.stats.endtime - origin:.6g} s,"
        f" {tr.stats.npts} samples"
        for tr in traces
    )


def _align(traces: list[Trace], align: str, notes: list[str]) -> None:
    """Bring traces to one sampling rate and one time window, in place.

    Components must share one sampling rate (``align="resample"`` brings them to the lowest)
    and cover one window: trimming them to their common window may drop at most
    :data:`WINDOW_TOLERANCE_FRACTION` of the record's span, or one sample; beyond that, or with
    ``align="strict"`` any difference, the record is refused with the numbers.
    """
    label = _source(traces[0])
    origin = min(tr.stats.starttime for tr in traces)
    rates = sorted({tr.stats.sampling_rate for tr in traces})
    if any(not math.isclose(rate, rates[0], rel_tol=1e-9) for rate in rates):
        if align != "resample":
            raise RecordError(
                label,
                f"components have different sampling rates ({_describe(traces, origin)});"
                " pass align='resample' to resample them to the lowest rate"
                f" ({rates[0]:g} Hz) after an anti-alias low-pass",
            )
        target = rates[0]
        for tr in traces:
            if tr.stats.sampling_rate != target:
                old = tr.stats.sampling_rate
                tr.filter(
                    "lowpass",
                    freq=ANTI_ALIAS_FRACTION * target / 2.0,
                    corners=ANTI_ALIAS_CORNERS,
                    zerophase=True,
                )
                tr.interpolate(sampling_rate=target, method="lanczos", a=LANCZOS_HALF_WIDTH)
                notes.append(
                    f"{tr.stats[COMPONENT_KEY]} ({tr.id}): resampled {old:g} -> {target:g} Hz"
                    " after a"
                    f" zero-phase Butterworth low-pass at {ANTI_ALIAS_FRACTION * target / 2:g} Hz"
                )
    else:
        for tr in traces[1:]:
            tr.stats.sampling_rate = traces[0].stats.sampling_rate  # equal within 1e-9
    delta = traces[0].stats.delta
    start = max(tr.stats.starttime for tr in traces)
    end = min(tr.stats.endtime for tr in traces)
    same = all(
        tr.stats.starttime == traces[0].stats.starttime and tr.stats.npts == traces[0].stats.npts
        for tr in traces
    )
    if same:
        return
    if align == "strict":
        raise RecordError(
            label,
            "components differ in start time or length: "
            + ", ".join(f"{tr.stats[COMPONENT_KEY]} {tr.stats.starttime} npts={tr.stats.npts}"
                        for tr in traces),
        )
    if end - start < delta:
        raise RecordError(label, "components do not overlap in time: "
                          + _describe(traces, origin))
    span = max(tr.stats.endtime for tr in traces) - origin + delta
    dropped = span - (end - start + delta)
    allowed = max(delta, WINDOW_TOLERANCE_FRACTION * span)
    if dropped > allowed * (1.0 + 1e-9):
        raise RecordError(
            label,
            f"components do not cover one time window: their common window"
            f" {start - origin:.6g}-{end - origin:.6g} s would drop {dropped:.6g} s"
            f" ({100.0 * dropped / span:.3g} %) of the record's {span:.6g} s, more than"
            f" {100.0 * WINDOW_TOLERANCE_FRACTION:g} % ({_describe(traces, origin)}): a"
            " truncated or damaged component?",
        )
    for tr in traces:
        offset = (start - tr.stats.starttime) / delta
        if abs(offset - round(offset)) > SAMPLE_FRACTION_TOLERANCE:
            npts = int(math.floor((tr.stats.endtime - start) / delta + 1e-9)) + 1
            tr.interpolate(
                sampling_rate=tr.stats.sampling_rate,
                method="lanczos",
                a=LANCZOS_HALF_WIDTH,
                starttime=start,
                npts=npts,
            )
            notes.append(f"{tr.stats[COMPONENT_KEY]}: interpolated onto the common time grid")
        else:
            tr.trim(starttime=start, nearest_sample=True)
    npts = min(tr.stats.npts for tr in traces)
    for tr in traces:
        if tr.stats.npts > npts:
            tr.data = tr.data[:npts]
    notes.append(f"components trimmed to the common window {start} ({npts} samples;"
                 f" {dropped:.6g} s of the {span:.6g} s span dropped)")


# --------------------------------------------------------------------------------------------
# GroundMotion
# --------------------------------------------------------------------------------------------


def _validate(stream: Stream, label: str) -> dict[str, Trace]:
    """The traces of a GroundMotion's stream by component, checked (see the class)."""
    traces = {}
    for trace in stream:
        if not isinstance(trace, Trace):
            raise ParameterTypeError(f"stream must hold obspy Traces, got a {type(trace).__name__}")
        component = trace.stats.get(COMPONENT_KEY)
        if component not in COMPONENTS:
            raise RecordError(
                label, f"trace {trace.id} has no stats.{COMPONENT_KEY} in {COMPONENTS}"
            )
        if component in traces:
            raise RecordError(label, f"two traces are tagged {component}")
        if trace.stats.get("units", _SI_UNITS) != _SI_UNITS:
            raise UnitsError(label, f"trace {component} is in {trace.stats.units}, not m/s**2")
        _check_finite(trace)
        check_sampling_interval(trace.stats.delta, label, f"{component} ({trace.id}): sampling"
                                                          " interval")
        check_plausible_samples(np.asarray(trace.data), label, f"{component} ({trace.id})")
        traces[component] = trace
    if "H1" not in traces and "H2" not in traces:
        raise RecordError(label, "no horizontal component")
    first = next(iter(traces.values()))
    for component, trace in traces.items():
        if trace.stats.npts != first.stats.npts:
            raise RecordError(
                label, f"{component} has {trace.stats.npts} samples, not {first.stats.npts}"
            )
        if not math.isclose(trace.stats.delta, first.stats.delta, rel_tol=1e-9):
            raise RecordError(label, f"{component} has dt={trace.stats.delta} s, not "
                                     f"{first.stats.delta} s")
        if abs(trace.stats.starttime - first.stats.starttime) > 0.5 * first.stats.delta:
            raise RecordError(label, f"{component} starts at {trace.stats.starttime}, not "
                                     f"{first.stats.starttime}")
    return traces


def _samples(values, name: str, factor: float, units: str) -> np.ndarray:
    """An array argument of :meth:`GroundMotion.from_arrays` in m/s^2, checked (a copy)."""
    raw = checks.as_real_array(values, name, f"a one-dimensional array of accelerations [{units}]")
    if raw.ndim != 1:
        raise ParameterError(f"{name} must be a one-dimensional (1-D) array, got shape "
                             f"{raw.shape}")
    with np.errstate(over="ignore", invalid="ignore"):
        data = np.array(raw, dtype=np.float64) * factor
    return checks.acceleration(data, name if factor == 1.0 else f"{name} (in m/s^2, from {units})")


class GroundMotion:
    """A three-component (or two-/one-component) ground acceleration in m/s^2.

    Holds an obspy :class:`~obspy.core.stream.Stream` whose traces are tagged with
    ``stats.motion_component`` in ``{"H1", "H2", "V"}``, share one sampling interval, start time and
    length, and are in m/s^2. Build it with :func:`read_motion` or :meth:`from_arrays`; after
    processing the stream, get a new one with :meth:`with_stream`.

    Parameters
    ----------
    stream : obspy.Stream
        Tagged traces (see above). Not copied.
    metadata : dict, optional
        Provenance: station, event, channels, azimuths, source files, units handling, processing.
    azimuth : float, optional
        Direction the solver's horizontal is projected on [deg clockwise from north].
    horizontal : {"H1", "H2"}, optional
        The horizontal component used as-is (exclusive with ``azimuth``).

    Raises
    ------
    ParameterError
        If an argument is of the wrong type (also a :class:`TypeError`: a stream that is not an
        obspy Stream, metadata that is not a dict) or value (an azimuth that is not a number
        within +-360 deg, a horizontal other than H1/H2, or both given).
    RecordError
        If the stream is not tagged, not aligned, not in m/s^2, or holds NaN/inf samples,
        samples above 100 g (:data:`shipblock.checks.MAX_ACCELERATION`) or a sampling interval
        outside 1e-4..1 s.
    """

    def __init__(self, stream: Stream, metadata: dict | None = None, azimuth=None,
                 horizontal=None):
        if not isinstance(stream, Stream):
            raise ParameterTypeError(
                f"stream must be an obspy Stream of traces tagged stats.{COMPONENT_KEY}, got "
                f"{type(stream).__name__} {stream!r}"[:300])
        if not (metadata is None or isinstance(metadata, Mapping)):
            raise ParameterTypeError(f"metadata must be a dict or None, got "
                                     f"{type(metadata).__name__} {metadata!r}"[:300])
        if azimuth is not None:
            azimuth = checks.azimuth(azimuth, "azimuth")
        if horizontal is not None:
            checks.choice(horizontal, "horizontal", ("H1", "H2"))
        if azimuth is not None and horizontal is not None:
            raise ParameterError("azimuth and horizontal exclude each other: give azimuth= or"
                                 " horizontal=, not both")
        self._metadata = dict(metadata or {})
        files = self._metadata.get("source_files") or []
        label = (", ".join(str(f) for f in files) if isinstance(files, list | tuple)
                 else str(files)) or "<stream>"
        self._traces = _validate(stream, label)
        self._stream = stream
        self._azimuth = azimuth
        self._horizontal = horizontal
        self._label = label

    # -- construction -------------------------------------------------------------------------

    @classmethod
    def from_arrays(cls, horizontal, vertical=None, dt: float = 0.01, units: str = "m/s^2",
                    name: str = "synthetic", azimuth_h1: float | None = None) -> GroundMotion:
        """Build a ground motion from sample arrays (synthetic records, tests).

        Parameters
        ----------
        horizontal : array_like
            Horizontal acceleration in ``units``; becomes component H1.
        vertical : array_like, optional
            Vertical acceleration in ``units``, positive up; same length as ``horizontal``.
        dt : float
            Sampling interval [s].
        units : str, optional
            Unit of the arrays (``"m/s^2"``, ``"cm/s^2"``, ``"gal"``, ``"g"``).
        name : str, optional
            Label used as station code and in messages.
        azimuth_h1 : float, optional
            Azimuth of the horizontal [deg clockwise from north], if meaningful.

        Returns
        -------
        GroundMotion
            The motion in m/s^2.

        Raises
        ------
        ParameterError
            Naming the argument (a :class:`~shipblock.errors.ParameterTypeError`, also a
            :class:`TypeError`, for a wrong type): ``horizontal`` or ``vertical`` not a
            one-dimensional array of at least two real numbers, holding NaN/inf or a sample
            above 100 g once in m/s^2, or of different lengths; ``dt`` outside 1e-4..1 s; an
            unknown ``units``; ``name`` not a non-empty string; ``azimuth_h1`` not a number
            within +-360 deg.
        """
        name = checks.text(name, "name")
        units = checks.unit(units, "units", velocity=False)
        factor = si_factor(units, name)
        dt = checks.time_step(dt, "dt")
        if azimuth_h1 is not None:
            azimuth_h1 = checks.azimuth(azimuth_h1, "azimuth_h1")
        arrays = {"H1": _samples(horizontal, "horizontal", factor, units)}
        if vertical is not None:
            arrays["V"] = _samples(vertical, "vertical", factor, units)
            if arrays["V"].size != arrays["H1"].size:
                raise ParameterError(f"vertical must have as many samples as horizontal"
                                     f" ({arrays['H1'].size}), got {arrays['V'].size}: the"
                                     " horizontal and vertical arrays differ in length")
        stream = Stream()
        for component, data in arrays.items():
            trace = Trace(data=data)
            trace.stats.delta = dt
            trace.stats.station = name[:64]
            trace.stats.channel = "HNZ" if component == "V" else "HN1"
            trace.stats[COMPONENT_KEY] = component
            trace.stats.units = _SI_UNITS
            trace.stats.source_file = name
            trace.stats.dip = -90.0 if component == "V" else 0.0
            if component == "H1" and azimuth_h1 is not None:
                trace.stats.azimuth = float(azimuth_h1)
            stream += trace
        metadata = {
            "station": {"name": name},
            "event": None,
            "channels": {c: tr.id for c, tr in zip(arrays, stream, strict=True)},
            "azimuths": {"H1": azimuth_h1},
            "source_files": [name],
            "units": {c: f"{units} -> m/s**2 (x{factor:g}), from arrays" for c in arrays},
            "processing": [],
            "notes": [],
        }
        return cls(stream, metadata)

    def with_stream(self, stream: Stream, note: str) -> GroundMotion:
        """Return a new ground motion built on a processed copy of :attr:`stream`.

        The processing steps (``shipblock.processing``, ``shipblock.scaling``) take
        ``gm.stream.copy()``, work on it, and call this to get a new ``GroundMotion`` with the
        same component tags, orientation choice and metadata, plus ``note`` appended to
        ``metadata["processing"]``.

        Parameters
        ----------
        stream : obspy.Stream
            The processed traces, still tagged with ``stats.motion_component`` and in m/s^2.
        note : str
            What was done, e.g. ``"bandpass 0.1-25 Hz, 4 corners, zero phase"``.

        Returns
        -------
        GroundMotion
            A new object; this one is unchanged.

        Raises
        ------
        ParameterError
            If ``stream`` is not an obspy Stream or ``note`` not a non-empty string (also a
            :class:`TypeError`); RecordError as the class does for a stream it cannot hold.
        """
        note = checks.text(note, "note")
        metadata = copy.deepcopy(self._metadata)
        metadata.setdefault("processing", []).append(note)
        return GroundMotion(stream, metadata, azimuth=self._azimuth, horizontal=self._horizontal)

    # -- data ---------------------------------------------------------------------------------

    @property
    def stream(self) -> Stream:
        """obspy.Stream: The traces [m/s^2], tagged with ``stats.motion_component``."""
        return self._stream

    @property
    def name(self) -> str:
        """Short name: the catalogue id, else NET.STA, else the name given to :meth:`from_arrays`."""
        md = self._metadata
        cat = md.get("catalogue") or {}
        if cat.get("id"):
            return str(cat["id"])
        st = md.get("station")
        if isinstance(st, dict) and (st.get("network") or st.get("station")):
            return ".".join(code for code in (st.get("network"), st.get("station")) if code)
        return str(st or md.get("name") or "record")

    @property
    def metadata(self) -> dict:
        """dict: Provenance: station, event, channels, azimuths, files, units, processing."""
        return self._metadata

    @property
    def dt(self) -> float:
        """float: Sampling interval [s]."""
        return float(next(iter(self._traces.values())).stats.delta)

    @property
    def npts(self) -> int:
        """int: Number of samples [-]."""
        return int(next(iter(self._traces.values())).stats.npts)

    @property
    def starttime(self) -> UTCDateTime:
        """obspy.UTCDateTime: Time of the first sample."""
        return next(iter(self._traces.values())).stats.starttime

    @property
    def time(self) -> np.ndarray:
        """numpy.ndarray: Sample times from the first sample [s]."""
        return np.arange(self.npts) * self.dt

    @property
    def components(self) -> dict[str, np.ndarray]:
        """dict: Component name (``"H1"``, ``"H2"``, ``"V"``) -> acceleration [m/s^2] (copies)."""
        return {c: np.array(self._traces[c].data, dtype=np.float64) for c in COMPONENTS
                if c in self._traces}

    @property
    def azimuths(self) -> dict[str, float | None]:
        """dict: Azimuth of each horizontal [deg clockwise from north], ``None`` if unknown."""
        return {c: self._traces[c].stats.get("azimuth") for c in ("H1", "H2") if c in self._traces}

    @property
    def horizontal(self) -> np.ndarray:
        """numpy.ndarray: The horizontal acceleration the solver uses [m/s^2].

        Projected on ``azimuth`` when one was given, else the chosen component (``H1`` by default,
        ``H2`` if there is no ``H1``).
        """
        comps = self.components
        if self._azimuth is not None:
            az = self.azimuths
            if "H1" in comps and "H2" in comps:
                if az.get("H1") is None or az.get("H2") is None:
                    raise RecordError(
                        self._label, "azimuths of the horizontals are unknown; cannot rotate"
                        " (give horizontal='H1'/'H2' instead, command line --horizontal H1, or an"
                        " inventory with azimuths, --inventory FILE)"
                    )
                try:
                    return rotate_to_azimuth(comps["H1"], comps["H2"], az["H1"], az["H2"],
                                             self._azimuth)
                except ValueError as exc:
                    raise RecordError(self._label, str(exc)) from exc
            (only,) = [c for c in ("H1", "H2") if c in comps]
            if az.get(only) is not None:
                angle = (self._azimuth - az[only]) % 180.0
                if min(angle, 180.0 - angle) <= ORIENTATION_TOLERANCE:
                    sign = math.cos(math.radians(self._azimuth - az[only]))
                    return comps[only] * math.copysign(1.0, sign)
            raise RecordError(
                self._label,
                f"only {only} is available; cannot rotate to azimuth {self._azimuth:g} deg",
            )
        name = self._horizontal or ("H1" if "H1" in comps else "H2")
        if name not in comps:
            raise RecordError(self._label, f"component {name} is missing")
        return comps[name]

    @property
    def vertical(self) -> np.ndarray | None:
        """numpy.ndarray or None: Vertical acceleration, positive up [m/s^2]; ``None`` if absent."""
        return self.components.get("V")

    def __repr__(self) -> str:
        comps = ", ".join(c for c in COMPONENTS if c in self._traces)
        return (
            f"GroundMotion({self._label!r}, components=[{comps}], dt={self.dt:g} s,"
            f" npts={self.npts})"
        )


# --------------------------------------------------------------------------------------------
# read_motion
# --------------------------------------------------------------------------------------------


def _names_many(source) -> bool:
    """Whether a source is a folder or a glob pattern (rather than files or traces)."""
    import glob as globbing

    if not isinstance(source, (str, os.PathLike)):
        return False
    name = os.fspath(source)
    return os.path.isdir(name) or (not os.path.exists(name) and globbing.has_magic(name))


def _one_of_folder(source, inventory, units, response, differentiate, align, gaps, event,
                   azimuth, horizontal, sensor) -> GroundMotion:
    """The single record (of ``sensor``, if given) of a folder or glob; refuse several."""
    from shipblock.collection import read_motions

    found = read_motions(source, inventory=inventory, units=units, response=response,
                         differentiate=differentiate, align=align, gaps=gaps, event=event)
    motions = found.motions
    if sensor is not None:
        motions = [m for m in motions if len(_select_sensor(m.stream, sensor, None, strict=False))]
    label = os.fspath(source)
    failures = "".join(f"\n  {where}: {why}" for where, why in found.failures)
    if not motions:
        if not found.motions and not found.failures:
            raise RecordError(label, f"holds no record file, only {len(found.skipped)} files"
                              " that are not waveforms" if found.skipped else
                              "holds no file (an empty folder)")
        raise RecordError(label, "no record could be read from it"
                          + (f" for sensor {sensor!r}" if sensor else "") + ":" + failures)
    if len(motions) > 1:
        raise RecordError(
            label,
            f"holds {len(motions)} records ("
            + ", ".join(next(iter(m.metadata["channels"].values()))[:-1] for m in motions)
            + "); choose one with sensor= (command line: --sensor) or name its files;"
            " read_motions() (command line: shipblock catalogue) reads them all" + failures,
        )
    motion = motions[0]
    if azimuth is not None or horizontal is not None:
        metadata = dict(motion.metadata)
        metadata["horizontal"] = (f"projected on azimuth {azimuth:g} deg" if azimuth is not None
                                  else horizontal)
        motion = GroundMotion(motion.stream, metadata, azimuth=azimuth, horizontal=horizontal)
    return motion


def read_motion(
    paths_or_stream,
    inventory=None,
    units: str | None = None,
    azimuth: float | None = None,
    horizontal: str | None = None,
    *,
    response: str = "sensitivity",
    channel_map: Mapping[str, str] | None = None,
    event=None,
    gaps: str = "refuse",
    align: str = "trim",
    format: str | None = None,
    differentiate: bool = False,
    sensor: str | None = None,
    **read_kwargs,
) -> GroundMotion:
    """Read record files (or a Stream) into a :class:`GroundMotion` in m/s^2.

    Parameters
    ----------
    paths_or_stream : str, os.PathLike, list of them, obspy.Stream or obspy.Trace
        One file with all components, several one-component files, traces in memory, or a
        folder or glob pattern holding exactly one record (use
        :func:`shipblock.collection.read_motions` for a folder of many).
    inventory : str, os.PathLike or obspy.Inventory, optional
        StationXML for raw counts (and channel azimuths/dips).
    units : str, optional
        Unit of records that do not carry one: ``"m/s^2"``, ``"cm/s^2"``, ``"gal"``, ``"g"``, or a
        velocity unit (``"m/s"``, ``"cm/s"``, with ``differentiate=True``).
    azimuth : float, optional
        Azimuth of the dock's transverse axis (the 2-D model's plane) [deg clockwise from north];
        the two horizontals are projected on it.
    horizontal : {"H1", "H2"}, optional
        Use this horizontal as-is instead of rotating.
    response : {"sensitivity", "full"}, optional
        With an inventory (or a response attached to a Stream's traces as ``stats.response``):
        divide by the overall sensitivity of the channel's epoch at the record's start (default;
        the only choice for StationXML that holds a sensitivity and no stages), or remove the
        full response to acceleration (:meth:`obspy.core.trace.Trace.remove_response`, no
        pre-filter; falls back to the sensitivity, and says so, when there are no stages).
    channel_map : dict, optional
        ``{channel code, SEED id or file name: "H1" | "H2" | "V"}`` when the files do not tell
        the components; unmapped traces are left out.
    event : str, os.PathLike, obspy.core.event.Event, obspy.Catalog or dict, optional
        The earthquake (QuakeML file or object), summarised into ``metadata["event"]``.
    gaps : {"refuse", "interpolate"}, optional
        What to do with gaps inside a channel: refuse them (default), or fill gaps of up to
        :data:`MAX_INTERPOLATED_GAP_S` by linear interpolation. Overlapping traces of a channel
        must hold the same samples.
    align : {"trim", "resample", "strict"}, optional
        ``"trim"`` (default) trims components of one sampling rate to their common time window,
        dropping at most :data:`WINDOW_TOLERANCE_FRACTION` of the record's span (or one sample);
        ``"resample"`` also brings components of different rates to the lowest (anti-alias
        low-pass first); ``"strict"`` refuses any mismatch.
    format : str, optional
        obspy format name for all files (auto-detected when omitted).
    differentiate : bool, optional
        Differentiate velocity records (a velocity sensor's sensitivity, a velocity unit given or
        stated by the file) to acceleration; without it they are refused. Said in the provenance.
    sensor : str, optional
        Which sensor of a station to use when the files hold several: the first two letters of the
        channel code (``"HN"``), optionally after the location (``"02.HN"``; K-NET/KiK-net:
        ``"01"`` is the borehole, ``"02"`` the surface sensor).
    **read_kwargs
        Passed to the file reader (e.g. ``dt`` [s] for one-column text files).

    Returns
    -------
    GroundMotion
        The aligned components in m/s^2 with their provenance in ``metadata``.

    Raises
    ------
    ParameterError
        Before any file is read, naming the argument and what it expects (a
        :class:`~shipblock.errors.ParameterTypeError`, also a :class:`TypeError`, for a wrong
        type): a source that is not a path, list of paths, Stream or Trace; an unknown unit
        (``units="furlongs"``), response, alignment, gap rule or format; an azimuth that is not a
        number within +-360 deg; a horizontal other than H1/H2, or both; a channel_map that is
        not a dict of components; ``differentiate`` not a bool; ``sensor`` not a string, or one
        the record does not hold; a reader keyword such as ``dt`` out of range.
    RecordError
        For a path (record, inventory or event) that names no file, or a folder where a file is
        needed (the message names the argument); for unreadable, corrupt or truncated files,
        unknown formats, NaN/inf samples, empty traces, gaps, overlapping records with different
        samples, components of different rates or windows (beyond the tolerances above),
        accelerations above 100 g, a sensitivity or calibration that is not a number an
        instrument has, missing horizontals, or an inventory that does not match.
    UnitsError
        If the units of a trace are unknown or contradictory.
    """
    options = check_read_arguments(inventory=inventory, units=units, response=response,
                                   differentiate=differentiate, align=align, gaps=gaps,
                                   event=event, format=format)
    inventory, event, format = options["inventory"], options["event"], options["format"]
    differentiate = options["differentiate"]
    if azimuth is not None:
        azimuth = checks.azimuth(azimuth, "azimuth")
    if horizontal is not None:
        checks.choice(horizontal, "horizontal", ("H1", "H2"))
    if azimuth is not None and horizontal is not None:
        raise ParameterError("azimuth and horizontal exclude each other: give azimuth= or"
                             " horizontal=, not both")
    channel_map = _check_channel_map(channel_map)
    sensor = checks.text(sensor, "sensor", optional=True,
                         what="a sensor code such as 'HN' or '02.HN'")
    paths_or_stream = _check_sources(paths_or_stream)
    if _names_many(paths_or_stream):
        return _one_of_folder(paths_or_stream, inventory, units, response, differentiate, align,
                              gaps, event, azimuth, horizontal, sensor)
    stream = _load_stream(paths_or_stream, units, format, read_kwargs)
    label = ", ".join(dict.fromkeys(_source(tr) for tr in stream)) or "<stream>"
    if len(stream) == 0:
        raise RecordError(label, "no traces")
    for trace in stream:
        _check_finite(trace)
    stream = _merge_gaps(stream, gaps)
    stream = _select_sensor(stream, sensor, channel_map)
    inv, inventory_name = _load_inventory(inventory)
    notes: list[str] = []
    processing: list[str] = []
    with warnings.catch_warnings():
        warnings.filterwarnings("ignore", message="Found more than one matching")
        assigned = _assign_components(stream, inv, channel_map, notes, processing)
    units_done = {}
    for component, trace in assigned.items():
        with warnings.catch_warnings():
            warnings.filterwarnings("ignore", message="Found more than one matching")
            units_done[component] = _to_si(
                trace, inv, inventory_name, units, response, differentiate
            )
        _check_finite(trace)
        check_plausible_samples(np.asarray(trace.data), _source(trace),
                                f"channel {trace.id} ({units_done[component]})")
    sites = {trace.stats.get("sensor_site") for trace in assigned.values()} & set(SITE_NOTES)
    for site in sorted(sites):
        notes.append(SITE_NOTES[site])
        logger.warning("%s: %s", label, notes[-1])
    if "V" in assigned:
        mean = float(np.mean(assigned["V"].data))
        if abs(mean) > GRAVITY_NOTE_THRESHOLD:
            notes.append(
                f"V ({assigned['V'].id}) averages {mean:.4g} m/s^2: gravity or an offset in the"
                " record; remove it (baseline correction) before simulating"
            )
            logger.warning("%s: %s", label, notes[-1])
    traces = [assigned[c] for c in COMPONENTS if c in assigned]
    _align(traces, align, processing)
    result = Stream(traces)
    first = traces[0].stats
    station = {"network": first.network, "station": first.station, "location": first.location}
    if "coordinates" in first:
        station["coordinates"] = dict(first.coordinates)
    elif inv is not None:
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                station["coordinates"] = inv.get_coordinates(traces[0].id, first.starttime)
        except Exception:  # noqa: BLE001 - coordinates are optional
            pass
    event_summary = _load_event(event)
    if event_summary is None and "shipblock_at2" in first:
        event_summary = {"name": first.shipblock_at2.event}
    metadata = {
        "station": station,
        "event": event_summary,
        "channels": {c: assigned[c].id for c in COMPONENTS if c in assigned},
        "azimuths": {c: assigned[c].stats.get("azimuth") for c in ("H1", "H2") if c in assigned},
        "source_files": list(dict.fromkeys(_source(tr) for tr in traces)),
        "inventory": inventory_name,
        "units": units_done,
        "processing": processing,
        "notes": notes,
        "horizontal": (
            f"projected on azimuth {azimuth:g} deg" if azimuth is not None
            else (horizontal or ("H1" if "H1" in assigned else "H2"))
        ),
    }
    gm = GroundMotion(result, metadata, azimuth=azimuth, horizontal=horizontal)
    gm.horizontal  # noqa: B018 - fail now, not in the solver, if the choice is impossible
    logger.debug("read %s", gm)
    return gm
