"""The rigid limit: no side blocks, roll held, caps stiffer and stiffer -> the seed model.

The reference is the existing rigid solver (:func:`shipblock.simulate`) on the same blocks,
ship and friction. The differences must fall as the cap stiffness k grows; the observed rates
(per decade of k) are asserted with margin and reported in ``docs/theory/section.md``:

* sliding under a one-sided pulse (Newmark's sliding block: the blocks are too squat to rock):
  first order in 1/k (the elastic shear and vertical settling of the caps);
* sliding with reversals (mu_s = mu_k): order about 1/2, because at each reversal the stick
  spring must swing the friction force from +mu N to -mu N, which takes half a period of the
  ship on its stick springs, pi sqrt(m / k_t), where the rigid model reverses instantly;
* rocking onset of slender blocks: order about 1/2, the dashpot of the heel spring letting it go
  a time ~ c / k = 2 zeta / omega early (omega ~ sqrt(k)).
"""

import numpy as np

from shipblock import ShipBlockSystem, simulate
from shipblock.section import Block, BlockLine, Cap, DockSection, Ship
from shipblock.section.simulate import simulate_section

G = 9.80665
SHIP_MASS = 2e5
N_BLOCKS = 4


def pair(k, half_width=24 * 0.0254, half_height=24 * 0.0254, mu_ground=0.2, mu_ship=0.8,
         damping=0.5, n_springs=5, proportional_limit=7.4e6):
    """The rigid system and its compliant counterpart with caps of stiffness k per block
    (crushing at ``proportional_limit`` [Pa])."""
    top = Cap(stiffness=k, mu_s=mu_ship, mu_k=mu_ship, damping_ratio=damping,
              proportional_limit=proportional_limit)
    bottom = Cap(stiffness=k, mu_s=mu_ground, mu_k=mu_ground, damping_ratio=damping,
                 proportional_limit=proportional_limit)
    blk = Block(half_width=half_width, half_height=half_height, top=top, bottom=bottom)
    ship = Ship(mass=SHIP_MASS, roll_inertia=SHIP_MASS * 4.0, g_height=3.0, keel_half_width=1.0,
                half_beam=5.0)
    sec = DockSection(ship, BlockLine(block=blk, n_blocks=N_BLOCKS), roll_held=True,
                      n_springs=n_springs)
    rigid = ShipBlockSystem(ship_mass=SHIP_MASS, block_mass=blk.block_mass, n_blocks=N_BLOCKS,
                            half_width=half_width, half_height=half_height,
                            mu_s_ground=mu_ground, mu_k_ground=mu_ground, mu_s_ship=mu_ship,
                            mu_k_ship=mu_ship)
    return rigid, sec


def sliding_differences(ah, dt, stiffnesses):
    """Largest difference of the block line's slip history from the rigid solver's [m]."""
    out = []
    for k in stiffnesses:
        rigid, sec = pair(k)
        ref = simulate(rigid, ah, None, dt)
        res = simulate_section(sec, ah, None, dt)
        assert abs(res.energy["residual"]) < 1e-6
        out.append(np.max(np.abs(res.lines["keel"][:, 0] - ref.x_b)))
    return np.array(out), np.max(np.abs(ref.x_b))


def rocking_differences(stiffnesses, duration=0.3, dt=0.002, amplitude=0.5):
    """Differences of the uplift time [s] and of the peak rotation up to ``duration`` [rad]."""
    t = np.arange(0.0, duration, dt)
    ah = amplitude * G * np.sin(2 * np.pi * 1.5 * t)
    onset, peak = [], []
    for k in stiffnesses:
        rigid, sec = pair(k, half_width=0.3, half_height=1.0, mu_ground=0.9, mu_ship=0.9,
                          n_springs=2)
        ref = simulate(rigid, ah, None, dt)
        res = simulate_section(sec, ah, None, dt)
        assert abs(res.energy["residual"]) < 1e-6
        uplift = next(e.time for e in ref.events if e.kind == "uplift")
        first = next(e.time for e in res.events
                     if e.kind == "spring_detaches" and e.where.startswith("keel_bottom"))
        onset.append(abs(first - uplift))
        peak.append(abs(np.max(np.abs(res.lines["keel"][:, 2])) - ref.summary["peak_rotation"]))
    return np.array(onset), np.array(peak), ref.summary["peak_rotation"]


def rates(diff):
    """Convergence rate per decade of k between successive stiffnesses (one decade apart)."""
    return np.log10(diff[:-1] / diff[1:])


def test_newmark_sliding_converges_at_first_order():
    dt = 0.002
    t = np.arange(0.0, 2.0, dt)
    ah = 0.5 * G * np.sin(2 * np.pi * 2 * t) * (t < 0.25)
    diff, slip = sliding_differences(ah, dt, [1e9, 1e10, 1e11])
    assert slip > 0.05  # it does slide, by 7 cm
    assert np.all(rates(diff) > 0.85)
    assert diff[-1] < 3e-3 * slip


def test_sliding_with_reversals_converges_at_half_order():
    dt = 0.002
    t = np.arange(0.0, 1.6, dt)
    ah = 0.4 * G * np.sin(2 * np.pi * 2 * t) * (t < 1.0)
    diff, slip = sliding_differences(ah, dt, [1e10, 1e11, 1e12])
    assert np.all(rates(diff) > 0.35)
    assert diff[-1] < 0.03 * slip


def test_rocking_onset_and_rotation_converge():
    onset, peak, ref_peak = rocking_differences([1e10, 1e11, 1e12])
    assert np.all(np.diff(onset) < 0) and onset[-1] < 1e-3
    assert np.all(rates(peak) > 0.5) and peak[-1] < 2e-3 * ref_peak
