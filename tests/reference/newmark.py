"""Slow, exact reference: Newmark's rigid sliding block under piecewise-linear input.

Independent of shipblock's solver (plain Python, no event machinery shared). Between samples the
ground acceleration a(t) and G(t) = g + ay(t) are linear, so while the block slides with
direction sigma its relative acceleration -a - sigma*mu*G is linear in time, the relative
velocity quadratic and the slip cubic; every stop and start is the root of a polynomial of
degree <= 2, found in closed form.

Reference: Newmark, N. M. (1965). Effects of earthquakes on dams and embankments.
Geotechnique 15(2), 139-160.
"""

from __future__ import annotations

import numpy as np


def _first_root(coeffs, lo, hi):
    """Smallest root of the polynomial (highest power first) in (lo, hi], or None."""
    roots = np.roots(np.trim_zeros(np.asarray(coeffs, float), "f")) if np.any(coeffs) else []
    best = None
    for r in np.atleast_1d(roots):
        if abs(r.imag) > 1e-12:
            continue
        r = r.real
        if lo + 1e-14 < r <= hi + 1e-14 and (best is None or r < best):
            best = min(r, hi)
    return best


def newmark_slip(a, ay, dt, mu, g=9.80665):
    """Relative slip x(t_k) of a rigid block (mu_s = mu_k = mu) at the samples.

    Returns
    -------
    x, v : ndarray
        Slip [m] and slip velocity [m/s] relative to the ground at the samples.
    """
    a = np.asarray(a, float)
    ay = np.zeros_like(a) if ay is None else np.asarray(ay, float)
    n = a.size
    x = np.zeros(n)
    v = np.zeros(n)
    xc = vc = 0.0
    sigma = 0
    for k in range(n - 1):
        a0, a1 = a[k], a[k + 1]
        G0, G1 = g + ay[k], g + ay[k + 1]
        da, dG = (a1 - a0) / dt, (G1 - G0) / dt
        tau = 0.0
        while tau < dt:
            if sigma == 0:
                # at rest: find when |a| first exceeds mu*G (both linear)
                at, Gt = a0 + da * tau, G0 + dG * tau
                if abs(at) > mu * Gt:
                    sigma = -1 if at > 0 else 1
                    continue
                t_hit = None
                for sgn in (1.0, -1.0):
                    # sgn*a(t) - mu*G(t) = 0
                    c1 = sgn * da - mu * dG
                    c0 = sgn * a0 - mu * G0
                    if c1 > 0:
                        r = -c0 / c1
                        if tau < r <= dt and (t_hit is None or r < t_hit):
                            t_hit = r
                if t_hit is None:
                    tau = dt
                else:
                    tau = t_hit
                    at = a0 + da * tau
                    sigma = -1 if at > 0 else 1
            else:
                # sliding: acc(t) = -a(t) - sigma*mu*G(t) = c0 + c1 t (t from 0 at sample k)
                c0 = -a0 - sigma * mu * G0
                c1 = -da - sigma * mu * dG
                # v(t) = vc + c0 (t - tau) + c1 (t^2 - tau^2)/2
                coeffs = [c1 / 2, c0, vc - c0 * tau - c1 * tau * tau / 2]
                t_stop = _first_root(coeffs, tau, dt)
                t_end = dt if t_stop is None else t_stop

                def vel(t, vc=vc, c0=c0, c1=c1, tau=tau):
                    return vc + c0 * (t - tau) + c1 * (t * t - tau * tau) / 2

                def pos(t, xc=xc, vc=vc, c0=c0, c1=c1, tau=tau):
                    s = t - tau
                    return xc + vc * s + c0 * s * s / 2 + c1 * (s**3 / 6 + tau * s * s / 2)

                xc, vc = pos(t_end), vel(t_end)
                tau = t_end
                if t_stop is not None:
                    vc = 0.0
                    at, Gt = a0 + da * tau, G0 + dG * tau
                    # stays stuck if friction can hold it, else slides against the ground acceleration
                    sigma = 0 if abs(at) <= mu * Gt else (-1 if at > 0 else 1)
        x[k + 1] = xc
        v[k + 1] = vc
    return x, v


def ground_pulse_kinematics(a, dt):
    """Exact velocity and displacement of a piecewise-linear acceleration at its last sample."""
    v = d = 0.0
    for k in range(len(a) - 1):
        d += v * dt + dt * dt * (2 * a[k] + a[k + 1]) / 6
        v += dt * (a[k] + a[k + 1]) / 2
    return v, d


__all__ = ["newmark_slip", "ground_pulse_kinematics"]
