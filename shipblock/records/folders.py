"""Folders of record files: grouped into ground motions, with every unreadable file named.

An agency download is a folder (or a glob) of files: one file per component (K-NET, MiniSEED,
SAC, ESM), three components per file (CSMIP, GeoNet, COSMOS), StationXML inventories and an
event file beside them. :func:`read_motions` reads every file it can, groups the traces into
one record per station sensor, converts each the way
:func:`~shipblock.records.reading.read_motion` does
(:func:`~shipblock.records.assembly.assemble_motion`), and returns the records together with
the list of files and groups that could not be used and why. One bad file never costs the
others.

Grouping key of a trace: network, station, location, the first two letters of the channel
(band and instrument: one sensor; K-NET/KiK-net borehole and surface sensors have locations
``01``/``02``), the format, and, for formats whose files are processing volumes (CSMIP ``.V1``
and ``.V2``, GeoNet ``.V1A`` and ``.V2A``, ...), the file's extension, so that a station's
uncorrected and corrected volumes are two records, not one with six components. Traces of one
key whose time windows do not overlap are different records (two earthquakes at one station,
or a recording split in two files); the traces of one file are never split by time (a damaged
record time then fails that file's record, by name, instead of making a record of its own). A
channel that still appears twice (two copies of one record, in two folders or two files) splits
the group by folder, then by file.
"""

from __future__ import annotations

import glob as globbing
import logging
import os
import warnings
from dataclasses import dataclass, field
from pathlib import Path

import obspy
from obspy import Stream

from shipblock import checks
from shipblock.errors import ParameterError, RecordError, ShipblockError
from shipblock.io import check_reader_keywords, read_record
from shipblock.records.arguments import check_channel_map, check_read_arguments
from shipblock.records.assembly import assemble_motion, load_stream
from shipblock.records.motion import GroundMotion
from shipblock.records.sensors import select_sensor, sensor_code

__all__ = ["MotionSet", "expand_sources", "read_motions"]

logger = logging.getLogger(__name__)

#: Extensions of files in agency folders that are never waveforms (lower case).
NOT_WAVEFORMS = {".json", ".yml", ".yaml", ".md", ".toml", ".zip", ".png", ".jpg", ".pdf",
                 ".html", ".py", ".pkl", ".xlsx", ".hdf", ".h5", ".grd", ".gz"}

#: Formats whose components come one per file, named by the file's extension (the extension is
#: then not a processing volume and does not enter the grouping key).
_COMPONENT_PER_EXTENSION = {"KNET", "MSEED", "SAC", "SHIPBLOCK_ESM", "SHIPBLOCK_AT2",
                            "SHIPBLOCK_USC", "SHIPBLOCK_SMC"}


@dataclass
class MotionSet:
    """The records read from a folder or glob, and what could not be read.

    Attributes
    ----------
    motions : list of GroundMotion
        One per station sensor (and processing volume), in file order.
    failures : list of (str, str)
        ``(file or record, reason)`` for every file that could not be read and every group of
        traces that did not make a ground motion.
    skipped : list of str
        Files that are not waveforms (by extension) or were used as inventory/event files.
    """

    motions: list[GroundMotion] = field(default_factory=list)
    failures: list[tuple[str, str]] = field(default_factory=list)
    skipped: list[str] = field(default_factory=list)

    def __iter__(self):
        return iter(self.motions)

    def __len__(self) -> int:
        return len(self.motions)

    def __getitem__(self, index):
        return self.motions[index]


_SOURCE = "a folder, glob pattern or record file"


def expand_sources(source, name: str = "source") -> list[Path]:
    """Files named by a folder (recursively), a glob pattern, a file, or a list of them.

    Parameters
    ----------
    source : str, os.PathLike, or list or tuple of them
        What to expand.
    name : str, optional
        The argument's name, for messages.

    Raises
    ------
    ParameterError
        If ``source`` (or an item of a list, named ``source[i]``) is not a path (also a
        :class:`TypeError`), or a list is empty.
    RecordError
        If a named file or folder does not exist, or a pattern matches nothing.
    """
    if isinstance(source, (list, tuple)):
        if not source:
            raise ParameterError(f"{name} must be {_SOURCE} (str or os.PathLike), or a list of"
                                 f" them, got an empty {type(source).__name__}")
        return [path for i, item in enumerate(source)
                for path in expand_sources(item, f"{name}[{i}]")]
    path = checks.pathname(source, name, _SOURCE)
    if os.path.isdir(path):
        # Broken symbolic links are listed too: reading them names them (not skipped silently).
        return sorted(p for p in Path(path).rglob("*") if not p.name.startswith(".")
                      and (p.is_file() or (p.is_symlink() and not p.exists())))
    if os.path.isfile(path):
        return [Path(path)]
    if globbing.has_magic(path):
        matches = sorted(Path(p) for p in globbing.glob(path, recursive=True)
                         if os.path.isfile(p) or (os.path.islink(p) and not os.path.exists(p)))
        if not matches:
            raise RecordError(path, f"the pattern matches no file ({name} must name {_SOURCE})")
        return matches
    raise RecordError(path, f"no such file or folder ({name} must name {_SOURCE})")


def _xml_kind(path: Path) -> str | None:
    """``"stationxml"``, ``"quakeml"`` or ``None`` from the first bytes of an XML file."""
    try:
        with open(path, "rb") as fh:
            head = fh.read(4096)
    except OSError:
        return None
    if b"FDSNStationXML" in head:
        return "stationxml"
    if b"quakeml" in head.lower():
        return "quakeml"
    return None


def _group_key(trace) -> tuple:
    stats = trace.stats
    fmt = stats.get("_format", "")
    source = str(stats.get("source_file", ""))
    volume = "" if fmt in _COMPONENT_PER_EXTENSION else Path(source).suffix.upper()
    if not (stats.network or stats.station):
        return ("", source, "", "", fmt, volume)  # no codes: a file is a record of its own
    return (stats.network, stats.station, stats.location, sensor_code(trace).split(".", 1)[1],
            fmt, volume)


def _overlapping(stream: Stream) -> list[Stream]:
    """Split traces into clusters whose time windows overlap.

    The traces of one file stay together, whatever their times: a file holding a channel in
    pieces far apart in time is one record with gaps (refused by read_motion, naming the file),
    not several records; a damaged record time must not make a record of its own.
    """
    files: dict[str, Stream] = {}
    for trace in stream:
        files.setdefault(str(trace.stats.get("source_file", "")), Stream()).append(trace)
    units = sorted(
        ((min(tr.stats.starttime for tr in part), max(tr.stats.endtime for tr in part), part)
         for part in files.values()),
        key=lambda unit: unit[0],
    )
    clusters: list[Stream] = []
    end = None
    for start, stop, part in units:
        if end is None or start > end:
            clusters.append(Stream())
            end = stop
        clusters[-1] += part
        end = max(end, stop)
    return clusters


def _by(stream: Stream, part) -> list[Stream]:
    """Split a stream by a function of each trace's source file, keeping file order."""
    parts: dict[str, Stream] = {}
    for trace in stream:
        parts.setdefault(part(str(trace.stats.get("source_file", ""))), Stream()).append(trace)
    return list(parts.values())


def _repeats(stream: Stream) -> bool:
    ids = [trace.id for trace in stream]
    return len(ids) != len(set(ids))


def _split_groups(groups: dict[tuple, Stream]):
    """Yield ``(key, stream)`` records: time clusters, then copies split by folder and file."""
    for key, stream in groups.items():
        for cluster in _overlapping(stream):
            parts = [cluster]
            for split in (lambda f: str(Path(f).parent), lambda f: f):
                if any(_repeats(p) for p in parts):
                    parts = [q for p in parts for q in _by(p, split)]
            for part in parts:
                yield key, part


def _label(key: tuple) -> str:
    network, station, location, sensor, fmt, volume = key
    if not (network or station):
        return station or location or "?"
    if not (network or location or sensor) and Path(station).name != station:
        return Path(station).name  # no codes: the key holds the file (_group_key)
    return f"{network}.{station}.{location}.{sensor}{volume and ' ' + volume}"


def read_motions(source, inventory=None, units: str | None = None, *,
                 response: str = "sensitivity", differentiate: bool = False,
                 align: str = "trim", gaps: str = "refuse", event=None,
                 channel_map=None, sensor: str | None = None,
                 format: str | None = None, **read_kwargs) -> MotionSet:  # noqa: A002
    """Read a folder, glob or list of record files into one ground motion per station sensor.

    Parameters
    ----------
    source : str, os.PathLike or list of them
        A folder (read recursively), a glob pattern (``"records/*.V2"``) or files.
    inventory : str, os.PathLike or obspy.Inventory, optional
        StationXML for raw counts. Default: every StationXML file among the sources, merged.
    units : str, optional
        Unit of records that state none (see :func:`~shipblock.records.reading.read_motion`).
    response, differentiate, align, gaps
        As in :func:`~shipblock.records.reading.read_motion`.
    event : optional
        QuakeML file or object; default: a QuakeML file among the sources, if there is one.
    channel_map : dict, optional
        As in :func:`~shipblock.records.reading.read_motion`, applied to every record (e.g. the
        channels ``"0"``, ``"3"``, ``"4"`` of Kinemetrics EVT files).
    sensor : str, optional
        Keep only the records of this sensor (``"HN"``, ``"02.HN"``); the others are left out
        (listed in ``skipped``).
    format : str, optional
        obspy format name of every file (auto-detected when omitted).
    **read_kwargs
        Passed to every file's reader (:func:`shipblock.io.read_record`): ``dt`` [s] of
        one-column text files, ``data_type`` of SMC files, ``resample_rate``, ...

    Returns
    -------
    MotionSet
        The ground motions, and the files and groups that failed with their reasons.

    Raises
    ------
    ParameterError
        Before any file is read, if an argument is of the wrong type or value, naming it (as
        :func:`~shipblock.records.reading.read_motion`: ``units="furlongs"``,
        ``response="partial"``...);
        a wrong option is not a failure of every record.
    ParameterTypeError
        For an unknown keyword, naming the closest (``unit``: did you mean ``units``?).
    RecordError
        If the source names nothing, or an inventory or event path names no file; a folder in
        which no file is readable gives an empty set with every failure listed, not an error.
    """
    check_reader_keywords(read_kwargs, "read_motions", checks.keyword_names(read_motions))
    options = check_read_arguments(inventory=inventory, units=units, response=response,
                                   differentiate=differentiate, align=align, gaps=gaps,
                                   event=event, format=format)
    inventory, event, differentiate = (options["inventory"], options["event"],
                                       options["differentiate"])
    format = options["format"]  # noqa: A001 - obspy's name for it
    channel_map = check_channel_map(channel_map)
    sensor = checks.text(sensor, "sensor", optional=True,
                         what="a sensor code such as 'HN' or '02.HN'")
    result = MotionSet()
    paths = expand_sources(source)
    inventories, events, waveforms = [], [], []
    for path in paths:
        suffix = path.suffix.lower()
        if suffix == ".xml":
            kind = _xml_kind(path)
            if kind == "stationxml":
                inventories.append(path)
            elif kind == "quakeml":
                events.append(path)
            result.skipped.append(str(path))
        elif suffix in NOT_WAVEFORMS:
            result.skipped.append(str(path))
        else:
            waveforms.append(path)
    if inventory is None and inventories:
        inventory = obspy.Inventory()
        for path in inventories:
            try:
                inventory += obspy.read_inventory(str(path))
            except Exception as exc:  # noqa: BLE001 - a bad inventory is one failure, not all
                result.failures.append((str(path), f"cannot be read as StationXML: {exc}"))
    if event is None and len(events) == 1:
        event = str(events[0])

    groups: dict[tuple, Stream] = {}
    for path in waveforms:
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                stream = read_record(path, format=format, units=units, **read_kwargs)
        except ShipblockError as exc:
            result.failures.append((str(path), getattr(exc, "problem", str(exc))))
            continue
        for trace in stream:
            groups.setdefault(_group_key(trace), Stream()).append(trace)

    for key, stream in _split_groups(groups):
        if sensor is not None and not len(select_sensor(stream, sensor, None, strict=False)):
            result.skipped.extend(dict.fromkeys(str(tr.stats.get("source_file", ""))
                                                for tr in stream))
            continue
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                motion = assemble_motion(
                    load_stream(stream, units, None, {}), inventory=inventory, units=units,
                    response=response, differentiate=differentiate, align=align, gaps=gaps,
                    event=event, channel_map=channel_map, sensor=sensor,
                )
        except ShipblockError as exc:
            files = ", ".join(dict.fromkeys(str(tr.stats.get("source_file", "")) for tr in stream))
            result.failures.append((f"{_label(key)} ({files})", getattr(exc, "problem", str(exc))))
            continue
        result.motions.append(motion)
    logger.info("%d records read from %d files; %d failures", len(result.motions), len(paths),
                len(result.failures))
    return result
