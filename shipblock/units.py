"""Physical constants and unit conversions.

This module is the only home of physical constants in shipblock. Everything inside the package is
SI (m, s, kg, rad, m/s^2); conversions from user units happen once, at the edges, through the
helpers below.
"""

from __future__ import annotations

import numpy as np

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
    "in/s^2": INCH,
    "in/s**2": INCH,
    "g": STANDARD_GRAVITY,
}


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
    try:
        factor = ACCELERATION_UNITS_TO_SI[unit.strip().lower()]
    except KeyError:
        known = ", ".join(sorted(ACCELERATION_UNITS_TO_SI))
        raise ValueError(f"unknown acceleration unit {unit!r}; known units: {known}") from None
    return np.asarray(values, dtype=float) * factor
