"""Impact at the end of a rocking half-cycle (theta = 0, pivot changes).

At :math:`\\theta = 0` the pivot jumps from the bottom corner :math:`(-sB, -H)` to
:math:`(sB, -H)` and the ship drops from one top corner onto the other. The duration of the
impact is neglected.

Two rules are available:

``"momentum"`` (default)
    :math:`\\dot\\theta^+ = e\\,\\dot\\theta^-`; impulses at interfaces that are slipping at the
    impact are frictionless, so the generalised momenta :math:`p_j = K_j\\cdot\\dot q` conjugate
    to the slipping coordinates are conserved (total horizontal momentum when the blocks slip on
    the ground, the ship's when the ship slips). With the Routhian split
    :math:`T = \\tfrac12 p_S^T K_{SS}^{-1} p_S + \\tfrac12 K_{eff}\\dot\\theta^2` an impact then never
    creates kinetic energy for :math:`0 \\le e \\le 1`.
``"paper"``
    :math:`\\dot\\theta^+ = e\\,\\dot\\theta^-` with the slip velocities unchanged (the paper's
    Sect. 4, read with :math:`e` instead of the printed :math:`2e`, see the errata). Exact when
    both interfaces stick; otherwise it can create energy.

When :math:`|\\dot\\theta^+|` falls below a threshold the rocking has stopped (the impacts of a
decaying rocking motion accumulate in finite time, Zeno behaviour): :math:`\\dot\\theta` is set to
zero and the lost kinetic energy is booked as impact loss.
"""

from __future__ import annotations

from numba import njit

from shipblock.equations import kinetic_energy, mass_matrix
from shipblock.system import P_E, P_RULE

RULE_MOMENTUM = 0
RULE_PAPER = 1


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
        Kinetic energy lost [J] (>= 0 for the momentum rule).
    stopped : bool
        True when the rocking stopped (Zeno threshold).
    """
    vb, om, vs = y[3], y[4], y[5]
    t_before = kinetic_energy(p, 0.0, 1.0, 1, vb, om, vs)
    om_new = p[P_E] * om
    stopped = abs(om_new) < zeno_omega
    if stopped:
        om_new = 0.0
    if int(p[P_RULE]) == RULE_MOMENTUM and (slip1 or slip2):
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


__all__ = ["apply_impact", "impact_velocities", "RULE_MOMENTUM", "RULE_PAPER"]
