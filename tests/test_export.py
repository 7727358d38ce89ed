"""``shipblock export results.nc --csv DIR``: the per-run and fragility tables of a study, units in
the column names, values those of the results file."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from shipblock.cli import main
from shipblock.fragility.export import fragility_table, run_table
from shipblock.fragility.pipeline import run_pipeline
from shipblock.units import STANDARD_GRAVITY as G

from .test_pipeline import write_pipeline


@pytest.fixture(scope="module")
def study(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("export")
    path = write_pipeline(tmp, levels="levels_g = [0.2, 0.4, 0.6]", n_records=2,
                          sweep="[sweep]\nmu_ship = [0.3, 0.35]\n")
    return tmp, run_pipeline(path, progress=False)


def test_export_writes_runs_and_fragility_tables_with_units(study, tmp_path, capsys):
    tmp, ds = study
    out = tmp_path / "csv"
    assert main(["-q", "export", str(tmp / "out" / "result.nc"), "--csv", str(out)]) == 0
    assert f"written {out / 'runs.csv'}" in capsys.readouterr().out
    runs = pd.read_csv(out / "runs.csv")
    # one row per run: 2 records x 3 levels x 2 swept values
    assert len(runs) == 2 * 3 * 2
    for column in ("record", "im_level [m/s^2]", "im_level_g [g]", "mu_ship [-]",
                   "peak_ship_slip [m]", "peak_rotation [rad]", "scale_factor [-]",
                   "peak_ground_normal_force [N]", "exceeded:ship_slip", "valid:any_failure"):
        assert column in runs.columns, column
    # each row's values are the file's at its coordinates
    for _, row in runs.iterrows():
        sel = {"record": row["record"], "im_level": row["im_level [m/s^2]"],
               "mu_ship": row["mu_ship [-]"]}
        assert row["im_level_g [g]"] == pytest.approx(row["im_level [m/s^2]"] / G, rel=1e-12)
        for name in ("peak_ship_slip", "scale_factor"):
            stored = float(ds[name].sel({k: v for k, v in sel.items() if k in ds[name].dims}))
            column = "peak_ship_slip [m]" if name == "peak_ship_slip" else "scale_factor [-]"
            assert row[column] == stored or (np.isnan(stored) and np.isnan(row[column]))
        assert bool(row["exceeded:ship_slip"]) == bool(
            ds["exceeded"].sel(limit_state="ship_slip", **sel))
    frag = pd.read_csv(out / "fragility.csv")
    assert len(frag) == 2 * 2  # limit states x swept values
    assert list(frag.columns[:6]) == ["limit_state", "mu_ship [-]", "edp", "condition",
                                      "threshold", "threshold_units"]
    row = frag[(frag["limit_state"] == "ship_slip") & (frag["mu_ship [-]"] == 0.35)].iloc[0]
    assert row["edp"] == "peak_ship_slip" and row["threshold"] == 0.005
    assert row["threshold_units"] == "m"
    median = float(ds["median"].sel(limit_state="ship_slip", mu_ship=0.35))
    assert row["median [m/s^2]"] == median or (np.isnan(median) and np.isnan(row["median [m/s^2]"]))
    assert "beta [-]" in frag.columns and "median_lower [m/s^2]" in frag.columns


def test_tables_match_the_library_functions(study):
    _, ds = study
    assert list(run_table(ds).columns)[:4] == ["record", "im_level [m/s^2]", "im_level_g [g]",
                                               "mu_ship [-]"]
    assert fragility_table(ds)["limit_state"].tolist() == ["ship_slip", "ship_slip",
                                                           "any_failure", "any_failure"]


def test_export_refuses_a_simulation_response(tmp_path, capsys):
    import xarray as xr

    nc = tmp_path / "r.nc"
    xr.Dataset({"x_b": ("time", np.zeros(3))}, coords={"time": np.arange(3.0)}).to_netcdf(nc)
    assert main(["-q", "export", str(nc), "--csv", str(tmp_path)]) == 2
    err = capsys.readouterr().err
    assert str(nc) in err and "not the result of a study" in err
