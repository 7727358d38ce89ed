r"""Limit states: named thresholds on the engineering demand parameters (EDPs) of a run.

A limit state (LS) turns the per-run summary of a simulation into a yes/no outcome, for example
"the ship slipped more than 5 cm on the blocks" or "a keel block carried more than its
capacity" (``edp = "peak_ground_normal_force"``, or ``"peak_corner_load"`` for the load on a
rocking block's edge: the contact loads of :mod:`shipblock.interface_forces`, per block [N]). Counting
these outcomes over records and IM levels gives the data that :mod:`shipblock.fragility.fit`
turns into fragility curves.

Limit states are declared in the pipeline TOML file::

    [[limit_states]]
    name = "ship_slip"
    edp = "peak_ship_slip"
    threshold = 0.05        # [m]; exceeded when edp > threshold
    [[limit_states]]
    name = "any_failure"
    edp = "failure"
    condition = "nonzero"

and read with :func:`parse_limit_states`. :func:`exceedance` evaluates one limit state on a
summary (a mapping of numpy arrays, or an :class:`xarray.Dataset`), with two rules:

* **Collapse exceeds every response limit state.** A run that ended in separation of the ship
  from the blocks or in overturning of a block (``failure != 0``) is counted as exceeding every
  limit state defined on a response EDP (everything except ``failure`` itself). The system has
  collapsed, which is beyond any deformation or rocking level; moreover the solver stops at the
  failure event, so the peak and residual EDPs of such a run are truncated and would otherwise
  be read as a *small* response.
* **Errored runs are missing.** A run whose EDP (or ``failure`` code) is NaN did not produce a
  result: it is neither exceeded nor not exceeded. :func:`exceedance` returns a ``valid`` mask
  and such runs must be left out of the counts (not counted as survivors).
"""

from __future__ import annotations

import math
import numbers
from collections.abc import Mapping, Sequence
from dataclasses import asdict, dataclass
from types import MappingProxyType
from typing import Any, NamedTuple

import numpy as np

from shipblock import checks
from shipblock.errors import ParameterError
from shipblock.models import DEFAULT_MODEL, Model, get_model
from shipblock.models.base import EDPInfo  # noqa: F401  (importable from here as before)
from shipblock.models.rigid import EDP_VARIABLES, FAILURE_CODES

__all__ = [
    "CONDITIONS",
    "EDP_VARIABLES",
    "FAILURE_CODES",
    "Exceedance",
    "LimitState",
    "evaluate_limit_states",
    "exceedance",
    "parse_limit_states",
]

#: Largest threshold accepted per EDP unit: beyond it no run can exceed the limit state, so the
#: number is a typo or a unit mistake (a slip of 1 km, a rotation beyond half a turn, a load of a
#: million tonnes on one block, a ratio or count of a billion).
_LARGEST_THRESHOLD: Mapping[str, float] = MappingProxyType(
    {"m": 1e3, "rad": math.pi, "N": 1e10, "1": 1e9})


#: Conditions a limit state may use, with the EDP kinds each applies to.
CONDITIONS: Mapping[str, tuple[str, ...]] = MappingProxyType(
    {
        "greater": ("float", "count"),  # |edp| > threshold
        "greater_equal": ("float", "count"),  # |edp| >= threshold
        "equal": ("count", "code"),  # edp == threshold
        "nonzero": ("count", "bool", "code"),  # edp != 0
    }
)

_NEEDS_THRESHOLD = frozenset({"greater", "greater_equal", "equal"})
_KEYS = ("name", "edp", "threshold", "condition", "description")


@dataclass(frozen=True)
class LimitState:
    """A named threshold on one EDP of a run summary.

    Construction does no checking (config objects hold no logic in ``__init__``); call
    :meth:`validate`, as :func:`parse_limit_states` and :func:`exceedance` do.

    Attributes
    ----------
    name : str
        Unique identifier, e.g. ``"ship_slip"``.
    edp : str
        Summary variable, a key of :data:`EDP_VARIABLES`.
    threshold : float or None
        Threshold in the units of the EDP (e.g. [m] for ``peak_ship_slip``); ``None`` for
        ``condition="nonzero"``.
    condition : str
        One of :data:`CONDITIONS`: ``"greater"`` (exceeded when ``edp > threshold``, the
        default), ``"greater_equal"``, ``"equal"`` (e.g. ``failure == 2``: overturning) or
        ``"nonzero"``. Residual slips are compared by absolute value.
    description : str
        Free text, optional.
    """

    name: str
    edp: str
    threshold: float | None = None
    condition: str = "greater"
    description: str = ""

    def validate(self, model: Model | None = None) -> LimitState:
        """Check the definition and return it unchanged.

        Parameters
        ----------
        model : shipblock.models.Model, optional
            The model whose EDPs (:attr:`~shipblock.models.base.Model.edps`) and failure codes the
            limit state refers to (default: the rigid model, :data:`EDP_VARIABLES`).

        Returns
        -------
        LimitState
            ``self``.

        Raises
        ------
        ValueError
            Naming the limit state and the offending field: empty name or one with a control or
            other non-printable character (:func:`shipblock.checks.label`), unknown EDP, unknown
            condition or one that does not apply to the EDP, missing, superfluous, non-numeric,
            non-finite or negative threshold, or a failure code that does not exist.
        """
        model = _model(model)
        edps = model.edps
        who = f"limit state {self.name!r}"
        checks.label(self.name, "limit state name", what="a non-empty string")
        if self.edp not in edps:
            hint = (
                " (failure_time is not an EDP; use edp = 'failure')"
                if self.edp == "failure_time"
                else ""
            )
            raise ParameterError(
                f"{who}: unknown edp {self.edp!r}{hint}; known EDPs: {', '.join(edps)}"
            )
        if self.condition not in CONDITIONS:
            raise ParameterError(
                f"{who}: unknown condition {self.condition!r}; use one of {', '.join(CONDITIONS)}"
            )
        info = edps[self.edp]
        if info.kind not in CONDITIONS[self.condition]:
            usable = [c for c, kinds in CONDITIONS.items() if info.kind in kinds]
            raise ParameterError(
                f"{who}: condition {self.condition!r} does not apply to {info.kind} EDP "
                f"{self.edp!r}; use one of {', '.join(usable)}"
            )
        if self.condition not in _NEEDS_THRESHOLD:
            if self.threshold is not None:
                raise ParameterError(
                    f"{who}: threshold is not used with condition {self.condition!r}; remove it"
                )
            return self
        t = self.threshold
        if t is None:
            raise ParameterError(f"{who}: missing threshold (condition {self.condition!r})")
        if isinstance(t, bool) or not isinstance(t, numbers.Real) or not math.isfinite(t):
            raise ParameterError(f"{who}: threshold must be a finite number, got {t!r}")
        if info.kind == "code":
            if t not in model.failure_codes or t == 0:
                codes = " or ".join(f"{c} ({what})" for c, what in model.failure_codes.items()
                                    if c)
                raise ParameterError(f"{who}: threshold {t!r} is not a failure code; use {codes}")
        elif t < 0:
            raise ParameterError(
                f"{who}: threshold {t!r} [{info.units}] is negative but {self.edp!r} is compared "
                "as a non-negative magnitude"
            )
        elif t > _LARGEST_THRESHOLD.get(info.units, math.inf):
            raise ParameterError(
                f"{who}: threshold {t!r} [{info.units}] is beyond any value {self.edp!r} can take "
                f"(at most {_LARGEST_THRESHOLD[info.units]:g} {info.units}); a unit mistake?"
            )
        return self

    def to_dict(self) -> dict[str, Any]:
        """Return the TOML-ready dictionary (``None`` and empty fields left out)."""
        return {k: v for k, v in asdict(self).items() if v is not None and v != ""}


def parse_limit_states(entries: Sequence[Mapping[str, Any]],
                       model: Model | None = None) -> tuple[LimitState, ...]:
    """Build validated limit states from the ``[[limit_states]]`` tables of a pipeline file.

    Parameters
    ----------
    entries : sequence of mappings
        For example ``tomllib.load(f)["limit_states"]``. Keys: ``name`` and ``edp``
        (required), ``threshold``, ``condition`` (default ``"greater"``), ``description``.
    model : shipblock.models.Model, optional
        Whose EDPs the limit states use (default: the rigid model).

    Returns
    -------
    tuple of LimitState
        In the order given.

    Raises
    ------
    ValueError
        With the index and name of the offending entry: not a table, unknown key, missing
        ``name``/``edp``, duplicate name, or any check of :meth:`LimitState.validate`.
    """
    if isinstance(entries, (str, bytes, Mapping)) or not isinstance(entries, Sequence):
        raise ParameterError(
            "limit_states must be a list of tables ([[limit_states]] in TOML), got "
            f"{type(entries).__name__}"
        )
    out: list[LimitState] = []
    seen: dict[str, int] = {}
    for i, entry in enumerate(entries):
        where = f"limit_states[{i}]"
        if not isinstance(entry, Mapping):
            raise ParameterError(f"{where}: expected a table, got {type(entry).__name__}")
        if "name" in entry:
            where += f" ({entry['name']!r})"
        unknown = sorted(set(entry) - set(_KEYS))
        if unknown:
            raise ParameterError(
                f"{where}: unknown key(s) {', '.join(map(repr, unknown))}; allowed keys: "
                f"{', '.join(_KEYS)}"
            )
        for key in ("name", "edp"):
            if key not in entry:
                raise ParameterError(f"{where}: missing required key {key!r}")
        ls = LimitState(
            name=entry["name"],
            edp=entry["edp"],
            threshold=entry.get("threshold"),
            condition=entry.get("condition", "greater"),
            description=entry.get("description", ""),
        )
        try:
            ls.validate(model)
        except ValueError as err:
            raise ParameterError(f"{where}: {err}") from None
        if ls.name in seen:
            raise ParameterError(
                f"{where}: duplicate limit state name {ls.name!r} (first defined in "
                f"limit_states[{seen[ls.name]}])"
            )
        seen[ls.name] = i
        out.append(ls)
    return tuple(out)


class Exceedance(NamedTuple):
    """Outcome of one limit state over a set of runs.

    Attributes
    ----------
    exceeded : numpy.ndarray or xarray.DataArray of bool
        Whether each run exceeded the limit state (``False`` where not ``valid``).
    valid : numpy.ndarray or xarray.DataArray of bool
        Whether the run produced a usable result (``False`` for errored runs, whose EDP or
        failure code is NaN). Count only valid runs.
    """

    exceeded: Any
    valid: Any


def _get(summary, key, ls_name):
    try:
        value = summary[key]
    except KeyError:
        raise KeyError(
            f"limit state {ls_name!r} needs summary variable {key!r}, which is missing"
        ) from None
    return value if hasattr(value, "dims") else np.asarray(value)


def exceedance(limit_state: LimitState, summary, model: Model | None = None) -> Exceedance:
    r"""Evaluate a limit state on per-run summary variables.

    .. math::

        e = \begin{cases}
            \text{undefined (invalid)} & \text{EDP or failure code is NaN} \\
            \text{true} & \text{failure} \ne 0 \text{ and the EDP is a response quantity} \\
            \lvert \mathrm{EDP} \rvert > t & \text{condition ``greater''}, \dots
        \end{cases}

    Parameters
    ----------
    limit_state : LimitState
        The limit state (validated here).
    summary : Mapping[str, array_like] or xarray.Dataset
        Per-run summary variables (see :data:`EDP_VARIABLES`), all of the same shape (or, for
        xarray, broadcastable dims). Must contain ``limit_state.edp`` and, for response EDPs,
        ``failure``.
    model : shipblock.models.Model, optional
        Whose EDPs the summary holds (default: the rigid model).

    Returns
    -------
    Exceedance
        ``exceeded`` and ``valid`` boolean arrays with the shape of the EDP (DataArrays with
        its dims and coords for xarray input). ``exceeded`` is ``False`` wherever ``valid`` is
        ``False``.

    Raises
    ------
    KeyError
        If a needed summary variable is missing. ``failure`` is required for response EDPs
        because, without it, collapsed runs (whose EDPs stop at the failure time) would be
        silently counted as small responses.
    ValueError
        If the limit state is invalid or numpy arrays differ in shape.

    Notes
    -----
    A run with ``failure != 0`` (separation or overturning) exceeds every response limit state
    even if its EDP is NaN: the collapse is known, and it is beyond any deformation level. For
    ``edp = "failure"`` the condition is applied to the code itself (so ``equal 2`` is exceeded
    only by overturning).
    """
    model = _model(model)
    ls = limit_state.validate(model)
    info = model.edps[ls.edp]
    value = _get(summary, ls.edp, ls.name)
    missing = value != value  # NaN test that also works on int/bool arrays and DataArrays
    v = abs(value) if info.magnitude else value
    if ls.condition == "greater":
        raw = v > ls.threshold
    elif ls.condition == "greater_equal":
        raw = v >= ls.threshold
    elif ls.condition == "equal":
        raw = v == ls.threshold
    else:  # nonzero
        raw = (v != 0) & ~missing
    if info.response:
        failure = _get(summary, "failure", ls.name)
        if not hasattr(value, "dims") and np.shape(failure) != np.shape(value):
            raise ParameterError(
                f"summary variables {ls.edp!r} {np.shape(value)} and 'failure' "
                f"{np.shape(failure)} differ in shape"
            )
        failure_missing = failure != failure
        collapsed = (failure != 0) & ~failure_missing
        valid = (~missing | collapsed) & ~failure_missing
        exceeded = (raw | collapsed) & valid
    else:
        valid = ~missing
        exceeded = raw & valid
    if hasattr(exceeded, "attrs"):
        exceeded = exceeded.rename(ls.name)
        exceeded.attrs = {
            "long_name": f"exceedance of limit state {ls.name}",
            **{f"limit_state_{k}": v for k, v in ls.to_dict().items() if k != "name"},
        }
        valid = valid.rename(f"{ls.name}_valid")
        valid.attrs = {"long_name": f"run usable for limit state {ls.name}"}
    return Exceedance(exceeded=exceeded, valid=valid)


def evaluate_limit_states(limit_states, summary,
                          model: Model | None = None) -> dict[str, Exceedance]:
    """Evaluate several limit states on the same summary.

    Parameters
    ----------
    limit_states : iterable of LimitState
        E.g. the output of :func:`parse_limit_states`.
    summary : Mapping[str, array_like] or xarray.Dataset
        Per-run summary variables, see :func:`exceedance`.
    model : shipblock.models.Model, optional
        Whose EDPs the summary holds (default: the rigid model).

    Returns
    -------
    dict[str, Exceedance]
        Keyed by limit state name, in input order.
    """
    return {ls.name: exceedance(ls, summary, model) for ls in limit_states}


def _model(model: Model | None) -> Model:
    return get_model(DEFAULT_MODEL) if model is None else model
