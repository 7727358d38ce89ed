"""Rocking impacts of the dock section: Housner's block on a stiff two-spring base, the damping
that calibrates a rocking impact, and rocking with a ship on top against the rigid model's
plastic impact rule (``impact_rule='plastic'``).

How the restitution is measured: a keel-block line (n_springs = 2, the classical two-spring
base) is set rocking about one bottom corner by an initial angular velocity ``omega0`` (the
ship on top moving with the diagonally opposite top corner) and rocks freely, without ground
motion. Between impacts a rigid rocking system conserves energy, ``J_O omega^2 / 2 + W R
cos(alpha - |theta|)`` with ``W = (n m + 2 M) g`` (the ship rides on the top corner opposite
the pivot, at 2R) and the same ``J_O`` on either corner, so the ratio of the angular velocities
at theta = 0 after and before an impact follows from the peak rotations either side of it:

    e = omega+ / omega- = sqrt(f(theta_2) / f(theta_1)),  f(theta) = cos(alpha - theta) - cos(alpha).

For the compliant model the peaks are measured from the static state at the samples (dt = 1 ms,
peaks of a slow swing: below ~3e-7 rad, ~3e-6 in e); the compliance adds O(1/k) to this measure.
The closed form is :func:`shipblock.system.system_restitution` (the plastic impact at the new
pivot with the interfaces sticking): Housner's ``1 - 1.5 sin^2(alpha)`` as the ship's mass
vanishes.
"""

import dataclasses

import numpy as np

from shipblock import simulate
from shipblock.section import Block, BlockLine, Cap, DockSection, Ship
from shipblock.section.simulate import simulate_section
from shipblock.system import system_restitution
from .test_section_rigid_limit import G, pair, rates

N_BLOCKS = 4
HALF_WIDTH, HALF_HEIGHT = 0.3, 1.0
ALPHA = np.arctan(HALF_WIDTH / HALF_HEIGHT)
HOUSNER = 1.0 - 1.5 * np.sin(ALPHA) ** 2
#: A ship of 10 kg on four blocks of 2.8 t: Housner's single block to 1e-4.
LIGHT_SHIP = 10.0


def free_rocking(k, damping, ship_mass=LIGHT_SHIP, omega0=0.4, duration=1.5, dt=1e-3, mu=0.9,
                 top_ratio=1.0):
    """Measured restitutions of the successive impacts of free rocking and the closed form.

    The bottom caps have stiffness ``k`` per block; the top caps carry the ship with the same
    natural frequency (``k`` scaled by the ship's share of the mass when the ship is lighter
    than the line, so that a very light ship does not set a tiny step), times ``top_ratio``.
    Both interfaces stick (mu = 0.9 on squat contact forces). Returns (e per impact, e_sys,
    result).
    """
    m = Block(half_width=HALF_WIDTH, half_height=HALF_HEIGHT).block_mass
    top = Cap(stiffness=top_ratio * k * min(1.0, ship_mass / (N_BLOCKS * m)), mu_s=mu, mu_k=mu,
              damping_ratio=damping)
    bottom = Cap(stiffness=k, mu_s=mu, mu_k=mu, damping_ratio=damping)
    blk = Block(half_width=HALF_WIDTH, half_height=HALF_HEIGHT, top=top, bottom=bottom)
    ship = Ship(mass=ship_mass, roll_inertia=4.0 * ship_mass, g_height=3.0,
                keel_half_width=HALF_WIDTH, half_beam=5.0)
    sec = DockSection(ship, BlockLine(block=blk, n_blocks=N_BLOCKS), roll_held=True, n_springs=2)
    w, b, h = omega0, HALF_WIDTH, HALF_HEIGHT
    # rotation about the bottom corner at -B: the centre at (B, H) and the top corner at (2B, 2H)
    # from it
    v0 = [[-2 * h * w, 2 * b * w, 0.0], [-h * w, b * w, w]]
    t = np.arange(0.0, duration, dt)
    res = simulate_section(sec, np.zeros_like(t), None, dt, initial_velocity=v0)
    theta = res.lines["keel"][:, 2]
    cross = np.nonzero(theta[:-1] * theta[1:] < 0.0)[0]
    bounds = [0, *(cross + 1)]  # the last, unfinished half-cycle is left out
    peaks = np.array([np.max(np.abs(theta[a:c])) for a, c in zip(bounds[:-1], bounds[1:],
                                                                    strict=True)])
    f = np.cos(ALPHA - peaks) - np.cos(ALPHA)
    e_sys = system_restitution(N_BLOCKS * m / ship_mass, ALPHA)
    return np.sqrt(f[1:] / f[:-1]), e_sys, res


def forced_rocking(k, damping, duration=3.0, dt=0.002, proportional_limit=1e10):
    """Rocking with a 200 t ship on top under a 1.5 Hz, 0.5 g sine: the largest difference of
    |theta| from the rigid solver with the plastic impact rule [rad], the rigid peak rotation
    and its impact count, the number of times a keel_top spring detaches and the error of the
    peak rotation [rad]. The caps do not
    crush (``proportional_limit`` 10 GPa): with oak's 7.4 MPa the impact forces of caps stiffer
    than 1e11 N/m crush them at every impact, a loss the rigid model does not have."""
    t = np.arange(0.0, duration, dt)
    ah = 0.5 * G * np.sin(2 * np.pi * 1.5 * t)
    rigid, sec = pair(k, half_width=HALF_WIDTH, half_height=HALF_HEIGHT, mu_ground=0.9,
                      mu_ship=0.9, n_springs=2, damping=damping,
                      proportional_limit=proportional_limit)
    ref = simulate(dataclasses.replace(rigid, impact_rule="plastic"), ah, None, dt)
    res = simulate_section(sec, ah, None, dt)
    assert abs(res.energy["residual"]) < 1e-6
    n = min(ref.theta.size, res.time.size)
    diff = np.max(np.abs(np.abs(res.lines["keel"][:n, 2]) - np.abs(ref.theta[:n])))
    impacts = sum(e.kind == "impact" for e in ref.events)
    detach = sum(e.kind == "spring_detaches" and e.where.startswith("keel_top")
                 for e in res.events)
    peak_error = abs(res.summary["keel_peak_rotation"] - ref.summary["peak_rotation"])
    return diff, ref.summary["peak_rotation"], impacts, detach, peak_error


def test_housner_block_on_stiff_two_spring_base_converges_at_first_order():
    errors = []
    for k in (1e9, 1e10, 1e11):
        e, e_sys, res = free_rocking(k, damping=5.0)
        assert res.failure is None and abs(res.energy["residual"]) < 1e-5
        assert e.size >= 3
        assert abs(e_sys - HOUSNER) < 2e-4  # the light ship: Housner's single block
        errors.append(np.max(np.abs(e[:3] - e_sys)))
    errors = np.array(errors)
    assert np.all(rates(errors) > 0.8)
    assert errors[-1] < 1e-4
    # the loss is that of the plastic impact, not of a bounce: 1 - e^2 is 23 % per impact
    assert abs((1 - e[0] ** 2) - (1 - HOUSNER**2)) < 3e-4


def test_damping_ratio_above_two_gives_the_plastic_impact_and_below_one_less_loss():
    """Reference section 8, 'damping cannot give any restitution': over damping ratios 2 to 20
    a compliant rocking impact loses Housner's plastic value; a light damping loses *less*
    (the heel bounces), so no damping gives a rotational e below the plastic one."""
    k = 1e11
    e_sys = None
    for zeta in (2.0, 5.0, 20.0):
        e, e_sys, _ = free_rocking(k, damping=zeta)
        assert np.max(np.abs(e[:2] - e_sys)) < 1e-4
    e, _, _ = free_rocking(k, damping=0.3)
    assert np.all(e[:2] > e_sys + 5e-3)


def test_heavy_ship_first_impact_is_near_the_rigid_systems_plastic_impact():
    """A 200 t ship on four 2.8 t blocks (M_n = 0.056): with equal top and bottom caps the first
    impact loses close to the rigid system's plastic value (e_sys = 0.836, Housner's 0.876 would
    be wrong), but the compliant limit is not e_sys: e - e_sys = -9.8e-5, +5.3e-4, +5.6e-4 at
    k = 1e11, 1e12, 1e13. The ship's top contact opens after the impacts (the reference's brief
    lift-off)."""
    for k in (1e11, 1e12):
        e, e_sys, res = free_rocking(k, damping=5.0, ship_mass=2e5, omega0=0.2, duration=0.9)
        assert abs(e[0] - e_sys) < 1e-3
        detach = sum(ev.kind == "spring_detaches" and ev.where.startswith("keel_top")
                     for ev in res.events)
        assert detach >= 2
    assert e[0] - e_sys > 3e-4  # levelled off above e_sys at 1e12, not converging to it
    assert e_sys < HOUSNER - 0.03


def test_two_contact_impact_depends_on_the_ratio_of_the_caps_stiffnesses():
    """The rocking impact under a heavy ship is a two-contact impact (the heel on the floor, the
    new top corner under the ship): its compliant limit depends on the ratio of the two caps'
    stiffnesses, so no single rigid rule is the limit of every dock. With top caps ten times
    stiffer than the bottom ones it loses markedly less than the plastic rule (e - e_sys =
    +2.1e-2, +1.2e-2, +9.6e-3 at k = 1e11, 1e12, 1e13: docs/theory/section.md)."""
    e, e_sys, _ = free_rocking(1e11, damping=5.0, ship_mass=2e5, omega0=0.2, duration=0.9,
                               top_ratio=10.0)
    assert e[0] - e_sys > 1e-2


def test_forced_rocking_with_a_ship_on_top_converges_to_the_plastic_rigid_model():
    """Under a sine with a 200 t ship on top and eight rigid impacts, the peak rotation agrees
    with the plastic rigid rule to 1e-3 of itself and the history difference falls with the
    stiffness. (Before the friction was measured at the centre of pressure it levelled off at
    1 % of the peak: docs/theory/section.md, 'Rocking impacts'.)"""
    out = [forced_rocking(k, damping=5.0) for k in (1e10, 1e11)]
    for _, peak, impacts, detach, peak_error in out:
        assert impacts >= 6 and detach >= impacts
        assert peak_error < 1e-3 * peak
    (diff10, peak, *_), (diff11, *_) = out
    assert diff11 < diff10 / 3 and diff11 < 4e-3 * peak


def test_rocking_pivot_corner_sticks_in_the_rigid_limit():
    """The friction of a strip acts, and its slip is measured, at the centre of pressure: a
    block rocking on its corner keeps that corner in place, as the rigid model's sticking
    pivot (when it was measured at the face centre the corner slid by B (1 - cos theta),
    1.3 mm at 0.09 rad: a different constraint, whatever the stiffness)."""
    _, _, res = free_rocking(1e11, damping=5.0, ship_mass=2e5, omega0=0.5, duration=0.5)
    y, _, theta = res.lines["keel"].T
    i = int(np.argmax(np.abs(theta)))
    assert theta[i] > 0.05 and np.all(theta[1:i + 1] > 0.0)  # rocking on the corner at -B
    # horizontal position of the pivot corner (-B, -H) of the line's centre, from rest; the
    # first millisecond (the stick springs taking up the start) left out
    corner = y - HALF_WIDTH * np.cos(theta) + HALF_HEIGHT * np.sin(theta) + HALF_WIDTH
    assert abs(corner[i] - corner[1]) < 0.01 * HALF_WIDTH * (1 - np.cos(theta[i]))
