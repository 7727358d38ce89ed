"""What a study prints and draws: the sweep table, plot --set, the median against a sweep,
limit-state definitions, records per level and readable observed fractions."""

from __future__ import annotations

import matplotlib
import numpy as np
import pytest
import xarray as xr

from shipblock.cli import main
from shipblock.fragility.pipeline import run_pipeline
from shipblock.fragility.report import fit_lines, study_report
from shipblock.plot import (
    marker_sizes,
    plot_fragility,
    plot_ida,
    plot_median_sweep,
    plot_section_response,
    study_caption,
    sweep_selection,
    sweep_text,
)
from shipblock.units import STANDARD_GRAVITY as G

from .test_pipeline import write_pipeline

matplotlib.use("Agg")

LEVELS = "levels_g = [0.2, 0.3, 0.4, 0.45, 0.5]"


@pytest.fixture(scope="module")
def sweep_run(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("sweep")
    path = write_pipeline(tmp, levels=LEVELS, sweep="[sweep]\nmu_ship = [0.3, 0.35]\n")
    return tmp, path, run_pipeline(path, progress=False)


def test_the_command_line_prints_a_table_of_medians_per_swept_value(sweep_run, capsys):
    tmp, path, ds = sweep_run
    assert main(["-q", "run", str(path), "-o", str(tmp / "again.nc")]) == 0
    out = capsys.readouterr().out
    assert "3 of 3 records used" in out
    header = "fitted fragility (lognormal, ida_interval): median PGA [g] (90 % bootstrap band), " \
             "beta"
    assert header in out
    table = out.split("  ship_slip:\n", 1)[1].splitlines()
    assert table[0].split() == ["mu_ship", "median", "band", "beta"]
    for row, mu in zip(table[1:3], (0.3, 0.35), strict=True):
        cells = row.split()
        assert float(cells[0]) == mu
        median = float(ds["median"].sel(limit_state="ship_slip", mu_ship=mu))
        if np.isfinite(median):
            assert cells[1] == f"{median / G:.3g}"
            assert cells[-1] == f"{float(ds['beta'].sel(limit_state='ship_slip', mu_ship=mu)):.3f}"
        else:
            assert "not fitted" in row
    assert fit_lines(ds) == study_report(ds)[-len(fit_lines(ds)):]


def test_a_swept_length_is_printed_and_drawn_with_its_unit(tmp_path, capsys):
    # a sweep over the blocks' half height: its values are metres, and the table's header,
    # its "not fitted at" notes and the figure's title say so (they used to print a bare
    # "half_height 0.5", read as anything from millimetres to feet)
    path = write_pipeline(tmp_path, levels=LEVELS, sweep="[sweep]\nhalf_height = [0.5, 0.6]\n")
    assert main(["-q", "run", str(path), "--figure", str(tmp_path / "f.png")]) == 0
    out = capsys.readouterr().out
    ds = xr.open_dataset(tmp_path / "out" / "result.nc")
    assert ds["half_height"].attrs["units"] == "m"
    table = out.split("  ship_slip:\n", 1)[1].splitlines()
    assert table[0].split()[:2] == ["half_height", "[m]"]
    for row, h in zip(table[1:3], (0.5, 0.6), strict=True):
        assert float(row.split()[0]) == h
    notes = [line for line in out.splitlines() if "not fitted at" in line]
    assert all("half_height = 0.5 m" in n or "half_height = 0.6 m" in n for n in notes)
    title = plot_fragility(ds).get_title(loc="left")
    assert "drawn at half_height = 0.5 m" in title
    # a dimensionless swept value stays bare
    assert sweep_text({"mu_ship": 0.3}, ds.assign_coords(mu_ship=("mu_ship", [0.3],
                                                                  {"units": "1"}))) \
        == "mu_ship = 0.3"


def test_sweep_selection_matches_values_and_names_the_choices(sweep_run):
    _, _, ds = sweep_run
    assert sweep_selection(ds) == {"mu_ship": 0.3}
    assert sweep_selection(ds, {"mu_ship": 0.35 + 1e-12}) == {"mu_ship": 0.35}
    with pytest.raises(ValueError, match="values: 0.3, 0.35"):
        sweep_selection(ds, {"mu_ship": 0.4})
    with pytest.raises(ValueError, match="swept: mu_ship"):
        sweep_selection(ds, {"mu_ground": 0.4})


def test_fragility_figure_names_thresholds_records_per_level_and_the_swept_value(sweep_run):
    _, _, ds = sweep_run
    ax = plot_fragility(ds, sweep={"mu_ship": 0.35})
    title = ax.get_title(loc="left")
    assert "3 records per level" in title and "mu_ship = 0.35" in title
    labels = [t.get_text() for t in ax.get_legend().get_texts()]
    assert labels[0].startswith("ship_slip (peak_ship_slip > 0.005 m)")
    assert labels[1].startswith("any_failure (failure != 0)")
    median = float(ds["median"].sel(limit_state="ship_slip", mu_ship=0.35)) / G
    if np.isfinite(median):
        assert f"median {median:.3g} g" in labels[0]
    # observed fractions at the levels themselves (not shifted), nested: the first limit
    # state's hollow marker the larger, and the fractions the counts of the study
    markers = [ln for ln in ax.get_lines() if ln.get_linestyle() == "None"]
    assert len(markers) == 2
    for line in markers:
        np.testing.assert_allclose(line.get_xdata(), [0.2, 0.3, 0.4, 0.45, 0.5], rtol=1e-12)
        assert line.get_markerfacecolor() == "none"
    assert [ln.get_markersize() for ln in markers] == marker_sizes(2)
    assert markers[0].get_markersize() > markers[1].get_markersize()
    assert "not shifted" in title and "nest" in title
    ex = ds["exceeded"].sel(limit_state="ship_slip", mu_ship=0.35)
    np.testing.assert_array_equal(markers[0].get_ydata(), ex.mean("record").values)


def test_study_figures_say_which_study_system_and_design_they_show(sweep_run):
    tmp, path, ds = sweep_run
    caption = study_caption(ds, {"mu_ship": 0.35})
    # the pipeline's title and file, the system with the swept value drawn, the design
    assert caption[0] == f"test ({path.name})" or caption[0] == f"test ({path})"
    assert caption[1] == ("system: ship 5000 t on 150 blocks of 1.2 t, 2B x 2H = 0.6 x 1.2 m; "
                          "friction blocks-floor 0.6/0.55, ship-blocks 0.35/0.3 (static/kinetic)")
    assert study_caption(ds, {"mu_ship": 0.3})[1].endswith(
        "ship-blocks 0.3/0.257 (static/kinetic)")  # kinetic/static ratio 0.30/0.35 kept
    assert caption[2] == ("design: IDA on PGA, 3 records x 5 levels (0.2 to 0.5 g); vertical "
                          "scaled with the horizontal")
    figures = (plot_fragility(ds, sweep={"mu_ship": 0.35}),
               plot_ida(ds, sweep={"mu_ship": 0.35}),
               plot_median_sweep(ds, "mu_ship"))
    for ax in figures:
        title = ax.get_title(loc="left")
        assert caption[0] in title and "system: ship 5000 t on 150 blocks" in title
        assert caption[2] in title
    assert "IDA curves: " in figures[1].get_title(loc="left")
    assert "mu_ship swept (x axis)" in figures[2].get_title(loc="left")


def test_the_bootstrap_band_is_named_only_when_one_is_drawn(sweep_run):
    from matplotlib.collections import PolyCollection

    _, _, ds = sweep_run

    def bands(ax):
        return [c for c in ax.collections if isinstance(c, PolyCollection)]

    # bootstrapped study: one band per limit state whose bounds exist at the value drawn
    fitted = int(np.isfinite(ds["median_lower"].sel(mu_ship=0.35)).sum())
    assert fitted >= 1
    ax = plot_fragility(ds, sweep={"mu_ship": 0.35})
    assert len(bands(ax)) == fitted
    assert "shaded: 90 % bootstrap band of the median" in ax.get_title(loc="left")
    # at mu_ship = 0.3 no curve was fitted, so no band: nothing drawn, nothing said
    assert not np.isfinite(ds["median_lower"].sel(mu_ship=0.3)).any()
    ax = plot_fragility(ds, sweep={"mu_ship": 0.3})
    assert bands(ax) == [] and "bootstrap" not in ax.get_title(loc="left")
    # a study without bootstrap: no band, and the title does not mention one
    plain = ds.drop_vars(["median_lower", "median_upper"])
    ax = plot_fragility(plain, sweep={"mu_ship": 0.35})
    assert bands(ax) == [] and "shaded" not in ax.get_title(loc="left")
    assert "bars" not in plot_median_sweep(plain).get_title(loc="left")
    assert "bars: 90 % bootstrap band" in plot_median_sweep(ds).get_title(loc="left")


def test_plot_command_draws_the_swept_value_asked_for_and_the_median_against_the_sweep(
        sweep_run, tmp_path, capsys):
    tmp, _, ds = sweep_run
    nc = tmp / "out" / "result.nc"
    png = tmp_path / "f.png"
    assert main(["-q", "plot", str(nc), "--set", "mu_ship=0.35", "-o", str(png)]) == 0
    assert png.exists()
    assert main(["-q", "plot", str(nc), "--kind", "median", "-o", str(tmp_path / "m.png")]) == 0
    assert (tmp_path / "m.png").exists()
    assert main(["-q", "plot", str(nc), "--set", "mu_ship=0.4", "-o", str(png)]) == 2
    assert "mu_ship = 0.4 is not a value of the study; values: 0.3, 0.35" in \
        capsys.readouterr().err
    ax = plot_median_sweep(ds)
    assert ax.get_xlabel().startswith("mu_ship [-]")
    line = ax.get_lines()[0]
    np.testing.assert_allclose(line.get_ydata(),
                               ds["median"].sel(limit_state="ship_slip").values / G)


def test_plot_command_draws_the_limit_states_asked_for(sweep_run, tmp_path, capsys,
                                                      monkeypatch):
    # plot_fragility's and plot_median_sweep's limit_state existed only in Python
    import shipblock.plot

    tmp, _, ds = sweep_run
    nc = tmp / "out" / "result.nc"
    drawn = []
    for name in ("plot_fragility", "plot_median_sweep"):
        original = getattr(shipblock.plot, name)

        def spy(*args, _original=original, **kw):
            ax = _original(*args, **kw)
            drawn.append([t.get_text().split(" (")[0] for t in ax.get_legend().get_texts()])
            return ax

        monkeypatch.setattr(shipblock.plot, name, spy)
    names = [str(n) for n in ds["limit_state"].values]
    assert len(names) >= 2
    for kind in ("fragility", "median"):
        assert main(["-q", "plot", str(nc), "--kind", kind, "--limit-state", names[1],
                     "-o", str(tmp_path / f"{kind}.png")]) == 0
        assert (tmp_path / f"{kind}.png").exists()
    assert drawn == [[names[1]], [names[1]]]
    assert main(["-q", "plot", str(nc), "--limit-state", "nope", "-o", str(tmp_path / "x.png")]) \
        == 2
    assert (f"--limit-state 'nope' is not a limit state of the study; limit states: "
            f"{', '.join(names)}") in capsys.readouterr().err
    assert main(["-q", "plot", str(nc), "--kind", "ida", "--limit-state", names[0], "-o",
                 str(tmp_path / "x.png")]) == 2
    assert "--limit-state draws with --kind fragility or median" in capsys.readouterr().err


def test_cloud_figure_draws_each_records_outcome_at_its_intensity(tmp_path):
    path = write_pipeline(tmp_path, kind="cloud", levels="")
    ds = run_pipeline(path, progress=False)
    ax = plot_fragility(ds)
    title = ax.get_title(loc="left")
    assert "design: cloud on PGA, 3 records at their own intensity" in title
    assert "records' outcome (1: exceeded, 0: not)" in title
    markers = [ln for ln in ax.get_lines() if ln.get_linestyle() == "None"]
    assert len(markers) == 2
    np.testing.assert_allclose(markers[0].get_xdata(), ds["achieved_im"].values / G,
                               rtol=1e-12)
    np.testing.assert_array_equal(markers[0].get_ydata(),
                                  ds["exceeded"].sel(limit_state="ship_slip").values)
    fitted = np.isfinite(ds["median"].values).any()
    assert ("lines: lognormal fit" in title) == bool(fitted)


def _section_histories(sway_peak_m, half_width_m=0.61):
    """A dataset shaped as a section run's histories, its sway one sine of ``sway_peak_m``."""
    t = np.arange(0.0, 10.0, 0.01)
    load = np.full(t.size, 3e5)
    return xr.Dataset(
        {"ship_sway": ("time", sway_peak_m * np.sin(t)), "ship_roll": ("time", 1e-4 * np.sin(t)),
         "keel_top_normal": ("time", load), "ground_acceleration_h": ("time", np.sin(3 * t)),
         "ground_acceleration_v": ("time", np.zeros(t.size))},
        coords={"time": t},
        attrs={"keel_cap_half_width": half_width_m, "keel_block_capacity": 3.288e6,
               "failure_name": "none", "record_description": "a test record"})


@pytest.mark.parametrize(("sway_m", "edges_drawn"), [(0.009, False), (0.3, True)])
def test_the_sway_panel_shows_a_small_sway_at_its_own_scale(sway_m, edges_drawn):
    """A 9 mm sway against a 610 mm keel cap's edge was a flat line: it has its own scale and
    the legend names the edge; a sway of half the half-width is drawn against the edges."""
    axes = plot_section_response(_section_histories(sway_m))
    ax_s = axes[1]
    low, high = ax_s.get_ylim()
    labels = [t.get_text() for t in ax_s.get_legend().get_texts()]
    if edges_drawn:
        assert high >= 610.0 and low <= -610.0
        assert labels == ["keel cap's edge"]
    else:
        assert 9.0 <= high < 12.0 and -12.0 < low <= -9.0  # the sway fills the panel
        assert labels == ["keel cap's edge at \u00b1610 mm (off scale)"]


def test_the_load_panel_names_the_side_each_line_stands_on():
    """Side lines are named with the side of the ship they stand on and their distance from
    the centre line (from the dataset's ``<line>_offset``, positive to starboard), as the
    ``simulate`` summary names them; a dataset without offsets keeps the bare names."""
    ds = _section_histories(0.01)
    for line in ("side0", "side1"):
        ds[f"{line}_top_normal"] = ds["keel_top_normal"]
        ds.attrs[f"{line}_block_capacity"] = 3.288e6
    bare = [t.get_text() for t in plot_section_response(ds)[3].get_legend().get_texts()]
    assert bare == ["keel", "side0", "side1", "capacity"]
    ds.attrs.update(keel_offset=0.0, side0_offset=4.5, side1_offset=-4.5)
    named = [t.get_text() for t in plot_section_response(ds)[3].get_legend().get_texts()]
    assert named == ["keel", "side0 (starboard, 4.5 m)", "side1 (port, 4.5 m)", "capacity"]
