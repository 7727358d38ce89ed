"""The processing steps: demean, detrend, taper, filters, baseline, resample, trim, pad.

Each is registered by :func:`shipblock.processing._registry.step` under its name in
:data:`shipblock.processing.STEPS`, works on a copy of its input and appends its provenance
string; every parameter is checked here, the message naming the step and the parameter.
Filtering, detrending, tapering and resampling delegate to ObsPy (``scipy.signal``); only the
polynomial baseline correction is written here. The public names are also those of
:mod:`shipblock.processing` (``shipblock.processing.bandpass``).
"""

from __future__ import annotations

import logging

import numpy as np

from shipblock import checks
from shipblock.intensity import displacement
from shipblock.processing._registry import ProcessingError, step

__all__ = [
    "ANTIALIAS_CORNERS",
    "ANTIALIAS_FRACTION",
    "bandpass",
    "baseline",
    "demean",
    "detrend",
    "highpass",
    "lowpass",
    "pad",
    "polynomial_baseline",
    "resample",
    "taper",
    "trim",
]

logger = logging.getLogger(__name__)

#: Corner of the anti-alias low-pass used before interpolating to a lower rate, as a fraction
#: of the *new* Nyquist frequency [-].
ANTIALIAS_FRACTION = 0.8

#: Number of corners (poles per pass) of the anti-alias Butterworth low-pass [-].
ANTIALIAS_CORNERS = 8

#: Window half-width (in samples) of Lanczos interpolation [-].
LANCZOS_A = 20


# --------------------------------------------------------------------------------------------
# parameter validation helpers
# --------------------------------------------------------------------------------------------
def _real(name, param, value, *, positive=False, nonnegative=False, minimum=None,
          maximum=None) -> float:
    if isinstance(value, bool) or not isinstance(value, int | float | np.integer | np.floating):
        raise ProcessingError(name, f"must be a number, got {value!r}", param)
    value = float(value)
    if not np.isfinite(value):
        raise ProcessingError(name, f"must be finite, got {value!r}", param)
    if positive and value <= 0.0:
        raise ProcessingError(name, f"must be > 0, got {value!r}", param)
    if nonnegative and value < 0.0:
        raise ProcessingError(name, f"must be >= 0, got {value!r}", param)
    if minimum is not None and value < minimum:
        raise ProcessingError(name, f"must be >= {minimum:g}, got {value!r}", param)
    if maximum is not None and value > maximum:
        raise ProcessingError(name, f"must be <= {maximum:g}, got {value!r}", param)
    return value


def _integer(name, param, value, *, minimum) -> int:
    if isinstance(value, bool) or not isinstance(value, int | np.integer):
        raise ProcessingError(name, f"must be an integer, got {value!r}", param)
    if value < minimum:
        raise ProcessingError(name, f"must be >= {minimum}, got {value!r}", param)
    return int(value)


def _boolean(name, param, value) -> bool:
    if not isinstance(value, bool | np.bool_):
        raise ProcessingError(name, f"must be true or false, got {value!r}", param)
    return bool(value)


def _choice(name, param, value, choices) -> str:
    if not isinstance(value, str) or value not in choices:
        raise ProcessingError(name, f"must be one of {sorted(choices)}, got {value!r}", param)
    return value


def _cap(name, param, freq, tr, nyquist_cap) -> float:
    """Apply the Nyquist cap to a low-pass corner and check it lies below Nyquist."""
    nyquist = 0.5 * tr.stats.sampling_rate
    if nyquist_cap is not None and freq > nyquist_cap * nyquist:
        logger.info(
            "%s: %s=%g Hz capped to %g x Nyquist = %g Hz for trace %s",
            name,
            param,
            freq,
            nyquist_cap,
            nyquist_cap * nyquist,
            tr.id,
        )
        freq = nyquist_cap * nyquist
    if freq >= nyquist:
        raise ProcessingError(
            name,
            f"{freq} Hz is not below the Nyquist frequency {nyquist} Hz of trace {tr.id} "
            "(set nyquist_cap to cap it automatically)",
            param,
        )
    return freq


def _check_cap(name, nyquist_cap):
    if nyquist_cap is None:
        return None
    cap = _real(name, "nyquist_cap", nyquist_cap, positive=True)
    if cap >= 1.0:
        raise ProcessingError(name, f"must be in (0, 1), got {cap}", "nyquist_cap")
    return cap


# --------------------------------------------------------------------------------------------
# steps
# --------------------------------------------------------------------------------------------
@step("demean")
def demean(stream):
    """Remove the mean of each trace.

    Parameters
    ----------
    stream : obspy.Stream
        Accelerations [m/s^2].

    Returns
    -------
    obspy.Stream
        Copy with zero-mean traces.
    """
    for tr in stream:
        tr.detrend("demean")


_DETREND_TYPES = frozenset({"linear", "constant", "demean", "simple"})


@step("detrend")
def detrend(stream, *, type="linear"):  # noqa: A002 - ObsPy's parameter name
    """Remove a trend from each trace (:meth:`obspy.core.trace.Trace.detrend`).

    Parameters
    ----------
    stream : obspy.Stream
        Accelerations [m/s^2].
    type : {"linear", "constant", "demean", "simple"}
        ``"linear"`` removes the least-squares straight line; ``"constant"``/``"demean"`` the
        mean; ``"simple"`` the line through the first and last samples.

    Returns
    -------
    obspy.Stream
        Detrended copy.
    """
    kind = _choice("detrend", "type", type, _DETREND_TYPES)
    for tr in stream:
        tr.detrend(kind)


_TAPER_TYPES = frozenset({"hann", "cosine", "hamming", "blackman", "bartlett", "triang"})
_TAPER_SIDES = frozenset({"both", "left", "right"})


@step("taper")
def taper(stream, *, max_percentage=0.05, type="hann", side="both"):  # noqa: A002
    """Taper the ends of each trace (:meth:`obspy.core.trace.Trace.taper`).

    ``type="hann"`` with ``max_percentage=0.05`` is the usual "5 % cosine taper": a half Hann
    (raised-cosine) window over the first and last 5 % of the record (a Tukey window).

    Parameters
    ----------
    stream : obspy.Stream
        Accelerations [m/s^2].
    max_percentage : float
        Taper length on each side as a fraction of the trace length, in (0, 0.5] [-].
    type : str
        Window type: ``"hann"``, ``"cosine"``, ``"hamming"``, ``"blackman"``, ``"bartlett"``
        or ``"triang"`` (any :func:`scipy.signal.get_window` name ObsPy accepts).
    side : {"both", "left", "right"}
        Which end(s) to taper.

    Returns
    -------
    obspy.Stream
        Tapered copy.
    """
    p = _real("taper", "max_percentage", max_percentage, positive=True)
    if p > 0.5:
        raise ProcessingError("taper", f"must be in (0, 0.5], got {p}", "max_percentage")
    kind = _choice("taper", "type", type, _TAPER_TYPES)
    where = _choice("taper", "side", side, _TAPER_SIDES)
    for tr in stream:
        tr.taper(max_percentage=p, type=kind, side=where)


def _filter_common(name, corners, zerophase):
    return _integer(name, "corners", corners, minimum=1), _boolean(name, "zerophase", zerophase)


@step("highpass")
def highpass(stream, *, freq, corners=4, zerophase=True):
    """Butterworth high-pass filter (:meth:`obspy.core.trace.Trace.filter`).

    With ``zerophase=True`` the filter runs forwards and backwards (acausal, no phase shift),
    so the amplitude response is the square of the ``corners``-pole response
    (:math:`|H|^2`, -6 dB at ``freq``).

    Parameters
    ----------
    stream : obspy.Stream
        Accelerations [m/s^2].
    freq : float
        Corner frequency [Hz], below Nyquist.
    corners : int
        Filter order (poles per pass) [-].
    zerophase : bool
        Zero-phase (two-pass) filtering.

    Returns
    -------
    obspy.Stream
        Filtered copy.
    """
    f = _real("highpass", "freq", freq, positive=True)
    n, zp = _filter_common("highpass", corners, zerophase)
    for tr in stream:
        _cap("highpass", "freq", f, tr, None)
        tr.filter("highpass", freq=f, corners=n, zerophase=zp)


@step("lowpass")
def lowpass(stream, *, freq, corners=4, zerophase=True, nyquist_cap=None):
    """Butterworth low-pass filter (:meth:`obspy.core.trace.Trace.filter`).

    Parameters
    ----------
    stream : obspy.Stream
        Accelerations [m/s^2].
    freq : float
        Corner frequency [Hz].
    corners : int
        Filter order (poles per pass) [-].
    zerophase : bool
        Zero-phase (two-pass) filtering; amplitude response :math:`|H|^2`.
    nyquist_cap : float or None
        If given, a corner above ``nyquist_cap`` x Nyquist is lowered to it (per trace);
        if None, a corner at or above Nyquist is an error.

    Returns
    -------
    obspy.Stream
        Filtered copy.
    """
    f = _real("lowpass", "freq", freq, positive=True)
    n, zp = _filter_common("lowpass", corners, zerophase)
    cap = _check_cap("lowpass", nyquist_cap)
    for tr in stream:
        f_tr = _cap("lowpass", "freq", f, tr, cap)
        tr.filter("lowpass", freq=f_tr, corners=n, zerophase=zp)


@step("bandpass")
def bandpass(stream, *, freqmin, freqmax, corners=4, zerophase=True, nyquist_cap=None):
    """Butterworth band-pass filter (:meth:`obspy.core.trace.Trace.filter`).

    Parameters
    ----------
    stream : obspy.Stream
        Accelerations [m/s^2].
    freqmin, freqmax : float
        Low and high corner frequencies [Hz], ``0 < freqmin < freqmax``.
    corners : int
        Filter order (poles per pass) [-].
    zerophase : bool
        Zero-phase (two-pass) filtering; amplitude response :math:`|H|^2`.
    nyquist_cap : float or None
        If given, ``freqmax`` above ``nyquist_cap`` x Nyquist is lowered to it (per trace);
        if None, ``freqmax`` at or above Nyquist is an error.

    Returns
    -------
    obspy.Stream
        Filtered copy.
    """
    f1 = _real("bandpass", "freqmin", freqmin, positive=True)
    f2 = _real("bandpass", "freqmax", freqmax, positive=True)
    if f1 >= f2:
        raise ProcessingError("bandpass", f"must be below freqmax={f2}, got {f1}", "freqmin")
    n, zp = _filter_common("bandpass", corners, zerophase)
    cap = _check_cap("bandpass", nyquist_cap)
    for tr in stream:
        f2_tr = _cap("bandpass", "freqmax", f2, tr, cap)
        if f1 >= f2_tr:
            raise ProcessingError(
                "bandpass",
                f"freqmin={f1} Hz is not below the capped freqmax={f2_tr} Hz of trace {tr.id}",
                "freqmin",
            )
        tr.filter("bandpass", freqmin=f1, freqmax=f2_tr, corners=n, zerophase=zp)


def polynomial_baseline(acc: np.ndarray, dt: float, order: int = 6) -> np.ndarray:
    r"""Acceleration baseline from a polynomial fit to the displacement.

    The displacement :math:`d(t)` of ``acc`` (exact double integration of the piecewise-linear
    acceleration, :func:`shipblock.intensity.displacement`) is fitted by least squares with

    .. math:: P(t) = \sum_{k=2}^{N} c_k\,t^k,

    i.e. with no constant or linear term, so the correction does not change the initial
    displacement and velocity (both zero). The baseline is :math:`P''(t)`; subtracting it from
    the acceleration removes the fitted drift from the displacement. This is the sixth-order
    (:math:`N = 6`) correction applied after filtering in the PEER NGA-West2 processing
    (Ancheta et al. 2013) and in USGS gmprocess (``correct_baseline``); see Boore & Bommer
    (2005) for why residual baseline offsets appear after filtering. Time is scaled to
    :math:`[0, 1]` internally for conditioning.

    Parameters
    ----------
    acc : numpy.ndarray
        Acceleration [m/s^2], shape ``(n,)`` with ``n > order``.
    dt : float
        Time step [s].
    order : int
        Highest polynomial degree :math:`N \ge 2` [-].

    Returns
    -------
    numpy.ndarray
        :math:`P''(t_i)` [m/s^2], shape ``(n,)``.
    """
    acc = checks.acceleration(acc, "acc")
    dt = checks.time_step(dt, "dt")
    order = checks.whole(order, "order", low=2, high=acc.size - 1)
    n = acc.size
    duration = (n - 1) * dt
    tau = np.arange(n) / (n - 1)
    powers = np.arange(2, order + 1)
    design = tau[:, None] ** powers
    coef, *_ = np.linalg.lstsq(design, displacement(acc, dt), rcond=None)
    second = powers * (powers - 1) * coef
    return (tau[:, None] ** (powers - 2)) @ second / duration**2


@step("baseline")
def baseline(stream, *, order=6):
    """Polynomial baseline correction of each trace (see :func:`polynomial_baseline`).

    Parameters
    ----------
    stream : obspy.Stream
        Accelerations [m/s^2].
    order : int
        Highest degree of the displacement polynomial, >= 2 [-]; 6 by default (Ancheta et al.
        2013; USGS gmprocess).

    Returns
    -------
    obspy.Stream
        Corrected copy.

    References
    ----------
    .. [1] Boore, D. M. and Bommer, J. J. (2005). Processing of strong-motion accelerograms:
       needs, options and consequences. *Soil Dyn. Earthq. Eng.* 25, 93-115.
    .. [2] Ancheta, T. D. et al. (2013). PEER NGA-West2 Database. PEER Report 2013/03.
    """
    k = _integer("baseline", "order", order, minimum=2)
    for tr in stream:
        if tr.stats.npts <= k:
            raise ProcessingError(
                "baseline",
                f"trace {tr.id} has {tr.stats.npts} samples, need more than {k}",
                "order",
            )
        tr.data = tr.data - polynomial_baseline(tr.data, tr.stats.delta, k)


_RESAMPLE_METHODS = frozenset({"fft", "linear", "cubic", "lanczos"})


@step("resample")
def resample(stream, *, sampling_rate, method="fft"):
    """Resample each trace to a new sampling rate, anti-aliased.

    ``method="fft"`` uses :meth:`obspy.core.trace.Trace.resample` (Fourier method: the spectrum
    above the new Nyquist frequency is discarded, which is an ideal anti-alias filter; the record
    is treated as periodic, so taper first). It is called with a rectangular (``"boxcar"``)
    spectral window because ObsPy's default Hann window tapers the whole *pass band* (a 10 Hz
    sine loses 10 % of its amplitude when 100 Hz data are resampled). The other
    methods use :meth:`obspy.core.trace.Trace.interpolate`; when they *reduce* the rate, a
    zero-phase Butterworth low-pass (:data:`ANTIALIAS_CORNERS` poles, corner at
    :data:`ANTIALIAS_FRACTION` x the new Nyquist frequency) is applied first.

    Parameters
    ----------
    stream : obspy.Stream
        Accelerations [m/s^2].
    sampling_rate : float
        New sampling rate [Hz].
    method : {"fft", "linear", "cubic", "lanczos"}
        Resampling method.

    Returns
    -------
    obspy.Stream
        Resampled copy.
    """
    fs = _real("resample", "sampling_rate", sampling_rate, positive=True,
               minimum=1.0 / checks.MAX_TIME_STEP, maximum=1.0 / checks.MIN_TIME_STEP)
    how = _choice("resample", "method", method, _RESAMPLE_METHODS)
    for tr in stream:
        if tr.stats.sampling_rate == fs:
            continue
        if how == "fft":
            tr.resample(fs, window="boxcar")
            continue
        if fs < tr.stats.sampling_rate:
            tr.filter(
                "lowpass",
                freq=ANTIALIAS_FRACTION * 0.5 * fs,
                corners=ANTIALIAS_CORNERS,
                zerophase=True,
            )
        kwargs = {"a": LANCZOS_A} if how == "lanczos" else {}
        tr.interpolate(fs, method=how, **kwargs)


@step("trim")
def trim(stream, *, start=0.0, end=None):
    """Cut the record to a time window.

    Times are measured from the earliest start time of the stream; the window edges snap to
    the nearest samples.

    Parameters
    ----------
    stream : obspy.Stream
        Accelerations [m/s^2].
    start : float
        Window start [s], >= 0.
    end : float or None
        Window end [s], > ``start``; None keeps the end of the record.

    Returns
    -------
    obspy.Stream
        Trimmed copy.
    """
    t_start = _real("trim", "start", start, nonnegative=True, maximum=checks.MAX_DURATION)
    t_end = (None if end is None
             else _real("trim", "end", end, positive=True, maximum=checks.MAX_DURATION))
    if t_end is not None and t_end <= t_start:
        raise ProcessingError("trim", f"must be greater than start={t_start}, got {t_end}", "end")
    if len(stream) == 0:
        return
    t0 = min(tr.stats.starttime for tr in stream)
    # obspy drops a trace the window misses entirely: name the window against the record instead
    for tr in stream:
        first = tr.stats.starttime - t0
        last = tr.stats.endtime - t0
        if t_start >= last:
            raise ProcessingError("trim", f"start={t_start:g} s is at or after the end of trace"
                                  f" {tr.id} ({last:.3f} s from the record's start)", "start")
        if t_end is not None and t_end <= first:
            raise ProcessingError("trim", f"end={t_end:g} s is at or before the start of trace"
                                  f" {tr.id} ({first:.3f} s from the record's start)", "end")
    stream.trim(
        starttime=t0 + t_start,
        endtime=None if t_end is None else t0 + t_end,
        nearest_sample=True,
    )
    for tr in stream:
        if tr.stats.npts < 2:
            raise ProcessingError("trim", f"window leaves trace {tr.id} with < 2 samples", "end")


@step("pad")
def pad(stream, *, before=0.0, after=0.0):
    """Add zeros before and/or after each trace.

    The number of added samples is ``round(before / dt)`` and ``round(after / dt)``; the start
    time moves back accordingly. Padding before acausal filtering avoids the filter transients
    being cut off (Boore 2005).

    Parameters
    ----------
    stream : obspy.Stream
        Accelerations [m/s^2].
    before, after : float
        Lengths of zero padding [s], >= 0.

    Returns
    -------
    obspy.Stream
        Padded copy.

    References
    ----------
    .. [1] Boore, D. M. (2005). On pads and filters: processing strong-motion data.
       *Bull. Seismol. Soc. Am.* 95(2), 745-750.
    """
    t_before = _real("pad", "before", before, nonnegative=True, maximum=checks.MAX_PADDING)
    t_after = _real("pad", "after", after, nonnegative=True, maximum=checks.MAX_PADDING)
    for tr in stream:
        dt = tr.stats.delta
        n0 = int(round(t_before / dt))
        n1 = int(round(t_after / dt))
        tr.data = np.concatenate([np.zeros(n0), tr.data, np.zeros(n1)])
        tr.stats.starttime = tr.stats.starttime - n0 * dt
