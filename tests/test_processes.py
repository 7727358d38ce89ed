"""No process outlives a killed run: pool workers die with ``shipblock run``, whatever ends it.

A real ``shipblock run`` (the command's ``main``) runs in a subprocess whose output is captured
through pipes. Its bootstrap resamples go to a local pool of two forked workers, each of which,
on its first block, leaves a file named by its pid and then takes long: the test acts only once
both files exist, so it knows the run is in the bootstrap with both workers busy. It then ends
the run with SIGKILL, SIGTERM or SIGINT (sent to the whole process group, as a terminal's
Ctrl-C is) and checks that the captured pipes close (no process holds them), that none of the
run's processes is left, and, for SIGTERM and SIGINT, the message and exit status and that no
traceback was printed. The SIGKILL case runs twice: with Linux's parent-death signal and with
the watchdog thread used where that does not exist.

The run is started as a shell starts a command in the foreground, with Ctrl-C's default
action, whatever this test process has: a process inherits an ignored SIGINT through fork and
exec, and Python keeps it ignored. pytest run as a background job of a shell without job
control (``.ci/run > log &``) ignores SIGINT, and a run it started without that reset ignored
the Ctrl-C and was still alive 30 s later, as in the full CI runs of session 19. To make that
condition part of every run of the test, the run is always started while this process ignores
SIGINT (:func:`_sigint_ignored`).
"""

from __future__ import annotations

import contextlib
import os
import signal
import subprocess
import sys
import textwrap
import time

import pytest

from .test_pipeline import IDA_LEVELS_G, write_pipeline

psutil = pytest.importorskip("psutil")

_RUN_HELD_IN_BOOTSTRAP = textwrap.dedent(
    """
    import os, signal, sys, time
    # Ctrl-C's default action, as a shell gives a foreground command: the SIGINT that this
    # process inherits from the test's process may be ignored (see the module's docstring)
    signal.signal(signal.SIGINT, signal.default_int_handler)
    from pathlib import Path
    from shipblock import processes
    from shipblock.fragility import workers
    import importlib
    fit = importlib.import_module("shipblock.fragility.fit.bootstrap")  # the module, not the function
    workers.LOCAL_POOL_SECONDS = 0.0   # the local pool from the first bootstrap on
    workers.usable_cores = lambda: 2   # two workers, also on a one-core machine
    if sys.argv[4] == "watchdog":      # as where prctl(PR_SET_PDEATHSIG) does not exist
        processes._set_parent_death_signal = lambda sig: False
    marks = Path(sys.argv[3])
    real = fit._bootstrap_block
    parent = os.getpid()
    def held(*args):
        if os.getpid() != parent:      # in a pool worker: say so, then take long
            (marks / str(os.getpid())).write_text("")
            time.sleep(600)
        return real(*args)
    fit._bootstrap_block = held
    from shipblock.cli import main
    sys.exit(main(["-q", "run", sys.argv[1], "--output", sys.argv[2]]))
    """
)


def _alive(pid: int) -> bool:
    """Whether ``pid`` is a live process (a zombie holds no memory, pipe or file: not alive)."""
    try:
        return psutil.Process(pid).status() != psutil.STATUS_ZOMBIE
    except psutil.NoSuchProcess:
        return False


@contextlib.contextmanager
def _sigint_ignored():
    """Ignore SIGINT in this process within the block, as a background job of a
    shell without job control does from its start; the previous handler is restored."""
    previous = signal.signal(signal.SIGINT, signal.SIG_IGN)
    try:
        yield
    finally:
        signal.signal(signal.SIGINT, previous)


@pytest.fixture(scope="module")
def pipeline(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("held")
    path = write_pipeline(tmp, levels=f"levels_g = {list(IDA_LEVELS_G)}")  # fits identified
    # 100 resamples: 16 probed here, the other 84 in 8 blocks for the pool
    path.write_text(path.read_text().replace("bootstrap = 20", "bootstrap = 100"))
    return path


@pytest.mark.parametrize(("how", "death"), [("SIGKILL", "prctl"), ("SIGKILL", "watchdog"),
                                            ("SIGTERM", "prctl"), ("SIGINT", "prctl")])
def test_no_process_outlives_a_run_ended_in_the_bootstrap(pipeline, tmp_path, how, death):
    marks = tmp_path / "marks"
    marks.mkdir()
    out = tmp_path / "result.nc"
    with _sigint_ignored():  # the run must not depend on how this process was started
        proc = subprocess.Popen([sys.executable, "-c", _RUN_HELD_IN_BOOTSTRAP, str(pipeline),
                                 str(out), str(marks), death],
                                stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                                start_new_session=True)
    workers = []
    try:
        deadline = time.monotonic() + 120
        while len(list(marks.iterdir())) < 2:
            if proc.poll() is not None:
                pytest.fail(f"the run ended before its bootstrap: {proc.communicate()}")
            if time.monotonic() > deadline:
                pytest.fail("the run's pool workers never started their blocks")
            time.sleep(0.05)
        workers = [int(p.name) for p in marks.iterdir()]
        children = [c.pid for c in psutil.Process(proc.pid).children(recursive=True)]
        assert sorted(workers) == sorted(children)  # the two workers are all there is
        if how == "SIGINT":
            os.killpg(proc.pid, signal.SIGINT)  # a terminal's Ctrl-C: the whole group
        else:
            os.kill(proc.pid, getattr(signal, how))
        # returns only once every holder of the pipes is gone
        stdout, stderr = proc.communicate(timeout=30)
        deadline = time.monotonic() + 10
        while any(_alive(pid) for pid in workers) and time.monotonic() < deadline:
            time.sleep(0.05)
        assert [pid for pid in workers if _alive(pid)] == []
    finally:
        for pid in [proc.pid, *workers]:
            if _alive(pid):
                os.kill(pid, signal.SIGKILL)
        proc.wait(timeout=30)
    stderr = stderr.decode()
    assert "Traceback" not in stderr
    partial = out.with_name(out.name + ".partial")
    assert len(list(partial.glob("chunk-*.npz"))) >= 1  # the finished batch is kept
    assert not out.exists()
    if how == "SIGKILL":
        assert proc.returncode == -signal.SIGKILL
    else:
        word = {"SIGTERM": "terminated", "SIGINT": "interrupted"}[how]
        assert proc.returncode == 128 + getattr(signal, how)
        assert f"shipblock: {word}" in stderr and "resumes" in stderr
        assert stderr.count("shipblock:") == 1  # one message, none from the workers


def test_sigterm_handler_is_restored_and_only_set_in_the_main_thread():
    from shipblock.processes import Terminated, terminate_as_interrupt

    before = signal.getsignal(signal.SIGTERM)
    with pytest.raises(Terminated), terminate_as_interrupt():
        os.kill(os.getpid(), signal.SIGTERM)
        time.sleep(5)  # the handler raises before this ends
    assert signal.getsignal(signal.SIGTERM) == before
    assert issubclass(Terminated, KeyboardInterrupt)  # cleaned up as Ctrl-C is

    import threading

    seen = []

    def in_thread():
        with terminate_as_interrupt():
            seen.append(signal.getsignal(signal.SIGTERM))

    t = threading.Thread(target=in_thread)
    t.start()
    t.join()
    assert seen == [before]
