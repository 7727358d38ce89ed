"""The registry of processing steps: the :func:`step` decorator, :data:`STEPS` and the error.

A step's implementation receives a private float64 copy of the input and the checked
parameters; the decorator makes the public step, which also writes the provenance string
(:mod:`shipblock.processing` describes the chain and the provenance).
"""

from __future__ import annotations

import functools
import inspect
from collections.abc import Callable, Mapping

import numpy as np
from obspy import Stream, Trace

from shipblock import checks
from shipblock.errors import ParameterError, ParameterTypeError, ShipblockError

__all__ = ["PROVENANCE_PREFIX", "STEPS", "ProcessingError", "step"]

#: Prefix of every provenance string written by the steps (``shipblock.processing.<step>(...)``).
PROVENANCE_PREFIX = "shipblock.processing."


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
