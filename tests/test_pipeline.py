"""End-to-end tests of pipeline files: validation, results, resume after SIGKILL, Dask.

Records are short synthetic MiniSEED files (6 s at 100 Hz, see ``test_batch.make_catalogue``)
so that the whole module runs in seconds once the solver is compiled.
"""

from __future__ import annotations

import contextlib
import os
import signal
import subprocess
import sys
import textwrap
import time
from pathlib import Path

import numpy as np
import pytest
import xarray as xr

import shipblock
from shipblock import simulate
from shipblock.catalogue import load_catalogue
from shipblock.fragility.pipeline import PipelineError, load_pipeline, run_pipeline
from shipblock.units import STANDARD_GRAVITY as G

from .test_batch import make_catalogue

PIPELINE = """
schema_version = 1
title = "test"
output = "out/result.nc"

[records]
catalogue = "records/catalogue.toml"
ids = {ids}
horizontal = "H1"

[[processing]]
step = "demean"
[[processing]]
step = "taper"
max_percentage = 0.05

[system]
ship_mass = 5.0e6
block_mass = 1200.0
n_blocks = 150
half_width = 0.3
half_height = 0.6
mu_s_ground = 0.6
mu_k_ground = 0.55
mu_s_ship = 0.35
mu_k_ship = 0.30
{sweep}
[design]
type = "{kind}"
{levels}

[[limit_states]]
name = "ship_slip"
edp = "peak_ship_slip"
threshold = 0.005

[[limit_states]]
name = "any_failure"
edp = "failure"
condition = "nonzero"

[fit]
bootstrap = 20
seed = 3

[execution]
chunk_size = {chunk_size}
"""


def write_pipeline(tmp_path, *, ids='"all"', kind="ida", sweep="", chunk_size=4,
                   levels='levels_g = [0.2, 0.4, 0.5, 0.6, 0.8]', n_records=3, bad=False,
                   name="p.toml") -> Path:
    if not (tmp_path / "records" / "catalogue.toml").exists():
        make_catalogue(tmp_path / "records", n_records=n_records, bad=bad)
    text = PIPELINE.format(ids=ids, kind=kind, sweep=sweep, chunk_size=chunk_size,
                           levels=levels)
    path = tmp_path / name
    path.write_text(text)
    return path


def assert_same_results(a: xr.Dataset, b: xr.Dataset):
    """Equal data and coordinates (NaN == NaN) and equal attributes except the time stamp."""
    xr.testing.assert_identical(a.drop_attrs(deep=False), b.drop_attrs(deep=False))
    strip = {k: v for k, v in a.attrs.items() if k != "created"}
    assert strip == {k: v for k, v in b.attrs.items() if k != "created"}


@pytest.fixture(scope="module")
def ida_run(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("ida")
    path = write_pipeline(tmp)
    ds = run_pipeline(path, progress=False)
    return tmp, path, ds


# -------------------------------------------------------------------------------------------
# results
# -------------------------------------------------------------------------------------------


def test_ida_dataset_layout_and_fits(ida_run):
    tmp, path, ds = ida_run
    assert (tmp / "out" / "result.nc").is_file()
    assert not (tmp / "out" / "result.nc.partial").exists()  # removed after the final write
    assert ds.sizes == {"record": 3, "im_level": 5, "limit_state": 2}
    assert list(ds["record"].values) == ["syn/S0", "syn/S1", "syn/S2"]
    np.testing.assert_allclose(ds["im_level"], np.array([0.2, 0.4, 0.5, 0.6, 0.8]) * G)
    assert ds["peak_ship_slip"].dims == ("record", "im_level")
    assert ds["exceeded"].dims == ("limit_state", "record", "im_level")
    # achieved IM equals the target level for every record
    np.testing.assert_allclose(ds["achieved_im"], np.broadcast_to(ds["im_level"], (3, 5)),
                               rtol=1e-9)
    # fitted median per limit state, in m/s^2, inside the analysed range
    median = ds["median"].sel(limit_state="ship_slip")
    assert ds["median"].attrs["units"] == "m/s^2"
    assert 0.2 * G < float(median) < 0.8 * G
    assert float(ds["beta"].sel(limit_state="ship_slip")) > 0
    # exceedance is consistent with the EDP and threshold
    expect = (ds["peak_ship_slip"] > 0.005) | (ds["failure"] != 0)
    assert (ds["exceeded"].sel(limit_state="ship_slip") == expect).all()
    # provenance
    assert ds.attrs["pipeline"] == path.read_text()
    assert ds.attrs["shipblock_version"] == shipblock.__version__
    assert '"step": "taper"' in ds.attrs["processing_chain"]
    assert "syn/S1" in ds.attrs["records_provenance"]
    assert '"ship_mass": 5000000.0' in ds.attrs["system"]


def test_runs_equal_single_simulate(ida_run):
    tmp, path, ds = ida_run
    pipe = load_pipeline(path)
    entry = load_catalogue(pipe.catalogue)["syn/S1"]
    from shipblock.processing import process_motion

    gm = process_motion(entry.read(horizontal="H1"), pipe.chain)
    for j in (1, 3):
        f = float(ds["scale_factor"].isel(record=1, im_level=j))
        fv = float(ds["vertical_scale_factor"].isel(record=1, im_level=j))
        assert fv == f
        res = simulate(pipe.design.system, f * gm.horizontal, fv * gm.vertical, gm.dt)
        for name in ("peak_ship_slip", "peak_block_slip", "residual_ship_slip", "n_events",
                     "input_work", "time_in_mode_1"):
            assert float(ds[name].isel(record=1, im_level=j)) == float(res.summary[name])


def test_netcdf_round_trip_units_and_compression(ida_run):
    tmp, path, ds = ida_run
    with xr.open_dataset(tmp / "out" / "result.nc") as plain:
        plain = plain.load()
        for name, var in plain.variables.items():
            assert "units" in var.attrs and "long_name" in var.attrs, name
            if var.dtype.kind == "f" and var.ndim:
                assert var.encoding.get("zlib"), name
        xr.testing.assert_identical(plain, ds)
        assert plain["exceeded"].dtype == bool
    assert plain["median"].sel(limit_state="ship_slip").size == 1


def test_output_override_and_rerun_gives_same_result(ida_run, tmp_path):
    tmp, path, ds = ida_run
    timings = {}
    again = run_pipeline(path, output=tmp_path / "other.nc", progress=False, timings=timings)
    assert (tmp_path / "other.nc").is_file()
    assert_same_results(ds, again)
    assert list(timings) == ["records", "solver", "runs", "fragility", "write"]
    assert all(t >= 0 for t in timings.values()) and timings["solver"] <= timings["runs"]


def test_sweep_msa_and_error_record(tmp_path):
    path = write_pipeline(
        tmp_path, kind="msa", bad=True, chunk_size=7,
        sweep='[sweep]\nmu_ship = [0.3, 0.45]\nslenderness = [0.4, 0.6]\n',
    )
    ds = run_pipeline(path, progress=False)
    assert ds["peak_ship_slip"].dims == ("record", "im_level", "mu_ship", "slenderness")
    assert ds["median"].dims == ("limit_state", "mu_ship", "slenderness")
    assert ds["mu_ship"].attrs["units"] == "1"
    assert "unknown format" in ds["record_error"].sel(record="syn/BAD").item()
    assert ds["peak_ship_slip"].sel(record="syn/BAD").isnull().all()
    assert not ds["valid"].sel(record="syn/BAD").any()
    assert ds["peak_ship_slip"].sel(record="syn/S0").notnull().all()
    # lower ship friction slips at least as much
    slip = ds["peak_ship_slip"].sel(record="syn/S0", slenderness=0.4)
    assert (slip.sel(mu_ship=0.3) >= slip.sel(mu_ship=0.45)).all()
    assert set(ds["fit_method"].sel(limit_state="ship_slip").values.ravel()) <= {"mle", ""}


def test_msa_with_a_record_set_per_stripe(tmp_path):
    # levels where the synthetic records' ship slip crosses the 5 mm threshold
    levels = "levels_g = [0.3, 0.4, 0.45, 0.475, 0.5, 0.6]"
    stripes = ('stripes = [["S0", "S1"], ["syn/S1", "S2"], ["S0", "S1"], ["S0", "S2"], ["S1"], '
               '["S2"]]')
    path = write_pipeline(tmp_path, kind="msa", levels=levels + "\n" + stripes)
    ds = run_pipeline(path, progress=False)
    full = run_pipeline(write_pipeline(tmp_path, kind="msa", levels=levels, name="full.toml"),
                        output=tmp_path / "full.nc", progress=False)
    mask = np.array([[1, 0, 1, 1, 0, 0], [1, 1, 1, 0, 1, 0], [0, 1, 0, 1, 0, 1]], dtype=bool)
    np.testing.assert_array_equal(ds["in_stripe"], mask)
    assert ds["in_stripe"].dims == ("record", "im_level")
    # runs in a stripe are the full design's runs bit for bit; the others are not made
    for name in ("peak_ship_slip", "residual_ship_slip", "n_events"):
        np.testing.assert_array_equal(ds[name].values[mask], full[name].values[mask])
        assert np.isnan(ds[name].values[~mask]).all()
    valid = ds["valid"].sel(limit_state="ship_slip").values
    np.testing.assert_array_equal(valid, mask)
    # the fit counts only the runs of each stripe
    from shipblock.fragility.fit import fit_msa

    exceeded = ds["exceeded"].sel(limit_state="ship_slip").values
    fit = fit_msa(exceeded, ds["im_level"].values, valid)
    assert float(ds["median"].sel(limit_state="ship_slip")) == pytest.approx(fit.median,
                                                                            rel=1e-12)
    # which is not the fit of the full grid
    assert float(ds["median"].sel(limit_state="ship_slip")) != float(
        full["median"].sel(limit_state="ship_slip"))


@pytest.mark.parametrize(
    ("stripes", "kind", "key", "needle"),
    [
        ('[["S0"], ["S1"]]', "msa", "design.stripes", "one record list per level"),
        ('[["S0"], ["S1"], ["nope"]]', "msa", "design.stripes[2]", "not one of the records"),
        ('[["S0"], ["S1"], ["S1"]]', "msa", "design.stripes", "in no stripe: syn/S2"),
        ('[["S0"], [], ["S1", "S2"]]', "msa", "design.stripes", "stripe 1 has no records"),
        ('[["S0", "S1", "S2"]] ', "ida", "design.stripes", "only to type 'msa'"),
        ('["S0", "S1", "S2"]', "msa", "design.stripes[0]", "list of record ids"),
    ],
)
def test_invalid_stripes_name_the_key(tmp_path, stripes, kind, key, needle):
    levels = "levels_g = [0.2, 0.5, 0.8]" if kind == "msa" else "levels_g = [0.2]"
    path = write_pipeline(tmp_path, kind=kind, levels=f"{levels}\nstripes = {stripes}")
    with pytest.raises(PipelineError, match=needle) as info:
        load_pipeline(path)
    assert info.value.key == key


@pytest.mark.parametrize(
    ("levels", "expected", "error"),
    [
        ('levels = [10.0, 20.0]\nunits = "cm/s"', [0.1, 0.2], None),
        ('levels = [0.1, 0.2]\nunits = "M/S"', [0.1, 0.2], None),
        ('levels = [4.0, 8.0]\nunits = "in/s"', [0.1016, 0.2032], None),
        ('levels = [10.0, 20.0]\nunits = "cm/s^2"', None, "unknown velocity unit"),
        ("levels_g = [0.1, 0.2]", None, "PGV levels are velocities"),
    ],
)
def test_pgv_levels_are_velocities_in_si(tmp_path, levels, expected, error):
    path = write_pipeline(tmp_path, levels='measure = "pgv"\n' + levels)
    if error:
        with pytest.raises(PipelineError, match=error):
            load_pipeline(path)
        return
    design = load_pipeline(path).design
    np.testing.assert_allclose(design.intensity.levels, expected, rtol=1e-15)
    assert design.intensity.units == "m/s"


def test_system_by_slenderness_and_mass_ratio(tmp_path):
    path = write_pipeline(tmp_path)
    text = path.read_text()
    path.write_text(text.replace("block_mass = 1200.0", "mass_ratio = 0.036")
                    .replace("half_width = 0.3", "slenderness = 0.5"))
    system = load_pipeline(path).design.system
    assert system.block_mass == pytest.approx(0.036 * 5.0e6 / 150, rel=1e-15)  # 1200 kg
    assert system.half_width == pytest.approx(0.5 * 0.6, rel=1e-15)
    for edit, key in [(("n_blocks = 150", "n_blocks = 150\nblock_mass = 1.0"), "system.mass_ratio"),
                      (("mass_ratio = 0.036\n", ""), "system.block_mass")]:
        path.write_text(text.replace("block_mass = 1200.0", "mass_ratio = 0.036")
                        .replace(*edit))
        with pytest.raises(PipelineError) as info:
            load_pipeline(path)
        assert info.value.key == key


def test_cloud_design(tmp_path):
    path = write_pipeline(tmp_path, kind="cloud", levels="", n_records=3)
    ds = run_pipeline(path, progress=False)
    assert "im_level" not in ds.dims
    assert ds["peak_ship_slip"].dims == ("record",)
    np.testing.assert_array_equal(ds["scale_factor"], 1.0)
    np.testing.assert_allclose(ds["achieved_im"], ds["record_im"])


# -------------------------------------------------------------------------------------------
# invalid pipelines
# -------------------------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("edit", "key"),
    [
        (lambda t: t.replace('title = "test"', 'title = "test"\ncolour = "red"'), "colour"),
        (lambda t: t.replace('type = "ida"', 'type = "ida"\nlevelz = [1]'), "design.levelz"),
        (lambda t: t.replace("levels_g = [0.2, 0.4, 0.5, 0.6, 0.8]", 'levels_g = "0.1"'),
         "design.levels_g"),
        (lambda t: t.replace("levels_g = [0.2, 0.4, 0.5, 0.6, 0.8]", "levels_g = [0.5, 0.1]"),
         "design.levels_g"),
        (lambda t: t.replace("levels_g = [0.2, 0.4, 0.5, 0.6, 0.8]", "levels = [1.0, 2.0]"),
         "design.units"),
        (lambda t: t.replace("n_blocks = 150", 'n_blocks = "many"'), "system.n_blocks"),
        (lambda t: t.replace("ship_mass = 5.0e6\n", ""), "system.ship_mass"),
        (lambda t: t.replace('ids = "all"', 'ids = ["syn/S0", "nope"]'), "records.ids"),
        (lambda t: t.replace('step = "demean"', 'step = "demeen"'), "processing[0].step"),
        (lambda t: t.replace("max_percentage = 0.05", "max_pct = 0.05"),
         "processing[1].max_pct"),
        (lambda t: t.replace('edp = "peak_ship_slip"', 'edp = "ship_slip"'), "limit_states"),
        (lambda t: t.replace("[fit]", "[sweep]\nfriction = [0.1]\n[fit]"), "sweep.friction"),
        (lambda t: t.replace("chunk_size = 4", "chunk_size = 0"), "execution.chunk_size"),
        (lambda t: t[: t.index("[design]")] + t[t.index("[[limit_states]]"):], "design"),
    ],
)
def test_invalid_pipelines_name_the_key(tmp_path, edit, key):
    path = write_pipeline(tmp_path)
    path.write_text(edit(path.read_text()))
    with pytest.raises(PipelineError) as info:
        load_pipeline(path)
    assert f"[{key}]" in str(info.value)
    assert info.value.key == key
    assert isinstance(info.value, ValueError) and isinstance(info.value, shipblock.ShipblockError)


def test_missing_section_and_bad_toml(tmp_path):
    path = write_pipeline(tmp_path)
    text = path.read_text()
    path.write_text(text.replace("[records]", "[recordz]"))
    with pytest.raises(PipelineError, match=r"\[recordz\] unknown key"):
        load_pipeline(path)
    path.write_text(text[: text.index("[records]")] + text[text.index("[[processing]]"):])
    with pytest.raises(PipelineError, match=r"\[records\] missing required section"):
        load_pipeline(path)
    path.write_text("this is = = not toml")
    with pytest.raises(PipelineError, match="not valid TOML"):
        load_pipeline(path)


LEVELS = "levels_g = [0.2, 0.4, 0.5, 0.6, 0.8]"


@pytest.mark.parametrize(
    ("edit", "key", "needle"),
    [
        (lambda t: t.replace(LEVELS, "levels_g = [1e6]"), "design.levels_g", "1e+06 g"),
        (lambda t: t.replace(LEVELS, "levels_g = [1e300]"), "design.levels_g", "0.001 .. 10 g"),
        (lambda t: t.replace(LEVELS, "levels_g = [1e-300]"), "design.levels_g", "0.001 .. 10 g"),
        (lambda t: t.replace(LEVELS, 'levels = [2.0, 1e300]\nunits = "m/s^2"'), "design.levels",
         "levels[1]"),
        (lambda t: t.replace(LEVELS, 'measure = "pgv"\nlevels = [50.0]\nunits = "m/s"'),
         "design.levels", "10 m/s"),
        (lambda t: t.replace(LEVELS, LEVELS + '\nvertical = "independent"\n'
                                              "vertical_levels_g = [1e6, 1, 1, 1, 1]"),
         "design.vertical_levels_g", "vertical_levels_g[0]"),
        (lambda t: t.replace('type = "ida"', 'type = "ida"\nmeasure = "sa"\nperiod = 1e300'),
         "design.period", "[0.0001, 100]"),
        (lambda t: t.replace("bootstrap = 20", "bootstrap = 1000000000000"), "fit.bootstrap",
         "[0, 10000]"),
        (lambda t: t.replace("bootstrap = 20", "bootstrap = 1e12"), "fit.bootstrap",
         "an integer"),
        (lambda t: t.replace('horizontal = "H1"', "azimuth = nan"), "records.azimuth", "nan"),
        (lambda t: t.replace('horizontal = "H1"', "azimuth = inf"), "records.azimuth", "inf"),
        (lambda t: t.replace("seed = 3", "seed = -1"), "fit.seed", "got -1"),
        (lambda t: t.replace("seed = 3", "seed = 1180591620717411303424"), "fit.seed",
         "9223372036854775807"),
        (lambda t: t.replace('output = "out/result.nc"', 'output = ""'), "output", "got ''"),
        (lambda t: t.replace('output = "out/result.nc"', 'output = "out/"'), "output", "'out/'"),
        (lambda t: t.replace('output = "out/result.nc"', 'output = "records"'), "output",
         "is a folder"),
        (lambda t: t.replace("[execution]", "[solver]\nrtol = 1e-300\n[execution]"),
         "solver.rtol", "1e-300"),
        (lambda t: t.replace("[execution]", "[solver]\nzeno_omega = inf\n[execution]"),
         "solver.zeno_omega", "inf"),
        (lambda t: t.replace("chunk_size = 4", "chunk_size = 1000000000000000"),
         "execution.chunk_size", "[1, 1000000]"),
        (lambda t: t.replace("[execution]", '[execution]\nscheduler = ""'),
         "execution.scheduler", "empty"),
        (lambda t: t.replace('ids = "all"', 'ids = ["syn/S0", "syn/S1", "syn/S0"]'),
         "records.ids", "repeats syn/S0"),
        (lambda t: t.replace("ship_mass = 5.0e6", "ship_mass = inf"), "system.ship_mass", "inf"),
        (lambda t: t.replace("half_width = 0.3", "slenderness = 1e300"), "system.slenderness",
         "half_width"),
        (lambda t: t.replace("[fit]", "[sweep]\nn_blocks = [150, 1e300]\n[fit]"),
         "sweep.n_blocks", "n_blocks"),
        (lambda t: t.replace("[fit]", "[sweep]\nmu_ground = [nan]\n[fit]"), "sweep.mu_ground",
         "mu_s_ground"),
        (lambda t: t.replace("[fit]", "[sweep]\nmu_ground = [" + ", ".join(
            f"{0.2 + 1e-4 * i:.4f}" for i in range(1000)) + "]\nslenderness = [" + ", ".join(
            f"{0.2 + 1e-4 * i:.4f}" for i in range(1000)) + "]\n[fit]"), "sweep",
         "15,000,000 runs"),
        (lambda t: t + '\n[histories]\nexceeding = ["ship_slip"]\nmax_runs = 0\n',
         "histories.max_runs", "got 0"),
    ],
)
def test_pipeline_values_of_issue_23_are_checked_when_loaded(tmp_path, edit, key, needle):
    """Implausible values, ranges and sizes are refused when the file is loaded (before any
    record is read or run is made), naming the key and what it expects."""
    path = write_pipeline(tmp_path)
    path.write_text(edit(path.read_text()))
    with pytest.raises(PipelineError) as info:
        load_pipeline(path)
    assert info.value.key == key, str(info.value)
    assert f"[{key}]" in str(info.value) and str(path) in str(info.value)
    assert needle in str(info.value), str(info.value)


def test_binary_pipeline_file_names_the_file(tmp_path):
    path = tmp_path / "p.toml"
    path.write_bytes(bytes(range(256)) * 4)
    with pytest.raises(PipelineError, match="not UTF-8 text") as info:
        load_pipeline(path)
    assert str(path) in str(info.value)
    path.write_bytes(b'schema_version = 1\x00\x01\x02 output = "x.nc"')
    with pytest.raises(PipelineError, match="binary data") as info:
        load_pipeline(path)
    assert str(path) in str(info.value)


def test_unknown_key_lists_the_known_keys(tmp_path):
    path = write_pipeline(tmp_path)
    path.write_text(path.read_text().replace("seed = 3", "seed = 3\nsede = 4"))
    with pytest.raises(PipelineError, match="allowed keys: bootstrap, confidence, seed, "
                                            "ida_method") as info:
        load_pipeline(path)
    assert info.value.key == "fit.sede"


def test_run_pipeline_arguments_are_named(tmp_path):
    from shipblock.errors import ParameterTypeError

    path = write_pipeline(tmp_path)
    for kwargs, name in (({"path": None}, "path"), ({"path": 3}, "path"),
                         ({"path": path, "output": 3}, "output"),
                         ({"path": path, "timings": []}, "timings"),
                         ({"path": path, "scheduler": 8786}, "scheduler")):
        with pytest.raises(ParameterTypeError, match=f"^{name} must be"):
            run_pipeline(progress=False, **kwargs)
    assert _no_partial(tmp_path) == []


def _no_partial(folder: Path) -> list:
    return sorted(p.name for p in folder.rglob("*.partial"))


def test_study_with_every_record_left_out_fails_before_the_batch(tmp_path):
    path = write_pipeline(tmp_path, ids='["syn/BAD"]', bad=True)
    with pytest.raises(PipelineError, match="every record was left out") as info:
        run_pipeline(path, progress=False)
    assert info.value.key == "records.ids" and "syn/BAD" in str(info.value)
    assert not (tmp_path / "out" / "result.nc").exists()
    assert _no_partial(tmp_path) == []


def test_bad_output_fails_before_the_batch(tmp_path, monkeypatch):
    from shipblock.fragility import batch

    monkeypatch.setattr(batch, "run_chunk", lambda *a, **k: pytest.fail("the batch ran"))
    path = write_pipeline(tmp_path)
    with pytest.raises(PipelineError, match="must name a NetCDF file") as info:
        run_pipeline(path, output="", progress=False)
    assert info.value.key == "output"
    (tmp_path / "a_file").write_text("")
    with pytest.raises(PipelineError, match="cannot create the folder"):
        run_pipeline(path, output=tmp_path / "a_file" / "result.nc", progress=False)
    assert _no_partial(tmp_path) == []


def test_dask_scheduler_without_dask_says_which_extra_to_install(tmp_path, monkeypatch):
    from shipblock.fragility import batch

    monkeypatch.setitem(sys.modules, "distributed", None)  # import distributed fails
    monkeypatch.setattr(batch, "run_chunk", lambda *a, **k: pytest.fail("the batch ran"))
    path = write_pipeline(tmp_path)
    path.write_text(path.read_text().replace("[execution]",
                                             '[execution]\nscheduler = "tcp://127.0.0.1:1"'))
    with pytest.raises(PipelineError) as info:
        run_pipeline(path, progress=False)
    assert info.value.key == "execution.scheduler"
    assert 'pip install "shipblock[dask]"' in str(info.value)
    assert "tcp://127.0.0.1:1" in str(info.value)
    with pytest.raises(PipelineError, match=r"shipblock\[dask\]"):  # the argument too
        run_pipeline(write_pipeline(tmp_path, name="q.toml"), scheduler="tcp://h:1",
                     progress=False)
    assert _no_partial(tmp_path) == []


def test_shipped_pipelines_are_valid():
    root = Path(__file__).resolve().parent.parent / "pipelines"
    for name in ("demo", "napa_ida", "sensitivity"):
        pipe = load_pipeline(root / f"{name}.toml")
        assert len(pipe.design.records) == 6
        assert len(pipe.limit_states) >= 3
    sens = load_pipeline(root / "sensitivity.toml")
    assert sens.design.dims == ("record", "im_level", "mu_ground", "slenderness")
    assert "any_failure" in [ls.name for ls in load_pipeline(root / "napa_ida.toml").limit_states]
    demo = load_pipeline(root / "demo.toml")
    assert len(demo.design.intensity.levels) == 8


# -------------------------------------------------------------------------------------------
# crash safety: SIGKILL mid-run, resume, same result
# -------------------------------------------------------------------------------------------

_SLOW_RUN = textwrap.dedent(
    """
    import sys, time
    from shipblock.fragility import batch
    real = batch.run_chunk
    def slow(*args, **kwargs):
        time.sleep(0.4)   # make chunks slow enough to be killed mid-run
        return real(*args, **kwargs)
    batch.run_chunk = slow
    from shipblock.fragility.pipeline import run_pipeline
    run_pipeline(sys.argv[1], output=sys.argv[2], progress=False)
    """
)


def test_resume_after_sigkill_gives_same_result(tmp_path, monkeypatch):
    path = write_pipeline(tmp_path, chunk_size=1)  # 15 chunks of one run
    reference = run_pipeline(path, output=tmp_path / "reference.nc", progress=False)

    out = tmp_path / "killed.nc"
    partial = tmp_path / "killed.nc.partial"
    proc = subprocess.Popen([sys.executable, "-c", _SLOW_RUN, str(path), str(out)])
    try:
        deadline = time.monotonic() + 120
        while time.monotonic() < deadline:
            if partial.is_dir() and len(list(partial.glob("chunk-*.npz"))) >= 2:
                break
            if proc.poll() is not None:
                pytest.fail("the run ended before it could be killed")
            time.sleep(0.02)
        os.kill(proc.pid, signal.SIGKILL)
        proc.wait(timeout=30)
    finally:
        if proc.poll() is None:
            proc.kill()
    assert proc.returncode == -signal.SIGKILL
    assert not out.exists()
    done = len(list(partial.glob("chunk-*.npz")))
    assert 2 <= done < 15

    from shipblock.fragility import batch

    calls = []
    real = batch.run_chunk
    monkeypatch.setattr(batch, "run_chunk", lambda *a, **k: (calls.append(1), real(*a, **k))[1])
    resumed = run_pipeline(path, output=out, progress=False)
    assert len(calls) == 15 - done  # finished chunks were not recomputed
    assert_same_results(reference, resumed)
    assert not partial.exists()


_SLOW_FITS = textwrap.dedent(
    """
    import sys, time
    from shipblock.fragility import pipeline
    pipeline.FIT_CHECKPOINT_INTERVAL = 0.0   # every fit written as soon as it is done
    real = pipeline._fit_one
    def slow(*args, **kwargs):
        time.sleep(0.4)   # make fits slow enough to be killed among them
        return real(*args, **kwargs)
    pipeline._fit_one = slow
    pipeline.run_pipeline(sys.argv[1], output=sys.argv[2], progress=False)
    """
)


def _run_until(proc, condition, what):
    """Wait until ``condition()`` holds, then SIGKILL ``proc``."""
    try:
        deadline = time.monotonic() + 180
        while time.monotonic() < deadline:
            if condition():
                break
            if proc.poll() is not None:
                pytest.fail(f"the run ended before {what}")
            time.sleep(0.02)
        os.kill(proc.pid, signal.SIGKILL)
        proc.wait(timeout=30)
    finally:
        if proc.poll() is None:
            proc.kill()
    assert proc.returncode == -signal.SIGKILL


def test_resume_after_sigkill_during_the_fits_gives_same_result(tmp_path, monkeypatch):
    """Fitted results are kept per (limit state, sweep point) like the chunks: a run killed
    after the batch resumes without running the batch or the finished fits again, and gives
    the uninterrupted run's dataset exactly."""
    path = write_pipeline(tmp_path, sweep="[sweep]\nmu_ground = [0.3, 0.4, 0.5, 0.6]\n",
                          chunk_size=64)  # 60 runs in one chunk; 2 limit states x 4 = 8 fits
    reference = run_pipeline(path, output=tmp_path / "reference.nc", progress=False)

    out = tmp_path / "killed.nc"
    partial = tmp_path / "killed.nc.partial"
    proc = subprocess.Popen([sys.executable, "-c", _SLOW_FITS, str(path), str(out)])
    _run_until(proc, lambda: partial.is_dir() and len(list(partial.glob("fit-*.npz"))) >= 3,
               "it could be killed among the fits")
    assert not out.exists()
    assert len(list(partial.glob("chunk-*.npz"))) == 1  # the batch was done
    done = len(list(partial.glob("fit-*.npz")))  # one fit a file
    assert 3 <= done < 8

    from shipblock.fragility import batch
    from shipblock.fragility import pipeline as pipeline_mod

    monkeypatch.setattr(batch, "run_chunk", lambda *a, **k: pytest.fail("the batch ran again"))
    calls = []
    real = pipeline_mod._fit_one
    monkeypatch.setattr(pipeline_mod, "_fit_one",
                        lambda *a, **k: (calls.append(1), real(*a, **k))[1])
    resumed = run_pipeline(path, output=out, progress=False)
    assert len(calls) == 8 - done  # finished fits were not made again
    assert_same_results(reference, resumed)
    assert not partial.exists()


_KILL_IN_WRITE = textwrap.dedent(
    """
    import os, signal, sys
    import xarray as xr
    real = xr.Dataset.to_netcdf
    def killed(self, path, *args, **kwargs):
        real(self, path, *args, **kwargs)      # the temporary file is written ...
        os.kill(os.getpid(), signal.SIGKILL)   # ... and the run killed before the rename
    xr.Dataset.to_netcdf = killed
    from shipblock.fragility.pipeline import run_pipeline
    run_pipeline(sys.argv[1], output=sys.argv[2], progress=False)
    """
)


def test_next_run_removes_the_temporary_file_of_a_killed_final_write(tmp_path):
    path = write_pipeline(tmp_path)
    out = tmp_path / "res" / "result.nc"
    out.parent.mkdir()
    other = out.parent / ".other.nc.abcdefgh.tmp"  # another output's temporary file
    lookalike = out.parent / ".result.nc.mine.tmp"  # not a name our writer makes
    for p in (other, lookalike):
        p.write_text("keep")
    proc = subprocess.run([sys.executable, "-c", _KILL_IN_WRITE, str(path), str(out)])
    assert proc.returncode == -signal.SIGKILL
    assert not out.exists()
    stale = [p for p in out.parent.glob(".result.nc.*.tmp") if p != lookalike]
    assert len(stale) == 1 and stale[0].stat().st_size > 0

    ds = run_pipeline(path, output=out, progress=False)
    assert out.is_file() and ds.sizes["record"] == 3
    assert not stale[0].exists()
    assert other.read_text() == "keep" and lookalike.read_text() == "keep"
    assert sorted(p.name for p in out.parent.iterdir()) == sorted(
        [".other.nc.abcdefgh.tmp", ".result.nc.mine.tmp", "result.nc"])


def test_partial_of_another_run_is_refused(tmp_path):
    path = write_pipeline(tmp_path)
    partial = tmp_path / "x.nc.partial"
    partial.mkdir()
    (partial / "manifest.json").write_text('{"fingerprint": "something else"}')
    with pytest.raises(PipelineError, match="different run"):
        run_pipeline(path, output=tmp_path / "x.nc", progress=False)


# -------------------------------------------------------------------------------------------
# Dask
# -------------------------------------------------------------------------------------------


@contextlib.contextmanager
def local_dask_client(n_workers=2, processes=True):
    """A Dask client on a LocalCluster of single-threaded workers (skips without distributed)."""
    distributed = pytest.importorskip("distributed")
    with distributed.LocalCluster(n_workers=n_workers, threads_per_worker=1,
                                  processes=processes, dashboard_address=None) as cluster, \
            distributed.Client(cluster) as client:
        yield client


def test_dask_equals_local(ida_run, tmp_path):
    tmp, path, local = ida_run
    with local_dask_client() as client:
        remote = run_pipeline(path, output=tmp_path / "dask.nc", client=client, progress=False)
    assert_same_results(local, remote)
