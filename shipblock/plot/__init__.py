"""Figures: response histories, records, spectra, IDA and fragility curves.

Every function takes ``ax=None`` (or ``axes=None`` for multi-panel figures), draws into the given
axes or a new figure, and returns what it drew. Nothing here calls ``plt.show()``. Accelerations
are shown in g, displacements in cm and rotations in mrad: the units engineers read at a glance;
the data stay SI.

Every figure says what it shows: a study's figures the study, system and design
(:func:`study_caption`), a response the record, system and outcome, a record its station,
component and event (:func:`record_text`), and each the time window shown when it is not the
whole record.

* :mod:`shipblock.plot.response`: :func:`plot_response`, :func:`plot_record`,
  :func:`plot_spectrum`;
* :mod:`shipblock.plot.section`: :func:`plot_section_response` (a run of the dock-section
  model);
* :mod:`shipblock.plot.study`: :func:`plot_fragility`, :func:`plot_ida`,
  :func:`plot_median_sweep`;
* :mod:`shipblock.plot.record`: :func:`plot_record_overview` (``shipblock info --figure``).
"""

from __future__ import annotations

import importlib

from shipblock.plot._common import (
    SUPTITLE_WIDTH,
    TITLE_WIDTH,
    active_window,
    record_line,
    record_text,
    system_text,
)
from shipblock.plot.record import SPECTRUM_PERIODS, plot_record_overview, stated_peaks
from shipblock.plot.response import (
    EVENT_STYLES,
    MAX_IMPACT_LINES,
    MAX_SLIP_EVENT_LINES,
    MODE_COLOURS,
    SLIP_EVENTS,
    dataset_record_line,
    mode_spans,
    plot_record,
    plot_response,
    plot_spectrum,
    run_name,
)
from shipblock.plot.section import is_section_response, plot_section_response
# The study figures load on first use: shipblock.fragility imports the solver, which a command
# that draws a response or a record must not import (nor compile).
_STUDY = ("DODGE", "MARKER_SIZE", "MARKER_STEP", "check_edp", "default_edp", "limit_state_text",
          "marker_sizes",
          "plot_fragility", "plot_ida", "plot_median_sweep", "study_caption", "sweep_selection",
          "sweep_text")


def __getattr__(name):
    if name in _STUDY:
        return getattr(importlib.import_module("shipblock.plot.study"), name)
    raise AttributeError(f"module 'shipblock.plot' has no attribute {name!r}")


def __dir__():
    """The names loaded so far and the study figures' (loaded on first use)."""
    return sorted(set(globals()) | set(_STUDY))


__all__ = [
    "DODGE",
    "EVENT_STYLES",
    "MARKER_SIZE",
    "MARKER_STEP",
    "MAX_IMPACT_LINES",
    "MAX_SLIP_EVENT_LINES",
    "MODE_COLOURS",
    "SLIP_EVENTS",
    "SPECTRUM_PERIODS",
    "SUPTITLE_WIDTH",
    "TITLE_WIDTH",
    "active_window",
    "check_edp",
    "dataset_record_line",
    "default_edp",
    "is_section_response",
    "limit_state_text",
    "marker_sizes",
    "mode_spans",
    "plot_fragility",
    "plot_ida",
    "plot_median_sweep",
    "plot_record",
    "plot_record_overview",
    "plot_response",
    "plot_section_response",
    "plot_spectrum",
    "record_line",
    "record_text",
    "run_name",
    "stated_peaks",
    "study_caption",
    "sweep_selection",
    "sweep_text",
    "system_text",
]
