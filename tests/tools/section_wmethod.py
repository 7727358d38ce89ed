"""Prototype (not the solver): linearly implicit (Rosenbrock and Rosenbrock-W) steps for the
dock-section model, with a Jacobian computed only at events, measured against the
Dormand-Prince kernel (issue 29's speed part). Findings: ``docs/theory/section_wmethod_notes.md``.

Methods (:data:`TABLEAUS`): ROS34PW2 (Rang and Angermann 2005: 4 stages, order 3 with an
embedded order 2, L-stable, stiffly accurate, and a *W-method*: it keeps its order with any
matrix ``J`` in ``W = I - h gamma J``); ROS34PW3 (same paper: order 4 with the exact Jacobian, 3
as a W-method, A-stable); RODAS4 (Hairer and Wanner 1996: order 4 with the exact Jacobian, not a
W-method, for comparison with the RODAS4 prototype of ``docs/theory/section.md`` that made a new
Jacobian at every step). All in the transformed variables of Hairer and Wanner (1996, IV.7,
eq. 7.25), which need no product with ``J``:

.. math::

    \Big(\frac{I}{h\gamma} - J\Big) U_i = f\Big(t + \alpha_i h,\; x_0 + \sum_{j<i}
    a_{ij} U_j\Big) + \sum_{j<i} \frac{c_{ij}}{h} U_j + \gamma_i h f_t, \qquad
    x_1 = x_0 + \sum_i m_i U_i,

with ``(a_ij) = alpha Gamma^-1``, ``(c_ij) = diag(1/gamma) - Gamma^-1``, ``m = b Gamma^-1``,
``gamma_i`` the sums of ``Gamma``'s rows and ``f_t`` the time derivative of the rates (the
ground motion's slope over the sample interval). Checked on a small nonlinear problem: global
orders 3.0 (ROS34PW2, also with a wrong ``J``), 3.6-3.8 (ROS34PW3) and 4.0 (RODAS4).

``J`` is a finite-difference Jacobian computed only at the start and after every event (with
the regime sums of :func:`shipblock.section._forces.stage_rhs`) and reused between events. It
is kept to *groups* of states: ``"lines"`` - one group per moving block line (its 6 positions
and velocities and the stick-spring extensions of its strips), the ship treated explicitly
(``W = I`` there) and the coupling between the ship and the lines left out; ``"lines+ship"`` -
also the ship's 6 states (and the stick springs of strips on fixed lines) as a group;
``"full"`` - all 6 n_b + n_s mechanical states, plus the energy integrals' rows. Groups of one
colour (the lines: no line's rate depends on another line's state) are differenced together,
so ``"lines"`` costs 8 evaluations per event, ``"full"`` 30. ``I/(h gamma) - J`` is factorised
per group (LU with partial pivoting) whenever ``h`` changes; the full one through its Schur
complement on the velocities and stick springs (18 x 18 for the benchmark, :func:`_factor`).

Dense output for the event location: the cubic Hermite interpolant of ``x_0, x_1`` and the
rates there (both evaluated anyway: ``f(x_0)`` is the first stage, ``f(x_1)`` the event
functions' forces), order 3. The events, their transitions and the settling after them are
the kernel's (:func:`shipblock.section._kernel._event_values_of`, ``_transition``,
``_settle``), unchanged.

Run: ``python tests/tools/section_wmethod.py`` (prints the table of the notes; ~1.5 min).
"""

from __future__ import annotations

import math
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

# --- the methods, in the transformed form (a, c, m, e, stage times, gamma, error exponent) -----


def _transformed(gam, alpha, b, bhat, order_est):
    """``(a, c, m, e, stage times, sums of Gamma's rows, gamma, 1 / (order_est + 1))`` from a
    method's ``Gamma``, ``alpha``, ``b`` and embedded ``bhat`` (Hairer and Wanner 1996, IV.7,
    eq. 7.25)."""
    gi = np.linalg.inv(gam)
    return (np.tril(alpha @ gi, -1), np.tril(np.diag(1.0 / np.diag(gam)) - gi, -1), b @ gi,
            (b - bhat) @ gi, alpha.sum(axis=1), gam.sum(axis=1), float(gam[0, 0]),
            1.0 / (order_est + 1.0))


def _tableaus():
    # ROS34PW2 (Rang and Angermann 2005): order 3 (also as a W-method), embedded 2, L-stable,
    # stiffly accurate
    g = 0.43586652150845900
    pw2 = _transformed(
        np.array([[g, 0.0, 0.0, 0.0], [-0.87173304301691801, g, 0.0, 0.0],
                  [-0.90338057013044082, 0.054180672388095326, g, 0.0],
                  [0.24212380706095346, -1.2232505839045147, 0.54526025533510214, g]]),
        np.array([[0.0, 0.0, 0.0, 0.0], [0.87173304301691801, 0.0, 0.0, 0.0],
                  [0.84457060015369423, -0.11299064236484185, 0.0, 0.0], [0.0, 0.0, 1.0, 0.0]]),
        np.array([0.24212380706095346, -1.2232505839045147, 1.5452602553351020, g]),
        np.array([0.37810903145819369, -0.096042292212423178, 0.5, 0.21793326075422950]), 2)
    # ROS34PW3 (same paper): order 4 with the exact Jacobian, 3 as a W-method, embedded 3,
    # A-stable
    g = 1.0685790213016289
    pw3 = _transformed(
        np.array([[g, 0.0, 0.0, 0.0], [-2.5155456020628817, g, 0.0, 0.0],
                  [-0.87991339217106512, -0.96014187766190695, g, 0.0],
                  [-0.41731389379448741, 0.41091047035857703, -1.3558873204765276, g]]),
        np.array([[0.0, 0.0, 0.0, 0.0], [2.5155456020628817, 0.0, 0.0, 0.0],
                  [0.50777280103144085, 0.75, 0.0, 0.0],
                  [0.13959081404277204, -0.33111001065419338, 0.82040559712714178, 0.0]]),
        np.array([0.22047681286931747, 0.0027828278331185935, 0.0071844787635140066,
                  0.76955588053404989]),
        np.array([0.31300297285209688, -0.28946895245112692, 0.97646597959903003, 0.0]), 3)
    # RODAS4 (Hairer and Wanner 1996, VI.4): order 4 with the exact Jacobian (not a W-method),
    # embedded 3, L-stable, stiffly accurate; given in the transformed form
    a = np.zeros((6, 6))
    c = np.zeros((6, 6))
    a[1, 0] = 1.544
    a[2, :2] = 0.9466785280815826, 0.2557011698983284
    a[3, :3] = 3.314825187068521, 2.896124015972201, 0.9986419139977817
    a[4, :4] = 1.221224509226641, 6.019134481288629, 12.53708332932087, -0.687886036105895
    a[5, :5] = 1.221224509226641, 6.019134481288629, 12.53708332932087, -0.687886036105895, 1.0
    c[1, 0] = -5.6688
    c[2, :2] = -2.430093356833875, -0.2063599157091915
    c[3, :3] = -0.1073529058151375, -9.594562251023355, -20.47028614809616
    c[4, :4] = 7.496443313967647, -10.24680431464352, -33.99990352819905, 11.7089089320616
    c[5, :5] = (8.083246795921522, -7.981132988064893, -31.52159432874371, 16.31930543123136,
                -6.058818238834054)
    rodas4 = (a, c, np.array([*a[4, :4], 1.0, 1.0]), np.array([0.0, 0.0, 0.0, 0.0, 0.0, 1.0]),
              np.array([0.0, 0.386, 0.21, 0.63, 1.0, 1.0]),
              np.array([0.25, -0.1043, 0.1035, -0.0362, 0.0, 0.0]), 0.25, 0.25)
    return {"ROS34PW2": pw2, "ROS34PW3": pw3, "RODAS4": rodas4}


#: name -> (a, c, m, e, stage times, sums of Gamma's rows, gamma, error exponent)
TABLEAUS = _tableaus()


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
              dt_rec, sums, gidx, gsize, gcol, jac, jace, xp, fp):
    """Forward differences of :func:`stage_rhs` (the current regimes) for every group's block,
    and in ``jace`` the energy integrals' rows (used with the full Jacobian only); ``f0`` is
    ``stage_rhs`` at ``x``. Returns the number of evaluations."""
    o_e = 6 * nb + ns
    n_eval = 0
    stage_n = np.zeros(ns)  # stage_rhs's strip forces (not used here)
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
                      ag_z, dt_rec, sums, fp, stage_n)
            n_eval += 1
            for g in range(gidx.shape[0]):
                if gcol[g] == colour and p < gsize[g]:
                    m = gidx[g, p]
                    e = xp[m] - x[m]
                    for r in range(gsize[g]):
                        jac[g, r, p] = (fp[gidx[g, r]] - f0[gidx[g, r]]) / e
                    for r in range(jace.shape[0]):
                        jace[r, m] = (fp[o_e + r] - f0[o_e + r]) / e
    return n_eval


@njit(cache=True)
def _lu(a, n, piv):
    """LU factorisation with partial pivoting of ``a[:n, :n]``, in place."""
    for k in range(n):
        p = k
        for r in range(k + 1, n):
            if abs(a[r, k]) > abs(a[p, k]):
                p = r
        piv[k] = p
        if p != k:
            for c in range(n):
                a[k, c], a[p, c] = a[p, c], a[k, c]
        inv = 1.0 / a[k, k]
        for r in range(k + 1, n):
            a[r, k] *= inv
            f = a[r, k]
            if f != 0.0:
                for c in range(k + 1, n):
                    a[r, c] -= f * a[k, c]


@njit(cache=True)
def _lu_solve(a, n, piv, z):
    """Solve with the factors of :func:`_lu`, ``z`` in place."""
    for k in range(n):
        p = piv[k]
        if p != k:
            z[k], z[p] = z[p], z[k]
    for r in range(n):
        s = z[r]
        for c in range(r):
            s -= a[r, c] * z[c]
        z[r] = s
    for r in range(n - 1, -1, -1):
        s = z[r]
        for c in range(r + 1, n):
            s -= a[r, c] * z[c]
        z[r] = s / a[r, r]


@njit(cache=True)
def _factor(h, gamma, jac, gsize, lu, piv, nq, reduced):
    """Factorise ``I / (h gamma) - J`` of every group; with ``reduced`` (one group of all the
    mechanical states, positions first: ``q' = v`` exactly) only its Schur complement on the
    velocities and stick springs ``z``: ``I / (h gamma) - J_zz - h gamma J_zq P`` (``P`` takes
    a velocity to its position), since the position rows give ``U_q = h gamma (b_q + U_v)``."""
    d = 1.0 / (h * gamma)
    if reduced:
        hg = h * gamma
        nz = gsize[0] - nq
        for r in range(nz):
            for c in range(nz):
                v = jac[0, nq + r, nq + c]
                if c < nq:
                    v += hg * jac[0, nq + r, c]
                lu[0, r, c] = -v
            lu[0, r, r] += d
        _lu(lu[0], nz, piv[0])
        return
    for g in range(jac.shape[0]):
        n = gsize[g]
        for r in range(n):
            for c in range(n):
                lu[g, r, c] = -jac[g, r, c]
            lu[g, r, r] += d
        _lu(lu[g], n, piv[g])


@njit(cache=True)
def _solve(h, gamma, b, out, gidx, gsize, lu, piv, grouped, z, jac, jace, nq, reduced):
    """``out = (I / (h gamma) - J)^-1 b``: ``h gamma b`` outside the groups (see
    :func:`_factor` for ``reduced``)."""
    hg = h * gamma
    for m in range(b.shape[0]):
        if not grouped[m]:
            out[m] = hg * b[m]
    if reduced:
        nz = gsize[0] - nq
        for r in range(nz):
            s = b[nq + r]
            for c in range(nq):
                s += hg * jac[0, nq + r, c] * b[c]
            z[r] = s
        _lu_solve(lu[0], nz, piv[0], z)
        for r in range(nz):
            out[nq + r] = z[r]
        for c in range(nq):
            out[c] = hg * (b[c] + z[c])
        # the energy integrals' rows: U_e = h gamma (b_e + J_e U) (nothing depends on them)
        o_e = gsize[0]
        for r in range(jace.shape[0]):
            s = b[o_e + r]
            for c in range(o_e):
                s += jace[r, c] * out[c]
            out[o_e + r] = hg * s
        return
    for g in range(gidx.shape[0]):
        n = gsize[g]
        for r in range(n):
            z[r] = b[gidx[g, r]]
        _lu_solve(lu[g], n, piv[g], z)
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
          ev_kind, ev_index, acc, peak_fe, peak_fn, peak_util, peak_n, gidx, gsize, gcol, reduced,
          hold, ta, tc, tm, te, tt, tg, gamma, expo, n_ctl, cnt):
    """:func:`shipblock.section._kernel.run` with Rosenbrock(-W) steps (the same arguments and
    returns, plus the groups, ``reduced`` (see :func:`_factor`), ``hold``: keep the step, and
    so the factorisation, while the controller would enlarge it by less than that factor; the
    method's :data:`TABLEAUS` entry; ``n_ctl``: the error is controlled on the first ``n_ctl``
    states (``6 n_b + n_s`` as in the kernel, or all: also the energy integrals); and ``cnt``:
    Jacobians, their evaluations, factorisations)."""
    ns = strip_i.shape[0]
    stage_n = np.zeros(ns)  # stage_rhs's strip forces (not used here)
    nsp = spring_f.shape[0]
    nx = x.shape[0]
    n_err = 6 * nb + ns
    nq = 3 * nb
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
    n_st = tm.shape[0]
    us = np.zeros((n_st, nx))
    ftv = np.zeros(nx)
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
    jace = np.zeros((nx - n_err, n_err))
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
                      ag_z, dt_rec, sums, f0, stage_n)
            cnt[1] += _jacobian(t, x, f0, nb, ns, mass, inertia, strip_f, strip_i, spring_f, fs,
                                opt, ag_y, ag_z, dt_rec, sums, gidx, gsize, gcol, jac, jace, y,
                                fp)
            cnt[0] += 1
            stale = False
            h_lu = -1.0
        if h != h_lu:
            _factor(h, gamma, jac, gsize, lu, piv, nq, reduced)
            cnt[2] += 1
            h_lu = h
        # f's time derivative (the ground motion's slope over this sample interval)
        ks = int(math.floor(t / dt_rec + 1e-9))
        say, saz = 0.0, 0.0
        if ks + 1 < ag_y.shape[0]:
            say = (ag_y[ks + 1] - ag_y[ks]) / dt_rec
            saz = (ag_z[ks + 1] - ag_z[ks]) / dt_rec
        wdot = 0.0
        for bo in range(nb):
            ftv[nq + 3 * bo] = -say
            ftv[nq + 3 * bo + 1] = -saz
            wdot -= mass[bo] * (say * x[nq + 3 * bo] + saz * x[nq + 3 * bo + 1])
        ftv[6 * nb + ns] = wdot
        # the stages
        for i in range(n_st):
            if i == 0:
                for m in range(nx):
                    b[m] = k1[m]
            else:
                for m in range(nx):
                    sy = x[m]
                    sb = 0.0
                    for j in range(i):
                        sy += ta[i, j] * us[j, m]
                        sb += tc[i, j] * us[j, m]
                    y[m] = sy
                    b[m] = sb / h
                stage_rhs(t + tt[i] * h, y, nb, ns, mass, inertia, strip_f, strip_i, spring_f, fs,
                          opt, ag_y, ag_z, dt_rec, sums, fst, stage_n)
                for m in range(nx):
                    b[m] += fst[m]
            if tg[i] != 0.0:
                for m in range(nx):
                    b[m] += tg[i] * h * ftv[m]
            _solve(h, gamma, b, us[i], gidx, gsize, lu, piv, grouped, z, jac, jace, nq,
                   reduced)
        err = 0.0
        for m in range(nx):
            sy = x[m]
            for i in range(n_st):
                sy += tm[i] * us[i, m]
            x1[m] = sy
        for m in range(n_ctl):
            e = 0.0
            for i in range(n_st):
                e += te[i] * us[i, m]
            sc = atol + rtol * max(abs(x[m]), abs(x1[m]))
            err += (e / sc) ** 2
        err = math.sqrt(err / n_ctl)
        if not (err <= 1.0):
            n_rej += 1
            if err != err:
                h *= 0.1
            else:
                h *= max(0.1, 0.9 * err ** -expo)
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
        h_new = h * min(5.0, max(0.2, 0.9 * max(err, 1e-10) ** -expo))
        h = h_lu if (not stale and h_lu <= h_new <= hold * h_lu) else h_new
    for i in range(nsp):
        if reg[i] == K.R_FREE and dc0[i] > dp[i]:
            rem = cap_surface(spring_f[i, K.PF_K], spring_f[i, K.PF_C], dp[i], dc0[i], tc0[i],
                              t) - dp[i]
            acc[K.A_CAP_RELAX] -= 0.5 * spring_f[i, K.PF_K] * rem * rem
            dc0[i] = dp[i] + rem
            tc0[i] = t
    return t, n_ev, failure, n_hist, n_acc, n_rej


def simulate_w(section, ah, av, dt, rtol, atol, kind="full", hold=1.0, method="ROS34PW2",
               energy_error=False):
    """One run of :func:`run_w` from the static state, as
    :func:`shipblock.section.simulate.simulate_section` makes it (the same energy balance and
    summary); ``kind`` names the Jacobian's groups (:func:`jacobian_groups`; ``"full"`` is
    solved through its Schur complement, :func:`_factor`), ``hold`` see :func:`run_w`,
    ``method`` a :data:`TABLEAUS` key, ``energy_error``: the energy integrals' error controlled
    too. Returns
    ``(SectionResult, counts)`` with the Jacobians, their evaluations and the factorisations."""
    if section.roll_held:
        raise ValueError("the prototype takes q' = v for every position: no held roll")
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
        gidx, gsize, gcol, kind == "full", hold, *TABLEAUS[method],
        x.size if energy_error else 6 * nb + ns, cnt)
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


#: the prototype's variants in the table: (label, Jacobian groups, method)
VARIANTS = (("ROS34PW2 [lines]", "lines", "ROS34PW2"), ("ROS34PW2 [full]", "full", "ROS34PW2"),
            ("ROS34PW3 [full]", "full", "ROS34PW3"), ("RODAS4 [full, at events]", "full", "RODAS4"))


@njit(cache=True)
def _repeat(part, n, t, x, f0, nb, ns, mass, inertia, strip_f, strip_i, spring_f, reg, dp, dc0,
            tc0, fs, opt, theta_c, ag_y, ag_z, dt_rec, sums, gidx, gsize, gcol, jac, jace, lu,
            piv, grouped, z, out, xp, gv):
    """Call one piece of a step ``n`` times (for :func:`part_costs`)."""
    nsp = spring_f.shape[0]
    delta, delta_dot, vt = np.zeros(nsp), np.zeros(nsp), np.zeros(ns)
    pos, fe, fn = np.zeros((nsp, 2)), np.zeros(nsp), np.zeros(nsp)
    normal, tang = np.zeros(ns), np.zeros(ns)
    stage_n = np.zeros(ns)  # stage_rhs's strip forces (not used here)
    for _ in range(n):
        if part == 0:
            stage_rhs(t, x, nb, ns, mass, inertia, strip_f, strip_i, spring_f, fs, opt, ag_y, ag_z,
                      dt_rec, sums, out, stage_n)
        elif part == 1:
            rhs(t, x, nb, ns, mass, inertia, strip_f, strip_i, spring_f, reg, dp, fs, opt, ag_y,
                ag_z, dt_rec, delta, delta_dot, vt, pos, fe, fn, normal, tang, out)
        elif part == 2:
            event_values(t, x, nb, ns, strip_f, strip_i, spring_f, reg, dp, dc0, tc0, fs, opt,
                         delta, delta_dot, vt, pos, fe, fn, normal, tang, theta_c, gv)
        elif part == 3:
            _factor(1e-3, GAMMA_PW2, jac, gsize, lu, piv, 3 * nb, True)
        elif part == 4:
            _solve(1e-3, GAMMA_PW2, f0, out, gidx, gsize, lu, piv, grouped, z, jac, jace, 3 * nb,
                   True)
        else:
            _jacobian(t, x, f0, nb, ns, mass, inertia, strip_f, strip_i, spring_f, fs, opt, ag_y,
                      ag_z, dt_rec, sums, gidx, gsize, gcol, jac, jace, xp, out)


GAMMA_PW2 = TABLEAUS["ROS34PW2"][6]


def part_costs(n=20000):
    """CPU microseconds per call of the pieces of a step at the benchmark's static state (the
    full Jacobian's Schur complement for the factorisation and the solve)."""
    dock = navy_dock()
    h, v, dt = record()
    asm = assemble(dock, DEFAULT_SEPARATION_HEIGHT)
    init = static_state(asm)
    nb, ns = asm.n_bodies, asm.n_strips
    nsp = asm.spring_f.shape[0]
    x, reg, fs = init.x.copy(), init.regime.copy(), init.friction.copy()
    dp, dc0, tc0 = np.zeros(nsp), np.zeros(nsp), np.zeros(nsp)
    sums = np.zeros((ns, N_RS))
    regime_sums(asm.strip_i, asm.spring_f, reg, dp, sums)
    gidx, gsize, gcol = jacobian_groups(asm, "full")
    nm = int(gsize[0])
    jac, jace = np.zeros((1, nm, nm)), np.zeros((x.size - nm, nm))
    lu, piv = np.zeros((1, nm, nm)), np.zeros((1, nm), np.int64)
    grouped = np.zeros(x.size, np.bool_)
    grouped[:nm] = True
    f0, out, xp = np.zeros(x.size), np.zeros(x.size), np.zeros(x.size)
    gv = np.zeros(2 * nsp + ns + nb - 1 + 4)
    args = (0.1, x, f0, nb, ns, asm.mass, asm.inertia, asm.strip_f, asm.strip_i, asm.spring_f,
            reg, dp, dc0, tc0, fs, asm.opt, asm.theta_c, h, v, dt, sums, gidx, gsize, gcol, jac,
            jace, lu, piv, grouped, np.zeros(nm), out, xp, gv)
    stage_rhs(0.1, x, nb, ns, asm.mass, asm.inertia, asm.strip_f, asm.strip_i, asm.spring_f, fs,
              asm.opt, h, v, dt, sums, f0, np.zeros(ns))
    names = ("stage_rhs", "rhs", "event_values", "factorisation (18 x 18 Schur complement)",
             "solve (Schur complement)", "Jacobian (30 differences)")
    out_us = {}
    for part, name in enumerate(names):
        _repeat(part, 10, *args)  # compile / warm
        m = n // 30 if part == 5 else n
        best = BIG
        for _ in range(3):
            c0 = time.process_time()
            _repeat(part, m, *args)
            best = min(best, time.process_time() - c0)
        out_us[name] = 1e6 * best / m
    return out_us


def main(variants=VARIANTS, tolerances=((1e-4, 1e-7), (1e-5, 1e-8), (1e-6, 1e-9)), repeats=3):
    """Print the table (markdown) and the cost of the pieces of a step."""
    print("CPU us per call:", {k: round(v, 3) for k, v in part_costs().items()}, flush=True)
    dock = navy_dock()
    h, v, dt = record()
    simulate_section(dock, h[:400], v[:400], dt)  # compile
    for _, kind, method in variants:
        simulate_w(dock, h[:400], v[:400], dt, 1e-6, 1e-9, kind, method=method)
    ref = simulate_section(dock, h, v, dt, rtol=1e-10, atol=1e-13)
    print("reference (DOPRI5, rtol 1e-10, atol 1e-13):", ref.stats,
          {k: ref.summary[k] for k in KEYS}, f"energy {ref.energy['residual']:.1e}")
    print("| method, rtol (atol) | accepted + rejected steps | events | Jacobians (evaluations) "
          "| CPU s | energy residual | sway history | keel peak load | side peak load "
          "| peak sway | peak roll |")
    print("|---|---|---|---|---|---|---|---|---|---|---|")
    for rtol, atol in tolerances:
        rows = [("DOPRI5 (kernel)",
                 lambda: (simulate_section(dock, h, v, dt, rtol=rtol, atol=atol), None))]
        for label, kind, method in variants:
            rows.append((label, lambda kind=kind, method=method: simulate_w(
                dock, h, v, dt, rtol, atol, kind, method=method)))
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
    main()
