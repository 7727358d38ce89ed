"""Interpolants over one accepted rocking step (compiled).

A Dormand-Prince step gives the rotation ``theta``, its rate and its acceleration at both
ends of the step (the acceleration at the end is the last, first-same-as-last stage). The
quintic Hermite interpolant through these six values is accurate to O(h^6), far below the
step's own error tolerance, and costs no evaluation of the equations of motion. The solver
uses it to place peak rotations (where ``theta_dot`` changes sign) and as the first guess
when it locates an impact (``theta = 0``), which it then confirms on the integrated state.

With ``u = (t - t_0) / h`` the interpolant is ``p(u) = sum c_i u^i`` with

.. math::

    c_0 &= \\theta_0, \\quad c_1 = h\\dot\\theta_0, \\quad c_2 = h^2\\ddot\\theta_0 / 2, \\\\
    c_3 &= 10(\\theta_1 - \\theta_0) - h(6\\dot\\theta_0 + 4\\dot\\theta_1)
          - h^2(3\\ddot\\theta_0 - \\ddot\\theta_1)/2, \\\\
    c_4 &= 15(\\theta_0 - \\theta_1) + h(8\\dot\\theta_0 + 7\\dot\\theta_1)
          + h^2(3\\ddot\\theta_0/2 - \\ddot\\theta_1), \\\\
    c_5 &= 6(\\theta_1 - \\theta_0) - 3h(\\dot\\theta_0 + \\dot\\theta_1)
          + h^2(\\ddot\\theta_1 - \\ddot\\theta_0)/2

(checked symbolically in ``tests/test_interpolate.py``).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from shipblock.solver._fused import fma


@njit(cache=True, forceinline=False)
def quintic_hermite(th0, om0, al0, th1, om1, al1, h):
    """Monomial coefficients ``(c0, ..., c5)`` of the quintic Hermite interpolant on u in [0, 1]."""
    d = th1 - th0
    h2 = h * h
    c3 = 10.0 * d - h * (6.0 * om0 + 4.0 * om1) - h2 * (1.5 * al0 - 0.5 * al1)
    c4 = -15.0 * d + h * (8.0 * om0 + 7.0 * om1) + h2 * (1.5 * al0 - al1)
    c5 = 6.0 * d - 3.0 * h * (om0 + om1) + 0.5 * h2 * (al1 - al0)
    return th0, h * om0, 0.5 * h2 * al0, c3, c4, c5


@njit(cache=True, forceinline=False)
def poly5(c0, c1, c2, c3, c4, c5, u):
    """Value of the quintic at ``u`` (Horner)."""
    return c0 + u * (c1 + u * (c2 + u * (c3 + u * (c4 + u * c5))))


@njit(cache=True, forceinline=False)
def poly5_slope(c1, c2, c3, c4, c5, u):
    """Derivative of the quintic with respect to ``u``."""
    return c1 + u * (2.0 * c2 + u * (3.0 * c3 + u * (4.0 * c4 + u * 5.0 * c5)))


@njit(cache=True, forceinline=True)
def quintic_and_slope(c0, c1, c2, c3, c4, c5, u):
    """Value and derivative of the quintic at ``u``: one Horner pass, fused (two short chains)."""
    d = c5
    q = fma(c5, u, c4)
    d = fma(d, u, q)
    q = fma(q, u, c3)
    d = fma(d, u, q)
    q = fma(q, u, c2)
    d = fma(d, u, q)
    q = fma(q, u, c1)
    d = fma(d, u, q)
    q = fma(q, u, c0)
    return q, d


@njit(cache=True, forceinline=False)
def bracketed_root(c0, c1, c2, c3, c4, c5, lo, hi, derivative):
    """Root in ``[lo, hi]`` of the quintic (or of its derivative) that changes sign there.

    Safeguarded Newton: a Newton step that leaves the bracket is replaced by bisection, so it
    converges for any sign-changing bracket. Returns -1 when the ends have the same sign.
    The derivative is the quartic of coefficients ``(c1, 2 c2, 3 c3, 4 c4, 5 c5)``; either
    polynomial is evaluated with its slope in one fused Horner pass
    (:func:`quintic_and_slope`), whose chain of dependent operations is what an iteration
    costs.
    """
    if derivative:
        b0, b1, b2, b3, b4, b5 = c1, 2.0 * c2, 3.0 * c3, 4.0 * c4, 5.0 * c5, 0.0
    else:
        b0, b1, b2, b3, b4, b5 = c0, c1, c2, c3, c4, c5
    f_lo, _ = quintic_and_slope(b0, b1, b2, b3, b4, b5, lo)
    f_hi, _ = quintic_and_slope(b0, b1, b2, b3, b4, b5, hi)
    if f_lo == 0.0:
        return lo
    if f_hi == 0.0:
        return hi
    if (f_lo > 0.0) == (f_hi > 0.0):
        return -1.0
    rising = f_hi > 0.0
    u = lo - f_lo * (hi - lo) / (f_hi - f_lo)
    for _ in range(60):
        f, df = quintic_and_slope(b0, b1, b2, b3, b4, b5, u)
        if f == 0.0:
            return u
        if (f > 0.0) == rising:
            hi = u
        else:
            lo = u
        step = f / df if df != 0.0 else math.inf
        # converged: tested before the safeguard, since a step below the spacing of floats
        # lands on the end of the bracket just moved to u and would be taken for one leaving it
        if abs(step) <= 1e-15 * max(1.0, abs(u)):
            un = u - step
            return un if lo <= un <= hi else u
        un = u - step
        if not (lo < un < hi):
            un = 0.5 * (lo + hi)
        if hi - lo <= 1e-15:
            return un
        u = un
    return u


@njit(cache=True, forceinline=False)
def hermite_extremum(g0, d0, g1, d1):
    """Interior extremum of the cubic Hermite interpolant on [0, 1]: (u, value) or (-1, 0).

    ``d0`` and ``d1`` are the end slopes scaled to the unit interval. Used to look for a
    velocity-type event function dipping below zero inside a step.
    """
    # p(u) = g0 + d0 u + c2 u^2 + c3 u^3
    c2 = 3.0 * (g1 - g0) - 2.0 * d0 - d1
    c3 = 2.0 * (g0 - g1) + d0 + d1
    # p'(u) = d0 + 2 c2 u + 3 c3 u^2
    qa, qb, qc = 3.0 * c3, 2.0 * c2, d0
    best_u = -1.0
    best_v = 0.0
    if abs(qa) < 1e-300:
        if qb != 0.0:
            u = -qc / qb
            if 0.0 < u < 1.0:
                best_u = u
    else:
        disc = qb * qb - 4.0 * qa * qc
        if disc >= 0.0:
            sq = math.sqrt(disc)
            for u in ((-qb - sq) / (2.0 * qa), (-qb + sq) / (2.0 * qa)):
                if 0.0 < u < 1.0:
                    v = g0 + d0 * u + c2 * u * u + c3 * u * u * u
                    if best_u < 0.0 or (d0 < 0.0 and v < best_v) or (d0 > 0.0 and v > best_v):
                        best_u = u
                        best_v = v
    if best_u >= 0.0:
        u = best_u
        best_v = g0 + d0 * u + c2 * u * u + c3 * u * u * u
    return best_u, best_v


@njit(cache=True, forceinline=False)
def rotation_extremum(th0, om0, al0, th1, om1, al1, h):
    """Peak |theta| inside a rocking step in which theta_dot changes sign, and its time.

    Read off the quintic Hermite interpolant of the step (no further integration), so peak
    rotations and their times do not depend on where the steps happen to end.

    Returns
    -------
    peak : float
        |theta| at the extremum [rad].
    s : float
        Its time after the start of the step [s].
    """
    c0, c1, c2, c3, c4, c5 = quintic_hermite(th0, om0, al0, th1, om1, al1, h)
    return quintic_extremum(c0, c1, c2, c3, c4, c5, th0, th1, h)


@njit(cache=True, forceinline=False)
def quintic_extremum(c0, c1, c2, c3, c4, c5, th0, th1, h):
    """:func:`rotation_extremum` from the step's interpolant ``(c0, ..., c5)``."""
    u = bracketed_root(c0, c1, c2, c3, c4, c5, 0.0, 1.0, np.bool_(True))
    if u < 0.0:
        return max(abs(th0), abs(th1)), 0.0
    return abs(poly5(c0, c1, c2, c3, c4, c5, u)), u * h


#: Relative margin on the bound of :func:`rotation_peak` (far above the rounding of the
#: interpolant's evaluation, so a skipped extremum can never have been the larger).
PEAK_BOUND_MARGIN = 1e-9


@njit(cache=True, forceinline=True)
def rotation_peak(peak, peak_time, th0, om0, al0, th1, om1, al1, h, t0, t1):
    """The running peak of |theta| and its time, updated with an accepted rocking step.

    The step runs from ``t0`` to ``t1 = t0 + h`` (both given, so that callers keep their own
    arithmetic for times); an extremum inside it is read off :func:`rotation_extremum`, unless
    it cannot exceed the running peak: on the step, :math:`|\\theta| \\le \\sum_k |c_k|` for
    the interpolant's coefficients (:math:`0 \\le u \\le 1`), a bound that a rocking cycle
    below the largest so far is well under, so its extremum is not sought.
    """
    if om0 * om1 < 0.0:
        c0, c1, c2, c3, c4, c5 = quintic_hermite(th0, om0, al0, th1, om1, al1, h)
        bound = abs(c0) + abs(c1) + abs(c2) + abs(c3) + abs(c4) + abs(c5)
        if bound * (1.0 + PEAK_BOUND_MARGIN) >= peak:
            ext, s_ext = quintic_extremum(c0, c1, c2, c3, c4, c5, th0, th1, h)
            if ext > peak:
                peak = ext
                peak_time = t0 + s_ext
    if abs(th1) > peak:
        peak = abs(th1)
        peak_time = t1
    return peak, peak_time


@njit(cache=True, forceinline=True)
def dip_possible(s, th0, al0, th1, al1, h):
    """Whether the rotation may cross zero and come back inside a step whose ends are on the
    pivot's side (``s th0 >= 0``, ``s th1 >= 0``): the screen of :func:`rotation_dip`.

    A dip below zero between two ends at or above it bends the curve by more than the lower
    end: :math:`\\min(s\\theta_0, s\\theta_1) < h^2 \\max|\\ddot\\theta| / 8`. The screen
    takes :math:`\\max|\\ddot\\theta|` as twice the larger end value (the input is linear
    within a step, so the angular acceleration varies little across it) and keeps a factor 4
    in hand: only steps with :math:`\\min(s\\theta_0, s\\theta_1) \\le h^2\\max(|\\ddot\\theta_0|,
    |\\ddot\\theta_1|)` are searched, the few near zero.
    """
    return min(s * th0, s * th1) <= h * h * max(abs(al0), abs(al1))


@njit(cache=True, forceinline=False)
def rotation_dip(s, th0, om0, al0, th1, om1, al1, h):
    """A point inside a step where the rotation has crossed zero and come back: ``(u_dip,
    u_top)`` on ``[0, 1]``, or ``(-1, -1)``.

    Both ends are on the pivot's side (``s th >= 0``), so no check of the ends sees such a
    pair of crossings (issue 32: rocking of 1e-9 to 1e-8 rad, impacts 0.1 ms apart inside one
    step at the default ``atol``). The minima of :math:`s\\,p(u)` for the step's quintic
    Hermite interpolant are the roots of its derivative where it turns from falling to
    rising, found by sampling the derivative at ``u = k / 8`` and refining each sign change
    (:func:`bracketed_root`); ``u_dip`` is the first with :math:`s\\,p < 0`, ``u_top`` the last
    point before it with :math:`s\\,p > 0` (0, or the interpolant's maximum before the dip when
    the step starts at zero, just after an impact).
    """
    c0, c1, c2, c3, c4, c5 = quintic_hermite(s * th0, s * om0, s * al0, s * th1, s * om1,
                                             s * al1, h)
    _, d_prev = quintic_and_slope(c0, c1, c2, c3, c4, c5, 0.0)
    u_prev = 0.0
    u_top = 0.0 if c0 > 0.0 else -1.0
    for k in range(1, 9):
        u = k / 8.0
        _, d = quintic_and_slope(c0, c1, c2, c3, c4, c5, u)
        if d_prev > 0.0 >= d:
            # a maximum: the top before a dip (kept if it is above zero)
            r = bracketed_root(c0, c1, c2, c3, c4, c5, u_prev, u, np.bool_(True))
            if r > 0.0 and poly5(c0, c1, c2, c3, c4, c5, r) > 0.0:
                u_top = r
        if d_prev < 0.0 <= d:
            r = bracketed_root(c0, c1, c2, c3, c4, c5, u_prev, u, np.bool_(True))
            if r > 0.0 and poly5(c0, c1, c2, c3, c4, c5, r) < 0.0 and u_top >= 0.0:
                return r, u_top
        d_prev = d
        u_prev = u
    return -1.0, -1.0
