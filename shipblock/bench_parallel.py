"""Benchmarks of parallel work: a batch beside a busy core, and Dask clusters of 1 and 2 workers.

Part of ``shipblock bench`` (:func:`shipblock.bench.run_benchmarks`).

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
    (:func:`shipblock.bench.interleaved_times`) for ``min_seconds``, first on the machine as it
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

    from shipblock.bench import _records, interleaved_times, sliding_system
    from shipblock.solver import RecordSet, simulate_batch
    from shipblock.solver._threads import batch_threads

    loaded = _busy_records()
    if loaded is None:
        recs, dts = zip(*[((h, None), dt) for _, h, _, dt in _records()], strict=True)
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


#: Runs of the pipeline of :func:`dask_scaling` (``--quick``: ``QUICK_DASK_RUNS``), and its
#: bootstrap resamples per fit.
DASK_RUNS = 3000
QUICK_DASK_RUNS = 600
DASK_BOOTSTRAP = 500


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
    from shipblock.bench import sliding_system
    from shipblock.solver import simulate_batch

    simulate_batch(sliding_system(), [(np.zeros(64), None)], [0.01], [[0, 0, 1.0, 1.0]])
    return True


def dask_scaling(n_workers=(1, 2), quick=False, directory=None):
    """A pipeline locally and on Dask LocalClusters of ``n_workers`` one-core worker processes.

    The pipeline is the bench's campaign pipeline (:func:`shipblock.bench.write_campaign_pipeline`:
    the six shipped records, IDA levels, a friction x slenderness sweep) of :data:`DASK_RUNS`
    runs with :data:`DASK_BOOTSTRAP` bootstrap resamples per fit. It runs once here (numba
    threads on all cores), then on each cluster: worker processes of one task thread and one
    numba thread each (``NUMBA_NUM_THREADS=1``: one core per worker, as on a cluster node
    shared out a core per worker), their solver loaded beforehand; the bootstrap resamples go to
    the cluster (each fit's are estimated above
    :data:`~shipblock.fragility.workers.DASK_SECONDS`). Each result is compared with the local
    one bit for bit.

    Returns
    -------
    dict or None
        ``runs``, ``local`` (``seconds``, ``runs_per_s``, ``stages``) and ``clusters``: per
        number of workers ``seconds``, ``runs_per_s``, ``runs_per_s_per_worker``, ``stages``
        (pipeline timings [s]: runs, fragility, ...), ``identical``; ``scaling`` (runs/s of the
        largest cluster over the smallest's); None without ``distributed``.
    """
    import tempfile
    from pathlib import Path

    try:
        import distributed
    except ImportError:
        return None
    from shipblock.bench import write_campaign_pipeline
    from shipblock.fragility.pipeline import run_pipeline

    n_runs = QUICK_DASK_RUNS if quick else DASK_RUNS
    out = {"runs": None, "clusters": {}}
    with tempfile.TemporaryDirectory(prefix="shipblock-dask-") as tmp:
        work = Path(directory) if directory is not None else Path(tmp)
        path, info = write_campaign_pipeline(work, n_runs)
        text = path.read_text().replace("bootstrap = 0", f"bootstrap = {DASK_BOOTSTRAP}")
        path.write_text(text)
        out.update(grid=info)
        timings = {}
        t0 = time.perf_counter()
        local = run_pipeline(path, output=work / "local.nc", progress=False, timings=timings)
        seconds = time.perf_counter() - t0
        runs = int(local["peak_rotation"].size)
        out["runs"] = runs
        out["local"] = {"seconds": seconds, "runs_per_s": runs / seconds, "stages": timings}
        for n in sorted(set(int(k) for k in n_workers)):
            with distributed.LocalCluster(n_workers=n, threads_per_worker=1, processes=True,
                                          dashboard_address=None,
                                          env={"NUMBA_NUM_THREADS": "1"}) as cluster, \
                    distributed.Client(cluster) as client:
                client.run(_warm_worker)
                timings = {}
                t0 = time.perf_counter()
                ds = run_pipeline(path, output=work / f"dask{n}.nc", client=client,
                                  progress=False, timings=timings)
                seconds = time.perf_counter() - t0
            out["clusters"][n] = {"seconds": seconds, "runs_per_s": runs / seconds,
                                  "runs_per_s_per_worker": runs / seconds / n, "stages": timings,
                                  "identical": _same_results(local, ds)}
    if len(out["clusters"]) > 1:
        lo, hi = min(out["clusters"]), max(out["clusters"])
        out["scaling"] = out["clusters"][hi]["runs_per_s"] / out["clusters"][lo]["runs_per_s"]
    return out


def write_dask_scaling(out, d):
    """Print the figures of :func:`dask_scaling`."""
    if d is None:
        out.write("dask              : distributed not installed (pip install 'shipblock[dask]')\n")
        return
    loc = d["local"]
    out.write(f"dask              : pipeline of {d['runs']} runs, {DASK_BOOTSTRAP} bootstrap "
              f"resamples per fit; here on all cores {loc['seconds']:.3g} s "
              f"({loc['runs_per_s']:.3g} runs/s; runs {loc['stages'].get('runs', 0):.2g} s, fits "
              f"{loc['stages'].get('fragility', 0):.2g} s)\n")
    for n, c in sorted(d["clusters"].items()):
        st = c["stages"]
        out.write(f"{'':20}LocalCluster of {n} one-core worker(s): {c['seconds']:.3g} s, "
                  f"{c['runs_per_s']:.3g} runs/s, {c['runs_per_s_per_worker']:.3g} per worker "
                  f"(runs {st.get('runs', 0):.2g} s, fits {st.get('fragility', 0):.2g} s); results "
                  f"{'identical to' if c['identical'] else 'DIFFERENT from'} the local run\n")
    if "scaling" in d:
        lo, hi = min(d["clusters"]), max(d["clusters"])
        out.write(f"{'':20}scaling from {lo} to {hi} workers: {d['scaling']:.2f}x\n")
