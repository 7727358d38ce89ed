"""The rocking mode on two stuck interfaces in its reduced form, and the solver's step for it.

:func:`shipblock.equations.stuck_rocking_rates` must be the general equations of mode 3
(symbolically, from the independent derivation in ``sympy_model``, and numerically, against
:func:`~shipblock.equations.solve_mode`), and the solver's mode-3 step
(:mod:`shipblock.solver._stuck_rocking`) the same Dormand-Prince step as the general one.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from numba import njit

from shipblock import ShipBlockSystem
from shipblock.equations import (
    I_FX,
    I_FY,
    I_SFX,
    I_SFY,
    I_TH_DD,
    N_SOLVE_OUT,
    input_power,
    solve_mode,
    stuck_rocking_gain,
    stuck_rocking_rates,
)
from shipblock.solver._events import event_functions, stuck_rocking_clear
from shipblock.solver._fused import fma
from shipblock.solver._kernel import advance, advance_general, error_norm
from shipblock.solver._layout import (
    MS_ROCK,
    MS_S,
    MS_SIG1,
    MS_SIG2,
    N_EVENTS,
    N_STATE,
    Y_OM,
    Y_TH,
    Y_WIN,
    parameter_tuple,
)
from shipblock.solver._stuck_rocking import (
    SHORT_ANGLE,
    SMALL_ANGLE,
    locate_impact,
    rotating_step,
    short_angle_sincos,
    small_angle_sincos,
    stuck_step,
)
from shipblock.system import P_G, P_M, P_NM, P_R, P_THC

try:  # tests/ as a package or as a plain directory
    from . import sympy_model as sm
except ImportError:
    import sympy_model as sm


def test_reduced_equation_is_mode_3_of_the_independent_derivation():
    """theta'' of mode 3 (Lagrange derivation) == (nm+2M)R (c a - s sn G) / (nI + (nm+4M)R^2)."""
    reduced = ((sm.nm + 2 * sm.M) * sm.R * (sm.cphi * sm.a - sm.s * sm.sphi * sm.G)
               / (sm.nI + (sm.nm + 4 * sm.M) * sm.R**2))
    assert sm.is_identity(sm.mode_solution(3)[sm.thdd] - reduced)
    # a sign error in either term would not be an identity
    wrong = ((sm.nm + 2 * sm.M) * sm.R * (sm.cphi * sm.a + sm.s * sm.sphi * sm.G)
             / (sm.nI + (sm.nm + 4 * sm.M) * sm.R**2))
    assert not sm.is_identity(sm.mode_solution(3)[sm.thdd] - wrong)


def _random_system(rng):
    return ShipBlockSystem(
        ship_mass=rng.uniform(1e4, 1e7), block_mass=rng.uniform(100.0, 5000.0),
        n_blocks=int(rng.integers(1, 200)), half_width=rng.uniform(0.05, 1.0),
        half_height=rng.uniform(0.2, 2.0), mu_s_ground=0.9, mu_k_ground=0.8, mu_s_ship=0.9,
        mu_k_ship=0.8)


def test_reduced_rates_equal_general_solve():
    rng = np.random.default_rng(3)
    out = np.empty(N_SOLVE_OUT)
    for _ in range(400):
        system = _random_system(rng)
        p = system.to_parameter_vector()
        s = float(rng.choice([-1.0, 1.0]))
        th = s * rng.uniform(0.0, system.critical_angle)
        om = rng.uniform(-3.0, 3.0)
        a, ay = rng.uniform(-10.0, 10.0, 2)
        assert solve_mode(p, 0, 1, 0, s, 1.0, 1.0, th, om, a, p[P_G] + ay, out)
        phi = p[P_THC] - s * th
        al, power = stuck_rocking_rates(p, stuck_rocking_gain(p), math.cos(phi), math.sin(phi),
                                        s, om, a, ay)
        scale = stuck_rocking_gain(p) * (abs(a) + p[P_G] + abs(ay)) + 1e-300
        assert abs(al - out[I_TH_DD]) <= 1e-12 * scale
        ref = input_power(p, th, s, 1, 0.0, om, 0.0, a, ay)
        pscale = (p[P_NM] + 2 * p[P_M]) * p[P_R] * abs(om) * (abs(a) + abs(ay)) + 1e-300
        assert abs(power - ref) <= 1e-13 * pscale


def test_small_angle_sincos():
    d = np.linspace(-SMALL_ANGLE, SMALL_ANGLE, 20001)
    for x in d:
        sn, cs = small_angle_sincos(x)
        assert abs(sn - math.sin(x)) <= 2.5e-16 * max(abs(x), 1e-300) + 1e-300
        assert abs(cs - math.cos(x)) <= 2.5e-16


def test_short_angle_sincos():
    """The short series of the usual step agrees with the library to rounding."""
    for x in np.linspace(-SHORT_ANGLE, SHORT_ANGLE, 20001):
        sn, cs = short_angle_sincos(x)
        assert abs(sn - math.sin(x)) <= 2.5e-16 * max(abs(x), 1e-300) + 1e-300
        assert abs(cs - math.cos(x)) <= 1.2e-16


@njit
def _fma(a, b, c):
    return fma(a, b, c)


def test_fma_rounds_once():
    """0.1 * 10 - 1 is 0 with two roundings and the exact 2**-54 with one."""
    assert 0.1 * 10.0 - 1.0 == 0.0
    assert _fma(0.1, 10.0, -1.0) == 2.0**-54
    x = 1.0 + 2.0**-30
    assert _fma(x, x, -(x * x)) == 2.0**-60  # the square's rounding error, exactly
    assert _fma(2.0, 3.0, 1.0) == 7.0


@njit
def _both_steps(p_vec, ms, y0, k, tau, h, dt, ax, ay, has_ay, first_known, rtol, atol):
    """The mode-3 step through advance() and the general step, from the same start."""
    p = parameter_tuple(p_vec)
    n = y0.size
    st_a = np.zeros((7, n))
    st_b = np.zeros((7, n))
    y1a = np.empty(n)
    y1b = np.empty(n)
    ytmp = np.empty(n)
    w7a = np.empty(N_SOLVE_OUT)
    w7b = np.empty(N_SOLVE_OUT)
    if first_known:
        # the first stage as a previous step would have left it
        advance_general(p, ms, y0, k, tau, 0.5 * h, dt, ax, ay, has_ay, 1.0, 1.0, y1a, st_a,
                        ytmp, w7a, False)
        for i in range(n):
            st_b[0, i] = st_a[0, i]
    err_a = advance(p, ms, y0, k, tau, h, dt, ax, ay, has_ay, 1.0, 1.0, y1a, st_a, ytmp, w7a,
                    first_known, rtol, atol)
    advance_general(p, ms, y0, k, tau, h, dt, ax, ay, has_ay, 1.0, 1.0, y1b, st_b, ytmp, w7b,
                    first_known)
    err_b = error_norm(y0, y1b, st_b, h, rtol, atol)
    return y1a, y1b, st_a[0].copy(), st_b[0].copy(), st_a[6].copy(), st_b[6].copy(), w7a, w7b, \
        err_a, err_b


@pytest.mark.parametrize("first_known", [False, True])
def test_mode_3_step_equals_general_step(first_known):
    """Same state, rates, forces and error norm to rounding, in small and large rotations."""
    rng = np.random.default_rng(11)
    n_large = 0
    for trial in range(300):
        system = _random_system(rng)
        p = system.to_parameter_vector()
        s = float(rng.choice([-1.0, 1.0]))
        dt = float(rng.choice([0.005, 0.01, 0.02]))
        ax = rng.uniform(-8.0, 8.0, 4)
        ay = rng.uniform(-3.0, 3.0, 4)
        has_ay = bool(trial % 2)
        y0 = np.zeros(N_STATE)
        y0[Y_TH] = s * rng.uniform(0.0, 0.9 * system.critical_angle)
        # angular velocities up to 40 rad/s: stages beyond SMALL_ANGLE take their own sine
        om_max = 40.0 if trial % 3 == 0 else 3.0
        y0[Y_OM] = rng.uniform(-om_max, om_max)
        y0[Y_WIN] = rng.uniform(0.0, 1e5)
        y0[0] = rng.uniform(-0.1, 0.1)  # slip displacements ride along unchanged
        y0[2] = rng.uniform(-0.1, 0.1)
        ms = np.zeros(6, np.int64)
        ms[MS_ROCK] = 1
        ms[MS_S] = int(s)
        ms[MS_SIG1] = 1
        ms[MS_SIG2] = -1
        tau = rng.uniform(0.0, 0.5) * dt
        h = rng.uniform(0.01, 1.0) * (dt - tau)
        n_large += abs(y0[Y_OM]) * h > SMALL_ANGLE
        y1a, y1b, s0a, s0b, s6a, s6b, w7a, w7b, err_a, err_b = _both_steps(
            p, ms, y0, 1, tau, h, dt, ax, ay, has_ay, first_known, 1e-8, 1e-10)
        scale = np.abs(y1b) + np.abs(y0) + 1e-12
        assert np.all(np.abs(y1a - y1b) <= 1e-13 * scale)
        for ra, rb in ((s0a, s0b), (s6a, s6b)):
            assert np.all(np.abs(ra - rb) <= 1e-12 * (np.abs(rb) + np.abs(rb).max() * 1e-3
                                                      + 1e-12))
        fscale = (p[P_M] + p[P_NM]) * (p[P_G] + 10.0)
        for i in (I_FX, I_FY, I_SFX, I_SFY):
            assert abs(w7a[i] - w7b[i]) <= 1e-12 * fscale
        # the error estimate is a small difference of stage sums: agreement to its own
        # rounding, i.e. relative to the sum's terms, not to the estimate
        assert abs(err_a - err_b) <= 1e-6 * max(err_b, 1e-3 * (1 + err_b))
    assert n_large > 10  # the large-rotation branch was exercised


def _general_theta(p, ms, y0, k, tau, h, dt, ax, ay):
    """theta, theta_dot and input work after the general step of ``h`` from ``y0``."""
    n = y0.size
    y1 = np.empty(n)
    advance_general(p, ms, y0, k, tau, h, dt, ax, ay, True, 1.0, 1.0, y1, np.zeros((7, n)),
                    np.empty(n), np.empty(N_SOLVE_OUT), False)
    return y1[Y_TH], y1[Y_OM], y1[Y_WIN]


@pytest.mark.parametrize("from_zero", [False, True])
def test_impact_is_located_at_the_integrators_own_root(from_zero):
    """locate_impact returns where the step's own solution reaches theta = 0, and the state there.

    Reference: bisection to 1e-15 s on the general step of the kernel (the 7x7 solve per stage)
    from the same start, taken over the trial length, which is what the kernel's root search
    does. Either the usual crossing (theta heading into zero) or, just after an impact, the
    rotation leaving zero and falling back within the step (``from_zero``): the root sought is
    then the second one, not the start.
    """
    rng = np.random.default_rng(5 + from_zero)
    checked = 0
    for _ in range(200):
        system = _random_system(rng)
        p_vec = system.to_parameter_vector()
        p = parameter_tuple(p_vec)
        s = float(rng.choice([-1.0, 1.0]))
        dt = float(rng.choice([0.005, 0.01, 0.02]))
        ax = rng.uniform(-3.0, 3.0, 3)
        ay = rng.uniform(-2.0, 2.0, 3)
        gain = stuck_rocking_gain(p)
        tau = float(rng.choice([0.0, rng.uniform(0.0, 0.8) * dt]))
        h = dt - tau
        f0 = tau / dt
        a0, da, b0, db = ax[1], ax[2] - ax[1], ay[1], ay[2] - ay[1]
        # restoring acceleration scale at theta = 0, to pick motions that reach zero in the step
        pull = gain * (p[P_G] * math.sin(p[P_THC]) + 3.0)
        if from_zero:
            th0, om0 = 0.0, s * rng.uniform(0.05, 0.4) * pull * h
        else:
            om0 = -s * rng.uniform(0.5, 5.0) * pull * h
            th0 = -om0 * rng.uniform(0.2, 0.9) * h
        phi = p[P_THC] - s * th0
        c, sn = math.cos(phi), math.sin(phi)
        al, pw = stuck_rocking_rates(p, gain, c, sn, s, om0, a0 + da * f0, b0 + db * f0)
        th1, om1, w1, al1, *_ = stuck_step(p, gain, s, c, sn, th0, om0, 0.0, al, pw, a0, da, b0,
                                           db, f0, 1.0 - f0, h)
        if not s * th1 < 0.0:
            continue  # no impact within this step
        ok, t, th_i, om_i, w_i, _ = locate_impact(p, gain, s, c, sn, th0, om0, 0.0, al, pw, th1,
                                                  om1, al1, a0, da, b0, db, f0, h, dt)
        assert ok
        ms = np.zeros(6, np.int64)
        ms[MS_ROCK] = 1
        ms[MS_S] = int(s)
        y0 = np.zeros(N_STATE)
        y0[Y_TH] = th0
        y0[Y_OM] = om0
        # bisection on the general step: theta of the step's solution changes sign in (lo, hi)
        lo = 0.0
        if from_zero:
            # past the turn: theta_dot has the sign of the return there
            lo = 0.5 * t
            assert s * _general_theta(p, ms, y0, 1, tau, lo, dt, ax, ay)[0] > 0.0
        hi = h
        while hi - lo > 1e-15:
            mid = 0.5 * (lo + hi)
            if s * _general_theta(p, ms, y0, 1, tau, mid, dt, ax, ay)[0] > 0.0:
                lo = mid
            else:
                hi = mid
        assert abs(t - lo) <= 2e-12
        th_r, om_r, w_r = _general_theta(p, ms, y0, 1, tau, t, dt, ax, ay)
        assert abs(th_i) <= 1e-15 + 1e-12 * abs(om0)
        assert abs(th_r) <= 2e-12 * abs(om_r)  # the reference's own theta at t: near zero too
        assert abs(om_i - om_r) <= 1e-12 * (abs(om0) + abs(al) * h)
        assert abs(w_i - w_r) <= 1e-11 * abs(w_r) + 1e-6
        assert s * om_i < 0.0  # arriving at the impact
        checked += 1
    assert checked > 40


def test_rotating_step_agrees_with_the_angle_form():
    """The whole-sample step with the geometry as states is the same method to truncation error.

    From random mode-3 states, one step of rotating_step and of stuck_step (angle form): the
    same rotation, angular velocity and input work within the step's own error estimate, and a
    geometry that stays on the unit circle and equals cos/sin(theta_c - s theta) at the step's
    end within that estimate too (the angle form's geometry is exact for its theta, whose own
    truncation error is of that size). A sign error in either geometry rate would put the
    geometry off by the step's rotation (~1e-3), far outside these bounds.
    """
    rng = np.random.default_rng(17)
    for _ in range(300):
        system = _random_system(rng)
        p = parameter_tuple(system.to_parameter_vector())
        s = float(rng.choice([-1.0, 1.0]))
        dt = float(rng.choice([0.005, 0.01, 0.02]))
        gain = stuck_rocking_gain(p)
        th0 = s * rng.uniform(0.05, 0.9) * p[P_THC]
        om0 = rng.uniform(-3.0, 3.0)
        a0, a1, b0, b1 = rng.uniform(-5.0, 5.0, 4)
        phi = p[P_THC] - s * th0
        c, sn = math.cos(phi), math.sin(phi)
        al, pw = stuck_rocking_rates(p, gain, c, sn, s, om0, a0, b0)
        ref = stuck_step(p, gain, s, c, sn, th0, om0, 10.0, al, pw, a0, a1 - a0, b0, b1 - b0, 0.0,
                         1.0, dt)
        new = rotating_step(p, gain, s, c, sn, th0, om0, 10.0, al, pw, a0, a1 - a0, b0, b1 - b0,
                            dt)
        th1, om1, w1, _, _, u1, v1, e_th, e_om = new
        # both are 5th-order solutions: they differ by less than the 4th-order error estimate
        assert abs(th1 - ref[0]) <= abs(e_th) + abs(ref[7]) + 1e-15
        assert abs(om1 - ref[1]) <= abs(e_om) + abs(ref[8]) + 1e-14 * abs(om0)
        assert abs(w1 - ref[2]) <= 1e-6 * (abs(w1 - 10.0) + 1e-9)
        # the geometry leaves the circle, and the angle, by the step's truncation error only
        bound = abs(e_th) + dt * abs(e_om) + 1e-15
        phi1 = p[P_THC] - s * th1
        assert abs(u1 * u1 + v1 * v1 - 1.0) <= bound
        assert abs(u1 - math.cos(phi1)) <= bound and abs(v1 - math.sin(phi1)) <= bound


def test_stuck_rocking_screen_agrees_with_the_event_functions():
    """The span's screen of a mode-3 step (signs of the numerators) says 'clear' exactly when
    every event function of mode 3 is >= 0: random forces and rotations around each boundary
    (friction cones, normal forces, theta = 0 and theta_c) on both pivots."""
    system = ShipBlockSystem(ship_mass=2e4, block_mass=1500.0, n_blocks=4, half_width=0.15,
                             half_height=0.6, mu_s_ground=0.6, mu_k_ground=0.5,
                             mu_s_ship=0.4, mu_k_ship=0.3)
    p = parameter_tuple(system.to_parameter_vector())
    rng = np.random.default_rng(17)
    g = np.empty(N_EVENTS)
    y = np.zeros(N_STATE)
    seen = set()
    for trial in range(4000):
        s = 1 if trial % 2 else -1
        ms = np.zeros(6, np.int64)
        ms[MS_ROCK] = 1
        ms[MS_S] = s
        weight = (system.total_block_mass + system.ship_mass) * system.g
        fy = rng.normal(1.0, 0.6) * weight
        Fy = rng.normal(1.0, 0.6) * system.ship_mass * system.g
        # horizontal forces near the friction limits
        fx = rng.choice([-1, 1]) * system.mu_s_ground * abs(fy) * rng.uniform(0.8, 1.2)
        Fx = rng.choice([-1, 1]) * system.mu_s_ship * abs(Fy) * rng.uniform(0.8, 1.2)
        theta = s * system.critical_angle * rng.uniform(-0.2, 1.2)
        y[Y_TH] = theta
        event_functions(p, ms, y, fx, fy, Fx, Fy, g)
        clear = stuck_rocking_clear(p, float(s), theta, fx, fy, Fx, Fy)
        assert clear == bool(np.all(g >= 0.0)), (trial, g)
        seen.update((clear, int(e)) for e in np.nonzero(g < 0.0)[0])
        seen.add((clear, -1))
    # both verdicts, and each of the six mode-3 constraints violated at least once
    assert {c for c, _ in seen} == {True, False}
    assert len({e for c, e in seen if e >= 0}) == 6
