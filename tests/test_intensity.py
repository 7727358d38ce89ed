"""Verification of shipblock.intensity against closed-form results.

Every reference value is analytic; the source of each is given in the test docstring. The
independent numerical reference for the oscillator is ``scipy.signal.lsim`` (first-order hold,
i.e. exact for piecewise-linear input, computed with a matrix exponential instead of the
Nigam-Jennings closed-form coefficients).
"""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy import signal

from shipblock import intensity as im
from shipblock.errors import RecordError
from shipblock.units import STANDARD_GRAVITY as G


def _sine(amplitude, freq, n_periods, samples_per_period):
    dt = 1.0 / (freq * samples_per_period)
    t = np.arange(n_periods * samples_per_period + 1) * dt
    return t, amplitude * np.sin(2.0 * np.pi * freq * t), dt


# ---------------------------------------------------------------------------------------------
# peaks and integrals
# ---------------------------------------------------------------------------------------------
def test_velocity_displacement_of_sine():
    """a = A sin(wt) from rest: v = A/w (1 - cos wt), d = A/w t - A/w^2 sin wt (calculus).

    Hence PGV = 2A/w at t = pi/w (first maximum) and PGD = A T_end / w at the last sample
    (d is non-decreasing because v >= 0).
    """
    amp, freq = 3.0, 2.0
    w = 2 * np.pi * freq
    t, a, dt = _sine(amp, freq, n_periods=5, samples_per_period=1000)
    v_exact = amp / w * (1 - np.cos(w * t))
    d_exact = amp / w * t - amp / w**2 * np.sin(w * t)
    np.testing.assert_allclose(im.velocity(a, dt), v_exact, rtol=0, atol=1e-5 * amp / w)
    np.testing.assert_allclose(im.displacement(a, dt), d_exact, rtol=1e-5, atol=1e-5 * amp / w**2)

    assert im.pgv(a, dt) == pytest.approx(2 * amp / w, rel=1e-5)
    assert im.peak_time(a, dt, "pgv") == pytest.approx(np.pi / w, abs=dt)
    assert im.pgd(a, dt) == pytest.approx(amp * t[-1] / w, rel=1e-5)
    assert im.peak_time(a, dt, "pgd") == pytest.approx(t[-1])


def test_integration_exact_for_linear_acceleration():
    """a = c0 + c1 t (piecewise linear, so exact): v = c0 t + c1 t^2/2, d = c0 t^2/2 + c1 t^3/6."""
    dt = 0.37
    t = np.arange(50) * dt
    c0, c1 = -0.8, 0.3
    a = c0 + c1 * t
    np.testing.assert_allclose(im.velocity(a, dt), c0 * t + c1 * t**2 / 2, rtol=1e-12, atol=1e-12)
    np.testing.assert_allclose(
        im.displacement(a, dt), c0 * t**2 / 2 + c1 * t**3 / 6, rtol=1e-12, atol=1e-11
    )


def test_pga_value_and_time_negative_peak():
    """PGA is the largest absolute value; its time is index * dt (definition)."""
    a = np.array([0.0, 1.0, -4.0, 2.0, 3.9])
    assert im.pga(a, 0.5) == 4.0
    assert im.peak_time(a, 0.5, "pga") == 1.0


def test_peak_measures_are_plain_numbers_that_scale():
    """A peak is one float, not a (value, time) pair: it multiplies and compares as a number
    (a tuple would be repeated by 2 * ..., and its time would be scaled along with it)."""
    a = np.array([0.0, 1.0, -4.0, 2.0])
    for measure in (im.pga, im.pgv, im.pgd):
        value = measure(a, 0.1)
        assert type(value) is float
        assert 2 * value == measure(2 * a, 0.1)
    with pytest.raises(ValueError, match="measure"):
        im.peak_time(a, 0.1, "sa")


# ---------------------------------------------------------------------------------------------
# Arias, CAV, CAV5, durations
# ---------------------------------------------------------------------------------------------
def test_arias_of_sine_whole_periods():
    """Ia = pi/(2g) * A^2 T/2 over whole periods (Arias 1970; mean of sin^2 is 1/2)."""
    amp, freq = 2.5, 1.5
    t, a, dt = _sine(amp, freq, n_periods=7, samples_per_period=200)
    expected = np.pi / (2 * G) * amp**2 * t[-1] / 2
    assert im.arias_intensity(a, dt) == pytest.approx(expected, rel=1e-12)


def test_cav_of_sine_whole_periods():
    """CAV = (2A/pi) T over whole periods (EPRI 1988 definition; mean of |sin| is 2/pi)."""
    amp, freq = 2.5, 1.5
    t, a, dt = _sine(amp, freq, n_periods=7, samples_per_period=2000)
    expected = 2 * amp / np.pi * t[-1]
    assert im.cav(a, dt) == pytest.approx(expected, rel=1e-5)


def test_cav5_of_sine():
    """CAV5 of A sin(wt) with threshold s*A: each half period contributes 2A sqrt(1-s^2)/w.

    Integral of A|sin| over the part of a half period where |sin| >= s (Kramer & Mitchell 2006
    convention). Also CAV5 with zero threshold is CAV.
    """
    amp, freq, n_periods = 0.4, 1.0, 4
    t, a, dt = _sine(amp, freq, n_periods=n_periods, samples_per_period=10000)
    w = 2 * np.pi * freq
    s = im.CAV5_THRESHOLD / amp
    expected = 2 * n_periods * 2 * amp * np.sqrt(1 - s**2) / w
    assert im.cav5(a, dt) == pytest.approx(expected, rel=1e-4)
    assert im.cav5(a, dt, threshold=0.0) == im.cav(a, dt)
    assert im.cav5(0.01 * a, dt) == 0.0  # never reaches 5 cm/s^2


@pytest.mark.parametrize(("start", "end"), [(0.05, 0.95), (0.05, 0.75)])
def test_significant_duration_known_husid(start, end):
    """a(t) = sqrt(t) on [0, T]: integral of a^2 is t^2/2, so H(t) = (t/T)^2 and
    D_p-q = T (sqrt(q) - sqrt(p)) (Husid curve in closed form)."""
    dt, n = 0.001, 20001
    t = np.arange(n) * dt
    a = np.sqrt(t)
    total = t[-1]
    np.testing.assert_allclose(im.husid(a, dt), (t / total) ** 2, atol=1e-8)
    expected = total * (np.sqrt(end) - np.sqrt(start))
    assert im.significant_duration(a, dt, start, end) == pytest.approx(expected, rel=1e-6)


def test_husid_of_zero_record_raises():
    with pytest.raises(RecordError, match="all-zero"):
        im.husid(np.zeros(10), 0.01)


# ---------------------------------------------------------------------------------------------
# SDOF oscillator and response spectrum
# ---------------------------------------------------------------------------------------------
def _lsim(acc, dt, period, damping):
    w = 2 * np.pi / period
    sys = signal.StateSpace([[0, 1], [-w * w, -2 * damping * w]], [[0], [-1]], [[1, 0]], [[0]])
    _, y, _ = signal.lsim(sys, acc, np.arange(acc.size) * dt)
    return y


@pytest.mark.parametrize(("period", "damping"), [(0.5, 0.05), (0.03, 0.0), (2.0, 0.3)])
def test_nigam_jennings_matches_first_order_hold(period, damping):
    """The recursion is exact for piecewise-linear input, like lsim's first-order hold."""
    rng = np.random.default_rng(3)
    acc, dt = rng.standard_normal(1500), 0.01
    u_ref = _lsim(acc, dt, period, damping)
    u, _ = im.sdof_response(acc, dt, period, damping)
    np.testing.assert_allclose(u, u_ref, rtol=0, atol=1e-10 * np.max(np.abs(u_ref)))
    spec = im.response_spectrum(acc, dt, [period], damping, samples_per_period=1)
    assert spec.sd[0] == pytest.approx(np.max(np.abs(u_ref)), rel=1e-10)
    # oversampled: the peak of the same piecewise-linear input's response on a grid of at
    # least 100 points per period (lsim on the linearly interpolated record)
    k = int(np.ceil(im.SAMPLES_PER_PERIOD * dt / period))
    fine = np.interp(np.arange((acc.size - 1) * k + 1) / k, np.arange(acc.size), acc)
    peak_fine = np.max(np.abs(_lsim(fine, dt / k, period, damping)))
    spec = im.response_spectrum(acc, dt, [period], damping)
    assert spec.sd[0] == pytest.approx(peak_fine, rel=1e-8)


@pytest.mark.parametrize(("phase", "plain_error"), [(0.0, 0.0), (np.pi / 20, 0.0123)])
def test_short_period_sa_is_oversampled_against_the_closed_form_harmonic_response(phase,
                                                                                   plain_error):
    """Resonant harmonic input a = A sin(w t + phase) on an oscillator of T = 20 dt.

    Steady state (Chopra 2017, eq. 3.2.3, r = 1): Sa = A / (2 zeta), times sinc^2(pi dt / T)
    for the piecewise-linear interpolation of the sampled sine (the interpolant's fundamental).
    With the crests on samples (phase 0) the response at the samples reaches the peak; with
    them half a sample off (phase = pi/20) it misses 1 - cos(pi/20) = 1.23 % without
    oversampling and at most 1 - cos(pi/100) = 0.05 % with the default 100 samples per period.
    """
    dt, zeta, amp = 0.01, 0.05, 1.3
    period = 20 * dt
    w = 2 * np.pi / period
    t = np.arange(int(60 * period / dt)) * dt  # transient decayed to exp(-18.8)
    a = amp * np.sin(w * t + phase)
    x = np.pi * dt / period
    exact = amp / (2 * zeta) * (np.sin(x) / x) ** 2
    plain = im.spectral_acceleration(a, dt, period, zeta, samples_per_period=1)
    assert plain / exact - 1 == pytest.approx(-plain_error, abs=2e-4)
    sa = im.spectral_acceleration(a, dt, period, zeta)
    assert abs(sa / exact - 1) < 1 - np.cos(np.pi / im.SAMPLES_PER_PERIOD) + 1e-6
    assert abs(sa / exact - 1) < 6e-4


def test_long_periods_are_not_oversampled():
    """At T >= 100 dt the oversampling is off: bit for bit the plain recursion."""
    rng = np.random.default_rng(8)
    acc = rng.standard_normal(3000)
    periods = [1.0, 2.5]
    np.testing.assert_array_equal(im.spectral_acceleration(acc, 0.01, periods),
                                  im.spectral_acceleration(acc, 0.01, periods,
                                                           samples_per_period=1))
    with pytest.raises(ValueError, match="samples_per_period"):
        im.response_spectrum(acc, 0.01, periods, samples_per_period=0)


@pytest.mark.parametrize("damping", [0.0, 0.05, 0.2])
def test_step_response_exact(damping):
    """Suddenly applied constant ground acceleration a0 (Chopra 2017, eq. 4.3.3):

    u(t) = -(a0/w^2) [1 - exp(-z w t) (cos wd t + z/sqrt(1-z^2) sin wd t)].

    A constant sampled record is exactly this input, so the match is to rounding.
    """
    a0, period, dt = 1.7, 0.8, 0.01
    t = np.arange(800) * dt
    w = 2 * np.pi / period
    wd = w * np.sqrt(1 - damping**2)
    exact = -(a0 / w**2) * (
        1
        - np.exp(-damping * w * t)
        * (np.cos(wd * t) + damping / np.sqrt(1 - damping**2) * np.sin(wd * t))
    )
    u, _ = im.sdof_response(np.full(t.size, a0), dt, period, damping)
    np.testing.assert_allclose(u, exact, rtol=0, atol=1e-12 * a0 / w**2)


def test_half_sine_pulse_duhamel():
    """Undamped response to a_g = a0 sin(pi t/td), 0 <= t <= td (Duhamel; Chopra 2017 §4.8):

    forced phase  u = (u_st/(1-b^2)) [sin(pi t/td) - b sin(w t)],  b = (pi/td)/w,
    free phase    u = u(td) cos w(t-td) + u'(td)/w sin w(t-td),
    with u_st = -a0/w^2 (load per unit mass is -a_g).
    """
    a0, td, period = 2.0, 0.3, 0.45
    w = 2 * np.pi / period
    b = (np.pi / td) / w
    u_st = -a0 / w**2
    dt = td / 3000
    t = np.arange(int(round(1.5 / dt)) + 1) * dt
    a = np.where(t <= td, a0 * np.sin(np.pi * np.clip(t, 0, td) / td), 0.0)

    def forced(tt):
        return u_st / (1 - b**2) * (np.sin(np.pi * tt / td) - b * np.sin(w * tt))

    def forced_dot(tt):
        return u_st / (1 - b**2) * (np.pi / td * np.cos(np.pi * tt / td) - b * w * np.cos(w * tt))

    exact = np.where(
        t <= td,
        forced(t),
        forced(td) * np.cos(w * (t - td)) + forced_dot(td) / w * np.sin(w * (t - td)),
    )
    u, _ = im.sdof_response(a, dt, period, 0.0)
    peak = np.max(np.abs(exact))
    np.testing.assert_allclose(u, exact, rtol=0, atol=1e-5 * peak)
    spec = im.response_spectrum(a, dt, [period], 0.0)
    assert spec.sd[0] == pytest.approx(peak, rel=1e-5)
    assert spec.psa[0] == pytest.approx(w**2 * peak, rel=1e-5)


@pytest.mark.parametrize("ratio", [0.5, 1.0, 2.0])
def test_harmonic_steady_state(ratio):
    """a_g = A sin(Wt): steady state u = -A/w^2 Rd sin(Wt - phi) (Chopra 2017, eq. 3.2.3),

    Rd = 1/sqrt((1-r^2)^2 + (2 z r)^2), tan(phi) = 2 z r/(1-r^2), r = W/w. At resonance
    (r = 1) the amplitude is A/(2 z w^2). Compared once the transient exp(-z w t) has decayed
    below 1e-7.
    """
    amp, period, zeta = 1.2, 0.5, 0.05
    w = 2 * np.pi / period
    big_w = ratio * w
    dt = period / 400
    n_decay = int(np.ceil(-np.log(1e-7) / (zeta * w) / dt))
    t = np.arange(n_decay + int(4 * period / dt)) * dt
    a = amp * np.sin(big_w * t)
    rd = 1 / np.sqrt((1 - ratio**2) ** 2 + (2 * zeta * ratio) ** 2)
    phi = np.arctan2(2 * zeta * ratio, 1 - ratio**2)
    exact = -amp / w**2 * rd * np.sin(big_w * t - phi)
    u, _ = im.sdof_response(a, dt, period, zeta)
    tail = slice(n_decay, None)
    np.testing.assert_allclose(u[tail], exact[tail], rtol=0, atol=1e-4 * amp / w**2 * rd)
    if ratio == 1.0:
        assert np.max(np.abs(u[tail])) == pytest.approx(amp / (2 * zeta * w**2), rel=1e-3)


def test_sa_at_zero_period_is_pga_and_short_period_limit():
    """Sa(T = 0) = PGA by definition; Sa(T -> 0) -> PGA (rigid oscillator follows the ground)."""
    t = np.arange(3000) * 0.01
    a = np.sin(2 * np.pi * 0.7 * t) * np.exp(-(((t - 12) / 4) ** 2)) * 3.0
    pga = im.pga(a, 0.01)
    assert im.spectral_acceleration(a, 0.01, 0.0) == pga
    sa = im.spectral_acceleration(a, 0.01, [0.0, 1e-3, 1e-4])
    np.testing.assert_allclose(sa, pga, rtol=1e-3)
    assert isinstance(im.spectral_acceleration(a, 0.01, 0.5), float)


@settings(max_examples=25, deadline=None)
@given(factor=st.floats(-50, 50).filter(lambda x: abs(x) > 1e-3))
def test_spectrum_is_homogeneous(factor):
    """Sa(k a) = |k| Sa(a) (linear oscillator, absolute peak)."""
    rng = np.random.default_rng(5)
    a = rng.standard_normal(400)
    periods = [0.0, 0.1, 1.0]
    np.testing.assert_allclose(
        im.spectral_acceleration(factor * a, 0.01, periods),
        abs(factor) * im.spectral_acceleration(a, 0.01, periods),
        rtol=1e-12,
    )


# ---------------------------------------------------------------------------------------------
# bundles and validation
# ---------------------------------------------------------------------------------------------
def test_intensity_measures_dict_consistent():
    t, a, dt = _sine(2.0, 1.0, n_periods=3, samples_per_period=400)
    out = im.intensity_measures(a, dt, periods=(0.0, 0.5))
    assert out["pga"] == im.pga(a, dt)
    assert out["arias"] == im.arias_intensity(a, dt)
    assert out["cav"] == im.cav(a, dt)
    assert out["d5_95"] == im.significant_duration(a, dt)
    np.testing.assert_array_equal(out["sa"], im.spectral_acceleration(a, dt, [0.0, 0.5]))
    assert out["sa"][0] == out["pga"]
    assert set(out) >= {"pgv", "t_pgv", "pgd", "t_pgd", "cav5", "d5_75", "periods", "damping"}


def test_intensity_measures_hv():
    t, a, dt = _sine(2.0, 1.0, n_periods=3, samples_per_period=400)
    out = im.intensity_measures_hv(a, 0.5 * a, dt, periods=(0.0, 0.5))
    assert out["v_over_h_pga"] == pytest.approx(0.5)
    assert out["V"]["arias"] == pytest.approx(0.25 * out["H"]["arias"], rel=1e-12)
    with pytest.raises(ValueError, match="same length"):
        im.intensity_measures_hv(a, a[:-1], dt)


def test_zero_record_bundle_has_nan_durations():
    out = im.intensity_measures(np.zeros(100), 0.01, periods=(0.0, 1.0))
    assert np.isnan(out["d5_95"]) and out["pga"] == 0.0 and np.all(out["sa"] == 0.0)


@pytest.mark.parametrize(
    ("call", "match"),
    [
        (lambda: im.pga(np.ones((2, 2)), 0.01), "1-D"),
        (lambda: im.pga([1.0, np.nan], 0.01), "NaN"),
        (lambda: im.pga([1.0, 2.0], 0.0), "dt"),
        (lambda: im.response_spectrum([1.0, 2.0], 0.01, [-1.0]), "periods"),
        (lambda: im.response_spectrum([1.0, 2.0], 0.01, [1.0], damping=1.0), "damping"),
        (lambda: im.significant_duration([1.0, 2.0], 0.01, 0.9, 0.1), "start"),
        (lambda: im.cav5([1.0, 2.0], 0.01, threshold=-1.0), "threshold"),
    ],
)
def test_validation_errors(call, match):
    with pytest.raises(ValueError, match=match):
        call()
