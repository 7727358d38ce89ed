r"""Common parts of the fragility fits: the fitted lognormal curve and its checks.

:class:`FragilityFit` holds a fitted curve
:math:`P(\mathrm{LS} \mid \mathrm{IM} = x) = \Phi(\ln(x/\theta)/\beta)` (see
:mod:`shipblock.fragility.fit`), :func:`lognormal_fragility` evaluates it, and
:class:`FragilityFitError` says that data cannot identify one. Used by every estimator
(:mod:`~shipblock.fragility.fit.msa`, :mod:`~shipblock.fragility.fit.ida`,
:mod:`~shipblock.fragility.fit.cloud`) and by the bootstrap.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field

import numpy as np
from scipy import special

from shipblock import checks
from shipblock.errors import ParameterError, ParameterTypeError, ShipblockError

#: Smallest dispersion accepted as a finite-beta fit [-]. Below it the data are (numerically)
#: separated and the lognormal curve degenerates to a step.
_MIN_BETA = 1e-6


class FragilityFitError(ShipblockError, ValueError):
    """The data cannot identify a lognormal fragility curve (e.g. no exceedances)."""


@dataclass(frozen=True)
class FragilityFit:
    r"""Fitted lognormal fragility function.

    Attributes
    ----------
    median : float
        Median capacity :math:`\theta` [IM units]: the IM with 50 % probability of exceedance.
    beta : float
        Logarithmic standard deviation :math:`\beta` [-].
    method : str
        How the curve was fitted: ``"mle"``, ``"mle_fixed_beta"``, ``"ida_moments"``,
        ``"ida_mle"``, ``"ida_interval"``, ``"ida_first_exceedance"``,
        ``"ida_first_exceedance_moments"``, ``"cloud_regression"`` or ``"cloud_probit"``.
    log_likelihood : float
        Maximised log-likelihood [-] (see the fitting function for its definition); ``nan``
        for moment estimators.
    n : int
        Number of observations: records x stripes for MSA, records for IDA and cloud.
    median_ci, beta_ci : tuple of float or None
        Lower and upper confidence bounds of ``median`` [IM units] and ``beta`` [-], filled in
        by :func:`bootstrap`.
    ci_level : float or None
        Confidence level of the bounds, e.g. 0.9 [-].
    details : Mapping[str, float]
        Method-specific diagnostics (regression coefficients, number censored, ...).
    """

    median: float
    beta: float
    method: str
    log_likelihood: float
    n: int
    median_ci: tuple[float, float] | None = None
    beta_ci: tuple[float, float] | None = None
    ci_level: float | None = None
    details: Mapping[str, float] = field(default_factory=dict)

    def probability(self, x):
        r"""Probability of exceedance at intensity ``x``.

        Parameters
        ----------
        x : array_like
            Intensity measure [IM units], non-negative.

        Returns
        -------
        numpy.ndarray
            :math:`\Phi(\ln(x/\theta)/\beta)` [-], same shape as ``x``.
        """
        return lognormal_fragility(x, self.median, self.beta)


def _reals(values, name: str, kinds: str = "iuf") -> np.ndarray:
    """An argument as a float array, or a ParameterTypeError naming it."""
    return checks.as_real_array(values, name, "an array of numbers", kinds)


def _method(value, name: str, choices: tuple[str, ...]) -> str:
    if not isinstance(value, str):
        raise ParameterTypeError(f"{name} must be one of {choices}, got {type(value).__name__}")
    return value


def lognormal_fragility(x, median, beta):
    r"""Lognormal fragility function, eq. :eq:`lognormal-fragility`.

    Parameters
    ----------
    x : array_like
        Intensity measure [IM units], non-negative. ``x = 0`` gives probability 0.
    median : float or array_like
        Median :math:`\theta` [IM units], positive.
    beta : float or array_like
        Dispersion :math:`\beta` [-], positive.

    Returns
    -------
    numpy.ndarray
        :math:`\Phi(\ln(x/\theta)/\beta)` [-], broadcast shape of the inputs.
    """
    x = _reals(x, "x")
    median, beta = _reals(median, "median"), _reals(beta, "beta")
    if not np.all(x >= 0.0):
        raise ParameterError("x must be non-negative [IM units] (no NaN)")
    for name, value in (("median", median), ("beta", beta)):
        if not np.all(np.isfinite(value) & (value > 0.0)):
            raise ParameterError(f"{name} must be finite and positive, got {value!r}")
    try:
        np.broadcast_shapes(x.shape, median.shape, beta.shape)
    except ValueError:
        raise ParameterError(f"x, median and beta must broadcast together, got shapes {x.shape}, "
                             f"{median.shape}, {beta.shape}") from None
    return _lognormal(x, median, beta)


def _lognormal(x, median, beta):
    """:func:`lognormal_fragility` without the argument checks (for arrays made here)."""
    with np.errstate(divide="ignore"):
        return special.ndtr((np.log(x) - np.log(median)) / beta)


