"""Prototype (not the solver): exponential steps of the dock section in its static regime, one
step per input sample, measured against the Dormand-Prince kernel (issue 29's speed part).
Findings: ``docs/theory/section_wmethod_notes.md`` (section *Exponential steps*). The kernel
now takes such steps itself (:mod:`shipblock.section.exponential`); this script keeps the first
measurement, against Dormand-Prince throughout.

While every spring keeps the regime it has at rest (closed, elastic) and every loaded strip
sticks, the section's equations are linear apart from the large-rotation geometry and the
vertical ground acceleration's product with the rotations. Write them as

.. math::

    \\dot y = A y + g(t, y), \\qquad y = x - x_s,

with ``A`` the Jacobian at the static state ``x_s`` (central differences of
:func:`shipblock.section._forces.rhs`, once per dock) and ``g = f - A y`` the ground motion,
gravity and wind and the small nonlinear remainder. Over a sample interval the input is linear
in time, so with ``g`` linear in time the step is exact (exponential time differencing, Cox and
Matthews 2002; Hochbruck and Ostermann 2010, eq. 2.9):

.. math::

    y_1 = e^{hA} y_0 + h\\varphi_1(hA)\\, g_0 + h\\varphi_2(hA)\\,(g_1 - g_0),

``phi_1(z) = (e^z - 1)/z``, ``phi_2(z) = (e^z - 1 - z)/z^2`` (all three from one exponential of
an augmented matrix, Van Loan's block trick). ``g_1`` needs ``y_1``: a predictor with the
remainder frozen (the input's slope exact through ``B = df/du``) and one corrector; their
difference is the error estimate. The stiff cap modes are integrated exactly, so the step is the
input's sample interval whatever the caps' stiffness: DOPRI5's stability floor (~1.3 ms on the
benchmark dock) is gone.

Event functions (the kernel's ``event_values``) are checked at the step's end and middle (the
middle from the same formula with ``h/2`` and ``g`` interpolated linearly); the energy integrals
(ground and wind work, damping, friction) by Simpson's rule on the rates at both ends and the
middle. The prototype stops at the first sign change (where a hybrid kernel would hand the
interval to Dormand-Prince).

Run: ``python tests/tools/section_exponential.py`` (~1 min).
"""

from __future__ import annotations

import time

import numpy as np
import scipy.linalg
from numba import njit

from shipblock.bench.section import navy_dock, record
from shipblock.section._forces import rhs
from shipblock.section._kernel import _force_arrays, event_values
from shipblock.section.model import assemble, static_state
from shipblock.section.simulate import simulate_section


def linearise(asm, init):
    """``A`` (mechanical states: positions, velocities, stick springs) and ``B`` (rates per unit
    horizontal and vertical ground acceleration) at the static state."""
    nb, ns = asm.n_bodies, asm.n_strips
    nsp = asm.spring_f.shape[0]
    x0 = init.x
    nm = 6 * nb + ns
    reg, fs, dp = init.regime.copy(), init.friction.copy(), np.zeros(nsp)
    work = _force_arrays(nsp, ns)

    def f(x, ay, az):
        out = np.zeros(x.size)
        rhs(0.0, x, nb, ns, asm.mass, asm.inertia, asm.strip_f, asm.strip_i, asm.spring_f, reg,
            dp, fs, asm.opt, np.array([ay, ay]), np.array([az, az]), 1.0, *work, out)
        return out[:nm]

    a = np.zeros((nm, nm))
    for m in range(nm):
        e = 1e-7 * max(1e-3, abs(x0[m]))
        xp, xm = x0.copy(), x0.copy()
        xp[m] += e
        xm[m] -= e
        a[:, m] = (f(xp, 0.0, 0.0) - f(xm, 0.0, 0.0)) / (2.0 * e)
    f0 = f(x0, 0.0, 0.0)
    b = np.stack([f(x0, 1.0, 0.0) - f0, f(x0, 0.0, 1.0) - f0], axis=1)
    return a, b


def phi_matrices(a, h):
    """``exp(hA)``, ``h phi_1(hA)``, ``h phi_2(hA)`` from one exponential (Van Loan 1978)."""
    n = a.shape[0]
    m = np.zeros((3 * n, 3 * n))
    m[:n, :n] = a * h
    m[:n, n:2 * n] = np.eye(n)
    m[n:2 * n, 2 * n:] = np.eye(n)
    e = scipy.linalg.expm(m)
    return e[:n, :n].copy(), h * e[:n, n:2 * n], h * e[:n, 2 * n:]


@njit(cache=True)
def _mv(m, v, out):
    for i in range(m.shape[0]):
        s = 0.0
        for j in range(m.shape[1]):
            s += m[i, j] * v[j]
        out[i] = s


@njit(cache=True)
def run_etd(x, x_s, reg, dp, dc0, tc0, fs, nb, mass, inertia, strip_f, strip_i, spring_f, opt,
            theta_c, ag_y, ag_z, dt, a, bmat, e1, p11, p21, eh, p1h, p2h, rtol, atol, hist,
            peak_n):
    """Exponential steps from sample 0 until the first event function changes sign (or the
    record ends). Returns (samples done, largest scaled error estimate, events seen)."""
    ns = strip_i.shape[0]
    nsp = spring_f.shape[0]
    nx = x.shape[0]
    nm = a.shape[0]
    ng = 2 * nsp + ns + (nb - 1) + 4
    delta, delta_dot, vt, pos, fe, fn, normal, tang = _force_arrays(nsp, ns)
    y = np.zeros(nm)
    g0 = np.zeros(nm)
    g1 = np.zeros(nm)
    ey = np.zeros(nm)
    ey1 = np.zeros(nm)
    g_end = np.zeros(nm)
    pg1 = np.zeros(nm)
    pg = np.zeros(nm)
    tmp = np.zeros(nm)
    y1 = np.zeros(nm)
    f0 = np.zeros(nx)
    f1 = np.zeros(nx)
    fm = np.zeros(nx)
    x1 = np.zeros(nx)
    xm = np.zeros(nx)
    ev0 = np.zeros(ng)
    ev1 = np.zeros(ng)
    evm = np.zeros(ng)
    du = np.zeros(2)
    n = ag_y.shape[0]
    o_e = 6 * nb + ns
    rhs(0.0, x, nb, ns, mass, inertia, strip_f, strip_i, spring_f, reg, dp, fs, opt, ag_y, ag_z,
        dt, delta, delta_dot, vt, pos, fe, fn, normal, tang, f0)
    event_values(0.0, x, nb, ns, strip_f, strip_i, spring_f, reg, dp, dc0, tc0, fs, opt, delta,
                 delta_dot, vt, pos, fe, fn, normal, tang, theta_c, ev0)
    for m in range(nm):
        y[m] = x[m] - x_s[m]
    _mv(a, y, tmp)
    for m in range(nm):
        g0[m] = f0[m] - tmp[m]
    err_max = 0.0
    n_over = 0
    for k in range(n - 1):
        t = k * dt
        for m in range(nm):
            y[m] = x[m] - x_s[m]
        _mv(e1, y, ey)
        _mv(p11, g0, pg)
        for m in range(nm):
            ey1[m] = ey[m]
            pg1[m] = pg[m]
        # predictor: the remainder frozen, the input's slope exact
        du[0] = ag_y[k + 1] - ag_y[k]
        du[1] = ag_z[k + 1] - ag_z[k]
        for m in range(nm):
            tmp[m] = bmat[m, 0] * du[0] + bmat[m, 1] * du[1]
        _mv(p21, tmp, y1)
        for m in range(nm):
            x1[m] = x_s[m] + ey[m] + pg[m] + y1[m]
        for m in range(nm, nx):
            x1[m] = x[m]
        rhs(t + dt, x1, nb, ns, mass, inertia, strip_f, strip_i, spring_f, reg, dp, fs, opt,
            ag_y, ag_z, dt, delta, delta_dot, vt, pos, fe, fn, normal, tang, f1)
        for m in range(nm):
            y1[m] = x1[m] - x_s[m]
        _mv(a, y1, tmp)
        for m in range(nm):
            g1[m] = f1[m] - tmp[m] - g0[m]
        _mv(p21, g1, tmp)
        for m in range(nm):
            x1[m] = x_s[m] + ey[m] + pg[m] + tmp[m]
        # the middle: exp((h/2)A) y0 + (h/2)phi1 g0 + (h/2)phi2 (g1 - g0)/2
        _mv(eh, y, ey)
        _mv(p1h, g0, pg)
        for m in range(nm):
            g1[m] *= 0.5
        _mv(p2h, g1, tmp)
        for m in range(nm):
            xm[m] = x_s[m] + ey[m] + pg[m] + tmp[m]
        for m in range(nm, nx):
            xm[m] = x[m]
        rhs(t + 0.5 * dt, xm, nb, ns, mass, inertia, strip_f, strip_i, spring_f, reg, dp, fs,
            opt, ag_y, ag_z, dt, delta, delta_dot, vt, pos, fe, fn, normal, tang, fm)
        event_values(t + 0.5 * dt, xm, nb, ns, strip_f, strip_i, spring_f, reg, dp, dc0, tc0,
                     fs, opt, delta, delta_dot, vt, pos, fe, fn, normal, tang, theta_c, evm)
        for j in range(ns):
            peak_n[j] = max(peak_n[j], normal[j])
        rhs(t + dt, x1, nb, ns, mass, inertia, strip_f, strip_i, spring_f, reg, dp, fs, opt,
            ag_y, ag_z, dt, delta, delta_dot, vt, pos, fe, fn, normal, tang, f1)
        event_values(t + dt, x1, nb, ns, strip_f, strip_i, spring_f, reg, dp, dc0, tc0, fs, opt,
                     delta, delta_dot, vt, pos, fe, fn, normal, tang, theta_c, ev1)
        for j in range(ns):
            peak_n[j] = max(peak_n[j], normal[j])
        # error estimate: a second corrector from the rates at the corrected end
        for m in range(nm):
            y1[m] = x1[m] - x_s[m]
        _mv(a, y1, tmp)
        for m in range(nm):
            g_end[m] = f1[m] - tmp[m]
            g1[m] = g_end[m] - g0[m]
        _mv(p21, g1, tmp)
        err = 0.0
        for m in range(nm):
            xc = x_s[m] + ey1[m] + pg1[m] + tmp[m]
            sc = atol + rtol * max(abs(x[m]), abs(x1[m]))
            err += ((xc - x1[m]) / sc) ** 2
        err = np.sqrt(err / nm)
        err_max = max(err_max, err)
        if err > 1.0:
            n_over += 1
        for q in range(ng):
            if ev0[q] > 0.0 and (evm[q] <= 0.0 or ev1[q] <= 0.0):
                return k, err_max, 1, n_over
        # energy integrals: Simpson on the rates at the ends and the middle
        for m in range(o_e, o_e + 4):
            x1[m] = x[m] + dt / 6.0 * (f0[m] + 4.0 * fm[m] + f1[m])
        for m in range(nx):
            x[m] = x1[m]
            f0[m] = f1[m]
        for q in range(ng):
            ev0[q] = ev1[q]
        for m in range(nm):
            g0[m] = g_end[m]
        for m in range(nm):
            hist[k + 1, m] = x[m]
    return n - 1, err_max, 0, n_over


def simulate_etd(section, ah, av, dt, rtol=1e-6, atol=1e-9, prepared=None):
    """Exponential steps from rest; returns (samples, histories, peaks, error, event, x)."""
    asm, init, a, b, mats = prepared if prepared is not None else prepare(section, dt)
    nb = asm.n_bodies
    nsp = asm.spring_f.shape[0]
    x = init.x.copy()
    hist = np.zeros((ah.size, x.size))
    hist[0] = x
    peak_n = np.zeros(asm.n_strips)
    k, err, ev, n_over = run_etd(x, init.x, init.regime.copy(), np.zeros(nsp), np.zeros(nsp),
                         np.zeros(nsp), init.friction.copy(), nb, asm.mass, asm.inertia,
                         asm.strip_f, asm.strip_i, asm.spring_f, asm.opt, asm.theta_c, ah, av,
                         dt, a, b, *mats, rtol, atol, hist, peak_n)
    return k, hist[:k + 1], peak_n, (err, n_over), ev, x


def prepare(section, dt):
    asm = assemble(section)
    init = static_state(asm)
    a, b = linearise(asm, init)
    return asm, init, a, b, phi_matrices(a, dt) + phi_matrices(a, 0.5 * dt)


def _cpu(fn, repeats=3):
    best = np.inf
    for _ in range(repeats):
        t0 = time.process_time()
        out = fn()
        best = min(best, time.process_time() - t0)
    return best, out


def main():
    dock = navy_dock()
    for pga in (0.02, 0.1, 0.2, 0.4):
        ah, av, dt = record(pga=pga)
        t_prep, prepared = _cpu(lambda: prepare(dock, dt), 1)
        simulate_etd(dock, ah[:100], av[:100], dt, prepared=prepared)  # compile
        t_etd, (k, hist, peak_n, err, ev, x) = _cpu(
            lambda: simulate_etd(dock, ah, av, dt, prepared=prepared))
        n = k + 1
        t_ker, ker = _cpu(lambda: simulate_section(dock, ah[:n], av[:n], dt,
                                                   exponential_steps=False))
        ref = simulate_section(dock, ah[:n], av[:n], dt, rtol=1e-10, atol=1e-13,
                               exponential_steps=False)
        nb = 4
        rel = {}
        for lab, res in (("kernel", ker), ("exponential", None)):
            if res is None:
                ship = hist[:, :3] - hist[0, :3]
                lines = [hist[:, 3 * b:3 * b + 3] - hist[0, 3 * b:3 * b + 3] for b in range(1, nb)]
            else:
                ship = res.ship
                lines = list(res.lines.values())
            rs = np.abs(ship - ref.ship).max(axis=0) / np.abs(ref.ship).max(axis=0)
            rl = max(float(np.max(np.abs(ln - lr).max(axis=0) / np.abs(lr).max(axis=0)))
                     for ln, lr in zip(lines, ref.lines.values()))
            rel[lab] = (rs, rl)
        print(f"pga {pga} g: {n - 1} samples exponential ({'stopped at an event' if ev else 'to the end'}), "
              f"CPU {t_etd * 1e3:.1f} ms (+ prepare {t_prep * 1e3:.0f} ms) against the kernel's "
              f"{t_ker * 1e3:.1f} ms ({ker.stats['accepted_steps']} + {ker.stats['rejected_steps']} steps); "
              f"error estimate: largest {err[0]:.2g}, above 1 in {err[1]} steps")
        for lab, (rs, rl) in rel.items():
            print(f"   {lab:12s} ship sway/heave/roll history error (rel. to peak) "
                  f"{rs[0]:.2g} / {rs[1]:.2g} / {rs[2]:.2g}; lines worst {rl:.2g}")
        o = 6 * nb + 6
        e_ref = ref.energy
        print(f"   energy: ground work {x[o]:.6g} J exponential, {e_ref['ground_work']:.6g} J reference; "
              f"damping {x[o + 2]:.6g} J, {e_ref['damping']:.6g} J")


if __name__ == "__main__":
    main()
