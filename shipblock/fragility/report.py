"""What a finished study says about itself, in the units its pipeline was written in.

:func:`study_report` turns a result dataset of :func:`~shipblock.fragility.pipeline.run_pipeline`
into the lines the ``shipblock run`` command prints: how many records were used and why any
were left out, the scale factors and the limit they were checked against, the runs that ended
in a solver error, and the fitted fragility curves (one line per limit state, or a table per
limit state over the swept parameters). Intensities are shown in the unit the pipeline gave
its levels in (:func:`display_units`: g for ``levels_g``), the data stay SI in the file.
"""

from __future__ import annotations

import itertools

import numpy as np
import xarray as xr

from shipblock.units import STANDARD_GRAVITY

__all__ = ["display_units", "fit_lines", "im_label", "study_report"]

#: Dimensions of a result that are not swept parameters.
_GRID_DIMS = ("record", "im_level", "limit_state")


def display_units(ds: xr.Dataset) -> tuple[str, float]:
    """The unit intensities are shown in, and its value in SI units.

    The pipeline's own unit (attributes ``im_display_units`` and ``im_display_factor``);
    for files without them, g for accelerations and the stored unit otherwise.

    Parameters
    ----------
    ds : xarray.Dataset
        A result of :func:`~shipblock.fragility.pipeline.run_pipeline`.

    Returns
    -------
    unit : str
    factor : float
        SI value of one ``unit``.
    """
    if "im_display_units" in ds.attrs:
        return str(ds.attrs["im_display_units"]), float(ds.attrs["im_display_factor"])
    units = str(ds.attrs.get("im_units", ""))
    if units in ("m/s^2", "m/s**2"):
        return "g", STANDARD_GRAVITY
    return units, 1.0


def im_label(ds: xr.Dataset) -> str:
    """Axis or column label of the intensity, e.g. ``"PGA [g]"`` or ``"Sa(1 s) [g]"``."""
    measure = str(ds.attrs.get("im_measure", "im"))
    name = measure.upper()
    if measure == "sa" and "im_period" in ds.attrs:
        name = f"Sa({float(ds.attrs['im_period']):g} s)"
    return f"{name} [{display_units(ds)[0]}]"


def _sweep_dims(da: xr.DataArray) -> list[str]:
    return [d for d in da.dims if d not in _GRID_DIMS]


def swept_unit(ds: xr.Dataset, name: str) -> str:
    """The unit of a swept parameter's coordinate, ``""`` when it has none (or is ``"1"``).

    Parameters
    ----------
    ds : xarray.Dataset
        A result of a sweep.
    name : str
        The swept parameter, e.g. ``"side_offset"``.

    Returns
    -------
    str
        e.g. ``"m"`` for a side line's distance; ``""`` for a friction coefficient.
    """
    units = str(ds[name].attrs.get("units", "")) if name in ds.coords else ""
    return "" if units in ("", "1") else units


def _median_text(ds, sel, factor) -> tuple[str, str]:
    median = float(ds["median"].sel(sel)) / factor
    band = ""
    if "median_lower" in ds:
        lo = float(ds["median_lower"].sel(sel)) / factor
        hi = float(ds["median_upper"].sel(sel)) / factor
        if np.isfinite(lo) and np.isfinite(hi):
            band = f"{lo:.3g} to {hi:.3g}"
    return f"{median:.3g}", band


def _bootstrap_text(ds: xr.Dataset, sel) -> str:
    """``"66 of 200 bootstrap resamples could not be fitted, left out of the band; the most
    frequent reason (48 of 66): ..."`` for a fit whose bootstrap lost resamples, else ``""``."""
    if "bootstrap_failed" not in ds:
        return ""
    n_failed = int(ds["bootstrap_failed"].sel(sel))
    if n_failed <= 0:
        return ""
    n_boot = ds["median_lower"].attrs.get("n_bootstrap") if "median_lower" in ds else None
    text = (f"{n_failed}{f' of {int(n_boot)}' if n_boot else ''} bootstrap resamples could not "
            "be fitted, left out of the band")
    why = str(ds["bootstrap_failure"].sel(sel).values) if "bootstrap_failure" in ds else ""
    return text + (f"; {why}" if why else "")


def fit_lines(ds: xr.Dataset) -> list[str]:
    """The fitted curves: one line per limit state, or a table over the swept parameters.

    Parameters
    ----------
    ds : xarray.Dataset
        A result with ``median``, ``beta`` and ``fit_error``.

    Returns
    -------
    list of str
    """
    if "median" not in ds:
        return []
    unit, factor = display_units(ds)
    label = im_label(ds)
    method = ""
    if "fit_method" in ds:
        methods = {str(m) for m in np.ravel(ds["fit_method"].values) if str(m)}
        method = f", {', '.join(sorted(methods))}" if methods else ""
    conf = ds["median_lower"].attrs.get("confidence") if "median_lower" in ds else None
    band_name = f"{100 * float(conf):g} % bootstrap band" if conf is not None else "band"
    lines = [f"fitted fragility (lognormal{method}): median {label} ({band_name}), beta"]
    sweep = _sweep_dims(ds["median"])
    for ls in ds["limit_state"].values:
        name = str(ls)
        if not sweep:
            sel = {"limit_state": ls}
            error = str(ds["fit_error"].sel(sel).values) if "fit_error" in ds else ""
            median, band = _median_text(ds, sel, factor)
            if median == "nan":
                # e.g. too few exceedances to identify beta: say why instead of printing nan
                lines.append(f"  {name:<24} not fitted: {error.split(': ', 1)[-1]}")
                continue
            band = f" ({band})" if band else ""
            lines.append(f"  {name:<24} median {median}{band}, beta "
                         f"{float(ds['beta'].sel(sel)):.3f}")
            if error:
                lines.append(f"  {'':<24} ({error})")
            if boot := _bootstrap_text(ds, sel):
                lines.append(f"  {'':<24} ({boot})")
            continue
        lines.append(f"  {name}:")
        units = [swept_unit(ds, d) for d in sweep]
        header = [f"{d} [{u}]" if u else d for d, u in zip(sweep, units, strict=True)]
        header += ["median", "band", "beta"]
        rows = []
        notes = []
        boot_notes = []
        for combo in itertools.product(*(ds[d].values for d in sweep)):
            sel = {"limit_state": ls, **dict(zip(sweep, combo, strict=True))}
            values = [f"{v:g}" if isinstance(v, int | float | np.number) else str(v)
                      for v in combo]
            median, band = _median_text(ds, sel, factor)
            if median == "nan":
                error = str(ds["fit_error"].sel(sel).values) if "fit_error" in ds else ""
                rows.append([*values, "not fitted", "", ""])
                where = ", ".join(f"{d} = {v}{f' {u}' if u else ''}"
                                  for d, v, u in zip(sweep, values, units, strict=True))
                notes.append(f"{where}: {error.split(': ', 1)[-1]}")
            else:
                rows.append([*values, median, band, f"{float(ds['beta'].sel(sel)):.3f}"])
                if boot := _bootstrap_text(ds, sel):
                    where = ", ".join(f"{d} = {v}{f' {u}' if u else ''}"
                                      for d, v, u in zip(sweep, values, units, strict=True))
                    boot_notes.append(f"{where}: {boot}")
        widths = [max(len(h), *(len(r[i]) for r in rows)) for i, h in enumerate(header)]
        lines.append("    " + "  ".join(h.ljust(w) for h, w in zip(header, widths, strict=True)).rstrip())
        for r in rows:
            lines.append("    " + "  ".join(c.ljust(w) for c, w in zip(r, widths, strict=True)).rstrip())
        lines += [f"    not fitted at {n}" for n in notes]
        lines += [f"    bootstrap at {n}" for n in boot_notes]
    return lines


def _scale_factor_line(ds: xr.Dataset) -> str | None:
    if "scale_factor" not in ds or "im_level" not in ds.dims:
        return None
    f = np.abs(ds["scale_factor"].values)
    made = np.isfinite(f)
    if "in_stripe" in ds:
        made &= ds["in_stripe"].values.astype(bool)
    if not made.any():
        return None
    text = f"scale factors {np.min(f[made]):.3g} to {np.max(f[made]):.3g}"
    limit = ds.attrs.get("max_scale_factor")
    if limit is None:
        return text
    above = ds["scale_factor_above_limit"].values if "scale_factor_above_limit" in ds else (
        made & (f > limit))
    policy = ds.attrs.get("scale_factor_policy", "warn")
    if not above.any():
        return text + f", all within max_scale_factor = {float(limit):g}"
    unit, factor = display_units(ds)
    worst = np.unravel_index(np.argmax(np.where(above, f, -np.inf)), f.shape)
    rec = str(ds["record"].values[worst[0]]).split("/")[-1]
    level = float(ds["im_level"].values[worst[1]]) / factor
    what = "not run (scale_factor_policy = 'refuse')" if policy == "refuse" else (
        "run anyway (scale_factor_policy = 'warn')")
    return (text + f": {int(above.sum())} of {int(made.sum())} runs above max_scale_factor = "
            f"{float(limit):g}, {what}; the largest {f[worst]:.4g} ({rec} at "
            f"{im_label(ds).split(' [')[0]} {level:.3g} {unit})")


def _spectrum_line(ds: xr.Dataset) -> str | None:
    if "spectrum_misfit" not in ds:
        return None
    misfit = ds["spectrum_misfit"].values
    misfit = misfit[np.isfinite(misfit)]
    lo, hi = ds.attrs.get("target_spectrum_period_range", [np.nan, np.nan])
    match = ds.attrs.get("target_spectrum_match", "")
    how = ("least squares in ln Sa over" if match == "range" else
           "Sa(T1) matched, misfit over")
    text = f"target spectrum {ds.attrs.get('target_spectrum_file', '')} ({how} {lo:g} to {hi:g} s)"
    if not misfit.size:
        return text + ": no record matched"
    return (text + f": misfit (RMS of ln Sa ratios) {misfit.min():.3g} to {misfit.max():.3g}, "
            f"mean {misfit.mean():.3g} (per record in spectrum_misfit)")


def _solver_error_line(ds: xr.Dataset) -> str | None:
    if "run_error" not in ds:
        return None
    errors = np.asarray(ds["run_error"].values, dtype=str)
    solver = np.char.startswith(errors, "solver error")
    if not solver.any():
        return None
    return (f"{int(solver.sum())} runs ended in a solver error and are left out of the fits "
            "(see the variable run_error)")


def study_report(ds: xr.Dataset) -> list[str]:
    """The lines ``shipblock run`` prints about a finished study.

    Parameters
    ----------
    ds : xarray.Dataset
        A result of :func:`~shipblock.fragility.pipeline.run_pipeline`.

    Returns
    -------
    list of str
        Records used (``"5 of 6 records used, 1 left out: NP.1737 (why)"``), scale factors and
        their limit, the target-spectrum misfits, solver errors, and :func:`fit_lines`.
    """
    lines = []
    if "records_used" in ds.attrs:
        lines.append(str(ds.attrs["records_used"]))
    for line in (_scale_factor_line(ds), _spectrum_line(ds), _solver_error_line(ds)):
        if line:
            lines.append(line)
    return lines + fit_lines(ds)
