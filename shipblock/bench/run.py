"""Benchmarks behind ``shipblock bench``: throughput, accuracy, pySLAMMER, scaling, campaign.

Measured, never asserted in unit tests. Figures go to the terminal and optionally to JSON; the
documentation's benchmark page quotes a run of this command.

* samples per second on one core and runs per second on all cores, sliding- and
  rocking-dominated, on the shipped records (:func:`~shipblock.bench.solver.throughput`,
  :func:`~shipblock.bench.solver.runs_per_second`);
* peak rotation at the default tolerance against a converged run;
* speed-up of :func:`~shipblock.simulate_batch` from one core to all;
* time per record against pySLAMMER (:func:`~shipblock.bench.solver.pyslammer_comparison`);
* a campaign of a generated pipeline through :func:`~shipblock.fragility.pipeline.run_pipeline`
  in a subprocess: wall time, stages and memory (:func:`~shipblock.bench.campaign.campaign`);
* a batch on one thread and on all, beside a busy process
  (:func:`shipblock.bench.parallel.busy_core_batch`);
* the README's demo command from an empty numba cache
  (:func:`shipblock.bench.startup.cold_start`);
* with ``--dask``, a pipeline on LocalClusters of 1 and 2 workers
  (:func:`shipblock.bench.parallel.dask_scaling`).
"""

from __future__ import annotations

import json
import os
import sys

import numpy as np

from shipblock.bench.campaign import campaign, write_campaign
from shipblock.bench.parallel import busy_core_batch, dask_scaling, write_busy_core, write_dask_scaling
from shipblock.bench.solver import (
    batch_scaling,
    pyslammer_comparison,
    rocking_accuracy,
    runs_per_second,
    throughput,
)
from shipblock.bench.section import section_speed
from shipblock.bench.startup import cold_start, write_cold_start
from shipblock.bench.targets import (
    CAMPAIGN_RUNS,
    QUICK_CAMPAIGN_RUNS,
    SPECTRUM_PERIODS,
    SPECTRUM_SAMPLES,
    TARGET_SAMPLES,
    TARGETS,
    scaling_verdict,
    timing_note,
    verdict,
)
from shipblock.bench.timing import benchmark_records, rocking_system, sliding_system, spectrum_time


def run_benchmarks(quick=False, pyslammer=True, output=None, stream=None, campaign_runs=None,
                   chunk_size=None, profile=None, cold=True, dask_workers=None):
    """Run all benchmarks and print a report.

    Parameters
    ----------
    quick : bool
        Shorter timings and a small campaign (:data:`~shipblock.bench.targets.QUICK_CAMPAIGN_RUNS` runs).
    pyslammer : bool
        Include the comparison with pySLAMMER (if installed).
    output : str or os.PathLike, optional
        Also write the results as JSON.
    stream : file-like, optional
        Where the report goes (default standard output).
    campaign_runs : int, optional
        Runs of the campaign (default :data:`~shipblock.bench.targets.CAMPAIGN_RUNS`, or
        :data:`~shipblock.bench.targets.QUICK_CAMPAIGN_RUNS` with ``quick``); 0 skips it.
    chunk_size : int, optional
        Cases per chunk of the campaign (default: about 100 chunks).
    profile : str or os.PathLike, optional
        Profile the campaign with :mod:`cProfile` and write the statistics to this file.
    cold : bool
        Include the cold start (:func:`shipblock.bench.startup.cold_start`: the demo command
        from an empty numba cache, in subprocesses).
    dask_workers : sequence of int, optional
        Also run :func:`shipblock.bench.parallel.dask_scaling` on LocalClusters of these numbers
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
    records = benchmark_records()
    out.write(f"records: {', '.join(r[0] for r in records)} "
              f"({sum(r[1].size for r in records)} samples)\n")
    results = {"machine": machine, "targets": TARGETS}
    slide = throughput(sliding_system(), records, scale=0.6, min_seconds=window)
    results["sliding"] = slide
    out.write(f"sliding-dominated : {slide['samples_per_s']:.3g} samples/s per core "
              f"(sliding {100 * slide['fraction_sliding']:.0f} % of the time; "
              f"{timing_note(slide)})\n")
    spectrum = spectrum_time(SPECTRUM_PERIODS, SPECTRUM_SAMPLES)
    results["spectrum"] = spectrum
    out.write(f"response spectrum : {spectrum['seconds']:.3f} s for {SPECTRUM_PERIODS} periods x "
              f"{SPECTRUM_SAMPLES} samples (best of {spectrum['rounds']}; target "
              f"{TARGETS['spectrum_seconds']:g} s: "
              f"{verdict(spectrum['seconds'] <= TARGETS['spectrum_seconds'])})\n")
    section = section_speed(repeats=2 if quick else 5)
    results["section"] = section
    out.write(f"dock section      : {1e3 * section['section_seconds_per_run']:.0f} ms of one core per"
              f" run (40 s at 200 Hz, keel and two side lines, Navy blocks; "
              f"{section['exponential_steps']} exponential + {section['accepted_steps']} "
              f"Dormand-Prince steps, {section['events']} events; Dormand-Prince throughout "
              f"{1e3 * section['section_dopri_seconds_per_run']:.0f} ms); rigid solver "
              f"{1e3 * section['rigid_seconds_per_run']:.2f} ms on the same record (target "
              f"{1e3 * TARGETS['section_seconds_per_run']:.0f} ms: "
              f"{verdict(section['section_seconds_per_run'] <= TARGETS['section_seconds_per_run'])})\n")
    rock = throughput(rocking_system(), records, scale=0.3, min_seconds=window)
    rock["peak_rotation_error"] = rocking_accuracy(rocking_system(), records, 0.3)
    results["rocking"] = rock
    out.write(f"rocking-dominated : {rock['samples_per_s']:.3g} samples/s per core "
              f"(rocking {100 * rock['fraction_rocking']:.0f} % of the time; "
              f"{rock['samples']:.0f} samples integrated of {rock['input_samples']}, "
              f"{rock['failures']} of {len(records)} runs overturn; {timing_note(rock)}), "
              f"peak theta within {rock['peak_rotation_error']:.2g} rad of a converged run "
              f"(target {TARGETS['rocking_samples_per_s']:.2g} samples/s: "
              f"{verdict(rock['samples_per_s'] >= TARGETS['rocking_samples_per_s'])}; "
              f"accuracy target {TARGETS['peak_rotation_error']:.0e} rad: "
              f"{verdict(rock['peak_rotation_error'] <= TARGETS['peak_rotation_error'])})\n")
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
                  f"(target {target}: {verdict(r['runs_per_s_at_target_length'] >= target)})\n")
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
                      f"faster (target {target:.0f}: {verdict(ps['speedup_batch'] >= target)}; "
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
        out.flush()
        results["cold_start"] = cold_start()
        write_cold_start(out, results["cold_start"])
    if dask_workers:
        out.flush()
        results["dask"] = dask_scaling(dask_workers, quick=quick)
        write_dask_scaling(out, results["dask"])
    if campaign_runs:
        out.flush()
        c = campaign(campaign_runs, chunk_size=chunk_size, profile=profile)
        results["campaign"] = c
        write_campaign(out, c)
    if output:
        with open(output, "w") as fh:
            json.dump(results, fh, indent=2)
        out.write(f"results written to {output}\n")
    return 0
