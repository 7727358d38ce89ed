"""What every figure shares: new axes, title widths, and the one-line descriptions of a
system, a record and the time window shown."""

from __future__ import annotations

import textwrap
from collections.abc import Mapping

import numpy as np

from shipblock.system import system_line


def _pyplot():
    import matplotlib.pyplot as plt

    return plt


def _new_axes(nrows, sharex=True, height=1.8):
    plt = _pyplot()
    fig, axes = plt.subplots(nrows, 1, sharex=sharex, figsize=(9.0, height * nrows + 0.8),
                             constrained_layout=True)
    return fig, np.atleast_1d(axes)


#: Longest line of a response figure's title [characters] (its font is wider than an axes
#: title's).
SUPTITLE_WIDTH = 140

#: Longest title line of a study figure [characters]: the width of the default figure's axes
#: at the title's font size (140 ran past the right edge of a fragility figure).
TITLE_WIDTH = 118


def _title(ax, caption, what):
    """Title of a study figure: the caption lines (:func:`study_caption`), then what it shows,
    each wrapped to :data:`TITLE_WIDTH` at spaces only (never inside "blocks-floor")."""
    ax.set_title(wrapped([*caption, *what], TITLE_WIDTH), fontsize=8.5, loc="left")




def wrapped(lines, width) -> str:
    """``lines`` joined by newlines, each wrapped to ``width`` characters."""
    return "\n".join(w for line in lines
                     for w in textwrap.wrap(line, width, break_on_hyphens=False))


def system_text(system) -> str:
    """One line naming a ship-block system of the rigid model as a report would
    (:func:`shipblock.system.system_line`): masses in t, block size in m, friction
    static/kinetic per interface.

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
    return system_line(system if isinstance(system, Mapping) else system.to_dict())


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
    start = motion.starttime
    start = str(start)[:19].replace("T", " ") if start.year > 1970 else None
    return record_line(motion.name, motion.metadata, start, scale)


def record_line(name, metadata, start=None, scale=None) -> str:
    """:func:`record_text` from a record's name and metadata (e.g. the provenance a batch's
    history file keeps); ``start`` the first sample's time as text when the file states it."""
    md = metadata
    site = (md.get("catalogue") or {}).get("site", "")
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
    elif start:  # 1970-01-01 is a start the file does not state: the caller leaves it out
        text += f", start {start} UTC"
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
