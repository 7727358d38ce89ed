"""Where the kernel takes the contact loads: the interface forces over a span, and at a state
(compiled), handed to the running peaks of the summary.

The kernel hands every set of interface forces it has at hand to :func:`note_loads` (of
:mod:`~shipblock.solver._running_peaks`, imported here): the forces
``(fx, fy)`` of the ground on the blocks and ``(Fx, Fy)`` of the blocks on the ship, totals over
the ``n`` blocks [N]. It keeps the peaks of ``fy``, ``|fx|``, ``Fy``, ``|Fx|``, of the friction
utilisations ``|fx| / (mu_s1 fy)`` and ``|Fx| / (mu_s2 Fy)`` and, while the blocks rock, of
``fy`` (then carried by the pivot corners), in the summary slots ``S_PEAK_FY`` ... ``S_PEAK_CORNER``
(:mod:`~shipblock.solver._layout`); the wrappers divide the forces by ``n``.

Where the forces come from decides the accuracy:

* rest and sliding (:func:`span_loads`): the forces are ``a w_a + G w_G`` with the mode's
  response vectors, linear in time between samples, and the utilisations ratios of such linear
  functions (monotone between samples), so the peaks over a span are at its samples and ends:
  exact. Without a vertical input the closed-form span notes its samples itself, in its own
  scan for the next event (:mod:`~shipblock.solver._running_peaks`);
* rocking: the forces at the end of every accepted step (the steps' own last stage, at most one
  sample long) and on both sides of every event (:func:`state_loads`). Between step ends the
  forces vary smoothly and their peak can be missed by about ``h^2 |f''| / 8``
  (docs/theory/solver.md and tests/test_loads.py give the measured size).

Impacts are instantaneous in the rigid-body model: their impulses are not forces and are not
part of the peaks; the forces just before and after an impact are.
"""

from __future__ import annotations

import math

from numba import njit

from shipblock.equations import I_FX, I_FY, I_SFX, I_SFY, N_SOLVE_OUT, solve_mode
from shipblock.solver._closed_form import mode_response_start
from shipblock.solver._ground import ground_motion_at
from shipblock.solver._layout import (
    MS_ROCK,
    MS_S,
    MS_SIG1,
    MS_SIG2,
    MS_SLIP1,
    MS_SLIP2,
    S_PEAK_UTIL_G,
    S_PEAK_UTIL_S,
    Y_OM,
    Y_TH,
)
from shipblock.solver._running_peaks import (
    folds_loads,
    note_loads,
)
from shipblock.system import P_G, P_MUS1, P_MUS2


@njit(cache=True, forceinline=True)
def _note_response(p, wa, wg, a, G, summary):
    """:func:`note_loads` of a non-rocking mode at input ``(a, G)`` from its response vectors."""
    note_loads(p, 0, wa[I_FX] * a + wg[I_FX] * G, wa[I_FY] * a + wg[I_FY] * G,
               wa[I_SFX] * a + wg[I_SFX] * G, wa[I_SFY] * a + wg[I_SFY] * G, summary)


#: Samples checked at once against the running extremes of :func:`_extremes_with_vertical`
#: (the extremes of a record settle early, so most blocks are passed by one vectorised
#: comparison).
EXTREMES_BLOCK = 64


@njit(cache=True, forceinline=False, _nrt=False)
def _extremes_with_vertical(ax, ay, sh, sv, grav, fx_a, fx_g, Fx_a, Fx_g, k0, k1):  # pragma: no cover
    """Extremes over samples ``k0:k1`` of ``fx``, ``Fx``, ``G = g + a_y`` and ``a / G``.

    A block of samples all inside the running extremes is passed after one branch-free count
    (vectorised); only blocks holding a new extreme are scanned.
    """
    fx_lo = Fx_lo = g_lo = r_lo = math.inf
    fx_hi = Fx_hi = g_hi = r_hi = -math.inf
    j = k0
    while j < k1:
        end = min(j + EXTREMES_BLOCK, k1)
        if end - j == EXTREMES_BLOCK and fx_lo <= fx_hi:
            bx = ax[j:end]
            by = ay[j:end]
            outside = 0
            for i in range(EXTREMES_BLOCK):
                a = sh * bx[i]
                g_tot = grav + sv * by[i]
                fx = fx_a * a + fx_g * g_tot
                Fx = Fx_a * a + Fx_g * g_tot
                # r = a / G outside [r_lo, r_hi], without the division (G > 0 in the span: the
                # normal forces are positive while the mode holds)
                outside += ((fx < fx_lo) | (fx > fx_hi) | (Fx < Fx_lo) | (Fx > Fx_hi)
                            | (g_tot < g_lo) | (g_tot > g_hi) | (a < r_lo * g_tot)
                            | (a > r_hi * g_tot))
            if outside == 0:
                j = end
                continue
        for i in range(j, end):
            a = sh * ax[i]
            g_tot = grav + sv * ay[i]
            fx = fx_a * a + fx_g * g_tot
            Fx = Fx_a * a + Fx_g * g_tot
            r = a / g_tot
            fx_lo, fx_hi = min(fx_lo, fx), max(fx_hi, fx)
            Fx_lo, Fx_hi = min(Fx_lo, Fx), max(Fx_hi, Fx)
            g_lo, g_hi = min(g_lo, g_tot), max(g_hi, g_tot)
            r_lo, r_hi = min(r_lo, r), max(r_hi, r)
        j = end
    return fx_lo, fx_hi, Fx_lo, Fx_hi, g_lo, g_hi, r_lo, r_hi


@njit(cache=True, error_model="numpy", _nrt=False)
def span_loads(p, ms, work, ax, ay, has_ay, sh, sv, dt, k0, tau0, k1, tau1, summary):
    """Peaks of the contact loads over a non-rocking span, from ``t_k0 + tau0`` to
    ``t_k1 + tau1``: exact.

    The mode's forces are ``a w_a + G w_G`` (``G = g + a_y``; the response vectors of
    :func:`~shipblock.solver._closed_form.mode_response_start`, solved by the span), linear in
    time between samples: their peaks, and those of the utilisations, are at the span's ends or
    at its samples. With nothing rotating the normal forces do not depend on ``a``
    (``fy = fy_G G``, ``Fy = Fy_G G``), so over the samples: the peak normal forces are those
    of the greatest ``G``; the peak ``|fx|`` that of the greatest or least ``fx``; the peak
    utilisation ``|fx_a (a/G) + fx_G| / (mu fy_G)`` that of the greatest or least ``a/G``.
    Without a vertical input ``G = g`` and the span notes its loads itself, ends included,
    from the least and greatest ``a`` it passed
    (:func:`~shipblock.solver._running_peaks.note_span_extremes`), and nothing is done here. (A
    mode whose normal forces did depend on ``a`` would be scanned sample by sample.)
    """
    start = mode_response_start(p, work, ms[MS_SLIP1], float(ms[MS_SIG1]), ms[MS_SLIP2],
                                float(ms[MS_SIG2]))
    if start < 0:
        return
    wa = work[start:start + N_SOLVE_OUT]
    wg = work[start + N_SOLVE_OUT:start + 2 * N_SOLVE_OUT]
    grav = p[P_G]
    if folds_loads(has_ay, wa[I_FY], wa[I_SFY]):
        return  # the span noted its own loads, ends included
    a, b = ground_motion_at(ax, ay, has_ay, sh, sv, k0, tau0, dt)
    _note_response(p, wa, wg, a, grav + b, summary)
    a, b = ground_motion_at(ax, ay, has_ay, sh, sv, k1, tau1, dt)
    _note_response(p, wa, wg, a, grav + b, summary)
    last = min(k1, ax.shape[0] - 1)
    if k0 + 1 > last:
        return
    if wa[I_FY] != 0.0 or wa[I_SFY] != 0.0:
        for j in range(k0 + 1, last + 1):
            _note_response(p, wa, wg, sh * ax[j], grav + (sv * ay[j] if has_ay else 0.0),
                           summary)
        return
    fx_lo, fx_hi, Fx_lo, Fx_hi, G_lo, G_hi, r_lo, r_hi = _extremes_with_vertical(
        ax, ay, sh, sv, grav, wa[I_FX], wg[I_FX], wa[I_SFX], wg[I_SFX], k0 + 1, last + 1)
    fy_g = wg[I_FY]
    Fy_g = wg[I_SFY]
    G_top = G_hi if fy_g >= 0.0 else G_lo
    note_loads(p, 0, 0.0, fy_g * G_top, 0.0, Fy_g * (G_hi if Fy_g >= 0.0 else G_lo), summary)
    note_loads(p, 0, fx_lo, -math.inf, Fx_lo, -math.inf, summary)
    note_loads(p, 0, fx_hi, -math.inf, Fx_hi, -math.inf, summary)
    # utilisations: |fx| / (mu fy) = |fx_a r + fx_G| / (mu fy_G) at the extreme r = a / G (the
    # normal forces positive: G > 0 while the mode holds)
    for r in (r_lo, r_hi):
        if fy_g > 0.0 and p[P_MUS1] > 0.0:
            u = abs(wa[I_FX] * r + wg[I_FX]) / (p[P_MUS1] * fy_g)
            if u > summary[S_PEAK_UTIL_G]:
                summary[S_PEAK_UTIL_G] = u
        if Fy_g > 0.0 and p[P_MUS2] > 0.0:
            u = abs(wa[I_SFX] * r + wg[I_SFX]) / (p[P_MUS2] * Fy_g)
            if u > summary[S_PEAK_UTIL_S]:
                summary[S_PEAK_UTIL_S] = u


@njit(cache=True, forceinline=False, _nrt=False)
def state_loads(p, ms, y, k, tau, dt, ax, ay, has_ay, sh, sv, w7, summary):
    """:func:`note_loads` of the mode ``ms`` at state ``y`` and time ``t_k + tau`` (one solve of
    the equations into the work array ``w7``): the kernel calls it on both sides of an event."""
    a, b = ground_motion_at(ax, ay, has_ay, sh, sv, k, tau, dt)
    ok = solve_mode(p, ms[MS_SLIP1], ms[MS_ROCK], ms[MS_SLIP2], float(ms[MS_S]),
                    float(ms[MS_SIG1]), float(ms[MS_SIG2]), y[Y_TH], y[Y_OM], a, p[P_G] + b, w7)
    if ok:
        note_loads(p, ms[MS_ROCK], w7[I_FX], w7[I_FY], w7[I_SFX], w7[I_SFY], summary)
