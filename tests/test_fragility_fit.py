"""Tests of shipblock.fragility.fit.

Reference values come from (a) synthetic data drawn from a planted lognormal fragility or a planted
log-linear demand model (tolerances several standard errors wide for the fixed seeds and sample
sizes used), (b) independent implementations: statsmodels' probit GLM (IRLS) for the binomial MLE,
a Nelder-Mead maximisation of a likelihood written with scipy.stats for the censored IDA MLE, and
the textbook moment formulas of Baker (2015) eqs. (2)-(3).
"""

from __future__ import annotations

import numpy as np
import pytest
import statsmodels.api as sm
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy import optimize, special, stats

from shipblock.fragility import (
    FragilityFit,
    FragilityFitError,
    bootstrap,
    fit_cloud,
    fit_ida,
    fit_ida_intervals,
    fit_ida_levels,
    fit_mle,
    fit_msa,
    ida_capacities,
    lognormal_fragility,
)

# Planted fragility: median 3.0 [m/s^2] (an Sa-like IM), dispersion 0.4 [-].
THETA = 3.0
BETA = 0.4
STRIPES = THETA * np.exp(BETA * np.linspace(-2.0, 2.0, 9))  # [m/s^2]


def probit_glm(x, k, n):
    """Probit GLM on ln(IM) with statsmodels (IRLS, independent of fit_mle)."""
    model = sm.GLM(
        np.column_stack([k, n - k]),
        sm.add_constant(np.log(x)),
        family=sm.families.Binomial(link=sm.families.links.Probit()),
    )
    return model.fit(tol=1e-13, maxiter=200)


def stripe_counts(seed, n_records=2000):
    """Capacities drawn from the planted lognormal; counts of capacity <= IM at each stripe."""
    rng = np.random.default_rng(seed)
    capacity = THETA * np.exp(BETA * rng.standard_normal(n_records))
    exceeded = capacity[:, None] <= STRIPES[None, :]
    return exceeded, exceeded.sum(axis=0), np.full(STRIPES.size, n_records)


# ---------------------------------------------------------------------------------------------
# lognormal_fragility and FragilityFit
# ---------------------------------------------------------------------------------------------


def test_lognormal_fragility_closed_form():
    """P(theta) = 1/2, P(theta e^beta) = Phi(1), P(0) = 0."""
    p = lognormal_fragility([0.0, THETA, THETA * np.exp(BETA)], THETA, BETA)
    np.testing.assert_allclose(p, [0.0, 0.5, special.ndtr(1.0)], rtol=1e-14)


def test_fragility_fit_probability_is_the_lognormal_curve():
    fit = FragilityFit(median=THETA, beta=BETA, method="mle", log_likelihood=0.0, n=1)
    x = np.linspace(0.1, 10, 7).reshape(7, 1)
    np.testing.assert_array_equal(fit.probability(x), lognormal_fragility(x, THETA, BETA))
    assert fit.probability(x).shape == x.shape


# ---------------------------------------------------------------------------------------------
# MSA: binomial MLE
# ---------------------------------------------------------------------------------------------


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_fit_mle_recovers_planted_curve(seed):
    """2000 records: s.e. of ln(theta) ~ 1 %, of beta ~ 2 %; 5 % tolerance."""
    _, k, n = stripe_counts(seed)
    fit = fit_mle(STRIPES, k, n)
    assert fit.method == "mle"
    assert fit.n == n.sum()
    assert fit.median == pytest.approx(THETA, rel=0.05)
    assert fit.beta == pytest.approx(BETA, rel=0.05)


@pytest.mark.parametrize(
    ("seed", "n_per_stripe"),
    [(0, 40), (1, 11), (2, 7), (3, np.array([3, 10, 20, 5, 40, 8, 15, 2, 30]))],
)
def test_fit_mle_matches_statsmodels_probit_glm(seed, n_per_stripe):
    """Same counts, independent algorithm: median = exp(-b0/b1), beta = 1/b1, same llf."""
    rng = np.random.default_rng(seed)
    n = np.broadcast_to(n_per_stripe, STRIPES.shape).astype(int)
    k = rng.binomial(n, lognormal_fragility(STRIPES, THETA, BETA))
    fit = fit_mle(STRIPES, k, n)
    glm = probit_glm(STRIPES, k, n)
    b0, b1 = glm.params
    assert fit.median == pytest.approx(np.exp(-b0 / b1), rel=1e-6)
    assert fit.beta == pytest.approx(1.0 / b1, rel=1e-6)
    assert fit.log_likelihood == pytest.approx(glm.llf, rel=1e-9)
    assert fit.details["b0"] == pytest.approx(b0, rel=1e-6)


def test_fit_mle_repeated_levels_equal_pooled_counts():
    """Two stripes at the same IM carry the same information as their pooled counts."""
    x = np.array([1.0, 2.0, 2.0, 4.0])
    fit_split = fit_mle(x, [1, 3, 4, 9], [10, 10, 10, 10])
    fit_pooled = fit_mle([1.0, 2.0, 4.0], [1, 7, 9], [10, 20, 10])
    assert fit_split.median == pytest.approx(fit_pooled.median, rel=1e-9)
    assert fit_split.beta == pytest.approx(fit_pooled.beta, rel=1e-9)


def test_fit_mle_ignores_empty_stripes():
    fit = fit_mle([1.0, 2.0, 3.0, 4.0], [1, 0, 4, 8], [10, 0, 10, 10])
    ref = fit_mle([1.0, 3.0, 4.0], [1, 4, 8], [10, 10, 10])
    assert fit.median == pytest.approx(ref.median, rel=1e-12)


def test_fit_mle_fixed_beta_matches_glm_with_offset():
    """With beta fixed, p = Phi(b0 + ln(x)/beta): a GLM with an offset and only an intercept."""
    rng = np.random.default_rng(5)
    n = np.full(STRIPES.size, 20)
    k = rng.binomial(n, lognormal_fragility(STRIPES, THETA, BETA))
    fit = fit_mle(STRIPES, k, n, fixed_beta=0.3)
    glm = sm.GLM(
        np.column_stack([k, n - k]),
        np.ones((STRIPES.size, 1)),
        offset=np.log(STRIPES) / 0.3,
        family=sm.families.Binomial(link=sm.families.links.Probit()),
    ).fit(tol=1e-13)
    assert fit.method == "mle_fixed_beta"
    assert fit.beta == 0.3
    assert fit.median == pytest.approx(np.exp(-glm.params[0] * 0.3), rel=1e-6)
    assert fit.log_likelihood == pytest.approx(glm.llf, rel=1e-9)


def test_fit_mle_fixed_beta_identifies_median_of_separated_stripes():
    """Separated stripes (0/10 then 10/10) give no beta, but a median once beta is fixed."""
    x = [1.0, 2.0, 4.0]
    with pytest.raises(FragilityFitError, match="separated"):
        fit_mle(x, [0, 10, 10], [10, 10, 10])
    fit = fit_mle(x, [0, 10, 10], [10, 10, 10], fixed_beta=0.3)
    assert 1.0 < fit.median < 2.0


@pytest.mark.parametrize(
    ("x", "k", "n", "match"),
    [
        ([1.0, 2.0, 3.0], [0, 0, 0], [10, 10, 10], "no exceedances"),
        ([1.0, 2.0, 3.0], [10, 5, 8], [10, 5, 8], "every record exceeds"),
        ([2.0, 2.0], [3, 4], [10, 10], "two distinct IM levels"),
        ([1.0, 2.0], [0, 0], [0, 0], "no records"),
        ([1.0, 2.0, 3.0], [0, 0, 10], [10, 10, 10], "separated"),
        ([1.0, 2.0, 3.0], [0, 4, 10], [10, 10, 10], "separated"),  # quasi-complete
        ([1.0, 2.0, 3.0], [10, 4, 0], [10, 10, 10], "decreases"),
        ([1.0, 2.0, 3.0], [8, 5, 2], [10, 10, 10], "does not increase"),
        ([1.0, 2.0, 3.0], [4, 4, 4], [10, 10, 10], "does not increase"),
    ],
)
def test_fit_mle_unidentifiable_data_raise(x, k, n, match):
    with pytest.raises(FragilityFitError, match=match) as info:
        fit_mle(x, k, n)
    assert isinstance(info.value, ValueError)


@pytest.mark.parametrize(
    ("x", "k", "n"),
    [
        ([1.0, 2.0], [3, 11], [10, 10]),  # more exceedances than records
        ([1.0, 2.0], [-1, 3], [10, 10]),
        ([1.0, 2.0], [1.5, 3], [10, 10]),
        ([0.0, 2.0], [1, 3], [10, 10]),
        ([1.0, 2.0, 3.0], [1, 3], [10, 10]),
    ],
)
def test_fit_mle_rejects_malformed_input(x, k, n):
    with pytest.raises(ValueError):
        fit_mle(x, k, n)


@settings(max_examples=25, deadline=None)
@given(
    scale=st.floats(min_value=1e-3, max_value=1e3),
    seed=st.integers(min_value=0, max_value=2**32 - 1),
)
def test_fit_mle_is_equivariant_to_im_units(scale, seed):
    """Changing the IM unit (x -> s x) scales the median by s and leaves beta unchanged."""
    rng = np.random.default_rng(seed)
    n = np.full(STRIPES.size, 15)
    k = rng.binomial(n, lognormal_fragility(STRIPES, THETA, BETA))
    try:
        ref = fit_mle(STRIPES, k, n)
    except FragilityFitError:
        return  # a rare separated draw
    fit = fit_mle(scale * STRIPES, k, n)
    assert fit.median == pytest.approx(scale * ref.median, rel=1e-7)
    assert fit.beta == pytest.approx(ref.beta, rel=1e-7)


def test_fit_msa_counts_only_valid_runs():
    exceeded, k, n = stripe_counts(seed=3, n_records=200)
    valid = np.ones_like(exceeded)
    valid[::7, 2] = False  # errored runs
    fit = fit_msa(exceeded, STRIPES, valid)
    ref = fit_mle(STRIPES, (exceeded & valid).sum(axis=0), valid.sum(axis=0))
    assert fit.median == ref.median
    assert fit.beta == ref.beta
    assert fit_msa(exceeded, STRIPES).median == fit_mle(STRIPES, k, n).median


def test_fit_msa_rejects_mismatched_shapes():
    with pytest.raises(ValueError, match="shape"):
        fit_msa(np.zeros((5, 3), dtype=bool), [1.0, 2.0])


# ---------------------------------------------------------------------------------------------
# IDA
# ---------------------------------------------------------------------------------------------


def test_ida_capacities_first_exceedance_resurrection_and_censoring():
    x = np.array([0.1, 0.2, 0.3, 0.4])
    exceeded = np.array(
        [
            [False, True, True, True],  # monotone: capacity 0.2
            [False, True, False, True],  # resurrection at 0.3: still capacity 0.2
            [False, False, False, False],  # never: censored at 0.4
            [False, True, True, True],  # 0.2 errored (invalid): capacity 0.3
            [False, False, False, True],  # last level errored: censored at 0.3
        ]
    )
    valid = np.ones_like(exceeded)
    valid[3, 1] = False
    valid[4, 3] = False
    caps = ida_capacities(exceeded, x, valid)
    np.testing.assert_array_equal(caps.capacity, [0.2, 0.2, np.inf, 0.3, np.inf])
    np.testing.assert_array_equal(caps.censored_at, [0.4, 0.4, 0.4, 0.4, 0.3])
    np.testing.assert_array_equal(caps.resurrected, [False, True, False, False, False])
    # the last valid level that held below the first exceedance: the lower capacity bound
    np.testing.assert_array_equal(caps.held, [0.1, 0.1, 0.4, 0.1, 0.3])


def test_ida_capacities_held_is_zero_for_a_record_failing_at_its_first_valid_level():
    x = np.array([0.1, 0.2, 0.3])
    exceeded = np.array([[True, True, True], [False, True, True], [True, True, True]])
    valid = np.array([[True, True, True], [False, True, True], [False, False, False]])
    caps = ida_capacities(exceeded, x, valid)
    np.testing.assert_array_equal(caps.held[:2], [0.0, 0.0])
    assert np.isnan(caps.held[2])  # no valid run: no bounds


# Demo-like coarse levels [g] and a planted capacity distribution between them.
COARSE_LEVELS = np.array([0.1, 0.2, 0.3, 0.45, 0.6, 0.8, 1.1, 1.5])
IDA_THETA, IDA_BETA = 0.55, 0.35


def test_interval_ida_fit_is_unbiased_on_coarse_levels_where_first_exceedance_is_not():
    """Synthetic lognormal capacities observed only at the demo's eight coarse levels.

    Over 150 replicates of 100 records the interval-censored fit recovers the planted median and
    beta to within 2 % on average (the standard error of the mean is ~0.3 % for the median and
    ~0.5 % for beta); the first-exceedance estimate overshoots the median by ~17 %, more than
    half of the mean level step.
    """
    rng = np.random.default_rng(2014)
    fits = {"interval": [], "first_exceedance": []}
    for _ in range(150):
        c = IDA_THETA * np.exp(IDA_BETA * rng.standard_normal(100))
        exceeded = c[:, None] <= COARSE_LEVELS[None, :]
        for method, out in fits.items():
            f = fit_ida_levels(exceeded, COARSE_LEVELS, method=method)
            out.append((f.median, f.beta))
    interval = np.mean(fits["interval"], axis=0)
    first = np.mean(fits["first_exceedance"], axis=0)
    assert interval[0] == pytest.approx(IDA_THETA, rel=0.02)
    assert interval[1] == pytest.approx(IDA_BETA, rel=0.02)
    assert first[0] / IDA_THETA - 1 > 0.10  # the old estimate's bias, shown


def test_interval_ida_fit_matches_scipy_censored_data_fit():
    """The same interval-censored likelihood maximised by scipy.stats (Nelder-Mead on
    CensoredData in ln IM): an independent implementation."""
    rng = np.random.default_rng(5)
    c = IDA_THETA * np.exp(IDA_BETA * rng.standard_normal(40))
    caps = ida_capacities(c[:, None] <= COARSE_LEVELS[None, :], COARSE_LEVELS)
    fit = fit_ida_intervals(caps.held, caps.capacity)
    assert fit.method == "ida_interval"
    with np.errstate(divide="ignore"):
        lo, hi = np.log(caps.held), np.log(caps.capacity)
    left, right = lo == -np.inf, hi == np.inf
    both = ~left & ~right
    data = stats.CensoredData(left=hi[left], right=lo[right],
                              interval=np.column_stack([lo[both], hi[both]]))
    mu, sigma = stats.norm.fit(data)
    assert fit.median == pytest.approx(np.exp(mu), rel=1e-3)
    assert fit.beta == pytest.approx(sigma, rel=1e-3)
    # the log-likelihood is that of the probabilities of the intervals
    p = stats.norm.cdf(hi, np.log(fit.median), fit.beta) - stats.norm.cdf(
        lo, np.log(fit.median), fit.beta)
    assert fit.log_likelihood == pytest.approx(np.sum(np.log(p)), rel=1e-10)
    assert fit.details["n_left_censored"] == int(left.sum())
    assert fit.details["n_right_censored"] == int(right.sum())


def test_interval_ida_fit_with_tails_far_out_keeps_its_precision():
    """Intervals far in a tail (probabilities ~1e-30) are taken on that tail, not as the
    difference of two numbers near 1."""
    lower = np.array([0.0, 1.0, 2.0, 3.0, 1e3])
    upper = np.array([1.0, 2.0, 3.0, 4.0, 2e3])
    fit = fit_ida_intervals(lower, upper)
    assert np.isfinite(fit.log_likelihood)
    assert 1.0 < fit.median < 100.0


@pytest.mark.parametrize(
    ("lower", "upper", "match"),
    [
        ([0.2, 0.3], [np.inf, np.inf], "bounded below"),
        ([0.0, 0.0], [0.1, 0.2], "bounded above"),
        ([0.1, 0.2, 0.1], [0.3, 0.3, 0.4], "beta -> 0"),  # all contain 0.3
        ([0.1, 0.2], [0.2, 0.3], "beta -> 0"),  # adjacent intervals touch at 0.2
    ],
)
def test_interval_ida_fit_refuses_unidentified_data(lower, upper, match):
    with pytest.raises(FragilityFitError, match=match):
        fit_ida_intervals(lower, upper)


def test_interval_ida_fit_rejects_malformed_bounds():
    with pytest.raises(ValueError, match="exceed its lower"):
        fit_ida_intervals([0.2, 0.1], [0.2, 0.3])
    with pytest.raises(ValueError, match="NaN"):
        fit_ida_intervals([np.nan, 0.1], [0.2, 0.3])
    with pytest.raises(ValueError, match="method must be one of"):
        fit_ida_levels(np.zeros((2, 3), bool), [0.1, 0.2, 0.3], method="mle")


def test_ida_capacities_feed_fit_ida():
    rng = np.random.default_rng(11)
    capacity = THETA * np.exp(BETA * rng.standard_normal(3000))
    levels = THETA * np.exp(np.linspace(-1.5, 0.8, 60))  # fine steps, ~30 % censored at top
    caps = ida_capacities(capacity[:, None] <= levels[None, :], levels)
    fit = fit_ida(caps.capacity, caps.censored_at)
    # First-exceedance capacities overshoot by < one level step (4 %): median biased up ~2 %.
    assert fit.median == pytest.approx(THETA, rel=0.05)
    assert fit.beta == pytest.approx(BETA, rel=0.05)


def test_fit_ida_moments_match_baker_formulas():
    """Baker (2015) eqs. (2)-(3): mean of ln c, and standard deviation with 1/(n-1)."""
    c = np.array([0.31, 0.52, 0.44, 0.8, 0.27, 0.6])
    fit = fit_ida(c, method="moments")
    y = np.log(c)
    assert fit.median == pytest.approx(np.exp(y.sum() / y.size), rel=1e-14)
    ref_beta = np.sqrt(np.sum((y - y.mean()) ** 2) / (y.size - 1))
    assert fit.beta == pytest.approx(ref_beta, rel=1e-14)
    assert fit.method == "ida_moments"
    assert np.isnan(fit.log_likelihood)


def test_fit_ida_mle_without_censoring_is_closed_form():
    c = np.array([0.31, 0.52, 0.44, 0.8, 0.27, 0.6])
    fit = fit_ida(c)
    assert fit.method == "ida_mle"
    assert fit.median == pytest.approx(np.exp(np.mean(np.log(c))), rel=1e-14)
    assert fit.beta == pytest.approx(np.std(np.log(c)), rel=1e-14)
    assert fit.log_likelihood == pytest.approx(
        stats.norm.logpdf(np.log(c), np.log(fit.median), fit.beta).sum(), rel=1e-12
    )


def test_fit_ida_censored_mle_matches_independent_maximisation():
    """Tobit likelihood written with scipy.stats, maximised by Nelder-Mead to 1e-12."""
    rng = np.random.default_rng(4)
    c = THETA * np.exp(BETA * rng.standard_normal(300))
    cmax = np.where(np.arange(300) % 2 == 0, 3.5, 2.8)  # per-record censoring levels
    censored = c > cmax
    y, yc = np.log(c[~censored]), np.log(cmax[censored])

    def negll(p):
        return -(stats.norm.logpdf(y, p[0], p[1]).sum() + stats.norm.logsf(yc, p[0], p[1]).sum())

    ref = optimize.minimize(
        negll,
        [np.log(2.5), 0.3],
        method="Nelder-Mead",
        options={"xatol": 1e-12, "fatol": 1e-13, "maxiter": 5000},
    )
    fit = fit_ida(np.where(censored, np.inf, c), cmax)
    assert fit.details["n_censored"] == censored.sum() > 50
    assert np.log(fit.median) == pytest.approx(ref.x[0], abs=1e-6)
    assert fit.beta == pytest.approx(ref.x[1], rel=1e-6)
    assert fit.log_likelihood == pytest.approx(-ref.fun, rel=1e-9)


def test_fit_ida_censored_mle_unbiased_where_naive_moments_are_not():
    """Half the records censored at the true median.

    The naive estimator replaces censored capacities by the censoring level, i.e. ln c ->
    min(ln c, ln theta); for a normal ln c that gives E = ln theta - beta/sqrt(2 pi) (median
    -15 %) and sd = beta sqrt(1/2 - 1/(2 pi)) (beta -42 %).
    """
    rng = np.random.default_rng(8)
    c = THETA * np.exp(BETA * rng.standard_normal(4000))
    observed = np.where(c > THETA, np.inf, c)
    mle = fit_ida(observed, censored_at=THETA)
    assert mle.median == pytest.approx(THETA, rel=0.03)
    assert mle.beta == pytest.approx(BETA, rel=0.05)
    with pytest.warns(RuntimeWarning, match="censored"):
        naive = fit_ida(observed, censored_at=THETA, method="moments")
    assert naive.median == pytest.approx(THETA * np.exp(-BETA / np.sqrt(2 * np.pi)), rel=0.02)
    assert naive.beta == pytest.approx(BETA * np.sqrt(0.5 - 0.5 / np.pi), rel=0.05)
    assert naive.median < 0.9 * THETA and naive.beta < 0.7 * BETA


def test_fit_ida_capacity_above_censoring_level_is_censored():
    c = np.array([1.0, 1.5, 2.0, 9.0])
    a = fit_ida(c, censored_at=3.0)
    b = fit_ida(np.array([1.0, 1.5, 2.0, np.inf]), censored_at=3.0)
    assert a.median == b.median and a.details["n_censored"] == 1


@pytest.mark.parametrize(
    ("kwargs", "error", "match"),
    [
        ({"capacities": [1.0, np.inf, 2.0]}, ValueError, "censored_at"),
        ({"capacities": [1.0, np.nan, 2.0]}, ValueError, "NaN"),
        ({"capacities": [1.0, -1.0]}, ValueError, "positive"),
        ({"capacities": [1.0, 2.0], "method": "bayes"}, ValueError, "method"),
        ({"capacities": [1.0, np.inf, np.inf], "censored_at": 3.0}, FragilityFitError, "beta"),
        ({"capacities": [np.inf, np.inf], "censored_at": 3.0}, FragilityFitError, "beta"),
        ({"capacities": [1.0], "method": "moments"}, FragilityFitError, "two"),
    ],
)
def test_fit_ida_rejects_bad_or_unidentifiable_input(kwargs, error, match):
    with pytest.raises(error, match=match):
        fit_ida(**kwargs)


# ---------------------------------------------------------------------------------------------
# Cloud
# ---------------------------------------------------------------------------------------------

# Planted demand model ln EDP = A + B ln IM + SIGMA eps, EDP in [m], IM in [m/s^2].
A, B, SIGMA, CAPACITY = np.log(0.02), 1.2, 0.3, 0.03


def cloud(seed, n):
    rng = np.random.default_rng(seed)
    im = 2.0 * np.exp(0.6 * rng.standard_normal(n))
    edp = np.exp(A + B * np.log(im) + SIGMA * rng.standard_normal(n))
    return im, edp


def test_fit_cloud_regression_formulas():
    """median = exp((ln C - a)/b), beta = sqrt(sigma^2 + beta_C^2)/b with OLS a, b, sigma."""
    im, edp = cloud(0, 50)
    b, a = np.polyfit(np.log(im), np.log(edp), 1)
    sigma = np.sqrt(np.sum((np.log(edp) - a - b * np.log(im)) ** 2) / (im.size - 2))
    fit = fit_cloud(im, edp, CAPACITY, capacity_beta=0.2)
    assert fit.details["a"] == pytest.approx(a, rel=1e-10)
    assert fit.details["b"] == pytest.approx(b, rel=1e-10)
    assert fit.details["sigma"] == pytest.approx(sigma, rel=1e-10)
    assert fit.median == pytest.approx(np.exp((np.log(CAPACITY) - a) / b), rel=1e-10)
    assert fit.beta == pytest.approx(np.sqrt(sigma**2 + 0.2**2) / b, rel=1e-10)


def test_fit_cloud_recovers_planted_regression():
    im, edp = cloud(1, 3000)
    fit = fit_cloud(im, edp, CAPACITY)
    assert fit.details["b"] == pytest.approx(B, rel=0.03)
    assert fit.details["sigma"] == pytest.approx(SIGMA, rel=0.05)
    assert fit.median == pytest.approx(np.exp((np.log(CAPACITY) - A) / B), rel=0.05)
    assert fit.beta == pytest.approx(SIGMA / B, rel=0.05)


def test_fit_cloud_probit_recovers_the_same_curve():
    """P(EDP > C | IM) of the planted model is exactly lognormal in IM; 10 000 binary outcomes."""
    im, edp = cloud(2, 10_000)
    fit = fit_cloud(im, edp, CAPACITY, method="probit")
    assert fit.method == "cloud_probit"
    assert fit.median == pytest.approx(np.exp((np.log(CAPACITY) - A) / B), rel=0.03)
    assert fit.beta == pytest.approx(SIGMA / B, rel=0.10)
    # Collapses (inf EDP) are allowed in the probit and count as exceeding.
    edp_collapse = np.where(im > 6.0, np.inf, edp)
    assert fit_cloud(im, edp_collapse, CAPACITY, method="probit").n == im.size


@pytest.mark.parametrize(
    ("edp_fn", "kwargs", "error", "match"),
    [
        (lambda im, edp: 1.0 / edp, {}, FragilityFitError, "slope"),
        (lambda im, edp: np.where(im > 4.0, np.inf, edp), {}, ValueError, "collapsed"),
        (lambda im, edp: edp, {"method": "probit", "capacity_beta": 0.2}, ValueError, "capacity"),
        (lambda im, edp: edp, {"method": "ols"}, ValueError, "method"),
    ],
)
def test_fit_cloud_errors(edp_fn, kwargs, error, match):
    im, edp = cloud(3, 100)
    with pytest.raises(error, match=match):
        fit_cloud(im, edp_fn(im, edp), CAPACITY, **kwargs)


# ---------------------------------------------------------------------------------------------
# Bootstrap
# ---------------------------------------------------------------------------------------------


def test_bootstrap_band_contains_true_curve_ida():
    rng = np.random.default_rng(21)
    c = THETA * np.exp(BETA * rng.standard_normal(60))
    x = THETA * np.exp(BETA * np.linspace(-2.0, 2.0, 41))
    state = np.random.get_state()
    result = bootstrap(fit_ida, {"capacities": c}, im=x, n_boot=400, confidence=0.95, seed=7)
    assert np.all(np.random.get_state()[1] == state[1])  # no global RNG use
    truth = lognormal_fragility(x, THETA, BETA)
    assert np.all((result.lower <= truth) & (truth <= result.upper))
    assert np.all(result.lower <= result.fit.probability(x) + 1e-12)
    assert result.fit.median_ci[0] < THETA < result.fit.median_ci[1]
    assert result.fit.beta_ci[0] < BETA < result.fit.beta_ci[1]
    assert result.fit.ci_level == 0.95
    assert result.medians.size == 400 and result.n_failed == 0


def test_bootstrap_is_reproducible_and_accepts_a_generator():
    rng = np.random.default_rng(22)
    c = THETA * np.exp(BETA * rng.standard_normal(30))
    a = bootstrap(fit_ida, {"capacities": c}, n_boot=50, seed=3)
    b = bootstrap(fit_ida, {"capacities": c}, n_boot=50, seed=np.random.default_rng(3))
    np.testing.assert_array_equal(a.medians, b.medians)
    np.testing.assert_array_equal(a.lower, b.lower)
    assert a.im.size == 100  # default grid


def test_bootstrap_msa_resamples_record_rows():
    exceeded, _, _ = stripe_counts(seed=6, n_records=40)
    valid = np.ones_like(exceeded)
    result = bootstrap(
        fit_msa, {"exceeded": exceeded, "valid": valid}, im_levels=STRIPES, n_boot=200, seed=1
    )
    base = fit_msa(exceeded, STRIPES)
    assert result.fit.median == base.median
    lo, hi = result.fit.median_ci
    assert lo < base.median < hi
    assert lo < THETA < hi


def test_bootstrap_cloud_with_fixed_capacity():
    im, edp = cloud(4, 80)
    result = bootstrap(fit_cloud, {"im": im, "edp": edp}, capacity=CAPACITY, n_boot=200, seed=2)
    lo, hi = result.fit.median_ci
    assert lo < np.exp((np.log(CAPACITY) - A) / B) < hi


def test_bootstrap_drops_unfittable_resamples_with_a_warning():
    """Few exceedances: some resamples contain none and cannot be fitted."""
    x = np.array([1.0, 2.0])
    exceeded = np.zeros((20, 2), dtype=bool)
    exceeded[0, :] = True  # the only exceedance at x = 1: resamples without it are separated
    exceeded[1:3, 1] = True
    with pytest.warns(RuntimeWarning, match="could not be fitted") as said:
        result = bootstrap(fit_msa, {"exceeded": exceeded}, im_levels=x, n_boot=100, seed=0)
    assert 0 < result.n_failed < 50
    assert result.medians.size == 100 - result.n_failed
    assert np.all(np.isfinite(result.medians)) and np.all(np.isfinite(result.lower))
    # why: each failed resample's FragilityFitError message counted, most frequent first
    assert sum(result.failures.values()) == result.n_failed
    counts = list(result.failures.values())
    assert counts == sorted(counts, reverse=True)
    reason, count = next(iter(result.failures.items()))
    assert reason and count > 0
    text = result.failure_text()
    assert text == f"the most frequent reason ({count} of {result.n_failed}): {reason}"
    assert text in str(said[0].message)
    exceeded[2, 1] = False  # only 2 exceeding records: most resamples are unfittable
    with pytest.raises(ValueError, match="too sparse for a bootstrap; the most frequent reason"):
        bootstrap(fit_msa, {"exceeded": exceeded}, im_levels=x, n_boot=100, seed=0)


def test_bootstrap_rejects_ragged_records():
    with pytest.raises(ValueError, match="same length"):
        bootstrap(fit_cloud, {"im": np.ones(5), "edp": np.ones(4)}, capacity=1.0)
