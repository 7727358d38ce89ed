"""Threads of a batch: how many a batch gets, and that results do not depend on them."""

import os
import threading

import numpy as np
import pytest

import shipblock.solver as solver_module
from shipblock import ShipBlockSystem, simulate, simulate_batch
from shipblock.solver import _threads


@pytest.mark.parametrize(
    ("requested", "n_cases", "n_samples", "others", "cores", "expected"),
    [
        (2, 1, 1e9, 0, 2, 1),  # one case: one thread
        (2, 50, 1e6, 0, 2, 2),  # a quiet machine: all threads
        (2, 50, 1e6, 1, 2, 1),  # a short batch beside a busy core: the free core only
        (2, 50, 1e6, 5, 2, 1),  # never fewer than one
        (2, 50, None, 1, 2, 1),  # unknown length: as a short batch
        (2, 50, 1e9, 1, 2, 2),  # a long batch gains from a shared core: all threads
        (2, 50, 1e4, 0, 2, 1),  # a tiny batch: not worth starting a thread
        (8, 50, 1e9, 0, 2, 2),  # no more threads than usable cores
        (1, 50, 1e9, 0, 4, 1),  # no more than requested
        (4, 3, 1e6, 0, 4, 3),  # no more than cases
    ],
)
def test_batch_threads(requested, n_cases, n_samples, others, cores, expected):
    got = _threads.batch_threads(requested, n_cases, n_samples, others=others, cores=cores)
    assert got == expected


def test_long_batch_threshold_is_per_thread():
    limit = _threads.SHORT_BATCH_SAMPLES
    assert _threads.batch_threads(2, 100, 2 * limit, others=1, cores=2) == 2
    assert _threads.batch_threads(2, 100, 1.9 * limit, others=1, cores=2) == 1


def test_other_runnable_reads_the_running_count(tmp_path, monkeypatch):
    fake = tmp_path / "loadavg"
    fake.write_text("0.52 0.41 0.30 3/120 9999\n")
    monkeypatch.setattr(_threads, "usable_cores", lambda: os.cpu_count())
    assert _threads.other_runnable(str(fake)) == 2  # the caller is one of the three
    fake.write_text("0.00 0.00 0.00 1/80 9999\n")
    assert _threads.other_runnable(str(fake)) == 0
    assert _threads.other_runnable(str(tmp_path / "missing")) is None
    fake.write_text("garbage\n")
    assert _threads.other_runnable(str(fake)) is None


def test_other_runnable_unknown_in_a_cpu_subset(tmp_path, monkeypatch):
    """With fewer usable CPUs than the machine has, the machine-wide count says nothing."""
    fake = tmp_path / "loadavg"
    fake.write_text("0.52 0.41 0.30 3/120 9999\n")
    monkeypatch.setattr(_threads, "usable_cores", lambda: (os.cpu_count() or 2) + 1)
    assert _threads.other_runnable(str(fake)) is None


@pytest.mark.parametrize(("files", "expected"), [
    ({"cpu.max": "150000 100000\n"}, 1.5),  # cgroup v2, a limit of 1.5 CPUs
    ({"cpu.max": "max 100000\n"}, None),  # v2, no limit
    ({"cpu/cpu.cfs_quota_us": "200000\n", "cpu/cpu.cfs_period_us": "100000\n"}, 2.0),  # v1
    ({"cpu/cpu.cfs_quota_us": "-1\n", "cpu/cpu.cfs_period_us": "100000\n"}, None),
    ({}, None),  # no cgroup file system
])
def test_cgroup_cpu_quota(tmp_path, files, expected):
    for name, text in files.items():
        (tmp_path / name).parent.mkdir(parents=True, exist_ok=True)
        (tmp_path / name).write_text(text)
    assert _threads.cgroup_cpu_quota(str(tmp_path)) == expected


def test_usable_cores_honours_a_quota(monkeypatch):
    monkeypatch.setattr(_threads, "cgroup_cpu_quota", lambda: 1.5)
    assert _threads.usable_cores() == min(2, len(os.sched_getaffinity(0)))
    monkeypatch.setattr(_threads, "cgroup_cpu_quota", lambda: 0.2)
    assert _threads.usable_cores() == 1


def test_run_on_threads_calls_on_distinct_threads_and_raises():
    seen = []
    lock = threading.Lock()
    barrier = threading.Barrier(3, timeout=10)

    def fn(tag):
        with lock:
            seen.append((tag, threading.get_ident()))
        barrier.wait()  # all three run at once

    _threads.run_on_threads(fn, ("x",), 3)
    assert len(seen) == 3 and len({ident for _, ident in seen}) == 3
    assert threading.get_ident() in {ident for _, ident in seen}  # the caller is one of them

    def fails(tag):
        if threading.current_thread().name.startswith("shipblock-batch"):
            raise RuntimeError(tag)

    with pytest.raises(RuntimeError, match="from a worker"):
        _threads.run_on_threads(fails, ("from a worker",), 2)


def _uneven_batch():
    rng = np.random.default_rng(5)
    dt = 0.01
    t = np.arange(2500) * dt
    pulse = 7.0 * np.sin(2 * np.pi * 1.2 * t) * np.exp(-0.25 * t) + rng.normal(0, 0.3, t.size)
    systems = [ShipBlockSystem(ship_mass=2e5, block_mass=500.0, n_blocks=8, half_width=bw,
                               half_height=0.6, mu_s_ground=mu, mu_k_ground=0.9 * mu,
                               mu_s_ship=0.7, mu_k_ship=0.6)
               for bw, mu in ((0.3, 0.8), (1.0, 0.15))]  # rocking; sliding
    scales = np.r_[np.full(10, 0.01), np.linspace(0.3, 1.2, 30)]
    cases = np.array([[0, k % 2, f, f] for k, f in enumerate(scales)])
    return systems, [(pulse, 0.3 * pulse)], dt, cases


@pytest.mark.parametrize("threads", [2, 3])
def test_batch_on_several_threads_equals_one_thread_and_simulate(monkeypatch, threads):
    """Whatever the threads and their share of the cases, each case is the simulate run."""
    systems, records, dt, cases = _uneven_batch()
    monkeypatch.setattr(solver_module, "batch_threads", lambda *args, **kwargs: 1)
    serial = simulate_batch(systems, records, dt, cases)
    monkeypatch.setattr(solver_module, "batch_threads", lambda *args, **kwargs: threads)
    parallel = simulate_batch(systems, records, dt, cases)
    assert serial["n_impacts"].sum() > 0 and serial["peak_block_slip"].max() > 0.0
    for key, values in serial.items():
        np.testing.assert_array_equal(parallel[key], values, err_msg=key)
    (h, v), = records
    for k in (0, 15, 24, 39):
        one = simulate(systems[int(cases[k, 1])], cases[k, 2] * h, cases[k, 3] * v, dt).summary
        for key in ("peak_rotation", "peak_block_slip", "peak_ship_slip", "end_time"):
            assert parallel[key][k] == one[key], (k, key)
