"""Physical constants, unit names and conversions.

This module is the only home of physical constants and of unit names in shipblock: the SI
factors of acceleration and velocity units, the spellings of units that records and users write
(:data:`UNIT_ALIASES`, :func:`canonical_unit`, :func:`canonical_velocity_unit`) and the
conversions. Everything inside the package is SI (m, s, kg, rad, m/s^2); conversions from user
and record units happen once, at the edges (the record readers of :mod:`shipblock.io`, the
records of :mod:`shipblock.records`, argument checks), through the helpers below. It sits at the
bottom of the package's layers (docs/architecture.rst) and imports only :mod:`shipblock.errors`.
"""

from __future__ import annotations

import numpy as np

from shipblock.errors import ParameterError, UnitsError

#: Standard acceleration of gravity [m/s^2] (CGPM 1901, ISO 80000-3).
STANDARD_GRAVITY = 9.80665

#: One inch [m] (international inch, 1959).
INCH = 0.0254

#: One long ton force [N] (2240 lb x 0.45359237 kg/lb x standard gravity): block capacities in
#: US Navy docking practice are stated in long tons.
LONG_TON_FORCE = 2240.0 * 0.45359237 * STANDARD_GRAVITY

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


#: Accepted spellings of acceleration units, mapped to the keys of
#: :data:`ACCELERATION_UNITS_TO_SI`.
UNIT_ALIASES: dict[str, str] = {
    "g": "g",
    "g's": "g",
    "gs": "g",
    "g'": "g",
    "gal": "gal",
    "gals": "gal",
    "cm/s^2": "cm/s^2",
    "cm/s**2": "cm/s^2",
    "cm/s/s": "cm/s^2",
    "cm/s2": "cm/s^2",
    "cm/sec^2": "cm/s^2",
    "cm/sec2": "cm/s^2",
    "cm/sec/sec": "cm/s^2",
    "cm/sec**2": "cm/s^2",
    "m/s^2": "m/s^2",
    "m/s**2": "m/s^2",
    "m/s/s": "m/s^2",
    "m/s2": "m/s^2",
    "m/sec^2": "m/s^2",
    "m/sec2": "m/s^2",
    "m/sec/sec": "m/s^2",
    "mm/s^2": "mm/s^2",
    "mm/s**2": "mm/s^2",
    "mm/s/s": "mm/s^2",
    "mm/s2": "mm/s^2",
    "nm/s^2": "nm/s^2",
    "nm/s**2": "nm/s^2",
    "nm/s/s": "nm/s^2",
    "nm/s2": "nm/s^2",
    "m/(s**2)": "m/s^2",
    "m/sec**2": "m/s^2",
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


def canonical_unit(unit: str) -> str | None:
    """Map a spelling of an acceleration unit to a key of the SI conversion table.

    Parameters
    ----------
    unit : str
        For example ``"g"``, ``"G's"``, ``"cm/sec2"``, ``"gal"``, ``"m/s^2"``.

    Returns
    -------
    str or None
        A key of :data:`ACCELERATION_UNITS_TO_SI`, or ``None`` if unknown.
    """
    key = unit.strip().lower().replace(" ", "")
    key = UNIT_ALIASES.get(key, key)
    return key if key in ACCELERATION_UNITS_TO_SI else None


def canonical_velocity_unit(unit: str | None) -> str | None:
    """Map a spelling of a velocity unit (``"M/S"``, ``"cm/sec"``) to a key of
    :data:`VELOCITY_UNITS_TO_SI`, or ``None`` if it is not one."""
    key = (unit or "").strip().lower().replace(" ", "").replace("sec", "s")
    return key if key in VELOCITY_UNITS_TO_SI else None


def si_factor(unit: str, name: str) -> float:
    """Return the factor that converts ``unit`` to m/s^2.

    Parameters
    ----------
    unit : str
        An acceleration unit (any spelling accepted by :func:`canonical_unit`).
    name : str
        File name, for the error message.

    Returns
    -------
    float
        Conversion factor [m/s^2 per unit].

    Raises
    ------
    UnitsError
        If the unit is not a known acceleration unit.
    """
    key = canonical_unit(unit)
    if key is None:
        known = ", ".join(sorted(set(UNIT_ALIASES.values())))
        raise UnitsError(name, f"unknown acceleration unit {unit!r}; known units: {known}")
    return ACCELERATION_UNITS_TO_SI[key]
