"""Exponential steps of the dock section in its static regime (compiled; the matrices are
:func:`shipblock.section.exponential.static_steps`'s, the loop that takes them
:func:`shipblock.section._kernel.run`)."""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from shipblock.section._events import _event_values_of, _is_gap, _track
from shipblock.section._forces import contact_forces, kinematics, rhs

# exponential steps (static regime): their error estimates are held to this fraction of the
# tolerance (at 1 a run's energy balance closed only to ~1e-5 where Dormand-Prince, stepping
# far below its tolerance in quiet spans, closes it to ~1e-8; 0.3 closes it to ~1e-8 too); a
# step refused for its error even as two half steps leaves this many samples to Dormand-Prince
STATIC_SAFETY = 0.3
STATIC_PAUSE = 2


def _hermite_table():
    """Coefficients of the quintic through values and slopes at theta = 0, 1/2, 1: row k of
    the result gives theta^k's coefficient from (x0, x_half, x1, x0', x_half', x1')."""
    rows = []
    for th in (0.0, 0.5, 1.0):
        rows.append([th**k for k in range(6)])
    for th in (0.0, 0.5, 1.0):
        rows.append([k * th ** (k - 1) if k > 0 else 0.0 for k in range(6)])
    return np.linalg.inv(np.array(rows))


_HERMITE = _hermite_table()


@njit(cache=True)
def _static_dense(theta, h, x0, xm, x1, f0, fm, f1, out):
    """State at ``t + theta h`` of an exponential step: the quintic through the ends' and the
    middle's states and rates (the exact trajectory's transients have decayed by then to the
    step's accuracy, or are what the rates carry)."""
    c0 = c1 = c2 = c3 = c4 = c5 = 0.0
    p = 1.0
    for kk in range(6):  # the basis at theta, summed over theta's powers (no array per call)
        c0 += _HERMITE[kk, 0] * p
        c1 += _HERMITE[kk, 1] * p
        c2 += _HERMITE[kk, 2] * p
        c3 += _HERMITE[kk, 3] * p
        c4 += _HERMITE[kk, 4] * p
        c5 += _HERMITE[kk, 5] * p
        p *= theta
    for m in range(out.shape[0]):
        out[m] = (c0 * x0[m] + c1 * xm[m] + c2 * x1[m]
                  + h * (c3 * f0[m] + c4 * fm[m] + c5 * f1[m]))


@njit(cache=True)
def _vertex(v0, vm, v1, peak):
    """Where in (0, 1) the parabola through (0, v0), (1/2, vm), (1, v1) peaks, and its gain
    over ``peak`` (relative); (-1, 0) if it does not peak inside."""
    a = 2.0 * (v1 - 2.0 * vm + v0)
    b = 4.0 * vm - 3.0 * v0 - v1
    if a < 0.0:
        s = -b / (2.0 * a)
        if 0.0 < s < 1.0:
            top = v0 - b * b / (4.0 * a)
            return s, (top - peak) / max(abs(peak), 1e-300)
    return -1.0, 0.0


@njit(cache=True)
def _static_inside(h, x0, xm, x1, f0, fm, f1, n_start, u_start, m_normal, m_tang, normal,
                   tang, nb, ns, nsp, strip_f, strip_i, spring_f, reg, dp, fs, xe, fa, peak_fe,
                   peak_fn, peak_util, peak_n):
    """Peaks inside an exponential step whose middle and end are tracked: where the parabola
    through a strip's normal force or friction utilisation at the start, middle and end peaks
    inside the step above the peak so far, the forces at its vertex (on :func:`_static_dense`),
    as :func:`_track_inside` does for Dormand-Prince steps. (Exact points at h/8 and h/4 for
    the caps' transients after the input's kink were tried: no peak changed.)"""
    best_n, gain_n, best_u, gain_u = -1.0, 0.0, -1.0, 0.0
    delta, delta_dot, vt, pos, fe, fn, nrm, tng = fa
    for j in range(ns):
        n0, nmid, n1 = n_start[j], m_normal[j], normal[j]
        s, gain = _vertex(n0, nmid, n1, peak_n[j])
        if gain > gain_n:
            best_n, gain_n = s, gain
        if nmid > 0.0 and n1 > 0.0 and u_start[j] >= 0.0:
            um, u1 = abs(m_tang[j]) / nmid, abs(tang[j]) / n1
            s, gain = _vertex(u_start[j], um, u1, peak_util[j])
            if gain > gain_u:
                best_u, gain_u = s, gain
    for s in (best_n, best_u):
        if s > 0.0:
            _static_dense(s, h, x0, xm, x1, f0, fm, f1, xe)
            kinematics(xe, nb, strip_f, strip_i, spring_f, delta, delta_dot, vt, pos)
            contact_forces(xe, 6 * nb, nb, strip_f, strip_i, spring_f, reg, dp, fs, delta,
                           delta_dot, vt, fe, fn, nrm, tng)
            _track(nsp, ns, fe, fn, nrm, tng, peak_fe, peak_fn, peak_util, peak_n)


@njit(cache=True)
def _in_static(reg, fs, reg_s, fs_s):
    """Whether every spring and strip is in its static regime (see :mod:`.exponential`)."""
    for i in range(reg.shape[0]):
        if reg[i] != reg_s[i]:
            return False
    for j in range(fs.shape[0]):
        if fs[j] != fs_s[j]:
            return False
    return True


@njit(cache=True)
def _mv(a_t, v, out, c0):
    """``out = a[:, c0:] @ v[c0:]`` from ``a_t`` = ``a``'s transpose (``v``'s entries before
    ``c0`` are zero): as a sum of ``a``'s columns, so that the inner loop has no chain of
    dependent additions and compiles to vector instructions (row by row it was bound by the
    additions' latency, ~4 times slower)."""
    n = a_t.shape[1]
    for i in range(n):
        out[i] = 0.0
    for j in range(c0, a_t.shape[0]):
        vj = v[j]
        row = a_t[j]
        for i in range(n):
            out[i] += row[i] * vj


@njit(cache=True, inline="always")
def _remainder_slope(x1, f1, xs, a_m, g0, h, tmp, ay, out):
    """``out = (g(x1) - g0) / h``, the slope of the remainder ``g = f - A (x - x_s)`` from its
    value ``g0`` at the step's start to its value at ``x1`` (rates ``f1``)."""
    nm = a_m.shape[0]
    for m in range(nm):
        tmp[m] = x1[m] - xs[m]
    _mv(a_m, tmp, ay, 0)
    for m in range(nm):
        out[m] = (f1[m] - ay[m] - g0[m]) / h


@njit(cache=True)
def _static_step(t, h, level, ay0, az0, slope_y, slope_z, x, f0, gv0, nb, ns, mass, inertia,
                 strip_f, strip_i, spring_f, reg, dp, dc0, tc0, fs, opt, theta_c, ag_y, ag_z,
                 dt_rec, rtol, atol, xs, mats_t, bmat, gram, rows, q_vel, wind_grad, rates0,
                 wk, x1, xm, f1, fm, gv1, gvm, fa, ma):
    """One exponential step ``[t, t + h]`` in the static regime
    (:mod:`shipblock.section.exponential`), a whole sample interval (``level`` 0) or half of
    one (1), the input ``ay0 + slope_y s`` (and z) over it: predictor, corrector, and two error
    estimates (a second corrector; the remainder's curvature). Returns 0 (taken: ``x1`` the
    state with its energy integrals, ``f1``, ``gv1`` and the force arrays ``fa`` its rates,
    event functions and forces, ``ma`` the middle's forces), 1 (an event function changes sign
    at the middle or the end) or 2 (an error estimate is above the tolerance). ``f0`` and
    ``gv0`` are the rates and event functions at ``x``; ``mats_t`` holds the transposes of
    :attr:`~shipblock.section.exponential.StaticSteps.mats`; ``wk`` (8, 3n) is work space."""
    nm = mats_t.shape[1]
    nsp = spring_f.shape[0]
    nv = 3 * nb
    o_e = nm
    y, g0, c, base, ta, tb, w = wk[0], wk[1], wk[2], wk[3], wk[4], wk[5], wk[6]
    o = 3 * level
    a_m, e_m, p1_m, pc_m, eh_m, p1h_m, pch_m = (
        mats_t[0], mats_t[1 + o], mats_t[2 + o], mats_t[3 + o], mats_t[4 + o], mats_t[5 + o],
        mats_t[6 + o])
    q_m = mats_t[10 + level]
    gram_l = gram[level]
    rows_l = rows[level]
    for m in range(nm):
        y[m] = x[m] - xs[m]
    _mv(a_m, y, ta, 0)
    for m in range(nm):
        g0[m] = f0[m] - ta[m]
    _mv(e_m, y, base, 0)
    _mv(p1_m, g0, ta, nv)
    for m in range(nm):
        base[m] += ta[m]
        c[m] = bmat[m, 0] * slope_y + bmat[m, 1] * slope_z
    # predictor: the remainder frozen, the input's slope exact
    _mv(pc_m, c, tb, nv)
    for m in range(nm):
        x1[m] = xs[m] + base[m] + tb[m]
    for m in range(nm, x.shape[0]):
        x1[m] = x[m]
    delta, delta_dot, vt, pos, fe, fn, normal, tang = fa
    rhs(t + h, x1, nb, ns, mass, inertia, strip_f, strip_i, spring_f, reg, dp, fs, opt, ag_y,
        ag_z, dt_rec, delta, delta_dot, vt, pos, fe, fn, normal, tang, f1)
    # corrector: the remainder linear over the step, through its value at the predicted end
    _remainder_slope(x1, f1, xs, a_m, g0, h, tb, ta, c)
    _mv(pc_m, c, tb, nv)
    for m in range(nm):
        x1[m] = xs[m] + base[m] + tb[m]
    rhs(t + h, x1, nb, ns, mass, inertia, strip_f, strip_i, spring_f, reg, dp, fs, opt, ag_y,
        ag_z, dt_rec, delta, delta_dot, vt, pos, fe, fn, normal, tang, f1)
    # error estimate: a second corrector from the rates at the corrected end
    _remainder_slope(x1, f1, xs, a_m, g0, h, tb, ta, w)
    _mv(pc_m, w, ta, nv)
    err = 0.0
    for m in range(nm):
        sc = atol + rtol * max(abs(x[m]), abs(x1[m]))
        err += ((xs[m] + base[m] + ta[m] - x1[m]) / sc) ** 2
    if not (math.sqrt(err / nm) <= STATIC_SAFETY):
        return 2
    _event_values_of(t + h, x1, nb, ns, strip_f, strip_i, spring_f, reg, dp, dc0, tc0, fs, opt,
                     delta, delta_dot, vt, fe, fn, normal, tang, theta_c, gv1)
    # the middle: exp(A h/2) y0 + (h/2) phi1 g0 + (h/2)^2 phi2 c
    _mv(eh_m, y, ta, 0)
    _mv(p1h_m, g0, tb, nv)
    for m in range(nm):
        xm[m] = xs[m] + ta[m] + tb[m]
    _mv(pch_m, c, ta, nv)
    for m in range(nm):
        xm[m] += ta[m]
    for m in range(nm, x.shape[0]):
        xm[m] = x[m]
    m_delta, m_delta_dot, m_vt, m_pos, m_fe, m_fn, m_normal, m_tang = ma
    rhs(t + 0.5 * h, xm, nb, ns, mass, inertia, strip_f, strip_i, spring_f, reg, dp, fs, opt,
        ag_y, ag_z, dt_rec, m_delta, m_delta_dot, m_vt, m_pos, m_fe, m_fn, m_normal, m_tang, fm)
    _event_values_of(t + 0.5 * h, xm, nb, ns, strip_f, strip_i, spring_f, reg, dp, dc0, tc0, fs,
                     opt, m_delta, m_delta_dot, m_vt, m_fe, m_fn, m_normal, m_tang, theta_c, gvm)
    # the remainder's curvature, which a remainder linear over the step misses: its value d
    # at the middle against the line through the ends'; the quadratic 4 d theta (1 - theta)
    # left out moves y1 by Q d (exactly, stiff modes damped as they are)
    for m in range(nm):
        tb[m] = xm[m] - xs[m]
    _mv(a_m, tb, ta, 0)
    for m in range(nm):
        tb[m] = fm[m] - ta[m] - (g0[m] + 0.5 * h * c[m]) if m >= nv else 0.0
    _mv(q_m, tb, ta, nv)
    err = 0.0
    for m in range(nm):
        sc = atol + rtol * max(abs(x[m]), abs(x1[m]))
        err += (ta[m] / sc) ** 2
    if not (math.sqrt(err / nm) <= STATIC_SAFETY):
        return 2
    for q in range(gv0.shape[0]):
        if (gvm[q] <= 0.0 or gv1[q] <= 0.0) and (
                gv0[q] > 0.0 or (gv0[q] == 0.0 and _is_gap(q, nsp, reg))):
            return 1
    # energy integrals over the step, w = (y0, g0, c) without g0's and c's zero position rows
    nr = nm - nv
    for m in range(nm):
        w[m] = y[m]
    for m in range(nr):
        w[nm + m] = g0[nv + m]
        w[nm + nr + m] = c[nv + m]
    nw = nm + 2 * nr
    r0 = 0.0
    r1 = 0.0
    r2 = 0.0
    r3 = 0.0
    r4 = 0.0
    quad = 0.0
    for i in range(nw):
        wi = w[i]
        r0 += rows_l[0, i] * wi
        r1 += rows_l[1, i] * wi
        r2 += rows_l[2, i] * wi
        r3 += rows_l[3, i] * wi
        r4 += rows_l[4, i] * wi
    # the damping's quadratic form w' G w, as w . (G' w) (G' by columns: _mv)
    _mv(gram_l, w, wk[7], 0)
    for i in range(nw):
        quad += w[i] * wk[7][i]
    ground = -(ay0 * r0 + slope_y * r1 + az0 * r2 + slope_z * r3)
    # what the geometry adds to the damping and wind rates beyond their forms: Simpson
    rem_d = 0.0
    rem_w = 0.0
    for node in range(3):
        if node == 0:
            xx, ff, wt = x, f0, 1.0
        elif node == 1:
            xx, ff, wt = xm, fm, 4.0
        else:
            xx, ff, wt = x1, f1, 1.0
        lin_w = rates0[0]
        for m in range(nm):
            lin_w += wind_grad[m] * (xx[m] - xs[m])
        qf = rates0[1]
        for i in range(nv):
            s = 0.0
            for j in range(nv):
                s += q_vel[i, j] * (xx[nv + j] - xs[nv + j])
            qf += (xx[nv + i] - xs[nv + i]) * s
        rem_w += wt * (ff[o_e + 1] - lin_w)
        rem_d += wt * (ff[o_e + 2] - qf)
    x1[o_e] = x[o_e] + ground
    x1[o_e + 1] = x[o_e + 1] + rates0[0] * h + r4 + h / 6.0 * rem_w
    x1[o_e + 2] = x[o_e + 2] + rates0[1] * h + quad + h / 6.0 * rem_d
    x1[o_e + 3] = x[o_e + 3] + h / 6.0 * (f0[o_e + 3] + 4.0 * fm[o_e + 3] + f1[o_e + 3])
    return 0
