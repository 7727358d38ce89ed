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

The steps are in :mod:`shipblock.processing.steps`, the registry (:func:`step`,
:data:`STEPS`, :class:`ProcessingError`) in ``shipblock.processing._registry``; their names
are imported here, so ``shipblock.processing.bandpass`` and the rest keep their paths.

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
from collections.abc import Iterable, Mapping
from types import MappingProxyType

from obspy import Stream, Trace

from shipblock.processing._registry import (
    PROVENANCE_PREFIX,
    STEPS,
    ProcessingError,
    _float_copy,
    step,
)
from shipblock.processing.steps import (
    ANTIALIAS_CORNERS,
    ANTIALIAS_FRACTION,
    bandpass,
    baseline,
    demean,
    detrend,
    highpass,
    lowpass,
    pad,
    polynomial_baseline,
    resample,
    taper,
    trim,
)
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

#: Fraction of the Nyquist frequency [-] that the low-pass corner of the default chain is
#: capped at, so the Butterworth roll-off is resolved below Nyquist.
DEFAULT_NYQUIST_CAP = 0.8


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
