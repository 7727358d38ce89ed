"""Risk over a docking period: the risk integral against its closed form and against a
trapezoid integration on a real USGS hazard curve, the hazard readers, measure and unit checks,
the bootstrap band made again, the command line and the figure."""

from __future__ import annotations

import hashlib
import json
import math
from pathlib import Path

import matplotlib
import numpy as np
import pytest
import xarray as xr
from scipy.special import ndtr

from shipblock.cli import main
from shipblock.errors import ParameterError
from shipblock.fragility.pipeline import run_pipeline
from shipblock.plot_risk import plot_deaggregation, plot_hazard_and_fragility, plot_risk
from shipblock.risk import (
    HazardError,
    period_probability,
    read_hazard_curve,
    risk_dataset,
    risk_integral,
    run_risk,
)
from shipblock.risk.study import risk_lines
from shipblock.units import STANDARD_GRAVITY as G

from .test_pipeline import write_pipeline

matplotlib.use("Agg")

DATA = Path(__file__).parent / "data" / "hazard" / "nshmp-haz-2008-wus"
PGA_CURVES = DATA / "PGA" / "total.csv"
SA1_CURVES = DATA / "SA1P0" / "total.csv"


def nshmp_rows(path):
    """Site name -> (levels [g], annual rates) as written in an nshmp-haz curve file."""
    lines = path.read_text().splitlines()
    levels = np.array([float(v) for v in lines[0].split(",")[3:]])
    return {ln.split(",")[0]: (levels, np.array([float(v) for v in ln.split(",")[3:]]))
            for ln in lines[1:]}


def trapezoid_risk(x, lam, median, beta, n=400_000, decades=8.0):
    """sum 0.5 (P_j + P_j+1) (lambda_j - lambda_j+1) on a fine log grid: the hazard
    interpolated log-log between its levels, extended with the end slopes (zero above the
    last positive level, where the rate drops to zero)."""
    positive = lam > 0
    xp, lp = np.log(x[positive]), np.log(lam[positive])
    truncated = not positive[-1]
    top = xp[-1] if truncated else np.log(median) + decades * beta * 2.3
    u = np.linspace(min(xp[0], np.log(median)) - decades * beta * 2.3, top, n)
    slope_lo = (lp[1] - lp[0]) / (xp[1] - xp[0])
    slope_hi = (lp[-1] - lp[-2]) / (xp[-1] - xp[-2])
    log_lam = np.interp(u, xp, lp)
    log_lam = np.where(u < xp[0], lp[0] + slope_lo * (u - xp[0]), log_lam)
    log_lam = np.where(u > xp[-1], lp[-1] + slope_hi * (u - xp[-1]), log_lam)
    lam_u = np.exp(log_lam)
    p = ndtr((u - np.log(median)) / beta)
    total = np.sum(0.5 * (p[1:] + p[:-1]) * (lam_u[:-1] - lam_u[1:]))
    if truncated:  # the rate drops from its last positive value to zero
        total += p[-1] * lam_u[-1]
    return total


# -------------------------------------------------------------------------------------------
# the integral
# -------------------------------------------------------------------------------------------


@pytest.mark.parametrize("k0, k", [(1e-4, 2.7), (3e-3, 1.2), (1e-5, 4.0)])
@pytest.mark.parametrize("n_levels", [3, 25])
def test_power_law_hazard_gives_the_closed_form(k0, k, n_levels):
    # lambda_LS = k0 theta^-k exp(k^2 beta^2 / 2) (Cornell et al. 2002, eq. 11), also from a
    # coarse curve: the power law between levels is exact on every piece
    x = np.geomspace(0.02, 2.0, n_levels) * G
    lam = k0 * (x / G) ** -k
    theta = np.array([0.1, 0.4, 1.0, 3.0]) * G
    beta = np.array([0.2, 0.35, 0.5, 0.7])
    r = risk_integral(x, lam, theta, beta)
    exact = k0 * (theta / G) ** -k * np.exp(k**2 * beta**2 / 2)
    np.testing.assert_allclose(r.annual_rate, exact, rtol=1e-12)
    np.testing.assert_allclose(r.contribution.sum(axis=-1), r.annual_rate, rtol=1e-12)
    assert np.all(r.contribution >= 0.0)
    # the share from beyond the levels grows as the median leaves the curve's range
    assert r.tail_fraction[0] < r.tail_fraction[-1]


def test_closed_form_is_not_the_median_hazard():
    # the dispersion matters: exp(k^2 beta^2 / 2) = 2.49 for k = 3, beta = 0.5
    x = np.geomspace(0.01, 5.0, 30)
    lam = 1e-4 * x**-3.0
    r = risk_integral(x, lam, 0.5, 0.5)
    assert r.annual_rate / (1e-4 * 0.5**-3.0) == pytest.approx(math.exp(9 * 0.25 / 2), rel=1e-12)


@pytest.mark.parametrize("site", ["San Francisco CA", "Seattle WA", "Los Angeles CA"])
@pytest.mark.parametrize("median_g, beta", [(0.54, 0.25), (0.85, 0.32), (0.2, 0.6)])
def test_real_usgs_curve_matches_a_trapezoid_integration(site, median_g, beta):
    levels_g, lam = nshmp_rows(PGA_CURVES)[site]
    x = levels_g * G
    r = risk_integral(x, lam, median_g * G, beta)
    reference = trapezoid_risk(x, lam, median_g * G, beta)
    assert float(r.annual_rate) == pytest.approx(reference, rel=2e-5)
    # and the deaggregation: every bin against the trapezoid over that bin alone
    for i in range(1, x.size):
        if lam[i] == 0.0:
            break
        seg_x, seg_l = x[i - 1:i + 1], lam[i - 1:i + 1]
        u = np.linspace(np.log(seg_x[0]), np.log(seg_x[1]), 20001)
        lam_u = np.exp(np.interp(u, np.log(seg_x), np.log(seg_l)))
        p = ndtr((u - np.log(median_g * G)) / beta)
        d = np.sum(0.5 * (p[1:] + p[:-1]) * (lam_u[:-1] - lam_u[1:]))
        assert float(r.contribution[i]) == pytest.approx(d, rel=1e-4, abs=1e-12 * r.annual_rate)


def test_probability_in_a_docking_period_is_poisson():
    assert period_probability(1e-3, 365.25) == pytest.approx(1 - math.exp(-1e-3), rel=1e-14)
    # small rates: lambda N / 365.25
    assert period_probability(1e-6, 120.0) == pytest.approx(1e-6 * 120 / 365.25, rel=1e-6)
    np.testing.assert_allclose(period_probability(np.array([0.0, 2.0]), 365.25),
                               [0.0, 1 - math.exp(-2.0)])
    with pytest.raises(ParameterError, match="days"):
        period_probability(1e-3, 0.0)


def test_bad_curves_and_fits_are_refused():
    with pytest.raises(ParameterError, match="increasing"):
        risk_integral([1.0, 0.5], [1e-2, 1e-3], 1.0, 0.3)
    with pytest.raises(ParameterError, match="non-increasing"):
        risk_integral([0.5, 1.0], [1e-3, 1e-2], 1.0, 0.3)
    with pytest.raises(ParameterError, match="positive"):
        risk_integral([0.5, 1.0], [1e-2, 1e-3], -1.0, 0.3)


# -------------------------------------------------------------------------------------------
# readers
# -------------------------------------------------------------------------------------------


def test_nshmp_csv_is_read_in_si_with_its_provenance():
    levels, lam = nshmp_rows(PGA_CURVES)["San Francisco CA"]
    curve = read_hazard_curve(PGA_CURVES, site="San Francisco CA")
    assert curve.measure == "pga" and curve.period is None and curve.source_units == "g"
    np.testing.assert_allclose(curve.im, levels * G, rtol=1e-15)
    np.testing.assert_array_equal(curve.rate, lam)
    prov = curve.provenance
    assert prov["format"] == "nshmp-csv" and prov["site"] == "San Francisco CA"
    assert prov["sha256"] == hashlib.sha256(PGA_CURVES.read_bytes()).hexdigest()
    assert prov["vs30_m_s"] == 760.0 and prov["value_format"] == "ANNUAL_RATE"
    # the same site by its coordinates
    by_place = read_hazard_curve(PGA_CURVES, site="-122.4,37.75")
    np.testing.assert_array_equal(by_place.rate, lam)
    sa = read_hazard_curve(SA1_CURVES, site=(-122.3, 47.6))
    assert (sa.measure, sa.period) == ("sa", 1.0)


def test_a_file_with_several_sites_lists_them():
    with pytest.raises(HazardError, match="holds 4 sites.*Seattle WA"):
        read_hazard_curve(PGA_CURVES)
    with pytest.raises(HazardError, match="site 'Bremerton WA' is not in the file"):
        read_hazard_curve(PGA_CURVES, site="Bremerton WA")


def write_openquake(path, levels_g, lam, t_years, old_header=False):
    poe = -np.expm1(-lam * t_years)
    head = (f'# mean, investigation_time={t_years},imt="PGA"' if old_header else
            '#,,,,"generated_by=\'OpenQuake engine 3.20.0\', start_date=\'2024-06-03T09:36:04\', '
            f"checksum=1, kind='mean', investigation_time={t_years}, imt='PGA'\"")
    cols = ",".join(f"poe-{v:.7f}" for v in levels_g)
    path.write_text(f"{head}\nlon,lat,depth,{cols}\n0.00000,0.00000,0.00000,"
                    + ",".join(f"{p:.17E}" for p in poe) + "\n")
    return path


@pytest.mark.parametrize("old_header", [False, True])
def test_openquake_probabilities_become_annual_rates(tmp_path, old_header):
    levels, lam = nshmp_rows(PGA_CURVES)["Seattle WA"]
    path = write_openquake(tmp_path / "hazard_curve-mean-PGA_1.csv", levels, lam, 50.0,
                           old_header)
    curve = read_hazard_curve(path)
    assert curve.provenance["format"] == "openquake"
    assert curve.provenance["investigation_time_yr"] == 50.0
    np.testing.assert_allclose(curve.im, levels * G, rtol=1e-7)
    np.testing.assert_allclose(curve.rate, lam, rtol=1e-8, atol=1e-18)


def test_openquake_probability_one_is_left_out(tmp_path):
    path = tmp_path / "hazard_curve-mean-PGA.csv"
    path.write_text("# investigation_time=50.0, imt='PGA'\nlon,lat,depth,poe-0.01,poe-0.1,"
                    "poe-0.5\n1,2,0,1.0,0.5,0.01\n")
    curve = read_hazard_curve(path)
    np.testing.assert_allclose(curve.im, [0.1 * G, 0.5 * G])
    np.testing.assert_allclose(curve.rate, -np.log1p(-np.array([0.5, 0.01])) / 50.0)
    assert curve.provenance["levels_dropped_poe_1"] == 1


def usgs_json(levels, lam, imts=("PGA",)):
    """A response in the layout of the USGS hazard service (nshmp-haz-ws HazardService)."""
    return json.dumps({"status": "success", "response": [{
        "metadata": {"edition": {"value": "E2008", "display": "USGS NSHM 2008"},
                     "region": {"value": "WUS"}, "longitude": -122.4, "latitude": 37.75,
                     "imt": {"id": 0, "value": imt, "display": imt},
                     "vs30": {"value": "760", "display": "760 m/s (B/C boundary)"},
                     "xlabel": "Ground Motion (g)", "ylabel": "Annual Frequency of Exceedence",
                     "xvalues": list(levels)},
        "data": [{"component": "Total", "yvalues": list(lam)},
                 {"component": "Fault", "yvalues": list(lam / 2)}]} for imt in imts]})


def test_usgs_service_json_reads_the_total_curve(tmp_path):
    levels, lam = nshmp_rows(PGA_CURVES)["San Francisco CA"]
    path = tmp_path / "hazard.json"
    path.write_text(usgs_json(levels, lam))
    curve = read_hazard_curve(path)
    np.testing.assert_array_equal(curve.rate, lam)
    np.testing.assert_allclose(curve.im, levels * G)
    assert curve.provenance["vs30"] == "760 m/s (B/C boundary)"
    path.write_text(usgs_json(levels, lam, imts=("PGA", "SA1P0")))
    with pytest.raises(HazardError, match="PGA, SA1P0: choose one with measure"):
        read_hazard_curve(path)
    assert read_hazard_curve(path, measure="SA(1.0)").period == 1.0


def test_usgs_nshmp_haz_2_service_json_reads_the_total_curve(tmp_path):
    # the layout of nshmp-haz 2's HazardService: response.hazardCurves[].data[].values.xs/ys,
    # the site in the request, here cut at 1e-4 ("truncate") as the service can
    levels, lam = nshmp_rows(PGA_CURVES)["Seattle WA"]
    keep = lam > 1e-4
    doc = {"name": "Hazard Service", "status": "success",
           "request": {"longitude": -122.3, "latitude": 47.6, "vs30": 760.0, "truncate": True,
                       "maxdir": False},
           "response": {"metadata": {"xlabel": "Ground Motion (g)",
                                     "ylabel": "Annual Frequency of Exceedance"},
                        "hazardCurves": [{"imt": {"display": "PGA", "value": "PGA"}, "data": [
                            {"component": "Total", "values": {"xs": list(levels[keep]),
                                                              "ys": list(lam[keep])}},
                            {"component": "Interface", "values": {"xs": list(levels[keep]),
                                                                  "ys": list(lam[keep] / 3)}}]}]}}
    path = tmp_path / "hazard2.json"
    path.write_text(json.dumps(doc))
    curve = read_hazard_curve(path, site="-122.3,47.6")
    np.testing.assert_array_equal(curve.rate, lam[keep])
    np.testing.assert_allclose(curve.im, levels[keep] * G)
    assert curve.provenance["truncate"] is True and curve.provenance["maxdir"] is False
    assert curve.provenance["vs30"] == 760.0
    with pytest.raises(HazardError, match="site 'Bremerton' is not in the file"):
        read_hazard_curve(path, site="Bremerton")


def test_two_column_tables_need_units_in_the_header(tmp_path):
    path = tmp_path / "curve.csv"
    path.write_text("# site: test\nPGA [m/s^2], annual_rate [1/yr]\n0.5, 1e-2\n2.0, 1e-3\n"
                    "5.0, 1e-4\n")
    curve = read_hazard_curve(path)
    np.testing.assert_allclose(curve.im, [0.5, 2.0, 5.0])
    path.write_text("Sa(1.0) [g]  poe_50yr [-]\n0.1  0.5\n0.4  0.1\n")
    curve = read_hazard_curve(path)
    assert (curve.measure, curve.period) == ("sa", 1.0)
    np.testing.assert_allclose(curve.rate, -np.log1p(-np.array([0.5, 0.1])) / 50.0)
    path.write_text("PGA, rate\n0.1, 1e-2\n0.4, 1e-3\n")
    with pytest.raises(HazardError, match=r"unit in brackets"):
        read_hazard_curve(path)
    path.write_text("PGA [cm/s], annual_rate [1/yr]\n0.1, 1e-2\n0.4, 1e-3\n")
    with pytest.raises(HazardError, match=r"unit 'cm/s' of the levels is not an acceleration"):
        read_hazard_curve(path)
    path.write_text("PGA [g], annual_rate [1/yr]\n0.1, 1e-3\n0.4, 1e-2\n")
    with pytest.raises(HazardError, match="increases"):
        read_hazard_curve(path)


# -------------------------------------------------------------------------------------------
# a study
# -------------------------------------------------------------------------------------------


@pytest.fixture(scope="module")
def study(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("risk")
    path = write_pipeline(tmp, levels="levels_g = [0.2, 0.3, 0.4, 0.45, 0.5]",
                          sweep="[sweep]\nmu_ship = [0.3, 0.35]\n")
    ds = run_pipeline(path, progress=False)
    return tmp, ds.encoding.get("source") or str(tmp / "out" / "result.nc"), ds


def test_study_risk_equals_the_integral_of_each_fit_with_a_reproduced_band(study, tmp_path):
    _, results, ds = study
    out = run_risk(results, PGA_CURVES, 120, site="San Francisco CA",
                   output=tmp_path / "risk.nc")
    levels, lam = nshmp_rows(PGA_CURVES)["San Francisco CA"]
    fitted = np.isfinite(ds["median"].values)
    assert fitted.any()
    expected = np.full(ds["median"].shape, np.nan)
    expected[fitted] = risk_integral(levels * G, lam, ds["median"].values[fitted],
                                     ds["beta"].values[fitted]).annual_rate
    np.testing.assert_allclose(out["risk_annual_rate"].values, expected, rtol=1e-12)
    np.testing.assert_allclose(out["risk_probability"].values,
                               -np.expm1(-expected * 120 / 365.25), rtol=1e-12)
    assert out["risk_annual_rate"].dims == ("limit_state", "mu_ship")
    assert out["risk_deaggregation"].dims == ("limit_state", "mu_ship", "hazard_bin")
    # the band was made again from the stored exceedances and checked against the stored bounds
    banded = np.isfinite(ds["median_lower"].values)
    assert banded.any()
    assert out.attrs["risk_band"] == "bootstrap replicates of the fits"
    lo, hi = out["risk_annual_rate_lower"].values, out["risk_annual_rate_upper"].values
    assert np.all(lo[banded] <= hi[banded])
    # a larger median is a smaller rate: the rate's band comes from the medians' other ends
    theta_lo, theta_hi = ds["median_lower"].values[banded], ds["median_upper"].values[banded]
    beta_mid = ds["beta"].values[banded]
    assert np.all(hi[banded] > risk_integral(levels * G, lam, theta_hi, beta_mid).annual_rate)
    assert np.all(lo[banded] < risk_integral(levels * G, lam, theta_lo, beta_mid).annual_rate)
    # written with the hazard's provenance, every variable with units and long_name
    with xr.open_dataset(tmp_path / "risk.nc") as back:
        assert back.attrs["hazard_sha256"] == hashlib.sha256(PGA_CURVES.read_bytes()).hexdigest()
        assert back.attrs["hazard_site"] == "San Francisco CA"
        assert back.attrs["docking_days"] == 120.0
        assert back["risk_annual_rate"].attrs["units"] == "1/yr"
        np.testing.assert_allclose(back["risk_annual_rate"].values, expected, rtol=1e-12)


def test_msa_band_is_made_again_and_a_study_without_bands_says_so(tmp_path):
    path = write_pipeline(tmp_path, kind="msa", n_records=6,
                          levels="levels_g = [0.2, 0.3, 0.35, 0.4, 0.45, 0.5, 0.6, 0.8]")
    ds = run_pipeline(path, progress=False)
    banded = np.isfinite(ds["median_lower"].values)
    assert banded.any()
    curve = read_hazard_curve(PGA_CURVES, site="Seattle WA")
    out = risk_dataset(ds, curve, 120)
    assert out.attrs["risk_band"] == "bootstrap replicates of the fits"
    lo, hi = out["risk_annual_rate_lower"].values, out["risk_annual_rate_upper"].values
    assert np.all(lo[banded] < out["risk_annual_rate"].values[banded])
    assert np.all(out["risk_annual_rate"].values[banded] < hi[banded])
    unbanded = ds.copy()
    for name in ("median_lower", "median_upper"):
        unbanded[name] = ds[name] * np.nan
    out = risk_dataset(unbanded, curve, 120)
    assert out.attrs["risk_band"] == "none: no fit of the study has a bootstrap band"
    assert "risk_annual_rate_lower" not in out


def test_risk_of_a_risk_file_replaces_the_earlier_hazard(study, tmp_path):
    _, results, _ = study
    first = run_risk(results, PGA_CURVES, 120, site="Seattle WA", output=tmp_path / "a.nc",
                     band=False)
    again = run_risk(tmp_path / "a.nc", PGA_CURVES, 30, site="Los Angeles CA", output="",
                     band=False)
    direct = run_risk(results, PGA_CURVES, 30, site="Los Angeles CA", output="", band=False)
    xr.testing.assert_identical(again.drop_attrs(deep=False), direct.drop_attrs(deep=False))
    assert again.attrs["hazard_site"] == "Los Angeles CA" and again.attrs["docking_days"] == 30
    assert first.attrs["hazard_site"] == "Seattle WA"


def test_a_band_that_does_not_reproduce_the_stored_bounds_is_left_out(study):
    _, _, ds = study
    curve = read_hazard_curve(PGA_CURVES, site="San Francisco CA")
    tampered = ds.copy(deep=True)
    tampered["median_lower"] = tampered["median_lower"] * 1.01
    out = risk_dataset(tampered, curve, 120)
    assert out.attrs["risk_band"].startswith("none: the bootstrap made again for ship_slip")
    assert "risk_annual_rate_lower" not in out


def test_a_curve_for_another_measure_is_refused_naming_both(study, tmp_path):
    _, results, _ = study
    with pytest.raises(HazardError, match=r"SA1P0/total.csv: is a hazard curve for SA\(1 s\), "
                                          r"but the study .* is on PGA"):
        run_risk(results, SA1_CURVES, 120, site="Seattle WA", output="")


def test_a_study_im_in_a_unit_not_of_its_kind_is_refused(study):
    _, _, ds = study
    curve = read_hazard_curve(PGA_CURVES, site="Seattle WA")
    bad = ds.copy()
    bad.attrs["im_units"] = "m/s"
    with pytest.raises(ParameterError, match=r"study's IM PGA is in 'm/s', which is not an "
                                             "acceleration"):
        risk_dataset(bad, curve, 120)
    # in another acceleration unit it is converted: medians in g give the same rates
    in_g = ds.copy()
    in_g["median"] = ds["median"] / G
    in_g.attrs["im_units"] = "g"
    a = risk_dataset(ds, curve, 120, band=False)
    b = risk_dataset(in_g, curve, 120, band=False)
    np.testing.assert_allclose(a["risk_annual_rate"].values, b["risk_annual_rate"].values,
                               rtol=1e-12)


def test_command_line_prints_writes_and_draws(study, tmp_path, capsys):
    _, results, _ = study
    target = tmp_path / "r.nc"
    figure = tmp_path / "r.png"
    assert main(["-q", "risk", results, "--hazard", str(PGA_CURVES), "--days", "120",
                 "--site", "Seattle WA", "-o", str(target), "--figure", str(figure),
                 "--target-probability", "1e-4"]) == 0
    out = capsys.readouterr().out
    risk = xr.open_dataset(target)
    upper = risk["risk_probability_upper"].sel(limit_state="ship_slip", mu_ship=0.35).item()
    assert upper > 1e-4  # Seattle's hazard at 0.42 g: well above one in ten thousand
    assert "[upper bound ABOVE the target 0.0001]" in out
    assert any(line.endswith("[upper bound below the target 0.5]")
               for line in risk_lines(risk, 0.5))
    risk.close()
    assert f"risk written to {target}" in out
    assert "hazard: PGA at Seattle WA (nshmp-csv" in out
    assert "mu_ship = 0.3" in out and "P(120 d) = " in out
    assert figure.stat().st_size > 10_000
    assert main(["-q", "risk", results, "--hazard", str(SA1_CURVES), "--days", "120",
                 "--site", "Seattle WA", "-o", str(tmp_path / "x.nc")]) == 2
    assert "is a hazard curve for SA(1 s), but the study" in capsys.readouterr().err
    # a file of several sites and no --site: the refusal names the flag and the sites
    assert main(["-q", "risk", results, "--hazard", str(PGA_CURVES), "--days", "120",
                 "-o", str(tmp_path / "y.nc")]) == 2
    err = capsys.readouterr().err
    assert "holds 4 sites; choose one with site (--site: a name or lon,lat)" in err
    assert "Seattle WA (-122.3, 47.6)" in err


def test_deaggregation_figure_shares_sum_to_100(study):
    _, _, ds = study
    curve = read_hazard_curve(PGA_CURVES, site="Los Angeles CA")
    risk = risk_dataset(ds, curve, 90, band=False)
    ax = plot_deaggregation(risk, limit_state="ship_slip", sweep={"mu_ship": 0.35})
    (stairs,) = [p for p in ax.patches if type(p).__name__ == "StepPatch"]
    assert stairs.get_data().values.sum() == pytest.approx(100.0, rel=1e-9)
    axes = plot_risk(risk)
    assert len(axes) == 2
    # the hazard curve has its legend entry (it had none: the legend was the fragilities'
    # twin axes' alone), first, in the one legend with the fragilities; its line is the curve
    hazard_ax, twin = plot_hazard_and_fragility(risk, sweep={"mu_ship": 0.35})
    legend = twin.get_legend()
    labels = [t.get_text() for t in legend.get_texts()]
    assert labels[0] == "site hazard (left axis)"
    fitted = [str(n) for n in risk["limit_state"].values
              if np.isfinite(risk["median"].sel(limit_state=n, mu_ship=0.35))]
    assert labels[1:] == fitted and fitted  # a limit state not fitted is not drawn
    (curve,) = [line for line in hazard_ax.get_lines() if line.get_label() == labels[0]]
    positive = risk["hazard_rate"].values > 0
    np.testing.assert_array_equal(curve.get_ydata(), risk["hazard_rate"].values[positive])
    assert hazard_ax.get_legend() is None  # one legend, not two
    with pytest.raises(ParameterError, match="limit state 'collapse' is not in the study"):
        plot_deaggregation(risk, limit_state="collapse")
