"""Event-driven simulation of the ship-block system.

:func:`simulate` runs one ground motion and returns the full response;
:func:`simulate_batch` runs many (record, scale, system) cases in one compiled, parallel call and
returns their summaries.
"""

from __future__ import annotations

import math
import warnings
from collections.abc import Sequence

import numba
import numpy as np

from shipblock.errors import ParameterError
from shipblock.result import Energy, EventLog, SimulationResult, failure_name
from shipblock.solver import _kernel as K
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


def _as_acceleration(values, name: str, check_finite: bool = True) -> np.ndarray:
    arr = np.asarray(values, dtype=float)
    if arr.ndim != 1:
        raise ParameterError(f"{name} must be a one-dimensional array, got shape {arr.shape}")
    if arr.size < 2:
        raise ParameterError(f"{name} must have at least 2 samples, got {arr.size}")
    if check_finite:
        _check_finite(arr, name)
    return np.ascontiguousarray(arr)


def _check_finite(arr: np.ndarray, name: str) -> None:
    bad = ~np.isfinite(arr)
    if bad.any():
        i = int(np.flatnonzero(bad)[0])
        raise ParameterError(f"{name} has {int(bad.sum())} non-finite samples (first at index {i})")


def _check_options(dt, rtol, atol, zeno_omega):
    if not (isinstance(dt, int | float | np.floating) and math.isfinite(dt) and dt > 0):
        raise ParameterError(f"dt must be a finite number > 0 [s], got {dt!r}")
    if not (0 < rtol < 1):
        raise ParameterError(f"rtol must lie in (0, 1), got {rtol!r}")
    if not (atol > 0):
        raise ParameterError(f"atol must be > 0, got {atol!r}")
    if not (zeno_omega >= 0):
        raise ParameterError(f"zeno_omega must be >= 0 [rad/s], got {zeno_omega!r}")


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
    _check_options(dt, rtol, atol, zeno_omega)
    ax = _as_acceleration(ax, "ax")
    if ay is None:
        ay_arr = ax  # a stand-in the kernel never reads (has_ay False): no zeros to allocate
        has_ay = False
    else:
        ay_arr = _as_acceleration(ay, "ay")
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


def simulate_batch(
    systems: ShipBlockSystem | Sequence[ShipBlockSystem],
    records: Sequence,
    dts: Sequence[float] | float,
    cases,
    *,
    rtol: float = DEFAULT_RTOL,
    atol: float = DEFAULT_ATOL,
    zeno_omega: float = DEFAULT_ZENO_OMEGA,
) -> dict:
    """Run many cases in one compiled call, in parallel over the available cores.

    Parameters
    ----------
    systems : ShipBlockSystem or sequence of ShipBlockSystem
        The systems; cases refer to them by index.
    records : sequence of (ax, ay)
        Ground motions [m/s^2]; ``ay`` may be None.
    dts : float or sequence of float
        Sample interval of each record [s].
    cases : array_like, shape (n_cases, 4)
        Rows ``(record_index, system_index, scale_h, scale_v)``.
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
    n_rec = len(records)
    if np.isscalar(dts):
        dts = [dts] * n_rec
    dts_arr = np.asarray(dts, dtype=float)
    if dts_arr.shape != (n_rec,):
        raise ParameterError(f"dts must give one sample interval per record ({n_rec})")
    checked = set()
    for i, d in enumerate(dts_arr.tolist()):
        if d in checked:
            continue
        try:
            _check_options(d, rtol, atol, zeno_omega)
        except ValueError as exc:
            raise ParameterError(f"record {i}: {exc}") from None
        checked.add(d)
    hs, vs, has_v = [], [], []
    for i, (h, v) in enumerate(records):
        # finiteness is checked below on all records at once (one pass, not one per record)
        h = _as_acceleration(h, f"records[{i}] horizontal", check_finite=False)
        hs.append(h)
        if v is None:
            vs.append(h)  # a stand-in the kernel never reads (has_v False)
            has_v.append(False)
        else:
            v = _as_acceleration(v, f"records[{i}] vertical", check_finite=False)
            if v.size != h.size:
                raise ParameterError(f"records[{i}]: horizontal and vertical lengths differ")
            vs.append(v)
            has_v.append(True)
    offsets = np.zeros(n_rec + 1, dtype=np.int64)
    offsets[1:] = np.cumsum([h.size for h in hs])
    acc_h = np.concatenate(hs)
    # without any vertical component the horizontal stands in (never read): a second array of
    # the records' size costs page faults out of proportion to a batch of short records
    acc_v = np.concatenate(vs) if any(has_v) else acc_h
    with np.errstate(over="ignore", invalid="ignore"):
        total = np.add.reduce(acc_h) + (np.add.reduce(acc_v) if any(has_v) else 0.0)
    if not math.isfinite(total):
        # a NaN or infinity makes the sum non-finite (so may an overflow of finite samples):
        # find the record and sample to name
        for i, (h, v) in enumerate(zip(hs, vs, strict=True)):
            _check_finite(h, f"records[{i}] horizontal")
            if has_v[i]:
                _check_finite(v, f"records[{i}] vertical")
    cases = np.asarray(cases, dtype=float)
    if cases.ndim != 2 or cases.shape[1] != 4:
        raise ParameterError("cases must have shape (n_cases, 4): record, system, scale_h, scale_v")
    rec_idx = cases[:, 0].astype(np.int64)
    par_idx = cases[:, 1].astype(np.int64)
    if rec_idx.min(initial=0) < 0 or rec_idx.max(initial=0) >= n_rec:
        raise ParameterError("a case refers to a record index out of range")
    if par_idx.min(initial=0) < 0 or par_idx.max(initial=0) >= len(params):
        raise ParameterError("a case refers to a system index out of range")
    summaries = np.empty((cases.shape[0], K.N_SUMMARY))
    K.run_many(
        params,
        acc_h,
        acc_v,
        offsets,
        dts_arr,
        np.array(has_v),
        rec_idx,
        par_idx,
        np.ascontiguousarray(cases[:, 2]),
        np.ascontiguousarray(cases[:, 3]),
        rtol,
        atol,
        zeno_omega,
        numba.get_num_threads(),
        np.zeros(1, dtype=np.int64),
        summaries,
    )
    # one field per row, each row contiguous: the arrays returned are views of one block
    by_field = np.ascontiguousarray(summaries.T)
    out = {name: by_field[i] for name, i in SUMMARY_FIELDS.items()}
    for m, name in enumerate(MODE_TIME_FIELDS):
        out[name] = by_field[K.S_MODE_TIME + m]
    thc = params[par_idx, P_THC]
    out["peak_rotation_ratio"] = out["peak_rotation"] / thc
    return out


__all__ = ["simulate", "simulate_batch", "SUMMARY_FIELDS", "MODE_TIME_FIELDS"]
