"""Event-driven simulation of the ship-block system.

:func:`simulate` runs one ground motion and returns the full response;
:func:`simulate_batch` runs many (record, scale, system) cases in one compiled, parallel call and
returns their summaries.
"""

from __future__ import annotations

from collections.abc import Sequence

import numba
import numpy as np

from shipblock import checks
from shipblock.errors import ParameterError, ParameterTypeError
from shipblock.result import Energy, EventLog, SimulationResult, failure_name
from shipblock.solver import _kernel as K
from shipblock.solver._inputs import (
    RecordSet,
    as_acceleration,
    check_dt,
    check_initial_state,
    check_options,
)
from shipblock.solver._threads import MIN_PARALLEL_SAMPLES, batch_threads, run_on_threads
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
    "n_jams": K.S_N_JAMS,
    "final_energy": K.S_ENERGY_FINAL,
    "peak_ground_normal_force": K.S_PEAK_FY,
    "peak_ground_friction_force": K.S_PEAK_FX,
    "peak_ship_normal_force": K.S_PEAK_SFY,
    "peak_ship_friction_force": K.S_PEAK_SFX,
    "peak_ground_friction_utilisation": K.S_PEAK_UTIL_G,
    "peak_ship_friction_utilisation": K.S_PEAK_UTIL_S,
    "peak_corner_load": K.S_PEAK_CORNER,
}
MODE_TIME_FIELDS = [f"time_in_mode_{m}" for m in range(1, 9)]
#: Summary fields the kernel keeps as totals over the n blocks [N] and the wrappers report per
#: block (divided by ``n_blocks``).
PER_BLOCK_FIELDS = ("peak_ground_normal_force", "peak_ground_friction_force",
                    "peak_ship_normal_force", "peak_ship_friction_force", "peak_corner_load")


#: The rows of the kernel's summaries that simulate_batch returns, by name.
_OUTPUT_ROWS = (*SUMMARY_FIELDS.items(),
                *((name, K.S_MODE_TIME + m) for m, name in enumerate(MODE_TIME_FIELDS)))


def _row_runs(rows) -> tuple[slice, ...]:
    """Sorted row indices as slices of consecutive rows (one in-place operation each)."""
    runs = []
    for i in sorted(rows):
        if runs and runs[-1][1] == i:
            runs[-1][1] = i + 1
        else:
            runs.append([i, i + 1])
    return tuple(slice(a, b) for a, b in runs)


_PER_BLOCK_ROWS = _row_runs(SUMMARY_FIELDS[name] for name in PER_BLOCK_FIELDS)


def _run_cases_in_new_work(*args) -> None:
    """:func:`~shipblock.solver._kernel.run_cases` in work arrays of its own (one set per
    thread)."""
    K.run_cases(*args, *K.new_work())


def _is_motion(value) -> bool:
    """Whether ``value`` is a :class:`shipblock.records.motion.GroundMotion` (without importing obspy)."""
    return all(hasattr(value, a) for a in ("horizontal", "vertical", "dt"))


def _check_not_wrapped(ax) -> None:
    """Refuse what :func:`shipblock.scaling.scale_motion` or ``scale_record`` returned, saying
    what to pass instead (a tuple or a record object would otherwise fail as a missing ``dt``
    or as an array of objects)."""
    if isinstance(ax, tuple | list) and ax and _is_motion(ax[0]):
        raise ParameterTypeError(
            f"ax is a {type(ax).__name__} ({', '.join(type(v).__name__ for v in ax)}), not a "
            "ground motion or an array: scale_motion returns (motion, scaled); pass its first "
            "item, e.g. simulate(system, scale_motion(motion, ...)[0]) or motion, _ = "
            "scale_motion(...); simulate(system, motion)")
    if hasattr(ax, "horizontal") and hasattr(ax, "factor_h") and not hasattr(ax, "dt"):
        raise ParameterTypeError(
            f"ax is a {type(ax).__name__} (the result of scale_record), which holds no dt: pass "
            "its arrays, simulate(system, scaled.horizontal, scaled.vertical, dt)")


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
        Horizontal ground acceleration at ``t_k = k dt`` [m/s^2], positive to the right; at
        least 2 samples, each finite and within :data:`shipblock.checks.MAX_ACCELERATION`
        (100 g). A :class:`shipblock.records.motion.GroundMotion` may be passed instead, in which case
        its horizontal, vertical and dt are used (``ay`` and ``dt`` are then not given).
    ay : array_like or None, optional
        Vertical ground acceleration [m/s^2], positive up; ``None`` for none. Same length and
        limits as ``ax``.
    dt : float
        Sample interval [s], within :data:`shipblock.checks.MIN_TIME_STEP` ..
        :data:`shipblock.checks.MAX_TIME_STEP` (1e-4 .. 1 s).
    rtol, atol : float, optional
        Relative and absolute error tolerance of the rocking phases; ``rtol`` in [1e-14, 1),
        ``atol`` in [1e-16, 1].
    zeno_omega : float, optional
        Rocking stops when an impact leaves less angular velocity than this [rad/s]; in
        [0, 1000].
    initial_state : sequence of 6 float, optional
        ``(x_b, theta, x_s, v_b, theta_dot, v_s)`` at t = 0 [m, rad, m, m/s, rad/s, m/s];
        default at rest. ``|theta|`` must be below the critical angle, displacements within
        100 m, velocities within 100 m/s and 100 rad/s.

    Returns
    -------
    SimulationResult
        Histories at the samples, events, failure, energy balance and summary.

    Raises
    ------
    ParameterTypeError
        For an argument of the wrong type (``system`` not a :class:`ShipBlockSystem`, a string
        for a number...).
    ParameterError
        For too short, non-finite or implausible accelerations, ``dt`` or a tolerance out of its
        range, ``ax``/``ay`` of different length or an implausible initial state. Both are
        :class:`ValueError`; the message names the argument and what it expects.

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
    if not isinstance(system, ShipBlockSystem):
        raise ParameterTypeError(f"system must be a ShipBlockSystem, got {type(system).__name__}")
    _check_not_wrapped(ax)
    if _is_motion(ax):
        motion = ax
        for name, value in (("ay", ay), ("dt", dt)):
            if value is not None:
                raise ParameterError(f"{name} must not be given with a GroundMotion as ax: the "
                                     f"motion holds its own (vertical and dt)")
        ax, ay, dt = motion.horizontal, motion.vertical, motion.dt
    elif dt is None:
        raise ParameterError("dt [s] is required when ax is an array")
    dt = check_dt(dt)
    rtol, atol, zeno_omega = check_options(rtol, atol, zeno_omega)
    ax = as_acceleration(ax, "ax")
    if ay is None:
        ay_arr = ax  # a stand-in the kernel never reads (has_ay False): no zeros to allocate
        has_ay = False
    else:
        ay_arr = as_acceleration(ay, "ay")
        if ay_arr.size != ax.size:
            raise ParameterError(f"ay must have the same length as ax ({ax.size} samples), got "
                                 f"{ay_arr.size}")
        has_ay = True
    y_init = np.zeros(6)
    if initial_state is not None:
        y_init = check_initial_state(initial_state, system.critical_angle)
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
    # the audit of the constraints (issue 32; not a batch field): >= -FORCE_TOL when each held
    # condition held to the tolerance at every accepted step, sample and event
    out["least_constraint_margin"] = values[K.S_MARGIN]
    for name in PER_BLOCK_FIELDS:
        out[name] /= system.n_blocks
    out["uplift"] = bool(out["uplift"])
    out["n_impacts"] = int(out["n_impacts"])
    out["n_jams"] = int(out["n_jams"])
    out["failure"] = int(out["failure"])
    return out


#: The columns of :func:`simulate_batch`'s cases, as its errors name them.
CASE_COLUMNS = ("record index", "system index", "horizontal scale", "vertical scale")


def _case_columns(cases, packed: RecordSet, n_systems: int):
    """Check a cases table and split it into the kernel's contiguous columns.

    Every entry must be finite, the two indices whole numbers within range (a fractional
    index would otherwise be truncated to another record, and a NaN scale would run as a
    record at rest: NaN compares false with every threshold), and each scaled record within
    the plausibility limit :data:`shipblock.checks.MAX_ACCELERATION`.
    """
    n_records = len(packed)
    table = checks.as_real_array(cases, "cases", "an array of rows (record, system, scale_h, "
                                                 "scale_v)")
    if table.size == 0 and table.ndim <= 2:
        table = table.reshape(0, 4)
    if table.ndim != 2 or table.shape[1] != 4:
        raise ParameterError("cases must have shape (n_cases, 4): record, system, scale_h, "
                             f"scale_v; got shape {table.shape}")
    columns = table.T.copy()  # one contiguous row per column
    limit = checks.MAX_ACCELERATION * (1.0 + 1e-12)  # a record scaled to exactly 100 g runs
    if columns.shape[1]:
        # the usual table at a few operations: every column within its bounds (a NaN makes its
        # column's extremes NaN, which fail every comparison), then the indices whole
        (lo_r, lo_s, lo_h, lo_v), (hi_r, hi_s, hi_h, hi_v) = (columns.min(axis=1).tolist(),
                                                              columns.max(axis=1).tolist())
        if (lo_r >= 0.0 and hi_r < n_records and lo_s >= 0.0 and hi_s < n_systems
                and max(-lo_h, hi_h) * packed.top_h <= limit
                and max(-lo_v, hi_v) * packed.top_v <= limit):
            idx = columns[:2].astype(np.int64)
            if (idx == columns[:2]).all():
                return idx[0], idx[1], columns[2], columns[3]
    # otherwise each check in turn, the first failure named
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
                        f"cases[{row}, {col}] ({what} index) is {idx[col, row]}: out of range, "
                        f"with {n} {what}{'s' if n != 1 else ''}")
        for col, peaks, what in ((2, packed.peak_h, "horizontal"), (3, packed.peak_v, "vertical")):
            scaled = np.abs(columns[col]) * peaks[idx[0]]
            if not (scaled <= limit).all():
                row = int(np.argmax(~(scaled <= limit)))
                raise ParameterError(
                    f"cases[{row}, {col}] ({CASE_COLUMNS[col]}) is {float(columns[col, row])!r}: it takes "
                    f"the {what} of records[{idx[0, row]}] to a peak of {scaled[row]:.6g} m/s^2, "
                    f"above the plausibility limit {checks.MAX_ACCELERATION:g} m/s^2 (100 g)")
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
        numbers within range (``CASE_COLUMNS`` names the columns in the errors), each scaled
        record within :data:`shipblock.checks.MAX_ACCELERATION` (100 g). No rows: empty
        results.
    rtol, atol, zeno_omega : float, optional
        As for :func:`simulate`.

    Returns
    -------
    dict of ndarray
        One array of length ``n_cases`` per summary field (see ``SUMMARY_FIELDS``,
        ``MODE_TIME_FIELDS`` and ``peak_rotation_ratio``).

    Raises
    ------
    ParameterTypeError
        For an argument of the wrong type: ``systems`` not systems, a record that is not an
        ``(ax, ay)`` pair, ``cases`` not numbers.
    ParameterError
        For no systems or no records, a bad record (see :class:`RecordSet`), a case that is not
        finite, refers to a record or system out of range, or scales a record above 100 g, or a
        tolerance out of range (see :func:`simulate`). Both are :class:`ValueError`; the message
        names the argument, and the record or case.
    """
    if isinstance(systems, ShipBlockSystem):
        systems = [systems]
    if isinstance(systems, str | bytes) or not isinstance(systems, Sequence):
        raise ParameterTypeError(f"systems must be a ShipBlockSystem or a sequence of them, got "
                                 f"{type(systems).__name__}")
    if not systems:
        raise ParameterError("systems must hold at least one ShipBlockSystem")
    for i, s in enumerate(systems):
        if not isinstance(s, ShipBlockSystem):
            raise ParameterTypeError(f"systems[{i}] must be a ShipBlockSystem, got "
                                     f"{type(s).__name__}")
    # (a writable copy: the kernel compiled for read-only arrays would be a second compile)
    params = (systems[0].kernel_parameters[None, :].copy() if len(systems) == 1
              else np.array([s.kernel_parameters for s in systems]))
    rtol, atol, zeno_omega = check_options(rtol, atol, zeno_omega)
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
    rec_idx, par_idx, scale_h, scale_v = _case_columns(cases, packed, len(params))
    if rec_idx.size == 0:
        return {name: np.zeros(0) for name in (*SUMMARY_FIELDS, *MODE_TIME_FIELDS,
                                                "peak_rotation_ratio")}
    summaries = np.empty((rec_idx.size, K.N_SUMMARY))
    args = (params, packed.acc_h, packed.acc_v, packed.offsets, packed.dts, packed.has_v, rec_idx,
            par_idx, scale_h, scale_v, rtol, atol, zeno_omega, np.zeros(1, dtype=np.int64), summaries,
            False, *K.no_histories(), np.zeros(6))
    n_threads = 1
    if rec_idx.size > 1:
        n_samples = float(packed.lengths[rec_idx].sum())
        if n_samples >= MIN_PARALLEL_SAMPLES:  # (below it, one thread whatever numba allows)
            n_threads = batch_threads(numba.get_num_threads(), rec_idx.size, n_samples)
    run_on_threads(_run_cases_in_new_work, args, n_threads)
    # one field per row, each row contiguous: the arrays returned are views of one block
    # (rows taken by iteration and the per-block totals divided in place: for a short batch
    # these steps would otherwise cost as much as some of its runs)
    by_field = np.ascontiguousarray(summaries.T)
    n_blocks = (float(systems[0].n_blocks) if len(systems) == 1
                else np.array([s.n_blocks for s in systems], dtype=float)[par_idx])
    for rows in _PER_BLOCK_ROWS:
        by_field[rows] /= n_blocks
    rows = list(by_field)
    out = {name: rows[i] for name, i in _OUTPUT_ROWS}
    out["peak_rotation_ratio"] = out["peak_rotation"] / params[par_idx, P_THC]
    return out


__all__ = ["simulate", "simulate_batch", "RecordSet", "SUMMARY_FIELDS", "MODE_TIME_FIELDS",
           "PER_BLOCK_FIELDS"]
