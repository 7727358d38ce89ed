"""The response history of one simulation (:func:`plot_response`), a record's acceleration,
velocity and displacement (:func:`plot_record`) and its response spectrum
(:func:`plot_spectrum`)."""

from __future__ import annotations

import json
import math
from collections.abc import Mapping

import numpy as np

from shipblock.modes import MODE_DESCRIPTIONS
from shipblock.plot._common import (
    SUPTITLE_WIDTH,
    _new_axes,
    active_window,
    record_line,
    system_text,
    wrapped,
)
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
        self.record = str(ds.attrs.get("record_description") or dataset_record_line(ds))


def run_name(ds) -> str:
    """A saved response's record and, for a run of a batch, its IM level (``"NP.1765, PGA
    0.8 g"``, in the unit the pipeline gave its levels in)."""
    name = str(ds.attrs.get("record", ""))
    if name and "im_level" in ds.attrs:
        value, unit = float(ds.attrs["im_level"]), ds.attrs.get("im_units", "")
        if "im_display_units" in ds.attrs:  # the unit the pipeline gave its levels in
            value /= float(ds.attrs["im_display_factor"])
            unit = ds.attrs["im_display_units"]
        elif unit == "m/s^2":
            value, unit = value / STANDARD_GRAVITY, "g"
        measure = ds.attrs.get("im_measure", "IM").upper().replace("SA", "Sa")
        name += f", {measure} {value:.3g} {unit}"
    return name


def dataset_record_line(ds) -> str:
    """The record line of a saved response without one of its own (a batch's history file):
    the record (:func:`record_line` of its kept provenance) at its IM level, the scale factor and
    the run of the pipeline; empty if the file names no record."""
    record = str(ds.attrs.get("record", ""))
    if not record:
        return ""
    try:
        metadata = json.loads(ds.attrs.get("record_provenance", "{}"))
    except ValueError:
        metadata = {}
    level = run_name(ds)[len(record) + 2:]  # "PGA 0.8 g" for a run of a batch
    scale = [f"scaled to {level}"] if level else []
    if "scale_factor" in ds.attrs:
        scale.append(f"scale factor {float(ds.attrs['scale_factor']):.4g}")
    text = record_line(record, metadata if isinstance(metadata, dict) else {},
                       scale=", ".join(scale) or None)
    if "pipeline_source" in ds.attrs and "case" in ds.attrs:
        text += f"; run {ds.attrs['case']} of {ds.attrs['pipeline_source']}"
    return text


#: Slip starts and stops are drawn as lines only up to this many (see :func:`plot_response`):
#: none by default, the mode bands show every slip episode and the legend counts them.
MAX_SLIP_EVENT_LINES = 0
#: Impacts likewise (a rocking episode has hundreds, mostly in its Zeno sequences).
MAX_IMPACT_LINES = 40

SLIP_EVENTS = ("ground_slip_start", "ground_slip_stop", "ship_slip_start", "ship_slip_stop")


def _slip_summary(events) -> list[str]:
    """Legend lines counting the slip episodes of each interface (their starts; a stop may
    also end a slip that another event began, so stops are not counted)."""
    out = []
    for start, what in (("ground_slip_start", "blocks on the floor"),
                        ("ship_slip_start", "ship on the blocks")):
        n_start = sum(e.kind == start for e in events)
        if n_start:
            out.append(f"{what}: {n_start} slip starts (see the mode bands)")
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
        none): the mode bands show each slip episode already, and the legend counts the slip
        starts per interface.
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
    fig.suptitle(wrapped(lines, SUPTITLE_WIDTH), fontsize=8.5)
    return axes


def plot_record(motion, axes=None, label=None):
    """Acceleration, velocity and displacement of a ground motion (H and, if present, V).

    Parameters
    ----------
    motion : GroundMotion or tuple
        A :class:`shipblock.records.motion.GroundMotion`, or ``(horizontal, vertical, dt)`` in m/s^2.
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
