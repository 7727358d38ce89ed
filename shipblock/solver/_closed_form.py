"""Closed-form integration of the non-rocking modes (1, 2, 4, 5), sample by sample.

With the blocks at rest (theta = theta_dot = 0) the equations of motion of a mode are linear
and homogeneous in the ground input (a, G = g + a_y): every acceleration and interface force is
``w(a, G) = a w_a + G w_G`` with two response vectors fixed while the mode lasts. Between two
samples a and G are linear in time, so within a sample interval

* the forces, and with them every force-type event function (stick margins, the uplift
  moment criterion, the normal forces), are linear in time, or the minimum of two linear
  functions, and their roots are found exactly;
* the slip velocities are quadratic in time and their zeros are found exactly;
* displacements are cubic and the input power and friction dissipation rate are cubic, so the
  state and the energy accounts advance exactly (Simpson's rule for the latter two).

:func:`nonrocking_span` runs this loop over as many samples as the mode lasts without leaving
compiled code or touching the general event machinery, which is what makes sliding and rest
phases cheap. Without a vertical input the conditions a non-rocking mode holds (positive
normal forces, no uplift, stick forces inside their friction cones) hold surely for horizontal
accelerations in an interval (:func:`held_interval`), so a sample inside it is screened only
for a slip that may stop, without the normal forces being computed. At rest nothing moves
and whether an interval may hold an event depends on the input at its end alone, so long
rest phases are screened a block of samples at a time (:func:`skip_rest`; without a vertical
input, mostly by two comparisons a sample against the interval of rest). The span stops at the first event, with
the state advanced exactly to it (the same polynomials, cut at the root), and returns the event
for the general kernel to apply.

The functions called once per span or per event are compiled without numba's reference
counting (``_nrt=False``; they neither allocate nor return arrays): it would otherwise update
the counts of all their array arguments on every call, atomically, and the record and output
arrays are shared by the runs that ``run_cases`` executes on several threads.
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
    I_XB_DD,
    I_XS_DD,
    N_SOLVE_OUT,
    kinetic_energy,
    solve_mode,
)
from shipblock.modes import MODE_NUMBER
from shipblock.solver._events import event_functions, note_held_margin, rearm
from shipblock.solver._ground import ground_motion_at
from shipblock.solver._history import store_sample
from shipblock.solver._layout import (
    EV_G_SLIP,
    EV_G_STICK,
    EV_IMPACT,
    EV_OVERTURN,
    EV_S_SLIP,
    EV_S_STICK,
    EV_SEP_G,
    EV_SEP_S,
    EV_UPLIFT,
    EVENT_PRIORITY,
    H_KIN,
    H_POT,
    MS_SIG1,
    MS_SIG2,
    MS_SLIP1,
    MS_SLIP2,
    N_EVENTS,
    N_STATE,
    ROOT_TIME_TOL,
    W_FOLDED,
    W_G,
    W_HELD,
    W_INV_W,
    W_INV_WR,
    W_INV_WS,
    W_NOTED,
    W_RESP,
    W_RESP_STATE,
    Y_DIS,
    Y_VB,
    Y_VS,
    Y_WIN,
    Y_XB,
    Y_XS,
)
from shipblock.solver._running_peaks import (
    folds_loads,
    note_span_extremes,
)
from shipblock.system import P_B, P_G, P_H, P_M, P_MUS1, P_MUS2, P_NM, P_R

NO_ROOT = math.inf
#: Samples screened at once at rest (see :func:`skip_rest`).
REST_BLOCK = 32
#: Samples of a rest phase screened one by one before :func:`skip_rest` takes over.
REST_FIRST = 64
#: Samples checked at once against the interval of :func:`held_interval`: a loop of 32 so
#: short would be unrolled whole and not vectorised.
FAST_BLOCK = 64


@njit(cache=True, forceinline=False, error_model="numpy")
def linear_root(l0, l1, h):
    """Time in [0, h] at which a linear function going from ``l0`` to ``l1`` turns negative.

    ``inf`` if it ends non-negative; 0 if it starts on or below zero and falls (the event is
    due now); ``inf`` if it starts below zero and rises: a force event watched at a shifted
    level whose function stood at or just below that level at the event that kept its mode
    (the mode selection found the condition held, and it is recovering) does not fire again
    at once (:func:`~shipblock.solver._events.shifted_level`).
    """
    if l1 >= 0.0:
        return NO_ROOT
    if l0 <= 0.0:
        return 0.0 if l1 < l0 else NO_ROOT
    return h * l0 / (l0 - l1)


@njit(cache=True, forceinline=False, error_model="numpy")
def min_linear_root(la0, la1, lb0, lb1, h):
    """As :func:`linear_root` for ``min(la, lb)`` of two linear functions (e.g. mu N - |T|).

    The minimum of linear functions is concave, so it is negative inside the interval only if
    it is negative at an end.
    """
    if min(la1, lb1) >= 0.0:
        return NO_ROOT
    return min(linear_root(la0, la1, h), linear_root(lb0, lb1, h))


@njit(cache=True, forceinline=False, error_model="numpy")
def quadratic_root(q0, d0, c, h):
    """First time in [0, h] at which ``q(s) = q0 + d0 s + c s^2`` crosses below zero.

    ``inf`` if it does not. Starting on the boundary (``q0 <= 0``) the event is due at once
    unless q rises first, in which case the root is where it comes back down.
    """
    q1 = q0 + h * (d0 + c * h)
    if q0 <= 0.0:
        if q1 >= 0.0:
            return NO_ROOT  # leaves the boundary into the admissible side
        if c >= 0.0:
            return 0.0  # convex and non-positive at both ends: negative throughout
    best = NO_ROOT
    if c == 0.0:
        if d0 < 0.0:
            r = -q0 / d0
            if 0.0 <= r <= h:
                best = r
    else:
        disc = d0 * d0 - 4.0 * c * q0
        if disc > 0.0:
            qq = -0.5 * (d0 + math.copysign(math.sqrt(disc), d0))
            r1 = qq / c
            r2 = q0 / qq if qq != 0.0 else r1
            # a down-crossing has q' = d0 + 2 c r < 0
            if 0.0 <= r1 <= h and d0 + 2.0 * c * r1 < 0.0:
                best = r1
            if 0.0 <= r2 <= h and d0 + 2.0 * c * r2 < 0.0 and r2 < best:
                best = r2
    if q0 <= 0.0 and best == NO_ROOT:
        return 0.0
    return best


@njit(cache=True, error_model="numpy", forceinline=True)
def slip_may_stop(sig, v0, u0, u1, h):
    """Whether a slip velocity, quadratic over the interval, may reach zero inside it.

    ``sig v`` starts at ``sig v0`` with slope ``sig u0``; it is suspect if it ends negative or
    if its slope turns from negative to positive inside (a dip, checked exactly afterwards).

    The test divides by ``2 h`` (the quadratic coefficient, as the root search uses it): a
    division on the way to the screen's branch in every sliding sample. It is made only when
    the same test without divisions (the coefficient times ``h`` taken as
    ``sig (u1 - u0) / 2``, the end slope compared times ``h``), with a margin far above the
    round-off between the two, cannot rule the interval out; so the result is the same.
    """
    d0 = sig * u0
    dd = sig * (u1 - u0)
    margin = 1e-12 * (abs(v0) + h * (abs(u0) + abs(u1)))
    if sig * v0 + h * (d0 + 0.5 * dd) >= margin and (d0 >= 0.0 or (d0 + dd) * h <= -margin):
        return False
    c = dd / (2.0 * h)
    return sig * v0 + h * (d0 + c * h) < 0.0 or (d0 < 0.0 and d0 + 2.0 * c * h > 0.0)


@njit(cache=True, error_model="numpy", forceinline=True)
def exact_update(y, h, ub0, ub1, us0, us1, a0, a1, fx0, fx1, Fx0, Fx1, mass_b, M):
    """Advance ``y`` by ``h`` with slip accelerations, ground acceleration and friction forces
    linear in time from their values at 0 (``*0``) to those at ``h`` (``*1``): :func:`exact_step`
    on the state's entries."""
    y[Y_XB], y[Y_VB], y[Y_XS], y[Y_VS], y[Y_WIN], y[Y_DIS] = exact_step(
        y[Y_XB], y[Y_VB], y[Y_XS], y[Y_VS], y[Y_WIN], y[Y_DIS], h, ub0, ub1, us0, us1, a0, a1,
        fx0, fx1, Fx0, Fx1, mass_b, M)


@njit(cache=True, error_model="numpy", forceinline=True)
def exact_step(xb, vb0, xs, vs0, w_in, dis, h, ub0, ub1, us0, us1, a0, a1, fx0, fx1, Fx0, Fx1,
               mass_b, M):
    """Slips, slip velocities, input work and dissipation (``xb, vb0, xs, vs0, w_in, dis``)
    advanced by ``h`` with slip accelerations, ground acceleration and friction forces linear in
    time from their values at 0 (``*0``) to those at ``h`` (``*1``).

    Velocities are quadratic and slips cubic in time; the input power -a P_x and the friction
    dissipation rate -(fx v_b + Fx v_s) are cubic, so Simpson's rule integrates them exactly.
    Values in and out (rather than the state array), so that the span's loop keeps them in
    locals and writes the state only where it is read.
    """
    vb1 = vb0 + 0.5 * h * (ub0 + ub1)
    vs1 = vs0 + 0.5 * h * (us0 + us1)
    vbm = vb0 + 0.5 * h * ub0 + 0.125 * h * (ub1 - ub0)
    vsm = vs0 + 0.5 * h * us0 + 0.125 * h * (us1 - us0)
    am = 0.5 * (a0 + a1)
    r0 = -a0 * (mass_b * vb0 + M * vs0)
    rm = -am * (mass_b * vbm + M * vsm)
    r1 = -a1 * (mass_b * vb1 + M * vs1)
    d0 = -(fx0 * vb0 + Fx0 * vs0)
    dm = -(0.5 * (fx0 + fx1) * vbm + 0.5 * (Fx0 + Fx1) * vsm)
    d1 = -(fx1 * vb1 + Fx1 * vs1)
    return (xb + (h * vb0 + h * h * (2.0 * ub0 + ub1) / 6.0), vb1,
            xs + (h * vs0 + h * h * (2.0 * us0 + us1) / 6.0), vs1,
            w_in + h * (r0 + 4.0 * rm + r1) / 6.0, dis + h * (d0 + 4.0 * dm + d1) / 6.0)


@njit(cache=True, error_model="numpy", forceinline=True)
def exact_step_one(x, v0, w_in, dis, h, u0, u1, a0, a1, f0, f1, m):
    """As :func:`exact_step` when only one interface moves: its slip ``x``, slip velocity
    ``v0``, acceleration ``u``, friction force ``f`` and the mass ``m`` it carries.

    The other interface's terms are products with its zero velocity and acceleration, so
    leaving them out gives the same values with half the arithmetic.
    """
    v1 = v0 + 0.5 * h * (u0 + u1)
    vm = v0 + 0.5 * h * u0 + 0.125 * h * (u1 - u0)
    am = 0.5 * (a0 + a1)
    r0 = -a0 * (m * v0)
    rm = -am * (m * vm)
    r1 = -a1 * (m * v1)
    d0 = -(f0 * v0)
    dm = -(0.5 * (f0 + f1) * vm)
    d1 = -(f1 * v1)
    return (x + (h * v0 + h * h * (2.0 * u0 + u1) / 6.0), v1,
            w_in + h * (r0 + 4.0 * rm + r1) / 6.0, dis + h * (d0 + 4.0 * dm + d1) / 6.0)


@njit(cache=True, error_model="numpy", forceinline=True)
def held_fails_at(slip1, slip2, a1, G1, fx_a, fx_g, fy_a, fy_g, Fx_a, Fx_g, Fy_a, Fy_g, mus1,
                  mus2, B, H):
    """Whether the conditions a non-rocking mode holds fail, at scaled ground input ``a1``,
    ``G1 = g + b1``, as the screen of :func:`nonrocking_span` computes them (no branches).

    The held conditions: both normal forces positive, the blocks' moment criterion (no
    uplift), and the static friction cone of each interface that sticks (``slip1``,
    ``slip2`` zero). A slipping interface's own condition, that its slip may stop, depends on
    the state and is screened apart.
    """
    fx1 = fx_a * a1 + fx_g * G1
    fy1 = fy_a * a1 + fy_g * G1
    Fx1 = Fx_a * a1 + Fx_g * G1
    Fy1 = Fy_a * a1 + Fy_g * G1
    return ((fy1 <= 0.0) | (Fy1 <= 0.0) | (B * (fy1 + Fy1) < H * abs(fx1 + Fx1))
            | ((slip1 == 0) & (mus1 * fy1 < abs(fx1))) | ((slip2 == 0) & (mus2 * Fy1 < abs(Fx1))))


@njit(cache=True, error_model="numpy", forceinline=True)
def rest_breaks(ax_j, ay_j, has_ay, sh, sv, grav, fx_a, fx_g, fy_a, fy_g, Fx_a, Fx_g, Fy_a, Fy_g,
                mus1, mus2, B, H):
    """Whether rest (mode 1, every event armed) fails the screen of :func:`nonrocking_span` at
    the end of an interval whose end sample is ``ax_j``, ``ay_j``.

    At rest nothing moves, so the screen is :func:`held_fails_at` of the input at the end
    sample alone.
    """
    return held_fails_at(np.int64(0), np.int64(0), sh * ax_j,
                         grav + (sv * ay_j if has_ay else 0.0), fx_a, fx_g, fy_a, fy_g, Fx_a, Fx_g,
                         Fy_a, Fy_g, mus1, mus2, B, H)


@njit(cache=True, forceinline=False, error_model="numpy")
def held_interval(slip1, slip2, grav, fx_a, fx_g, fy_a, fy_g, Fx_a, Fx_g, Fy_a, Fy_g, mus1, mus2,
                  B, H):
    """Horizontal accelerations ``[lo, hi]`` at which the held conditions of a non-rocking mode
    surely pass :func:`held_fails_at` when there is no vertical input (``lo > hi`` if none is
    known).

    With ``G = g`` and the normal forces independent of ``a`` (as they are while the blocks
    do not rock), every held condition reads ``|s a + q| <= r``: an interval of ``a`` (all of
    them if ``s = 0``, as for the moment criterion while both interfaces slip). Their
    intersection is shrunk by a margin (1e-9 relative) and kept where the terms in ``a`` are
    at most 1e4 times ``|q| + r``, so that the round-off of the screen's arithmetic (some
    1e-16 of its terms) stays far below the margin: a sample inside passes the screen as
    computed; a sample outside is screened in full. Finite ends are checked against the
    screen itself; an infinite one means that ``a`` does not enter the conditions at all.
    """
    empty = (1.0, -1.0)
    if fy_a != 0.0 or Fy_a != 0.0 or not H > 0.0:
        return empty
    fy = fy_g * grav  # as the screen computes fy_a a + fy_g G with fy_a = 0
    Fy = Fy_g * grav
    if not (fy > 0.0 and Fy > 0.0):
        return empty
    lo = -math.inf
    hi = math.inf
    for i in range(3):
        if i == 0:  # the moment criterion
            s, q, r = fx_a + Fx_a, (fx_g + Fx_g) * grav, B * (fy + Fy) / H
            scale = abs(fx_a) + abs(Fx_a)
        elif i == 1:  # the ground friction cone, if the ground interface sticks
            if slip1:
                continue
            s, q, r, scale = fx_a, fx_g * grav, mus1 * fy, abs(fx_a)
        else:  # the ship's
            if slip2:
                continue
            s, q, r, scale = Fx_a, Fx_g * grav, mus2 * Fy, abs(Fx_a)
        margin = 1e-9 * (abs(q) + abs(r))
        if scale > 0.0:
            cap = 1e4 * (abs(q) + abs(r)) / scale
            lo = max(lo, -cap)
            hi = min(hi, cap)
        if s == 0.0:
            if not abs(q) < r - margin:
                return empty
            continue
        c = -q / s
        w = (r - margin) / abs(s)
        lo = max(lo, c - w)
        hi = min(hi, c + w)
    if not lo <= hi or math.isnan(lo) or math.isnan(hi):
        return empty
    # the finite ends themselves pass the screen (a check of the margin's argument)
    for end in (lo, hi):
        if math.isfinite(end) and held_fails_at(slip1, slip2, end, grav + 0.0, fx_a, fx_g, fy_a,
                                                fy_g, Fx_a, Fx_g, Fy_a, Fy_g, mus1, mus2, B, H):
            return empty
    return lo, hi


@njit(cache=True, forceinline=False, error_model="numpy")
def add_repeated(t, dt, n):
    """``t`` with ``dt > 0`` added ``n`` times, rounded after each addition: the same value as
    the loop of ``n`` additions, in a few operations per power of two passed.

    ``t`` is a multiple of its ulp ``u``, and while the sums stay below the next power of two
    they are rounded to multiples of ``u``; unless ``dt`` lies exactly halfway between two of
    them (a tie, broken by the parity of ``t``), each addition then adds the same exact
    increment ``d = (t + dt) - t``, and ``m`` additions add ``m d``, exactly. So the additions
    are made ``m`` at a time up to the next power of two, and one by one across it (and
    wherever that cannot be shown: a tie, ``t`` zero or not normal).

    The loop is one serial chain of additions, a few cycles each: the time of a long rest
    phase (see :func:`skip_rest`) would cost more than screening its samples.
    """
    while n > 0:
        if 1e-300 < t < 1e300:
            top = math.ldexp(1.0, math.frexp(t)[1])  # the power of two above t
            u = math.ldexp(top, -53)  # ulp of t
            d = (t + dt) - t  # exact: both multiples of u (or m below is 0)
            if abs(dt - d) != 0.5 * u:
                if d == 0.0:
                    return t  # dt below half an ulp: no addition changes t
                # m d <= top - t - u (exact right side): each sum t + i d + dt, i < m, ends
                # below top (dt <= d + u / 2); and m d, a multiple of u below top, is exact
                room = (top - t) - u
                m = min(n, int(room / d))
                while m > 0 and m * d > room:
                    m -= 1  # the quotient rounded up
                t += m * d
                n -= m
        if n > 0:
            t += dt
            n -= 1
    return t


@njit(cache=True, forceinline=False, error_model="numpy", _nrt=False)
def skip_rest(ax, ay, has_ay, sh, sv, k, dt, time, grav, fx_a, fx_g, fy_a, fy_g, Fx_a, Fx_g,
              Fy_a, Fy_g, mus1, mus2, B, H, lo, hi, loads, a_lo, a_hi, n_lo, n_hi):
    """Advance rest from sample ``k`` to the first interval that fails the screen (see
    :func:`rest_breaks`), or to the end of the record.

    Blocks of ``REST_BLOCK`` intervals are screened at once, with no branches in the loop
    (vectorised, a fraction of the cost of the sample-by-sample loop): first ``FAST_BLOCK``
    intervals by whether their accelerations lie in ``[lo, hi]`` (two comparisons a sample),
    else ``REST_BLOCK`` by the screen itself, the first failing interval found by a minimum
    over the block's indices. The time is added at the end (:func:`add_repeated`).

    With ``loads`` the range of the scaled input over the samples passed is kept too, for
    :func:`~shipblock.solver._running_peaks.note_span_extremes`: the fast blocks are checked
    against ``[lo, hi]`` cut to the range already covered (the span's ``[a_lo, a_hi]`` and the
    range ``[n_lo, n_hi]`` whose loads are noted: their hull, whose ends are all noted by the
    end of the span), and only a block that reaches beyond it is scanned for its least and
    greatest input, once. The break found is the same either way.

    Parameters
    ----------
    ax, ay, has_ay, sh, sv, dt
        Record and scale factors as in :func:`nonrocking_span`.
    k : int
        Sample at which rest goes on (``tau`` = 0).
    time : float
        Time in the mode so far [s].
    grav, fx_a, ..., H : float
        As :func:`rest_breaks` takes them.
    lo, hi : float
        Scaled horizontal accelerations at which rest surely passes the screen
        (:func:`held_interval` of rest; ``lo > hi`` for none, as with a vertical input).
    loads : bool
        Whether to keep the range of the input (only where
        :func:`~shipblock.solver._running_peaks.folds_loads`: no vertical input).
    a_lo, a_hi : float
        The span's range of scaled input so far [m/s^2].
    n_lo, n_hi : float
        The range whose loads are noted (``inf, -inf`` for none).

    Returns
    -------
    k : int
        The sample whose interval fails the screen (``n - 1`` at the end of the record).
    time : float
        The time in the mode, with ``dt`` added interval by interval as the span adds it.
    a_lo, a_hi : float
        The span's range, with the samples passed.
    """
    n = ax.shape[0]
    k0 = k
    # a fast block inside [f_lo, f_hi] holds rest and raises no peak beyond the covered range
    if loads:
        f_lo, f_hi = max(lo, min(a_lo, n_lo)), min(hi, max(a_hi, n_hi))
    else:
        f_lo, f_hi = lo, hi
    while True:
        if k + REST_BLOCK >= n:
            # the last samples, one by one
            while k < n - 1 and not rest_breaks(ax[k + 1], ay[k + 1], has_ay, sh, sv, grav,
                                                 fx_a, fx_g, fy_a, fy_g, Fx_a, Fx_g, Fy_a,
                                                 Fy_g, mus1, mus2, B, H):
                a1 = sh * ax[k + 1]
                a_lo = min(a_lo, a1)
                a_hi = max(a_hi, a1)
                k += 1
            break
        # indices from 0 in a slice, so that the loads are contiguous (no negative-index
        # wraparound to allow for) and vectorise without gathers
        if lo <= hi and k + FAST_BLOCK < n:
            bx = ax[k + 1:k + 1 + FAST_BLOCK]
            outside = 0
            for j in range(FAST_BLOCK):
                a1 = sh * bx[j]  # as rest_breaks scales it
                outside += (a1 < f_lo) | (a1 > f_hi)
            if outside != 0 and loads:
                # beyond the covered range: if the block is all rest all the same, its range
                # widens the span's
                outside = 0
                for j in range(FAST_BLOCK):
                    a1 = sh * bx[j]
                    outside += (a1 < lo) | (a1 > hi)
                if outside == 0:
                    for j in range(FAST_BLOCK):
                        a1 = sh * bx[j]
                        a_lo = min(a_lo, a1)
                        a_hi = max(a_hi, a1)
                    f_lo, f_hi = max(lo, min(a_lo, n_lo)), min(hi, max(a_hi, n_hi))
            if outside == 0:
                k += FAST_BLOCK
                continue
        bx = ax[k + 1:k + 1 + REST_BLOCK]
        by = ay[k + 1:k + 1 + REST_BLOCK]
        first = REST_BLOCK
        for j in range(REST_BLOCK):
            bad = rest_breaks(bx[j], by[j], has_ay, sh, sv, grav, fx_a, fx_g, fy_a, fy_g, Fx_a,
                              Fx_g, Fy_a, Fy_g, mus1, mus2, B, H)
            first = min(first, j if bad else REST_BLOCK)
        if loads:
            for j in range(first):  # the samples passed
                a1 = sh * bx[j]
                a_lo = min(a_lo, a1)
                a_hi = max(a_hi, a1)
            f_lo, f_hi = max(lo, min(a_lo, n_lo)), min(hi, max(a_hi, n_hi))
        if first < REST_BLOCK:
            k += first
            break
        k += REST_BLOCK  # not k += first: the next block's range need not wait for the minimum
    return k, add_repeated(time, dt, k - k0), a_lo, a_hi


@njit(cache=True, forceinline=True)
def response_slot(slip1, sig1, slip2, sig2):
    """Row of the response cache of a non-rocking mode: 3 ground x 3 ship interface states.

    An interface sticks (0) or slips forward (1) or backward (2); a sticking interface's sign
    does not enter the equations.
    """
    g = 0 if not slip1 else (1 if sig1 > 0.0 else 2)
    s = 0 if not slip2 else (1 if sig2 > 0.0 else 2)
    return 3 * g + s


# inlined: mode selection calls it for every non-rocking candidate
@njit(cache=True, forceinline=True)
def mode_response_start(p, work, slip1, sig1, slip2, sig2):
    """Where the response vectors of a non-rocking mode lie in the run's work array, solved on
    first use.

    Per :func:`response_slot`, ``work[W_RESP_STATE + slot]`` is 0 (not solved yet), 1 (solved)
    or 2 (singular), and ``w_a = work[start:start + N_SOLVE_OUT]``, ``w_G`` the next
    ``N_SOLVE_OUT`` entries, are the mode's :func:`~shipblock.equations.solve_mode` outputs for
    unit horizontal acceleration (a = 1, G = 0) and unit gravity (a = 0, G = 1): at theta =
    theta_dot = 0 its output at any input is ``a w_a + G w_G``. Solved with them, the mode's
    :func:`held_interval`, at ``work[W_HELD + 2 slot]`` and the next entry. The closed-form
    spans and mode selection (:func:`~shipblock.solver._kernel.select_mode`) share them, so
    each is solved once per run.

    Parameters
    ----------
    p : ndarray
        Parameter vector.
    work : ndarray, shape (N_SPAN_WORK,)
        The run's work array (see :func:`nonrocking_span`).
    slip1, slip2 : int
        Ground and ship interface flags (1 slipping).
    sig1, sig2 : float
        Their slip directions.

    Returns
    -------
    int
        ``start``, or -1 if the mode is singular.
    """
    slot = response_slot(slip1, sig1, slip2, sig2)
    start = W_RESP + 2 * N_SOLVE_OUT * slot
    if work[W_RESP_STATE + slot] == 0.0:
        wa = work[start:start + N_SOLVE_OUT]
        wg = work[start + N_SOLVE_OUT:start + 2 * N_SOLVE_OUT]
        # (np.int64, not the literal 0: numba would compile solve_mode once more for a literal)
        ok_a = solve_mode(p, slip1, np.int64(0), slip2, 1.0, sig1, sig2, 0.0, 0.0, 1.0, 0.0, wa)
        ok_g = solve_mode(p, slip1, np.int64(0), slip2, 1.0, sig1, sig2, 0.0, 0.0, 0.0, 1.0, wg)
        work[W_RESP_STATE + slot] = 1.0 if ok_a and ok_g else 2.0
        # no input noted yet for the mode's contact loads (see note_span_extremes)
        work[W_NOTED + 2 * slot] = math.inf
        work[W_NOTED + 2 * slot + 1] = -math.inf
        if ok_a and ok_g:
            work[W_HELD + 2 * slot], work[W_HELD + 2 * slot + 1] = held_interval(
                slip1, slip2, p[P_G], wa[I_FX], wg[I_FX], wa[I_FY], wg[I_FY], wa[I_SFX],
                wg[I_SFX], wa[I_SFY], wg[I_SFY], p[P_MUS1], p[P_MUS2], p[P_B], p[P_H])
    return start if work[W_RESP_STATE + slot] == 1.0 else -1


# inlined into the kernel's loop: a call passed some 75 machine words of arguments at every
# event, a few per cent of a stick-slip record's time
@njit(cache=True, error_model="numpy", _nrt=False, forceinline=True)
def nonrocking_span(p, ms, y, k, tau, dt, ax, ay, has_ay, sh, sv, levels, peak_xb, peak_xs,
                    store, hist, modes, work, summary):
    """Advance a non-rocking mode sample by sample until an event or the end of the record.

    Parameters
    ----------
    p : ndarray
        Parameter vector (see ``shipblock.system.P_*``). The array rather than the kernel's
        tuple: numba passes a tuple as its 14 floats, an array as a few machine words, and
        without reference counting here an array costs nothing else.
    ms, y : ndarray
        Mode state and state (``y`` is updated in place).
    k, tau : int, float
        Current sample interval and time into it [s].
    dt, ax, ay, has_ay, sh, sv
        Record and scale factors as in :func:`shipblock.solver._kernel.run`.
    levels : ndarray
        The level below which each event function fires (0, shifted or -inf: see
        :func:`~shipblock.solver._events.shifted_level`); restored to 0 once clear of zero.
    peak_xb, peak_xs : float
        Running peaks of |x_b| and |x_s| at the samples.
    store, hist, modes
        History output, as in ``run``: each sample the span completes is written.
    work : ndarray, shape (N_SPAN_WORK,)
        Per-run work array (layout ``W_*`` in :mod:`~shipblock.solver._layout`), zero at the
        start of a run: the event functions; per :func:`response_slot` of the non-rocking
        modes its state (0 not solved yet, 1 solved, 2 singular) and response vectors ``w_a``,
        ``w_G`` (:func:`mode_response_start`), solved on a mode's first use and reused by its
        later spans and mode selections in the run (a stick-slip record enters the same few
        modes thousands of times); the inverse weights
        that scale the event functions, set by the first span; per response slot the
        interval of :func:`held_interval`, set with its response vectors, and the range of
        input whose contact loads are noted.
    summary : ndarray, shape (N_SUMMARY,)
        The run's summary. Where :func:`~shipblock.solver._running_peaks.folds_loads` (no
        vertical input), the span notes the contact loads of its start, its samples and its
        end itself: it keeps the least and greatest scaled input over them (two operations a
        sample; :func:`skip_rest` keeps them over a long rest) and notes the loads there on
        leaving (:func:`~shipblock.solver._running_peaks.note_span_extremes`). Otherwise
        :func:`~shipblock.solver._force_sampling.span_loads`, which the kernel calls next (when
        ``work[W_FOLDED]`` is 0), scans them.

    Returns
    -------
    k, tau : int, float
        Where the span stopped: at the event (``y`` is the state there), or at the end of the
        record.
    event : int
        The event (``EV_*``), -1 at the end of the record, -2 if the mode is singular.
    time_in_mode : float
        Time the span spent in the mode [s], to be added to the summary (0 if singular).
    peak_xb, peak_xs : float
        The running peaks, updated.
    """
    n = ax.shape[0]
    slip1, slip2 = ms[MS_SLIP1], ms[MS_SLIP2]
    sig1, sig2 = float(ms[MS_SIG1]), float(ms[MS_SIG2])
    start = mode_response_start(p, work, slip1, sig1, slip2, sig2)
    if start < 0:
        return k, tau, -2, 0.0, peak_xb, peak_xs
    slot = response_slot(slip1, sig1, slip2, sig2)
    wa = work[start:start + N_SOLVE_OUT]
    wg = work[start + N_SOLVE_OUT:start + 2 * N_SOLVE_OUT]
    g = work[W_G:W_G + N_EVENTS]
    grav = p[P_G]
    mus1, mus2, B, H = p[P_MUS1], p[P_MUS2], p[P_B], p[P_H]
    ub_a, us_a, fx_a, fy_a, Fx_a, Fy_a = wa[I_XB_DD], wa[I_XS_DD], wa[I_FX], wa[I_FY], wa[I_SFX], wa[I_SFY]
    ub_g, us_g, fx_g, fy_g, Fx_g, Fy_g = wg[I_XB_DD], wg[I_XS_DD], wg[I_FX], wg[I_FY], wg[I_SFX], wg[I_SFY]
    # without a vertical input, the held conditions surely hold for a in [lo, hi]
    lo, hi = (work[W_HELD + 2 * slot], work[W_HELD + 2 * slot + 1]) if not has_ay else (1.0, -1.0)
    M = p[P_M]
    mass_b = p[P_NM] + M
    if work[W_INV_W] == 0.0:
        # once per run: divisions that would otherwise be made at every event
        work[W_INV_W] = 1.0 / (mass_b * grav)
        work[W_INV_WS] = 1.0 / (M * grav)
        work[W_INV_WR] = work[W_INV_W] / p[P_R]
    inv_w, inv_ws, inv_wr = work[W_INV_W], work[W_INV_WS], work[W_INV_WR]
    mode = MODE_NUMBER[slip1, 0, slip2]
    loads = folds_loads(has_ay, fy_a, Fy_a)
    work[W_FOLDED] = 1.0 if loads else 0.0
    # the least and greatest scaled horizontal input over the points the span passes (its
    # start, its samples, its end): the forces are linear in it, so their peaks are at these two
    a0, b0 = ground_motion_at(ax, ay, has_ay, sh, sv, k, tau, dt)  # the start
    a_lo = a_hi = a0
    all_armed = True
    for e in range(N_EVENTS):
        if levels[e] != 0.0:
            all_armed = False
    time_in_mode = 0.0  # accumulated here, added to the summary by the caller
    if not slip1 and not slip2 and all_armed and y[Y_VB] == 0.0 and y[Y_VS] == 0.0:
        # Rest: nothing moves and an interval passes the screen on the input at its end alone.
        # The first intervals are screened one by one (rest often ends within a few), then
        # skip_rest goes on up to the first that fails, where the loop below takes over.
        k_first = k
        while k < n - 1 and k - k_first < REST_FIRST and (
                lo <= sh * ax[k + 1] <= hi or not rest_breaks(
                    ax[k + 1], ay[k + 1], has_ay, sh, sv, grav, fx_a, fx_g, fy_a, fy_g, Fx_a,
                    Fx_g, Fy_a, Fy_g, mus1, mus2, B, H)):
            a1 = sh * ax[k + 1]
            a_lo = min(a_lo, a1)
            a_hi = max(a_hi, a1)
            time_in_mode += dt - tau
            tau = 0.0
            k += 1
        if k - k_first == REST_FIRST:
            k, time_in_mode, a_lo, a_hi = skip_rest(
                ax, ay, has_ay, sh, sv, k, dt, time_in_mode, grav, fx_a, fx_g, fy_a, fy_g, Fx_a,
                Fx_g, Fy_a, Fy_g, mus1, mus2, B, H, lo, hi, loads, a_lo, a_hi,
                work[W_NOTED + 2 * slot], work[W_NOTED + 2 * slot + 1])
        if store and k > k_first:
            _store_rest(p, y, hist, modes, k_first + 1, k + 1, mode)
    if tau == 0.0:
        # the start of the interval, at a sample (the rest above may have passed some): as
        # ground_motion_at gives it there
        a0 = sh * ax[k]
        b0 = sv * ay[k] if has_ay else 0.0
    G0 = grav + b0
    fx0 = fx_a * a0 + fx_g * G0
    Fx0 = Fx_a * a0 + Fx_g * G0
    ub0 = ub_a * a0 + ub_g * G0
    us0 = us_a * a0 + us_g * G0
    # the state that moves, in locals through the loop (in y at every exit and before any use)
    xb, vb, xs, vs, w_in, dis = y[Y_XB], y[Y_VB], y[Y_XS], y[Y_VS], y[Y_WIN], y[Y_DIS]
    while k < n - 1:
        h = dt - tau
        a1 = sh * ax[k + 1]
        b1 = sv * ay[k + 1] if has_ay else 0.0
        G1 = grav + b1
        fx1 = fx_a * a1 + fx_g * G1
        Fx1 = Fx_a * a1 + Fx_g * G1
        ub1 = ub_a * a1 + ub_g * G1
        us1 = us_a * a1 + us_g * G1
        vb0 = vb
        vs0 = vs
        # Cheap screen at the end of the interval: force-type event functions are linear (or
        # concave) in time and can only fire if negative at the end; slip velocities are
        # quadratic and can also dip below zero inside. Only a suspect interval is searched.
        # The held conditions (normal forces, moment criterion, stick cones) need no check
        # inside [lo, hi]; the normal forces are then not computed at all.
        held_fails = not lo <= a1 <= hi and held_fails_at(
            slip1, slip2, a1, G1, fx_a, fx_g, fy_a, fy_g, Fx_a, Fx_g, Fy_a, Fy_g, mus1, mus2, B, H)
        suspect = held_fails or not all_armed
        # a slipping interface: its slip may stop
        if slip1:
            suspect = suspect or slip_may_stop(sig1, vb0, ub0, ub1, h)
        if slip2:
            suspect = suspect or slip_may_stop(sig2, vs0, us0, us1, h)
        if suspect:
            fy0 = fy_a * a0 + fy_g * G0
            Fy0 = Fy_a * a0 + Fy_g * G0
            fy1 = fy_a * a1 + fy_g * G1
            Fy1 = Fy_a * a1 + Fy_g * G1
            best_h = h + 1.0
            best_e = -1
            for ie in range(N_EVENTS):
                e = EVENT_PRIORITY[ie]
                # only the events a non-rocking mode can meet, and not disarmed ones; each
                # crosses its level (0 unless shifted)
                level = levels[e]
                if level == -math.inf or e in (EV_IMPACT, EV_OVERTURN) \
                        or (e == EV_G_STICK and slip1) or (e == EV_G_SLIP and not slip1) \
                        or (e == EV_S_STICK and slip2) or (e == EV_S_SLIP and not slip2):
                    continue
                if e == EV_SEP_G:
                    r = linear_root(fy0 * inv_w - level, fy1 * inv_w - level, h)
                elif e == EV_SEP_S:
                    r = linear_root(Fy0 * inv_ws - level, Fy1 * inv_ws - level, h)
                elif e == EV_G_STICK:
                    r = min_linear_root((mus1 * fy0 - fx0) * inv_w - level,
                                        (mus1 * fy1 - fx1) * inv_w - level,
                                        (mus1 * fy0 + fx0) * inv_w - level,
                                        (mus1 * fy1 + fx1) * inv_w - level, h)
                elif e == EV_S_STICK:
                    r = min_linear_root((mus2 * Fy0 - Fx0) * inv_ws - level,
                                        (mus2 * Fy1 - Fx1) * inv_ws - level,
                                        (mus2 * Fy0 + Fx0) * inv_ws - level,
                                        (mus2 * Fy1 + Fx1) * inv_ws - level, h)
                elif e == EV_UPLIFT:
                    r = min_linear_root(
                        (B * (fy0 + Fy0) - H * (fx0 + Fx0)) * inv_wr - level,
                        (B * (fy1 + Fy1) - H * (fx1 + Fx1)) * inv_wr - level,
                        (B * (fy0 + Fy0) + H * (fx0 + Fx0)) * inv_wr - level,
                        (B * (fy1 + Fy1) + H * (fx1 + Fx1)) * inv_wr - level, h)
                elif e == EV_G_SLIP:
                    r = quadratic_root(sig1 * vb0, sig1 * ub0, sig1 * (ub1 - ub0) / (2.0 * h), h)
                else:  # EV_S_SLIP
                    r = quadratic_root(sig2 * vs0, sig2 * us0, sig2 * (us1 - us0) / (2.0 * h), h)
                # a later-priority event wins only if it is clearly earlier (as in the kernel)
                if r < best_h - 2.0 * ROOT_TIME_TOL:
                    best_h = r
                    best_e = e
            # the run's least constraint margin (the audit, S_MARGIN): at the ends of the
            # intervals the screen does not pass (it passes only those where every held
            # condition holds), and up to the event
            if best_e < 0:
                if held_fails or not all_armed:
                    note_held_margin(p, ms, y, fx1, fy1, Fx1, Fy1, g, np.int64(-1), summary)
            else:
                # advance to the event: the same polynomials, cut at best_h (u = best_h / h)
                u = best_h / h
                a_end = a0 + (a1 - a0) * u
                if best_e != EV_SEP_G and best_e != EV_SEP_S:  # (as the kernel's events)
                    note_held_margin(p, ms, y, fx0 + (fx1 - fx0) * u, fy0 + (fy1 - fy0) * u,
                                     Fx0 + (Fx1 - Fx0) * u, Fy0 + (Fy1 - Fy0) * u, g, best_e,
                                     summary)
                y[Y_XB], y[Y_XS], y[Y_WIN], y[Y_DIS] = xb, xs, w_in, dis
                y[Y_VB], y[Y_VS] = vb, vs
                exact_update(y, best_h, ub0, ub0 + (ub1 - ub0) * u, us0, us0 + (us1 - us0) * u,
                             a0, a_end, fx0, fx0 + (fx1 - fx0) * u, Fx0,
                             Fx0 + (Fx1 - Fx0) * u, mass_b, M)
                if loads:
                    note_span_extremes(p, work, slot, fx_a, fx_g, fy_g, Fx_a, Fx_g, Fy_g,
                                       min(a_lo, a_end), max(a_hi, a_end), grav, summary)
                return k, tau + best_h, best_e, time_in_mode + best_h, peak_xb, peak_xs
        # no event: advance exactly to the next sample
        moving_b = slip1 or vb0 != 0.0
        moving_s = slip2 or vs0 != 0.0
        if moving_b or moving_s:
            if not moving_s:
                xb, vb, w_in, dis = exact_step_one(xb, vb, w_in, dis, h, ub0, ub1, a0, a1, fx0,
                                                   fx1, mass_b)
            elif not moving_b:
                xs, vs, w_in, dis = exact_step_one(xs, vs, w_in, dis, h, us0, us1, a0, a1, Fx0,
                                                   Fx1, M)
            else:
                xb, vb, xs, vs, w_in, dis = exact_step(xb, vb, xs, vs, w_in, dis, h, ub0, ub1, us0,
                                                       us1, a0, a1, fx0, fx1, Fx0, Fx1, mass_b, M)
            axb = abs(xb)
            if axb > peak_xb:
                peak_xb = axb
            axs = abs(xs)
            if axs > peak_xs:
                peak_xs = axs
        time_in_mode += h
        k += 1
        tau = 0.0
        a_lo = min(a_lo, a1)
        a_hi = max(a_hi, a1)
        # the end of this interval is the start of the next: the same values, not recomputed
        a0 = a1
        G0 = G1
        fx0, Fx0, ub0, us0 = fx1, Fx1, ub1, us1
        if not all_armed or store:
            y[Y_XB], y[Y_VB], y[Y_XS], y[Y_VS], y[Y_WIN], y[Y_DIS] = xb, vb, xs, vs, w_in, dis
            if not all_armed:
                event_functions(p, ms, y, fx1, fy_a * a1 + fy_g * G1, Fx1,
                                Fy_a * a1 + Fy_g * G1, g)
                all_armed = rearm(levels, g)
            if store:
                store_sample(p, ms, y, hist, modes, k, mode)
    y[Y_XB], y[Y_VB], y[Y_XS], y[Y_VS], y[Y_WIN], y[Y_DIS] = xb, vb, xs, vs, w_in, dis
    if loads:
        note_span_extremes(p, work, slot, fx_a, fx_g, fy_g, Fx_a, Fx_g, Fy_g, a_lo, a_hi, grav,
                           summary)
    return k, tau, -1, time_in_mode, peak_xb, peak_xs


@njit(cache=True, forceinline=False, error_model="numpy", _nrt=False)
def _store_rest(p, y, hist, modes, k0, k1, mode):
    """History columns ``k0:k1`` of a rest phase: the same column repeated, row by row.

    Filling each row over the whole range (contiguous, vectorised) rather than column by
    column makes storing a skipped rest block about as cheap as skipping it.
    """
    kin = kinetic_energy(p, 0.0, 1.0, np.int64(0), y[Y_VB], 0.0, y[Y_VS])
    for i in range(N_STATE):
        v = y[i]
        for j in range(k0, k1):
            hist[i, j] = v
    for j in range(k0, k1):
        hist[H_KIN, j] = kin
        hist[H_POT, j] = 0.0
        modes[j] = mode
