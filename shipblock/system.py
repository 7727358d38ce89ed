"""The ship-block system: parameters, validation and derived quantities.

A rigid ship of mass :math:`M` stands on :math:`n` identical rigid keel blocks, each
:math:`2B` wide and :math:`2H` tall with mass :math:`m` and centroidal inertia :math:`I`.
Coulomb friction acts at the block-ground interface (:math:`\\mu_{s1}, \\mu_{k1}`) and at the
block-ship interface (:math:`\\mu_{s2}, \\mu_{k2}`).
"""

from __future__ import annotations

import logging
import math
from dataclasses import MISSING, asdict, dataclass, fields
from functools import cached_property

import numpy as np

from shipblock.checks import choice, pathname, real, toml_file, whole
from shipblock.errors import ParameterError, ParameterTypeError
from shipblock.quantities import to_si
from shipblock.units import STANDARD_GRAVITY

logger = logging.getLogger(__name__)

IMPACT_RULES = ("momentum", "paper", "plastic")

# Positions in the parameter vector handed to the compiled kernels.
P_M = 0  # ship mass M [kg]
P_NM = 1  # total block mass n*m [kg]
P_NI = 2  # total block centroidal inertia n*I [kg m^2]
P_B = 3  # block half width B [m]
P_H = 4  # block half height H [m]
P_R = 5  # half diagonal R = sqrt(B^2 + H^2) [m]
P_THC = 6  # critical angle theta_c = atan(B/H) [rad]
P_MUS1 = 7  # static friction, blocks on ground [-]
P_MUK1 = 8  # kinetic friction, blocks on ground [-]
P_MUS2 = 9  # static friction, ship on blocks [-]
P_MUK2 = 10  # kinetic friction, ship on blocks [-]
P_E = 11  # coefficient of restitution theta_dot+/theta_dot- [-]
P_RULE = 12  # impact rule: 0 momentum-consistent, 1 paper (scale theta_dot only), 2 plastic
P_G = 13  # gravity [m/s^2]
N_PARAMS = 14

#: Accepted range of every numeric field: name -> (lowest, highest, units), bounds included.
#: Outside them a value is a typing or unit mistake, not a ship on keel blocks. The ranges are
#: far wider than any dock (a 1e-9 kg "ship" stands for a block alone, friction up to 100 locks
#: an interface) and narrow enough that every derived quantity stays a finite float.
FIELD_LIMITS: dict[str, tuple[float | None, float | None, str]] = {
    "ship_mass": (1e-9, 1e10, "kg"),
    "block_mass": (1e-6, 1e8, "kg"),
    "n_blocks": (1, 100_000, ""),
    "half_width": (1e-4, 100.0, "m"),
    "half_height": (1e-4, 100.0, "m"),
    "mu_s_ground": (0.0, 100.0, ""),
    "mu_k_ground": (0.0, 100.0, ""),
    "mu_s_ship": (0.0, 100.0, ""),
    "mu_k_ship": (0.0, 100.0, ""),
    "restitution": (0.0, 1.0, ""),
    "block_inertia": (0.0, None, "kg m^2"),  # and MIN_INERTIA_RATIO .. 1 times m (B^2 + H^2)
    "g": (0.1, 100.0, "m/s^2"),
}

#: SI unit of each dimensional field in pint's spelling: a string value (``"20000 t"``,
#: ``"600 mm"``) is converted to it (:func:`shipblock.quantities.to_si`).
FIELD_UNITS: dict[str, str] = {
    "ship_mass": "kg",
    "block_mass": "kg",
    "half_width": "m",
    "half_height": "m",
    "block_inertia": "kg * m**2",
    "g": "m/s**2",
}

#: Plausibility of a dock (:func:`implausible`): a system outside these ranges runs, but with a
#: warning, since it is most likely a unit mistake (tonnes given as kg). Density of a block taken
#: :data:`ASSUMED_BLOCK_LENGTH` long along the keel [kg/m^3]: timber 500-900, concrete about
#: 2400, steel 7850, and keel-block stacks of steel, concrete and timber between.
BLOCK_DENSITY_RANGE = (300.0, 8000.0)
#: The block length along the keel the density check assumes [m] (the 2-D model does not know
#: it; keel blocks are 0.5 to 2 m long).
ASSUMED_BLOCK_LENGTH = 1.0
#: Ship weight per block, M g / n [N]: small craft on few blocks to the heaviest docked hulls.
LOAD_PER_BLOCK_RANGE = (5e3, 4e6)
#: Ship mass over the mass of all blocks, M / (n m) [-]: the ship outweighs its blocks.
SHIP_TO_BLOCKS_RANGE = (1.0, 1e4)

#: Smallest ratio I / (m R^2) of a block_inertia given explicitly [-] (1/3 for a uniform block).
MIN_INERTIA_RATIO = 1e-6


def system_restitution(mass_ratio: float, alpha: float, inertia_ratio: float = 1.0 / 3.0) -> float:
    """Coefficient of restitution of the ship-block system for a plastic impact at the new pivot.

    .. math::

        e_{sys} = \\frac{nI + (nm+4M)(H^2 - B^2)}{nI + (nm+4M)(H^2 + B^2)}
                = 1 - \\frac{3}{2}\\sin^2\\alpha\\,\\frac{M_n+4}{M_n+3}
                \\quad (\\kappa = 1/3)

    It follows from conservation of the generalised momentum conjugate to :math:`\\theta`
    through the impact, with the impulses at the new pivot and the new ship contact doing no
    work in the post-impact rocking mode; for :math:`M_n \\to \\infty` it is Housner's
    :math:`1 - \\tfrac32\\sin^2\\alpha` [1]_. Negative values (squat blocks under a heavy ship)
    mean the blocks stop rocking at the impact; they are returned as 0.

    Parameters
    ----------
    mass_ratio : float
        :math:`M_n = nm/M` [-].
    alpha : float
        Slenderness angle :math:`\\alpha = \\arctan(B/H)` [rad].
    inertia_ratio : float, optional
        :math:`\\kappa = I/(mR^2)` [-]; 1/3 for a uniform block.

    Returns
    -------
    float
        :math:`e_{sys} \\in [0, 1)` [-].

    References
    ----------
    .. [1] Housner, G. W. (1963). The behavior of inverted pendulum structures during
       earthquakes. Bull. Seismol. Soc. Am. 53(2), 403-417.
    """
    mass_ratio = real(mass_ratio, "mass_ratio", low=0.0)
    alpha = real(alpha, "alpha", low=0.0, high=math.pi / 2, low_open=True, high_open=True,
                 units="rad")
    inertia_ratio = real(inertia_ratio, "inertia_ratio", low=0.0, high=1.0, low_open=True)
    # In units of M R^2: nI = kappa*Mn, (nm + 4M) = Mn + 4.
    num = inertia_ratio * mass_ratio + (mass_ratio + 4.0) * math.cos(2.0 * alpha)
    den = inertia_ratio * mass_ratio + (mass_ratio + 4.0)
    return max(0.0, num / den)


@dataclass(frozen=True)
class ShipBlockSystem:
    """A rigid ship on ``n_blocks`` identical rigid keel blocks.

    Parameters
    ----------
    ship_mass : float
        Ship mass :math:`M` [kg].
    block_mass : float
        Mass of one keel block :math:`m` [kg].
    n_blocks : int
        Number of keel blocks :math:`n` [-].
    half_width, half_height : float
        Block half width :math:`B` and half height :math:`H` [m].
    mu_s_ground, mu_k_ground : float
        Static and kinetic friction coefficients between blocks and ground [-].
    mu_s_ship, mu_k_ship : float
        Static and kinetic friction coefficients between blocks and ship [-].
    restitution : float or None, optional
        Ratio :math:`\\dot\\theta^+/\\dot\\theta^-` at an impact [-]. ``None`` (default) uses
        :func:`system_restitution`.
    impact_rule : {"momentum", "paper", "plastic"}, optional
        ``"momentum"`` (default) keeps the generalised momenta of the slipping coordinates
        through an impact (impulses at slipping interfaces are frictionless), so an impact
        never creates energy. ``"paper"`` scales :math:`\\dot\\theta` only and keeps the slip
        velocities (exact only when both interfaces stick). ``"plastic"`` takes all the
        velocities after the impact from the momentum balance about the new pivot
        (generalised Housner; :func:`shipblock.impact.apply_impact`); it fixes the
        restitution itself, so ``restitution`` must then be None.
    block_inertia : float or None, optional
        Centroidal inertia of one block :math:`I` [kg m^2]; ``None`` gives the uniform block
        :math:`m(B^2+H^2)/3`.
    g : float, optional
        Gravity [m/s^2], default 9.80665.

    Raises
    ------
    ParameterTypeError
        For a field of the wrong type (a string or None for a number, a bool...).
    ParameterError
        For a value outside its range in :data:`FIELD_LIMITS` (non-finite, a non-positive mass
        or size, negative friction...), a kinetic coefficient above the static one, a
        ``block_inertia`` outside :data:`MIN_INERTIA_RATIO` .. 1 times :math:`m(B^2+H^2)` or
        an unknown impact rule. Both are
        :class:`ValueError`; the message names the field and what it expects.
    """

    ship_mass: float
    block_mass: float
    n_blocks: int
    half_width: float
    half_height: float
    mu_s_ground: float
    mu_k_ground: float
    mu_s_ship: float
    mu_k_ship: float
    restitution: float | None = None
    impact_rule: str = "momentum"
    block_inertia: float | None = None
    g: float = STANDARD_GRAVITY

    def __post_init__(self):
        for name, (low, high, units) in FIELD_LIMITS.items():
            value = getattr(self, name)
            if value is None and name in ("restitution", "block_inertia"):
                continue
            if name == "n_blocks":
                # a whole float (3.0, as TOML or a sweep may give it) is kept as the int 3
                object.__setattr__(self, name, whole(value, name, low=low, high=high))
            else:
                real(value, name, low=low, high=high, units=units,
                     low_open=name == "block_inertia")
        for iface in ("ground", "ship"):
            mus, muk = getattr(self, f"mu_s_{iface}"), getattr(self, f"mu_k_{iface}")
            if muk > mus:
                raise ParameterError(
                    f"mu_k_{iface} ({muk}) must not exceed mu_s_{iface} ({mus}): kinetic friction "
                    "above static friction is not physical"
                )
        choice(self.impact_rule, "impact_rule", IMPACT_RULES)
        if self.impact_rule == "plastic" and self.restitution is not None:
            raise ParameterError(
                f"restitution must be None with impact_rule='plastic' (got {self.restitution!r}): "
                "the plastic projection gives the velocities after an impact itself")
        if self.block_inertia is not None:
            # every point of a block lies within R of its centroid: I <= m R^2; far below
            # MIN_INERTIA_RATIO m R^2 the block is a point mass and the ratio underflows
            most = self.block_mass * (self.half_width**2 + self.half_height**2)
            if not MIN_INERTIA_RATIO * most <= self.block_inertia <= most:
                raise ParameterError(
                    f"block_inertia must lie between {MIN_INERTIA_RATIO:g} and 1 times "
                    f"block_mass * (half_width^2 + half_height^2) = {most:g} kg m^2 (all the "
                    f"mass at the corners), got {self.block_inertia!r}"
                )

    # Derived quantities ------------------------------------------------------------------
    @property
    def total_block_mass(self) -> float:
        """:math:`nm` [kg]."""
        return self.n_blocks * self.block_mass

    @property
    def inertia(self) -> float:
        """Centroidal inertia of one block :math:`I` [kg m^2]."""
        if self.block_inertia is not None:
            return float(self.block_inertia)
        return self.block_mass * (self.half_width**2 + self.half_height**2) / 3.0

    @property
    def half_diagonal(self) -> float:
        """:math:`R = \\sqrt{B^2 + H^2}` [m]."""
        return math.hypot(self.half_width, self.half_height)

    @property
    def critical_angle(self) -> float:
        """:math:`\\theta_c = \\alpha = \\arctan(B/H)` [rad]: overturning angle."""
        return math.atan2(self.half_width, self.half_height)

    @property
    def mass_ratio(self) -> float:
        """:math:`M_n = nm/M` [-]."""
        return self.total_block_mass / self.ship_mass

    @property
    def inertia_ratio(self) -> float:
        """:math:`\\kappa = I/(mR^2)` [-] (1/3 for a uniform block)."""
        return self.inertia / (self.block_mass * self.half_diagonal**2)

    @property
    def effective_restitution(self) -> float:
        """Restitution used by the solver [-]: ``restitution`` or :func:`system_restitution`."""
        if self.restitution is not None:
            return float(self.restitution)
        return system_restitution(self.mass_ratio, self.critical_angle, self.inertia_ratio)

    def to_parameter_vector(self) -> np.ndarray:
        """Pack the system into the float vector the compiled kernels take."""
        p = np.empty(N_PARAMS)
        p[P_M] = self.ship_mass
        p[P_NM] = self.total_block_mass
        p[P_NI] = self.n_blocks * self.inertia
        p[P_B] = self.half_width
        p[P_H] = self.half_height
        p[P_R] = self.half_diagonal
        p[P_THC] = self.critical_angle
        p[P_MUS1] = self.mu_s_ground
        p[P_MUK1] = self.mu_k_ground
        p[P_MUS2] = self.mu_s_ship
        p[P_MUK2] = self.mu_k_ship
        p[P_E] = self.effective_restitution
        p[P_RULE] = IMPACT_RULES.index(self.impact_rule)
        p[P_G] = self.g
        return p

    @cached_property
    def kernel_parameters(self) -> np.ndarray:
        """:meth:`to_parameter_vector`, made once per system and read-only: the batch entry
        point takes it at every call, which for a short batch costs as much as a few runs."""
        p = self.to_parameter_vector()
        p.flags.writeable = False
        return p

    @classmethod
    def example(cls) -> ShipBlockSystem:
        """A typical dry-dock configuration, used by the command line when no system is given.

        An 8,000 t ship on 200 concrete keel blocks with timber caps, each 0.7 m wide, 1.2 m tall
        and 1.5 t; concrete on concrete at the dock floor (mu_s = 0.6, mu_k = 0.5) and steel on
        timber at the hull (mu_s = 0.5, mu_k = 0.4). Illustrative values, not a design basis.
        """
        return cls(
            ship_mass=8.0e6, block_mass=1500.0, n_blocks=200, half_width=0.35, half_height=0.6,
            mu_s_ground=0.6, mu_k_ground=0.5, mu_s_ship=0.5, mu_k_ship=0.4,
        )

    @classmethod
    def from_mapping(cls, values, source: str = "system") -> ShipBlockSystem:
        """Build a system from a mapping (for example a TOML table), naming unknown keys.

        Parameters
        ----------
        values : Mapping
            Constructor arguments; a nested ``system`` table is accepted too. A dimensional
            field (:data:`FIELD_UNITS`) may be a string with a unit (``"20000 t"``), converted
            to SI; numbers are SI. A system outside a dock's ranges is logged as a warning
            (:func:`warn_implausible`).
        source : str
            Where the values came from, for error messages.

        Raises
        ------
        ValueError
            For an unknown or missing key, or an invalid value; the message names it.
        """
        if "system" in values and isinstance(values["system"], dict):
            values = values["system"]
        known = set(cls.__dataclass_fields__)
        unknown = sorted(set(values) - known)
        if unknown:
            raise ParameterError(f"{source}: unknown system parameter(s) {unknown}; known: {sorted(known)}")
        missing = [f.name for f in fields(cls) if f.name not in values
                   and f.default is MISSING and f.default_factory is MISSING]
        if missing:
            raise ParameterTypeError(f"{source}: missing system parameter(s) {missing}")
        try:
            system = cls(**si_values(values))
        except ParameterError as exc:  # also a ParameterTypeError: keep the type
            raise type(exc)(f"{source}: {exc}") from None
        except TypeError as exc:  # a missing field
            raise ParameterTypeError(f"{source}: {exc}") from None
        warn_implausible(system, source)
        return system

    @classmethod
    def from_toml(cls, path) -> ShipBlockSystem:
        """Read a system from a TOML file with a ``[system]`` table: numbers in SI units, or
        strings with a unit (``ship_mass = "20000 t"``, ``half_width = "600 mm"``).

        Raises
        ------
        ParameterTypeError
            If ``path`` is not a path (``None``, a number: never a file descriptor).
        ParameterError
            Naming the file: unreadable, not UTF-8, not TOML, nested deeper than
            :data:`shipblock.checks.MAX_TOML_DEPTH` levels, or an invalid system.
        """
        path = pathname(path, "path", "a system TOML file")
        return cls.from_mapping(toml_file(path, "system file"), source=str(path))

    def replace(self, **changes) -> ShipBlockSystem:
        """A copy with some parameters changed (validated again)."""
        values = self.to_dict()
        values.update(changes)
        return ShipBlockSystem(**values)

    def to_dict(self) -> dict:
        """The constructor arguments as a plain dict (for provenance and TOML)."""
        return asdict(self)


def implausible(system: ShipBlockSystem) -> list[str]:
    r"""What about a system is outside any dock, in words an engineer can check.

    Three quantities, each with its range (a unit mistake, tonnes given as kilograms, leaves at
    least one of them orders of magnitude out):

    * the density of a block :data:`ASSUMED_BLOCK_LENGTH` (1 m) long along the keel,
      :math:`\rho = m / (2B \cdot 2H \cdot L)`, within :data:`BLOCK_DENSITY_RANGE`;
    * the ship's weight per block, :math:`Mg/n`, within :data:`LOAD_PER_BLOCK_RANGE`;
    * the ship-to-blocks mass ratio :math:`M/(nm)`, within :data:`SHIP_TO_BLOCKS_RANGE`.

    Parameters
    ----------
    system : ShipBlockSystem

    Returns
    -------
    list of str
        One sentence per quantity out of its range (empty for a plausible dock).
    """
    found = []
    density = system.block_mass / (4.0 * system.half_width * system.half_height
                                   * ASSUMED_BLOCK_LENGTH)
    low, high = BLOCK_DENSITY_RANGE
    if not low <= density <= high:
        found.append(
            f"block density {density:.3g} kg/m^3 (block mass {system.block_mass:.4g} kg in a"
            f" {2 * system.half_width:g} m x {2 * system.half_height:g} m section, taken"
            f" {ASSUMED_BLOCK_LENGTH:g} m long) is outside {low:g}-{high:g} kg/m^3 (timber to"
            " steel): is block_mass in kg (--block-mass \"4 t\" for tonnes)?")
    load = system.ship_mass * system.g / system.n_blocks
    low, high = LOAD_PER_BLOCK_RANGE
    if not low <= load <= high:
        found.append(
            f"ship weight per block {load / 1e3:.3g} kN (ship mass {system.ship_mass:.4g} kg on"
            f" {system.n_blocks} blocks) is outside {low / 1e3:g}-{high / 1e3:g} kN: is"
            " ship_mass in kg (--ship-mass \"20000 t\" for tonnes)?")
    ratio = system.ship_mass / (system.n_blocks * system.block_mass)
    low, high = SHIP_TO_BLOCKS_RANGE
    if not low <= ratio <= high:
        found.append(
            f"ship-to-blocks mass ratio M/(n m) = {ratio:.3g} is outside {low:g}-{high:g}"
            " (a docked ship outweighs its blocks, and blocks are not feathers)")
    return found


def warn_implausible(system: ShipBlockSystem, source: str = "system") -> list[str]:
    """Log a warning (logger ``shipblock.system``) for each of :func:`implausible`'s findings.

    Parameters
    ----------
    system : ShipBlockSystem
    source : str, optional
        Where the system came from (a file, the command line), for the message.

    Returns
    -------
    list of str
        The findings warned about.
    """
    found = implausible(system)
    for finding in found:
        logger.warning("%s: implausible for a ship on keel blocks: %s", source, finding)
    return found


def si_values(values) -> dict:
    """A ``[system]`` table's values with the quantities given with a unit in SI.

    Parameters
    ----------
    values : Mapping
        Field name -> value; a dimensional field (:data:`FIELD_UNITS`) may be a string with a
        unit (``"20000 t"``, ``"600 mm"``). Numbers (SI) and other fields pass unchanged.

    Returns
    -------
    dict

    Raises
    ------
    ParameterError
        Naming the key, for a string that is not a quantity of the field's dimension
        (:func:`shipblock.quantities.to_si`).
    """
    return {key: (to_si(value, FIELD_UNITS[key], key)
                  if key in FIELD_UNITS and isinstance(value, str) else value)
            for key, value in values.items()}


def system_line(system) -> str:
    """One line naming a ship-block system as a report would: masses in t, block size in m,
    friction static/kinetic per interface.

    Parameters
    ----------
    system : Mapping
        :meth:`ShipBlockSystem.to_dict`.

    Returns
    -------
    str
        e.g. ``"ship 5000 t on 150 blocks of 1.2 t, 2B x 2H = 0.6 x 1.2 m; friction
        blocks-floor 0.6/0.55, ship-blocks 0.35/0.3 (static/kinetic)"``.
    """
    d = system
    return (f"ship {float(d['ship_mass']) / 1e3:.4g} t on {int(d['n_blocks'])} blocks of "
            f"{float(d['block_mass']) / 1e3:.3g} t, 2B x 2H = {2 * float(d['half_width']):.3g} x "
            f"{2 * float(d['half_height']):.3g} m; friction blocks-floor "
            f"{float(d['mu_s_ground']):.3g}/{float(d['mu_k_ground']):.3g}, ship-blocks "
            f"{float(d['mu_s_ship']):.3g}/{float(d['mu_k_ship']):.3g} (static/kinetic)")
