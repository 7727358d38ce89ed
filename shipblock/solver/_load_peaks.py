"""Running peaks of the contact loads (compiled): noting the forces at an instant, and the
horizontal accelerations at which the forces of a non-rocking mode cannot raise any peak.

:func:`note_loads` raises the summary's peaks (``S_PEAK_FY`` ... ``S_PEAK_CORNER`` of
:mod:`~shipblock.solver._layout`) with the interface forces at one instant; see
:mod:`~shipblock.solver._loads` for where the kernel takes them. :func:`quiet_interval` lets
the closed-form spans (:mod:`~shipblock.solver._closed_form`) fold the loads of their samples
into the scan that looks for the next event: a sample whose scaled acceleration lies inside
it is passed by two comparisons, as the span's own screen passes it, and only the others are
noted. The peaks come out bit-identical to noting every sample.
"""

from __future__ import annotations

import math

from numba import njit

from shipblock.solver._layout import (
    N_QUIET,
    S_PEAK_CORNER,
    S_PEAK_FX,
    S_PEAK_FY,
    S_PEAK_SFX,
    S_PEAK_SFY,
    S_PEAK_UTIL_G,
    S_PEAK_UTIL_S,
    W_QUIET,
)
from shipblock.system import P_MUS1, P_MUS2


@njit(cache=True, forceinline=True)
def note_loads(p, rock, fx, fy, Fx, Fy, summary):
    """Raise the running peaks of the contact loads with the forces at one instant [N].

    ``rock`` is nonzero while the blocks rock (``fy`` then rests on their pivot corners). NaN
    forces (a singular mode) compare false and change nothing.
    """
    afx = abs(fx)
    aFx = abs(Fx)
    if fy > summary[S_PEAK_FY]:
        summary[S_PEAK_FY] = fy
    if afx > summary[S_PEAK_FX]:
        summary[S_PEAK_FX] = afx
    if Fy > summary[S_PEAK_SFY]:
        summary[S_PEAK_SFY] = Fy
    if aFx > summary[S_PEAK_SFX]:
        summary[S_PEAK_SFX] = aFx
    if fy > 0.0 and p[P_MUS1] > 0.0:
        u = afx / (p[P_MUS1] * fy)
        if u > summary[S_PEAK_UTIL_G]:
            summary[S_PEAK_UTIL_G] = u
    if Fy > 0.0 and p[P_MUS2] > 0.0:
        u = aFx / (p[P_MUS2] * Fy)
        if u > summary[S_PEAK_UTIL_S]:
            summary[S_PEAK_UTIL_S] = u
    if rock and fy > summary[S_PEAK_CORNER]:
        summary[S_PEAK_CORNER] = fy


@njit(cache=True, forceinline=True)
def note_mode_loads(p, fx_a, fx_g, fy_a, fy_g, Fx_a, Fx_g, Fy_a, Fy_g, a, G, summary):
    """:func:`note_loads` of a non-rocking mode at input ``(a, G)``: the forces
    ``a w_a + G w_G`` from the components of its response vectors (as
    :func:`~shipblock.solver._loads.span_loads` computes them, to the bit)."""
    note_loads(p, 0, fx_a * a + fx_g * G, fy_a * a + fy_g * G, Fx_a * a + Fx_g * G,
               Fy_a * a + Fy_g * G, summary)


@njit(cache=True, forceinline=True)
def folds_loads(has_ay, fy_a, Fy_a):
    """Whether a closed-form span notes the loads of its samples itself (through
    :func:`quiet_interval`): without a vertical input and with normal forces that do not
    depend on ``a`` (as while the blocks do not rock). Otherwise
    :func:`~shipblock.solver._loads.span_loads` scans the span's samples afterwards."""
    return not has_ay and fy_a == 0.0 and Fy_a == 0.0


@njit(cache=True, forceinline=False, error_model="numpy", _nrt=False)
def quiet_interval(p, grav, fx_a, fx_g, fy_g, Fx_a, Fx_g, Fy_g, summary):  # pragma: no cover
    """Scaled horizontal accelerations ``[lo, hi]`` [m/s^2] at which the forces of a
    non-rocking mode (``G = g``, normal forces independent of ``a``: see :func:`folds_loads`)
    surely raise none of the running peaks in ``summary`` (``lo > hi`` if none is known).

    The normal forces ``fy_G g``, ``Fy_G g`` are the same at every sample and are noted at
    the span's ends. Each other peak reads ``|s a + q| <= r``: ``|fx|`` below its peak, ``|Fx|``
    below its peak, and ``|fx|``, ``|Fx|`` below their peak utilisations times ``mu fy``,
    ``mu Fy``. With ``s = 0`` (a sliding interface's friction force) the value is the same at
    every ``a`` and is compared with its peak as :func:`note_loads` would compute it: the
    condition holds for all ``a`` or none. Otherwise, as in
    :func:`~shipblock.solver._closed_form.held_interval`, the intersection is shrunk by a
    margin (1e-9 of ``|q| + r``) and kept where the terms in ``a`` are at most 1e4 times
    ``|q| + r``, far above the round-off of :func:`note_mode_loads`: at an ``a`` inside,
    every force and utilisation as computed stays strictly below its peak, so noting it would
    change nothing; an ``a`` outside is noted. The interval only widens as the peaks rise, so
    one computed earlier in a run is still right, only narrower.

    Parameters
    ----------
    p : ndarray
        Parameter vector (for the friction coefficients).
    grav : float
        ``G = g`` [m/s^2].
    fx_a, fx_g, fy_g, Fx_a, Fx_g, Fy_g : float
        Components of the mode's response vectors (``fy_a = Fy_a = 0``).
    summary : ndarray
        The run's summary, holding the running peaks.

    Returns
    -------
    lo, hi : float
    """
    lo = -math.inf
    hi = math.inf
    fy = fy_g * grav
    Fy = Fy_g * grav
    mus1 = p[P_MUS1]
    mus2 = p[P_MUS2]
    for i in range(4):
        if i == 0:
            s, q, r, peak, div = fx_a, fx_g * grav, summary[S_PEAK_FX], summary[S_PEAK_FX], 1.0
        elif i == 1:
            s, q, r, peak, div = Fx_a, Fx_g * grav, summary[S_PEAK_SFX], summary[S_PEAK_SFX], 1.0
        elif i == 2:
            if not (fy > 0.0 and mus1 > 0.0):
                continue
            div = mus1 * fy
            s, q, peak = fx_a, fx_g * grav, summary[S_PEAK_UTIL_G]
            r = peak * div
        else:
            if not (Fy > 0.0 and mus2 > 0.0):
                continue
            div = mus2 * Fy
            s, q, peak = Fx_a, Fx_g * grav, summary[S_PEAK_UTIL_S]
            r = peak * div
        if s == 0.0:
            # the same value at every (finite) a, |0 a + q| = |q|, computed as noting it would
            v = abs(q) if i < 2 else abs(q) / div
            if not v <= peak:
                return 1.0, -1.0
            continue
        scale = abs(q) + abs(r)
        if not math.isfinite(scale) or not math.isfinite(s):
            return 1.0, -1.0
        margin = 1e-9 * scale
        cap = 1e4 * scale / abs(s)
        c = -q / s
        w = (r - margin) / abs(s)
        if not w >= 0.0:
            return 1.0, -1.0
        lo = max(lo, -cap, c - w)
        hi = min(hi, cap, c + w)
    if not lo <= hi:
        return 1.0, -1.0
    return lo, hi


@njit(cache=True, forceinline=True)
def cached_quiet_interval(p, work, slot, grav, fx_a, fx_g, fy_g, Fx_a, Fx_g, Fy_g, summary):
    """:func:`quiet_interval` of the non-rocking mode in response slot ``slot``, kept in the
    run's work array (``W_QUIET``) with the four peaks it was computed from and computed
    again only once one of them has risen: the closed-form spans ask for it at every start,
    and most spans of a record start with the peaks of the one before."""
    base = W_QUIET + N_QUIET * slot
    if (work[base + 6] == 1.0 and work[base + 2] == summary[S_PEAK_FX]
            and work[base + 3] == summary[S_PEAK_SFX] and work[base + 4] == summary[S_PEAK_UTIL_G]
            and work[base + 5] == summary[S_PEAK_UTIL_S]):
        return work[base], work[base + 1]
    lo, hi = quiet_interval(p, grav, fx_a, fx_g, fy_g, Fx_a, Fx_g, Fy_g, summary)
    work[base] = lo
    work[base + 1] = hi
    work[base + 2] = summary[S_PEAK_FX]
    work[base + 3] = summary[S_PEAK_SFX]
    work[base + 4] = summary[S_PEAK_UTIL_G]
    work[base + 5] = summary[S_PEAK_UTIL_S]
    work[base + 6] = 1.0
    return lo, hi


@njit(cache=True, forceinline=True)
def note_span_extremes(p, work, slot, fx_a, fx_g, fy_g, Fx_a, Fx_g, Fy_g, a_lo, a_hi, G, summary):
    """:func:`note_mode_loads` of a non-rocking mode whose normal forces do not depend on ``a``
    (:func:`folds_loads`) over a span whose scaled horizontal input [m/s^2] ranged over
    ``[a_lo, a_hi]`` at its samples and ends (``G = g``): the peaks of noting every one of them,
    to the bit.

    Each force ``s a + q`` is computed with one rounding per operation, each monotone, so it is
    monotone in ``a`` as computed; its magnitude, and its utilisation (its magnitude over a
    fixed ``mu fy``), are greatest at one of the two ends of the range.
    """
    base = W_QUIET + N_QUIET * slot
    if (work[base + 6] == 1.0 and work[base] <= a_lo and a_hi <= work[base + 1]
            and fy_g * G <= summary[S_PEAK_FY] and Fy_g * G <= summary[S_PEAK_SFY]):
        return  # inside the quiet interval kept for the mode (peaks since risen only widen it)
    note_mode_loads(p, fx_a, fx_g, 0.0, fy_g, Fx_a, Fx_g, 0.0, Fy_g, a_lo, G, summary)
    note_mode_loads(p, fx_a, fx_g, 0.0, fy_g, Fx_a, Fx_g, 0.0, Fy_g, a_hi, G, summary)
    cached_quiet_interval(p, work, slot, G, fx_a, fx_g, fy_g, Fx_a, Fx_g, Fy_g, summary)
