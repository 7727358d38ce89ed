r"""K-NET and KiK-net records (NIED, Japan) as obspy reads them, named the SEED way.

obspy's ``KNET`` reader [1]_ reads both networks' ASCII files and keeps the file's direction as
the channel code: ``NS``, ``EW``, ``UD`` for K-NET, and ``NS1``/``EW1``/``UD1`` (the borehole
sensor, 100-200 m down) and ``NS2``/``EW2``/``UD2`` (the surface sensor) for KiK-net [2]_. Taken
as SEED codes these say nothing shipblock can use: ``UD2`` ends in a digit like a horizontal
``HN2``, and a KiK-net station's six files look like one record with four horizontals.

:func:`normalise_knet` renames each trace to SEED codes: channel ``HNN``/``HNE``/``HNZ`` (band
letter by sampling rate), location ``""`` for K-NET, ``"01"`` for the KiK-net borehole and
``"02"`` for the surface sensor, ``stats.dip`` (-90: UD is positive up) and ``stats.azimuth``
(0 or 90 deg, the nominal directions; KiK-net borehole sensors can be rotated from them, which
the files do not state), and ``stats.sensor_site`` (``"surface"`` or ``"borehole"``). The file's
own code stays in ``stats.knet_direction``. Samples stay counts with obspy's ``stats.calib``
(m/s^2 per count, from the header's scale factor).

The counts carry the digitiser's offset (``-18000`` counts, 0.04 m/s^2, in obspy's
``test.knet``). NIED states that the header's maximum acceleration is taken after subtracting the
mean of the whole record [3]_, and that is how the samples are meant to be used:
:func:`normalise_knet` subtracts it,

.. math:: c_i' = c_i - \frac{1}{N}\sum_{j=1}^{N} c_j ,

so that :math:`\max_i |c_i'|\,\mathrm{calib}` is the header's ``Max. Acc.`` (to its printed
digits: all 49 files of the gmprocess corpus agree to 0.001 gal). The file is then checked against
what its header states, so that a damaged file is refused rather than read:

* the number of samples must be ``Duration Time(s)`` x ``Sampling Freq(Hz)`` (the header gives
  whole seconds; every real file has exactly that many): a line lost or doubled shifts every
  later sample in time;
* the peak after the offset must be ``Max. Acc.`` within :data:`PEAK_TOLERANCE` (relative) plus
  :data:`PEAK_RESOLUTION_GAL`: a changed sample, a wrong scale factor.

References
----------
.. [1] obspy.io.nied.knet, https://docs.obspy.org/packages/obspy.io.nied.html
.. [2] National Research Institute for Earth Science and Disaster Resilience (2019), NIED
   K-NET, KiK-net, doi:10.17598/NIED.0004.
.. [3] NIED, "K-NET, KiK-net FAQ", answer 2 (the maximum acceleration is computed from the
   series after subtracting the mean of the whole record, its offset),
   https://www.kyoshin.bosai.go.jp/kyoshin/faq.html; format: "About K-NET ASCII format",
   https://www.kyoshin.bosai.go.jp/kyoshin/man/knetform_en.html.
"""

from __future__ import annotations

import math

import numpy as np

from shipblock.errors import RecordError
from shipblock.io._common import orientation_stats

__all__ = ["normalise_knet"]

#: Relative tolerance of the peak after the offset against the header's ``Max. Acc.``.
PEAK_TOLERANCE = 0.005

#: Absolute tolerance of that comparison [gal]: the header prints three decimals.
PEAK_RESOLUTION_GAL = 0.002

#: One gal in m/s^2.
_GAL = 0.01

#: File direction -> (vertical, azimuth [deg]).
_DIRECTIONS = {"NS": (False, 0.0), "EW": (False, 90.0), "UD": (True, None)}

#: KiK-net sensor digit -> (SEED location code, site of the sensor).
_KIKNET_SENSORS = {"1": ("01", "borehole"), "2": ("02", "surface")}


def _check_against_header(trace, name: str) -> None:
    """Refuse a K-NET trace whose length or peak contradicts its header (see the module notes)."""
    stats = trace.stats
    header = stats.get("knet") or {}
    what = f"K-NET channel {stats.channel}"
    duration = header.get("duration")
    if duration is not None and math.isfinite(duration) and duration > 0:
        expected = int(round(duration * stats.sampling_rate))
        if stats.npts != expected:
            change = "missing" if stats.npts < expected else "extra"
            raise RecordError(
                name, f"{what} has {stats.npts} samples but its header states Duration Time(s)"
                f" {duration:g} x Sampling Freq(Hz) {stats.sampling_rate:g} = {expected}"
                f" ({abs(expected - stats.npts)} samples {change}: a damaged file)")
    stated = header.get("accmax")
    if stated is not None and math.isfinite(stated) and stats.npts:
        peak_gal = float(np.max(np.abs(trace.data))) * stats.calib / _GAL
        if abs(peak_gal - stated) > PEAK_TOLERANCE * stated + PEAK_RESOLUTION_GAL:
            raise RecordError(
                name, f"{what} peaks at {peak_gal:.4g} gal after its offset is removed, but its"
                f" header states Max. Acc. {stated:g} gal (a damaged sample or scale factor)")


def normalise_knet(stream, name: str | None = None) -> None:
    """Name K-NET/KiK-net traces the SEED way, remove their offset, check them; in place.

    Parameters
    ----------
    stream : obspy.Stream
        Traces read by obspy's ``KNET`` reader (``stats._format == "KNET"``); other traces and
        K-NET traces with a direction code not listed above are left as they are.
    name : str, optional
        The file, for error messages (default: the trace's ``stats.source_file``, else its id).

    Raises
    ------
    RecordError
        If a trace's sample count is not the header's duration x rate, or its peak after the
        offset is not the header's ``Max. Acc.``.
    """
    for trace in stream:
        stats = trace.stats
        if stats.get("_format") != "KNET":
            continue
        if not stats.get("knet_offset_removed", False):
            counts = np.asarray(trace.data, dtype=np.float64)
            offset = float(counts.mean()) if counts.size else 0.0
            trace.data = counts - offset
            stats.knet_offset_counts = offset
            stats.knet_offset_removed = True
            _check_against_header(trace, name or stats.get("source_file", trace.id))
        code = stats.channel.strip().upper().replace("-", "")
        direction, digit = code[:2], code[2:]
        if direction not in _DIRECTIONS or digit not in ("", *_KIKNET_SENSORS):
            continue
        vertical, azimuth = _DIRECTIONS[direction]
        location, site = _KIKNET_SENSORS.get(digit, ("", "surface"))
        stats.knet_direction = stats.channel
        for key, value in orientation_stats(
            stats.sampling_rate, vertical=vertical, azimuth_deg=azimuth
        ).items():
            stats[key] = value
        stats.location = location
        stats.sensor_site = site
