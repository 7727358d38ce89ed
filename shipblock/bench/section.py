"""Benchmark of the dock-section solver (issue 29): a 40 s record at 200 Hz on a dock with a keel
line and two moving side lines, Navy-block defaults; and the rigid solver on the same record.

Part of ``shipblock bench`` (target: 50 ms of one core per run); ``python -m
shipblock.bench.section`` prints the JSON alone, ``python -m shipblock.bench.section --study``
also times a small study (:func:`section_study`: 200 runs in 2 processes, extrapolated to the
target's 10,000 runs on 2 cores in 10 minutes).
"""

from __future__ import annotations

import json
import sys
import time
from concurrent.futures import ProcessPoolExecutor

import numpy as np

from shipblock.bench.targets import TARGETS
from shipblock.section import NAVY_BLOCK, Block, BlockLine, DockSection, Ship
from shipblock.section.simulate import simulate_section, simulate_section_batch
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
    ``repeats``, compiled first), with the section run's step and event counts; the section
    also with Dormand-Prince throughout (``exponential_steps=False``), interleaved with the
    default runs so that both see the same load."""
    dock = navy_dock()
    h, v, dt = record()
    simulate_section(dock, h[:400], v[:400], dt)  # compile
    times, dopri_times = [], []
    for _ in range(repeats):
        t0 = time.process_time()
        res = simulate_section(dock, h, v, dt)
        times.append(time.process_time() - t0)
        t0 = time.process_time()
        dopri = simulate_section(dock, h, v, dt, exponential_steps=False)
        dopri_times.append(time.process_time() - t0)
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
        "exponential_steps": res.stats["exponential_steps"],
        "settled_regimes": res.stats["settled_regimes"],
        "events": res.stats["events"],
        "section_dopri_seconds_per_run": min(dopri_times),
        "dopri_accepted_steps": dopri.stats["accepted_steps"],
        "dopri_rejected_steps": dopri.stats["rejected_steps"],
        "energy_residual": res.energy["residual"],
        "failure": res.failure,
    }


def _study_share(seeds):
    """One process's share of :func:`section_study`: the batch of its seeds' records, timed
    after a short compile/warm-up run (CPU and wall seconds, failures)."""
    dock = navy_dock()
    h, v, dt = record()
    simulate_section(dock, h[:400], v[:400], dt)
    motions = [record(pga=0.2 + 0.4 * ((s * 0.618034) % 1.0), seed=s)
               for s in seeds]
    c0, w0 = time.process_time(), time.perf_counter()
    out = simulate_section_batch(dock, motions)
    return (time.process_time() - c0, time.perf_counter() - w0,
            sum(r["failure"] is not None for r in out))


def section_study(n_runs=200, processes=2, target_runs=10_000) -> dict:
    """A study's cost: ``n_runs`` records (seeded, PGA 0.2-0.6 g, 40 s at 200 Hz) on the
    benchmark dock through :func:`simulate_section_batch`, split over ``processes`` processes
    started together; the wall time of the slowest share extrapolated linearly to
    ``target_runs`` (the target: 10,000 runs on 2 cores within 600 s), and the CPU time per run
    times ``target_runs / processes`` (what free cores would take)."""
    shares = [list(range(1000 + k, 1000 + n_runs, processes)) for k in range(processes)]
    with ProcessPoolExecutor(processes) as pool:
        res = list(pool.map(_study_share, shares))
    wall = max(r[1] for r in res)
    cpu = sum(r[0] for r in res) / n_runs
    # on a shared machine the wall time holds the other users' load; the CPU time per run over
    # the processes is what two free cores would take
    return {"runs": n_runs, "processes": processes, "wall_seconds": wall,
            "cpu_seconds_per_run": cpu, "failures": sum(r[2] for r in res),
            "extrapolated_wall_seconds": wall * target_runs / n_runs,
            "extrapolated_cpu_seconds_on_free_cores": cpu * target_runs / processes,
            "target_runs": target_runs, "target_seconds": TARGETS["section_study_seconds"]}


if __name__ == "__main__":
    print(json.dumps(section_speed(), indent=1))
    if "--study" in sys.argv[1:]:
        print(json.dumps(section_study(), indent=1))
