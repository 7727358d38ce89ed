"""Figures: response histories, records, spectra, IDA and fragility curves.

Every function takes ``ax=None`` (or ``axes=None`` for multi-panel figures), draws into the given
axes or a new figure, and returns what it drew. Nothing here calls ``plt.show()``. Accelerations
are shown in g, displacements in cm and rotations in mrad: the units engineers read at a glance;
the data stay SI.
"""

from __future__ import annotations

import json
import math
import textwrap
from collections.abc import Mapping
from pathlib import PurePath

import numpy as np

from shipblock.errors import ParameterError
from shipblock.fragility.design import apply_parameters
from shipblock.fragility.report import display_units, im_label
from shipblock.modes import MODE_DESCRIPTIONS
from shipblock.system import ShipBlockSystem
from shipblock.units import STANDARD_GRAVITY

#: One colour per mode (1..8), light enough to sit behind the curves.
MODE_COLOURS = {
    1: "#ffffff",
    2: "#cfe3f7",
    3: "#f9d7b5",
    4: "#d5ecd0",
    5: "#b9d3ee",
    6: "#f3c6c6",
    7: "#e6d5f0",
    8: "#f5e9a8",
}
EVENT_STYLES = {
    "impact": dict(color="0.55", lw=0.5, ls="-"),
    "uplift": dict(color="tab:orange", lw=0.8, ls="--"),
    "rocking_stop": dict(color="tab:orange", lw=0.8, ls=":"),
    "ground_slip_start": dict(color="tab:blue", lw=0.6, ls="--"),
    "ground_slip_stop": dict(color="tab:blue", lw=0.6, ls=":"),
    "ship_slip_start": dict(color="tab:green", lw=0.6, ls="--"),
    "ship_slip_stop": dict(color="tab:green", lw=0.6, ls=":"),
    "overturning": dict(color="red", lw=2.0, ls="-"),
    "separation": dict(color="red", lw=2.0, ls="-"),
    "solver_error": dict(color="red", lw=2.0, ls="-."),
}


def _pyplot():
    import matplotlib.pyplot as plt

    return plt


def _new_axes(nrows, sharex=True, height=1.8):
    plt = _pyplot()
    fig, axes = plt.subplots(nrows, 1, sharex=sharex, figsize=(9.0, height * nrows + 0.8),
                             constrained_layout=True)
    return fig, np.atleast_1d(axes)


def mode_spans(time, mode):
    """Contiguous runs of one mode: list of (t_start, t_end, mode)."""
    mode = np.asarray(mode)
    if mode.size == 0:
        return []
    change = np.flatnonzero(np.diff(mode)) + 1
    starts = np.concatenate([[0], change])
    ends = np.concatenate([change, [mode.size - 1]])
    return [(time[s], time[e], int(mode[s])) for s, e in zip(starts, ends, strict=True)]


class _DatasetResponse:
    """Read-only view of a response Dataset (from ``SimulationResult.to_dataset``) for plotting."""

    def __init__(self, ds):
        from shipblock.result import Event

        self.time = ds["time"].values
        self.x_b = ds["x_b"].values
        self.theta = ds["theta"].values
        self.x_s = ds["x_s"].values
        self.mode = ds["mode"].values.astype(int)
        self.ground_acceleration = (ds["ground_acceleration_h"].values,
                                    ds["ground_acceleration_v"].values)
        self.events = [
            Event(float(t), str(k), int(f), int(to))
            for t, k, f, to in zip(ds["event_time"].values, ds["event_kind"].values,
                                   ds["event_from_mode"].values, ds["event_to_mode"].values,
                                   strict=True)
        ]
        failure = ds.attrs.get("failure", "none")
        self.failure = None if failure == "none" else failure
        self.failure_time = float(ds.attrs.get("failure_time_s", float("nan")))
        self.system = {k[len("system_"):]: v for k, v in ds.attrs.items()
                       if k.startswith("system_")}
        self.system["critical_angle"] = math.atan2(float(ds.attrs["system_half_width"]),
                                                   float(ds.attrs["system_half_height"]))
        #: the record line of the title (written by ``shipblock simulate`` and ``history``)
        self.record = str(ds.attrs.get("record_description", ds.attrs.get("record", "")))


def record_text(motion, scale=None) -> str:
    """One line naming a record as a report would: id, station and site, the horizontal used
    (component, channel, azimuth), the event or the start date, and the scale factor.

    Parameters
    ----------
    motion : GroundMotion
        The record as read (its ``metadata``: catalogue, station, channels, azimuths, event,
        the horizontal chosen).
    scale : float or str, optional
        Scale factor applied (a number), or a phrase such as ``"scaled to PGA 0.4 g (factor
        1.03)"``; left out when None.

    Returns
    -------
    str
        e.g. ``"record south-napa-2014/NP.1765 (CA:Napa;FS 3): horizontal H1 = NP.1765..HNN
        (0 deg), event 2014-08-24 10:20:44 UTC Mw 6.02, scale factor 2.6"``.
    """
    md = motion.metadata
    site = (md.get("catalogue") or {}).get("site", "")
    station = md.get("station")
    # GroundMotion.name gives the repr of from_arrays's station dict {"name": ...}
    name = (station["name"] if isinstance(station, Mapping) and station.get("name")
            and not (md.get("catalogue") or {}).get("id") else motion.name)
    text = f"record {name}" + (f" ({site})" if site else "")
    horizontal = str(md.get("horizontal") or "")
    channels = md.get("channels") or {}
    if horizontal in channels:
        az = (md.get("azimuths") or {}).get(horizontal)
        horizontal = f"{horizontal} = {channels[horizontal]}" + (
            f" ({float(az):g} deg)" if az is not None else "")
    if horizontal:
        text += f": horizontal {horizontal}"
    event = md.get("event") or {}
    when = event.get("time") or ""
    if when:
        when = str(when).replace("T", " ")[:19] + " UTC"
        magnitude = event.get("magnitude")
        if magnitude is not None:
            kind = str(event.get("magnitude_type") or "M")
            kind = "Mw" if kind.lower() == "mw" else kind
            when += f" {kind} {float(magnitude):.3g}"
        text += f", event {when}"
    elif motion.starttime.year > 1970:  # 1970-01-01: a start the file does not state
        text += f", start {str(motion.starttime)[:19].replace('T', ' ')} UTC"
    if isinstance(scale, str):
        text += f", {scale}"
    elif scale is not None:
        text += f", scale factor {float(scale):.4g}"
    return text


def active_window(time, acc, events=(), margin=2.0, end=None):
    """Time window holding 1-99 % of the Arias intensity and all events, plus a margin [s].

    ``end`` (e.g. the failure time) cuts the window there: nothing is computed after it.
    """
    energy = np.cumsum(np.asarray(acc, float) ** 2)
    if energy[-1] <= 0:
        return time[0], time[-1]
    frac = energy / energy[-1]
    t0 = time[np.searchsorted(frac, 0.01)]
    t1 = time[min(np.searchsorted(frac, 0.99), time.size - 1)]
    ev = [e.time for e in events if e.kind != "start"]
    if ev:
        t0, t1 = min(t0, min(ev)), max(t1, max(ev))
    if end is not None and np.isfinite(end):
        t1 = min(t1, end)
    return max(time[0], t0 - margin), min(time[-1], t1 + 1.5 * margin)


#: Longest line of a response figure's title [characters] (its font is wider than an axes
#: title's).
SUPTITLE_WIDTH = 140

#: Slip starts and stops are drawn as lines only up to this many (see :func:`plot_response`):
#: none by default, the mode bands show every slip episode and the legend counts them.
MAX_SLIP_EVENT_LINES = 0
#: Impacts likewise (a rocking episode has hundreds, mostly in its Zeno sequences).
MAX_IMPACT_LINES = 40

SLIP_EVENTS = ("ground_slip_start", "ground_slip_stop", "ship_slip_start", "ship_slip_stop")


def _slip_summary(events) -> list[str]:
    """Legend lines counting the slip episodes of each interface (their starts)."""
    out = []
    for start, stop, what in (("ground_slip_start", "ground_slip_stop", "blocks on the floor"),
                              ("ship_slip_start", "ship_slip_stop", "ship on the blocks")):
        n_start = sum(e.kind == start for e in events)
        n_stop = sum(e.kind == stop for e in events)
        if n_start or n_stop:
            out.append(f"{what}: {n_start} slip starts, {n_stop} stops (see the mode bands)")
    return out


def plot_response(result, axes=None, max_event_lines=MAX_IMPACT_LINES, window="auto",
                  max_slip_event_lines=MAX_SLIP_EVENT_LINES, record=None):
    """Response history: ground acceleration, block slip, rotation, ship slip, modes, events.

    The title names the record (``record``, e.g. from :func:`record_text`: station, component,
    event, scale factor), the system (:func:`system_text`) and the outcome (failure or none,
    peaks); the time axis label says which window is shown when it is not the whole record.

    Parameters
    ----------
    result : SimulationResult or xarray.Dataset
        The simulation to draw (or its :meth:`~SimulationResult.to_dataset`; its attribute
        ``record_description``, else ``record``, is the record line).
    axes : sequence of 4 matplotlib Axes, optional
        Panels for ground acceleration, x_b, theta and x_s; a new figure when None.
    max_event_lines : int, optional
        Draw impacts as lines only if there are at most this many: a rocking episode has
        hundreds (mostly in the Zeno sequences that end it), whose lines would hide the curves;
        the rotation's zero crossings show them as well (the legend gives their number).
    max_slip_event_lines : int, optional
        Draw slip starts and stops as lines only if there are at most this many (default
        none): the mode bands show each slip episode already, and the legend counts the starts
        and stops per interface.
    window : "auto", None or (t0, t1), optional
        Time axis limits [s]; "auto" shows 1-99 % of the Arias intensity and every event (up to
        a failure), with 2 s before and 3 s after; None the whole record.
    record : str, optional
        The record line of the title (default: the dataset's, or none for a result).

    Returns
    -------
    numpy.ndarray of Axes
        The four panels.
    """
    if hasattr(result, "data_vars"):
        result = _DatasetResponse(result)
        record = record or result.record
    if axes is None:
        fig, axes = _new_axes(4)
    else:
        axes = np.atleast_1d(axes)
        fig = axes[0].figure
    t = result.time
    ax_g, ax_b, ax_t, ax_s = axes[:4]
    a_h, a_v = result.ground_acceleration
    ax_g.plot(t, a_h / STANDARD_GRAVITY, color="k", lw=0.7, label="horizontal")
    if np.any(a_v):
        ax_g.plot(t, a_v / STANDARD_GRAVITY, color="tab:purple", lw=0.6, alpha=0.8,
                  label="vertical")
    ax_g.set_ylabel("ground acc. [g]")
    ax_g.legend(loc="upper right", fontsize=8, ncol=2)
    ax_b.plot(t, 100 * result.x_b, color="tab:blue", lw=1.0)
    ax_b.set_ylabel("block slip $x_b$ [cm]")
    system = result.system
    theta_c = system["critical_angle"] if isinstance(system, Mapping) else system.critical_angle
    ax_t.plot(t, 1000 * result.theta, color="tab:orange", lw=1.0)
    ax_t.set_ylabel(r"rotation $\theta$ [mrad]")
    peak = np.nanmax(np.abs(result.theta)) if np.isfinite(result.theta).any() else 0.0
    if peak > 0.3 * theta_c:
        for sgn in (1, -1):
            ax_t.axhline(sgn * 1000 * theta_c, color="red", lw=0.8, ls="--")
        # x in axes fraction: the label stays inside whatever time window is shown
        ax_t.text(0.005, 1000 * theta_c, r"$\theta_c$ (overturning)", color="red",
                  va="bottom", fontsize=8, transform=ax_t.get_yaxis_transform())
    ax_s.plot(t, 100 * result.x_s, color="tab:green", lw=1.0)
    ax_s.set_ylabel("ship slip $x_s$ [cm]")
    # modes as coloured bands behind every panel
    spans = mode_spans(t, result.mode)
    seen = set()
    for ax in axes[:4]:
        for t0, t1, m in spans:
            if m != 1 and m != 0:
                ax.axvspan(t0, t1, color=MODE_COLOURS[m], lw=0, zorder=0)
        ax.grid(True, lw=0.3, alpha=0.5)
    for _, _, m in spans:
        seen.add(m)
    # events
    impacts = [e for e in result.events if e.kind == "impact"]
    draw_impacts = len(impacts) <= max_event_lines
    for e in impacts if draw_impacts else ():
        for ax in axes[1:4]:
            ax.axvline(e.time, **EVENT_STYLES["impact"], zorder=1)
    n_slip = sum(e.kind in SLIP_EVENTS for e in result.events)
    draw_slips = n_slip <= max_slip_event_lines
    for e in result.events:
        if e.kind in ("impact", "start") or (e.kind in SLIP_EVENTS and not draw_slips):
            continue
        style = EVENT_STYLES.get(e.kind)
        if style is None:
            continue
        for ax in axes[1:4]:
            ax.axvline(e.time, **style, zorder=1)
    # legend of modes and events in the top panel's figure
    from matplotlib.lines import Line2D
    from matplotlib.patches import Patch

    handles = [Patch(facecolor=MODE_COLOURS[m], edgecolor="0.6", label=f"{m}: {MODE_DESCRIPTIONS[m]}")
               for m in sorted(seen) if m >= 1]
    kinds = {e.kind for e in result.events} - {"start"}
    if not draw_slips:
        kinds -= set(SLIP_EVENTS)
        handles += [Patch(facecolor="none", edgecolor="none", label=line)
                    for line in _slip_summary(result.events)]
    if not draw_impacts:
        kinds.discard("impact")
        # counted as the summary counts them: an impact that ends rocking is one too
        n_stops = sum(e.kind == "rocking_stop" for e in result.events)
        label = f"{len(impacts) + n_stops} impacts: see the zero crossings of theta"
        if n_stops:
            label += f" ({n_stops} ending in rest: rocking stop)"
        handles.append(Patch(facecolor="none", edgecolor="none", label=label))
    handles += [Line2D([], [], **EVENT_STYLES[k], label=k.replace("_", " ")) for k in sorted(kinds)
                if k in EVENT_STYLES]
    if handles:
        axes[3].legend(handles=handles, loc="upper center", bbox_to_anchor=(0.5, -0.35),
                       ncol=3 if len(handles) > 4 else 2, fontsize=7, frameon=False)
    xlabel = "time [s]"
    shown = window
    if window == "auto":
        shown = active_window(t, a_h, result.events, end=result.failure_time)
    if shown is not None:
        axes[0].set_xlim(*shown)
        if shown[0] > t[0] or shown[1] < t[-1]:
            why = ((": 1-99 % of the Arias intensity" + (" up to the failure" if result.failure
                                                         else "") + " and every event, +2/3 s")
                   if window == "auto" else "")
            xlabel += (f"   (shown: {shown[0]:.1f} to {shown[1]:.1f} s of the record's "
                       f"{t[0]:.1f} to {t[-1]:.1f} s{why})")
    ax_s.set_xlabel(xlabel, fontsize=8.5)
    outcome = ("response: no failure" if not result.failure
               else f"response: {result.failure} at t = {result.failure_time:.3f} s")
    outcome += (f"; peaks |x_b| {100 * np.nanmax(np.abs(result.x_b)):.3g} cm, |theta| "
                f"{1000 * peak:.3g} mrad, |x_s| {100 * np.nanmax(np.abs(result.x_s)):.3g} cm")
    lines = [record] if record else []
    lines += ["system: " + system_text(system), outcome]
    fig.suptitle("\n".join(w for line in lines for w in textwrap.wrap(line, SUPTITLE_WIDTH)),
                 fontsize=8.5)
    return axes


def plot_record(motion, axes=None, label=None):
    """Acceleration, velocity and displacement of a ground motion (H and, if present, V).

    Parameters
    ----------
    motion : GroundMotion or tuple
        A :class:`shipblock.motion.GroundMotion`, or ``(horizontal, vertical, dt)`` in m/s^2.
    axes : sequence of 3 Axes, optional
    label : str, optional
        Title.

    Returns
    -------
    numpy.ndarray of Axes
    """
    from shipblock import intensity

    if hasattr(motion, "horizontal"):
        h, v, dt = motion.horizontal, motion.vertical, motion.dt
        label = label or motion.name
    else:
        h, v, dt = motion
    if axes is None:
        fig, axes = _new_axes(3)
    else:
        axes = np.atleast_1d(axes)
        fig = axes[0].figure
    t = np.arange(h.size) * dt
    for acc, name, colour in ((h, "horizontal", "k"), (v, "vertical", "tab:purple")):
        if acc is None:
            continue
        axes[0].plot(t, acc / STANDARD_GRAVITY, color=colour, lw=0.6, label=name)
        axes[1].plot(t, 100 * intensity.velocity(acc, dt), color=colour, lw=0.8)
        axes[2].plot(t, 100 * intensity.displacement(acc, dt), color=colour, lw=0.8)
    axes[0].set_ylabel("acceleration [g]")
    axes[1].set_ylabel("velocity [cm/s]")
    axes[2].set_ylabel("displacement [cm]")
    axes[2].set_xlabel("time [s]")
    axes[0].legend(loc="upper right", fontsize=8)
    for ax in axes:
        ax.grid(True, lw=0.3, alpha=0.5)
    axes[0].set_xlim(*active_window(t, h, margin=3.0))
    if label:
        fig.suptitle(str(label))
    return axes


def plot_spectrum(acc, dt, periods=None, damping=0.05, ax=None, label=None, **line_kw):
    """Pseudo-spectral acceleration Sa(T) [g] of a record (exact for piecewise-linear input).

    Returns
    -------
    matplotlib.axes.Axes
    """
    from shipblock import intensity

    if periods is None:
        periods = np.logspace(-2, 1, 200)
    spec = intensity.response_spectrum(acc, dt, periods, damping)
    if ax is None:
        _, axs = _new_axes(1, height=3.2)
        ax = axs[0]
    ax.plot(spec.periods, spec.psa / STANDARD_GRAVITY, label=label, **line_kw)
    ax.set_xscale("log")
    ax.set_xlabel("period T [s]")
    ax.set_ylabel(f"Sa [g] ({100 * damping:g}% damping)")
    ax.grid(True, which="both", lw=0.3, alpha=0.5)
    if label:
        ax.legend(fontsize=8)
    return ax


def system_text(system) -> str:
    """One line naming a ship-block system as a report would: masses in t, block size in m,
    friction static/kinetic per interface.

    Parameters
    ----------
    system : ShipBlockSystem or Mapping
        The system, or its :meth:`~shipblock.system.ShipBlockSystem.to_dict`.

    Returns
    -------
    str
        e.g. ``"ship 5000 t on 150 blocks of 1.2 t, 2B x 2H = 0.6 x 1.2 m; friction
        blocks-floor 0.6/0.55, ship-blocks 0.35/0.3 (static/kinetic)"``.
    """
    d = system if isinstance(system, Mapping) else system.to_dict()
    return (f"ship {float(d['ship_mass']) / 1e3:.4g} t on {int(d['n_blocks'])} blocks of "
            f"{float(d['block_mass']) / 1e3:.3g} t, 2B x 2H = {2 * float(d['half_width']):.3g} x "
            f"{2 * float(d['half_height']):.3g} m; friction blocks-floor "
            f"{float(d['mu_s_ground']):.3g}/{float(d['mu_k_ground']):.3g}, ship-blocks "
            f"{float(d['mu_s_ship']):.3g}/{float(d['mu_k_ship']):.3g} (static/kinetic)")


_DESIGN_NAMES = {"ida": "IDA", "msa": "MSA", "cloud": "cloud"}
_VERTICAL_TEXT = {"same": "vertical scaled with the horizontal",
                  "independent": "vertical scaled to its own levels",
                  "unscaled": "vertical as recorded", "zero": "no vertical"}


def study_caption(ds, sweep=None) -> list[str]:
    """What study, system and design a result shows: three lines for a figure's title.

    The study is the pipeline's ``title`` and file (attributes ``title`` and
    ``pipeline_source``); the system is the pipeline's, with the swept values drawn
    (``sweep``) applied (:func:`shipblock.fragility.design.apply_parameters`); the design names
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
    if "system" in ds.attrs:
        system = json.loads(ds.attrs["system"])
        if sweep:
            system = apply_parameters(ShipBlockSystem(**system), dict(sweep)).to_dict()
        lines.append("system: " + system_text(system))
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


#: Longest title line of a study figure [characters]: about the width of the default figure
#: at the title's font size.
TITLE_WIDTH = 140


def _title(ax, caption, what):
    """Title of a study figure: the caption lines (:func:`study_caption`), then what it shows,
    each wrapped to :data:`TITLE_WIDTH`."""
    lines = [w for line in [*caption, *what] for w in textwrap.wrap(line, TITLE_WIDTH)]
    ax.set_title("\n".join(lines), fontsize=8.5, loc="left")


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
        Swept parameter -> value; a value is matched to the study's within 1e-9 relative.

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
        close = np.flatnonzero(np.isclose(values.astype(float), float(sweep[dim]), rtol=1e-9,
                                          atol=0.0))
        if close.size != 1:
            raise ParameterError(f"{dim} = {sweep[dim]!r} is not a value of the study; values: "
                                 f"{', '.join(f'{v:g}' for v in values)}")
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


def _sweep_text(sweep) -> str:
    return ", ".join(f"{k} = {v:g}" if isinstance(v, float | int | np.number) else f"{k} = {v}"
                     for k, v in (sweep or {}).items())


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
    band_drawn = False
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
        handles.append(Line2D([], [], color=c, lw=1.8 if fitted else 0,
                              marker=marker if scaled else None, mfc="white", mew=1.5,
                              ms=sizes[i], label=desc))
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
    ax.set_xlabel(xlabel)
    ax.set_ylabel("probability of exceedance")
    ax.set_ylim(-0.03, 1.03)
    ax.set_xlim(0, x_plot[-1])
    ax.grid(True, lw=0.3, alpha=0.5)
    curves = "fragility: lines: lognormal fit"
    if band_drawn:
        conf = ds["median_lower"].attrs.get("confidence")
        curves += ("; shaded: " + (f"{100 * float(conf):g} % " if conf is not None else "")
                   + "bootstrap band of the median")
    if sweep:
        curves += f"; drawn at {_sweep_text(sweep)}"
    what = [curves]
    if n_per_level is not None:
        counts = np.unique(n_per_level)
        per_level = (f"{int(counts[0])} records per level" if counts.size == 1 else
                     "records per level: " + ", ".join(str(int(k)) for k in n_per_level))
        what.append(f"markers: fraction of the {per_level} exceeding, at the level itself "
                    "(not shifted; coinciding ones nest, largest first)")
    else:
        n_rec = int(ds["valid"].sel(limit_state=names[0]).pipe(_select_sweep, sweep).sum())
        what.append(f"{n_rec} records at their own intensity (no fractions per level)")
    _title(ax, study_caption(ds, sweep), what)
    ax.legend(handles=handles, fontsize=7.5, loc="best")
    return ax


def plot_median_sweep(ds, parameter=None, limit_state=None, ax=None, sweep=None):
    """Fitted median against a swept parameter, with its bootstrap band, per limit state.

    Limit states are drawn side by side (offset by :data:`DODGE` of the parameter's range), so
    that equal medians and their bars stay visible: the swept values are a few known settings
    (the ticks), not a measured abscissa, so the offset misplaces nothing, and the title says
    it. The legend names the values where a fit failed; the title the study, system and design
    (:func:`study_caption`; the system with the other swept values drawn).

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
    x = ds[parameter].values.astype(float)
    span = float(np.ptp(x)) or 1.0
    _, ylabel, factor = _im_axis(ds, [])
    bars_drawn = False
    for i, name in enumerate(names):
        c = f"C{i % 10}"
        # limit states with equal medians side by side
        xd = x + DODGE * span * (i - (len(names) - 1) / 2)
        med = ds["median"].sel(limit_state=name).sel(others).values / factor
        label = f"{name} ({limit_state_text(ds, name)})"
        missing = [f"{v:g}" for v, m in zip(x, med, strict=True) if not np.isfinite(m)]
        if missing:
            label += f"; not fitted at {parameter} = {', '.join(missing)}"
        ax.plot(xd, med, "-" + _MARKERS[i % len(_MARKERS)], color=c, lw=1.5, ms=5,
                mfc="white", mew=1.5, label=label)
        if "median_lower" in ds:
            lo = ds["median_lower"].sel(limit_state=name).sel(others).values / factor
            hi = ds["median_upper"].sel(limit_state=name).sel(others).values / factor
            bars_drawn = bars_drawn or bool(np.isfinite(lo).any() and np.isfinite(hi).any())
            ax.errorbar(xd, med, yerr=[med - lo, hi - med], fmt="none", ecolor=c, elinewidth=1,
                        capsize=3)
    units = ds[parameter].attrs.get("units", "")
    long_name = ds[parameter].attrs.get("long_name", "").replace("swept parameter: ", "")
    ax.set_xlabel(f"{parameter} [{units if units not in ('', '1') else '-'}]"
                  + (f": {long_name}" if long_name else ""))
    ax.set_ylabel(f"median {ylabel}")
    ax.grid(True, lw=0.3, alpha=0.5)
    what = f"fitted median against {parameter}"
    if bars_drawn:
        conf = ds["median_lower"].attrs.get("confidence")
        what += "; bars: " + (f"{100 * float(conf):g} % " if conf is not None else "") \
            + "bootstrap band"
    if len(names) > 1:
        what += (f"; limit states side by side, {100 * DODGE:g} % of the {parameter} range "
                 "apart")
    if others:
        what += f"; drawn at {_sweep_text(others)}"
    # the system line holds the base value of the parameter on the x axis: say it is swept
    caption = [line + (f"; {parameter} swept (x axis)" if line.startswith("system: ") else "")
               for line in study_caption(ds, others)]
    _title(ax, caption, [what])
    ax.legend(fontsize=7.5)
    return ax


def plot_ida(ds, edp="peak_ship_slip", ax=None, sweep=None):
    """IDA curves: the demand ``edp`` of each record against the intensity it was scaled to.

    Runs that failed (separation, overturning) are marked with a cross at the right edge. The
    title says which study, system and design the curves come from (:func:`study_caption`).

    Parameters
    ----------
    ds : xarray.Dataset
        Result of :func:`shipblock.run_pipeline` of an IDA or MSA study.
    edp : str
        The demand on the x axis.
    ax : matplotlib Axes, optional
    sweep : dict, optional
        Value of each swept parameter to draw (default: the first of each); named in the title.

    Returns
    -------
    matplotlib.axes.Axes
    """
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
            f"intensity it was scaled to; x: failure (separation, overturning), drawn at the "
            f"right edge")
    if sweep:
        what += f"; drawn at {_sweep_text(sweep)}"
    _title(ax, study_caption(ds, sweep), [what])
    ax.legend(fontsize=8, ncol=2)
    return ax
