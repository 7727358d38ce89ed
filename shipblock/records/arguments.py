"""The options of reading records, checked before any file is read.

:func:`check_read_arguments` checks the options :func:`~shipblock.records.reading.read_motion` and
:func:`~shipblock.records.folders.read_motions` share, so that a wrong option is one error naming
it, not a failure of every record.
"""

from __future__ import annotations

import os
from collections.abc import Mapping

import obspy

from shipblock import checks
from shipblock.errors import ParameterError, ParameterTypeError
from shipblock.io import check_format
from shipblock.records.motion import COMPONENTS

__all__ = ["ALIGNS", "GAPS", "RESPONSES", "add_read_arguments", "check_channel_map",
           "check_read_arguments", "read_options"]

#: Choices of read_motion's options.
RESPONSES = ("sensitivity", "full")
GAPS = ("refuse", "interpolate")
ALIGNS = ("trim", "resample", "strict")


def check_read_arguments(*, inventory=None, units=None, response="sensitivity",
                         differentiate=False, align="trim", gaps="refuse", event=None,
                         format=None) -> dict:  # noqa: A002 - obspy's name for it
    """Check the options :func:`read_motion` and :func:`shipblock.records.folders.read_motions` share.

    Called before any file is read, so that a wrong option is one error naming it, not a
    failure of every record (``read_motions`` lists failures per record).

    Parameters
    ----------
    inventory, units, response, differentiate, align, gaps, event, format
        As in :func:`read_motion`.

    Returns
    -------
    dict
        The arguments, paths as ``str`` and ``format`` in upper case.

    Raises
    ------
    ParameterError
        Naming the argument and what it expects (a :class:`~shipblock.errors.ParameterTypeError`,
        also a :class:`TypeError`, for a wrong type): an unknown unit, response, alignment, gap
        rule or format; ``differentiate`` not a bool; an empty event Catalog.
    RecordError
        Naming the file and the argument, if an inventory or event path names no file or a
        folder.
    """
    if inventory is not None and not isinstance(inventory, obspy.Inventory):
        if not isinstance(inventory, str | os.PathLike):
            raise ParameterTypeError(
                "inventory must be a StationXML file (str or os.PathLike), an obspy Inventory"
                f" or None, got {type(inventory).__name__} {inventory!r}")
        inventory = checks.existing_file(inventory, "inventory", "a StationXML file")
    if units is not None:
        checks.unit(units, "units")
    checks.choice(response, "response", RESPONSES)
    differentiate = checks.flag(differentiate, "differentiate")
    checks.choice(align, "align", ALIGNS)
    checks.choice(gaps, "gaps", GAPS)
    if isinstance(event, obspy.Catalog):
        if len(event) == 0:
            raise ParameterError("event must hold an earthquake, got an empty obspy Catalog")
    elif isinstance(event, str | os.PathLike):
        event = checks.existing_file(event, "event", "a QuakeML event file")
    elif not (event is None or isinstance(event, Mapping | obspy.core.event.Event)):
        raise ParameterTypeError(
            "event must be a QuakeML file (str or os.PathLike), an obspy Event or Catalog, a dict"
            f" or None, got {type(event).__name__} {event!r}")
    return dict(inventory=inventory, units=units, response=response,
                differentiate=differentiate, align=align, gaps=gaps, event=event,
                format=check_format(format))


def check_channel_map(channel_map):
    """``channel_map`` checked: ``None`` or a mapping of strings to component names."""
    if channel_map is None:
        return None
    if not isinstance(channel_map, Mapping):
        raise ParameterTypeError(
            "channel_map must be a dict {channel code, SEED id or file name: 'H1' | 'H2' | 'V'},"
            f" got {type(channel_map).__name__} {channel_map!r}")
    for key, value in channel_map.items():
        if not isinstance(key, str):
            raise ParameterTypeError(f"channel_map keys must be channel codes, SEED ids or file"
                                     f" names (str), got {type(key).__name__} {key!r}")
        checks.choice(value, f"channel_map[{key!r}]", COMPONENTS)
    return dict(channel_map)


# ----------------------------------------------------------------- the command line
def add_read_arguments(g) -> None:
    """Add the read options of :func:`shipblock.read_motion` to an argparse group, one flag
    each (:data:`shipblock.checks.READ_OPTIONS` names them, and the catalogue key of each);
    the ``shipblock`` command's ``simulate``, ``info``, ``process`` and ``catalogue`` share
    them."""
    g.add_argument("--inventory", help="StationXML for raw counts (and channel orientations)")
    g.add_argument("--units", help="units of records that do not state them: m/s^2, cm/s^2, gal,"
                                   " g, or velocity m/s, cm/s (with --differentiate)")
    g.add_argument("--response", choices=["sensitivity", "full"],
                   help="with --inventory: divide by the overall sensitivity (default) or remove"
                        " the full instrument response")
    g.add_argument("--differentiate", action="store_true", default=None,
                   help="differentiate velocity records to acceleration (said in the provenance)")
    g.add_argument("--channel-map", action="append", metavar="CHANNEL=COMPONENT",
                   help="component of a channel the file does not name (channel code, SEED id or"
                        " file name = H1, H2 or V), e.g. --channel-map 0=H1 --channel-map 3=H2"
                        " or --channel-map 0=H1,3=H2,4=V (Kinemetrics EVT); unmapped channels"
                        " are left out")
    g.add_argument("--sensor", help="sensor to use when a station has several: LOC.CODE, e.g."
                                    " 02.HN (KiK-net surface) or HN")
    g.add_argument("--align", choices=["trim", "resample", "strict"],
                   help="components of different windows or sampling rates: trim to the common"
                        " window (default), resample to the lowest rate, or refuse (strict)")
    g.add_argument("--gaps", choices=["refuse", "interpolate"],
                   help="gaps inside a channel: refuse (default) or fill short ones linearly")
    g.add_argument("--event", metavar="QUAKEML", help="the earthquake (QuakeML file)")
    g.add_argument("--input-format", dest="read_format", metavar="FORMAT",
                   help="obspy format name of the files (default: detected), e.g. SHIPBLOCK_TEXT")
    g.add_argument("--dt", type=float, metavar="SECONDS",
                   help="sampling interval of one-column text records [s]")
    g.add_argument("--data-type", choices=["acceleration"],
                   help="state what an SMC file whose header says '0 UNKNOWN' holds (only"
                        " acceleration, in the format's cm/s^2, can be read)")
    g.add_argument("--resample-rate", type=float, metavar="HZ",
                   help="rate onto which SMC/USC files of (time, value) pairs are interpolated"
                        " [samples/s] (default 200); refused for an evenly sampled file")
    g.add_argument("--resample-interval", type=float, metavar="SECONDS",
                   help="interval onto which a DMG file's uneven time/value pairs are"
                        " interpolated [s]; refused for an evenly sampled file")


def _channel_map(items) -> dict | None:
    """``["0=H1,3=H2", "4=V"]`` -> ``{"0": "H1", "3": "H2", "4": "V"}`` (``--channel-map``)."""
    if not items:
        return None
    mapping = {}
    for item in items:
        for part in item.split(","):
            channel, sep, component = part.partition("=")
            if not sep or not channel.strip() or component.strip() not in ("H1", "H2", "V"):
                raise ParameterError(f"--channel-map expects CHANNEL=H1, CHANNEL=H2 or"
                                     f" CHANNEL=V (comma-separated or repeated), got {part!r}")
            mapping[channel.strip()] = component.strip()
    return mapping


#: The flags of add_read_arguments: read_motion keyword -> attribute of the parsed arguments.
_READ_OPTION_ARGS = {"inventory": "inventory", "units": "units", "response": "response",
                     "differentiate": "differentiate", "sensor": "sensor", "align": "align",
                     "gaps": "gaps", "event": "event", "format": "read_format", "dt": "dt",
                     "data_type": "data_type", "resample_rate": "resample_rate",
                     "resample_interval": "resample_interval"}


def read_options(args) -> dict:
    """The read options given on the command line, as :func:`shipblock.read_motion` keywords
    (only those given: the others keep the library's defaults, or a catalogue entry's keys).

    Raises
    ------
    ParameterError
        Naming ``--channel-map``, for a mapping that is not ``CHANNEL=H1|H2|V``.
    """
    options = {key: getattr(args, attr) for key, attr in _READ_OPTION_ARGS.items()
               if getattr(args, attr, None) is not None}
    channel_map = _channel_map(getattr(args, "channel_map", None))
    if channel_map:
        options["channel_map"] = channel_map
    return options
