"""The Painleve regime: a slipping interface jams (docs/theory/transitions.rst, "Jams").

When a slipping interface's friction makes the effective inertia of the rocking negative
(``s sigma = -1`` and ``mu_k`` above a threshold ``mu*``), no mode of motion is consistent. The
interface then jams: an impulsive friction force stops its slip and the rotation keeps its
generalised momentum (:func:`shipblock.impact.apply_jam`). Checked here:

* the derivation (sympy, from the corner kinematics of ``tests/sympy_model.py``): the jam's
  impulse ratio at the jammed interface *is* the threshold ``mu*`` at which the mode's
  effective inertia vanishes, so the jam's friction impulse lies inside the kinetic friction
  cone exactly in the Painleve regime;
* the jam is the end of a Darboux-Keller tangential impact (sliding, then sticking, until
  the normal approach velocity is zero again), integrated step by step in impulse;
* the documented example (B/H = 0.2, M_n = 0.02, mu_k1 = 0.6) against closed forms;
* random states in the regime: the state before the jam has no consistent mode, the one after
  has, the jam never gains energy and its impulses are admissible;
* random runs that reach the regime: energy balance, event sequences, convergence.
"""

from __future__ import annotations

import math
import warnings

import numpy as np
import pytest
import sympy as sp
from scipy.integrate import IntegrationWarning

from shipblock import ShipBlockSystem, simulate
from shipblock.impact import jam_velocities
from shipblock.solver import _kernel as K
from shipblock.solver._layout import N_SPAN_WORK

from . import sympy_model as sm
from .test_mode_selection import reference_choice, reference_ship_liftoff
from .test_solver_rocking import _launched_peak, rocking_constants
from .tools.random_campaign import check_run

B, H, M, m, n, Ib, s = sm.B, sm.H, sm.M, sm.m, sm.n, sm.Ib, sm.s
nm, nI = sm.nm, sm.nI


# ------------------------------------------------------------------------------------------
# the derivation
# ------------------------------------------------------------------------------------------
def _momentum_matrix():
    """K5 = J^T diag(masses) J over q5 = (x_b, y_b, theta, x_s, y_s) at y_b = y_s = 0: the
    generalised momenta, including the normal ones (lift of the pivot y_b, of the ship y_s)."""
    xb_, yb_, th_, xs_, ys_ = sp.symbols("xb_ yb_ th_ xs_ ys_", real=True)
    _, rb, _, rs = sm.kinematics(xb=xb_, yb=yb_, theta=th_, xs=xs_, ys=ys_)
    r = sp.Matrix([rb[0], rb[1], th_, rs[0], rs[1]])
    J = r.jacobian([xb_, yb_, th_, xs_, ys_]).subs({yb_: 0, ys_: 0, th_: sm.th})
    return J.T * sp.diag(nm, nm, nI, M, M) * J


def _jam_impulses(jam):
    """Impulses (generalised, over q5) of a jam of one interface with the other held, for a
    slip velocity v of the jammed interface: the rotation is free (no impulse on theta)."""
    K5 = _momentum_matrix()
    v = sp.Symbol("v", real=True)
    dth = sp.Symbol("dth", real=True)
    i = 0 if jam == "ground" else 3  # the jammed slip coordinate, brought from v to 0
    d = sp.zeros(5, 1)
    d[i], d[2] = -v, dth
    dth_val = sp.solve((K5 * d)[2], dth)[0]  # no impulse on the rotation
    return (K5 * d).subs(dth, dth_val), v


# the threshold of the Painleve regime: the friction coefficient at which the effective inertia
# of mode 6 (ground slipping, ship stuck) / mode 7 (ship slipping, ground stuck) vanishes, for
# s sigma = -1 (the closed-form denominators of docs/theory/derivation.md)
MU_STAR = {
    "ground": ((nm + M) * (nI + (nm + 4 * M) * sm.R**2) - (nm + 2 * M) ** 2 * sm.R**2 * sm.cphi**2)
    / ((nm + 2 * M) ** 2 * sm.R**2 * sm.sphi * sm.cphi),
    "ship": (nI + nm * sm.R**2 + 4 * M * sm.R**2 * sm.sphi**2) / (4 * M * sm.R**2 * sm.sphi * sm.cphi),
}


@pytest.mark.parametrize("jam", ["ground", "ship"])
def test_jam_impulse_ratio_is_the_painleve_threshold(jam):
    """The jam's friction impulse over its normal impulse, at the jammed interface, equals the
    friction coefficient mu* at which the effective inertia of the slipping mode vanishes
    (symbolic identity for any angle, block and ship); the normal impulse is compressive exactly
    when the slip opposes the pivot side (s sigma = -1). So the jam's impulse lies inside the
    kinetic friction cone, |L_t| <= mu_k L_n, exactly in the Painleve regime mu_k > mu*, and
    Coulomb's law holds throughout the jam (see test_jam_is_the_end_of_a_darboux_keller_impact).
    mu* is also checked against the singular mode matrix of the independent derivation."""
    L, v = _jam_impulses(jam)
    t_row, n_row = (0, 1) if jam == "ground" else (3, 4)
    w = sp.Symbol("w", positive=True)
    Lw = L.subs(v, -s * w)  # a slip against the pivot side: sigma = -s
    ratio = s * Lw[t_row] / Lw[n_row]  # -sigma L_t / L_n
    assert sm.is_identity(ratio - MU_STAR[jam])
    mode = 6 if jam == "ground" else 7
    i_mu = 14 if jam == "ground" else 15
    fA, _ = sm.mode_matrix_function(mode)
    f_ratio = sp.lambdify(sm.PARAMS + (w,), ratio)
    f_ln = sp.lambdify(sm.PARAMS + (v,), L[n_row])
    rng = np.random.default_rng(3)
    for sv in (1.0, -1.0):
        for _ in range(10):
            p = list(sm.rand_params(rng, sv, -sv, -sv))
            mu = float(f_ratio(*p, 1.0))
            assert mu > 0
            # the mode matrix of the derivation is singular at mu = mu*, regular elsewhere
            p[i_mu] = mu
            det_star = np.linalg.det(np.array(fA(*p), dtype=float))
            p[i_mu] = 0.5 * mu
            det_half = np.linalg.det(np.array(fA(*p), dtype=float))
            assert abs(det_star) < 1e-9 * abs(det_half)
            # a slip against the pivot side presses the contact; one towards it would pull
            assert f_ln(*p, -sv * 0.5) > 0 > f_ln(*p, sv * 0.5)


def _documented_system(**kw):
    """B/H = 0.2, M_n = 0.02, mu_k1 = 0.6 (docs/theory/derivation.md, the Painleve example)."""
    values = dict(ship_mass=1e6, block_mass=1000.0, n_blocks=20, half_width=0.2, half_height=1.0,
                  mu_s_ground=0.6, mu_k_ground=0.6, mu_s_ship=0.8, mu_k_ship=0.7)
    values.update(kw)
    return ShipBlockSystem(**values)


def test_jam_is_the_end_of_a_darboux_keller_impact():
    """The documented example sliding to the left at 0.3 m/s, its blocks flat on the ground:
    an impulse process at the leading corner (Darboux 1880, Keller 1986), with the normal
    impulse as the time-like variable and the ship stuck. While the corner slides, Coulomb's
    law dL_t = mu_k dL_n holds and, the effective inertia being negative, the normal velocity
    *decreases* (compression builds up by itself: the Painleve regime); the slip reaches zero
    during compression; then the corner sticks (incremental impulse ratio below mu_s1) and the
    compression is recovered until the normal velocity is zero (plastic: no rebound). The end
    state is the jam of apply_jam, the other corner never moves into the ground, and the total
    impulse ratio is mu*."""
    system = _documented_system()
    Mv, nmv, nIv = system.ship_mass, system.total_block_mass, system.n_blocks * system.inertia
    Bv, Hv, R = system.half_width, system.half_height, system.half_diagonal
    v0 = -0.3
    s_v = -np.sign(v0)  # the leading corner
    # (x_b, y_b, theta) with the ship held on its corner, at theta = 0 (rows of K5)
    Kp = np.array([[nmv + Mv, 0.0, -(nmv + 2 * Mv) * Hv],
                   [0.0, nmv + Mv, (nmv + 2 * Mv) * s_v * Bv],
                   [-(nmv + 2 * Mv) * Hv, (nmv + 2 * Mv) * s_v * Bv, nIv + (nmv + 4 * Mv) * R**2]])
    W = np.linalg.inv(Kp)
    mu_k, mu_s = system.mu_k_ground, system.mu_s_ground
    sig = np.sign(v0)
    # sliding phase: dq = W (-sig mu_k, 1, 0) dLn
    d1 = W @ np.array([-sig * mu_k, 1.0, 0.0])
    assert d1[1] < 0.0  # Painleve: pressing the corner makes it approach faster
    assert sig * d1[0] < 0.0  # the slip decreases
    Ln1 = -v0 / d1[0]
    q1 = np.array([v0, 0.0, 0.0]) + Ln1 * d1
    assert q1[1] < 0.0 and abs(q1[0]) < 1e-15  # stuck while compressing
    # sticking phase: dL_t = r dLn with d(x_b') = 0
    r = -W[0, 1] / W[0, 0]
    assert abs(r) < mu_s
    d2 = W @ np.array([r, 1.0, 0.0])
    assert d2[1] > 0.0
    Ln2 = -q1[1] / d2[1]
    q2 = q1 + Ln2 * d2
    # the other corner (2 s B further along) rises throughout: y_b' + 2 s B theta' >= 0
    for q in (q1, q2):
        assert q[1] + 2 * s_v * Bv * q[2] >= -1e-12
    vb, om, vs, loss, admissible = jam_velocities(system, 0.0, 0.0, v_block=v0)
    assert admissible
    assert abs(q2[1]) < 1e-14 and abs(q2[0]) < 1e-14
    assert q2[2] == pytest.approx(om, rel=1e-12)
    assert vb == 0.0 and vs == 0.0
    Lt = -sig * mu_k * Ln1 + r * Ln2
    mu_star = abs(Lt) / (Ln1 + Ln2)
    assert mu_star < mu_k
    c, sn = Hv / R, Bv / R
    mu_star_closed = ((nmv + Mv) * (nIv + (nmv + 4 * Mv) * R**2) - (nmv + 2 * Mv) ** 2 * Hv**2) / (
        (nmv + 2 * Mv) ** 2 * R**2 * sn * c)
    assert mu_star == pytest.approx(mu_star_closed, rel=1e-12)
    assert mu_star == pytest.approx(0.2342, abs=1e-4)


def test_documented_example_jams_and_rocks_on_its_leading_corner():
    """The documented example released sliding at 0.3 m/s to the left on still ground: mode 2
    breaks the moment criterion (mu_k1 > B/H) and mode 6 rotates the wrong way (negative
    effective inertia), so no mode is consistent. The blocks jam at t = 0 on their leading
    (left) corner: the rotation's momentum about it is kept,
    theta_dot+ = (nm + 2M) H |v| / (nI + (nm + 4M) R^2), the energy lost is the rest of the
    kinetic energy, and the blocks then rock freely on stuck interfaces: the peak rotation is
    that of free rocking launched with theta_dot+ (energy quadrature), at every tolerance."""
    system = _documented_system()
    v0 = -0.3
    Mv, nmv = system.ship_mass, system.total_block_mass
    J, Wg = rocking_constants(system)
    w_plus = (nmv + 2 * Mv) * system.half_height * abs(v0) / J
    t_minus = 0.5 * (nmv + Mv) * v0**2
    t_plus = 0.5 * J * w_plus**2
    vb, om, vs, loss, admissible = jam_velocities(system, 0.0, 0.0, v_block=v0)
    assert admissible and (vb, vs) == (0.0, 0.0)
    assert om == pytest.approx(w_plus, rel=1e-13)  # positive: pivot on the left corner
    assert loss == pytest.approx(t_minus - t_plus, rel=1e-10) and loss > 0
    # no consistent mode before the jam, a consistent one (mode 3) after
    y = np.zeros(9)
    y[3] = v0
    _, consistent = reference_choice(system, y, 0.0, 0.0, -1)
    assert not consistent and not reference_ship_liftoff(system, y, 0.0, 0.0)
    y[3], y[4] = vb, om
    want, consistent = reference_choice(system, y, 0.0, 0.0, -1)
    assert consistent and want == (0, 1, 0, 1, 1, 1)
    with warnings.catch_warnings():
        # the quadrature's own round-off note near its singular end; its result is checked
        # to 1e-9 against the runs at rtol = 1e-12 below
        warnings.simplefilter("ignore", IntegrationWarning)
        theta_max, t_peak = _launched_peak(system, w_plus)
    peaks = []
    for rtol in (1e-6, 1e-8, 1e-10, 1e-12):
        with warnings.catch_warnings():
            warnings.simplefilter("error")
            res = simulate(system, np.zeros(300), None, 0.005, rtol=rtol, atol=rtol * 1e-2,
                           initial_state=(0, 0, 0, v0, 0, 0))
        kinds = res.events.kinds
        assert list(kinds[:2]) == ["start", "jam"]
        assert [(e.from_mode, e.to_mode) for e in res.events[:2]] == [(0, 2), (2, 3)]
        assert set(kinds[2:]) == {"impact"} and res.summary["n_jams"] == 1
        assert res.failure is None
        # sample 0 holds the initial state; the jam's loss is in the impact account after it
        assert res.v_b[0] == v0 and res.energy.impact[1] >= loss * (1 - 1e-12)
        assert res.summary["impact_loss"] >= loss
        resid = np.abs(res.energy.residual).max() / t_minus
        assert resid < 10 * rtol
        peaks.append(res.summary["peak_rotation"])
        first_impact = res.events[2].time
        assert first_impact == pytest.approx(2 * t_peak, abs=max(1e-9, 10 * rtol))
    err = np.abs(np.array(peaks) - theta_max) / theta_max
    assert err[-1] < 1e-9 and err.max() < 1e-5
    # the answer converges as the tolerance tightens
    assert err[-1] <= err[0]


def _painleve_state(rng):
    """A random system and state near the Painleve regime: a heavy ship (M_n 0.005-0.2),
    blocks slender to squat, friction above their slenderness, sliding at one or both
    interfaces against the side the blocks rock (or would rock) on."""
    Hv = rng.uniform(0.3, 1.5)
    Bv = Hv * rng.uniform(0.1, 0.6)
    mu1 = min(0.95, Bv / Hv + rng.uniform(0.02, 0.5))
    mu2 = min(0.95, Bv / Hv + rng.uniform(0.02, 0.5))
    nmv = rng.uniform(500.0, 2e5)
    system = ShipBlockSystem(
        ship_mass=nmv / rng.uniform(0.005, 0.2), block_mass=nmv / 50, n_blocks=50,
        half_width=Bv, half_height=Hv, mu_s_ground=mu1, mu_k_ground=mu1 * rng.uniform(0.8, 1),
        mu_s_ship=mu2, mu_k_ship=mu2 * rng.uniform(0.8, 1))
    y = np.zeros(9)
    sv = rng.choice([-1.0, 1.0])
    if rng.random() < 0.5:
        y[1] = sv * rng.uniform(0.0, 0.3) * system.critical_angle
        y[4] = rng.normal(0.0, 0.1)
    which = rng.integers(0, 3)
    if which in (0, 2):
        y[3] = -sv * rng.uniform(0.01, 1.0)
    if which in (1, 2):
        y[5] = -sv * rng.uniform(0.01, 1.0)
    a, ay = rng.normal(0.0, 3.0), rng.normal(0.0, 1.0)
    return system, y, a, ay


def _impulses(system, y0, y1):
    """Generalised impulses (on x_b, theta, x_s) and normal impulses (pivot, ship) of a jam."""
    th = y0[1]
    sv = 1.0 if th > 0 else (-1.0 if th < 0 else np.sign(y1[4] - y0[4]))
    phi = system.critical_angle - abs(th)
    c, sn = math.cos(phi), math.sin(phi)
    Mv, nmv = system.ship_mass, system.total_block_mass
    R = system.half_diagonal
    Kq = np.array([[nmv + Mv, -(nmv + 2 * Mv) * R * c, Mv],
                   [-(nmv + 2 * Mv) * R * c, system.n_blocks * system.inertia + (nmv + 4 * Mv) * R**2,
                    -2 * Mv * R * c],
                   [Mv, -2 * Mv * R * c, Mv]])
    d = np.array(y1[3:6]) - np.array(y0[3:6])
    L = Kq @ d
    ln = (nmv + 2 * Mv) * R * sv * sn * d[1]
    lsn = 2 * Mv * R * sv * sn * d[1]
    return L, ln, lsn, 0.5 * d @ Kq @ d


def test_random_painleve_states():
    """Random states in the regime through the kernel's resolve_mode: where it jams, the state
    before had no consistent mode and no separation (exhaustive reference), the state after has
    the consistent mode the reference picks; the jammed slip is at rest, the momentum of the
    rotation (and of a slip that goes on: frictionless) is kept, the energy lost is
    1/2 d^T K d >= 0, and the impulses are admissible: the normal impulses press and every
    jammed or held interface's friction impulse lies in its static cone. A single slipping
    interface jams, the other held, in every such state, with its impulse ratio mu* below mu_k
    (test_jam_impulse_ratio_is_the_painleve_threshold). Only with both interfaces sliding and
    the blocks flat (a mode-5 state) does the kernel sometimes find no admissible jam and take
    the first that leaves a consistent mode (never in random runs: test_random_campaign)."""
    rng = np.random.default_rng(22)
    counts = {"single": 0, "other sliding": 0, "both": 0, "inadmissible": 0}
    w7 = np.zeros(7)
    Kw = np.zeros((3, 3))
    ms = np.zeros(6, dtype=np.int64)
    for _ in range(3000):
        system, y, a, ay = _painleve_state(rng)
        p = system.to_parameter_vector()
        y0 = y.copy()
        work = np.zeros(N_SPAN_WORK)
        first = K.select_mode(p, y, ms, a, ay, -1, w7, work, 0.0, 0.0)
        status, loss, jammed, _ = K.resolve_mode(p, y, ms, a, ay, a, ay, -1, w7, work, Kw, first,
                                                 0.0, 0.0)
        if not jammed:
            continue
        assert status in (0, 2)
        _, consistent = reference_choice(system, y0, a, ay, -1)
        assert not consistent and not reference_ship_liftoff(system, y0, a, ay)
        if status == 0:
            want, consistent = reference_choice(system, y, a, ay, -1)
            assert consistent and tuple(int(v) for v in ms) == want
        L, ln, lsn, lost = _impulses(system, y0, y)
        assert loss == pytest.approx(lost, rel=1e-9) and loss >= 0.0
        scale = np.abs(L).max() + ln
        assert abs(L[1]) <= 1e-9 * scale  # no impulse on the rotation
        *_, admissible = jam_velocities(system, y0[1], y0[4], y0[3], y0[5], jammed & 1,
                                        jammed & 2)
        both_sliding = y0[3] != 0.0 and y0[5] != 0.0
        if not admissible:
            assert both_sliding and y0[1] == 0.0 and y0[4] == 0.0
            counts["inadmissible"] += 1
            continue
        assert ln > 0.0 and lsn > 0.0
        for i, bit, mu_k, mu_s, normal in ((0, 1, system.mu_k_ground, system.mu_s_ground, ln),
                                           (2, 2, system.mu_k_ship, system.mu_s_ship, lsn)):
            if jammed & bit or y0[3 + i] == 0.0:
                assert y[3 + i] == 0.0 and abs(L[i]) <= mu_s * normal * (1 + 1e-12)
                if jammed & bit and not both_sliding:
                    assert abs(L[i]) < mu_k * normal  # the threshold mu* < mu_k
            else:
                assert abs(L[i]) <= 1e-9 * scale  # a slip that goes on: frictionless
        counts["both" if jammed == 3 else ("other sliding" if both_sliding else "single")] += 1
    assert counts["single"] > 500 and counts["both"] > 50
    assert counts["inadmissible"] < 0.05 * sum(counts.values())


def _regime_case(rng):
    """A random system prone to the regime (heavy ship, friction above the slenderness) under
    a short random two-component record."""
    Hv = rng.uniform(0.4, 1.5)
    Bv = Hv * rng.uniform(0.15, 0.6)
    mu1 = min(0.9, Bv / Hv + rng.uniform(0.0, 0.3))
    mu2 = min(0.9, Bv / Hv + rng.uniform(0.0, 0.3))
    nmv = rng.uniform(5e3, 5e5)
    system = ShipBlockSystem(
        ship_mass=nmv / rng.uniform(0.02, 0.2), block_mass=nmv / 100, n_blocks=100,
        half_width=Bv, half_height=Hv, mu_s_ground=mu1, mu_k_ground=mu1 * rng.uniform(0.6, 1),
        mu_s_ship=mu2, mu_k_ship=mu2 * rng.uniform(0.6, 1),
        impact_rule=rng.choice(["momentum", "plastic"]))
    n, dt = 400, 0.005
    kernel = np.hanning(int(rng.integers(5, 30)))
    kernel /= kernel.sum()
    amp = rng.uniform(3.0, 15.0)
    ax = np.convolve(rng.normal(0, amp, n), kernel, mode="same")
    ay = np.convolve(rng.normal(0, 0.5 * amp, n), kernel, mode="same")
    return system, ax, ay, dt


def test_random_runs_that_reach_the_regime():
    """Random heavy-ship systems under short records: the runs that jam keep their energy
    balance (1e-6 of the input work), never gain energy in a jam or an impact, have valid event
    sequences (the campaign's checks), and converge: at rtol = 1e-10 and 1e-12 the same events,
    the jams at the same times to 1e-8 s, and the peak rotation and final slips closer together
    than at the default tolerance and 1e-12."""
    rng = np.random.default_rng(2026)
    n_jammed = 0
    for i in range(600):
        system, ax, ay, dt = _regime_case(rng)
        with warnings.catch_warnings():
            warnings.simplefilter("error")
            res = simulate(system, ax, ay, dt)
        if res.summary["n_jams"] == 0:
            continue
        n_jammed += 1
        rc = check_run(i, system, res)
        assert not rc.problems, rc.problems
        assert rc.residual < 1e-6
        if n_jammed > 8:
            continue
        runs = [simulate(system, ax, ay, dt, rtol=r, atol=r * 1e-2) for r in (1e-10, 1e-12)]
        k10, k12 = (r.events.kind_code for r in runs)
        assert np.array_equal(k10, k12)
        jam = k12 == 11
        np.testing.assert_allclose(runs[0].events.time[jam], runs[1].events.time[jam], atol=1e-8)
        for key in ("peak_rotation", "residual_block_slip", "residual_ship_slip"):
            ref = runs[1].summary[key]
            scale = max(abs(ref), 1e-9)
            assert abs(runs[0].summary[key] - ref) <= 1e-5 * scale + 1e-12
            assert abs(runs[0].summary[key] - ref) <= abs(res.summary[key] - ref) + 1e-9 * scale
    assert n_jammed >= 10
