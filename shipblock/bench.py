"""Benchmarks behind ``shipblock bench``: throughput, accuracy at speed, pySLAMMER, scaling.

Measured, never asserted in unit tests. Figures go to the terminal and optionally to JSON; the
documentation's benchmark page quotes a run of this command.
"""

from __future__ import annotations

import json
import sys
import time

import numpy as np

from shipblock.solver import simulate, simulate_batch
from shipblock.system import ShipBlockSystem
from shipblock.units import STANDARD_GRAVITY


def _records(quick):
    """Processed shipped South Napa records (H, V, dt), trimmed to their strong motion.

    The window holds 1-99 % of the horizontal Arias intensity, so that "sliding-dominated" and
    "rocking-dominated" runs are dominated by motion, not by quiet record tails.
    """
    from shipblock.catalogue import load_catalogue
    from shipblock.processing import process_motion

    out = []
    for entry in load_catalogue().values():
        m = process_motion(entry.read())
        h, v = m.horizontal, m.vertical
        frac = np.cumsum(h**2) / np.sum(h**2)
        i0, i1 = np.searchsorted(frac, 0.01), np.searchsorted(frac, 0.99)
        # normalise to PGA = 1 g so one scale factor means the same for every record
        f = STANDARD_GRAVITY / np.abs(h).max()
        out.append((entry.id, f * h[i0:i1], f * v[i0:i1], m.dt))
        if quick and len(out) >= 2:
            break
    return out


def sliding_system():
    """Blocks far too wide to rock, friction 0.1 on the ground; the ship held by friction."""
    return ShipBlockSystem(ship_mass=5e6, block_mass=1500.0, n_blocks=150, half_width=1.5,
                           half_height=0.5, mu_s_ground=0.1, mu_k_ground=0.1, mu_s_ship=0.8,
                           mu_k_ship=0.8)


def rocking_system():
    """Slender blocks (B/H = 0.15) held by high friction: they rock through most strong shaking."""
    return ShipBlockSystem(ship_mass=5e6, block_mass=1500.0, n_blocks=150, half_width=0.12,
                           half_height=0.8, mu_s_ground=0.8, mu_k_ground=0.8, mu_s_ship=0.8,
                           mu_k_ship=0.8)


def _time(fn, repeat=3):
    best = np.inf
    out = None
    for _ in range(repeat):
        t0 = time.perf_counter()
        out = fn()
        best = min(best, time.perf_counter() - t0)
    return best, out


def throughput(system, records, scale, rtol=1e-8):
    """Samples per second on one core for full simulations of the records at a scale factor."""
    import numba

    threads = numba.get_num_threads()
    numba.set_num_threads(1)
    try:
        simulate(system, records[0][1][:200], None, records[0][3])  # compile / warm up
        cases = np.array([[i, 0, scale, scale] for i in range(len(records))], float)
        recs = [(h, v) for _, h, v, _ in records]
        dts = [d for *_, d in records]
        seconds, summ = _time(lambda: simulate_batch(system, recs, dts, cases, rtol=rtol))
    finally:
        numba.set_num_threads(threads)
    n = sum(h.size for _, h, _, _ in records)
    mode_time = {m: float(np.sum(summ[f"time_in_mode_{m}"])) for m in range(1, 9)}
    total = sum(mode_time.values())
    rocking = sum(mode_time[m] for m in (3, 6, 7, 8)) / total
    sliding = sum(mode_time[m] for m in (2, 4, 5, 6, 7, 8)) / total
    return {"samples": n, "seconds": seconds, "samples_per_s": n / seconds,
            "fraction_rocking": rocking, "fraction_sliding": sliding,
            "peak_rotation": summ["peak_rotation"].tolist()}


def rocking_accuracy(system, records, scale):
    """Peak rotation at the default tolerance vs a converged run (rtol = 1e-12)."""
    diffs = []
    for _, h, v, dt in records:
        a = simulate(system, h * scale, v * scale, dt).summary["peak_rotation"]
        b = simulate(system, h * scale, v * scale, dt, rtol=1e-12, atol=1e-14).summary["peak_rotation"]
        diffs.append(abs(a - b))
    return max(diffs)


def batch_scaling(system, records, scale, n_copies=8):
    """Speed-up of simulate_batch from 1 to all cores (numba threads)."""
    import numba

    recs = [(h, v) for _, h, v, _ in records]
    dts = [d for *_, d in records]
    cases = np.array([[i % len(records), 0, scale * (1 + 0.01 * i), scale * (1 + 0.01 * i)]
                      for i in range(n_copies * len(records))], float)
    n_threads = numba.config.NUMBA_NUM_THREADS
    numba.set_num_threads(1)
    simulate_batch(system, recs, dts, cases[:1])
    t1, r1 = _time(lambda: simulate_batch(system, recs, dts, cases), repeat=2)
    numba.set_num_threads(n_threads)
    tn, rn = _time(lambda: simulate_batch(system, recs, dts, cases), repeat=2)
    identical = all(np.array_equal(r1[k], rn[k], equal_nan=True) for k in r1)
    return {"cores": n_threads, "cases": len(cases), "seconds_1": t1, "seconds_n": tn,
            "speedup": t1 / tn, "identical": identical, "runs_per_s": len(cases) / tn}


def pyslammer_comparison(ky_g=0.1):
    """Time pySLAMMER's RigidAnalysis vs shipblock on pySLAMMER's sample records.

    shipblock runs the ship-block system configured so only the blocks slide (friction
    mu = ky, blocks too wide to rock, ship held by friction): a two-way Newmark block, exact
    for piecewise-linear input. pySLAMMER's rigid analysis is one-way (down-slope) with
    trapezoidal time stepping, so the displacements are not expected to agree; the
    comparison is of speed. Exactness of shipblock's sliding is established separately
    against the exact reference integrator in the test suite.
    """
    try:
        import pyslammer
        from pyslammer.utilities import sample_ground_motions
    except ImportError:
        return None
    gms = sample_ground_motions()
    system = sliding_system().replace(mu_s_ground=ky_g, mu_k_ground=ky_g)
    rows = []
    first = next(iter(gms.values()))
    simulate(system, np.asarray(first.accel[:100]) * STANDARD_GRAVITY, None, first.dt)
    for name, gm in gms.items():
        acc = np.asarray(gm.accel, float) * STANDARD_GRAVITY
        t_ps, ra = _time(lambda gm=gm: pyslammer.RigidAnalysis(ky_g, gm), repeat=1)
        t_sb, res = _time(lambda acc=acc, gm=gm: simulate(system, acc, None, gm.dt), repeat=3)
        rows.append({"record": name, "samples": acc.size, "pyslammer_s": t_ps, "shipblock_s": t_sb,
                     "speedup": t_ps / t_sb,
                     "pyslammer_disp_m": float(ra.max_sliding_disp),
                     "shipblock_peak_slip_m": res.summary["peak_block_slip"]})
    return rows


def run_benchmarks(quick=False, pyslammer=True, output=None, stream=None):
    """Run all benchmarks and print a report; returns 0."""
    out = stream or sys.stdout
    records = _records(quick)
    out.write(f"records: {', '.join(r[0] for r in records)} "
              f"({sum(r[1].size for r in records)} samples)\n")
    results = {}
    slide = throughput(sliding_system(), records, scale=0.6)
    results["sliding"] = slide
    out.write(f"sliding-dominated : {slide['samples_per_s']:.3g} samples/s per core "
              f"(sliding {100 * slide['fraction_sliding']:.0f} % of the time)\n")
    rock = throughput(rocking_system(), records, scale=0.3)
    rock["peak_rotation_error"] = rocking_accuracy(rocking_system(), records[:2], 0.3)
    results["rocking"] = rock
    out.write(f"rocking-dominated : {rock['samples_per_s']:.3g} samples/s per core "
              f"(rocking {100 * rock['fraction_rocking']:.0f} % of the time), "
              f"peak theta within {rock['peak_rotation_error']:.2g} rad of a converged run\n")
    scaling = batch_scaling(rocking_system(), records, 0.3, n_copies=4 if quick else 12)
    results["batch_scaling"] = scaling
    out.write(f"batch scaling     : {scaling['speedup']:.2f}x on {scaling['cores']} cores "
              f"({scaling['cases']} cases, {scaling['runs_per_s']:.3g} runs/s, results "
              f"{'identical' if scaling['identical'] else 'DIFFERENT'})\n")
    if pyslammer:
        rows = pyslammer_comparison()
        if rows is None:
            out.write("pySLAMMER         : not installed (pip install pyslammer)\n")
        else:
            results["pyslammer"] = rows
            sp = np.array([r["speedup"] for r in rows])
            out.write(f"pySLAMMER         : shipblock {np.median(sp):.0f}x faster per record "
                      f"(min {sp.min():.0f}x, max {sp.max():.0f}x, {len(rows)} records, ky = 0.1 g)\n")
    if output:
        with open(output, "w") as fh:
            json.dump(results, fh, indent=2)
        out.write(f"results written to {output}\n")
    return 0
