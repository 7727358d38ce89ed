"""Physical constants and unit conversions.

This module is the only home of physical constants in shipblock. Everything inside the package is
SI (m, s, kg, rad, m/s^2); conversions from user units happen once, at the edges, through the
helpers below.
"""

from __future__ import annotations

import numpy as np

from shipblock.errors import ParameterError

#: Standard acceleration of gravity [m/s^2] (CGPM 1901, ISO 80000-3).
STANDARD_GRAVITY = 9.80665

#: One inch [m] (international inch, 1959).
INCH = 0.0254

#: Factors that convert an acceleration in the named unit to m/s^2.
ACCELERATION_UNITS_TO_SI: dict[str, float] = {
    "m/s^2": 1.0,
    "m/s**2": 1.0,
    "m/s/s": 1.0,
    "cm/s^2": 0.01,
    "cm/s**2": 0.01,
    "cm/s/s": 0.01,
    "gal": 0.01,
    "mm/s^2": 0.001,
    "mm/s**2": 0.001,
    "nm/s^2": 1e-9,
    "nm/s**2": 1e-9,
    "in/s^2": INCH,
    "in/s**2": INCH,
    "g": STANDARD_GRAVITY,
    "mg": STANDARD_GRAVITY * 1e-3,
    "micro-g": STANDARD_GRAVITY * 1e-6,
}


#: Factors that convert a velocity in the named unit to m/s (e.g. PGV levels).
VELOCITY_UNITS_TO_SI: dict[str, float] = {
    "m/s": 1.0,
    "cm/s": 0.01,
    "mm/s": 0.001,
    "nm/s": 1e-9,
    "in/s": INCH,
}


def _to_si(values, unit: str, table: dict[str, float], quantity: str):
    try:
        factor = table[unit.strip().lower()]
    except KeyError:
        known = ", ".join(sorted(table))
        raise ParameterError(f"unknown {quantity} unit {unit!r}; known units: {known}") from None
    return np.asarray(values, dtype=float) * factor


def acceleration_to_si(values, unit: str):
    """Convert accelerations from ``unit`` to m/s^2.

    Parameters
    ----------
    values : array_like
        Accelerations in ``unit``.
    unit : str
        One of the keys of :data:`ACCELERATION_UNITS_TO_SI` (case-insensitive), for example
        ``"g"``, ``"cm/s^2"``, ``"gal"`` or ``"m/s^2"``.

    Returns
    -------
    numpy.ndarray
        Accelerations [m/s^2].

    Raises
    ------
    ValueError
        If the unit is not known.
    """
    return _to_si(values, unit, ACCELERATION_UNITS_TO_SI, "acceleration")


def velocity_to_si(values, unit: str):
    """Convert velocities from ``unit`` to m/s.

    Parameters
    ----------
    values : array_like
        Velocities in ``unit``.
    unit : str
        One of the keys of :data:`VELOCITY_UNITS_TO_SI` (case-insensitive): ``"m/s"``,
        ``"cm/s"``, ``"mm/s"`` or ``"in/s"``.

    Returns
    -------
    numpy.ndarray
        Velocities [m/s].

    Raises
    ------
    ValueError
        If the unit is not known.
    """
    return _to_si(values, unit, VELOCITY_UNITS_TO_SI, "velocity")
