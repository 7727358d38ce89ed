r"""Orientation-independent response spectra of two horizontals: RotD50 and RotD100.

For each period :math:`T` the oscillator responses :math:`u_1(t), u_2(t)` to the two
horizontal components (orthogonal, as recorded) are combined into the response at azimuth
:math:`\theta` from the first,

.. math:: u(\theta, t) = u_1(t)\cos\theta + u_2(t)\sin\theta,

whose peak :math:`S_d(\theta) = \max_t |u(\theta, t)|` is taken for :math:`\theta` = 0, 1, ...,
179 deg. RotD50 is the median and RotD100 the largest of these peaks over the angles (Boore
2010 [1]_; :math:`S_a = \omega^2 S_d`). The responses are the exact Nigam-Jennings recursion of
:func:`shipblock.intensity.response_spectrum`, with the same oversampling of short periods, so
that a record with one component zero gives RotD100 equal to that component's spectrum.

Closed forms used in the tests: two identical horizontals give
:math:`S_d(\theta) = |\cos\theta + \sin\theta|\,S_d = \sqrt2\,|\sin(\theta + 45^\circ)|\,S_d`,
whose median over the 180 angles is exactly :math:`S_d` (RotD50 equals the spectrum of either
component, RotD100 is :math:`\sqrt2` times it); one component alone gives RotD50 =
:math:`S_d/\sqrt2`.

References
----------
.. [1] Boore, D. M. (2010). Orientation-independent, nongeometric-mean measures of seismic
   intensity from two horizontal components of motion. *Bull. Seismol. Soc. Am.* 100(4),
   1830-1835.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
from numba import njit

from shipblock.errors import ParameterError
from shipblock.intensity._checks import _as_record, _check_damping, _check_dt, _check_periods
from shipblock.intensity.spectrum import (
    DEFAULT_DAMPING,
    SAMPLES_PER_PERIOD,
    _nigam_jennings_coefficients,
)

__all__ = ["ANGLES_DEG", "RotDSpectrum", "rotd_spectrum"]

#: Azimuths of the rotated responses [deg] (Boore 2010: 1 deg steps over half a turn).
ANGLES_DEG = np.arange(180.0)


class RotDSpectrum(NamedTuple):
    """Result of :func:`rotd_spectrum`: ``periods`` [s], ``damping`` [-], ``rotd50`` and
    ``rotd100`` pseudo-spectral accelerations [m/s^2], and ``peaks`` [m], the peak
    displacement at each period (rows) and angle of :data:`ANGLES_DEG` (columns)."""

    periods: np.ndarray
    damping: float
    rotd50: np.ndarray
    rotd100: np.ndarray
    peaks: np.ndarray


@njit(cache=True)
def _rotated_peaks(acc1, acc2, sub, cos, sin, a, b, c, d, ap, bp, cp, dp):  # pragma: no cover
    """Peak |u1 cos + u2 sin| per oscillator (rows) and angle (columns).

    The angle loop runs only when the response radius sqrt(u1^2 + u2^2), an upper bound of
    every projection, exceeds the smallest peak so far: exact, and most steps after the
    strong motion skip it.
    """
    m = a.shape[0]
    n = acc1.shape[0]
    k_ang = cos.shape[0]
    out = np.zeros((m, k_ang))
    for j in range(m):
        u1 = 0.0
        v1 = 0.0
        u2 = 0.0
        v2 = 0.0
        low = 0.0
        k = sub[j]
        for i in range(n - 1):
            q1 = -acc1[i]
            q2 = -acc2[i]
            dq1 = (-acc1[i + 1] - q1) / k
            dq2 = (-acc2[i + 1] - q2) / k
            p1 = q1
            p2 = q2
            for s in range(1, k + 1):
                n1 = -acc1[i + 1] if s == k else q1 + dq1 * s
                n2 = -acc2[i + 1] if s == k else q2 + dq2 * s
                un = a[j] * u1 + b[j] * v1 + c[j] * p1 + d[j] * n1
                v1 = ap[j] * u1 + bp[j] * v1 + cp[j] * p1 + dp[j] * n1
                u1 = un
                un = a[j] * u2 + b[j] * v2 + c[j] * p2 + d[j] * n2
                v2 = ap[j] * u2 + bp[j] * v2 + cp[j] * p2 + dp[j] * n2
                u2 = un
                p1 = n1
                p2 = n2
                if u1 * u1 + u2 * u2 > low * low:
                    low = np.inf
                    for q in range(k_ang):
                        x = abs(u1 * cos[q] + u2 * sin[q])
                        if x > out[j, q]:
                            out[j, q] = x
                        if out[j, q] < low:
                            low = out[j, q]
    return out


def rotd_spectrum(acc1, acc2, dt, periods, damping=DEFAULT_DAMPING,
                  samples_per_period=SAMPLES_PER_PERIOD) -> RotDSpectrum:
    """RotD50 and RotD100 pseudo-spectral accelerations of two orthogonal horizontals.

    Parameters
    ----------
    acc1, acc2 : array_like
        The two horizontal accelerations [m/s^2], orthogonal, same length ``(n,)``.
    dt : float
        Time step [s].
    periods : array_like
        Natural periods [s], ``> 0``.
    damping : float
        Fraction of critical damping [-]; default 0.05.
    samples_per_period : int
        Fewest response samples per oscillator period (see
        :func:`shipblock.intensity.response_spectrum`).

    Returns
    -------
    RotDSpectrum
        ``rotd50`` and ``rotd100`` [m/s^2] per period, and the peaks per period and angle [m].

    Raises
    ------
    ParameterError
        For records of different lengths, a period of zero or less, or arguments the single
        spectrum refuses (the message names the argument).
    """
    a1 = _as_record(acc1, "acc1")
    a2 = _as_record(acc2, "acc2")
    if a1.size != a2.size:
        raise ParameterError(f"acc1 and acc2 must have the same length, got {a1.size} and "
                             f"{a2.size}: the two horizontals of one record")
    dt = _check_dt(dt)
    zeta = _check_damping(damping)
    periods = _check_periods(periods)
    if np.any(periods <= 0):
        raise ParameterError("periods must be above zero for RotD spectra (T = 0 is the PGA "
                             "of the rotated record)")
    omega = 2.0 * np.pi / periods
    sub = np.maximum(1, np.ceil(samples_per_period * dt / periods)).astype(np.int64)
    coef = _nigam_jennings_coefficients(omega, zeta, dt / sub)
    theta = np.radians(ANGLES_DEG)
    peaks = _rotated_peaks(a1, a2, sub, np.cos(theta), np.sin(theta),
                           *(np.ascontiguousarray(x) for x in coef))
    return RotDSpectrum(periods.copy(), zeta, omega**2 * np.median(peaks, axis=1),
                        omega**2 * peaks.max(axis=1), peaks)
