"""Run a pipeline on a SLURM cluster through dask-jobqueue, kill a worker mid-run, compare.

Start a cluster first (on one machine: ``tools/slurm/one-node.sh start``, then ``export
SLURM_CONF=...`` as it says), then::

    python tools/slurm/check_slurm.py [--pipeline pipelines/napa_ida.toml] [--work DIR]

1. runs the pipeline here, without Dask: the reference;
2. starts two SLURM jobs of one Dask worker each (``dask_jobqueue.SLURMCluster``: one task
   thread, one core), and runs the same pipeline on them (``run_pipeline(client=...)``);
3. once the run has written its first fitted result (its batch is done and its bootstrap
   resamples are on the workers), cancels one worker's job (``scancel``, as a pre-emption or a
   time limit would end it; ``--kill process`` SIGKILLs the worker process instead, which its
   nanny restarts);
4. runs it again from the command line on the same cluster (``shipblock run --scheduler
   <the cluster's scheduler address>``);
5. checks that the runs finished, that the worker was lost mid-run (fits still to do), and
   that both results equal the reference bit for bit (every variable, coordinate and
   attribute but the time stamp).

Exit status 0 if all holds, 1 otherwise. The output is quoted in docs/user_guide/dask.rst.
"""

from __future__ import annotations

import argparse
import os
import shutil
import signal
import subprocess
import sys
import threading
import time
from pathlib import Path

import psutil
import xarray as xr
from dask_jobqueue import SLURMCluster
from distributed import Client

from shipblock.fragility.pipeline import load_pipeline, run_pipeline
from shipblock.fragility.store import open_results

ROOT = Path(__file__).resolve().parents[2]


def say(message: str) -> None:
    print(f"[{time.strftime('%H:%M:%S')}] {message}", flush=True)


def squeue() -> str:
    return subprocess.run(["squeue", "-o", "%.6i %.9P %.22j %.8u %.2t %.8M %.4C %R"],
                          capture_output=True, text=True, check=True).stdout.rstrip()


def differences(a: xr.Dataset, b: xr.Dataset) -> list[str]:
    """What differs between two results, bit for bit (NaN equal to NaN), but the time stamp."""
    out = []
    if set(a.variables) != set(b.variables):
        out.append(f"variables {sorted(set(a.variables) ^ set(b.variables))}")
    for name in sorted(set(a.variables) & set(b.variables)):
        if not a[name].variable.identical(b[name].variable):
            out.append(f"variable {name}")
    keys = (set(a.attrs) | set(b.attrs)) - {"created"}
    out += [f"attribute {k}" for k in sorted(keys) if a.attrs.get(k) != b.attrs.get(k)]
    return out


class Killer(threading.Thread):
    """Ends one worker once the run has written its first fitted result."""

    def __init__(self, cluster, client, partial: Path, n_fits: int, how: str):
        super().__init__(daemon=True)
        self.cluster, self.client = cluster, client
        self.partial, self.n_fits, self.how = partial, n_fits, how
        self.report = None
        self.stop = threading.Event()

    def fits_done(self) -> int:
        return len(list(self.partial.glob("fit-*.npz"))) if self.partial.is_dir() else 0

    def run(self):
        while not self.stop.is_set() and self.fits_done() == 0:
            time.sleep(0.05)
        if self.stop.is_set():
            return
        name, job = sorted(self.cluster.workers.items())[0]
        address = [a for a, w in self.client.scheduler_info()["workers"].items()
                   if w.get("name") == name]
        # at a moment when the worker has work: between two fits it may have none
        deadline = time.monotonic() + 30
        in_flight = 0
        while not self.stop.is_set() and time.monotonic() < deadline:
            in_flight = sum(len(t) for t in self.client.processing(workers=address).values())
            if in_flight:
                break
            time.sleep(0.01)
        done = self.fits_done()
        if self.how == "scancel":
            subprocess.run(["scancel", str(job.job_id)], check=True)
            what = f"job {job.job_id} (worker {name}) cancelled with scancel"
        else:
            # the nanny runs the job's command; the worker is its child process
            nanny = [p for p in psutil.process_iter(["cmdline", "environ"])
                     if (p.info["environ"] or {}).get("SLURM_JOB_ID") == str(job.job_id)
                     and "distributed.cli.dask_worker" in " ".join(p.info["cmdline"] or [])]
            worker = [c for n in nanny for c in n.children()
                      if "resource_tracker" not in " ".join(c.cmdline())]
            for c in worker:
                os.kill(c.pid, signal.SIGKILL)
            what = (f"worker process {[c.pid for c in worker]} of job {job.job_id} "
                    "SIGKILLed (its nanny restarts it)")
        self.report = (what, done)
        say(f"{what} after {done} of {self.n_fits} fits were on disk, with {in_flight} tasks "
            "(blocks of bootstrap resamples) on it")
        say("queue now:\n" + squeue())


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--pipeline", default=str(ROOT / "pipelines" / "napa_ida.toml"))
    p.add_argument("--work", default="/tmp/shipblock-slurm-check",
                   help="folder of the two results and the job logs (emptied first)")
    p.add_argument("--kill", choices=["scancel", "process"], default="scancel")
    p.add_argument("--jobs", type=int, default=2, help="SLURM jobs of one worker each")
    args = p.parse_args(argv)
    if "SLURM_CONF" not in os.environ and not Path("/etc/slurm/slurm.conf").exists():
        print("no SLURM: start one with tools/slurm/one-node.sh start, then export SLURM_CONF",
              file=sys.stderr)
        return 1
    work = Path(args.work)
    shutil.rmtree(work, ignore_errors=True)
    work.mkdir(parents=True)
    pipe = load_pipeline(args.pipeline)
    name = pipe.output.name
    n_fits = len(pipe.limit_states) * pipe.design.n_systems
    say(f"pipeline {args.pipeline}: {pipe.design.n_cases} runs, {n_fits} fits of "
        f"{pipe.fit['bootstrap']} bootstrap resamples")

    t0 = time.perf_counter()
    local = run_pipeline(args.pipeline, output=work / "local" / name, progress=False)
    say(f"local run (no Dask): {time.perf_counter() - t0:.1f} s")

    cluster = SLURMCluster(
        cores=1, processes=1, memory="2GB", walltime="00:30:00", job_cpu=1,
        job_name="shipblock-worker", log_directory=str(work / "logs"),
        scheduler_options={"dashboard_address": None},
        worker_extra_args=["--no-dashboard"],
    )
    killer = None
    try:
        say("job script:\n" + cluster.job_script())
        cluster.scale(jobs=args.jobs)
        with Client(cluster) as client:
            t0 = time.perf_counter()
            client.wait_for_workers(args.jobs, timeout=300)
            say(f"{args.jobs} workers up in {time.perf_counter() - t0:.1f} s:\n" + squeue())
            out = work / "slurm" / name
            killer = Killer(cluster, client, out.with_name(out.name + ".partial"), n_fits, args.kill)
            killer.start()
            t0 = time.perf_counter()
            remote = run_pipeline(args.pipeline, output=out, client=client, progress=False)
            killer.stop.set()
            say(f"SLURM run: {time.perf_counter() - t0:.1f} s; workers at the end: "
                f"{len(client.scheduler_info()['workers'])}")
            # the command line, pointed at the same cluster by its scheduler's address
            command = [sys.executable, "-m", "shipblock.cli", "-q", "run", args.pipeline,
                       "--output", str(work / "cli" / name), "--scheduler",
                       cluster.scheduler_address]
            say("$ shipblock " + " ".join(command[3:]))
            t0 = time.perf_counter()
            done = subprocess.run(command, capture_output=True, text=True)
            lines = [line for line in done.stdout.splitlines()
                     if "written" in line or "median" in line] + done.stderr.splitlines()[-3:]
            say(f"exit status {done.returncode} in {time.perf_counter() - t0:.1f} s:\n"
                + "\n".join(lines))
    finally:
        if killer is not None:
            killer.stop.set()
        cluster.close()
    problems = []
    if killer.report is None:
        problems.append("no worker was killed (the run ended before its first fit was on disk)")
    elif killer.report[1] >= n_fits:
        problems.append("the worker was killed after the last fit: not mid-run")
    results = {"SLURM (worker killed)": remote}
    if done.returncode != 0:
        problems.append(f"'shipblock run --scheduler' failed with status {done.returncode}")
    else:
        results["SLURM (command line)"] = open_results(work / "cli" / name)
    for what, ds in results.items():
        diff = differences(local, ds)
        if diff:
            problems.append(f"the {what} result differs from the local one: " + ", ".join(diff))
        else:
            say(f"{what} result equals the local one bit for bit: {len(local.variables)} "
                f"variables and coordinates, {len(local.attrs) - 1} attributes (all but "
                "'created')")
    for problem in problems:
        say(f"FAILED: {problem}")
    if not problems:
        say("OK")
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
