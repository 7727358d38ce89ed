"""Which traces make a record's components: sensor selection, orientation, H1/H2/V.

:func:`select_sensor` keeps the traces of one sensor of a station (``sensor="02.HN"``) and
refuses a choice between several that nobody made; :func:`assign_components` tells each trace's
orientation (from its header, SAC ``cmpaz``/``cmpinc``, a StationXML inventory or the channel
code), tags the horizontals H1, H2 and the vertical V (flipped to positive up if recorded
positive down), or follows the caller's ``channel_map``.
"""

from __future__ import annotations

import math
import os
import warnings
from collections.abc import Mapping

import numpy as np
from obspy import Stream, Trace

from shipblock.checks import how_to_pass
from shipblock.errors import ParameterError, RecordError
from shipblock.records.motion import COMPONENT_KEY, COMPONENTS, ORIENTATION_TOLERANCE, trace_source

__all__ = ["HORIZONTAL_RULE", "assign_components", "describe_horizontal", "orientation_letter",
           "select_sensor", "sensor_code"]

_TWO_LETTER = {"NS": "N", "EW": "E", "UD": "Z"}


#: Formats whose channel codes are channel numbers (``"0"``, ``"1"``, ...), not orientation
#: codes: their components come from ``channel_map`` (or an inventory), never from the code.
CHANNEL_NUMBER_FORMATS = {"KINEMETRICS_EVT"}


def orientation_letter(channel: str) -> str:
    """The orientation letter of a channel code (``"HNZ"`` -> ``"Z"``, ``"UD"`` -> ``"Z"``)."""
    code = channel.strip().upper()
    if code in _TWO_LETTER:
        return _TWO_LETTER[code]
    return code[-1] if code else ""


def _orientation(trace: Trace, inventory):
    """Return ``(kind, azimuth, dip, note)`` with kind in {"V", "H", None}."""
    stats = trace.stats
    azimuth = stats.get("azimuth")
    dip = stats.get("dip")
    note = None
    sac = stats.get("sac")
    if sac is not None:
        if dip is None and sac.get("cmpinc") is not None and sac.get("cmpinc") != -12345.0:
            dip = float(sac["cmpinc"]) - 90.0  # SAC: 0 = up, 90 = horizontal, 180 = down
        if azimuth is None and sac.get("cmpaz") is not None and sac.get("cmpaz") != -12345.0:
            azimuth = float(sac["cmpaz"])
    if inventory is not None and (azimuth is None or dip is None):
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                found = inventory.get_orientation(trace.id, stats.starttime)
        except Exception:  # noqa: BLE001 - the channel may simply be absent
            found = {}
        if azimuth is None and found.get("azimuth") is not None:
            azimuth = float(found["azimuth"])
        if dip is None and found.get("dip") is not None:
            dip = float(found["dip"])
    letter = orientation_letter(stats.channel)
    if stats.get("_format") in CHANNEL_NUMBER_FORMATS or not stats.get("seed_channel", True):
        # "1", "2" are channel numbers there, not orientations; a code a reader made from a word
        # that states no orientation (PEER's fault-normal "FN") ends in N by chance:
        # channel_map tells
        letter = ""
    if dip is not None:
        if abs(abs(dip) - 90.0) <= ORIENTATION_TOLERANCE:
            return "V", None, float(math.copysign(90.0, dip)), note
        if abs(dip) <= ORIENTATION_TOLERANCE:
            if azimuth is None:
                azimuth = {"N": 0.0, "E": 90.0}.get(letter)
            return "H", azimuth, 0.0, note
        raise RecordError(
            trace_source(trace), f"channel {trace.id} is tilted (dip {dip:g} deg); cannot use it"
        )
    if letter in ("Z", "U"):
        note = f"{trace.id}: vertical polarity not stated; taken positive up (SEED convention)"
        return "V", None, -90.0, note
    if letter in ("N", "E", "1", "2"):
        if azimuth is None:
            azimuth = {"N": 0.0, "E": 90.0}.get(letter)
        return "H", azimuth, 0.0, note
    return None, azimuth, dip, note


def sensor_code(trace: Trace) -> str:
    """``"<location>.<band+instrument>"`` of a trace, e.g. ``"02.HN"``: one sensor of a station.

    Only SEED channel codes (three characters, band and instrument letters first) name a sensor;
    other codes (the codes the AT2 reader makes from a component word, ``HN1`` from ``180``,
    marked ``stats.seed_channel = False``; an EVT file's ``"0"``) leave it empty.
    """
    channel = trace.stats.channel
    seed = trace.stats.get("seed_channel", True) and len(channel) == 3 and channel[:2].isalpha()
    code = channel[:2] if seed else ""
    return f"{trace.stats.location}.{code}"


def select_sensor(stream: Stream, sensor: str | None, channel_map, strict: bool = True) -> Stream:
    """Keep the traces of one sensor; refuse a choice between several that nobody made.

    With ``strict=False`` a sensor that matches nothing gives an empty Stream, not an error.
    """
    sensors = dict.fromkeys(sensor_code(tr) for tr in stream)
    if sensor is None:
        if len(sensors) <= 1 or channel_map:
            return stream
        stations = {(tr.stats.network, tr.stats.station) for tr in stream}
        if len(stations) > 1:
            return stream  # several stations: assign_components says so
        label = trace_source(stream[0])
        raise RecordError(
            label,
            "the files hold several sensors of one station: "
            + ", ".join(f"{code} ({', '.join(tr.stats.channel for tr in stream if sensor_code(tr) == code)})"
                        for code in sensors)
            + "; choose one: " + how_to_pass("sensor", next(iter(sensors)).lstrip(".")),
        )
    wanted = sensor.strip().upper()
    chosen = Stream([tr for tr in stream if sensor_code(tr).upper() == wanted
                     or ("." not in wanted and tr.stats.channel[:2].upper() == wanted)])
    if not chosen and strict:
        raise ParameterError(
            f"sensor={sensor!r} matches none of the record's sensors: {', '.join(sensors)}"
        )
    return chosen


def _match_map(trace: Trace, channel_map: Mapping[str, str]):
    source = trace_source(trace)
    # file_component: the component as the file writes it, when the reader made the channel
    # code (an AT2 file's "180" for HN1), so that a map written for the file's words works
    for key in (trace.id, trace.stats.channel, trace.stats.get("file_component"),
                os.path.basename(source), source):
        if key in channel_map:
            return channel_map[key]
    return None


def assign_components(
    stream: Stream, inventory, channel_map, notes, processing
) -> dict[str, Trace]:
    """Tag each trace with ``stats.motion_component``; return the component -> trace mapping."""
    assigned: dict[str, Trace] = {}
    info = {}
    for trace in stream:
        info[id(trace)] = _orientation(trace, inventory)
        if info[id(trace)][3]:
            notes.append(info[id(trace)][3])
    label = trace_source(stream[0])
    if channel_map:
        for trace in stream:
            component = _match_map(trace, channel_map)
            if component is None:
                notes.append(f"{trace.id} not in the component mapping; left out")
                continue
            if component not in COMPONENTS:
                raise ParameterError(f"channel_map values must be one of {COMPONENTS}: {component!r}")
            if component in assigned:
                raise RecordError(label, f"two channels are mapped to {component}")
            assigned[component] = trace
        absent = sorted({c for c in channel_map.values() if c in COMPONENTS} - set(assigned),
                        key=COMPONENTS.index)
        if absent:
            raise RecordError(
                label, "the component mapping names "
                + ", ".join(f"{c} ({', '.join(k for k, v in channel_map.items() if v == c)})"
                            for c in absent)
                + " but the files hold no such channel (a missing or damaged file?); they hold "
                + ", ".join(tr.id for tr in stream),
            )
    else:
        stations = {(tr.stats.network.upper(), tr.stats.station.upper(), tr.stats.location.upper())
                        for tr in stream}
        if len(stations) > 1:
            raise RecordError(
                label,
                "traces of several stations/locations: "
                + ", ".join(".".join(s) for s in sorted(stations))
                + f"; {how_to_pass('channel_map', None)}",
            )
        verticals = [tr for tr in stream if info[id(tr)][0] == "V"]
        horizontals = [tr for tr in stream if info[id(tr)][0] == "H"]
        unknown = [tr for tr in stream if info[id(tr)][0] is None]
        if unknown:
            if len(stream) == 1:
                horizontals = unknown
                notes.append(
                    f"{unknown[0].id.strip('.') or trace_source(unknown[0])}: orientation unknown;"
                    " the single"
                    " record is taken as horizontal H1"
                )
            else:
                raise RecordError(
                    label,
                    "cannot tell the component of "
                    + ", ".join(f"{tr.id} ({trace_source(tr)})" for tr in unknown)
                    + f"; {how_to_pass('channel_map', None)}",
                )
        if len(verticals) > 1:
            raise RecordError(label, f"{len(verticals)} vertical channels;"
                                    f" {how_to_pass('channel_map', None)}")
        if len(horizontals) > 2:
            raise RecordError(label, f"{len(horizontals)} horizontal channels;"
                                    f" {how_to_pass('channel_map', None)}")
        if len(horizontals) == 2:
            horizontals = _order_horizontals(horizontals, info)
        for component, trace in zip(("H1", "H2"), horizontals, strict=False):
            assigned[component] = trace
        if verticals:
            assigned["V"] = verticals[0]
    if "H1" not in assigned and "H2" not in assigned:
        if "V" in assigned:
            raise RecordError(
                label, f"holds only a vertical component ({assigned['V'].id}); the model needs a"
                " horizontal one"
            )
        raise RecordError(label, "no horizontal component found")
    for component, trace in assigned.items():
        kind, azimuth, dip, _ = info[id(trace)]
        trace.stats[COMPONENT_KEY] = component
        if component == "V":
            if kind == "H":
                raise RecordError(trace_source(trace), f"{trace.id} is horizontal but mapped to V")
            dip = -90.0 if dip is None else dip
            if dip > 0:
                trace.data = -np.asarray(trace.data)
                processing.append(
                    f"{trace.id}: vertical recorded positive down; flipped to positive up"
                )
                dip = -90.0
            trace.stats.dip = dip
        else:
            if kind == "V":
                raise RecordError(
                    trace_source(trace), f"{trace.id} is vertical but mapped to {component}"
                )
            trace.stats.dip = 0.0
            if azimuth is not None:
                trace.stats.azimuth = float(azimuth) % 360.0
    return assigned


#: How H1 and H2 are told apart when the channels are not mapped (``channel_map``); the solver
#: uses H1 unless told otherwise (``horizontal=``, ``azimuth=``). Printed by ``shipblock info``
#: and ``simulate`` and documented in docs/user_guide/records.rst.
HORIZONTAL_RULE = (
    "H1 is the record's first horizontal: N before E and 1 before 2 by the channel codes'"
    " last letters (not the codes made from PEER component words); otherwise the first in the"
    " file (a file holding all components, e.g. a CSMIP V2), or, for one file per component,"
    " the one the other is 90 deg clockwise from (PEER 000/090: 000), else the first file given"
)


def _order_horizontals(horizontals, info):
    """H1 first (:data:`HORIZONTAL_RULE`). Channel codes a reader made (``seed_channel``
    False: AT2) are not the file's: their order comes from the azimuths."""
    letters = [orientation_letter(tr.stats.channel) if tr.stats.get("seed_channel", True) else ""
               for tr in horizontals]
    for first, second in (("N", "E"), ("1", "2")):
        if set(letters) == {first, second}:
            return sorted(
                horizontals, key=lambda tr: orientation_letter(tr.stats.channel) != first
            )
    if trace_source(horizontals[0]) == trace_source(horizontals[1]):
        return list(horizontals)  # one file: its order
    az = [info[id(tr)][1] for tr in horizontals]
    if None not in az:
        separation = (az[1] - az[0]) % 360.0
        if abs(separation - 270.0) <= ORIENTATION_TOLERANCE:
            return [horizontals[1], horizontals[0]]
    return list(horizontals)


def describe_horizontal(motion) -> str:
    """Which horizontal the solver uses for a GroundMotion, where it came from, and by which
    rule (:data:`HORIZONTAL_RULE`), in words for ``shipblock info`` and ``simulate``."""
    chosen = motion.metadata.get("horizontal", "H1")
    if chosen not in ("H1", "H2"):
        return f"{chosen} (--azimuth)"
    channel = motion.metadata.get("channels", {}).get(chosen, "")
    azimuth = motion.azimuths.get(chosen)
    where = ", ".join(x for x in (channel.strip("."), "" if azimuth is None
                                  else f"azimuth {azimuth:g} deg") if x)
    how = ("chosen with --horizontal" if motion._horizontal is not None
           else f"the default (--horizontal H2 or --azimuth DEG to change)\n  rule: {HORIZONTAL_RULE}")
    return f"{chosen}{f' ({where})' if where else ''}, {how}"
