"""Running peaks of the contact loads (compiled): noting the forces at an instant, and the
non-rocking spans' loads from the range of their input.

:func:`note_loads` raises the summary's peaks (``S_PEAK_FY`` ... ``S_PEAK_CORNER`` of
:mod:`~shipblock.solver._layout`) with the interface forces at one instant; see
:mod:`~shipblock.solver._force_sampling` for where the kernel takes them. Without a vertical input the
forces of a non-rocking mode are linear in the scaled horizontal input ``a`` alone, so the
closed-form spans (:mod:`~shipblock.solver._closed_form`) keep only the least and greatest
``a`` they pass, at two operations a sample, and :func:`note_span_extremes` notes the loads
there: the peaks are those of noting every sample, to the bit. Per mode the run keeps the range
of ``a`` already noted, so that a span inside it notes nothing, and a rest phase screens its
samples against it, vectorised, as it screens them against the limits of rest.
"""

from __future__ import annotations

from numba import njit

from shipblock.solver._layout import (
    S_PEAK_CORNER,
    S_PEAK_FX,
    S_PEAK_FY,
    S_PEAK_SFX,
    S_PEAK_SFY,
    S_PEAK_UTIL_G,
    S_PEAK_UTIL_S,
    W_NOTED,
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
    :func:`~shipblock.solver._force_sampling.span_loads` computes them, to the bit)."""
    note_loads(p, 0, fx_a * a + fx_g * G, fy_a * a + fy_g * G, Fx_a * a + Fx_g * G,
               Fy_a * a + Fy_g * G, summary)


@njit(cache=True, forceinline=True)
def note_span_extremes(p, work, slot, fx_a, fx_g, fy_g, Fx_a, Fx_g, Fy_g, a_lo, a_hi, G,
                       summary):
    """Note the loads of a non-rocking span whose scaled horizontal input [m/s^2] ranged over
    ``[a_lo, a_hi]`` at its samples and ends, in a mode whose normal forces do not depend on
    it (:func:`folds_loads`, ``G = g``): the peaks of noting every one of those inputs, to the
    bit.

    Each force ``s a + q`` is computed with one rounding per operation, each monotone, so it is
    monotone in ``a`` as computed; its magnitude, and its utilisation (its magnitude over a
    fixed ``mu fy``), are greatest at an end of any range of ``a``. The run's work array keeps,
    per response slot ``slot``, the range whose ends have been noted (``W_NOTED``; empty,
    ``(inf, -inf)``, until the first span of the mode): only an end beyond it is noted, and the
    range widened to take it in.
    """
    base = W_NOTED + 2 * slot
    if a_lo < work[base]:
        note_mode_loads(p, fx_a, fx_g, 0.0, fy_g, Fx_a, Fx_g, 0.0, Fy_g, a_lo, G, summary)
        work[base] = a_lo
    if a_hi > work[base + 1]:
        note_mode_loads(p, fx_a, fx_g, 0.0, fy_g, Fx_a, Fx_g, 0.0, Fy_g, a_hi, G, summary)
        work[base + 1] = a_hi


@njit(cache=True, forceinline=True)
def folds_loads(has_ay, fy_a, Fy_a):
    """Whether a closed-form span notes the loads of its samples itself (from the range of its
    input, :func:`note_span_extremes`): without a vertical input and with normal forces that
    do not depend on ``a`` (as while the blocks do not rock). Otherwise
    :func:`~shipblock.solver._force_sampling.span_loads` scans the span's samples afterwards."""
    return not has_ay and fy_a == 0.0 and Fy_a == 0.0
