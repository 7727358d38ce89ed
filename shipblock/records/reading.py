"""Reading a ground motion: from record files to the (horizontal, vertical) pair the solver takes.

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

Component conventions: H1 and H2 are the horizontals (H1 the record's first, used by the solver
unless ``horizontal=`` or ``azimuth=`` says otherwise:
:data:`~shipblock.records.sensors.HORIZONTAL_RULE`), V the vertical, positive up (a vertical
recorded positive down is flipped). Azimuths are in degrees clockwise from north.
"""

from __future__ import annotations

import glob as globbing
import os
from collections.abc import Iterable, Mapping

import numpy as np
from obspy import Stream, Trace

from shipblock import checks
from shipblock.errors import ParameterError, ParameterTypeError, RecordError
from shipblock.io import check_reader_keywords
from shipblock.records.arguments import check_channel_map, check_read_arguments
from shipblock.records.assembly import assemble_motion, load_stream
from shipblock.records.folders import read_motions
from shipblock.records.motion import GroundMotion, check_direction
from shipblock.records.sensors import select_sensor

__all__ = ["read_motion"]


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


def _names_many(source) -> bool:
    """Whether a source is a folder or a glob pattern (rather than files or traces)."""
    if not isinstance(source, (str, os.PathLike)):
        return False
    name = os.fspath(source)
    return os.path.isdir(name) or (not os.path.exists(name) and globbing.has_magic(name))


def _one_of_folder(source, inventory, units, response, differentiate, align, gaps, event,
                   azimuth, horizontal, sensor, channel_map, format,  # noqa: A002
                   read_kwargs) -> GroundMotion:
    """The single record (of ``sensor``, if given) of a folder or glob; refuse several."""
    found = read_motions(source, inventory=inventory, units=units, response=response,
                         differentiate=differentiate, align=align, gaps=gaps, event=event,
                         channel_map=channel_map, format=format, **read_kwargs)
    motions = found.motions
    if sensor is not None:
        motions = [m for m in motions if len(select_sensor(m.stream, sensor, None, strict=False))]
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
            + "); choose one: " + checks.how_to_pass("sensor", "HN") + ", or name its files;"
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
        :func:`shipblock.records.folders.read_motions` for a folder of many).
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
        Passed to the file reader: ``dt`` [s] for one-column text files, ``data_type``
        (``"acceleration"``) for SMC files of type ``0 UNKNOWN``, ``resample_rate`` [Hz],
        ``resample_interval`` [s] (:func:`shipblock.io.read_record`). Every option here is also
        a command-line flag and a catalogue entry key (:data:`shipblock.checks.READ_OPTIONS`).
        Any keyword that neither :func:`obspy.read` nor a format's reader takes is refused
        before a file is read (``unit="g"``: did you mean ``units``?).

    Returns
    -------
    GroundMotion
        The aligned components in m/s^2 with their provenance in ``metadata``.

    Raises
    ------
    ParameterError
        Before any file is read, naming the argument and what it expects (a
        :class:`~shipblock.errors.ParameterTypeError`, also a :class:`TypeError`, for a wrong
        type): a keyword that neither read_motion nor a reader takes, naming the closest
        one; a source that is not a path, list of paths, Stream or Trace; an unknown unit
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
    check_reader_keywords(read_kwargs, "read_motion", checks.keyword_names(read_motion))
    options = check_read_arguments(inventory=inventory, units=units, response=response,
                                   differentiate=differentiate, align=align, gaps=gaps,
                                   event=event, format=format)
    inventory, event, format = options["inventory"], options["event"], options["format"]
    differentiate = options["differentiate"]
    azimuth = check_direction(azimuth, horizontal)
    channel_map = check_channel_map(channel_map)
    sensor = checks.text(sensor, "sensor", optional=True,
                         what="a sensor code such as 'HN' or '02.HN'")
    paths_or_stream = _check_sources(paths_or_stream)
    if _names_many(paths_or_stream):
        return _one_of_folder(paths_or_stream, inventory, units, response, differentiate, align,
                              gaps, event, azimuth, horizontal, sensor, channel_map, format,
                              read_kwargs)
    stream = load_stream(paths_or_stream, units, format, read_kwargs)
    return assemble_motion(stream, inventory=inventory, units=units, response=response,
                           differentiate=differentiate, align=align, gaps=gaps, event=event,
                           azimuth=azimuth, horizontal=horizontal, channel_map=channel_map,
                           sensor=sensor)
