"""``shipblock report``: one self-contained HTML file of a study (definition, records, limit
states, fragility with bands, risk) with the export's CSV tables beside it; the values shown are
the file's."""

from __future__ import annotations

import base64
import re
import shutil
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
import xarray as xr

from shipblock.cli import main
from shipblock.fragility.export import fragility_table
from shipblock.fragility.pipeline import run_pipeline
from shipblock.report import record_spectra, report_html, study_spectra
from shipblock.risk import run_risk
from shipblock.scaling import read_target_spectrum

from .test_pipeline import write_pipeline

REPO = Path(__file__).parent.parent
PGA_CURVES = Path(__file__).parent / "data" / "hazard" / "nshmp-haz-2008-wus" / "PGA" / "total.csv"


@pytest.fixture(scope="module")
def demo(tmp_path_factory):
    """The shipped demo study, run by the command line in a folder of its own."""
    tmp = tmp_path_factory.mktemp("demo")
    (tmp / "pipelines").mkdir()
    shutil.copy(REPO / "pipelines" / "demo.toml", tmp / "pipelines" / "demo.toml")
    (tmp / "records").symlink_to(REPO / "records", target_is_directory=True)
    assert main(["-q", "run", str(tmp / "pipelines" / "demo.toml")]) == 0
    return tmp / "results" / "demo.nc"


def _images(text):
    return [base64.b64decode(m) for m in re.findall(r'src="data:image/png;base64,([^"]+)"', text)]


def test_demo_report_holds_the_study_records_and_medians_of_its_tables(demo, tmp_path, capsys):
    out = tmp_path / "rep" / "report.html"
    assert main(["-q", "report", str(demo), "-o", str(out)]) == 0
    said = capsys.readouterr().out
    assert f"report written to {out}" in said
    text = out.read_text(encoding="utf-8")
    with xr.open_dataset(demo) as ds:
        ds = ds.load()
    assert f"<h1>{ds.attrs['title']}</h1>" in text
    # every record, used, with its station and the horizontal channel used
    for rid in ds["record"].values:
        station = rid.split("/")[-1]
        assert re.search(rf"<tr><td>{re.escape(rid)}</td><td>{station}</td>.*?"
                         rf"H1 = {station}\.\.HNN.*?<td>yes</td></tr>", text), rid
    # the fit table shows each median of fragility.csv (in g, as the pipeline gave its levels)
    table = pd.read_csv(out.parent / "report_csv" / "fragility.csv")
    assert len(table) == 3
    for _, row in table.iterrows():
        assert (f"<tr><td>{row['limit_state']}</td><td>{row['median_g [g]']:.3g}</td>"
                f"<td>{row['median_lower_g [g]']:.3g} to {row['median_upper_g [g]']:.3g}</td>"
                f"<td>{row['beta [-]']:.3f}</td>") in text, row["limit_state"]
    # the tables are the export's, values as stored
    np.testing.assert_array_equal(table["median [m/s^2]"].to_numpy(),
                                  fragility_table(ds)["median [m/s^2]"].to_numpy())
    assert "href='report_csv/runs.csv'" in text and (out.parent / "report_csv/runs.csv").is_file()
    # the limit states' definitions, the system with units, the chain and solver options
    assert "<td>ship_slip</td><td>peak_ship_slip &gt; 0.02 m</td>" in text
    assert "<td>ship_mass</td><td>5e+06</td><td>kg</td>" in text
    assert "<td>bandpass</td><td>corners = 4, freqmax = 25, freqmin = 0.1" in text
    assert "<td>zeno_omega</td><td>1e-07</td><td>rad/s</td>" in text
    assert "seed = 20140824" in text
    # self-contained: every figure a PNG inside the file, nothing fetched
    images = _images(text)
    assert len(images) == 2  # fragility, IDA
    assert all(png.startswith(b"\x89PNG\r\n\x1a\n") and len(png) > 20_000 for png in images)
    assert not re.search(r"""(src|href)=["'](?!data:|report_csv/)""", text)
    assert "No target spectrum" in text and "Not computed: make it with" in text


def test_a_record_left_out_is_named_with_its_reason(demo):
    with xr.open_dataset(demo) as ds:
        ds = ds.load()
    ds["record_used"].values[2] = False
    ds["record_error"] = ds["record_error"].astype(object)
    ds["record_error"].values[2] = "RecordError: no vertical <HNZ>"
    text = report_html(ds)
    rid = str(ds["record"].values[2])
    assert re.search(rf"<td>{re.escape(rid)}</td>.*?<td>left out: RecordError: no vertical "
                     r"&lt;HNZ&gt;</td></tr>", text)


def test_report_of_a_risk_result_holds_the_annual_rates(demo, tmp_path, capsys):
    risk = run_risk(demo, PGA_CURVES, 120, site="San Francisco CA", output=tmp_path / "risk.nc")
    out = tmp_path / "report.html"
    assert main(["-q", "report", str(demo), "--hazard-results", str(tmp_path / "risk.nc"),
                 "-o", str(out)]) == 0
    text = out.read_text(encoding="utf-8")
    for ls in risk["limit_state"].values:
        r = risk.sel(limit_state=ls)
        rate = float(r["risk_annual_rate"])
        assert (f"<tr><td>{ls}</td><td>{rate:.3g} ({float(r['risk_annual_rate_lower']):.3g} to "
                f"{float(r['risk_annual_rate_upper']):.3g})</td><td>{1 / rate:.4g}</td>"
                f"<td>{float(r['risk_probability']):.3g} ") in text, ls
    assert "hazard: PGA at San Francisco CA (nshmp-csv" in text
    assert len(_images(text)) == 3  # fragility, IDA, hazard with deaggregation
    # the risk columns go into the fragility table beside it
    table = pd.read_csv(tmp_path / "report_csv" / "fragility.csv")
    np.testing.assert_array_equal(table["risk_annual_rate [1/yr]"].to_numpy(),
                                  risk["risk_annual_rate"].values)
    # the risk file of another study is refused, named
    other = risk.copy()
    other.attrs["pipeline_fingerprint"] = "0" * 64
    other.to_netcdf(tmp_path / "other.nc")
    capsys.readouterr()
    assert main(["-q", "report", str(demo), "--hazard-results", str(tmp_path / "other.nc"),
                 "-o", str(out)]) == 2
    assert f"{tmp_path / 'other.nc'}: the risk of another study" in capsys.readouterr().err


def test_not_a_study_is_refused_by_name(tmp_path, capsys):
    response = tmp_path / "response.nc"
    xr.Dataset({"x_b": ("time", np.zeros(3))}, coords={"time": np.arange(3.0)}).to_netcdf(
        response)
    other = tmp_path / "other.nc"
    xr.Dataset({"median": ("limit_state", [1.0])}, coords={"limit_state": ["a"]}).to_netcdf(other)
    text = tmp_path / "notes.nc"
    text.write_text("not a NetCDF file\n")
    for path, why in ((response, "not the result of a study ('shipblock run'): a simulation's "
                                 "response"),
                      (other, "a study result without the attribute(s) pipeline, system"),
                      (text, "not a NetCDF results file"),
                      (tmp_path / "missing.nc", "no such results file")):
        assert main(["-q", "report", str(path), "-o", str(tmp_path / "r.html")]) == 2
        err = capsys.readouterr().err
        assert str(path) in err and why in err, err
    assert not (tmp_path / "r.html").exists()


def test_records_against_a_given_target_are_least_squares_in_ln_sa(demo, tmp_path, capsys):
    """``--target``: each record read and processed again, scaled by its least-squares factor
    in ln Sa over the range (the log residuals average zero) and its misfit their RMS."""
    (tmp_path / "uhs.csv").write_text("period [s], Sa [g]\n0.05, 0.6\n0.2, 1.2\n0.6, 1.1\n"
                                      "1.0, 0.7\n2.0, 0.35\n4.0, 0.15\n")
    with xr.open_dataset(demo) as ds:
        ds = ds.load()
    target = read_target_spectrum(tmp_path / "uhs.csv", "g")
    spectra = record_spectra(ds, target, (0.1, 2.0))
    assert spectra["periods"][0] == pytest.approx(0.1) and spectra["periods"][-1] == pytest.approx(2)
    np.testing.assert_allclose(spectra["target"], target.at(spectra["periods"]), rtol=1e-15)
    assert list(spectra["matches"]) == list(ds["record"].values)
    for m in spectra["matches"].values():
        resid = np.log(m["factor"] * m["sa"] / spectra["target"])
        assert abs(resid.mean()) < 1e-12
        assert m["misfit"] == pytest.approx(np.sqrt(np.mean(resid**2)), rel=1e-12)
    out = tmp_path / "report.html"
    assert main(["-q", "report", str(demo), "--target", str(tmp_path / "uhs.csv"),
                 "--period-range", "0.1", "2.0", "-o", str(out)]) == 0
    text = out.read_text(encoding="utf-8")
    for rid, m in spectra["matches"].items():
        assert re.search(rf"<td>{re.escape(rid)}</td>.*?<td>{m['misfit']:.3g}</td><td>yes</td>",
                         text), rid
    assert len(_images(text)) == 3
    # a range the target does not cover is refused before a record is read, naming the file
    assert main(["-q", "report", str(demo), "--target", str(tmp_path / "uhs.csv"),
                 "--period-range", "0.01", "2.0", "-o", str(out)]) == 2
    err = capsys.readouterr().err
    assert "uhs.csv: the target spectrum covers 0.05 to 4 s; periods 0.01 to 2 s are needed" in err


@pytest.mark.parametrize("match", ["range", "anchor"])
def test_a_study_matched_to_a_target_draws_its_own_spectra(tmp_path, match):
    """The study's stored match (record_sa, target_sa): the factor the report scales each
    record by gives back the misfit the study stored, for either kind of match."""
    (tmp_path / "target.csv").write_text(
        "period_s, sa_g\n0.05, 0.5\n0.2, 1.0\n0.6, 1.0\n2.0, 0.3\n4.0, 0.15\n")
    levels = ('measure = "sa"\nperiod = 1.0\nlevels_g = [0.3, 0.6]\n'
              '[design.target_spectrum]\nfile = "target.csv"\nunits = "g"\n'
              f'period_range = [0.2, 2.0]\nmatch = "{match}"\n')
    ds = run_pipeline(write_pipeline(tmp_path, kind="msa", levels=levels), progress=False)
    spectra = study_spectra(ds)
    target = ds["target_sa"].values
    given = read_target_spectrum(tmp_path / "target.csv", "g")
    for i, m in enumerate(spectra["matches"].values()):
        resid = np.log(m["factor"] * m["sa"] / target)
        assert np.sqrt(np.mean(resid**2)) == pytest.approx(
            float(ds["spectrum_misfit"].values[i]), rel=1e-10)
        if match == "anchor":  # Sa(T1 = 1 s) of the scaled record is the target's there
            assert m["factor"] * float(ds["record_im"].values[i]) == pytest.approx(
                float(given.at(1.0)[0]), rel=1e-12)
    text = report_html(ds, spectra=spectra)
    assert len(_images(text)) >= 2 and "against the target" in text


def test_a_swept_study_reports_each_arrangement(tmp_path):
    """A [sweep]: the fit table and the risk table have a row per swept value, and there is a
    fragility figure per value and the median against the swept parameter."""
    path = write_pipeline(tmp_path, levels="levels_g = [0.2, 0.3, 0.4, 0.45, 0.5]",
                          sweep="[sweep]\nmu_ship = [0.3, 0.35]\n")
    ds = run_pipeline(path, progress=False)
    risk = run_risk(tmp_path / "out" / "result.nc", PGA_CURVES, 90, site="Seattle WA",
                    output=tmp_path / "risk.nc", band=False)
    assert np.isfinite(risk["risk_annual_rate"].sel(limit_state="ship_slip")).any()
    out = tmp_path / "report.html"
    assert main(["-q", "report", str(tmp_path / "risk.nc"), "-o", str(out)]) == 0
    text = out.read_text(encoding="utf-8")
    for value in (0.3, 0.35):
        sel = {"limit_state": "ship_slip", "mu_ship": value}
        median = float(ds["median_g"].sel(sel))
        assert (f"<tr><td>ship_slip</td><td>{value:g}</td><td>"
                + (f"{median:.3g}" if np.isfinite(median) else "not fitted")) in text
        rate = float(risk["risk_annual_rate"].sel(sel))
        if np.isfinite(rate):
            assert f"<tr><td>ship_slip</td><td>{value:g}</td><td>{rate:.3g}</td>" in text
        assert f'alt="fragility curves at mu_ship = {value:g}"' in text
        if np.isfinite(risk["risk_annual_rate"].sel(mu_ship=value)).any():
            assert f'alt="hazard, fragilities and deaggregation at mu_ship = {value:g}"' in text
        else:
            assert f"No figure at mu_ship = {value:g}: no limit state was fitted there" in text
    assert 'alt="median against mu_ship"' in text and "P(90 d) [-]" in text
    # fragility x 2, median sweep, IDA, risk where a limit state was fitted
    assert len(_images(text)) == 4 + int(np.isfinite(risk["risk_annual_rate"]).any("limit_state")
                                         .sum())
