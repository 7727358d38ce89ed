"""Sliding modes against closed forms and an independent exact Newmark integrator.

Cases 2-7 of the physics notes, section 7. Every reference value is a closed form derived in the
docstring or computed by ``tests/reference/newmark.py`` (plain Python, exact for
piecewise-linear input).
"""

import numpy as np
import pytest

from shipblock import ShipBlockSystem, simulate
from tests.reference.newmark import ground_pulse_kinematics, newmark_slip

G0 = 9.80665


def sliding_system(mu=0.2, ship_mass=1e6, mass_ratio=0.3, mu_ship=0.8, aspect=3.0, mu_s=None):
    """Blocks that slide but cannot rock (B/H = aspect) under a ship held by friction."""
    n = 50
    return ShipBlockSystem(
        ship_mass=ship_mass,
        block_mass=mass_ratio * ship_mass / n,
        n_blocks=n,
        half_width=0.5 * aspect,
        half_height=0.5,
        mu_s_ground=mu if mu_s is None else mu_s,
        mu_k_ground=mu,
        mu_s_ship=mu_ship,
        mu_k_ship=mu_ship,
    )


def rectangular_pulse(amplitude, n_pulse, n_total):
    a = np.zeros(n_total)
    a[: n_pulse + 1] = amplitude
    return a


@pytest.mark.parametrize("ship_mass", [1e3, 1e6])
@pytest.mark.parametrize("ay_const", [0.0, 0.25 * G0, -0.25 * G0])
def test_newmark_rectangular_pulse(ship_mass, ay_const):
    """Newmark (1965): a block on a ground pulse A slides until its velocity catches up.

    With friction mu and G = g + ay the block accelerates at mu G; the ground, after the pulse,
    moves at V. The block stops at t_s = V/(mu G) and its slip is
    d = D_p + V (t_s - t_p) - V^2/(2 mu G), which for a rectangular pulse is
    V^2/(2 mu G)(1 - mu G/A). The sampled pulse ends with a one-sample ramp, so V and D_p are
    those of the piecewise-linear input. The result does not depend on the ship mass while the
    ship sticks (mu_k1 <= mu_s2).
    """
    mu, dt = 0.2, 0.01
    system = sliding_system(mu=mu, ship_mass=ship_mass)
    A = 0.6 * G0
    a = rectangular_pulse(A, 30, 300)
    ay = np.full_like(a, ay_const)
    res = simulate(system, a, ay, dt)
    G = G0 + ay_const
    V, Dp = ground_pulse_kinematics(a[:32], dt)
    tp = 31 * dt
    t_stop = V / (mu * G)
    expected = -(Dp + V * (t_stop - tp) - V**2 / (2 * mu * G))
    assert res.failure is None
    assert res.x_b[-1] == pytest.approx(expected, rel=1e-10, abs=1e-13)
    assert np.all(res.x_s == 0.0)
    stops = res.events_of("ground_slip_stop")
    assert len(stops) == 1
    assert stops[0].time == pytest.approx(t_stop, abs=1e-10)
    # rectangular-pulse form, to the accuracy of the one-sample ramp
    t0 = 30.5 * dt
    rect = -(A * t0) ** 2 / (2 * mu * G) * (1 - mu * G / A)
    assert res.x_b[-1] == pytest.approx(rect, rel=2e-2)
    assert [e.kind for e in res.events] == ["start", "ground_slip_stop"]
    assert res.events[0].to_mode == 2


def test_half_sine_pulse_matches_exact_newmark():
    """A sampled half-sine pulse: shipblock vs the exact reference integrator at every sample."""
    dt = 0.005
    t = np.arange(0, 3.0, dt)
    a = np.where(t < 0.5, 0.5 * G0 * np.sin(np.pi * t / 0.5), 0.0)
    mu = 0.15
    res = simulate(sliding_system(mu=mu), a, None, dt)
    x_ref, v_ref = newmark_slip(a, None, dt, mu)
    np.testing.assert_allclose(res.x_b, x_ref, rtol=0, atol=1e-11)
    np.testing.assert_allclose(res.v_b, v_ref, rtol=0, atol=1e-11)
    assert abs(x_ref[-1]) > 0.05  # a real slip was compared


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_random_records_match_exact_newmark(seed):
    """Random two-component piecewise-linear records, two-way sliding, vs the exact reference."""
    rng = np.random.default_rng(seed)
    dt = 0.01
    n = 1500
    a = np.convolve(rng.normal(0, 3.0, n), np.ones(5) / 5, mode="same")
    ay = np.convolve(rng.normal(0, 1.5, n), np.ones(5) / 5, mode="same")
    mu = 0.2
    res = simulate(sliding_system(mu=mu), a, ay, dt)
    x_ref, _ = newmark_slip(a, ay, dt, mu)
    assert res.failure is None
    assert len(res.events_of("ground_slip_start")) > 10
    np.testing.assert_allclose(res.x_b, x_ref, rtol=0, atol=1e-9)


def test_ship_only_sliding_is_newmark_with_ship_friction():
    """Mode 4: blocks held by high friction, the ship slides as a Newmark block with mu_k2."""
    mu2, dt = 0.12, 0.01
    system = ShipBlockSystem(
        ship_mass=1e6, block_mass=3000.0, n_blocks=100, half_width=1.5, half_height=0.5,
        mu_s_ground=0.9, mu_k_ground=0.9, mu_s_ship=mu2, mu_k_ship=mu2,
    )
    A = 0.4 * G0
    a = rectangular_pulse(A, 25, 300)
    res = simulate(system, a, None, dt)
    V, Dp = ground_pulse_kinematics(a[:27], dt)
    t_stop = V / (mu2 * G0)
    expected = -(Dp + V * (t_stop - 26 * dt) - V**2 / (2 * mu2 * G0))
    assert res.x_s[-1] == pytest.approx(expected, rel=1e-10)
    assert np.all(res.x_b == 0.0)
    assert {e.to_mode for e in res.events} == {4, 1}


def test_two_layer_sliding_closed_form_and_mode_sequence():
    """Mode 5 under a pulse, blocks and ship both slide from t = 0, then 5 -> 4 -> 1.

    Absolute accelerations while both slide: ship mu2 G, blocks
    a_b = (mu1 (Mn+1) - mu2) G / Mn. The blocks catch the ground first at t_b = V/a_b, then the
    ship at t_s = V/(mu2 G):
    x_b = -V^2/(2 a_b) - D_p + V t_p and x_s = -V^2/2 (1/(mu2 G) - 1/a_b), which for a
    rectangular pulse are the notes' -V^2/2 (1/a_b - 1/A) and the same x_s.
    """
    mu1, mu2, Mn, dt = 0.5, 0.3, 0.2, 0.005
    n = 10
    M = 1e6
    system = ShipBlockSystem(
        ship_mass=M, block_mass=Mn * M / n, n_blocks=n, half_width=1.0, half_height=0.5,
        mu_s_ground=mu1, mu_k_ground=mu1, mu_s_ship=mu2, mu_k_ship=mu2,
    )
    A = 3.0 * G0
    a = rectangular_pulse(A, 20, 400)
    res = simulate(system, a, None, dt)
    V, Dp = ground_pulse_kinematics(a[:22], dt)
    tp = 21 * dt
    a_b = (mu1 * (Mn + 1) - mu2) * G0 / Mn
    t_b, t_s = V / a_b, V / (mu2 * G0)
    assert res.x_b[-1] == pytest.approx(-(V**2) / (2 * a_b) - Dp + V * tp, rel=1e-10)
    assert res.x_s[-1] == pytest.approx(-(V**2) / 2 * (1 / (mu2 * G0) - 1 / a_b), rel=1e-10)
    assert [e.to_mode for e in res.events] == [5, 4, 1]
    assert res.events[1].time == pytest.approx(t_b, abs=1e-10)
    assert res.events[2].time == pytest.approx(t_s, abs=1e-10)


@pytest.mark.parametrize("ay_const", [0.0, 0.25 * G0, -0.25 * G0])
def test_ramp_onset_times(ay_const):
    """Under a = k t the rest margins are linear in t; each onset happens at mu_s G/k or alpha G/k.

    Block slip at t1 = mu_s1 G/k when mu_s1 is the smallest of (mu_s1, mu_s2, B/H); after it, with
    mu_k1 < mu_s1, x_b(t) = -k (t^3 - t1^3)/6 + k t1^2 (t - t1)/2 + mu_k1 G (t - t1)^2/2.
    """
    k, dt = 2.0, 0.01
    G = G0 + ay_const
    t = np.arange(0, 2.0, dt)
    a = k * t
    ay = np.full_like(t, ay_const)
    base = dict(ship_mass=1e6, block_mass=2000.0, n_blocks=100, half_height=0.5)
    # block slip first
    s1 = ShipBlockSystem(**base, half_width=0.25, mu_s_ground=0.1, mu_k_ground=0.08,
                         mu_s_ship=0.4, mu_k_ship=0.4)
    r1 = simulate(s1, a, ay, dt)
    t1 = 0.1 * G / k
    assert r1.events[1].kind == "ground_slip_start"
    assert r1.events[1].time == pytest.approx(t1, abs=1e-10)
    te = t[-1]
    expected = -k * (te**3 - t1**3) / 6 + k * t1**2 * (te - t1) / 2 + 0.08 * G * (te - t1) ** 2 / 2
    assert r1.x_b[-1] == pytest.approx(expected, rel=1e-10)
    # ship slip first
    s2 = s1.replace(mu_s_ground=0.6, mu_k_ground=0.6, mu_s_ship=0.12, mu_k_ship=0.1)
    r2 = simulate(s2, a, ay, dt)
    assert r2.events[1].kind == "ship_slip_start"
    assert r2.events[1].time == pytest.approx(0.12 * G / k, abs=1e-10)
    # uplift first: alpha = B/H = 0.3
    s3 = s1.replace(half_width=0.15, mu_s_ground=0.6, mu_k_ground=0.6, mu_s_ship=0.6,
                    mu_k_ship=0.6)
    r3 = simulate(s3, a, ay, dt)
    assert r3.events[1].kind == "uplift"
    assert r3.events[1].time == pytest.approx(0.3 * G / k, abs=1e-10)
    assert r3.events[1].to_mode == 3
    # a ground pushed right tips the blocks counter-clockwise, and the growing ramp overturns them
    assert np.nanmin(r3.theta) >= 0 and np.nanmax(r3.theta) > 0
    assert r3.failure in (None, "overturning")


def test_sliding_mirror_symmetry():
    """ax -> -ax mirrors the response: x_b, theta, x_s change sign, the modes stay."""
    rng = np.random.default_rng(5)
    dt = 0.01
    a = np.convolve(rng.normal(0, 4.0, 800), np.ones(4) / 4, mode="same")
    ay = np.convolve(rng.normal(0, 1.0, 800), np.ones(4) / 4, mode="same")
    system = sliding_system(mu=0.2, mu_ship=0.22, mu_s=0.25)
    r_pos = simulate(system, a, ay, dt)
    r_neg = simulate(system, -a, ay, dt)
    np.testing.assert_allclose(r_neg.x_b, -r_pos.x_b, atol=1e-12)
    np.testing.assert_allclose(r_neg.x_s, -r_pos.x_s, atol=1e-12)
    np.testing.assert_array_equal(r_neg.mode, r_pos.mode)
    assert np.abs(r_pos.x_b).max() > 0.01


def test_event_log_is_a_sequence_of_events_and_reaches_the_dataset():
    """The lazily built event log behaves as a list of Event, and to_dataset carries it."""
    from shipblock.result import Event

    system = ShipBlockSystem(ship_mass=2e6, block_mass=1500.0, n_blocks=100, half_width=2.0,
                             half_height=0.5, mu_s_ground=0.1, mu_k_ground=0.1, mu_s_ship=0.8,
                             mu_k_ship=0.8)
    t = np.arange(0, 4, 0.01)
    res = simulate(system, 2.0 * np.sin(2 * np.pi * t), None, 0.01)
    events = list(res.events)
    assert len(events) == len(res.events) > 3
    assert all(isinstance(e, Event) for e in events)
    assert res.events[-1] == events[-1] and res.events[1:3] == events[1:3]
    assert [e.time for e in events] == sorted(e.time for e in events)
    assert {e.kind for e in events} >= {"start", "ground_slip_start", "ground_slip_stop"}
    ds = res.to_dataset()
    np.testing.assert_array_equal(ds["event_time"].values, [e.time for e in events])
    assert list(ds["event_kind"].values) == [e.kind for e in events]
