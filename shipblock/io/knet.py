"""K-NET and KiK-net records (NIED, Japan) as obspy reads them, named the SEED way.

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

References
----------
.. [1] obspy.io.nied.knet, https://docs.obspy.org/packages/obspy.io.nied.html
.. [2] National Research Institute for Earth Science and Disaster Resilience (2019), NIED
   K-NET, KiK-net, doi:10.17598/NIED.0004.
"""

from __future__ import annotations

from shipblock.io._common import orientation_stats

__all__ = ["normalise_knet"]

#: File direction -> (vertical, azimuth [deg]).
_DIRECTIONS = {"NS": (False, 0.0), "EW": (False, 90.0), "UD": (True, None)}

#: KiK-net sensor digit -> (SEED location code, site of the sensor).
_KIKNET_SENSORS = {"1": ("01", "borehole"), "2": ("02", "surface")}


def normalise_knet(stream) -> None:
    """Give the K-NET/KiK-net traces of a Stream SEED channel codes and orientations, in place.

    Parameters
    ----------
    stream : obspy.Stream
        Traces read by obspy's ``KNET`` reader (``stats._format == "KNET"``); other traces and
        K-NET traces with a direction code not listed above are left as they are.
    """
    for trace in stream:
        stats = trace.stats
        if stats.get("_format") != "KNET":
            continue
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
