r"""The rigid ship-block model of the seed paper as a :class:`~shipblock.models.base.Model`.

The adapter between the study machinery and the rigid model: a rigid ship on ``n`` identical
rigid keel blocks (:class:`shipblock.ShipBlockSystem`), solved event by event
(:func:`shipblock.simulate` for one run with histories, :func:`shipblock.simulate_batch` for
a batch). Its parameters are the fields of :class:`~shipblock.ShipBlockSystem` (ranges of
:data:`shipblock.system.FIELD_LIMITS`) and two conveniences of a ``[system]`` table:

``slenderness``
    :math:`B/H` [-]: ``half_width = slenderness * half_height`` (instead of ``half_width``).
``mass_ratio``
    :math:`nm/M` [-]: ``block_mass = mass_ratio * ship_mass / n_blocks`` (instead of
    ``block_mass``).

Swept parameters (:data:`SWEEP_PARAMETERS`) are any field plus four conveniences:
``slenderness`` and ``mass_ratio`` as above, and ``mu_ground``, ``mu_ship``: the static
friction coefficient of an interface [-], the kinetic one keeping its ratio to the static one
in the base system (``mu_k = mu * mu_k_base / mu_s_base``), so a sweep never produces kinetic
friction above static friction. Conveniences are applied after the plain fields, so
``half_height`` and ``slenderness`` may be swept together (the width follows the height).

:meth:`RigidModel.run_batch` hands whole batches to the compiled
:func:`~shipblock.simulate_batch` (one call per chunk of a study), so the seam costs nothing
per run.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import fields
from types import MappingProxyType
from typing import Any

import numpy as np

from shipblock.checks import whole
from shipblock.errors import ParameterError
from shipblock.interface_forces import LOAD_FIELDS
from shipblock.models.base import EDPInfo, Field, FieldError, Model
from shipblock.modes import MODE_DESCRIPTIONS, MODE_FLAGS, Failure
from shipblock.solver import (
    DEFAULT_ATOL,
    DEFAULT_RTOL,
    DEFAULT_ZENO_OMEGA,
    MODE_TIME_FIELDS,
    SUMMARY_FIELDS,
    simulate,
    simulate_batch,
)
from shipblock.solver._inputs import ATOL_RANGE, MAX_ZENO_OMEGA, RTOL_RANGE
from shipblock.system import (
    FIELD_LIMITS,
    FIELD_UNITS,
    IMPACT_RULES,
    MIN_INERTIA_RATIO,
    ShipBlockSystem,
    system_line,
    warn_implausible,
)

__all__ = [
    "EDP_VARIABLES",
    "FAILURE_CODES",
    "RUN_VARIABLES",
    "SWEEP_PARAMETERS",
    "SYSTEM_FIELDS",
    "RigidModel",
    "apply_parameters",
]

#: ShipBlockSystem constructor fields.
SYSTEM_FIELDS = tuple(f.name for f in fields(ShipBlockSystem))

#: Meaning of the integer ``failure`` code of a run summary.
FAILURE_CODES: Mapping[int, str] = MappingProxyType({0: "none", 1: "separation", 2: "overturning"})

#: Parameters that may be swept: name -> (units, long name). The plain names are fields of
#: :class:`~shipblock.ShipBlockSystem`; see the module docstring for the conveniences.
SWEEP_PARAMETERS: Mapping[str, tuple[str, str]] = {
    "ship_mass": ("kg", "ship mass M"),
    "block_mass": ("kg", "mass of one keel block m"),
    "n_blocks": ("1", "number of keel blocks n"),
    "half_width": ("m", "block half width B"),
    "half_height": ("m", "block half height H"),
    "mu_s_ground": ("1", "static friction coefficient, blocks on ground"),
    "mu_k_ground": ("1", "kinetic friction coefficient, blocks on ground"),
    "mu_s_ship": ("1", "static friction coefficient, ship on blocks"),
    "mu_k_ship": ("1", "kinetic friction coefficient, ship on blocks"),
    "restitution": ("1", "coefficient of restitution of rocking impacts"),
    "block_inertia": ("kg m^2", "centroidal inertia of one block I"),
    "g": ("m/s^2", "acceleration of gravity"),
    "slenderness": ("1", "block slenderness B/H (half width over half height)"),
    "mass_ratio": ("1", "total block mass over ship mass nm/M"),
    "mu_ground": ("1", "static friction coefficient blocks-ground (kinetic/static ratio kept)"),
    "mu_ship": ("1", "static friction coefficient ship-blocks (kinetic/static ratio kept)"),
}

_CONVENIENCES = ("slenderness", "mass_ratio", "mu_ground", "mu_ship")
_CONFLICTS = {
    "slenderness": ("half_width",),
    "mass_ratio": ("block_mass",),
    "mu_ground": ("mu_s_ground", "mu_k_ground"),
    "mu_ship": ("mu_s_ship", "mu_k_ship"),
}

#: Summary variables that limit states may refer to. ``failure_time`` [s] is also part of a run
#: summary but is not an EDP (it is undefined for runs that did not fail).
EDP_VARIABLES: Mapping[str, EDPInfo] = MappingProxyType(
    {
        "peak_block_slip": EDPInfo("m", "peak absolute block slip max|x_b|", "float", True),
        "peak_ship_slip": EDPInfo("m", "peak absolute ship slip max|x_s|", "float", True),
        "peak_rotation": EDPInfo("rad", "peak absolute block rotation max|theta|", "float", True),
        "peak_rotation_ratio": EDPInfo(
            "1", "peak rotation over critical rotation max|theta|/theta_c", "float", True
        ),
        "residual_block_slip": EDPInfo("m", "residual block slip", "float", True, True),
        "residual_ship_slip": EDPInfo("m", "residual ship slip", "float", True, True),
        "uplift": EDPInfo("1", "block uplift (rocking) occurred", "bool", True),
        # contact loads, per block (shipblock.interface_forces): e.g. "keel block load above its capacity"
        **{name: EDPInfo(units, long_name, "float", True)
           for name, (units, long_name) in LOAD_FIELDS.items()},
        "n_impacts": EDPInfo("1", "number of rocking impacts", "count", True),
        "failure": EDPInfo(
            "1", "failure code (0 none, 1 separation, 2 overturning)", "code", False
        ),
    }
)


def _run_variables() -> dict[str, tuple[str, str]]:
    extra = {
        "peak_rotation_time": ("s", "time of the peak absolute block rotation"),
        "failure_time": ("s", "time of separation or overturning (NaN if none)"),
        "end_time": ("s", "time the simulation ended"),
        "n_events": ("1", "number of mode transitions and impacts"),
        "input_work": ("J", "work done by the ground motion"),
        "friction_dissipation": ("J", "energy dissipated by friction"),
        "impact_loss": ("J", "kinetic energy lost in rocking impacts"),
        "n_jams": ("1", "number of jams of a slipping interface (Painleve regime)"),
        "final_energy": ("J", "kinetic plus potential energy at the end of the run"),
    }
    out = {}
    for name in [*SUMMARY_FIELDS, "peak_rotation_ratio", *MODE_TIME_FIELDS]:
        if name in EDP_VARIABLES:
            info = EDP_VARIABLES[name]
            out[name] = (info.units, info.long_name)
        elif name in extra:
            out[name] = extra[name]
        elif name.startswith("time_in_mode_"):
            mode = int(name.rsplit("_", 1)[1])
            flags = ", ".join(f"{what} {state[bit]}" for what, state, bit in zip(
                ("blocks on ground", "blocks", "ship on blocks"),
                (("stick", "slide"), ("at rest", "rocking"), ("stick", "slide")),
                MODE_FLAGS[mode], strict=True))
            out[name] = ("s", f"time spent in mode {mode}: {MODE_DESCRIPTIONS[mode]} ({flags})")
        else:  # a summary field added to the solver later
            out[name] = ("1", name.replace("_", " "))
    return out


#: Per-run summary variables of a result dataset: name -> (units, long name). All are stored as
#: float64 with NaN for runs that produced no result (record or solver error); ``failure`` is
#: the code 0 none, 1 separation, 2 overturning (a solver error, code 3, is stored as NaN and
#: described in ``run_error``).
RUN_VARIABLES: dict[str, tuple[str, str]] = _run_variables()


def _parameter(name: str) -> Field:
    low, high, units = FIELD_LIMITS[name]
    doc = SWEEP_PARAMETERS[name][1]
    required = name not in ("restitution", "block_inertia", "g", "half_width", "block_mass")
    defaults = {"restitution": "from the mass and inertia ratios (system_restitution)",
                "block_inertia": "uniform block m (B^2 + H^2) / 3", "g": "9.80665",
                "half_width": "required unless slenderness", "block_mass":
                "required unless mass_ratio"}
    return Field(name, (float,), doc, units or "1", default=None, required=required, low=low,
                 high=high, low_open=name == "block_inertia", default_doc=defaults.get(name, ""),
                 quantity=FIELD_UNITS.get(name))


#: The ``[system]`` parameters of the rigid model.
PARAMETERS: Mapping[str, Field] = MappingProxyType({
    **{name: _parameter(name) for name in SYSTEM_FIELDS if name != "impact_rule"},
    "impact_rule": Field("impact_rule", (str,), "impact rule of a rocking block "
                         "(shipblock.impact)", default="momentum", choices=IMPACT_RULES),
    "slenderness": Field("slenderness", (float,), "block slenderness B/H; gives half_width = "
                         "slenderness * half_height", "1", default_doc="none (or half_width)"),
    "mass_ratio": Field("mass_ratio", (float,), "total block mass over ship mass nm/M; gives "
                        "block_mass = mass_ratio * ship_mass / n_blocks", "1",
                        default_doc="none (or block_mass)"),
})

#: The ``[solver]`` options of the rigid model (:func:`shipblock.simulate`).
OPTIONS: Mapping[str, Field] = MappingProxyType({
    "rtol": Field("rtol", (float,), "relative tolerance of the event-driven integration", "1",
                  default=DEFAULT_RTOL, low=RTOL_RANGE[0], high=RTOL_RANGE[1], high_open=True),
    "atol": Field("atol", (float,), "absolute tolerance of the event-driven integration", "1",
                  default=DEFAULT_ATOL, low=ATOL_RANGE[0], high=ATOL_RANGE[1]),
    "zeno_omega": Field("zeno_omega", (float,), "rocking rate below which impacts end in rest "
                        "(Zeno)", "rad/s", default=DEFAULT_ZENO_OMEGA, low=0.0,
                        high=MAX_ZENO_OMEGA),
})

# What a convenience multiplies to give the field it replaces.
_FACTOR = {"half_width": "half_height", "block_mass": "ship_mass / n_blocks"}

# Relations between parameters that no single range expresses: the parameter each names is
# the one reported when ShipBlockSystem refuses the combination.
_RELATIONS = (
    ("mu_k_ground", lambda p: p["mu_k_ground"] <= p["mu_s_ground"]),
    ("mu_k_ship", lambda p: p["mu_k_ship"] <= p["mu_s_ship"]),
    ("restitution", lambda p: p.get("impact_rule") != "plastic" or p.get("restitution") is None),
    ("block_inertia", lambda p: p.get("block_inertia") is None or MIN_INERTIA_RATIO
     <= p["block_inertia"] / (p["block_mass"] * (p["half_width"]**2 + p["half_height"]**2))
     <= 1.0),
)


def apply_parameters(system: ShipBlockSystem, values: Mapping[str, object]) -> ShipBlockSystem:
    """Return ``system`` with some parameters (plain fields or conveniences) changed.

    Parameters
    ----------
    system : ShipBlockSystem
        The base system.
    values : Mapping[str, object]
        Parameter name (a key of :data:`SWEEP_PARAMETERS`) -> value, in the units listed there.

    Returns
    -------
    ShipBlockSystem
        The changed, validated system.

    Raises
    ------
    ValueError
        If a name is unknown, two names set the same field (e.g. ``slenderness`` and
        ``half_width``), or the resulting system is invalid (the message of
        :class:`~shipblock.ShipBlockSystem` names the field).
    """
    unknown = [k for k in values if k not in SWEEP_PARAMETERS]
    if unknown:
        raise ParameterError(
            f"unknown system parameter(s) {', '.join(map(repr, unknown))}; known: "
            f"{', '.join(SWEEP_PARAMETERS)}"
        )
    for conv, plain in _CONFLICTS.items():
        clash = [p for p in plain if conv in values and p in values]
        if clash:
            raise ParameterError(f"{conv!r} and {clash[0]!r} both set the same parameter; give one")
    plain = {k: v for k, v in values.items() if k not in _CONVENIENCES}
    if "n_blocks" in plain:
        low, high, _ = FIELD_LIMITS["n_blocks"]
        plain["n_blocks"] = whole(plain["n_blocks"], "n_blocks", low=low, high=high)
    out = system.replace(**plain) if plain else system
    changes = {}
    if "slenderness" in values:
        changes["half_width"] = float(values["slenderness"]) * out.half_height
    if "mass_ratio" in values:
        changes["block_mass"] = float(values["mass_ratio"]) * out.ship_mass / out.n_blocks
    for iface in ("ground", "ship"):
        key = f"mu_{iface}"
        if key in values:
            mu = float(values[key])
            mus, muk = getattr(system, f"mu_s_{iface}"), getattr(system, f"mu_k_{iface}")
            ratio = muk / mus if mus > 0 else 1.0
            changes[f"mu_s_{iface}"] = mu
            changes[f"mu_k_{iface}"] = mu * ratio
    return out.replace(**changes) if changes else out


class RigidModel(Model):
    """The rigid ship on rigid keel blocks (seed paper), solved by :mod:`shipblock.solver`."""

    name = "rigid"
    description = "rigid ship on n identical rigid keel blocks (sliding, rocking, impacts)"
    parameters = PARAMETERS
    options = OPTIONS
    sweep_parameters = MappingProxyType(SWEEP_PARAMETERS)
    edps = EDP_VARIABLES
    outputs = MappingProxyType(RUN_VARIABLES)
    failure_codes = FAILURE_CODES
    solver_error_code = int(Failure.SOLVER_ERROR)
    default_edp = "peak_ship_slip"

    def build(self, values: Mapping[str, Any]) -> ShipBlockSystem:
        """A :class:`~shipblock.ShipBlockSystem` from a ``[system]`` table (see the module).

        The numbers were checked against :data:`PARAMETERS` by the caller; here the
        conveniences are resolved and the relations between parameters checked.

        Raises
        ------
        FieldError
            Naming the parameter as given (``slenderness`` for a ``half_width`` computed
            from it).
        """
        table = dict(values)
        given = {}
        for conv, plain in (("slenderness", "half_width"), ("mass_ratio", "block_mass")):
            if conv in table:
                if plain in table:
                    raise FieldError(conv, f"give {conv} or {plain}, not both")
                given[plain] = conv
            elif plain not in table:
                raise FieldError(plain, f"missing (give {plain} or {conv})")
        if "slenderness" in table:
            table["half_width"] = float(table.pop("slenderness")) * table["half_height"]
        if "mass_ratio" in table:
            n = table["n_blocks"]
            if isinstance(n, bool) or not isinstance(n, int) or n < 1:
                raise FieldError("n_blocks", f"must be a whole number >= 1, got {n!r}")
            table["block_mass"] = float(table.pop("mass_ratio")) * table["ship_mass"] / n
        for plain, conv in given.items():
            try:
                PARAMETERS[plain].check(table[plain])
            except FieldError as exc:
                raise FieldError(conv, f"{plain} = {conv} x {_FACTOR[plain]} "
                                 f"{exc.problem}") from None
        try:
            system = ShipBlockSystem(**table)
        except (TypeError, ValueError) as exc:
            field = next((f for f, holds in _RELATIONS if not _holds(holds, table)), "")
            raise FieldError(given.get(field, field), str(exc)) from None
        warn_implausible(system, "the [system] table")  # most likely a unit mistake
        return system

    def vary(self, system: ShipBlockSystem, values: Mapping[str, Any]) -> ShipBlockSystem:
        """:func:`apply_parameters`."""
        return apply_parameters(system, values)

    def describe(self, system: ShipBlockSystem) -> dict:
        """:meth:`ShipBlockSystem.to_dict <shipblock.ShipBlockSystem.to_dict>`."""
        return system.to_dict()

    def restore(self, described: Mapping[str, Any]) -> ShipBlockSystem:
        """:class:`~shipblock.ShipBlockSystem` from its ``to_dict()``."""
        return ShipBlockSystem(**described)

    def caption(self, system: ShipBlockSystem) -> str:
        """:func:`system_line`."""
        return system_line(system.to_dict())

    def run_batch(self, systems: Sequence[ShipBlockSystem], inputs: Sequence[tuple],
                  dts: Sequence[float], cases: np.ndarray, **options) -> dict[str, np.ndarray]:
        """One :func:`shipblock.simulate_batch` call for all the cases (unit scale factors:
        the inputs are scaled already)."""
        cases = np.asarray(cases, dtype=np.int64).reshape(-1, 2)
        ones = np.ones(len(cases))
        batch = np.column_stack([cases[:, 0], cases[:, 1], ones, ones])
        return simulate_batch(systems, inputs, dts, batch, **options)

    def simulate(self, system: ShipBlockSystem, horizontal, vertical, dt: float, **options):
        """:func:`shipblock.simulate`: a :class:`~shipblock.SimulationResult`."""
        return simulate(system, horizontal, vertical, dt, **options)


def _holds(relation, table) -> bool:
    try:
        return bool(relation(table))
    except (KeyError, TypeError, ZeroDivisionError, ArithmeticError):
        return True  # a missing or non-numeric value: not this relation's failure

