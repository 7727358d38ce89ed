"""Benchmark of the dock-section solver (issue 29): a 40 s record at 200 Hz on a dock with a keel
line and two moving side lines, Navy-block defaults; and the rigid solver on the same record.

Part of ``shipblock bench`` (target: 50 ms of one core per run); ``python -m
shipblock.bench.section`` prints the JSON alone.
"""

from __future__ import annotations

import json
import time

import numpy as np

from shipblock.section import NAVY_BLOCK, Block, BlockLine, DockSection, Ship
from shipblock.section.simulate import simulate_section
from shipblock.solver import simulate
from shipblock.system import ShipBlockSystem
from shipblock.units import STANDARD_GRAVITY


def navy_dock() -> DockSection:
    """A ship section of 600 t on 4 keel blocks and two lines of 2 side blocks at +-3.5 m."""
    side = Block(half_height=NAVY_BLOCK.half_height + 0.15)
    sides = (BlockLine(block=side, n_blocks=2, offset=-3.5, hull_height=0.3, hull_slope=-0.08),
             BlockLine(block=side, n_blocks=2, offset=3.5, hull_height=0.3, hull_slope=0.08))
    ship = Ship(mass=6e5, roll_inertia=6e5 * 9.0, g_height=4.0, keel_half_width=0.8,
                half_beam=6.0, g_offset=0.05)
    return DockSection(ship, BlockLine(n_blocks=4), sides)


def record(duration=40.0, dt=0.005, pga=0.4, seed=2014):
    """A seeded broadband record: filtered noise in a 10 s strong-motion envelope."""
    rng = np.random.default_rng(seed)
    t = np.arange(0.0, duration, dt)
    noise = rng.normal(size=t.size)
    spec = np.fft.rfft(noise)
    f = np.fft.rfftfreq(t.size, dt)
    spec *= (f > 0.2) * (f < 12.0) / (1.0 + (f / 3.0) ** 2)
    acc = np.fft.irfft(spec, t.size) * np.exp(-((t - 12.0) / 6.0) ** 2)
    h = pga * STANDARD_GRAVITY * acc / np.max(np.abs(acc))
    return h, 0.3 * np.roll(h, 37), dt


def section_speed(repeats=5) -> dict:
    """CPU time [s] per run of the section and rigid solvers on :func:`record` (best of
    ``repeats``, compiled first), with the section run's step and event counts."""
    dock = navy_dock()
    h, v, dt = record()
    simulate_section(dock, h[:400], v[:400], dt)  # compile
    times = []
    for _ in range(repeats):
        t0 = time.process_time()
        res = simulate_section(dock, h, v, dt)
        times.append(time.process_time() - t0)
    keel = NAVY_BLOCK
    rigid = ShipBlockSystem(ship_mass=dock.ship.mass, block_mass=keel.block_mass, n_blocks=4,
                            half_width=keel.half_width, half_height=keel.half_height,
                            mu_s_ground=0.5, mu_k_ground=0.4, mu_s_ship=0.5, mu_k_ship=0.4)
    simulate(rigid, h, v, dt)
    rigid_times = []
    for _ in range(repeats):
        t0 = time.process_time()
        simulate(rigid, h, v, dt)
        rigid_times.append(time.process_time() - t0)
    return {
        "section_seconds_per_run": min(times),
        "rigid_seconds_per_run": min(rigid_times),
        "ratio": min(times) / min(rigid_times),
        "accepted_steps": res.stats["accepted_steps"],
        "rejected_steps": res.stats["rejected_steps"],
        "events": res.stats["events"],
        "energy_residual": res.energy["residual"],
        "failure": res.failure,
    }


if __name__ == "__main__":
    print(json.dumps(section_speed(), indent=1))
