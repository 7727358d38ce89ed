r"""Impulsive events: impacts at the end of a rocking half-cycle, and jams of a slipping interface.

**Impacts.** At :math:`\theta = 0` the pivot jumps from the bottom corner :math:`(-sB, -H)` to
:math:`(sB, -H)` and the ship drops from one top corner onto the other. The duration of the
impact is neglected. Three rules are available:

``"momentum"`` (default)
    :math:`\dot\theta^+ = e\,\dot\theta^-`; impulses at interfaces that are slipping at the
    impact are frictionless, so the generalised momenta :math:`p_j = K_j\cdot\dot q` conjugate
    to the slipping coordinates are conserved (total horizontal momentum when the blocks slip on
    the ground, the ship's when the ship slips). With the Routhian split
    :math:`T = \tfrac12 p_S^T K_{SS}^{-1} p_S + \tfrac12 K_{eff}\dot\theta^2` an impact then never
    creates kinetic energy for :math:`0 \le e \le 1`.
``"paper"``
    :math:`\dot\theta^+ = e\,\dot\theta^-` with the slip velocities unchanged (the paper's
    Sect. 4, read with :math:`e` instead of the printed :math:`2e`, see the errata). Exact when
    both interfaces stick; otherwise it can create energy.
``"plastic"``
    The plastic projection (generalised Housner): the new pivot and the new ship contact take
    the impulses, which are frictionless at interfaces that slip, and nothing rebounds. The
    generalised momentum of the post-impact coordinates is
    :math:`p^+ = K\dot q^- - 2(nm+4M)B^2\dot\theta^-\,e_\theta`; the rows of the free
    coordinates (the rotation and the slipping interfaces) are conserved and the sticking ones
    are held at zero. Then :math:`\dot\theta^+ = e_F\,\dot\theta^-`, with :math:`e_F` depending
    on which interfaces slip (not on how fast): :math:`e_{sys}` when both stick, less while one
    slips (``docs/theory/impact.rst``); a non-positive :math:`e_F` stops the rocking.

When :math:`|\dot\theta^+|` falls below a threshold the rocking has stopped (the impacts of a
decaying rocking motion accumulate in finite time, Zeno behaviour): :math:`\dot\theta` is set to
zero and the lost kinetic energy is booked as impact loss.

**Jams.** In the Painleve regime (a slipping interface whose friction makes the effective
inertia of the rocking negative) no mode of motion is consistent. The slipping interface then
jams: an impulsive friction force brings it to stick (a tangential impact, Genot and Brogliato
1999; the limit of a velocity-level time-stepping, Stewart 2000). The velocities after the jam
are the projection, in the metric of the kinetic energy, of those before onto the velocities
with the jammed interface (and any sticking one) at rest and the rotation free
(:func:`apply_jam`): the momentum conjugate to :math:`\theta` is conserved (no impulse acts on
it), so is that of an interface that keeps slipping (frictionless impulse), and the energy
lost, :math:`\tfrac12(\dot q^- - \dot q^+)^T K (\dot q^- - \dot q^+) \ge 0`, is booked as impact
loss. See ``docs/theory/transitions.rst``.

References
----------
Genot, F. and Brogliato, B. (1999). New results on Painleve paradoxes. *Eur. J. Mech. A/Solids*
18(4), 653-677.

Stewart, D. E. (2000). Rigid-body dynamics with friction and impact. *SIAM Review* 42(1), 3-39.

Housner, G. W. (1963). The behavior of inverted pendulum structures during earthquakes.
*Bull. Seismol. Soc. Am.* 53(2), 403-417.
"""

from __future__ import annotations

from numba import njit

from shipblock.equations import kinetic_energy, mass_matrix, pivot_geometry
from shipblock.system import P_B, P_E, P_M, P_MUS1, P_MUS2, P_NM, P_R, P_RULE

RULE_MOMENTUM = 0
RULE_PAPER = 1
RULE_PLASTIC = 2


@njit(cache=True)
def project_velocities(K, free_b, free_s, m0, m1, m2, y):
    """Velocities with the given generalised momenta on the free coordinates, the others zero.

    The rotation is free; the block slip (``free_b``) and the ship slip (``free_s``) are free
    or held at zero. Solves :math:`K_{FF}\\dot q_F = m_F` for the free coordinates ``F`` and
    writes ``(v_b, theta_dot, v_s)`` into ``y[3:6]``. With ``m = K qdot^-`` (or that of the
    post-impact coordinates) this is the projection of the velocities, in the metric of the
    kinetic energy, onto those that leave the held interfaces at rest.
    """
    vb = 0.0
    vs = 0.0
    if free_b and free_s:
        # 3 x 3, by Cramer's rule on the symmetric K
        c00 = K[1, 1] * K[2, 2] - K[1, 2] * K[2, 1]
        c01 = K[1, 2] * K[2, 0] - K[1, 0] * K[2, 2]
        c02 = K[1, 0] * K[2, 1] - K[1, 1] * K[2, 0]
        det = K[0, 0] * c00 + K[0, 1] * c01 + K[0, 2] * c02
        vb = (m0 * c00 + m1 * (K[0, 2] * K[2, 1] - K[0, 1] * K[2, 2])
              + m2 * (K[0, 1] * K[1, 2] - K[0, 2] * K[1, 1])) / det
        om = (m0 * c01 + m1 * (K[0, 0] * K[2, 2] - K[0, 2] * K[2, 0])
              + m2 * (K[0, 2] * K[1, 0] - K[0, 0] * K[1, 2])) / det
        vs = (m0 * c02 + m1 * (K[0, 1] * K[2, 0] - K[0, 0] * K[2, 1])
              + m2 * (K[0, 0] * K[1, 1] - K[0, 1] * K[1, 0])) / det
    elif free_b:
        det = K[0, 0] * K[1, 1] - K[0, 1] * K[1, 0]
        vb = (m0 * K[1, 1] - K[0, 1] * m1) / det
        om = (K[0, 0] * m1 - K[1, 0] * m0) / det
    elif free_s:
        det = K[1, 1] * K[2, 2] - K[1, 2] * K[2, 1]
        om = (m1 * K[2, 2] - K[1, 2] * m2) / det
        vs = (K[1, 1] * m2 - K[2, 1] * m1) / det
    else:
        om = m1 / K[1, 1]
    y[3] = vb
    y[4] = om
    y[5] = vs


@njit(cache=True)
def apply_impact(p, slip1, slip2, y, zeno_omega, K):
    """Apply an impact in place to the velocities ``y[3:6]`` (theta must be 0 already).

    Parameters
    ----------
    p : ndarray
        Parameter vector.
    slip1, slip2 : int
        1 when the ground / ship interface slips at the impact.
    y : ndarray
        State ``[x_b, theta, x_s, v_b, omega, v_s, ...]``; velocities are updated.
    zeno_omega : float
        Below this :math:`|\\dot\\theta^+|` [rad/s] rocking stops.
    K : ndarray, shape (3, 3)
        Work array.

    Returns
    -------
    loss : float
        Kinetic energy lost [J] (>= 0 for the momentum and plastic rules).
    stopped : bool
        True when the rocking stopped (Zeno threshold, or a plastic impact that leaves no
        rotation onto the new pivot).
    """
    vb, om, vs = y[3], y[4], y[5]
    t_before = kinetic_energy(p, 0.0, 1.0, 1, vb, om, vs)
    rule = int(p[P_RULE])
    if rule == RULE_PLASTIC:
        mass_matrix(p, 0.0, 1.0, 1, K)
        # momenta of the post-impact coordinates: those of the slips are continuous, that of
        # the rotation loses 2 (nm + 4M) B^2 omega (docs/theory/impact.rst)
        m0 = K[0, 0] * vb + K[0, 1] * om + K[0, 2] * vs
        m1 = (K[1, 0] * vb + K[1, 1] * om + K[1, 2] * vs
              - 2.0 * (p[P_NM] + 4.0 * p[P_M]) * p[P_B] * p[P_B] * om)
        m2 = K[2, 0] * vb + K[2, 1] * om + K[2, 2] * vs
        project_velocities(K, slip1, slip2, m0, m1, m2, y)
        om_new = y[4]
        # rocking on the new pivot needs the rotation to go on in its direction
        stopped = abs(om_new) < zeno_omega or om_new * om <= 0.0
        if not stopped:
            return t_before - kinetic_energy(p, 0.0, 1.0, 1, y[3], om_new, y[5]), False
        om_new = 0.0  # no rocking after it: the slips as for the momentum rule with omega = 0
    else:
        om_new = p[P_E] * om
        stopped = abs(om_new) < zeno_omega
        if stopped:
            om_new = 0.0
    if rule != RULE_PAPER and (slip1 or slip2):
        mass_matrix(p, 0.0, 1.0, 1, K)
        # Conserved momenta of the slipping coordinates, with the new angular velocity.
        r0 = K[0, 0] * vb + K[0, 1] * om + K[0, 2] * vs - K[0, 1] * om_new
        r2 = K[2, 0] * vb + K[2, 1] * om + K[2, 2] * vs - K[2, 1] * om_new
        if slip1 and slip2:
            det = K[0, 0] * K[2, 2] - K[0, 2] * K[2, 0]
            vb = (r0 * K[2, 2] - K[0, 2] * r2) / det
            vs = (K[0, 0] * r2 - K[2, 0] * r0) / det
        elif slip1:
            vb = r0 / K[0, 0]  # the ship sticks: vs stays 0
        else:
            vs = r2 / K[2, 2]  # the blocks stick: vb stays 0
    y[3] = vb
    y[4] = om_new
    y[5] = vs
    t_after = kinetic_energy(p, 0.0, 1.0, 1, vb, om_new, vs)
    return t_before - t_after, stopped


@njit(cache=True)
def apply_jam(p, jam1, jam2, y, K):
    """Jam a slipping interface: an impulsive friction force brings its slip to rest, in place.

    The velocities ``y[3:6]`` become their projection, in the metric of the kinetic energy
    :math:`K(\\theta)`, onto those with the jammed interfaces and every interface already at
    rest held at zero and the rotation free: the momentum conjugate to :math:`\\theta` is
    conserved (the impulses act at the pivot and at the ship contact, on the slip and
    contact coordinates only), and so is that of an interface that keeps slipping
    (frictionless impulse, as for the impacts). The positions do not change.

    The jam is *admissible* when its impulses are those contacts can give: both normal
    impulses press, :math:`(nm+2M)R\\,s\\bar s\\,\\Delta\\dot\\theta \\ge 0` at the pivot and
    :math:`2MR\\,s\\bar s\\,\\Delta\\dot\\theta \\ge 0` at the ship (``s`` the pivot side, that of
    the rotation after the jam at :math:`\\theta = 0`), and the friction impulse of every
    jammed or held interface lies inside its static cone, :math:`|\\Lambda_t| \\le \\mu_s
    \\Lambda_n`, with :math:`\\Lambda = K\\Delta\\dot q`.

    Parameters
    ----------
    p : ndarray or tuple
        Parameter vector.
    jam1, jam2 : bool
        Jam the block slip on the ground / the ship slip on the blocks.
    y : ndarray
        State ``[x_b, theta, x_s, v_b, omega, v_s, ...]``; velocities are updated.
    K : ndarray, shape (3, 3)
        Work array.

    Returns
    -------
    loss : float
        Kinetic energy lost [J], :math:`\\tfrac12(\\dot q^- - \\dot q^+)^T K(\\dot q^- - \\dot q^+)
        \\ge 0`.
    admissible : bool
        Whether the impulses are admissible (above).
    """
    th, vb, om, vs = y[1], y[3], y[4], y[5]
    s = 1.0 if th >= 0.0 else -1.0
    mass_matrix(p, th, s, 1, K)
    m0 = K[0, 0] * vb + K[0, 1] * om + K[0, 2] * vs
    m1 = K[1, 0] * vb + K[1, 1] * om + K[1, 2] * vs
    m2 = K[2, 0] * vb + K[2, 1] * om + K[2, 2] * vs
    held1 = vb == 0.0 or jam1
    held2 = vs == 0.0 or jam2
    project_velocities(K, not held1, not held2, m0, m1, m2, y)
    d0, d1, d2 = y[3] - vb, y[4] - om, y[5] - vs
    # impulses: generalised (on the slips) and normal (pivot, ship contact), per unit mass ratio
    if th == 0.0:
        s = 1.0 if y[4] >= 0.0 else -1.0
    rsn = p[P_R] * pivot_geometry(p, th, s, 1)[1]
    press = s * rsn * d1  # the normal impulses are (nm + 2M) press and 2M press
    ok = press >= 0.0
    lt1 = K[0, 0] * d0 + K[0, 1] * d1 + K[0, 2] * d2
    lt2 = K[2, 0] * d0 + K[2, 1] * d1 + K[2, 2] * d2
    if held1 and abs(lt1) > p[P_MUS1] * (p[P_NM] + 2.0 * p[P_M]) * press * (1.0 + 1e-12):
        ok = False
    if held2 and abs(lt2) > p[P_MUS2] * 2.0 * p[P_M] * press * (1.0 + 1e-12):
        ok = False
    loss = 0.5 * (lt1 * d0 + (K[1, 0] * d0 + K[1, 1] * d1 + K[1, 2] * d2) * d1 + lt2 * d2)
    return loss, ok


def impact_velocities(system, theta_dot, v_block=0.0, v_ship=0.0, zeno_omega=0.0):
    """Velocities just after an impact (Python convenience wrapper of :func:`apply_impact`).

    Parameters
    ----------
    system : ShipBlockSystem
        The system (its restitution and impact rule are used).
    theta_dot : float
        Angular velocity just before the impact [rad/s].
    v_block, v_ship : float
        Slip velocities just before the impact [m/s]; a nonzero value means that interface slips.
    zeno_omega : float
        Rocking-stop threshold [rad/s].

    Returns
    -------
    tuple of float
        ``(v_block, theta_dot, v_ship, energy_loss)`` after the impact [m/s, rad/s, m/s, J].
    """
    import numpy as np

    p = system.to_parameter_vector()
    y = np.array([0.0, 0.0, 0.0, v_block, theta_dot, v_ship, 0.0, 0.0])
    loss, _ = apply_impact(
        p, int(v_block != 0.0), int(v_ship != 0.0), y, zeno_omega, np.empty((3, 3))
    )
    return float(y[3]), float(y[4]), float(y[5]), float(loss)


def jam_velocities(system, theta, theta_dot, v_block=0.0, v_ship=0.0, ground=True, ship=False):
    """Velocities just after a jam (Python convenience wrapper of :func:`apply_jam`).

    Parameters
    ----------
    system : ShipBlockSystem
        The system.
    theta, theta_dot : float
        Rotation [rad] and angular velocity [rad/s] at the jam.
    v_block, v_ship : float
        Slip velocities before the jam [m/s]; zero means that interface sticks.
    ground, ship : bool
        Which slipping interfaces jam (the blocks on the ground, the ship on the blocks).

    Returns
    -------
    tuple
        ``(v_block, theta_dot, v_ship, energy_loss, admissible)`` after the jam [m/s, rad/s,
        m/s, J, bool]; see :func:`apply_jam`.
    """
    import numpy as np

    p = system.to_parameter_vector()
    y = np.array([0.0, theta, 0.0, v_block, theta_dot, v_ship, 0.0, 0.0])
    loss, ok = apply_jam(p, bool(ground), bool(ship), y, np.empty((3, 3)))
    return float(y[3]), float(y[4]), float(y[5]), float(loss), bool(ok)


__all__ = ["apply_impact", "apply_jam", "impact_velocities", "jam_velocities", "RULE_MOMENTUM",
           "RULE_PAPER", "RULE_PLASTIC"]
