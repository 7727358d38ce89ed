"""Speed and accuracy of the solver: samples and runs per second, batch scaling, pySLAMMER."""

from __future__ import annotations

import numpy as np

from shipblock.bench.timing import (
    best_time,
    control_loop,
    integrated_samples,
    interleaved_times,
    median_spreads,
    sliding_system,
)
from shipblock.solver import RecordSet, simulate, simulate_batch
from shipblock.units import STANDARD_GRAVITY


def throughput(system, records, scale, rtol=1e-8, min_seconds=1.0):
    """Samples per second on one core for full simulations of the records at a scale factor.

    The samples counted are those integrated: a run that fails (overturns) stops there. One
    :func:`~shipblock.simulate_batch` call over all records is timed again and again for
    ``min_seconds``, each call followed by a pure arithmetic loop of about the same length
    (:func:`~shipblock.bench.timing.control_loop`), all on one thread
    (:func:`~shipblock.bench.timing.interleaved_times`).

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
    spread, control_spread = median_spreads(times)
    best, median = times[:, 0].min(), np.median(times[:, 0])
    return {"samples": n, "input_samples": sum(h.size for _, h, _, _ in records),
            "failures": int(np.count_nonzero(summ["failure"])), "seconds": best,
            "samples_per_s": n / best, "samples_per_s_median": n / median,
            "rounds": len(times), "spread": float(spread), "control_spread": float(control_spread),
            "fraction_rocking": rocking, "fraction_sliding": sliding,
            "peak_rotation": summ["peak_rotation"].tolist()}


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
        seconds, _ = best_time(lambda n=n: simulate_batch(system, recs, dts, cases_of(n)), repeat=1)
        if seconds >= min_seconds or n >= 10**6:
            break
        n = int(min(10 * n, max(2 * n, 1.2 * n * min_seconds / max(seconds, 1e-9))))
        n = -(-n // n_rec) * n_rec
    again, summ = best_time(lambda: simulate_batch(system, recs, dts, cases_of(n)), repeat=1)
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
    loop of about the same length (:func:`~shipblock.bench.timing.control_loop`) on one thread and on all
    (:func:`~shipblock.bench.timing.interleaved_times`), rounds for ``min_seconds``: the loop's speed-up is the ceiling
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
        t_sb, res = best_time(lambda acc=acc, gm=gm: simulate(system, acc, None, gm.dt), repeat=3)
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
                t_ps, ra = best_time(lambda gm=gm: pyslammer.RigidAnalysis(ky_g, gm), repeat=1)
                row["pyslammer_s"] = min(row["pyslammer_s"], t_ps)
                row["pyslammer_disp_m"] = float(ra.max_sliding_disp)
                t_round += t_ps
            t_ps_best = min(t_ps_best, t_round)
            t, summ = best_time(lambda: simulate_batch(system, packed, cases=cases), repeat=3)
            t_batch = min(t_batch, t)
            t, _ = best_time(lambda: simulate_batch(system, recs, dts, cases), repeat=3)
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
