"""General equations of motion and interface forces of the ship-block system.

All eight modes come from one set of equations. With the generalised accelerations
:math:`u = (\\ddot x_b, \\ddot\\theta, \\ddot x_s)`, pivot sign :math:`s = \\operatorname{sign}\\theta`,
:math:`\\varphi = \\theta_c - s\\theta`, :math:`c = \\cos\\varphi`, :math:`\\bar s = \\sin\\varphi`,
:math:`a = \\ddot x_g` and :math:`G = g + \\ddot y_g`, the rocking parts of the block-centroid
acceleration are

.. math::

    X' = -R(c\\,\\ddot\\theta + s\\bar s\\,\\dot\\theta^2), \\qquad
    Y' = R(s\\bar s\\,\\ddot\\theta - c\\,\\dot\\theta^2)

(the ship's are :math:`2X'` and :math:`2Y'`). Newton's equations of the ship and of the
blocks give the interface forces, affine in :math:`u`:

.. math::

    F_x &= M(a + \\ddot x_b + \\ddot x_s + 2X'), & F_y &= M(G + 2Y'), \\\\
    f_x &= nm(a + \\ddot x_b + X') + F_x, & f_y &= nm(G + Y') + F_y,

where :math:`(F_x, F_y)` is the force on the ship from the blocks and :math:`(f_x, f_y)` the
force on the blocks from the ground. Three more rows close the system, each chosen by the
state of one interface:

.. math::

    \\text{ground:}\\quad & \\ddot x_b = 0 \\;\\text{(stick)} \\quad\\text{or}\\quad
        f_x + \\sigma_1\\mu_{k1} f_y = 0 \\;\\text{(slip)} \\\\
    \\text{blocks:}\\quad & \\ddot\\theta = 0 \\;\\text{(at rest)} \\quad\\text{or}\\quad
        nI\\ddot\\theta = Rc(f_x + F_x) - sR\\bar s(f_y + F_y) \\;\\text{(rocking)} \\\\
    \\text{ship:}\\quad & \\ddot x_s = 0 \\;\\text{(stick)} \\quad\\text{or}\\quad
        F_x + \\sigma_2\\mu_{k2} F_y = 0 \\;\\text{(slip)}

This is the 7x7 linear system of the physics notes with the four force rows substituted:
a 3x3 system in :math:`u`, solved here by Cramer's rule. See ``docs/theory`` for the
derivation, the closed forms per mode and the errata against the paper.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from shipblock.errors import ParameterError
from shipblock.modes import MODE_FLAGS
from shipblock.system import (
    P_B,
    P_G,
    P_H,
    P_M,
    P_MUK1,
    P_MUK2,
    P_NI,
    P_NM,
    P_R,
    P_THC,
)

# Layout of the output vector of solve_mode.
I_XB_DD, I_TH_DD, I_XS_DD, I_FX, I_FY, I_SFX, I_SFY = 0, 1, 2, 3, 4, 5, 6
N_SOLVE_OUT = 7

#: A 3x3 determinant below this fraction of the product of its rows' largest entries is singular.
SINGULAR_RELATIVE = 1e-12


@njit(cache=True, inline="always")
def pivot_geometry(p, theta, s, rock):
    """Return ``(c, sn)`` = (cos phi, sin phi) with phi = theta_c - s*theta.

    At rest, or rocking at theta = 0 (just after an impact), the geometry is ``R c = H`` and
    ``R sn = B`` (no cosine and sine to take).
    """
    if rock and theta != 0.0:
        phi = p[P_THC] - s * theta
        return math.cos(phi), math.sin(phi)
    return p[P_H] / p[P_R], p[P_B] / p[P_R]


# without reference counting (it neither allocates nor returns arrays): the counts of ``out``
# would otherwise be updated, atomically, at every evaluation of the equations
@njit(cache=True, _nrt=False)
def solve_mode(p, slip1, rock, slip2, s, sig1, sig2, theta, omega, a, G, out):
    """Accelerations and interface forces in the mode given by three interface flags.

    Parameters
    ----------
    p : ndarray
        Parameter vector (:meth:`ShipBlockSystem.to_parameter_vector`).
    slip1, rock, slip2 : int
        1 when the blocks slide on the ground / rock / the ship slides on the blocks.
    s, sig1, sig2 : float
        Pivot sign (+1: pivot on the bottom-left corner) and slip directions
        :math:`\\sigma_1 = \\operatorname{sign}\\dot x_b`, :math:`\\sigma_2 = \\operatorname{sign}\\dot x_s`.
    theta, omega : float
        Block rotation [rad] and angular velocity [rad/s].
    a, G : float
        Horizontal ground acceleration [m/s^2] and :math:`G = g + \\ddot y_g` [m/s^2].
    out : ndarray, shape (7,)
        Receives ``[xb_dd, theta_dd, xs_dd, fx, fy, Fx, Fy]`` (SI units).

    Returns
    -------
    bool
        False when the 3x3 system is singular (no unique motion in that mode).
    """
    c, sn = pivot_geometry(p, theta, s, rock)
    return solve_mode_at(p, slip1, rock, slip2, s, sig1, sig2, c, sn, omega, a, G, out)


# not inlined: inlining it into the rocking step's call sites gained about 4 % of rocking speed
# for about 10 s more compilation on every new installation
@njit(cache=True, _nrt=False)
def solve_mode_at(p, slip1, rock, slip2, s, sig1, sig2, c, sn, omega, a, G, out):
    """:func:`solve_mode` with the pivot geometry ``(c, sn)`` of :func:`pivot_geometry` given.

    For callers that need the geometry for more than the equations (the rocking right-hand
    side also takes the input power), so that its cosine and sine are taken once.
    """
    M = p[P_M]
    nm = p[P_NM]
    R = p[P_R]
    w2 = omega * omega
    Rc = R * c
    Rss = R * s * sn
    # Forces as F0 + J . u, u = (xb_dd, th_dd, xs_dd).
    Fx0 = M * (a - 2.0 * Rss * w2)
    Fxb = M
    Fxt = -2.0 * M * Rc
    Fxs = M
    Fy0 = M * (G - 2.0 * Rc * w2)
    Fyt = 2.0 * M * Rss
    fx0 = nm * (a - Rss * w2) + Fx0
    fxb = nm + M
    fxt = -nm * Rc + Fxt
    fxs = M
    fy0 = nm * (G - Rc * w2) + Fy0
    fyt = nm * Rss + Fyt
    # Row 1: rocking moment about the block centroid.
    if rock:
        a10 = -Rc * (fxb + Fxb)
        a11 = p[P_NI] - Rc * (fxt + Fxt) + Rss * (fyt + Fyt)
        a12 = -Rc * (fxs + Fxs)
        b1 = Rc * (fx0 + Fx0) - Rss * (fy0 + Fy0)
        if not slip1 and not slip2:
            # Rocking on two stuck interfaces, the common rocking mode: rows 0 and 2 are unit
            # rows, and Cramer's rule reduces to u1 = b1 / a11 with the same singularity test
            # (det = a11, scale = the largest entry of row 1). The terms skipped are products
            # with exact zeros, so the results equal those of the general solve.
            if not abs(a11) > SINGULAR_RELATIVE * max(abs(a10), abs(a11), abs(a12)):
                for i in range(N_SOLVE_OUT):
                    out[i] = np.nan
                return False
            u1 = b1 / a11
            out[I_XB_DD] = 0.0
            out[I_TH_DD] = u1
            out[I_XS_DD] = 0.0
            out[I_FX] = fx0 + fxt * u1
            out[I_FY] = fy0 + fyt * u1
            out[I_SFX] = Fx0 + Fxt * u1
            out[I_SFY] = Fy0 + Fyt * u1
            return True
    else:
        a10, a11, a12, b1 = 0.0, 1.0, 0.0, 0.0
    # Row 0: ground interface.
    if slip1:
        mu = sig1 * p[P_MUK1]
        a00, a01, a02, b0 = fxb, fxt + mu * fyt, fxs, -(fx0 + mu * fy0)
    else:
        a00, a01, a02, b0 = 1.0, 0.0, 0.0, 0.0
    # Row 2: ship interface.
    if slip2:
        mu = sig2 * p[P_MUK2]
        a20, a21, a22, b2 = Fxb, Fxt + mu * Fyt, Fxs, -(Fx0 + mu * Fy0)
    else:
        a20, a21, a22, b2 = 0.0, 0.0, 1.0, 0.0
    c0 = a11 * a22 - a12 * a21
    c1 = a12 * a20 - a10 * a22
    c2 = a10 * a21 - a11 * a20
    det = a00 * c0 + a01 * c1 + a02 * c2
    scale = (
        max(abs(a00), abs(a01), abs(a02))
        * max(abs(a10), abs(a11), abs(a12))
        * max(abs(a20), abs(a21), abs(a22))
    )
    if not abs(det) > SINGULAR_RELATIVE * scale:
        for i in range(N_SOLVE_OUT):
            out[i] = np.nan
        return False
    u0 = (b0 * c0 + b1 * (a02 * a21 - a01 * a22) + b2 * (a01 * a12 - a02 * a11)) / det
    u1 = (b0 * c1 + b1 * (a00 * a22 - a02 * a20) + b2 * (a02 * a10 - a00 * a12)) / det
    u2 = (b0 * c2 + b1 * (a01 * a20 - a00 * a21) + b2 * (a00 * a11 - a01 * a10)) / det
    out[I_XB_DD] = u0
    out[I_TH_DD] = u1
    out[I_XS_DD] = u2
    out[I_FX] = fx0 + fxb * u0 + fxt * u1 + fxs * u2
    out[I_FY] = fy0 + fyt * u1
    out[I_SFX] = Fx0 + Fxb * u0 + Fxt * u1 + Fxs * u2
    out[I_SFY] = Fy0 + Fyt * u1
    return True


@njit(cache=True, inline="always")
def stuck_rocking_gain(p):
    """:math:`(nm + 2M)R / (nI + (nm + 4M)R^2)` [1/m] of :func:`stuck_rocking_rates`."""
    R = p[P_R]
    return (p[P_NM] + 2.0 * p[P_M]) * R / (p[P_NI] + (p[P_NM] + 4.0 * p[P_M]) * R * R)


@njit(cache=True, inline="always")
def stuck_rocking_rates(p, gain, c, sn, s, omega, a, ay):
    """Angular acceleration and input power of the rocking mode on two stuck interfaces.

    With :math:`\\ddot x_b = \\ddot x_s = 0` (and no slip velocities) row 1 of
    :func:`solve_mode` reduces to a pendulum equation: the centripetal terms cancel between the
    two force rows and :math:`c^2 + \\bar s^2 = 1` leaves a constant inertia,

    .. math::

        \\ddot\\theta = \\frac{(nm + 2M)R}{nI + (nm + 4M)R^2}\\,(c\\,a - s\\bar s\\,G),
        \\qquad
        P = (nm + 2M)R\\,\\dot\\theta\\,(c\\,a - s\\bar s\\,\\ddot y_g),

    with :math:`G = g + \\ddot y_g`; :math:`P` is :func:`input_power_at` with no slip
    velocities. For a single block (:math:`M = 0`, :math:`n = 1`) this is Housner's
    :math:`I_O\\ddot\\theta = -mR(g\\sin(\\theta_c - \\theta) - \\ddot x_g \\cos(\\theta_c - \\theta))`
    for :math:`\\theta > 0` in this sign convention (positive ground acceleration tips the
    block about its left corner). The rocking steps of the solver evaluate the mode through this
    form (about a fifth of the general solve's arithmetic); ``tests/test_equations.py`` checks
    it symbolically and numerically against the general solve.

    Parameters
    ----------
    p : ndarray or tuple
        Parameter vector.
    gain : float
        :func:`stuck_rocking_gain` of ``p`` [1/m].
    c, sn : float
        :func:`pivot_geometry` at the rotation (cos and sin of theta_c - s theta).
    s : float
        Pivot sign.
    omega : float
        Angular velocity [rad/s].
    a, ay : float
        Horizontal and vertical ground acceleration [m/s^2].

    Returns
    -------
    theta_dd : float
        Angular acceleration [rad/s^2].
    power : float
        Input power of the ground motion [W].
    """
    ssn = s * sn
    theta_dd = gain * (c * a - ssn * (p[P_G] + ay))
    power = (p[P_NM] + 2.0 * p[P_M]) * p[P_R] * omega * (c * a - ssn * ay)
    return theta_dd, power


@njit(cache=True, inline="always")
def stuck_rocking_forces(p, c, sn, s, omega, theta_dd, a, G):
    """Interface forces ``(fx, fy, Fx, Fy)`` [N] of the rocking mode on two stuck interfaces.

    The force rows of :func:`solve_mode` with :math:`\\ddot x_b = \\ddot x_s = 0`:
    :math:`F_x = M(a + 2X')`, :math:`F_y = M(G + 2Y')`, :math:`f_x = nm(a + X') + F_x`,
    :math:`f_y = nm(G + Y') + F_y`, with ``theta_dd`` from :func:`stuck_rocking_rates`.
    """
    Rc = p[P_R] * c
    Rss = p[P_R] * s * sn
    w2 = omega * omega
    xp = -(Rc * theta_dd + Rss * w2)
    yp = Rss * theta_dd - Rc * w2
    Fx = p[P_M] * (a + 2.0 * xp)
    Fy = p[P_M] * (G + 2.0 * yp)
    return p[P_NM] * (a + xp) + Fx, p[P_NM] * (G + yp) + Fy, Fx, Fy


@njit(cache=True)
def mass_matrix(p, theta, s, rock, K):
    """Fill ``K`` (3x3) with the kinetic-energy matrix, T = 1/2 qdot^T K qdot.

    .. math::

        K = \\begin{bmatrix} nm+M & -(nm+2M)Rc & M \\\\ -(nm+2M)Rc & nI+(nm+4M)R^2 & -2MRc \\\\
            M & -2MRc & M \\end{bmatrix}
    """
    M = p[P_M]
    nm = p[P_NM]
    R = p[P_R]
    c, sn = pivot_geometry(p, theta, s, rock)
    Rc = R * c
    K[0, 0] = nm + M
    K[0, 1] = -(nm + 2.0 * M) * Rc
    K[0, 2] = M
    K[1, 0] = K[0, 1]
    K[1, 1] = p[P_NI] + (nm + 4.0 * M) * R * R
    K[1, 2] = -2.0 * M * Rc
    K[2, 0] = M
    K[2, 1] = K[1, 2]
    K[2, 2] = M


@njit(cache=True)
def kinetic_energy(p, theta, s, rock, vb, om, vs):
    """Kinetic energy relative to the ground [J]."""
    M = p[P_M]
    nm = p[P_NM]
    R = p[P_R]
    c, sn = pivot_geometry(p, theta, s, rock)
    Rc = R * c
    return 0.5 * (
        (nm + M) * vb * vb
        + (p[P_NI] + (nm + 4.0 * M) * R * R) * om * om
        + M * vs * vs
        - 2.0 * (nm + 2.0 * M) * Rc * vb * om
        + 2.0 * M * vb * vs
        - 4.0 * M * Rc * om * vs
    )


@njit(cache=True)
def potential_energy(p, theta):
    r"""Gravity potential energy above the rest position [J].

    :math:`(nm+2M)\,gR\,(\cos\varphi - \cos\theta_c)` with :math:`\varphi = \theta_c - |\theta|`,
    evaluated as :math:`2\sin(\theta_c - |\theta|/2)\sin(|\theta|/2)`: the difference of
    cosines loses the relative precision of a small rotation (all of it below about 1e-16 rad,
    where a brief uplift's input work is already stored: the energy balance of such a run
    failed by 100 %).
    """
    t = abs(theta)
    lift = 2.0 * math.sin(p[P_THC] - 0.5 * t) * math.sin(0.5 * t)
    return (p[P_NM] + 2.0 * p[P_M]) * p[P_G] * p[P_R] * lift


@njit(cache=True, inline="always")
def input_power(p, theta, s, rock, vb, om, vs, a, ay):
    """Power of the inertial forces of the ground motion, -a P_x - ay P_y [W].

    :math:`P_x = nm(\\dot x_b - Rc\\dot\\theta) + M(\\dot x_b - 2Rc\\dot\\theta + \\dot x_s)` and
    :math:`P_y = (nm+2M)sR\\bar s\\,\\dot\\theta` are the momenta relative to the ground.
    """
    c, sn = pivot_geometry(p, theta, s, rock)
    return input_power_at(p, c, sn, s, vb, om, vs, a, ay)


@njit(cache=True, inline="always")
def input_power_at(p, c, sn, s, vb, om, vs, a, ay):
    """:func:`input_power` with the pivot geometry ``(c, sn)`` of :func:`pivot_geometry` given."""
    M = p[P_M]
    nm = p[P_NM]
    R = p[P_R]
    px = nm * (vb - R * c * om) + M * (vb - 2.0 * R * c * om + vs)
    py = (nm + 2.0 * M) * s * R * sn * om
    return -a * px - ay * py


def mode_response(system, mode, theta, theta_dot, ax, ay, s=1, sigma_ground=1, sigma_ship=1):
    """Accelerations and interface forces of one mode at one instant.

    Parameters
    ----------
    system : ShipBlockSystem
        The system.
    mode : int
        Mode number 1..8 (paper numbering, see :class:`shipblock.modes.Mode`).
    theta, theta_dot : float
        Block rotation [rad] and angular velocity [rad/s] (ignored unless the mode rocks).
    ax, ay : float
        Horizontal and vertical ground acceleration [m/s^2].
    s : {1, -1}
        Pivot sign when the mode rocks (+1: pivot on the bottom-left corner, theta >= 0).
    sigma_ground, sigma_ship : {1, -1}
        Slip directions of the blocks on the ground and of the ship on the blocks.

    Returns
    -------
    acc : ndarray, shape (3,)
        :math:`(\\ddot x_b, \\ddot\\theta, \\ddot x_s)` [m/s^2, rad/s^2, m/s^2].
    forces : ndarray, shape (4,)
        :math:`(f_x, f_y, F_x, F_y)` [N]: ground on blocks, blocks on ship (totals over n blocks).

    Raises
    ------
    ValueError
        For a mode outside 1..8 or a mode whose equations are singular at this state.
    """
    if int(mode) != mode or not 1 <= mode <= 8:
        raise ParameterError(f"mode must be an integer 1..8, got {mode!r}")
    flags = MODE_FLAGS[int(mode)]
    p = system.to_parameter_vector()
    out = np.empty(N_SOLVE_OUT)
    rock = int(flags[1])
    th = float(theta) if rock else 0.0
    om = float(theta_dot) if rock else 0.0
    ok = solve_mode(
        p, int(flags[0]), rock, int(flags[2]), float(s), float(sigma_ground), float(sigma_ship),
        th, om, float(ax), p[P_G] + float(ay), out,
    )
    if not ok:
        raise ParameterError(f"the equations of mode {mode} are singular at this state")
    return out[:3].copy(), out[3:].copy()
