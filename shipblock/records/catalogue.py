"""The catalogue of shipped ground-motion records (``records/catalogue.toml``).

Each ``[[record]]`` table of the catalogue names one station's record: its files, StationXML
inventory, event (QuakeML), station and site, licence and credit, and the mapping of its channel
codes to the components H1, H2 and V. Paths are relative to the catalogue file.
:func:`load_catalogue` parses and validates the file (without reading any waveform); each
:class:`CatalogueEntry` reads its :class:`~shipblock.records.motion.GroundMotion` on demand.
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from shipblock import checks
from shipblock.errors import ParameterError, ParameterTypeError, RecordError
from shipblock.io import code_from_name
from shipblock.records.arguments import check_read_arguments
from shipblock.records.folders import MotionSet
from shipblock.records.motion import COMPONENTS, GroundMotion
from shipblock.records.reading import read_motion
from shipblock.units import STANDARD_GRAVITY

__all__ = ["READ_KEYS", "CatalogueEntry", "catalogue_toml", "default_catalogue_path",
           "load_catalogue", "record_file_stem", "record_id", "relative_path", "toml_value"]

#: Catalogue layout version this module reads.
SCHEMA_VERSION = 1

_REQUIRED = ("id", "files", "station")

#: Keys of a catalogue entry that are options of reading it (read_motion's keywords of the same
#: name; ``components`` is its channel_map, ``units``, ``inventory`` and ``event`` are entry
#: fields). What they accept is what read_motion and the command-line flags accept
#: (:data:`shipblock.checks.READ_OPTIONS`).
READ_KEYS = ("response", "differentiate", "align", "gaps", "format", "sensor", "dt", "data_type",
             "resample_rate", "resample_interval")


def default_catalogue_path() -> Path:
    """Return the path of the repository's catalogue, ``records/catalogue.toml``.

    Returns
    -------
    pathlib.Path
        ``<repository>/records/catalogue.toml`` (the records are not part of the wheel).
    """
    return Path(__file__).resolve().parents[2] / "records" / "catalogue.toml"


@dataclass(frozen=True)
class CatalogueEntry:
    """One shipped record (one station of one earthquake).

    Attributes
    ----------
    id : str
        Unique name, e.g. ``"south-napa-2014/NP.1765"``.
    files : tuple of pathlib.Path
        Waveform files (absolute).
    inventory : pathlib.Path or None
        StationXML with the instrument response, for raw counts.
    event : pathlib.Path or None
        QuakeML of the earthquake.
    network, station : str
        SEED network and station codes.
    site : str
        Site description.
    license, credit : str
        Terms of use and the credit line to give (empty when not known: a private record).
    components : dict
        Channel code (or file name) -> ``"H1"``, ``"H2"`` or ``"V"``.
    units : str or None
        Unit to state for files that carry none (``None`` when the files or the inventory tell).
    options : dict
        The entry's read options (keys of :data:`READ_KEYS`: ``align = "resample"``,
        ``dt = 0.01``, ``data_type = "acceleration"``, ...), passed to
        :func:`shipblock.read_motion`.
    extra : dict
        Every other key of the table (event name, coordinates, source, ...).
    """

    id: str
    files: tuple[Path, ...]
    inventory: Path | None
    event: Path | None
    network: str
    station: str
    site: str
    license: str
    credit: str
    components: dict = field(default_factory=dict)
    units: str | None = None
    options: dict = field(default_factory=dict)
    extra: dict = field(default_factory=dict)

    def read(self, azimuth: float | None = None, horizontal: str | None = None,
             **kwargs) -> GroundMotion:
        """Read the record into a ground motion in m/s^2.

        Parameters
        ----------
        azimuth : float, optional
            Dock transverse axis [deg clockwise from north]; see :func:`shipblock.read_motion`.
        horizontal : {"H1", "H2"}, optional
            Use one horizontal as-is.
        **kwargs
            Passed to :func:`shipblock.read_motion` (e.g. ``response="full"``); they take the
            place of the entry's own read options (:attr:`options`) of the same name.

        Returns
        -------
        GroundMotion
            The motion, with the catalogue entry's licence and credit in ``metadata["catalogue"]``.

        Raises
        ------
        ParameterError
            If a keyword is one the entry sets (``units``, ``inventory``, ``event``,
            ``channel_map``, the files), or as :func:`shipblock.read_motion` for a wrong one.
        """
        fixed = sorted(set(kwargs) & {"paths_or_stream", "inventory", "units", "channel_map",
                                      "event"})
        if fixed:
            raise ParameterError(f"{fixed[0]} is set by the catalogue entry {self.id!r}; edit"
                                 " the catalogue to change it (or read the files with"
                                 " read_motion)")
        gm = read_motion(
            [str(p) for p in self.files],
            inventory=None if self.inventory is None else str(self.inventory),
            units=self.units,
            azimuth=azimuth,
            horizontal=horizontal,
            channel_map=self.components or None,
            event=None if self.event is None else str(self.event),
            **{**self.options, **kwargs},
        )
        gm.metadata["catalogue"] = {
            "id": self.id, "site": self.site, "license": self.license, "credit": self.credit,
        }
        return gm


def _path(base: Path, value, catalogue: Path, entry_id: str, key: str) -> Path:
    if not isinstance(value, str) or not value:
        raise RecordError(catalogue, f"record {entry_id!r}: {key} must be a non-empty path")
    path = (base / value).resolve()
    if not path.is_file():
        raise RecordError(catalogue, f"record {entry_id!r}: {key} {value!r} does not exist")
    return path


#: Keys of a catalogue record whose values are words (strings).
_TEXT_KEYS = ("id", "network", "station", "site", "license", "credit")


def _entry(table: dict, base: Path, catalogue: Path) -> CatalogueEntry:
    entry_id = table.get("id", "?")
    missing = [k for k in _REQUIRED if k not in table]
    if missing:
        raise RecordError(catalogue, f"record {entry_id!r} lacks {', '.join(missing)}")
    for key in _TEXT_KEYS:
        if key in table and not isinstance(table[key], str):
            raise RecordError(catalogue, f"record {entry_id!r}: {key} must be a string, got"
                                         f" {table[key]!r}")
    if not table["id"].strip():
        raise RecordError(catalogue, "a record's id is empty: id must be a non-empty string")
    try:
        checks.label(table["id"], "id", what="a record id")
    except ParameterError as exc:
        raise RecordError(catalogue, f"record {entry_id!r}: {exc}") from None
    files = table["files"]
    if isinstance(files, str):
        files = [files]
    if not isinstance(files, list):
        raise RecordError(catalogue, f"record {entry_id!r}: files must be a path or a list of"
                                     f" paths, got {files!r}")
    if not files:
        raise RecordError(catalogue, f"record {entry_id!r} lists no files")
    components = table.get("components", {})
    if not isinstance(components, dict):
        raise RecordError(catalogue, f"record {entry_id!r}: components must be a table of channel"
                                     f" code = component, got {components!r}")
    bad = {k: v for k, v in components.items() if v not in COMPONENTS}
    if bad:
        raise RecordError(catalogue, f"record {entry_id!r}: components must map to {COMPONENTS}:"
                                     f" {bad}")
    units = table.get("units")
    if units is not None:
        try:
            checks.unit(units, "units")
        except ParameterError as exc:
            raise RecordError(catalogue, f"record {entry_id!r}: {exc}") from None
    options = _read_options(table, catalogue, entry_id)
    known = {"id", "files", "inventory", "event", "network", "station", "site", "license",
             "credit", "components", "units", *READ_KEYS}
    return CatalogueEntry(
        id=str(entry_id),
        files=tuple(_path(base, f, catalogue, entry_id, "file") for f in files),
        inventory=(_path(base, table["inventory"], catalogue, entry_id, "inventory")
                   if table.get("inventory") else None),
        event=(_path(base, table["event"], catalogue, entry_id, "event")
               if table.get("event") else None),
        network=str(table.get("network", "")),
        station=str(table["station"]),
        site=str(table.get("site", "")),
        license=str(table.get("license", "")),
        credit=str(table.get("credit", "")),
        components=dict(components),
        units=units,
        options=options,
        extra={k: v for k, v in table.items() if k not in known},
    )


def _read_options(table: dict, catalogue: Path, entry_id) -> dict:
    """The read options of a catalogue entry (:data:`READ_KEYS`), checked as read_motion
    checks them; a wrong one is an error naming the catalogue, the record and the key."""
    options = {key: table[key] for key in READ_KEYS if key in table}
    try:
        checked = check_read_arguments(**{k: v for k, v in options.items()
                                          if k in ("response", "differentiate", "align", "gaps",
                                                   "format")})
        if "format" in options:
            options["format"] = checked["format"]
        if "sensor" in options:
            checks.text(options["sensor"], "sensor", what="a sensor code such as 'HN' or '02.HN'")
        for key in ("dt", "resample_interval"):
            if key in options:
                options[key] = checks.time_step(options[key], key)
        if "resample_rate" in options:
            options["resample_rate"] = checks.real(
                options["resample_rate"], "resample_rate", low=1.0 / checks.MAX_TIME_STEP,
                high=1.0 / checks.MIN_TIME_STEP, units="Hz")
        if "data_type" in options:
            checks.choice(options["data_type"], "data_type", ("acceleration",))
    except ParameterError as exc:
        raise RecordError(catalogue, f"record {entry_id!r}: {exc} (a key of the [[record]]"
                                     " table)") from None
    return options


def load_catalogue(path=None) -> dict[str, CatalogueEntry]:
    """Load a record catalogue.

    Parameters
    ----------
    path : str or os.PathLike, optional
        A catalogue TOML file; default :func:`default_catalogue_path`.

    Returns
    -------
    dict
        Entry id -> :class:`CatalogueEntry`, in file order.

    Raises
    ------
    ParameterError
        If ``path`` is not a path (also a :class:`TypeError`).
    RecordError
        If the file is missing, a folder or malformed, an entry lacks a required key or has one of
        the wrong type (files, components, an unknown units word), an id repeats, or a listed
        file does not exist.
    """
    catalogue = (default_catalogue_path() if path is None
                 else Path(checks.pathname(path, "path", "a catalogue TOML file")))
    if catalogue.is_dir():
        raise RecordError(catalogue, "is a folder, not a file (path must name a catalogue TOML"
                                     " file; 'shipblock catalogue FOLDER' writes one)")
    document = checks.toml_file(catalogue, "catalogue file", error=RecordError)
    version = document.get("schema_version", SCHEMA_VERSION)
    if version != SCHEMA_VERSION:
        raise RecordError(catalogue, f"schema_version {version} is not {SCHEMA_VERSION}")
    base = catalogue.resolve().parent
    tables = document.get("record", [])
    if not (isinstance(tables, list) and all(isinstance(t, dict) for t in tables)):
        raise RecordError(catalogue, "record must be an array of tables ([[record]] sections)")
    entries: dict[str, CatalogueEntry] = {}
    for table in tables:
        entry = _entry(table, base, catalogue)
        if entry.id in entries:
            raise RecordError(catalogue, f"record id {entry.id!r} appears twice")
        entries[entry.id] = entry
    return entries


# --------------------------------------------------------------------------------------------
# Writing a catalogue from a folder of records
# --------------------------------------------------------------------------------------------


def toml_value(value) -> str:
    """A TOML literal for a string, number or list of them (JSON's string escapes are TOML's)."""
    import json
    import math

    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, (int, float)):
        if isinstance(value, float) and not math.isfinite(value):
            raise ValueError(f"cannot write {value!r} to TOML")
        return repr(float(value)) if isinstance(value, float) else str(value)
    if isinstance(value, (list, tuple)):
        return "[" + ", ".join(toml_value(v) for v in value) + "]"
    return json.dumps(str(value), ensure_ascii=False)


def relative_path(path, base: Path) -> str:
    """``path`` relative to the folder ``base``, with forward slashes (as a catalogue stores it)."""
    import os

    return Path(os.path.relpath(Path(path).resolve(), base)).as_posix()


def _station_inventories(paths) -> dict[Path, object]:
    """Each StationXML file parsed once: path -> obspy Inventory (unreadable files left out)."""
    import warnings

    import obspy

    parsed = {}
    for path in paths:
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                parsed[Path(path)] = obspy.read_inventory(str(path))
        except Exception:  # noqa: BLE001 - read_motions already reported it
            continue
    return parsed


def _inventory_file(motion, inventories: dict) -> Path | None:
    """The StationXML file among the parsed ``inventories`` that holds the motion's station."""
    station = motion.metadata.get("station") or {}
    for path, inventory in inventories.items():
        if len(inventory.select(network=station.get("network"), station=station.get("station"))):
            return path
    return None


def _id_part(text: str) -> str:
    """A piece of a record id: runs of anything but letters, digits, ``_`` and ``-`` become one
    ``-`` (``"Anaheim - Lakeview & Riverdale"`` -> ``"Anaheim-Lakeview-Riverdale"``)."""
    return code_from_name(text)


def record_id(motion: GroundMotion) -> str:
    """The catalogue id of a record: ``NET.STA.LOC.SENSOR`` (SEED codes, e.g. ``NP.1765..HN``).

    A record without a network code (PEER AT2, Kinemetrics EVT, SMC) is named by its station and
    sensor (or its channels when they are no SEED codes) instead, each cleaned by
    :func:`_id_part`: ``CORRALITOS.HN`` (Loma Prieta, ``RSN753_LOMAP_CLS000.AT2``, read as
    ``.CORRALITOS..HNN``), ``ANAHEIM-LAKEVIEW-RIVERDALE.HN``. Ids never start with a dot or hold
    spaces, so that file names made of them are neither hidden nor quoted.

    Parameters
    ----------
    motion : GroundMotion

    Returns
    -------
    str
    """
    station = motion.metadata.get("station") or {}
    first = motion.stream[0]
    channel = first.stats.channel
    seed = len(channel) == 3 and channel[:2].isalpha()
    if station.get("network") and seed:
        return ".".join([station.get("network", ""), station.get("station", ""),
                         station.get("location", ""), channel[:2]])
    channels = "-".join(_id_part(tr.stats.channel) for tr in motion.stream if tr.stats.channel)
    parts = [_id_part(station.get(key, "")) for key in ("network", "station", "location")]
    parts.append(_id_part(channel[:2]) if seed else channels)
    parts = [part for part in parts if part]
    if not parts:  # nothing names it: its first file
        parts = [_id_part(Path(motion.metadata.get("source_files", ["record"])[0]).stem)]
    return ".".join(parts)


def record_file_stem(record: str) -> str:
    """A file name stem made of a record id: ``/`` and anything but letters, digits, ``.``, ``_``
    and ``-`` become ``_``, and no leading dot (no hidden files).

    Parameters
    ----------
    record : str
        A record id (``"south-napa-2014/NP.1765..HN"``).

    Returns
    -------
    str
        E.g. ``"south-napa-2014_NP.1765..HN"``.
    """
    stem = re.sub(r"[^A-Za-z0-9._-]+", "_", str(record)).lstrip(".")
    return stem or "record"


def catalogue_toml(motions, output, licence: str | None = None, credit: str | None = None,
                   units: str | None = None, options: dict | None = None) -> str:
    """The text of a record catalogue for the records of a :class:`~shipblock.records.folders.MotionSet`.

    Each record becomes a ``[[record]]`` table that :func:`load_catalogue` reads back: id
    (``NET.STA.LOC.SENSOR``), files and StationXML inventory relative to the catalogue's folder,
    the channel -> component mapping, station, event, format, sampling interval ``dt_s``,
    duration ``duration_s``, start time and the peak of each component (``pga_m_s2`` and
    ``pga_g``: of the record as read, before any processing). ``license`` and ``credit`` are
    written when given (a private record has none). Files and groups that could not be read are
    listed in comments at the top.

    Parameters
    ----------
    motions : MotionSet
        From :func:`shipblock.records.folders.read_motions`.
    output : str or os.PathLike
        Where the catalogue will be written (paths in it are relative to its folder).
    licence, credit : str, optional
        Terms of use and credit line of the records.
    units : str, optional
        The ``units=`` the records were read with (stored so that they read back the same).
    options : dict, optional
        The read options the records were read with (:func:`read_motions`' keywords: ``units``,
        ``event``, ``align``, ``dt``, ...), stored in each entry so that it reads back the same
        (``channel_map`` is stored as each entry's components, ``inventory`` as the StationXML
        file that holds the station).

    Returns
    -------
    str
        TOML text.

    Raises
    ------
    ParameterError
        Naming the argument (also a :class:`TypeError` for a wrong type): ``motions`` not a
        MotionSet, ``output`` not a path, ``licence`` or ``credit`` not a string, an unknown
        ``units``.
    """
    if not isinstance(motions, MotionSet):
        raise ParameterTypeError(f"motions must be a MotionSet (from read_motions), got "
                                 f"{type(motions).__name__} {motions!r}"[:300])
    output = checks.pathname(output, "output", "the catalogue file to write")
    licence = checks.text(licence, "licence", optional=True)
    credit = checks.text(credit, "credit", optional=True)
    options = dict(options or {})
    units = options.pop("units", units)
    if units is not None:
        checks.unit(units, "units")
    base = Path(output).resolve().parent
    inventories = _station_inventories(p for p in motions.skipped if p.lower().endswith(".xml"))
    lines = [
        "# Record catalogue written by 'shipblock catalogue'. One [[record]] table per station",
        "# sensor; paths are relative to this file. pga_* are peaks of the records as read (before",
        "# baseline correction and filtering).",
        f"# {len(motions.motions)} records; {len(motions.failures)} files or groups not used:",
    ]
    lines += [f"#   {where}: {why}".replace("\n", " ") for where, why in motions.failures]
    lines += ["", f"schema_version = {SCHEMA_VERSION}", ""]
    seen: dict[str, int] = {}
    for motion in motions.motions:
        md = motion.metadata
        station = md.get("station") or {}
        first = motion.stream[0]
        name = record_id(motion)
        seen[name] = seen.get(name, 0) + 1
        if seen[name] > 1:
            name += f"-{seen[name]}"
        table = {
            "id": name,
            "files": [relative_path(f, base) for f in md.get("source_files", [])],
            "network": station.get("network", ""),
            "station": station.get("station", ""),
            "location": station.get("location", ""),
            "format": str(first.stats.get("_format", "")),
            "starttime": str(motion.starttime),
            "dt_s": float(motion.dt),
            "npts": int(motion.npts),
            "duration_s": float(motion.dt * (motion.npts - 1)),
        }
        inventory = _inventory_file(motion, inventories) if md.get("inventory") else None
        if inventory is None and isinstance(options.get("inventory"), str):
            inventory = options["inventory"]  # given with --inventory
        if inventory is not None:
            table["inventory"] = relative_path(inventory, base)
        if units:
            table["units"] = units
        if options.get("event") is not None and isinstance(options["event"], str):
            table["event"] = relative_path(options["event"], base)
        for key in READ_KEYS:
            if options.get(key) is not None:
                table[key] = options[key]
        event = md.get("event") or {}
        if event.get("id") or event.get("name"):
            table["event_name"] = str(event.get("id") or event.get("name"))
        coordinates = station.get("coordinates") or {}
        for key in ("latitude", "longitude"):
            if coordinates.get(key) is not None:
                table[key] = float(coordinates[key])
        if licence:
            table["license"] = licence
        if credit:
            table["credit"] = credit
        for component, data in motion.components.items():
            peak = float(np.max(np.abs(data)))
            table[f"pga_{component}_m_s2"] = peak
            table[f"pga_{component}_g"] = peak / STANDARD_GRAVITY
        lines.append("[[record]]")
        lines += [f"{key} = {toml_value(value)}" for key, value in table.items()]
        lines += ["", "[record.components]    # channel code -> component"]
        for component, seed_id in md.get("channels", {}).items():
            lines.append(f"{toml_value(seed_id)} = {toml_value(component)}")
        lines.append("")
    return "\n".join(lines)
