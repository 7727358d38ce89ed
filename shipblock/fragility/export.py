"""A study's results as CSV tables, for spreadsheets and reports.

:func:`write_csv` writes two tables of a result of
:func:`~shipblock.fragility.pipeline.run_pipeline` (``shipblock export results.nc --csv DIR``):

* ``runs.csv``: one row per run (record x IM level x swept values), with the run's demand
  parameters (EDPs), scale factors, achieved intensity, failure and, per limit state, whether
  it was exceeded (``exceeded:NAME``) and counted (``valid:NAME``);
* ``fragility.csv``: one row per limit state (x swept values), with its definition (EDP,
  condition, threshold and the threshold's unit) and the fitted median, its bootstrap band and
  the dispersion beta.

Every column of a quantity carries its unit in the name, ``peak_ship_slip [m]``,
``median [m/s^2]``, ``median_g [g]``; ``[-]`` marks a dimensionless number. The values are those
stored in the file (SI, plus the display-unit copies the pipeline wrote); nothing is recomputed.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd
import xarray as xr

__all__ = ["fragility_table", "run_table", "write_csv"]

#: Dimensions of a result that are not swept parameters.
_GRID_DIMS = ("record", "im_level", "limit_state")


def _column(name: str, var: xr.DataArray) -> str:
    """``name [unit]`` for a number, ``[-]`` for a dimensionless one, ``name`` otherwise."""
    if var.dtype.kind not in "fiu":
        return name
    units = str(var.attrs.get("units", "")).strip()
    if units in ("", "1"):
        return f"{name} [-]"
    return f"{name} [{units}]"


def _run_dims(ds: xr.Dataset) -> tuple[str, ...]:
    """The dimensions of one run: record, IM level (if scaled) and the swept parameters."""
    swept = [d for d in ds["median"].dims if d not in _GRID_DIMS]
    return ("record", *(["im_level"] if "im_level" in ds.dims else []), *swept)


def run_table(ds: xr.Dataset) -> pd.DataFrame:
    """One row per run: its coordinates, demands, scaling, failure and exceedances.

    Parameters
    ----------
    ds : xarray.Dataset
        A result of :func:`~shipblock.fragility.pipeline.run_pipeline`.

    Returns
    -------
    pandas.DataFrame
        Columns: ``record``, the IM level (``im_level [m/s^2]`` and its display copy such as
        ``im_level_g [g]``) and each swept parameter with its unit, then every per-run
        variable (``peak_ship_slip [m]``, ``scale_factor [-]``, ...), then
        ``exceeded:NAME`` and ``valid:NAME`` per limit state.
    """
    dims = _run_dims(ds)
    columns = {}
    index = pd.MultiIndex.from_product([ds[d].values for d in dims], names=dims).to_frame(
        index=False)
    for dim in dims:
        columns[_column(dim, ds[dim])] = index[dim].to_numpy()
        for name, coord in ds.coords.items():  # display copies, e.g. im_level_g
            if name != dim and coord.dims == (dim,):
                columns[_column(name, coord)] = coord.values[
                    pd.Index(ds[dim].values).get_indexer(index[dim])]
    # a variable the same for every swept value (the achieved IM...) repeats along the sweep
    template = xr.DataArray(np.zeros([ds.sizes[d] for d in dims]), dims=dims)

    def flat(da):
        return xr.broadcast(da, template)[0].transpose(*dims).values.reshape(-1)

    for name, var in ds.data_vars.items():
        if "record" in var.dims and "limit_state" not in var.dims and set(var.dims) <= set(dims):
            columns[_column(name, var)] = flat(var)
    for ls in ds["limit_state"].values:
        for what in ("exceeded", "valid"):
            if what in ds:
                columns[f"{what}:{ls}"] = flat(ds[what].sel(limit_state=ls, drop=True))
    return pd.DataFrame(columns)


def fragility_table(ds: xr.Dataset) -> pd.DataFrame:
    """One row per limit state (and swept value): definition and fitted lognormal curve.

    Parameters
    ----------
    ds : xarray.Dataset
        A result of :func:`~shipblock.fragility.pipeline.run_pipeline`.

    Returns
    -------
    pandas.DataFrame
        Columns ``limit_state``, the swept parameters, ``edp``, ``condition``, ``threshold``,
        ``threshold_units``, then every fitted variable with its unit (``median [m/s^2]``,
        ``median_lower [m/s^2]``, ``median_upper [m/s^2]``, ``beta [-]``, the display copies
        such as ``median_g [g]``, ``n_fit_records [-]``, ``fit_method``, ``fit_error``).
    """
    dims = tuple(ds["median"].dims)
    index = pd.MultiIndex.from_product([ds[d].values for d in dims], names=dims).to_frame(
        index=False)
    columns = {}
    for dim in dims:
        columns[_column(dim, ds[dim]) if dim != "limit_state" else dim] = index[dim].to_numpy()
    ls = index["limit_state"].to_numpy()
    for key, coord in (("edp", "limit_state_edp"), ("condition", "limit_state_condition"),
                       ("threshold", "limit_state_threshold")):
        if coord in ds.coords:
            columns[key] = ds[coord].sel(limit_state=ls).values
    if "limit_state_edp" in ds.coords:
        columns["threshold_units"] = [
            str(ds[edp].attrs.get("units", "")) if edp in ds else ""
            for edp in ds["limit_state_edp"].sel(limit_state=ls).values]
    for name, var in ds.data_vars.items():
        if set(var.dims) == set(dims):
            values = var.transpose(*dims).values.reshape(-1)
            columns[_column(name, var)] = values
    return pd.DataFrame(columns)


def write_csv(ds: xr.Dataset, directory) -> list[Path]:
    """Write ``runs.csv`` (:func:`run_table`) and ``fragility.csv`` (:func:`fragility_table`).

    Parameters
    ----------
    ds : xarray.Dataset
        A result of :func:`~shipblock.fragility.pipeline.run_pipeline`.
    directory : str or Path
        Folder to write to (created if missing); existing tables there are replaced.

    Returns
    -------
    list of Path
        The files written.
    """
    out = Path(directory)
    out.mkdir(parents=True, exist_ok=True)
    written = []
    for name, table in (("runs.csv", run_table(ds)), ("fragility.csv", fragility_table(ds))):
        path = out / name
        partial = path.with_name(path.name + ".part")
        # floats as their shortest round-trip text: the file's values, to be read back
        table.to_csv(partial, index=False, na_rep="nan")
        partial.replace(path)
        written.append(path)
    return written

