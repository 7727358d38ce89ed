"""The command line as a user meets it: outputs written, numbers consistent, errors in one line."""

import numpy as np
import pytest
import xarray as xr

from shipblock.cli import main
from shipblock.units import STANDARD_GRAVITY


def run(capsys, *argv):
    code = main(["-q", *argv])
    out = capsys.readouterr()
    return code, out.out, out.err


def test_simulate_shipped_record_writes_netcdf_and_figure(tmp_path, capsys):
    nc = tmp_path / "r.nc"
    code, out, _ = run(capsys, "simulate", "--record", "NP.1765", "--scale", "2.6",
                       "--mu-s-ground", "0.45", "--mu-k-ground", "0.4", "--output", str(nc))
    assert code == 0
    assert "peak block slip" in out and "time per mode" in out
    assert nc.exists() and nc.with_suffix(".png").exists()
    ds = xr.open_dataset(nc)
    # every variable explains itself
    for name, var in ds.variables.items():
        assert "units" in var.attrs and "long_name" in var.attrs, name
    # the printed peak is the stored history's peak (within the sampling of the history)
    peak_cm = float(out.split("peak block slip |x_b|")[1].split("cm")[0])
    assert peak_cm == pytest.approx(100 * np.nanmax(np.abs(ds["x_b"].values)), rel=0.02)
    assert peak_cm > 1.0  # the scaled record does slide the blocks
    # the applied scale is visible in the stored input
    assert np.abs(ds["ground_acceleration_h"]).max() / STANDARD_GRAVITY > 1.0
    code, out, _ = run(capsys, "plot", str(nc), "--figure", str(tmp_path / "again.png"))
    assert code == 0 and (tmp_path / "again.png").exists()
    # a newcomer's --output, as for simulate, names the figure of plot
    code, out, _ = run(capsys, "plot", str(nc), "--output", str(tmp_path / "once_more.png"))
    assert code == 0 and (tmp_path / "once_more.png").exists()


def test_info_reports_pga_of_the_readme_table(capsys):
    code, out, _ = run(capsys, "info", "--record", "NP.1759", "--processing", "demean")
    assert code == 0
    h2 = [line for line in out.splitlines() if line.startswith("H2")][0]
    # README of the shipped records: NP.1759 HNE PGA 0.3305 g (demeaned, sensitivity removed):
    # the 'processed' column; 'as read' (sensitivity removed only) is beside it
    component, azimuth, as_read, processed = h2.split()[:4]
    assert float(processed) == pytest.approx(0.3305, abs=0.002)
    from shipblock.records.catalogue import load_catalogue

    raw = load_catalogue()["south-napa-2014/NP.1759"].read()
    assert float(as_read) == pytest.approx(
        np.abs(raw.components["H2"]).max() / STANDARD_GRAVITY, abs=6e-5)


def test_info_says_a_start_the_file_does_not_state_instead_of_printing_1970(capsys):
    # a PEER AT2 file has no start time; its reader leaves obspy's epoch, which 'info' printed
    # as if the record had started on 1970-01-01
    from pathlib import Path

    at2 = Path(__file__).parent / "data" / "helena_synthetic_180.AT2"
    code, out, _ = run(capsys, "info", str(at2), "--processing", "none")
    assert code == 0
    start = next(line for line in out.splitlines() if line.startswith("start"))
    assert "not stated in the file" in start and "1970-01-01T" not in start
    # a record that states its start keeps it, to the sample
    code, out, _ = run(capsys, "info", "--record", "NP.1759", "--processing", "none")
    assert code == 0
    start = next(line for line in out.splitlines() if line.startswith("start"))
    assert start.split()[1].startswith("2014-08-24T10:20:")


def test_process_writes_records_and_intensity_table(tmp_path, capsys):
    code, out, _ = run(capsys, "process", "--record", "NP.1743", "-o", str(tmp_path),
                       "--format", "SAC")
    assert code == 0
    sacs = sorted(tmp_path.glob("*.sac"))
    assert len(sacs) == 3
    table = (tmp_path / "south-napa-2014_NP.1743_intensity.csv").read_text().splitlines()
    assert table[0].startswith("component,pga_m_s2")
    assert len(table) == 4


@pytest.mark.parametrize(
    "argv,needle",
    [
        (["simulate", "--record", "NP.9999"], "not in the catalogue"),
        (["simulate", "no_such_file.mseed"], "no such file"),
        (["simulate", "--record", "NP.1765", "--ship-mass", "-5"], "ship_mass"),
        (["simulate", "--record", "NP.1765", "--mu-k-ship", "0.9"], "mu_k_ship"),
        (["plot", "missing.nc"], "missing.nc"),
    ],
)
def test_user_errors_are_one_line_with_exit_code_2(argv, needle, capsys):
    code, _, err = run(capsys, *argv)
    assert code == 2
    assert err.startswith("shipblock: error:") and needle in err
    assert "Traceback" not in err


def test_run_demo_pipeline_prints_fits_and_draws(tmp_path, capsys):
    """The README's main job, end to end, into a temporary output."""
    nc = tmp_path / "demo.nc"
    png = tmp_path / "demo.png"
    code, out, _ = run(capsys, "run", "pipelines/demo.toml", "--output", str(nc), "--figure",
                       str(png))
    assert code == 0, out
    assert nc.exists() and png.exists()
    ds = xr.open_dataset(nc)
    assert "median" in ds and set(ds["limit_state"].values) >= {"ship_slip"}
    med = float(ds["median"].sel(limit_state="ship_slip")) / STANDARD_GRAVITY
    printed = [line for line in out.splitlines() if line.strip().startswith("ship_slip ")][0]
    assert f"{med:.3g}" in printed
    # resamples of the bootstrap that could not be fitted are said, with the count stored and
    # the most frequent reason (they used to be dropped from the band without a word)
    lines = out.splitlines()
    for ls in ds["limit_state"].values:
        n_failed = int(ds["bootstrap_failed"].sel(limit_state=ls))
        row = next(i for i, line in enumerate(lines) if line.strip().startswith(f"{ls} "))
        note = lines[row + 1].strip()
        if n_failed:
            n_boot = ds["median_lower"].attrs["n_bootstrap"]
            why = str(ds["bootstrap_failure"].sel(limit_state=ls).values)
            assert note == (f"({n_failed} of {n_boot} bootstrap resamples could not be fitted, "
                            f"left out of the band; {why})")
            assert why.startswith("the most frequent reason (") and why.endswith("[IM in g]")
        else:
            assert "bootstrap" not in note
    assert int(ds["bootstrap_failed"].sel(limit_state="ship_slip")) > 0  # the demo's 66 of 200
    code, _, _ = run(capsys, "plot", str(nc), "--kind", "ida", "--figure", str(tmp_path / "i.png"))
    assert code == 0 and (tmp_path / "i.png").exists()
    # the study says what it used, in the pipeline's units (levels_g: g, no m/s^2 anywhere)
    assert "6 of 6 records used" in out
    # the demo's weak records need large factors for the upper levels: said, and run
    f = np.abs(ds["scale_factor"].values)
    n_above = int((f > 5).sum())
    assert n_above == int(ds["scale_factor_above_limit"].sum()) > 0
    worst = np.unravel_index(np.argmax(f), f.shape)
    assert (f"scale factors {f.min():.3g} to {f.max():.3g}: {n_above} of 48 runs above "
            f"max_scale_factor = 5, run anyway (scale_factor_policy = 'warn'); the largest "
            f"{f.max():.4g} ({str(ds['record'].values[worst[0]]).split('/')[-1]} at PGA "
            f"{float(ds['im_level_g'][worst[1]]):.3g} g)") in out
    assert "median PGA [g]" in out and "m/s" not in out
    np.testing.assert_allclose(ds["im_level_g"], [0.1, 0.2, 0.3, 0.45, 0.6, 0.8, 1.1, 1.5])
    assert ds["im_level_g"].attrs["units"] == "g"
    np.testing.assert_allclose(ds["median_g"], ds["median"] / STANDARD_GRAVITY, rtol=1e-15)


def test_run_invalid_pipeline_names_the_key(tmp_path, capsys):
    bad = tmp_path / "bad.toml"
    bad.write_text((__import__("pathlib").Path("pipelines/demo.toml").read_text())
                   .replace('type = "ida"', 'type = "idaa"')
                   .replace('"../records/catalogue.toml"', '"' + str(
                       __import__("pathlib").Path("records/catalogue.toml").resolve()) + '"'))
    code, _, err = run(capsys, "run", str(bad), "--output", str(tmp_path / "x.nc"))
    assert code == 2 and "design" in err and "type" in err


def test_response_figure_window_ends_at_the_failure_and_keeps_labels_inside():
    """The automatic time window covers the strong motion and every event but stops after a
    failure (nothing is computed beyond it), and the theta_c label sits inside the panel."""
    import matplotlib

    matplotlib.use("Agg")
    import numpy as np

    from shipblock import ShipBlockSystem, simulate
    from shipblock.plot import active_window, plot_response

    t = np.arange(0, 60, 0.01)
    acc = np.where((t > 5) & (t < 50), 1.0, 0.02) * np.sin(2 * np.pi * 1.5 * t)
    # without an end the window covers the strong motion; with one it stops there
    t0, t1 = active_window(t, acc, margin=2.0)
    assert t0 < 6 and t1 > 48
    assert active_window(t, acc, margin=2.0, end=20.0)[1] == 20.0 + 3.0
    system = ShipBlockSystem(ship_mass=1e-6, block_mass=1000.0, n_blocks=1, half_width=0.2,
                             half_height=1.0, mu_s_ground=10, mu_k_ground=10, mu_s_ship=10,
                             mu_k_ship=10)
    res = simulate(system, 6.0 * np.sign(np.sin(2 * np.pi * 0.5 * t)) * (t > 5), None, 0.01)
    assert res.failure == "overturning"
    axes = plot_response(res)
    lo, hi = axes[0].get_xlim()
    assert lo <= 5 and hi <= res.failure_time + 3.0 + 1e-9
    # the label's x is a fraction of the panel width (y axis transform), so it is inside it
    label = [txt for txt in axes[2].texts if "overturning" in txt.get_text()]
    assert len(label) == 1
    assert label[0].get_transform() == axes[2].get_yaxis_transform()
    assert 0.0 <= label[0].get_position()[0] <= 1.0


def test_response_figure_summarises_slip_events_and_draws_lines_only_when_asked():
    """Slip starts and stops (hundreds in a stick-slip record) are left to the mode bands and
    counted per interface in the legend; lines are drawn only when asked for."""
    import matplotlib

    matplotlib.use("Agg")
    import numpy as np

    from shipblock import ShipBlockSystem, simulate
    from shipblock.plot import SLIP_EVENTS, plot_response

    t = np.arange(0, 20, 0.01)
    system = ShipBlockSystem(ship_mass=5e6, block_mass=1200.0, n_blocks=150, half_width=1.5,
                             half_height=0.5, mu_s_ground=0.1, mu_k_ground=0.1, mu_s_ship=0.6,
                             mu_k_ship=0.55)
    res = simulate(system, 2.0 * np.sin(2 * np.pi * 2.0 * t), None, 0.01)
    n_slip = sum(e.kind in SLIP_EVENTS for e in res.events)
    assert n_slip > 40

    def vertical_lines(axes):
        return sum(len([ln for ln in ax.get_lines() if len(set(ln.get_xdata())) == 1])
                   for ax in axes[1:4])

    many = plot_response(res)
    assert vertical_lines(many) == 0
    labels = [txt.get_text() for txt in many[3].get_legend().get_texts()]
    starts = sum(e.kind == "ground_slip_start" for e in res.events)
    assert starts > 0 and not any(e.kind == "ship_slip_start" for e in res.events)
    assert f"blocks on the floor: {starts} slip starts (see the mode bands)" in labels
    assert not any("ship on the blocks" in label for label in labels)
    few = plot_response(res, max_slip_event_lines=n_slip)
    assert vertical_lines(few) == 3 * n_slip  # one line per event in each of three panels


def test_response_figure_draws_impact_lines_only_when_few():
    """A rocking episode has hundreds of impacts: beyond the limit they are counted in the
    legend instead of drawn (their lines made the panels grey); below it each is a line."""
    import matplotlib

    matplotlib.use("Agg")
    import numpy as np

    from shipblock import ShipBlockSystem, simulate
    from shipblock.plot import EVENT_STYLES, MAX_IMPACT_LINES, plot_response

    t = np.arange(0, 6, 0.005)
    system = ShipBlockSystem(ship_mass=5e6, block_mass=1500.0, n_blocks=150, half_width=0.12,
                             half_height=0.8, mu_s_ground=0.8, mu_k_ground=0.8, mu_s_ship=0.8,
                             mu_k_ship=0.8)
    ax = np.where(t < 1.0, 1.6 * np.sin(2 * np.pi * 1.0 * t), 0.0)  # rocks, about 300 impacts
    res = simulate(system, ax, None, 0.005)
    n_imp = sum(e.kind == "impact" for e in res.events)
    assert n_imp > MAX_IMPACT_LINES

    def vertical_lines(axes):
        return sum(len([ln for ln in a.get_lines() if len(set(ln.get_xdata())) == 1])
                   for a in axes[1:4])

    n_other = sum(e.kind in EVENT_STYLES and e.kind != "impact" for e in res.events)
    many = plot_response(res)
    assert vertical_lines(many) == 3 * n_other
    labels = [txt.get_text() for txt in many[3].get_legend().get_texts()]
    # counted as the CLI's summary counts them: the impact that ended rocking is one
    n_stop = sum(e.kind == "rocking_stop" for e in res.events)
    assert n_imp + n_stop == res.summary["n_impacts"]
    expected = f"{n_imp + n_stop} impacts: see the zero crossings of theta"
    if n_stop:
        expected += f" ({n_stop} ending in rest: rocking stop)"
    assert expected in labels
    assert "impact" not in labels
    few = plot_response(res, max_event_lines=n_imp)
    assert vertical_lines(few) == 3 * (n_imp + n_other)


def test_run_says_why_a_limit_state_was_not_fitted(tmp_path, capsys):
    """A limit state whose fit failed (e.g. beta not identified) is reported with the reason
    kept in the dataset's fit_error, never as a 'nan' median."""
    nc = tmp_path / "napa.nc"
    code, out, _ = run(capsys, "run", "pipelines/napa_ida.toml", "--output", str(nc))
    assert code == 0, out
    ds = xr.open_dataset(nc)
    lines = out.split("fitted fragility (lognormal", 1)[1].splitlines()[1:]
    for ls in ds["limit_state"].values:
        line = next(x for x in lines if x.strip().startswith(f"{ls} "))
        error = str(ds["fit_error"].sel(limit_state=ls).values)
        assert "nan" not in line
        if error:
            assert "not fitted: " in line and error.split(": ", 1)[-1] in line
        else:
            assert "median" in line


def test_compile_notice_speaks_once_and_only_when_numba_compiles():
    """A first use compiles (the notice is said once, however many functions compile); a
    function already compiled, or loaded from the cache, is not a compilation."""
    import numba

    from shipblock.cli import compile_notice

    said = []

    @numba.njit
    def twice(x):
        return 2.0 * x

    @numba.njit
    def thrice(x):
        return 3.0 * twice(x) / 2.0

    done = []
    with compile_notice(said.append, lambda what, seconds: done.append((what, seconds))):
        assert thrice(1.0) == 3.0  # compiles both
    assert len(said) == 1 and said[0].startswith(f"compiling numba code of {__name__}")
    assert len(done) == 1 and done[0][0] == f"numba code of {__name__}" and done[0][1] > 0.0
    with compile_notice(said.append):
        assert thrice(2.0) == 6.0  # already compiled
    assert len(said) == 1


def test_processing_chain_file_is_read_through_the_checked_toml_reader(tmp_path, capsys):
    """--processing FILE: a chain file is applied; a file that is not TOML, or nests deeper than
    shipblock reads, is refused in one line naming the file (shipblock.checks.toml_file)."""
    from shipblock.checks import MAX_TOML_DEPTH

    good = tmp_path / "chain.toml"
    good.write_text('[[processing]]\nstep = "demean"\n', encoding="utf-8")
    code, demeaned, _ = run(capsys, "info", "--record", "NP.1759", "--processing", "demean")
    assert code == 0
    code, out, _ = run(capsys, "info", "--record", "NP.1759", "--processing", str(good))
    assert code == 0 and out == demeaned
    broken = tmp_path / "broken.toml"
    broken.write_text('[[processing]]\nstep = "demean\n', encoding="utf-8")
    code, _, err = run(capsys, "info", "--record", "NP.1759", "--processing", str(broken))
    assert code != 0
    assert str(broken) in err and "not valid TOML" in err and "Traceback" not in err
    deep = tmp_path / "deep.toml"
    deep.write_text("x = " + "[" * (MAX_TOML_DEPTH + 5) + "]" * (MAX_TOML_DEPTH + 5) + "\n",
                    encoding="utf-8")
    code, _, err = run(capsys, "info", "--record", "NP.1759", "--processing", str(deep))
    assert code != 0 and str(deep) in err and "nested deeper" in err


def test_vertical_scale_with_no_vertical_is_a_usage_error_naming_both(capsys):
    """--vertical-scale with --no-vertical used to run with the scale ignored: now argparse
    refuses the pair (exit status 2) naming both flags, before any record is read."""
    with pytest.raises(SystemExit) as exc:
        main(["-q", "simulate", "--record", "NP.1765", "--vertical-scale", "2", "--no-vertical"])
    assert exc.value.code == 2
    err = capsys.readouterr().err
    assert "--vertical-scale" in err and "--no-vertical" in err and "not allowed" in err


def test_vertical_scale_of_a_record_without_vertical_is_refused(capsys):
    from pathlib import Path

    at2 = Path(__file__).parent / "data" / "helena_synthetic_180.AT2"  # one horizontal only
    code, _, err = run(capsys, "simulate", str(at2), "--processing", "none",
                       "--vertical-scale", "2")
    assert code == 2
    assert err.startswith("shipblock: error: --vertical-scale 2:") and "no vertical" in err


@pytest.mark.parametrize("flag,value", [("--atol", "5"), ("--atol", "0"), ("--rtol", "5")])
def test_tolerance_outside_the_solvers_range_names_the_flag(flag, value, capsys):
    code, _, err = run(capsys, "simulate", "--record", "NP.1765", flag, value)
    assert code == 2
    assert err.startswith(f"shipblock: error: {flag} must be") and "rigid model" in err


def test_atol_reaches_the_rigid_solver_and_is_stored(tmp_path, capsys):
    """--atol is the rigid solver's absolute tolerance: the value used is the one stored with
    the response (solver_atol), beside the default --rtol; the default run stores 1e-10."""
    from shipblock.solver import DEFAULT_ATOL

    given, default = tmp_path / "given.nc", tmp_path / "default.nc"
    common = ["simulate", "--record", "NP.1765", "--scale", "2.6", "--figure",
              str(tmp_path / "f.png")]
    assert run(capsys, *common, "--atol", "1e-7", "-o", str(given))[0] == 0
    assert run(capsys, *common, "-o", str(default))[0] == 0
    with xr.open_dataset(given) as a, xr.open_dataset(default) as b:
        assert a.attrs["solver_atol"] == 1e-7 and b.attrs["solver_atol"] == DEFAULT_ATOL
        assert a.attrs["solver_rtol"] == b.attrs["solver_rtol"] == 1e-8
