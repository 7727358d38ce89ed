"""Event-driven simulation of the ship-block system.

:func:`simulate` runs one ground motion and returns the full response;
:func:`simulate_batch` runs many (record, scale, system) cases in one compiled, parallel call and
returns their summaries.
"""

from __future__ import annotations

import warnings
from collections.abc import Sequence

import numba
import numpy as np

from shipblock.errors import ParameterError
from shipblock.result import Energy, EventLog, SimulationResult, failure_name
from shipblock.solver import _kernel as K
from shipblock.solver._inputs import RecordSet, as_acceleration, check_dt, check_options
from shipblock.solver._threads import batch_threads, run_on_threads
from shipblock.system import P_THC, ShipBlockSystem

#: Default relative tolerance of the rocking integration [-].
DEFAULT_RTOL = 1e-8
#: Default absolute tolerance of the rocking integration [SI units of each state].
DEFAULT_ATOL = 1e-10
#: Rocking stops when an impact leaves less angular velocity than this [rad/s].
DEFAULT_ZENO_OMEGA = 1e-7

#: Names of the summary entries, in the order of the compiled summary vector.
SUMMARY_FIELDS = {
    "peak_block_slip": K.S_PEAK_XB,
    "peak_rotation": K.S_PEAK_TH,
    "peak_rotation_time": K.S_PEAK_TH_TIME,
    "peak_ship_slip": K.S_PEAK_XS,
    "residual_block_slip": K.S_RES_XB,
    "residual_ship_slip": K.S_RES_XS,
    "uplift": K.S_UPLIFT,
    "n_impacts": K.S_N_IMPACTS,
    "failure": K.S_FAILURE,
    "failure_time": K.S_FAILURE_TIME,
    "end_time": K.S_END_TIME,
    "n_events": K.S_N_EVENTS,
    "input_work": K.S_W_IN,
    "friction_dissipation": K.S_DISSIPATED,
    "impact_loss": K.S_IMPACT_LOSS,
    "n_mode_fallbacks": K.S_N_FALLBACK,
    "final_energy": K.S_ENERGY_FINAL,
}
MODE_TIME_FIELDS = [f"time_in_mode_{m}" for m in range(1, 9)]


def simulate(
    system: ShipBlockSystem,
    ax,
    ay=None,
    dt: float | None = None,
    *,
    rtol: float = DEFAULT_RTOL,
    atol: float = DEFAULT_ATOL,
    zeno_omega: float = DEFAULT_ZENO_OMEGA,
    initial_state=None,
) -> SimulationResult:
    """Simulate the ship-block system under a horizontal and vertical ground acceleration.

    The ground acceleration is linear between samples. Every transition between modes (slip
    onset and arrest at either interface, uplift, impact, rocking arrest, overturning,
    separation) is located in time by root finding to about 1e-12 s. Rest and sliding phases are
    integrated exactly; rocking phases by an embedded Runge-Kutta 5(4) method with error
    control by ``rtol``/``atol``.

    Parameters
    ----------
    system : ShipBlockSystem
        The ship-block system.
    ax : array_like or GroundMotion
        Horizontal ground acceleration at ``t_k = k dt`` [m/s^2], positive to the right. A
        :class:`shipblock.motion.GroundMotion` may be passed instead, in which case its
        horizontal, vertical and dt are used.
    ay : array_like or None, optional
        Vertical ground acceleration [m/s^2], positive up; ``None`` for none.
    dt : float
        Sample interval [s].
    rtol, atol : float, optional
        Relative and absolute error tolerance of the rocking phases.
    zeno_omega : float, optional
        Rocking stops when an impact leaves less angular velocity than this [rad/s].
    initial_state : sequence of 6 float, optional
        ``(x_b, theta, x_s, v_b, theta_dot, v_s)`` at t = 0 [m, rad, m, m/s, rad/s, m/s];
        default at rest. ``|theta|`` must be below the critical angle.

    Returns
    -------
    SimulationResult
        Histories at the samples, events, failure, energy balance and summary.

    Raises
    ------
    ValueError
        For empty or non-finite accelerations, ``dt <= 0`` or ``ax``/``ay`` of different length;
        the message names the argument.

    Examples
    --------
    >>> import numpy as np
    >>> from shipblock import ShipBlockSystem, simulate
    >>> system = ShipBlockSystem(ship_mass=2e6, block_mass=1500.0, n_blocks=120,
    ...                          half_width=0.4, half_height=0.6, mu_s_ground=0.5,
    ...                          mu_k_ground=0.45, mu_s_ship=0.6, mu_k_ship=0.55)
    >>> t = np.arange(0, 2, 0.005)
    >>> res = simulate(system, 6.0 * np.sin(2 * np.pi * t), None, 0.005)
    >>> res.failure is None
    True
    """
    if dt is None and hasattr(ax, "horizontal") and hasattr(ax, "dt"):
        motion = ax
        ax, ay, dt = motion.horizontal, motion.vertical, motion.dt
    if dt is None:
        raise ParameterError("dt [s] is required when ax is an array")
    if not isinstance(system, ShipBlockSystem):
        raise TypeError(f"system must be a ShipBlockSystem, got {type(system).__name__}")
    check_dt(dt)
    check_options(rtol, atol, zeno_omega)
    ax = as_acceleration(ax, "ax")
    if ay is None:
        ay_arr = ax  # a stand-in the kernel never reads (has_ay False): no zeros to allocate
        has_ay = False
    else:
        ay_arr = as_acceleration(ay, "ay")
        if ay_arr.size != ax.size:
            raise ParameterError(f"ax and ay must have the same length, got {ax.size} and {ay_arr.size}")
        has_ay = True
    y_init = np.zeros(6)
    if initial_state is not None:
        y_init = np.asarray(initial_state, dtype=float)
        if y_init.shape != (6,) or not np.isfinite(y_init).all():
            raise ParameterError(
                f"initial_state must be 6 finite numbers (x_b, theta, x_s, v_b, theta_dot, v_s), got {initial_state!r}"
            )
        if abs(y_init[1]) >= system.critical_angle:
            raise ParameterError(
                f"initial_state theta={y_init[1]} is beyond the critical angle {system.critical_angle:.6g} rad"
            )
    p = system.to_parameter_vector()
    n = ax.size
    hist = np.empty((K.N_HIST, n))  # one contiguous row per history
    modes = np.empty(n, dtype=np.int64)
    summary = np.empty(K.N_SUMMARY)
    # room in the event log for more events than samples; a run with even more (chattering
    # contacts) is made again with room for all
    log_size = n + 16
    while True:
        ev_t = np.empty(log_size)
        ev_kft = np.empty((3, log_size), dtype=np.int64)
        K.run(
            p,
            ax,
            ay_arr,
            has_ay,
            1.0,
            1.0,
            float(dt),
            rtol,
            atol,
            zeno_omega,
            True,
            hist,
            modes,
            ev_t,
            ev_kft,
            summary,
            y_init,
        )
        n_ev = int(summary[K.S_N_EVENTS])
        if n_ev <= log_size:
            break
        log_size = n_ev
    ev_t = ev_t[:n_ev].copy()
    ev_k, ev_f, ev_to = (ev_kft[i, :n_ev].copy() for i in range(3))
    time = np.arange(n) * float(dt)
    theta = hist[K.Y_TH]
    vb, om, vs = hist[K.Y_VB], hist[K.Y_OM], hist[K.Y_VS]
    energy = Energy(
        input_work=hist[K.Y_WIN],
        kinetic=hist[K.H_KIN],
        potential=hist[K.H_POT],
        friction=hist[K.Y_DIS],
        impact=hist[K.Y_IMP],
    )
    events = EventLog(ev_t, ev_k, ev_f, ev_to)
    summ = _summary_dict(summary, system)
    if summ["n_mode_fallbacks"] > 0:
        warnings.warn(
            f"no mode was consistent at {int(summ['n_mode_fallbacks'])} event(s); the least-violating "
            "candidate was taken. This happens in the Painleve regime of rocking with Coulomb "
            "friction (mu_k > tan(phi) while the pivot slides against the rocking direction), "
            "where the rigid-body model has no consistent solution; see docs/theory/transitions.",
            RuntimeWarning,
            stacklevel=2,
        )
    fail = failure_name(summary[K.S_FAILURE])
    return SimulationResult(
        time=time,
        x_b=hist[K.Y_XB],
        theta=theta,
        x_s=hist[K.Y_XS],
        v_b=vb,
        theta_dot=om,
        v_s=vs,
        mode=modes,
        events=events,
        failure=fail,
        failure_time=None if fail is None else float(summary[K.S_FAILURE_TIME]),
        energy=energy,
        summary=summ,
        system=system,
        ground_acceleration=(ax.copy(), ay_arr.copy() if has_ay else np.zeros(n)),
        options={"rtol": rtol, "atol": atol, "zeno_omega": zeno_omega},
    )


def _summary_dict(summary: np.ndarray, system: ShipBlockSystem) -> dict:
    values = summary.tolist()  # Python floats at once, not one conversion per field
    out = {name: values[i] for name, i in SUMMARY_FIELDS.items()}
    for m, name in enumerate(MODE_TIME_FIELDS):
        out[name] = values[K.S_MODE_TIME + m]
    out["peak_rotation_ratio"] = out["peak_rotation"] / system.critical_angle
    out["uplift"] = bool(out["uplift"])
    out["n_impacts"] = int(out["n_impacts"])
    out["failure"] = int(out["failure"])
    return out


#: The columns of :func:`simulate_batch`'s cases, as its errors name them.
CASE_COLUMNS = ("record index", "system index", "horizontal scale", "vertical scale")


def _case_columns(cases, n_records, n_systems):
    """Check a cases table and split it into the kernel's contiguous columns.

    Every entry must be finite and the two indices whole numbers within range: a fractional
    index would otherwise be truncated to another record, and a NaN scale would run as a
    record at rest (NaN compares false with every threshold).
    """
    table = np.asarray(cases, dtype=float)
    if table.ndim != 2 or table.shape[1] != 4:
        raise ParameterError("cases must have shape (n_cases, 4): record, system, scale_h, scale_v")
    columns = table.T.copy()  # one contiguous row per column
    if not np.isfinite(columns).all():
        col, row = np.argwhere(~np.isfinite(columns))[0]
        raise ParameterError(f"cases[{row}, {col}] ({CASE_COLUMNS[col]}) is {columns[col, row]}: "
                             "every entry of cases must be finite")
    idx = columns[:2].astype(np.int64)
    if not (idx == columns[:2]).all():
        col, row = np.argwhere(idx != columns[:2])[0]
        raise ParameterError(f"cases[{row}, {col}] ({CASE_COLUMNS[col]}) is {columns[col, row]}: "
                             "an index must be a whole number")
    if idx.shape[1]:
        (lo_r, lo_s), (hi_r, hi_s) = idx.min(axis=1).tolist(), idx.max(axis=1).tolist()
        if lo_r < 0 or hi_r >= n_records or lo_s < 0 or hi_s >= n_systems:
            for col, n, what in ((0, n_records, "record"), (1, n_systems, "system")):
                bad = (idx[col] < 0) | (idx[col] >= n)
                if bad.any():
                    row = int(np.argmax(bad))
                    raise ParameterError(
                        f"a case refers to a {what} index out of range: cases[{row}, {col}] is "
                        f"{idx[col, row]}, with {n} {what}{'s' if n != 1 else ''}")
    return idx[0], idx[1], columns[2], columns[3]


def simulate_batch(
    systems: ShipBlockSystem | Sequence[ShipBlockSystem],
    records: Sequence | RecordSet,
    dts: Sequence[float] | float | None = None,
    cases=None,
    *,
    rtol: float = DEFAULT_RTOL,
    atol: float = DEFAULT_ATOL,
    zeno_omega: float = DEFAULT_ZENO_OMEGA,
) -> dict:
    """Run many cases in one compiled call, in parallel over the available cores.

    The cases are shared out dynamically: each thread takes the next case not yet started,
    so cases of very different cost (early failure, long rocking) keep all threads busy.
    Results do not depend on the number of threads or on the order of the cases.

    The threads are at most :func:`numba.get_num_threads` (set it with
    :func:`numba.set_num_threads`), one per case and one per CPU this process may run on; a
    batch of under a millisecond of work runs on one thread, and a short batch (under about
    20 ms of work per thread) leaves the cores other programs keep busy to them, so that it
    never runs slower on all threads than on one
    (:func:`shipblock.solver._threads.batch_threads`).

    Parameters
    ----------
    systems : ShipBlockSystem or sequence of ShipBlockSystem
        The systems; cases refer to them by index.
    records : sequence of (ax, ay), or RecordSet
        Ground motions [m/s^2]; ``ay`` may be None. A :class:`RecordSet` (the records checked
        and packed once) saves that work in repeated calls on the same records.
    dts : float or sequence of float, optional
        Sample interval of each record [s]; required with a sequence of records, not given
        with a :class:`RecordSet` (which holds its own).
    cases : array_like, shape (n_cases, 4)
        Rows ``(record_index, system_index, scale_h, scale_v)``: finite, the indices whole
        numbers within range (``CASE_COLUMNS`` names the columns in the errors).
    rtol, atol, zeno_omega : float, optional
        As for :func:`simulate`.

    Returns
    -------
    dict of ndarray
        One array of length ``n_cases`` per summary field (see ``SUMMARY_FIELDS``,
        ``MODE_TIME_FIELDS`` and ``peak_rotation_ratio``).
    """
    if isinstance(systems, ShipBlockSystem):
        systems = [systems]
    params = np.array([s.to_parameter_vector() for s in systems])
    check_options(rtol, atol, zeno_omega)
    if isinstance(records, RecordSet):
        if dts is not None:
            raise ParameterError("dts must not be given with a RecordSet: it holds the records' own")
        packed = records
    else:
        if dts is None:
            raise ParameterError("dts (the records' sample intervals [s]) is required")
        packed = RecordSet(records, dts)
    if cases is None:
        raise ParameterError("cases is required: rows (record, system, scale_h, scale_v)")
    rec_idx, par_idx, scale_h, scale_v = _case_columns(cases, len(packed), len(params))
    summaries = np.empty((rec_idx.size, K.N_SUMMARY))
    args = (params, packed.acc_h, packed.acc_v, packed.offsets, packed.dts, packed.has_v, rec_idx,
            par_idx, scale_h, scale_v, rtol, atol, zeno_omega, np.zeros(1, dtype=np.int64), summaries,
            False, *K.no_histories(), np.zeros(6))
    n_samples = float(np.diff(packed.offsets)[rec_idx].sum()) if rec_idx.size else 0.0
    run_on_threads(K.run_cases, args, batch_threads(numba.get_num_threads(), rec_idx.size, n_samples))
    # one field per row, each row contiguous: the arrays returned are views of one block
    by_field = np.ascontiguousarray(summaries.T)
    out = {name: by_field[i] for name, i in SUMMARY_FIELDS.items()}
    for m, name in enumerate(MODE_TIME_FIELDS):
        out[name] = by_field[K.S_MODE_TIME + m]
    thc = params[par_idx, P_THC]
    out["peak_rotation_ratio"] = out["peak_rotation"] / thc
    return out


__all__ = ["simulate", "simulate_batch", "RecordSet", "SUMMARY_FIELDS", "MODE_TIME_FIELDS"]
