"""Layout of the solver's arrays: state, mode state, events, summary; numerical constants.

Shared by the compiled kernels (:mod:`shipblock.solver._kernel` and
:mod:`shipblock.solver._closed_form`) and the Python wrappers that read their outputs.
"""

import numpy as np
from numba import njit

from shipblock.equations import N_SOLVE_OUT

# State vector.
Y_XB, Y_TH, Y_XS, Y_VB, Y_OM, Y_VS, Y_WIN, Y_DIS, Y_IMP = 0, 1, 2, 3, 4, 5, 6, 7, 8
N_STATE = 9  # the last three accumulate input work, friction dissipation and impact loss [J]
N_DYN = 6  # components under error control
# Extra columns of the stored history: kinetic and potential energy at the samples [J].
H_KIN, H_POT = N_STATE, N_STATE + 1
N_HIST = N_STATE + 2

# Mode state vector: interface flags and signs.
MS_SLIP1, MS_ROCK, MS_SLIP2, MS_S, MS_SIG1, MS_SIG2 = 0, 1, 2, 3, 4, 5

# Event functions; each is >= 0 while its constraint holds.
EV_G_STICK = 0  # blocks stick on the ground: mu_s1 fy - |fx|
EV_G_SLIP = 1  # blocks slide: sigma1 * v_b
EV_UPLIFT = 2  # blocks at rest: B (fy + Fy) - H |fx + Fx|
EV_IMPACT = 3  # rocking: s * theta
EV_OVERTURN = 4  # rocking: theta_c - s * theta
EV_S_STICK = 5  # ship sticks: mu_s2 Fy - |Fx|
EV_S_SLIP = 6  # ship slides: sigma2 * v_s
EV_SEP_G = 7  # fy > 0
EV_SEP_S = 8  # Fy > 0
N_EVENTS = 9
#: Order in which simultaneous events are taken: failures first, then velocity events.
EVENT_PRIORITY = np.array(
    [EV_SEP_G, EV_SEP_S, EV_OVERTURN, EV_IMPACT, EV_G_SLIP, EV_S_SLIP, EV_UPLIFT, EV_G_STICK,
     EV_S_STICK],
    dtype=np.int64,
)

# Summary vector of one run.
S_PEAK_XB = 0
S_PEAK_TH = 1
S_PEAK_XS = 2
S_RES_XB = 3
S_RES_XS = 4
S_UPLIFT = 5
S_N_IMPACTS = 6
S_FAILURE = 7
S_FAILURE_TIME = 8
S_MODE_TIME = 9  # 8 entries, modes 1..8
S_END_TIME = 17
S_N_EVENTS = 18
S_W_IN = 19
S_DISSIPATED = 20
S_IMPACT_LOSS = 21
S_N_JAMS = 22  # jams of a slipping interface (Painleve regime)
S_ENERGY_FINAL = 23  # T + V at the end
S_PEAK_TH_TIME = 24
# Peak contact loads (see shipblock.solver._force_sampling): interface forces, totals over the n blocks
# [N], and friction utilisations [-].
S_PEAK_FY = 25  # ground on blocks, normal
S_PEAK_FX = 26  # ground on blocks, |friction|
S_PEAK_SFY = 27  # blocks on ship, normal
S_PEAK_SFX = 28  # blocks on ship, |friction|
S_PEAK_UTIL_G = 29  # |fx| / (mu_s1 fy)
S_PEAK_UTIL_S = 30  # |Fx| / (mu_s2 Fy)
S_PEAK_CORNER = 31  # fy while the blocks rock (on their pivot corners)
# The least margin of the conditions the mode holds (stick cones, the blocks' moment criterion,
# normal forces: EV_G_STICK, EV_S_STICK, EV_UPLIFT, EV_SEP_G, EV_SEP_S where they apply) over the
# ends of the run's accepted steps and sample intervals and up to each event (the event's own
# function, at its level there, left out; and none up to a separation) [-], see
# shipblock.solver._events.held_margin. The mode an event enters is judged by the mode
# selection ONE_SIDED_DT after it. At least -FORCE_TOL (to rounding) when every constraint holds
# to the tolerance (issue 32). Not one of the batch's fields: simulate reports it as
# "least_constraint_margin".
S_MARGIN = 32
N_SUMMARY = 33

# Work array of the closed-form spans (one per run, see ``nonrocking_span``): the event
# functions, then per response slot its state (0 not solved, 1 solved, 2 singular) and its two
# response vectors, then the inverse weights (0 until the first span sets them), then per
# response slot its interval of held conditions. One array
# rather than several: the span is called at every event, and numba passes each array argument
# as several machine words.
N_RESP_SLOTS = 9  # 3 ground x 3 ship interface states
W_G = 0
W_RESP_STATE = W_G + N_EVENTS
W_RESP = W_RESP_STATE + N_RESP_SLOTS
W_INV_W = W_RESP + 2 * N_SOLVE_OUT * N_RESP_SLOTS  # 1 / weight
W_INV_WS = W_INV_W + 1  # 1 / ship weight
W_INV_WR = W_INV_W + 2  # 1 / (weight R)
# per response slot, the horizontal accelerations [lo, hi] at which the conditions the mode
# holds surely hold without a vertical input (see ``held_interval``), set with its response
W_HELD = W_INV_W + 3
# per response slot, the range [lo, hi] of scaled horizontal input whose contact loads have been
# noted in the run's peaks (see ``note_span_extremes`` in shipblock.solver._running_peaks), set
# empty (inf, -inf) with its response vectors
W_NOTED = W_HELD + 2 * N_RESP_SLOTS
# 1 if the last span noted its contact loads itself, 0 if span_loads is to scan them
W_FOLDED = W_NOTED + 2 * N_RESP_SLOTS
N_SPAN_WORK = W_FOLDED + 1

# Numerical constants (documented in docs/theory/solver.md).
ROOT_TIME_TOL = 1e-12  # [s] width of the bracket that locates an event
# [s] offset of the second trial after an interpolated first guess: half ROOT_TIME_TOL, so a
# good guess closes the bracket at once
GUESS_PROBE = 5e-13
ONE_SIDED_DT = 1e-8  # [s] candidate modes are checked this long after an event
# [s] and this long, when none is consistent at ONE_SIDED_DT (a slow crossing, see resolve_mode)
ONE_SIDED_WIDE = 1e-6
FORCE_TOL = 1e-10  # [-] tolerance on force margins, relative to the weight
ACC_TOL = 1e-10  # [-] a new motion must accelerate by more than this times g
REARM_TOL = 1e-9  # [-] a disarmed event is re-armed once its function exceeds this
# [-] a force event re-selected is watched at least this far below its function's value
# (above the rounding of event functions of order 1; see _events.shifted_level)
LEVEL_GAP = 1e-15
MAX_STEP_SAMPLES = 1.0  # [-] longest rocking step, in input samples (see docs/theory/solver)
MIN_STEP = 1e-13  # [s] smallest rocking step before the run is declared failed
MAX_EVENTS_PER_SAMPLE = 20000  # guards against chattering
SAFETY = 0.9
MIN_FACTOR = 0.2
MAX_FACTOR = 5.0


@njit(cache=True, forceinline=False)
def parameter_tuple(p):
    """The parameter vector as a tuple (see ``shipblock.system.P_*``, 14 entries)."""
    return (p[0], p[1], p[2], p[3], p[4], p[5], p[6], p[7], p[8], p[9], p[10], p[11], p[12],
            p[13])
