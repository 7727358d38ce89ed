"""Where a study's independent work runs: threads per Dask task, and the bootstrap's resamples.

Two concerns of a study spread over cores or over a Dask cluster:

* **numba threads of a Dask task.** :func:`~shipblock.simulate_batch` runs on
  :func:`numba.get_num_threads` threads. Dask workers run tasks on threads of their own, and a
  worker process on a node shares its cores with the other workers there: each chunk task
  (:func:`run_chunk_task`) sets numba's thread count (thread-local, for the task's thread) to
  the cores of its process divided by the task threads of all workers on its host
  (:func:`numba_threads_per_task`), so that workers x task threads x numba threads never exceed
  the cores. A 2-worker LocalCluster on 2 cores gets one numba thread per task; one worker of
  one thread on 8 cores, eight.
* **The bootstrap's resamples.** :class:`Workers` maps blocks of resamples
  (:func:`~shipblock.fragility.fit.bootstrap`) onto a Dask client when one is given, else onto
  a pool of local processes (forked on Linux) once the resamples run here would take long
  enough (:data:`LOCAL_POOL_SECONDS`, counting those of the fits before) to pay for starting
  it, else runs them here. Each resample has its own seed (``numpy.random.SeedSequence.spawn``),
  so the result does not depend on where or in what blocks the resamples ran.
"""

from __future__ import annotations

import os
import sys
import warnings
from collections.abc import Callable, Sequence
from pathlib import Path
from urllib.parse import urlparse

from shipblock.fragility.chunk import run_chunk
from shipblock.processes import pool_worker_start, stop_pool
from shipblock.solver._threads import usable_cores

#: Serial estimate [s] from which the bootstrap's resamples go to local processes (without
#: Dask), counting those already run here: on Linux the pool's processes are forked, which
#: takes some 20 ms; elsewhere they are spawned, each importing numpy and scipy (about a
#: second), and the estimate must reach :data:`SPAWN_POOL_SECONDS`.
LOCAL_POOL_SECONDS = 0.2
SPAWN_POOL_SECONDS = 2.0

#: Serial estimate [s] above which the resamples go to the Dask client when there is one: a
#: round trip of a few tasks costs tens of milliseconds.
DASK_SECONDS = 0.05

#: Bootstrap replicates run here first, timed, to estimate how long the others would take.
PROBE_REPLICATES = 16

#: Blocks of resamples per parallel slot (worker thread or process): several, so that a slow
#: slot does not hold the others up; but at least :data:`MIN_BLOCK` resamples a block.
BLOCKS_PER_SLOT = 4
MIN_BLOCK = 8


def numba_threads_per_task(cores: int, host_task_threads: int) -> int:
    """numba threads for one Dask task: the cores shared out over the host's task threads.

    Parameters
    ----------
    cores : int
        CPUs the worker process may run on.
    host_task_threads : int
        Task threads of all workers on the same host (each worker's ``nthreads``, summed).

    Returns
    -------
    int
        ``cores // host_task_threads``, at least 1.
    """
    return max(1, int(cores) // max(1, int(host_task_threads)))


def host_task_threads(client) -> dict[str, int]:
    """Task threads of the client's workers per host, from the scheduler's view of them."""
    out: dict[str, int] = {}
    for address, info in client.scheduler_info().get("workers", {}).items():
        host = info.get("host") or urlparse(address).hostname or address
        out[host] = out.get(host, 0) + int(info.get("nthreads", 1))
    return out


def _task_numba_threads(hosts: dict[str, int] | None) -> int:
    """numba threads for a task on the current Dask worker (see :func:`numba_threads_per_task`)."""
    from distributed import get_worker

    worker = get_worker()
    host = urlparse(worker.address).hostname or ""
    threads = (hosts or {}).get(host)
    if threads is None:  # a worker that joined later: alone on its host
        threads = worker.state.nthreads
    return numba_threads_per_task(usable_cores(), threads)


def run_chunk_task(records, systems, cases, hosts=None, **options) -> dict:
    """:func:`~shipblock.fragility.chunk.run_chunk` as a Dask task, on its share of the cores.

    Sets numba's thread count of the task's thread to :func:`numba_threads_per_task` of the
    worker's cores and of the task threads on its host (``hosts``, from
    :func:`host_task_threads`; a host not listed counts this worker's threads alone), runs the
    chunk, and restores the count. The results do not depend on the thread count.
    """
    import numba

    n = min(_task_numba_threads(hosts), numba.config.NUMBA_NUM_THREADS)
    before = numba.get_num_threads()
    numba.set_num_threads(n)
    try:
        return run_chunk(records, systems, cases, **options)
    finally:
        numba.set_num_threads(before)


class Workers:
    """Where blocks of independent work run: a Dask client, local processes, or here.

    Use as a context manager: a local pool, if one was started, is shut down at the end.

    Parameters
    ----------
    client : distributed.Client, optional
        Send the work to this client's workers.
    processes : int, optional
        Local processes when there is no client (default: the usable cores); 1 runs
        everything here.
    local_pool_seconds, dask_seconds : float, optional
        Serial estimates [s] from which work goes to local processes or to the client
        (default :data:`LOCAL_POOL_SECONDS`, or :data:`SPAWN_POOL_SECONDS` where processes are
        spawned, and :data:`DASK_SECONDS`); 0 sends all of it.

    Notes
    -----
    On Linux the local processes are forked: they start in milliseconds and do not import the
    caller's main module again. Elsewhere they are spawned, which runs the main script again in
    each process: the pool is then used only when that is safe (:func:`main_is_safe_to_spawn`).
    The processes die with this one, however it ends, and ignore Ctrl-C, which this one
    handles (:mod:`shipblock.processes`).
    """

    def __init__(self, client=None, processes: int | None = None,
                 local_pool_seconds: float | None = None, dask_seconds: float | None = None):
        self.client = client
        self.processes = usable_cores() if processes is None else max(1, int(processes))
        self._context = pool_context()
        if self._context.get_start_method() != "fork" and not main_is_safe_to_spawn():
            self.processes = 1
        default = LOCAL_POOL_SECONDS if self._context.get_start_method() == "fork" else \
            SPAWN_POOL_SECONDS
        self.local_pool_seconds = float(default if local_pool_seconds is None
                                        else local_pool_seconds)
        self.dask_seconds = float(DASK_SECONDS if dask_seconds is None else dask_seconds)
        self._pool = None
        #: estimated seconds of the work run here so far
        self.here_seconds = 0.0
        #: where each :meth:`map` ran: "here", "processes" or "dask" (for reports and tests)
        self.used: list[str] = []

    def __enter__(self):
        return self

    def __exit__(self, exc_type, *exc):
        self.close(abort=exc_type is not None)

    def close(self, abort: bool = False):
        """Shut the local pool down, if one was started.

        ``abort`` (an exception, Ctrl-C or SIGTERM leaving the ``with`` block): cancel the
        work not started and stop the workers at once
        (:func:`~shipblock.processes.stop_pool`).
        """
        if self._pool is not None:
            pool, self._pool = self._pool, None
            stop_pool(pool, abort)

    def slots(self) -> int:
        """Work items that can run at once where the next large map would go."""
        if self.client is not None:
            workers = self.client.scheduler_info().get("workers", {})
            return max(1, sum(int(w.get("nthreads", 1)) for w in workers.values()))
        return self.processes

    def where(self, estimated_seconds: float) -> str:
        """Where work estimated at ``estimated_seconds`` here would run.

        On the client if it is estimated at :attr:`dask_seconds` or more. Without a client, on
        the local processes once the work run here, this included, reaches
        :attr:`local_pool_seconds` (many short bootstraps pay for the pool as one long one
        does) and from then on, the pool being started.
        """
        if self.client is not None:
            return "dask" if estimated_seconds >= self.dask_seconds else "here"
        if self.processes > 1 and (self._pool is not None or self.here_seconds + estimated_seconds
                                   >= self.local_pool_seconds):
            return "processes"
        return "here"

    def map(self, fn: Callable, items: Sequence, estimated_seconds: float = float("inf")) -> list:
        """``[fn(*item) for item in items]``, wherever :meth:`where` sends the estimate.

        ``fn`` and the items must be picklable for the local processes and for Dask.
        """
        items = list(items)
        where = self.where(estimated_seconds) if len(items) > 1 else "here"
        self.used.append(where)
        if where == "here" and estimated_seconds != float("inf"):
            self.here_seconds += estimated_seconds
        if where == "dask":
            futures = [self.client.submit(fn, *item, pure=False) for item in items]
            return self.client.gather(futures)
        if where == "processes":
            if self._pool is None:
                from concurrent.futures import ProcessPoolExecutor

                # workers die with this process and leave Ctrl-C to it (processes.py)
                self._pool = ProcessPoolExecutor(max_workers=self.processes,
                                                 mp_context=self._context,
                                                 initializer=pool_worker_start,
                                                 initargs=(os.getpid(),))
            with warnings.catch_warnings():
                # Python 3.12+ warns that forking a process with threads may deadlock the
                # child; the children only fit (numpy, scipy) and hold no lock of ours
                warnings.simplefilter("ignore", DeprecationWarning)
                futures = [self._pool.submit(fn, *item) for item in items]
            return [f.result() for f in futures]
        return [fn(*item) for item in items]


def pool_context():
    """The multiprocessing context of local pools: forked on Linux, spawned elsewhere."""
    import multiprocessing

    return multiprocessing.get_context("fork" if sys.platform.startswith("linux") else "spawn")


def main_is_safe_to_spawn() -> bool:
    """Whether spawned processes can import the main module again without re-running work.

    A spawned process imports the caller's main script as ``__mp_main__``: harmless for an
    interactive session, ``python -c``, a notebook, shipblock's command line, or a script whose
    work is under ``if __name__ == "__main__":``; a script without that guard would run again,
    pipeline and all, in every process.
    """
    main = sys.modules.get("__main__")
    path = getattr(main, "__file__", None)
    if path is None:
        return True
    name = getattr(getattr(main, "__spec__", None), "name", "") or ""
    if name.split(".")[0] == "shipblock":
        return True
    try:
        source = Path(path).read_text(errors="replace")
    except OSError:
        return False
    return "__name__ == \"__main__\"" in source or "__name__ == '__main__'" in source


def blocks(n: int, slots: int) -> list[range]:
    """Split ``range(n)`` into contiguous blocks for ``slots`` parallel slots.

    About :data:`BLOCKS_PER_SLOT` blocks per slot, none shorter than :data:`MIN_BLOCK` (but one
    block for fewer items).
    """
    if n <= 0:
        return []
    count = max(1, min(slots * BLOCKS_PER_SLOT, n // MIN_BLOCK))
    edges = [round(i * n / count) for i in range(count + 1)]
    return [range(a, b) for a, b in zip(edges[:-1], edges[1:], strict=True) if b > a]


__all__ = ["Workers", "blocks", "host_task_threads", "main_is_safe_to_spawn",
           "numba_threads_per_task", "pool_context", "run_chunk_task",
           "LOCAL_POOL_SECONDS", "SPAWN_POOL_SECONDS", "DASK_SECONDS", "PROBE_REPLICATES"]
