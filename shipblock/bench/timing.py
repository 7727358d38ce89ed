"""Timing on a shared machine, and the systems and records the benchmarks run.

A core of a shared virtual machine slows down by up to 1.8x for periods from milliseconds to
seconds; :func:`interleaved_times` times several calls in turn, round after round, and
:func:`control_loop` is a pure arithmetic workload timed beside them, so that a report can tell
the machine's slowness from the code's.
"""

from __future__ import annotations

import math
import time

import numpy as np
from numba import njit, prange

from shipblock.processing import process_motion
from shipblock.records.catalogue import load_catalogue
from shipblock.system import ShipBlockSystem
from shipblock.units import STANDARD_GRAVITY


def benchmark_records():
    """Processed shipped South Napa records (id, H, V, dt), trimmed to their strong motion.

    The window holds 1-99 % of the horizontal Arias intensity, so that "sliding-dominated" and
    "rocking-dominated" runs are dominated by motion, not by quiet record tails.
    """
    out = []
    for entry in load_catalogue().values():
        m = process_motion(entry.read())
        h, v = m.horizontal, m.vertical
        frac = np.cumsum(h**2) / np.sum(h**2)
        i0, i1 = np.searchsorted(frac, 0.01), np.searchsorted(frac, 0.99)
        # normalise to PGA = 1 g so one scale factor means the same for every record
        f = STANDARD_GRAVITY / np.abs(h).max()
        out.append((entry.id, f * h[i0:i1], f * v[i0:i1], m.dt))
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


def best_time(fn, repeat=3):
    best = np.inf
    out = None
    for _ in range(repeat):
        t0 = time.perf_counter()
        out = fn()
        best = min(best, time.perf_counter() - t0)
    return best, out


def interleaved_times(calls, min_seconds, min_rounds=5, max_rounds=5000):
    """Time several calls in turn, round after round, for at least ``min_seconds``.

    On a shared virtual machine the speed of one core drops by up to 1.8x for periods from
    milliseconds to seconds (a neighbour's load); calls timed in the same round meet the same
    conditions, and a window of many rounds holds the machine's undisturbed speed as well as
    its disturbed one. Each call's best time estimates the first, its median time shows how
    much of the window was disturbed.

    Parameters
    ----------
    calls : sequence of (int, callable)
        Numba threads to run the call on, and the call.
    min_seconds : float
        Rounds continue until this much wall time has passed (and ``min_rounds`` are done).

    Returns
    -------
    times : ndarray, shape (rounds, len(calls))
        Wall time [s] of every call in every round.
    results : list
        Each call's result in the last round.
    """
    import numba

    threads = numba.get_num_threads()
    rows, results = [], [None] * len(calls)
    start = time.perf_counter()
    try:
        while len(rows) < min_rounds or (time.perf_counter() - start < min_seconds
                                         and len(rows) < max_rounds):
            row = []
            for k, (n_threads, fn) in enumerate(calls):
                numba.set_num_threads(n_threads)
                t0 = time.perf_counter()
                results[k] = fn()
                row.append(time.perf_counter() - t0)
            rows.append(row)
    finally:
        numba.set_num_threads(threads)
    return np.array(rows), results


@njit(cache=True, parallel=True)
def _spin(n, out):
    """Control workload: a recurrence of ``n`` steps per entry of ``out``, entries in parallel."""
    for c in prange(out.size):
        x = 0.0
        for i in range(n):
            x = x * 0.9999999 + math.sin(i * 1e-3 + c)
        out[c] = x


def control_loop(seconds):
    """A pure arithmetic loop lasting about ``seconds`` on one thread, as a callable.

    No memory traffic, no shared data; ``4 x numba threads`` equal entries, in parallel when
    numba runs on more than one thread. Its speed is the machine's, whatever the code under
    test does: timed beside that code, it tells a disturbed window from a slower program.
    """
    import numba

    out = np.zeros(4 * numba.config.NUMBA_NUM_THREADS)
    _spin(10, out)  # compiled
    threads = numba.get_num_threads()
    numba.set_num_threads(1)
    try:
        n = 1000
        while True:
            t0 = time.perf_counter()
            _spin(n, out)
            took = time.perf_counter() - t0
            if took >= 0.2 * seconds or n >= 10**9:
                break
            n *= 4
    finally:
        numba.set_num_threads(threads)
    n = max(100, int(n * seconds / max(took, 1e-9)))
    return lambda: _spin(n, out)


def median_spreads(times):
    """Median over best of each column of ``times``: 1 in an undisturbed window."""
    return np.median(times, axis=0) / times.min(axis=0)


def integrated_samples(summary, dts):
    """Samples a batch actually integrated: a run that fails stops there, not at its record's end.

    ``end_time / dt + 1`` per run (the first sample included), from :func:`simulate_batch`'s
    summary and each case's sample interval ``dts``.
    """
    return float(np.sum(summary["end_time"] / dts + 1.0))


def spectrum_time(periods: int, samples: int, rounds: int = 3) -> dict:
    """Best wall time [s] of a 5 %-damped response spectrum of ``periods`` periods (0.01-10 s)
    of a record of ``samples`` samples at 0.01 s, the kernel compiled (or loaded) first."""
    from shipblock.intensity import response_spectrum

    acc = np.random.default_rng(0).standard_normal(samples)
    grid = np.linspace(0.01, 10.0, periods)
    response_spectrum(acc, 0.01, grid[:2])  # compile or load from the cache
    took = []
    for _ in range(rounds):
        t0 = time.perf_counter()
        response_spectrum(acc, 0.01, grid)
        took.append(time.perf_counter() - t0)
    return {"seconds": min(took), "periods": periods, "samples": samples, "rounds": rounds}
