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

__all__ = ["ALIGNS", "GAPS", "RESPONSES", "check_channel_map", "check_read_arguments"]

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
