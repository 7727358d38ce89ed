r"""Cloud analysis of unscaled records.

:func:`fit_cloud` regresses :math:`\ln \mathrm{EDP}` on :math:`\ln \mathrm{IM}` (Cornell et
al. 2002, Jalayer 2003) or fits a probit to the binary outcome. References in
:mod:`shipblock.fragility.fit`.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
from scipy import stats

from shipblock import checks
from shipblock.errors import ParameterError
from shipblock.fragility.fit._core import FragilityFit, FragilityFitError, _method, _reals
from shipblock.fragility.fit.msa import fit_mle


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


