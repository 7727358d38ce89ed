"""Benchmarks behind ``shipblock bench``: throughput, accuracy, pySLAMMER, scaling, campaign.

Measured, never asserted in unit tests. Figures go to the terminal and optionally to JSON; the
documentation's benchmark page quotes a run of this command.

* samples per second on one core and runs per second on all cores, sliding- and
  rocking-dominated, on the shipped records (:func:`throughput`, :func:`runs_per_second`);
* peak rotation at the default tolerance against a converged run;
* speed-up of :func:`~shipblock.simulate_batch` from one core to all;
* time per record against pySLAMMER (:func:`pyslammer_comparison`);
* a campaign of a generated pipeline through :func:`~shipblock.fragility.pipeline.run_pipeline`
  in a subprocess: wall time, stages and memory (:func:`campaign`);
* a batch on one thread and on all, beside a busy process
  (:func:`shipblock.bench_parallel.busy_core_batch`);
* the README's demo command from an empty numba cache
  (:func:`shipblock.bench_startup.cold_start`);
* with ``--dask``, a pipeline on LocalClusters of 1 and 2 workers
  (:func:`shipblock.bench_parallel.dask_scaling`).
"""

from __future__ import annotations

import json
import math
import os
import sys
import time
from pathlib import Path

import numpy as np
from numba import njit, prange

from shipblock.solver import RecordSet, simulate, simulate_batch
from shipblock.system import ShipBlockSystem
from shipblock.units import STANDARD_GRAVITY


def _records():
    """Processed shipped South Napa records (id, H, V, dt), trimmed to their strong motion.

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


def _spread(times):
    """Median over best of each column of ``times``: 1 in an undisturbed window."""
    return np.median(times, axis=0) / times.min(axis=0)


def throughput(system, records, scale, rtol=1e-8, min_seconds=1.0):
    """Samples per second on one core for full simulations of the records at a scale factor.

    The samples counted are those integrated: a run that fails (overturns) stops there. One
    :func:`~shipblock.simulate_batch` call over all records is timed again and again for
    ``min_seconds``, each call followed by a pure arithmetic loop of about the same length
    (:func:`control_loop`), all on one thread (:func:`interleaved_times`).

    Returns
    -------
    dict
        ``samples_per_s`` from the best call and ``samples_per_s_median`` from the median one,
        ``seconds`` (best call), ``rounds``, ``spread`` and ``control_spread`` (median over
        best time of the calls and of the control loop: the two are alike when the machine,
        not the program, varied), ``samples`` integrated, ``input_samples``, ``failures``,
        the fractions of time rocking and sliding and each run's ``peak_rotation``.
    """
    cases = np.array([[i, 0, scale, scale] for i in range(len(records))], float)
    dts = [d for *_, d in records]
    # packed once, as a campaign's chunk is: the solver's speed is measured, not the packing
    packed = RecordSet([(h, v) for _, h, v, _ in records], dts)
    call = lambda: simulate_batch(system, packed, cases=cases, rtol=rtol)  # noqa: E731
    warm_up, _ = interleaved_times([(1, call)], 0.0, min_rounds=2)  # compiles, loads
    times, (summ, _) = interleaved_times([(1, call), (1, control_loop(warm_up.min()))],
                                         min_seconds)
    n = integrated_samples(summ, np.array(dts))
    mode_time = {m: float(np.sum(summ[f"time_in_mode_{m}"])) for m in range(1, 9)}
    total = sum(mode_time.values())
    rocking = sum(mode_time[m] for m in (3, 6, 7, 8)) / total
    sliding = sum(mode_time[m] for m in (2, 4, 5, 6, 7, 8)) / total
    spread, control_spread = _spread(times)
    best, median = times[:, 0].min(), np.median(times[:, 0])
    return {"samples": n, "input_samples": sum(h.size for _, h, _, _ in records),
            "failures": int(np.count_nonzero(summ["failure"])), "seconds": best,
            "samples_per_s": n / best, "samples_per_s_median": n / median,
            "rounds": len(times), "spread": float(spread), "control_spread": float(control_spread),
            "fraction_rocking": rocking, "fraction_sliding": sliding,
            "peak_rotation": summ["peak_rotation"].tolist()}


def integrated_samples(summary, dts):
    """Samples a batch actually integrated: a run that fails stops there, not at its record's end.

    ``end_time / dt + 1`` per run (the first sample included), from :func:`simulate_batch`'s
    summary and each case's sample interval ``dts``.
    """
    return float(np.sum(summary["end_time"] / dts + 1.0))


def runs_per_second(system, records, scale, min_seconds=1.0, spread=0.2):
    """Runs per second of :func:`~shipblock.simulate_batch` on all cores (numba threads).

    Each case is one of the records at a scale factor spread over ``scale * (1 +- spread/2)``;
    the number of cases grows until one call takes at least ``min_seconds``; the better of that
    call and one more is kept.

    Returns
    -------
    dict
        ``cores``, ``cases``, ``seconds``, ``runs_per_s``, ``samples_per_run`` (mean samples
        integrated in a run: up to its failure if it fails), ``samples_per_s``, ``failures``
        and the fractions of time sliding and rocking.
    """
    import numba

    recs = [(h, v) for _, h, v, _ in records]
    dts = [d for *_, d in records]
    n_rec = len(recs)
    cores = numba.get_num_threads()

    def cases_of(n):
        k = np.arange(n)
        f = scale * (1.0 + spread * (np.modf(k * 0.6180339887498949)[0] - 0.5))
        return np.column_stack([k % n_rec, np.zeros(n), f, f])

    simulate_batch(system, recs, dts, cases_of(1))  # compile / warm up
    n = 2 * cores * n_rec
    while True:
        seconds, _ = _time(lambda n=n: simulate_batch(system, recs, dts, cases_of(n)), repeat=1)
        if seconds >= min_seconds or n >= 10**6:
            break
        n = int(min(10 * n, max(2 * n, 1.2 * n * min_seconds / max(seconds, 1e-9))))
        n = -(-n // n_rec) * n_rec
    again, summ = _time(lambda: simulate_batch(system, recs, dts, cases_of(n)), repeat=1)
    seconds = min(seconds, again)
    mode_time = np.array([np.sum(summ[f"time_in_mode_{m}"]) for m in range(1, 9)])
    total = mode_time.sum()
    samples = integrated_samples(summ, np.asarray(dts)[np.arange(n) % n_rec])
    return {"cores": cores, "cases": n, "seconds": seconds, "runs_per_s": n / seconds,
            "samples_per_run": samples / n, "samples_per_s": samples / seconds,
            "failures": int(np.count_nonzero(summ["failure"])),
            "fraction_rocking": float(mode_time[[2, 5, 6, 7]].sum() / total),
            "fraction_sliding": float(mode_time[[1, 3, 4, 5, 6, 7]].sum() / total)}


def rocking_accuracy(system, records, scale):
    """Peak rotation at the default tolerance vs a converged run (rtol = 1e-12)."""
    diffs = []
    for _, h, v, dt in records:
        a = simulate(system, h * scale, v * scale, dt).summary["peak_rotation"]
        b = simulate(system, h * scale, v * scale, dt, rtol=1e-12, atol=1e-14).summary["peak_rotation"]
        diffs.append(abs(a - b))
    return max(diffs)


def batch_scaling(system, records, scale, n_copies=8, min_seconds=3.0):
    """Speed-up of simulate_batch from one core to all cores (numba threads), beside the machine's.

    In every round the batch runs on one thread and on all threads, then a pure arithmetic
    loop of about the same length (:func:`control_loop`) on one thread and on all
    (:func:`interleaved_times`), rounds for ``min_seconds``: the loop's speed-up is the ceiling
    the machine allows in the same window, and no batch of simulations can scale better.

    Returns
    -------
    dict
        ``cores``, ``cases``, ``seconds_1`` and ``seconds_n`` (best calls), ``speedup`` (their
        ratio) and ``speedup_median`` (median over rounds of the round's ratio), the same for
        the control loop (``machine_speedup``, ``machine_speedup_median``), ``rounds``,
        ``runs_per_s`` on all cores and whether the results on one and all cores are
        ``identical``.
    """
    import numba

    recs = [(h, v) for _, h, v, _ in records]
    dts = [d for *_, d in records]
    cases = np.array([[i % len(records), 0, scale * (1 + 0.01 * i), scale * (1 + 0.01 * i)]
                      for i in range(n_copies * len(records))], float)
    call = lambda: simulate_batch(system, recs, dts, cases)  # noqa: E731
    n_threads = numba.config.NUMBA_NUM_THREADS
    warm_up, _ = interleaved_times([(1, call)], 0.0, min_rounds=2)  # compiles, loads
    control = control_loop(warm_up.min())
    times, (r1, rn, _, _) = interleaved_times(
        [(1, call), (n_threads, call), (1, control), (n_threads, control)], min_seconds)
    best = times.min(axis=0)
    identical = all(np.array_equal(r1[k], rn[k], equal_nan=True) for k in r1)
    return {"cores": n_threads, "cases": len(cases), "seconds_1": best[0], "seconds_n": best[1],
            "speedup": best[0] / best[1],
            "speedup_median": float(np.median(times[:, 0] / times[:, 1])),
            "machine_speedup": best[2] / best[3],
            "machine_speedup_median": float(np.median(times[:, 2] / times[:, 3])),
            "rounds": len(times), "identical": identical, "runs_per_s": len(cases) / best[1]}


def pyslammer_comparison(ky_g=0.1, rounds=5):
    """Time pySLAMMER's RigidAnalysis vs shipblock on pySLAMMER's sample records.

    shipblock runs the ship-block system configured so only the blocks slide (friction
    mu = ky, blocks too wide to rock, ship held by friction): a two-way Newmark block, exact
    for piecewise-linear input. pySLAMMER's rigid analysis is one-way (down-slope) with
    trapezoidal time stepping, so the displacements are not expected to agree; the
    comparison is of speed. Exactness of shipblock's sliding is established separately
    against the exact reference integrator in the test suite.

    The two programs are timed in alternation, ``rounds`` times: each round runs pySLAMMER
    once on every record and :func:`~shipblock.simulate_batch` (one call over all records, one
    thread) three times; each program's time is its best round, so that both are measured in
    the machine's best minute (on a virtual machine the speed of either varies by up to 1.8x
    from one minute to the next). Each program gets its records loaded beforehand:
    pySLAMMER's ``GroundMotion`` objects, shipblock's :class:`~shipblock.RecordSet`; the
    batch call on the plain list of records (checked and packed at every call) is timed too.
    :func:`~shipblock.simulate`, which also builds the full histories, is timed per record
    (best of three) beside them.

    Returns
    -------
    dict or None
        ``records`` (one row per record: samples, best times [s], speed-up of
        :func:`~shipblock.simulate`, peak displacements [m]), ``batch_s`` and the times per
        record [s] ``batch_s_per_record`` (packed records), ``batch_list_s_per_record``
        (list of records), ``simulate_s_per_record`` and ``pyslammer_s_per_record``,
        ``speedup_batch`` (pySLAMMER's over the packed batch's), ``speedup_batch_list``,
        ``rounds`` and
        ``batch_equals_simulate`` (same peak slips from both entry points); None without
        pySLAMMER.
    """
    import numba

    try:
        import pyslammer
        from pyslammer.utilities import sample_ground_motions
    except ImportError:
        return None
    gms = list(sample_ground_motions().items())
    system = sliding_system().replace(mu_s_ground=ky_g, mu_k_ground=ky_g)
    recs = [(np.asarray(gm.accel, float) * STANDARD_GRAVITY, None) for _, gm in gms]
    dts = [gm.dt for _, gm in gms]
    simulate(system, recs[0][0][:100], None, dts[0])  # compiled before any timing
    rows = []
    for (name, gm), (acc, _) in zip(gms, recs, strict=True):
        t_sb, res = _time(lambda acc=acc, gm=gm: simulate(system, acc, None, gm.dt), repeat=3)
        rows.append({"record": name, "samples": acc.size, "shipblock_s": t_sb,
                     "pyslammer_s": np.inf, "shipblock_peak_slip_m": res.summary["peak_block_slip"]})
    cases = np.array([[i, 0, 1.0, 1.0] for i in range(len(recs))])
    threads = numba.get_num_threads()
    numba.set_num_threads(1)
    t_ps_best = t_batch = t_list = np.inf
    packed = RecordSet(recs, dts)
    try:
        simulate_batch(system, recs[:1], dts[:1], cases[:1])
        for _ in range(max(1, rounds)):  # at least one round: it gives the batch's summary
            t_round = 0.0
            for row, (_, gm) in zip(rows, gms, strict=True):
                t_ps, ra = _time(lambda gm=gm: pyslammer.RigidAnalysis(ky_g, gm), repeat=1)
                row["pyslammer_s"] = min(row["pyslammer_s"], t_ps)
                row["pyslammer_disp_m"] = float(ra.max_sliding_disp)
                t_round += t_ps
            t_ps_best = min(t_ps_best, t_round)
            t, summ = _time(lambda: simulate_batch(system, packed, cases=cases), repeat=3)
            t_batch = min(t_batch, t)
            t, _ = _time(lambda: simulate_batch(system, recs, dts, cases), repeat=3)
            t_list = min(t_list, t)
    finally:
        numba.set_num_threads(threads)
    for row in rows:
        row["speedup"] = row["pyslammer_s"] / row["shipblock_s"]
    same = bool(np.array_equal(summ["peak_block_slip"],
                               [r["shipblock_peak_slip_m"] for r in rows]))
    t_ps = t_ps_best / len(recs)
    return {"records": rows, "rounds": rounds, "batch_s": t_batch,
            "batch_s_per_record": t_batch / len(recs), "batch_equals_simulate": same,
            "batch_list_s_per_record": t_list / len(recs),
            "speedup_batch_list": t_ps / (t_list / len(recs)),
            "pyslammer_s_per_record": t_ps,
            "simulate_s_per_record": float(np.mean([r["shipblock_s"] for r in rows])),
            "speedup_batch": t_ps / (t_batch / len(recs))}


#: Targets of the project's issues 2 and 4: samples per second on one core in rocking-dominated
#: runs (with peak theta within ``peak_rotation_error`` [rad] of a converged run), runs per second
#: on all cores (2) of records of about 10k samples, wall time [s] and memory increase [bytes] of
#: a 100,000-run campaign, speed-up over pySLAMMER and scaling of the batch entry point.
TARGETS = {"rocking_samples_per_s": 2e7, "peak_rotation_error": 1e-4,
           "sliding_runs_per_s": 20_000, "rocking_runs_per_s": 1_000,
           "campaign_seconds": 120.0, "campaign_memory": 200e6, "pyslammer_speedup": 200.0,
           "batch_speedup": 1.8}

#: Record length [samples] the runs-per-second targets refer to.
TARGET_SAMPLES = 10_000

#: Default number of runs of the campaign (``--quick``: ``QUICK_CAMPAIGN_RUNS``).
CAMPAIGN_RUNS = 100_000
QUICK_CAMPAIGN_RUNS = 300


def _timing_note(r):
    """How a :func:`throughput` figure was obtained, for the report."""
    spread, control = r["spread"], r["control_spread"]
    return (f"best of {r['rounds']} calls alternating with a control loop; median "
            f"{r['samples_per_s_median']:.3g}: the median call took {spread:.2f}x "
            f"the best, the control loop's {control:.2f}x")


def scaling_verdict(scaling, target=None):
    """Verdict on a :func:`batch_scaling` result against the target speed-up.

    A miss is said to be the machine's when the control loop timed in the same rounds missed
    the target too: no batch can scale better than the machine allows.
    """
    target = TARGETS["batch_speedup"] if target is None else target
    if scaling["speedup"] >= target:
        return _verdict(True)
    if scaling["machine_speedup"] < target:
        return (f"{_verdict(False)}, nor did the control loop: the machine allowed no more "
                "in this window")
    return _verdict(False)


def _verdict(ok):
    return "met" if ok else "NOT met"


def _mb(n):
    return f"{n / 1e6:.0f} MB"


def run_benchmarks(quick=False, pyslammer=True, output=None, stream=None, campaign_runs=None,
                   chunk_size=None, profile=None, cold=True, dask_workers=None):
    """Run all benchmarks and print a report.

    Parameters
    ----------
    quick : bool
        Shorter timings and a small campaign (:data:`QUICK_CAMPAIGN_RUNS` runs).
    pyslammer : bool
        Include the comparison with pySLAMMER (if installed).
    output : str or os.PathLike, optional
        Also write the results as JSON.
    stream : file-like, optional
        Where the report goes (default standard output).
    campaign_runs : int, optional
        Runs of the campaign (default :data:`CAMPAIGN_RUNS`, or :data:`QUICK_CAMPAIGN_RUNS`
        with ``quick``); 0 skips it.
    chunk_size : int, optional
        Cases per chunk of the campaign (default: about 100 chunks).
    profile : str or os.PathLike, optional
        Profile the campaign with :mod:`cProfile` and write the statistics to this file.
    cold : bool
        Include the cold start (:func:`shipblock.bench_startup.cold_start`: the demo command
        from an empty numba cache, in subprocesses).
    dask_workers : sequence of int, optional
        Also run :func:`shipblock.bench_parallel.dask_scaling` on LocalClusters of these numbers
        of worker processes.

    Returns
    -------
    int
        0.
    """
    import numba

    out = stream or sys.stdout
    if campaign_runs is None:
        campaign_runs = QUICK_CAMPAIGN_RUNS if quick else CAMPAIGN_RUNS
    min_seconds = 0.3 if quick else 1.0
    # throughput windows longer than most of this VM's slow periods (milliseconds to ~2 s)
    window = 0.3 if quick else 2.0
    machine = {"cpus": os.cpu_count(), "numba_threads": numba.get_num_threads(),
               "load_average": os.getloadavg() if hasattr(os, "getloadavg") else None}
    load = machine["load_average"]
    load = "" if load is None else f", load average {load[0]:.2f} at the start"
    out.write(f"machine: {machine['cpus']} CPUs, {machine['numba_threads']} numba threads{load}\n")
    records = _records()
    out.write(f"records: {', '.join(r[0] for r in records)} "
              f"({sum(r[1].size for r in records)} samples)\n")
    results = {"machine": machine, "targets": TARGETS}
    slide = throughput(sliding_system(), records, scale=0.6, min_seconds=window)
    results["sliding"] = slide
    out.write(f"sliding-dominated : {slide['samples_per_s']:.3g} samples/s per core "
              f"(sliding {100 * slide['fraction_sliding']:.0f} % of the time; "
              f"{_timing_note(slide)})\n")
    rock = throughput(rocking_system(), records, scale=0.3, min_seconds=window)
    rock["peak_rotation_error"] = rocking_accuracy(rocking_system(), records, 0.3)
    results["rocking"] = rock
    out.write(f"rocking-dominated : {rock['samples_per_s']:.3g} samples/s per core "
              f"(rocking {100 * rock['fraction_rocking']:.0f} % of the time; "
              f"{rock['samples']:.0f} samples integrated of {rock['input_samples']}, "
              f"{rock['failures']} of {len(records)} runs overturn; {_timing_note(rock)}), "
              f"peak theta within {rock['peak_rotation_error']:.2g} rad of a converged run "
              f"(target {TARGETS['rocking_samples_per_s']:.2g} samples/s: "
              f"{_verdict(rock['samples_per_s'] >= TARGETS['rocking_samples_per_s'])}; "
              f"accuracy target {TARGETS['peak_rotation_error']:.0e} rad: "
              f"{_verdict(rock['peak_rotation_error'] <= TARGETS['peak_rotation_error'])})\n")
    for key, system, scale in (("sliding", sliding_system(), 0.6),
                               ("rocking", rocking_system(), 0.3)):
        r = runs_per_second(system, records, scale, min_seconds)
        r["runs_per_s_at_target_length"] = r["samples_per_s"] / TARGET_SAMPLES
        results[f"{key}_runs"] = r
        target = TARGETS[f"{key}_runs_per_s"]
        out.write(f"{key + ' runs':<18}: {r['runs_per_s']:.3g} runs/s on {r['cores']} cores "
                  f"({r['cases']} runs of {r['samples_per_run']:.0f} samples integrated on average, "
                  f"{r['failures']} failing, "
                  f"{key} {100 * r[f'fraction_{key}']:.0f} % of the time); "
                  f"{r['runs_per_s_at_target_length']:.3g} runs/s of {TARGET_SAMPLES} samples "
                  f"(target {target}: {_verdict(r['runs_per_s_at_target_length'] >= target)})\n")
    scaling = batch_scaling(rocking_system(), records, 0.3, n_copies=4 if quick else 24,
                            min_seconds=1.0 if quick else 3.0)
    results["batch_scaling"] = scaling
    out.write(f"batch scaling     : {scaling['speedup']:.3f}x on {scaling['cores']} cores "
              f"({scaling['cases']} cases, {scaling['runs_per_s']:.3g} runs/s, results "
              f"{'identical' if scaling['identical'] else 'DIFFERENT'}; target "
              f"{TARGETS['batch_speedup']}x: {scaling_verdict(scaling)}); a pure arithmetic loop "
              f"timed in the same rounds scales "
              f"{scaling['machine_speedup']:.3f}x (best calls of {scaling['rounds']} rounds; "
              f"median of the rounds' ratios: batch {scaling['speedup_median']:.2f}x, "
              f"loop {scaling['machine_speedup_median']:.2f}x)\n")
    from shipblock.bench_parallel import busy_core_batch, write_busy_core

    busy = busy_core_batch(min_seconds=1.0 if quick else 3.0, copies=(1,) if quick else (1, 10))
    results["busy_core"] = busy
    write_busy_core(out, busy)
    if pyslammer:
        ps = pyslammer_comparison()
        if ps is None:
            out.write("pySLAMMER         : not installed (pip install pyslammer)\n")
        else:
            results["pyslammer"] = ps
            rows = ps["records"]
            sp = np.array([r["speedup"] for r in rows])
            target = TARGETS["pyslammer_speedup"]
            out.write(f"pySLAMMER         : {len(rows)} records, ky = 0.1 g; mean time per record "
                      f"pySLAMMER {1e3 * ps['pyslammer_s_per_record']:.3g} ms, shipblock "
                      f"simulate_batch (1 thread, {len(rows)} records in one call, records "
                      f"packed beforehand as pySLAMMER's are loaded) "
                      f"{1e3 * ps['batch_s_per_record']:.3g} ms: {ps['speedup_batch']:.3g}x "
                      f"faster (target {target:.0f}: {_verdict(ps['speedup_batch'] >= target)}; "
                      f"results {'equal' if ps['batch_equals_simulate'] else 'DIFFERENT'} "
                      f"to simulate())\n")
            out.write(f"{'':20}simulate_batch on the list of records (packed at the call) "
                      f"{1e3 * ps['batch_list_s_per_record']:.3g} ms per record: "
                      f"{ps['speedup_batch_list']:.3g}x\n")
            out.write(f"{'':20}simulate() with full histories "
                      f"{1e3 * ps['simulate_s_per_record']:.3g} ms per record: "
                      f"{ps['pyslammer_s_per_record'] / ps['simulate_s_per_record']:.2g}x "
                      f"(per record: median {np.median(sp):.2g}x, min {sp.min():.2g}x, "
                      f"max {sp.max():.2g}x)\n")
    if cold:
        from shipblock.bench_startup import cold_start, write_cold_start

        out.flush()
        results["cold_start"] = cold_start()
        write_cold_start(out, results["cold_start"])
    if dask_workers:
        from shipblock.bench_parallel import dask_scaling, write_dask_scaling

        out.flush()
        results["dask"] = dask_scaling(dask_workers, quick=quick)
        write_dask_scaling(out, results["dask"])
    if campaign_runs:
        out.flush()
        c = campaign(campaign_runs, chunk_size=chunk_size, profile=profile)
        results["campaign"] = c
        _write_campaign(out, c)
    if output:
        with open(output, "w") as fh:
            json.dump(results, fh, indent=2)
        out.write(f"results written to {output}\n")
    return 0


def _write_campaign(out, c):
    """Print the campaign figures."""
    st = c["stages"]
    full = c["runs"] >= CAMPAIGN_RUNS  # the targets are for a campaign of this size

    def verdict(ok):
        return _verdict(ok) if full else f"applies to {CAMPAIGN_RUNS} runs"

    out.write(f"campaign          : {c['runs']} runs ({c['records']} records x {c['levels']} levels "
              f"x {c['n_mu'] * c['n_slenderness']} systems, chunks of {c['chunk_size']}) in "
              f"{c['seconds']:.3g} s: {c['runs_per_s']:.3g} runs/s, {c['us_per_run']:.3g} us/run "
              f"(target {TARGETS['campaign_seconds']:.0f} s: "
              f"{verdict(c['seconds'] <= TARGETS['campaign_seconds'])})\n")
    bookkeeping = st["runs"] - st.get("solver", float("nan"))
    out.write(f"{'':20}stages: records {st['records']:.3g} s, runs {st['runs']:.3g} s (in "
              f"run_chunk {st.get('solver', float('nan')):.3g} s, chunk bookkeeping "
              f"{1e6 * bookkeeping / c['runs']:.3g} us/run), fragility {st['fragility']:.3g} s, "
              f"write {st['write']:.3g} s; {c['failed_runs']} runs failed\n")
    if "profile" in c:
        p = c["profile"]
        ps = p["stages"]
        outside = p["total"] - p["kernel"]
        out.write(f"campaign profile  : {100 * p['kernel'] / p['total']:.1f} % of the profiled "
                  f"time in compiled kernels; outside them {outside:.3g} s "
                  f"({1e6 * outside / c['runs']:.3g} us/run): batch loop "
                  f"{ps['batch'] - p['kernel']:.3g} s, records {ps['records']:.3g} s, fits "
                  f"{ps['fits']:.3g} s, NetCDF {ps['netcdf_write'] + ps['netcdf_read']:.3g} s "
                  f"(cProfile overhead included)\n")
    if "memory" in c:
        m = c["memory"]
        note = "" if m["peak_reset"] else " (peak not reset: includes the start-up)"
        out.write(f"campaign memory   : {_mb(m['imports'])} after python + imports + kernel, "
                  f"{_mb(m['warmup'])} after a warm-up pipeline; the campaign added "
                  f"{_mb(m['increase'])} (peak {_mb(m['peak'])}){note} (target "
                  f"{_mb(TARGETS['campaign_memory'])}: "
                  f"{verdict(m['increase'] <= TARGETS['campaign_memory'])})\n")


# --------------------------------------------------------------------------------------------
# campaign: a generated pipeline through run_pipeline, in a subprocess
# --------------------------------------------------------------------------------------------

#: Campaign system: the demo pipeline's ship on 150 blocks of 1.2 t, H = 0.6 m; the sweep sets
#: the block slenderness B/H and the static friction on the ground.
_CAMPAIGN_TEMPLATE = """\
# Generated by shipblock.bench.write_campaign_pipeline: {n_runs} runs.
schema_version = 1
title = "shipblock bench campaign"
output = "campaign.nc"

[records]
{catalogue}ids = "all"
horizontal = "H1"

[system]
ship_mass = 5.0e6           # [kg]
block_mass = 1200.0         # [kg]
n_blocks = 150
half_height = 0.6           # [m]
slenderness = 0.5           # B/H [-] (swept)
mu_s_ground = 0.5           # (swept, kinetic/static ratio kept)
mu_k_ground = 0.45
mu_s_ship = 0.5
mu_k_ship = 0.45

[sweep]
mu_ground = {mu}
slenderness = {slenderness}

[design]
type = "ida"
measure = "pga"
levels_g = {levels}
vertical = "same"

[[limit_states]]
name = "block_slip"
edp = "peak_block_slip"
threshold = 0.01            # [m]

[[limit_states]]
name = "any_failure"
edp = "failure"
condition = "nonzero"

[fit]
bootstrap = 0
seed = 1

[execution]
chunk_size = {chunk_size}
"""


def campaign_grid(n_runs, n_records=6, max_levels=12):
    """Sizes of a records x levels x friction x slenderness grid holding about ``n_runs`` runs.

    Parameters
    ----------
    n_runs : int
        Wanted number of runs.
    n_records : int
        Number of records.
    max_levels : int
        Most IM levels; at least ``max_levels - 4`` are used when there are runs enough.

    Returns
    -------
    tuple of int
        ``(n_levels, n_mu, n_slenderness)``: of the grids with a near-square sweep
        (``n_mu <= n_slenderness <= 2 n_mu``), the smallest with at least ``n_runs`` runs
        (ties: the most levels).
    """
    per_record = max(1, -(-int(n_runs) // n_records))
    top = min(max_levels, per_record)
    best = None
    for n_levels in range(top, max(1, top - 4) - 1, -1):
        n_sys = -(-per_record // n_levels)
        for n_mu in range(1, math.isqrt(n_sys) + 1):
            n_sl = -(-n_sys // n_mu)
            if n_sl > 2 * n_mu and n_mu < math.isqrt(n_sys):
                continue
            key = (n_levels * n_mu * n_sl, -n_levels)
            if best is None or key < best[0]:
                best = (key, (n_levels, n_mu, n_sl))
    return best[1]


def write_campaign_pipeline(directory, n_runs, chunk_size=None, catalogue=None):
    """Write a pipeline of about ``n_runs`` runs on the catalogue's records.

    IDA on PGA (levels 0.05 g to 1.2 g) of every record of the catalogue, swept over the static
    friction on the ground (0.2 to 0.7) and the block slenderness B/H (0.2 to 1.0): a mix of
    rest, sliding, rocking and failure. Two limit states; fits without bootstrap.

    Parameters
    ----------
    directory : str or os.PathLike
        Where the pipeline file is written (its output ``campaign.nc`` goes there too).
    n_runs : int
        Wanted number of runs; the grid is the smallest one with at least that many
        (:func:`campaign_grid`).
    chunk_size : int, optional
        Cases per chunk; default: about 100 chunks, at least 64 cases each.
    catalogue : str or os.PathLike, optional
        Record catalogue; default: the shipped one.

    Returns
    -------
    path : pathlib.Path
        The pipeline file.
    info : dict
        ``runs``, ``records``, ``levels``, ``n_mu``, ``n_slenderness``, ``chunk_size``.
    """
    from shipblock.catalogue import load_catalogue

    directory = Path(directory)
    directory.mkdir(parents=True, exist_ok=True)
    n_records = len(load_catalogue(catalogue))
    n_levels, n_mu, n_sl = campaign_grid(n_runs, n_records)
    runs = n_records * n_levels * n_mu * n_sl
    if chunk_size is None:
        chunk_size = max(64, -(-runs // 100))

    def fmt(values):
        return "[" + ", ".join(f"{v:.6g}" for v in values) + "]"

    cat = "" if catalogue is None else f"catalogue = {json.dumps(str(Path(catalogue).resolve()))}\n"
    text = _CAMPAIGN_TEMPLATE.format(
        n_runs=runs, catalogue=cat, chunk_size=int(chunk_size),
        levels=fmt(np.geomspace(0.05, 1.2, n_levels) if n_levels > 1 else [0.4]),
        mu=fmt(np.linspace(0.2, 0.7, n_mu) if n_mu > 1 else [0.5]),
        slenderness=fmt(np.linspace(0.2, 1.0, n_sl) if n_sl > 1 else [0.5]),
    )
    path = directory / "campaign.toml"
    path.write_text(text)
    return path, {"runs": runs, "records": n_records, "levels": n_levels, "n_mu": n_mu,
                  "n_slenderness": n_sl, "chunk_size": int(chunk_size)}


def _memory():
    """Current and peak resident set size of this process [bytes], or None off Linux.

    Read from ``/proc/self/status`` (``VmRSS``, ``VmHWM``): unlike ``getrusage``'s
    ``ru_maxrss``, ``VmHWM`` is the peak of this process's own address space and does not
    inherit the resident size of the parent that spawned it.
    """
    try:
        with open("/proc/self/status") as fh:
            fields = dict(line.split(":", 1) for line in fh if line.startswith("Vm"))
        return (int(fields["VmRSS"].split()[0]) * 1024, int(fields["VmHWM"].split()[0]) * 1024)
    except (OSError, KeyError, ValueError):
        return None


def _reset_peak():
    """Reset this process's peak RSS (``VmHWM``) to its current RSS; False if impossible."""
    try:
        with open("/proc/self/clear_refs", "w") as fh:
            fh.write("5")
    except OSError:
        return False
    return True


def _kernel_seconds(stats):
    """Time spent inside compiled numba functions in a :class:`pstats.Stats` [s]."""
    import importlib

    from numba.core.dispatcher import Dispatcher

    import shipblock

    root = str(Path(shipblock.__file__).resolve().parent)
    modules = {}
    total = 0.0
    for (filename, _, name), (_, _, tottime, _, _) in stats.stats.items():
        path = str(Path(filename).resolve()) if filename not in ("~", "") else ""
        if not path.startswith(root) or not path.endswith(".py"):
            continue
        if path not in modules:
            rel = Path(path).relative_to(Path(root).parent).with_suffix("")
            parts = rel.parts[:-1] if rel.name == "__init__" else rel.parts
            try:
                modules[path] = importlib.import_module(".".join(parts))
            except ImportError:
                modules[path] = None
        if isinstance(getattr(modules[path], name, None), Dispatcher):
            total += tottime
    return total


#: Pipeline functions whose cumulative profiled time is reported: label -> function name.
_PROFILED_STAGES = {"batch": "run_batch", "records": "prepare_record",
                    "fits": "fragility_variables", "netcdf_write": "write_dataset",
                    "netcdf_read": "open_results"}


def _stage_seconds(stats):
    """Cumulative time [s] of the functions of :data:`_PROFILED_STAGES` in a profile."""
    out = dict.fromkeys(_PROFILED_STAGES, 0.0)
    for (filename, _, name), (_, _, _, cumtime, _) in stats.stats.items():
        for label, func in _PROFILED_STAGES.items():
            if name == func and "shipblock" in filename:
                out[label] += cumtime
    return out


def _campaign_main(argv):
    """Entry point of the campaign subprocess: ``pipeline warmup output result.json [profile]``.

    Imports shipblock and loads the compiled kernel, runs the small ``warmup`` pipeline (which
    imports everything a pipeline uses), then runs ``pipeline`` and writes its timings and
    memory figures to ``result.json``.
    """
    mem = {"start": _memory()}
    import shipblock.fragility.pipeline as pipeline

    t0 = time.perf_counter()
    simulate(sliding_system(), np.zeros(64), None, 0.01)
    mem["imports"] = _memory()
    pipeline.run_pipeline(argv[1], progress=False)
    mem["warmup"] = _memory()
    warm_seconds = time.perf_counter() - t0
    reset = _reset_peak()
    mem["before"] = _memory()
    timings = {}
    profiler = None
    if len(argv) > 4:
        import cProfile

        profiler = cProfile.Profile()
        profiler.enable()
    t0 = time.perf_counter()
    ds = pipeline.run_pipeline(argv[0], output=argv[2], progress=True, timings=timings)
    seconds = time.perf_counter() - t0
    if profiler is not None:
        profiler.disable()
    mem["campaign"] = _memory()
    result = {"seconds": seconds, "timings": timings, "warm_seconds": warm_seconds,
              "memory": mem, "peak_reset": reset, "runs": int(ds["peak_rotation"].size),
              "failed_runs": int(np.count_nonzero(ds["run_error"].values != ""))}
    if profiler is not None:
        import pstats

        profiler.dump_stats(argv[4])
        stats = pstats.Stats(argv[4])
        result["profile"] = {"total": stats.total_tt, "kernel": _kernel_seconds(stats),
                             "stages": _stage_seconds(stats)}
    Path(argv[3]).write_text(json.dumps(result))
    return 0


def campaign(n_runs, chunk_size=None, directory=None, profile=None, catalogue=None):
    """Run a generated campaign through :func:`~shipblock.fragility.pipeline.run_pipeline`.

    The campaign runs in a fresh Python subprocess, so that its memory is its own, with its
    progress bar on standard error. Before it, the subprocess loads the compiled kernel and runs
    a warm-up pipeline of one run per record, so that every module a pipeline imports is
    loaded. Memory is read in the subprocess from ``/proc/self/status`` (Linux): ``ru_maxrss``
    of a child process is not used because on Linux it includes the resident size of the
    parent that spawned it. The peak is reset just before the campaign.

    Parameters
    ----------
    n_runs : int
        Wanted number of runs (see :func:`write_campaign_pipeline`).
    chunk_size : int, optional
        Cases per chunk of the pipeline.
    directory : str or os.PathLike, optional
        Work directory (kept); default: a temporary directory, removed afterwards.
    profile : str or os.PathLike, optional
        Also profile the campaign with :mod:`cProfile` and write the statistics here.
    catalogue : str or os.PathLike, optional
        Record catalogue; default: the shipped one.

    Returns
    -------
    dict
        Grid, wall time [s], runs per second, time per run [us], stage timings [s], result
        file size [bytes] and, on Linux, ``memory`` [bytes]: ``imports`` (RSS after the
        interpreter, the imports and the kernel), ``warmup`` (RSS after the warm-up pipeline),
        ``before`` (RSS just before the campaign), ``peak`` (peak RSS during the campaign) and
        ``increase`` (``peak - before``).
    """
    import subprocess
    import tempfile

    with tempfile.TemporaryDirectory(prefix="shipblock-bench-") as tmp:
        work = Path(directory) if directory is not None else Path(tmp)
        path, info = write_campaign_pipeline(work, n_runs, chunk_size, catalogue)
        warm, _ = write_campaign_pipeline(work / "warmup", 1, catalogue=catalogue)
        result_file = work / "campaign-result.json"
        cmd = [sys.executable, "-c",
               "import sys; from shipblock.bench import _campaign_main; "
               "sys.exit(_campaign_main(sys.argv[1:]))",
               str(path), str(warm), str(work / "campaign.nc"), str(result_file)]
        if profile is not None:
            cmd.append(str(Path(profile).resolve()))
        t0 = time.perf_counter()
        subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL)
        wall = time.perf_counter() - t0
        child = json.loads(result_file.read_text())
        size = (work / "campaign.nc").stat().st_size
    runs = child["runs"]
    mem = child["memory"]
    out = {**info, "runs": runs, "failed_runs": child["failed_runs"],
           "seconds": child["seconds"], "runs_per_s": runs / child["seconds"],
           "us_per_run": 1e6 * child["seconds"] / runs, "process_seconds": wall,
           "startup_seconds": child["warm_seconds"], "stages": child["timings"],
           "netcdf_bytes": size}
    if mem["campaign"] is not None:
        # without a peak reset, the peak (and the increase) also cover the warm-up
        out["memory"] = {"imports": mem["imports"][0], "warmup": mem["warmup"][0],
                         "before": mem["before"][0], "peak": mem["campaign"][1],
                         "increase": mem["campaign"][1] - mem["before"][0],
                         "peak_reset": child["peak_reset"]}
    if "profile" in child:
        out["profile"] = child["profile"]
    return out
