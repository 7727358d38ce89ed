r"""Amplitude scaling of ground-motion records.

A record is scaled by multiplying its acceleration by a constant factor :math:`f`. The
intensity measures used as scaling targets are positively homogeneous in the record,
:math:`IM(f\,a) = |f|^p\,IM(a)`, with degree :math:`p = 1` for PGA, PGV, PGD, CAV and
:math:`S_a(T)` and :math:`p = 2` for Arias intensity, so the factor that reaches a target
:math:`IM^*` is

.. math:: |f| = \left(\frac{IM^*}{IM(a)}\right)^{1/p}.

CAV5 is not homogeneous (its threshold is absolute) and is not offered as a target.

The horizontal component sets the scale. The vertical one is, by default, multiplied by the
*same* factor, which keeps the record's V/H ratio (``vertical_mode="same"``); it can instead be
scaled to its own target or factor (``"independent"``), left as recorded (``"unscaled"``) or
removed (``"zero"``). Polarity reversal multiplies a component by -1 and is reported as a
negative factor, so that always ``scaled = factor * original``.

Records can also be scaled to a *target spectrum* over a period range, as ASCE 7 and PEER
practice do (:func:`spectrum_match`): the factor minimising the squared differences of
:math:`\ln S_a` over :math:`[T_a, T_b]` (least squares in log spectral acceleration), or the
factor that matches :math:`S_a(T_1)` exactly with the misfit over the range reported. The
target comes from a two-column file of periods and spectral accelerations
(:func:`read_target_spectrum`).

All inputs and outputs are SI: accelerations [m/s^2], velocities [m/s], displacements [m],
periods [s].
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from shipblock import checks, intensity
from shipblock.errors import ParameterError, ParameterTypeError, RecordError, ShipblockError
from shipblock.units import STANDARD_GRAVITY, acceleration_to_si

__all__ = [
    "MATCH_MODES",
    "MEASURES",
    "VERTICAL_MODES",
    "ScaledRecord",
    "SpectrumMatch",
    "TargetSpectrum",
    "acceleration_target",
    "amplitude_factor",
    "measure_value",
    "read_target_spectrum",
    "scale",
    "scale_motion",
    "scale_record",
    "spectrum_match",
]

#: Scaling measures: name -> (description with unit, homogeneity degree p [-]).
MEASURES: dict[str, tuple[str, int]] = {
    "pga": ("peak ground acceleration [m/s^2]", 1),
    "pgv": ("peak ground velocity [m/s]", 1),
    "pgd": ("peak ground displacement [m]", 1),
    "sa": ("pseudo-spectral acceleration Sa(T, damping) [m/s^2]", 1),
    "cav": ("cumulative absolute velocity [m/s]", 1),
    "arias": ("Arias intensity [m/s]", 2),
}

#: Accepted ways of treating the vertical component.
VERTICAL_MODES = ("same", "independent", "unscaled", "zero")


@dataclass(frozen=True)
class ScaledRecord:
    """Result of :func:`scale_record`.

    Attributes
    ----------
    horizontal : numpy.ndarray
        Scaled horizontal acceleration [m/s^2], ``factor_h * horizontal_in``.
    vertical : numpy.ndarray or None
        Scaled vertical acceleration [m/s^2], ``factor_v * vertical_in``; None if no vertical
        was given.
    factor_h : float
        Signed factor applied to the horizontal [-] (negative when its polarity is reversed).
    factor_v : float or None
        Signed factor applied to the vertical [-]; 0 for ``vertical_mode="zero"``.
    measure : str
        Measure of the horizontal that was targeted, or, when scaled by a factor, the measure
        reported in ``achieved`` (a key of :data:`MEASURES`).
    achieved : float
        Value of ``measure`` of the scaled horizontal, in the measure's unit; equals the
        target up to rounding.
    achieved_v : float or None
        Value of the vertical's measure after scaling (the vertical target measure in
        ``"independent"`` mode, the horizontal one otherwise).
    """

    horizontal: np.ndarray
    vertical: np.ndarray | None
    factor_h: float
    factor_v: float | None
    measure: str
    achieved: float
    achieved_v: float | None


def _check_record(acc, label: str) -> np.ndarray:
    """A record as a 1-D float array of at least 2 samples, finite and within 100 g."""
    return checks.acceleration(acc, label)


def _check_measure(measure, period, damping, names=("measure", "period")):
    if not isinstance(measure, str):
        raise ParameterTypeError(f"{names[0]} must be a string, one of {', '.join(MEASURES)}; "
                                 f"got {type(measure).__name__} {measure!r}")
    if measure not in MEASURES:
        raise ParameterError(f"unknown scaling measure {measure!r} ({names[0]}); known: "
                             f"{', '.join(MEASURES)}")
    if measure == "sa":
        if period is None:
            raise ParameterError(f"measure 'sa' needs a period [s] ({names[1]})")
        period = checks.real(period, names[1], low=checks.MIN_PERIOD, high=checks.MAX_PERIOD,
                             units="s")
        damping = checks.real(damping, "damping", low=0.0, high=1.0, high_open=True)
    elif period is not None:
        raise ParameterError(f"{names[1]}: period applies only to measure 'sa', not {measure!r}")
    return period, damping


def _check_target(target, label="target") -> float:
    if not checks.is_real(target):
        raise ParameterTypeError(f"{label} must be a positive finite number, got "
                                 f"{type(target).__name__} {target!r}")
    target = float(target)
    if not np.isfinite(target) or target <= 0.0:
        raise ParameterError(f"{label} must be a positive finite value, got {target}")
    return target


def _check_factor(factor, label="factor") -> float:
    return checks.real(factor, label)


def _check_scaled_peak(acc: np.ndarray, factor: float, name: str, value) -> None:
    """Refuse a scale factor that takes ``acc`` above :data:`shipblock.checks.MAX_ACCELERATION`."""
    peak = abs(factor) * float(np.abs(acc).max())
    if not peak <= checks.MAX_ACCELERATION:
        raise ParameterError(
            f"{name} = {value!r} needs a scale factor of {factor:.6g}, which takes the peak "
            f"acceleration to {peak:.6g} m/s^2 ({peak / STANDARD_GRAVITY:.6g} g), above the "
            f"plausibility limit {checks.MAX_ACCELERATION:g} m/s^2 (100 g)")


def _check_flag(value, name: str) -> bool:
    if not isinstance(value, bool | np.bool_):
        raise ParameterTypeError(f"{name} must be True or False, got {value!r}")
    return bool(value)


_QUANTITY = re.compile(r"\s*([-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?)\s*(\S*)\s*")


def acceleration_target(text, name: str = "target") -> float:
    """An acceleration target written with its unit (``"0.4g"``, ``"3.9 m/s^2"``, ``"392gal"``)
    as m/s^2, for :func:`scale_record`'s ``target`` (e.g. ``--target-pga``).

    The unit is required: a bare ``0.4`` would be 0.4 m/s^2 = 0.041 g where a PGA of 0.4 g was
    almost surely meant, a silent factor of ten.

    Parameters
    ----------
    text : str
        A number and an acceleration unit of :data:`shipblock.units.ACCELERATION_UNITS_TO_SI`.
    name : str
        How messages name the value (a keyword or a command-line flag).

    Returns
    -------
    float
        The target [m/s^2], above zero (the scaled record is checked against 100 g by
        :func:`scale_record`).

    Raises
    ------
    ParameterError
        Naming ``name``: not a number with a unit, an unknown unit (the known ones listed), no
        unit, or a value out of range.
    """
    match = _QUANTITY.fullmatch(str(text))
    if match is None:
        raise ParameterError(f"{name} {text!r}: expected a number and its unit, e.g. 0.4g")
    value, unit = float(match.group(1)), match.group(2)
    if not unit:
        raise ParameterError(f"{name} {text}: give its unit, e.g. {text}g, {text}m/s^2 or "
                             f"{text}gal (a bare number would be m/s^2)")
    try:
        target = float(acceleration_to_si(value, unit))
    except ParameterError as exc:
        raise ParameterError(f"{name} {text}: {exc}") from None
    return _check_target(target, name)


def measure_value(acc, dt, measure="pga", period=None, damping=intensity.DEFAULT_DAMPING) -> float:
    """Value of a scaling measure of one component.

    Parameters
    ----------
    acc : array_like
        Acceleration [m/s^2], shape ``(n,)``.
    dt : float
        Time step [s].
    measure : str
        A key of :data:`MEASURES`.
    period : float, optional
        Oscillator period [s], > 0; required for (and only for) ``measure="sa"``.
    damping : float
        Fraction of critical damping for ``"sa"`` [-].

    Returns
    -------
    float
        The measure, in its unit (see :data:`MEASURES`).
    """
    period, damping = _check_measure(measure, period, damping)
    if measure == "pga":
        return intensity.pga(acc, dt)
    if measure == "pgv":
        return intensity.pgv(acc, dt)
    if measure == "pgd":
        return intensity.pgd(acc, dt)
    if measure == "sa":
        return intensity.spectral_acceleration(acc, dt, period, damping)
    if measure == "cav":
        return intensity.cav(acc, dt)
    return intensity.arias_intensity(acc, dt)


def amplitude_factor(
    acc,
    dt,
    target,
    measure="pga",
    period=None,
    damping=intensity.DEFAULT_DAMPING,
    label="<array>",
) -> float:
    r"""Positive factor :math:`f` such that ``measure(f * acc) == target``.

    .. math:: f = \left(\frac{IM^*}{IM(a)}\right)^{1/p}

    with :math:`p` the homogeneity degree of the measure (:data:`MEASURES`).

    Parameters
    ----------
    acc : array_like
        Acceleration [m/s^2], shape ``(n,)``.
    dt : float
        Time step [s].
    target : float
        Target value of the measure, > 0, in the measure's unit.
    measure : str
        A key of :data:`MEASURES`.
    period : float, optional
        Period [s] for ``measure="sa"``.
    damping : float
        Fraction of critical damping for ``"sa"`` [-].
    label : str
        Name of the record used in error messages.

    Returns
    -------
    float
        The factor [-], > 0.

    Raises
    ------
    ValueError
        For a non-positive target, an unknown measure, or a bad period/damping.
    shipblock.errors.RecordError
        If the record's measure is zero (no factor can reach a positive target).
    """
    a = _check_record(acc, "acc" if label == "<array>" else label)
    target = _check_target(target)
    value = measure_value(a, dt, measure, period, damping)
    if not value > 0.0:
        raise RecordError(label, f"has zero {measure.upper()}; it cannot be scaled to a target")
    return float((target / value) ** (1.0 / MEASURES[measure][1]))


def scale(acc, factor) -> np.ndarray:
    """Scaled copy ``factor * acc``.

    Parameters
    ----------
    acc : array_like
        Acceleration [m/s^2].
    factor : float
        Finite factor [-]; negative reverses polarity.

    Returns
    -------
    numpy.ndarray
        New array [m/s^2].
    """
    a = _check_record(acc, "acc")
    factor = _check_factor(factor)
    _check_scaled_peak(a, factor, "factor", factor)
    return factor * a


def scale_record(
    horizontal,
    vertical,
    dt,
    *,
    target=None,
    factor=None,
    measure="pga",
    period=None,
    damping=intensity.DEFAULT_DAMPING,
    vertical_mode="same",
    vertical_target=None,
    vertical_factor=None,
    vertical_measure=None,
    vertical_period=None,
    reverse=False,
    reverse_vertical=False,
) -> ScaledRecord:
    """Scale a horizontal (+ optional vertical) record to a target or by a factor.

    Exactly one of ``target`` and ``factor`` sets the horizontal scale (neither means a factor
    of 1). The vertical follows ``vertical_mode``:

    * ``"same"`` -- multiplied by the horizontal factor (keeps V/H); default.
    * ``"independent"`` -- its own ``vertical_target`` (of ``vertical_measure``, default
      ``measure``, at ``vertical_period``, default ``period``) or ``vertical_factor``.
    * ``"unscaled"`` -- left as recorded (factor 1).
    * ``"zero"`` -- replaced by zeros (factor 0), to run without vertical excitation.

    Parameters
    ----------
    horizontal : array_like
        Horizontal acceleration [m/s^2], shape ``(n,)``.
    vertical : array_like or None
        Vertical acceleration [m/s^2], shape ``(n,)``, or None.
    dt : float
        Time step [s].
    target : float, optional
        Target of ``measure`` for the horizontal, > 0 (unit of the measure).
    factor : float, optional
        Factor for the horizontal [-], > 0 (use ``reverse`` to flip polarity).
    measure : str
        A key of :data:`MEASURES`; default ``"pga"``.
    period : float, optional
        Period [s] for ``measure="sa"``.
    damping : float
        Fraction of critical damping for ``"sa"`` [-]; default 0.05.
    vertical_mode : {"same", "independent", "unscaled", "zero"}
        Treatment of the vertical.
    vertical_target, vertical_factor : float, optional
        For ``"independent"`` only: exactly one of them.
    vertical_measure : str, optional
        For ``"independent"`` only: measure of ``vertical_target`` (default ``measure``).
    vertical_period : float, optional
        For ``"independent"`` only: period [s] for a vertical ``"sa"`` target (default
        ``period``).
    reverse : bool
        Reverse the polarity of the horizontal.
    reverse_vertical : bool
        Reverse the polarity of the vertical.

    Returns
    -------
    ScaledRecord
        Scaled copies, the signed factors and the achieved measures.

    Raises
    ------
    ValueError
        For inconsistent options, a non-positive target or factor, or a bad period/damping.
    shipblock.errors.RecordError
        For an invalid record or one whose targeted measure is zero.
    """
    h = _check_record(horizontal, "horizontal")
    v = None if vertical is None else _check_record(vertical, "vertical")
    reverse = _check_flag(reverse, "reverse")
    reverse_vertical = _check_flag(reverse_vertical, "reverse_vertical")
    if v is not None and v.shape != h.shape:
        raise RecordError("<vertical>", f"has {v.size} samples but the horizontal has {h.size}")
    if not isinstance(vertical_mode, str) or vertical_mode not in VERTICAL_MODES:
        raise ParameterError(f"vertical_mode must be one of {VERTICAL_MODES}, got {vertical_mode!r}")
    independent_opts = (vertical_target, vertical_factor, vertical_measure, vertical_period)
    if vertical_mode != "independent" and any(x is not None for x in independent_opts):
        raise ParameterError(
            "vertical_target/vertical_factor/vertical_measure/vertical_period apply only to "
            f"vertical_mode='independent', not {vertical_mode!r}"
        )

    # horizontal
    if target is not None and factor is not None:
        raise ParameterError("give either target or factor, not both")
    if target is not None:
        f_h = amplitude_factor(h, dt, target, measure, period, damping, label="<horizontal>")
        h_measure = measure
    else:
        _check_measure(measure, period, damping)
        f_h = 1.0 if factor is None else _check_factor(factor)
        if f_h <= 0.0:
            raise ParameterError(f"factor must be > 0 (use reverse=True to flip polarity), got {f_h}")
        h_measure = measure
    _check_scaled_peak(h, f_h, "target" if target is not None else "factor",
                       target if target is not None else factor)
    if reverse:
        f_h = -f_h
    h_out = f_h * h
    achieved = measure_value(h_out, dt, h_measure, period, damping)

    # vertical
    if v is None:
        if vertical_mode == "independent":
            raise ParameterError("vertical_mode='independent' needs a vertical component")
        return ScaledRecord(h_out, None, f_h, None, h_measure, achieved, None)
    v_measure, v_period = measure, period
    if vertical_mode == "same":
        f_v = abs(f_h)
    elif vertical_mode == "unscaled":
        f_v = 1.0
    elif vertical_mode == "zero":
        f_v = 0.0
    else:
        if (vertical_target is None) == (vertical_factor is None):
            raise ParameterError(
                "vertical_mode='independent' needs exactly one of vertical_target and "
                "vertical_factor"
            )
        if vertical_measure is not None:
            v_measure = vertical_measure
        if vertical_period is not None or v_measure != "sa":
            v_period = vertical_period
        if vertical_target is not None:
            f_v = amplitude_factor(
                v,
                dt,
                _check_target(vertical_target, "vertical_target"),
                v_measure,
                v_period,
                damping,
                label="<vertical>",
            )
        else:
            _check_measure(v_measure, v_period, damping, ("vertical_measure", "vertical_period"))
            f_v = _check_factor(vertical_factor, "vertical_factor")
            if f_v <= 0.0:
                raise ParameterError(
                    f"vertical_factor must be > 0 (use reverse_vertical=True), got {f_v}"
                )
    if vertical_mode == "independent":
        _check_scaled_peak(v, f_v, "vertical_target" if vertical_target is not None
                           else "vertical_factor",
                           vertical_target if vertical_target is not None else vertical_factor)
    elif vertical_mode == "same":
        _check_scaled_peak(v, f_v, "target" if target is not None else "factor",
                           target if target is not None else factor)
    if reverse_vertical and f_v != 0.0:
        f_v = -f_v
    v_out = f_v * v
    achieved_v = measure_value(v_out, dt, v_measure, v_period, damping)
    return ScaledRecord(h_out, v_out, f_h, f_v, h_measure, achieved, achieved_v)


def scale_motion(motion, **options):
    """Scale a :class:`shipblock.records.motion.GroundMotion` with :func:`scale_record`.

    The factors are computed on ``motion.horizontal`` (the solver's horizontal) and
    ``motion.vertical``; the horizontal factor multiplies *both* horizontal traces (H1, H2), so
    a projection on any azimuth is scaled by the same factor, and the vertical factor
    multiplies V.

    Parameters
    ----------
    motion : shipblock.records.motion.GroundMotion
        Input motion [m/s^2]; unchanged.
    **options
        Keyword arguments of :func:`scale_record` (``target``, ``factor``, ``measure``,
        ``period``, ``damping``, ``vertical_mode``, ..., ``reverse``); another keyword is a
        :class:`~shipblock.errors.ParameterTypeError` naming it and the closest one.

    Returns
    -------
    motion : shipblock.records.motion.GroundMotion
        New scaled motion, with a note in ``metadata["processing"]`` and a provenance string
        ``shipblock.scaling.scale_record(...)`` in every trace's ``stats.processing``.
    scaled : ScaledRecord
        The factors and achieved measures.

    Examples
    --------
    The pair is unpacked; the motion is what :func:`shipblock.simulate` takes
    (``simulate(system, scale_motion(gm, target=...)[0])``)::

        scaled_motion, info = scale_motion(gm, target=0.4 * 9.80665)
        result = simulate(system, scaled_motion)
    """
    # lazy, for start-up time: the records import obspy
    from shipblock.records.motion import COMPONENT_KEY, check_motion

    check_motion(motion)
    checks.keywords(options, checks.keyword_names(scale_record, 3), "scale_motion")
    result = scale_record(motion.horizontal, motion.vertical, motion.dt, **options)
    args = ", ".join(f"{k}={v!r}" for k, v in sorted(options.items()))
    entry = (
        f"shipblock.scaling.scale_record({args}) -> factor_h={result.factor_h!r}, "
        f"factor_v={result.factor_v!r}"
    )
    stream = motion.stream.copy()
    for tr in stream:
        factor = result.factor_v if tr.stats[COMPONENT_KEY] == "V" else result.factor_h
        tr.data = factor * np.asarray(tr.data, dtype=np.float64)
        tr.stats.processing = [*tr.stats.get("processing", []), entry]
    return motion.with_stream(stream, entry), result


# --------------------------------------------------------------------------------------------
# scaling to a target spectrum
# --------------------------------------------------------------------------------------------

#: How :func:`spectrum_match` sets the factor: least squares in ln Sa over the period range, or
#: Sa(T1) matched exactly (the misfit over the range reported).
MATCH_MODES = ("range", "anchor")

#: Periods of the matching grid, log-spaced over the range [-].
DEFAULT_MATCH_PERIODS = 40


class TargetSpectrumError(ShipblockError, ValueError):
    """A target spectrum file cannot be used; the message names the file and the line."""


@dataclass(frozen=True)
class TargetSpectrum:
    """A target pseudo-spectral acceleration spectrum, interpolated log-log.

    Attributes
    ----------
    periods : numpy.ndarray
        Periods [s], positive and strictly increasing.
    sa : numpy.ndarray
        Spectral accelerations [m/s^2], positive.
    source : str
        Where it came from (file name), for messages and provenance.
    """

    periods: np.ndarray
    sa: np.ndarray
    source: str = "<array>"

    def __post_init__(self):
        t = np.asarray(self.periods, dtype=float)
        sa = np.asarray(self.sa, dtype=float)
        if t.ndim != 1 or sa.shape != t.shape or t.size < 2:
            raise TargetSpectrumError(f"{self.source}: a target spectrum needs at least two "
                                      f"(period, Sa) pairs of equal length, got {t.shape} and "
                                      f"{sa.shape}")
        if not (np.all(np.isfinite(t)) and np.all(t > 0) and np.all(np.diff(t) > 0)):
            raise TargetSpectrumError(f"{self.source}: periods must be positive and strictly "
                                      "increasing [s]")
        if not (np.all(np.isfinite(sa)) and np.all(sa > 0)):
            raise TargetSpectrumError(f"{self.source}: spectral accelerations must be positive")
        object.__setattr__(self, "periods", t)
        object.__setattr__(self, "sa", sa)

    def at(self, periods) -> np.ndarray:
        """The target at ``periods`` [s], interpolated linearly in (ln T, ln Sa) [m/s^2].

        Raises
        ------
        TargetSpectrumError
            For a period outside the target's range (no extrapolation).
        """
        t = np.atleast_1d(np.asarray(periods, dtype=float))
        lo, hi = self.periods[0], self.periods[-1]
        if np.any(t < lo * (1 - 1e-12)) or np.any(t > hi * (1 + 1e-12)):
            raise TargetSpectrumError(
                f"{self.source}: the target spectrum covers {lo:g} to {hi:g} s; periods "
                f"{t.min():g} to {t.max():g} s are needed")
        t = np.clip(t, lo, hi)
        return np.exp(np.interp(np.log(t), np.log(self.periods), np.log(self.sa)))


def read_target_spectrum(path, units) -> TargetSpectrum:
    """Read a target spectrum: two columns, period [s] and Sa in ``units``.

    Columns are separated by commas, semicolons or white space; lines starting with ``#`` and
    a first line of column names are skipped.

    Parameters
    ----------
    path : str or os.PathLike
        The file.
    units : str
        Unit of the Sa column: ``"g"``, ``"m/s^2"``, ``"cm/s^2"``, ... (any unit of
        :func:`shipblock.units.acceleration_to_si`). Required: a file of numbers does not say.

    Returns
    -------
    TargetSpectrum
        Periods [s] and Sa [m/s^2].

    Raises
    ------
    ParameterTypeError
        If ``path`` is not a path (``None``, bytes, a number).
    TargetSpectrumError
        Naming the file and line: missing file, a line that is not two numbers, periods not
        increasing, non-positive values, an unknown unit.
    """
    path = Path(checks.pathname(path, "path", "a target spectrum file (period [s], Sa)"))
    try:
        factor = float(acceleration_to_si(1.0, units))
    except ValueError as exc:
        raise TargetSpectrumError(f"{path}: {exc}") from None
    try:
        text = path.read_text(encoding="utf-8")
    except OSError as exc:
        raise TargetSpectrumError(f"{path}: cannot read the target spectrum ({exc})") from None
    rows = []
    for number, line in enumerate(text.splitlines(), start=1):
        stripped = line.split("#", 1)[0].strip()
        if not stripped:
            continue
        fields = stripped.replace(",", " ").replace(";", " ").split()
        try:
            values = [float(f) for f in fields]
        except ValueError:
            if not rows and number == _first_content_line(text):
                continue  # a header of column names
            raise TargetSpectrumError(f"{path}, line {number}: expected two numbers (period [s],"
                                      f" Sa [{units}]), got {line.strip()!r}") from None
        if len(values) != 2:
            raise TargetSpectrumError(f"{path}, line {number}: expected two columns (period [s],"
                                      f" Sa [{units}]), got {len(values)}")
        rows.append(values)
    if not rows:
        raise TargetSpectrumError(f"{path}: no (period, Sa) rows")
    data = np.array(rows, dtype=float)
    return TargetSpectrum(data[:, 0], data[:, 1] * factor, source=str(path))


def _first_content_line(text: str) -> int:
    for number, line in enumerate(text.splitlines(), start=1):
        if line.split("#", 1)[0].strip():
            return number
    return 0


@dataclass(frozen=True)
class SpectrumMatch:
    r"""Result of :func:`spectrum_match`.

    Attributes
    ----------
    factor : float
        Scale factor of the record [-], > 0.
    misfit : float
        RMS of :math:`\ln(f S_a^{rec}(T_i) / S_a^{target}(T_i))` over the matching periods [-]
        (0.1 is about 10 % off on average).
    periods : numpy.ndarray
        The matching periods [s], log-spaced over the range.
    sa_record : numpy.ndarray
        Pseudo-spectral acceleration of the *unscaled* record there [m/s^2].
    sa_target : numpy.ndarray
        The target there [m/s^2].
    """

    factor: float
    misfit: float
    periods: np.ndarray
    sa_record: np.ndarray
    sa_target: np.ndarray


def spectrum_match(acc, dt, target: TargetSpectrum, period_range, *, mode="range",
                   anchor_period=None, damping=intensity.DEFAULT_DAMPING,
                   n_periods=DEFAULT_MATCH_PERIODS) -> SpectrumMatch:
    r"""Scale factor of a record to a target spectrum over a period range, and its misfit.

    On ``n_periods`` periods :math:`T_i` log-spaced over :math:`[T_a, T_b]`:

    * ``mode="range"``: least squares in :math:`\ln S_a`, as the PEER ground-motion database
      scales records (the mean squared error of :math:`\ln S_a` over the range minimised,
      equal weights; Ancheta et al. 2013 [1]_), over a range such as ASCE 7-16 chapter 16's
      :math:`0.2\,T` to :math:`2\,T` [2]_,

      .. math:: \ln f = \frac{1}{n}\sum_i \ln\frac{S_a^{target}(T_i)}{S_a^{rec}(T_i)};

    * ``mode="anchor"``: the spectrum conditional on :math:`S_a(T_1)`, matched there exactly,
      :math:`f = S_a^{target}(T_1)/S_a^{rec}(T_1)`, the rest of the range only reported.

    Either way the misfit is the RMS of the log residuals,
    :math:`\sqrt{\frac1n \sum_i \ln^2(f S_a^{rec}(T_i)/S_a^{target}(T_i))}`.

    Parameters
    ----------
    acc : array_like
        Horizontal acceleration [m/s^2].
    dt : float
        Time step [s].
    target : TargetSpectrum
        The target [m/s^2]; it must cover the range (and ``anchor_period``).
    period_range : tuple of float
        :math:`(T_a, T_b)` [s], ``0 < T_a < T_b``.
    mode : {"range", "anchor"}
        See above.
    anchor_period : float, optional
        :math:`T_1` [s], required for ``"anchor"``.
    damping : float
        Fraction of critical damping of the spectra [-].
    n_periods : int
        Number of matching periods [-], >= 2.

    Returns
    -------
    SpectrumMatch

    Raises
    ------
    ValueError
        For a bad range, mode, anchor or a target that does not cover them.
    shipblock.errors.RecordError
        For a record with zero spectral acceleration in the range.

    References
    ----------
    .. [1] Ancheta, T. D. et al. (2013). PEER NGA-West2 database. PEER Report 2013/03, Pacific
       Earthquake Engineering Research Center (record scaling by minimum MSE of ln Sa).
    .. [2] ASCE/SEI 7-16 (2017). *Minimum Design Loads and Associated Criteria for Buildings
       and Other Structures*, chapter 16 (amplitude scaling over a period range).
    """
    if mode not in MATCH_MODES:
        raise ParameterError(f"mode must be one of {MATCH_MODES}, got {mode!r}")
    try:
        ta, tb = (float(x) for x in period_range)
    except (TypeError, ValueError):
        raise ParameterError(f"period_range must be two periods [s], got {period_range!r}") from None
    if not (0 < ta < tb and np.isfinite(tb)):
        raise ParameterError(f"period_range must satisfy 0 < T_a < T_b [s], got {period_range!r}")
    if int(n_periods) != n_periods or n_periods < 2:
        raise ParameterError(f"n_periods must be a whole number >= 2, got {n_periods!r}")
    periods = np.geomspace(ta, tb, int(n_periods))
    sa_t = target.at(periods)
    sa_r = intensity.spectral_acceleration(acc, dt, periods, damping)
    if not np.all(sa_r > 0):
        raise RecordError("<horizontal>", f"has zero Sa between {ta:g} and {tb:g} s")
    if mode == "range":
        factor = float(np.exp(np.mean(np.log(sa_t / sa_r))))
    else:
        if anchor_period is None:
            raise ParameterError("mode 'anchor' needs anchor_period [s] (T1)")
        t1 = float(anchor_period)
        sa_r1 = intensity.spectral_acceleration(acc, dt, t1, damping)
        if not sa_r1 > 0:
            raise RecordError("<horizontal>", f"has zero Sa at T1 = {t1:g} s")
        factor = float(target.at(t1)[0] / sa_r1)
    misfit = float(np.sqrt(np.mean(np.log(factor * sa_r / sa_t) ** 2)))
    return SpectrumMatch(factor, misfit, periods, sa_r, sa_t)
