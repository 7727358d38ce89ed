"""The dock-section model assembled: bodies, cap strips, springs, and the initial static state.

Bodies and coordinates
----------------------
Axes y across the dock (positive to starboard) and z up, in the floor's frame; the floor moves
with ``(a_y, a_z)`` and every body carries the inertial loads ``-m a_y`` and ``-m (g + a_z)``.
Body 0 is the ship, with the state ``(y_G, z_G, phi)`` of its centre of gravity G (roll ``phi``
counter-clockwise, looking forward: positive roll lifts the starboard side). Each *moving* line
is one body with ``N m`` and ``N I`` and the state ``(y, z, theta)`` of its centre. A fixed side
line is not a body: its top cap sits on a block wedged to the floor.

Strips and springs
------------------
Every face where a cap touches something is a *strip*: the cap on body C (a block) pressed
against the straight surface of body S (the hull, or the floor). Its ``n`` springs stand at the
Gauss-Lobatto points of the face, with the Lobatto weights as tributary fractions: the ends of
the face are springs (a block rocks on its corners, as in the rigid model), and the force and
moment of a fully loaded, linearly compressed layer are exact for ``n >= 3`` (the quadrature is
exact to degree ``2n - 3``), so the cap's rotational stiffness is the continuous layer's. With
``n = 2`` (the classical two-spring model) it is 3 times the layer's. Per spring of tributary
area ``A_i = A w_i / 2`` (``A`` the face's area along its slope):

* closure ``delta = (q_S - p_C) . n_S`` (``p_C`` the spring's point on the face, ``q_S`` a point
  of S's surface, ``n_S`` its outward normal): the spring force ``f n_S`` acts on C at ``p_C``
  and ``-f n_S`` on S there, which is the exact gradient of ``k delta^2 / 2``;
* elastic: ``f = k (delta - delta_p) + c delta_dot`` with ``k = k_strip w_i / 2``,
  ``k_strip = N E_perp A / t`` (or the given stiffness);
* crushing: when the elastic part reaches ``N sigma_pl A_i`` the spring is perfectly plastic,
  ``f = N sigma_pl A_i + c delta_dot``, and the set ``delta_p`` grows with the closure; it is
  kept when the spring unloads (a crushed cap never springs back);
* no tension: when ``f`` would pull, the spring lets go. The cap then relaxes on its own
  (Kelvin-Voigt with a massless free surface: its compression decays towards ``delta_p`` with
  the time constant ``c / k``) and carries nothing until the body meets its surface again; a
  spring meeting a relaxed cap starts with the force ``c delta_dot`` (the dashpot's jump);
* damping: ``c_strip = 2 zeta sqrt(k_strip m_eff)``, spread like ``k``; ``m_eff`` is the mass
  the strip carries by the stiffness rule: the ship's mass shared among the strips under it in
  proportion to their vertical stiffness, plus the line's own mass for a floor strip.

Friction acts per strip on its total normal force ``N``, at the strip's centre of pressure (the
point of C's face where the resultant of its spring forces acts: the loaded corner of a rocking
block, as the rigid model's sticking pivot; the face centre while the strip carries nothing)
along the tangent ``t = (n_z, -n_y)``: a stick spring ``F_t = -k_t u - c_t v_t`` (``k_t`` the
cap's ``shear_ratio`` times ``k_strip``, ``c_t = 2 zeta sqrt(k_t m_eff)``), with ``u`` the
integral since the last stick point of ``v_t``, the relative tangential velocity of C's material
point at the centre of pressure (the force acts where its rate is taken: the energy balance is
exact; at rest ``u`` is the displacement of the face centre, see *Initial state*); slip when ``|F_t|`` reaches ``mu_s N``, then
``F_t = -mu_k N sign(v_t)``; stick again when ``v_t`` changes sign, the stick spring preloaded
to ``mu_k N`` (the force continuous) but to no more energy than the face has lost since its
slip began (a slip-stick cycle cannot create energy). The stick spring's energy at a slip onset
is counted as friction loss, a preload's against it.

Initial state
-------------
The elastic static solution under gravity (and a steady wind) with every loaded strip sticking,
the stick springs measuring from the stress-free touching position (the ship set down on the keel
line, side lines as built). :func:`static_state` computes it; a dock whose caps would crush at
rest is refused.
"""

from __future__ import annotations

import math
import dataclasses
from dataclasses import dataclass

import numpy as np
from numpy.polynomial import legendre
from scipy import optimize

from shipblock.errors import ParameterError, ParameterTypeError
from shipblock.section import _kernel as K
from shipblock.section.parameters import DockSection

__all__ = ["Assembly", "InitialState", "NoStaticSolution", "SlidesAtRest", "assemble",
           "check_static_state", "damping_for_restitution", "impact_restitution", "lobatto",
           "static_state", "sunk_state"]

#: Largest rotation the model is written for [rad] (beyond it a run stops as out of validity).
MAX_ANGLE = math.pi / 3.0
#: Largest displacement of a body from its start [m].
MAX_DISPLACEMENT = 10.0


def impact_restitution(damping_ratio: float) -> float:
    """Coefficient of restitution of a normal impact on a cap of damping ratio zeta < 1.

    A mass on a linear spring and dashpot (``c = 2 zeta sqrt(k m)``) that leaves when the contact
    force falls to zero (the no-tension law of this model) rebounds with

    .. math::

        e = \\exp\\left(-\\frac{\\zeta\\,\\vartheta}{\\sqrt{1-\\zeta^2}}\\right), \\qquad
        \\tan\\vartheta = -\\frac{2\\zeta\\sqrt{1-\\zeta^2}}{1-2\\zeta^2},
        \\quad \\vartheta \\in (0, \\pi)

    (Schwager and Poeschel 2007, Granular Matter 9, 465-469). Gravity during the contact is
    neglected (a contact much shorter than the flight). This is the *normal* impact of a body on
    its cap, with ``zeta`` the cap's damping ratio as defined in the module docstring; a rocking
    impact loses more (the rigid model's plastic value is approached for zeta of a few).
    """
    z = float(damping_ratio)
    if not 0.0 <= z < 1.0:
        raise ParameterError(f"damping_ratio must be in [0, 1) for the closed form, got {z!r}")
    if z == 0.0:
        return 1.0
    s = math.sqrt(1.0 - z * z)
    angle = math.atan2(2.0 * z * s, 2.0 * z * z - 1.0)  # sin = 2 z s, cos = 2 z^2 - 1
    return math.exp(-z * angle / s)


def damping_for_restitution(restitution: float) -> float:
    """The cap damping ratio whose normal impact has ``restitution`` (inverse of
    :func:`impact_restitution`), for restitution in (0.001, 1]."""
    e = float(restitution)
    if not 1e-3 < e <= 1.0:
        raise ParameterError(f"restitution must be in (0.001, 1], got {e!r}")
    if e == 1.0:
        return 0.0
    return optimize.brentq(lambda z: impact_restitution(z) - e, 0.0, 1.0 - 1e-12, xtol=1e-14)


def lobatto(n: int) -> tuple[np.ndarray, np.ndarray]:
    """Gauss-Lobatto nodes on [-1, 1] and weights (summing to 2) for ``n >= 2`` points.

    The nodes are -1, 1 and the roots of :math:`P'_{n-1}`; the weights
    :math:`w_i = 2 / (n (n-1) P_{n-1}(x_i)^2)` (Abramowitz and Stegun 25.4.32).
    """
    p = legendre.Legendre.basis(n - 1)
    inner = np.sort(p.deriv().roots().real) if n > 2 else np.array([])
    x = np.concatenate(([-1.0], inner, [1.0]))
    w = 2.0 / (n * (n - 1) * p(x) ** 2)
    return x, w


@dataclass(frozen=True)
class Assembly:
    """The compiled kernel's view of a :class:`DockSection` (arrays, SI units).

    Attributes
    ----------
    section : DockSection
    mass, inertia : ndarray
        Per body (ship, then moving lines) [kg], [kg m^2].
    body_line : tuple of int
        Line index (0 keel, 1.. sides) of each moving line body; body b is line ``body_line[b-1]``.
    strip_f, strip_i, spring_f : ndarray
        Strip and spring tables (layout in :mod:`shipblock.section._kernel`).
    strip_line, strip_top : ndarray
        Line index of each strip and whether it is the line's top (under the hull).
    q0 : ndarray
        Stress-free touching position of every body.
    opt : ndarray
        Option vector (gravity, wind, failure geometry).
    theta_c : ndarray
        Critical angle atan(B/H) of each body (unused for the ship).
    m_eff : ndarray
        Mass carried by each strip by the stiffness rule [kg].
    """

    section: DockSection
    mass: np.ndarray
    inertia: np.ndarray
    body_line: tuple
    strip_f: np.ndarray
    strip_i: np.ndarray
    spring_f: np.ndarray
    strip_line: np.ndarray
    strip_top: np.ndarray
    q0: np.ndarray
    opt: np.ndarray
    theta_c: np.ndarray
    m_eff: np.ndarray

    @property
    def n_bodies(self) -> int:
        return self.mass.shape[0]

    @property
    def n_strips(self) -> int:
        return self.strip_i.shape[0]

    @property
    def n_state(self) -> int:
        return 6 * self.n_bodies + self.n_strips + 4


def assemble(section: DockSection, separation_height: float = 0.02) -> Assembly:
    """Build the kernel's tables for ``section`` (see the module docstring for every law)."""
    ship, keel = section.ship, section.keel
    xi, w = lobatto(section.n_springs)
    lines = section.lines
    body_of_line = {}
    mass, inertia, theta_c, q0 = [ship.mass], [ship.roll_inertia], [0.0], []
    q0 += [ship.g_offset, 2.0 * keel.block.half_height + ship.g_height, 0.0]
    body_line = []
    for li, line in enumerate(lines):
        if line.moving:
            body_of_line[li] = len(mass)
            body_line.append(li)
            blk = line.block
            mass.append(line.n_blocks * blk.block_mass)
            inertia.append(line.n_blocks * blk.inertia)
            theta_c.append(math.atan2(blk.half_width, blk.half_height))
            q0 += [line.offset, blk.half_height, 0.0]
    strips = []  # (c_body, s_body, fixed pose, surf point, normal, centre, springs, cap, line, top)
    for li, line in enumerate(lines):
        blk = line.block
        cb = body_of_line.get(li, -1)
        pose = (line.offset, blk.half_height, 0.0)
        beta = line.hull_slope
        if li == 0:
            half = min(blk.half_width, ship.keel_half_width)
            surf = (-ship.g_offset, -ship.g_height)
        else:
            half = blk.half_width
            surf = (line.offset - ship.g_offset, line.hull_height - ship.g_height)
        tb = math.tan(beta)
        springs = [(x * half, blk.half_height + x * half * tb) for x in xi]
        area = blk.length * 2.0 * half / math.cos(beta)
        normal = (math.sin(beta), -math.cos(beta))
        strips.append((cb, 0, pose, surf, normal, (0.0, blk.half_height), springs, blk.top, area,
                       line, li, True))
        if cb >= 0:
            springs = [(x * blk.half_width, -blk.half_height) for x in xi]
            area = blk.length * 2.0 * blk.half_width
            strips.append((cb, -1, pose, (0.0, 0.0), (0.0, 1.0), (0.0, -blk.half_height),
                           springs, blk.bottom, area, line, li, False))
    # stiffness, then the mass each strip carries (stiffness rule), then damping
    k_strip = [s[7].normal_stiffness(s[8]) * s[9].n_blocks for s in strips]
    top_vertical = sum(k * s[4][1] ** 2 for k, s in zip(k_strip, strips, strict=True) if s[11])
    m_eff = []
    for k, s in zip(k_strip, strips, strict=True):
        if s[11]:
            m_eff.append(ship.mass * k * s[4][1] ** 2 / top_vertical)
    top_of_line = {s[10]: m for s, m in zip((s for s in strips if s[11]), m_eff, strict=True)}
    m_eff = []
    for s in strips:
        if s[11]:
            m_eff.append(top_of_line[s[10]])
        else:
            m_eff.append(top_of_line[s[10]] + mass[s[0]])
    ns = len(strips)
    nsp = ns * len(xi)
    strip_f = np.zeros((ns, K.N_SF))
    strip_i = np.zeros((ns, K.N_SI), dtype=np.int64)
    spring_f = np.zeros((nsp, K.N_PF))
    for j, s in enumerate(strips):
        cb, sb, pose, surf, normal, centre, springs, cap, area, line, li, top = s
        k = k_strip[j]
        kt = cap.shear_ratio * k
        strip_f[j, K.SF_SQY:K.SF_SQZ + 1] = surf
        strip_f[j, K.SF_SNY:K.SF_SNZ + 1] = normal
        strip_f[j, K.SF_CY:K.SF_CZ + 1] = centre
        strip_f[j, K.SF_KT] = kt
        strip_f[j, K.SF_CT] = 2.0 * cap.damping_ratio * math.sqrt(kt * m_eff[j])
        strip_f[j, K.SF_MUS] = cap.mu_s
        strip_f[j, K.SF_MUK] = cap.mu_k
        strip_f[j, K.SF_PY:K.SF_PA + 1] = pose
        strip_i[j] = (cb, sb, j * len(xi), len(xi))
        c = 2.0 * cap.damping_ratio * math.sqrt(k * m_eff[j])
        for i, (r, wi) in enumerate(zip(springs, w, strict=True)):
            row = spring_f[j * len(xi) + i]
            row[K.PF_RY], row[K.PF_RZ] = r
            row[K.PF_K] = k * wi / 2.0
            row[K.PF_C] = c * wi / 2.0
            row[K.PF_AREA] = area * wi / 2.0  # per block
            row[K.PF_FY] = line.n_blocks * cap.proportional_limit * row[K.PF_AREA]
    opt = np.zeros(K.N_OPT)
    opt[K.O_G] = section.g
    if section.wind is not None:
        opt[K.O_WIND_F] = section.wind.lateral_force
        opt[K.O_WIND_Y] = -ship.g_offset
        opt[K.O_WIND_Z] = section.wind.height - ship.g_height
    opt[K.O_ROLL_HELD] = float(section.roll_held)
    opt[K.O_SEP] = separation_height
    opt[K.O_TIP_POS], opt[K.O_TIP_NEG] = _tip_angles(section)
    opt[K.O_KEEL_B] = keel.block.half_width
    opt[K.O_KEEL_TOP_Y], opt[K.O_KEEL_TOP_Z] = 0.0, keel.block.half_height
    opt[K.O_SHIP_KY], opt[K.O_SHIP_KZ] = -ship.g_offset, -ship.g_height
    opt[K.O_MAX_ANGLE] = MAX_ANGLE
    opt[K.O_MAX_DISP] = MAX_DISPLACEMENT
    return Assembly(section, np.array(mass), np.array(inertia), tuple(body_line), strip_f, strip_i,
                    spring_f, np.array([s[10] for s in strips]), np.array([s[11] for s in strips]),
                    np.array(q0), opt, np.array(theta_c), np.array(m_eff))


def _tip_angles(section: DockSection) -> tuple[float, float]:
    """Roll angles (positive roll, negative roll) at which G passes over the outermost support.

    Positive roll heels the ship to port (lifts starboard): it pivots on the port-most support.
    Supports are the keel's edges and the side strips' outer edges, relative to the keel's
    underside at the centre line.
    """
    ship = section.ship
    b = min(section.keel.block.half_width, ship.keel_half_width)
    port, stbd = (-b, 0.0), (b, 0.0)
    for line in section.sides:
        edge = abs(line.offset) + line.block.half_width
        z = line.hull_height + math.copysign(line.block.half_width, line.offset) * math.tan(
            line.hull_slope)
        if line.offset < 0 and -edge < port[0]:
            port = (-edge, z)
        if line.offset > 0 and edge > stbd[0]:
            stbd = (edge, z)
    pos = math.atan2(ship.g_offset - port[0], ship.g_height - port[1])
    neg = math.atan2(stbd[0] - ship.g_offset, ship.g_height - stbd[1])
    return min(pos, MAX_ANGLE), min(neg, MAX_ANGLE)


def tangent_coordinates(asm: Assembly, q: np.ndarray) -> np.ndarray:
    """Tangential coordinate of every strip's face centre (on C) in S's frame [m]."""
    out = np.zeros(asm.n_strips)
    for j in range(asm.n_strips):
        cb, sb = asm.strip_i[j, K.SI_C], asm.strip_i[j, K.SI_S]
        c = asm.strip_f[j, K.SF_PY:K.SF_PA + 1] if cb < 0 else q[3 * cb:3 * cb + 3]
        s = np.zeros(3) if sb < 0 else q[3 * sb:3 * sb + 3]
        ry, rz = asm.strip_f[j, K.SF_CY], asm.strip_f[j, K.SF_CZ]
        py = c[0] + math.cos(c[2]) * ry - math.sin(c[2]) * rz
        pz = c[1] + math.sin(c[2]) * ry + math.cos(c[2]) * rz
        dy, dz = py - s[0], pz - s[1]
        ly = math.cos(s[2]) * dy + math.sin(s[2]) * dz  # in S's frame
        lz = -math.sin(s[2]) * dy + math.cos(s[2]) * dz
        ny, nz = asm.strip_f[j, K.SF_SNY], asm.strip_f[j, K.SF_SNZ]
        out[j] = ly * nz - lz * ny
    return out


@dataclass(frozen=True)
class InitialState:
    """The static state a run starts from (:func:`static_state`).

    Attributes
    ----------
    x : numpy.ndarray
        The kernel's state (positions, zero velocities, each strip's stick spring).
    regime, plastic_set, spring_force : numpy.ndarray
        Per spring: its regime, permanent set [m] (none) and force [N].
    friction, normal : numpy.ndarray
        Per strip: its friction state and normal force [N] (whole line).
    section : DockSection or None
        The section it was solved for (None: not a static state, :func:`sunk_state`).
    settled_separation_height : float or None
        The separation height [m] of the run that let the dock settle before the solve
        (:func:`shipblock.section.simulate.rest_state`): that run stops at a separation, so the
        state is one of assemblies with this separation height only. None: solved without
        settling, a state of the section at every separation height.
    """

    x: np.ndarray
    regime: np.ndarray
    plastic_set: np.ndarray
    friction: np.ndarray
    normal: np.ndarray  # per strip [N], whole line
    spring_force: np.ndarray  # per spring [N], whole line
    section: DockSection | None = dataclasses.field(default=None, repr=False)
    settled_separation_height: float | None = None


def _forces(asm: Assembly, q: np.ndarray, u: np.ndarray):
    """Generalised forces at rest at q (stick springs at u), with the regimes they imply."""
    nb, ns = asm.n_bodies, asm.n_strips
    nsp = asm.spring_f.shape[0]
    x = np.zeros(asm.n_state)
    x[:3 * nb] = q
    x[6 * nb:6 * nb + ns] = u
    delta, ddot, vt = np.zeros(nsp), np.zeros(nsp), np.zeros(ns)
    pos = np.zeros((nsp, 2))
    K.kinematics(x, nb, asm.strip_f, asm.strip_i, asm.spring_f, delta, ddot, vt, pos)
    reg = np.where(delta > 0.0, K.R_ELASTIC, K.R_FREE).astype(np.int64)
    fs = np.full(ns, K.F_FREE, dtype=np.int64)
    for j in range(ns):
        a, n = asm.strip_i[j, K.SI_FIRST], asm.strip_i[j, K.SI_COUNT]
        if np.any(reg[a:a + n] == K.R_ELASTIC):
            fs[j] = K.F_STICK
    xdot = np.zeros_like(x)
    fe, fn, normal, tang = np.zeros(nsp), np.zeros(nsp), np.zeros(ns), np.zeros(ns)
    K.rhs(0.0, x, nb, ns, asm.mass, asm.inertia, asm.strip_f, asm.strip_i, asm.spring_f, reg,
          np.zeros(nsp), fs, asm.opt, np.zeros(2), np.zeros(2), 1.0, delta, ddot, vt, pos, fe, fn,
          normal, tang, xdot)
    acc = xdot[3 * nb:6 * nb]
    gen = acc * np.repeat(asm.mass, 3)
    gen[2::3] = acc[2::3] * asm.inertia
    return x, gen, reg, fs, normal, fn


#: Scale of the static solver's unknowns [m, m, rad].
_SCALE_Q = 1e-3
#: Steps of the continuation in the side lines' gaps (see :func:`static_state`).
_GAP_STEPS = 10


def _free(asm: Assembly) -> np.ndarray:
    free = np.ones(3 * asm.n_bodies, dtype=bool)
    if asm.section.roll_held:
        free[2] = False
    return free


def _residual(asm: Assembly, slip: np.ndarray | None = None):
    """The static residual (generalised forces over the weight) of the free displacements from
    ``asm.q0`` (scaled by ``_SCALE_Q``), and the map from those to the positions; each strip's
    stick spring stretched by its tangential displacement from the touching position less its
    ``slip`` (default none)."""
    free = _free(asm)
    u0 = tangent_coordinates(asm, asm.q0) + (0.0 if slip is None else slip)
    scale_f = asm.mass.sum() * asm.section.g

    def unpack(z):
        q = asm.q0.copy()
        q[free] += z * _SCALE_Q
        return q

    def residual(z):
        q = unpack(z)
        _, gen, *_ = _forces(asm, q, tangent_coordinates(asm, q) - u0)
        return gen[free] / scale_f

    return residual, unpack


def _solve(residual, z0) -> tuple[np.ndarray, float]:
    """Powell's hybrid method from ``z0``; where it stalls on a kink of the piecewise smooth
    residual (a side line's preload lifting the ship off the keel line), the trust-region
    least-squares method from the same start. Returns the solution and its largest residual."""
    sol = optimize.root(residual, z0, method="hybr", options={"xtol": 1e-13, "maxfev": 20000})
    worst = float(np.max(np.abs(residual(sol.x))))
    if worst < 1e-9:
        return sol.x, worst
    lsq = optimize.least_squares(residual, z0, xtol=1e-15, ftol=1e-15, gtol=1e-15, max_nfev=2000)
    worst_lsq = float(np.max(np.abs(residual(lsq.x))))
    return (lsq.x, worst_lsq) if worst_lsq < worst else (sol.x, worst)


def _sunk(asm: Assembly) -> np.ndarray:
    """Every body lowered by the static deflection of its own supports: a start from which the
    loaded springs are closed at the first iteration (the residual is piecewise smooth)."""
    nb = asm.n_bodies
    sink = np.zeros(3 * nb)
    g = asm.section.g
    k_top = sum(asm.spring_f[asm.strip_i[j, K.SI_FIRST]:asm.strip_i[j, K.SI_FIRST]
                             + asm.strip_i[j, K.SI_COUNT], K.PF_K].sum()
                for j in range(asm.n_strips) if asm.strip_top[j])
    for j in range(asm.n_strips):
        springs = slice(asm.strip_i[j, K.SI_FIRST], asm.strip_i[j, K.SI_FIRST]
                        + asm.strip_i[j, K.SI_COUNT])
        if not asm.strip_top[j]:
            b = asm.strip_i[j, K.SI_C]
            sink[3 * b + 1] = -asm.m_eff[j] * g / asm.spring_f[springs, K.PF_K].sum()
    sink[1] = -asm.mass[0] * g / k_top + min(sink[1::3].min(), 0.0)
    return sink


def sunk_state(asm: Assembly) -> InitialState:
    """The stress-free touching position with every body lowered by its supports' static
    deflection, at rest, every loaded strip sticking: where :func:`static_state` starts, and
    where :func:`shipblock.section.simulate.rest_state` lets the dock settle (not an
    equilibrium)."""
    free = _free(asm)
    q = asm.q0.copy()
    q[free] += _sunk(asm)[free]
    x, _, reg, fs, normal, fn = _forces(asm, q, tangent_coordinates(asm, q)
                                        - tangent_coordinates(asm, asm.q0))
    return InitialState(x, reg, np.zeros(asm.spring_f.shape[0]), fs, normal, fn)


def _by_continuation(asm: Assembly) -> tuple[np.ndarray, float]:
    """The static solution reached by opening the side lines' gaps (or interferences) from zero
    to their values in ``_GAP_STEPS`` steps, each solved from the last (Powell's method alone
    does not find it from the sunk start when a gap makes the ship roll onto a line)."""
    sec = asm.section
    sep = asm.opt[K.O_SEP]
    z = None
    for frac in np.linspace(0.0, 1.0, _GAP_STEPS + 1):
        if frac < 1.0:
            sides = tuple(dataclasses.replace(line, block=dataclasses.replace(
                line.block, half_height=line.block.half_height + (1.0 - frac) * sec.side_gap(i) / 2))
                for i, line in enumerate(sec.sides))
            step = assemble(dataclasses.replace(sec, sides=sides), sep)
        else:
            step = asm
        residual, _ = _residual(step)
        z, worst = _solve(residual, _sunk(step)[_free(step)] / _SCALE_Q if z is None else z)
    return z, worst


class NoStaticSolution(ParameterError):
    """:func:`static_state` found no static solution."""


class SlidesAtRest(ParameterError):
    """:func:`static_state`'s solution needs more friction than a sticking strip's ``mu_s``."""


def static_state(asm: Assembly, start: np.ndarray | None = None,
                 slip: np.ndarray | None = None) -> InitialState:
    """The elastic static solution under gravity and steady wind, every loaded strip sticking.

    Solved by Powell's hybrid method (:func:`scipy.optimize.root`) on the generalised forces,
    from ``start`` (the bodies' positions, shape ``(3 n_bodies,)``), by default from the
    stress-free touching position with every body lowered by its supports' static deflection
    (and, failing that with a side line's gap, by continuation in the gaps). Each strip's stick
    spring is stretched by its tangential displacement from the touching position, less its
    ``slip`` (per strip [m]; default none: nothing slipped while the dock was landed).
    :func:`shipblock.section.simulate.rest_state` tries again from where the dock comes to rest
    under gravity alone, with what slipped on the way, when this finds nothing.

    Raises
    ------
    NoStaticSolution
        If it finds no static solution (a :class:`ParameterError`).
    SlidesAtRest
        If a sticking strip of the solution is outside its friction cone (naming the line).
    ParameterError
        If the static state is unstable, or the caps would crush under the static load.
    """
    nb = asm.n_bodies
    free = _free(asm)
    scale_f = asm.mass.sum() * asm.section.g
    residual, unpack = _residual(asm, slip)
    # what rounding of the positions leaves unbalanced in the stiffest spring, times 100
    def floor(z):
        return 100 * np.finfo(float).eps * asm.spring_f[:, K.PF_K].max() * max(
            1.0, np.abs(unpack(z)).max()) * asm.spring_f.shape[0] / scale_f

    if start is None:
        z, worst = _solve(residual, _sunk(asm)[free] / _SCALE_Q)
        if not worst < 1e-8 + floor(z) and any(asm.section.side_gap(i) != 0.0
                                               for i in range(len(asm.section.sides))):
            z, worst = _by_continuation(asm)
    else:
        z, worst = _solve(residual, (np.asarray(start, dtype=float) - asm.q0)[free] / _SCALE_Q)
    q = unpack(z)
    x, gen, reg, fs, normal, fn = _forces(asm, q, tangent_coordinates(asm, q)
                                          - tangent_coordinates(asm, asm.q0)
                                          - (0.0 if slip is None else slip))
    if not (worst < 1e-8 + floor(z)):
        raise NoStaticSolution(
            f"the section has no static solution under gravity (largest unbalanced force "
            f"{worst:.2e} of the weight): the ship is not stable on its supports at rest; add side "
            "lines, widen the keel block or lower Ship.g_height")
    # the static state must be stable: the tangent stiffness (finite differences of the
    # generalised forces, the stick springs following the displacement) positive definite
    n_free = int(free.sum())
    stiff = np.zeros((n_free, n_free))
    step = 1e-7
    for m in range(n_free):
        dz = np.zeros(n_free)
        dz[m] = step / _SCALE_Q
        stiff[:, m] = -(residual(z + dz) - residual(z - dz)) * scale_f / (2 * step)
    stiff = 0.5 * (stiff + stiff.T)
    lowest = np.linalg.eigvalsh(stiff)[0]
    if lowest <= 0.0:
        raise ParameterError(
            f"the section's static state is unstable (tangent stiffness {lowest:.3g} < 0 in its "
            "softest direction): the ship would tip off its supports at rest; add side lines, "
            "widen the keel block or lower Ship.g_height")
    over = fn > asm.spring_f[:, K.PF_FY]
    if np.any(over):
        j = int(np.searchsorted(asm.strip_i[:, K.SI_FIRST], np.argmax(over), side="right") - 1)
        li = int(asm.strip_line[j])
        key = "DockSection.keel" if li == 0 else f"DockSection.sides[{li - 1}]"
        face = "top" if asm.strip_top[j] else "bottom"
        raise ParameterError(
            f"{key}: the {face} caps would crush under the static load (a spring at "
            f"{fn[over].max() / asm.spring_f[over, K.PF_FY].max():.2f} x its proportional-limit "
            "force): the line is overloaded at rest; add blocks or give a stronger cap")
    # and admissible: every sticking strip inside its friction cone
    u = x[6 * nb:6 * nb + asm.n_strips]
    demand = np.abs(asm.strip_f[:, K.SF_KT] * u)
    for j in range(asm.n_strips):
        if fs[j] == K.F_STICK and demand[j] > asm.strip_f[j, K.SF_MUS] * normal[j]:
            li = int(asm.strip_line[j])
            key = "DockSection.keel" if li == 0 else f"DockSection.sides[{li - 1}]"
            face = "top" if asm.strip_top[j] else "bottom"
            raise SlidesAtRest(
                f"{key}: at rest its {face} face needs a friction coefficient of "
                f"{demand[j] / normal[j]:.3g}, above its mu_s "
                f"({asm.strip_f[j, K.SF_MUS]:.3g}): the line would slide under the static load "
                "(a hull slope too steep for the friction, or an unbalanced side line)")
    return InitialState(x, reg, np.zeros(asm.spring_f.shape[0]), fs, normal, fn, asm.section)


def check_static_state(asm: Assembly, state, name: str = "initial_state") -> InitialState:
    """``state`` checked as the static state of ``asm``, to start its runs from.

    It must have been solved for an equal section (:attr:`InitialState.section`: every
    parameter the same; the static solve and the settling are deterministic, so the runs from
    it equal those from solving it again), and one that
    :func:`~shipblock.section.simulate.rest_state` found after letting the dock settle at
    ``asm``'s separation height (:attr:`InitialState.settled_separation_height`).

    Parameters
    ----------
    asm : Assembly
    state : InitialState
        From :func:`static_state` or :func:`~shipblock.section.simulate.rest_state`.
    name : str
        What to call ``state`` in an error.

    Returns
    -------
    InitialState
        ``state``.

    Raises
    ------
    ParameterTypeError
        If ``state`` is not an :class:`InitialState`.
    ParameterError
        If it is not the static state of ``asm`` (naming ``name`` and why).
    """
    if not isinstance(state, InitialState):
        raise ParameterTypeError(f"{name} must be an InitialState (rest_state's), got "
                                 f"{type(state).__name__}")
    if state.section is None or state.section != asm.section:
        raise ParameterError(f"{name} is not the static state of this section: it was solved "
                             f"for {'none' if state.section is None else 'another section'} "
                             "(rest_state of this section's assembly is)")
    settled = state.settled_separation_height
    if settled is not None and settled != asm.opt[K.O_SEP]:
        raise ParameterError(f"{name} was settled with separation_height = {settled:g} m, "
                             f"this run has {asm.opt[K.O_SEP]:g} m: solve it again "
                             "(rest_state of this assembly)")
    return state
