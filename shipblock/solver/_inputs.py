"""Checks of the solver's inputs, and ground motions packed for batches (:class:`RecordSet`).

Every check names the argument (and for a batch the record and sample) it rejects.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from shipblock import checks
from shipblock.errors import ParameterError, ParameterTypeError

#: Accepted range of the relative tolerance of the rocking integration [-]: below 1e-14 the
#: error estimate is round-off, at 1 or above there is no error control.
RTOL_RANGE = (1e-14, 1.0)
#: Accepted range of the absolute tolerance [SI units of each state].
ATOL_RANGE = (1e-16, 1.0)
#: Largest zeno_omega accepted [rad/s] (rocking stops at an impact below it).
MAX_ZENO_OMEGA = 1e3
#: Largest |displacement| [m], |velocity| [m/s] and |angular velocity| [rad/s] of an initial state.
MAX_INITIAL_DISPLACEMENT = 100.0
MAX_INITIAL_VELOCITY = 100.0
MAX_INITIAL_ANGULAR_VELOCITY = 100.0
INITIAL_STATE_NAMES = ("x_b", "theta", "x_s", "v_b", "theta_dot", "v_s")


def as_acceleration(values, name: str, check_finite: bool = True) -> np.ndarray:
    """``values`` as a contiguous float array of at least two samples, else a named error.

    With ``check_finite`` every sample must also be finite and within
    :data:`shipblock.checks.MAX_ACCELERATION`.
    """
    if check_finite:
        return checks.acceleration(values, name)
    arr = checks.as_real_array(values, name, "a one-dimensional array of accelerations [m/s^2]")
    if arr.ndim != 1:
        raise ParameterError(f"{name} must be a one-dimensional array, got shape {arr.shape}")
    if arr.size < 2:
        raise ParameterError(f"{name} must have at least 2 samples, got {arr.size}")
    return np.ascontiguousarray(arr)


def check_finite_samples(arr: np.ndarray, name: str) -> None:
    """Raise a ParameterError naming ``name`` and the first non-finite or implausible sample."""
    checks.check_samples(arr, name)


def check_dt(dt, name: str = "dt") -> float:
    """A sampling interval in [MIN_TIME_STEP, MAX_TIME_STEP] of :mod:`shipblock.checks` [s]."""
    return checks.time_step(dt, name)


def check_options(rtol, atol, zeno_omega) -> tuple[float, float, float]:
    """The solver tolerances as floats, each checked against its range (named in the error)."""
    if (type(rtol) is float and type(atol) is float and type(zeno_omega) is float
            and RTOL_RANGE[0] <= rtol < RTOL_RANGE[1] and ATOL_RANGE[0] <= atol <= ATOL_RANGE[1]
            and 0.0 <= zeno_omega <= MAX_ZENO_OMEGA):
        return rtol, atol, zeno_omega  # the usual case (NaN fails a comparison, and goes below)
    return (
        checks.real(rtol, "rtol", low=RTOL_RANGE[0], high=RTOL_RANGE[1], high_open=True),
        checks.real(atol, "atol", low=ATOL_RANGE[0], high=ATOL_RANGE[1]),
        checks.real(zeno_omega, "zeno_omega", low=0.0, high=MAX_ZENO_OMEGA, units="rad/s"),
    )


def check_initial_state(initial_state, critical_angle: float) -> np.ndarray:
    """``(x_b, theta, x_s, v_b, theta_dot, v_s)`` as 6 floats within plausible bounds."""
    y = checks.as_real_array(initial_state, "initial_state",
                             "a sequence of 6 numbers (x_b, theta, x_s, v_b, theta_dot, v_s)")
    if y.shape != (6,):
        raise ParameterError(f"initial_state must hold 6 numbers (x_b, theta, x_s, v_b, theta_dot, "
                             f"v_s), got shape {y.shape}")
    bounds = (MAX_INITIAL_DISPLACEMENT, critical_angle, MAX_INITIAL_DISPLACEMENT,
              MAX_INITIAL_VELOCITY, MAX_INITIAL_ANGULAR_VELOCITY, MAX_INITIAL_VELOCITY)
    units = ("m", "rad", "m", "m/s", "rad/s", "m/s")
    for i, (value, bound) in enumerate(zip(y.tolist(), bounds, strict=True)):
        if not (abs(value) < bound if i == 1 else abs(value) <= bound):
            relation = "< {:.6g} rad (the critical angle)" if i == 1 else "<= {:.6g} " + units[i]
            raise ParameterError(
                f"initial_state {INITIAL_STATE_NAMES[i]} = {value!r} must be finite with "
                f"|{INITIAL_STATE_NAMES[i]}| {relation.format(bound)}")
    return np.ascontiguousarray(y)


class RecordSet:
    """Ground motions packed for :func:`~shipblock.simulate_batch`: checked and laid end to end once.

    :func:`~shipblock.simulate_batch` runs on the records laid end to end in one array. Given a
    list of records it checks and packs them at every call; a study that runs the same records
    many times (systems swept one call at a time, repeated batches of a benchmark) packs them
    once into a ``RecordSet`` and passes that instead, with the same results.

    Parameters
    ----------
    records : sequence of (ax, ay)
        Ground accelerations [m/s^2]: horizontal, and vertical or None; at least one record.
        Each at least two finite samples within 100 g; ``ax`` and ``ay`` of a record of equal
        length.
    dts : float or sequence of float
        Sample interval of each record [s] (one value: all records).

    Attributes
    ----------
    acc_h, acc_v : ndarray
        The horizontal and vertical records end to end [m/s^2]. Without any vertical record
        ``acc_v`` is ``acc_h`` (a stand-in the solver never reads).
    offsets : ndarray of int64, shape (n + 1,)
        Record ``r`` occupies ``offsets[r]:offsets[r + 1]``.
    dts : ndarray, shape (n,)
        Sample intervals [s].
    has_v : ndarray of bool, shape (n,)
        Whether each record has a vertical component.
    peak_h, peak_v : ndarray, shape (n,)
        Peak absolute acceleration of each record's horizontal and vertical [m/s^2] (0 without
        a vertical).

    Raises
    ------
    ParameterTypeError
        If ``records`` is not a sequence of ``(ax, ay)`` pairs (a bare array in place of a
        pair, for example) or ``dts`` not numbers.
    ParameterError
        Naming the record (and the first bad sample) of any input it rejects: fewer than two
        samples, a non-finite sample or one above :data:`shipblock.checks.MAX_ACCELERATION`,
        lengths of ``ax`` and ``ay`` that differ, a sample interval outside
        :data:`shipblock.checks.MIN_TIME_STEP` .. :data:`shipblock.checks.MAX_TIME_STEP`.

    Examples
    --------
    >>> import numpy as np
    >>> from shipblock import RecordSet, ShipBlockSystem, simulate_batch
    >>> t = np.arange(0, 10, 0.01)
    >>> packed = RecordSet([(3 * np.sin(2 * np.pi * t), None), (2 * np.sin(5 * t), None)], 0.01)
    >>> out = simulate_batch(ShipBlockSystem.example(), packed, cases=[(0, 0, 1, 1), (1, 0, 2, 2)])
    >>> out["peak_block_slip"].shape
    (2,)
    """

    def __init__(self, records: Sequence, dts: Sequence[float] | float):
        pair = "a pair (ax, ay) of arrays [m/s^2], ay None for no vertical"
        if isinstance(records, str | bytes | np.ndarray) or not isinstance(records, Sequence):
            raise ParameterTypeError(f"records must be a sequence of pairs (ax, ay), got "
                                     f"{type(records).__name__}")
        n_rec = len(records)
        if n_rec == 0:
            raise ParameterError("records must hold at least one record (ax, ay)")
        if checks.is_real(dts):
            dts_arr = np.full(n_rec, check_dt(dts, "dts"), dtype=float)
        else:
            dts_arr = checks.as_real_array(dts, "dts", "a number or one number per record [s]")
            if dts_arr.shape != (n_rec,):
                raise ParameterError(f"dts must give one sample interval per record ({n_rec}), "
                                     f"got shape {dts_arr.shape}")
            for d in np.unique(dts_arr).tolist():  # each distinct interval once
                if not (checks.MIN_TIME_STEP * (1.0 - 1e-9) <= d
                        <= checks.MAX_TIME_STEP * (1.0 + 1e-9)):
                    first = int(np.flatnonzero((dts_arr == d) | (np.isnan(dts_arr) & (d != d)))[0])
                    check_dt(d, f"dts[{first}] (record {first})")
        hs, vs, has_v = [], [], []
        for i, rec in enumerate(records):
            if not (isinstance(rec, tuple | list) and len(rec) == 2):
                raise ParameterTypeError(f"records[{i}] must be {pair}, got "
                                         f"{type(rec).__name__}"
                                         + (f" of shape {rec.shape}" if hasattr(rec, "shape")
                                            else ""))
            h, v = rec
            # the samples are checked below on all records at once (one pass, not one per record)
            h = as_acceleration(h, f"records[{i}] horizontal", check_finite=False)
            hs.append(h)
            if v is None:
                vs.append(h)  # a stand-in the kernel never reads (has_v False)
                has_v.append(False)
            else:
                v = as_acceleration(v, f"records[{i}] vertical", check_finite=False)
                if v.size != h.size:
                    raise ParameterError(f"records[{i}]: horizontal and vertical lengths differ "
                                         f"({h.size} and {v.size} samples)")
                vs.append(v)
                has_v.append(True)
        offsets = np.zeros(n_rec + 1, dtype=np.int64)
        offsets[1:] = np.cumsum([h.size for h in hs])
        acc_h = np.concatenate(hs)
        # without any vertical component the horizontal stands in (never read): a second array
        # of the records' size costs page faults out of proportion to a batch of short records
        has_v = np.array(has_v, dtype=bool)
        acc_v = np.concatenate(vs) if has_v.any() else acc_h
        # peak of each record (NaN propagates): one pass over the samples finds the records
        # with a non-finite or implausible sample and gives the scaled peaks of simulate_batch
        starts = offsets[:-1]
        peak_h = np.maximum(np.maximum.reduceat(acc_h, starts), -np.minimum.reduceat(acc_h, starts))
        peak_v = np.zeros(n_rec)
        if has_v.any():
            peak_v[has_v] = np.maximum(np.maximum.reduceat(acc_v, starts),
                                       -np.minimum.reduceat(acc_v, starts))[has_v]
        for peaks, arrays, label in ((peak_h, hs, "horizontal"), (peak_v, vs, "vertical")):
            bad = ~(peaks <= checks.MAX_ACCELERATION)
            if bad.any():
                i = int(np.flatnonzero(bad)[0])
                check_finite_samples(arrays[i], f"records[{i}] {label}")
        self.acc_h, self.acc_v, self.offsets = acc_h, acc_v, offsets
        self.lengths = np.diff(offsets)  # samples per record
        self.dts = dts_arr
        self.has_v = has_v
        self.peak_h, self.peak_v = peak_h, peak_v
        # the largest peaks (0.0 with no records): a bound on every scaled record's
        self.top_h = float(peak_h.max(initial=0.0))
        self.top_v = float(peak_v.max(initial=0.0))

    def __len__(self) -> int:
        return self.dts.size

    def __repr__(self) -> str:
        return (f"RecordSet({len(self)} records, {self.acc_h.size} samples, "
                f"{int(self.has_v.sum())} with vertical)")
