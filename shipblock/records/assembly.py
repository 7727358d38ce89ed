"""One ground motion from the traces of one record.

:func:`assemble_motion` is the path every record takes, whether :func:`read_motion`
(:mod:`shipblock.records.reading`) read it from files or :func:`read_motions`
(:mod:`shipblock.records.folders`) grouped it out of a folder: gaps merged
(:mod:`~shipblock.records.alignment`), a sensor chosen and the components assigned
(:mod:`~shipblock.records.sensors`), every trace converted to m/s^2
(:mod:`~shipblock.records.response`), the components aligned, and the provenance of each step
written into ``GroundMotion.metadata``.
"""

from __future__ import annotations

import logging
import os
import warnings
from collections.abc import Mapping

import numpy as np
import obspy
from obspy import Stream, Trace

from shipblock.errors import RecordError
from shipblock.io import check_plausible_samples, read_record
from shipblock.records.alignment import align_components, merge_gaps
from shipblock.records.motion import COMPONENTS, GroundMotion, check_finite, trace_source
from shipblock.records.response import to_si
from shipblock.records.sensors import assign_components, select_sensor
from shipblock.units import STANDARD_GRAVITY

__all__ = ["SITE_NOTES", "assemble_motion", "load_event", "load_inventory", "load_stream"]

logger = logging.getLogger(__name__)

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


def load_stream(paths_or_stream, units, fmt, read_kwargs) -> Stream:
    """The traces of record files (read with :func:`~shipblock.io.read_record`), or a copy of
    a Stream or Trace, each trace tagged with its ``stats.source_file``."""
    if isinstance(paths_or_stream, Stream):
        stream = paths_or_stream.copy()
        for trace in stream:
            trace.stats.setdefault("source_file", "<stream>")
        return stream
    if isinstance(paths_or_stream, Trace):
        return load_stream(Stream([paths_or_stream]), units, fmt, read_kwargs)
    single = isinstance(paths_or_stream, (str, os.PathLike))
    paths = [paths_or_stream] if single else list(paths_or_stream)
    stream = Stream()
    for path in paths:
        stream += read_record(path, format=fmt, units=units, **read_kwargs)
    return stream


def load_inventory(inventory):
    """``(obspy.Inventory or None, its name for messages)`` of a StationXML file or object."""
    if inventory is None or isinstance(inventory, obspy.Inventory):
        return inventory, ("<inventory>" if inventory is not None else None)
    name = os.fspath(inventory)  # an existing file: check_read_arguments
    try:
        return obspy.read_inventory(name), name
    except Exception as exc:  # noqa: BLE001 - any parser failure means a bad inventory file
        raise RecordError(name, f"cannot be read as a StationXML inventory: {exc}") from exc


def load_event(event):
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


def assemble_motion(stream: Stream, *, inventory=None, units: str | None = None,
                    response: str = "sensitivity", differentiate: bool = False,
                    align: str = "trim", gaps: str = "refuse", event=None,
                    azimuth: float | None = None, horizontal: str | None = None,
                    channel_map: Mapping[str, str] | None = None,
                    sensor: str | None = None) -> GroundMotion:
    """The :class:`GroundMotion` of the traces of one record, converted to m/s^2.

    Parameters
    ----------
    stream : obspy.Stream
        The record's traces, as :func:`load_stream` gives them (changed in place).
    inventory, units, response, differentiate, align, gaps, event
        As in :func:`~shipblock.records.reading.read_motion`, already checked
        (:func:`~shipblock.records.arguments.check_read_arguments`).
    azimuth, horizontal, channel_map, sensor
        As in :func:`~shipblock.records.reading.read_motion`, already checked.

    Returns
    -------
    GroundMotion
        The aligned components in m/s^2 with their provenance in ``metadata``.

    Raises
    ------
    RecordError, UnitsError
        As :func:`~shipblock.records.reading.read_motion`, naming the file.
    """
    label = ", ".join(dict.fromkeys(trace_source(tr) for tr in stream)) or "<stream>"
    if len(stream) == 0:
        raise RecordError(label, "no traces")
    for trace in stream:
        check_finite(trace)
    stream = merge_gaps(stream, gaps)
    stream = select_sensor(stream, sensor, channel_map)
    inv, inventory_name = load_inventory(inventory)
    notes: list[str] = []
    processing: list[str] = []
    with warnings.catch_warnings():
        warnings.filterwarnings("ignore", message="Found more than one matching")
        assigned = assign_components(stream, inv, channel_map, notes, processing)
    units_done = {}
    for component, trace in assigned.items():
        with warnings.catch_warnings():
            warnings.filterwarnings("ignore", message="Found more than one matching")
            units_done[component] = to_si(
                trace, inv, inventory_name, units, response, differentiate
            )
        check_finite(trace)
        check_plausible_samples(np.asarray(trace.data), trace_source(trace),
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
    align_components(traces, align, processing)
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
    event_summary = load_event(event)
    if event_summary is None and "shipblock_at2" in first:
        event_summary = {"name": first.shipblock_at2.event}
    metadata = {
        "station": station,
        "event": event_summary,
        "channels": {c: assigned[c].id for c in COMPONENTS if c in assigned},
        "azimuths": {c: assigned[c].stats.get("azimuth") for c in ("H1", "H2") if c in assigned},
        "source_files": list(dict.fromkeys(trace_source(tr) for tr in traces)),
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
