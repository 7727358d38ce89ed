r"""Ground-motion intensity measures of an acceleration record.

All functions take a uniformly sampled ground acceleration ``acc`` [m/s^2] with time step
``dt`` [s] and return SI values. The record is interpreted as the *piecewise-linear*
function through its samples, :math:`a(t_i) = a_i`, :math:`t_i = i\,\Delta t`; every integral
below is computed under that interpretation, which is also the assumption of the exact
Nigam-Jennings (1969) oscillator recursion used for the response spectrum.

Integration rules
-----------------
* Velocity: trapezoid rule, which is the *exact* integral of the piecewise-linear
  acceleration,

  .. math:: v_{i+1} = v_i + \tfrac{\Delta t}{2}(a_i + a_{i+1}), \qquad v_0 = 0.

* Displacement: exact double integral of the piecewise-linear acceleration (cubic in each
  step),

  .. math:: d_{i+1} = d_i + v_i\,\Delta t + \tfrac{\Delta t^2}{6}(2a_i + a_{i+1}),
            \qquad d_0 = 0,

  which differs from the trapezoid rule applied to :math:`v` by
  :math:`\Delta t^2 (a_{i+1} - a_i)/12` per step.
* Arias intensity, CAV, CAV5 and the Husid curve: trapezoid rule on :math:`a^2` or
  :math:`|a|` (the usual strong-motion practice, e.g. USGS gmprocess).

The acceleration of gravity is :data:`shipblock.units.STANDARD_GRAVITY` = 9.80665 m/s^2.

The response spectrum is computed in :mod:`shipblock.intensity.spectrum`; its names are
imported here, so ``shipblock.intensity.response_spectrum`` and the other public names keep
their paths.

References
----------
.. [1] Arias, A. (1970). A measure of earthquake intensity. In R. J. Hansen (ed.), *Seismic
   Design for Nuclear Power Plants*, MIT Press, 438-483.
.. [2] EPRI (1988). *A criterion for determining exceedance of the operating basis
   earthquake*. Report NP-5930, Electric Power Research Institute, Palo Alto.
.. [3] EPRI (1991). *Standardization of the cumulative absolute velocity*. Report
   TR-100082, Electric Power Research Institute, Palo Alto.
.. [4] Kramer, S. L. and Mitchell, R. A. (2006). Ground motion intensity measures for
   liquefaction hazard evaluation. *Earthquake Spectra* 22(2), 413-438.
.. [5] Trifunac, M. D. and Brady, A. G. (1975). A study on the duration of strong earthquake
   ground motion. *Bull. Seismol. Soc. Am.* 65(3), 581-626.
.. [6] Husid, R. (1969). Analisis de terremotos: analisis general. *Revista del IDIEM* 8(1),
   21-42.
.. [7] Nigam, N. C. and Jennings, P. C. (1969). Calculation of response spectra from
   strong-motion earthquake records. *Bull. Seismol. Soc. Am.* 59(2), 909-922.
.. [8] Chopra, A. K. (2017). *Dynamics of Structures*, 5th ed., Pearson, Section 5.2
   (interpolation of excitation).
"""

from __future__ import annotations

import numpy as np

from shipblock import checks
from shipblock.errors import ParameterError, RecordError
from shipblock.intensity._checks import _SOURCE, _as_record, _check_dt
from shipblock.intensity.spectrum import (
    DEFAULT_DAMPING,
    SAMPLES_PER_PERIOD,
    ResponseSpectrum,
    response_spectrum,
    sdof_response,
    spectral_acceleration,
)
from shipblock.units import STANDARD_GRAVITY

__all__ = [
    "CAV5_THRESHOLD",
    "DEFAULT_DAMPING",
    "DEFAULT_PERIODS",
    "SAMPLES_PER_PERIOD",
    "ResponseSpectrum",
    "arias_intensity",
    "cav",
    "cav5",
    "displacement",
    "husid",
    "intensity_measures",
    "intensity_measures_hv",
    "pga",
    "pgd",
    "pgv",
    "peak_time",
    "response_spectrum",
    "sdof_response",
    "significant_duration",
    "spectral_acceleration",
    "velocity",
]

#: Acceleration threshold of CAV5 [m/s^2] (5 cm/s^2, Kramer & Mitchell 2006).
CAV5_THRESHOLD = 0.05

#: Default oscillator periods of :func:`intensity_measures` [s]; ``0`` stands for PGA.
DEFAULT_PERIODS = (0.0, 0.05, 0.1, 0.2, 0.3, 0.5, 0.75, 1.0, 1.5, 2.0, 3.0, 4.0, 5.0)


# --------------------------------------------------------------------------------------------
# integration and peaks
# --------------------------------------------------------------------------------------------
def velocity(acc, dt) -> np.ndarray:
    r"""Ground velocity by the trapezoid rule (exact for piecewise-linear acceleration).

    .. math:: v_{i+1} = v_i + \frac{\Delta t}{2}(a_i + a_{i+1}), \qquad v_0 = 0

    Parameters
    ----------
    acc : array_like
        Ground acceleration [m/s^2], shape ``(n,)``.
    dt : float
        Time step [s].

    Returns
    -------
    numpy.ndarray
        Ground velocity [m/s], shape ``(n,)``, starting at rest.
    """
    a = _as_record(acc)
    dt = _check_dt(dt)
    v = np.empty_like(a)
    v[0] = 0.0
    np.cumsum(0.5 * dt * (a[1:] + a[:-1]), out=v[1:])
    return v


def displacement(acc, dt) -> np.ndarray:
    r"""Ground displacement by exact double integration of piecewise-linear acceleration.

    .. math:: d_{i+1} = d_i + v_i\,\Delta t + \frac{\Delta t^2}{6}(2a_i + a_{i+1}),
              \qquad d_0 = v_0 = 0

    with :math:`v` from :func:`velocity`.

    Parameters
    ----------
    acc : array_like
        Ground acceleration [m/s^2], shape ``(n,)``.
    dt : float
        Time step [s].

    Returns
    -------
    numpy.ndarray
        Ground displacement [m], shape ``(n,)``, starting at rest at the origin.
    """
    a = _as_record(acc)
    dt = _check_dt(dt)
    v = velocity(a, dt)
    d = np.empty_like(a)
    d[0] = 0.0
    np.cumsum(v[:-1] * dt + dt * dt / 6.0 * (2.0 * a[:-1] + a[1:]), out=d[1:])
    return d


def pga(acc, dt) -> float:
    r"""Peak ground acceleration :math:`\max_i |a_i|`.

    Parameters
    ----------
    acc : array_like
        Ground acceleration [m/s^2], shape ``(n,)``.
    dt : float
        Time step [s] (checked; the peak of samples does not depend on it).

    Returns
    -------
    float
        PGA [m/s^2], >= 0. Its time is :func:`peak_time` ``(acc, dt, "pga")``.
    """
    a = _as_record(acc)
    _check_dt(dt)
    return float(np.max(np.abs(a)))


def pgv(acc, dt) -> float:
    """Peak ground velocity, velocity from :func:`velocity`.

    Parameters
    ----------
    acc : array_like
        Ground acceleration [m/s^2], shape ``(n,)``.
    dt : float
        Time step [s].

    Returns
    -------
    float
        PGV [m/s], >= 0. Its time is :func:`peak_time` ``(acc, dt, "pgv")``.
    """
    return float(np.max(np.abs(velocity(acc, dt))))


def pgd(acc, dt) -> float:
    """Peak ground displacement, displacement from :func:`displacement`.

    Parameters
    ----------
    acc : array_like
        Ground acceleration [m/s^2], shape ``(n,)``.
    dt : float
        Time step [s].

    Returns
    -------
    float
        PGD [m], >= 0. Its time is :func:`peak_time` ``(acc, dt, "pgd")``.
    """
    return float(np.max(np.abs(displacement(acc, dt))))


_PEAK_SERIES = {"pga": lambda a, dt: a, "pgv": velocity, "pgd": displacement}


def peak_time(acc, dt, measure="pga") -> float:
    """Time of the (first) sample at which PGA, PGV or PGD is reached.

    Parameters
    ----------
    acc : array_like
        Ground acceleration [m/s^2], shape ``(n,)``.
    dt : float
        Time step [s].
    measure : {"pga", "pgv", "pgd"}
        The peak whose time is wanted.

    Returns
    -------
    float
        Time from the first sample [s].
    """
    if measure not in _PEAK_SERIES:
        raise ParameterError(f"measure must be one of {', '.join(_PEAK_SERIES)}, got {measure!r}")
    a = _as_record(acc)
    dt = _check_dt(dt)
    return float(np.argmax(np.abs(_PEAK_SERIES[measure](a, dt)))) * dt


# --------------------------------------------------------------------------------------------
# energy and duration measures
# --------------------------------------------------------------------------------------------
def _cumtrapz(y: np.ndarray, dt: float) -> np.ndarray:
    out = np.empty_like(y)
    out[0] = 0.0
    np.cumsum(0.5 * dt * (y[1:] + y[:-1]), out=out[1:])
    return out


def arias_intensity(acc, dt) -> float:
    r"""Arias intensity (Arias 1970).

    .. math:: I_a = \frac{\pi}{2g}\int_0^{t_{end}} a(t)^2\,dt

    with :math:`g` = 9.80665 m/s^2 and the integral by the trapezoid rule.

    Parameters
    ----------
    acc : array_like
        Ground acceleration [m/s^2], shape ``(n,)``.
    dt : float
        Time step [s].

    Returns
    -------
    float
        Arias intensity [m/s].

    References
    ----------
    .. [1] Arias, A. (1970). A measure of earthquake intensity. In *Seismic Design for
       Nuclear Power Plants*, MIT Press, 438-483.
    """
    a = _as_record(acc)
    dt = _check_dt(dt)
    return float(np.pi / (2.0 * STANDARD_GRAVITY) * np.trapezoid(a * a, dx=dt))


def husid(acc, dt) -> np.ndarray:
    r"""Normalised Husid curve, the cumulative Arias intensity (Husid 1969).

    .. math:: H(t) = \frac{\int_0^t a^2\,d\tau}{\int_0^{t_{end}} a^2\,d\tau}

    Parameters
    ----------
    acc : array_like
        Ground acceleration [m/s^2], shape ``(n,)``.
    dt : float
        Time step [s].

    Returns
    -------
    numpy.ndarray
        :math:`H(t_i)` [-], non-decreasing from 0 to 1, shape ``(n,)``.

    Raises
    ------
    ValueError
        If the record is identically zero (the curve is undefined).
    """
    a = _as_record(acc)
    dt = _check_dt(dt)
    cum = _cumtrapz(a * a, dt)
    if cum[-1] <= 0.0:
        raise RecordError(_SOURCE, "the Husid curve of an all-zero record is undefined")
    return cum / cum[-1]


def significant_duration(acc, dt, start=0.05, end=0.95) -> float:
    r"""Significant duration between two fractions of the Arias intensity.

    .. math:: D_{p\text{-}q} = t(H = q) - t(H = p)

    where :math:`H` is the Husid curve (:func:`husid`); the crossing times are found by linear
    interpolation of :math:`H` between samples. ``start=0.05, end=0.95`` gives the
    Trifunac & Brady (1975) duration D5-95; ``end=0.75`` gives D5-75.

    Parameters
    ----------
    acc : array_like
        Ground acceleration [m/s^2], shape ``(n,)``.
    dt : float
        Time step [s].
    start, end : float
        Fractions of the total Arias intensity with ``0 <= start < end <= 1`` [-].

    Returns
    -------
    float
        Duration [s].

    References
    ----------
    .. [1] Trifunac, M. D. and Brady, A. G. (1975). A study on the duration of strong
       earthquake ground motion. *Bull. Seismol. Soc. Am.* 65(3), 581-626.
    """
    start = checks.real(start, "start", low=0.0, high=1.0)
    end = checks.real(end, "end", low=0.0, high=1.0)
    if not start < end:
        raise ParameterError(f"need 0 <= start < end <= 1, got start={start}, end={end}")
    h = husid(acc, dt)
    t = np.arange(h.size) * _check_dt(dt)
    return float(_crossing_time(h, t, end) - _crossing_time(h, t, start))


def _crossing_time(h: np.ndarray, t: np.ndarray, level: float) -> float:
    """First time at which the non-decreasing ``h`` reaches ``level`` (linear interpolation)."""
    i = int(np.searchsorted(h, level, side="left"))
    if i == 0:
        return float(t[0])
    if i >= h.size:
        return float(t[-1])
    h0, h1 = h[i - 1], h[i]
    frac = 0.0 if h1 == h0 else (level - h0) / (h1 - h0)
    return float(t[i - 1] + frac * (t[i] - t[i - 1]))


def cav(acc, dt) -> float:
    r"""Cumulative absolute velocity (EPRI 1988).

    .. math:: \mathrm{CAV} = \int_0^{t_{end}} |a(t)|\,dt

    by the trapezoid rule on :math:`|a_i|`. This is the plain CAV, not the EPRI (1991)
    *standardized* CAV (1-s windows exceeding 0.025 g), which is not implemented.

    Parameters
    ----------
    acc : array_like
        Ground acceleration [m/s^2], shape ``(n,)``.
    dt : float
        Time step [s].

    Returns
    -------
    float
        CAV [m/s].

    References
    ----------
    .. [1] EPRI (1988). A criterion for determining exceedance of the operating basis
       earthquake. Report NP-5930, Electric Power Research Institute.
    """
    a = _as_record(acc)
    return float(np.trapezoid(np.abs(a), dx=_check_dt(dt)))


def cav5(acc, dt, threshold=CAV5_THRESHOLD) -> float:
    r"""CAV counting only samples whose absolute acceleration reaches a threshold.

    Convention (Kramer & Mitchell 2006, eq. 3):

    .. math:: \mathrm{CAV}_5 = \int_0^{t_{end}} \chi(t)\,|a(t)|\,dt, \qquad
              \chi = \begin{cases} 0 & |a| < 5\ \mathrm{cm/s^2} \\
                                   1 & |a| \ge 5\ \mathrm{cm/s^2}\end{cases}

    :math:`\chi` is evaluated *sample by sample* and the integrand :math:`\chi_i |a_i|` is
    integrated by the trapezoid rule (so a step into or out of the counted set contributes
    half a trapezoid). With ``threshold=0`` this equals :func:`cav`.

    Parameters
    ----------
    acc : array_like
        Ground acceleration [m/s^2], shape ``(n,)``.
    dt : float
        Time step [s].
    threshold : float
        Acceleration threshold [m/s^2]; default 0.05 m/s^2 = 5 cm/s^2.

    Returns
    -------
    float
        CAV5 [m/s].

    References
    ----------
    .. [1] Kramer, S. L. and Mitchell, R. A. (2006). Ground motion intensity measures for
       liquefaction hazard evaluation. *Earthquake Spectra* 22(2), 413-438.
    .. [2] EPRI (1988). Report NP-5930 (definition of CAV).
    """
    a = _as_record(acc)
    threshold = checks.real(threshold, "threshold", low=0.0, high=checks.MAX_ACCELERATION,
                            units="m/s^2")
    absa = np.abs(a)
    return float(np.trapezoid(np.where(absa >= threshold, absa, 0.0), dx=_check_dt(dt)))


# --------------------------------------------------------------------------------------------
# convenience bundles
# --------------------------------------------------------------------------------------------
def intensity_measures(acc, dt, periods=DEFAULT_PERIODS, damping=DEFAULT_DAMPING) -> dict:
    """All scalar intensity measures of one component plus its response spectrum.

    Parameters
    ----------
    acc : array_like
        Ground acceleration [m/s^2], shape ``(n,)``.
    dt : float
        Time step [s].
    periods : array_like
        Periods of the pseudo-acceleration spectrum [s]; default :data:`DEFAULT_PERIODS`.
    damping : float
        Fraction of critical damping of the spectrum [-]; default 0.05.

    Returns
    -------
    dict
        ``"pga"`` [m/s^2], ``"t_pga"`` [s], ``"pgv"`` [m/s], ``"t_pgv"`` [s], ``"pgd"`` [m],
        ``"t_pgd"`` [s], ``"arias"`` [m/s], ``"cav"`` [m/s], ``"cav5"`` [m/s], ``"d5_75"`` [s],
        ``"d5_95"`` [s], ``"periods"`` [s] (array), ``"damping"`` [-], ``"sa"`` [m/s^2]
        (array, same shape as ``periods``). Durations are NaN for an all-zero record.
    """
    a = _as_record(acc)
    dt = _check_dt(dt)
    v = velocity(a, dt)
    d = displacement(a, dt)
    i_a, i_v, i_d = (int(np.argmax(np.abs(x))) for x in (a, v, d))
    if np.any(a != 0.0):
        d575 = significant_duration(a, dt, 0.05, 0.75)
        d595 = significant_duration(a, dt, 0.05, 0.95)
    else:
        d575 = d595 = float("nan")
    spec = response_spectrum(a, dt, periods, damping)
    return {
        "pga": float(abs(a[i_a])),
        "t_pga": i_a * dt,
        "pgv": float(abs(v[i_v])),
        "t_pgv": i_v * dt,
        "pgd": float(abs(d[i_d])),
        "t_pgd": i_d * dt,
        "arias": arias_intensity(a, dt),
        "cav": cav(a, dt),
        "cav5": cav5(a, dt),
        "d5_75": d575,
        "d5_95": d595,
        "periods": spec.periods,
        "damping": spec.damping,
        "sa": spec.psa,
    }


def intensity_measures_hv(
    horizontal, vertical, dt, periods=DEFAULT_PERIODS, damping=DEFAULT_DAMPING
) -> dict:
    """Intensity measures of a horizontal + vertical pair.

    Parameters
    ----------
    horizontal, vertical : array_like
        Horizontal and vertical ground acceleration [m/s^2], same shape ``(n,)``.
    dt : float
        Time step [s].
    periods : array_like
        Spectrum periods [s].
    damping : float
        Fraction of critical damping [-].

    Returns
    -------
    dict
        ``{"H": intensity_measures(horizontal, ...), "V": intensity_measures(vertical, ...),
        "v_over_h_pga": PGA_V / PGA_H [-]}`` (NaN if the horizontal is all zero).
    """
    h = _as_record(horizontal, "horizontal")
    v = _as_record(vertical, "vertical")
    if h.shape != v.shape:
        raise ParameterError(
            f"horizontal and vertical must have the same length, got {h.size} and {v.size}"
        )
    im_h = intensity_measures(h, dt, periods, damping)
    im_v = intensity_measures(v, dt, periods, damping)
    ratio = im_v["pga"] / im_h["pga"] if im_h["pga"] > 0.0 else float("nan")
    return {"H": im_h, "V": im_v, "v_over_h_pga": ratio}
