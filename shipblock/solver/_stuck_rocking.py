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

The span of whole samples (:func:`stuck_rocking_span`) steps with :func:`rotating_step`
instead, the same tableau on the geometry integrated as two more states, which halves the
chain of dependent operations per stage; it agrees with the angle form to truncation error.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from shipblock.equations import (
    I_FX,
    I_FY,
    I_SFX,
    I_SFY,
    I_TH_DD,
    I_XB_DD,
    I_XS_DD,
    pivot_geometry,
    stuck_rocking_forces,
    stuck_rocking_gain,
    stuck_rocking_rates,
)
from shipblock.solver._dopri import DP_A, DP_C, DP_E
from shipblock.solver._events import (
    event_functions,
    held_margin,
    impact_return_time,
    rearm,
    stuck_rocking_clear,
)
from shipblock.solver._fused import fma
from shipblock.solver._history import store_sample
from shipblock.solver._interpolate import (
    bracketed_root,
    dip_possible,
    quintic_hermite,
    rotation_dip,
    rotation_peak,
)
from shipblock.solver._layout import (
    EV_IMPACT,
    MS_ROCK,
    MS_S,
    MS_SLIP1,
    MS_SLIP2,
    N_DYN,
    N_EVENTS,
    N_STATE,
    ROOT_TIME_TOL,
    S_MARGIN,
    Y_OM,
    Y_TH,
    Y_VB,
    Y_VS,
    Y_WIN,
    Y_XB,
    Y_XS,
)
from shipblock.solver._force_sampling import note_loads
from shipblock.system import P_B, P_G, P_H, P_M, P_MUS1, P_MUS2, P_NM, P_R

#: Largest |delta| [rad] for the series of :func:`small_angle_sincos` (truncation below 1e-17
#: relative); beyond it the stage takes its own sine and cosine.
SMALL_ANGLE = 0.25

#: Newton iterations allowed to :func:`locate_impact` (two or three are usual).
IMPACT_NEWTON_ITERATIONS = 8

#: Longest Taylor step [s] that finishes :func:`locate_impact` from a trial: the terms it
#: leaves out (of order delta^2 in the rates) are then below rounding.
IMPACT_TAYLOR_STEP = 1e-9

# The tableau as scalars (numba freezes module floats into the machine code).
A21 = float(DP_A[1, 0])
A31, A32 = float(DP_A[2, 0]), float(DP_A[2, 1])
A41, A42, A43 = float(DP_A[3, 0]), float(DP_A[3, 1]), float(DP_A[3, 2])
A51, A52, A53, A54 = (float(DP_A[4, j]) for j in range(4))
A61, A62, A63, A64, A65 = (float(DP_A[5, j]) for j in range(5))
B1, B3, B4, B5, B6 = (float(DP_A[6, j]) for j in (0, 2, 3, 4, 5))  # DP_A[6, 1] == 0
C2, C3, C4, C5 = (float(DP_C[j]) for j in (1, 2, 3, 4))
E1, E3, E4, E5, E6, E7 = (float(DP_E[j]) for j in (0, 2, 3, 4, 5, 6))  # DP_E[1] == 0


@njit(cache=True, forceinline=True)
def small_angle_sincos(d):
    """``(sin d, cos d)`` by their Taylor series, for ``|d| <= SMALL_ANGLE``."""
    d2 = d * d
    sn = d * (1.0 + d2 * (-1.0 / 6.0 + d2 * (1.0 / 120.0 + d2 * (
        -1.0 / 5040.0 + d2 * (1.0 / 362880.0 - d2 * (1.0 / 39916800.0))))))
    cs = 1.0 + d2 * (-0.5 + d2 * (1.0 / 24.0 + d2 * (-1.0 / 720.0 + d2 * (
        1.0 / 40320.0 + d2 * (-1.0 / 3628800.0 + d2 * (1.0 / 479001600.0))))))
    return sn, cs


#: Largest |delta| [rad] for the short series of :func:`short_angle_sincos` (truncation below
#: 1e-18 relative): a step's rotation is almost always this small (|omega| h <= 0.02).
SHORT_ANGLE = 0.02


@njit(cache=True, forceinline=True)
def short_angle_sincos(d):
    """``(sin d, cos d)`` by their Taylor series to degree 7 and 6, for ``|d| <= SHORT_ANGLE``."""
    d2 = d * d
    sn = fma(d * d2, fma(d2, fma(d2, -1.0 / 5040.0, 1.0 / 120.0), -1.0 / 6.0), d)
    cs = fma(d2, fma(d2, fma(d2, -1.0 / 720.0, 1.0 / 24.0), -0.5), 1.0)
    return sn, cs


@njit(cache=True, forceinline=True)
def turn(d):
    """``(sin d, cos d)`` of a stage's rotation within a step: the shortest accurate way."""
    ad = abs(d)
    if ad <= SHORT_ANGLE:
        return short_angle_sincos(d)
    if ad <= SMALL_ANGLE:
        return small_angle_sincos(d)
    return math.sin(d), math.cos(d)


@njit(cache=True, forceinline=True)
def _turned(sd, cd, pr, qr, pp, qp, om):
    """Stage rates (theta_dd, power) after a turn ``(sd, cd)``: see :func:`stuck_step`."""
    return fma(cd, pr, sd * qr), om * fma(cd, pp, sd * qp)


@njit(cache=True, forceinline=True)
def _turn_coefficients(gain, kpow, s, c0, s0, a0, da, b0, db, G0, f):
    """``(P, Q)`` of the rate and of the power at the fraction ``f`` of the sample interval.

    The input there is ``a = a0 + da f``, ``ay = b0 + db f`` and ``G = G0 + db f``
    (``G0 = g + b0``).
    """
    a = a0 + da * f
    ay = b0 + db * f
    G = G0 + db * f
    sa = s * a
    return (gain * (a * c0 - s * G * s0), gain * (sa * s0 + G * c0),
            kpow * (a * c0 - s * ay * s0), kpow * (sa * s0 + ay * c0))


@njit(cache=True, forceinline=True)
def stuck_step(p, gain, s, c0, s0, th0, om0, w0, al1, pw1, a0, da, b0, db, f0, fh, h):
    """One Dormand-Prince 5(4) step of ``h`` in mode 3, in scalars.

    The geometry enters through its value ``(c0, s0)`` at the start of the step: at a rotation
    :math:`\\delta` further, by the angle-addition formulas and :math:`s^2 = 1`, the rate and
    the input power of :func:`~shipblock.equations.stuck_rocking_rates` are

    .. math::

        \\ddot\\theta = P\\cos\\delta + Q\\sin\\delta, \\qquad
        P = k(c_0 a - s\\bar s_0 G), \\quad Q = k(s\\bar s_0 a + c_0 G),

    (:math:`k` the gain; the power likewise with :math:`(nm + 2M)R\\dot\\theta` and
    :math:`\\ddot y_g` for :math:`G`), so a stage's only work after its rotation is known is
    :func:`turn` and two products: the chain of dependent operations from one stage to the
    next is as short as the mode allows.

    Parameters
    ----------
    p : tuple
        Parameters.
    gain, s : float
        :func:`~shipblock.equations.stuck_rocking_gain` and the pivot sign.
    c0, s0 : float
        :func:`~shipblock.equations.pivot_geometry` at ``th0``.
    th0, om0, w0 : float
        Rotation, angular velocity and input work at the start.
    al1, pw1 : float
        Angular acceleration and input power at the start (the first stage).
    a0, da, b0, db : float
        The sample interval's horizontal and vertical input, ``a0 + da * f`` at ``f`` (the
        fraction of the interval), already scaled.
    f0, fh : float
        Fraction of the interval at the start of the step, and the step's length in it.
    h : float
        Step [s].

    Returns
    -------
    th1, om1, w1, al7, pw7, c7, sn7, e_th, e_om : float
        The 5th-order solution, the rates and the geometry there (first same as last), and the
        embedded error estimates of theta and theta_dot.
    """
    G0 = p[P_G] + b0
    kpow = (p[P_NM] + 2.0 * p[P_M]) * p[P_R]
    # the input at each stage, and its (P, Q) coefficients: off the chain of stages
    pr2, qr2, pp2, qp2 = _turn_coefficients(gain, kpow, s, c0, s0, a0, da, b0, db, G0, f0 + C2 * fh)
    pr3, qr3, pp3, qp3 = _turn_coefficients(gain, kpow, s, c0, s0, a0, da, b0, db, G0, f0 + C3 * fh)
    pr4, qr4, pp4, qp4 = _turn_coefficients(gain, kpow, s, c0, s0, a0, da, b0, db, G0, f0 + C4 * fh)
    pr5, qr5, pp5, qp5 = _turn_coefficients(gain, kpow, s, c0, s0, a0, da, b0, db, G0, f0 + C5 * fh)
    pr6, qr6, pp6, qp6 = _turn_coefficients(gain, kpow, s, c0, s0, a0, da, b0, db, G0, f0 + fh)
    # each stage's sums end with a fused term: the newest rate, the only one just computed
    om1 = om0
    om2 = fma(h * A21, al1, om0)
    sd, cd = turn(h * (A21 * om1))
    al2, pw2 = _turned(sd, cd, pr2, qr2, pp2, qp2, om2)
    om3 = fma(h * A32, al2, om0 + h * (A31 * al1))
    sd, cd = turn(fma(h * A32, om2, h * (A31 * om1)))
    al3, pw3 = _turned(sd, cd, pr3, qr3, pp3, qp3, om3)
    om4 = fma(h * A43, al3, om0 + h * (A41 * al1 + A42 * al2))
    sd, cd = turn(fma(h * A43, om3, h * (A41 * om1 + A42 * om2)))
    al4, pw4 = _turned(sd, cd, pr4, qr4, pp4, qp4, om4)
    om5 = fma(h * A54, al4, om0 + h * (A51 * al1 + A52 * al2 + A53 * al3))
    sd, cd = turn(fma(h * A54, om4, h * (A51 * om1 + A52 * om2 + A53 * om3)))
    al5, pw5 = _turned(sd, cd, pr5, qr5, pp5, qp5, om5)
    om6 = fma(h * A65, al5, om0 + h * (A61 * al1 + A62 * al2 + A63 * al3 + A64 * al4))
    sd, cd = turn(fma(h * A65, om5, h * (A61 * om1 + A62 * om2 + A63 * om3 + A64 * om4)))
    al6, pw6 = _turned(sd, cd, pr6, qr6, pp6, qp6, om6)
    # the 5th-order solution, and the rates there (first same as last)
    d7 = fma(h * B6, om6, h * (B1 * om1 + B3 * om3 + B4 * om4 + B5 * om5))
    om7 = fma(h * B6, al6, om0 + h * (B1 * al1 + B3 * al3 + B4 * al4 + B5 * al5))
    w1 = w0 + h * (B1 * pw1 + B3 * pw3 + B4 * pw4 + B5 * pw5 + B6 * pw6)
    sd, cd = turn(d7)
    al7, pw7 = _turned(sd, cd, pr6, qr6, pp6, qp6, om7)
    c7 = c0 * cd + s * s0 * sd
    sn7 = s0 * cd - s * c0 * sd
    e_th = h * (E1 * om1 + E3 * om3 + E4 * om4 + E5 * om5 + E6 * om6 + E7 * om7)
    e_om = h * (E1 * al1 + E3 * al3 + E4 * al4 + E5 * al5 + E6 * al6 + E7 * al7)
    return th0 + d7, om7, w1, al7, pw7, c7, sn7, e_th, e_om


@njit(cache=True, forceinline=True)
def _rotating_coefficients(gain, ks, kpow, kps, a0, da, b0, db, G0, f):
    """Coefficients of ``u`` and ``v`` in the rate and the power at the fraction ``f`` of a sample."""
    a = a0 + da * f
    return gain * a, ks * (G0 + db * f), kpow * a, kps * (b0 + db * f)


@njit(cache=True, forceinline=True)
def rotating_step(p, gain, s, c0, s0, th0, om0, w0, al1, pw1, a0, da, b0, db, h):
    """One Dormand-Prince 5(4) step of a whole sample interval in mode 3, geometry as states.

    The pivot geometry :math:`u = \\cos\\varphi`, :math:`v = \\sin\\varphi`
    (:math:`\\varphi = \\theta_c - s\\theta`) is integrated with the motion instead of being
    evaluated at each stage, :math:`\\dot u = s\\dot\\theta v`, :math:`\\dot v = -s\\dot\\theta u`,
    which makes the equation of the mode polynomial,

    .. math::

        \\ddot\\theta = k(a u - s G v), \\qquad P = (nm + 2M)R\\,\\dot\\theta\\,(a u - s \\ddot y_g v),

    so that a stage's only dependent work is two products and two fused sums, about half the
    chain of :func:`stuck_step` (whose stages turn the start's geometry by a series in the
    stage's rotation). The same tableau and the same error estimates of theta and theta_dot;
    the geometry at the end is the step's own, which agrees with
    :math:`\\cos(\\theta_c - s\\theta_1)` to the step's truncation error (and the span's next
    start takes it afresh from theta). Arguments and results as for :func:`stuck_step` with
    ``f0 = 0``, ``fh = 1``.
    """
    G0 = p[P_G] + b0
    kpow = (p[P_NM] + 2.0 * p[P_M]) * p[P_R]
    ks = -s * gain
    kps = -s * kpow
    # the input's coefficients at each stage, off the chain of stages (stage 2's power has
    # no weight in the solution)
    P2, Q2 = gain * (a0 + da * C2), ks * (G0 + db * C2)
    P3, Q3, R3, S3 = _rotating_coefficients(gain, ks, kpow, kps, a0, da, b0, db, G0, C3)
    P4, Q4, R4, S4 = _rotating_coefficients(gain, ks, kpow, kps, a0, da, b0, db, G0, C4)
    P5, Q5, R5, S5 = _rotating_coefficients(gain, ks, kpow, kps, a0, da, b0, db, G0, C5)
    P6, Q6, R6, S6 = _rotating_coefficients(gain, ks, kpow, kps, a0, da, b0, db, G0, 1.0)
    sh = s * h
    u1, v1, om1 = c0, s0, om0
    du1, dv1 = om1 * v1, -om1 * u1
    u2 = fma(sh * A21, du1, u1)
    v2 = fma(sh * A21, dv1, v1)
    om2 = fma(h * A21, al1, om0)
    al2 = fma(P2, u2, Q2 * v2)
    du2, dv2 = om2 * v2, -om2 * u2
    u3 = fma(sh * A32, du2, u1 + sh * (A31 * du1))
    v3 = fma(sh * A32, dv2, v1 + sh * (A31 * dv1))
    om3 = fma(h * A32, al2, om0 + h * (A31 * al1))
    al3 = fma(P3, u3, Q3 * v3)
    du3, dv3 = om3 * v3, -om3 * u3
    u4 = fma(sh * A43, du3, u1 + sh * (A41 * du1 + A42 * du2))
    v4 = fma(sh * A43, dv3, v1 + sh * (A41 * dv1 + A42 * dv2))
    om4 = fma(h * A43, al3, om0 + h * (A41 * al1 + A42 * al2))
    al4 = fma(P4, u4, Q4 * v4)
    du4, dv4 = om4 * v4, -om4 * u4
    u5 = fma(sh * A54, du4, u1 + sh * (A51 * du1 + A52 * du2 + A53 * du3))
    v5 = fma(sh * A54, dv4, v1 + sh * (A51 * dv1 + A52 * dv2 + A53 * dv3))
    om5 = fma(h * A54, al4, om0 + h * (A51 * al1 + A52 * al2 + A53 * al3))
    al5 = fma(P5, u5, Q5 * v5)
    du5, dv5 = om5 * v5, -om5 * u5
    u6 = fma(sh * A65, du5, u1 + sh * (A61 * du1 + A62 * du2 + A63 * du3 + A64 * du4))
    v6 = fma(sh * A65, dv5, v1 + sh * (A61 * dv1 + A62 * dv2 + A63 * dv3 + A64 * dv4))
    om6 = fma(h * A65, al5, om0 + h * (A61 * al1 + A62 * al2 + A63 * al3 + A64 * al4))
    al6 = fma(P6, u6, Q6 * v6)
    du6, dv6 = om6 * v6, -om6 * u6
    # the 5th-order solution, and the rates there (first same as last)
    u7 = fma(sh * B6, du6, u1 + sh * (B1 * du1 + B3 * du3 + B4 * du4 + B5 * du5))
    v7 = fma(sh * B6, dv6, v1 + sh * (B1 * dv1 + B3 * dv3 + B4 * dv4 + B5 * dv5))
    om7 = fma(h * B6, al6, om0 + h * (B1 * al1 + B3 * al3 + B4 * al4 + B5 * al5))
    th7 = th0 + h * (B1 * om1 + B3 * om3 + B4 * om4 + B5 * om5 + B6 * om6)
    pw3 = om3 * fma(R3, u3, S3 * v3)
    pw4 = om4 * fma(R4, u4, S4 * v4)
    pw5 = om5 * fma(R5, u5, S5 * v5)
    pw6 = om6 * fma(R6, u6, S6 * v6)
    w7 = w0 + h * (B1 * pw1 + B3 * pw3 + B4 * pw4 + B5 * pw5 + B6 * pw6)
    al7 = fma(P6, u7, Q6 * v7)
    pw7 = om7 * fma(R6, u7, S6 * v7)
    e_th = h * (E1 * om1 + E3 * om3 + E4 * om4 + E5 * om5 + E6 * om6 + E7 * om7)
    e_om = h * (E1 * al1 + E3 * al3 + E4 * al4 + E5 * al5 + E6 * al6 + E7 * al7)
    return th7, om7, w7, al7, pw7, u7, v7, e_th, e_om


@njit(cache=True, forceinline=True)
def stuck_error_norm(th0, om0, th1, om1, e_th, e_om, rtol, atol):
    """The error norm of :func:`~shipblock.solver._kernel.error_norm` for a mode-3 step."""
    sc_th = atol + rtol * max(abs(th0), abs(th1))
    sc_om = atol + rtol * max(abs(om0), abs(om1))
    return math.sqrt(((e_th / sc_th) ** 2 + (e_om / sc_om) ** 2) / N_DYN)


@njit(cache=True, forceinline=True)
def is_stuck_rocking(ms, y):
    """Whether mode ``ms`` at state ``y`` is mode 3: rocking, no interface slipping."""
    return (ms[MS_ROCK] != 0 and ms[MS_SLIP1] == 0 and ms[MS_SLIP2] == 0 and y[Y_VB] == 0.0
            and y[Y_VS] == 0.0)


@njit(cache=True, forceinline=True)
def advance_stuck(p, ms, y0, k, tau, h, dt, ax, ay, has_ay, sh, sv, y1, stages, w7,
                  first_stage_known, rtol, atol):
    """One Dormand-Prince 5(4) step of ``h`` in mode 3: the error norm (>= 0).

    The contract of :func:`~shipblock.solver._kernel.advance`: ``y1`` gets the 5th-order
    solution, ``stages[0]`` (if not known) and ``stages[6]`` the rates at both ends (the other
    stages are not stored), ``w7`` the accelerations and forces at the end of the step.
    Requires no slip velocities in ``y0`` (mode 3 keeps them zero). The step itself is
    :func:`stuck_step`.
    """
    s = float(ms[MS_S])
    gain = stuck_rocking_gain(p)
    a0 = sh * ax[k]
    da = sh * ax[k + 1] - a0
    b0 = sv * ay[k] if has_ay else 0.0
    db = (sv * ay[k + 1] if has_ay else 0.0) - b0
    th0 = y0[Y_TH]
    om0 = y0[Y_OM]
    c0, s0 = pivot_geometry(p, th0, s, 1)
    f0 = tau / dt
    if first_stage_known:
        al1 = stages[0, Y_OM]
        pw1 = stages[0, Y_WIN]
    else:
        al1, pw1 = stuck_rocking_rates(p, gain, c0, s0, s, om0, a0 + da * f0, b0 + db * f0)
        _store_rates(y0, om0, al1, pw1, stages, np.int64(0))
    th1, om1, w1, al7, pw7, c7, sn7, e_th, e_om = stuck_step(
        p, gain, s, c0, s0, th0, om0, y0[Y_WIN], al1, pw1, a0, da, b0, db, f0, h / dt, h)
    for i in range(N_STATE):
        y1[i] = y0[i]
    y1[Y_TH] = th1
    y1[Y_OM] = om1
    y1[Y_WIN] = w1
    _store_rates(y0, om1, al7, pw7, stages, np.int64(6))
    f = (tau + h) / dt
    stuck_forces_into(p, s, c7, sn7, om1, al7, a0 + da * f, b0 + db * f, w7)
    return stuck_error_norm(th0, om0, th1, om1, e_th, e_om, rtol, atol)


@njit(cache=True, forceinline=True)
def _store_rates(y0, om, al, pw, stages, st):
    """Row ``st`` of the stages: the rates of the whole state in mode 3."""
    for i in range(N_STATE):
        stages[st, i] = 0.0
    stages[st, Y_XB] = y0[Y_VB]
    stages[st, Y_TH] = om
    stages[st, Y_XS] = y0[Y_VS]
    stages[st, Y_OM] = al
    stages[st, Y_WIN] = pw


@njit(cache=True, forceinline=True)
def stuck_forces_into(p, s, c, sn, om, al, a, ay, w7):
    """``w7``: the accelerations and interface forces of mode 3 at geometry ``(c, sn)``."""
    fx, fy, Fx, Fy = stuck_rocking_forces(p, c, sn, s, om, al, a, p[P_G] + ay)
    w7[I_XB_DD] = 0.0
    w7[I_TH_DD] = al
    w7[I_XS_DD] = 0.0
    w7[I_FX] = fx
    w7[I_FY] = fy
    w7[I_SFX] = Fx
    w7[I_SFY] = Fy


@njit(cache=True, forceinline=False, error_model="numpy", _nrt=False)
def locate_impact(p, gain, s, c, sn, th, om, w, al, pw, th1, om1, al1, a0, da, b0, db, f0, h, dt):
    """Time to the impact inside an accepted mode-3 step: ``(ok, t, theta, omega, work, alpha)``.

    The step of ``h`` from ``(th, om)`` ends past zero (``s th1 < 0``); it starts off zero
    (``s th > 0``), or at zero from an impact just before (``th = 0``, ``s om > 0``), when the
    root sought is the one after the turn of the rotation. The first guess is the root of the
    step's quintic Hermite interpolant; Newton's iteration then runs on
    the integrator's own solution, each trial a :func:`stuck_step` of length ``t`` from the same
    start (no sine or cosine): :math:`\\delta = -\\theta(t)/\\dot\\theta(t)`. Once the next
    Newton error, :math:`|\\ddot\\theta\\,\\delta^2 / (2\\dot\\theta)|`, is below
    ``ROOT_TIME_TOL`` and :math:`|\\delta|` at most ``IMPACT_TAYLOR_STEP``, the state is carried
    to :math:`t + \\delta` by its Taylor series from the trial
    (:math:`\\theta \\approx \\ddot\\theta\\delta^2/2`, :math:`\\dot\\theta + \\ddot\\theta\\delta`,
    :math:`W + P\\delta`; the terms left out, of order :math:`\\delta^2` in the rates, are then
    below rounding), so one trial step usually suffices after the quintic's guess. ``ok`` is
    False (the kernel then locates the impact by bracketing) if the rotation is not heading
    into zero at a trial or an iterate leaves the bracket.
    """
    c0, c1, c2, c3, c4, c5 = quintic_hermite(th, om, al, th1, om1, al1, h)
    lo = 0.0
    if th == 0.0:
        # from the impact before: out and back within the step; the root is past the turn
        lo = bracketed_root(c0, c1, c2, c3, c4, c5, 0.0, 1.0, np.bool_(True))
        if not lo > 0.0:
            return False, 0.0, 0.0, 0.0, 0.0, 0.0
    u = bracketed_root(c0, c1, c2, c3, c4, c5, lo, 1.0, np.bool_(False))
    if not u > lo:
        return False, 0.0, 0.0, 0.0, 0.0, 0.0
    t = u * h
    t_lo = lo * h
    for _ in range(IMPACT_NEWTON_ITERATIONS):
        tht, omt, wt, alt, pwt, _c, _sn, _e, _eo = stuck_step(
            p, gain, s, c, sn, th, om, w, al, pw, a0, da, b0, db, f0, t / dt, t)
        if not s * omt < 0.0:
            break
        delta = -tht / omt
        t_next = t + delta
        if not t_lo < t_next <= h:
            break
        if abs(delta) <= IMPACT_TAYLOR_STEP and (
                abs(alt * delta * delta) <= 2.0 * ROOT_TIME_TOL * abs(omt)):
            return (True, t_next, 0.5 * alt * delta * delta, fma(alt, delta, omt),
                    fma(pwt, delta, wt), alt)
        t = t_next
    return False, 0.0, 0.0, 0.0, 0.0, 0.0


@njit(cache=True, forceinline=True)
def note_margin(p, s, th1, fx1, fy1, Fx1, Fy1, g1, summary):
    """Lower the run's least constraint margin (``S_MARGIN``) by an accepted step's end.

    Only where an event function is not clear of zero: :func:`checked_step` has then put them
    all in ``g1`` (the others are positive, and so is the margin).
    """
    if not stuck_rocking_clear(p, s, th1, fx1, fy1, Fx1, Fy1):
        summary[S_MARGIN] = min(summary[S_MARGIN], held_margin(g1, np.int64(-1)))


@njit(cache=True, forceinline=True)
def held_at_impact(p, s, th_i, om_i, al_i, a_i, b_i):
    r"""Whether the conditions mode 3 holds (both stick cones, both normal forces) hold at the
    impact that ends a step, at the rotation ``th_i`` within ``ROOT_TIME_TOL`` of zero.

    The end of the step, past the impact, tells nothing about them: there the mode's equations
    have run on with the pivot on the wrong corner. A condition crossed before the impact and
    met again by the step's end was missed until 2026-11-26 (found by the constraint audit of
    the random campaign: stick violated by up to 1 % of the weight at the impact). Where one
    fails the span refuses the step, and the kernel locates that event before the impact. The
    geometry at ``th_i`` to first order (its square is below rounding):
    :math:`\cos\varphi = (H + s\theta B)/R`, :math:`\sin\varphi = (B - s\theta H)/R`.
    """
    R = p[P_R]
    c = (p[P_H] + s * th_i * p[P_B]) / R
    sn = (p[P_B] - s * th_i * p[P_H]) / R
    fx, fy, Fx, Fy = stuck_rocking_forces(p, c, sn, s, om_i, al_i, a_i, p[P_G] + b_i)
    return (p[P_MUS1] * fy - abs(fx) >= 0.0 and p[P_MUS2] * Fy - abs(Fx) >= 0.0 and fy > 0.0
            and Fy > 0.0)


#: Verdicts of :func:`checked_step`.
STEP_ACCEPTED, STEP_REFUSED, STEP_TO_IMPACT = 0, 1, 2


@njit(cache=True, forceinline=True)
def checked_step(p, ms, y, gain, s, c, sn, th, om, w, al, pw, a0, a1, b0, b1, f0, fh, h, dt,
                 rtol, atol, levels, g1, need_g, whole):
    """One mode-3 step of the span to the next sample, and what the span makes of it.

    Returns the verdict, the step's end (state, rates, geometry, interface forces) and, for
    ``STEP_TO_IMPACT``, the time and state (theta, omega, work, alpha) at the impact. The step is
    ``STEP_ACCEPTED`` when the kernel would accept it with nothing to do: its error norm is at
    most 1 and no watched event function ends below zero or, for the impact, may have dipped
    below it inside the step (the rotation heading for zero at the start and away from it at the
    end). A step that ends past an impact, with no other event and the impact located by
    :func:`locate_impact`, is ``STEP_TO_IMPACT``. Otherwise ``STEP_REFUSED``: the kernel takes
    the step. ``g1`` gets the event functions at the step's end unless the step is accepted and
    ``need_g`` is False; ``y[Y_TH]`` is left at the step's end if it is accepted, else at its
    start.
    """
    if whole:
        th1, om1, w1, al1, pw1, c1, sn1, e_th, e_om = rotating_step(
            p, gain, s, c, sn, th, om, w, al, pw, a0, a1 - a0, b0, b1 - b0, h)
    else:
        th1, om1, w1, al1, pw1, c1, sn1, e_th, e_om = stuck_step(
            p, gain, s, c, sn, th, om, w, al, pw, a0, a1 - a0, b0, b1 - b0, f0, fh, h)
    verdict = STEP_REFUSED
    t_imp = th_i = om_i = w_i = al_i = 0.0
    fx1 = fy1 = Fx1 = Fy1 = 0.0
    # the error norm of stuck_error_norm <= 1, without its divisions and square root (False
    # too when the state is not finite)
    sc_th = atol + rtol * max(abs(th), abs(th1))
    sc_om = atol + rtol * max(abs(om), abs(om1))
    if (e_th * sc_om) ** 2 + (e_om * sc_th) ** 2 <= N_DYN * (sc_th * sc_om) ** 2:
        fx1, fy1, Fx1, Fy1 = stuck_rocking_forces(p, c1, sn1, s, om1, al1, a1, p[P_G] + b1)
        y[Y_TH] = th1
        # the usual case first: every event function clear of zero (read off the signs of
        # their numerators) and the rotation not dipping through zero inside the step
        clear = stuck_rocking_clear(p, s, th1, fx1, fy1, Fx1, Fy1)
        quiet = clear and not (levels[EV_IMPACT] == 0.0 and s * th > 0.0 and s * om < 0.0
                               and s * om1 > 0.0)
        if need_g or not clear:
            event_functions(p, ms, y, fx1, fy1, Fx1, Fy1, g1)
        if not clear:
            quiet = not (levels[EV_IMPACT] == 0.0 and s * th > 0.0 and s * om < 0.0
                         and s * om1 > 0.0)
            for e in range(N_EVENTS):
                if g1[e] < levels[e]:
                    quiet = False
        if quiet and levels[EV_IMPACT] == 0.0 and dip_possible(s, th, al, th1, al1, h):
            # both ends on the pivot's side, but the rotation may have crossed zero and come
            # back inside the step: then the kernel takes it and locates the first crossing
            quiet = rotation_dip(s, th, om, al, th1, om1, al1, h)[0] < 0.0
        if quiet:
            verdict = STEP_ACCEPTED
        else:
            y[Y_TH] = th
            impact_alone = g1[EV_IMPACT] < levels[EV_IMPACT] and (
                s * th > 0.0 or th == 0.0 and s * om > 0.0)
            for e in range(N_EVENTS):
                if g1[e] < levels[e] and e != EV_IMPACT:
                    impact_alone = False
            if impact_alone:
                ok, t_imp, th_i, om_i, w_i, al_i = locate_impact(
                    p, gain, s, c, sn, th, om, w, al, pw, th1, om1, al1, a0, a1 - a0, b0, b1 - b0,
                    f0, h, dt)
                if ok and held_at_impact(p, s, th_i, om_i, al_i, a0 + (a1 - a0) * (f0 + t_imp / dt),
                                         b0 + (b1 - b0) * (f0 + t_imp / dt)):
                    verdict = STEP_TO_IMPACT
    return (verdict, th1, om1, w1, al1, pw1, c1, sn1, fx1, fy1, Fx1, Fy1, t_imp, th_i, om_i, w_i,
            al_i)


@njit(cache=True, forceinline=False, error_model="numpy", _nrt=False)
def stuck_rocking_span(p, ms, y, k, tau, dt, ax, ay, has_ay, sh, sv, rtol, atol, levels, g0, g1,
                       peak_th, peak_th_time, store, hist, modes, mode, summary):
    """Advance mode 3 to the next sample and on by whole samples, up to the next event.

    The rocking counterpart of :func:`~shipblock.solver._closed_form.nonrocking_span`: the
    kernel's steps, but with the state and the pivot geometry carried from step to step in
    registers (the geometry at a step's end is the angle-addition result of its last stage, so
    no sine or cosine is taken per step). Each step is judged by :func:`checked_step`: accepted,
    cut at an impact (the span then stops there, with the state just before the impact, for the
    kernel to apply it), or refused (the span stops at the step's start and the kernel takes
    that step itself, locating and applying the event). A span that starts inside a sample
    (after an impact) first takes the rest of that sample, outside the loop of whole samples,
    whose step length and input fractions are then constants of the loop.

    Parameters
    ----------
    p : tuple
        Parameters.
    ms, y : ndarray
        Mode state (mode 3) and state at ``k * dt + tau`` (``y`` is updated in place).
    k : int
        Current sample.
    tau : float
        Time since sample ``k`` [s], 0 <= tau < dt.
    dt, ax, ay, has_ay, sh, sv, rtol, atol
        As in :func:`~shipblock.solver._kernel.run`.
    levels : ndarray
        The level below which each event function fires (see
        :func:`~shipblock.solver._events.shifted_level`); restored to 0 once clear of zero.
    g0, g1 : ndarray, shape (N_EVENTS,)
        The event functions at the start (updated to those where the span stopped, unless at
        an impact) and work.
    peak_th, peak_th_time : float
        Running peak of |theta| and its time.
    store, hist, modes, mode
        History output as in ``run``, and the mode number to write.
    summary : ndarray, shape (N_SUMMARY,)
        The run's summary: the contact loads at every accepted step's end raise its peaks
        (:func:`~shipblock.solver._force_sampling.note_loads`).

    Returns
    -------
    k : int
        The sample where the span stopped.
    tau : float
        Time since that sample [s]: 0, unless the span stopped inside a sample (at an impact,
        or before the rest of the sample it started in).
    impact : bool
        Whether the span stopped at an impact (``y`` just before it, theta within
        ``ROOT_TIME_TOL`` of zero in time).
    time_in_mode : float
        Time advanced [s].
    peak_th, peak_th_time : float
        The running peak, updated.
    """
    n = ax.shape[0]
    s = float(ms[MS_S])
    gain = stuck_rocking_gain(p)
    th = y[Y_TH]
    om = y[Y_OM]
    w = y[Y_WIN]
    c, sn = pivot_geometry(p, th, s, 1)
    a0 = sh * ax[k]
    b0 = sv * ay[k] if has_ay else 0.0
    time_in_mode = 0.0
    all_armed = False  # until rearm() has looked
    forces_known = False
    fx = fy = Fx = Fy = 0.0
    verdict = STEP_ACCEPTED
    t_imp = th_i = om_i = w_i = al_i = 0.0
    if tau > 0.0:
        # the rest of the sample the span starts in: one step, or two when the first, from an
        # impact, may not pass the rotation's return to zero (see impact_return_time)
        a1 = sh * ax[k + 1]
        b1 = sv * ay[k + 1] if has_ay else 0.0
        while tau > 0.0 and verdict == STEP_ACCEPTED:
            f0 = tau / dt
            al, pw = stuck_rocking_rates(p, gain, c, sn, s, om, a0 + (a1 - a0) * f0,
                                         b0 + (b1 - b0) * f0)
            h = dt - tau
            fh = 1.0 - f0
            t_return = impact_return_time(s, th, om, al)
            to_sample = h <= t_return
            if not to_sample:
                h = t_return
                fh = h / dt
            (verdict, th1, om1, w1, al1, pw1, c1, sn1, fx1, fy1, Fx1, Fy1, t_imp, th_i, om_i,
             w_i, al_i) = checked_step(p, ms, y, gain, s, c, sn, th, om, w, al, pw, a0, a1, b0,
                                       b1, f0, fh, h, dt, rtol, atol, levels, g1, np.bool_(True),
                                       np.bool_(False))
            if verdict == STEP_ACCEPTED:
                all_armed = rearm(levels, g1)
                note_loads(p, 1, fx1, fy1, Fx1, Fy1, summary)
                note_margin(p, s, th1, fx1, fy1, Fx1, Fy1, g1, summary)
                t0 = k * dt + tau
                peak_th, peak_th_time = rotation_peak(peak_th, peak_th_time, th, om, al, th1,
                                                      om1, al1, h, t0,
                                                      k * dt + dt if to_sample else t0 + h)
                time_in_mode += h
                th, om, w, al, pw, c, sn = th1, om1, w1, al1, pw1, c1, sn1
                fx, fy, Fx, Fy = fx1, fy1, Fx1, Fy1
                forces_known = True
                y[Y_TH] = th
                y[Y_OM] = om
                y[Y_WIN] = w
                if to_sample:
                    k += 1
                    tau = 0.0
                    a0, b0 = a1, b1
                    if store:
                        store_sample(p, ms, y, hist, modes, k, mode)
                else:
                    tau += h
    else:
        al, pw = stuck_rocking_rates(p, gain, c, sn, s, om, a0, b0)
    while verdict == STEP_ACCEPTED and k < n - 1:
        a1 = sh * ax[k + 1]
        b1 = sv * ay[k + 1] if has_ay else 0.0
        (verdict, th1, om1, w1, al1, pw1, c1, sn1, fx1, fy1, Fx1, Fy1, t_imp, th_i, om_i, w_i,
         al_i) = checked_step(p, ms, y, gain, s, c, sn, th, om, w, al, pw, a0, a1, b0, b1, 0.0,
                              1.0, dt, dt, rtol, atol, levels, g1, not all_armed, np.bool_(True))
        if verdict != STEP_ACCEPTED:
            break
        note_loads(p, 1, fx1, fy1, Fx1, Fy1, summary)
        note_margin(p, s, th1, fx1, fy1, Fx1, Fy1, g1, summary)
        if not all_armed:
            all_armed = rearm(levels, g1)
        if om * om1 <= 0.0:
            # between turns of theta_dot, |theta| is monotone (theta cannot cross zero inside
            # an accepted step): the running peak can only grow at a turn, or where the span
            # stops (below)
            peak_th, peak_th_time = rotation_peak(peak_th, peak_th_time, th, om, al, th1, om1,
                                                  al1, dt, k * dt, k * dt + dt)
        time_in_mode += dt
        k += 1
        th, om, w, al, pw, c, sn, a0, b0 = th1, om1, w1, al1, pw1, c1, sn1, a1, b1
        fx, fy, Fx, Fy = fx1, fy1, Fx1, Fy1
        forces_known = True
        y[Y_OM] = om
        y[Y_WIN] = w
        if store:
            store_sample(p, ms, y, hist, modes, k, mode)
    if abs(th) > peak_th:
        # the end of the last step accepted (as rotation_peak would have timed it)
        peak_th = abs(th)
        peak_th_time = (k - 1) * dt + dt if time_in_mode > 0.0 and tau == 0.0 else k * dt + tau
    if verdict == STEP_TO_IMPACT:
        t0 = k * dt + tau
        peak_th, peak_th_time = rotation_peak(peak_th, peak_th_time, th, om, al, th_i, om_i, al_i,
                                              t_imp, t0, t0 + t_imp)
        y[Y_TH] = th_i
        y[Y_OM] = om_i
        y[Y_WIN] = w_i
        tau += t_imp
        time_in_mode += t_imp
        return k, tau, True, time_in_mode, peak_th, peak_th_time
    if forces_known:
        # the event functions where the span stopped, for the kernel's next step
        event_functions(p, ms, y, fx, fy, Fx, Fy, g0)
    return k, tau, False, time_in_mode, peak_th, peak_th_time
