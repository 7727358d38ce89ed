"""Incremental dynamic analysis: each record's capacity and the fits to the capacities.

:func:`ida_capacities` turns a record x level exceedance matrix into capacity bounds (the last
level that held, the first that failed); :func:`fit_ida_levels` fits them, by default as
intervals (:func:`fit_ida_intervals`, interval-censored maximum likelihood), and
:func:`fit_ida` fits capacities known exactly (moments or right-censored maximum likelihood).
References in :mod:`shipblock.fragility.fit`.
"""

from __future__ import annotations

import warnings
from dataclasses import replace
from typing import NamedTuple

import numpy as np
from scipy import optimize, special

from shipblock.errors import ParameterError
from shipblock.fragility.fit._core import (
    _MIN_BETA,
    FragilityFit,
    FragilityFitError,
    _method,
    _reals,
)

#: Gradient tolerance per observation of the censored IDA likelihood maximisation [-].
_GTOL_PER_OBS = 1e-9

_LOG_SQRT_2PI = np.log(np.sqrt(2 * np.pi))


def _norm_logpdf(x):
    """Standard normal log density.

    The expression of ``scipy.stats.norm.logpdf(x)`` (the same result bit for bit) without its
    per-call overhead, which dominated the time of the censored IDA fits.
    """
    return -(x**2) / 2.0 - _LOG_SQRT_2PI



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


