"""Event functions of the solver: one per constraint of the current mode (compiled).

Each function is >= 0 while its constraint holds and is scaled to be dimensionless
(forces by the weights, moments by weight x R); see ``EV_*`` in
:mod:`shipblock.solver._layout`. Constraints that do not apply to the mode are set to 1.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from shipblock.solver._layout import (
    EV_G_SLIP,
    EV_G_STICK,
    EV_IMPACT,
    EV_OVERTURN,
    EV_S_SLIP,
    EV_S_STICK,
    EV_SEP_G,
    EV_SEP_S,
    EV_UPLIFT,
    MS_ROCK,
    MS_S,
    MS_SIG1,
    MS_SIG2,
    MS_SLIP1,
    MS_SLIP2,
    FORCE_TOL,
    LEVEL_GAP,
    N_EVENTS,
    REARM_TOL,
    S_MARGIN,
    Y_TH,
    Y_VB,
    Y_VS,
)
from shipblock.system import P_B, P_G, P_H, P_M, P_MUS1, P_MUS2, P_NM, P_R, P_THC


@njit(cache=True, forceinline=True)
def rearm(levels, g):
    """Restore the shifted or disarmed event levels whose function ``g`` is clear of zero: True
    if every level is back at 0.

    Event ``e`` fires when its function falls below ``levels[e]``: 0 normally, between
    ``-FORCE_TOL`` and 0 for a force event whose mode was selected again when it fired
    (:func:`shifted_level`), ``-inf`` for a velocity event in that case. A level is restored to
    0 once its function exceeds ``REARM_TOL``.
    """
    all_armed = True
    for e in range(N_EVENTS):
        if levels[e] != 0.0 and g[e] > REARM_TOL:
            levels[e] = 0.0
        all_armed = all_armed and levels[e] == 0.0
    return all_armed


@njit(cache=True, forceinline=True)
def shifted_level(e, level, value):
    """The level at which event ``e`` is watched after it fired at ``level`` (its function
    then at ``value``) and the mode selection kept the mode: the event is shifted, not
    switched off.

    A force event (the friction cones, the blocks' moment criterion) is watched again halfway
    from its level to ``-FORCE_TOL``, the tolerance of the mode selection's held conditions in
    the units of the event functions (forces by the weights, moments by weight x R): a
    constraint that merely touched zero stays watched, and one that goes on being violated
    fires again before its violation exceeds the tolerance, when the mode selection, now
    seeing a violation beyond half of it grow, releases it. The levels ``-FORCE_TOL/2``,
    ``-3 FORCE_TOL/4``, ... tend to ``-FORCE_TOL``; the level is at least ``LEVEL_GAP`` below
    the function's value, so that an event does not fire again at the same instant where the
    levels have come within rounding of ``-FORCE_TOL`` (the selection computes the margin its
    own way, and at the tolerance's edge the two may differ by some 1e-16): one more firing
    then needs the function to fall by ``LEVEL_GAP``, and the selection releases the
    constraint once its own margin is past the tolerance, so the function never goes past
    ``-FORCE_TOL`` by more than rounding and a few ``LEVEL_GAP``. A velocity event (a slip
    velocity brought to zero and moving on the same way) is disarmed (``-inf``) until clear of
    zero, as before 2026-11-26; the other events never keep their mode.
    """
    if e == EV_G_STICK or e == EV_S_STICK or e == EV_UPLIFT:
        return min(0.5 * (level - FORCE_TOL), value - LEVEL_GAP)
    return -math.inf


@njit(cache=True, forceinline=True)
def held_margin(g, skip):
    """The least of the event functions ``g`` of the conditions a mode holds: the stick cones,
    the blocks' moment criterion and the normal forces (1 where none applies, as
    :func:`event_functions` sets those that do not), leaving out event ``skip`` (-1: none).

    Dimensionless like the event functions; at least ``-FORCE_TOL`` wherever the mode's
    constraints hold to the tolerance of the mode selection. The kernel keeps its least value
    over a run (``S_MARGIN``), the audit of the random campaign.
    """
    m = 1.0
    for e in (EV_G_STICK, EV_S_STICK, EV_UPLIFT, EV_SEP_G, EV_SEP_S):
        if e != skip and g[e] < m:
            m = g[e]
    return m


@njit(cache=True, forceinline=True)
def rotation_event(p, ms, e, theta):
    """The event functions that depend on the rotation alone: impact and overturning."""
    if e == EV_IMPACT:
        return ms[MS_S] * theta
    return p[P_THC] - ms[MS_S] * theta


@njit(cache=True, forceinline=True)
def event_functions(p, ms, y, fx, fy, Fx, Fy, g):
    """Fill ``g`` with the event functions of mode ``ms`` at state ``y`` and interface forces.

    ``(fx, fy)`` is the force of the ground on the blocks and ``(Fx, Fy)`` that of the blocks
    on the ship [N] (totals over the n blocks).
    """
    weight = (p[P_NM] + p[P_M]) * p[P_G]
    ship_weight = p[P_M] * p[P_G]
    for e in range(N_EVENTS):
        g[e] = 1.0
    if ms[MS_SLIP1]:
        g[EV_G_SLIP] = ms[MS_SIG1] * y[Y_VB]
    else:
        g[EV_G_STICK] = (p[P_MUS1] * fy - abs(fx)) / weight
    if ms[MS_ROCK]:
        g[EV_IMPACT] = rotation_event(p, ms, np.int64(EV_IMPACT), y[Y_TH])
        g[EV_OVERTURN] = rotation_event(p, ms, np.int64(EV_OVERTURN), y[Y_TH])
    else:
        g[EV_UPLIFT] = (p[P_B] * (fy + Fy) - p[P_H] * abs(fx + Fx)) / (weight * p[P_R])
    if ms[MS_SLIP2]:
        g[EV_S_SLIP] = ms[MS_SIG2] * y[Y_VS]
    else:
        g[EV_S_STICK] = (p[P_MUS2] * Fy - abs(Fx)) / ship_weight
    g[EV_SEP_G] = fy / weight
    g[EV_SEP_S] = Fy / ship_weight


@njit(cache=True, forceinline=True)
def impact_return_time(s, theta, omega, alpha):
    """Longest first step after an impact [s]: the rotation's return to zero at its start rates.

    A step from an impact (``theta == 0``, the block rotating out, ``s omega > 0``) whose
    rotation already turns back (``s alpha < 0``) returns to zero after about
    ``-2 omega / alpha``. A longer step can hold the return and a second crossing (the mode's
    equations run on past the impact with the pivot on the wrong corner) and end on the right
    side of zero, where no check of its ends sees the impact: small rocking after an impact
    then went on with the wrong pivot (found by random testing: energy balances off by up to
    30 %). Infinite (no limit) otherwise. The kernel's rocking steps and the mode-3 span's
    first step into a sample both keep to it.
    """
    if theta == 0.0 and s * omega > 0.0 and s * alpha < 0.0:
        return -2.0 * omega / alpha
    return math.inf


@njit(cache=True, forceinline=True)
def stuck_rocking_clear(p, s, theta, fx, fy, Fx, Fy):
    """Whether every event function of mode 3 (rocking, no interface slipping) is >= 0.

    The signs of the numerators of :func:`event_functions` for that mode (it divides them by
    positive weights), without the divisions or the array: the screen of the rocking span's
    steps. ``s`` is the pivot sign as a float.
    """
    return (p[P_MUS1] * fy - abs(fx) >= 0.0 and p[P_MUS2] * Fy - abs(Fx) >= 0.0
            and fy >= 0.0 and Fy >= 0.0 and s * theta >= 0.0 and p[P_THC] - s * theta >= 0.0)


@njit(cache=True, forceinline=True)
def held_clear(p, ms, fx, fy, Fx, Fy):
    """Whether every condition mode ``ms`` holds is met (margin >= 0) under the interface
    forces ``fx, fy, Fx, Fy`` [N]: the signs of the numerators of :func:`event_functions`,
    without its divisions, the screen of :func:`note_held_margin`."""
    return ((ms[MS_SLIP1] != 0 or p[P_MUS1] * fy - abs(fx) >= 0.0)
            and (ms[MS_SLIP2] != 0 or p[P_MUS2] * Fy - abs(Fx) >= 0.0)
            and (ms[MS_ROCK] != 0 or p[P_B] * (fy + Fy) - p[P_H] * abs(fx + Fx) >= 0.0)
            and fy >= 0.0 and Fy >= 0.0)


@njit(cache=True, forceinline=True)
def note_held_margin(p, ms, y, fx, fy, Fx, Fy, g, skip, summary):
    """Lower the run's least constraint margin (``S_MARGIN``) by the held conditions of mode
    ``ms`` under the interface forces ``fx, fy, Fx, Fy`` [N], leaving out event ``skip``
    (-1: none); ``g`` is work for the event functions, computed only where a condition is not
    clear of zero (:func:`held_clear`): a margin >= 0 cannot lower the least one."""
    if not held_clear(p, ms, fx, fy, Fx, Fy):
        event_functions(p, ms, y, fx, fy, Fx, Fy, g)
        summary[S_MARGIN] = min(summary[S_MARGIN], held_margin(g, skip))

