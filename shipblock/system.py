"""The ship-block system: parameters, validation and derived quantities.

A rigid ship of mass :math:`M` stands on :math:`n` identical rigid keel blocks, each
:math:`2B` wide and :math:`2H` tall with mass :math:`m` and centroidal inertia :math:`I`.
Coulomb friction acts at the block-ground interface (:math:`\\mu_{s1}, \\mu_{k1}`) and at the
block-ship interface (:math:`\\mu_{s2}, \\mu_{k2}`).
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass

import numpy as np

from shipblock.errors import ParameterError
from shipblock.units import STANDARD_GRAVITY

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
    ValueError
        For a non-positive mass or size, negative friction, a kinetic coefficient above the
        static one, restitution outside [0, 1] or an unknown impact rule; the message names the
        field.
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
        def positive(name):
            value = getattr(self, name)
            if not (isinstance(value, int | float | np.floating | np.integer)) or not (
                math.isfinite(value) and value > 0
            ):
                raise ParameterError(f"{name} must be a finite number > 0, got {value!r}")

        for name in ("ship_mass", "block_mass", "half_width", "half_height", "g"):
            positive(name)
        if int(self.n_blocks) != self.n_blocks or self.n_blocks < 1:
            raise ParameterError(f"n_blocks must be a whole number >= 1, got {self.n_blocks!r}")
        for name in ("mu_s_ground", "mu_k_ground", "mu_s_ship", "mu_k_ship"):
            value = getattr(self, name)
            if not (math.isfinite(value) and value >= 0):
                raise ParameterError(f"{name} must be a finite number >= 0, got {value!r}")
        for iface in ("ground", "ship"):
            mus, muk = getattr(self, f"mu_s_{iface}"), getattr(self, f"mu_k_{iface}")
            if muk > mus:
                raise ParameterError(
                    f"mu_k_{iface} ({muk}) must not exceed mu_s_{iface} ({mus}): kinetic friction "
                    "above static friction is not physical"
                )
        if self.restitution is not None and not (0.0 <= self.restitution <= 1.0):
            raise ParameterError(f"restitution must lie in [0, 1], got {self.restitution!r}")
        if self.impact_rule not in IMPACT_RULES:
            raise ParameterError(f"impact_rule must be one of {IMPACT_RULES}, got {self.impact_rule!r}")
        if self.impact_rule == "plastic" and self.restitution is not None:
            raise ParameterError(
                f"restitution must be None with impact_rule='plastic' (got {self.restitution!r}): "
                "the plastic projection gives the velocities after an impact itself")
        if self.block_inertia is not None and not (
            math.isfinite(self.block_inertia) and self.block_inertia > 0
        ):
            raise ParameterError(f"block_inertia must be a finite number > 0, got {self.block_inertia!r}")

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
            Constructor arguments; a nested ``system`` table is accepted too.
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
        try:
            return cls(**values)
        except TypeError as exc:
            raise ParameterError(f"{source}: {exc}") from None
        except ValueError as exc:
            raise ParameterError(f"{source}: {exc}") from None

    @classmethod
    def from_toml(cls, path) -> ShipBlockSystem:
        """Read a system from a TOML file with a ``[system]`` table (SI units)."""
        import tomllib

        with open(path, "rb") as fh:
            try:
                data = tomllib.load(fh)
            except tomllib.TOMLDecodeError as exc:
                raise ParameterError(f"{path}: not valid TOML: {exc}") from None
        return cls.from_mapping(data, source=str(path))

    def replace(self, **changes) -> ShipBlockSystem:
        """A copy with some parameters changed (validated again)."""
        values = self.to_dict()
        values.update(changes)
        return ShipBlockSystem(**values)

    def to_dict(self) -> dict:
        """The constructor arguments as a plain dict (for provenance and TOML)."""
        return asdict(self)
