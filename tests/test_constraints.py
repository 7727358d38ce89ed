"""Every constraint of a mode holds wherever the solver keeps that mode (issue 32).

When a stick or uplift event fired and the mode selection chose the same mode again, the
solver used to switch the event off until its function climbed back above 1e-9; after a real
crossing it never did, and the interface stayed stuck beyond its friction limit (or the blocks
at rest with the resultant outside their base) for the rest of the run. Two routes led there,
each tested here as a class of motions, not as one reproducer:

* a crossing driven by the rotation itself (the mode selection looked at the candidates with
  the state frozen at the event): a rocking block whose ship interface reaches its friction
  limit in free rocking after a pulse;
* a crossing so slow that its violation is still within the force tolerance 1e-8 s after the
  event: a ramp of the input through the ground's friction limit or the blocks' uplift
  threshold.

Also: the forces at a sample where the blocks rock from theta = theta_dot = 0 (the pivot), and
the search for a pair of zero crossings of the rotation inside one step (hairline rocking).
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from shipblock import ShipBlockSystem, simulate
from shipblock.equations import I_FX, I_FY, I_SFX, I_SFY, I_TH_DD, N_SOLVE_OUT, solve_mode
from shipblock.modes import MODE_FLAGS
from shipblock.solver._interpolate import dip_possible, poly5, quintic_hermite, rotation_dip
from shipblock.solver._layout import FORCE_TOL

from .tools.random_campaign import KERNEL_ROUNDING, sample_margins

G0 = 9.80665


def _assert_constraints_hold(res):
    """The kernel's least margin and the margins recomputed at the samples, to FORCE_TOL."""
    assert res.summary["least_constraint_margin"] >= -FORCE_TOL - KERNEL_ROUNDING
    for name, margin in sample_margins(res).items():
        assert margin >= -FORCE_TOL - 1e-12, (name, margin)


def _slender_stack(ship_mass, mu_ship):
    """Slender blocks (B/H = 0.116) under a heavy ship, the ground's friction high."""
    return ShipBlockSystem(ship_mass=ship_mass, block_mass=1900.08, n_blocks=174,
                           half_width=0.14102, half_height=1.21685, mu_s_ground=0.46734,
                           mu_k_ground=0.46734, mu_s_ship=mu_ship, mu_k_ship=mu_ship,
                           impact_rule="plastic")


def _ship_friction_crossing(system, res, k, t_end):
    """Independent: the first time after sample ``k`` (in mode 3) at which the ship's friction
    demand reaches mu_s2 Fy, integrating mode 3 with scipy (rtol 1e-12) from the state there."""
    p = system.to_parameter_vector()
    out = np.zeros(N_SOLVE_OUT)
    th0, om0 = res.theta[k], res.theta_dot[k]
    s = 1.0 if (th0 > 0 or (th0 == 0 and om0 > 0)) else -1.0
    ax = res.ground_acceleration[0]

    def solve(t, y):
        a = np.interp(t, res.time, ax)
        assert solve_mode(p, 0, 1, 0, s, 1.0, 1.0, y[0], y[1], a, system.g, out)
        return out

    def rhs(t, y):
        return [y[1], solve(t, y)[I_TH_DD]]

    def margin(t, y):
        w = solve(t, y)
        return system.mu_s_ship * w[I_SFY] - abs(w[I_SFX])

    margin.terminal = True
    margin.direction = -1
    sol = solve_ivp(rhs, (res.time[k], t_end), [th0, om0], rtol=1e-12, atol=1e-16,
                    events=margin, max_step=1e-3)
    return sol.t_events[0][0]


def test_rotation_driven_ship_friction_limit():
    """Free rocking after a pulse drives the ship's friction to its limit: the ship slips there.

    For slender blocks under a heavy ship, the ship's friction demand in free rocking,
    |a + 2X'| / (G + 2Y') with a = 0, peaks near theta = 0 at about 0.11 g: a ship friction
    coefficient just below it is reached by the rotation itself. Over a family of such
    systems and pulses, every ship slip onset from mode 3 must leave mode 3 into a mode in
    which the ship slides, at the time an independent integration of mode 3 finds the limit,
    and no held condition may be violated anywhere (before the fix the onset re-selected
    mode 3 and the ship stayed stuck at up to 1.047 times its friction limit).
    """
    dt = 0.01
    t = np.arange(500) * dt
    onsets = 0
    for ship_mass in (1.2e7, 1.6948e7, 2.5e7):
        for mu_ship in (0.107, 0.11102, 0.114):
            for amp, dur in ((0.77, 0.08), (0.77, 0.09), (0.9, 0.06), (0.9, 0.07), (0.6, 0.15)):
                system = _slender_stack(ship_mass, mu_ship)
                res = simulate(system, np.where(t < dur, amp * G0, 0.0), None, dt)
                _assert_constraints_hold(res)
                for e in res.events:
                    if e.kind != "ship_slip_start" or e.from_mode != 3:
                        continue
                    onsets += 1
                    assert MODE_FLAGS[e.to_mode, 2] == 1, (ship_mass, mu_ship, amp, dur, e)
                    k = int(np.floor(e.time / dt))
                    before = [x for x in res.events if k * dt <= x.time < e.time]
                    if res.mode[k] == 3 and not before and abs(res.theta[k]) > 0:
                        t_ref = _ship_friction_crossing(system, res, k, e.time + 0.01)
                        assert t_ref == pytest.approx(e.time, abs=1e-7)
    # the family reaches what it is meant to test
    assert onsets >= 10


@pytest.mark.parametrize("ship_mass", [1e3, 1e6])
def test_slow_crossing_of_the_ground_friction_limit(ship_mass):
    """A ramp through mu_s g so slow that the violation 1e-8 s after the crossing is within the
    force tolerance: the blocks must still slide, once the violation reaches it.

    With ``a = mu g + k (t - t*)`` and ``mu_k = mu_s``, the ground's friction margin falls at
    ``k / g`` of the weight per second: by 1e-11 in 1e-8 s for ``k = 1e-3 g``/s. The slip
    must start within ``FORCE_TOL g / k`` = 1e-7 s of ``t*`` and then follow Newmark's closed
    form, ``x_b = -k (t - t*)^3 / 6``, whatever the ship (before the fix the blocks stayed
    stuck for good).
    """
    mu = 0.5
    system = ShipBlockSystem(ship_mass=ship_mass, block_mass=2000.0, n_blocks=50,
                             half_width=0.6, half_height=1.0, mu_s_ground=mu, mu_k_ground=mu,
                             mu_s_ship=0.9, mu_k_ship=0.9)
    dt, t_star, k = 0.01, 0.5, 1e-3 * G0
    t = np.arange(200) * dt
    res = simulate(system, mu * G0 + k * (t - t_star), None, dt)
    _assert_constraints_hold(res)
    onset = [e for e in res.events if e.kind == "ground_slip_start" and e.to_mode == 2]
    assert len(onset) == 1
    assert t_star <= onset[0].time <= t_star + FORCE_TOL * G0 / k * 1.001
    late = t > t_star + 0.1
    np.testing.assert_allclose(res.x_b[late], -k * (t[late] - t_star) ** 3 / 6, rtol=1e-5)


def test_slow_crossing_of_the_uplift_threshold():
    """The same for the blocks' moment criterion: a ramp through a = (B/H) G, friction high.

    The blocks must start rocking within the tolerance's time after the threshold
    (FORCE_TOL (nm + M) g R / ((nm + M) H k) = FORCE_TOL R g / (H k) s), never rest beyond it.
    """
    system = ShipBlockSystem(ship_mass=5e5, block_mass=2000.0, n_blocks=20, half_width=0.3,
                             half_height=1.2, mu_s_ground=0.9, mu_k_ground=0.9, mu_s_ship=0.9,
                             mu_k_ship=0.9)
    dt, t_star, k = 0.01, 0.3, 1e-3 * G0
    t = np.arange(60) * dt
    res = simulate(system, 0.25 * G0 + k * (t - t_star), None, dt)
    _assert_constraints_hold(res)
    uplift = [e for e in res.events if e.kind == "uplift" and MODE_FLAGS[e.to_mode, 1]]
    assert len(uplift) == 1
    R = system.half_diagonal
    late = FORCE_TOL * R * G0 / (system.half_height * k)
    assert t_star <= uplift[0].time <= t_star + late * 1.001
    assert res.summary["uplift"] and res.theta[-1] > 0


@pytest.mark.parametrize("sign", [1.0, -1.0])
def test_forces_at_a_rocking_start_take_the_pivot(sign):
    """At t = 0 the blocks rock from theta = theta_dot = 0 (the input exceeds the uplift
    threshold at once): the forces there are those of the pivot the rotation starts on, so a
    run and its mirror image have the same normal forces and utilisations and opposite
    friction at every sample, t = 0 included (the pivot used to be taken as +1 there)."""
    system = ShipBlockSystem(ship_mass=2e6, block_mass=2000.0, n_blocks=50, half_width=0.2,
                             half_height=1.0, mu_s_ground=0.6, mu_k_ground=0.6, mu_s_ship=0.5,
                             mu_k_ship=0.5)
    ax = np.full(100, 0.4 * G0)
    res = simulate(system, ax, None, 0.01)
    mirror = simulate(system, sign * ax, None, 0.01)
    assert res.mode[0] == 3 and res.theta[0] == 0.0 and res.theta_dot[0] == 0.0
    f, fm = res.forces, mirror.forces
    for name in ("ground_normal", "ship_normal", "ground_utilisation", "ship_utilisation"):
        np.testing.assert_allclose(getattr(fm, name), getattr(f, name), rtol=1e-12)
    for name in ("ground_friction", "ship_friction"):
        np.testing.assert_allclose(getattr(fm, name), sign * getattr(f, name), rtol=1e-12)
    # and at t = 0 they are mode 3's at theta = theta_dot = 0 on the left corner (s = +1)
    w = np.zeros(N_SOLVE_OUT)
    assert solve_mode(system.to_parameter_vector(), 0, 1, 0, 1.0, 1.0, 1.0, 0.0, 0.0, ax[0],
                      system.g, w)
    n = system.n_blocks
    np.testing.assert_allclose([f.ground_friction[0], f.ground_normal[0], f.ship_friction[0],
                                f.ship_normal[0]],
                               np.array([w[I_FX], w[I_FY], w[I_SFX], w[I_SFY]]) / n, rtol=1e-12)


def _dip_step(roots, h, lift=0.0):
    """A step of length ``h`` whose rotation is the quartic ``-(t - r1)(t - r2)(t - r3)(t - r4)``
    at the scale of 1e-9 rad (plus ``lift``): its ends, rates and accelerations, and the
    quartic."""
    poly = np.poly1d(np.poly(roots)) * (-1e-9 / h ** 4) + lift
    d1, d2 = poly.deriv(), poly.deriv(2)
    return (poly(0.0), d1(0.0), d2(0.0), poly(h), d1(h), d2(h)), poly


@pytest.mark.parametrize("s", [1.0, -1.0])
def test_a_pair_of_crossings_inside_one_step_is_found(s):
    """A hairline rotation that crosses zero and comes back within 0.1 ms of a 10 ms step, on
    the pivot's side and heading the same way at both ends (no end shows it, and the
    double-crossing test of the end slopes does not apply): the interpolant's dip is found, at
    a point where the rotation is below zero, after a point where it is above."""
    h = 0.01
    # crossings at 4.0 and 4.1 ms, above zero elsewhere, falling at both ends
    (th0, om0, al0, th1, om1, al1), poly = _dip_step([0.004, 0.0041, -0.002, 0.011], h)
    assert th0 > 0 and th1 > 0 and om0 < 0 and om1 < 0
    args = (s * th0, s * om0, s * al0, s * th1, s * om1, s * al1)
    assert dip_possible(s, args[0], args[2], args[3], args[5], h)
    u, u_top = rotation_dip(s, *args, h)
    assert 0.004 < u * h < 0.0041
    assert poly(u * h) < 0 and poly(u_top * h) > 0 and 0 <= u_top < u
    c = quintic_hermite(*args, h)
    assert s * poly5(*c, u) < 0
    # the same rotation lifted clear of zero: no dip
    (th0, om0, al0, th1, om1, al1), _ = _dip_step([0.004, 0.0041, -0.002, 0.011], h, lift=1e-9)
    assert rotation_dip(s, s * th0, s * om0, s * al0, s * th1, s * om1, s * al1, h)[0] < 0


def test_a_dip_after_an_impact_is_found():
    """A step that starts at zero (an impact just before), goes out, comes back through zero
    and out again: the dip is found after the step's own maximum."""
    h = 0.01
    (th0, om0, al0, th1, om1, al1), poly = _dip_step([0.0, 0.006, 0.0062, 0.02], h)
    assert th0 == 0.0 and om0 > 0
    u, u_top = rotation_dip(1.0, th0, om0, al0, th1, om1, al1, h)
    assert 0.006 < u * h < 0.0062 and 0 < u_top * h < 0.006 and poly(u_top * h) > 0
