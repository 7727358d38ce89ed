r"""The model seam: what a fragility study needs from a physical model, and nothing more.

A study (:mod:`shipblock.fragility`: design, batch, store, limit states, histories, reruns,
pipelines, the command line) never touches a model's equations. It talks to a :class:`Model`:

* **parameters in** -- :attr:`Model.parameters` declares every parameter of the model's
  ``[system]`` table as a :class:`Field` (name, type, unit, range, default, one-line doc);
  :meth:`Model.build` turns a table of them into the model's validated *system* (any object the
  model understands), raising a :class:`FieldError` that carries the parameter's name as data.
  :attr:`Model.sweep_parameters` lists what a study may sweep and :meth:`Model.vary` applies
  swept values to a system;
* **named EDPs out** -- :attr:`Model.edps` describes each engineering demand parameter a limit
  state may use (:class:`EDPInfo`: units, long name, kind, whether collapse exceeds it), and
  :attr:`Model.outputs` every per-run variable the batch stores. Every model returns a
  ``failure`` code (0: none; the meaning of the others in :attr:`Model.failure_codes`): a run
  whose ``failure`` is not 0 has collapsed and exceeds every response limit state;
* **a batch entry point** -- :meth:`Model.run_batch` runs many (input, system) cases in one
  call and returns one array per output, so that a model with a compiled batch kernel keeps
  its speed (the study makes one call per chunk of cases, never one per run);
  :meth:`Model.simulate` runs one case with its full time histories (reruns, histories);
* **a caption** -- :meth:`Model.caption` names a system in one line for figures and reports,
  and :meth:`Model.restore` rebuilds it from what a result file stores (:meth:`Model.describe`).

Models are found by name (:func:`get_model`); a pipeline chooses one with
``[system] model = "<name>"`` (default ``"rigid"``, :class:`shipblock.models.rigid.RigidModel`).
A new model is a subclass of :class:`Model` registered with :func:`register_model`; no study
code changes (``docs/contributing.rst``). A model whose module is heavy to import (a compiled
kernel, its numba caches) may be registered by the path of its class instead,
``"package.module:Class"``: the module is imported, and the model made, when the model is
first asked for by name, so that a study of another model never pays for it.
"""

from __future__ import annotations

import importlib
import math
import threading
from abc import ABC, abstractmethod
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any, ClassVar, NamedTuple

import numpy as np

from shipblock.errors import ParameterError, ParameterTypeError
from shipblock.quantities import to_si

__all__ = [
    "EDPInfo",
    "Field",
    "FieldError",
    "Model",
    "get_model",
    "model_names",
    "register_model",
    "unregister_model",
]


class FieldError(ParameterError):
    """A declared value is invalid; :attr:`field` names it as data, not only in the text.

    Parameters
    ----------
    field : str
        The value's name (a parameter, a key; ``""`` when no single one is at fault).
    problem : str
        What is wrong (the message).
    """

    def __init__(self, field: str, problem: str):
        self.field = field
        self.problem = problem
        super().__init__(problem)

    def __reduce__(self):
        """Keep the error picklable (e.g. across Dask workers)."""
        return (type(self), (self.field, self.problem))


_TYPE_NAMES = {int: "an integer", float: "a number", str: "a string", list: "a list",
               dict: "a table", bool: "true/false"}

# An example of a quantity in the messages, per SI unit.
_QUANTITY_EXAMPLES = {"kg": "20000 t", "m": "600 mm"}


@dataclass(frozen=True)
class Field:
    """One declared value: of a pipeline file (a key) or of a model (a parameter).

    From this declaration alone the value is parsed and checked (:meth:`check`), its error
    names it (:class:`FieldError`) and the documentation's table of keys is written.

    Attributes
    ----------
    name : str
        Key or parameter name.
    types : tuple of type
        Accepted TOML types (``int``, ``float``, ``str``, ``bool``, ``list``, ``dict``); with
        ``float`` an ``int`` is accepted too, never a ``bool`` unless listed.
    doc : str
        One line: what it is.
    units : str
        SI unit (``""`` for none, ``"1"`` for dimensionless).
    default : object
        Value taken when the key is absent (None: none; see :attr:`default_doc`).
    required : bool
        Whether the key must be given.
    low, high : float or None
        Range of a number (bounds included unless :attr:`low_open` / :attr:`high_open`).
    low_open, high_open : bool
    choices : tuple of str or None
        Accepted values of a string.
    default_doc : str
        How the docs state the default when it is not a plain value (e.g. "the shipped
        catalogue").
    quantity : str or None
        The SI unit in pint's spelling (``"kg"``, ``"m"``, ``"kg * m**2"``) of a number that
        may also be given as a string with a unit (``"20000 t"``, ``"600 mm"``), converted
        to SI by :func:`shipblock.quantities.to_si`; None: numbers only.
    """

    name: str
    types: tuple[type, ...]
    doc: str
    units: str = ""
    default: Any = None
    required: bool = False
    low: float | None = None
    high: float | None = None
    low_open: bool = False
    high_open: bool = False
    choices: tuple[str, ...] | None = None
    default_doc: str = ""
    quantity: str | None = None

    # -- checks --------------------------------------------------------------------------------
    def type_ok(self, value) -> bool:
        """Whether ``value`` has one of the accepted types (a bool only if ``bool`` is one)."""
        if isinstance(value, bool):
            return bool in self.types
        if isinstance(value, str) and self.quantity is not None:
            return True  # a quantity with a unit, converted by check()
        kinds = self.types + ((int,) if float in self.types else ())
        return isinstance(value, kinds)

    def expected(self) -> str:
        """What the type check asks for, e.g. ``"a number or a string"``."""
        names = [_TYPE_NAMES[t] for t in dict.fromkeys(self.types)]
        if self.quantity is not None:
            names.append(f"a quantity with a unit ('{_QUANTITY_EXAMPLES.get(self.quantity, '1 ' + self.quantity)}')")
        return " or ".join(names)

    def range_text(self, with_units: bool = True) -> str:
        """The accepted range or choices in words (``""`` for none), with the unit or not."""
        if self.choices is not None:
            return "one of " + ", ".join(map(repr, self.choices))
        if self.low is None and self.high is None:
            return ""
        if int in self.types and float not in self.types:
            return f"an integer in [{self.low}, {self.high}]"
        unit = f" [{self.units}]" if with_units and self.units not in ("", "1") else ""
        if self.low is not None and self.high is not None:
            return (f"{'(' if self.low_open else '['}{self.low:g}, {self.high:g}"
                    f"{')' if self.high_open else ']'}{unit}")
        if self.low is not None:
            return f"{'>' if self.low_open else '>='} {self.low:g}{unit}"
        return f"{'<' if self.high_open else '<='} {self.high:g}{unit}"

    def check_type(self, value, key: str | None = None):
        """``value`` if its type is accepted, else a :class:`FieldError` naming ``key``."""
        if not self.type_ok(value):
            raise FieldError(key or self.name, f"must be {self.expected()}, got "
                                               f"{type(value).__name__} {value!r}")
        return value

    def check(self, value, key: str | None = None):
        """``value`` checked against the declaration: type, then range or choices.

        Parameters
        ----------
        value : object
        key : str, optional
            The name the error gives (default :attr:`name`, e.g. ``"fit.seed"`` for a key).

        Returns
        -------
        object
            ``value`` (a number as ``int`` or ``float`` as declared).

        Raises
        ------
        FieldError
            With ``field = key``: a wrong type, a number outside the range (NaN and
            infinities included) or a string not among the choices.
        """
        key = key or self.name
        if self.quantity is not None and isinstance(value, str):
            try:
                value = to_si(value, self.quantity, key)
            except ParameterError as exc:
                raise FieldError(key, str(exc).removeprefix(f"{key} ")) from None
        self.check_type(value, key)
        if self.choices is not None and isinstance(value, str):
            if value not in self.choices:
                raise FieldError(key, f"must be {self.range_text()}, got {value!r}")
            return value
        if isinstance(value, bool) or not isinstance(value, int | float):
            return value
        if int in self.types and float not in self.types:
            if (self.low is not None and value < self.low) or \
                    (self.high is not None and value > self.high):
                raise FieldError(key, f"must be {self.range_text()}, got {value}")
            return int(value)
        x = float(value) if abs(value) < 2.0**1023 else math.copysign(math.inf, value)
        ok = math.isfinite(x) and (
            self.low is None or (x > self.low if self.low_open else x >= self.low)) and (
            self.high is None or (x < self.high if self.high_open else x <= self.high))
        if not ok:
            what = self.range_text()
            what = f" in {what}" if what.startswith(("[", "(")) else f" {what}" if what else ""
            raise FieldError(key, f"must be a finite number{what}, got {value!r}")
        return x

    def default_text(self) -> str:
        """The default as the docs show it."""
        if self.default_doc:
            return self.default_doc
        if self.required:
            return "required"
        if self.default is None:
            return "none"
        if isinstance(self.default, bool):
            return "true" if self.default else "false"
        if isinstance(self.default, str):
            return repr(self.default)
        return f"{self.default:g}" if isinstance(self.default, float) else str(self.default)


class EDPInfo(NamedTuple):
    """Description of one per-run output usable as an EDP of a limit state.

    Attributes
    ----------
    units : str
        Units of the variable (``"1"`` for dimensionless).
    long_name : str
        Human-readable description.
    kind : str
        ``"float"`` (continuous, non-negative), ``"count"`` (non-negative integer), ``"bool"``
        or ``"code"`` (categorical integer, e.g. the ``failure`` code).
    response : bool
        Whether it is a response quantity, so that collapse (``failure != 0``) exceeds every
        limit state defined on it.
    magnitude : bool
        Whether the limit state compares the absolute value (for possibly signed residuals).
    """

    units: str
    long_name: str
    kind: str
    response: bool
    magnitude: bool = False


class Model(ABC):
    """A physical model as a fragility study sees it (see the module docstring).

    Subclasses set the class attributes and implement the abstract methods. An instance must
    be picklable (it travels to Dask workers with each chunk): keep its state in plain
    attributes.

    Attributes
    ----------
    name : str
        Registry name (``[system] model = "<name>"``).
    description : str
        One line, for the docs and messages.
    parameters : Mapping[str, Field]
        The ``[system]`` parameters, SI units.
    options : Mapping[str, Field]
        The ``[solver]`` options (with their defaults).
    sweep_parameters : Mapping[str, tuple of (str, str)]
        What a study may sweep: name -> (units, long name).
    edps : Mapping[str, EDPInfo]
        EDPs a limit state may use; ``failure`` (the collapse code) among them.
    outputs : Mapping[str, tuple of (str, str)]
        Every per-run output of :meth:`run_batch`: name -> (units, long name); the keys of
        :attr:`edps` among them.
    failure_codes : Mapping[int, str]
        Meaning of the ``failure`` codes (0: none).
    solver_error_code : int or None
        A ``failure`` code meaning "the solver failed" (the run has no result: the batch
        stores NaN and a message), or None if the model has none.
    default_edp : str or None
        The EDP figures show when none is named (e.g. IDA curves); None: the first float EDP.
    """

    name: ClassVar[str]
    description: ClassVar[str]
    parameters: ClassVar[Mapping[str, Field]]
    options: ClassVar[Mapping[str, Field]] = {}
    sweep_parameters: ClassVar[Mapping[str, tuple[str, str]]]
    edps: ClassVar[Mapping[str, EDPInfo]]
    outputs: ClassVar[Mapping[str, tuple[str, str]]]
    failure_codes: ClassVar[Mapping[int, str]] = {0: "none"}
    solver_error_code: ClassVar[int | None] = None
    default_edp: ClassVar[str | None] = None

    @abstractmethod
    def build(self, values: Mapping[str, Any]):
        """The model's validated system from its ``[system]`` parameters.

        Parameters
        ----------
        values : Mapping[str, object]
            Parameter name -> value in the units of :attr:`parameters` (types already checked
            against the declarations).

        Returns
        -------
        object
            The system, as :meth:`vary`, :meth:`describe`, :meth:`run_batch` and
            :meth:`simulate` take it.

        Raises
        ------
        FieldError
            Naming the parameter at fault in :attr:`FieldError.field` (``""`` if none alone).
        """

    @abstractmethod
    def vary(self, system, values: Mapping[str, Any]):
        """``system`` with some :attr:`sweep_parameters` changed (validated).

        Raises
        ------
        ParameterError
            If a name is unknown or the changed system is invalid.
        """

    @abstractmethod
    def describe(self, system) -> dict:
        """The system's parameters as a JSON-ready dict (stored with the results)."""

    def restore(self, described: Mapping[str, Any]):
        """The system again from :meth:`describe`'s output (e.g. a result file's ``system``
        attribute); by default :meth:`build`."""
        return self.build(described)

    def caption(self, system) -> str:
        """One line naming ``system`` for a figure's or report's title (by default its
        :meth:`describe`, ``name = value`` pairs)."""
        return ", ".join(f"{k} = {v:g}" if isinstance(v, float) else f"{k} = {v}"
                         for k, v in self.describe(system).items())

    def check_options(self, options: Mapping[str, Any]) -> dict:
        """The ``[solver]`` options with their defaults, each checked by its declaration.

        Raises
        ------
        FieldError
            Naming the option.
        """
        out = {}
        for name, field in self.options.items():
            value = options.get(name, field.default)
            out[name] = field.check(value) if value is not None else None
        return out

    @abstractmethod
    def run_batch(self, systems: Sequence, inputs: Sequence[tuple], dts: Sequence[float],
                  cases: np.ndarray, **options) -> dict[str, np.ndarray]:
        """Run many cases in one call: the batch entry point.

        Parameters
        ----------
        systems : sequence
            Systems (from :meth:`build` / :meth:`vary`).
        inputs : sequence of (numpy.ndarray, numpy.ndarray or None)
            Scaled ground accelerations ``(horizontal, vertical)`` [m/s^2], vertical positive
            up (None: none).
        dts : sequence of float
            Sampling interval of each input [s].
        cases : numpy.ndarray of int, shape (n, 2)
            ``(input index, system index)`` per case.
        **options
            The checked :attr:`options`.

        Returns
        -------
        dict of numpy.ndarray
            One array of length ``n`` per name of :attr:`outputs`.
        """

    @abstractmethod
    def simulate(self, system, horizontal: np.ndarray, vertical: np.ndarray | None,
                 dt: float, **options):
        """Run one case with its full time histories.

        Returns
        -------
        object
            With ``summary`` (a mapping holding the :attr:`outputs` of the run, equal to
            :meth:`run_batch`'s for the same case) and ``to_dataset()`` (the histories as an
            :class:`xarray.Dataset`).
        """

    def __repr__(self) -> str:
        return f"<shipblock model {self.name!r}: {self.description}>"


# ------------------------------------------------------------------------------------------
# registry
# ------------------------------------------------------------------------------------------

# A name -> its model, or the "module:Class" path of a model not loaded yet (get_model loads it
# once; the lock keeps two threads of a Dask worker from making two instances of it).
_REGISTRY: dict[str, Model | str] = {}
_LOADING = threading.Lock()


def register_model(model: Model | str, *, name: str | None = None, replace: bool = False
                   ) -> Model | str:
    """Make ``model`` available by its name (to pipelines: ``[system] model = "<name>"``).

    Parameters
    ----------
    model : Model or str
        An instance, or the path ``"package.module:Class"`` of a :class:`Model` subclass (or
        of an instance) loaded when the model is first asked for (:func:`get_model`): its
        module is imported only then, so that a model that is heavy to import (a compiled
        kernel) costs nothing to the studies of other models.
    name : str, optional
        The name a path is registered under (required with a path; the loaded model's
        :attr:`Model.name` must equal it). Not given with an instance, which names itself.
    replace : bool
        Replace a model registered under the same name (else that is an error).

    Returns
    -------
    Model or str
        ``model``.

    Raises
    ------
    ParameterTypeError
        If ``model`` is neither a :class:`Model` nor a string.
    ParameterError
        If the name is taken, a path is not ``"module:Class"`` or comes without ``name``, or
        ``name`` is given with an instance.
    """
    if isinstance(model, str):
        module, _, attribute = model.partition(":")
        if not module or not attribute:
            raise ParameterError(f"a model's path must be 'package.module:Class', got {model!r}")
        if not isinstance(name, str) or not name:
            raise ParameterError(f"a model registered by its path ({model!r}) needs a name=")
        key = name
    elif isinstance(model, Model):
        if name is not None:
            raise ParameterError(f"name= is for a model registered by its path; {model!r} is "
                                 f"named {model.name!r} by its class")
        key = model.name
    else:
        raise ParameterTypeError(f"model must be a shipblock.models.Model or the path "
                                 f"'package.module:Class' of one, got {type(model).__name__}")
    if key in _REGISTRY and not replace and _REGISTRY[key] is not model:
        raise ParameterError(f"a model named {key!r} is already registered")
    _REGISTRY[key] = model
    return model


def unregister_model(name: str) -> None:
    """Remove a registered model (e.g. a test's)."""
    _REGISTRY.pop(name, None)


def model_names() -> tuple[str, ...]:
    """Names of the registered models, in registration order (those registered by a path
    included, loaded or not)."""
    return tuple(_REGISTRY)


def _load(name: str, path: str) -> Model:
    """The model at ``path`` (``"module:Class"``, registered as ``name``), made once."""
    module, _, attribute = path.partition(":")
    target = getattr(importlib.import_module(module), attribute)
    model = target() if isinstance(target, type) else target
    if not isinstance(model, Model):
        raise ParameterTypeError(f"model {name!r} ({path}) is not a shipblock.models.Model: "
                                 f"{type(model).__name__}")
    if model.name != name:
        raise ParameterError(f"model {name!r} ({path}) names itself {model.name!r}")
    return model


def get_model(name: str) -> Model:
    """The registered model called ``name`` (one registered by its path is loaded on the first
    call, and the same instance returned afterwards).

    Raises
    ------
    FieldError
        With ``field = "model"``, naming the registered models.
    """
    try:
        model = _REGISTRY[name]
    except (KeyError, TypeError):
        raise FieldError("model", f"unknown model {name!r}; registered models: "
                                  f"{', '.join(map(repr, _REGISTRY))}") from None
    if isinstance(model, Model):
        return model
    with _LOADING:
        model = _REGISTRY[name]
        if isinstance(model, str):
            model = _REGISTRY[name] = _load(name, model)
    return model
