r"""The dock-section model (:mod:`shipblock.section`) as a :class:`~shipblock.models.base.Model`.

The adapter between the study machinery and the dock section of issue 29: a ship that sways,
heaves and rolls on a keel-block line and zero, one or two side-block lines with compliant
timber caps (:class:`~shipblock.section.DockSection`), run by
:func:`~shipblock.section.simulate_section`. A pipeline chooses it with
``[system] model = "section"``.

The ``[system]`` table
----------------------
The nested description of :mod:`shipblock.section.parameters` (a ship, lines, blocks, caps,
wind) flattened into keys a dock engineer can write in a docking plan's units (every
dimensional key also takes a quantity with a unit: ``ship_mass = "9000 t"``,
``block_half_width = "24 in"``, ``cap_modulus = "0.886 GPa"``); every key is declared in
:data:`PARAMETERS` with the range of the section's own checks (the ``LIMITS`` of
:class:`~shipblock.section.Ship`, :class:`~shipblock.section.Block`,
:class:`~shipblock.section.Cap`, :class:`~shipblock.section.BlockLine`,
:class:`~shipblock.section.Wind`), and a relation no single range expresses is refused by the
section's own constructors with the ``[system]`` key named (:meth:`SectionModel.build`).

* the ship: ``ship_mass``, ``roll_inertia`` or ``roll_radius`` (radius of gyration about G:
  :math:`I = M r^2`), ``g_height`` (KG above the keel's underside), ``g_offset`` (G off the
  centre line, a list), ``keel_half_width``, ``half_beam`` (at the supports);
* the keel line: ``keel_blocks`` (blocks under the whole ship);
* the side lines: ``side_lines`` (0, 1 or 2), ``side_blocks`` (per line), ``side_offset``
  (distance of a line's centre from the centre line), ``side_hull_height`` and
  ``side_hull_slope`` (the hull's underside there, above the keel's underside and rising
  outboard), ``side_moving`` (false: fixed to the floor), ``side_block_half_height`` (default:
  built to touch the hull, ``block_half_height + side_hull_height / 2``). Two lines stand
  symmetrically, starboard (``side0``) and port (``side1``); one line stands to starboard;
  with ``side_lines = 0`` the other side keys are ignored (so a study may sweep
  ``side_lines`` from one base table);
* the blocks (every line; defaults the US Navy keel block of
  :data:`~shipblock.section.NAVY_BLOCK`): ``block_half_width``, ``block_half_height``,
  ``block_length``, ``block_mass`` (default: concrete core and oak caps), ``block_capacity``;
* the caps (top and bottom alike; defaults white oak): ``cap_thickness``, ``cap_material``
  (a timber of :data:`~shipblock.section.parameters.CAP_MATERIALS`, which gives the modulus
  and the proportional limit) or ``cap_modulus`` and ``cap_proportional_limit`` (not both),
  ``cap_stiffness`` (default ``E A / t``), ``cap_damping_ratio``, ``cap_shear_ratio``;
* friction: ``mu_s_top``, ``mu_k_top`` (hull on the top caps), ``mu_s_bottom``,
  ``mu_k_bottom`` (blocks on the floor);
* wind: ``wind_force``, or ``wind_pressure`` and ``wind_area``; ``wind_height``;
* ``n_springs`` (springs across a cap) and ``g``.

Swept parameters are every numeric key, ``cap_material`` (a list of names: a string
dimension of the study) and two conveniences, ``mu_top`` and ``mu_bottom``:
the static friction coefficient of a face, the kinetic one keeping its ratio to the static one
in the base system (as the rigid model's ``mu_ship``).

EDPs and failure codes
----------------------
:data:`EDP_VARIABLES`: the capacity ratios of issue 30 (``keel_load_ratio``: peak load per
keel block over its capacity; ``side_load_ratio``; the cap pressures over the proportional
limit), the ship's roll and sway (also relative to the keel cap's half-width: ``sway_ratio``
1 means the keel's centre stands over the cap's edge), the crushing set, and each failure kind
as a boolean EDP of its own (``tipped_off``, ``block_line_overturned``, ``slid_off``,
``separated``, ``out_of_validity``) beside the ``failure`` code (:data:`FAILURE_CODES`). A run
that stalls (too many events) or raises is a solver error (code 6): the batch stores NaN and a
message, and never loses the chunk's other runs.
"""

from __future__ import annotations

import logging
import math
import re
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field, replace
from types import MappingProxyType
from typing import Any

import numpy as np

from shipblock.errors import ParameterError, ShipblockError
from shipblock.models.base import EDPInfo, Field, FieldError, Model
from shipblock.section import NAVY_BLOCK, Block, BlockLine, Cap, DockSection, Ship, Wind
from shipblock.section.model import InitialState, assemble
from shipblock.section.parameters import (
    CAP_MATERIALS,
    DEFAULT_CAP_MATERIAL,
    DEFAULT_SPRINGS,
    MAX_BLOCKS,
    MAX_HULL_SLOPE,
    MAX_SIDE_LINES,
    SPRING_COUNTS,
    ZERO_ALLOWED,
)
from shipblock.section.simulate import (
    DEFAULT_ATOL,
    DEFAULT_MAX_EVENTS,
    DEFAULT_RTOL,
    DEFAULT_SEPARATION_HEIGHT,
    SectionResult,
    SectionRunner,
    rest_state,
)
from shipblock.units import STANDARD_GRAVITY

__all__ = ["EDP_VARIABLES", "FAILURE_CODES", "OPTIONS", "PARAMETERS", "RUN_VARIABLES",
           "SWEEP_PARAMETERS", "SectionModel", "SectionRun", "SectionSystem"]

logger = logging.getLogger(__name__)

#: Meaning of the integer ``failure`` code (0 and the first two as the rigid model's).
FAILURE_CODES: Mapping[int, str] = MappingProxyType({
    0: "none", 1: "separation", 2: "block line overturned", 3: "slid off the keel cap",
    4: "tipped off a support line", 5: "out of the model's validity", 6: "solver error"})
SOLVER_ERROR = 6
#: :func:`~shipblock.section.simulate_section`'s failure name -> code.
_FAILURE_OF = {"separation": 1, "block_line_overturns": 2, "slid_off_keel": 3, "ship_tips": 4,
               "out_of_validity": 5, "stalled": SOLVER_ERROR}
#: Boolean EDP of each failure kind -> its code.
FAILURE_FLAGS: Mapping[str, int] = MappingProxyType({
    "separated": 1, "block_line_overturned": 2, "slid_off": 3, "tipped_off": 4,
    "out_of_validity": 5})


# ------------------------------------------------------------------------------------------
# parameters
# ------------------------------------------------------------------------------------------

def _limited(name, limits, key, doc, units, quantity, default=None, **kw) -> Field:
    """A number field with the range of a section class's ``LIMITS`` entry ``key``."""
    low, high, _, _ = limits[key]
    return Field(name, (float,), doc, units, default=default, low=low, high=high,
                 low_open=low == 0.0 and key not in ZERO_ALLOWED, quantity=quantity, **kw)


_CAP, _BLOCK, _SHIP = Cap(), NAVY_BLOCK, Ship.LIMITS
_NUMBER = (float,)

#: The ``[system]`` parameters of the section model (SI units; see the module docstring).
PARAMETERS: Mapping[str, Field] = MappingProxyType({f.name: f for f in (
    # the ship
    _limited("ship_mass", _SHIP, "mass", "ship's mass carried by the blocks", "kg", "kg",
             required=True),
    _limited("roll_inertia", _SHIP, "roll_inertia", "ship's roll inertia about G", "kg m^2",
             "kg * m**2", default_doc="none (or roll_radius)"),
    Field("roll_radius", _NUMBER, "ship's radius of gyration in roll about G: roll_inertia = "
          "ship_mass * roll_radius^2", "m", low=1e-3, high=100.0, quantity="m",
          default_doc="none (or roll_inertia)"),
    Field("g_height", _NUMBER, "height of G above the keel's underside (KG)", "m",
          required=True, low=0.0, high=100.0, low_open=True, quantity="m"),
    _limited("g_offset", _SHIP, "g_offset", "offset of G from the centre line, positive to "
             "starboard (a list)", "m", "m", default=0.0),
    _limited("keel_half_width", _SHIP, "keel_half_width", "half-width of the flat keel", "m",
             "m", required=True),
    _limited("half_beam", _SHIP, "half_beam", "half the ship's beam at the supports", "m", "m",
             required=True),
    # the keel line
    Field("keel_blocks", (int,), "number of keel blocks under the ship", "1", required=True,
          low=1, high=MAX_BLOCKS),
    # the side lines
    Field("side_lines", (int,), "number of side-block lines: 0; 1 (starboard); 2 (starboard "
          "and port, symmetric)", "1", default=2, low=0, high=MAX_SIDE_LINES),
    Field("side_blocks", (int,), "number of blocks in each side line", "1", low=1,
          high=MAX_BLOCKS, default_doc="required with side lines"),
    Field("side_offset", _NUMBER, "distance of a side line's centre from the centre line",
          "m", low=0.0, high=100.0, low_open=True, quantity="m",
          default_doc="required with side lines"),
    _limited("side_hull_height", BlockLine.LIMITS, "hull_height", "height of the hull's "
             "underside above the keel's underside at the side lines", "m", "m", default=0.0),
    Field("side_hull_slope", _NUMBER, "slope (deadrise) of the hull at the side lines, "
          "rising outboard", "rad", default=0.0, low=-MAX_HULL_SLOPE, high=MAX_HULL_SLOPE,
          quantity="rad"),
    Field("side_moving", (bool,), "side lines slide, rock and lift off (false: fixed to the "
          "floor)", default=True),
    _limited("side_block_half_height", Block.LIMITS, "half_height", "half the overall height "
             "of a side block", "m", "m",
             default_doc="block_half_height + side_hull_height / 2 (touching the hull)"),
    # the blocks
    _limited("block_half_width", Block.LIMITS, "half_width", "half the width of a block "
             "across the dock B", "m", "m", default=_BLOCK.half_width),
    _limited("block_half_height", Block.LIMITS, "half_height", "half the overall height of a "
             "keel block, caps included H", "m", "m", default=_BLOCK.half_height),
    _limited("block_length", Block.LIMITS, "length", "length of a block along the keel", "m",
             "m", default=_BLOCK.length),
    _limited("block_mass", Block.LIMITS, "mass", "mass of one block", "kg", "kg",
             default_doc="concrete core and oak caps"),
    _limited("block_capacity", Block.LIMITS, "capacity", "rated load of one block", "N", "N",
             default=_BLOCK.capacity),
    # the caps
    _limited("cap_thickness", Cap.LIMITS, "thickness", "thickness of a cap (top and bottom)",
             "m", "m", default=_CAP.thickness),
    Field("cap_material", (str,), "timber of the caps (Wood Handbook 2010 values: "
          "cap_modulus and cap_proportional_limit)", default=DEFAULT_CAP_MATERIAL,
          choices=tuple(CAP_MATERIALS)),
    _limited("cap_modulus", Cap.LIMITS, "modulus", "modulus of the caps across the grain "
             "(instead of cap_material's)", "Pa", "Pa",
             default_doc=f"cap_material's ({_CAP.modulus:.4g} Pa for white oak)"),
    _limited("cap_proportional_limit", Cap.LIMITS, "proportional_limit", "compression "
             "perpendicular to the grain at the proportional limit, crushing beyond (instead "
             "of cap_material's)", "Pa", "Pa",
             default_doc=f"cap_material's ({_CAP.proportional_limit:.4g} Pa for white oak)"),
    _limited("cap_stiffness", Cap.LIMITS, "stiffness", "normal stiffness of one block's cap",
             "N/m", "N/m", default_doc="cap_modulus x area / cap_thickness"),
    _limited("cap_damping_ratio", Cap.LIMITS, "damping_ratio", "viscous damping ratio of a "
             "cap", "1", None, default=_CAP.damping_ratio),
    _limited("cap_shear_ratio", Cap.LIMITS, "shear_ratio", "tangential over normal cap "
             "stiffness", "1", None, default=_CAP.shear_ratio),
    # friction
    _limited("mu_s_top", Cap.LIMITS, "mu_s", "static friction, hull on the top caps", "1",
             None, default=_CAP.mu_s),
    _limited("mu_k_top", Cap.LIMITS, "mu_k", "kinetic friction, hull on the top caps", "1",
             None, default=_CAP.mu_k),
    _limited("mu_s_bottom", Cap.LIMITS, "mu_s", "static friction, blocks on the floor", "1",
             None, default=_CAP.mu_s),
    _limited("mu_k_bottom", Cap.LIMITS, "mu_k", "kinetic friction, blocks on the floor", "1",
             None, default=_CAP.mu_k),
    # wind
    _limited("wind_force", Wind.LIMITS, "force", "steady lateral wind force on the ship, "
             "positive to starboard", "N", "N", default_doc="none (no wind)"),
    _limited("wind_pressure", Wind.LIMITS, "pressure", "wind pressure, positive to starboard "
             "(with wind_area)", "Pa", "Pa", default_doc="none"),
    _limited("wind_area", Wind.LIMITS, "area", "lateral area of the ship in the wind", "m^2",
             "m**2", default_doc="none"),
    _limited("wind_height", Wind.LIMITS, "height", "height of the wind's line of action above "
             "the keel's underside", "m", "m", default_doc="required with wind"),
    # the model
    Field("n_springs", (int,), "springs across each cap (Gauss-Lobatto points)", "1",
          default=DEFAULT_SPRINGS, low=SPRING_COUNTS[0], high=SPRING_COUNTS[1]),
    Field("g", _NUMBER, "acceleration of gravity", "m/s^2", default=STANDARD_GRAVITY,
          low=0.1, high=100.0),
)})

_WIND_KEYS = ("wind_force", "wind_pressure", "wind_area", "wind_height")
_CONVENIENCES = {"mu_top": ("mu_s_top", "mu_k_top"), "mu_bottom": ("mu_s_bottom", "mu_k_bottom")}

#: Parameters a study may sweep: name -> (units, long name).
SWEEP_PARAMETERS: Mapping[str, tuple[str, str]] = MappingProxyType({
    **{name: (f.units or "1", f.doc) for name, f in PARAMETERS.items()
       if bool not in f.types},
    "mu_top": ("1", "static friction, hull on the top caps (kinetic/static ratio kept)"),
    "mu_bottom": ("1", "static friction, blocks on the floor (kinetic/static ratio kept)"),
})

#: The ``[solver]`` options (:func:`~shipblock.section.simulate_section`).
OPTIONS: Mapping[str, Field] = MappingProxyType({
    "rtol": Field("rtol", _NUMBER, "relative tolerance of the integration", "1",
                  default=DEFAULT_RTOL, low=1e-12, high=1e-2),
    "atol": Field("atol", _NUMBER, "absolute tolerance of the integration", "1",
                  default=DEFAULT_ATOL, low=1e-15, high=1e-3),
    "separation_height": Field("separation_height", _NUMBER, "lift of the ship off every "
                               "support that counts as separation", "m",
                               default=DEFAULT_SEPARATION_HEIGHT, low=0.0, high=1.0,
                               low_open=True),
    "max_events": Field("max_events", (int,), "most located events of a run before it stops "
                        "as a solver error", "1", default=DEFAULT_MAX_EVENTS, low=1,
                        high=10**9),
    "exponential_steps": Field("exponential_steps", (bool,), "one exponential step per sample "
                               "while the dock is in its static regime or one it has settled "
                               "in (false: Dormand-Prince throughout)", "1", default=True),
})

# ------------------------------------------------------------------------------------------
# outputs
# ------------------------------------------------------------------------------------------

#: EDPs a limit state may use.
EDP_VARIABLES: Mapping[str, EDPInfo] = MappingProxyType({
    "keel_load_ratio": EDPInfo("1", "peak load per keel block over the block's capacity",
                               "float", True),
    "side_load_ratio": EDPInfo("1", "peak load per side block over its capacity, the larger "
                               "line (0 without side lines)", "float", True),
    "cap_pressure_ratio": EDPInfo("1", "peak cap pressure over the cap's proportional limit, "
                                  "the largest of every cap", "float", True),
    "keel_cap_pressure_ratio": EDPInfo("1", "peak keel-cap pressure over the proportional "
                                       "limit (top and bottom caps)", "float", True),
    "crushing_set": EDPInfo("m", "largest permanent set of a crushed cap", "float", True),
    "peak_roll": EDPInfo("rad", "peak absolute roll of the ship", "float", True),
    "residual_roll": EDPInfo("rad", "residual roll of the ship", "float", True, True),
    "peak_sway": EDPInfo("m", "peak sway of the keel relative to the keel blocks' tops",
                         "float", True),
    "residual_sway": EDPInfo("m", "residual sway of the keel relative to the keel blocks' "
                             "tops", "float", True, True),
    "sway_ratio": EDPInfo("1", "peak sway over the keel cap's half-width (1: the keel's centre "
                          "over the cap's edge)", "float", True),
    "residual_sway_ratio": EDPInfo("1", "residual sway over the keel cap's half-width",
                                   "float", True, True),
    "keel_slip": EDPInfo("m", "peak slip of the keel line on the floor", "float", True),
    "keel_rotation": EDPInfo("rad", "peak rotation of the keel line", "float", True),
    "friction_utilisation": EDPInfo("1", "peak friction utilisation |F_t|/N of any face",
                                    "float", True),
    **{name: EDPInfo("1", f"the run ended: {FAILURE_CODES[code]}", "bool", False)
       for name, code in FAILURE_FLAGS.items()},
    "failure": EDPInfo("1", "failure code (" + ", ".join(
        f"{c} {w}" for c, w in FAILURE_CODES.items() if c != SOLVER_ERROR) + ")", "code",
        False),
})


def _run_variables() -> dict[str, tuple[str, str]]:
    out = {name: (info.units, info.long_name) for name, info in EDP_VARIABLES.items()}
    for line, what in (("keel", "keel"), ("side0", "starboard side"), ("side1", "port side")):
        absent = "" if line == "keel" else " (NaN without the line)"
        out[f"{line}_peak_load_per_block"] = ("N", f"peak load per {what} block{absent}")
        out[f"{line}_capacity_ratio"] = ("1", f"peak load per {what} block over its "
                                         f"capacity{absent}")
        out[f"{line}_peak_top_pressure_ratio"] = ("1", f"peak {what} top-cap pressure over the "
                                                  f"proportional limit{absent}")
        out[f"{line}_peak_slip"] = ("m", f"peak slip of the {what} line{absent}")
        out[f"{line}_lift_off_time"] = ("s", f"time the hull was off the {what} line{absent}")
    out["failure_time"] = ("s", "time the run failed (NaN if it did not)")
    out["energy_residual"] = ("1", "relative residual of the run's energy balance")
    out["n_events"] = ("1", "number of located events")
    return out


#: Every per-run output of the batch: name -> (units, long name).
RUN_VARIABLES: Mapping[str, tuple[str, str]] = MappingProxyType(_run_variables())


# ------------------------------------------------------------------------------------------
# the system
# ------------------------------------------------------------------------------------------

@dataclass(frozen=True)
class SectionSystem:
    """A dock section as a study holds it: the ``[system]`` values as given, the section and
    the static state its runs start from.

    Attributes
    ----------
    values : dict
        The given ``[system]`` parameters (checked, SI units); derived defaults are derived
        again from them when a study varies one (:meth:`SectionModel.vary`, which builds a new
        system and solves its state).
    section : DockSection
        The section they describe.
    rest : InitialState or None
        :func:`~shipblock.section.simulate.rest_state` of the section, solved once by
        :meth:`SectionModel.build` (which refuses a dock without one) and handed to every
        runner of the system, here or in a worker process (it pickles with the system); None:
        each runner solves it.
    """

    values: dict
    section: DockSection = field(repr=False)
    rest: InitialState | None = field(default=None, repr=False, compare=False)

    def runner(self, **options) -> SectionRunner:
        """A :class:`~shipblock.section.SectionRunner` of the section with ``options``,
        starting from :attr:`rest` (unless that was settled at another ``separation_height``
        than the options': then the runner settles the dock again at theirs)."""
        rest = self.rest
        if rest is not None and rest.settled_separation_height not in (
                None, options.get("separation_height", DEFAULT_SEPARATION_HEIGHT)):
            rest = None
        return SectionRunner(self.section, initial_state=rest, **options)


# first dotted name of a section error -> the [system] key (relations: see _key_of)
_CLASS_KEYS = {
    "Ship.mass": "ship_mass", "Ship.roll_inertia": "roll_inertia", "Ship.g_height": "g_height",
    "Ship.keel_half_width": "keel_half_width", "Ship.half_beam": "half_beam",
    "Ship.g_offset": "g_offset", "Block.half_width": "block_half_width",
    "Block.half_height": "block_half_height", "Block.length": "block_length",
    "Block.mass": "block_mass", "Block.capacity": "block_capacity",
    "Block.top.thickness": "cap_thickness", "BlockLine.hull_height": "side_hull_height",
    "BlockLine.hull_slope": "side_hull_slope", "BlockLine.offset": "side_offset",
    "Wind.height": "wind_height", "Wind.force": "wind_force", "Wind.pressure": "wind_pressure",
    "Wind.area": "wind_area", "Wind": "wind_force",
    **{f"Cap.{k}": f"cap_{k}" for k in ("thickness", "modulus", "proportional_limit",
                                       "stiffness", "damping_ratio", "shear_ratio")},
}
_NAME = re.compile(r"(Ship|Block|Cap|BlockLine|Wind|DockSection)((?:\.[a-z_]+|\[\d\])*)")


def _key_of(message: str, values: Mapping) -> str:
    """The ``[system]`` key a section's error is about (``""`` if no single one)."""
    match = _NAME.search(message)
    if match is None:
        return ""
    name = match.group(0)
    if name.startswith("DockSection.keel"):
        if "friction" in message:
            return "mu_s_top" if "top face" in message else "mu_s_bottom"
        return "keel_blocks" if "crush" in message else ""
    if name.startswith("DockSection.sides"):
        if name.endswith(".offset"):
            return "side_offset"
        if "crush" in message:
            return "side_blocks"
        if "friction" in message:
            return "side_hull_slope"
        return ("side_block_half_height" if "side_block_half_height" in values
                else "side_hull_height")
    if name == "Ship.roll_inertia" and "roll_radius" in values:
        return "roll_radius"
    return _CLASS_KEYS.get(name, "")


def _integral(value, key: str) -> int:
    """A swept count given as a number: a whole one, as int."""
    if isinstance(value, bool) or not float(value).is_integer():
        raise FieldError(key, f"must be a whole number, got {value!r}")
    return int(value)


def _section(v: Mapping[str, Any]) -> DockSection:
    """The :class:`DockSection` of checked ``[system]`` values (defaults not yet applied)."""
    p = {name: v.get(name, f.default) for name, f in PARAMETERS.items()}
    for kind in ("top", "bottom"):
        if p[f"mu_k_{kind}"] > p[f"mu_s_{kind}"]:
            raise FieldError(f"mu_k_{kind}", f"({p[f'mu_k_{kind}']:g}) must not exceed "
                                             f"mu_s_{kind} ({p[f'mu_s_{kind}']:g}): kinetic "
                                             "friction above static friction is not physical")
    if (p["roll_inertia"] is None) == (p["roll_radius"] is None):
        raise FieldError("roll_inertia", "give roll_inertia or roll_radius (one of them)")
    inertia = (p["roll_inertia"] if p["roll_inertia"] is not None
               else p["ship_mass"] * p["roll_radius"] ** 2)
    n_sides = p["side_lines"]
    if n_sides:
        for key in ("side_blocks", "side_offset"):
            if p[key] is None:
                raise FieldError(key, f"missing: required with side_lines = {n_sides}")
    wind = None
    if any(v.get(k) is not None for k in _WIND_KEYS):
        if p["wind_height"] is None:
            raise FieldError("wind_height", "missing: required with a wind")
        if (p["wind_force"] is None) == (p["wind_pressure"] is None and p["wind_area"] is None) \
                or (p["wind_force"] is None and None in (p["wind_pressure"], p["wind_area"])):
            raise FieldError("wind_force", "give wind_force, or wind_pressure and wind_area "
                                           "together (not both, not neither)")
        wind = Wind(p["wind_height"], p["wind_force"], p["wind_pressure"], p["wind_area"])
    material = CAP_MATERIALS[p["cap_material"]]
    for key in ("cap_modulus", "cap_proportional_limit"):
        if "cap_material" in v and v.get(key) is not None:
            raise FieldError(key, f"and cap_material ({p['cap_material']!r}) both set the "
                                  "caps' timber; give one")
    modulus = material.modulus if p["cap_modulus"] is None else p["cap_modulus"]
    limit = (material.proportional_limit if p["cap_proportional_limit"] is None
             else p["cap_proportional_limit"])
    caps = {kind: Cap(p["cap_thickness"], modulus, limit,
                      p["cap_stiffness"], p["cap_damping_ratio"], p[f"mu_s_{kind}"],
                      p[f"mu_k_{kind}"], p["cap_shear_ratio"]) for kind in ("top", "bottom")}
    block = Block(p["block_half_width"], p["block_half_height"], p["block_length"],
                  p["block_mass"], p["block_capacity"], caps["top"], caps["bottom"])
    ship = Ship(p["ship_mass"], inertia, p["g_height"], p["keel_half_width"], p["half_beam"],
                p["g_offset"])
    sides = ()
    if n_sides:
        height = p["side_block_half_height"]
        if height is None:
            height = p["block_half_height"] + 0.5 * p["side_hull_height"]
        side_block = replace(block, half_height=height)
        sides = tuple(BlockLine(side_block, p["side_blocks"], sign * p["side_offset"],
                                p["side_moving"], p["side_hull_height"],
                                sign * p["side_hull_slope"])
                      for sign in (1.0, -1.0)[:n_sides])
    return DockSection(ship, BlockLine(block, p["keel_blocks"]), sides, wind, p["n_springs"],
                       g=p["g"])


def _as_table(values: Mapping[str, Any]) -> dict:
    """``values`` checked by their declarations (unknown names refused), quantities in SI."""
    unknown = [k for k in values if k not in PARAMETERS]
    if unknown:
        raise FieldError(unknown[0], f"unknown parameter of the section model; known: "
                                     f"{', '.join(PARAMETERS)}")
    out = {}
    for name, value in values.items():
        if value is None:
            continue
        f = PARAMETERS[name]
        if int in f.types and not isinstance(value, bool) and isinstance(value, float | np.number):
            value = _integral(value, name)
        out[name] = f.check(value.item() if isinstance(value, np.generic) else value)
    return out


# ------------------------------------------------------------------------------------------
# one run's outputs
# ------------------------------------------------------------------------------------------

def _nan_outputs() -> dict[str, float]:
    return dict.fromkeys(RUN_VARIABLES, math.nan)


def outputs(section: DockSection, result: SectionResult) -> dict[str, float]:
    """The model's per-run outputs (:data:`RUN_VARIABLES`) of one run's result.

    Parameters
    ----------
    section : DockSection
    result : SectionResult
        Of :func:`~shipblock.section.simulate_section` on ``section``.

    Returns
    -------
    dict of float
        Booleans as 0/1, absent side lines as NaN (their ratios in the line-wide EDPs as 0).
    """
    s = result.summary
    out = _nan_outputs()
    sides = [f"side{i}" for i in range(len(section.sides))]
    for line in ("keel", *sides):
        for name in ("peak_load_per_block", "capacity_ratio", "peak_top_pressure_ratio",
                     "peak_slip", "lift_off_time"):
            out[f"{line}_{name}"] = float(s[f"{line}_{name}"])
    faces = [f"{line}_peak_{face}_pressure_ratio" for line in ("keel", *sides)
             for face in ("top", "bottom") if f"{line}_peak_{face}_pressure_ratio" in s]
    sets = [s[k] for k in s if "_crushing_set_" in k]
    utils = [s[k] for k in s if "_friction_utilisation_" in k]
    out["keel_load_ratio"] = float(s["keel_capacity_ratio"])
    out["side_load_ratio"] = max((float(s[f"{line}_capacity_ratio"]) for line in sides),
                                 default=0.0)
    out["cap_pressure_ratio"] = max(float(s[k]) for k in faces)
    out["keel_cap_pressure_ratio"] = max(float(s[k]) for k in faces if k.startswith("keel_"))
    out["crushing_set"] = max(sets, default=0.0)
    out["friction_utilisation"] = max(utils, default=0.0)
    for name in ("peak_roll", "residual_roll", "peak_sway", "residual_sway"):
        out[name] = float(s[name])
    half_width = section.keel.block.half_width
    out["sway_ratio"] = out["peak_sway"] / half_width
    out["residual_sway_ratio"] = out["residual_sway"] / half_width
    out["keel_slip"] = float(s["keel_peak_slip"])
    out["keel_rotation"] = float(s["keel_peak_rotation"])
    code = _FAILURE_OF[s["failure"]] if s["failure"] else 0
    out["failure"] = float(code)
    for name, c in FAILURE_FLAGS.items():
        out[name] = float(code == c)
    out["failure_time"] = float(s["failure_time"]) if s["failure"] else math.nan
    out["energy_residual"] = float(result.energy["residual"])
    out["n_events"] = float(result.stats["events"])
    return out


@dataclass(frozen=True)
class SectionRun:
    """One run of the section model with its histories (:meth:`SectionModel.simulate`).

    Attributes
    ----------
    result : SectionResult
        The full result of :func:`~shipblock.section.simulate_section` (histories, events,
        energy balance).
    summary : dict
        The model's outputs of the run (:data:`RUN_VARIABLES`), equal to the batch's.
    ground : numpy.ndarray, shape (n, 2)
        The ground acceleration the run was given, horizontal and vertical [m/s^2].
    """

    result: SectionResult
    summary: dict
    ground: np.ndarray = field(default_factory=lambda: np.zeros((0, 2)), repr=False)

    @property
    def events(self) -> list:
        """The located events of the run."""
        return self.result.events

    @property
    def failure(self) -> str | None:
        """The failure's name (None if none)."""
        return self.result.failure

    @property
    def failure_time(self) -> float | None:
        """The failure's time [s] (None if none)."""
        return self.result.failure_time

    def to_dataset(self):
        """The histories (:meth:`SectionResult.to_dataset
        <shipblock.section.simulate.SectionResult.to_dataset>`) with the model's outputs as
        attributes (``failure`` as its code, ``failure_name`` its name)."""
        ds = self.result.to_dataset()
        ds["time"].attrs["long_name"] = "time from the start of the record"
        n = ds.sizes["time"]
        if self.ground.shape[0] >= n:
            for k, (name, what) in enumerate((("h", "horizontal, positive to starboard"),
                                              ("v", "vertical, positive up"))):
                ds[f"ground_acceleration_{name}"] = ("time", self.ground[:n, k], {
                    "units": "m/s^2", "long_name": f"ground acceleration, {what}"})
        sec = self.result.section
        lines = {"keel": sec.keel, **{f"side{i}": line for i, line in enumerate(sec.sides)}}
        ds.attrs = {**self.summary, "failure_name": self.result.failure or "none",
                    "model": SectionModel.name, "keel_cap_half_width": sec.keel.block.half_width,
                    **{f"{name}_block_capacity": line.block.capacity
                       for name, line in lines.items()},
                    # where each line stands [m], positive to starboard (the figure names the side)
                    **{f"{name}_offset": line.offset for name, line in lines.items()}}
        return ds


# ------------------------------------------------------------------------------------------
# the model
# ------------------------------------------------------------------------------------------

class SectionModel(Model):
    """The dock section (issue 29) behind the model seam (see the module docstring)."""

    name = "section"
    description = ("ship that sways, heaves and rolls on a keel line and 0-2 side-block lines "
                   "with compliant timber caps")
    parameters = PARAMETERS
    options = OPTIONS
    sweep_parameters = SWEEP_PARAMETERS
    edps = EDP_VARIABLES
    outputs = RUN_VARIABLES
    failure_codes = FAILURE_CODES
    solver_error_code = SOLVER_ERROR
    default_edp = "keel_load_ratio"

    def build(self, values: Mapping[str, Any]) -> SectionSystem:
        """A :class:`SectionSystem` from a ``[system]`` table.

        Every value is checked by its declaration (the range of the section's own checks),
        then the section is built (:class:`~shipblock.section.DockSection`) and its static
        state solved (:func:`~shipblock.section.simulate.rest_state`), so that a dock whose
        caps crush at rest or whose ship is unstable on its blocks is refused here, before any
        run; the system keeps the state for its runs (:attr:`SectionSystem.rest`).

        Raises
        ------
        FieldError
            Naming the ``[system]`` key at fault (``""`` when no single key is: a ship unstable
            on its supports).
        """
        table = _as_table(values)
        for name, f in PARAMETERS.items():
            if f.required and name not in table:
                raise FieldError(name, f"missing: {f.doc} [{f.units}]")
        try:
            section = _section(table)
            rest = rest_state(assemble(section, DEFAULT_SEPARATION_HEIGHT))
        except FieldError:
            raise
        except ParameterError as exc:
            raise FieldError(_key_of(str(exc), table), str(exc)) from None
        return SectionSystem(table, section, rest)

    def vary(self, system: SectionSystem, values: Mapping[str, Any]) -> SectionSystem:
        """``system`` with swept parameters changed (derived defaults derived again).

        Raises
        ------
        ParameterError
            If a name is unknown, a convenience and a parameter it sets are both given, or the
            changed section is invalid (naming the key).
        """
        unknown = [k for k in values if k not in SWEEP_PARAMETERS]
        if unknown:
            raise ParameterError(f"unknown section parameter(s) {', '.join(map(repr, unknown))}"
                                 f"; known: {', '.join(SWEEP_PARAMETERS)}")
        table = dict(system.values)
        for name, value in values.items():
            if name in _CONVENIENCES:
                mu_s, mu_k = _CONVENIENCES[name]
                clash = [k for k in (mu_s, mu_k) if k in values]
                if clash:
                    raise ParameterError(f"{name!r} and {clash[0]!r} both set the same "
                                         "parameter; give one")
                base = {k: table.get(k, PARAMETERS[k].default) for k in (mu_s, mu_k)}
                ratio = base[mu_k] / base[mu_s] if base[mu_s] > 0 else 1.0
                table[mu_s], table[mu_k] = float(value), float(value) * ratio
            else:
                table[name] = value
        return self.build(table)

    def describe(self, system: SectionSystem) -> dict:
        """The ``[system]`` values as given (SI units; JSON-ready, :meth:`build` takes it)."""
        return dict(system.values)

    def caption(self, system: SectionSystem) -> str:
        """One line naming the dock section for a figure's title."""
        sec = system.section
        ship, keel, b = sec.ship, sec.keel, sec.keel.block
        text = (f"ship {ship.mass / 1e3:.4g} t, KG {ship.g_height:.3g} m, on {keel.n_blocks} "
                f"keel blocks {2 * b.half_width:.3g} x {b.length:.3g} x {2 * b.half_height:.3g} "
                f"m (capacity {b.capacity / 1e3:.4g} kN)")
        if sec.sides:
            line = sec.sides[0]
            text += (f" and {len(sec.sides)} side line{'s' if len(sec.sides) > 1 else ''} of "
                     f"{line.n_blocks} at {abs(line.offset):.3g} m"
                     f"{'' if line.moving else ' (fixed)'}")
        cap = b.top
        given = system.values
        timber = ("" if "cap_modulus" in given or "cap_proportional_limit" in given
                  else f"{given.get('cap_material', DEFAULT_CAP_MATERIAL)}, ")
        return (text + f"; caps {cap.thickness * 1e3:.3g} mm, {timber}E {cap.modulus / 1e9:.3g}"
                f" GPa; "
                f"friction top {cap.mu_s:.3g}/{cap.mu_k:.3g}, floor {b.bottom.mu_s:.3g}/"
                f"{b.bottom.mu_k:.3g} (static/kinetic)")

    def run_batch(self, systems: Sequence[SectionSystem], inputs: Sequence[tuple],
                  dts: Sequence[float], cases: np.ndarray, **options) -> dict[str, np.ndarray]:
        """Every case of a chunk, one :func:`~shipblock.section.simulate_section` run each.

        A run that raises is a solver-error row (``failure`` = 6, the rest NaN; its message is
        logged): the chunk's other runs are kept.
        """
        cases = np.asarray(cases, dtype=np.int64).reshape(-1, 2)
        out = {name: np.full(len(cases), np.nan) for name in RUN_VARIABLES}
        runners = {}  # per system: its exponential steps made once (its state is the system's)
        for k, (i, s) in enumerate(cases.tolist()):
            h, v = inputs[i]
            try:
                if s not in runners:
                    runners[s] = systems[s].runner(**options)
                row = outputs(systems[s].section, runners[s](h, v, dts[i]))
            except (ShipblockError, ArithmeticError, ValueError, np.linalg.LinAlgError) as exc:
                logger.warning("section run (input %d, system %d) failed: %s", i, s, exc)
                row = {**_nan_outputs(), "failure": float(SOLVER_ERROR)}
            for name, value in row.items():
                out[name][k] = value
        return out

    def simulate(self, system: SectionSystem, horizontal, vertical, dt: float,
                 **options) -> SectionRun:
        """One run with its histories (:func:`~shipblock.section.simulate_section`, from the
        system's static state)."""
        result = system.runner(**options)(horizontal, vertical, dt)
        h = np.asarray(horizontal, dtype=float)
        v = np.zeros_like(h) if vertical is None else np.asarray(vertical, dtype=float)
        return SectionRun(result, outputs(system.section, result), np.column_stack([h, v]))
