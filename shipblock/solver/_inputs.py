"""Checks of the solver's inputs, and ground motions packed for batches (:class:`RecordSet`).

Every check names the argument (and for a batch the record and sample) it rejects.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

from shipblock.errors import ParameterError


def as_acceleration(values, name: str, check_finite: bool = True) -> np.ndarray:
    """``values`` as a contiguous float array of at least two samples, else a named error."""
    arr = np.asarray(values, dtype=float)
    if arr.ndim != 1:
        raise ParameterError(f"{name} must be a one-dimensional array, got shape {arr.shape}")
    if arr.size < 2:
        raise ParameterError(f"{name} must have at least 2 samples, got {arr.size}")
    if check_finite:
        check_finite_samples(arr, name)
    return np.ascontiguousarray(arr)


def check_finite_samples(arr: np.ndarray, name: str) -> None:
    """Raise a ParameterError naming ``name`` and the first non-finite sample, if any."""
    bad = ~np.isfinite(arr)
    if bad.any():
        i = int(np.flatnonzero(bad)[0])
        raise ParameterError(f"{name} has {int(bad.sum())} non-finite samples (first at index {i})")


def check_dt(dt) -> None:
    if not (isinstance(dt, int | float | np.floating) and math.isfinite(dt) and dt > 0):
        raise ParameterError(f"dt must be a finite number > 0 [s], got {dt!r}")


def check_options(rtol, atol, zeno_omega) -> None:
    if not (0 < rtol < 1):
        raise ParameterError(f"rtol must lie in (0, 1), got {rtol!r}")
    if not (atol > 0):
        raise ParameterError(f"atol must be > 0, got {atol!r}")
    if not (zeno_omega >= 0):
        raise ParameterError(f"zeno_omega must be >= 0 [rad/s], got {zeno_omega!r}")


class RecordSet:
    """Ground motions packed for :func:`~shipblock.simulate_batch`: checked and laid end to end once.

    :func:`~shipblock.simulate_batch` runs on the records laid end to end in one array. Given a
    list of records it checks and packs them at every call; a study that runs the same records
    many times (systems swept one call at a time, repeated batches of a benchmark) packs them
    once into a ``RecordSet`` and passes that instead, with the same results.

    Parameters
    ----------
    records : sequence of (ax, ay)
        Ground accelerations [m/s^2]: horizontal, and vertical or None. Each at least two
        finite samples; ``ax`` and ``ay`` of a record of equal length.
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

    Raises
    ------
    ParameterError
        Naming the record (and the first bad sample) of any input it rejects.

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
        n_rec = len(records)
        dts_arr = np.full(n_rec, dts, dtype=float) if np.isscalar(dts) else np.asarray(dts, float)
        if dts_arr.shape != (n_rec,):
            raise ParameterError(f"dts must give one sample interval per record ({n_rec})")
        for d in np.unique(dts_arr).tolist():  # each distinct interval once
            try:
                check_dt(d)
            except ValueError as exc:
                first = int(np.flatnonzero((dts_arr == d) | (np.isnan(dts_arr) & (d != d)))[0])
                raise ParameterError(f"record {first}: {exc}") from None
        hs, vs, has_v = [], [], []
        for i, (h, v) in enumerate(records):
            # finiteness is checked below on all records at once (one pass, not one per record)
            h = as_acceleration(h, f"records[{i}] horizontal", check_finite=False)
            hs.append(h)
            if v is None:
                vs.append(h)  # a stand-in the kernel never reads (has_v False)
                has_v.append(False)
            else:
                v = as_acceleration(v, f"records[{i}] vertical", check_finite=False)
                if v.size != h.size:
                    raise ParameterError(f"records[{i}]: horizontal and vertical lengths differ")
                vs.append(v)
                has_v.append(True)
        offsets = np.zeros(n_rec + 1, dtype=np.int64)
        offsets[1:] = np.cumsum([h.size for h in hs])
        acc_h = np.concatenate(hs) if hs else np.zeros(0)
        # without any vertical component the horizontal stands in (never read): a second array
        # of the records' size costs page faults out of proportion to a batch of short records
        acc_v = np.concatenate(vs) if any(has_v) else acc_h
        with np.errstate(over="ignore", invalid="ignore"):
            total = np.add.reduce(acc_h) + (np.add.reduce(acc_v) if any(has_v) else 0.0)
        if not math.isfinite(total):
            # a NaN or infinity makes the sum non-finite (so may an overflow of finite
            # samples): find the record and sample to name
            for i, (h, v) in enumerate(zip(hs, vs, strict=True)):
                check_finite_samples(h, f"records[{i}] horizontal")
                if has_v[i]:
                    check_finite_samples(v, f"records[{i}] vertical")
        self.acc_h, self.acc_v, self.offsets = acc_h, acc_v, offsets
        self.dts = dts_arr
        self.has_v = np.array(has_v, dtype=bool)

    def __len__(self) -> int:
        return self.dts.size

    def __repr__(self) -> str:
        return (f"RecordSet({len(self)} records, {self.acc_h.size} samples, "
                f"{int(self.has_v.sum())} with vertical)")
