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
from shipblock.records.catalogue import load_catalogue
from shipblock.fragility.fit import fit_ida
from shipblock.fragility.pipeline import (
    PipelineError,
    fragility_variables,
    load_pipeline,
    run_pipeline,
)
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


IDA_LEVELS_G = (0.2, 0.3, 0.4, 0.45, 0.5)


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
    # levels fine enough around the three records' capacities for the interval-censored fit
    # to identify beta (their intervals do not all share a point)
    path = write_pipeline(tmp, levels=f"levels_g = {list(IDA_LEVELS_G)}")
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
    np.testing.assert_allclose(ds["im_level"], np.array(IDA_LEVELS_G) * G)
    assert ds["peak_ship_slip"].dims == ("record", "im_level")
    assert ds["exceeded"].dims == ("limit_state", "record", "im_level")
    # achieved IM equals the target level for every record
    np.testing.assert_allclose(ds["achieved_im"], np.broadcast_to(ds["im_level"], (3, 5)),
                               rtol=1e-9)
    # fitted median per limit state, in m/s^2, inside the analysed range
    median = ds["median"].sel(limit_state="ship_slip")
    assert ds["median"].attrs["units"] == "m/s^2"
    assert 0.2 * G < float(median) < 0.5 * G
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
    # IDA fitted on the capacity intervals (last level held, first failed] by default
    assert str(ds["fit_method"].sel(limit_state="ship_slip").values) == "ida_interval"
    lower = ds["ida_capacity_lower"].sel(limit_state="ship_slip")
    upper = ds["ida_capacity"].sel(limit_state="ship_slip")
    assert bool((lower < upper).all())
    for rec in ds["record"].values:
        ex = ds["exceeded"].sel(limit_state="ship_slip", record=rec).values
        levels = ds["im_level"].values
        first = levels[np.argmax(ex)] if ex.any() else np.inf
        held = levels[:np.argmax(ex)] if ex.any() else levels
        assert float(upper.sel(record=rec)) == first
        assert float(lower.sel(record=rec)) == (held[-1] if held.size else 0.0)


def test_first_exceedance_option_reproduces_the_old_estimate_and_old_names_are_refused(
        ida_run):
    tmp, path, ds = ida_run
    text = path.read_text()
    path = tmp / "first_exceedance.toml"
    path.write_text(text.replace("[fit]", '[fit]\nida_method = "mle"'))
    with pytest.raises(PipelineError, match="now named 'first_exceedance'") as info:
        load_pipeline(path)
    assert info.value.key == "fit.ida_method"
    path.write_text(text.replace("[fit]", '[fit]\nida_method = "first_exceedance"'))
    pipe = load_pipeline(path)
    assert pipe.fit["ida_method"] == "first_exceedance"
    # the option fits the first exceeding levels as capacities, right-censored at the top
    out = fragility_variables(ds, pipe.design, pipe.limit_states, {**pipe.fit, "bootstrap": 0})
    upper = ds["ida_capacity"].sel(limit_state="ship_slip").values
    old = fit_ida(upper, censored_at=ds["im_level"].values[-1])
    assert float(out["median"].values[0]) == old.median  # limit state 0 is ship_slip
    assert str(out["fit_method"].values[0]) == "ida_first_exceedance"
    assert old.median > float(ds["median"].sel(limit_state="ship_slip"))


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
    # the study says how many records it used, and why one was left out
    assert ds.attrs["n_records_used"] == 3
    assert ds.attrs["records_used"].startswith("3 of 4 records used, 1 left out: syn/BAD "
                                               "(RecordError: ")
    np.testing.assert_array_equal(ds["record_used"], [True, True, True, False])


def test_strict_study_fails_instead_of_leaving_a_record_out(tmp_path):
    path = write_pipeline(tmp_path, bad=True)
    path.write_text(path.read_text().replace('horizontal = "H1"',
                                             'horizontal = "H1"\nstrict = true'))
    with pytest.raises(PipelineError, match=r"syn/BAD \(RecordError: ") as info:
        run_pipeline(path, progress=False)
    assert info.value.key == "records.strict"
    out = tmp_path / "out"  # failed before any run: no result, no partial results
    assert not out.exists() or not any(out.iterdir())


def test_runs_above_the_scale_factor_limit_are_reported_or_refused(ida_run, tmp_path, caplog):
    """max_scale_factor = 2.5 on the synthetic records (factors 1.3 to 3.7 over the levels):
    'warn' runs them and says so; 'refuse' does not make them (NaN, run_error says why), the
    other runs equal the warned study's bit for bit and the fit counts only them."""
    tmp, path, full = ida_run
    text = path.read_text()
    factors = np.abs(full["scale_factor"].values)
    expect = factors > 2.5
    assert expect.any() and not expect.all()
    out = {}
    for policy in ("warn", "refuse"):
        p = tmp / f"{policy}.toml"
        p.write_text(text.replace('type = "ida"', f'type = "ida"\nmax_scale_factor = 2.5\n'
                                                  f'scale_factor_policy = "{policy}"'))
        caplog.clear()
        out[policy] = run_pipeline(p, output=tmp_path / f"{policy}.nc", progress=False)
        assert f"{int(expect.sum())} of 15 runs have a scale factor above max_scale_factor = " \
               "2.5" in caplog.text
        np.testing.assert_array_equal(out[policy]["scale_factor_above_limit"], expect)
        assert out[policy].attrs["max_scale_factor"] == 2.5
        assert out[policy].attrs["scale_factor_policy"] == policy
    warn, refuse = out["warn"], out["refuse"]
    np.testing.assert_array_equal(warn["peak_ship_slip"], full["peak_ship_slip"])
    made = refuse["peak_ship_slip"].values
    np.testing.assert_array_equal(made[~expect], full["peak_ship_slip"].values[~expect])
    assert np.isnan(made[expect]).all()
    errors = refuse["run_error"].values
    assert all(e.startswith("not run: scale factor ") and e.endswith(
        "above max_scale_factor 2.5") for e in errors[expect])
    assert not any(errors[~expect])
    assert not refuse["valid"].values[:, expect].any()
    assert refuse.attrs["records_used"] == "3 of 3 records used"


def test_fits_and_levels_are_also_kept_in_the_pipelines_units(ida_run):
    """levels_g: the levels and medians are stored in g beside SI, and fit messages quote
    the levels in g (no SI number beside a g level)."""
    _, _, ds = ida_run
    np.testing.assert_allclose(ds["im_level_g"], IDA_LEVELS_G, rtol=1e-15)
    assert ds.attrs["im_display_units"] == "g"
    for name in ("median", "median_lower", "median_upper"):
        assert ds[f"{name}_g"].attrs["units"] == "g"
        np.testing.assert_allclose(ds[f"{name}_g"], ds[name] / G, rtol=1e-15)
    error = str(ds["fit_error"].sel(limit_state="any_failure").values)
    assert error.endswith("highest level (0.5); analyse higher IM levels [IM in g]")


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


def test_resume_after_sigkill_gives_same_result(tmp_path, monkeypatch):
    path = write_pipeline(tmp_path, chunk_size=1)  # 15 chunks of one run
    reference = run_pipeline(path, output=tmp_path / "reference.nc", progress=False)

    out = tmp_path / "killed.nc"
    partial = tmp_path / "killed.nc.partial"
    proc = subprocess.Popen([sys.executable, "-c", _SLOW_RUN, str(path), str(out)])
    _run_until(proc, lambda: partial.is_dir() and len(list(partial.glob("chunk-*.npz"))) >= 2,
               "it could be killed")
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
    from shipblock.fragility import fit_step, pipeline
    from shipblock.fragility.fit import checkpoint
    checkpoint.FIT_CHECKPOINT_INTERVAL = 0.0   # every fit written as soon as it is done
    real = fit_step._fit_one
    def slow(*args, **kwargs):
        time.sleep(0.4)   # make fits slow enough to be killed among them
        return real(*args, **kwargs)
    fit_step._fit_one = slow
    pipeline.run_pipeline(sys.argv[1], output=sys.argv[2], progress=False)
    """
)


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
    from shipblock.fragility import fit_step as fit_step_mod

    monkeypatch.setattr(batch, "run_chunk", lambda *a, **k: pytest.fail("the batch ran again"))
    calls = []
    real = fit_step_mod._fit_one
    monkeypatch.setattr(fit_step_mod, "_fit_one",
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


# -------------------------------------------------------------------------------------------
# scaling to a target spectrum
# -------------------------------------------------------------------------------------------


@pytest.mark.parametrize("match", ["range", "anchor"])
def test_msa_scaled_to_a_target_spectrum(tmp_path, match):
    """Levels are Sa(1 s); the target file (in g) is anchored to each level at T1 = 1 s.

    'range': each record's scaled spectrum is the least-squares fit, in ln Sa over 0.2-2 s, of
    the anchored target (its log residuals average zero); 'anchor': Sa(T1) equals the level.
    The misfit stored is the RMS of those residuals, smaller for 'range'; a run made again
    alone gets the batch's factors (the same summary)."""
    from shipblock.fragility.pipeline import rerun_case
    from shipblock.scaling import read_target_spectrum

    (tmp_path / "target.csv").write_text(
        "period_s, sa_g\n0.05, 0.5\n0.2, 1.0\n0.6, 1.0\n2.0, 0.3\n4.0, 0.15\n")
    levels = ('measure = "sa"\nperiod = 1.0\nlevels_g = [0.3, 0.6]\n'
              '[design.target_spectrum]\nfile = "target.csv"\nunits = "g"\n'
              f'period_range = [0.2, 2.0]\nmatch = "{match}"\n')
    path = write_pipeline(tmp_path, kind="msa", levels=levels)
    ds = run_pipeline(path, progress=False)
    target = read_target_spectrum(tmp_path / "target.csv", "g")
    periods = ds["spectrum_period"].values
    np.testing.assert_allclose(periods, np.geomspace(0.2, 2.0, 40))
    np.testing.assert_allclose(ds["target_sa"], target.at(periods), rtol=1e-15)
    levels_si = ds["im_level"].values
    for r in range(3):
        for j, level in enumerate(levels_si):
            f = float(ds["scale_factor"].isel(record=r, im_level=j))
            anchored = target.at(periods) * level / target.at(1.0)[0]
            resid = np.log(f * ds["record_sa"].isel(record=r).values / anchored)
            if match == "range":
                assert abs(resid.mean()) < 1e-12
            else:
                assert float(ds["achieved_im"].isel(record=r, im_level=j)) == pytest.approx(
                    level, rel=1e-12)
            assert float(ds["spectrum_misfit"].isel(record=r)) == pytest.approx(
                np.sqrt(np.mean(resid**2)), rel=1e-10)
    assert ds.attrs["target_spectrum_match"] == match
    res = rerun_case(path, "S1", im_level_g=0.6)
    assert res.summary["peak_ship_slip"] == float(
        ds["peak_ship_slip"].sel(record="syn/S1").isel(im_level=1))


def test_target_spectrum_keys_are_checked(tmp_path):
    (tmp_path / "target.csv").write_text("0.5 1.0\n1.0 0.8\n")
    base = 'measure = "sa"\nperiod = 1.0\nlevels_g = [0.3]\n[design.target_spectrum]\n'
    cases = [
        ('file = "target.csv"\nunits = "g"\nperiod_range = [0.2, 2.0]\n',
         "design.target_spectrum.file", "covers 0.5 to 1 s"),
        ('file = "target.csv"\nperiod_range = [0.6, 0.9]\n', "design.target_spectrum.units",
         "missing"),
        ('file = "target.csv"\nunits = "g"\nperiod_range = [0.9, 0.6]\n',
         "design.target_spectrum.period_range", "0 < T_a < T_b"),
        ('file = "target.csv"\nunits = "g"\nperiod_range = [0.6, 0.9]\nmatch = "best"\n',
         "design.target_spectrum.match", "'range'"),
    ]
    for i, (table, key, needle) in enumerate(cases):
        path = write_pipeline(tmp_path, kind="msa", levels=base + table, name=f"p{i}.toml")
        with pytest.raises(PipelineError, match=needle) as info:
            load_pipeline(path)
        assert info.value.key == key
    path = write_pipeline(tmp_path, kind="msa", name="pga.toml", levels=(
        'levels_g = [0.3]\n[design.target_spectrum]\nfile = "target.csv"\nunits = "g"\n'
        'period_range = [0.6, 0.9]\n'))
    with pytest.raises(PipelineError, match="measure = 'sa'") as info:
        load_pipeline(path)
    assert info.value.key == "design.target_spectrum"
