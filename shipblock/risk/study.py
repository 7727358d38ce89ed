r"""Risk over a docking period for a finished fragility study: :func:`run_risk`.

A fragility result (:func:`~shipblock.fragility.pipeline.run_pipeline`) holds, per limit state
and swept parameter, a lognormal median :math:`\theta` [SI] and dispersion :math:`\beta`, and
the study's intensity measure in its attributes (``im_measure``, ``im_period`` for Sa,
``im_units``). :func:`risk_dataset` checks that a :class:`~shipblock.risk.hazard.HazardCurve`
is for the same measure (and period), converts the study's medians to SI by their stated unit,
and adds to a copy of the result

``risk_annual_rate``, ``risk_return_period``, ``risk_probability``
    :math:`\lambda_{LS}` [1/yr], :math:`1/\lambda_{LS}` [yr], and the probability of at least
    one exceedance during the docking period of ``docking_days`` [-]
    (:mod:`shipblock.risk.integral`), on ``(limit_state, *sweep)``;
``risk_*_lower``, ``risk_*_upper``
    their bootstrap band: the same percentiles as the study's ``median_lower``/``median_upper``
    of the integral over the bootstrap replicates of the fit (:func:`bootstrap_replicates`);
``risk_deaggregation``
    the contribution of each bin of the hazard's levels (``hazard_bin``, edges
    ``hazard_bin_lower``/``hazard_bin_upper``) [1/yr], and ``risk_tail_fraction``;
``hazard_rate``
    the hazard curve itself on ``hazard_im`` [SI];

and the hazard's provenance as attributes ``hazard_file``, ``hazard_sha256``,
``hazard_format``, ``hazard_site``, ``hazard_measure``, ``hazard_source_units`` and
``hazard_provenance`` (JSON of everything the file said about itself).

The bootstrap replicates are not stored in a result; they are made again from its stored
exceedances with the study's own fit options and seeds, as the pipeline made them
(``[seed, limit state, combination]``), and checked: their percentiles must equal the stored
``median_lower``/``median_upper``, or no band is given and ``risk_band`` says why.
"""

from __future__ import annotations

import itertools
import json
import warnings
from pathlib import Path

import numpy as np
import xarray as xr

from shipblock import checks
from shipblock.errors import ParameterError
from shipblock.fragility.fit import bootstrap, fit_cloud, fit_ida_levels, fit_msa
from shipblock.fragility.store import open_results, write_dataset
from shipblock.risk.hazard import HazardCurve, HazardError, describe_measure, read_hazard_curve
from shipblock.risk.integral import DAYS_PER_YEAR, period_probability, risk_integral
from shipblock.units import ACCELERATION_UNITS_TO_SI, VELOCITY_UNITS_TO_SI

__all__ = [
    "bootstrap_replicates",
    "check_measure",
    "risk_dataset",
    "risk_lines",
    "run_risk",
    "study_measure",
]

#: Relative tolerance of the check that the replicates made again reproduce the stored band.
_BAND_TOLERANCE = 1e-9

_GRID_DIMS = ("record", "im_level", "limit_state")


def study_measure(ds: xr.Dataset, name: str = "results") -> tuple[str, float | None, float]:
    """The intensity measure of a fragility result and the SI value of its unit.

    Parameters
    ----------
    ds : xarray.Dataset
        A result of :func:`~shipblock.fragility.pipeline.run_pipeline`.
    name : str
        The file, for messages.

    Returns
    -------
    measure : str
        ``"pga"``, ``"pgv"`` or ``"sa"``.
    period : float or None
        Sa period [s].
    factor : float
        SI value of one ``im_units`` (1 for the SI results the pipeline writes).

    Raises
    ------
    ParameterError
        If the result names no measure or a unit that is not one of its kind.
    """
    measure = str(ds.attrs.get("im_measure", ""))
    if measure not in ("pga", "pgv", "sa"):
        raise ParameterError(f"{name}: im_measure {measure!r} is not pga, pgv or sa: not a "
                             "fragility result of shipblock run")
    period = float(ds.attrs["im_period"]) if measure == "sa" else None
    unit = str(ds.attrs.get("im_units", ds["median"].attrs.get("units", "")))
    table = VELOCITY_UNITS_TO_SI if measure == "pgv" else ACCELERATION_UNITS_TO_SI
    factor = table.get(unit.strip().lower())
    if factor is None:
        kind = "a velocity" if measure == "pgv" else "an acceleration"
        raise ParameterError(f"{name}: the study's IM {describe_measure(measure, period)} is in "
                             f"{unit!r}, which is not {kind}")
    return measure, period, factor


def check_measure(ds: xr.Dataset, curve: HazardCurve, name: str = "results") -> float:
    """Refuse a hazard curve for another measure or period than the study's.

    Returns
    -------
    float
        The SI value of the study's IM unit (see :func:`study_measure`).

    Raises
    ------
    HazardError
        Naming the hazard file, its measure and the study's.
    """
    measure, period, factor = study_measure(ds, name)
    same = curve.measure == measure and (
        measure != "sa" or abs(curve.period - period) <= 1e-6 * max(1.0, period))
    if not same:
        raise HazardError(curve.provenance.get("file", "<hazard>"),
                          f"is a hazard curve for {curve.label}, but the study {name} is on "
                          f"{describe_measure(measure, period)} (im_measure = {measure!r}"
                          f"{'' if period is None else f', im_period = {period:g} s'}): the "
                          "measures must be the same")
    return factor


def _sweep_dims(ds: xr.Dataset) -> list[str]:
    return [d for d in ds["median"].dims if d not in _GRID_DIMS]


def bootstrap_replicates(ds: xr.Dataset):
    """The bootstrap medians and dispersions of every fit of a result, made again.

    Parameters
    ----------
    ds : xarray.Dataset
        A fragility result with ``exceeded``, ``valid`` and the ``fit_options`` attribute.

    Returns
    -------
    medians, betas : numpy.ndarray or None
        Shape ``(*median.shape, n_bootstrap)`` [SI; -], NaN for a replicate that could not be
        fitted; ``None`` when the result has no bootstrap.
    reason : str
        Empty if the replicates reproduce the stored bounds; else why there is no band.
    """
    try:
        fit_opts = json.loads(ds.attrs["fit_options"])
    except (KeyError, ValueError):
        return None, None, "the result states no fit options"
    n_boot = int(fit_opts.get("bootstrap", 0))
    if n_boot < 1:
        return None, None, "the study made no bootstrap ([fit] bootstrap = 0)"
    kind = str(ds.attrs.get("design_type", ""))
    factor = float(ds.attrs.get("im_display_factor", 1.0))
    sweep = _sweep_dims(ds)
    shape = ds["median"].shape
    medians = np.full((*shape, n_boot), np.nan)
    betas = medians.copy()
    confidence = float(fit_opts["confidence"])
    q = 100 * np.array([(1 - confidence) / 2, (1 + confidence) / 2])
    levels = ds["im_level"].values / factor if "im_level" in ds.dims else None
    n_done = 0
    for i, ls in enumerate(ds["limit_state"].values):
        lead = ["record", "im_level"] if levels is not None else ["record"]
        e_all = ds["exceeded"].sel(limit_state=ls).transpose(*lead, *sweep).values
        w_all = ds["valid"].sel(limit_state=ls).transpose(*lead, *sweep).values
        for c, combo in enumerate(itertools.product(*(range(ds.sizes[d]) for d in sweep))):
            index = (i, *combo)
            if not np.isfinite(ds["median_lower"].values[index]):
                continue
            sel = (slice(None),) * len(lead) + combo
            e, w = e_all[sel], w_all[sel]
            keep = w.any(axis=1) if e.ndim == 2 else w
            if kind == "ida":
                fn, kw = fit_ida_levels, {"im_levels": levels, "method": fit_opts["ida_method"]}
                args = {"exceeded": e[keep], "valid": w[keep]}
            elif kind == "msa":
                fn, kw = fit_msa, {"im_levels": levels}
                args = {"exceeded": e[keep], "valid": w[keep]}
            elif kind == "cloud":
                im = ds["achieved_im"].transpose("record", *sweep).values[(slice(None), *combo)]
                im = im / factor
                if fit_opts.get("cloud_method") == "probit":
                    fn, kw = fit_cloud, {"capacity": 0.5, "method": "probit"}
                    args = {"im": im[keep], "edp": e[keep].astype(float)}
                else:
                    edp_name = str(ds["limit_state_edp"].values[i])
                    edp = ds[edp_name].transpose("record", *sweep).values[(slice(None), *combo)]
                    fn = fit_cloud
                    kw = {"capacity": float(ds["limit_state_threshold"].values[i]),
                          "method": "regression"}
                    args = {"im": im[keep], "edp": np.abs(edp[keep])}
            else:
                return None, None, f"design type {kind!r} is not one whose fits can be redone"
            rng = np.random.default_rng([int(fit_opts["seed"]), i, c])
            try:
                with warnings.catch_warnings():  # the study recorded its failed resamples
                    warnings.simplefilter("ignore", RuntimeWarning)
                    b = bootstrap(fn, args, n_boot=n_boot, confidence=confidence, seed=rng, **kw)
            except ValueError as exc:
                return None, None, f"the bootstrap of {ls} could not be made again: {exc}"
            m = np.asarray(b.medians) * factor
            bounds = np.percentile(m, q)
            stored = np.array([ds["median_lower"].values[index], ds["median_upper"].values[index]])
            if not np.allclose(bounds, stored, rtol=_BAND_TOLERANCE, atol=0.0):
                return None, None, (f"the bootstrap made again for {ls} gives median bounds "
                                    f"{bounds} instead of the stored {stored}: the band is left out")
            medians[index][: m.size] = m
            betas[index][: m.size] = b.betas
            n_done += 1
    if not n_done:
        return None, None, "no fit of the study has a bootstrap band"
    return medians, betas, ""


def _integral_over(curve: HazardCurve, median, beta):
    """Annual rates of an array of fits, NaN where a fit is missing."""
    median, beta = np.broadcast_arrays(np.asarray(median, float), np.asarray(beta, float))
    ok = np.isfinite(median) & np.isfinite(beta) & (median > 0) & (beta > 0)
    rate = np.full(median.shape, np.nan)
    contribution = np.full((*median.shape, curve.im.size + 1), np.nan)
    tail = np.full(median.shape, np.nan)
    if np.any(ok):
        r = risk_integral(curve.im, curve.rate, median[ok], beta[ok])
        rate[ok], contribution[ok], tail[ok] = r.annual_rate, r.contribution, r.tail_fraction
    return rate, contribution, tail


def risk_dataset(ds: xr.Dataset, curve: HazardCurve, days: float, *, band: bool = True,
                 name: str = "results") -> xr.Dataset:
    """A copy of a fragility result with the risk over a docking period (see the module text).

    Parameters
    ----------
    ds : xarray.Dataset
        A fragility result.
    curve : HazardCurve
        The site hazard, for the study's measure.
    days : float
        Docking period :math:`N` [d].
    band : bool
        Also the bootstrap band (when the study has one).
    name : str
        The result's file, for messages.

    Returns
    -------
    xarray.Dataset

    Raises
    ------
    HazardError
        If the curve's measure is not the study's.
    ParameterError
        For a result without fits or a ``days`` that is not positive.
    """
    if "median" not in ds or "beta" not in ds:
        raise ParameterError(f"{name}: no fitted fragility (median, beta): not a result of "
                             "shipblock run")
    days = checks.real(days, "days", low=0.0, low_open=True, high=3650.0 * DAYS_PER_YEAR,
                       units="d")
    factor = check_measure(ds, curve, name)
    # the risk of an earlier hazard (a file written here, given again) is replaced, not mixed
    earlier = [v for v in ds.variables if str(v).startswith(("risk_", "hazard_"))]
    ds = ds.drop_vars(earlier)
    ds.attrs = {k: v for k, v in ds.attrs.items()
                if not k.startswith(("risk_", "hazard_")) and k != "docking_days"}
    dims = ds["median"].dims
    theta = ds["median"].values * factor
    beta = ds["beta"].values
    rate, contribution, tail = _integral_over(curve, theta, beta)
    out = ds.copy()
    label = curve.label
    out = out.assign_coords(
        hazard_im=("hazard_im", curve.im, {"units": "m/s" if curve.measure == "pgv" else "m/s^2",
                                           "long_name": f"intensity level of the hazard curve "
                                                        f"({label})"}),
        hazard_bin=("hazard_bin", np.arange(curve.im.size + 1),
                    {"units": "1", "long_name": "bin of the hazard's levels (0: below the first"
                                                " level; last: above the last)"}),
    )
    im_units = out["hazard_im"].attrs["units"]
    lower = np.concatenate([[0.0], curve.im])
    upper = np.concatenate([curve.im, [np.inf]])
    out["hazard_rate"] = xr.DataArray(curve.rate, dims=("hazard_im",), attrs={
        "units": "1/yr", "long_name": f"annual rate of exceedance of the site hazard ({label})"})
    out["hazard_bin_lower"] = xr.DataArray(lower, dims=("hazard_bin",), attrs={
        "units": im_units, "long_name": "lower edge of the hazard bin"})
    out["hazard_bin_upper"] = xr.DataArray(upper, dims=("hazard_bin",), attrs={
        "units": im_units, "long_name": "upper edge of the hazard bin (inf: no edge)"})
    probability = period_probability(rate, days)
    out["risk_annual_rate"] = xr.DataArray(rate, dims=dims, attrs={
        "units": "1/yr", "long_name": "annual rate of exceedance of the limit state "
                                      "(fragility convolved with the site hazard)"})
    with np.errstate(divide="ignore"):
        out["risk_return_period"] = xr.DataArray(1.0 / rate, dims=dims, attrs={
            "units": "yr", "long_name": "return period of the limit state's exceedance"})
    out["risk_probability"] = xr.DataArray(probability, dims=dims, attrs={
        "units": "1", "long_name": f"probability of exceeding the limit state at least once "
                                   f"during the docking period of {days:g} days (Poisson)",
        "docking_days": days})
    out["risk_deaggregation"] = xr.DataArray(contribution, dims=(*dims, "hazard_bin"), attrs={
        "units": "1/yr", "long_name": "contribution of each bin of the hazard's levels to the "
                                      "annual rate of exceedance"})
    out["risk_tail_fraction"] = xr.DataArray(tail, dims=dims, attrs={
        "units": "1", "long_name": "share of the annual rate from beyond the hazard curve's "
                                   "levels (extended power law or lumped at the last level)"})
    reason = "not asked for" if not band else ""
    if band:
        medians, betas, reason = bootstrap_replicates(ds)
        if medians is not None:
            confidence = float(ds["median_lower"].attrs.get("confidence", 0.9))
            q = np.array([(1 - confidence) / 2, (1 + confidence) / 2]) * 100
            rates, _, _ = _integral_over(curve, medians, betas)
            with warnings.catch_warnings():  # all-NaN for a fit without a band
                warnings.simplefilter("ignore", RuntimeWarning)
                lo, hi = np.nanpercentile(rates, q, axis=-1)
            attrs = {"confidence": confidence, "n_bootstrap": int(medians.shape[-1])}
            for suffix, value in (("lower", lo), ("upper", hi)):
                out[f"risk_annual_rate_{suffix}"] = xr.DataArray(value, dims=dims, attrs={
                    "units": "1/yr", "long_name": f"{suffix} bootstrap bound of the annual rate "
                                                  "of exceedance", **attrs})
                out[f"risk_probability_{suffix}"] = xr.DataArray(
                    period_probability(value, days), dims=dims, attrs={
                        "units": "1", "long_name": f"{suffix} bootstrap bound of the probability "
                                                   "during the docking period", **attrs})
    prov = curve.provenance
    out.attrs.update({
        "docking_days": days,
        "risk_band": "bootstrap replicates of the fits" if not reason else f"none: {reason}",
        "hazard_file": str(prov.get("file", "")),
        "hazard_sha256": str(prov.get("sha256", "")),
        "hazard_format": str(prov.get("format", "")),
        "hazard_site": str(prov.get("site", "")),
        "hazard_measure": label,
        "hazard_source_units": curve.source_units,
        "hazard_provenance": json.dumps(prov, sort_keys=True),
        "risk_method": "lognormal fragility x hazard curve, power law between levels (exact "
                       "per piece), shipblock.risk.integral",
    })
    return out


def run_risk(results, hazard, days: float, *, output=None, site=None, format: str = "auto",  # noqa: A002
             measure: str | None = None, band: bool = True) -> xr.Dataset:
    """Read a fragility result and a hazard curve, compute the risk and write a copy of the result.

    Parameters
    ----------
    results : str or os.PathLike
        A NetCDF of ``shipblock run``.
    hazard : str or os.PathLike
        A hazard curve file (:func:`~shipblock.risk.hazard.read_hazard_curve`).
    days : float
        Docking period [d].
    output : str or os.PathLike, optional
        Where to write; default ``<results stem>_risk.nc`` beside the results; ``""`` writes
        nothing (the dataset is only returned).
    site, format, measure
        Passed to :func:`~shipblock.risk.hazard.read_hazard_curve`; for a file with curves of
        several measures and no ``measure``, the study's is taken.
    band : bool
        Also the bootstrap band.

    Returns
    -------
    xarray.Dataset
        The dataset written (``encoding["source"]`` is its path).
    """
    path = checks.existing_file(results, "results", "a fragility result NetCDF")
    ds = open_results(path)
    try:
        curve = read_hazard_curve(hazard, format=format, site=site, measure=measure)
    except HazardError as exc:
        if measure is not None or "choose one with measure" not in str(exc):
            raise
        # a file with curves for several measures: take the study's
        m, period, _ = study_measure(ds, path)
        wanted = "PGA" if m == "pga" else "PGV" if m == "pgv" else f"SA({period:g})"
        curve = read_hazard_curve(hazard, format=format, site=site, measure=wanted)
    out = risk_dataset(ds, curve, days, band=band, name=path)
    if output != "":
        target = Path(output) if output else Path(path).with_name(Path(path).stem + "_risk.nc")
        write_dataset(out, target)
        out.encoding["source"] = str(target)
    return out


def _format_rate(ds: xr.Dataset, name: str, index) -> str:
    value = float(ds[name].values[index])
    band = ""
    if f"{name}_lower" in ds:
        lo, hi = (float(ds[f"{name}_{s}"].values[index]) for s in ("lower", "upper"))
        if np.isfinite(lo) and np.isfinite(hi):
            band = f" ({lo:.3g} to {hi:.3g})"
    return f"{value:.3g}{band}"


def risk_lines(ds: xr.Dataset, target_probability: float | None = None) -> list[str]:
    """What ``shipblock risk`` prints: the hazard, then one line per fit.

    Parameters
    ----------
    ds : xarray.Dataset
        A result of :func:`risk_dataset`.
    target_probability : float, optional
        An acceptable probability during the docking period [-]: each line then says whether
        the fit (its upper bootstrap bound when there is a band) is below it, so that the
        arrangements of a sweep that meet it stand out.

    Returns
    -------
    list of str
    """
    if target_probability is not None:
        target_probability = checks.real(target_probability, "target_probability", low=0.0,
                                         high=1.0, low_open=True, high_open=True)
    days = float(ds.attrs["docking_days"])
    lines = [f"hazard: {ds.attrs['hazard_measure']} at {ds.attrs['hazard_site'] or 'the site'} "
             f"({ds.attrs['hazard_format']}, {Path(ds.attrs['hazard_file']).name}, sha256 "
             f"{ds.attrs['hazard_sha256'][:12]}...)"]
    if "risk_annual_rate_lower" in ds:
        confidence = float(ds["risk_annual_rate_lower"].attrs["confidence"])
        lines.append(f"in brackets: {confidence:.0%} bootstrap band")
    else:
        lines.append(f"no band ({ds.attrs['risk_band']})")
    dims = ds["risk_annual_rate"].dims
    for index in np.ndindex(ds["risk_annual_rate"].shape):
        where = ", ".join(f"{d} = {ds[d].values[i]}" for d, i in zip(dims[1:], index[1:],
                                                                        strict=True))
        ls = str(ds["limit_state"].values[index[0]])
        rate = float(ds["risk_annual_rate"].values[index])
        if not np.isfinite(rate):
            lines.append(f"  {ls:<20}{' ' + where if where else ''}: not fitted, no risk")
            continue
        lines.append(
            f"  {ls:<20}{' ' + where if where else ''}: annual rate "
            f"{_format_rate(ds, 'risk_annual_rate', index)} /yr, return period "
            f"{1.0 / rate:.4g} yr, P({days:g} d) = {_format_rate(ds, 'risk_probability', index)}"
            + (f", {float(ds['risk_tail_fraction'].values[index]):.1%} from beyond the curve"
               if float(ds["risk_tail_fraction"].values[index]) >= 0.01 else "")
            + _verdict(ds, index, target_probability))
    return lines


def _verdict(ds: xr.Dataset, index, target: float | None) -> str:
    if target is None:
        return ""
    banded = "risk_probability_upper" in ds and np.isfinite(
        ds["risk_probability_upper"].values[index])
    value = float(ds["risk_probability_upper" if banded else "risk_probability"].values[index])
    what = "upper bound" if banded else "estimate"
    return (f"  [{what} below the target {target:g}]" if value < target
            else f"  [{what} ABOVE the target {target:g}]")
