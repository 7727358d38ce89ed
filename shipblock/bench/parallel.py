"""Benchmarks of parallel work: a batch beside a busy core, and Dask clusters of 1 and 2 workers.

Part of ``shipblock bench`` (:func:`shipblock.bench.run.run_benchmarks`).

* :func:`busy_core_batch`: :func:`~shipblock.simulate_batch` on one thread and on all, on the
  machine as it is and with a competing busy process (issue 21: with one core held busy, a
  batch on all threads must never be slower than on one).
* :func:`dask_scaling`: a pipeline on a ``distributed.LocalCluster`` of 1 and of 2 worker
  processes (one thread each), runs per second per worker, the scaling from 1 to 2 workers,
  and whether the results equal the local run's bit for bit (``--dask``).
"""

from __future__ import annotations

import contextlib
import subprocess
import sys
import time

import numpy as np

from shipblock.bench.campaign import write_campaign_pipeline
from shipblock.bench.timing import benchmark_records, interleaved_times, sliding_system
from shipblock.solver import RecordSet, simulate_batch
from shipblock.solver._threads import batch_threads
from shipblock.units import STANDARD_GRAVITY

#: Scale factors per record in :func:`busy_core_batch` (18 pySLAMMER records: 360 cases).
BUSY_SCALES = 20


@contextlib.contextmanager
def busy_process():
    """A competing process that keeps one core busy (a pure Python loop) while in the block."""
    proc = subprocess.Popen([sys.executable, "-c", "while True: pass"])
    try:
        time.sleep(0.3)  # running before the timing starts
        yield proc
    finally:
        proc.kill()
        proc.wait()


def _busy_records():
    """pySLAMMER's 18 sample records (accelerations [m/s^2], dts), or None without pySLAMMER."""
    try:
        from pyslammer.utilities import sample_ground_motions
    except ImportError:
        return None
    gms = list(sample_ground_motions().values())
    return ([(np.asarray(g.accel, float) * STANDARD_GRAVITY, None) for g in gms],
            [g.dt for g in gms])


def busy_core_batch(min_seconds=3.0, copies=(1, 10)):
    """A batch on one thread and on all threads, quiet and beside a busy process.

    The batch is that of the pySLAMMER comparison: its 18 records, blocks sliding on friction
    0.1, each record at ``BUSY_SCALES`` scale factors from 0.5 to 1.45 (360 cases, packed in a
    :class:`~shipblock.RecordSet`; without pySLAMMER the bench's six shipped records at 60
    factors). Each entry of ``copies`` repeats the cases that many times (10: a batch ten times
    as long). In every round the batch runs on one thread and on all
    (:func:`shipblock.bench.timing.interleaved_times`) for ``min_seconds``, first on the machine as it
    is, then with :func:`busy_process` running.

    Returns
    -------
    list of dict
        Per entry of ``copies`` and condition (``busy`` False, True): ``cases``,
        ``seconds_1``/``seconds_n`` (best calls), ``median_1``/``median_n`` [s], ``threads``
        (what :func:`~shipblock.solver._threads.batch_threads` chose at the start) and
        ``identical`` (the two give the same results).
    """
    import numba

    loaded = _busy_records()
    if loaded is None:
        recs, dts = zip(*[((h, None), dt) for _, h, _, dt in benchmark_records()], strict=True)
        scales = np.linspace(0.5, 1.45, 3 * BUSY_SCALES)
    else:
        recs, dts = loaded
        scales = 0.5 + 0.05 * np.arange(BUSY_SCALES)
    packed = RecordSet(list(recs), list(dts))
    system = sliding_system().replace(mu_s_ground=0.1, mu_k_ground=0.1)
    n_threads = numba.config.NUMBA_NUM_THREADS
    rows = []
    for n_copies in copies:
        base = np.array([[r, 0, f, f] for f in scales for r in range(len(recs))])
        cases = np.tile(base, (n_copies, 1))
        samples = float(np.diff(packed.offsets)[cases[:, 0].astype(int)].sum())

        def call(cases=cases):
            return simulate_batch(system, packed, cases=cases)

        call()  # compiled, loaded
        for busy in (False, True):
            with busy_process() if busy else contextlib.nullcontext():
                chosen = batch_threads(n_threads, len(cases), samples)
                times, (r1, rn) = interleaved_times([(1, call), (n_threads, call)],
                                                    min_seconds, min_rounds=3)
            rows.append({"cases": len(cases), "busy": busy, "threads": chosen,
                         "cores": n_threads, "seconds_1": float(times[:, 0].min()),
                         "seconds_n": float(times[:, 1].min()),
                         "median_1": float(np.median(times[:, 0])),
                         "median_n": float(np.median(times[:, 1])), "rounds": len(times),
                         "identical": all(np.array_equal(r1[k], rn[k], equal_nan=True)
                                          for k in r1)})
    return rows


def write_busy_core(out, rows):
    """Print the figures of :func:`busy_core_batch`."""
    for r in rows:
        where = "beside a busy process" if r["busy"] else "machine as it is    "
        slower = r["median_n"] > 1.05 * r["median_1"]
        out.write(f"{'busy core' if r is rows[0] else '':<18}: {r['cases']:>5} cases {where}: "
                  f"1 thread {1e3 * r['median_1']:.3g} ms, {r['cores']} threads "
                  f"{1e3 * r['median_n']:.3g} ms (medians of {r['rounds']} rounds; best "
                  f"{1e3 * r['seconds_1']:.3g} and {1e3 * r['seconds_n']:.3g} ms; "
                  f"{r['threads']} thread(s) chosen; results "
                  f"{'identical' if r['identical'] else 'DIFFERENT'}; all threads never slower: "
                  f"{'NOT met' if slower else 'met'})\n")


#: The pipelines of :func:`dask_scaling`: (name, runs, bootstrap resamples per fit), and their
#: runs with ``--quick``. "runs" times the solver's part (no bootstrap), "fits" the bootstrap.
DASK_CASES = (("runs", 30000, 0), ("fits", 3000, 500))
QUICK_DASK_CASES = (("runs", 3000, 0), ("fits", 600, 500))


def _same_results(a, b) -> bool:
    """Equal data, coordinates and attributes (NaN == NaN), the time stamp aside."""
    import xarray as xr

    try:
        xr.testing.assert_identical(a.drop_attrs(deep=False), b.drop_attrs(deep=False))
    except AssertionError:
        return False
    strip = {k: v for k, v in a.attrs.items() if k != "created"}
    return strip == {k: v for k, v in b.attrs.items() if k != "created"}


def _warm_worker():
    """Load the compiled solver in a worker process (from numba's cache, compiling if empty)
    and import what a chunk task and a bootstrap block import, as a long campaign would have."""
    import shipblock.fragility.pipeline  # noqa: F401  (batch, fit, workers, xarray)

    simulate_batch(sliding_system(), [(np.zeros(64), None)], [0.01], [[0, 0, 1.0, 1.0]])
    return True


def _timed_pipeline(path, output, client=None):
    """Run a pipeline; ``(dataset, seconds, stage timings)``."""
    from shipblock.fragility.pipeline import run_pipeline

    timings = {}
    t0 = time.perf_counter()
    ds = run_pipeline(path, output=output, client=client, progress=False, timings=timings)
    return ds, time.perf_counter() - t0, timings


def dask_scaling(n_workers=(1, 2), quick=False, directory=None):
    """Pipelines here and on Dask LocalClusters of ``n_workers`` one-core worker processes.

    Two pipelines (:data:`DASK_CASES`), both the bench's campaign pipeline
    (:func:`shipblock.bench.campaign.write_campaign_pipeline`: the six shipped records, IDA levels, a
    friction x slenderness sweep): "runs", 30,000 runs without bootstrap, for the solver's part;
    "fits", 3,000 runs with 500 bootstrap resamples per fit, for the fits. Each runs once here
    (the batch on all cores, the bootstrap here or on local processes), then on each cluster:
    worker processes of one task thread and one numba thread each (``NUMBA_NUM_THREADS=1``: one
    core per worker, as on a node shared out a core per worker), their solver loaded
    beforehand; the bootstrap resamples go to the cluster (each fit's are estimated above
    :data:`~shipblock.fragility.workers.DASK_SECONDS`). Each result is compared with the local
    one bit for bit.

    Returns
    -------
    dict or None
        Per pipeline name: ``runs``, ``bootstrap``, ``local`` (``seconds``, ``runs_per_s``,
        ``stages``) and ``clusters``: per number of workers ``seconds``, ``runs_per_s``,
        ``runs_per_s_per_worker``, ``stage_seconds`` (the pipeline's timings [s]: runs,
        fragility, ...), ``identical``; and ``scaling`` (the largest cluster's wall time
        against the smallest's). None without ``distributed``.
    """
    import tempfile
    from pathlib import Path

    try:
        import distributed
    except ImportError:
        return None
    cases = QUICK_DASK_CASES if quick else DASK_CASES
    out = {}
    with tempfile.TemporaryDirectory(prefix="shipblock-dask-") as tmp:
        work = Path(directory) if directory is not None else Path(tmp)
        paths, locals_ = {}, {}
        for name, n_runs, n_boot in cases:
            path, _ = write_campaign_pipeline(work / name, n_runs)
            path.write_text(path.read_text().replace("bootstrap = 0", f"bootstrap = {n_boot}"))
            ds, seconds, stages = _timed_pipeline(path, work / name / "local.nc")
            runs = int(ds["peak_rotation"].size)
            paths[name], locals_[name] = path, ds
            out[name] = {"runs": runs, "bootstrap": n_boot, "clusters": {},
                         "local": {"seconds": seconds, "runs_per_s": runs / seconds,
                                   "stages": stages}}
        for n in sorted(set(int(k) for k in n_workers)):
            with distributed.LocalCluster(n_workers=n, threads_per_worker=1, processes=True,
                                          dashboard_address=None,
                                          env={"NUMBA_NUM_THREADS": "1"}) as cluster, \
                    distributed.Client(cluster) as client:
                client.run(_warm_worker)
                for name, _, _ in cases:
                    ds, seconds, stages = _timed_pipeline(paths[name],
                                                          work / name / f"dask{n}.nc", client)
                    runs = out[name]["runs"]
                    out[name]["clusters"][n] = {
                        "seconds": seconds, "runs_per_s": runs / seconds,
                        "runs_per_s_per_worker": runs / seconds / n, "stages": stages,
                        "identical": _same_results(locals_[name], ds)}
    for d in out.values():
        if len(d["clusters"]) > 1:
            lo, hi = min(d["clusters"]), max(d["clusters"])
            d["scaling"] = d["clusters"][lo]["seconds"] / d["clusters"][hi]["seconds"]
    return out


def write_dask_scaling(out, results):
    """Print the figures of :func:`dask_scaling`."""
    if results is None:
        out.write("dask              : distributed not installed (pip install 'shipblock[dask]')\n")
        return
    first = True
    for name, d in results.items():
        loc = d["local"]
        stage = "runs" if d["bootstrap"] == 0 else "fragility"
        what = ("solver part" if d["bootstrap"] == 0
                else f"{d['bootstrap']} bootstrap resamples per fit")
        out.write(f"{'dask' if first else '':<18}: pipeline '{name}' of {d['runs']} runs ({what});"
                  f" here on all cores {loc['seconds']:.3g} s ({stage} "
                  f"{loc['stages'].get(stage, 0):.3g} s)\n")
        first = False
        for n, c in sorted(d["clusters"].items()):
            st = c["stages"]
            out.write(f"{'':20}LocalCluster of {n} one-core worker(s): {c['seconds']:.3g} s, "
                      f"{c['runs_per_s']:.3g} runs/s, {c['runs_per_s_per_worker']:.3g} per "
                      f"worker ({stage} {st.get(stage, 0):.3g} s); results "
                      f"{'identical to' if c['identical'] else 'DIFFERENT from'} the local "
                      f"run\n")
        if "scaling" in d:
            lo, hi = min(d["clusters"]), max(d["clusters"])
            out.write(f"{'':20}scaling from {lo} to {hi} workers: {d['scaling']:.2f}x\n")
