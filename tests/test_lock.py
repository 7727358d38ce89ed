"""One run per output: a second run is refused with the holder's pid, or waits (``--wait``).

The two-run test uses real processes: run A (``shipblock run``) holds its output and is held
in its batch until the test lets it go, so that what the others see does not depend on timing;
run B is refused while A holds the output, run C (``--wait``) says it waits, and runs once A
has ended, to the same result.
"""

from __future__ import annotations

import json
import os
import pickle
import signal
import socket
import subprocess
import sys
import textwrap
import threading
import time

import pytest

from shipblock.errors import ShipblockError
from shipblock.fragility.lock import OutputLockedError, hold_output, lock_path
from shipblock.fragility.pipeline import run_pipeline
from shipblock.fragility.store import open_results

from .test_pipeline import assert_same_results, write_pipeline

_HELD_RUN = textwrap.dedent(
    """
    import sys, time
    from pathlib import Path
    from shipblock.fragility import batch
    real = batch.run_chunk
    go = Path(sys.argv[3])
    def held(*args, **kwargs):
        deadline = time.monotonic() + 120
        while not go.exists() and time.monotonic() < deadline:   # until the test lets it go
            time.sleep(0.05)
        return real(*args, **kwargs)
    batch.run_chunk = held
    from shipblock.cli import main
    sys.exit(main(["-q", "run", sys.argv[1], "--output", sys.argv[2]]))
    """
)


def _wait_for(condition, what, proc=None, timeout=120.0):
    deadline = time.monotonic() + timeout
    while not condition():
        if proc is not None and proc.poll() is not None:
            pytest.fail(f"the run ended before {what}: {proc.communicate()}")
        if time.monotonic() > deadline:
            pytest.fail(f"timed out waiting for {what}")
        time.sleep(0.05)


def _shipblock(*args):
    return [sys.executable, "-m", "shipblock.cli", *args]


def test_a_second_run_is_refused_with_the_holders_pid_or_waits(tmp_path):
    path = write_pipeline(tmp_path)
    reference = run_pipeline(path, output=tmp_path / "ref" / "result.nc", progress=False)
    out = tmp_path / "out" / "result.nc"
    go = tmp_path / "go"
    a = subprocess.Popen([sys.executable, "-c", _HELD_RUN, str(path), str(out), str(go)],
                         stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    c = None
    try:
        _wait_for(lambda: lock_path(out).exists() and lock_path(out).read_text(),
                  "run A took its lock", a)
        holder = json.loads(lock_path(out).read_text())
        assert holder["pid"] == a.pid and holder["host"] == socket.gethostname()

        b = subprocess.run(_shipblock("run", str(path), "--output", str(out)),
                           capture_output=True, text=True, timeout=120)
        assert b.returncode == 2
        assert f"{out} is being written by another run (pid {a.pid} on " in b.stderr
        assert "--wait" in b.stderr and "Traceback" not in b.stderr
        assert json.loads(lock_path(out).read_text())["pid"] == a.pid  # A's lock untouched

        c_err = tmp_path / "c.err"
        with open(c_err, "w") as err:
            c = subprocess.Popen(_shipblock("run", str(path), "--output", str(out), "--wait"),
                                 stdout=subprocess.DEVNULL, stderr=err)
        _wait_for(lambda: "waiting for the run that holds" in c_err.read_text(),
                  "run C said it waits", c)
        assert f"pid {a.pid}" in c_err.read_text()
        assert not out.exists()
        go.touch()  # A goes on and ends; then C runs
        assert a.wait(timeout=120) == 0
        assert c.wait(timeout=120) == 0
    finally:
        go.touch()
        for proc in (a, c):
            if proc is not None and proc.poll() is None:
                proc.kill()
                proc.wait()
    assert "Traceback" not in c_err.read_text()
    assert_same_results(reference, open_results(out))
    assert not lock_path(out).exists()  # removed by the run that held it last


def test_one_process_cannot_hold_an_output_twice(tmp_path):
    out = tmp_path / "r.nc"
    with hold_output(out) as held:
        assert held == lock_path(out) and json.loads(held.read_text())["pid"] == os.getpid()
        with pytest.raises(OutputLockedError) as info, hold_output(out):
            pass
        assert info.value.holder["pid"] == os.getpid()
        assert isinstance(info.value, ShipblockError)
        copy = pickle.loads(pickle.dumps(info.value))  # crosses process boundaries intact
        assert str(copy) == str(info.value)
    assert not lock_path(out).exists()
    with hold_output(out):  # free again
        pass


def test_a_waiting_holder_gets_the_output_when_the_first_lets_go(tmp_path):
    out = tmp_path / "r.nc"
    order = []
    first_holds = threading.Event()

    def first():
        with hold_output(out):
            first_holds.set()
            time.sleep(0.5)
            order.append("first done")

    t = threading.Thread(target=first)
    t.start()
    first_holds.wait(10)
    with hold_output(out, wait=True):
        order.append("second holds")
    t.join()
    assert order == ["first done", "second holds"]


def test_a_leftover_lock_file_of_a_killed_run_is_no_obstacle(tmp_path):
    out = tmp_path / "r.nc"
    lock_path(out).write_text(json.dumps({"pid": 2**22 + 7, "host": socket.gethostname()}))
    with hold_output(out):
        assert json.loads(lock_path(out).read_text())["pid"] == os.getpid()
    lock_path(out).write_text("not json at all")
    with hold_output(out):
        pass


_HOLD_FOR_A_DEAD_PID = textwrap.dedent(
    """
    import fcntl, json, os, socket, sys, time
    fd = os.open(sys.argv[1], os.O_RDWR | os.O_CREAT, 0o666)
    fcntl.flock(fd, fcntl.LOCK_EX)
    os.write(fd, json.dumps({"pid": int(sys.argv[2]), "host": socket.gethostname()}).encode())
    print("held", flush=True)
    time.sleep(120)
    """
)


def test_a_lock_held_by_processes_a_dead_run_left_is_taken_over(tmp_path, caplog):
    """A run's forked children share its lock; if they outlived it, the lock names a dead pid."""
    dead = subprocess.Popen([sys.executable, "-c", "pass"])
    dead.wait()
    out = tmp_path / "r.nc"
    leftover = subprocess.Popen([sys.executable, "-c", _HOLD_FOR_A_DEAD_PID, str(lock_path(out)),
                                 str(dead.pid)], stdout=subprocess.PIPE, text=True)
    try:
        assert leftover.stdout.readline().strip() == "held"
        with caplog.at_level("WARNING", logger="shipblock.fragility.lock"), hold_output(out):
            assert json.loads(lock_path(out).read_text())["pid"] == os.getpid()
        assert f"pid {dead.pid}" in caplog.text and "taking it over" in caplog.text
    finally:
        leftover.send_signal(signal.SIGKILL)
        leftover.wait()


def test_a_live_holder_on_another_host_is_never_taken_over(tmp_path):
    """A pid means nothing on another host: such a holder is waited for or refused."""
    out = tmp_path / "r.nc"
    other = subprocess.Popen([sys.executable, "-c", _HOLD_FOR_A_DEAD_PID.replace(
        "socket.gethostname()", '"elsewhere"'), str(lock_path(out)), "1"],
        stdout=subprocess.PIPE, text=True)
    try:
        assert other.stdout.readline().strip() == "held"
        with pytest.raises(OutputLockedError, match="pid 1 on elsewhere"), hold_output(out):
            pass
    finally:
        other.send_signal(signal.SIGKILL)
        other.wait()
