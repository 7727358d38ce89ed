"""Rocking, impact, failure and energy: closed forms, quadratures and invariants.

Cases 8-13 of the physics notes, section 7, each checked against a reference computed here from
first principles (energy quadrature with scipy), never from shipblock's own output.
"""

import math

import numpy as np
import pytest
from scipy.integrate import quad

from shipblock import ShipBlockSystem, simulate, system_restitution
from shipblock.impact import impact_velocities

G0 = 9.80665
TIGHT = dict(rtol=1e-11, atol=1e-13)


def rocking_system(ship_mass=1e-6, n=1, m=1000.0, B=0.2, H=1.0, mu=10.0, **kw):
    """Blocks held by friction (mu = 10) so they only rock; tiny ship mass = Housner's block."""
    return ShipBlockSystem(
        ship_mass=ship_mass, block_mass=m, n_blocks=n, half_width=B, half_height=H,
        mu_s_ground=mu, mu_k_ground=mu, mu_s_ship=mu, mu_k_ship=mu, **kw,
    )


def rocking_constants(system):
    """J = nI + (nm+4M)R^2 and W = (nm+2M) g R of the single-DOF rocking motion."""
    M, nm = system.ship_mass, system.total_block_mass
    R = system.half_diagonal
    J = system.n_blocks * system.inertia + (nm + 4 * M) * R**2
    W = (nm + 2 * M) * system.g * R
    return J, W


def quarter_time(theta_k, alpha, J, W):
    """Time from rest at theta_k to theta = 0 under gravity alone (energy quadrature).

    Energy: J w^2 / 2 = W (cos(alpha - theta_k) - cos(alpha - theta)); substitute
    theta = theta_k (1 - u^2) to remove the inverse-square-root singularity at theta_k.
    """

    def integrand(u):
        th = theta_k * (1 - u * u)
        de = math.cos(alpha - theta_k) - math.cos(alpha - th)
        return 2 * theta_k * u / math.sqrt(2 * W / J * de) if de > 0 else 0.0

    val, _ = quad(integrand, 0.0, 1.0, epsabs=1e-14, epsrel=1e-13, limit=200)
    return val


def free_rocking_reference(theta0, alpha, e, J, W, n_impacts):
    """Impact times and amplitudes of free rocking from rest at theta0.

    Amplitude recursion (energy after an impact scales with e^2):
    cos(alpha - theta_{k+1}) = cos(alpha) + e^2 (cos(alpha - theta_k) - cos(alpha)).
    """
    times, amps = [], [theta0]
    t = quarter_time(theta0, alpha, J, W)
    times.append(t)
    th = theta0
    for _ in range(n_impacts - 1):
        c = math.cos(alpha) + e * e * (math.cos(alpha - th) - math.cos(alpha))
        th = alpha - math.acos(c)
        amps.append(th)
        t += 2 * quarter_time(th, alpha, J, W)
        times.append(t)
    return np.array(times), np.array(amps)


@pytest.mark.parametrize("tolerances", [TIGHT, {}], ids=["tight", "default"])
@pytest.mark.parametrize("ship_mass,n", [(1e-6, 1), (2e4, 4)])
def test_free_rocking_impact_times(ship_mass, n, tolerances):
    """Housner (1963) free rocking (ship mass -> 0), and the compound block + ship pendulum.

    Impact times from the energy quadrature with the system restitution; the ship is lumped into
    J = nI + (nm+4M)R^2 and W = (nm+2M) g R (notes section 5). At the default tolerance the
    rocking is stepped a sample at a time and the impacts are located inside those steps
    (``locate_impact``); at the tight one, by the kernel's own root search.
    """
    system = rocking_system(ship_mass=ship_mass, n=n)
    alpha = system.critical_angle
    J, W = rocking_constants(system)
    e = system.effective_restitution
    if ship_mass < 1:
        assert e == pytest.approx(1 - 1.5 * math.sin(alpha) ** 2, abs=1e-9)  # Housner
    dt = 0.01
    theta0 = 0.6 * alpha
    res = simulate(system, np.zeros(800), None, dt, initial_state=(0, theta0, 0, 0, 0, 0),
                   **tolerances)
    impacts = np.array([ev.time for ev in res.events_of("impact")])
    ref, amps = free_rocking_reference(theta0, alpha, e, J, W, 12)
    assert len(impacts) >= 12
    np.testing.assert_allclose(impacts[:12], ref, rtol=0, atol=1e-8)
    # the rotation changes sign at every impact: negative between the 3rd and 4th
    mid = 0.5 * (impacts[2] + impacts[3])
    assert np.interp(mid, res.time, res.theta) < 0
    # amplitudes follow the recursion (peak after the 2nd impact is amps[2])
    window = (res.time > impacts[1]) & (res.time < impacts[2])
    assert np.abs(res.theta[window]).max() == pytest.approx(amps[2], rel=2e-3)
    assert res.failure is None


def test_zeno_rocking_ends_at_rest():
    """Impacts of a decaying rocking accumulate in finite time; the run must end at rest."""
    system = rocking_system(restitution=0.7)
    res = simulate(system, np.zeros(1500), None, 0.01, initial_state=(0, 0.1, 0, 0, 0, 0))
    stops = res.events_of("rocking_stop")
    assert len(stops) == 1
    assert res.mode[-1] == 1
    assert res.theta[-1] == 0.0 and res.theta_dot[-1] == 0.0
    # with e = 0.7 the number of impacts to fall from ~0.3 rad/s below 1e-7 rad/s is ~40
    assert 20 < len(res.events_of("impact")) < 80


def test_restitution_formula():
    """e_sys = 1 - 1.5 sin^2(alpha) (Mn+4)/(Mn+3) for uniform blocks (notes section 5)."""
    alpha = 0.2
    assert system_restitution(1e12, alpha) == pytest.approx(1 - 1.5 * math.sin(alpha) ** 2)
    assert system_restitution(1e-12, alpha) == pytest.approx(math.cos(2 * alpha))
    for mn in (0.02, 0.5, 3.0):
        expected = 1 - 1.5 * math.sin(alpha) ** 2 * (mn + 4) / (mn + 3)
        assert system_restitution(mn, alpha) == pytest.approx(expected, rel=1e-13)
    # the notes' worked values
    assert system_restitution(0.02, 0.2) == pytest.approx(0.921, abs=5e-4)
    assert system_restitution(0.5, 0.2) == pytest.approx(0.924, abs=5e-4)
    assert system_restitution(0.02, 0.675) == pytest.approx(0.220, abs=5e-4)
    assert system_restitution(0.5, 0.675) == pytest.approx(0.247, abs=5e-4)
    assert system_restitution(0.1, 1.2) == 0.0  # squat block under a heavy ship stops


def test_restitution_equals_angular_momentum_about_new_pivot():
    """Plastic impact with the ship lumped at the new contact corner: angular momentum about P2.

    Pre-impact (pivot P1 = (-B,-H), w < 0): L = [nI + nm(H^2-B^2) + 4M(H^2-B^2)] w; post:
    [nI + (nm + 4M) R^2] w+. The ratio must equal the system restitution (sticking interfaces).
    """
    system = rocking_system(ship_mass=5e3, n=3, B=0.3, H=0.7)
    B, H, R = 0.3, 0.7, system.half_diagonal
    nI, nm, M = 3 * system.inertia, system.total_block_mass, system.ship_mass
    ratio = (nI + (nm + 4 * M) * (H * H - B * B)) / (nI + (nm + 4 * M) * R * R)
    _, w_after, _, loss = impact_velocities(system, -1.0)
    assert w_after == pytest.approx(-ratio, rel=1e-13)
    assert loss > 0


@pytest.mark.parametrize("slip", ["ground", "ship", "both"])
def test_momentum_impact_rule_conserves_slip_momenta_and_never_gains_energy(slip):
    """Impulses at slipping interfaces are frictionless: their conjugate momenta are conserved."""
    system = rocking_system(ship_mass=5e3, n=3, B=0.3, H=0.7)
    vb = 0.3 if slip in ("ground", "both") else 0.0
    vs = -0.2 if slip in ("ship", "both") else 0.0
    M, nm, H = system.ship_mass, system.total_block_mass, system.half_height
    w = -0.8
    vb2, w2, vs2, loss = impact_velocities(system, w, vb, vs)
    assert w2 == pytest.approx(system.effective_restitution * w)
    if vb:
        px = lambda b, o, s: (nm + M) * b - (nm + 2 * M) * H * o + M * s  # noqa: E731
        assert px(vb2, w2, vs2) == pytest.approx(px(vb, w, vs), rel=1e-12)
    if vs:
        ps = lambda b, o, s: M * b - 2 * M * H * o + M * s  # noqa: E731
        assert ps(vb2, w2, vs2) == pytest.approx(ps(vb, w, vs), rel=1e-12)
    assert loss >= 0.0
    # the paper's rule keeps slip velocities and can create energy in the same situation
    paper = system.replace(impact_rule="paper")
    vb3, w3, vs3, loss3 = impact_velocities(paper, w, vb, vs)
    assert (vb3, vs3) == (vb, vs) and w3 == pytest.approx(w2)
    assert loss3 != pytest.approx(loss)


@pytest.mark.parametrize("frictionless", ["ground", "ship", "both"])
def test_frictionless_free_rocking_quarter_period(frictionless):
    """Modes 6, 7, 8 with zero friction: slip momenta stay zero, theta-dependent inertia.

    With p_S = 0 the kinetic energy is J_eff(theta) w^2 / 2 with
    J_eff = K_tt - K_tS K_SS^-1 K_St (K the mass matrix at theta), and
    J_eff(theta) w^2 / 2 = V(theta_0) - V(theta). The time from release to the first impact
    is the quadrature of dtheta / w.
    """
    mu_g = 0.0 if frictionless in ("ground", "both") else 10.0
    mu_s = 0.0 if frictionless in ("ship", "both") else 10.0
    system = ShipBlockSystem(
        ship_mass=3e3, block_mass=1000.0, n_blocks=2, half_width=0.25, half_height=0.8,
        mu_s_ground=mu_g, mu_k_ground=mu_g, mu_s_ship=mu_s, mu_k_ship=mu_s,
    )
    M, nm, nI = system.ship_mass, system.total_block_mass, 2 * system.inertia
    R, alpha = system.half_diagonal, system.critical_angle
    slipping = [i for i, mu in ((0, mu_g), (2, mu_s)) if mu == 0.0]

    def j_eff(th):
        c = math.cos(alpha - th)
        Kf = np.array([
            [nm + M, -(nm + 2 * M) * R * c, M],
            [-(nm + 2 * M) * R * c, nI + (nm + 4 * M) * R * R, -2 * M * R * c],
            [M, -2 * M * R * c, M],
        ])
        S = slipping
        return Kf[1, 1] - Kf[1, S] @ np.linalg.solve(Kf[np.ix_(S, S)], Kf[S, 1])

    def potential(th):
        return (nm + 2 * M) * G0 * R * (math.cos(alpha - th) - math.cos(alpha))

    theta0 = 0.5 * alpha

    def integrand(u):
        th = theta0 * (1 - u * u)
        de = potential(theta0) - potential(th)
        return 2 * theta0 * u / math.sqrt(2 * de / j_eff(th)) if de > 0 else 0.0

    t_ref, _ = quad(integrand, 0, 1, epsabs=1e-14, epsrel=1e-12, limit=200)
    res = simulate(system, np.zeros(200), None, 0.01, initial_state=(0, theta0, 0, 0, 0, 0), **TIGHT)
    impacts = res.events_of("impact")
    assert impacts[0].time == pytest.approx(t_ref, abs=1e-8)
    expected_mode = {"ground": 6, "ship": 7, "both": 8}[frictionless]
    assert res.events[0].to_mode == expected_mode
    # slip momenta stay zero: horizontal momentum (ground frictionless) / ship's (ship frictionless)
    i = int(0.5 * impacts[0].time / 0.01)
    c = math.cos(alpha - abs(res.theta[i]))
    vb, w, vs = res.v_b[i], res.theta_dot[i], res.v_s[i]
    if mu_g == 0.0:
        assert abs((nm + M) * vb - (nm + 2 * M) * R * c * w + M * vs) < 1e-9 * nm * R * abs(w)
    if mu_s == 0.0:
        assert abs(M * vb - 2 * M * R * c * w + M * vs) < 1e-9 * M * R * abs(w)


def overturning_pulse_duration(system, A):
    """Critical duration of a rectangular pulse A (> g tan alpha) for overturning.

    During the pulse J w^2/2 = W/g [A (sin a - sin(a - th)) - g (cos(a - th) - cos a)]; the block
    overturns after the pulse iff it ends beyond theta* with
    sin(alpha - theta*) = sin(alpha) - g (1 - cos alpha)/A. The duration is the quadrature of
    dtheta/w from 0 to theta*.
    """
    alpha = system.critical_angle
    J, W = rocking_constants(system)
    th_star = alpha - math.asin(math.sin(alpha) - G0 * (1 - math.cos(alpha)) / A)

    def w(th):
        e = (W / G0) * (A * (math.sin(alpha) - math.sin(alpha - th))
                        - G0 * (math.cos(alpha - th) - math.cos(alpha)))
        return math.sqrt(2 * e / J)

    # theta ~ t^2 near 0, so use theta = th_star * u^2
    val, _ = quad(lambda u: 2 * th_star * u / w(th_star * u * u), 0, 1, epsrel=1e-12, limit=200)
    return val


@pytest.mark.parametrize("ship_mass,n", [(1e-6, 1), (2e4, 4)])
def test_overturning_threshold_under_rectangular_pulse(ship_mass, n):
    system = rocking_system(ship_mass=ship_mass, n=n, B=0.25, H=1.0)
    A = 0.5 * G0  # > g tan(alpha) = 0.25 g: rocking starts at once
    t_crit = overturning_pulse_duration(system, A)
    dt = 0.0005

    def run(duration):
        n_pulse = int(round(duration / dt))
        a = np.zeros(int(3.0 / dt))
        a[: n_pulse + 1] = A
        return simulate(system, a, None, dt)

    survived = run(0.97 * t_crit)
    failed = run(1.03 * t_crit)
    assert survived.failure is None
    assert survived.summary["peak_rotation_ratio"] > 0.5
    assert failed.failure == "overturning"
    assert failed.events[-1].kind == "overturning"
    assert np.isnan(failed.theta[-1]) and failed.mode[-1] == 0


def test_separation_under_falling_ground():
    """ay = -k t: the normal forces vanish at G = 0, t = g/k; ay < -g separates at once."""
    system = rocking_system(ship_mass=1e6, n=10, mu=0.5)
    k, dt = 20.0, 0.01
    t = np.arange(0, 1.0, dt)
    res = simulate(system, np.zeros_like(t), -k * t, dt)
    assert res.failure == "separation"
    assert res.failure_time == pytest.approx(G0 / k, abs=1e-10)
    import warnings

    with warnings.catch_warnings():
        warnings.simplefilter("error")  # a plain separation, not a mode inconsistency
        res2 = simulate(system, np.zeros(10), np.full(10, -1.2 * G0), dt)
    assert res2.failure == "separation" and res2.failure_time == 0.0


def all_modes_system():
    """Slender blocks (B/H = 0.25) with friction near the slenderness: all 8 modes occur."""
    return ShipBlockSystem(
        ship_mass=2e5, block_mass=2000.0, n_blocks=20, half_width=0.25, half_height=1.0,
        mu_s_ground=0.26, mu_k_ground=0.2, mu_s_ship=0.3, mu_k_ship=0.2,
    )


def random_record(seed, n=3000, dt=0.005, amp_h=2.5, amp_v=2.0):
    rng = np.random.default_rng(seed)
    kernel = np.hanning(15)
    kernel /= kernel.sum()
    a = np.convolve(rng.normal(0, amp_h * 3, n), kernel, mode="same")
    ay = np.convolve(rng.normal(0, amp_v * 3, n), kernel, mode="same")
    return a, ay, dt


@pytest.mark.parametrize("seed", [3, 11])
def test_energy_balance_all_modes(seed):
    """dT + dV = W_in - D - E_imp on random two-component records visiting all 8 modes."""
    a, ay, dt = random_record(seed)
    res = simulate(all_modes_system(), a, ay, dt, rtol=1e-12, atol=1e-14)
    visited = {m for m in range(1, 9) if res.summary[f"time_in_mode_{m}"] > 0}
    assert visited == set(range(1, 9)), visited
    finite = np.isfinite(res.energy.residual)
    scale = np.abs(res.energy.input_work[finite]).max()
    assert scale > 0
    assert np.abs(res.energy.residual[finite]).max() <= 1e-8 * scale
    assert np.all(np.diff(res.energy.friction[finite]) >= -1e-9 * scale)  # dissipation grows
    assert np.all(np.diff(res.energy.impact[finite]) >= -1e-9 * scale)  # momentum rule: no gain


def test_mirror_symmetry_all_modes():
    """ax -> -ax mirrors x_b, theta and x_s and leaves the mode history unchanged."""
    a, ay, dt = random_record(3, n=2000)
    system = all_modes_system()
    r1 = simulate(system, a, ay, dt, rtol=1e-11, atol=1e-13)
    r2 = simulate(system, -a, ay, dt, rtol=1e-11, atol=1e-13)
    assert r1.summary["n_impacts"] > 5
    ok = np.isfinite(r1.theta)
    np.testing.assert_allclose(r2.theta[ok], -r1.theta[ok], atol=1e-8)
    np.testing.assert_allclose(r2.x_b[ok], -r1.x_b[ok], atol=1e-8)
    np.testing.assert_allclose(r2.x_s[ok], -r1.x_s[ok], atol=1e-8)
    np.testing.assert_array_equal(r1.mode, r2.mode)


def test_rocking_converges_as_tolerance_tightens():
    """Rocking results converge with the tolerance: no hidden fixed-step error.

    Free rocking of the compound system across long sample intervals (dt = 0.5 s), where the
    step is limited by the tolerance alone: the error of the first eight impact times against
    the energy quadrature falls in proportion to rtol. On a random record visiting all eight
    modes (1-in-200-s samples, where a step per sample already meets every tolerance here)
    every tolerance agrees with a tight run to far below any engineering interest; what is
    left there is rounding amplified by ~900 impacts (~3e-11).
    """
    system = rocking_system(ship_mass=2e4, n=4)
    alpha = system.critical_angle
    J, W = rocking_constants(system)
    theta0 = 0.6 * alpha
    ref, _ = free_rocking_reference(theta0, alpha, system.effective_restitution, J, W, 8)
    errors = []
    for rtol in (1e-5, 1e-7, 1e-9):
        res = simulate(system, np.zeros(16), None, 0.5, initial_state=(0, theta0, 0, 0, 0, 0),
                       rtol=rtol, atol=rtol * 1e-2)
        impacts = np.array([ev.time for ev in res.events_of("impact")])[:8]
        errors.append(np.abs(impacts - ref).max())
        assert errors[-1] < 100 * rtol
    assert errors[1] < errors[0] / 30 and errors[2] < errors[1] / 30

    a, ay, dt = random_record(3, n=2000)
    system = all_modes_system()
    peaks = []
    for rtol in (1e-5, 1e-7, 1e-9, 1e-12):
        r = simulate(system, a, ay, dt, rtol=rtol, atol=rtol * 1e-2)
        peaks.append((r.summary["peak_rotation"], r.summary["residual_block_slip"]))
    peaks = np.array(peaks)
    assert np.abs(peaks[:-1] - peaks[-1]).max() < 1e-9


def test_invalid_inputs_are_named():
    system = all_modes_system()
    with pytest.raises(ValueError, match="dt"):
        simulate(system, np.zeros(10), None, 0.0)
    with pytest.raises(ValueError, match="ax.*non-finite"):
        simulate(system, np.array([0.0, np.nan, 1.0]), None, 0.01)
    with pytest.raises(ValueError, match="same length"):
        simulate(system, np.zeros(10), np.zeros(9), 0.01)
    with pytest.raises(ValueError, match="at least 2"):
        simulate(system, np.zeros(0), None, 0.01)
    for field, value in [("ship_mass", 0.0), ("half_width", -1.0), ("restitution", 1.5),
                         ("impact_rule", "bounce"), ("n_blocks", 0), ("mu_k_ground", 0.9)]:
        with pytest.raises(ValueError, match=field):
            system.replace(**{field: value})


def test_batch_entry_point_equals_single_runs():
    """simulate_batch (parallel, summaries only) gives exactly what simulate gives per case."""
    from shipblock import simulate_batch

    a1, ay1, dt = random_record(3, n=1200)
    a2, _, _ = random_record(4, n=900)
    systems = [all_modes_system(), all_modes_system().replace(half_width=0.4, mu_s_ship=0.5)]
    cases = [(0, 0, 1.0, 1.0), (1, 0, 0.7, 0.0), (0, 1, 1.3, 0.5), (1, 1, -1.0, 1.0)]
    out = simulate_batch(systems, [(a1, ay1), (a2, None)], dt, cases)
    for c, (r, s, fh, fv) in enumerate(cases):
        ay = (ay1 * fv) if r == 0 else None
        single = simulate(systems[s], (a1, a2)[r] * fh, ay, dt)
        for key in ("peak_block_slip", "peak_rotation", "peak_ship_slip", "residual_ship_slip",
                    "n_impacts", "time_in_mode_3"):
            assert out[key][c] == single.summary[key], (c, key)



def test_missing_vertical_equals_zero_vertical():
    """Without a vertical component the kernels get the horizontal as a stand-in they must never
    read: results equal those with an explicit vertical of zeros, and the result reports zeros."""
    from shipblock import simulate_batch

    a, _, dt = random_record(5, n=1500)
    system = all_modes_system()
    none = simulate(system, a, None, dt)
    zero = simulate(system, a, np.zeros_like(a), dt)
    np.testing.assert_array_equal(none.theta, zero.theta)
    np.testing.assert_array_equal(none.x_s, zero.x_s)
    np.testing.assert_array_equal(none.mode, zero.mode)
    np.testing.assert_equal(none.summary, zero.summary)  # NaN where a peak never occurred
    assert not none.ground_acceleration[1].any()
    cases = [(0, 0, 1.0, 1.0), (0, 0, 0.6, 1.0)]
    without = simulate_batch(system, [(a, None)], dt, cases)
    with_zero = simulate_batch(system, [(a, np.zeros_like(a))], dt, cases)
    for key, values in without.items():
        np.testing.assert_array_equal(values, with_zero[key], err_msg=key)

def _launched_peak(system, w0):
    """Peak rotation and its time of free rocking launched from theta = 0 with theta_dot = w0:
    J w0^2 / 2 = W (cos(alpha - theta_max) - cos(alpha)), reached after the quarter time of
    free rocking from theta_max."""
    alpha = system.critical_angle
    J, W = rocking_constants(system)
    theta_max = alpha - math.acos(math.cos(alpha) + J * w0**2 / (2 * W))
    return theta_max, quarter_time(theta_max, alpha, J, W)


@pytest.mark.parametrize("ship_mass,n", [(1e-6, 1), (2e4, 4)])
def test_peak_rotation_and_its_time_from_energy(ship_mass, n):
    """Launched from theta = 0 with theta_dot = w0 and no ground motion, the block rises to
    theta_max with J w0^2 / 2 = W (cos(alpha - theta_max) - cos(alpha)), reached after the
    quarter time of free rocking from theta_max. The peak falls inside a solver step, so this
    checks the located extremum (value and time), not the nearest sample."""
    system = rocking_system(ship_mass=ship_mass, n=n)
    w0 = 0.35
    theta_max, t_peak = _launched_peak(system, w0)
    res = simulate(system, np.zeros(200), None, 0.01, initial_state=(0, 0, 0, 0, w0, 0), **TIGHT)
    assert res.summary["peak_rotation"] == pytest.approx(theta_max, rel=1e-9)
    assert res.summary["peak_rotation_time"] == pytest.approx(t_peak, abs=1e-8)
    assert abs(res.theta).max() < theta_max  # the samples miss the peak itself


@pytest.mark.parametrize("ship_mass,n", [(1e-6, 1), (2e4, 4)])
def test_peak_rotation_at_default_tolerance_and_mid_swing(ship_mass, n):
    """The same launch at the default tolerance (whole-sample steps of the mode-3 span, which
    updates the running peak only where theta_dot turns and where it stops): the located
    extremum; and on a record that ends while the block is still rising, the peak is the last
    sample, at its time."""
    system = rocking_system(ship_mass=ship_mass, n=n)
    w0 = 0.35
    theta_max, t_peak = _launched_peak(system, w0)
    launch = (0, 0, 0, 0, w0, 0)
    res = simulate(system, np.zeros(200), None, 0.01, initial_state=launch)
    assert res.summary["peak_rotation"] == pytest.approx(theta_max, rel=1e-7)
    assert res.summary["peak_rotation_time"] == pytest.approx(t_peak, abs=1e-6)
    n_rising = int(t_peak / 0.01) - 2
    short = simulate(system, np.zeros(n_rising), None, 0.01, initial_state=launch)
    assert np.all(np.diff(short.theta) > 0.0)
    assert short.summary["peak_rotation"] == abs(short.theta[-1])
    assert short.summary["peak_rotation_time"] == pytest.approx(short.time[-1], abs=1e-12)


def test_parameter_tuple_carries_the_whole_parameter_vector():
    """The kernels index the parameters as a tuple; it must hold every entry of the vector."""
    from shipblock.solver._layout import parameter_tuple
    from shipblock.system import N_PARAMS

    p = all_modes_system().to_parameter_vector()
    assert p.size == N_PARAMS
    assert parameter_tuple(p) == tuple(p)


def test_potential_energy_keeps_the_precision_of_small_rotations():
    """V = (nm+2M) g R (cos(alpha - |theta|) - cos alpha): to full relative precision down to
    tiny rotations (a difference of cosines gives 0 below ~1e-16 rad and an energy balance of a
    run with a brief uplift off by 100 %), symmetric, exact at overturning."""
    from shipblock.equations import potential_energy

    system = all_modes_system()
    p = system.to_parameter_vector()
    alpha = system.critical_angle
    k = (system.total_block_mass + 2 * system.ship_mass) * system.g * system.half_diagonal
    for th in (1e-20, 1e-14, 1e-9, 1e-5):
        series = k * (math.sin(alpha) * th - math.cos(alpha) * th**2 / 2
                      - math.sin(alpha) * th**3 / 6)
        assert potential_energy(p, th) == pytest.approx(series, rel=1e-13)
        assert potential_energy(p, -th) == potential_energy(p, th)
    assert potential_energy(p, alpha) == pytest.approx(k * (1 - math.cos(alpha)), rel=1e-14)
    th = 0.3 * alpha
    assert potential_energy(p, th) == pytest.approx(
        k * (math.cos(alpha - th) - math.cos(alpha)), rel=1e-13)


def test_small_rocking_after_an_impact_keeps_its_impacts():
    """A step from an impact may not pass the rotation's return to zero (impact_return_time).

    Found by random testing: slender blocks under a tiny, light ship lift off under strong
    two-component shaking and rock with rotations of 1e-8 rad, below ``atol``; the error
    control then allowed a step of 1.4 ms from an impact, in which the rotation returned
    through zero (0.17 ms), crossed again with the pivot on the wrong corner and ended on the
    right side: two impacts missed, energy balance off by 2.4 % of the input work. At the
    default tolerance the events must be those of a converged run.
    """
    system = ShipBlockSystem(ship_mass=1369.0, block_mass=4346.0, n_blocks=287, half_width=0.1156,
                             half_height=0.6832, mu_s_ground=0.4651, mu_k_ground=0.3689,
                             mu_s_ship=0.2565, mu_k_ship=0.2123)
    ax = np.array([1.893, -2.010, -2.599, 7.945, 5.072])
    ay = np.array([4.036, 9.454, 3.943, -5.469, -12.586])
    res = simulate(system, ax, ay, 0.002)
    ref = simulate(system, ax, ay, 0.002, rtol=1e-12, atol=1e-14)
    assert ref.events_of("impact") and len(ref.events_of("impact")) == 3
    assert [e.kind for e in res.events] == [e.kind for e in ref.events]
    np.testing.assert_allclose([e.time for e in res.events], [e.time for e in ref.events],
                               atol=1e-9)
    ok = np.isfinite(res.energy.residual)
    assert np.abs(res.energy.residual[ok]).max() <= 1e-8 * np.abs(res.energy.input_work[ok]).max()
