"""Compiled event-driven integration of the ship-block system.

One loop serves every mode. Between two input samples the ground acceleration is linear in
time. Rest and sliding phases are handed to :func:`~shipblock.solver._closed_form.nonrocking_span`,
which advances them exactly and finds their events in closed form, sample after sample, until
an event. Rocking phases are advanced by Dormand-Prince 5(4) steps that never cross a sample,
with error control; after every step the event functions (one per constraint of the current
mode, see ``EV_*``) are checked, and when one changes sign its root is located by the Illinois
method on the step length (an impact starting from the root of the step's quintic
interpolant). The state is advanced to the root, the event is applied, and the next mode is
chosen among all candidate modes consistent with the velocities by :func:`select_mode`.

Nothing here allocates per step; the kernels take only arrays and scalars.
:func:`run_cases`, the one compiled entry point (:func:`run` and
:func:`~shipblock.simulate_batch` call it), only allocates the work arrays: the loop itself
(:func:`integrate`), mode selection and the functions it calls are compiled without reference
counting, like the closed-form span (see
:mod:`~shipblock.solver._closed_form`).

Compilation. The small functions of the step (``forceinline=True`` throughout the solver's
modules) are inlined by LLVM, not by numba: numba's own inlining (``inline="always"``) typed
and copied a function's body again at every call site, in every caller, which took most of the
two minutes the first run spent compiling. Each is now typed and compiled once and marked
``alwaysinline``; LLVM inlines it where it is called, so the machine code and the results are
those of before, bit for bit, at the same speed (docs/benchmarks). The other functions say
``forceinline=False``: numba hands the flags of a function being compiled down to the callees
it compiles for it, and a function that should stay out of line must not inherit the flag
from whichever caller compiled it first. Constants passed to compiled functions are typed
``np.int64(0)`` or ``np.bool_(True)`` where a plain ``0`` or ``True`` would be a literal:
numba compiles a function once more for each literal argument.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from shipblock.equations import (
    I_FX,
    I_FY,
    I_SFX,
    I_SFY,
    N_SOLVE_OUT,
    input_power_at,
    kinetic_energy,
    pivot_geometry,
    potential_energy,
    solve_mode,
    solve_mode_at,
    stuck_rocking_gain,
    stuck_rocking_rates,
)
from shipblock.impact import apply_impact, apply_jam
from shipblock.modes import MODE_NUMBER, EventKind, Failure
from shipblock.solver._closed_form import mode_response_start, nonrocking_span
from shipblock.solver._dopri import DP_A, DP_C, DP_E, DP_ERROR_ORDER
from shipblock.solver._events import (
    event_functions,
    held_margin,
    impact_return_time,
    note_held_margin,
    rearm,
    rotation_event,
    shifted_level,
)
from shipblock.solver._ground import ground_motion_at, one_sided_motion
from shipblock.solver._history import store_sample
from shipblock.solver._interpolate import (
    bracketed_root,
    dip_possible,
    hermite_extremum,
    quintic_hermite,
    rotation_dip,
    rotation_peak,
)
from shipblock.solver._layout import (  # noqa: F401  (re-exported for the wrappers)
    ACC_TOL,
    EV_G_SLIP,
    EV_G_STICK,
    EV_IMPACT,
    EV_OVERTURN,
    EV_S_SLIP,
    EV_S_STICK,
    EV_SEP_G,
    EV_SEP_S,
    EV_UPLIFT,
    EVENT_PRIORITY,
    FORCE_TOL,
    GUESS_PROBE,
    H_KIN,
    H_POT,
    MAX_EVENTS_PER_SAMPLE,
    MAX_FACTOR,
    MIN_FACTOR,
    MIN_STEP,
    MS_ROCK,
    MS_S,
    MS_SIG1,
    MS_SIG2,
    MS_SLIP1,
    MS_SLIP2,
    N_DYN,
    N_EVENTS,
    N_HIST,
    N_SPAN_WORK,
    N_STATE,
    N_SUMMARY,
    ONE_SIDED_DT,
    ONE_SIDED_WIDE,
    REARM_TOL,
    ROOT_TIME_TOL,
    S_DISSIPATED,
    S_END_TIME,
    S_ENERGY_FINAL,
    S_FAILURE,
    S_FAILURE_TIME,
    S_IMPACT_LOSS,
    S_MARGIN,
    S_MODE_TIME,
    S_N_EVENTS,
    S_N_IMPACTS,
    S_N_JAMS,
    S_PEAK_CORNER,
    S_PEAK_FX,
    S_PEAK_FY,
    S_PEAK_SFX,
    S_PEAK_SFY,
    S_PEAK_TH,
    S_PEAK_TH_TIME,
    S_PEAK_UTIL_G,
    S_PEAK_UTIL_S,
    S_PEAK_XB,
    S_PEAK_XS,
    S_RES_XB,
    S_RES_XS,
    S_UPLIFT,
    S_W_IN,
    SAFETY,
    W_FOLDED,
    W_NOTED,
    W_RESP_STATE,
    Y_DIS,
    Y_IMP,
    Y_OM,
    Y_TH,
    Y_VB,
    Y_VS,
    Y_WIN,
    Y_XB,
    Y_XS,
    parameter_tuple,
)
from shipblock.solver._force_sampling import note_loads, span_loads, state_loads
from shipblock.solver._stuck_rocking import (
    advance_stuck,
    is_stuck_rocking,
    stuck_forces_into,
    stuck_rocking_span,
)
from shipblock.solver._workqueue import claim_next
from shipblock.system import P_B, P_G, P_H, P_M, P_MUS1, P_MUS2, P_NM, P_R


@njit(cache=True, forceinline=True)
def rhs(p, ms, y, a, ay, stages, st, w7):
    """Time derivative of the state in the mode ``ms`` into ``stages[st]``; False if singular."""
    rock = ms[MS_ROCK]
    s = float(ms[MS_S])
    # the geometry once for both the equations and the input power (one sine and cosine)
    c, sn = pivot_geometry(p, y[Y_TH], s, rock)
    ok = solve_mode_at(
        p, ms[MS_SLIP1], rock, ms[MS_SLIP2], s, float(ms[MS_SIG1]), float(ms[MS_SIG2]), c, sn,
        y[Y_OM], a, p[P_G] + ay, w7,
    )
    stages[st, Y_XB] = y[Y_VB]
    stages[st, Y_TH] = y[Y_OM]
    stages[st, Y_XS] = y[Y_VS]
    stages[st, Y_VB] = w7[0]
    stages[st, Y_OM] = w7[1]
    stages[st, Y_VS] = w7[2]
    stages[st, Y_WIN] = input_power_at(p, c, sn, s, y[Y_VB], y[Y_OM], y[Y_VS], a, ay)
    stages[st, Y_DIS] = -(w7[I_FX] * y[Y_VB] + w7[I_SFX] * y[Y_VS])
    stages[st, Y_IMP] = 0.0
    return ok


@njit(cache=True, forceinline=True)
def advance(p, ms, y0, k, tau, h, dt, ax, ay, has_ay, sh, sv, y1, stages, ytmp, w7,
            first_stage_known, rtol, atol):
    """One Dormand-Prince 5(4) step of ``h`` within sample interval ``k``: its error norm.

    Returns the RMS of the embedded error estimate scaled by ``atol + rtol*|y|``
    (:func:`error_norm`), or -1 if the equations are singular. ``y1`` gets the 5th-order
    solution, ``stages[6]`` the rates there and ``w7`` the accelerations and forces there.
    Used for rocking modes (rest and sliding are advanced in closed form by
    :func:`~shipblock.solver._closed_form.nonrocking_span`). With ``first_stage_known`` the
    first stage, f(t, y0), is taken from ``stages[0]`` as left there by the previous step
    (first same as last) or by an earlier step from the same ``y0``.

    The usual rocking mode, on two stuck interfaces, takes the same step on its three moving
    states (:func:`~shipblock.solver._stuck_rocking.advance_stuck`).
    """
    if h == 0.0:
        for i in range(y0.shape[0]):
            y1[i] = y0[i]
        return 0.0
    if is_stuck_rocking(ms, y0):
        return advance_stuck(p, ms, y0, k, tau, h, dt, ax, ay, has_ay, sh, sv, y1, stages, w7,
                             first_stage_known, rtol, atol)
    if not advance_general(p, ms, y0, k, tau, h, dt, ax, ay, has_ay, sh, sv, y1, stages, ytmp,
                           w7, first_stage_known):
        return -1.0
    return error_norm(y0, y1, stages, h, rtol, atol)


@njit(cache=True, forceinline=True)
def advance_general(p, ms, y0, k, tau, h, dt, ax, ay, has_ay, sh, sv, y1, stages, ytmp, w7,
                    first_stage_known):
    """The step of :func:`advance` in any rocking mode, on the whole state: False if singular.

    The error estimate is left in ``stages`` for :func:`error_norm`.
    """
    n = y0.shape[0]
    # the step stays within sample interval k, where the input is linear in time
    # (the same arithmetic as ground_motion_at)
    a0 = sh * ax[k]
    a1 = sh * ax[k + 1]
    b0 = sv * ay[k] if has_ay else 0.0
    b1 = sv * ay[k + 1] if has_ay else 0.0
    for st in range(7):
        if st == 0 and first_stage_known:
            continue
        for i in range(n):
            acc = y0[i]
            for j in range(st):
                acc += h * DP_A[st, j] * stages[j, i]
            ytmp[i] = acc
        f = (tau + DP_C[st] * h) / dt
        if not rhs(p, ms, ytmp, a0 + (a1 - a0) * f, b0 + (b1 - b0) * f, stages, st, w7):
            return False
    for i in range(n):
        y1[i] = ytmp[i]  # the 7th stage point is the 5th-order solution (FSAL)
    return True


@njit(cache=True, forceinline=True)
def error_norm(y0, y1, stages, h, rtol, atol):
    """RMS of the embedded error estimate scaled by atol + rtol*|y| over the dynamic states."""
    acc = 0.0
    for i in range(N_DYN):
        e = 0.0
        for st in range(7):
            e += DP_E[st] * stages[st, i]
        e *= h
        sc = atol + rtol * max(abs(y0[i]), abs(y1[i]))
        acc += (e / sc) ** 2
    return math.sqrt(acc / N_DYN)


@njit(cache=True, forceinline=False, _nrt=False)
def event_values(p, ms, y, k, tau, dt, ax, ay, has_ay, sh, sv, g, w7):
    """Fill ``g`` with the event functions at (t_k + tau, y); ``w7`` gets accelerations/forces."""
    a, b = ground_motion_at(ax, ay, has_ay, sh, sv, k, tau, dt)
    ok = solve_mode(
        p, ms[MS_SLIP1], ms[MS_ROCK], ms[MS_SLIP2], float(ms[MS_S]), float(ms[MS_SIG1]),
        float(ms[MS_SIG2]), y[Y_TH], y[Y_OM], a, p[P_G] + b, w7,
    )
    event_functions(p, ms, y, w7[I_FX], w7[I_FY], w7[I_SFX], w7[I_SFY], g)
    return ok


@njit(cache=True, forceinline=True)
def event_slope(e, ms, y, w7):
    """Time derivative of the velocity-type event functions (0 for the others)."""
    if e == EV_G_SLIP:
        return ms[MS_SIG1] * w7[0]
    if e == EV_S_SLIP:
        return ms[MS_SIG2] * w7[2]
    if e == EV_IMPACT:
        return ms[MS_S] * y[Y_OM]
    return 0.0


@njit(cache=True, forceinline=True)
def start_slope(e, ms, y, acc_b, acc_s):
    """Slope of a velocity-type event function at the start of a step.

    ``acc_b`` and ``acc_s`` are the slip accelerations there (the step's first stage).
    """
    if e == EV_G_SLIP:
        return ms[MS_SIG1] * acc_b
    if e == EV_S_SLIP:
        return ms[MS_SIG2] * acc_s
    return ms[MS_S] * y[Y_OM]


@njit(cache=True, forceinline=True)
def has_slope(e):
    """Whether event ``e`` has a slope at the ends of a step (a velocity or the rotation)."""
    return e in (EV_G_SLIP, EV_S_SLIP, EV_IMPACT)


@njit(cache=True, forceinline=False, _nrt=False)
def event_after(e, p, ms, y0, k, tau, h, dt, ax, ay, has_ay, sh, sv, y1, stages, ytmp, w7, g):
    """Event function ``e`` after advancing ``y0`` by ``h`` (state left in ``y1``).

    Called only after a step from ``y0``, so ``stages[0]`` already holds f(t, y0). ``g`` gets
    all event functions there, except for the events of the rotation alone (impact,
    overturning), which need no forces.
    """
    advance(p, ms, y0, k, tau, h, dt, ax, ay, has_ay, sh, sv, y1, stages, ytmp, w7, np.bool_(True), 1.0,
            1.0)
    if e in (EV_IMPACT, EV_OVERTURN):
        return rotation_event(p, ms, e, y1[Y_TH])
    event_values(p, ms, y1, k, tau + h, dt, ax, ay, has_ay, sh, sv, g, w7)
    return g[e]


@njit(cache=True, forceinline=False, _nrt=False)
def locate_root(e, level, lo, g_lo, hi, g_hi, guess, p, ms, y0, k, tau, dt, ax, ay, has_ay,
                sh, sv, y1, stages, ytmp, w7, g):
    """Illinois iteration for the step length at which event ``e`` crosses its ``level`` (0,
    or the shifted level of :func:`~shipblock.solver._events.shifted_level`).

    ``g_lo >= 0 > g_hi``, both relative to ``level``. ``guess`` (ignored unless inside the
    bracket) is a first estimate of the root, e.g. from an interpolant: it and a point
    ``GUESS_PROBE`` beyond it are tried first, which usually leaves a bracket a few
    ``ROOT_TIME_TOL`` wide. Returns the violated
    end of the final bracket (width <= ROOT_TIME_TOL), so the event has just happened there.
    """
    if lo < guess < hi:
        gm = event_after(e, p, ms, y0, k, tau, guess, dt, ax, ay, has_ay, sh, sv,
                         y1, stages, ytmp, w7, g) - level
        if gm < 0.0:
            hi, g_hi = guess, gm
            probe = guess - GUESS_PROBE
        else:
            lo, g_lo = guess, gm
            probe = guess + GUESS_PROBE
        if lo < probe < hi:
            gm = event_after(e, p, ms, y0, k, tau, probe, dt, ax, ay, has_ay, sh, sv,
                             y1, stages, ytmp, w7, g) - level
            if gm < 0.0:
                hi, g_hi = probe, gm
            else:
                lo, g_lo = probe, gm
    side = 0
    for _ in range(200):
        if hi - lo <= ROOT_TIME_TOL:
            break
        # a secant step, or the midpoint when the ends are level
        mid = 0.5 * (lo + hi) if g_lo == g_hi else hi - g_hi * (hi - lo) / (g_hi - g_lo)
        # keep the trial strictly inside, and fall back to bisection near the ends
        width = hi - lo
        if not (lo + 0.01 * width < mid < hi - 0.01 * width):
            mid = 0.5 * (lo + hi)
        gm = event_after(e, p, ms, y0, k, tau, mid, dt, ax, ay, has_ay, sh, sv,
                         y1, stages, ytmp, w7, g) - level
        if gm < 0.0:
            hi, g_hi = mid, gm
            if side == -1:
                g_lo *= 0.5
            side = -1
        else:
            lo, g_lo = mid, gm
            if side == 1:
                g_hi *= 0.5
            side = 1
    return hi


@njit(cache=True, forceinline=False, _nrt=False)
def first_before_impact(t_imp, p, ms, y0, k, tau, dt, ax, ay, has_ay, sh, sv, y1, stages, ytmp,
                        w7, g, g0, levels):
    """The first event of a step that holds an impact at ``t_imp``: ``(time, event)``.

    The events of a step are found from its end, but past an impact the mode's equations run
    on with the pivot on the wrong corner, so a condition crossed before the impact and met
    again by the end of the step went unseen (until 2026-11-26; found by the constraint audit
    of the random campaign, a stick cone violated by up to 1 % of the weight at the impact).
    The event functions are evaluated at the impact (one step of ``t_imp`` from ``y0``,
    whose event functions are ``g0``), and any below its level there is located before it;
    the earliest is returned, or the impact.
    """
    best_h = t_imp
    best_e = np.int64(EV_IMPACT)
    event_after(np.int64(EV_SEP_G), p, ms, y0, k, tau, t_imp, dt, ax, ay, has_ay, sh, sv, y1,
                stages, ytmp, w7, g)
    below = 0  # (a bit per event below its level at the impact; g is work of the root search)
    for e in range(N_EVENTS):
        level = levels[e]
        if (e != EV_IMPACT and e != EV_OVERTURN and level != -np.inf and g[e] < level
                and g0[e] > level):
            below |= 1 << e
    if below == 0:
        return best_h, best_e
    for ie in range(N_EVENTS):
        e = EVENT_PRIORITY[ie]
        if below & (1 << e):
            level = levels[e]
            g_hi = event_after(e, p, ms, y0, k, tau, t_imp, dt, ax, ay, has_ay, sh, sv, y1,
                               stages, ytmp, w7, g) - level
            root = locate_root(e, level, 0.0, g0[e] - level, t_imp, g_hi, -1.0, p, ms, y0, k,
                               tau, dt, ax, ay, has_ay, sh, sv, y1, stages, ytmp, w7, g)
            if root < best_h - 2.0 * ROOT_TIME_TOL:
                best_h = root
                best_e = e
    return best_h, best_e


@njit(cache=True, forceinline=True)
def mode_number_of(slip1, rock, slip2):
    """Paper mode number (1..8) of the three interface flags."""
    return MODE_NUMBER[slip1, rock, slip2]


@njit(cache=True, forceinline=True)
def mode_number(ms):
    """Paper mode number (1..8) of a mode state vector."""
    return mode_number_of(ms[MS_SLIP1], ms[MS_ROCK], ms[MS_SLIP2])


@njit(cache=True, forceinline=False)
def interface_option(v, i):
    """Option ``i`` (0..2) of an interface whose motion has velocity ``v``: (flag, sign, new).

    A moving interface (``v != 0``) has one option, moving on in its direction. One at rest
    may stay (flag 0), or start moving either way (flag 1, sign +1 or -1; ``new`` = 1).
    Returns flag -1 for an option that does not exist.
    """
    if v != 0.0:
        if i > 0:
            return -1, 0, 0
        return 1, (1 if v > 0.0 else -1), 0
    flag = 0 if i == 0 else 1
    return flag, (-1 if i == 2 else 1), flag


@njit(cache=True, forceinline=True)
def interface_violated(held, excess, excess_tol, new, push, push_tol):
    """Whether a candidate violates one interface's conditions.

    A held interface (stick, rest) violates its friction cone or moment criterion by
    ``excess`` > ``excess_tol`` (``FORCE_TOL`` times the weight the criterion is relative
    to); a motion that would start must accelerate in its direction, ``push`` >
    ``push_tol`` (``ACC_TOL`` times g, with the acceleration at the interface). The
    tolerances are scaled instead of the quantities divided: this runs for every candidate.
    """
    if held:
        return excess > excess_tol
    return new and push <= push_tol


@njit(cache=True, forceinline=False)
def candidate_options(idx, vb, rot, vs):
    """Interface options of candidate ``idx`` (0..26): three (flag, sign, new) triples.

    ``idx = 9 i_ground + 3 i_rocking + i_ship`` enumerates the options of
    :func:`interface_option`; ``rot`` is theta, or theta_dot at theta = 0 (just after an
    impact), whose sign gives the pivot.
    """
    slip1, sig1, new1 = interface_option(vb, idx // 9)
    rock, s, newr = interface_option(rot, (idx // 3) % 3)
    slip2, sig2, new2 = interface_option(vs, idx % 3)
    return slip1, sig1, new1, rock, s, newr, slip2, sig2, new2


def _candidate_order():
    """The candidates of :func:`select_mode` in its order of preference, for every case.

    The order depends only on which of ``vb``, ``rot``, ``vs`` are zero (``case`` =
    4 [vb != 0] + 2 [rot != 0] + [vs != 0]) and on the trigger, so it is tabulated once here
    instead of being sorted after every event.

    Returns
    -------
    keys : ndarray of int, shape (8, 4, 27)
        By case and trigger + 1, the candidates as ``(r * 16 + mode number) * 32 + idx``
        (``r`` = 0 if the candidate releases the trigger, else 1; ``idx`` as in
        :func:`candidate_options`), sorted by number of new motions, then key.
    counts : ndarray of int, shape (8, 4)
        How many of them exist.
    """
    option = interface_option.py_func  # plain Python: nothing is compiled at import
    keys = np.zeros((8, 4, 27), dtype=np.int64)
    counts = np.zeros((8, 4), dtype=np.int64)
    for case in range(8):
        vb, rot, vs = float(case >> 2), float((case >> 1) & 1), float(case & 1)
        for trigger in range(-1, 3):
            ranked = []
            for idx in range(27):
                slip1, _, new1 = option(vb, idx // 9)
                rock, _, newr = option(rot, (idx // 3) % 3)
                slip2, _, new2 = option(vs, idx % 3)
                if slip1 < 0 or rock < 0 or slip2 < 0:
                    continue
                releases = (new1, newr, new2)[trigger] if trigger >= 0 else 0
                mode = int(MODE_NUMBER[slip1, rock, slip2])
                ranked.append((new1 + newr + new2, ((0 if releases else 1) * 16 + mode) * 32 + idx))
            ranked.sort()
            counts[case, trigger + 1] = len(ranked)
            keys[case, trigger + 1, :len(ranked)] = [key for _, key in ranked]
    return keys, counts


CANDIDATE_KEYS, CANDIDATE_COUNTS = _candidate_order()


@njit(cache=True, forceinline=False, _nrt=False)
def select_mode(p, y, ms, a, b, trigger, w7, work, lead, alpha):
    r"""Choose the next mode among the candidates consistent with the velocities.

    Candidates: an interface with a nonzero slip velocity keeps slipping that way; one at zero
    velocity may stick or start slipping either way; a block with theta != 0 (or theta_dot != 0
    after an impact) rocks on the pivot given by that sign; one at rest may stay or start rocking
    on either corner. Each candidate is evaluated ONE_SIDED_DT after the event (the ground input
    ``a``, ``b`` there; a rotation ``theta != 0`` advanced along the motion by ``lead``, see
    below) and is consistent when stick forces lie inside their static friction cones, the
    block-rest moment criterion holds, new motions accelerate in their assumed direction and
    both normal forces are positive.
    Among consistent candidates the one with the fewest new motions wins; ties go to the one
    releasing ``trigger`` (0 ground, 1 rocking, 2 ship), then to the lower paper mode number.
    If none is consistent, the system separates when every candidate has a non-positive normal
    force or when the ship leaving the blocks is consistent (:func:`ship_lifts_off`);
    otherwise the state is in the Painleve regime and the caller jams a slipping interface
    (:func:`resolve_mode`).

    The candidates are visited in that order of preference (by number of new motions, then
    trigger, then mode number; tabulated in ``CANDIDATE_KEYS``), so the first consistent one is
    the choice and the search stops there: after most events one or two candidates are evaluated
    instead of up to 27. A non-rocking candidate is not solved at all: it exists only with the
    block at theta = theta_dot = 0, where its accelerations and forces are ``a w_a + G w_G``
    from the response vectors the closed-form spans keep per run (solved here on the mode's
    first use, see :func:`~shipblock.solver._closed_form.mode_response_start`). After an event
    between sliding and rest modes, the common event of a stick-slip record, no equations are
    solved.

    Parameters
    ----------
    p : ndarray
        Parameter vector (an array, as for
        :func:`~shipblock.solver._closed_form.nonrocking_span`).
    y : ndarray
        State at the event.
    ms : ndarray of int
        Receives the chosen mode state.
    a, b : float
        Scaled horizontal and vertical ground acceleration ONE_SIDED_DT after the event
        [m/s^2] (taken by the caller, so that the record need not be passed: numba passes each
        array argument as several machine words, and this runs at every event).
    trigger : int
        Interface whose event this is: 0 ground, 1 rocking, 2 ship, -1 none.
    lead, alpha : float
        The rocking candidates are evaluated at the rotation the motion reaches ``lead`` [s]
        after the event, :math:`\theta + \dot\theta\,\ell + \alpha\ell^2/2` and
        :math:`\dot\theta + \alpha\ell`, with ``alpha`` the angular acceleration of the
        mode before the event [rad/s^2] (the kernel passes ``ONE_SIDED_DT``, or
        ``ONE_SIDED_WIDE`` with the wider input, after an event in a rocking mode other than
        an impact; 0 otherwise). With the state frozen at the event, a constraint crossed by
        the rotation itself (the ship's friction in free rocking, driven by
        :math:`\ddot\theta` and :math:`\dot\theta^2`) looked as held as at the crossing, and
        the mode was kept past it (issue 32). The candidates' interface options are those of
        the state at the event; a rotation that would reach zero within ``lead`` is not
        advanced.
    w7 : ndarray, shape (N_SOLVE_OUT,)
        Work array: a candidate's :func:`~shipblock.equations.solve_mode` output.
    work : ndarray, shape (N_SPAN_WORK,)
        The run's work array of the closed-form spans (see
        :func:`~shipblock.solver._closed_form.nonrocking_span`), zero at the start of a run:
        its response vectors of the non-rocking modes.

    Returns
    -------
    status : int
        0 a consistent mode was chosen (into ``ms``), 1 none was consistent (``ms`` is then
        left undefined), 2 separation.
    """
    G = p[P_G] + b
    if G <= 0.0:
        return 2  # the ground falls at least as fast as gravity: nothing presses the bodies together
    force_tol = FORCE_TOL * (p[P_NM] + p[P_M]) * p[P_G]  # relative to the weight
    ship_force_tol = FORCE_TOL * p[P_M] * p[P_G]  # to the ship's
    acc_tol = ACC_TOL * p[P_G]
    vb, th, om, vs = y[Y_VB], y[Y_TH], y[Y_OM], y[Y_VS]
    rot = th if th != 0.0 else om
    # the rotation along the motion, ONE_SIDED_DT on (not past zero: an impact is an event)
    th_on = th + lead * (om + 0.5 * alpha * lead)
    om_on = om + alpha * lead
    if not th_on * th > 0.0:
        th_on, om_on = th, om
    all_separate = True
    case = (4 if vb != 0.0 else 0) + (2 if rot != 0.0 else 0) + (1 if vs != 0.0 else 0)
    order = CANDIDATE_KEYS[case, trigger + 1]
    for jc in range(CANDIDATE_COUNTS[case, trigger + 1]):
        idx = order[jc] % 32
        slip1, sig1, new1, rock, s, newr, slip2, sig2, new2 = candidate_options(idx, vb, rot, vs)
        if rock == 0:
            # a non-rocking candidate exists only at theta = theta_dot = 0 (candidate_options),
            # where its output is linear in (a, G): superposed as the closed-form spans do
            start = mode_response_start(p, work, slip1, float(sig1), slip2, float(sig2))
            if start < 0:
                continue  # singular, as solve_mode_at would find
            for i in range(N_SOLVE_OUT):
                w7[i] = work[start + i] * a + work[start + N_SOLVE_OUT + i] * G
        else:
            c, sn = pivot_geometry(p, th_on, float(s), rock)
            if slip1 == 0 and slip2 == 0:
                # mode 3 (both interfaces held, so no slip velocities): its reduced form, the
                # general equations to rounding (tests/test_stuck_rocking.py), after every impact
                al, _ = stuck_rocking_rates(p, stuck_rocking_gain(p), c, sn, float(s), om_on, a,
                                            b)
                stuck_forces_into(p, float(s), c, sn, om_on, al, a, b, w7)
            # solve_mode without its wrapper's call: this runs for one to three candidates per
            # event
            elif not solve_mode_at(p, slip1, rock, slip2, float(s), float(sig1), float(sig2), c,
                                   sn, om_on, a, G, w7):
                continue
        fx, fy, Fx, Fy = w7[I_FX], w7[I_FY], w7[I_SFX], w7[I_SFY]
        if fy <= 0.0 or Fy <= 0.0:
            continue  # a normal force pulls: this contact would separate
        all_separate = False
        # ground, rocking, ship: the constraint held, or the new motion's push
        if interface_violated(slip1 == 0, abs(fx) - p[P_MUS1] * fy, force_tol, new1,
                              sig1 * w7[0], acc_tol):
            continue
        if interface_violated(rock == 0, p[P_H] * abs(fx + Fx) - p[P_B] * (fy + Fy),
                              force_tol * p[P_R], newr, s * w7[1] * p[P_R], acc_tol):
            continue
        if not interface_violated(slip2 == 0, abs(Fx) - p[P_MUS2] * Fy, ship_force_tol, new2,
                                  sig2 * w7[2], acc_tol):
            # the most preferred consistent candidate: the choice
            ms[0], ms[1], ms[2], ms[3], ms[4], ms[5] = slip1, rock, slip2, s, sig1, sig2
            return 0
    if all_separate or ship_lifts_off(p, y, a, G, w7) or blocks_lift_off(p, y, a, G, w7):
        return 2
    return 1


@njit(cache=True, forceinline=False, _nrt=False)
def blocks_lift_off(p, y, a, G, w7):
    """Whether the blocks leaving the ground is a consistent continuation at state ``y``.

    Only rocking blocks can (without rocking, :math:`f_y > 0` while :math:`G > 0`): their
    corner lifts when the centripetal terms outweigh what presses it, in practice when the
    ground falls at nearly :math:`g`. With the ground's friction removed, the pivot's
    effective inertia is positive, so a negative :math:`f_y` of that frictionless contact and
    a consistent lift-off go together (the lift-off does not depend on the ground's friction,
    which it releases). The ship is taken as it is: stuck, or sliding without friction.
    """
    th, om, vs = y[Y_TH], y[Y_OM], y[Y_VS]
    rot = th if th != 0.0 else om
    # frictionless ground (and ship, if it slides)
    pf = (p[0], p[1], p[2], p[3], p[4], p[5], p[6], p[7], 0.0, p[9], 0.0, p[11], p[12], p[13])
    slip2 = 1 if vs != 0.0 else 0
    for ir in range(3):
        rock, s, _ = interface_option(rot, ir)
        if rock != 1:
            continue
        c, sn = pivot_geometry(pf, th, float(s), 1)
        if (solve_mode_at(pf, 1, 1, slip2, float(s), 1.0, 1.0, c, sn, om, a, G, w7)
                and w7[I_FY] < -FORCE_TOL * (p[P_NM] + p[P_M]) * p[P_G]):
            return True
    return False


@njit(cache=True, forceinline=False, _nrt=False)
def ship_lifts_off(p, y, a, G, w7):
    """Whether the ship leaving the blocks is a consistent continuation at state ``y``.

    For each candidate motion of the blocks that rocks (a corner carrying the ship can only
    drop away from it while the blocks rock), the blocks are solved without the ship; the
    continuation is consistent when that motion is (ground force inside its static cone or a
    new slip accelerating in its direction, new rocking accelerating in its direction,
    :math:`f_y > 0`) and the ship's contact corner then accelerates downwards faster than the
    ship falls, :math:`-G - 2Y' > 0` relative to the ground. Called when no mode with contact
    is consistent: with a regular (positive) effective inertia of the ship's contact, a
    negative contact force there and a consistent lift-off go together, and the ship
    separates (:doc:`/theory/transitions`).

    ``p`` is the parameter array, ``a`` and ``G`` the ground input (``G = g + ay``) [m/s^2],
    ``w7`` a work array.
    """
    g = p[P_G]
    R = p[P_R]
    th, om, vb = y[Y_TH], y[Y_OM], y[Y_VB]
    rot = th if th != 0.0 else om
    # the blocks alone: the parameters with no ship
    pf = (0.0, p[1], p[2], p[3], p[4], p[5], p[6], p[7], p[8], p[9], p[10], p[11], p[12],
          p[13])
    block_weight = p[P_NM] * g
    for ir in range(3):
        rock, s, newr = interface_option(rot, ir)
        if rock != 1:
            continue
        c, sn = pivot_geometry(pf, th, float(s), 1)
        for ig in range(3):
            slip1, sig1, new1 = interface_option(vb, ig)
            if slip1 < 0:
                continue
            if not solve_mode_at(pf, slip1, 1, 0, float(s), float(sig1), 1.0, c, sn, om, a, G,
                                 w7):
                continue
            fx, fy = w7[I_FX], w7[I_FY]
            if fy <= 0.0:
                continue
            if slip1 == 0 and abs(fx) - p[P_MUS1] * fy > FORCE_TOL * block_weight:
                continue
            if new1 and sig1 * w7[0] <= ACC_TOL * g:
                continue
            if newr and s * w7[1] * R <= ACC_TOL * g:
                continue
            corner_yacc = 2.0 * R * (s * sn * w7[1] - c * om * om)
            if -G - corner_yacc > ACC_TOL * g:
                return True
    return False


@njit(cache=True, forceinline=False, _nrt=False)
def resolve_mode(p, y, ms, a, b, a_wide, b_wide, trigger, w7, work, K, status, lead_wide,
                 alpha):
    """What follows :func:`select_mode` at ``(a, b)`` when it chose no mode: a jam of a slipping
    interface when no mode is consistent.

    ``status`` is the selection's result. The kernel makes the selection itself and calls this
    only when it was not 0 (so the usual event costs one call and one ground input, and the
    later input ``(a_wide, b_wide)`` is taken only here).

    When the selection finds no consistent mode and no separation, the state is in the
    Painleve regime: a slipping interface's friction makes the effective inertia of the
    rocking negative. The interface jams (:func:`shipblock.impact.apply_jam`: an impulsive
    friction force stops its slip, the rotation keeps its generalised momentum) and the mode
    is selected again from the velocities after the jam. Trials: each slipping interface alone
    (the one slipping against the rocking direction first, the ground first otherwise), then
    both. The first trial whose impulses are admissible (pressing, inside the friction cones)
    and after which a mode is consistent is taken; failing that, the first admissible one
    after which the system separates; failing that, the first after which a mode is
    consistent (impulses beyond a friction cone: not met in random testing).

    Before any of this, a selection with none consistent is repeated with the ground input
    ``(a_wide, b_wide)`` a little later (``ONE_SIDED_WIDE``, and the rotation advanced by
    ``lead_wide`` with the angular acceleration ``alpha``, as in :func:`select_mode`): where a
    constraint is crossed at a slow rate, its violation ``ONE_SIDED_DT`` after the event can
    exceed ``FORCE_TOL`` while the new motion's push is still below ``ACC_TOL`` (the two
    tolerances are in different units), and neither the held nor the released state passes.
    The selections after a jam take the state as it is (the jam changed the velocities).

    Returns
    -------
    status : int
        0 a consistent mode (in ``ms``; also for a ``status`` of 0 given), 2 separation, 1 no
        trial helped (the velocities are then those before the jam).
    loss : float
        Kinetic energy lost in the jam [J] (0 without one).
    jammed : int
        0 no jam, 1 the ground interface, 2 the ship interface, 3 both.
    jam_from : int
        Mode number of the motions at the event (the interfaces moving before a jam).
    """
    if status == 0:
        return 0, 0.0, 0, mode_number(ms)
    if status == 1 and select_mode(p, y, ms, a_wide, b_wide, trigger, w7, work, lead_wide,
                                   alpha) == 0:
        return 0, 0.0, 0, mode_number(ms)
    vb, om, vs = y[Y_VB], y[Y_OM], y[Y_VS]
    rot = y[Y_TH] if y[Y_TH] != 0.0 else om
    jam_from = mode_number_of(1 if vb != 0.0 else 0, 1 if rot != 0.0 else 0,
                              1 if vs != 0.0 else 0)
    if status != 1 or (vb == 0.0 and vs == 0.0):
        return status, 0.0, 0, jam_from
    first = 1 if vb != 0.0 else 2
    if vb != 0.0 and vs != 0.0 and rot * vs < 0.0 <= rot * vb:
        first = 2  # the ship slips against the rocking direction, the ground does not
    sep_jam = 0
    any_jam = 0
    for trial in range(3):
        jam = first if trial == 0 else (3 - first if trial == 1 else 3)
        if (jam & 1 and vb == 0.0) or (jam & 2 and vs == 0.0):
            continue
        y[Y_VB], y[Y_OM], y[Y_VS] = vb, om, vs
        loss, admissible = apply_jam(p, jam & 1 != 0, jam & 2 != 0, y, K)
        status = select_mode(p, y, ms, a, b, trigger, w7, work, 0.0, 0.0)
        if status == 0 and admissible:
            return 0, loss, jam, jam_from
        if status == 2 and admissible and sep_jam == 0:
            sep_jam = jam
        if status == 0 and any_jam == 0:
            any_jam = jam
    jam = sep_jam if sep_jam != 0 else any_jam
    y[Y_VB], y[Y_OM], y[Y_VS] = vb, om, vs
    if jam == 0:
        return 1, 0.0, 0, jam_from
    loss, _ = apply_jam(p, jam & 1 != 0, jam & 2 != 0, y, K)
    status = select_mode(p, y, ms, a, b, trigger, w7, work, 0.0, 0.0)
    return status, loss, jam, jam_from


@njit(cache=True, forceinline=True)
def log_event(ev_t, ev_kft, log_size, n_ev, t, kind, from_mode, to_mode):
    """Write event ``n_ev`` (time, kind, modes before and after) if the log has room: n_ev + 1."""
    if n_ev < log_size:
        ev_t[n_ev] = t
        ev_kft[0, n_ev] = kind
        ev_kft[1, n_ev] = from_mode
        ev_kft[2, n_ev] = to_mode
    return n_ev + 1


def run(p_vec, ax, ay, has_ay, sh, sv, dt, rtol, atol, zeno_omega, store, hist, modes, ev_t,
        ev_kft, summary, y_init):
    """Integrate one record: a batch of one case of :func:`run_cases`.

    Parameters
    ----------
    p_vec : ndarray
        Parameter vector (used as a tuple inside: a tuple is passed by value, with no
        reference count for parallel runs to contend on; the functions compiled without
        reference counting, called at every event, take the array, which is cheaper to pass).
    ax, ay : ndarray
        Horizontal and vertical ground acceleration at the samples [m/s^2] (``ay`` ignored
        unless ``has_ay``).
    sh, sv : float
        Scale factors applied to ``ax`` and ``ay``.
    dt : float
        Sample interval [s].
    rtol, atol : float
        Error tolerances of the rocking integration.
    zeno_omega : float
        Rocking stops when an impact leaves less than this angular velocity [rad/s].
    store : bool
        Fill ``hist`` (N_HIST x n: state, kinetic and potential energy, one row per quantity so
        each history is contiguous) and ``modes`` (n).
    hist, modes : ndarray
        History outputs (ignored unless ``store``).
    ev_t, ev_kft : ndarray, shapes (m,) and (3, m)
        Event log (filled when ``store``): time and (kind, mode before, mode after) of the
        first ``m`` events. The caller sizes it (the count is ``summary[S_N_EVENTS]``; a log
        too short is run again longer): a log grown in here would be an array reassigned in
        the main loop, which numba reference-counts on every pass.
    summary : ndarray, shape (N_SUMMARY,)
        Receives the summary of the run.
    y_init : ndarray, shape (6,)
        Initial ``(x_b, theta, x_s, v_b, theta_dot, v_s)``.
    """
    ints = np.zeros((3, 1), dtype=np.int64)  # record, parameter row, claim counter
    # numba types a read-only array apart: it would compile the whole solver once more for one
    if not ax.flags.writeable:
        ax, ay = np.array(ax), (None if ay is ax else ay)
        ay = ax if ay is None else ay
    if not ay.flags.writeable:
        ay = np.array(ay)
    run_cases(np.ascontiguousarray(p_vec).reshape(1, -1), ax, ay,
              np.array([0, ax.shape[0]], dtype=np.int64), np.array([float(dt)]),
              np.array([has_ay], dtype=np.bool_), ints[0], ints[1], np.array([float(sh)]),
              np.array([float(sv)]), rtol, atol, zeno_omega, ints[2], summary.reshape(1, -1),
              bool(store), hist, modes, ev_t, ev_kft, np.asarray(y_init, dtype=float),
              *new_work())


# IEEE division (error_model="numpy") as in the closed-form span inlined here: the default
# would add a zero test before every division
@njit(cache=True, forceinline=False, error_model="numpy", _nrt=False)
def integrate(p_vec, ax, ay, has_ay, sh, sv, dt, rtol, atol, zeno_omega, store, hist, modes,
              ev_t, ev_kft, summary, y_init, y, y1, yr, ytmp, f_end, stages, w7, w7b, K, g0, g1,
              gw, span_work, levels, ms):
    """The integration of one case of :func:`run_cases`, in work arrays allocated there.

    Compiled without reference counting: numba would otherwise update the counts of the work
    arrays, atomically, around the functions inlined into the loop, which cost about a quarter
    of a rocking step.

    Parameters
    ----------
    p_vec, ax, ay, has_ay, sh, sv, dt, rtol, atol, zeno_omega, store, hist, modes, ev_t, ev_kft, \
summary, y_init
        As for :func:`run`.
    y, y1, yr, ytmp, f_end : ndarray, shape (N_STATE,)
        Work: the state, the end of a step, a trial state of the root search, the stage point
        and the derivative at the end of a step.
    stages : ndarray, shape (7, N_STATE)
        Work: the Runge-Kutta stages.
    w7, w7b : ndarray, shape (N_SOLVE_OUT,)
        Work: accelerations and forces.
    K : ndarray, shape (3, 3)
        Work of the impact law.
    g0, g1, gw : ndarray, shape (N_EVENTS,)
        Work: the event functions at both ends of a step and in the root search.
    span_work : ndarray, shape (N_SPAN_WORK,)
        Work of the closed-form spans, zero on entry; mode selection shares its response
        vectors.
    levels : ndarray, shape (N_EVENTS,)
        Work: the level below which each event function fires (all 0 on entry; see
        :func:`~shipblock.solver._events.shifted_level`).
    ms : ndarray of int, shape (6,)
        Work: the mode state.
    """
    p = parameter_tuple(p_vec)
    n = ax.shape[0]
    fsal = False  # stages[0] holds f(y) in the current mode
    log_size = ev_t.shape[0] if store else 0
    n_ev = 0
    for i in range(N_SUMMARY):
        summary[i] = 0.0
    summary[S_MARGIN] = 1.0  # (the least margin of the held conditions: none yet)
    impact_loss = 0.0
    failure = 0
    failure_time = np.nan
    n_impacts = 0
    n_jams = 0
    uplift = 0
    peak_xb = 0.0
    peak_th = 0.0
    peak_th_time = 0.0
    peak_xs = 0.0

    for i in range(N_DYN):
        y[i] = y_init[i]
    # the sample index and "no trigger" typed int64 from the start, not as the literals 0 and
    # -1: numba would compile every function they are passed to once more for the literal
    k = np.int64(0)
    tau = 0.0
    a_next, b_next = ground_motion_at(ax, ay, has_ay, sh, sv, k, ONE_SIDED_DT, dt)
    a_wide, b_wide = ground_motion_at(ax, ay, has_ay, sh, sv, k, ONE_SIDED_WIDE, dt)
    status, jam_loss, jammed, jam_from = resolve_mode(
        p_vec, y, ms, a_next, b_next, a_wide, b_wide, np.int64(-1), w7, span_work, K,
        select_mode(p_vec, y, ms, a_next, b_next, np.int64(-1), w7, span_work, 0.0, 0.0), 0.0,
        0.0)
    if status == 2:
        failure = Failure.SEPARATION
        failure_time = 0.0
    elif status == 1:
        failure = Failure.SOLVER_ERROR  # no consistent mode and nothing to jam
        failure_time = 0.0
    kind = EventKind.START
    if status == 2:
        kind = EventKind.SEPARATION
    elif status == 1:
        kind = EventKind.SOLVER_ERROR
    if jammed:
        n_jams += 1
        impact_loss += jam_loss
        y[Y_IMP] += jam_loss
        n_ev = log_event(ev_t, ev_kft, log_size, n_ev, 0.0, EventKind.START, 0, jam_from)
        n_ev = log_event(ev_t, ev_kft, log_size, n_ev, 0.0, EventKind.JAM, jam_from,
                         jam_from if failure else mode_number(ms))
        if failure:
            n_ev = log_event(ev_t, ev_kft, log_size, n_ev, 0.0, kind, jam_from, 0)
    else:
        n_ev = log_event(ev_t, ev_kft, log_size, n_ev, 0.0, kind, 0,
                         0 if failure else mode_number(ms))
    if ms[MS_ROCK]:
        uplift = 1
    event_values(p, ms, y, k, 0.0, dt, ax, ay, has_ay, sh, sv, g0, w7)
    if failure == 0:
        note_loads(p, ms[MS_ROCK], w7[I_FX], w7[I_FY], w7[I_SFX], w7[I_SFY], summary)
    if store:
        if jammed:
            # sample 0 holds the initial state as given (the jam at t = 0 shows from sample 1 on),
            # so that the energy balance of the histories starts from it
            vb_jam, om_jam, vs_jam = y[Y_VB], y[Y_OM], y[Y_VS]
            y[Y_VB], y[Y_OM], y[Y_VS], y[Y_IMP] = y_init[3], y_init[4], y_init[5], 0.0
            store_sample(p, ms, y, hist, modes, k, 0 if failure else mode_number(ms))
            y[Y_VB], y[Y_OM], y[Y_VS], y[Y_IMP] = vb_jam, om_jam, vs_jam, jam_loss
        else:
            store_sample(p, ms, y, hist, modes, k, 0 if failure else mode_number(ms))
    h_rock = dt
    events_here = 0
    g0_stale = False
    loads_pending = False
    while k < n - 1 and failure == 0:
        if ms[MS_ROCK] == 0:
            # rest and sliding: closed form, sample by sample, up to the next event
            k_before = k
            tau_before = tau
            span_impact = False
            k, tau, best_e, span_time, peak_xb, peak_xs = nonrocking_span(
                p_vec, ms, y, k, tau, dt, ax, ay, has_ay, sh, sv, levels, peak_xb, peak_xs, store,
                hist, modes, span_work, summary)
            if best_e != -2:
                summary[S_MODE_TIME + mode_number(ms) - 1] += span_time
                if span_work[W_FOLDED] == 0.0:  # the span left its loads to be scanned
                    span_loads(p_vec, ms, span_work, ax, ay, has_ay, sh, sv, dt, k_before,
                               tau_before, k, tau, summary)
                loads_pending = False
            if k != k_before:
                events_here = 0
            if best_e == -1:
                break  # end of the record
            if best_e == -2:
                failure = Failure.SOLVER_ERROR
                failure_time = k * dt + tau
                break
        else:
            span_impact = False
            if h_rock >= dt and is_stuck_rocking(ms, y):
                # the usual rocking mode: to the next sample and on by whole samples while
                # nothing happens, or up to an impact
                k_before = k
                k, tau, span_impact, span_time, peak_th, peak_th_time = stuck_rocking_span(
                    p, ms, y, k, tau, dt, ax, ay, has_ay, sh, sv, rtol, atol, levels, g0, g1,
                    peak_th, peak_th_time, store, hist, modes, mode_number(ms), summary)
                if span_time > 0.0:
                    summary[S_MODE_TIME + mode_number(ms) - 1] += span_time
                    fsal = False
                    g0_stale = span_impact  # the span left them where it stopped
                if k != k_before:
                    events_here = 0
                if k >= n - 1:
                    break
                if span_impact:
                    best_e = EV_IMPACT  # applied below; the span has advanced to it
                # (otherwise the step the span stopped before is taken below)
            if not span_impact:
                # rocking: error-controlled Dormand-Prince steps within the sample interval, where
                # the input is linear (a step across a sample would straddle a kink of the input)
                if g0_stale:
                    event_values(p, ms, y, k, tau, dt, ax, ay, has_ay, sh, sv, g0, w7)
                    g0_stale = False
                remaining = dt - tau
                h = min(h_rock, remaining)
                err = advance(p, ms, y, k, tau, h, dt, ax, ay, has_ay, sh, sv, y1, stages, ytmp, w7,
                              fsal, rtol, atol)
                fsal = True  # stages[0] holds f(y) now, whatever happens to this step
                if err < 0.0:
                    failure = Failure.SOLVER_ERROR
                    failure_time = k * dt + tau
                    break
                if err > 1.0:
                    h_rock = h * max(MIN_FACTOR, SAFETY * err ** (-1.0 / (DP_ERROR_ORDER + 1)))
                    if h_rock < MIN_STEP:
                        failure = Failure.SOLVER_ERROR
                        failure_time = k * dt + tau
                        break
                    continue
                t_return = impact_return_time(float(ms[MS_S]), y[Y_TH], y[Y_OM], stages[0, Y_OM])
                if h > t_return >= MIN_STEP:
                    # from an impact, no step past the rotation's return to zero: see
                    # impact_return_time (stages[0] stays f(y) for the shorter step)
                    h_rock = t_return
                    continue
                # slopes at both ends (first and last stage) for the interpolants and event checks
                d_start_b = stages[0, Y_VB]
                d_start_s = stages[0, Y_VS]
                al0 = stages[0, Y_OM]
                al1 = stages[6, Y_OM]
                for i in range(N_STATE):
                    f_end[i] = stages[6, i]
                # the last stage solved the equations at (t + h, y1): its forces give the events
                for i in range(N_SOLVE_OUT):
                    w7b[i] = w7[i]
                event_functions(p, ms, y1, w7b[I_FX], w7b[I_FY], w7b[I_SFX], w7b[I_SFY], g1)
                best_h = h + 1.0
                best_e = -1
                for ie in range(N_EVENTS):
                    e = EVENT_PRIORITY[ie]
                    level = levels[e]  # 0, or shifted (a force event), or -inf (disarmed)
                    if level == -np.inf:
                        continue
                    lo = 0.0
                    g_lo = g0[e] - level
                    hi = h
                    g_hi = g1[e] - level
                    fired = False
                    if g_hi < 0.0 and (g_lo > 0.0 or has_slope(e) or g_hi < g_lo):
                        # (a force event that starts at or below its level fires only if it
                        # falls further: one at a shifted level whose mode was kept, recovering,
                        # does not fire again at once; see linear_root)
                        fired = True
                        if g_lo <= 0.0:
                            # started on the boundary: look for the interior maximum first
                            g_lo = 0.0
                            if has_slope(e):
                                d0 = start_slope(e, ms, y, d_start_b, d_start_s)
                                d1 = event_slope(e, ms, y1, w7b)
                                u, _ = hermite_extremum(g0[e], d0 * h, g1[e], d1 * h)
                                if u > 0.0:
                                    gm = event_after(e, p, ms, y, k, tau, u * h, dt, ax, ay, has_ay,
                                                     sh, sv, yr, stages, ytmp, w7, gw)
                                    if gm > 0.0:
                                        lo = u * h
                                        g_lo = gm
                    elif has_slope(e) and g0[e] > 0.0:
                        d0 = start_slope(e, ms, y, d_start_b, d_start_s)
                        d1 = event_slope(e, ms, y1, w7b)
                        if d0 < 0.0 and d1 > 0.0:
                            u, vmin = hermite_extremum(g0[e], d0 * h, g1[e], d1 * h)
                            if u > 0.0 and vmin < 0.0:
                                gm = event_after(e, p, ms, y, k, tau, u * h, dt, ax, ay, has_ay,
                                                 sh, sv, yr, stages, ytmp, w7, gw)
                                if gm < 0.0:
                                    fired = True
                                    hi = u * h
                                    g_hi = gm
                    if (e == EV_IMPACT and not fired and g0[e] >= 0.0
                            and dip_possible(float(ms[MS_S]), y[Y_TH], al0, y1[Y_TH], al1, h)):
                        # both ends on the pivot's side: a pair of crossings inside the step
                        # (out and back, or back and out), read off the rotation's interpolant
                        u, u_top = rotation_dip(float(ms[MS_S]), y[Y_TH], y[Y_OM], al0,
                                                y1[Y_TH], y1[Y_OM], al1, h)
                        if u > 0.0:
                            gm = event_after(e, p, ms, y, k, tau, u * h, dt, ax, ay, has_ay, sh,
                                             sv, yr, stages, ytmp, w7, gw)
                            g_top = g0[e]
                            if u_top > 0.0:
                                g_top = event_after(e, p, ms, y, k, tau, u_top * h, dt, ax, ay,
                                                    has_ay, sh, sv, yr, stages, ytmp, w7, gw)
                            if gm < 0.0 and g_top > 0.0:
                                fired = True
                                lo, g_lo = u_top * h, g_top
                                hi, g_hi = u * h, gm
                    if fired:
                        if g_lo > 0.0:
                            guess = -1.0
                            if e == EV_IMPACT:
                                # first guess: the root of the step's quintic interpolant of theta
                                c0, c1, c2, c3, c4, c5 = quintic_hermite(
                                    y[Y_TH], y[Y_OM], al0, y1[Y_TH], y1[Y_OM], al1, h)
                                u = bracketed_root(c0, c1, c2, c3, c4, c5, lo / h, hi / h, np.bool_(False))
                                if u >= 0.0:
                                    guess = u * h
                            root = locate_root(e, level, lo, g_lo, hi, g_hi, guess, p, ms, y, k,
                                               tau, dt, ax, ay, has_ay, sh, sv, yr, stages, ytmp,
                                               w7, gw)
                        else:
                            root = lo
                        # a later-priority event wins only if it is clearly earlier
                        if root < best_h - 2.0 * ROOT_TIME_TOL:
                            best_h = root
                            best_e = e
                if best_e == EV_IMPACT:
                    best_h, best_e = first_before_impact(
                        best_h, p, ms, y, k, tau, dt, ax, ay, has_ay, sh, sv, yr, stages, ytmp,
                        w7, gw, g0, levels)
                if best_e < 0:
                    # accept the whole step (w7b: the forces at its end)
                    note_loads(p, 1, w7b[I_FX], w7b[I_FY], w7b[I_SFX], w7b[I_SFY], summary)
                    summary[S_MARGIN] = min(summary[S_MARGIN], held_margin(g1, np.int64(-1)))
                    peak_th, peak_th_time = rotation_peak(
                        peak_th, peak_th_time, y[Y_TH], y[Y_OM], al0, y1[Y_TH], y1[Y_OM], al1, h,
                        k * dt + tau, k * dt + (tau + h))
                    for i in range(N_STATE):
                        y[i] = y1[i]
                        stages[0, i] = f_end[i]  # first same as last: f(y) for the next step
                    fsal = True
                    for e in range(N_EVENTS):
                        g0[e] = g1[e]
                    rearm(levels, g1)
                    summary[S_MODE_TIME + mode_number(ms) - 1] += h
                    tau += h
                    if h < remaining:
                        grow = SAFETY * max(err, 1e-10) ** (-1.0 / (DP_ERROR_ORDER + 1))
                        h_rock = h * min(MAX_FACTOR, max(MIN_FACTOR, grow))
        if best_e >= 0:
            # advance to the event (the spans have done so already) and apply it
            if ms[MS_ROCK] and not span_impact:
                advance(p, ms, y, k, tau, best_h, dt, ax, ay, has_ay, sh, sv, y1, stages, ytmp,
                        w7, fsal, rtol, atol)
                for i in range(N_STATE):
                    y[i] = y1[i]
                summary[S_MODE_TIME + mode_number(ms) - 1] += best_h
                tau += best_h
            fsal = False
            t_now = k * dt + tau
            from_mode = mode_number(ms)
            alpha = 0.0  # the angular acceleration before the event, if it rocked
            if ms[MS_ROCK]:
                # (a non-rocking mode's forces here are the end of its span, noted by span_loads)
                state_loads(p_vec, ms, y, k, tau, dt, ax, ay, has_ay, sh, sv, w7, summary)
                # the conditions the mode held up to the event (but the event's own, at its
                # level to within the root's ROOT_TIME_TOL; and none at a separation, where
                # the normal forces vanish and with them the friction they bound)
                if best_e != EV_SEP_G and best_e != EV_SEP_S:
                    note_held_margin(p, ms, y, w7[I_FX], w7[I_FY], w7[I_SFX], w7[I_SFY], gw,
                                     best_e, summary)
                if best_e != EV_IMPACT and math.isfinite(w7[1]):
                    alpha = w7[1]  # (the solve of state_loads; an impact changes the pivot)
            trigger = -1
            kind = EventKind.START
            jammed = 0
            if best_e == EV_G_SLIP:
                y[Y_VB] = 0.0
                trigger = 0
                kind = EventKind.GROUND_SLIP_STOP
            elif best_e == EV_S_SLIP:
                y[Y_VS] = 0.0
                trigger = 2
                kind = EventKind.SHIP_SLIP_STOP
            elif best_e == EV_G_STICK:
                trigger = 0
                kind = EventKind.GROUND_SLIP_START
            elif best_e == EV_S_STICK:
                trigger = 2
                kind = EventKind.SHIP_SLIP_START
            elif best_e == EV_UPLIFT:
                trigger = 1
                kind = EventKind.UPLIFT
                uplift = 1
            elif best_e == EV_IMPACT:
                y[Y_TH] = 0.0
                loss, stopped = apply_impact(p, ms[MS_SLIP1], ms[MS_SLIP2], y, zeno_omega, K)
                impact_loss += loss
                y[Y_IMP] += loss
                n_impacts += 1
                trigger = 1
                kind = EventKind.ROCKING_STOP if stopped else EventKind.IMPACT
            elif best_e == EV_OVERTURN:
                failure = Failure.OVERTURNING
                kind = EventKind.OVERTURNING
            else:
                failure = Failure.SEPARATION
                kind = EventKind.SEPARATION
            trigger_kind = kind
            jam_from = from_mode
            if failure == 0:
                old0, old1, old2, old3, old4, old5 = ms[0], ms[1], ms[2], ms[3], ms[4], ms[5]
                # the input's one-sided limit: on the line of this sample interval
                a_next, b_next = one_sided_motion(ax, ay, has_ay, sh, sv, k, tau, ONE_SIDED_DT,
                                                  dt)
                # the rotation along the motion too, but for an impact (its pivot is new)
                lead = ONE_SIDED_DT if best_e != EV_IMPACT else 0.0
                status = select_mode(p_vec, y, ms, a_next, b_next, trigger, w7, span_work, lead,
                                     alpha)
                jam_loss = 0.0
                if status != 0:
                    a_wide, b_wide = one_sided_motion(ax, ay, has_ay, sh, sv, k, tau,
                                                      ONE_SIDED_WIDE, dt)
                    status, jam_loss, jammed, jam_from = resolve_mode(
                        p_vec, y, ms, a_next, b_next, a_wide, b_wide, trigger, w7, span_work, K,
                        status, ONE_SIDED_WIDE if best_e != EV_IMPACT else 0.0, alpha)
                if jammed:
                    # the jam's loss is booked with the impacts' (a tangential impact)
                    n_jams += 1
                    impact_loss += jam_loss
                    y[Y_IMP] += jam_loss
                if status == 2:
                    failure = Failure.SEPARATION
                    kind = EventKind.SEPARATION
                elif status == 1:
                    # no consistent mode, no separation and no slip to jam: not met in random
                    # testing (docs/theory/transitions.rst); the run stops rather than guess
                    failure = Failure.SOLVER_ERROR
                    kind = EventKind.SOLVER_ERROR
                else:
                    same = (old0 == ms[0] and old1 == ms[1] and old2 == ms[2]
                            and old3 == ms[3] and old4 == ms[4] and old5 == ms[5])
                    if same and best_e != EV_IMPACT and not jammed:
                        # the constraint touched zero and held again as far as the selection
                        # looked: watched on at a shifted level (a force), off until clear of
                        # zero (a slip velocity), see shifted_level
                        if best_e == EV_G_STICK or best_e == EV_S_STICK or best_e == EV_UPLIFT:
                            # (a force event: its level follows its value here)
                            event_values(p, ms, y, k, tau, dt, ax, ay, has_ay, sh, sv, gw, w7)
                        levels[best_e] = shifted_level(best_e, levels[best_e], gw[best_e])
                    else:
                        for e in range(N_EVENTS):
                            levels[e] = 0.0
                    if ms[MS_ROCK]:
                        uplift = 1
                    if ms[MS_ROCK]:
                        state_loads(p_vec, ms, y, k, tau, dt, ax, ay, has_ay, sh, sv, w7, summary)
                    else:
                        # a non-rocking mode's forces here start its span, noted by span_loads;
                        # noted after the loop if no span follows
                        loads_pending = True
            if failure != 0:
                failure_time = t_now
            if jammed or kind != trigger_kind:
                # the event itself, into the motions it leaves; the jam or the failure the mode
                # selection found follows it
                n_ev = log_event(ev_t, ev_kft, log_size, n_ev, t_now, trigger_kind, from_mode,
                                 jam_from)
                events_here += 1
                from_mode = jam_from
            if jammed:
                n_ev = log_event(ev_t, ev_kft, log_size, n_ev, t_now, EventKind.JAM, jam_from,
                                 jam_from if failure else mode_number(ms))
                events_here += 1
            if not jammed or failure != 0:
                n_ev = log_event(ev_t, ev_kft, log_size, n_ev, t_now, kind, from_mode,
                                 0 if failure else mode_number(ms))
                events_here += 1
            if events_here > MAX_EVENTS_PER_SAMPLE and failure == 0:
                failure = Failure.SOLVER_ERROR
                failure_time = t_now
            # the rocking steps compare with the event functions here: evaluated before the
            # kernel's next step, unless a span has left its own (the closed-form span finds
            # its own)
            g0_stale = failure == 0 and ms[MS_ROCK] != 0
        # peaks
        axb = abs(y[Y_XB])
        if axb > peak_xb:
            peak_xb = axb
        ath = abs(y[Y_TH])
        if ath > peak_th:
            peak_th = ath
            peak_th_time = k * dt + tau
        axs = abs(y[Y_XS])
        if axs > peak_xs:
            peak_xs = axs
        if failure == 0 and dt - tau <= 1e-12 * dt:
            k += 1
            tau = 0.0
            events_here = 0
            if store:
                store_sample(p, ms, y, hist, modes, k, mode_number(ms))
    if loads_pending:
        state_loads(p_vec, ms, y, k, tau, dt, ax, ay, has_ay, sh, sv, w7, summary)
    end_time = k * dt + tau
    if failure != 0 and store:
        for j in range(k + 1, n):
            for i in range(N_HIST):
                hist[i, j] = np.nan
            modes[j] = 0
    summary[S_PEAK_XB] = peak_xb
    summary[S_PEAK_TH] = peak_th
    summary[S_PEAK_TH_TIME] = peak_th_time
    summary[S_PEAK_XS] = peak_xs
    summary[S_RES_XB] = y[Y_XB]
    summary[S_RES_XS] = y[Y_XS]
    summary[S_UPLIFT] = uplift
    summary[S_N_IMPACTS] = n_impacts
    summary[S_FAILURE] = failure
    summary[S_FAILURE_TIME] = failure_time
    summary[S_END_TIME] = end_time
    summary[S_N_EVENTS] = n_ev
    summary[S_W_IN] = y[Y_WIN]
    summary[S_DISSIPATED] = y[Y_DIS]
    summary[S_IMPACT_LOSS] = impact_loss
    summary[S_N_JAMS] = n_jams
    s_final = float(ms[MS_S]) if ms[MS_ROCK] else 1.0
    summary[S_ENERGY_FINAL] = kinetic_energy(
        p, y[Y_TH], s_final, ms[MS_ROCK], y[Y_VB], y[Y_OM], y[Y_VS]
    ) + potential_energy(p, y[Y_TH])


# without reference counting: with it, every array passed to integrate had its count raised and
# lowered around each case (some fifty atomic operations, half the start of a short case); and
# the work arrays are allocated by the caller (new_work), not here: a compiled function that
# allocated them and called this one would have the solver's code optimised once more (2 s of
# the cold start)
@njit(cache=True, forceinline=False, nogil=True, _nrt=False)
def run_cases(params, acc_h, acc_v, offsets, dts, has_v, case_record, case_params, case_sh,
              case_sv, rtol, atol, zeno_omega, next_case, summaries, store, hist, modes, ev_t,
              ev_kft, y_init, vectors, stages, w7, K, g, span_work, levels, ms):
    """Run cases until none is left; each case is (record, parameter row, H scale, V scale).

    The one compiled entry point of the solver: :func:`run` (one record, with its histories)
    and :func:`~shipblock.simulate_batch` (many cases, summaries only) both call it, so that
    the integration is compiled once, for one caller.

    Records are concatenated in ``acc_h``/``acc_v``; record ``r`` occupies
    ``offsets[r]:offsets[r+1]``. The caller claims the next unclaimed case from the counter
    ``next_case`` (int64, length 1, zero at the start of the batch) until none is left, so that
    several threads calling this at once on the same arguments share the cases out
    dynamically: uneven case costs do not idle a thread, and a thread the operating system sets
    aside holds up at most the one case it has claimed. The GIL is released (``nogil``) and
    the threads are Python's (:mod:`shipblock.solver._threads`): no parallel region of
    numba's, whose worker threads spin at its barrier, and which takes seconds more to compile.
    The counter must live outside the compiled function, whose optimiser does not see the
    atomic writes to an array it allocated.

    Parameters
    ----------
    params : ndarray, shape (n_systems, n_parameters)
        Parameter vectors, one row per system.
    acc_h, acc_v, offsets, dts, has_v : ndarray
        The records (see :class:`~shipblock.solver._inputs.RecordSet`); ``acc_v`` of a record
        is ignored unless ``has_v``.
    case_record, case_params, case_sh, case_sv : ndarray, shape (n_cases,)
        Each case's record, parameter row and horizontal and vertical scale factors.
    rtol, atol, zeno_omega : float
        As for :func:`run`.
    next_case : ndarray of int64, shape (1,)
        The claim counter.
    summaries : ndarray, shape (n_cases, N_SUMMARY)
        Receives each case's summary.
    store, hist, modes, ev_t, ev_kft : bool and ndarray
        Histories and event log as for :func:`run`, for a batch of one case only (False and
        empty arrays otherwise).
    y_init : ndarray, shape (6,)
        Initial state of every case.
    vectors, stages, w7, K, g, span_work, levels, ms : ndarray
        Work arrays of :func:`integrate`, as :func:`new_work` allocates them, one set per
        calling thread.
    """
    n_cases = case_record.shape[0]
    # the rows of the work arrays, taken once (a view taken per case costs as much as a
    # reference count update would)
    y, y1, yr, ytmp, f_end = vectors[0], vectors[1], vectors[2], vectors[3], vectors[4]
    w7a, w7b = w7[0], w7[1]
    g0, g1, gw = g[0], g[1], g[2]
    last_params = -1
    while True:
        c = claim_next(next_case)
        if c >= n_cases:
            break
        if last_params >= 0:
            # every case starts from the work arrays as allocated (zeros, every event level 0),
            # but for the non-rocking modes' response vectors, kept from the case before when
            # it had the same parameters (they depend on nothing else)
            _reset_work(vectors, stages, w7, K, g, span_work, levels, ms,
                        case_params[c] == last_params)
        last_params = case_params[c]
        r = case_record[c]
        a0 = offsets[r]
        a1 = offsets[r + 1]
        integrate(params[case_params[c]], acc_h[a0:a1], acc_v[a0:a1], has_v[r], case_sh[c],
                  case_sv[c], dts[r], rtol, atol, zeno_omega, store, hist, modes, ev_t, ev_kft,
                  summaries[c], y_init, y, y1, yr, ytmp, f_end, stages, w7a, w7b, K, g0, g1, gw,
                  span_work, levels, ms)


def new_work() -> tuple:
    """A set of work arrays for one thread's :func:`run_cases`: zeros (every event level 0)."""
    return (np.zeros((5, N_STATE)), np.zeros((7, N_STATE)), np.zeros((2, N_SOLVE_OUT)),
            np.zeros((3, 3)), np.zeros((3, N_EVENTS)), np.zeros(N_SPAN_WORK),
            np.zeros(N_EVENTS), np.zeros(6, dtype=np.int64))


def no_histories():
    """Empty ``(hist, modes, ev_t, ev_kft)`` for :func:`run_cases` without histories."""
    return (np.zeros((N_HIST, 0)), np.zeros(0, dtype=np.int64), np.zeros(0),
            np.zeros((3, 0), dtype=np.int64))


@njit(cache=True, forceinline=True, _nrt=False)
def _reset_work(vectors, stages, w7, K, g, span_work, levels, ms, keep_responses):
    """The work arrays of :func:`run_cases` back to their state as allocated; with
    ``keep_responses`` (the next case has the same parameters) all but the closed-form spans'
    solutions that depend on the parameters alone: the non-rocking modes' response vectors,
    held intervals and inverse weights (``W_RESP_STATE`` up to ``W_NOTED``). The range of
    input noted per mode belongs to a run: it is emptied."""
    # each array in turn, not a tuple of them: building a tuple of arrays updates their
    # reference counts (atomically), which cost as much as the rest of a short case's start
    vectors[:, :] = 0.0
    stages[:, :] = 0.0
    w7[:, :] = 0.0
    K[:, :] = 0.0
    g[:, :] = 0.0
    if keep_responses:
        for i in range(W_RESP_STATE):
            span_work[i] = 0.0
        for i in range(W_NOTED, W_FOLDED, 2):
            span_work[i] = np.inf
            span_work[i + 1] = -np.inf
        span_work[W_FOLDED] = 0.0
    else:
        for i in range(span_work.shape[0]):
            span_work[i] = 0.0
    for i in range(levels.shape[0]):
        levels[i] = 0.0
    for i in range(ms.shape[0]):
        ms[i] = 0
