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

All inputs and outputs are SI: accelerations [m/s^2], velocities [m/s], displacements [m],
periods [s].
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from shipblock import intensity
from shipblock.errors import ParameterError, RecordError

__all__ = [
    "MEASURES",
    "VERTICAL_MODES",
    "ScaledRecord",
    "amplitude_factor",
    "measure_value",
    "scale",
    "scale_motion",
    "scale_record",
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
    arr = np.asarray(acc, dtype=np.float64)
    if arr.ndim != 1 or arr.size < 2:
        raise RecordError(
            label, f"must be a 1-D array of at least 2 samples, got shape {arr.shape}"
        )
    if not np.all(np.isfinite(arr)):
        raise RecordError(label, "contains NaN or infinite values")
    return arr


def _check_measure(measure: str, period, damping):
    if measure not in MEASURES:
        raise ParameterError(f"unknown scaling measure {measure!r}; known: {', '.join(MEASURES)}")
    if measure == "sa":
        if period is None:
            raise ParameterError("measure 'sa' needs a period [s]")
        period = float(period)
        if not np.isfinite(period) or period <= 0.0:
            raise ParameterError(
                f"period must be > 0 [s] for measure 'sa', got {period} (use measure 'pga' "
                "for the zero-period limit)"
            )
        damping = float(damping)
        if not (0.0 <= damping < 1.0):
            raise ParameterError(f"damping must be in [0, 1), got {damping}")
    elif period is not None:
        raise ParameterError(f"period applies only to measure 'sa', not {measure!r}")
    return period, damping


def _check_target(target, label="target") -> float:
    target = float(target)
    if not np.isfinite(target) or target <= 0.0:
        raise ParameterError(f"{label} must be a positive finite value, got {target}")
    return target


def _check_factor(factor, label="factor") -> float:
    factor = float(factor)
    if not np.isfinite(factor):
        raise ParameterError(f"{label} must be finite, got {factor}")
    return factor


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
    a = _check_record(acc, label)
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
    return _check_factor(factor) * np.asarray(acc, dtype=np.float64)


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
    h = _check_record(horizontal, "<horizontal>")
    v = None if vertical is None else _check_record(vertical, "<vertical>")
    if v is not None and v.shape != h.shape:
        raise RecordError("<vertical>", f"has {v.size} samples but the horizontal has {h.size}")
    if vertical_mode not in VERTICAL_MODES:
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
            _check_measure(v_measure, v_period, damping)
            f_v = _check_factor(vertical_factor, "vertical_factor")
            if f_v <= 0.0:
                raise ParameterError(
                    f"vertical_factor must be > 0 (use reverse_vertical=True), got {f_v}"
                )
    if reverse_vertical and f_v != 0.0:
        f_v = -f_v
    v_out = f_v * v
    achieved_v = measure_value(v_out, dt, v_measure, v_period, damping)
    return ScaledRecord(h_out, v_out, f_h, f_v, h_measure, achieved, achieved_v)


def scale_motion(motion, **options):
    """Scale a :class:`shipblock.motion.GroundMotion` with :func:`scale_record`.

    The factors are computed on ``motion.horizontal`` (the solver's horizontal) and
    ``motion.vertical``; the horizontal factor multiplies *both* horizontal traces (H1, H2), so
    a projection on any azimuth is scaled by the same factor, and the vertical factor
    multiplies V.

    Parameters
    ----------
    motion : shipblock.motion.GroundMotion
        Input motion [m/s^2]; unchanged.
    **options
        Keyword arguments of :func:`scale_record` (``target``, ``factor``, ``measure``,
        ``period``, ``damping``, ``vertical_mode``, ..., ``reverse``).

    Returns
    -------
    motion : shipblock.motion.GroundMotion
        New scaled motion, with a note in ``metadata["processing"]`` and a provenance string
        ``shipblock.scaling.scale_record(...)`` in every trace's ``stats.processing``.
    scaled : ScaledRecord
        The factors and achieved measures.
    """
    from shipblock.motion import COMPONENT_KEY  # lazy: motion imports obspy

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
