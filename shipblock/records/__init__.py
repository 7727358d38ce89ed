"""Ground-motion records: the record type, reading, sensors, response removal, folders, catalogue.

The layer above the format readers (:mod:`shipblock.io`) and below processing, the models and
the studies (docs/architecture.rst). Its modules, in the order a record passes them:

=====================================  =======================================================
:mod:`~shipblock.records.reading`      :func:`read_motion`: files, a folder holding one record,
                                       or a Stream, to a :class:`GroundMotion`
:mod:`~shipblock.records.arguments`    the reading options, checked before any file is read
:mod:`~shipblock.records.assembly`     the traces of one record to a :class:`GroundMotion`
:mod:`~shipblock.records.alignment`    gaps inside a channel; one rate and window per record
:mod:`~shipblock.records.sensors`      sensor selection, orientation, components H1/H2/V
:mod:`~shipblock.records.response`     counts or stated units to m/s^2 (response removal)
:mod:`~shipblock.records.motion`       the record type :class:`GroundMotion`
:mod:`~shipblock.records.folders`      :func:`read_motions`: a folder to one record per sensor
:mod:`~shipblock.records.catalogue`    the catalogue of shipped records (:func:`load_catalogue`)
=====================================  =======================================================

The names below are re-exported here; the top-level package also offers the main ones
(``shipblock.read_motion``, ``shipblock.GroundMotion``, ``shipblock.read_motions``,
``shipblock.load_catalogue``).
"""

from __future__ import annotations

from shipblock.records.catalogue import load_catalogue
from shipblock.records.folders import MotionSet, read_motions
from shipblock.records.motion import (
    COMPONENT_KEY,
    COMPONENTS,
    GroundMotion,
    require_components,
    rotate_to_azimuth,
)
from shipblock.records.reading import read_motion

__all__ = [
    "COMPONENTS",
    "COMPONENT_KEY",
    "GroundMotion",
    "MotionSet",
    "load_catalogue",
    "read_motion",
    "read_motions",
    "require_components",
    "rotate_to_azimuth",
]
