"""Parameters of the dock section: the ship, its keel- and side-block lines, caps and wind.

Everything a dock engineer has for a docking plan, in SI units, each value range-checked with
its key named (the style of :mod:`shipblock.checks`). Stiffnesses are derived from the cap's
modulus across the grain, its loaded area and its thickness unless given.

Defaults are the standard US Navy keel block with white-oak caps. Each value, its source and
what was *not* found are in ``docs/theory/section.md`` (table "Parameters and defaults"):

* block 42 x 48 in in plan and 48 in tall overall, concrete capped top and bottom with three
  48 x 6 x 14 in white-oak timbers, so caps 6 in thick (NAVFAC, Navy SBIR topic N254-122,
  2025, which points to UFC 4-213-10 *Graving Drydocks*, Figure 8-2, for the standard drawing;
  the figure itself was not read). Which of 42 and 48 in lies along the keel is not stated
  there; this module reads 42 in along the keel and 48 in across the dock: check it against
  your docking drawing;
* white oak, clear wood at 12 % moisture content, USDA Forest Products Laboratory, *Wood
  Handbook*, FPL-GTR-190 (2010), Chapter 5: compression perpendicular to the grain (fibre
  stress at the proportional limit) 7,400 kPa (Table 5-3a; 1,070 lbf/in^2 in Table 5-3b);
  static-bending modulus 12,300 MPa (1.78e6 lbf/in^2), which Table 5-3's footnote says to
  raise by 10 % to remove shear deflection, so E_L = 13.5 GPa; E_T / E_L = 0.072 (Table 5-1),
  so E_T = 0.974 GPa (a flat-sawn cap is loaded in its tangential direction). Green wood (a
  soaked cap) is softer and weaker: 4,600 kPa and 8,600 MPa;
* block capacity 330 long tons force: the load the Navy asks a replacement cap to carry for
  five years (SBIR topic N254-122); no rated block capacity was found in the documents read.

The friction coefficients, the damping ratio and the ratio of tangential to normal cap stiffness
are model parameters with typical values, not handbook data; give your own.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from types import MappingProxyType

from shipblock.checks import flag, real, whole
from shipblock.errors import ParameterError, ParameterTypeError
from shipblock.units import INCH, LONG_TON_FORCE, STANDARD_GRAVITY

__all__ = [
    "CAP_MATERIALS",
    "LONG_TON_FORCE",
    "NAVY_BLOCK",
    "Block",
    "BlockLine",
    "Cap",
    "CapMaterial",
    "DockSection",
    "Ship",
    "Wind",
]

#: Density of the concrete of a block [kg/m^3]: the usual value for plain normal-weight concrete
#: (150 lb/ft^3); not taken from a Navy document.
CONCRETE_DENSITY = 2400.0
#: Density of white oak at 12 % moisture content [kg/m^3]: specific gravity 0.68 (oven-dry mass,
#: volume at 12 %; Wood Handbook 2010, Table 5-3a) times 1.12 for the water, 762 kg/m^3.
OAK_DENSITY = 760.0
#: White oak, clear wood, 12 % moisture content (Wood Handbook 2010, FPL-GTR-190, Table 5-3a):
#: static-bending modulus of elasticity [Pa] and compression perpendicular to the grain, fibre
#: stress at the proportional limit [Pa].
WHITE_OAK_BENDING_MODULUS = 12.3e9
WHITE_OAK_PROPORTIONAL_LIMIT = 7.4e6
#: Table 5-3 footnote: the bending modulus includes shear deflection; raise it by 10 % for E_L.
SHEAR_FREE_FACTOR = 1.10
#: Elastic ratio E_T / E_L of white oak at about 12 % moisture content (Wood Handbook 2010,
#: Table 5-1).
WHITE_OAK_ET_OVER_EL = 0.072
#: Modulus of white oak across the grain, tangential direction [Pa]: 0.072 * 1.10 * 12.3 GPa.
WHITE_OAK_MODULUS_T = WHITE_OAK_ET_OVER_EL * SHEAR_FREE_FACTOR * WHITE_OAK_BENDING_MODULUS
@dataclass(frozen=True)
class CapMaterial:
    r"""A cap timber: its modulus across the grain and its proportional limit in compression.

    Parameters
    ----------
    name : str
        The name a ``[system] cap_material`` key gives.
    bending_modulus : float
        Static-bending modulus of elasticity of clear wood [Pa] (Wood Handbook 2010, Table 5-3a).
    proportional_limit : float
        Compression perpendicular to the grain, fibre stress at the proportional limit [Pa]
        (same table).
    et_over_el : float
        Elastic ratio E_T / E_L (Table 5-1, given there at about 12 % moisture content only).
    source : str
        Where the numbers were read.

    Notes
    -----
    The modulus across the grain of a flat-sawn cap (loaded tangentially) is
    :math:`E_T = (E_T/E_L)\,1.10\,E_{bend}`, the 1.10 removing the shear deflection from the
    bending modulus (Table 5-3's footnote).
    """

    name: str
    bending_modulus: float
    proportional_limit: float
    et_over_el: float
    source: str

    @property
    def modulus(self) -> float:
        """Modulus across the grain, tangential direction E_T [Pa]."""
        return self.et_over_el * SHEAR_FREE_FACTOR * self.bending_modulus


_HANDBOOK = "USDA FPL Wood Handbook 2010 (FPL-GTR-190), Table 5-3a"
_ENGDATABASE = ("as reproduced by engdatabase.com (wood properties from the Wood Handbook), "
                "not read in the Handbook itself")

#: Cap timbers a ``[system] cap_material`` names; clear wood, Wood Handbook 2010. The green
#: (soaked) rows keep the 12 % elastic ratio: Table 5-1 gives none for green wood. Each number
#: and where it was read: ``docs/theory/section.md``, table "Cap materials".
CAP_MATERIALS = MappingProxyType({m.name: m for m in (
    CapMaterial("white_oak", WHITE_OAK_BENDING_MODULUS, WHITE_OAK_PROPORTIONAL_LIMIT,
                WHITE_OAK_ET_OVER_EL, f"{_HANDBOOK}, 12 % MC; Table 5-1 (E_T/E_L 0.072)"),
    CapMaterial("white_oak_green", 8.6e9, 4.6e6, WHITE_OAK_ET_OVER_EL,
                f"{_HANDBOOK}, green; E_T/E_L of Table 5-1 at 12 % MC"),
    CapMaterial("douglas_fir_interior_south", 10.3e9, 5.1e6, 0.050,
                f"{_HANDBOOK}, Douglas-fir, Interior South, 12 % MC; Table 5-1 (E_T/E_L "
                f"0.050); {_ENGDATABASE}"),
    CapMaterial("douglas_fir_interior_south_green", 8.0e9, 2.3e6, 0.050,
                f"{_HANDBOOK}, Douglas-fir, Interior South, green; E_T/E_L of Table 5-1 at "
                f"12 % MC; {_ENGDATABASE}"),
)})
#: The material of the default caps.
DEFAULT_CAP_MATERIAL = "white_oak"

#: Steepest hull slope a block top can be cut to [rad]: beyond 45 deg the normal force on the cap
#: pushes the block sideways harder than down (a shore, not a block).
MAX_HULL_SLOPE = math.radians(45.0)
#: Most blocks in one line, most side lines, spring counts across a strip.
MAX_BLOCKS = 10_000
MAX_SIDE_LINES = 2
SPRING_COUNTS = (2, 15)
#: Springs across a cap strip unless given: the fewest whose demand parameters, averaged over
#: records as a fragility study sees them, are those of 15 springs (docs: theory of the dock
#: section, *Springs per strip*); 5 underestimated the blocks' rotation at 0.55 g by 15-21 %.
DEFAULT_SPRINGS = 7


def _check(obj, limits: dict) -> None:
    """Range-check every field of ``obj`` named in ``limits`` (None skipped where allowed)."""
    prefix = type(obj).__name__
    for name, (low, high, units, optional) in limits.items():
        value = getattr(obj, name)
        if value is None and optional:
            continue
        real(value, f"{prefix}.{name}", low=low, high=high, units=units, low_open=low == 0.0
             and name not in ZERO_ALLOWED)


#: Fields whose range starts at 0 included (the others with a lower bound of 0 exclude it).
ZERO_ALLOWED = {"g_offset", "offset", "hull_height", "hull_slope", "mu_s", "mu_k",
                "damping_ratio", "force", "pressure", "area"}


@dataclass(frozen=True)
class Cap:
    """A timber cap (or any compliant contact layer) on one face of a block.

    Parameters
    ----------
    thickness : float
        Cap thickness t [m]; default 6 in.
    modulus : float
        Modulus of the cap across the grain E_perp [Pa]; default 0.974 GPa (white oak at 12 %,
        E_T = 0.072 E_L with E_L = 1.1 x 12.3 GPa; Wood Handbook 2010, Tables 5-1 and 5-3a).
    proportional_limit : float
        Compression perpendicular to the grain at the proportional limit sigma_pl [Pa]; beyond it
        the cap crushes (perfectly plastic) and keeps the set; default 7.4 MPa (white oak at 12 %,
        Wood Handbook 2010, Table 5-3a; green wood 4.6 MPa).
    stiffness : float or None
        Normal stiffness of one block's cap [N/m]; None derives ``modulus * area / thickness``.
    damping_ratio : float
        Viscous damping ratio of the cap's normal mode with the mass it carries at rest [-]
        (:mod:`shipblock.section.model` says which mode exactly); default 0.1.
    mu_s, mu_k : float
        Static and kinetic Coulomb friction on this face [-]; defaults 0.5 and 0.4 (inside the
        0.2-0.6 of general tables for wood on metal; no source for oak caps on a hull or on
        concrete was found).
    shear_ratio : float
        Stiffness of the tangential stick spring over the normal stiffness [-]; default 0.5.
    """

    thickness: float = 6.0 * INCH
    modulus: float = WHITE_OAK_MODULUS_T
    proportional_limit: float = WHITE_OAK_PROPORTIONAL_LIMIT
    stiffness: float | None = None
    damping_ratio: float = 0.1
    mu_s: float = 0.5
    mu_k: float = 0.4
    shear_ratio: float = 0.5

    LIMITS = {
        "thickness": (1e-4, 10.0, "m", False),
        "modulus": (1e5, 1e13, "Pa", False),
        "proportional_limit": (1e3, 1e10, "Pa", False),
        "stiffness": (1.0, 1e15, "N/m", True),
        "damping_ratio": (0.0, 50.0, "", False),
        "mu_s": (0.0, 10.0, "", False),
        "mu_k": (0.0, 10.0, "", False),
        "shear_ratio": (1e-4, 100.0, "", False),
    }

    def __post_init__(self):
        _check(self, self.LIMITS)
        if self.mu_k > self.mu_s:
            raise ParameterError(f"Cap.mu_k ({self.mu_k}) must not exceed Cap.mu_s ({self.mu_s}):"
                                 " kinetic friction above static friction is not physical")

    def normal_stiffness(self, area: float) -> float:
        """Normal stiffness of the cap over ``area`` [N/m]: ``stiffness`` or E_perp A / t."""
        return self.stiffness if self.stiffness is not None else self.modulus * area / self.thickness


@dataclass(frozen=True)
class Block:
    """One block: its size, mass, capacity and caps.

    Parameters
    ----------
    half_width : float
        Half the width across the dock B [m]; default 24 in.
    half_height : float
        Half the overall height, caps included, H [m]; default 24 in.
    length : float
        Length along the keel [m]; default 42 in.
    mass : float or None
        Mass of one block [kg]; None: concrete between the caps plus oak caps.
    capacity : float
        Rated load of one block [N]; default 330 long tons force (the load a Navy block cap is
        asked to carry, SBIR topic N254-122; not a rated capacity from a standard).
    top, bottom : Cap
        Cap under the hull and on the floor; default white-oak caps 6 in thick.
    """

    half_width: float = 24.0 * INCH
    half_height: float = 24.0 * INCH
    length: float = 42.0 * INCH
    mass: float | None = None
    capacity: float = 330.0 * LONG_TON_FORCE
    top: Cap = field(default_factory=Cap)
    bottom: Cap = field(default_factory=Cap)

    LIMITS = {
        "half_width": (1e-3, 50.0, "m", False),
        "half_height": (1e-3, 50.0, "m", False),
        "length": (1e-3, 100.0, "m", False),
        "mass": (1e-3, 1e8, "kg", True),
        "capacity": (1.0, 1e10, "N", False),
    }

    def __post_init__(self):
        _check(self, self.LIMITS)
        for name in ("top", "bottom"):
            if not isinstance(getattr(self, name), Cap):
                raise ParameterTypeError(f"Block.{name} must be a Cap, got "
                                         f"{type(getattr(self, name)).__name__}")
        caps = self.top.thickness + self.bottom.thickness
        if caps >= 2.0 * self.half_height:
            raise ParameterError(
                f"Block.top.thickness + Block.bottom.thickness ({caps:g} m) must be less than the "
                f"block's height 2 * Block.half_height ({2.0 * self.half_height:g} m): caps thicker "
                "than the block")

    @property
    def block_mass(self) -> float:
        """Mass of one block [kg] (given, or concrete core plus oak caps)."""
        if self.mass is not None:
            return self.mass
        plan = 2.0 * self.half_width * self.length
        caps = self.top.thickness + self.bottom.thickness
        return plan * ((2.0 * self.half_height - caps) * CONCRETE_DENSITY + caps * OAK_DENSITY)

    @property
    def inertia(self) -> float:
        """Centroidal roll inertia of one block [kg m^2] (uniform block)."""
        return self.block_mass * (self.half_width**2 + self.half_height**2) / 3.0


#: The standard US Navy keel block with white-oak caps (module docstring for the sources).
NAVY_BLOCK = Block()


@dataclass(frozen=True)
class BlockLine:
    """A line of identical blocks, all moving alike (one body in the section).

    Parameters
    ----------
    block : Block
        The block.
    n_blocks : int
        Number of blocks in the line.
    offset : float
        Transverse position of the line's centre y [m], positive to starboard; 0 for the keel line.
    moving : bool
        True: the line slides, rocks and lifts off; False: fixed to the floor (wedged cribbing;
        only its top cap is compliant). The keel line always moves.
    hull_height : float
        Height of the hull's underside above the keel's underside at ``offset`` [m] (0 for the
        keel line).
    hull_slope : float
        Slope (deadrise) of the hull's underside at ``offset`` [rad], positive when the hull rises
        to starboard; the block top is cut to it.
    """

    block: Block = NAVY_BLOCK
    n_blocks: int = 1
    offset: float = 0.0
    moving: bool = True
    hull_height: float = 0.0
    hull_slope: float = 0.0

    LIMITS = {
        "offset": (-100.0, 100.0, "m", False),
        "hull_height": (0.0, 50.0, "m", False),
        "hull_slope": (-MAX_HULL_SLOPE, MAX_HULL_SLOPE, "rad", False),
    }

    def __post_init__(self):
        if not isinstance(self.block, Block):
            raise ParameterTypeError(f"BlockLine.block must be a Block, got "
                                     f"{type(self.block).__name__}")
        object.__setattr__(self, "n_blocks",
                           whole(self.n_blocks, "BlockLine.n_blocks", low=1, high=MAX_BLOCKS))
        object.__setattr__(self, "moving", flag(self.moving, "BlockLine.moving"))
        if is_steep(self.hull_slope):
            raise ParameterError(
                f"BlockLine.hull_slope must be within +-45 deg ({MAX_HULL_SLOPE:.4f} rad), got "
                f"{self.hull_slope!r}: a block top cannot be cut to match it")
        _check(self, self.LIMITS)
        blk = self.block
        drop = blk.half_width * abs(math.tan(self.hull_slope))
        core = 2.0 * blk.half_height - blk.top.thickness - blk.bottom.thickness
        if drop >= core:
            raise ParameterError(
                f"BlockLine.hull_slope ({self.hull_slope!r} rad): a block top cut to it drops "
                f"{drop:g} m from its centre to its low edge (Block.half_width * tan(hull_slope)), "
                f"not less than the block's core between its caps ({core:g} m): a block top "
                "cannot be cut to match it; use a wider-topped shore or a narrower block")


def is_steep(slope) -> bool:
    """Whether a (real) hull slope is steeper than a block top can be cut to."""
    try:
        return abs(float(slope)) > MAX_HULL_SLOPE and math.isfinite(float(slope))
    except (TypeError, ValueError):
        return False


@dataclass(frozen=True)
class Ship:
    """The ship as the supports see it (rigid, in the transverse plane).

    Parameters
    ----------
    mass : float
        Mass of the ship carried by the section's lines [kg].
    roll_inertia : float
        Roll inertia about the centre of gravity G [kg m^2].
    g_height : float
        Height of G above the keel's underside h_G [m] (> 0).
    keel_half_width : float
        Half-width of the flat keel b_K [m].
    half_beam : float
        Half the beam at the supports [m]: side blocks must stand under the hull.
    g_offset : float
        Offset of G from the centre line e_G [m], positive to starboard (a list).
    """

    mass: float
    roll_inertia: float
    g_height: float
    keel_half_width: float
    half_beam: float
    g_offset: float = 0.0

    LIMITS = {
        "mass": (1.0, 1e10, "kg", False),
        "roll_inertia": (1e-3, 1e14, "kg m^2", False),
        "keel_half_width": (1e-3, 50.0, "m", False),
        "half_beam": (1e-3, 100.0, "m", False),
        "g_offset": (-50.0, 50.0, "m", False),
    }

    def __post_init__(self):
        if real(self.g_height, "Ship.g_height", high=100.0, units="m") <= 0.0:
            raise ParameterError(f"Ship.g_height must be above the keel's underside (> 0 m), got "
                                 f"{self.g_height!r}: G below the keel")
        _check(self, self.LIMITS)
        if self.keel_half_width > self.half_beam:
            raise ParameterError(f"Ship.keel_half_width ({self.keel_half_width:g} m) must not "
                                 f"exceed Ship.half_beam ({self.half_beam:g} m)")
        if abs(self.g_offset) >= self.half_beam:
            raise ParameterError(f"Ship.g_offset ({self.g_offset:g} m) must lie within the beam "
                                 f"(|g_offset| < Ship.half_beam = {self.half_beam:g} m)")


@dataclass(frozen=True)
class Wind:
    """A steady lateral wind load on the ship.

    Give ``force`` directly, or ``pressure`` and ``area`` (force = pressure * area).

    Parameters
    ----------
    height : float
        Height of the line of action above the keel's underside [m].
    force : float or None
        Lateral force [N], positive to starboard.
    pressure, area : float or None
        Wind pressure [Pa] (signed, positive to starboard) and lateral area [m^2].
    """

    height: float
    force: float | None = None
    pressure: float | None = None
    area: float | None = None

    LIMITS = {
        "height": (0.0, 200.0, "m", False),
        "force": (-1e10, 1e10, "N", True),
        "pressure": (-1e5, 1e5, "Pa", True),
        "area": (0.0, 1e5, "m^2", True),
    }

    def __post_init__(self):
        _check(self, self.LIMITS)
        direct = self.force is not None
        derived = self.pressure is not None or self.area is not None
        if direct == derived or (derived and (self.pressure is None or self.area is None)):
            raise ParameterError("Wind takes force=, or pressure= and area= together (not both,"
                                 " not neither)")

    @property
    def lateral_force(self) -> float:
        """The lateral force [N]."""
        return self.force if self.force is not None else self.pressure * self.area


@dataclass(frozen=True)
class DockSection:
    """A ship on a keel-block line and zero, one or two side-block lines.

    Parameters
    ----------
    ship : Ship
    keel : BlockLine
        The keel line (offset 0, on the centre line, moving).
    sides : tuple of BlockLine
        Zero, one or two side lines, standing under the hull clear of the keel line.
    wind : Wind or None
    n_springs : int
        Springs across each cap strip (Gauss-Lobatto points, 2..15; 2 is the classical
        two-spring rocking model). Default ``DEFAULT_SPRINGS`` = 7: fewer make a rocking
        block's short contact near its corner too coarse (5 underestimate strong responses).
    roll_held : bool
        Hold the ship's roll at zero (the seed model's ship; for the rigid limit).
    g : float
        Gravity [m/s^2].

    Raises
    ------
    ParameterError
        For impossible geometry, named by key: a side block not under the hull or overlapping the
        keel line, a side block whose height leaves a gap or interference larger than its top
        cap's thickness, a keel line off the centre line.
    """

    ship: Ship
    keel: BlockLine
    sides: tuple = ()
    wind: Wind | None = None
    n_springs: int = DEFAULT_SPRINGS
    roll_held: bool = False
    g: float = STANDARD_GRAVITY

    def __post_init__(self):
        if not isinstance(self.ship, Ship):
            raise ParameterTypeError(f"DockSection.ship must be a Ship, got "
                                     f"{type(self.ship).__name__}")
        if not isinstance(self.keel, BlockLine):
            raise ParameterTypeError(f"DockSection.keel must be a BlockLine, got "
                                     f"{type(self.keel).__name__}")
        if not (self.wind is None or isinstance(self.wind, Wind)):
            raise ParameterTypeError(f"DockSection.wind must be a Wind or None, got "
                                     f"{type(self.wind).__name__}")
        sides = tuple(self.sides) if isinstance(self.sides, list | tuple) else None
        if sides is None or not all(isinstance(s, BlockLine) for s in sides):
            raise ParameterTypeError("DockSection.sides must be a tuple of BlockLine")
        if len(sides) > MAX_SIDE_LINES:
            raise ParameterError(f"DockSection.sides holds at most {MAX_SIDE_LINES} lines, got "
                                 f"{len(sides)}")
        object.__setattr__(self, "sides", sides)
        object.__setattr__(self, "n_springs", whole(self.n_springs, "DockSection.n_springs",
                                                    low=SPRING_COUNTS[0], high=SPRING_COUNTS[1]))
        object.__setattr__(self, "roll_held", flag(self.roll_held, "DockSection.roll_held"))
        real(self.g, "DockSection.g", low=0.1, high=100.0, units="m/s^2")
        keel = self.keel
        if keel.offset != 0.0 or keel.hull_height != 0.0 or keel.hull_slope != 0.0:
            raise ParameterError("DockSection.keel must stand on the centre line under the flat "
                                 "keel: offset, hull_height and hull_slope 0")
        if not keel.moving:
            raise ParameterError("DockSection.keel.moving must be True (the keel line moves)")
        ship = self.ship
        for i, line in enumerate(sides):
            key = f"DockSection.sides[{i}]"
            b = line.block.half_width
            inner, outer = abs(line.offset) - b, abs(line.offset) + b
            if outer > ship.half_beam:
                raise ParameterError(
                    f"{key}.offset ({line.offset:g} m): the side block reaches {outer:g} m from "
                    f"the centre line, beyond Ship.half_beam ({ship.half_beam:g} m): not under "
                    "the hull")
            clear = max(keel.block.half_width, ship.keel_half_width)
            if inner <= clear:
                raise ParameterError(
                    f"{key}.offset ({line.offset:g} m): the side block's inner edge ({inner:g} m "
                    f"from the centre line) is not clear of the keel line and the keel "
                    f"({clear:g} m)")
            gap = self.side_gap(i)
            if abs(gap) >= line.block.top.thickness:
                raise ParameterError(
                    f"{key}: the block top (2 * half_height = {2 * line.block.half_height:g} m) and "
                    f"the hull (keel height {2 * keel.block.half_height:g} m + hull_height "
                    f"{line.hull_height:g} m) leave a {'gap' if gap > 0 else 'interference'} of "
                    f"{abs(gap):g} m, not less than its top cap's thickness "
                    f"({line.block.top.thickness:g} m)")

    def side_gap(self, i: int) -> float:
        """Gap (positive) or interference (negative) between side line ``i``'s top and the hull
        at the line's centre, with the ship resting stress-free on the keel line [m]."""
        line = self.sides[i]
        return 2.0 * self.keel.block.half_height + line.hull_height - 2.0 * line.block.half_height

    @property
    def lines(self) -> tuple:
        """The keel line, then the side lines."""
        return (self.keel, *self.sides)
