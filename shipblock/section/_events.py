"""Event functions of the dock section's current regimes, and the peaks kept at step ends
(compiled; used by the Dormand-Prince loop of :mod:`shipblock.section._kernel` and by the
exponential steps of :mod:`shipblock.section._static`)."""

from __future__ import annotations

import math

from numba import njit

from shipblock.section._forces import (
    F_FREE, F_STICK, O_KEEL_B, O_KEEL_TOP_Y, O_KEEL_TOP_Z, O_MAX_ANGLE, O_MAX_DISP, O_SEP,
    O_SHIP_KY, O_SHIP_KZ, O_TIP_NEG, O_TIP_POS, PF_C, PF_FY, PF_K, R_ELASTIC, R_FREE, SF_KT,
    SF_MUS, SF_PY, SF_SQY, SI_C, SI_COUNT, SI_FIRST, SI_S, cap_surface, contact_forces,
    kinematics, strip_of, strips_forces, strips_kinematics)

#: An event function's value where no event can happen.
BIG = 1e300


@njit(cache=True)
def event_values(t, x, nb, ns, strip_f, strip_i, spring_f, reg, dp, dc0, tc0, fs, opt,
                 delta, delta_dot, vt, pos, fe, fn, normal, tang, theta_c, gv):
    """Event functions of the current regimes: an event happens when one goes from > 0 to <= 0."""
    kinematics(x, nb, strip_f, strip_i, spring_f, delta, delta_dot, vt, pos)
    contact_forces(x, 6 * nb, nb, strip_f, strip_i, spring_f, reg, dp, fs, delta,
                   delta_dot, vt, fe, fn, normal, tang)
    _event_values_of(t, x, nb, ns, strip_f, strip_i, spring_f, reg, dp, dc0, tc0, fs, opt,
                     delta, delta_dot, vt, fe, fn, normal, tang, theta_c, gv)


@njit(cache=True)
def _event_values_of(t, x, nb, ns, strip_f, strip_i, spring_f, reg, dp, dc0, tc0, fs, opt,
                     delta, delta_dot, vt, fe, fn, normal, tang, theta_c, gv):
    """:func:`event_values` from the kinematics and contact forces of ``x`` already in the work
    arrays (after :func:`rhs` at the same state and regimes)."""
    nsp = spring_f.shape[0]
    min_gap = _strips_event_values(t, 0, ns, nsp, strip_f, strip_i, spring_f, reg, dp, dc0, tc0,
                                   fs, delta, delta_dot, vt, fe, fn, normal, tang, gv)
    o = 2 * nsp + ns
    for b in range(1, nb):
        gv[o + b - 1] = theta_c[b] - abs(x[3 * b + 2])
    o += nb - 1
    # ship slid off the keel line's top: keel centre vs the keel block's top centre
    ca, sa = math.cos(x[2]), math.sin(x[2])
    ky = x[0] + ca * opt[O_SHIP_KY] - sa * opt[O_SHIP_KZ]
    cb, sb = math.cos(x[5]), math.sin(x[5])
    ty = x[3] + cb * opt[O_KEEL_TOP_Y] - sb * opt[O_KEEL_TOP_Z]
    gv[o] = opt[O_KEEL_B] - abs(ky - ty)
    phi = x[2]
    gv[o + 1] = opt[O_TIP_POS] - phi if phi >= 0.0 else opt[O_TIP_NEG] + phi
    gv[o + 2] = opt[O_SEP] - min_gap
    # validity: displacements (from the body's place as built: G's offset for the ship, the
    # line's offset for a block line) and rotations within what the model is written for
    worst = 0.0
    for b in range(nb):
        ref = -strip_f[0, SF_SQY]  # strip 0 is the keel top, its surface point -g_offset on S
        if b > 0:
            for j in range(strip_i.shape[0]):
                if strip_i[j, SI_C] == b:
                    ref = strip_f[j, SF_PY]
        worst = max(worst, abs(x[3 * b] - ref) / opt[O_MAX_DISP])
        worst = max(worst, abs(x[3 * b + 2]) / opt[O_MAX_ANGLE])
    gv[o + 3] = 1.0 - worst


@njit(cache=True, inline="always")
def _strips_event_values(t, j0, j1, nsp, strip_f, strip_i, spring_f, reg, dp, dc0, tc0, fs, delta,
                         delta_dot, vt, fe, fn, normal, tang, gv):
    """The event functions of strips ``j0 .. j1 - 1`` and their springs (from their kinematics
    and forces); returns the smallest gap of their floor springs (``BIG`` if none)."""
    min_gap = BIG
    for j in range(j0, j1):
        first, count = strip_i[j, SI_FIRST], strip_i[j, SI_COUNT]
        for i in range(first, first + count):
            k, c = spring_f[i, PF_K], spring_f[i, PF_C]
            if reg[i] == R_FREE:
                gv[2 * i] = cap_surface(k, c, dp[i], dc0[i], tc0[i], t) - delta[i]
                gv[2 * i + 1] = BIG
            elif reg[i] == R_ELASTIC:
                gv[2 * i] = fn[i] / k  # detaches when the force would pull
                gv[2 * i + 1] = (spring_f[i, PF_FY] - fe[i]) / k  # starts to crush
            else:
                gv[2 * i] = delta_dot[i]  # stops crushing when it unloads
                gv[2 * i + 1] = BIG
            if strip_i[j, SI_S] == 0:
                min_gap = min(min_gap, dp[i] - delta[i])
        if fs[j] == F_STICK:
            gv[2 * nsp + j] = (strip_f[j, SF_MUS] * normal[j] - abs(tang[j])) / strip_f[j, SF_KT]
        elif fs[j] == F_FREE:
            gv[2 * nsp + j] = BIG
        else:
            gv[2 * nsp + j] = fs[j] * vt[j]
    return min_gap


@njit(cache=True)
def event_value(q, t, x, nb, ns, strip_f, strip_i, spring_f, reg, dp, dc0, tc0, fs, opt,
                delta, delta_dot, vt, pos, fe, fn, normal, tang, theta_c, gv):
    """Event function ``q`` of :func:`event_values`, for locating its sign change: a spring's or
    a strip's from that strip's kinematics and forces alone (the work arrays then hold them for
    that strip only), the others from all of them."""
    nsp = spring_f.shape[0]
    if q >= 2 * nsp + ns:
        event_values(t, x, nb, ns, strip_f, strip_i, spring_f, reg, dp, dc0, tc0, fs, opt, delta,
                     delta_dot, vt, pos, fe, fn, normal, tang, theta_c, gv)
        return gv[q]
    j = q - 2 * nsp if q >= 2 * nsp else strip_of(q // 2, strip_i)
    strips_kinematics(x, nb, j, j + 1, strip_f, strip_i, spring_f, delta, delta_dot, vt, pos)
    strips_forces(x, 6 * nb, nb, j, j + 1, strip_f, strip_i, spring_f, reg, dp, fs, delta,
                  delta_dot, vt, fe, fn, normal, tang)
    _strips_event_values(t, j, j + 1, nsp, strip_f, strip_i, spring_f, reg, dp, dc0, tc0, fs,
                         delta, delta_dot, vt, fe, fn, normal, tang, gv)
    return gv[q]


@njit(cache=True)
def _track(nsp, ns, fe, fn, normal, tang, peak_fe, peak_fn, peak_util, peak_n):
    for i in range(nsp):
        peak_fe[i] = max(peak_fe[i], fe[i])
        peak_fn[i] = max(peak_fn[i], fn[i])
    for j in range(ns):
        peak_n[j] = max(peak_n[j], normal[j])
        if normal[j] > 0.0:
            peak_util[j] = max(peak_util[j], abs(tang[j]) / normal[j])


@njit(cache=True, inline="always")
def _is_gap(q, nsp, reg):
    """Whether event function ``q`` is the gap of a spring that is not carrying."""
    return q < 2 * nsp and q % 2 == 0 and reg[q // 2] == R_FREE
