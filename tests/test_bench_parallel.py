"""The benchmark machinery of the cold start, the busy core and the Dask clusters (what is
measured and reported, never the speed itself)."""

import io
import time

import numpy as np
import pytest

from shipblock.bench import parallel, startup
from shipblock.cli import main


def test_busy_process_keeps_a_core_busy_and_ends():
    with parallel.busy_process() as proc:
        assert proc.poll() is None  # running
        t0 = time.process_time()
        time.sleep(0.2)
        assert time.process_time() - t0 < 0.1  # the load is the other process's, not ours
    assert proc.poll() is not None  # killed at the end of the block


def test_busy_core_rows_are_reported_with_a_verdict():
    rows = [{"cases": 360, "busy": False, "threads": 2, "cores": 2, "seconds_1": 6e-3,
             "seconds_n": 3.4e-3, "median_1": 6.2e-3, "median_n": 3.5e-3, "rounds": 40,
             "identical": True},
            {"cases": 360, "busy": True, "threads": 1, "cores": 2, "seconds_1": 6e-3,
             "seconds_n": 6e-3, "median_1": 6.2e-3, "median_n": 8.0e-3, "rounds": 40,
             "identical": True}]
    out = io.StringIO()
    parallel.write_busy_core(out, rows)
    lines = out.getvalue().splitlines()
    assert len(lines) == 2
    assert lines[0].endswith("never slower: met)")
    assert "beside a busy process" in lines[1] and lines[1].endswith("never slower: NOT met)")


def test_busy_core_batch_measures_both_conditions():
    rows = parallel.busy_core_batch(min_seconds=0.0, copies=(1,))
    assert [r["busy"] for r in rows] == [False, True]
    for r in rows:
        assert r["identical"] and r["rounds"] >= 3
        assert 1 <= r["threads"] <= r["cores"]
        assert 0 < r["seconds_1"] <= r["median_1"] and 0 < r["seconds_n"] <= r["median_n"]


def test_cold_start_report():
    c = {"cold": {"wall": 21.0, "cpu": 19.5, "code": 0, "compiled": {"the solver": 16.9}},
         "warm": {"wall": 4.1, "cpu": 4.0, "code": 0, "compiled": {}},
         "info_cold": {"wall": 1.8, "cpu": 1.9, "code": 0,
                       "compiled": {"the intensity measures": 0.3}},
         "target": 30.0, "load_average_before": (0.2, 0.3, 0.4), "load_average_after": None}
    out = io.StringIO()
    startup.write_cold_start(out, c)
    text = out.getvalue()
    assert "21.0 s" in text and "the solver 16.9 s" in text and "target 30 s: met" in text
    assert "the intensity measures 0.30 s" in text
    out = io.StringIO()
    startup.write_cold_start(out, {**c, "cold": {**c["cold"], "wall": 31.0}})
    assert "NOT met" in out.getvalue()
    out = io.StringIO()
    startup.write_cold_start(out, None)
    assert "skipped" in out.getvalue()


def test_cold_start_child_reports_what_compiled(tmp_path):
    """The child process of the cold start: exit code, CPU time, compile time by part."""
    result = startup.run_command(["info", "--record", "NP.1765"], tmp_path / "cache",
                                       tmp_path)
    assert result["code"] == 0 and result["wall"] > 0 and result["cpu"] > 0
    # an empty cache: the intensity measures compile, nothing of the solver
    assert set(result["compiled"]) == {"the intensity measures"}
    again = startup.run_command(["info", "--record", "NP.1765"], tmp_path / "cache",
                                      tmp_path)
    assert again["compiled"] == {}  # loaded from the cache filled by the first run


def test_dask_report():
    clusters = {1: {"seconds": 5.0, "runs_per_s": 600.0, "runs_per_s_per_worker": 600.0,
                    "stages": {"runs": 4.0}, "identical": True},
                2: {"seconds": 3.0, "runs_per_s": 1000.0, "runs_per_s_per_worker": 500.0,
                    "stages": {"runs": 2.0}, "identical": False}}
    d = {"runs": {"runs": 3000, "bootstrap": 0, "clusters": clusters, "scaling": 5.0 / 3.0,
                  "local": {"seconds": 4.0, "runs_per_s": 750.0, "stages": {"runs": 2.5}}}}
    out = io.StringIO()
    parallel.write_dask_scaling(out, d)
    text = out.getvalue()
    assert "pipeline 'runs' of 3000 runs (solver part)" in text
    assert "identical to the local run" in text and "DIFFERENT from the local run" in text
    assert "scaling from 1 to 2 workers: 1.67x" in text
    out = io.StringIO()
    parallel.write_dask_scaling(out, None)
    assert "not installed" in out.getvalue()


@pytest.mark.parametrize(("value", "needle"), [("1,x", "numbers of workers"),
                                               ("0,2", "must be >= 1")])
def test_bench_dask_argument_is_checked(value, needle, capsys):
    assert main(["bench", "--dask", value]) == 2
    assert needle in capsys.readouterr().err


def test_same_results_ignores_only_the_time_stamp():
    import xarray as xr

    a = xr.Dataset({"x": ("i", np.array([1.0, np.nan]))}, attrs={"created": "t0", "k": 1})
    b = a.copy(deep=True)
    b.attrs["created"] = "t1"
    assert parallel._same_results(a, b)
    b["x"].values[0] = 1.0 + 1e-15
    assert not parallel._same_results(a, b)
    c = a.copy(deep=True)
    c.attrs["k"] = 2
    assert not parallel._same_results(a, c)
