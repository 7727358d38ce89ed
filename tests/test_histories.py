"""Full time histories of selected batch runs: selection, bit-identity with the batch, resume.

Uses the short synthetic records of ``test_batch.make_catalogue`` through real pipeline files.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import xarray as xr

import shipblock
from shipblock.cli import main
from shipblock.fragility import histories as hist_module
from shipblock.fragility.histories import SelectionError, case_number, select_cases
from shipblock.fragility.pipeline import PipelineError, load_pipeline, rerun_case, run_pipeline
from shipblock.units import STANDARD_GRAVITY as G

from .test_pipeline import local_dask_client, write_pipeline

#: Summary values compared bit for bit between a history file and its batch run.
COMPARED = ("peak_ship_slip", "peak_block_slip", "peak_rotation", "residual_ship_slip",
            "residual_block_slip", "n_impacts", "n_events", "input_work", "failure",
            "time_in_mode_1", "time_in_mode_4")

HISTORIES = """
[histories]
runs = [{record = "S1", im_level_g = 0.6}, {record = "syn/S2"}]
exceeding = ["ship_slip"]
max_runs = 40
"""


def with_histories(path, table=HISTORIES):
    path.write_text(path.read_text() + table)
    return path


@pytest.fixture(scope="module")
def history_run(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("hist")
    path = with_histories(write_pipeline(tmp))
    ds = run_pipeline(path, progress=False)
    return tmp, path, ds


def test_files_hold_the_batch_runs_bit_for_bit(history_run):
    tmp, path, ds = history_run
    files = ds["history_file"]
    assert files.dims == ("record", "im_level")
    assert files.attrs["units"] == "1" and "long_name" in files.attrs
    listed = {str(f) for f in files.values.ravel() if f}
    assert listed == {f"result_histories/{p.name}"
                      for p in (tmp / "out" / "result_histories").glob("*.nc")}
    assert ds.attrs["histories_directory"] == "result_histories"
    for rec in ds["record"].values:
        for level in ds["im_level"].values:
            name = str(files.sel(record=rec, im_level=level).values)
            if not name:
                continue
            run = ds.sel(record=rec, im_level=level)
            with xr.open_dataset(tmp / "out" / name) as h:
                assert h.attrs["record"] == rec
                assert h.attrs["im_level"] == level
                assert h.attrs["scale_factor"] == float(run["scale_factor"])
                assert h.attrs["pipeline_fingerprint"] == ds.attrs["pipeline_fingerprint"]
                for key in COMPARED:
                    assert h.attrs[f"summary_{key}"] == float(run[key]), (name, key)
                # the stored histories are the run: last x_s is the residual slip, the input
                # is the record scaled to the level
                assert float(h["x_s"][-1]) == float(run["residual_ship_slip"])
                pga = float(np.abs(h["ground_acceleration_h"]).max())
                assert pga == pytest.approx(level, rel=1e-9)
                for var in h.variables.values():
                    assert "units" in var.attrs and "long_name" in var.attrs


def test_selection_is_selectors_then_exceeding_runs(history_run):
    tmp, path, ds = history_run
    has = ds["history_file"] != ""
    # selector 1: one run; selector 2: every level of S2 (im_level left out)
    assert bool(has.sel(record="syn/S1", im_level=0.6 * G))
    assert bool(has.sel(record="syn/S2").all())
    # every run exceeding ship_slip, and nothing else
    exceeded = ds["exceeded"].sel(limit_state="ship_slip") & ds["valid"].sel(
        limit_state="ship_slip")
    assert exceeded.any() and not exceeded.all()  # the test means something
    expected = exceeded.copy()
    expected.loc[{"record": "syn/S1", "im_level": 0.6 * G}] = True
    expected.loc[{"record": "syn/S2"}] = True
    assert (has == expected).all()


def test_max_runs_caps_selected_first(tmp_path):
    path = with_histories(write_pipeline(tmp_path), HISTORIES.replace("max_runs = 40",
                                                                      "max_runs = 3"))
    ds = run_pipeline(path, progress=False)
    has = ds["history_file"] != ""
    assert int(has.sum()) == 3
    assert bool(has.sel(record="syn/S1", im_level=0.6 * G))  # selectors come first
    assert int(has.sel(record="syn/S2").sum()) == 2


def test_rerun_keeps_written_histories_and_result(history_run, monkeypatch):
    tmp, path, ds = history_run

    def fail(*args, **kwargs):
        raise AssertionError("a finished history was computed again")

    monkeypatch.setattr(hist_module, "run_case", fail)
    again = run_pipeline(path, progress=False)
    xr.testing.assert_identical(ds.drop_attrs(deep=False), again.drop_attrs(deep=False))


def test_rerun_removes_temporary_files_of_a_killed_history_write(history_run):
    """A run killed while writing a history file leaves ``.<name>.<random>.tmp``; the next run
    removes it (and only it), as it does for the result file."""
    tmp, path, ds = history_run
    written = [Path(tmp) / "out" / f for f in ds["history_file"].values.ravel() if f]
    target = written[0]
    stale = target.parent / f".{target.name}.0a1b2c3d.tmp"
    other = target.parent / f".{target.name}.keep.tmp"  # not our pattern: kept
    stale.write_bytes(b"half a NetCDF file")
    other.write_bytes(b"someone else's")
    run_pipeline(path, progress=False)
    assert not stale.exists()
    assert other.exists()


def test_history_request_is_not_part_of_the_run_identity(tmp_path):
    path = write_pipeline(tmp_path)
    plain = load_pipeline(path)
    with_histories(path)
    asked = load_pipeline(path)
    assert asked.histories is not None and plain.histories is None
    assert asked.identity() == plain.identity()


def test_rerun_case_equals_the_batch(history_run):
    tmp, path, ds = history_run
    res = rerun_case(path, "S0", im_level_g=0.8)
    run = ds.sel(record="syn/S0", im_level=0.8 * G)
    for key in COMPARED:
        assert float(res.summary[key]) == float(run[key]), key
    assert res.x_s.size == int(ds["record_npts"].sel(record="syn/S0"))


def test_sweep_selectors_and_file_names(tmp_path):
    path = write_pipeline(tmp_path, kind="msa", levels="levels_g = [0.3, 0.6]",
                          sweep="[sweep]\nmu_ship = [0.3, 0.45]\n")
    pipe = load_pipeline(path)
    design = pipe.design
    cases = select_cases(design, {"record": "S1", "mu_ship": 0.45})
    assert len(cases) == 2  # both levels
    assert [hist_module.history_filename(design, c) for c in cases] == [
        "S1_im0_mu_ship1.nc", "S1_im1_mu_ship1.nc"]
    one = case_number(design, {"record": "S1", "im_level_g": 0.6, "mu_ship": 0.45})
    assert one == cases[1]
    coords = hist_module.case_coordinates(design, one)
    assert coords == {"record": "syn/S1", "im_level": pytest.approx(0.6 * G), "mu_ship": 0.45}
    with pytest.raises(SelectionError, match="also give mu_ship"):
        case_number(design, {"record": "S1", "im_level_g": 0.6})
    res = rerun_case(path, "S1", im_level_g=0.3, mu_ship=0.3)
    assert res.system.mu_s_ship == 0.3


@pytest.mark.parametrize(
    ("table", "key"),
    [
        ('runs = [{record = "nope"}]', "histories.runs[0].record"),
        ('runs = [{record = "S0", im_level_g = 0.7}]', "histories.runs[0].im_level_g"),
        ('runs = [{record = "S0", level = 1}]', "histories.runs[0].level"),
        ('runs = [{im_level_g = 0.2}]', "histories.runs[0].record"),
        ('runs = ["S0"]', "histories.runs[0]"),
        ('exceeding = ["nope"]', "histories.exceeding"),
        ('exceeding = ["ship_slip"]\nmax_runs = 0', "histories.max_runs"),
        ('directory = "h"', "histories"),
        ('colour = "red"', "histories.colour"),
    ],
)
def test_invalid_history_requests_name_the_key(tmp_path, table, key):
    path = with_histories(write_pipeline(tmp_path), "[histories]\n" + table + "\n")
    with pytest.raises(PipelineError) as info:
        load_pipeline(path)
    assert info.value.key == key, str(info.value)


def test_history_command_prints_writes_and_draws(history_run, tmp_path, capsys):
    tmp, path, ds = history_run
    out_nc = tmp_path / "one.nc"
    code = main(["-q", "history", str(path), "--record", "S2", "--im-level-g", "0.5",
                 "-o", str(out_nc)])
    out = capsys.readouterr().out
    assert code == 0, out
    assert "syn/S2" in out and "peak ship slip" in out
    assert "syn/S2 at PGA 0.5 g, scale factor" in out  # the pipeline's unit, not m/s^2
    assert out_nc.exists() and out_nc.with_suffix(".png").exists()
    with xr.open_dataset(out_nc) as h:
        run = ds.sel(record="syn/S2", im_level=0.5 * G)
        assert h.attrs["summary_peak_ship_slip"] == float(run["peak_ship_slip"])
    code = main(["-q", "plot", str(out_nc), "--figure", str(tmp_path / "again.png")])
    assert code == 0 and (tmp_path / "again.png").exists()
    # a selection naming no single run: one line naming the key, exit status 2
    code = main(["-q", "history", str(path), "--record", "S2"])
    err = capsys.readouterr().err
    assert code == 2 and "[im_level]" in err and "several runs" in err


def test_a_level_or_swept_value_not_in_the_design_is_named_in_the_unit_it_was_given(
        tmp_path, capsys):
    # --im-level-g 0.65 used to be reported as "[im_level_g] 6.3743225 is not a value ...;
    # values: 0.3, 0.6": the level in m/s^2 under the name in g, beside the values in g
    path = write_pipeline(tmp_path, kind="msa", levels="levels_g = [0.3, 0.6]",
                          sweep="[sweep]\nhalf_height = [0.5, 0.6]\n")
    base = ["-q", "history", str(path), "--record", "S1"]
    assert main([*base, "--im-level-g", "0.65", "--set", "half_height=0.5"]) == 2
    err = capsys.readouterr().err
    assert "[im_level_g] 0.65 g is not a value of the design; values: 0.3, 0.6 g" in err
    assert main([*base, "--im-level", "3", "--set", "half_height=0.5"]) == 2
    err = capsys.readouterr().err
    assert (f"[im_level] 3.0 m/s^2 is not a value of the design; values: {0.3 * G:g}, "
            f"{0.6 * G:g} m/s^2") in err
    assert main([*base, "--im-level-g", "0.6", "--set", "half_height=0.55"]) == 2
    err = capsys.readouterr().err
    assert "[half_height] 0.55 m is not a value of the design; values: 0.5, 0.6 m" in err


def test_top_level_export():
    assert shipblock.rerun_case is rerun_case


def test_selectors_skip_runs_outside_a_stripe(tmp_path):
    levels = 'levels_g = [0.3, 0.6]\nstripes = [["S0", "S1"], ["S1", "S2"]]'
    path = write_pipeline(tmp_path, kind="msa", levels=levels)
    design = load_pipeline(path).design
    assert [hist_module.history_filename(design, c)
            for c in select_cases(design, {"record": "S1"})] == ["S1_im0.nc", "S1_im1.nc"]
    assert [hist_module.history_filename(design, c)
            for c in select_cases(design, {"record": "S2"})] == ["S2_im1.nc"]
    with pytest.raises(SelectionError, match="not in the stripe"):
        case_number(design, {"record": "S2", "im_level_g": 0.3})
    with pytest.raises(SelectionError, match="in no stripe"):
        select_cases(design, {"record": "S0", "im_level_g": 0.6})


def test_histories_of_a_dask_batch_equal_the_local_ones(history_run, tmp_path):
    tmp, path, local = history_run
    with local_dask_client(n_workers=1, processes=False) as client:
        remote = run_pipeline(path, output=tmp_path / "dask.nc", client=client, progress=False)
    np.testing.assert_array_equal(remote["history_file"].values,
                                  np.char.replace(local["history_file"].values.astype(str),
                                                  "result_histories", "dask_histories"))
    for name in local["history_file"].values.ravel():
        if name:
            with xr.open_dataset(tmp / "out" / name) as a, \
                    xr.open_dataset(tmp_path / name.replace("result_", "dask_")) as b:
                xr.testing.assert_identical(a.drop_attrs(deep=False), b.drop_attrs(deep=False))
