"""Threads of a batch: how many a batch gets, and running the compiled case loop on them.

:func:`~shipblock.simulate_batch` runs :func:`~shipblock.solver._kernel.run_cases` (compiled
with ``nogil``) on plain Python threads, each claiming the next unclaimed case from a shared
counter, instead of in a numba parallel region. The parallel region (numba's ``omp`` or
``workqueue`` threading layer) was the cause of batches that ran slower on two threads than on
one when another process kept a core busy: its threads wait for each other at the barrier that
ends the region by spinning for a while before they sleep, so a finished thread burns the core
the unfinished one needs, and every batch call starts by waking a worker that may have to wait
for a core first. A Python thread that finds no case left returns at once, and the caller waits
for the others asleep (:meth:`threading.Thread.join`).

How many threads: numba's thread count (:func:`numba.get_num_threads`, which the user, a test
or a Dask worker sets), at most one per case, and at most the CPUs this process may run on
(:func:`usable_cores`: its affinity mask and its cgroup's CPU quota); for a short batch, less
the cores other runnable threads occupy (:func:`other_runnable`, :func:`batch_threads`). A
thread beyond a free core buys a short batch nothing: it shares a core with another program
and the batch waits, at its end, for whichever thread the scheduler set aside.
"""

from __future__ import annotations

import functools
import math
import os
import threading


def usable_cores() -> int:
    """CPUs this process may run on: its affinity mask, capped by a CPU quota.

    The affinity mask (``os.sched_getaffinity``; all CPUs where there is none) is what a
    SLURM job or ``taskset`` allows; a container's CPU limit (Docker ``--cpus``, a Kubernetes
    pod's ``limits.cpu``) is a quota of the cgroup instead (:func:`cgroup_cpu_quota`), rounded
    up to whole CPUs.
    """
    try:
        cores = len(os.sched_getaffinity(0))
    except (AttributeError, OSError):
        cores = os.cpu_count() or 1
    quota = cgroup_cpu_quota()
    if quota is not None:
        cores = min(cores, math.ceil(quota))
    return max(1, cores)


@functools.lru_cache(maxsize=8)
def cgroup_cpu_quota(root: str = "/sys/fs/cgroup") -> float | None:
    """CPUs' worth of time this process's cgroup may use, or None without a limit (or off Linux).

    Read once per process (a container's limit does not change while it runs) from
    ``cpu.max`` (cgroup v2: ``"<quota> <period>"``, or ``"max <period>"`` without a limit) or
    from ``cpu/cpu.cfs_quota_us`` and ``cpu/cpu.cfs_period_us`` (cgroup v1; -1 without a limit).

    Parameters
    ----------
    root : str
        Where the cgroup file system is mounted (a parameter for the tests).
    """
    try:
        with open(os.path.join(root, "cpu.max")) as fh:
            quota, period = fh.read().split()[:2]
        return None if quota == "max" else int(quota) / int(period)
    except (OSError, ValueError):
        pass
    try:
        with open(os.path.join(root, "cpu", "cpu.cfs_quota_us")) as fh:
            quota = int(fh.read())
        with open(os.path.join(root, "cpu", "cpu.cfs_period_us")) as fh:
            period = int(fh.read())
    except (OSError, ValueError):
        return None
    return None if quota <= 0 or period <= 0 else quota / period


def other_runnable(loadavg: str = "/proc/loadavg") -> int | None:
    """Threads runnable on this machine at this instant besides the caller, or None if unknown.

    Read from the fourth field of ``/proc/loadavg`` (``running/total``, the caller counted in
    ``running``; Linux). None off Linux, or when the process may use fewer CPUs than the
    machine has (a container's CPU set or CPU quota): the count is then the whole machine's,
    which says nothing about the CPUs this process has.

    Parameters
    ----------
    loadavg : str
        The file to read (a parameter for the tests).
    """
    try:
        if usable_cores() != (os.cpu_count() or 0):
            return None
        fd = os.open(loadavg, os.O_RDONLY)  # a few microseconds: this runs at every batch
        try:
            text = os.read(fd, 256)
        finally:
            os.close(fd)
        running = int(text.split()[3].split(b"/")[0])
    except (OSError, ValueError, IndexError):
        return None
    return max(0, running - 1)


#: Samples per thread [-] below which a batch runs only on the cores no other thread occupies:
#: about 20 ms of work at the solver's fastest (3e8 samples/s in rest and sliding, ten times
#: fewer rocking). A thread that shares its core with another program is set aside by the
#: scheduler for a time slice (milliseconds) now and then, and the batch waits, at its end, for
#: the case that thread holds: a short batch loses more to that wait than the extra thread
#: gains. A longer one gains: with one of two cores busy, two threads get 4/3 of a core
#: between them, one thread one core (docs/benchmarks).
SHORT_BATCH_SAMPLES = 6e6

#: Samples [-] below which a batch runs on one thread: starting a thread and waiting for it
#: costs 0.05 to 0.3 ms, more than a batch of under a millisecond of work gains from it.
MIN_PARALLEL_SAMPLES = 2e5


def batch_threads(requested: int, n_cases: int, n_samples: float | None = None,
                  others: int | None = None, cores: int | None = None) -> int:
    """Threads to run a batch of ``n_cases`` (``n_samples`` input samples in all) on.

    At most ``requested`` (numba's thread count), one per case and one per usable core; one for
    a batch of fewer than :data:`MIN_PARALLEL_SAMPLES` samples. A short batch (fewer than
    :data:`SHORT_BATCH_SAMPLES` samples per thread, or of unknown length) leaves the cores that
    other runnable threads occupy (``others``, :func:`other_runnable` if not given) to them, but
    runs on one thread at least.

    Parameters
    ----------
    requested : int
        Threads allowed (:func:`numba.get_num_threads`).
    n_cases : int
        Cases in the batch.
    n_samples : float, optional
        Input samples of all the cases (each case's record length) [-].
    others : int, optional
        Other runnable threads on the machine; default: :func:`other_runnable`.
    cores : int, optional
        Usable CPUs; default: :func:`usable_cores`.

    Returns
    -------
    int
        The number of threads, at least 1.
    """
    n = min(int(requested), int(n_cases))
    if n <= 1 or (n_samples is not None and n_samples < MIN_PARALLEL_SAMPLES):
        return 1  # no system calls for a batch on one thread
    cores = usable_cores() if cores is None else int(cores)
    n = min(n, cores)
    if n <= 1 or (n_samples is not None and n_samples >= SHORT_BATCH_SAMPLES * n):
        return max(1, n)
    if others is None:
        others = other_runnable()
    return max(1, min(n, cores - (others or 0)))


def run_on_threads(fn, args, n_threads: int) -> None:
    """Call ``fn(*args)`` on ``n_threads`` threads at once, the caller's one of them.

    ``fn`` shares its work out itself (here: by claiming cases from a counter among ``args``)
    and releases the GIL while it works. Returns when every call has returned; the first
    exception a call raised is raised here.
    """
    if n_threads <= 1:
        fn(*args)
        return
    errors = []

    def work():
        try:
            fn(*args)
        except BaseException as exc:  # handed to the caller below
            errors.append(exc)

    threads = [threading.Thread(target=work, name=f"shipblock-batch-{i}", daemon=True)
               for i in range(n_threads - 1)]
    for t in threads:
        t.start()
    work()
    for t in threads:
        t.join()
    if errors:
        raise errors[0]
