r"""Declarative processing of ground-acceleration records held in obspy Streams.

Every step is a pure function ``step(stream, **params) -> Stream`` that works on a copy of its
input (the input is never mutated), registered under a name in :data:`STEPS` by the
:func:`step` decorator. A *chain* is a list of mappings ``{"step": name, **params}``, which is
what the ``[[processing]]`` tables of a pipeline TOML file contain; :func:`apply_chain` runs it.

Each step appends one provenance string per trace to ``trace.stats.processing`` (the list
ObsPy uses for the same purpose), of the form::

    shipblock.processing.bandpass(freqmin=0.1, freqmax=25.0, corners=4, zerophase=True, ...)

with *all* parameters, defaults included, so that the log alone reproduces the chain (see
:func:`chain_from_provenance`). Entries that ObsPy's own methods add while a step runs are
replaced by the single shipblock entry so the log stays one line per step.

Streams are expected to hold accelerations [m/s^2]; time quantities are [s] and frequencies
[Hz]. Filtering, detrending, tapering and resampling delegate to ObsPy (which uses
``scipy.signal``); only the polynomial baseline correction is written here.

References
----------
.. [1] Boore, D. M. and Bommer, J. J. (2005). Processing of strong-motion accelerograms:
   needs, options and consequences. *Soil Dyn. Earthq. Eng.* 25, 93-115.
.. [2] Boore, D. M. (2005). On pads and filters: processing strong-motion data.
   *Bull. Seismol. Soc. Am.* 95(2), 745-750.
.. [3] Ancheta, T. D. et al. (2013). *PEER NGA-West2 Database*. PEER Report 2013/03.
.. [4] Hearne, M. et al. USGS gmprocess (groundmotion-processing), ``correct_baseline``.
"""

from __future__ import annotations

import ast
import functools
import inspect
import logging
from collections.abc import Callable, Iterable, Mapping
from types import MappingProxyType

import numpy as np
from obspy import Stream, Trace

from shipblock import checks
from shipblock.errors import ParameterError, ParameterTypeError, ShipblockError
from shipblock.intensity import displacement
from shipblock.records.motion import check_motion

__all__ = [
    "ANTIALIAS_CORNERS",
    "ANTIALIAS_FRACTION",
    "DEFAULT_CHAIN",
    "DEFAULT_NYQUIST_CAP",
    "PROVENANCE_PREFIX",
    "STEPS",
    "ProcessingError",
    "apply_chain",
    "bandpass",
    "baseline",
    "chain_from_provenance",
    "default_chain",
    "demean",
    "detrend",
    "highpass",
    "lowpass",
    "pad",
    "polynomial_baseline",
    "process_motion",
    "resample",
    "step",
    "taper",
    "trim",
]

logger = logging.getLogger(__name__)

#: Prefix of every provenance string written by this module.
PROVENANCE_PREFIX = "shipblock.processing."

#: Fraction of the Nyquist frequency [-] that the low-pass corner of the default chain is
#: capped at, so the Butterworth roll-off is resolved below Nyquist.
DEFAULT_NYQUIST_CAP = 0.8

#: Corner of the anti-alias low-pass used before interpolating to a lower rate, as a fraction
#: of the *new* Nyquist frequency [-].
ANTIALIAS_FRACTION = 0.8

#: Number of corners (poles per pass) of the anti-alias Butterworth low-pass [-].
ANTIALIAS_CORNERS = 8

#: Window half-width (in samples) of Lanczos interpolation [-].
LANCZOS_A = 20


class ProcessingError(ShipblockError, ValueError):
    """A processing step or chain entry is unknown or has a bad parameter.

    Parameters
    ----------
    step : str
        Name of the step (or ``"<chain>"`` for a malformed chain).
    problem : str
        What is wrong.
    parameter : str, optional
        Name of the offending parameter, if any.
    """

    def __init__(self, step: str, problem: str, parameter: str | None = None):
        self.step = step
        self.parameter = parameter
        self.problem = problem
        where = f"step {step!r}" + (f", parameter {parameter!r}" if parameter else "")
        super().__init__(f"{where}: {problem}")

    def __reduce__(self):
        """Keep the error picklable (for example across Dask workers)."""
        return (type(self), (self.step, self.problem, self.parameter))


#: Registry of processing steps: name -> public step function. Filled at import time by
#: :func:`step`; treat it as read-only.
STEPS: dict[str, Callable[..., Stream]] = {}


# --------------------------------------------------------------------------------------------
# registry machinery
# --------------------------------------------------------------------------------------------
def _bind(name: str, signature: inspect.Signature, params: Mapping) -> dict:
    """Check ``params`` against ``signature`` and return all parameters, defaults included."""
    accepted = [p for p in signature.parameters.values() if p.kind is p.KEYWORD_ONLY]
    names = {p.name for p in accepted}
    for key in params:
        if key not in names:
            known = ", ".join(sorted(names)) or "none"
            raise ProcessingError(name, f"unknown parameter{checks.closest(key, names)} "
                                        f"(accepted: {known})", str(key))
    bound = {}
    for p in accepted:
        if p.name in params:
            bound[p.name] = params[p.name]
        elif p.default is inspect.Parameter.empty:
            raise ProcessingError(name, "required parameter is missing", p.name)
        else:
            bound[p.name] = p.default
    return bound


def _format_call(name: str, params: Mapping) -> str:
    args = ", ".join(f"{k}={v!r}" for k, v in params.items())
    return f"{PROVENANCE_PREFIX}{name}({args})"


def _float_copy(stream: Stream) -> Stream:
    if isinstance(stream, Trace):
        stream = Stream([stream])
    if not isinstance(stream, Stream):
        raise ParameterTypeError(f"stream must be an obspy Stream (or Trace), got "
                                 f"{type(stream).__name__}")
    out = stream.copy()
    for tr in out:
        tr.data = np.asarray(tr.data, dtype=np.float64)
    return out


def step(name: str):
    """Register a processing step under ``name`` in :data:`STEPS`.

    The decorated implementation has the signature ``impl(stream, *, p1=..., ...)``, receives a
    private float64 copy of the input that it may modify in place, and returns nothing. The
    decorator returns the public step ``f(stream, **params) -> Stream`` which validates the
    parameter names, copies the input, runs the implementation and appends the provenance
    string to every trace.

    Parameters
    ----------
    name : str
        Step name used in chains and provenance.

    Returns
    -------
    callable
        Decorator.
    """

    def register(impl):
        if name in STEPS:
            raise ParameterError(f"processing step {name!r} is registered twice")
        signature = inspect.signature(impl)

        @functools.wraps(impl)
        def public(stream, **params):
            bound = _bind(name, signature, params)
            out = _float_copy(stream)
            n_before = [len(tr.stats.get("processing", [])) for tr in out]
            impl(out, **bound)
            entry = _format_call(name, bound)
            for tr, n in zip(out, n_before, strict=True):
                history = list(tr.stats.get("processing", []))[:n]
                tr.stats.processing = [*history, entry]
            return out

        public.step_name = name
        STEPS[name] = public
        return public

    return register


def apply_chain(stream: Stream, chain: Iterable[Mapping]) -> Stream:
    """Apply a list of processing steps in order.

    Parameters
    ----------
    stream : obspy.Stream
        Input accelerations [m/s^2]; not modified.
    chain : iterable of mapping
        Entries ``{"step": name, **params}``, e.g. the ``[[processing]]`` tables of a
        pipeline TOML file or :data:`DEFAULT_CHAIN`.

    Returns
    -------
    obspy.Stream
        Processed copy, with one provenance string per step in each ``stats.processing``.

    Raises
    ------
    ProcessingError
        If an entry is not a mapping, lacks ``"step"``, names an unknown step, or has an
        unknown, missing or invalid parameter. The message names the step and parameter.
    """
    out = _float_copy(stream)
    if isinstance(chain, Mapping | str | bytes) or not isinstance(chain, Iterable):
        raise ProcessingError("<chain>", f"chain must be a list of tables {{step = ...}}, got "
                                         f"{type(chain).__name__} {chain!r}")
    for k, entry in enumerate(chain):
        if not isinstance(entry, Mapping):
            raise ProcessingError("<chain>", f"entry {k} is not a table/mapping: {entry!r}")
        params = dict(entry)
        name = params.pop("step", None)
        if name is None:
            raise ProcessingError("<chain>", f"entry {k} has no 'step' key: {entry!r}", "step")
        if name not in STEPS:
            known = ", ".join(sorted(STEPS))
            raise ProcessingError(str(name), f"unknown processing step (known steps: {known})")
        out = STEPS[name](out, **params)
    return out


def process_motion(motion, chain: Iterable[Mapping] | None = None):
    """Apply a chain to a :class:`shipblock.records.motion.GroundMotion` and return a new one.

    Parameters
    ----------
    motion : shipblock.records.motion.GroundMotion
        Input motion [m/s^2]; unchanged.
    chain : iterable of mapping, optional
        Processing chain (see :func:`apply_chain`); None means :data:`DEFAULT_CHAIN`.

    Returns
    -------
    shipblock.records.motion.GroundMotion
        New motion built with ``motion.with_stream``; the chain's provenance strings (joined by
        ``"; "``) are appended to ``metadata["processing"]`` as one note, and each trace keeps
        them in ``stats.processing``.
    """
    chain = DEFAULT_CHAIN if chain is None else chain
    check_motion(motion)
    processed = apply_chain(motion.stream, chain)
    n_old = len(motion.stream[0].stats.get("processing", [])) if len(motion.stream) else 0
    notes = list(processed[0].stats.get("processing", [])[n_old:]) if len(processed) else []
    if not notes:
        return motion  # an empty chain changes nothing
    return motion.with_stream(processed, "; ".join(notes))


def chain_from_provenance(trace: Trace) -> list[dict]:
    """Rebuild the chain that produced ``trace`` from its shipblock provenance strings.

    Parameters
    ----------
    trace : obspy.Trace
        A trace processed by this module.

    Returns
    -------
    list of dict
        ``[{"step": name, **params}, ...]`` in order; non-shipblock entries are skipped.
    """
    chain = []
    for entry in trace.stats.get("processing", []):
        if not entry.startswith(PROVENANCE_PREFIX):
            continue
        call = ast.parse(entry[len(PROVENANCE_PREFIX) :], mode="eval").body
        params = {kw.arg: ast.literal_eval(kw.value) for kw in call.keywords}
        chain.append({"step": call.func.id, **params})
    return chain


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


#: Default processing chain (read-only; :func:`default_chain` returns a mutable copy).
#:
#: 1. ``demean`` and ``detrend(type="linear")``: remove the offset and linear trend that
#:    otherwise integrate into large velocity/displacement drifts.
#: 2. ``taper(max_percentage=0.05, type="hann")``: a 5 % cosine (Tukey) taper brings both ends
#:    smoothly to zero so the filter does not ring on the step at the record ends.
#: 3. ``bandpass(0.1-25 Hz, corners=4, zerophase=True, nyquist_cap=0.8)``: a zero-phase
#:    Butterworth keeps peak times and the H/V phase relation the ship responds to; 0.1 Hz
#:    removes long-period noise while keeping periods up to 10 s (well beyond the rocking and
#:    sliding periods of a docked ship); 25 Hz removes high-frequency noise that a rigid ship
#:    on blocks does not feel, capped at 80 % of Nyquist for coarsely sampled records.
#: 4. ``baseline(order=6)``: removes the residual displacement drift left after filtering
#:    (Ancheta et al. 2013; gmprocess; Boore & Bommer 2005).
#:
#: The corners are generic; records with little pre-event signal benefit from a ``pad`` step
#: before the filter (Boore 2005) and record-specific corners chosen from the signal-to-noise
#: ratio, which this chain does not do.
DEFAULT_CHAIN: tuple[Mapping, ...] = tuple(
    MappingProxyType(entry)
    for entry in (
        {"step": "demean"},
        {"step": "detrend", "type": "linear"},
        {"step": "taper", "max_percentage": 0.05, "type": "hann", "side": "both"},
        {
            "step": "bandpass",
            "freqmin": 0.1,
            "freqmax": 25.0,
            "corners": 4,
            "zerophase": True,
            "nyquist_cap": DEFAULT_NYQUIST_CAP,
        },
        {"step": "baseline", "order": 6},
    )
)


def default_chain() -> list[dict]:
    """Return a mutable copy of :data:`DEFAULT_CHAIN`.

    Returns
    -------
    list of dict
        ``[{"step": name, **params}, ...]``, ready to edit or write to TOML.
    """
    return [dict(entry) for entry in DEFAULT_CHAIN]
