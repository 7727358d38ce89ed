"""Prototype (not the solver): a Rosenbrock-W method for the dock-section model, measured
against the Dormand-Prince kernel (issue 29's speed part).

ROS34PW2 (Rang and Angermann 2005: 4 stages, order 3 with an embedded order 2, L-stable,
stiffly accurate, and a *W-method*: it keeps its order with any matrix ``J`` in
``W = I - h gamma J``). Written in the transformed variables of Hairer and Wanner (1996,
IV.7, eq. 7.25), which need no product with ``J``:

.. math::

    \\Big(\\frac{I}{h\\gamma} - J\\Big) U_i = f\\Big(t + \\alpha_i h,\\; x_0 + \\sum_{j<i}
    a_{ij} U_j\\Big) + \\sum_{j<i} \\frac{c_{ij}}{h} U_j, \\qquad
    x_1 = x_0 + \\sum_i m_i U_i,

with ``(a_ij) = alpha Gamma^-1``, ``(c_ij) = diag(1/gamma) - Gamma^-1``, ``m = b Gamma^-1``. The
time derivative of ``f`` (the ground motion, linear between samples) is left out of the matrix,
which a W-method allows.

``J`` is a finite-difference Jacobian computed only at the start and after every event (with
the regime sums of :func:`shipblock.section._forces.stage_rhs`) and reused between events. It
is kept to *groups* of states: ``"lines"`` - one group per moving block line (its 6 positions
and velocities and the stick-spring extensions of its strips), the ship treated explicitly
(``W = I`` there) and the coupling between the ship and the lines left out; ``"lines+ship"`` -
also the ship's 6 states (and the stick springs of strips on fixed lines) as a group;
``"full"`` - one group of all 6 n_b + n_s mechanical states. Groups of one colour (the lines:
no line's rate depends on another line's state) are differenced together, so ``"lines"`` costs
8 evaluations per event, ``"full"`` 30. The matrix ``I/(h gamma) - J`` is factorised per group
(LU with partial pivoting) whenever ``h`` changes.

Dense output for the event location: the cubic Hermite interpolant of ``x_0, x_1`` and the
rates there (both evaluated anyway: ``f(x_0)`` is the first stage, ``f(x_1)`` the event
functions' forces), order 3 like the method. The events, their transitions and the settling
after them are the kernel's (:func:`shipblock.section._kernel._event_values_of`,
``_transition``, ``_settle``), unchanged.

Run: ``python tests/tools/section_wmethod.py`` (prints the table of
``docs/theory/section_wmethod_notes.md``; a few minutes).
"""

from __future__ import annotations

import math
import sys
import time

import numpy as np
from numba import njit

from shipblock.bench.section import navy_dock, record
from shipblock.section import _kernel as K
from shipblock.section._forces import N_RS, regime_sums, rhs, stage_rhs
from shipblock.section._kernel import (BIG, EV_OVERTURN, EV_STALL, _event_values_of, _log,
                                       _settle, _track, _transition, cap_surface,
                                       contact_forces, event_values, kinematics)
from shipblock.section.model import assemble, static_state
from shipblock.section.simulate import (DEFAULT_SEPARATION_HEIGHT, _result, energy_terms,
                                        simulate_section)

# --- ROS34PW2 (Rang and Angermann 2005, table of ROS34PW2), transformed to (a, c, m) ---------
GAMMA = 0.43586652150845900
_GAM = np.array([[GAMMA, 0.0, 0.0, 0.0],
                 [-0.87173304301691801, GAMMA, 0.0, 0.0],
                 [-0.90338057013044082, 0.054180672388095326, GAMMA, 0.0],
                 [0.24212380706095346, -1.2232505839045147, 0.54526025533510214, GAMMA]])
_ALPHA = np.array([[0.0, 0.0, 0.0, 0.0],
                   [0.87173304301691801, 0.0, 0.0, 0.0],
                   [0.84457060015369423, -0.11299064236484185, 0.0, 0.0],
                   [0.0, 0.0, 1.0, 0.0]])
_B = np.array([0.24212380706095346, -1.2232505839045147, 1.5452602553351020, GAMMA])
_BHAT = np.array([0.37810903145819369, -0.096042292212423178, 0.5, 0.21793326075422950])
_GI = np.linalg.inv(_GAM)
_AT = np.tril(_ALPHA @ _GI, -1)
_CT = np.tril(np.diag(1.0 / np.diag(_GAM)) - _GI, -1)
_M = _B @ _GI
_ME = (_B - _BHAT) @ _GI  # the error estimate: order 3 minus order 2
_C = _ALPHA.sum(axis=1)  # stage times
A21, A31, A32, A41, A42, A43 = _AT[1, 0], _AT[2, 0], _AT[2, 1], _AT[3, 0], _AT[3, 1], _AT[3, 2]
C21, C31, C32, C41, C42, C43 = _CT[1, 0], _CT[2, 0], _CT[2, 1], _CT[3, 0], _CT[3, 1], _CT[3, 2]
M1, M2, M3, M4 = _M
E1, E2, E3, E4 = _ME
T2, T3, T4 = _C[1], _C[2], _C[3]


def jacobian_groups(asm, kind="lines"):
    """State indices of every group of the approximate Jacobian, their sizes and colours (see the
    module's text); returns ``(gidx, gsize, gcolour)``."""
    nb, ns = asm.n_bodies, asm.n_strips
    if kind == "full":
        idx = [list(range(6 * nb + ns))]
        colour = [0]
    elif kind in ("lines", "lines+ship"):
        owner = [int(c) if c >= 0 else int(s) for c, s in asm.strip_i[:, :2]]
        idx, colour = [], []
        first = 0 if kind == "lines+ship" else 1
        for b in range(first, nb):
            idx.append([3 * b, 3 * b + 1, 3 * b + 2, 3 * nb + 3 * b, 3 * nb + 3 * b + 1,
                        3 * nb + 3 * b + 2] + [6 * nb + j for j in range(ns) if owner[j] == b])
            colour.append(1 if b == 0 else 0)  # the ship's rows see every line: its own colour
    else:
        raise ValueError(f"kind must be 'lines', 'lines+ship' or 'full', got {kind!r}")
    gmax = max(len(g) for g in idx)
    gidx = np.full((len(idx), gmax), -1, np.int64)
    for g, ii in enumerate(idx):
        gidx[g, :len(ii)] = ii
    return gidx, np.array([len(g) for g in idx], np.int64), np.array(colour, np.int64)


@njit(cache=True)
def _jacobian(t, x, f0, nb, ns, mass, inertia, strip_f, strip_i, spring_f, fs, opt, ag_y, ag_z,
              dt_rec, sums, gidx, gsize, gcol, jac, xp, fp):
    """Forward differences of :func:`stage_rhs` (the current regimes) for every group's block;
    ``f0`` is ``stage_rhs`` at ``x``. Returns the number of evaluations."""
    n_eval = 0
    for colour in range(gcol.max() + 1):
        width = 0
        for g in range(gidx.shape[0]):
            if gcol[g] == colour:
                width = max(width, gsize[g])
        for p in range(width):
            for m in range(x.shape[0]):
                xp[m] = x[m]
            for g in range(gidx.shape[0]):
                if gcol[g] == colour and p < gsize[g]:
                    m = gidx[g, p]
                    xp[m] = x[m] + 1e-8 * max(abs(x[m]), 1e-3)
            stage_rhs(t, xp, nb, ns, mass, inertia, strip_f, strip_i, spring_f, fs, opt, ag_y,
                      ag_z, dt_rec, sums, fp)
            n_eval += 1
            for g in range(gidx.shape[0]):
                if gcol[g] == colour and p < gsize[g]:
                    m = gidx[g, p]
                    e = xp[m] - x[m]
                    for r in range(gsize[g]):
                        jac[g, r, p] = (fp[gidx[g, r]] - f0[gidx[g, r]]) / e
    return n_eval


@njit(cache=True)
def _factor(h, jac, gsize, lu, piv):
    """LU (partial pivoting) of ``I / (h gamma) - J`` of every group."""
    d = 1.0 / (h * GAMMA)
    for g in range(jac.shape[0]):
        n = gsize[g]
        for r in range(n):
            for c in range(n):
                lu[g, r, c] = -jac[g, r, c]
            lu[g, r, r] += d
        for k in range(n):
            p = k
            for r in range(k + 1, n):
                if abs(lu[g, r, k]) > abs(lu[g, p, k]):
                    p = r
            piv[g, k] = p
            if p != k:
                for c in range(n):
                    lu[g, k, c], lu[g, p, c] = lu[g, p, c], lu[g, k, c]
            inv = 1.0 / lu[g, k, k]
            for r in range(k + 1, n):
                lu[g, r, k] *= inv
                f = lu[g, r, k]
                if f != 0.0:
                    for c in range(k + 1, n):
                        lu[g, r, c] -= f * lu[g, k, c]


@njit(cache=True)
def _solve(h, b, out, gidx, gsize, lu, piv, grouped, z):
    """``out = (I / (h gamma) - J)^-1 b``: ``h gamma b`` outside the groups."""
    hg = h * GAMMA
    for m in range(b.shape[0]):
        if not grouped[m]:
            out[m] = hg * b[m]
    for g in range(gidx.shape[0]):
        n = gsize[g]
        for r in range(n):
            z[r] = b[gidx[g, r]]
        for k in range(n):
            p = piv[g, k]
            if p != k:
                z[k], z[p] = z[p], z[k]
        for r in range(n):
            s = z[r]
            for c in range(r):
                s -= lu[g, r, c] * z[c]
            z[r] = s
        for r in range(n - 1, -1, -1):
            s = z[r]
            for c in range(r + 1, n):
                s -= lu[g, r, c] * z[c]
            z[r] = s / lu[g, r, r]
        for r in range(n):
            out[gidx[g, r]] = z[r]


@njit(cache=True, inline="always")
def _hermite(x0, x1, f0, f1, h, th, out):
    """Cubic Hermite interpolant at ``t0 + th h``."""
    s = 1.0 - th
    h00 = (1.0 + 2.0 * th) * s * s
    h10 = th * s * s * h
    h01 = th * th * (3.0 - 2.0 * th)
    h11 = -th * th * s * h
    for m in range(out.shape[0]):
        out[m] = h00 * x0[m] + h10 * f0[m] + h01 * x1[m] + h11 * f1[m]


@njit(cache=True)
def run_w(x, reg, dp, dc0, tc0, fs, nb, mass, inertia, strip_f, strip_i, spring_f, opt, theta_c,
          ag_y, ag_z, dt_rec, t_end, rtol, atol, h_max, max_events, hist_x, hist_n, hist_t, ev_t,
          ev_kind, ev_index, acc, peak_fe, peak_fn, peak_util, peak_n, gidx, gsize, gcol, cnt):
    """:func:`shipblock.section._kernel.run` with ROS34PW2 steps (the same arguments and
    returns, plus the groups and ``cnt``: Jacobians, their evaluations, factorisations)."""
    ns = strip_i.shape[0]
    nsp = spring_f.shape[0]
    nx = x.shape[0]
    n_err = 6 * nb + ns
    ng = 2 * nsp + ns + (nb - 1) + 4
    delta = np.zeros(nsp)
    delta_dot = np.zeros(nsp)
    vt = np.zeros(ns)
    pos = np.zeros((nsp, 2))
    fe = np.zeros(nsp)
    fn = np.zeros(nsp)
    normal = np.zeros(ns)
    tang = np.zeros(ns)
    k1 = np.zeros(nx)
    k7 = np.zeros(nx)
    fst = np.zeros(nx)
    b = np.zeros(nx)
    u1 = np.zeros(nx)
    u2 = np.zeros(nx)
    u3 = np.zeros(nx)
    u4 = np.zeros(nx)
    y = np.zeros(nx)
    x1 = np.zeros(nx)
    xe = np.zeros(nx)
    f0 = np.zeros(nx)
    fp = np.zeros(nx)
    g0 = np.zeros(ng)
    g1 = np.zeros(ng)
    ge = np.zeros(ng)
    sums = np.zeros((ns, N_RS))
    n_g, gmax = gidx.shape
    jac = np.zeros((n_g, gmax, gmax))
    lu = np.zeros((n_g, gmax, gmax))
    piv = np.zeros((n_g, gmax), np.int64)
    z = np.zeros(gmax)
    grouped = np.zeros(nx, np.bool_)
    for g in range(n_g):
        for r in range(gsize[g]):
            grouped[gidx[g, r]] = True
    t = 0.0
    ev_t[0] = 0.0
    ev_kind[0] = K.EV_START
    ev_index[0] = -1
    n_ev = 1
    n_acc = 0
    n_rej = 0
    h = min(h_max, 1e-4)
    h_lu = -1.0
    kinematics(x, nb, strip_f, strip_i, spring_f, delta, delta_dot, vt, pos)
    contact_forces(x, 6 * nb, nb, strip_f, strip_i, spring_f, reg, dp, fs, delta,
                   delta_dot, vt, fe, fn, normal, tang)
    n_samples = hist_x.shape[0]
    for m in range(nx):
        hist_x[0, m] = x[m]
    for j in range(ns):
        hist_n[0, j] = normal[j]
        hist_t[0, j] = tang[j]
    n_hist = 1
    _track(nsp, ns, fe, fn, normal, tang, peak_fe, peak_fn, peak_util, peak_n)
    event_values(t, x, nb, ns, strip_f, strip_i, spring_f, reg, dp, dc0, tc0, fs, opt, delta,
                 delta_dot, vt, pos, fe, fn, normal, tang, theta_c, g0)
    failure, n_ev = _settle(t, x, nb, ns, nsp, strip_f, strip_i, spring_f, reg, dp, dc0, tc0, fs,
                            opt, delta, delta_dot, vt, pos, fe, fn, normal, tang, theta_c, g0,
                            acc, n_ev, ev_t, ev_kind, ev_index)
    regime_sums(strip_i, spring_f, reg, dp, sums)
    rhs(t, x, nb, ns, mass, inertia, strip_f, strip_i, spring_f, reg, dp, fs, opt, ag_y, ag_z,
        dt_rec, delta, delta_dot, vt, pos, fe, fn, normal, tang, k1)
    event_values(t, x, nb, ns, strip_f, strip_i, spring_f, reg, dp, dc0, tc0, fs, opt, delta,
                 delta_dot, vt, pos, fe, fn, normal, tang, theta_c, g0)
    stale = True  # the Jacobian is redone at the start and after every event
    while t < t_end and failure == 0:
        t_next = (math.floor(t / dt_rec + 1e-9) + 1.0) * dt_rec
        if t_end - t < 1e-12 * dt_rec:
            break
        h = min(h, h_max, t_next - t, t_end - t)
        if h < 1e-15 * max(1.0, t):
            failure = EV_STALL
            break
        if stale:
            stage_rhs(t, x, nb, ns, mass, inertia, strip_f, strip_i, spring_f, fs, opt, ag_y,
                      ag_z, dt_rec, sums, f0)
            cnt[1] += _jacobian(t, x, f0, nb, ns, mass, inertia, strip_f, strip_i, spring_f, fs,
                                opt, ag_y, ag_z, dt_rec, sums, gidx, gsize, gcol, jac, y, fp)
            cnt[0] += 1
            stale = False
            h_lu = -1.0
        if h != h_lu:
            _factor(h, jac, gsize, lu, piv)
            cnt[2] += 1
            h_lu = h
        # the four stages
        _solve(h, k1, u1, gidx, gsize, lu, piv, grouped, z)
        for m in range(nx):
            y[m] = x[m] + A21 * u1[m]
        stage_rhs(t + T2 * h, y, nb, ns, mass, inertia, strip_f, strip_i, spring_f, fs, opt, ag_y,
                  ag_z, dt_rec, sums, fst)
        for m in range(nx):
            b[m] = fst[m] + C21 / h * u1[m]
        _solve(h, b, u2, gidx, gsize, lu, piv, grouped, z)
        for m in range(nx):
            y[m] = x[m] + A31 * u1[m] + A32 * u2[m]
        stage_rhs(t + T3 * h, y, nb, ns, mass, inertia, strip_f, strip_i, spring_f, fs, opt, ag_y,
                  ag_z, dt_rec, sums, fst)
        for m in range(nx):
            b[m] = fst[m] + (C31 * u1[m] + C32 * u2[m]) / h
        _solve(h, b, u3, gidx, gsize, lu, piv, grouped, z)
        for m in range(nx):
            y[m] = x[m] + A41 * u1[m] + A42 * u2[m] + A43 * u3[m]
        stage_rhs(t + T4 * h, y, nb, ns, mass, inertia, strip_f, strip_i, spring_f, fs, opt, ag_y,
                  ag_z, dt_rec, sums, fst)
        for m in range(nx):
            b[m] = fst[m] + (C41 * u1[m] + C42 * u2[m] + C43 * u3[m]) / h
        _solve(h, b, u4, gidx, gsize, lu, piv, grouped, z)
        err = 0.0
        for m in range(nx):
            x1[m] = x[m] + M1 * u1[m] + M2 * u2[m] + M3 * u3[m] + M4 * u4[m]
        for m in range(n_err):
            e = E1 * u1[m] + E2 * u2[m] + E3 * u3[m] + E4 * u4[m]
            sc = atol + rtol * max(abs(x[m]), abs(x1[m]))
            err += (e / sc) ** 2
        err = math.sqrt(err / n_err)
        if not (err <= 1.0):
            n_rej += 1
            if err != err:
                h *= 0.1
            else:
                h *= max(0.1, 0.9 * err ** (-1.0 / 3.0))
            continue
        n_acc += 1
        rhs(t + h, x1, nb, ns, mass, inertia, strip_f, strip_i, spring_f, reg, dp, fs, opt,
            ag_y, ag_z, dt_rec, delta, delta_dot, vt, pos, fe, fn, normal, tang, k7)
        _event_values_of(t + h, x1, nb, ns, strip_f, strip_i, spring_f, reg, dp, dc0, tc0, fs,
                         opt, delta, delta_dot, vt, fe, fn, normal, tang, theta_c, g1)
        # the earliest event in the step, located as the kernel does, on the Hermite cubic
        first = -1
        lo, hi = 0.0, 1.0
        for q in range(ng):
            if g0[q] > 0.0 and g1[q] <= 0.0:
                a, bb, ga, gb = 0.0, 1.0, g0[q], g1[q]
                if first >= 0:
                    _hermite(x, x1, k1, k7, h, hi, xe)
                    event_values(t + hi * h, xe, nb, ns, strip_f, strip_i, spring_f, reg, dp,
                                 dc0, tc0, fs, opt, delta, delta_dot, vt, pos, fe, fn, normal,
                                 tang, theta_c, ge)
                    if ge[q] > 0.0:
                        continue
                    bb, gb = hi, ge[q]
                side = 0
                for _ in range(100):
                    if (bb - a) * h < 1e-12:
                        break
                    mid = (a * gb - bb * ga) / (gb - ga)
                    if not (a + 0.01 * (bb - a) < mid < bb - 0.01 * (bb - a)):
                        mid = min(max(mid, a + 0.01 * (bb - a)), bb - 0.01 * (bb - a))
                    _hermite(x, x1, k1, k7, h, mid, xe)
                    event_values(t + mid * h, xe, nb, ns, strip_f, strip_i, spring_f, reg, dp,
                                 dc0, tc0, fs, opt, delta, delta_dot, vt, pos, fe, fn, normal,
                                 tang, theta_c, ge)
                    gm = ge[q]
                    if gm > 0.0:
                        a, ga = mid, gm
                        if side == 1:
                            gb *= 0.5
                        side = 1
                    else:
                        bb, gb = mid, gm
                        if side == -1:
                            ga *= 0.5
                        side = -1
                first, lo, hi = q, a, bb
        t_new = t + h if first < 0 else t + hi * h
        # histories at the samples passed, on the step's interpolant (x1 is still its end)
        sampled = False
        while n_hist < n_samples and n_hist * dt_rec <= t_new + 1e-12 * dt_rec:
            sampled = True
            ts = n_hist * dt_rec
            _hermite(x, x1, k1, k7, h, min(1.0, max(0.0, (ts - t) / h)), xe)
            kinematics(xe, nb, strip_f, strip_i, spring_f, delta, delta_dot, vt, pos)
            contact_forces(xe, 6 * nb, nb, strip_f, strip_i, spring_f, reg, dp,
                           fs, delta, delta_dot, vt, fe, fn, normal, tang)
            for m in range(nx):
                hist_x[n_hist, m] = xe[m]
            for j in range(ns):
                hist_n[n_hist, j] = normal[j]
                hist_t[n_hist, j] = tang[j]
            n_hist += 1
        if first >= 0:
            _hermite(x, x1, k1, k7, h, hi, xe)
            for m in range(nx):
                x1[m] = xe[m]
        t = t_new
        for m in range(nx):
            x[m] = x1[m]
        if first >= 0 or sampled:
            kinematics(x, nb, strip_f, strip_i, spring_f, delta, delta_dot, vt, pos)
            contact_forces(x, 6 * nb, nb, strip_f, strip_i, spring_f, reg, dp, fs,
                           delta, delta_dot, vt, fe, fn, normal, tang)
        _track(nsp, ns, fe, fn, normal, tang, peak_fe, peak_fn, peak_util, peak_n)
        if first >= 0:
            kind, index = _transition(first, t, x, nb, ns, nsp, strip_f, strip_i, spring_f, reg,
                                      dp, dc0, tc0, fs, delta, normal, tang, acc)
            n_ev = _log(n_ev, t, kind, index, ev_t, ev_kind, ev_index)
            if kind >= EV_OVERTURN:
                failure = kind
                break
            failure, n_ev = _settle(t, x, nb, ns, nsp, strip_f, strip_i, spring_f, reg, dp, dc0,
                                    tc0, fs, opt, delta, delta_dot, vt, pos, fe, fn, normal, tang,
                                    theta_c, g0, acc, n_ev, ev_t, ev_kind, ev_index)
            if failure != 0:
                break
            if n_ev > max_events:
                failure = EV_STALL
                break
        if first < 0:
            for m in range(nx):
                k1[m] = k7[m]
            for q in range(ng):
                g0[q] = g1[q]
        else:
            regime_sums(strip_i, spring_f, reg, dp, sums)
            rhs(t, x, nb, ns, mass, inertia, strip_f, strip_i, spring_f, reg, dp, fs, opt, ag_y,
                ag_z, dt_rec, delta, delta_dot, vt, pos, fe, fn, normal, tang, k1)
            event_values(t, x, nb, ns, strip_f, strip_i, spring_f, reg, dp, dc0, tc0, fs, opt,
                         delta, delta_dot, vt, pos, fe, fn, normal, tang, theta_c, g0)
            stale = True
        h = h * min(5.0, max(0.2, 0.9 * max(err, 1e-10) ** (-1.0 / 3.0)))
    for i in range(nsp):
        if reg[i] == K.R_FREE and dc0[i] > dp[i]:
            rem = cap_surface(spring_f[i, K.PF_K], spring_f[i, K.PF_C], dp[i], dc0[i], tc0[i],
                              t) - dp[i]
            acc[K.A_CAP_RELAX] -= 0.5 * spring_f[i, K.PF_K] * rem * rem
            dc0[i] = dp[i] + rem
            tc0[i] = t
    return t, n_ev, failure, n_hist, n_acc, n_rej


def simulate_w(section, ah, av, dt, rtol, atol, kind="lines"):
    """One run of :func:`run_w` from the static state, as
    :func:`shipblock.section.simulate.simulate_section` makes it (the same energy balance and
    summary); returns ``(SectionResult, counts)`` with the Jacobians, their evaluations and the
    factorisations."""
    asm = assemble(section, DEFAULT_SEPARATION_HEIGHT)
    init = static_state(asm)
    nb, ns = asm.n_bodies, asm.n_strips
    nsp = asm.spring_f.shape[0]
    x, reg, fs = init.x.copy(), init.regime.copy(), init.friction.copy()
    dp, dc0, tc0 = np.zeros(nsp), np.zeros(nsp), np.zeros(nsp)
    e0 = energy_terms(asm, x, reg, dp, dc0, tc0, fs, 0.0)
    n = ah.size
    hist_x, hist_n, hist_t = np.zeros((n, x.size)), np.zeros((n, ns)), np.zeros((n, ns))
    log = 4 * n + 64
    ev_t, ev_kind, ev_index = np.zeros(log), np.zeros(log, np.int64), np.zeros(log, np.int64)
    acc = np.zeros(K.N_ACC)
    peak_fe, peak_fn, peak_util, peak_n = np.zeros(nsp), np.zeros(nsp), np.zeros(ns), np.zeros(ns)
    gidx, gsize, gcol = jacobian_groups(asm, kind)
    cnt = np.zeros(3, np.int64)
    t, n_ev, failure, n_hist, n_acc, n_rej = run_w(
        x, reg, dp, dc0, tc0, fs, nb, asm.mass, asm.inertia, asm.strip_f, asm.strip_i,
        asm.spring_f, asm.opt, asm.theta_c, ah, av, dt, (n - 1) * dt, rtol, atol, dt, 10**6,
        hist_x, hist_n, hist_t, ev_t, ev_kind, ev_index, acc, peak_fe, peak_fn, peak_util, peak_n,
        gidx, gsize, gcol, cnt)
    e1 = energy_terms(asm, x, reg, dp, dc0, tc0, fs, t)
    o = 6 * nb + ns
    w_ground, w_wind, d_damp, d_fric = x[o:o + 4]
    pot = float(np.sum(asm.mass * section.g * (x[1:3 * nb:3] - init.x[1:3 * nb:3])))
    mech = e1["kinetic"] - e0["kinetic"] + pot + e1["elastic"] - e0["elastic"]
    losses = d_damp + acc[K.A_CAP_RELAX] + d_fric + acc[K.A_FRIC_EVENT] + e1["crushing"]
    work = w_ground + w_wind
    scale = max(abs(work), losses, e0["kinetic"], e1["kinetic"], abs(pot),
                abs(e1["elastic"] - e0["elastic"]), 1e-300)
    energy = {"residual": float((work - mech - losses) / scale)}
    m = min(n_ev, log)
    res = _result(section, asm, init, hist_x[:n_hist], hist_n[:n_hist], hist_t[:n_hist], dt, t,
                  ev_t[:m], ev_kind[:m], ev_index[:m], failure, dp, peak_fe, peak_fn, peak_util,
                  peak_n, energy, {"accepted_steps": int(n_acc), "rejected_steps": int(n_rej),
                                   "events": int(n_ev)})
    return res, {"jacobians": int(cnt[0]), "jacobian_evaluations": int(cnt[1]),
                 "factorisations": int(cnt[2])}


KEYS = ("keel_peak_load_per_block", "side0_peak_load_per_block", "side1_peak_load_per_block",
        "peak_sway", "peak_roll")


def errors(res, ref):
    """Relative errors of the summary's peaks and of the sway history (largest difference over
    the record relative to the peak sway) against a reference run."""
    out = {k: abs(res.summary[k] - ref.summary[k]) / abs(ref.summary[k]) for k in KEYS}
    n = min(res.ship_sway.size, ref.ship_sway.size)
    out["sway_history"] = float(np.max(np.abs(res.ship_sway[:n] - ref.ship_sway[:n]))
                                / ref.summary["peak_sway"])
    return out


def _cpu(fn, repeats):
    best, out = BIG, None
    for _ in range(repeats):
        c0 = time.process_time()
        out = fn()
        best = min(best, time.process_time() - c0)
    return best, out


def main(kinds=("lines",), tolerances=((1e-4, 1e-7), (1e-5, 1e-8), (1e-6, 1e-9)), repeats=3):
    dock = navy_dock()
    h, v, dt = record()
    simulate_section(dock, h[:400], v[:400], dt)  # compile
    for kind in kinds:
        simulate_w(dock, h[:400], v[:400], dt, 1e-6, 1e-9, kind)
    ref = simulate_section(dock, h, v, dt, rtol=1e-10, atol=1e-13)
    print("reference (DOPRI5, rtol 1e-10, atol 1e-13):", ref.stats,
          {k: ref.summary[k] for k in KEYS}, f"energy {ref.energy['residual']:.1e}")
    print("| method, rtol (atol) | accepted + rejected steps | events | Jacobians (evaluations) "
          "| CPU s | energy residual | sway history | keel peak load | side peak load "
          "| peak sway | peak roll |")
    print("|---|---|---|---|---|---|---|---|---|---|---|")
    for rtol, atol in tolerances:
        rows = [("DOPRI5", lambda: (simulate_section(dock, h, v, dt, rtol=rtol, atol=atol), None))]
        for kind in kinds:
            rows.append((f"ROS34PW2 [{kind}]",
                         lambda kind=kind: simulate_w(dock, h, v, dt, rtol, atol, kind)))
        for name, fn in rows:
            cpu, (res, cnt) = _cpu(fn, repeats)
            e = errors(res, ref)
            side = max(e["side0_peak_load_per_block"], e["side1_peak_load_per_block"])
            jac = "-" if cnt is None else f"{cnt['jacobians']} ({cnt['jacobian_evaluations']})"
            fail = "" if res.failure is None else f" FAILED {res.failure} at {res.failure_time}"
            print(f"| {name}, {rtol:.0e} ({atol:.0e}){fail} | {res.stats['accepted_steps']} + "
                  f"{res.stats['rejected_steps']} | {res.stats['events']} | {jac} | {cpu:.3f} | "
                  f"{res.energy['residual']:.1e} | {e['sway_history']:.1e} | "
                  f"{e['keel_peak_load_per_block']:.1e} | {side:.1e} | {e['peak_sway']:.1e} | "
                  f"{e['peak_roll']:.1e} |", flush=True)


if __name__ == "__main__":
    main(kinds=tuple(sys.argv[1:]) or ("lines",))
