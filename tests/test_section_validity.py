"""A run of the dock section that leaves the model's validity stops with a named failure, never a
NaN (issue 29, *Bad input*).

The model is written for rotations up to 60 deg and displacements up to 10 m
(:data:`shipblock.section.model.MAX_ANGLE`, :data:`~shipblock.section.model.MAX_DISPLACEMENT`).
Case: the ship on its keel line launched across the dock at 9 m/s on a floor of low friction
(the ship sticks on the keel caps): the stack slides as Newmark's block, ``y(t) = v0 t - mu_k g
t^2 / 2``, and crosses 10 m at ``t* = (v0 - sqrt(v0^2 - 2 mu_k g 10 m)) / (mu_k g)``; the run must
stop there as ``out_of_validity`` with finite histories.
"""

import math

import numpy as np
import pytest

from shipblock.section import NAVY_BLOCK, Block, BlockLine, Cap, DockSection, Ship
from shipblock.section.model import MAX_DISPLACEMENT
from shipblock.section.simulate import simulate_section

MU_FLOOR = 0.05
V0 = 9.0


def sliding_stack():
    blk = Block(top=Cap(mu_s=0.9, mu_k=0.9), bottom=Cap(mu_s=MU_FLOOR, mu_k=MU_FLOOR))
    ship = Ship(mass=4e5, roll_inertia=4e5 * 9.0, g_height=3.0, keel_half_width=0.6, half_beam=6.0)
    return DockSection(ship, BlockLine(block=blk, n_blocks=4), roll_held=True)


def test_sliding_beyond_ten_metres_stops_as_out_of_validity():
    sec = sliding_stack()
    dt = 0.01
    t = np.arange(0.0, 2.0, dt)
    res = simulate_section(sec, np.zeros_like(t), None, dt,
                           initial_velocity=[[V0, 0.0, 0.0], [V0, 0.0, 0.0]])
    assert res.failure == "out_of_validity"
    a = MU_FLOOR * sec.g
    expected = (V0 - math.sqrt(V0**2 - 2 * a * MAX_DISPLACEMENT)) / a
    # the caps' shear compliance and the stick-to-slip transient at the start (measured 1.2e-7 s)
    assert res.failure_time == pytest.approx(expected, abs=1e-5)
    assert res.events[-1].kind == "out_of_validity" and res.events[-1].where == "ship"
    for h in (res.ship, res.ship_velocity, res.lines["keel"], *res.normal.values(),
              *res.friction.values()):
        assert np.all(np.isfinite(h))
    assert all(math.isfinite(v) for v in res.energy.values())
    assert abs(res.energy["residual"]) < 1e-6
    # the friction of the floor took the kinetic energy lost by then
    total_mass = sec.ship.mass + 4 * sec.keel.block.block_mass
    assert res.energy["friction"] == pytest.approx(total_mass * a * MAX_DISPLACEMENT, rel=2e-3)


def test_floor_falling_faster_than_gravity_stops_as_separation():
    """The floor falls at 2 g: the rigid model fails at once (its contact forces vanish); here the
    stack is thrown off the floor, the compressed caps push the ship off its keel line and the
    run stops as ``separation`` when the ship is 2 cm clear of every support, finite throughout."""
    sec = sliding_stack()
    dt = 0.01
    t = np.arange(0.0, 3.0, dt)
    res = simulate_section(sec, np.zeros_like(t), -2.0 * sec.g * np.ones_like(t), dt)
    assert res.failure == "separation" and 0.0 < res.failure_time < 3.0
    assert np.all(np.isfinite(res.ship)) and np.all(np.isfinite(res.lines["keel"]))
    assert abs(res.energy["residual"]) < 1e-6
    # the stack has left the floor: every spring open at the end
    assert all(n[-1] == 0.0 for n in res.normal.values())


def test_side_lines_beyond_ten_metres_from_the_centre_line_are_valid():
    """The 10 m limit is on a body's displacement from where it was built, not on its distance
    from the centre line: a wide ship on moving side lines at +-12 m (a real docking plan) runs
    (it stopped at t = 0 as out_of_validity before)."""
    ship = Ship(mass=2e6, roll_inertia=2e6 * 100.0, g_height=6.0, keel_half_width=0.8,
                half_beam=16.0)
    side = Block(half_height=NAVY_BLOCK.half_height + 0.15)
    sides = tuple(BlockLine(block=side, n_blocks=2, offset=s * 12.0, hull_height=0.3)
                  for s in (-1, 1))
    dock = DockSection(ship, BlockLine(n_blocks=6), sides)
    dt = 0.005
    t = np.arange(0.0, 1.0, dt)
    res = simulate_section(dock, 0.1 * 9.80665 * np.sin(2 * np.pi * t), None, dt)
    assert res.failure is None and res.time[-1] == pytest.approx(t[-1])
    assert res.summary["side0_peak_slip"] < 1e-2
    assert abs(res.energy["residual"]) < 1e-6
