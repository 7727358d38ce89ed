"""Processes that end with the run: pool workers that die with their parent, SIGTERM as Ctrl-C.

A local pool (:class:`~shipblock.fragility.workers.Workers`) forks worker processes that wait
on a queue for work. A parent killed outright (SIGKILL, or SIGTERM with Python's default
handling) never tells them to stop: they would wait forever, each holding the memory it
inherited and the dead run's standard output and error, so that a caller reading those pipes
to their end would hang. And Ctrl-C, which the terminal sends to every process of the
foreground group, would print a traceback from every worker besides the parent's message.

Hence:

* :func:`pool_worker_start`, the pool's initializer, makes each worker **die with its
  parent**: on Linux the kernel sends it SIGKILL when the parent goes (``prctl(2)``
  ``PR_SET_PDEATHSIG``), and a check right after closes the window in which the parent died
  before that was set; elsewhere a daemon thread (:func:`watch_parent`) ends the worker once
  its parent process is gone. Workers **ignore SIGINT**: the parent handles Ctrl-C and shuts
  the pool down (:func:`stop_pool`), which ends them with SIGTERM (its default action
  restored in the worker).
* :func:`terminate_as_interrupt` has SIGTERM raise :class:`Terminated` (a
  :class:`KeyboardInterrupt`) in the main thread, so that a terminated run cleans up exactly
  as an interrupted one: pool shut down, finished work kept on disk for a rerun to resume.

Notes
-----
``PR_SET_PDEATHSIG`` fires when the *thread* that forked the worker ends, not only the
process: the pool's workers are forked by the thread that first maps work onto it
(:meth:`~shipblock.fragility.workers.Workers.map`), which must outlive the pool, as it does
when the pool is used in a ``with`` block.

References
----------
.. [1] ``prctl(2)``, Linux man-pages: ``PR_SET_PDEATHSIG``.
.. [2] Python documentation, :mod:`signal`: handlers run in the main thread only.
"""

from __future__ import annotations

import contextlib
import ctypes
import ctypes.util
import os
import signal
import sys
import threading
import time

__all__ = ["Terminated", "pool_worker_start", "stop_pool", "terminate_as_interrupt",
           "watch_parent"]

#: ``PR_SET_PDEATHSIG`` of ``<linux/prctl.h>``.
PR_SET_PDEATHSIG = 1

#: How often [s] a worker without ``PR_SET_PDEATHSIG`` checks that its parent is alive.
WATCH_INTERVAL = 0.5

#: Seconds a stopped pool's workers get to end after SIGTERM before they are killed.
STOP_GRACE = 5.0


class Terminated(KeyboardInterrupt):
    """SIGTERM received: raised in the main thread to unwind the run as Ctrl-C does."""


def _set_parent_death_signal(sig: int) -> bool:
    """Ask Linux to send ``sig`` to this process when its parent thread ends; False elsewhere
    or if the call fails."""
    if not sys.platform.startswith("linux"):
        return False
    try:
        libc = ctypes.CDLL(ctypes.util.find_library("c") or "libc.so.6", use_errno=True)
        return libc.prctl(PR_SET_PDEATHSIG, int(sig), 0, 0, 0) == 0
    except (OSError, AttributeError):
        return False


def watch_parent(parent_pid: int, interval: float = WATCH_INTERVAL) -> threading.Thread:
    """Start a daemon thread that ends this process once its parent is no longer ``parent_pid``.

    An orphan is adopted by another process (init, or a subreaper), so ``os.getppid()``
    changes when the parent dies. The process ends with ``os._exit(1)``: nothing of a pool
    worker needs saving, its results go to the parent.
    """
    def watch():
        while os.getppid() == parent_pid:
            time.sleep(interval)
        os._exit(1)

    thread = threading.Thread(target=watch, name="shipblock-parent-watch", daemon=True)
    thread.start()
    return thread


def pool_worker_start(parent_pid: int) -> None:
    """Initializer of a local pool's worker: die with the parent, leave Ctrl-C to it.

    Parameters
    ----------
    parent_pid : int
        Process id of the process that starts the pool (``os.getpid()`` there).
    """
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    # a fork inherits the parent's Python handlers: SIGTERM must end a worker, not raise
    signal.signal(signal.SIGTERM, signal.SIG_DFL)
    if not _set_parent_death_signal(signal.SIGKILL):
        watch_parent(parent_pid)
    # the parent may have died before the death signal was asked for
    if os.getppid() != parent_pid:
        os._exit(1)


def stop_pool(pool, abort: bool) -> None:
    """Shut a ``concurrent.futures.ProcessPoolExecutor`` down.

    Parameters
    ----------
    pool : concurrent.futures.ProcessPoolExecutor
    abort : bool
        False: wait for the work submitted (the normal end). True (an exception, Ctrl-C,
        SIGTERM): cancel the work not started, terminate the workers (SIGTERM, then SIGKILL
        after :data:`STOP_GRACE` s) and reap them, without waiting for blocks that are running.
    """
    if not abort:
        pool.shutdown(wait=True)
        return
    # the executor names its processes only in a private attribute before Python 3.14
    # (terminate_workers there)
    processes = getattr(pool, "_processes", None)
    processes = list(processes.values()) if isinstance(processes, dict) else []
    pool.shutdown(wait=False, cancel_futures=True)
    for process in processes:
        with contextlib.suppress(OSError, ValueError, AttributeError):
            process.terminate()
    deadline = time.monotonic() + STOP_GRACE
    for process in processes:
        with contextlib.suppress(OSError, ValueError, AttributeError):
            process.join(max(0.0, deadline - time.monotonic()))
            if process.is_alive():
                process.kill()
                process.join(1.0)


@contextlib.contextmanager
def terminate_as_interrupt():
    """Within the block, SIGTERM raises :class:`Terminated` in the main thread.

    Outside the main thread (where Python cannot set signal handlers) the block runs with
    SIGTERM's handling unchanged. The previous handler is restored on exit.
    """
    if threading.current_thread() is not threading.main_thread():
        yield
        return

    def raise_terminated(signum, frame):
        raise Terminated(f"signal {signal.Signals(signum).name}")

    previous = signal.signal(signal.SIGTERM, raise_terminated)
    try:
        yield
    finally:
        signal.signal(signal.SIGTERM, previous)
