"""Quantities with units where a user types them: ``"20000 t"``, ``"600mm"``, ``"1.2e6 kg"``.

The command line (``--ship-mass "20000 t"``, ``--half-width 600mm``) and TOML files
(``ship_mass = "20000 t"`` in a ``[system]`` table) accept a number with a unit for every
dimensional parameter; :func:`to_si` converts it, once, at that edge, to the SI unit the
parameter is kept in. Plain numbers (``20000``, ``0.6``, also as strings) are SI already and are
returned unchanged. Parsing and conversion are pint's [1]_ (its default unit registry: ``t`` and
``tonne`` are the metric ton, ``mm``, ``cm``, ``ft``, ``lb``, ``kN``, ...); a unit of the wrong
dimension (``"20 kt"`` is 20 knots in pint, a speed, not 20 kilotonnes) or one pint does not know
is a :class:`~shipblock.errors.ParameterError` naming the parameter (its key or command-line
flag).

References
----------
.. [1] pint, physical quantities for Python, https://pint.readthedocs.io
"""

from __future__ import annotations

import math
from functools import cache

import pint

from shipblock.errors import ParameterError, ParameterTypeError

__all__ = ["to_si"]


@cache
def _registry() -> pint.UnitRegistry:
    """pint's default unit registry (made once: building it takes ~0.1 s)."""
    return pint.UnitRegistry()


def to_si(value, unit: str, key: str) -> float:
    """A number, or a number with a unit, in the SI unit of a parameter.

    Parameters
    ----------
    value : float, int or str
        A plain number (already in ``unit``), or a string: a number alone (``"0.6"``, SI) or
        with a unit (``"20000 t"``, ``"600mm"``, ``"1.2e6 kg"``).
    unit : str
        The parameter's SI unit in pint's spelling (``"kg"``, ``"m"``, ``"kg * m**2"``,
        ``"m/s**2"``; ``""`` for a dimensionless one).
    key : str
        The parameter's name where the user gave it (``"ship_mass"``, ``"--ship-mass"``), for
        messages.

    Returns
    -------
    float
        The value in ``unit``.

    Raises
    ------
    ParameterError
        Naming ``key``: a string that is not a quantity, a unit pint does not know, a unit of
        another dimension than ``unit``'s, or a value that is not finite (also a
        :class:`~shipblock.errors.ParameterTypeError`, a :class:`TypeError`, for a value that is
        neither a number nor a string).

    Examples
    --------
    >>> to_si("20000 t", "kg", "ship_mass")
    20000000.0
    >>> to_si("600mm", "m", "--half-width")
    0.6
    >>> to_si(0.6, "m", "half_width")
    0.6
    """
    wanted = f"a number in {unit or 'no unit'} or a quantity such as " + (
        {"kg": "'20000 t'", "m": "'600 mm'"}.get(unit, f"'1 {unit}'") if unit else "'0.5'")
    if isinstance(value, bool) or not isinstance(value, int | float | str):
        raise ParameterTypeError(f"{key} must be {wanted}, got {type(value).__name__} {value!r}")
    if not isinstance(value, str):
        return float(value)
    ureg = _registry()
    try:
        quantity = ureg.Quantity(value.strip())
    except (pint.UndefinedUnitError, pint.errors.DefinitionSyntaxError, ValueError,
            AttributeError, TypeError, SyntaxError) as exc:
        raise ParameterError(f"{key} must be {wanted}, got {value!r} ({exc})") from None
    if not isinstance(quantity, pint.Quantity):  # "3" parses to a plain number
        quantity = ureg.Quantity(float(quantity), "")
    if quantity.unitless:
        number = float(quantity.magnitude)
    else:
        try:
            number = float(quantity.to(unit or "dimensionless").magnitude)
        except pint.DimensionalityError:
            raise ParameterError(
                f"{key} must be {wanted}: {value!r} is a {quantity.dimensionality}, not a"
                f" {ureg.Quantity(1, unit or 'dimensionless').dimensionality}"
                f" (pint reads {quantity.units:~} as {quantity.units})") from None
    if not math.isfinite(number):
        raise ParameterError(f"{key} must be a finite quantity, got {value!r}")
    return number
