"""A record's own picture: what an engineer looks at before using a record.

:func:`plot_record_overview` draws, for each component (H1, H2, V), the acceleration as read and
as processed with the file's own stated peak marked, and beside them the 5 %-damped response
spectra of the processed components with the RotD50 of the two horizontals
(:func:`shipblock.rotd.rotd_spectrum`, Boore 2010) and their Fourier amplitude spectra
(``shipblock info FILE --figure OUT.png``).
"""

from __future__ import annotations

import re

import numpy as np

from shipblock import intensity
from shipblock.records.motion import COMPONENT_KEY
from shipblock.plot._common import SUPTITLE_WIDTH, active_window, record_text, wrapped
from shipblock.rotd import rotd_spectrum
from shipblock.units import STANDARD_GRAVITY

__all__ = ["SPECTRUM_PERIODS", "plot_record_overview", "stated_peaks"]

#: Periods of the response spectra drawn [s]: 0.01 to 10 s, 20 per decade.
SPECTRUM_PERIODS = np.logspace(-2, 1, 61)

_COLOURS = {"H1": "k", "H2": "tab:blue", "V": "tab:purple"}


def stated_peaks(motion) -> dict[str, float]:
    """The peak each component's file states [m/s^2], where the reader kept it.

    Readers put a file's own stated peak acceleration in ``stats.stated_peak_si`` of its trace
    (COSMOS, CSMIP, ESM, GeoNet, K-NET, SMC, ...); components without one are left out.
    """
    out = {}
    for tr in motion.stream:
        peak = tr.stats.get("stated_peak_si")
        if peak is not None and np.isfinite(peak):
            out[tr.stats[COMPONENT_KEY]] = float(peak)
    return out


def _fourier(acc, dt):
    """Frequencies [Hz] (without 0) and Fourier amplitudes |dt * FFT| [m/s]."""
    amp = np.abs(np.fft.rfft(acc)) * dt
    freq = np.fft.rfftfreq(acc.size, dt)
    return freq[1:], amp[1:]


def plot_record_overview(raw, processed=None, periods=None, damping=0.05):
    """Raw and processed components, their response spectra with RotD50, and Fourier amplitudes.

    Parameters
    ----------
    raw : GroundMotion
        The record as read (converted to m/s^2, not processed); its stated peaks are marked
        (:func:`stated_peaks`).
    processed : GroundMotion, optional
        The same record processed (e.g. by the default chain); None when nothing was done.
    periods : array_like, optional
        Periods of the spectra [s] (default :data:`SPECTRUM_PERIODS`).
    damping : float
        Damping of the spectra [-]; default 0.05.

    Returns
    -------
    dict
        ``{"H1": Axes, ..., "spectra": Axes, "fourier": Axes}``.
    """
    import matplotlib.pyplot as plt

    periods = SPECTRUM_PERIODS if periods is None else np.asarray(periods, float)
    shown = processed if processed is not None else raw
    comps = list(raw.components)
    fig = plt.figure(figsize=(12.0, 2.1 * max(len(comps), 2) + 1.4), constrained_layout=True)
    grid = fig.add_gridspec(len(comps) * 2, 2, width_ratios=[1.7, 1.0])
    axes = {}
    t = raw.time
    stated = stated_peaks(raw)
    for i, comp in enumerate(comps):
        ax = fig.add_subplot(grid[2 * i:2 * i + 2, 0], sharex=axes.get(comps[0]))
        axes[comp] = ax
        a_raw = raw.components[comp]
        ax.plot(t, a_raw / STANDARD_GRAVITY, color="0.6", lw=0.6,
                label=f"as read: peak {np.abs(a_raw).max() / STANDARD_GRAVITY:.4g} g")
        if processed is not None:
            a_pro = processed.components[comp]
            ax.plot(processed.time, a_pro / STANDARD_GRAVITY, color=_COLOURS[comp], lw=0.6,
                    label=f"processed: peak {np.abs(a_pro).max() / STANDARD_GRAVITY:.4g} g")
        if comp in stated:
            peak = stated[comp] / STANDARD_GRAVITY
            for sign in (1, -1):
                ax.axhline(sign * peak, color="red", lw=0.8, ls="--",
                           label=f"file's stated peak {peak:.4g} g" if sign > 0 else None)
        az = raw.azimuths.get(comp)
        channel = (raw.metadata.get("channels") or {}).get(comp, "")
        ax.set_ylabel(f"{comp} [g]")
        ax.set_title(f"{comp}: {channel}" + (f", azimuth {az:g} deg" if az is not None else ""),
                     fontsize=8.5, loc="left")
        ax.legend(loc="upper right", fontsize=7)
        ax.grid(True, lw=0.3, alpha=0.5)
    t0, t1 = active_window(t, raw.components[comps[0]], margin=3.0)
    axes[comps[0]].set_xlim(t0, t1)
    window = ""
    if t0 > t[0] or t1 < t[-1]:
        window = (f"   (shown: {t0:.1f} to {t1:.1f} s of {t[0]:.1f} to {t[-1]:.1f} s: 1-99 % of "
                  f"the Arias intensity of {comps[0]}, +3/4.5 s)")
    axes[comps[-1]].set_xlabel("time [s]" + window, fontsize=8.5)
    # spectra of the processed components, RotD50 of the two horizontals
    half = len(comps)
    ax_sa = fig.add_subplot(grid[0:half, 1])
    ax_fa = fig.add_subplot(grid[half:, 1])
    axes["spectra"], axes["fourier"] = ax_sa, ax_fa
    for comp, acc in shown.components.items():
        psa = intensity.response_spectrum(acc, shown.dt, periods, damping).psa
        ax_sa.plot(periods, psa / STANDARD_GRAVITY, color=_COLOURS[comp], lw=1.0, label=comp)
        ax_fa.loglog(*_fourier(acc, shown.dt), color=_COLOURS[comp], lw=0.4, alpha=0.8,
                     label=comp)
    if "H1" in shown.components and "H2" in shown.components:
        rot = rotd_spectrum(shown.components["H1"], shown.components["H2"], shown.dt, periods,
                            damping)
        ax_sa.plot(periods, rot.rotd50 / STANDARD_GRAVITY, color="tab:red", lw=2.0,
                   label="RotD50 (H1, H2)")
    ax_sa.set_xscale("log")
    ax_sa.set_xlabel("period T [s]")
    ax_sa.set_ylabel("Sa [g]")
    what = "processed" if processed is not None else "as read"
    ax_sa.set_title(f"response spectra, {100 * damping:g} % damping ({what})", fontsize=8.5,
                    loc="left")
    ax_sa.legend(fontsize=7)
    ax_sa.grid(True, which="both", lw=0.3, alpha=0.5)
    ax_fa.set_xlabel("frequency [Hz]")
    ax_fa.set_ylabel("Fourier amplitude [m/s]")
    ax_fa.set_title(f"Fourier amplitude spectra ({what})", fontsize=8.5, loc="left")
    ax_fa.legend(fontsize=7)
    ax_fa.grid(True, which="both", lw=0.3, alpha=0.5)
    nyquist = 0.5 / shown.dt
    ax_fa.set_xlim(max(0.5 / (shown.npts * shown.dt), 0.01), nyquist)
    lines = [record_text(raw), f"{raw.npts} samples at dt = {raw.dt:g} s "
             f"({raw.npts * raw.dt:.1f} s); grey: as read (in m/s^2, not processed)"]
    notes = (processed.metadata.get("processing") or []) if processed is not None else []
    steps = [m for note in notes for m in re.findall(r"(\w+)\(", str(note))]
    if steps:
        lines.append("processed: " + ", ".join(steps) + " (their parameters: shipblock info)")
    if stated:
        lines.append("red dashed: the peak the file itself states")
    fig.suptitle(wrapped(lines, SUPTITLE_WIDTH), fontsize=8.5)
    return axes
