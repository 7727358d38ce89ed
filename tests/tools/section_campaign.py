"""Random campaign of the dock-section model (issue 29): random docks and motions, seeded.

Every run must end without an exception other than a refused dock (ParameterError at
construction or at the static state), with finite results, the energy balance within 1e-5 and
non-negative losses, and every strip's friction inside its cone at the samples.

Run: ``python tests/tools/section_campaign.py N`` (prints counts and the worst values).
"""

from __future__ import annotations

import math
import sys

import numpy as np

from shipblock.errors import ParameterError
from shipblock.section import Block, BlockLine, Cap, DockSection, Ship
from shipblock.section.simulate import simulate_section

G = 9.80665


def random_dock(rng) -> DockSection:
    def cap():
        mu_s = rng.uniform(0.2, 0.7)
        return Cap(modulus=rng.uniform(0.3e9, 3e9), proportional_limit=rng.uniform(3e6, 10e6),
                   damping_ratio=rng.uniform(0.05, 0.5), mu_s=mu_s,
                   mu_k=mu_s * rng.uniform(0.7, 1.0), shear_ratio=rng.uniform(0.2, 1.0))

    keel_blk = Block(top=cap(), bottom=cap())
    beam = rng.uniform(4.0, 12.0)
    mass = rng.uniform(1e5, 2e6)
    ship = Ship(mass=mass, roll_inertia=mass * (0.35 * 2 * beam) ** 2,
                g_height=rng.uniform(1.5, 8.0), keel_half_width=rng.uniform(0.4, 1.2),
                half_beam=beam, g_offset=rng.uniform(-0.3, 0.3))
    n_sides = int(rng.integers(0, 3))
    offset = rng.uniform(0.45, 0.8) * beam
    sides = []
    for side in range(n_sides):
        sign = -1.0 if (n_sides == 2 and side == 0) or (n_sides == 1 and rng.uniform() < 0.5) \
            else 1.0
        hull = rng.uniform(0.0, 0.5)
        slope = rng.uniform(0.0, 0.3)
        blk = Block(half_height=keel_blk.half_height + hull / 2, top=cap(), bottom=cap())
        sides.append(BlockLine(block=blk, n_blocks=int(rng.integers(1, 5)), offset=sign * offset,
                               moving=bool(rng.uniform() < 0.6), hull_height=hull,
                               hull_slope=sign * slope))
    return DockSection(ship, BlockLine(block=keel_blk, n_blocks=int(rng.integers(2, 9))),
                       tuple(sides), n_springs=int(rng.integers(2, 8)))


def random_motion(rng, duration=3.0, dt=0.005):
    t = np.arange(0.0, duration, dt)
    pga = rng.uniform(0.1, 1.0) * G
    h = sum(rng.normal() * np.sin(2 * np.pi * rng.uniform(0.5, 8) * t + rng.uniform(0, 6))
            for _ in range(4))
    env = np.exp(-((t - duration / 3) / (duration / 4)) ** 2)
    h = pga * env * h / np.max(np.abs(env * h))
    v = rng.uniform(0.0, 0.5) * np.roll(h, int(rng.integers(1, 50)))
    return h, v, dt


def run(n: int, seed: int = 29) -> dict:
    rng = np.random.default_rng(seed)
    refused = ran = failures = 0
    worst_energy = worst_cone = 0.0
    for _ in range(n):
        try:
            dock = random_dock(rng)
            h, v, dt = random_motion(rng)
            res = simulate_section(dock, h, v, dt)
        except ParameterError:
            refused += 1
            continue
        ran += 1
        failures += res.failure is not None
        e = res.energy
        assert all(math.isfinite(x) for x in e.values()), e
        assert e["damping"] >= 0 and e["crushing"] >= 0 and e["friction"] >= -1e-6 * max(
            abs(e["ground_work"]), 1.0), e
        worst_energy = max(worst_energy, abs(e["residual"]))
        assert np.all(np.isfinite(res.ship)) and np.all(np.isfinite(res.ship_sway))
        for name in res.normal:
            line, face = name.split("_")
            blk = dock.keel.block if line == "keel" else dock.sides[int(line[4:])].block
            mu = getattr(blk, face).mu_s
            n_, f = res.normal[name], res.friction[name]
            over = np.abs(f) - mu * n_
            worst_cone = max(worst_cone, float(np.max(over / max(np.abs(n_).max(), 1.0))))
    return {"ran": ran, "refused": refused, "failures": failures, "worst_energy": worst_energy,
            "worst_cone_excess": worst_cone}


if __name__ == "__main__":
    print(run(int(sys.argv[1]) if len(sys.argv) > 1 else 100))
