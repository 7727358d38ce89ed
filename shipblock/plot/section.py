"""The response figure of one run of the dock-section model (:mod:`shipblock.models.section`):
ground acceleration, the ship's sway relative to the keel cap, its roll, and the load per block
of every line over the block's capacity.

It draws a run's histories as a dataset (:meth:`SectionRun.to_dataset
<shipblock.models.section.SectionRun.to_dataset>`, a history file of a study), so that drawing
a saved file neither imports nor compiles the section's kernel.
"""

from __future__ import annotations

import numpy as np

from shipblock.plot._common import SUPTITLE_WIDTH, _new_axes, wrapped
from shipblock.plot.response import dataset_record_line
from shipblock.units import STANDARD_GRAVITY

__all__ = ["is_section_response", "plot_section_response"]


#: The sway panel draws the keel cap's edges when the peak sway reaches this fraction of the
#: cap's half-width; below it the sway has its own scale and the legend names the edge.
EDGE_SHOWN = 0.1


def is_section_response(ds) -> bool:
    """Whether ``ds`` holds the histories of one run of the dock-section model."""
    return hasattr(ds, "data_vars") and "ship_sway" in ds and "time" in ds.dims


def plot_section_response(run, axes=None, record=None):
    """Histories of one section run: ground acceleration, sway, roll and block loads.

    The sway panel shows the keel's offset from the keel blocks' tops against the keel cap's
    half-width (where the ship slides off the cap; named in the legend, off scale, when the peak
    sway is below ``EDGE_SHOWN`` of it); the load panel each line's top-cap normal
    force per block over the block's capacity (1: the capacity), so that the capacity-ratio EDPs
    (``keel_load_ratio``, ``side_load_ratio``) are the peaks of these curves. The title names the
    record (``record``, or the dataset's own line) and the outcome (failure and peaks).

    Parameters
    ----------
    run : SectionRun or xarray.Dataset
        The run (:meth:`SectionModel.simulate <shipblock.models.section.SectionModel.simulate>`)
        or its ``to_dataset()``.
    axes : sequence of 4 matplotlib Axes, optional
        A new figure when None.
    record : str, optional
        The record line of the title (default: the dataset's).

    Returns
    -------
    numpy.ndarray of Axes
        The four panels.
    """
    ds = run if hasattr(run, "data_vars") else run.to_dataset()
    record = record or str(ds.attrs.get("record_description") or dataset_record_line(ds))
    if axes is None:
        fig, axes = _new_axes(4)
    else:
        axes = np.atleast_1d(axes)
        fig = axes[0].figure
    t = ds["time"].values
    ax_g, ax_s, ax_r, ax_n = axes[:4]
    if "ground_acceleration_h" in ds:
        ax_g.plot(t, ds["ground_acceleration_h"].values / STANDARD_GRAVITY, color="k", lw=0.7,
                  label="horizontal")
        a_v = ds["ground_acceleration_v"].values
        if np.any(a_v):
            ax_g.plot(t, a_v / STANDARD_GRAVITY, color="tab:purple", lw=0.6, alpha=0.8,
                      label="vertical")
        ax_g.legend(loc="upper right", fontsize=8, ncol=2)
    ax_g.set_ylabel("ground acc. [g]")
    sway_mm = 1e3 * ds["ship_sway"].values
    ax_s.plot(t, sway_mm, color="tab:blue", lw=1.0)
    half = ds.attrs.get("keel_cap_half_width")
    if half is not None:
        edge_mm = 1e3 * float(half)
        peak_mm = float(np.nanmax(np.abs(sway_mm), initial=0.0))
        if peak_mm >= EDGE_SHOWN * edge_mm:
            for sign in (1, -1):
                ax_s.axhline(sign * edge_mm, color="tab:red", lw=0.8, ls="--",
                             label="keel cap's edge" if sign > 0 else None)
        else:  # at the edge's scale a small sway is a flat line: its own scale, the edge named
            ax_s.plot([], [], color="tab:red", lw=0.8, ls="--",
                      label=f"keel cap's edge at \u00b1{edge_mm:.0f} mm (off scale)")
        ax_s.legend(loc="upper right", fontsize=8)
    ax_s.set_ylabel("sway [mm]")
    ax_r.plot(t, 1e3 * ds["ship_roll"].values, color="tab:green", lw=1.0)
    ax_r.set_ylabel("roll [mrad]")
    for k, name in enumerate(n for n in ds.data_vars if n.endswith("_top_normal")):
        line = name[:-len("_top_normal")]
        capacity = float(ds.attrs.get(f"{line}_block_capacity", np.nan))
        ax_n.plot(t, ds[name].values / capacity, color=f"C{k}", lw=0.9,
                  label=_line_label(line, ds.attrs.get(f"{line}_offset")))
    ax_n.axhline(1.0, color="tab:red", lw=0.8, ls="--", label="capacity")
    ax_n.set_ylabel("load / capacity [-]")
    ax_n.legend(loc="upper right", fontsize=8, ncol=4)
    ax_n.set_xlabel("time [s]")
    for ax in axes[:4]:
        ax.grid(True, lw=0.3, alpha=0.5)
    failure = str(ds.attrs.get("failure_name", "none"))
    outcome = ("response: no failure" if failure == "none" else
               f"response: {failure.replace('_', ' ')} at t = "
               f"{float(ds.attrs.get('failure_time', np.nan)):.3f} s")
    peaks = [(name, ds.attrs.get(name)) for name in ("keel_load_ratio", "side_load_ratio",
                                                     "cap_pressure_ratio")]
    outcome += "; peaks " + ", ".join(f"{n} {float(v):.3g}" for n, v in peaks if v is not None)
    if "peak_roll" in ds.attrs:
        outcome += (f", roll {1e3 * float(ds.attrs['peak_roll']):.3g} mrad, sway "
                    f"{1e3 * float(ds.attrs['peak_sway']):.3g} mm")
    lines = ([record] if record else []) + ["dock-section model", outcome]
    fig.suptitle(wrapped(lines, SUPTITLE_WIDTH), fontsize=8.5)
    return axes


def _line_label(line: str, offset) -> str:
    """A support line's legend entry: a side line with the side it stands on (as the
    ``simulate`` summary names it) and its distance from the centre line."""
    if offset is None or line == "keel" or float(offset) == 0.0:
        return line
    side = "starboard" if float(offset) > 0.0 else "port"
    return f"{line} ({side}, {abs(float(offset)):g} m)"
