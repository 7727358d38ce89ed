r"""Lognormal fragility functions fitted to multiple-stripe, incremental and cloud analyses.

A fragility function gives the probability that a limit state is exceeded given the
intensity measure (IM) of the ground motion,

.. math::
    :label: lognormal-fragility

    P(\mathrm{LS} \mid \mathrm{IM} = x) = \Phi\!\left(\frac{\ln(x/\theta)}{\beta}\right),

with median :math:`\theta` [IM units] and logarithmic standard deviation (dispersion)
:math:`\beta` [-]; :math:`\Phi` is the standard normal CDF.

Three kinds of analysis are supported, following Baker (2015) [1]_:

* **Multiple-stripe analysis (MSA)**: at each IM level :math:`x_j` a set of :math:`n_j` records
  is run and :math:`z_j` of them exceed the limit state. :func:`fit_mle` maximises the binomial
  likelihood; :func:`fit_msa` does the same from a record x IM-level exceedance matrix.
* **Incremental dynamic analysis (IDA)**: each record is scaled up until it exceeds the limit
  state, giving one IM capacity per record. On discrete IM levels a record's capacity is only
  known to lie between the last level that held and the first that failed:
  :func:`fit_ida_levels` fits the exceedance matrix by interval-censored maximum likelihood
  (:func:`fit_ida_intervals`, the default) or, as an option, takes the first exceeding level as
  the capacity (biased high by up to one level step). :func:`ida_capacities` turns an exceedance
  matrix into capacity bounds; :func:`fit_ida` fits capacities known exactly (e.g. from a
  hunt-and-fill IDA), by the method of moments or right-censored maximum likelihood.
* **Cloud analysis** of unscaled records: :func:`fit_cloud` regresses :math:`\ln \mathrm{EDP}`
  on :math:`\ln \mathrm{IM}` (Cornell et al. 2002 [2]_, Jalayer 2003 [3]_) or fits a probit
  to the binary outcome.

:func:`bootstrap` resamples records with replacement and refits, giving percentile confidence
bands for the curve and for :math:`\theta` and :math:`\beta`.

All functions are pure: no global random state is used or changed.

References
----------
.. [1] Baker, J. W. (2015). Efficient analytical fragility function fitting using dynamic
   structural analysis. *Earthquake Spectra*, 31(1), 579-599. doi:10.1193/021113EQS025M
.. [2] Cornell, C. A., Jalayer, F., Hamburger, R. O., & Foutch, D. A. (2002). Probabilistic
   basis for 2000 SAC Federal Emergency Management Agency steel moment frame guidelines.
   *Journal of Structural Engineering*, 128(4), 526-533.
.. [3] Jalayer, F. (2003). *Direct probabilistic seismic analysis: implementing non-linear
   dynamic assessments*. PhD thesis, Stanford University.
"""

from __future__ import annotations

import time
import warnings
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field, replace
from typing import Any, NamedTuple

import numpy as np
from scipy import optimize, special, stats

from shipblock import checks
from shipblock.errors import ParameterError, ParameterTypeError, ShipblockError

__all__ = [
    "BootstrapResult",
    "FragilityFit",
    "FragilityFitError",
    "IDACapacities",
    "bootstrap",
    "fit_cloud",
    "IDA_METHODS",
    "fit_ida",
    "fit_ida_intervals",
    "fit_ida_levels",
    "fit_mle",
    "fit_msa",
    "ida_capacities",
    "lognormal_fragility",
]

#: Gradient tolerance per observation of the censored IDA likelihood maximisation [-].
_GTOL_PER_OBS = 1e-9

_LOG_SQRT_2PI = np.log(np.sqrt(2 * np.pi))


def _norm_logpdf(x):
    """Standard normal log density.

    The expression of ``scipy.stats.norm.logpdf(x)`` (the same result bit for bit) without its
    per-call overhead, which dominated the time of the censored IDA fits.
    """
    return -(x**2) / 2.0 - _LOG_SQRT_2PI


#: Smallest dispersion accepted as a finite-beta fit [-]. Below it the data are (numerically)
#: separated and the lognormal curve degenerates to a step.
_MIN_BETA = 1e-6


#: Newton decrement per observation below which the probit MLE has converged [-].
_NEWTON_TOL_PER_OBS = 1e-16

#: Smallest line-search step fraction before Newton gives up improving (round-off) [-].
_MIN_STEP_FRACTION = 1e-10

#: Default bootstrap band grid: number of points and half-width in units of beta [-].
_GRID_POINTS = 100
_GRID_HALF_WIDTH = 3.0

#: Smallest change of the probit index b1 * ln(x) over the range of the IM levels that counts as
#: an IM-dependent fit [-]; below it the fitted probability is flat (beta -> infinity).
_MIN_SLOPE_RANGE = 1e-6


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


# ---------------------------------------------------------------------------------------------
# Multiple-stripe analysis: binomial MLE
# ---------------------------------------------------------------------------------------------


def _probit_terms(z):
    """Log-CDF terms and inverse Mills ratios of the probit link, numerically stable.

    Returns ``log Phi(z)``, ``log Phi(-z)``, ``phi(z)/Phi(z)`` and ``phi(z)/Phi(-z)``.
    """
    log_p = special.log_ndtr(z)
    log_q = special.log_ndtr(-z)
    log_pdf = -0.5 * z**2 - 0.5 * np.log(2.0 * np.pi)
    return log_p, log_q, np.exp(log_pdf - log_p), np.exp(log_pdf - log_q)


def _check_overlap(x, k, n):
    """Raise :class:`FragilityFitError` unless the stripes identify a finite (median, beta).

    In one dimension the probit MLE exists iff the data are not (quasi-)completely separated:
    some stripe with a survivor lies strictly above some stripe with an exceedance.
    """
    used = n > 0
    if np.unique(x[used]).size < 2:
        raise FragilityFitError(
            "at least two distinct IM levels with records are needed to fit median and beta"
        )
    if not np.any(k > 0):
        raise FragilityFitError(
            "no exceedances at any IM level: the median is only bounded below by the highest "
            f"level ({x[used].max():g}); analyse higher IM levels"
        )
    if not np.any(k < n):
        raise FragilityFitError(
            "every record exceeds at every IM level: the median is only bounded above by the "
            f"lowest level ({x[used].min():g}); analyse lower IM levels"
        )
    if x[k > 0].max() <= x[(n - k) > 0].min():
        raise FragilityFitError(
            "every exceedance occurs at an IM at or below every survivor: the probability of "
            "exceedance decreases with IM; check the limit state definition and the IM levels"
        )
    lowest_exceed = x[k > 0].min()
    highest_survive = x[(n - k) > 0].max()
    if highest_survive <= lowest_exceed:
        raise FragilityFitError(
            "the stripes are separated (all records survive at IM <= "
            f"{highest_survive:g} and all exceed at IM >= {lowest_exceed:g}): beta -> 0 and the "
            "median is not identified; add IM levels in between or fix beta (fixed_beta=...)"
        )


def _binomial_log_coefficient(k, n):
    """Log binomial coefficient ln C(n, k) [-]."""
    return special.gammaln(n + 1.0) - special.gammaln(k + 1.0) - special.gammaln(n - k + 1.0)


def fit_mle(im_levels, n_exceed, n_total, *, fixed_beta=None) -> FragilityFit:
    r"""Maximum-likelihood lognormal fragility from exceedance counts at IM stripes.

    At IM level :math:`x_j`, :math:`z_j` of :math:`n_j` records exceed the limit state. Treating
    the counts as independent binomial observations, Baker (2015) [1]_ eq. (11) maximises

    .. math::

        \ln L(\theta, \beta) = \sum_j \left[\ln\binom{n_j}{z_j}
            + z_j \ln p_j + (n_j - z_j)\ln(1 - p_j)\right],
        \qquad p_j = \Phi\!\left(\frac{\ln(x_j/\theta)}{\beta}\right).

    This is a probit generalised linear model in :math:`\ln x` with
    :math:`p_j = \Phi(b_0 + b_1 \ln x_j)`, :math:`\beta = 1/b_1`, :math:`\theta = \exp(-b_0/b_1)`.
    The log-likelihood is concave in :math:`(b_0, b_1)`, so it is maximised there by damped
    Newton steps with the exact Hessian, which converge to the unique maximum whenever it
    exists.

    Parameters
    ----------
    im_levels : array_like, shape (m,)
        IM of each stripe [IM units], positive. Levels may repeat.
    n_exceed : array_like of int, shape (m,)
        Number of records exceeding the limit state at each stripe [-].
    n_total : array_like of int, shape (m,)
        Number of (valid) records analysed at each stripe [-]. Stripes with 0 records are
        ignored.
    fixed_beta : float, optional
        Fix the dispersion [-] and fit only the median. Useful when the stripes are separated
        (see Raises), or to impose a dispersion from the literature.

    Returns
    -------
    FragilityFit
        ``method="mle"`` (or ``"mle_fixed_beta"``), ``n = sum(n_total)``, ``log_likelihood`` the
        full binomial log-likelihood above (it includes the binomial coefficients, as
        statsmodels' ``GLM(..., family=Binomial()).llf`` does). ``details`` holds the probit
        coefficients ``b0``, ``b1`` and the number of iterations.

    Raises
    ------
    FragilityFitError
        If the data cannot identify the curve: no exceedances at all (the median is only bounded
        below), all records exceeding everywhere (only bounded above), fewer than two distinct
        IM levels, complete or quasi-complete separation (all survivors at IMs at or below all
        exceedances: :math:`\beta \to 0`), or a fitted fragility that does not increase with IM
        (:math:`b_1 \le 0`, or so small that :math:`\beta` is effectively infinite).
        With ``fixed_beta`` only the first two checks apply.
    ValueError
        On malformed inputs (shapes, negative counts, ``n_exceed > n_total``, IM <= 0).

    References
    ----------
    .. [1] Baker, J. W. (2015). Efficient analytical fragility function fitting using dynamic
       structural analysis. *Earthquake Spectra*, 31(1), 579-599.
    """
    x, k, n = _validate_counts(im_levels, n_exceed, n_total)
    used = n > 0
    x, k, n = x[used], k[used], n[used]
    if x.size == 0:
        raise FragilityFitError("no records at any IM level (all n_total are 0)")
    u = np.log(x)
    # Centre the regressor for conditioning: p = Phi(c0 + b1 (u - u_bar)).
    u_bar = float(np.average(u, weights=n))
    v = u - u_bar
    log_coef = float(np.sum(_binomial_log_coefficient(k, n)))

    def negloglik_parts(c0, b1):
        z = c0 + b1 * v
        log_p, log_q, mills_p, mills_q = _probit_terms(z)
        nll = -np.sum(k * log_p + (n - k) * log_q)
        dz = k * mills_p - (n - k) * mills_q  # d lnL / dz
        d2z = -k * mills_p * (z + mills_p) - (n - k) * mills_q * (mills_q - z)  # d2 lnL / dz2
        return nll, dz, d2z

    if fixed_beta is not None:
        beta = checks.real(fixed_beta, "fixed_beta", low=0.0, low_open=True)
        if not np.any(k > 0):
            raise FragilityFitError(
                "no exceedances at any IM level: the median is only bounded below by the "
                f"highest level ({x.max():g})"
            )
        if not np.any(k < n):
            raise FragilityFitError(
                "every record exceeds at every IM level: the median is only bounded above by "
                f"the lowest level ({x.min():g})"
            )
        b1 = 1.0 / beta

        def parts(c):
            nll, dz, d2z = negloglik_parts(c[0], b1)
            return nll, -np.array([np.sum(dz)]), -np.array([[np.sum(d2z)]])

        (c0,), nll, n_iter = _newton_minimize(parts, np.array([0.0]), scale=float(n.sum()))
        c0 = float(c0)
        method = "mle_fixed_beta"
    else:
        _check_overlap(x, k, n)

        def parts(c):
            nll, dz, d2z = negloglik_parts(c[0], c[1])
            grad = -np.array([np.sum(dz), np.sum(dz * v)])
            hess = -np.array(
                [[np.sum(d2z), np.sum(d2z * v)], [np.sum(d2z * v), np.sum(d2z * v * v)]]
            )
            return nll, grad, hess

        # Start from a line through the empirical probits (continuity-corrected fractions, so
        # never 0 or 1); any start works because the problem is concave.
        p_hat = (k + 0.5) / (n + 1.0)
        slope0 = np.polyfit(v, special.ndtri(p_hat), 1, w=np.sqrt(n))[0]
        x0 = np.array([float(np.average(special.ndtri(p_hat), weights=n)), max(slope0, 0.1)])
        (c0, b1), nll, n_iter = _newton_minimize(parts, x0, scale=float(n.sum()))
        c0, b1 = float(c0), float(b1)
        if b1 <= _MIN_SLOPE_RANGE / np.ptp(u):
            raise FragilityFitError(
                f"the fitted probability of exceedance does not increase with IM (b1 = {b1:g}); "
                "check the limit state definition and the IM levels"
            )
        beta = 1.0 / b1
        if beta < _MIN_BETA:
            raise FragilityFitError(
                f"fitted beta = {beta:g} ~ 0: the stripes are (nearly) separated and the median "
                "is not identified; add IM levels in between or fix beta"
            )
        method = "mle"
    b0 = c0 - b1 * u_bar
    with np.errstate(over="ignore"):
        median = float(np.exp(-b0 / b1))
    if not 0 < median < np.inf:
        raise FragilityFitError(
            f"the fitted median ln(theta) = {-b0 / b1:g} is outside the floating-point range"
        )
    return FragilityFit(
        median=median,
        beta=beta,
        method=method,
        log_likelihood=float(-nll + log_coef),
        n=int(n.sum()),
        details={"b0": b0, "b1": b1, "n_iterations": n_iter},
    )


def _newton_minimize(parts, x0, *, scale, max_iter=100):
    """Damped Newton minimisation of a convex function.

    ``parts(x)`` returns ``(f, gradient, hessian)``. Steps are halved until ``f`` decreases;
    iteration stops when the Newton decrement ``g' H^-1 g`` falls below
    ``_NEWTON_TOL_PER_OBS * scale``
    (``scale`` ~ number of observations, ``f`` is of that order), after one last full step.

    Returns
    -------
    x, f, n_iter
        Minimiser, minimum and number of iterations.

    Raises
    ------
    FragilityFitError
        If the Hessian is singular or the iteration does not converge (which for the probit
        likelihood means the maximum is at infinity: separated data).
    """
    x = np.asarray(x0, dtype=float)
    f, g, h = parts(x)
    for it in range(1, max_iter + 1):
        try:
            step = np.linalg.solve(h, g)
        except np.linalg.LinAlgError:
            raise FragilityFitError(
                "singular information matrix: parameters not identified"
            ) from None
        decrement = float(g @ step)
        if not np.isfinite(decrement):
            break
        if decrement < _NEWTON_TOL_PER_OBS * scale:
            x_new = x - step  # final, quadratically convergent step (kept if not worse)
            f_new = parts(x_new)[0]
            return (x_new, f_new, it) if f_new <= f else (x, f, it)
        t = 1.0
        while t > _MIN_STEP_FRACTION:
            x_new = x - t * step
            f_new, g_new, h_new = parts(x_new)
            if np.isfinite(f_new) and f_new <= f:
                break
            t *= 0.5
        else:
            # No decrease possible along the Newton step: at the minimum within round-off.
            return x, f, it
        x, f, g, h = x_new, f_new, g_new, h_new
    raise FragilityFitError(
        f"the likelihood maximisation did not converge in {max_iter} Newton steps; the data "
        "may be (nearly) separated"
    )


def _validate_counts(im_levels, n_exceed, n_total):
    x = _reals(im_levels, "im_levels")
    k = _reals(n_exceed, "n_exceed")
    n = _reals(n_total, "n_total")
    if x.ndim != 1 or k.shape != x.shape or n.shape != x.shape:
        raise ParameterError(
            "im_levels, n_exceed and n_total must be 1-D arrays of the same length, got shapes "
            f"{x.shape}, {k.shape}, {n.shape}"
        )
    if not np.all(np.isfinite(x) & (x > 0)):
        raise ParameterError("im_levels must be finite and positive [IM units]")
    for name, arr in (("n_exceed", k), ("n_total", n)):
        if not np.all(np.isfinite(arr)) or np.any(arr < 0) or np.any(arr != np.round(arr)):
            raise ParameterError(f"{name} must hold non-negative integers")
    k = k.astype(float)
    n = n.astype(float)
    if np.any(k > n):
        raise ParameterError("n_exceed cannot exceed n_total at any IM level")
    return x, k, n


def fit_msa(exceeded, im_levels, valid=None, *, fixed_beta=None) -> FragilityFit:
    """MSA fragility from a record x IM-level exceedance matrix, via :func:`fit_mle`.

    Parameters
    ----------
    exceeded : array_like of bool, shape (n_records, m)
        Whether record ``i`` exceeded the limit state at IM level ``j``.
    im_levels : array_like, shape (m,)
        IM of each stripe [IM units].
    valid : array_like of bool, shape (n_records, m), optional
        Which runs are usable (e.g. the ``valid`` mask of
        :func:`shipblock.fragility.limit_states.exceedance`); invalid runs are not counted.
        Default: all valid.
    fixed_beta : float, optional
        Passed to :func:`fit_mle`.

    Returns
    -------
    FragilityFit
        As from :func:`fit_mle` on the per-level counts.

    Notes
    -----
    The record axis comes first so that :func:`bootstrap` can resample records (rows).
    """
    e = _reals(exceeded, "exceeded", "biuf").astype(bool)
    x = _reals(im_levels, "im_levels")
    if e.ndim != 2 or e.shape[1] != x.size:
        raise ParameterError(
            f"exceeded must have shape (n_records, {x.size}) to match im_levels, got {e.shape}"
        )
    w = np.ones_like(e) if valid is None else _reals(valid, "valid", "biuf").astype(bool)
    if w.shape != e.shape:
        raise ParameterError(f"valid must have the shape of exceeded {e.shape}, got {w.shape}")
    return fit_mle(x, np.sum(e & w, axis=0), np.sum(w, axis=0), fixed_beta=fixed_beta)


# ---------------------------------------------------------------------------------------------
# Incremental dynamic analysis
# ---------------------------------------------------------------------------------------------


class IDACapacities(NamedTuple):
    """Per-record IM capacity bounds extracted from an IDA exceedance matrix.

    The capacity :math:`C_i` of record ``i`` lies in ``(held[i], capacity[i]]``.

    Attributes
    ----------
    capacity : numpy.ndarray, shape (n_records,)
        IM at the first exceedance [IM units], the upper bound of the capacity; ``inf`` if the
        record never exceeded.
    censored_at : numpy.ndarray, shape (n_records,)
        Highest valid IM analysed for the record [IM units]: the right-censoring level of
        records that never exceeded (``nan`` if the record has no valid run at all; drop such
        records before fitting).
    resurrected : numpy.ndarray of bool, shape (n_records,)
        Records that stopped exceeding at some valid level above their first exceedance
        (non-monotone IDA, "resurrection").
    held : numpy.ndarray, shape (n_records,)
        The last valid level below the first exceedance at which the record held [IM units],
        the lower bound of the capacity: 0 if the record exceeded at its first valid level
        (left-censored), ``censored_at`` if it never exceeded (right-censored).
    """

    capacity: np.ndarray
    censored_at: np.ndarray
    resurrected: np.ndarray
    held: np.ndarray


def ida_capacities(exceeded, im_levels, valid=None) -> IDACapacities:
    """Per-record IM capacity bounds from an IDA exceedance matrix.

    Parameters
    ----------
    exceeded : array_like of bool, shape (n_records, m)
        Whether record ``i`` scaled to IM level ``j`` exceeded the limit state.
    im_levels : array_like, shape (m,)
        IM levels [IM units], positive and strictly increasing.
    valid : array_like of bool, shape (n_records, m), optional
        Usable runs; invalid (errored) runs are skipped as if that level had not been analysed.

    Returns
    -------
    IDACapacities
        ``capacity`` (first exceeding level), ``held`` (last level that held below it),
        ``censored_at`` and ``resurrected`` per record.

    Notes
    -----
    The record is taken to fail at the *first* IM level at which it exceeds the limit state.
    Non-monotone IDA curves, where a record exceeds at one level and not at a higher one
    ("resurrection", Vamvatsikos & Cornell 2002 [1]_), are treated conservatively: the record is
    considered failed from its first exceedance on, and later non-exceedances are ignored. They
    are flagged in ``resurrected`` so that they can be reported.

    With discrete IM levels the true capacity lies between the last level that held and the
    first exceeding one, ``(held, capacity]``: taking the upper bound as the capacity biases
    the median upward by up to one level step; :func:`fit_ida_intervals` uses the interval.

    References
    ----------
    .. [1] Vamvatsikos, D., & Cornell, C. A. (2002). Incremental dynamic analysis. *Earthquake
       Engineering & Structural Dynamics*, 31(3), 491-514.
    """
    e = _reals(exceeded, "exceeded", "biuf").astype(bool)
    x = _reals(im_levels, "im_levels")
    if e.ndim != 2 or e.shape[1] != x.size:
        raise ParameterError(
            f"exceeded must have shape (n_records, {x.size}) to match im_levels, got {e.shape}"
        )
    if not (np.all(np.isfinite(x) & (x > 0)) and np.all(np.diff(x) > 0)):
        raise ParameterError("im_levels must be finite, positive and strictly increasing "
                             "[IM units]")
    w = np.ones_like(e) if valid is None else _reals(valid, "valid", "biuf").astype(bool)
    if w.shape != e.shape:
        raise ParameterError(f"valid must have the shape of exceeded {e.shape}, got {w.shape}")
    hit = e & w
    ever = hit.any(axis=1)
    first = np.argmax(hit, axis=1)
    capacity = np.where(ever, x[first], np.inf)
    any_valid = w.any(axis=1)
    last_valid = w.shape[1] - 1 - np.argmax(w[:, ::-1], axis=1)
    censored_at = np.where(any_valid, x[last_valid], np.nan)
    after_first = np.arange(x.size)[None, :] > first[:, None]
    resurrected = ever & np.any(after_first & w & ~e, axis=1)
    # last valid level that held below the first exceedance (all valid levels if none)
    below = np.where(ever[:, None], np.arange(x.size)[None, :] < first[:, None], True)
    held_mask = below & w & ~e
    any_held = held_mask.any(axis=1)
    last_held = held_mask.shape[1] - 1 - np.argmax(held_mask[:, ::-1], axis=1)
    held = np.where(any_held, x[last_held], 0.0)
    held = np.where(any_valid, held, np.nan)
    return IDACapacities(capacity=capacity, censored_at=censored_at, resurrected=resurrected,
                         held=held)


def fit_ida(capacities, censored_at=None, *, method="mle") -> FragilityFit:
    r"""Lognormal fragility from per-record IM capacities (IDA).

    Parameters
    ----------
    capacities : array_like, shape (n,)
        IM at which each record first exceeds the limit state [IM units]. Records that did not
        exceed up to the highest analysed level are given as ``inf`` (or any value above their
        ``censored_at``).
    censored_at : float or array_like, shape (n,), optional
        Highest IM analysed, per record or common [IM units]. Record ``i`` is right-censored
        when ``capacities[i]`` is not finite or is greater than ``censored_at[i]``: all that is
        known is :math:`C_i > c_i^{\max}`. Required when any capacity is not finite.
    method : {"mle", "moments"}
        ``"mle"`` (default): censored maximum likelihood,

        .. math::

            \ln L = \sum_{i\ \mathrm{exceeded}} \ln\left[\frac{1}{\beta}
                \phi\!\left(\frac{\ln c_i - \ln\theta}{\beta}\right)\right]
              + \sum_{i\ \mathrm{censored}} \ln\left[1 - \Phi\!\left(
                \frac{\ln c_i^{\max} - \ln\theta}{\beta}\right)\right],

        written in :math:`\ln` IM (the Jacobian :math:`1/c_i` is left out, so ``log_likelihood``
        does not depend on the IM unit). Without censoring it reduces to the sample mean and
        the (``ddof=0``) standard deviation of :math:`\ln c_i`.

        ``"moments"``: Baker (2015) [1]_ eqs. (2)-(3),

        .. math::

            \ln\hat\theta = \frac{1}{n}\sum_i \ln c_i, \qquad
            \hat\beta = \sqrt{\frac{1}{n-1}\sum_i \left(\ln\frac{c_i}{\hat\theta}\right)^2}.

        Censored records are then replaced by their censoring level, which biases
        :math:`\theta` and :math:`\beta` low; a :class:`RuntimeWarning` says so.

    Returns
    -------
    FragilityFit
        ``method="ida_mle"`` or ``"ida_moments"``; ``n`` the number of records; ``details``
        holds ``n_censored``.

    Raises
    ------
    FragilityFitError
        If fewer than two records exceeded at distinct IMs (for ``"mle"`` with censoring), or
        fewer than two records in total (``"moments"``): the dispersion is not identified.
    ValueError
        On malformed input (non-positive capacities, a non-finite capacity without
        ``censored_at``, unknown method).

    References
    ----------
    .. [1] Baker, J. W. (2015). Efficient analytical fragility function fitting using dynamic
       structural analysis. *Earthquake Spectra*, 31(1), 579-599.
    """
    c = _reals(capacities, "capacities")
    method = _method(method, "method", ("mle", "moments"))
    if c.ndim != 1:
        raise ParameterError(f"capacities must be 1-D, got shape {c.shape}")
    if np.any(np.isnan(c)):
        raise ParameterError(
            "capacities contain NaN; drop missing records, or give inf for records that never "
            "exceeded"
        )
    if np.any(c <= 0):
        raise ParameterError("capacities must be positive [IM units]")
    if censored_at is None:
        if not np.all(np.isfinite(c)):
            raise ParameterError("capacities that never exceeded (inf) need censored_at")
        cmax = np.full_like(c, np.inf)
    else:
        try:
            cmax = np.broadcast_to(_reals(censored_at, "censored_at"), c.shape)
        except ValueError:
            raise ParameterError(f"censored_at must be a number or one per capacity "
                                 f"({c.size})") from None
    censored = ~np.isfinite(c) | (c > cmax)
    if np.any(censored & ~(np.isfinite(cmax) & (cmax > 0))):
        raise ParameterError("censored records need a finite positive censored_at [IM units]")
    n_censored = int(censored.sum())
    if method == "moments":
        return _fit_ida_moments(np.where(censored, cmax, c), n_censored)
    if method != "mle":
        raise ParameterError(f"method must be 'mle' or 'moments', got {method!r}")

    y = np.log(c[~censored])
    y_cens = np.log(cmax[censored])
    if np.unique(y).size < 2:
        raise FragilityFitError(
            f"only {np.unique(y).size} distinct exceedance capacities among {c.size} records "
            f"({n_censored} censored): the dispersion beta is not identified"
        )
    mu0, sigma0 = float(np.mean(y)), float(np.std(y))
    if n_censored == 0:
        mu, sigma = mu0, sigma0
        nll = -np.sum(_norm_logpdf((y - mu) / sigma) - np.log(sigma))
        n_iter = 0
    else:

        def fun(p):
            mu, log_s = p
            s = np.exp(log_s)
            r = (y - mu) / s
            rc = (y_cens - mu) / s
            log_sf = special.log_ndtr(-rc)
            mills = np.exp(_norm_logpdf(rc) - log_sf)  # hazard of the censored terms
            nll = -np.sum(_norm_logpdf(r) - log_s) - np.sum(log_sf)
            g_mu = -np.sum(r) / s - np.sum(mills) / s
            g_ls = -np.sum(r**2 - 1.0) - np.sum(mills * rc)
            return nll, np.array([g_mu, g_ls])

        res = optimize.minimize(
            fun,
            x0=np.array([mu0, np.log(sigma0)]),
            jac=True,
            method="BFGS",
            options={"gtol": _GTOL_PER_OBS * c.size},
        )
        if not res.success and np.linalg.norm(res.jac) > 1e3 * _GTOL_PER_OBS * c.size:
            warnings.warn(
                f"censored IDA MLE did not converge: {res.message}", RuntimeWarning, stacklevel=2
            )
        mu, sigma = float(res.x[0]), float(np.exp(res.x[1]))
        nll = float(res.fun)
        n_iter = int(res.nit)
        if sigma < _MIN_BETA:
            raise FragilityFitError(f"fitted beta = {sigma:g} ~ 0: dispersion not identified")
    return FragilityFit(
        median=float(np.exp(mu)),
        beta=sigma,
        method="ida_mle",
        log_likelihood=float(-nll),
        n=int(c.size),
        details={"n_censored": n_censored, "n_iterations": n_iter},
    )


def _fit_ida_moments(c, n_censored):
    if c.size < 2:
        raise FragilityFitError("the method of moments needs at least two records")
    if n_censored:
        warnings.warn(
            f"{n_censored} of {c.size} records are censored; the method of moments uses their "
            "censoring level as capacity, which biases median and beta low (use method='mle')",
            RuntimeWarning,
            stacklevel=3,
        )
    y = np.log(c)
    return FragilityFit(
        median=float(np.exp(np.mean(y))),
        beta=float(np.std(y, ddof=1)),
        method="ida_moments",
        log_likelihood=float("nan"),
        n=int(c.size),
        details={"n_censored": n_censored},
    )


#: Methods of :func:`fit_ida_levels` (and of the pipeline's ``fit.ida_method``).
IDA_METHODS = ("interval", "first_exceedance", "first_exceedance_moments")

#: Largest dispersion accepted from the interval-censored fit [-]: beyond it the data do not
#: bound beta (e.g. only left- and right-censored records) and the fit runs off to infinity.
_MAX_BETA = 50.0


def _log_interval_probability(a, b):
    """``ln(Phi(b) - Phi(a))`` for ``a < b`` (either may be infinite), without cancellation.

    Both bounds on the same side of zero are taken on that side's tail, where the difference of
    two small probabilities keeps its relative precision.
    """
    log_pb, log_pa = special.log_ndtr(b), special.log_ndtr(a)
    log_qa, log_qb = special.log_ndtr(-a), special.log_ndtr(-b)
    with np.errstate(divide="ignore", invalid="ignore"):
        lower_tail = log_pb + np.log1p(-np.exp(log_pa - log_pb))  # both below zero
        upper_tail = log_qa + np.log1p(-np.exp(log_qb - log_qa))  # both above zero
        middle = np.log(special.ndtr(b) - special.ndtr(a))
    return np.where(b <= 0.0, lower_tail, np.where(a >= 0.0, upper_tail, middle))


def fit_ida_intervals(lower, upper) -> FragilityFit:
    r"""Lognormal fragility from interval-censored IDA capacities.

    Record ``i``'s capacity :math:`C_i` is known only to lie in ``(lower[i], upper[i]]``: on
    discrete IM levels, between the last level at which the record held and the first at which
    it exceeded the limit state. ``lower = 0`` is a record that exceeded at its first level
    (left-censored), ``upper = inf`` one that never exceeded (right-censored). The
    log-likelihood, maximised over :math:`(\ln\theta, \ln\beta)` with its analytic gradient,
    is

    .. math::

        \ln L = \sum_i \ln\left[\Phi\!\left(\frac{\ln u_i - \ln\theta}{\beta}\right)
               - \Phi\!\left(\frac{\ln l_i - \ln\theta}{\beta}\right)\right],

    with :math:`\Phi(-\infty) = 0` and :math:`\Phi(\infty) = 1` (Lawless 2003 [1]_, sect.
    2.2.1; the record-wise form of the IDA likelihood with the capacity between two stripes).
    Unlike the first exceeding level, which is always above the capacity, this is unbiased on
    coarse levels (tests/test_fragility_fit.py: mean of the medians within 2 % of the truth on
    the demo's eight levels, where the first-exceedance estimate is 10-20 % high).

    Parameters
    ----------
    lower : array_like, shape (n,)
        Lower bounds [IM units], >= 0 (0: left-censored).
    upper : array_like, shape (n,)
        Upper bounds [IM units], > ``lower`` (``inf``: right-censored).

    Returns
    -------
    FragilityFit
        ``method="ida_interval"``, ``n`` the number of records, ``log_likelihood`` the value
        above (probabilities, so it does not depend on the IM unit); ``details`` holds
        ``n_left_censored``, ``n_right_censored`` and ``n_iterations``.

    Raises
    ------
    FragilityFitError
        If the data do not identify a finite (median, beta): no record exceeded (median only
        bounded below), every record exceeded at its first level (only bounded above), every
        interval shares a point (:math:`\beta \to 0`: add levels in between), or the fit runs
        off to :math:`\beta >` 50 (the censored records alone do not bound it).
    ValueError
        On malformed input (shapes, NaN, ``lower < 0``, ``upper <= lower``).

    References
    ----------
    .. [1] Lawless, J. F. (2003). *Statistical Models and Methods for Lifetime Data*, 2nd ed.
       Wiley, sect. 2.2 (censoring) and 5.3 (interval censoring).
    """
    lo = np.asarray(lower, dtype=float)
    hi = np.asarray(upper, dtype=float)
    if lo.ndim != 1 or hi.shape != lo.shape:
        raise ParameterError(
            f"lower and upper must be 1-D of equal length, got shapes {lo.shape} and {hi.shape}"
        )
    if np.any(np.isnan(lo)) or np.any(np.isnan(hi)):
        raise ParameterError("capacity bounds contain NaN: drop records without a valid run")
    if np.any(lo < 0) or not np.all(np.isfinite(lo)):
        raise ParameterError("lower bounds must be finite and >= 0 [IM units]")
    if np.any(hi <= lo):
        raise ParameterError("every upper bound must exceed its lower bound [IM units]")
    left = lo == 0.0
    right = ~np.isfinite(hi)
    if np.all(right):
        raise FragilityFitError(
            "no record exceeded the limit state: the median is only bounded below by the "
            f"highest level ({lo.max():g}); analyse higher IM levels"
        )
    if np.all(left):
        raise FragilityFitError(
            "every record exceeded at its first level: the median is only bounded above by "
            f"the lowest level ({hi.min():g}); analyse lower IM levels"
        )
    if lo.max() <= hi.min():
        raise FragilityFitError(
            f"every record's capacity interval contains IM {hi.min():g} (all held at "
            f"{lo.max():g} or below and exceeded at {hi.min():g} or above): beta -> 0 and the "
            "median is not identified; add IM levels in between"
        )
    with np.errstate(divide="ignore"):
        u_lo = np.log(lo)  # -inf for left-censored records
    u_hi = np.log(hi)  # inf for right-censored records
    # start: moments of the interval mid-points (one level step beyond a censoring level)
    step = float(np.median(u_hi[~right & ~left] - u_lo[~right & ~left])) if np.any(
        ~right & ~left) else 0.5
    with np.errstate(invalid="ignore"):
        mid = np.where(left, u_hi - 0.5 * step,
                       np.where(right, u_lo + 0.5 * step, 0.5 * (u_lo + u_hi)))
    x0 = np.array([float(np.mean(mid)), np.log(max(float(np.std(mid)), 0.5 * step, 0.05))])

    def fun(p):
        mu, log_s = p
        s = np.exp(log_s)
        a = (u_lo - mu) / s
        b = (u_hi - mu) / s
        log_p = _log_interval_probability(a, b)
        # phi(bound)/P and bound*phi(bound)/P, 0 at an infinite bound
        with np.errstate(invalid="ignore"):
            ra = np.where(left, 0.0, np.exp(_norm_logpdf(a) - log_p))
            rb = np.where(right, 0.0, np.exp(_norm_logpdf(b) - log_p))
            ta = np.where(left, 0.0, a * ra)
            tb = np.where(right, 0.0, b * rb)
        nll = -float(np.sum(log_p))
        g_mu = float(np.sum(rb - ra)) / s
        g_ls = float(np.sum(tb - ta))
        return nll, np.array([g_mu, g_ls])

    res = optimize.minimize(fun, x0=x0, jac=True, method="BFGS",
                            options={"gtol": _GTOL_PER_OBS * lo.size})
    mu, sigma = float(res.x[0]), float(np.exp(res.x[1]))
    if not np.isfinite(res.fun):
        raise FragilityFitError("the interval-censored likelihood could not be evaluated")
    if sigma > _MAX_BETA:
        raise FragilityFitError(
            f"fitted beta = {sigma:g}: the records' capacity bounds do not bound the dispersion "
            "(too few records with a capacity between two analysed levels)"
        )
    if sigma < _MIN_BETA:
        raise FragilityFitError(f"fitted beta = {sigma:g} ~ 0: dispersion not identified")
    if not res.success and np.linalg.norm(res.jac) > 1e3 * _GTOL_PER_OBS * lo.size:
        warnings.warn(
            f"interval-censored IDA fit did not converge: {res.message}", RuntimeWarning,
            stacklevel=2,
        )
    return FragilityFit(
        median=float(np.exp(mu)),
        beta=sigma,
        method="ida_interval",
        log_likelihood=float(-res.fun),
        n=int(lo.size),
        details={"n_left_censored": int(left.sum()), "n_right_censored": int(right.sum()),
                 "n_iterations": int(res.nit)},
    )


def fit_ida_levels(exceeded, im_levels, valid=None, *, method="interval") -> FragilityFit:
    """IDA fragility from a record x IM-level exceedance matrix.

    Parameters
    ----------
    exceeded : array_like of bool, shape (n_records, m)
        Whether record ``i`` scaled to IM level ``j`` exceeded the limit state.
    im_levels : array_like, shape (m,)
        IM levels [IM units], positive and strictly increasing.
    valid : array_like of bool, shape (n_records, m), optional
        Usable runs (default all). Records without any valid run are left out.
    method : {"interval", "first_exceedance", "first_exceedance_moments"}
        ``"interval"`` (default): each record's capacity lies between the last level that held
        and the first that failed (:func:`ida_capacities`), fitted by
        :func:`fit_ida_intervals`: unbiased on discrete levels.
        ``"first_exceedance"``: the first exceeding level taken as the capacity, fitted by
        right-censored maximum likelihood (:func:`fit_ida`, ``method="mle"``);
        ``"first_exceedance_moments"``: the same capacities by the method of moments
        (``method="moments"``). Both overestimate the median by up to one level step (about
        half a step on average); they are kept to reproduce earlier studies.

    Returns
    -------
    FragilityFit
        ``method`` ``"ida_interval"``, ``"ida_first_exceedance"`` or
        ``"ida_first_exceedance_moments"``.

    Raises
    ------
    FragilityFitError
        If the curve is not identified (see the fitting functions).
    ValueError
        On malformed input or an unknown method.

    Notes
    -----
    The record axis comes first so that :func:`bootstrap` can resample records (rows).
    """
    if method not in IDA_METHODS:
        raise ParameterError(f"method must be one of {', '.join(IDA_METHODS)}, got {method!r}")
    e = np.asarray(exceeded, dtype=bool)
    w = np.ones_like(e) if valid is None else np.asarray(valid, dtype=bool)
    if e.ndim != 2 or w.shape != e.shape:
        raise ParameterError(
            f"exceeded and valid must be 2-D (n_records, n_levels) of one shape, got {e.shape} "
            f"and {w.shape}"
        )
    keep = w.any(axis=1)
    caps = ida_capacities(e[keep], im_levels, w[keep])
    if method == "interval":
        return fit_ida_intervals(caps.held, caps.capacity)
    fit = fit_ida(caps.capacity, caps.censored_at,
                  method="mle" if method == "first_exceedance" else "moments")
    return replace(fit, method=f"ida_{method}")


# ---------------------------------------------------------------------------------------------
# Cloud analysis
# ---------------------------------------------------------------------------------------------


def fit_cloud(im, edp, capacity, *, method="regression", capacity_beta=0.0) -> FragilityFit:
    r"""Fragility from a cloud of unscaled records: (IM, EDP) pairs and an EDP capacity.

    Parameters
    ----------
    im : array_like, shape (n,)
        IM of each record [IM units], positive.
    edp : array_like, shape (n,)
        Engineering demand parameter of each record [EDP units]. For ``"regression"`` it must
        be finite and positive; for ``"probit"`` it is compared with ``capacity`` (``inf`` for a
        collapsed run is allowed and counts as exceeding).
    capacity : float
        Median EDP capacity :math:`C` [EDP units] defining the limit state ``edp > capacity``.
    method : {"regression", "probit"}
        ``"regression"`` (default): least squares on
        :math:`\ln \mathrm{EDP} = a + b \ln \mathrm{IM} + \varepsilon`, with
        :math:`\sigma = \sqrt{\sum \varepsilon_i^2 / (n-2)}` (Cornell et al. 2002 [1]_,
        Jalayer 2003 [2]_). Then

        .. math::

            \theta = \exp\!\left(\frac{\ln C - a}{b}\right), \qquad
            \beta = \frac{\sqrt{\sigma^2 + \beta_C^2}}{b}.

        ``log_likelihood`` is the Gaussian log-likelihood of the residuals of
        :math:`\ln \mathrm{EDP}` at the maximum-likelihood :math:`\sigma`.

        ``"probit"``: the binary outcome ``edp > capacity`` of each record is fitted by
        :func:`fit_mle` with one trial per record (a probit GLM on :math:`\ln \mathrm{IM}`);
        ``capacity_beta`` must then be 0.
    capacity_beta : float
        Dispersion :math:`\beta_C` of the capacity [-] (regression only), combined with the
        demand dispersion by square root of the sum of squares. Default 0 (deterministic
        capacity).

    Returns
    -------
    FragilityFit
        ``method="cloud_regression"`` with ``details`` ``a``, ``b`` and ``sigma``; or
        ``method="cloud_probit"`` with the details of :func:`fit_mle`.

    Raises
    ------
    FragilityFitError
        If the fitted slope :math:`b \le 0` (demand not increasing with IM), or if the probit
        cannot be identified (see :func:`fit_mle`).
    ValueError
        On malformed input.

    Notes
    -----
    The regression assumes a power-law median demand with constant lognormal dispersion over the
    range of the cloud; collapsed runs (no finite EDP) must not be in the regression. Treat them
    separately (e.g. Jalayer et al. 2017 [3]_) or use ``method="probit"``.

    References
    ----------
    .. [1] Cornell, C. A., Jalayer, F., Hamburger, R. O., & Foutch, D. A. (2002). Probabilistic
       basis for 2000 SAC Federal Emergency Management Agency steel moment frame guidelines.
       *Journal of Structural Engineering*, 128(4), 526-533.
    .. [2] Jalayer, F. (2003). *Direct probabilistic seismic analysis: implementing non-linear
       dynamic assessments*. PhD thesis, Stanford University.
    .. [3] Jalayer, F., Ebrahimian, H., Miano, A., Manfredi, G., & Sezen, H. (2017). Analytical
       fragility assessment using unscaled ground motion records. *Earthquake Engineering &
       Structural Dynamics*, 46(15), 2639-2663.
    """
    x = _reals(im, "im")
    d = _reals(edp, "edp")
    method = _method(method, "method", ("regression", "probit"))
    capacity_beta = checks.real(capacity_beta, "capacity_beta", low=0.0)
    if x.ndim != 1 or d.shape != x.shape:
        raise ParameterError(f"im and edp must be 1-D of equal length, got {x.shape} and {d.shape}")
    if not np.all(np.isfinite(x) & (x > 0)):
        raise ParameterError("im must be finite and positive [IM units]")
    capacity = checks.real(capacity, "capacity", low=0.0, low_open=True)
    if method == "probit":
        if capacity_beta:
            raise ParameterError("capacity_beta is only used with method='regression'")
        if np.any(np.isnan(d)):
            raise ParameterError("edp contains NaN: drop errored runs before fitting")
        fit = fit_mle(x, (d > capacity).astype(int), np.ones(x.size, dtype=int))
        return replace(fit, method="cloud_probit")
    if method != "regression":
        raise ParameterError(f"method must be 'regression' or 'probit', got {method!r}")
    if not np.all(np.isfinite(d) & (d > 0)):
        raise ParameterError(
            "edp must be finite and positive for the cloud regression; remove collapsed or "
            "errored runs (or use method='probit')"
        )
    if x.size < 3:
        raise FragilityFitError("the cloud regression needs at least 3 records")
    u, y = np.log(x), np.log(d)
    res = stats.linregress(u, y)
    a, b = float(res.intercept), float(res.slope)
    resid = y - (a + b * u)
    ssr = float(np.sum(resid**2))
    sigma = np.sqrt(ssr / (x.size - 2))
    if b <= 0:
        raise FragilityFitError(
            f"the cloud regression slope b = {b:g} is not positive: demand does not increase "
            "with IM, so no fragility in this IM follows"
        )
    sigma_mle = np.sqrt(ssr / x.size)
    log_lik = float(np.sum(stats.norm.logpdf(resid, scale=sigma_mle))) if ssr > 0 else np.inf
    return FragilityFit(
        median=float(np.exp((np.log(capacity) - a) / b)),
        beta=float(np.hypot(sigma, capacity_beta) / b),
        method="cloud_regression",
        log_likelihood=log_lik,
        n=int(x.size),
        details={"a": a, "b": b, "sigma": float(sigma)},
    )


# ---------------------------------------------------------------------------------------------
# Bootstrap over records
# ---------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class BootstrapResult:
    """Percentile bootstrap of a fragility fit over records.

    Attributes
    ----------
    fit : FragilityFit
        Fit to the original data, with ``median_ci``, ``beta_ci`` and ``ci_level`` filled in.
    im : numpy.ndarray, shape (k,)
        IM grid of the curve band [IM units].
    lower, upper : numpy.ndarray, shape (k,)
        Pointwise percentile band of the probability of exceedance at ``im`` [-].
    medians, betas : numpy.ndarray, shape (n_ok,)
        Medians [IM units] and dispersions [-] of the successful bootstrap refits.
    n_failed : int
        Number of resamples whose refit raised :class:`FragilityFitError` (e.g. a resample with no
        exceedance); they are left out of the percentiles, which therefore condition on
        identifiable resamples.
    """

    fit: FragilityFit
    im: np.ndarray
    lower: np.ndarray
    upper: np.ndarray
    medians: np.ndarray
    betas: np.ndarray
    n_failed: int


def bootstrap(
    fit_function: Callable[..., FragilityFit],
    records: Mapping[str, Any],
    *,
    im=None,
    n_boot: int = 1000,
    confidence: float = 0.9,
    seed: int | np.random.Generator | np.random.SeedSequence | None = None,
    workers=None,
    **fit_kwargs,
) -> BootstrapResult:
    """Bootstrap confidence bands of a fragility fit by resampling records with replacement.

    Each replicate draws ``n_records`` record indices with replacement, takes those rows
    (axis 0) of every array in ``records``, and refits with
    ``fit_function(**resampled_records, **fit_kwargs)``. Replicate ``k`` draws from its own
    generator, seeded with the ``k``-th child of the seed's :class:`numpy.random.SeedSequence`
    (``SeedSequence.spawn``), so the replicates can be spread over processes or a Dask cluster
    (``workers``) in any blocks with the same result. The band is the pointwise
    ``(1 - confidence)/2`` and ``(1 + confidence)/2`` percentiles of the refitted curves;
    ``median_ci`` and ``beta_ci`` are the same percentiles of the refitted parameters (Efron &
    Tibshirani 1993 [1]_, percentile method).

    Parameters
    ----------
    fit_function : callable
        One of :func:`fit_msa`, :func:`fit_ida`, :func:`fit_cloud` (or any function returning a
        :class:`FragilityFit`).
    records : Mapping[str, array_like]
        Per-record data, resampled jointly along axis 0, passed by keyword. For example
        ``{"exceeded": E, "valid": V}`` for :func:`fit_msa`, ``{"capacities": c}`` (and
        per-record ``censored_at``) for :func:`fit_ida`, ``{"im": im, "edp": edp}`` for
        :func:`fit_cloud`.
    im : array_like, optional
        IM grid for the band [IM units]. Default: 100 points log-spaced over
        ``[median / exp(3 beta), median * exp(3 beta)]`` of the original fit.
    n_boot : int
        Number of bootstrap replicates [-].
    confidence : float
        Confidence level of the bands, in (0, 1) [-].
    seed : int, numpy.random.Generator or numpy.random.SeedSequence, optional
        Seed of the resampling (a generator's own seed sequence is spawned from); no global
        random state is used.
    workers : shipblock.fragility.workers.Workers, optional
        Where the replicates run, in blocks: a Dask client, local processes, or here (default),
        depending on the time the others are estimated to take here, from the time of the first
        ``PROBE_REPLICATES`` (run here). ``fit_function`` and the arrays must then be picklable (the fits of
        this module are).
    **fit_kwargs
        Arguments that are not resampled (``im_levels=...``, ``capacity=...``, ...).

    Returns
    -------
    BootstrapResult

    Raises
    ------
    ValueError
        If the record arrays differ in length, or if fewer than half of the replicates could
        be refitted.

    References
    ----------
    .. [1] Efron, B., & Tibshirani, R. J. (1993). *An Introduction to the Bootstrap*. Chapman &
       Hall, ch. 13.
    """
    if not callable(fit_function):
        raise ParameterTypeError(f"fit_function must be a fitting function such as fit_ida, got "
                                 f"{type(fit_function).__name__}")
    if not isinstance(records, Mapping) or not records:
        raise ParameterTypeError("records must be a non-empty mapping of per-record arrays, "
                                 f"got {type(records).__name__}")
    checks.real(confidence, "confidence", low=0.0, high=1.0, low_open=True, high_open=True)
    n_boot = checks.whole(n_boot, "n_boot", low=1, high=1_000_000)
    if im is not None:
        im = _reals(im, "im")
    arrays = {name: np.asarray(value) for name, value in records.items()}
    lengths = {name: a.shape[0] if a.ndim else None for name, a in arrays.items()}
    n_rec = set(lengths.values())
    if len(n_rec) != 1 or None in n_rec:
        raise ParameterError(f"all record arrays need the same length along axis 0, got {lengths}")
    (n_rec,) = n_rec
    try:
        seeds = _replicate_seeds(seed, int(n_boot))
    except (TypeError, ValueError) as exc:
        raise ParameterTypeError(f"seed must be None, a non-negative integer (or sequence of "
                                 f"them) or a numpy Generator, got {seed!r} ({exc})") from None
    base = fit_function(**arrays, **fit_kwargs)
    grid = (
        base.median
        * np.exp(np.linspace(-_GRID_HALF_WIDTH, _GRID_HALF_WIDTH, _GRID_POINTS) * base.beta)
        if im is None
        else np.asarray(im, dtype=float)
    )
    if workers is None:
        parts = [_bootstrap_block(fit_function, arrays, fit_kwargs, seeds)]
    else:
        from shipblock.fragility.workers import PROBE_REPLICATES, blocks

        # the first replicates here, timed: the estimate of where the others should go
        t0 = time.perf_counter()
        parts = [_bootstrap_block(fit_function, arrays, fit_kwargs, seeds[:PROBE_REPLICATES])]
        rest = seeds[PROBE_REPLICATES:]
        if rest:
            estimate = (time.perf_counter() - t0) / PROBE_REPLICATES * len(rest)
            items = [(fit_function, arrays, fit_kwargs, rest[b.start:b.stop])
                     for b in blocks(len(rest), workers.slots())]
            parts += workers.map(_bootstrap_block, items, estimated_seconds=estimate)
    fitted = np.concatenate(parts, axis=1) if parts else np.zeros((2, 0))
    ok = np.isfinite(fitted[0])
    medians, betas = fitted[0, ok].tolist(), fitted[1, ok].tolist()
    n_failed = int(np.count_nonzero(~ok))
    if len(medians) < max(2, n_boot / 2):
        raise ParameterError(
            f"only {len(medians)} of {n_boot} bootstrap refits succeeded; the data are too "
            "sparse for a bootstrap"
        )
    if n_failed:
        warnings.warn(
            f"{n_failed} of {n_boot} bootstrap resamples could not be fitted and were dropped",
            RuntimeWarning,
            stacklevel=2,
        )
    medians, betas = np.asarray(medians), np.asarray(betas)
    q = 100 * np.array([(1 - confidence) / 2, (1 + confidence) / 2])
    curves = _lognormal(grid[None, :], medians[:, None], betas[:, None])
    lower, upper = np.percentile(curves, q, axis=0)
    fit = replace(
        base,
        median_ci=tuple(float(v) for v in np.percentile(medians, q)),
        beta_ci=tuple(float(v) for v in np.percentile(betas, q)),
        ci_level=float(confidence),
    )
    return BootstrapResult(
        fit=fit,
        im=grid,
        lower=lower,
        upper=upper,
        medians=medians,
        betas=betas,
        n_failed=n_failed,
    )


def _replicate_seeds(seed, n_boot: int) -> list:
    """One :class:`numpy.random.SeedSequence` per bootstrap replicate, spawned from ``seed``."""
    if isinstance(seed, np.random.Generator):
        sequence = seed.bit_generator.seed_seq
    elif isinstance(seed, np.random.SeedSequence):
        sequence = seed
    else:
        sequence = np.random.SeedSequence(seed)
    return sequence.spawn(n_boot)


def _bootstrap_block(fit_function, arrays, fit_kwargs, seeds) -> np.ndarray:
    """Medians and betas of the replicates with these seeds: shape (2, len(seeds)), NaN if unfittable.

    A pure function of its arguments (a task for local processes or Dask): replicate ``k``
    resamples the records with ``numpy.random.default_rng(seeds[k])``.
    """
    n_rec = next(iter(arrays.values())).shape[0]
    out = np.full((2, len(seeds)), np.nan)
    for k, child in enumerate(seeds):
        idx = np.random.default_rng(child).integers(0, n_rec, size=n_rec)
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore", RuntimeWarning)
                f = fit_function(**{name: a[idx] for name, a in arrays.items()}, **fit_kwargs)
        except FragilityFitError:
            continue
        out[0, k], out[1, k] = f.median, f.beta
    return out
