r"""The risk integral: a lognormal fragility convolved with a site hazard curve.

The annual rate of exceeding a limit state LS is the total-probability sum over the intensity

.. math:: \lambda_{LS} = \int_0^\infty P(LS \mid x)\, \left|\mathrm{d}\lambda_{IM}(x)\right|
          = \int_0^\infty \lambda_{IM}(x)\, f_C(x)\, \mathrm{d}x,
   :label: risk-integral

(the second form by parts, :math:`P(LS\mid 0) = 0`, :math:`\lambda_{IM}(\infty) = 0`), where
:math:`P(LS \mid x) = \Phi(\ln(x/\theta)/\beta)` is the fitted fragility and
:math:`f_C` its density, the lognormal density of the capacity :math:`C` (Cornell et al. 2002
[1]_). Between two levels :math:`x_i < x_{i+1}` of the curve the hazard is taken as the power
law through them (a straight line on log-log axes, the usual interpolation of hazard curves),
:math:`\lambda(x) = \lambda_i (x/x_i)^{-k_i}`, and on that piece the integral is exact: with
:math:`U = \ln C \sim N(\mu, \beta^2)`, :math:`\mu = \ln\theta`,

.. math:: S_i = \int_{x_i}^{x_{i+1}} \lambda f_C\,\mathrm{d}x
          = \lambda_i\, e^{k_i(u_i - \mu) + k_i^2\beta^2/2}
            \left[\Phi\!\left(\frac{u_{i+1} - \mu + k_i\beta^2}{\beta}\right)
                - \Phi\!\left(\frac{u_i - \mu + k_i\beta^2}{\beta}\right)\right],
            \quad u_i = \ln x_i,

evaluated in logarithms (no overflow of the exponential against a vanishing :math:`\Phi`
difference). For a hazard that is one power law, :math:`\lambda = k_0 x^{-k}`, the sum is the
closed form :math:`\lambda_{LS} = k_0\,\theta^{-k} e^{k^2\beta^2/2}` (Cornell et al. 2002,
eq. 11), which the tests check. Beyond the curve's levels the end pieces are extended with
their slopes (below the first level, and above the last if its rate is positive); where the
curve reaches a rate of zero the hazard is zero above the last positive level. The share of
:math:`\lambda_{LS}` from beyond the levels is reported (``tail_fraction``): a large one says
the curve does not cover the capacities.

**Deaggregation.** The contribution of the hazard between :math:`x_i` and :math:`x_{i+1}`
(earthquakes whose IM falls there causing LS) is :math:`D_i = \int_{x_i}^{x_{i+1}} P\,
|\mathrm{d}\lambda| = S_i + \lambda_i P_i - \lambda_{i+1} P_{i+1}` (by parts), and
:math:`\sum_i D_i = \lambda_{LS}`.

**Docking period.** Earthquakes as a Poisson process, the probability of at least one
exceedance during :math:`N` days is :math:`1 - \exp(-\lambda_{LS} N / 365.25)`; the return
period is :math:`1/\lambda_{LS}`.

References
----------
.. [1] Cornell, C. A., Jalayer, F., Hamburger, R. O. and Foutch, D. A. (2002). Probabilistic
   basis for 2000 SAC Federal Emergency Management Agency steel moment frame guidelines.
   *J. Struct. Eng.* 128(4), 526-533.
.. [2] Eads, L., Miranda, E., Krawinkler, H. and Lignos, D. G. (2013). An efficient method for
   estimating the collapse risk of structures in seismic regions. *Earthquake Eng. Struct.
   Dyn.* 42(1), 25-41 (the deaggregation of the collapse rate over the intensity).
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
from scipy.special import log_ndtr, ndtr

from shipblock import checks
from shipblock.errors import ParameterError

__all__ = [
    "DAYS_PER_YEAR",
    "RiskIntegral",
    "period_probability",
    "risk_integral",
]

#: Days of a year in the Poisson conversion of a docking period [d] (Julian year).
DAYS_PER_YEAR = 365.25


class RiskIntegral(NamedTuple):
    """Result of :func:`risk_integral` for a batch of fragility curves.

    Attributes
    ----------
    annual_rate : numpy.ndarray
        :math:`\\lambda_{LS}` [1/yr], shape of the medians.
    contribution : numpy.ndarray
        :math:`D_i` [1/yr] of each hazard bin, shape ``(*median.shape, n + 1)``.
    bin_lower, bin_upper : numpy.ndarray
        Edges of the bins [IM units]: ``(0, x_0)``, ``(x_0, x_1)``, ..., ``(x_{n-1}, inf)``.
    tail_fraction : numpy.ndarray
        Share of :math:`\\lambda_{LS}` from the bins beyond the curve's levels [-].
    """

    annual_rate: np.ndarray
    contribution: np.ndarray
    bin_lower: np.ndarray
    bin_upper: np.ndarray
    tail_fraction: np.ndarray


def _log_phi_difference(a, b):
    """:math:`\\ln(\\Phi(b) - \\Phi(a))` for ``a <= b``, accurate in both tails."""
    a, b = np.broadcast_arrays(np.asarray(a, float), np.asarray(b, float))
    upper = a > 0.0  # both in the upper tail: use the survival function, Phi(-a) - Phi(-b)
    hi = np.where(upper, log_ndtr(-a), log_ndtr(b))
    lo = np.where(upper, log_ndtr(-b), log_ndtr(a))
    with np.errstate(divide="ignore", invalid="ignore"):
        return hi + np.log1p(-np.exp(lo - hi))


def _piece(log_rate, k, u_start, u_from, u_to, mu, beta):
    r""":math:`\int \lambda f_C` over :math:`u \in (u_{from}, u_{to})` for the power law
    :math:`\lambda = e^{\text{log\_rate}}\, e^{-k (u - u_{start})}` (exact)."""
    shift = k * beta**2
    log_value = (log_rate + k * (u_start - mu) + 0.5 * shift * k
                 + _log_phi_difference((u_from - mu + shift) / beta, (u_to - mu + shift) / beta))
    return np.where(np.isfinite(log_value), np.exp(log_value), 0.0)


def risk_integral(im, rate, median, beta) -> RiskIntegral:
    r"""Annual rate of exceedance of lognormal fragilities on a hazard curve, eq.
    :eq:`risk-integral`, with its deaggregation over the curve's levels.

    Parameters
    ----------
    im : array_like
        Levels of the hazard curve [IM units], positive, increasing, shape ``(n,)``, ``n >= 2``.
    rate : array_like
        Annual rate of exceedance of each level [1/yr], non-increasing, first one positive.
    median : float or array_like
        Median capacities :math:`\theta` [same IM units], positive.
    beta : float or array_like
        Dispersions :math:`\beta` [-], positive; broadcast with ``median``.

    Returns
    -------
    RiskIntegral

    Raises
    ------
    ParameterError
        For a curve that is not one or a median or beta that is not positive and finite.
    """
    x = checks.as_real_array(im, "im", "hazard levels")
    lam = checks.as_real_array(rate, "rate", "annual rates of exceedance")
    if x.ndim != 1 or x.shape != lam.shape or x.size < 2:
        raise ParameterError(f"im and rate must be 1-D of the same length >= 2, got shapes "
                             f"{x.shape} and {lam.shape}")
    if not (np.all(x > 0.0) and np.all(np.diff(x) > 0.0)):
        raise ParameterError("im must be positive and increasing [IM units]")
    if not (np.all(lam >= 0.0) and lam[0] > 0.0 and np.all(np.diff(lam) <= 0.0)):
        raise ParameterError("rate must be non-increasing, non-negative, its first value positive "
                             "[1/yr]")
    theta = checks.as_real_array(median, "median", "median capacities")
    b = checks.as_real_array(beta, "beta", "dispersions")
    theta, b = np.broadcast_arrays(theta, b)
    if not (np.all(theta > 0.0) and np.all(b > 0.0)):
        raise ParameterError("median and beta must be positive (no NaN)")
    shape = theta.shape
    mu = np.log(theta).reshape(-1, 1)
    bb = b.reshape(-1, 1)

    n = x.size
    last = int(np.flatnonzero(lam > 0.0)[-1])  # the last level with a positive rate
    truncated = last < n - 1
    u = np.log(x[: last + 1])
    log_lam = np.log(lam[: last + 1])
    if last >= 1:
        k = -np.diff(log_lam) / np.diff(u)
    else:  # one positive level: a step of the hazard, no slope to extend
        k = np.zeros(1)
    p = ndtr((np.log(x)[None, :] - mu) / bb)  # fragility at every level, (m, n)
    lam_p = lam[None, :] * p

    contribution = np.zeros((mu.shape[0], n + 1))
    # bins 1 .. last: the pieces between positive levels
    for i in range(last):
        s = _piece(log_lam[i], k[i], u[i], u[i], u[i + 1], mu, bb)
        contribution[:, i + 1] = s[:, 0] + lam_p[:, i] - lam_p[:, i + 1]
    # bin 0: below the first level, the first piece extended
    s_low = _piece(log_lam[0], k[0], u[0], -np.inf, u[0], mu, bb)[:, 0]
    contribution[:, 0] = s_low - lam_p[:, 0]
    # above the last positive level
    if truncated:
        contribution[:, last + 1] = lam_p[:, last]  # the rate drops to zero there
    else:
        s_up = _piece(log_lam[last], k[-1], u[last], u[last], np.inf, mu, bb)[:, 0]
        contribution[:, n] = s_up + lam_p[:, last]
    contribution = np.maximum(contribution, 0.0)  # rounding of the by-parts differences
    total = contribution.sum(axis=1)
    tails = contribution[:, 0] + (contribution[:, n] if not truncated else 0.0)
    lower = np.concatenate([[0.0], x])
    upper = np.concatenate([x, [np.inf]])
    return RiskIntegral(total.reshape(shape), contribution.reshape(*shape, n + 1), lower, upper,
                        (tails / total).reshape(shape))


def period_probability(annual_rate, days):
    r"""Probability of at least one exceedance in a period of ``days`` (Poisson occurrences).

    .. math:: P_N = 1 - \exp(-\lambda\, N / 365.25)

    Parameters
    ----------
    annual_rate : float or array_like
        :math:`\lambda` [1/yr], non-negative.
    days : float
        :math:`N` [d], positive.

    Returns
    -------
    numpy.ndarray or float
        :math:`P_N` [-].
    """
    days = checks.real(days, "days", low=0.0, low_open=True, high=3650.0 * DAYS_PER_YEAR,
                       units="d")
    lam = np.asarray(annual_rate, dtype=float)
    out = -np.expm1(-lam * days / DAYS_PER_YEAR)
    return float(out) if out.ndim == 0 else out
