"""Interpolants and closed-form roots used by the solver's event location.

The quintic Hermite interpolant is checked symbolically (sympy) and by reproducing quintics
exactly; the closed-form event roots of the non-rocking modes against dense sampling of the
same functions.
"""

import numpy as np
import pytest
import sympy as sp

from shipblock.solver._closed_form import linear_root, min_linear_root, quadratic_root
from shipblock.solver._interpolate import (
    bracketed_root,
    poly5,
    poly5_slope,
    quintic_and_slope,
    quintic_hermite,
    rotation_peak,
)


def test_quintic_hermite_matches_symbolic_interpolation_conditions():
    u, h = sp.symbols("u h", positive=True)
    t0, w0, a0, t1, w1, a1 = sp.symbols("t0 w0 a0 t1 w1 a1")
    c = sp.symbols("c0:6")
    p = sum(ci * u**i for i, ci in enumerate(c))
    # derivatives in time: d/dt = (1/h) d/du
    conds = [p.subs(u, 0) - t0, sp.diff(p, u).subs(u, 0) - h * w0,
             sp.diff(p, u, 2).subs(u, 0) - h**2 * a0, p.subs(u, 1) - t1,
             sp.diff(p, u).subs(u, 1) - h * w1, sp.diff(p, u, 2).subs(u, 1) - h**2 * a1]
    sol = sp.solve(conds, c)
    rng = np.random.default_rng(3)
    for _ in range(5):
        vals = dict(zip((t0, w0, a0, t1, w1, a1, h), rng.normal(size=6).tolist() + [0.37],
                        strict=True))
        got = quintic_hermite(*(vals[s] for s in (t0, w0, a0, t1, w1, a1, h)))
        want = [float(sol[ci].subs(vals)) for ci in c]
        np.testing.assert_allclose(got, want, rtol=1e-12, atol=1e-12)


def test_quintic_hermite_reproduces_quintics():
    """Degree <= 5 polynomials in time are reproduced exactly (to rounding) on any step."""
    rng = np.random.default_rng(7)
    q = rng.normal(size=6)  # theta(t) = sum q_i t^i
    t_start, h = 0.8, 0.013
    th = np.polynomial.Polynomial(q)
    om, al = th.deriv(), th.deriv(2)
    c = quintic_hermite(th(t_start), om(t_start), al(t_start), th(t_start + h), om(t_start + h),
                        al(t_start + h), h)
    for uu in np.linspace(0, 1, 11):
        assert poly5(*c, uu) == pytest.approx(th(t_start + uu * h), rel=1e-12, abs=1e-13)
        assert poly5_slope(*c[1:], uu) / h == pytest.approx(om(t_start + uu * h), rel=1e-9)


def test_bracketed_root_of_value_and_of_slope():
    # p(u) = (u - 0.3)(u - 0.8)(u + 1) (u^2 + 1): roots 0.3 and 0.8, a minimum between them
    poly = np.polynomial.Polynomial.fromroots([0.3, 0.8, -1.0]) * np.polynomial.Polynomial([1, 0, 1])
    c = tuple(poly.coef) + (0.0,) * (6 - poly.coef.size)
    assert bracketed_root(*c, 0.0, 0.5, False) == pytest.approx(0.3, abs=1e-14)
    assert bracketed_root(*c, 0.5, 1.0, False) == pytest.approx(0.8, abs=1e-14)
    # its derivative's root inside [0, 1], from numpy's roots of p'
    crit = [r.real for r in poly.deriv().roots() if abs(r.imag) < 1e-12 and 0 < r.real < 1]
    assert len(crit) == 1
    assert bracketed_root(*c, 0.0, 1.0, True) == pytest.approx(crit[0], abs=1e-13)
    # no sign change: no root
    assert bracketed_root(*c, 0.0, 1.0, False) == -1.0


def test_quintic_and_slope_agrees_with_separate_horner():
    rng = np.random.default_rng(5)
    for _ in range(50):
        c = tuple(rng.normal(size=6))
        u = rng.uniform(-0.5, 1.5)
        q, d = quintic_and_slope(*c, u)
        assert q == pytest.approx(poly5(*c, u), rel=1e-13, abs=1e-14)
        assert d == pytest.approx(poly5_slope(*c[1:], u), rel=1e-13, abs=1e-14)


def test_bracketed_root_when_the_last_newton_step_is_below_float_spacing():
    """A near-linear quintic whose last Newton correction is smaller than the spacing of floats
    at the root (a rocking step through an impact): the root to rounding, from either side."""
    c = (1.44858649e-03, -3.51880060e-03, -1.53347102e-05, 4.09628242e-06, -1.11469536e-17,
         1.41454502e-18)
    u = sp.symbols("u")
    roots = sp.Poly(sum(sp.Float(ci, 30) * u**i for i, ci in enumerate(c)), u).nroots(n=30)
    exact = [float(sp.re(r)) for r in roots if abs(sp.im(r)) < 1e-20 and 0 < sp.re(r) < 1]
    assert len(exact) == 1
    for lo, hi in ((0.0, 1.0), (0.2, 0.9), (0.4, 0.5)):
        assert bracketed_root(*c, lo, hi, False) == pytest.approx(exact[0], abs=1e-15)


def test_rotation_peak_finds_every_extremum_above_the_running_peak():
    """The bound that lets rotation_peak skip an extremum never skips one above the running
    peak: against the interpolant sampled densely, with running peaks just below and just
    above each step's extremum."""
    rng = np.random.default_rng(21)
    h = 0.005
    uu = np.linspace(0.0, 1.0, 20001)
    tested = 0
    for _ in range(300):
        # theta_dot changes sign inside the step: omega = om0 + al * t + j t^2 / 2
        th0 = rng.normal() * 0.05
        al0 = rng.normal() * 10.0
        jerk = rng.normal() * 300.0
        t_turn = rng.uniform(0.05, 0.95) * h
        om0 = -(al0 * t_turn + 0.5 * jerk * t_turn**2)
        om1 = om0 + al0 * h + 0.5 * jerk * h * h
        if om0 * om1 >= 0.0:
            continue
        th1 = th0 + om0 * h + al0 * h * h / 2 + jerk * h**3 / 6
        al1 = al0 + jerk * h
        c = quintic_hermite(th0, om0, al0, th1, om1, al1, h)
        dense = np.abs(np.polynomial.Polynomial(c)(uu))
        if dense.argmax() == 0:
            continue  # the largest |theta| at the start: counted with the step before
        ext = dense.max()
        t0 = 1.0
        for factor in (1.0 - 1e-7, 1.0 + 1e-7):
            running = ext * factor
            peak, when = rotation_peak(running, -1.0, th0, om0, al0, th1, om1, al1, h, t0, t0 + h)
            if factor < 1.0:
                # an extremum (or the end) above the running peak is found, at its time
                assert peak == pytest.approx(ext, rel=1e-9, abs=1e-15)
                assert abs(when - (t0 + uu[dense.argmax()] * h)) <= 2.0 * h / 20000
            else:
                assert (peak, when) == (running, -1.0)
        tested += 1
    assert tested > 100


def _first_crossing(f, h, velocity=False, n=200001):
    """First sampled time at which f turns negative (brute force), or inf.

    The solver's convention for a function that starts on or below zero: no event if it has
    recovered by the end of the interval (a constraint being restored after a grazing contact);
    otherwise the event is due at once, except that a slip velocity starting at zero that
    first grows (a slip that has just started) stops where it comes back through zero.
    """
    s = np.linspace(0.0, h, n)
    v = f(s)
    if v[0] <= 0.0:
        if v[-1] >= 0.0:
            return np.inf
        rising = np.nonzero(v > 0.0)[0]
        if rising.size == 0 or not velocity:
            return 0.0
        v[: rising[0]] = 1.0  # it rose first: the event is where it comes back down
    neg = np.nonzero(v < 0.0)[0]
    return s[neg[0]] if neg.size else np.inf


def test_closed_form_event_roots_agree_with_dense_sampling():
    rng = np.random.default_rng(11)
    h = 0.005
    tol = h / 200000 * 1.01
    for _ in range(300):
        l0, l1, m0, m1 = rng.normal(size=4)
        r = linear_root(l0, l1, h)
        if l0 <= 0.0:
            # below zero at the start: due now if it falls, none while it recovers (a force
            # event at a shifted level whose mode was kept, issue 32)
            assert r == (0.0 if l1 < l0 else np.inf)
        else:
            ref = _first_crossing(lambda s, a=l0, b=l1: a + (b - a) * s / h, h)
            assert (np.isinf(r) and np.isinf(ref)) or abs(r - ref) <= tol
        r = min_linear_root(l0, l1, m0, m1, h)
        if l0 <= 0.0 or m0 <= 0.0:
            assert r == min(linear_root(l0, l1, h), linear_root(m0, m1, h))
        else:
            ref = _first_crossing(
                lambda s, a=l0, b=l1, c=m0, d=m1: np.minimum(a + (b - a) * s / h,
                                                             c + (d - c) * s / h), h)
            assert (np.isinf(r) and np.isinf(ref)) or abs(r - ref) <= tol
        # velocity-like: q(s) = q0 + d0 s + c s^2 with q0 >= 0 (the slip velocity in its direction)
        q0 = abs(rng.normal()) * 1e-3
        d0, cc = rng.normal() * 0.5, rng.normal() * 200.0
        r = quadratic_root(q0, d0, cc, h)
        ref = _first_crossing(lambda s, a=q0, b=d0, c=cc: a + b * s + c * s * s, h, True)
        assert (np.isinf(r) and np.isinf(ref)) or abs(r - ref) <= tol


def test_quadratic_root_on_the_boundary():
    h = 1.0
    # starts at zero and rises: no event; then comes back down at s = 0.5
    assert quadratic_root(0.0, 1.0, -2.0, h) == pytest.approx(0.5)
    assert quadratic_root(0.0, 1.0, 0.5, h) == np.inf
    # starts at zero and falls: the event is due at once
    assert quadratic_root(0.0, -1.0, 0.5, h) == 0.0
