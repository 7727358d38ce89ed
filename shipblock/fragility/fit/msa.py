r"""Multiple-stripe analysis: the binomial maximum-likelihood fit (Baker 2015).

At each IM level :math:`x_j` of :math:`n_j` runs, :math:`z_j` exceed the limit state;
:func:`fit_mle` maximises the binomial likelihood of the counts, :func:`fit_msa` does the same
from a record x level exceedance matrix. References in :mod:`shipblock.fragility.fit`.
"""

from __future__ import annotations

import numpy as np
from scipy import special, stats

from shipblock import checks
from shipblock.errors import ParameterError
from shipblock.fragility.fit._core import _MIN_BETA, FragilityFit, FragilityFitError, _reals

#: Newton decrement per observation below which the probit MLE has converged [-].
_NEWTON_TOL_PER_OBS = 1e-16

#: Smallest line-search step fraction before Newton gives up improving (round-off) [-].
_MIN_STEP_FRACTION = 1e-10

#: Smallest change of the probit index b1 * ln(x) over the range of the IM levels that counts as
#: an IM-dependent fit [-]; below it the fitted probability is flat (beta -> infinity).
_MIN_SLOPE_RANGE = 1e-6



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


