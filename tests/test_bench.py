"""Tests of the benchmark machinery (what is measured and how), never of the speed itself.

The campaign is run end to end on two short synthetic records (see
``test_batch.make_catalogue``), in its own subprocess as ``shipblock bench`` runs it.
"""

from __future__ import annotations

import io
import math
import mmap
import sys

import numpy as np
import pytest

from shipblock.bench import campaign, solver, targets, timing
from shipblock.cli import main
from shipblock.fragility.pipeline import load_pipeline

from .test_batch import make_catalogue


@pytest.mark.parametrize("n_runs", [1, 6, 50, 324, 1000, 3000, 100_000])
def test_campaign_grid_is_the_smallest_near_square_grid(n_runs):
    n_levels, n_mu, n_sl = campaign.campaign_grid(n_runs, n_records=6)
    total = 6 * n_levels * n_mu * n_sl
    assert total >= n_runs
    assert total <= 1.01 * n_runs or total - n_runs < 6 * n_levels * n_mu
    assert n_mu <= n_sl <= max(2 * n_mu, n_mu + 1)
    assert 1 <= n_levels <= 12
    assert campaign.campaign_grid(3000) == (10, 5, 10)  # exactly 3000 runs
    assert 6 * math.prod(campaign.campaign_grid(100_000)) < 100_200


def test_campaign_pipeline_is_valid_and_has_the_runs(tmp_path):
    path, info = campaign.write_campaign_pipeline(tmp_path, 1000, chunk_size=128)
    pipe = load_pipeline(path)
    assert pipe.design.n_cases == info["runs"] >= 1000
    assert len(pipe.design.records) == info["records"] == 6  # the shipped catalogue
    assert pipe.design.shape == (6, info["levels"], info["n_mu"], info["n_slenderness"])
    assert pipe.chunk_size == 128
    assert pipe.fit["bootstrap"] == 0
    _, info = campaign.write_campaign_pipeline(tmp_path / "b", 100_000)
    assert info["chunk_size"] == -(-info["runs"] // 100)  # about 100 chunks


def test_kernel_time_is_found_in_a_profile():
    import cProfile
    import pstats

    from shipblock import simulate_batch

    system = timing.sliding_system()
    acc = np.sin(np.arange(4000) * 0.02)
    cases = np.array([[0, 0, 1.0, 1.0]] * 4)
    simulate_batch(system, [(acc, None)], [0.005], cases[:1])
    prof = cProfile.Profile()
    prof.runcall(simulate_batch, system, [(acc, None)], [0.005], cases)
    stats = pstats.Stats(prof)
    kernel = campaign._kernel_seconds(stats)
    assert 0 < kernel <= stats.total_tt


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="/proc/self/status is Linux")
def test_memory_is_read_from_proc():
    rss, peak = campaign._memory()
    assert 1e6 < rss <= peak
    # the peak is a high-water mark: reset it to the current size first (as the campaign does)
    if not campaign._reset_peak():
        pytest.skip("this kernel does not allow resetting the peak resident size")
    rss, peak = campaign._memory()
    # touch 50 MB of fresh pages (an anonymous map: a numpy array could reuse resident memory
    # the allocator kept from earlier tests, and the resident size would not grow)
    with mmap.mmap(-1, 50_000_000) as block:
        np.frombuffer(block, dtype=np.uint8)[::4096] = 1
        assert campaign._memory()[1] >= peak + 40e6


def test_campaign_runs_the_pipeline_in_a_subprocess(tmp_path):
    catalogue = make_catalogue(tmp_path / "records", n_records=2)
    res = campaign.campaign(40, directory=tmp_path / "work", catalogue=catalogue,
                         profile=tmp_path / "campaign.prof")
    assert res["runs"] == 2 * res["levels"] * res["n_mu"] * res["n_slenderness"] >= 40
    assert res["failed_runs"] == 0
    assert set(res["stages"]) == {"records", "runs", "solver", "fragility", "write"}
    assert res["stages"]["solver"] <= res["stages"]["runs"] <= res["seconds"]
    assert res["runs_per_s"] == pytest.approx(res["runs"] / res["seconds"])
    assert (tmp_path / "work" / "campaign.nc").stat().st_size == res["netcdf_bytes"] > 0
    assert (tmp_path / "campaign.prof").is_file()
    prof = res["profile"]
    assert 0 < prof["kernel"] <= prof["stages"]["batch"] < prof["total"]
    assert set(prof["stages"]) == {"batch", "records", "fits", "netcdf_write", "netcdf_read"}
    assert all(t > 0 for t in prof["stages"].values())
    if sys.platform.startswith("linux"):
        mem = res["memory"]
        assert 0 < mem["imports"] <= mem["warmup"] and mem["before"] <= mem["peak"]
        assert mem["increase"] == mem["peak"] - mem["before"]


def test_campaign_report_states_targets_only_for_a_full_campaign():
    c = {"runs": 324, "records": 6, "levels": 9, "n_mu": 2, "n_slenderness": 3,
         "chunk_size": 64, "seconds": 2.0, "runs_per_s": 162.0, "us_per_run": 6173.0,
         "failed_runs": 0, "stages": {"records": 0.3, "runs": 1.5, "solver": 1.4,
                                      "fragility": 0.1, "write": 0.1},
         "memory": {"imports": 250e6, "warmup": 350e6, "before": 350e6, "peak": 380e6,
                    "increase": 30e6, "peak_reset": True}}
    out = io.StringIO()
    campaign.write_campaign(out, c)
    text = out.getvalue()
    assert "applies to 100000 runs" in text and "NOT met" not in text
    assert "the campaign added 30 MB" in text
    out = io.StringIO()
    profile = {"total": 210.0, "kernel": 190.0,
               "stages": {"batch": 195.0, "records": 1.0, "fits": 3.0, "netcdf_write": 0.5,
                          "netcdf_read": 0.2}}
    campaign.write_campaign(out, {**c, "runs": 100_122, "seconds": 200.0, "profile": profile})
    text = out.getvalue()
    assert "(target 120 s: NOT met)" in text and "(target 200 MB: met)" in text
    assert "90.5 % of the profiled time in compiled kernels" in text
    assert "batch loop 5 s, records 1 s, fits 3 s, NetCDF 0.7 s" in text


@pytest.mark.parametrize("argv, needle", [
    (["bench", "--campaign-runs", "-1"], "--campaign-runs must be >= 0"),
    (["bench", "--chunk-size", "0"], "--chunk-size must be >= 1"),
])
def test_bench_arguments_are_checked(argv, needle, capsys):
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert needle in err and err.count("\n") == 1


def test_samples_counted_stop_where_a_run_fails():
    """A run that overturns integrates only up to its failure: only those samples count."""
    from shipblock import ShipBlockSystem, simulate_batch

    dt = 0.01
    t = np.arange(2000) * dt
    pulse = np.where(t < 0.5, 30.0, 0.0)  # overturns the slender blocks early
    quiet = 0.5 * np.sin(2 * np.pi * t)  # never moves them
    system = ShipBlockSystem(ship_mass=5e6, block_mass=1500.0, n_blocks=150, half_width=0.12,
                             half_height=0.8, mu_s_ground=0.8, mu_k_ground=0.8, mu_s_ship=0.8,
                             mu_k_ship=0.8)
    summ = simulate_batch(system, [(pulse, None), (quiet, None)], dt, [(0, 0, 1, 1), (1, 0, 1, 1)])
    assert summ["failure"][0] != 0 and summ["failure"][1] == 0
    n = timing.integrated_samples(summ, np.array([dt, dt]))
    failed_at = summ["failure_time"][0]
    assert n == pytest.approx(failed_at / dt + 1 + t.size, rel=1e-12)
    assert n < 1.5 * t.size  # not the 2 x 2000 input samples


def test_interleaved_times_alternate_the_calls_on_their_threads():
    """Each round calls every function once, in order, on its own thread count; restored after."""
    import numba

    calls_seen = []

    def probe(tag):
        def call():
            calls_seen.append((tag, numba.get_num_threads()))
            return tag
        return call

    before = numba.get_num_threads()
    n = numba.config.NUMBA_NUM_THREADS
    times, results = timing.interleaved_times([(1, probe("a")), (n, probe("b"))], 0.0,
                                             min_rounds=3)
    assert times.shape == (3, 2) and np.all(times >= 0)
    assert calls_seen == [("a", 1), ("b", n)] * 3
    assert results == ["a", "b"]
    assert numba.get_num_threads() == before


def test_control_loop_is_calibrated_to_the_requested_length(monkeypatch):
    """The control loop's calibration, on a clock that the loop itself advances (1e-8 s per
    iteration): it lasts what was asked. Wall-clock lengths belong to ``shipblock bench``, not to
    a unit test on a shared machine (a timed test fails by chance under load)."""
    clock = {"now": 0.0}
    per_iteration = 1e-8

    def spin(n, out):
        clock["now"] += n * per_iteration

    monkeypatch.setattr(timing, "_spin", spin)
    monkeypatch.setattr(timing.time, "perf_counter", lambda: clock["now"])
    for seconds in (0.02, 0.5):
        loop = timing.control_loop(seconds)
        t0 = clock["now"]
        loop()
        assert clock["now"] - t0 == pytest.approx(seconds, rel=1e-6)


def test_throughput_reports_best_and_median_of_its_window():
    """Best and median rates from the same calls; samples counted are those integrated."""
    dt = 0.01
    t = np.arange(1500) * dt
    records = [("sine", 3.0 * np.sin(2 * np.pi * t), 0.3 * np.sin(3 * np.pi * t), dt)]
    r = solver.throughput(timing.rocking_system(), records, scale=1.0, min_seconds=0.05)
    assert r["rounds"] >= 5
    assert r["samples_per_s"] == pytest.approx(r["samples"] / r["seconds"])
    assert r["samples_per_s"] >= r["samples_per_s_median"] > 0
    assert r["spread"] == pytest.approx(r["samples_per_s"] / r["samples_per_s_median"])
    assert r["spread"] >= 1.0 and r["control_spread"] >= 1.0
    assert r["samples"] <= r["input_samples"] == t.size
    assert r["fraction_rocking"] > 0.1  # the sine rocks the slender blocks


@pytest.mark.parametrize("batch, machine, expected", [
    (1.9, 1.95, "met"),
    (1.9, 1.5, "met"),
    (1.6, 1.95, "NOT met"),
    (1.6, 1.5, "NOT met, nor did the control loop: the machine allowed no more in this window"),
])
def test_scaling_verdict_says_when_the_machine_missed_too(batch, machine, expected):
    got = targets.scaling_verdict({"speedup": batch, "machine_speedup": machine}, target=1.8)
    assert got == expected


def test_spectrum_case_reports_its_size_and_a_positive_time():
    """The spectrum case (which replaced a timed unit test) runs the kernel on the size asked."""
    r = timing.spectrum_time(periods=4, samples=200, rounds=2)
    assert r["periods"] == 4 and r["samples"] == 200 and r["rounds"] == 2
    assert r["seconds"] > 0
