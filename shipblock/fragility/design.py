r"""Analysis designs: records x intensity levels x system parameters.

An :class:`AnalysisDesign` is the grid of runs of a fragility study:

* ``record``: the ground-motion records (catalogue ids);
* ``im_level``: the intensity levels each record is scaled to (IDA and MSA), in SI units of the
  scaling measure (PGA and Sa [m/s^2], PGV [m/s]); absent for a cloud analysis of unscaled
  records;
* one dimension per swept system parameter (:data:`SWEEP_PARAMETERS`), named after it.

Every run (a *case*) is one point of that grid. Cases are numbered in C order over the dims
``(record, im_level, *sweep)``, so the case number alone locates a run; a *chunk* is a
contiguous range of case numbers (:meth:`AnalysisDesign.chunks`), the unit of work that is sent
to :func:`shipblock.simulate_batch`, written to disk when done and never recomputed.

Swept parameters are those of the study's model
(:attr:`Model.sweep_parameters <shipblock.models.base.Model.sweep_parameters>`; for the rigid model
any field of :class:`shipblock.ShipBlockSystem` plus the conveniences ``slenderness``,
``mass_ratio``, ``mu_ground`` and ``mu_ship`` of :mod:`shipblock.models.rigid`). The design
changes a system only through :meth:`Model.vary <shipblock.models.base.Model.vary>`.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from contextlib import contextmanager
from dataclasses import dataclass, field
from functools import cached_property

import numpy as np

from shipblock.checks import MAX_PERIOD, MIN_PERIOD, choice, label, real
from shipblock.errors import ParameterError, ParameterTypeError
from shipblock.intensity import DEFAULT_DAMPING
from shipblock.models import DEFAULT_MODEL, FieldError, Model, get_model
from shipblock.models.rigid import SWEEP_PARAMETERS, SYSTEM_FIELDS, apply_parameters
from shipblock.units import STANDARD_GRAVITY

__all__ = [
    "DESIGN_TYPES",
    "IM_LEVEL_RANGE",
    "IM_MEASURES",
    "SWEEP_PARAMETERS",
    "VERTICAL_MODES",
    "AnalysisDesign",
    "IntensityDesign",
    "SYSTEM_FIELDS",
    "apply_parameters",
    "as_sweep",
    "check_levels",
]

#: Analysis types: incremental dynamic analysis, multiple-stripe analysis, cloud analysis.
DESIGN_TYPES = ("ida", "msa", "cloud")

#: Scaling intensity measures of the horizontal: name -> (SI unit, long name).
IM_MEASURES: Mapping[str, tuple[str, str]] = {
    "pga": ("m/s^2", "peak ground acceleration of the horizontal"),
    "pgv": ("m/s", "peak ground velocity of the horizontal"),
    "sa": ("m/s^2", "pseudo-spectral acceleration Sa(T) of the horizontal"),
}

#: Treatment of the vertical component (see :func:`shipblock.scaling.scale_record`): scaled by
#: the horizontal factor (keeps V/H), scaled to its own levels, left unscaled, or dropped.
VERTICAL_MODES = ("same", "independent", "unscaled", "zero")

#: Accepted range of IM levels per measure [SI units of the measure]: PGA and Sa 0.001 g to
#: 10 g, PGV 1 mm/s to 10 m/s. Outside it a level is a unit mistake (1e6 g) or no motion at
#: all, and scaling a record to it would give an implausible ground motion.
IM_LEVEL_RANGE: Mapping[str, tuple[float, float]] = {
    "pga": (1e-3 * STANDARD_GRAVITY, 10.0 * STANDARD_GRAVITY),
    "pgv": (1e-3, 10.0),
    "sa": (1e-3 * STANDARD_GRAVITY, 10.0 * STANDARD_GRAVITY),
}

@contextmanager
def _field(name: str):
    """Re-raise a ParameterError of the block as a FieldError naming ``name`` (same text)."""
    try:
        yield
    except FieldError:
        raise
    except ParameterError as exc:
        error = FieldError(name, str(exc))
        if isinstance(exc, ParameterTypeError):
            error = _FieldTypeError(name, str(exc))
        raise error from None


class _FieldTypeError(FieldError, ParameterTypeError):
    """A FieldError that is also a ParameterTypeError (a value of the wrong type)."""


def check_levels(values, name: str, measure: str) -> np.ndarray:
    """IM levels as a float array, each a number within :data:`IM_LEVEL_RANGE` of ``measure``.

    Parameters
    ----------
    values : sequence of float
        Levels in SI units of the measure.
    name : str
        The argument's name, for the message.
    measure : {"pga", "pgv", "sa"}
        The intensity measure.

    Returns
    -------
    numpy.ndarray

    Raises
    ------
    ParameterTypeError, ParameterError
        Naming the first level (``name[i]``) that is not a number within range.
    """
    if isinstance(values, str | bytes) or not isinstance(values, Sequence | np.ndarray):
        raise ParameterTypeError(f"{name} must be a sequence of IM levels, got "
                                 f"{type(values).__name__}")
    low, high = IM_LEVEL_RANGE[measure]
    units = IM_MEASURES[measure][0]
    out = []
    for i, value in enumerate(values):
        x = real(value, f"{name}[{i}]", units=units)
        if not low <= x <= high:
            in_g = (f" ({low / STANDARD_GRAVITY:g} g .. {high / STANDARD_GRAVITY:g} g)"
                    if units == "m/s^2" else "")
            raise ParameterError(f"{name}[{i}] = {x:g} {units} is outside the accepted range "
                                 f"{low:g} .. {high:g} {units}{in_g} of {measure.upper()} levels")
        out.append(x)
    return np.array(out, dtype=float)


@dataclass(frozen=True)
class IntensityDesign:
    """How records are scaled: analysis type, intensity measure and levels.

    Construction does no checking; call :meth:`validate`.

    Attributes
    ----------
    kind : {"ida", "msa", "cloud"}
        Incremental dynamic analysis (each record scaled to every level, fitted with
        :func:`~shipblock.fragility.fit.fit_ida`), multiple-stripe analysis (same runs, fitted
        per stripe with :func:`~shipblock.fragility.fit.fit_msa`) or cloud analysis (unscaled
        records, :func:`~shipblock.fragility.fit.fit_cloud`).
    measure : {"pga", "pgv", "sa"}
        Scaling intensity measure of the horizontal component.
    levels : tuple of float
        Target IM levels in SI units of the measure ([m/s^2] for PGA and Sa, [m/s] for PGV),
        strictly increasing, each within :data:`IM_LEVEL_RANGE`; empty for a cloud.
    period : float or None
        Oscillator period for ``measure="sa"`` [s], in [0.0001, 100].
    damping : float
        Fraction of critical damping for ``measure="sa"`` [-].
    vertical : {"same", "independent", "unscaled", "zero"}
        Treatment of the vertical component; ``"same"`` (default) multiplies it by the
        horizontal factor, which keeps the record's V/H ratio.
    vertical_levels : tuple of float or None
        For ``vertical="independent"``: target of the same measure for the vertical at each
        level, SI units.
    """

    kind: str
    measure: str = "pga"
    levels: tuple[float, ...] = ()
    period: float | None = None
    damping: float = DEFAULT_DAMPING
    vertical: str = "same"
    vertical_levels: tuple[float, ...] | None = None

    @property
    def units(self) -> str:
        """str: SI unit of the intensity measure."""
        return IM_MEASURES[self.measure][0]

    @property
    def scaled(self) -> bool:
        """bool: Whether records are scaled to levels (IDA, MSA) rather than used as recorded."""
        return self.kind != "cloud"

    @property
    def n_levels(self) -> int:
        """int: Number of scaling levels (1 for a cloud: the record as recorded)."""
        return len(self.levels) if self.scaled else 1

    @property
    def long_name(self) -> str:
        """str: Description of the IM, with the period for Sa."""
        name = IM_MEASURES[self.measure][1]
        if self.measure == "sa":
            name += f" at T = {self.period:g} s, {100 * self.damping:g} % damping"
        return name

    def validate(self) -> IntensityDesign:
        """Check the design and return it unchanged.

        Returns
        -------
        IntensityDesign
            ``self``.

        Raises
        ------
        shipblock.models.FieldError
            With the offending field as :attr:`~shipblock.models.base.FieldError.field` (``type``,
            ``measure``, ``period``, ``damping``, ``vertical``, ``levels``,
            ``vertical_levels``): an unknown type, measure or vertical mode, a period or
            damping out of range, a level that is not a number within
            :data:`IM_LEVEL_RANGE`, levels not strictly increasing. A
            :class:`~shipblock.errors.ParameterError` (a ``ParameterTypeError`` for a wrong
            type).
        """
        with _field("type"):
            choice(self.kind, "type", DESIGN_TYPES)
        with _field("measure"):
            choice(self.measure, "measure", tuple(IM_MEASURES))
        with _field("period"):
            if self.measure == "sa":
                if self.period is None:
                    raise ParameterError("period [s] is required for measure 'sa'")
                real(self.period, "period", low=MIN_PERIOD, high=MAX_PERIOD, units="s")
            elif self.period is not None:
                raise ParameterError(f"period applies only to measure 'sa', not "
                                     f"{self.measure!r}")
        with _field("damping"):
            real(self.damping, "damping", low=0.0, high=1.0, high_open=True)
        with _field("vertical"):
            choice(self.vertical, "vertical", VERTICAL_MODES)
        with _field("levels"):
            levels = check_levels(self.levels, "levels", self.measure)
            if self.scaled:
                if levels.size == 0:
                    raise ParameterError(f"levels: a {self.kind!r} design needs at least one IM "
                                         "level")
                if np.any(np.diff(levels) <= 0):
                    raise ParameterError("levels must be strictly increasing")
            elif levels.size:
                raise ParameterError("levels: a 'cloud' design uses the records as recorded; "
                                     "remove the levels")
        with _field("vertical_levels"):
            if self.vertical == "independent":
                if not self.scaled:
                    raise ParameterError("vertical 'independent' needs scaled levels (not a "
                                         "cloud)")
                v = check_levels(self.vertical_levels if self.vertical_levels is not None
                                 else (), "vertical_levels", self.measure)
                if v.shape != levels.shape:
                    raise ParameterError(f"vertical_levels must give one vertical target per "
                                         f"level ({levels.size})")
            elif self.vertical_levels is not None:
                raise ParameterError("vertical_levels apply only to vertical = 'independent'")
        return self

    def scale_options(self, level_index: int) -> dict:
        """Keyword arguments of :func:`shipblock.scaling.scale_record` for one level.

        Parameters
        ----------
        level_index : int
            Index into :attr:`levels` (ignored for a cloud).

        Returns
        -------
        dict
            ``target``/``factor``, ``measure``, ``period``, ``damping``, ``vertical_mode`` and,
            for an independent vertical, ``vertical_target``.
        """
        opts = {"measure": self.measure, "period": self.period, "damping": self.damping}
        if self.scaled:
            opts["target"] = float(self.levels[level_index])
        else:
            opts["factor"] = 1.0
        opts["vertical_mode"] = self.vertical
        if self.vertical == "independent":
            opts["vertical_target"] = float(self.vertical_levels[level_index])
        return opts


@dataclass(frozen=True)
class AnalysisDesign:
    """The grid of runs: records x IM levels x swept system parameters.

    Attributes
    ----------
    records : tuple of str
        Record ids (catalogue ids), the ``record`` dimension.
    intensity : IntensityDesign
        Analysis type, IM and levels (the ``im_level`` dimension, absent for a cloud).
    system : object
        The base system of the model (a :class:`~shipblock.ShipBlockSystem` for the rigid
        model).
    sweep : tuple of (str, tuple)
        ``(parameter, values)`` pairs, one dimension each, in order.
    stripes : tuple of tuple of str, optional
        Multiple-stripe analysis only: the records run at each IM level (one tuple per level,
        each a subset of ``records``), as when every stripe has its own record selection
        (e.g. matched to a conditional spectrum). Runs of a record outside a level's stripe
        are not made; their results are NaN and they count as invalid in every limit state.
        None (default): every record at every level.
    model : shipblock.models.Model, optional
        The model that runs the cases (default: the rigid model).
    """

    records: tuple[str, ...]
    intensity: IntensityDesign
    system: object
    sweep: tuple[tuple[str, tuple], ...] = field(default_factory=tuple)
    stripes: tuple[tuple[str, ...], ...] | None = None
    model: Model | None = None

    def __post_init__(self):
        if self.model is None:
            object.__setattr__(self, "model", get_model(DEFAULT_MODEL))

    def validate(self) -> AnalysisDesign:
        """Check the grid and build every swept system once.

        Returns
        -------
        AnalysisDesign
            ``self``.

        Raises
        ------
        ValueError
            For no records, repeated record ids, a record id that is not a string or holds a
            control character (:func:`shipblock.checks.label`), an unknown or repeated sweep
            parameter, an empty or repeated list of values, or an invalid swept system (the
            message names the parameter values).
        """
        if not self.records:
            raise ParameterError("the design has no records")
        if len(set(self.records)) != len(self.records):
            raise ParameterError("record ids repeat in the design")
        for i, record in enumerate(self.records):
            label(record, f"records[{i}]", what="a record id")
        self.intensity.validate()
        names = [name for name, _ in self.sweep]
        if len(set(names)) != len(names):
            raise ParameterError("a parameter is swept twice")
        known = self.model.sweep_parameters
        for name, values in self.sweep:
            if name not in known:
                raise ParameterError(
                    f"unknown sweep parameter {name!r}; known: {', '.join(known)}"
                )
            if len(values) == 0:
                raise ParameterError(f"sweep {name!r} has no values")
            if len(set(values)) != len(values):
                raise ParameterError(f"sweep {name!r} repeats a value")
        if self.stripes is not None:
            self._validate_stripes()
        self.systems()
        return self

    def _validate_stripes(self) -> None:
        if self.intensity.kind != "msa":
            raise ParameterError("stripes (a record set per level) apply only to type 'msa'")
        if len(self.stripes) != self.intensity.n_levels:
            raise ParameterError(f"stripes must give one record list per level "
                             f"({self.intensity.n_levels}), got {len(self.stripes)}")
        for j, stripe in enumerate(self.stripes):
            if not stripe:
                raise ParameterError(f"stripe {j} has no records")
            unknown = [r for r in stripe if r not in self.records]
            if unknown:
                raise ParameterError(f"stripe {j}: {', '.join(map(repr, unknown))} not among the "
                                 "design's records")
            if len(set(stripe)) != len(stripe):
                raise ParameterError(f"stripe {j} repeats a record")
        unused = [r for r in self.records if not any(r in s for s in self.stripes)]
        if unused:
            raise ParameterError(f"records in no stripe: {', '.join(unused)}")

    def stripe_mask(self) -> np.ndarray:
        """Which (record, level) pairs are run.

        Returns
        -------
        numpy.ndarray of bool, shape (n_records, n_levels)
            All True unless :attr:`stripes` is given.
        """
        mask = np.ones(self.shape[:2], dtype=bool)
        if self.stripes is not None:
            for j, stripe in enumerate(self.stripes):
                mask[:, j] = [r in stripe for r in self.records]
        return mask

    def in_design(self, cases) -> np.ndarray:
        """Whether each case is run (False for a record outside its level's stripe).

        Parameters
        ----------
        cases : array_like of int

        Returns
        -------
        numpy.ndarray of bool
        """
        idx = self.case_indices(cases)
        return self.stripe_mask()[idx[:, 0], idx[:, 1]]

    # -- grid --------------------------------------------------------------------------------
    @property
    def sweep_names(self) -> tuple[str, ...]:
        """tuple of str: Names of the swept parameters (= their dimension names)."""
        return tuple(name for name, _ in self.sweep)

    @property
    def dims(self) -> tuple[str, ...]:
        """tuple of str: Dimensions of a per-run variable, in case order."""
        level = ("im_level",) if self.intensity.scaled else ()
        return ("record", *level, *self.sweep_names)

    @property
    def sweep_shape(self) -> tuple[int, ...]:
        """tuple of int: Number of values of each swept parameter."""
        return tuple(len(values) for _, values in self.sweep)

    @property
    def shape(self) -> tuple[int, ...]:
        """tuple of int: Shape of the grid ``(n_records, n_levels, *sweep_shape)``.

        The level axis is always present here (length 1 for a cloud), so that case numbers
        are computed the same way for every design type; :attr:`dims` drops it for a cloud.
        """
        return (len(self.records), self.intensity.n_levels, *self.sweep_shape)

    @property
    def n_cases(self) -> int:
        """int: Number of runs."""
        return int(np.prod(self.shape))

    @property
    def n_systems(self) -> int:
        """int: Number of system-parameter combinations."""
        return int(np.prod(self.sweep_shape)) if self.sweep else 1

    def systems(self) -> list:
        """Every swept system, in C order over the sweep dimensions.

        Returns
        -------
        list
            ``n_systems`` systems of the model; a design without a sweep has just the base system.

        Raises
        ------
        ValueError
            If a combination gives an invalid system (names the combination).
        """
        return [self.system_at(i) for i in range(self.n_systems)]

    def system_at(self, index: int):
        """The swept system of one system index (C order over the sweep dimensions).

        Parameters
        ----------
        index : int
            In ``[0, n_systems)``, as in the third column of :meth:`case_indices`.

        Returns
        -------
        object
            The model's system (:meth:`Model.vary <shipblock.models.base.Model.vary>`).

        Raises
        ------
        ParameterError
            If the combination gives an invalid system (names the combination).

        Notes
        -----
        Each system is built once per design and kept (:meth:`validate`, the batch and a rerun
        use the same one): building one can cost a full run (the section model solves its
        static state, letting a dock settle first where it must).
        """
        if not self.sweep:
            return self.system
        index = int(index)
        if index in self._built:
            return self._built[index]
        combo = np.unravel_index(index, self.sweep_shape)
        values = {name: vals[int(i)] for (name, vals), i in zip(self.sweep, combo, strict=True)}
        try:
            system = self.model.vary(self.system, values)
        except ValueError as exc:
            raise ParameterError(f"sweep {values}: {exc}") from None
        self._built[index] = system
        return system

    @cached_property
    def _built(self) -> dict:
        """The swept systems built so far, by index (the design is frozen: they stay valid)."""
        return {}

    def case_indices(self, cases) -> np.ndarray:
        """Grid indices of case numbers.

        Parameters
        ----------
        cases : array_like of int
            Case numbers in ``[0, n_cases)``.

        Returns
        -------
        numpy.ndarray of int, shape (n, 3)
            Columns ``(record index, level index, system index)``.
        """
        idx = np.unravel_index(np.asarray(cases, dtype=np.int64), self.shape)
        system = (
            np.ravel_multi_index(idx[2:], self.sweep_shape)
            if self.sweep
            else np.zeros_like(idx[0])
        )
        return np.stack([idx[0], idx[1], system], axis=1).astype(np.int64)

    def chunks(self, chunk_size: int) -> list[range]:
        """Split the case numbers into contiguous chunks.

        Parameters
        ----------
        chunk_size : int
            Largest number of cases per chunk, >= 1.

        Returns
        -------
        list of range
            Consecutive ranges covering ``range(n_cases)``.
        """
        if int(chunk_size) != chunk_size or chunk_size < 1:
            raise ParameterError(f"chunk_size must be a whole number >= 1, got {chunk_size!r}")
        n = self.n_cases
        return [range(a, min(a + int(chunk_size), n)) for a in range(0, n, int(chunk_size))]

    def coords(self) -> dict:
        """Coordinates of the grid as ``{name: (dims, values, attrs)}``.

        Returns
        -------
        dict
            ``record``, ``im_level`` (scaled designs, SI units) and one per swept parameter,
            each with ``units`` and ``long_name``.
        """
        out = {
            "record": (("record",), np.array(self.records, dtype=object),
                       {"long_name": "ground-motion record (catalogue id)", "units": "1"}),
        }
        if self.intensity.scaled:
            out["im_level"] = (
                ("im_level",),
                np.asarray(self.intensity.levels, dtype=float),
                {
                    "long_name": f"target intensity level: {self.intensity.long_name}",
                    "units": self.intensity.units,
                    "measure": self.intensity.measure,
                },
            )
        for name, values in self.sweep:
            units, long_name = self.model.sweep_parameters[name]
            arr = np.asarray(values)
            if arr.dtype.kind in "iu":
                arr = arr.astype(np.int64)
            elif arr.dtype.kind == "f":
                arr = arr.astype(float)
            out[name] = ((name,), arr, {"long_name": f"swept parameter: {long_name}",
                                        "units": units})
        return out


def as_sweep(mapping: Mapping[str, Sequence]) -> tuple[tuple[str, tuple], ...]:
    """Turn ``{parameter: [values]}`` into the ``sweep`` tuple of :class:`AnalysisDesign`.

    Parameters
    ----------
    mapping : Mapping[str, Sequence]
        Parameter name -> values, in dimension order.

    Returns
    -------
    tuple of (str, tuple)
    """
    return tuple((str(k), tuple(v)) for k, v in mapping.items())



