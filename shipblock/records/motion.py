"""The record type: a ground motion in m/s^2, with its components and provenance.

:class:`GroundMotion` holds the aligned components H1, H2 and V of one record (an obspy Stream
whose traces are tagged with :data:`COMPONENT_KEY`) and the provenance of every conversion in
``metadata``; :func:`read_motion` (:mod:`shipblock.records.reading`) builds one from files,
:meth:`GroundMotion.from_arrays` from arrays. Component conventions: H1 and H2 are the
horizontals (H1 the record's first, which the solver uses by default:
:data:`shipblock.records.sensors.HORIZONTAL_RULE`), V the vertical, positive up. Azimuths
are in degrees clockwise from north.
"""

from __future__ import annotations

import copy
import math
import os
from collections.abc import Mapping

import numpy as np
from obspy import Stream, Trace, UTCDateTime

from shipblock import checks
from shipblock.errors import ParameterError, ParameterTypeError, RecordError, UnitsError
from shipblock.io import check_plausible_samples, check_sampling_interval
from shipblock.units import si_factor

__all__ = ["COMPONENTS", "COMPONENT_KEY", "GroundMotion", "check_motion", "require_components",
           "rotate_to_azimuth"]

#: Component names, in order.
COMPONENTS = ("H1", "H2", "V")

#: Key of ``trace.stats`` that tags each trace with its component name. (obspy reserves
#: ``stats.motion_component``: it is the last letter of the channel code, and setting it renames the
#: channel, so the tag lives under its own key.)
COMPONENT_KEY = "motion_component"

#: Largest departure from a right angle accepted between two horizontals, and from exact
#: vertical/horizontal accepted for a sensor axis [deg].
ORIENTATION_TOLERANCE = 1.0

#: The unit obspy's traces of a GroundMotion carry (``stats.units``).
SI_UNITS = "m/s**2"


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


def check_direction(azimuth, horizontal) -> float | None:
    """``azimuth`` checked (a number within +-360 deg, or None), ``horizontal`` one of H1/H2 or
    None, not both given; returns the azimuth [deg]."""
    if azimuth is not None:
        azimuth = checks.azimuth(azimuth, "azimuth")
    if horizontal is not None:
        checks.choice(horizontal, "horizontal", ("H1", "H2"))
    if azimuth is not None and horizontal is not None:
        raise ParameterError("azimuth and horizontal exclude each other: give azimuth= or"
                             " horizontal=, not both")
    return azimuth


def trace_source(trace: Trace) -> str:
    """The file a trace was read from, for messages (``"<stream>"`` for traces in memory)."""
    return str(trace.stats.get("source_file", "<stream>"))


def check_finite(trace: Trace) -> None:
    """Refuse a trace without samples or with NaN/inf samples (RecordError naming the file)."""
    name = trace_source(trace)
    if trace.stats.npts == 0 or len(trace.data) == 0:
        raise RecordError(name, f"channel {trace.id} has no samples (zero-length trace)")
    data = np.asarray(trace.data)
    if np.issubdtype(data.dtype, np.floating):
        bad = ~np.isfinite(data)
        if bad.any():
            raise RecordError(name, f"channel {trace.id} has {int(bad.sum())} NaN/inf samples")


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
        if trace.stats.get("units", SI_UNITS) != SI_UNITS:
            raise UnitsError(label, f"trace {component} is in {trace.stats.units}, not m/s**2")
        check_finite(trace)
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
        azimuth = check_direction(azimuth, horizontal)
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
            trace.stats.units = SI_UNITS
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
        """Short name: the catalogue id, else NET.STA, else the name given to :meth:`from_arrays`
        (as given: it is a label, not a file), else the first file's name (a file that states no
        codes, e.g. an SMC file of type ``0 UNKNOWN``), else ``"record"``; never a dict's repr."""
        md = self._metadata
        cat = md.get("catalogue") or {}
        if cat.get("id"):
            return str(cat["id"])
        st = md.get("station")
        if not isinstance(st, Mapping):
            return str(st or md.get("name") or "record")
        if st.get("network") or st.get("station"):
            return ".".join(code for code in (st.get("network"), st.get("station")) if code)
        if st.get("name"):
            return str(st["name"])
        if md.get("source_files"):
            return os.path.basename(str(md["source_files"][0]))
        return str(md.get("name") or "record")

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
                        f" (use one as recorded: {checks.how_to_pass('horizontal', 'H1')}; or give"
                        " an inventory with azimuths: "
                        f"{checks.how_to_pass('inventory', 'FILE.xml', placeholder=True)})"
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


def check_motion(value, name: str = "motion") -> GroundMotion:
    """``value`` checked to be a :class:`GroundMotion`, or a ParameterTypeError naming ``name``."""
    if not isinstance(value, GroundMotion):
        raise ParameterTypeError(
            f"{name} must be a shipblock.GroundMotion (from read_motion or "
            f"GroundMotion.from_arrays), got {type(value).__name__}")
    return value


def require_components(motion: GroundMotion, components, *, record: str, key: str) -> None:
    """Refuse a record that lacks components a study needs.

    A pipeline whose vertical is scaled with the horizontal (``vertical = "same"``) needs a
    vertical in every record: without one the runs would be horizontal-only, and only NaNs in
    the results would show it.

    Parameters
    ----------
    motion : GroundMotion
        The record as read.
    components : iterable of {"H1", "H2", "V"}
        The components needed (``"H1"`` stands for any horizontal: a record has H1 or H2).
    record : str
        The record's id, for the message.
    key : str
        What needs them, as the user wrote it (``'vertical = "same"'``), for the message.

    Raises
    ------
    RecordError
        Naming the record, the missing components, what it holds, and ``key``.
    ParameterError
        If a component name is not one of :data:`COMPONENTS`.

    Examples
    --------
    >>> require_components(motion, ("H1", "V"), record="CORRALITOS.HN",
    ...                    key='vertical = "same"')  # doctest: +SKIP
    """
    held = set(motion.components)
    missing = []
    for component in components:
        checks.choice(component, "components", COMPONENTS)
        if component == "H1" and held & {"H1", "H2"}:
            continue
        if component not in held:
            missing.append(component)
    if missing:
        name = "vertical (V)" if missing == ["V"] else "component " + ", ".join(missing)
        raise RecordError(
            record, f"has no {name}; it holds {', '.join(c for c in COMPONENTS if c in held)},"
            f" but {key} needs it (leave the record out, or choose a study setting that does"
            " not need it)")
