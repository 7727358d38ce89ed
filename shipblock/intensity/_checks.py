"""Argument checks shared by the intensity measures and the response spectrum.

Thin wrappers over :mod:`shipblock.checks` with the argument names of
:mod:`shipblock.intensity`.
"""

from __future__ import annotations

import numpy as np

from shipblock import checks
from shipblock.errors import ParameterError

#: Label used as the ``source`` of :class:`~shipblock.errors.RecordError` for in-memory arrays.
_SOURCE = "<array>"


def _as_record(acc, name: str = "acc") -> np.ndarray:
    """``acc`` as a 1-D float64 array of at least 2 samples, each finite and within 100 g.

    The checks and limits are those of :mod:`shipblock.checks`; the message names ``name``.
    """
    return checks.acceleration(acc, name)


def _check_dt(dt) -> float:
    """A sampling interval within :data:`shipblock.checks.MIN_TIME_STEP` .. ``MAX_TIME_STEP``."""
    return checks.time_step(dt, "dt")


def _check_damping(damping) -> float:
    """A fraction of critical damping in [0, 1) (under-damped oscillator)."""
    return checks.real(damping, "damping", low=0.0, high=1.0, high_open=True)


def _check_periods(periods) -> np.ndarray:
    """Oscillator periods as a 1-D array, each 0 (PGA) or in [MIN_PERIOD, MAX_PERIOD] [s]."""
    arr = np.atleast_1d(checks.as_real_array(periods, "periods", "periods [s]"))
    if arr.ndim != 1:
        raise ParameterError(f"periods must be a scalar or 1-D array, got shape {arr.shape}")
    bad = ~((arr == 0.0) | ((arr >= checks.MIN_PERIOD) & (arr <= checks.MAX_PERIOD)))
    if bad.any():
        i = int(np.flatnonzero(bad)[0])
        raise ParameterError(f"periods must be 0 (PGA) or in [{checks.MIN_PERIOD:g}, "
                             f"{checks.MAX_PERIOD:g}] [s], got {float(arr[i])!r} at index {i}")
    return arr
