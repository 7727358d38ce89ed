"""Figures for a report (issue 31): the response figure names the record, system, outcome and the
window shown; simulate scales to a target PGA; plot --edp lists the valid names."""

from __future__ import annotations

import matplotlib
import numpy as np
import pytest
import xarray as xr

from shipblock import ShipBlockSystem, simulate
from shipblock.cli import main
from shipblock.records.motion import GroundMotion
from shipblock.plot import plot_response, record_text, system_text
from shipblock.units import STANDARD_GRAVITY as G

matplotlib.use("Agg")


def run(capsys, *argv):
    code = main(["-q", *argv])
    out = capsys.readouterr()
    return code, out.out, out.err


def test_system_text_names_masses_in_tonnes_block_size_and_friction():
    system = ShipBlockSystem.example()
    text = system_text(system)
    assert text == (f"ship {system.ship_mass / 1e3:.4g} t on {system.n_blocks} blocks of "
                    f"{system.block_mass / 1e3:.3g} t, 2B x 2H = {2 * system.half_width:.3g} x "
                    f"{2 * system.half_height:.3g} m; friction blocks-floor "
                    f"{system.mu_s_ground:.3g}/{system.mu_k_ground:.3g}, ship-blocks "
                    f"{system.mu_s_ship:.3g}/{system.mu_k_ship:.3g} (static/kinetic)")
    assert system_text(system.to_dict()) == text


def test_response_figure_names_record_system_outcome_and_the_window_shown():
    dt = 0.01
    t = np.arange(0.0, 40.0, dt)
    # 2 s of shaking in the middle of 40 s of quiet: the automatic window crops
    acc = np.where((t > 18) & (t < 20), 3.0, 0.0) * np.sin(2 * np.pi * 2.0 * t)
    motion = GroundMotion.from_arrays(acc, dt=dt, name="pulse")
    system = ShipBlockSystem.example()
    res = simulate(system, motion)
    line = record_text(motion, 1.5)
    assert line == "record pulse, scale factor 1.5"
    axes = plot_response(res, record=line)
    title = axes[0].figure.get_suptitle()
    assert line in title.replace("\n", " ")
    assert "system: " + system_text(system) in title.replace("\n", " ")
    assert "response: no failure; peaks |x_b|" in title
    lo, hi = axes[0].get_xlim()
    assert lo > 0 and hi < t[-1]
    assert (f"(shown: {lo:.1f} to {hi:.1f} s of the record's 0.0 to {t[-1]:.1f} s: 1-99 % of the "
            "Arias intensity and every event") in axes[3].get_xlabel()
    # the whole record shown: nothing to say about a window
    assert "shown" not in plot_response(res, window=None)[3].get_xlabel()


def test_simulate_scales_to_a_target_pga_and_the_figure_says_so(tmp_path, capsys):
    nc = tmp_path / "r.nc"
    code, out, err = run(capsys, "simulate", "--record", "NP.1765", "--target-pga", "0.3g",
                         "--output", str(nc))
    assert code == 0, err
    assert "PGA_H = 0.300 g" in out
    ds = xr.open_dataset(nc)
    assert float(np.abs(ds["ground_acceleration_h"]).max()) == pytest.approx(0.3 * G, rel=1e-9)
    description = ds.attrs["record_description"]
    assert description.startswith("record south-napa-2014/NP.1765")
    assert "event 2014-08-24 10:20:44 UTC" in description
    assert "scaled to PGA 0.3 g (factor " in description
    # the vertical follows the horizontal factor (V/H kept)
    factor = float(description.split("(factor ")[1].split(")")[0])
    assert factor > 0
    assert nc.with_suffix(".png").exists()


@pytest.mark.parametrize(("argv", "needle"), [
    (["--target-pga", "0.4"], "--target-pga 0.4: give its unit, e.g. 0.4g"),
    (["--target-pga", "0.4furlongs"], "unknown acceleration unit 'furlongs'"),
    (["--target-pga", "0.4g", "--scale", "2"], "give --scale or --target-pga, not both"),
])
def test_target_pga_errors_name_the_flag(argv, needle, capsys):
    code, _, err = run(capsys, "simulate", "--record", "NP.1765", *argv)
    assert code == 2 and needle in err


def test_plot_edp_typo_lists_the_valid_names(tmp_path, capsys):
    from .test_pipeline import write_pipeline

    from shipblock.fragility.pipeline import run_pipeline

    path = write_pipeline(tmp_path, levels="levels_g = [0.2, 0.4]", n_records=2)
    run_pipeline(path, progress=False)
    nc = tmp_path / "out" / "result.nc"
    code, _, err = run(capsys, "plot", str(nc), "--kind", "ida", "--edp", "peak_shp_slip",
                       "-o", str(tmp_path / "x.png"))
    assert code == 2
    assert "--edp 'peak_shp_slip' is not a demand parameter" in err
    assert "did you mean 'peak_ship_slip'?" in err
    assert "valid: peak_block_slip, peak_ship_slip, peak_rotation" in err
    code, _, err = run(capsys, "plot", str(nc), "--kind", "ida", "--edp", "residual_ship_slip",
                       "-o", str(tmp_path / "x.png"))
    assert code == 0, err


def test_acceleration_target_reads_a_number_with_its_unit():
    from shipblock.errors import ParameterError
    from shipblock.scaling import acceleration_target

    assert acceleration_target("0.4g") == pytest.approx(0.4 * G, rel=1e-15)
    assert acceleration_target(" 392 gal ") == pytest.approx(3.92, rel=1e-15)
    assert acceleration_target("3.9m/s^2") == 3.9
    assert acceleration_target("1e-1 g") == pytest.approx(0.1 * G, rel=1e-15)
    for text, needle in (("0.4", "target 0.4: give its unit"), ("g", "a number and its unit"),
                         ("-0.4g", "positive"), ("0.4 furlongs", "unknown acceleration unit")):
        with pytest.raises(ParameterError, match=needle):
            acceleration_target(text)


def test_a_batch_history_file_is_titled_with_its_record_level_and_run():
    import json

    from shipblock.plot import dataset_record_line

    provenance = {"catalogue": {"id": "napa/NP.1765", "site": "Napa"}, "horizontal": "H1",
                  "channels": {"H1": "NP.1765..HNN"}, "azimuths": {"H1": 0.0},
                  "event": {"time": "2014-08-24T10:20:44.07Z", "magnitude": 6.02,
                            "magnitude_type": "mw"}}
    ds = xr.Dataset(attrs={"record": "napa/NP.1765", "record_provenance": json.dumps(provenance),
                           "im_level": 0.8 * G, "im_units": "m/s^2", "im_measure": "pga",
                           "scale_factor": 1.95, "case": 37,
                           "pipeline_source": "pipelines/demo.toml"})
    assert dataset_record_line(ds) == (
        "record napa/NP.1765 (Napa): horizontal H1 = NP.1765..HNN (0 deg), event 2014-08-24 "
        "10:20:44 UTC Mw 6.02, scaled to PGA 0.8 g, scale factor 1.95; run 37 of "
        "pipelines/demo.toml")
    assert dataset_record_line(xr.Dataset()) == ""


def test_record_text_names_a_motion_from_arrays_by_its_label():
    """The figure title's record line uses GroundMotion.name, which is the label of a motion
    built from arrays (no workaround in the plot code), even when it looks like a path."""
    motion = GroundMotion.from_arrays(np.sin(np.linspace(0.0, 20.0, 400)), dt=0.01,
                                      name="runs/case 3")
    assert record_text(motion) == "record runs/case 3"
