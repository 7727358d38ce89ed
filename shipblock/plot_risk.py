"""Figures of the risk over a docking period: the hazard with the fragilities, and the
deaggregation of each limit state's annual rate over the intensity.

The functions take a dataset of :func:`shipblock.risk.risk_dataset` (or the file ``shipblock
risk`` writes, opened), draw into given axes or a new figure, and return the axes. Intensities
are shown in the study's unit (g for a study written with ``levels_g``); the data stay SI.
"""

from __future__ import annotations

import numpy as np
from scipy.special import ndtr

from shipblock.errors import ParameterError
from shipblock.fragility.report import display_units
from shipblock.plot import sweep_text, sweep_selection

__all__ = ["plot_deaggregation", "plot_hazard_and_fragility", "plot_risk"]


def _check(ds):
    if "risk_deaggregation" not in ds:
        raise ParameterError("the dataset holds no risk (risk_deaggregation): make it with "
                             "shipblock.risk.run_risk or 'shipblock risk'")


def _at(da, sweep):
    """``da`` at the swept values of ``sweep`` (from :func:`~shipblock.plot.sweep_selection`)."""
    return da.sel({dim: value for dim, value in sweep.items() if dim in da.dims})


def _limit_states(ds, limit_state):
    names = [str(n) for n in ds["limit_state"].values]
    if limit_state is None:
        return names
    wanted = [limit_state] if isinstance(limit_state, str) else list(limit_state)
    unknown = [n for n in wanted if n not in names]
    if unknown:
        raise ParameterError(f"limit state {unknown[0]!r} is not in the study; limit states: "
                             f"{', '.join(names)}")
    return wanted


def plot_deaggregation(ds, limit_state=None, ax=None, sweep=None):
    r"""Share of each limit state's annual rate contributed by each bin of the hazard's levels.

    A step line per limit state over the bins of the hazard curve's levels (log axis): the
    height is :math:`D_i / \lambda_{LS}` in percent (:mod:`shipblock.risk.integral`), so each
    line sums to 100 %. The bins beyond the curve's first and last levels are drawn as one
    half-decade step each, hatched when they hold more than 1 %.

    Parameters
    ----------
    ds : xarray.Dataset
        With the risk variables.
    limit_state : str or list of str, optional
        Default: all.
    ax : matplotlib.axes.Axes, optional
    sweep : dict, optional
        Swept parameter -> value (default: the first of each).

    Returns
    -------
    matplotlib.axes.Axes
    """
    import matplotlib.pyplot as plt

    _check(ds)
    sweep = sweep_selection(ds, sweep)
    unit, factor = display_units(ds)
    if ax is None:
        _, ax = plt.subplots(figsize=(7.5, 4.0), constrained_layout=True)
    lower = ds["hazard_bin_lower"].values / factor
    upper = ds["hazard_bin_upper"].values / factor
    # the open end bins drawn over half a decade
    lower[0] = upper[0] / 10**0.5
    upper[-1] = lower[-1] * 10**0.5
    for name in _limit_states(ds, limit_state):
        contribution = _at(ds["risk_deaggregation"].sel(limit_state=name), sweep).values
        total = float(np.nansum(contribution))
        if not np.isfinite(total) or total <= 0.0:
            continue
        share = 100.0 * contribution / total
        edges = np.concatenate([lower, upper[-1:]])
        line = ax.stairs(share, edges, label=name, lw=1.6)
        for i in (0, share.size - 1):
            if share[i] > 1.0:
                ax.bar(lower[i], share[i], width=upper[i] - lower[i], align="edge", fill=False,
                       hatch="//", edgecolor=line.get_edgecolor(), lw=0.0)
    ax.set_xscale("log")
    ax.set_xlabel(f"{ds.attrs.get('hazard_measure', 'IM')} [{unit}]")
    ax.set_ylabel("share of the annual rate [%]")
    ax.set_ylim(bottom=0.0)
    ax.grid(True, which="both", alpha=0.3)
    if ax.get_legend_handles_labels()[0]:
        ax.legend(fontsize="small")
    title = "deaggregation over the intensity"
    if sweep:
        title += f" ({sweep_text(sweep, ds)})"
    ax.set_title(title, fontsize="medium")
    return ax


def plot_hazard_and_fragility(ds, limit_state=None, ax=None, sweep=None):
    """The site hazard curve (left axis, log) and the fitted fragility curves (right axis).

    Parameters
    ----------
    ds : xarray.Dataset
        With the risk variables.
    limit_state : str or list of str, optional
        Default: all.
    ax : matplotlib.axes.Axes, optional
    sweep : dict, optional

    Returns
    -------
    tuple of matplotlib.axes.Axes
        The hazard's axes and the fragilities' (twin) axes.
    """
    import matplotlib.pyplot as plt

    _check(ds)
    sweep = sweep_selection(ds, sweep)
    unit, factor = display_units(ds)
    if ax is None:
        _, ax = plt.subplots(figsize=(7.5, 4.0), constrained_layout=True)
    x = ds["hazard_im"].values / factor
    rate = ds["hazard_rate"].values
    positive = rate > 0
    ax.loglog(x[positive], rate[positive], "k.-", label="site hazard (left axis)")
    ax.set_xlabel(f"{ds.attrs.get('hazard_measure', 'IM')} [{unit}]")
    ax.set_ylabel("annual rate of exceedance [1/yr]")
    ax.grid(True, which="both", alpha=0.3)
    twin = ax.twinx()
    grid = np.geomspace(x[0], x[-1], 300)
    for name in _limit_states(ds, limit_state):
        median = float(_at(ds["median"].sel(limit_state=name), sweep)) / factor
        beta = float(_at(ds["beta"].sel(limit_state=name), sweep))
        if np.isfinite(median) and np.isfinite(beta):
            twin.plot(grid, ndtr(np.log(grid / median) / beta), label=name)
    twin.set_ylim(0.0, 1.0)
    twin.set_ylabel("P(limit state | IM)")
    # one legend for both axes, on the twin (drawn above the hazard's axes): the hazard curve
    # first, then each limit state's fragility; centre left, where a hazard curve falling
    # from the top left and fragilities rising at the right leave the axes empty (lower left
    # covered the fragilities' zero line)
    hazard, fragilities = ax.get_legend_handles_labels(), twin.get_legend_handles_labels()
    twin.legend(hazard[0] + fragilities[0], hazard[1] + fragilities[1], fontsize="small",
                loc="center left")
    site = ds.attrs.get("hazard_site", "")
    ax.set_title(f"hazard at {site}" if site else "site hazard", fontsize="medium")
    return ax, twin


def plot_risk(ds, limit_state=None, sweep=None):
    """Both panels in one figure: hazard with fragilities, and the deaggregation.

    Parameters
    ----------
    ds : xarray.Dataset
        With the risk variables.
    limit_state : str or list of str, optional
    sweep : dict, optional

    Returns
    -------
    numpy.ndarray of matplotlib.axes.Axes
        The two main axes.
    """
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(2, 1, figsize=(8.0, 7.5), constrained_layout=True)
    plot_hazard_and_fragility(ds, limit_state, ax=axes[0], sweep=sweep)
    plot_deaggregation(ds, limit_state, ax=axes[1], sweep=sweep)
    days = ds.attrs.get("docking_days")
    fig.suptitle(f"{ds.attrs.get('title', 'study')}: risk"
                 + (f" over a docking period of {float(days):g} days" if days else ""),
                 fontsize="medium")
    return axes
