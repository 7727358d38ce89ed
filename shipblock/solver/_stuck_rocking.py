"""Dormand-Prince step of the rocking mode on two stuck interfaces (mode 3), in scalars.

The usual rocking mode (blocks rocking, neither interface slipping) has two moving states,
theta and theta_dot, and one accumulating one, the input work. Its equation is the pendulum
form of :func:`~shipblock.equations.stuck_rocking_rates`. This module takes the same
Dormand-Prince 5(4) step as the general one (:func:`~shipblock.solver._kernel.advance`, same
tableau, same error norm), but on those three states only, with the stages in registers
instead of a 7 x 9 array, and with the pivot geometry of each stage obtained from the step's
start by the angle-addition formulas (one sine and cosine per step instead of one per stage):

.. math::

    \\cos(\\varphi_0 - s\\delta) = \\cos\\varphi_0\\cos\\delta + s\\sin\\varphi_0\\sin\\delta,
    \\qquad
    \\sin(\\varphi_0 - s\\delta) = \\sin\\varphi_0\\cos\\delta - s\\cos\\varphi_0\\sin\\delta,

where :math:`\\delta = \\theta - \\theta_0` is the stage's rotation within the step, small
enough for short Taylor series (:func:`small_angle_sincos`). The results equal the general
step's to rounding (tests/test_stuck_rocking.py).
"""

from __future__ import annotations

import math

from numba import njit

from shipblock.equations import (
    I_FX,
    I_FY,
    I_SFX,
    I_SFY,
    I_TH_DD,
    I_XB_DD,
    I_XS_DD,
    stuck_rocking_forces,
    stuck_rocking_gain,
    stuck_rocking_rates,
)
from shipblock.solver._dopri import DP_A, DP_C, DP_E
from shipblock.solver._layout import (
    MS_S,
    N_DYN,
    N_STATE,
    Y_DIS,
    Y_IMP,
    Y_OM,
    Y_TH,
    Y_VB,
    Y_VS,
    Y_WIN,
    Y_XB,
    Y_XS,
)
from shipblock.system import P_G, P_THC

#: Largest |delta| [rad] for the series of :func:`small_angle_sincos` (truncation below 1e-17
#: relative); beyond it the stage takes its own sine and cosine.
SMALL_ANGLE = 0.25

# The tableau as scalars (numba freezes module floats into the machine code).
A21 = float(DP_A[1, 0])
A31, A32 = float(DP_A[2, 0]), float(DP_A[2, 1])
A41, A42, A43 = float(DP_A[3, 0]), float(DP_A[3, 1]), float(DP_A[3, 2])
A51, A52, A53, A54 = (float(DP_A[4, j]) for j in range(4))
A61, A62, A63, A64, A65 = (float(DP_A[5, j]) for j in range(5))
B1, B3, B4, B5, B6 = (float(DP_A[6, j]) for j in (0, 2, 3, 4, 5))  # DP_A[6, 1] == 0
C2, C3, C4, C5 = (float(DP_C[j]) for j in (1, 2, 3, 4))
E1, E3, E4, E5, E6, E7 = (float(DP_E[j]) for j in (0, 2, 3, 4, 5, 6))  # DP_E[1] == 0


@njit(cache=True, inline="always")
def small_angle_sincos(d):
    """``(sin d, cos d)`` by their Taylor series, for ``|d| <= SMALL_ANGLE``."""
    d2 = d * d
    sn = d * (1.0 + d2 * (-1.0 / 6.0 + d2 * (1.0 / 120.0 + d2 * (
        -1.0 / 5040.0 + d2 * (1.0 / 362880.0 - d2 * (1.0 / 39916800.0))))))
    cs = 1.0 + d2 * (-0.5 + d2 * (1.0 / 24.0 + d2 * (-1.0 / 720.0 + d2 * (
        1.0 / 40320.0 + d2 * (-1.0 / 3628800.0 + d2 * (1.0 / 479001600.0))))))
    return sn, cs


@njit(cache=True, inline="always")
def _rates(p, gain, s, th0, c0, s0, d, om, a, ay):
    """Stage rates (theta_dd, power) at theta0 + d; also the geometry ``(c, sn)`` there."""
    if abs(d) <= SMALL_ANGLE:
        sd, cd = small_angle_sincos(d)
        c = c0 * cd + s * s0 * sd
        sn = s0 * cd - s * c0 * sd
    else:
        phi = p[P_THC] - s * (th0 + d)
        c = math.cos(phi)
        sn = math.sin(phi)
    al, pw = stuck_rocking_rates(p, gain, c, sn, s, om, a, ay)
    return al, pw, c, sn


@njit(cache=True, inline="always")
def advance_stuck(p, ms, y0, k, tau, h, dt, ax, ay, has_ay, sh, sv, y1, stages, w7,
                  first_stage_known, rtol, atol):
    """One Dormand-Prince 5(4) step of ``h`` in mode 3: the error norm (>= 0).

    The contract of :func:`~shipblock.solver._kernel.advance`: ``y1`` gets the 5th-order
    solution, ``stages[0]`` (if not known) and ``stages[6]`` the rates at both ends (the other
    stages are not stored), ``w7`` the accelerations and forces at the end of the step.
    Requires no slip velocities in ``y0`` (mode 3 keeps them zero).
    """
    s = float(ms[MS_S])
    gain = stuck_rocking_gain(p)
    a0 = sh * ax[k]
    a1 = sh * ax[k + 1]
    b0 = sv * ay[k] if has_ay else 0.0
    b1 = sv * ay[k + 1] if has_ay else 0.0
    da = a1 - a0
    db = b1 - b0
    th0 = y0[Y_TH]
    om0 = y0[Y_OM]
    phi0 = p[P_THC] - s * th0
    c0 = math.cos(phi0)
    s0 = math.sin(phi0)
    if first_stage_known:
        al1 = stages[0, Y_OM]
        pw1 = stages[0, Y_WIN]
    else:
        f = tau / dt
        al1, pw1 = stuck_rocking_rates(p, gain, c0, s0, s, om0, a0 + da * f, b0 + db * f)
        for i in range(N_STATE):
            stages[0, i] = 0.0
        stages[0, Y_XB] = y0[Y_VB]
        stages[0, Y_TH] = om0
        stages[0, Y_XS] = y0[Y_VS]
        stages[0, Y_OM] = al1
        stages[0, Y_WIN] = pw1
    om1 = om0
    # stage 2
    f = (tau + C2 * h) / dt
    om2 = om0 + h * (A21 * al1)
    al2, pw2, _, _ = _rates(p, gain, s, th0, c0, s0, h * (A21 * om1), om2,
                            a0 + da * f, b0 + db * f)
    # stage 3
    f = (tau + C3 * h) / dt
    om3 = om0 + h * (A31 * al1 + A32 * al2)
    al3, pw3, _, _ = _rates(p, gain, s, th0, c0, s0, h * (A31 * om1 + A32 * om2), om3,
                            a0 + da * f, b0 + db * f)
    # stage 4
    f = (tau + C4 * h) / dt
    om4 = om0 + h * (A41 * al1 + A42 * al2 + A43 * al3)
    al4, pw4, _, _ = _rates(p, gain, s, th0, c0, s0, h * (A41 * om1 + A42 * om2 + A43 * om3),
                            om4, a0 + da * f, b0 + db * f)
    # stage 5
    f = (tau + C5 * h) / dt
    om5 = om0 + h * (A51 * al1 + A52 * al2 + A53 * al3 + A54 * al4)
    al5, pw5, _, _ = _rates(p, gain, s, th0, c0, s0,
                            h * (A51 * om1 + A52 * om2 + A53 * om3 + A54 * om4), om5,
                            a0 + da * f, b0 + db * f)
    # stage 6 (at the end of the step)
    f = (tau + h) / dt
    om6 = om0 + h * (A61 * al1 + A62 * al2 + A63 * al3 + A64 * al4 + A65 * al5)
    al6, pw6, _, _ = _rates(p, gain, s, th0, c0, s0,
                            h * (A61 * om1 + A62 * om2 + A63 * om3 + A64 * om4 + A65 * om5),
                            om6, a0 + da * f, b0 + db * f)
    # the 5th-order solution, and the rates there (first same as last)
    d7 = h * (B1 * om1 + B3 * om3 + B4 * om4 + B5 * om5 + B6 * om6)
    om7 = om0 + h * (B1 * al1 + B3 * al3 + B4 * al4 + B5 * al5 + B6 * al6)
    w7_work = y0[Y_WIN] + h * (B1 * pw1 + B3 * pw3 + B4 * pw4 + B5 * pw5 + B6 * pw6)
    a_end = a0 + da * f
    b_end = b0 + db * f
    al7, pw7, c7, sn7 = _rates(p, gain, s, th0, c0, s0, d7, om7, a_end, b_end)
    for i in range(N_STATE):
        y1[i] = y0[i]
        stages[6, i] = 0.0
    y1[Y_TH] = th0 + d7
    y1[Y_OM] = om7
    y1[Y_WIN] = w7_work
    stages[6, Y_XB] = y0[Y_VB]
    stages[6, Y_TH] = om7
    stages[6, Y_XS] = y0[Y_VS]
    stages[6, Y_OM] = al7
    stages[6, Y_WIN] = pw7
    stages[6, Y_DIS] = 0.0
    stages[6, Y_IMP] = 0.0
    # accelerations and forces at the end of the step, for the event functions
    fx, fy, Fx, Fy = stuck_rocking_forces(p, c7, sn7, s, om7, al7, a_end, p[P_G] + b_end)
    w7[I_XB_DD] = 0.0
    w7[I_TH_DD] = al7
    w7[I_XS_DD] = 0.0
    w7[I_FX] = fx
    w7[I_FY] = fy
    w7[I_SFX] = Fx
    w7[I_SFY] = Fy
    # the embedded error estimate (the other dynamic states have none: their rates are zero)
    e_th = h * (E1 * om1 + E3 * om3 + E4 * om4 + E5 * om5 + E6 * om6 + E7 * om7)
    e_om = h * (E1 * al1 + E3 * al3 + E4 * al4 + E5 * al5 + E6 * al6 + E7 * al7)
    sc_th = atol + rtol * max(abs(th0), abs(y1[Y_TH]))
    sc_om = atol + rtol * max(abs(om0), abs(om7))
    return math.sqrt(((e_th / sc_th) ** 2 + (e_om / sc_om) ** 2) / N_DYN)
