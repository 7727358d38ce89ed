"""Figures of a study (:func:`shipblock.run_pipeline`): fragility curves, IDA curves and the
fitted median against a swept parameter, each titled with the study, system and design it
shows (:func:`study_caption`)."""

from __future__ import annotations

import difflib
import json
from pathlib import PurePath

import numpy as np
from matplotlib.transforms import ScaledTranslation

from shipblock.errors import ParameterError
from shipblock.fragility.report import display_units, im_label, swept_unit
from shipblock.fragility.store import dataset_model
from shipblock.models import DEFAULT_MODEL, get_model
from shipblock.plot._common import _new_axes, _title

_DESIGN_NAMES = {"ida": "IDA", "msa": "MSA", "cloud": "cloud"}
_VERTICAL_TEXT = {"same": "vertical scaled with the horizontal",
                  "independent": "vertical scaled to its own levels",
                  "unscaled": "vertical as recorded", "zero": "no vertical"}


def study_caption(ds, sweep=None) -> list[str]:
    """What study, system and design a result shows: three lines for a figure's title.

    The study is the pipeline's ``title`` and file (attributes ``title`` and
    ``pipeline_source``); the system is the pipeline's, with the swept values drawn
    (``sweep``) applied (:meth:`Model.vary <shipblock.models.base.Model.vary>` of the model that
    wrote it, :func:`~shipblock.fragility.store.dataset_model`, named by its
    :meth:`~shipblock.models.base.Model.caption`); the design names
    the analysis (IDA, MSA or cloud), the measure, the records and levels run, and the
    vertical.

    Parameters
    ----------
    ds : xarray.Dataset
        A result of :func:`shipblock.run_pipeline`.
    sweep : dict, optional
        Swept parameter -> value drawn (:func:`sweep_selection`).

    Returns
    -------
    list of str
        ``[study, "system: ...", "design: ..."]``; a line whose attributes are missing (a file
        of an older version) is left out.
    """
    lines = []
    title = str(ds.attrs.get("title", "")).strip()
    source = str(ds.attrs.get("pipeline_source", "")).strip()
    if source and (PurePath(source).is_absolute() or len(source) > 40):
        source = PurePath(source).name
    if title or source:
        lines.append(title + (f" ({source})" if source and title else source))
    model = dataset_model(ds)
    if "system" in ds.attrs and model is not None:
        system = model.restore(json.loads(ds.attrs["system"]))
        if sweep:
            system = model.vary(system, {k: _plain(v) for k, v in dict(sweep).items()})
        lines.append("system: " + model.caption(system))
    kind = str(ds.attrs.get("design_type", ""))
    if kind:
        measure = im_label(ds).rsplit(" [", 1)[0]
        n_rec = int(ds.attrs.get("n_records_used", ds.sizes.get("record", 0)))
        text = f"design: {_DESIGN_NAMES.get(kind, kind)} on {measure}, {n_rec} records"
        if "im_level" in ds.coords:
            levels, _, _ = _im_axis(ds, ds["im_level"].values)
            unit = display_units(ds)[0]
            text += (f" x {levels.size} levels ({levels.min():.3g} to {levels.max():.3g} {unit})")
        else:
            text += " at their own intensity"
        vertical = _VERTICAL_TEXT.get(str(ds.attrs.get("vertical_mode", "")))
        if vertical:
            text += f"; {vertical}"
        lines.append(text)
    return lines


def _plain(value):
    """A numpy scalar of a coordinate as a Python number (a model's checks want those)."""
    return value.item() if isinstance(value, np.generic) else value


def _im_axis(ds, values):
    """IM values for display in the pipeline's unit (g for ``levels_g``): (values, label, factor)."""
    unit, factor = display_units(ds)
    return np.asarray(values, float) / factor, im_label(ds), factor


def sweep_selection(ds, sweep=None) -> dict:
    """The value of every swept parameter to draw: those named, the first of the others.

    Parameters
    ----------
    ds : xarray.Dataset
        A result of :func:`shipblock.run_pipeline`.
    sweep : dict, optional
        Swept parameter -> value; a number is matched to the study's within 1e-9 relative, a
        name (a string dimension such as ``cap_material``) exactly.

    Returns
    -------
    dict
        Every swept parameter -> the study's value (as stored).

    Raises
    ------
    ValueError
        If a name is not a swept parameter of the study or a value is not one of its values
        (the message lists them).
    """
    swept = [d for d in ds["median"].dims if d != "limit_state"] if "median" in ds else []
    sweep = dict(sweep or {})
    unknown = [k for k in sweep if k not in swept]
    if unknown:
        raise ParameterError(
            f"{unknown[0]!r} is not a swept parameter of this study"
            + (f"; swept: {', '.join(swept)}" if swept else " (it sweeps none)"))
    out = {}
    for dim in swept:
        values = ds[dim].values
        if dim not in sweep:
            out[dim] = values[0]
            continue
        if values.dtype.kind in "US":  # a string dimension (a choice): the name itself
            close = np.flatnonzero(values == str(sweep[dim]))
            shown = ", ".join(map(repr, values.tolist()))
        else:
            shown = ", ".join(f"{v:g}" for v in values)
            try:
                wanted = float(sweep[dim])
            except (TypeError, ValueError):
                raise ParameterError(f"{dim} = {sweep[dim]!r} is not a number; values: "
                                     f"{shown}") from None
            close = np.flatnonzero(np.isclose(values.astype(float), wanted, rtol=1e-9,
                                              atol=0.0))
        if close.size != 1:
            raise ParameterError(f"{dim} = {sweep[dim]!r} is not a value of the study; values: "
                                 f"{shown}")
        out[dim] = values[close[0]]
    return out


def _select_sweep(da, sweep):
    """``da`` at one value of every swept dimension (``sweep`` from :func:`sweep_selection`)."""
    sel = {dim: value for dim, value in (sweep or {}).items() if dim in da.dims}
    da = da.sel(sel)
    for dim in list(da.dims):
        if dim not in ("record", "im_level", "limit_state"):
            da = da.isel({dim: 0})
    return da


def sweep_text(sweep, ds=None) -> str:
    """``"mu_ground = 0.5, side_offset = 3 m"``: the swept values drawn, for titles.

    With the result ``ds``, each value carries the unit of its coordinate (none for a
    dimensionless one), so that a title never shows a length without its unit.
    """
    def one(k, v):
        text = f"{k} = {v:g}" if isinstance(v, float | int | np.number) else f"{k} = {v}"
        unit = swept_unit(ds, k) if ds is not None else ""
        return f"{text} {unit}" if unit else text

    return ", ".join(one(k, v) for k, v in (sweep or {}).items())


_CONDITION_SYMBOLS = {"greater": ">", "greater_equal": ">=", "equal": "=", "nonzero": "!= 0"}


def limit_state_text(ds, name) -> str:
    """``"peak_ship_slip > 0.02 m"``: the definition of a limit state, for legends."""
    if "limit_state_edp" not in ds.coords:
        return str(name)
    sel = ds.sel(limit_state=name)
    edp = str(sel["limit_state_edp"].values)
    condition = str(sel["limit_state_condition"].values)
    threshold = float(sel["limit_state_threshold"].values)
    symbol = _CONDITION_SYMBOLS.get(condition, condition)
    if condition == "nonzero" or not np.isfinite(threshold):
        return f"{edp} {symbol}"
    units = ds[edp].attrs.get("units", "") if edp in ds else ""
    units = "" if units in ("1", "") else f" {units}"
    return f"{edp} {symbol} {threshold:g}{units}"


#: Marker of each limit state's observed fractions (the curves are told apart by colour; the
#: markers also where fractions coincide).
_MARKERS = ("o", "s", "^", "D", "v", "P", "X", "<", ">", "h")


#: Sideways offset between the medians of successive limit states in
#: :func:`plot_median_sweep`, as a fraction of the swept parameter's range [-].
DODGE = 0.012

#: Marker size of the innermost observed fractions [pt]; each limit state before it is
#: :data:`MARKER_STEP` larger, so that coinciding fractions nest (see :func:`plot_fragility`).
MARKER_SIZE = 5.0
MARKER_STEP = 2.2


def marker_sizes(n: int) -> list[float]:
    """Marker size of each of ``n`` limit states: the first the largest, the last
    :data:`MARKER_SIZE` (nested hollow markers)."""
    return [MARKER_SIZE + MARKER_STEP * (n - 1 - i) for i in range(n)]


def plot_fragility(ds, limit_state=None, ax=None, sweep=None):
    """Fitted lognormal fragility curves with the observed fractions of exceedance.

    The title says which study (pipeline title and file), system (with the swept values drawn)
    and design (analysis, measure, records x levels) the figure shows (:func:`study_caption`),
    then what is drawn: the bootstrap band is named only when one is drawn. The legend gives
    each limit state's definition (EDP, condition, threshold with its units) and fit.

    The observed fractions are drawn at the intensity they were observed at, not moved
    sideways: a report's reader takes values off the figure, and a marker moved by a few
    hundredths of a g would misplace the point it stands for. Fractions of different limit
    states that coincide (typically 0 and 1 at the ends) stay visible as *nested* hollow
    markers: each limit state has its own shape, and the first is the largest
    (:func:`marker_sizes`), so a small triangle inside a larger square inside a circle reads
    as "all three". The title says so.

    Parameters
    ----------
    ds : xarray.Dataset
        Result of :func:`shipblock.run_pipeline` (``exceeded``, ``valid``, ``median``, ``beta``
        and, when bootstrapped, ``median_lower``/``median_upper``).
    limit_state : str or sequence of str, optional
        Limit states to draw (default all).
    ax : matplotlib Axes, optional
    sweep : dict, optional
        Value of each swept parameter to draw (default: the first of each;
        :func:`sweep_selection`).

    Returns
    -------
    matplotlib.axes.Axes
    """
    from matplotlib.lines import Line2D
    from scipy.stats import norm

    if ax is None:
        _, axs = _new_axes(1, height=4.6)
        ax = axs[0]
    sweep = sweep_selection(ds, sweep)
    names = list(ds["limit_state"].values)
    if limit_state is not None:
        names = [limit_state] if isinstance(limit_state, str) else list(limit_state)
    scaled = "im_level" in ds.coords
    x_obs_si = ds["im_level"].values if scaled else None
    # the axis covers the levels run (IDA) or the intensities achieved (cloud)
    x_max = 1.15 * float(np.nanmax(x_obs_si if scaled else ds["achieved_im"].values))
    x_si = np.linspace(x_max / 400, x_max, 400)
    x_plot, xlabel, _ = _im_axis(ds, x_si)
    sizes = marker_sizes(len(names))
    n_per_level = None
    handles = []
    band_drawn = any_fitted = False
    for i, name in enumerate(names):
        c = f"C{i % 10}"
        marker = _MARKERS[i % len(_MARKERS)]
        median = float(_select_sweep(ds["median"].sel(limit_state=name), sweep))
        beta = float(_select_sweep(ds["beta"].sel(limit_state=name), sweep))
        desc = f"{name} ({limit_state_text(ds, name)})"
        fitted = np.isfinite(median) and np.isfinite(beta) and beta > 0
        if fitted:
            med_plot, _, _ = _im_axis(ds, [median])
            desc += f": median {med_plot[0]:.3g} {display_units(ds)[0]}, beta {beta:.2f}"
        else:
            desc += ": no fit"
        handles.append(Line2D([], [], color=c, lw=1.8 if fitted else 0, marker=marker,
                              mfc="white", mew=1.5, ms=sizes[i], label=desc))
        any_fitted = any_fitted or fitted
        if fitted:
            ax.plot(x_plot, norm.cdf(np.log(x_si / median) / beta), color=c, lw=1.8)
            if "median_lower" in ds:
                lo = float(_select_sweep(ds["median_lower"].sel(limit_state=name), sweep))
                hi = float(_select_sweep(ds["median_upper"].sel(limit_state=name), sweep))
                if np.isfinite(lo) and np.isfinite(hi):
                    band_drawn = True
                    ax.fill_between(x_plot, norm.cdf(np.log(x_si / hi) / beta),
                                    norm.cdf(np.log(x_si / lo) / beta), color=c, alpha=0.15,
                                    lw=0)
        if scaled:
            ex = _select_sweep(ds["exceeded"].sel(limit_state=name), sweep)
            ok = _select_sweep(ds["valid"].sel(limit_state=name), sweep)
            n_ex = (ex & ok).sum("record").values
            n = ok.sum("record").values
            if n_per_level is None:
                n_per_level = n
            frac = np.where(n > 0, n_ex / np.maximum(n, 1), np.nan)
            xo, _, _ = _im_axis(ds, x_obs_si)
            # at the level itself; the first limit state's marker the largest (nested)
            ax.plot(xo, frac, marker, color=c, ms=sizes[i], mfc="none", mew=1.5, zorder=3 + i)
        else:
            # a cloud: each record's outcome (1 exceeded, 0 not) at the intensity it had
            ex = _select_sweep(ds["exceeded"].sel(limit_state=name), sweep)
            ok = _select_sweep(ds["valid"].sel(limit_state=name), sweep).values
            im = _select_sweep(ds["achieved_im"], sweep).values
            xo, _, _ = _im_axis(ds, im[ok])
            ax.plot(xo, ex.values[ok].astype(float), marker, color=c, ms=sizes[i], mfc="none",
                    mew=1.5, zorder=3 + i)
    ax.set_xlabel(xlabel)
    ax.set_ylabel("probability of exceedance")
    ax.set_ylim(-0.03, 1.03)
    ax.set_xlim(0, x_plot[-1])
    ax.grid(True, lw=0.3, alpha=0.5)
    curves = ("fragility: lines: lognormal fit" if any_fitted
              else "fragility: no curve could be fitted (the legend says which)")
    if band_drawn:
        conf = ds["median_lower"].attrs.get("confidence")
        curves += ("; shaded: " + (f"{100 * float(conf):g} % " if conf is not None else "")
                   + "bootstrap band of the median")
    if sweep:
        curves += f"; drawn at {sweep_text(sweep, ds)}"
    what = [curves]
    if n_per_level is not None:
        counts = np.unique(n_per_level)
        per_level = (f"{int(counts[0])} records per level" if counts.size == 1 else
                     "records per level: " + ", ".join(str(int(k)) for k in n_per_level))
        what.append(f"markers: fraction of the {per_level} exceeding, at the level itself "
                    "(not shifted; coinciding ones nest, largest first)")
    else:
        n_rec = int(ds["valid"].sel(limit_state=names[0]).pipe(_select_sweep, sweep).sum())
        what.append(f"markers: each of the {n_rec} records' outcome (1: exceeded, 0: not) at "
                    "its own intensity (coinciding ones nest, largest first)")
    _title(ax, study_caption(ds, sweep), what)
    ax.legend(handles=handles, fontsize=7.5, loc="best")
    return ax


def plot_median_sweep(ds, parameter=None, limit_state=None, ax=None, sweep=None):
    """Fitted median against a swept parameter, with its bootstrap band, per limit state.

    Limit states are drawn side by side (offset by :data:`DODGE` of the parameter's range), so
    that equal medians and their bars stay visible: the swept values are a few known settings
    (the ticks), not a measured abscissa, so the offset misplaces nothing, and the title says
    it. The legend names the values where a fit failed; the title the study, system and design
    (:func:`study_caption`; the system with the other swept values drawn). A string dimension
    (names, such as the section model's ``cap_material``) is drawn at one tick per name, its
    medians unjoined; the bars run from the band's lower to its upper bound (a bootstrap band
    need not contain the fitted median).

    Parameters
    ----------
    ds : xarray.Dataset
        Result of :func:`shipblock.run_pipeline` of a study with a ``[sweep]``.
    parameter : str, optional
        The swept parameter on the x axis (default: the first).
    limit_state : str or sequence of str, optional
        Limit states to draw (default all).
    ax : matplotlib Axes, optional
    sweep : dict, optional
        Values of the other swept parameters (default: the first of each); named in the title.

    Returns
    -------
    matplotlib.axes.Axes

    Raises
    ------
    ValueError
        If the study sweeps nothing or ``parameter`` is not swept.
    """
    swept = [d for d in ds["median"].dims if d != "limit_state"]
    if not swept:
        raise ParameterError("the study sweeps no parameter: nothing to draw the median against")
    parameter = parameter or swept[0]
    if parameter not in swept:
        raise ParameterError(f"{parameter!r} is not a swept parameter; swept: {', '.join(swept)}")
    others = sweep_selection(ds, {k: v for k, v in (sweep or {}).items() if k != parameter})
    others.pop(parameter, None)
    if ax is None:
        _, axs = _new_axes(1, height=3.6)
        ax = axs[0]
    names = list(ds["limit_state"].values)
    if limit_state is not None:
        names = [limit_state] if isinstance(limit_state, str) else list(limit_state)
    values = ds[parameter].values
    # a string dimension (a choice such as cap_material): one position per name, named ticks
    categorical = values.dtype.kind in "US"
    x = np.arange(values.size, dtype=float) if categorical else values.astype(float)
    span = float(np.ptp(x)) or 1.0
    _, ylabel, factor = _im_axis(ds, [])
    bars_drawn = False
    for i, name in enumerate(names):
        c = f"C{i % 10}"
        # limit states with equal medians side by side
        xd = x + DODGE * span * (i - (len(names) - 1) / 2)
        med = ds["median"].sel(limit_state=name).sel(others).values / factor
        label = f"{name} ({limit_state_text(ds, name)})"
        missing = [str(v) if categorical else f"{v:g}"
                   for v, m in zip(values, med, strict=True) if not np.isfinite(m)]
        if missing:
            unit = swept_unit(ds, parameter)
            label += (f"; not fitted at {parameter} = {', '.join(missing)}"
                      + (f" {unit}" if unit and not categorical else ""))
        # names have no order between them: no line joins their medians
        ax.plot(xd, med, ("" if categorical else "-") + _MARKERS[i % len(_MARKERS)], color=c,
                lw=1.5, ms=5,
                mfc="white", mew=1.5, label=label)
        if "median_lower" in ds:
            lo = ds["median_lower"].sel(limit_state=name).sel(others).values / factor
            hi = ds["median_upper"].sel(limit_state=name).sel(others).values / factor
            bars_drawn = bars_drawn or bool(np.isfinite(lo).any() and np.isfinite(hi).any())
            # bars from bound to bound: a bootstrap band need not contain the fitted median
            # (a skewed or few-record bootstrap), which errorbar's yerr cannot draw
            ax.vlines(xd, lo, hi, colors=c, lw=1)
            ax.plot(np.r_[xd, xd], np.r_[lo, hi], "_", color=c, ms=6)
    if categorical:
        ax.set_xticks(x, [str(v) for v in values], fontsize=7.5)
        ax.set_xlim(-0.5, values.size - 0.5)
    units = ds[parameter].attrs.get("units", "")
    long_name = ds[parameter].attrs.get("long_name", "").replace("swept parameter: ", "")
    ax.set_xlabel(f"{parameter}" + ("" if categorical else
                                    f" [{units if units not in ('', '1') else '-'}]")
                  + (f": {long_name}" if long_name else ""))
    ax.set_ylabel(f"median {ylabel}")
    ax.grid(True, lw=0.3, alpha=0.5)
    what = f"fitted median against {parameter}"
    if bars_drawn:
        conf = ds["median_lower"].attrs.get("confidence")
        what += "; bars: " + (f"{100 * float(conf):g} % " if conf is not None else "") \
            + "bootstrap band"
    if len(names) > 1:
        what += (f"; limit states side by side, {100 * DODGE:g} % of the "
                 + ("span of the names" if categorical else f"{parameter} range") + " apart")
    if others:
        what += f"; drawn at {sweep_text(others, ds)}"
    # the system line holds the base value of the parameter on the x axis: say it is swept
    caption = [line + (f"; {parameter} swept (x axis)" if line.startswith("system: ") else "")
               for line in study_caption(ds, others)]
    _title(ax, caption, [what])
    # under the axes: inside, the long labels of several limit states cover their markers
    # (half an inch below the axes' bottom, clear of the tick labels and the axis label)
    below = ax.transAxes + ScaledTranslation(0.0, -0.5, ax.figure.dpi_scale_trans)
    ax.legend(fontsize=7.5, loc="upper center", bbox_to_anchor=(0.5, 0.0),
              bbox_transform=below, ncol=2, borderaxespad=0.0)
    return ax


def numeric_edps(ds) -> list[str]:
    """The float and count EDPs of the results' model that the results hold."""
    model = dataset_model(ds) or get_model(DEFAULT_MODEL)
    return [k for k, info in model.edps.items() if k in ds and info.kind in ("float", "count")]


def default_edp(ds) -> str:
    """The EDP a figure of the results shows when none is named: the model's
    :attr:`~shipblock.models.base.Model.default_edp` if the results hold it, else the first
    numeric one."""
    model = dataset_model(ds) or get_model(DEFAULT_MODEL)
    valid = numeric_edps(ds)
    if model.default_edp in valid or not valid:
        return model.default_edp or ""
    return valid[0]


def failures_text(ds) -> str:
    """``"separation, overturning"``: the failure kinds of the results' model."""
    model = dataset_model(ds) or get_model(DEFAULT_MODEL)
    return ", ".join(what for code, what in model.failure_codes.items()
                     if code and code != model.solver_error_code)


def check_edp(ds, edp, name="edp") -> str:
    """``edp`` if the results hold it as a numeric demand parameter, else a ParameterError
    naming ``name`` (a keyword or a flag), the closest valid name and all of them.

    The valid names are the EDPs of the results' model
    (:attr:`Model.edps <shipblock.models.base.Model.edps>`, :func:`dataset_model`) of kind
    float or count that the results hold.
    """
    valid = numeric_edps(ds)
    if edp in valid:
        return edp
    close = difflib.get_close_matches(str(edp), valid, n=1)
    raise ParameterError(f"{name} {edp!r} is not a demand parameter of these results"
                         + (f" (did you mean {close[0]!r}?)" if close else "")
                         + f"; valid: {', '.join(valid)}")


def plot_ida(ds, edp=None, ax=None, sweep=None):
    """IDA curves: the demand ``edp`` of each record against the intensity it was scaled to.

    Runs that failed (separation, overturning) are marked with a cross at the right edge. The
    title says which study, system and design the curves come from (:func:`study_caption`).

    Parameters
    ----------
    ds : xarray.Dataset
        Result of :func:`shipblock.run_pipeline` of an IDA or MSA study.
    edp : str, optional
        The demand on the x axis (a ParameterError lists the valid names: :func:`check_edp`);
        default: the model's :attr:`~shipblock.models.base.Model.default_edp`
        (``peak_ship_slip`` for the rigid model, ``keel_load_ratio`` for the section model).
    ax : matplotlib Axes, optional
    sweep : dict, optional
        Value of each swept parameter to draw (default: the first of each); named in the title.

    Returns
    -------
    matplotlib.axes.Axes
    """
    edp = default_edp(ds) if edp is None else edp
    check_edp(ds, edp)
    if ax is None:
        _, axs = _new_axes(1, height=4.0)
        ax = axs[0]
    sweep = sweep_selection(ds, sweep)
    demand = _select_sweep(ds[edp], sweep)
    failure = _select_sweep(ds["failure"], sweep) if "failure" in ds else None
    im_si = ds["achieved_im"].values
    units = ds[edp].attrs.get("units", "")
    scale, unit_label = (100.0, "cm") if units == "m" else (1.0, units)
    finite = demand.values[np.isfinite(demand.values)]
    x_fail = (finite.max() * scale * 1.1) if finite.size else 1.0
    for i, rec in enumerate(ds["record"].values):
        y, ylabel, _ = _im_axis(ds, im_si[i])
        x = demand.sel(record=rec).values * scale
        c = f"C{i % 10}"
        failed = (failure.sel(record=rec).values > 0) if failure is not None else np.zeros(x.size, bool)
        ax.plot(np.where(failed, np.nan, x), y, "-o", color=c, ms=3.5, lw=1.2,
                label=str(rec).split("/")[-1])
        ax.plot(np.full(failed.sum(), x_fail), y[failed], "x", color=c, ms=7, mew=2)
    ax.set_xlabel(f"{ds[edp].attrs.get('long_name', edp)} [{unit_label}]")
    ax.set_ylabel(ylabel)
    ax.grid(True, lw=0.3, alpha=0.5)
    what = (f"IDA curves: {ds[edp].attrs.get('long_name', edp)} of each record against the "
            f"intensity it was scaled to; x: a failed run ({failures_text(ds)}), drawn at the "
            f"right edge")
    if sweep:
        what += f"; drawn at {sweep_text(sweep, ds)}"
    _title(ax, study_caption(ds, sweep), [what])
    ax.legend(fontsize=8, ncol=2)
    return ax
