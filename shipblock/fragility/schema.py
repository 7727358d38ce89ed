r"""Pipeline files read and validated: :func:`load_pipeline`, :func:`parse_pipeline`.

A pipeline file (TOML, ``schema_version = 1``; units in brackets, paths relative to the file)
names the records (a catalogue and record ids), the processing chain, the component, the model
and its parameters, the parameters swept, the analysis design (IDA, MSA or cloud; scaling IM
and levels), the limit states, the fit and solver options and the output file::

    schema_version = 1
    output = "results/demo.nc"

    [records]
    ids = "all"                         # or a list of catalogue ids
    horizontal = "H1"                   # or azimuth = <dock transverse axis> [deg]

    [system]                            # model = "rigid" (default): ShipBlockSystem fields
    ship_mass = 5.0e6                   # [kg]; slenderness = B/H may replace half_width,
    ...                                 # mass_ratio = n m / M block_mass

    [sweep]                             # optional; one dimension per parameter
    mu_ground = [0.3, 0.4, 0.5]

    [design]
    type = "ida"                        # "ida", "msa" or "cloud"
    levels_g = [0.1, 0.2, 0.4]          # or levels = [...] with units = "m/s^2"

    [[limit_states]]                    # see shipblock.fragility.limit_states
    name = "block_slip"
    edp = "peak_block_slip"
    threshold = 0.02                    # [m]

Every key, with its type, unit, range, default and meaning, is declared once in
:mod:`shipblock.fragility.keys` (the ``[system]`` and ``[solver]`` keys by the model); the
user guide's table of keys is generated from those declarations. A selector of ``[histories]
runs`` names a record (catalogue id or its last part) and optionally ``im_level`` [SI] or
``im_level_g`` [g] and values of swept parameters; what it leaves out, it takes all of
(:mod:`shipblock.fragility.histories`).

Every value is checked when the file is loaded, with the key named (:class:`PipelineError`
carries it in :attr:`~PipelineError.key`): types, choices and ranges from the declarations,
and the relations between keys here (``levels`` or ``levels_g``, ``azimuth`` or
``horizontal``, stripes against the records...). IM levels are converted to SI once, here:
``levels_g`` multiplies by :data:`shipblock.units.STANDARD_GRAVITY`; ``levels`` with ``units``
goes through :func:`shipblock.units.acceleration_to_si` (:func:`shipblock.units.velocity_to_si`
for PGV).
"""

from __future__ import annotations

import logging
import math
import os
import tomllib
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import xarray as xr

from shipblock import checks
from shipblock.errors import ParameterTypeError, ShipblockError, TomlNestingError
from shipblock.fragility.design import (
    IM_LEVEL_RANGE,
    IM_MEASURES,
    AnalysisDesign,
    IntensityDesign,
)
from shipblock.fragility.histories import SelectionError, select_cases
from shipblock.fragility.keys import (
    DEFAULT_MAX_SCALE_FACTOR,
    MAX_RUNS,
    MODEL_KEY,
    SCHEMA_VERSION,
    PipelineError,
    check_table,
    value,
)
from shipblock.fragility.limit_states import LimitState, parse_limit_states
from shipblock.models import DEFAULT_MODEL, FieldError, Model, get_model
from shipblock.units import STANDARD_GRAVITY, acceleration_to_si, velocity_to_si

__all__ = ["HistoryRequest", "Pipeline", "PipelineError", "load_pipeline", "load_solver",
           "load_system", "parse_pipeline"]

logger = logging.getLogger(__name__)

_NUM = (int, float)


# --------------------------------------------------------------------------------------------
# parsed pipeline
# --------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class HistoryRequest:
    """The ``[histories]`` table of a pipeline: which runs get full time histories.

    Attributes
    ----------
    cases : tuple of int
        Case numbers picked by the ``runs`` selectors, in the order given.
    exceeding : tuple of str
        Limit states whose exceeding runs are added after them.
    max_runs : int
        Largest number of histories written.
    directory : pathlib.Path or None
        Output folder; None for ``<output stem>_histories/`` beside the output file.
    """

    cases: tuple[int, ...]
    exceeding: tuple[str, ...]
    max_runs: int
    directory: Path | None

    def select(self, ds: xr.Dataset, design: AnalysisDesign) -> list[int]:
        """Case numbers to write: the selected ones, then the exceeding ones, capped.

        Parameters
        ----------
        ds : xarray.Dataset
            Summaries with ``exceeded`` and ``valid``
            (:func:`~shipblock.fragility.fit_step.fragility_variables`).
        design : AnalysisDesign

        Returns
        -------
        list of int
        """
        chosen = dict.fromkeys(self.cases)
        for name in self.exceeding:
            hit = (ds["exceeded"].sel(limit_state=name) & ds["valid"].sel(limit_state=name))
            chosen.update(dict.fromkeys(np.flatnonzero(
                hit.transpose(*design.dims).values.ravel()).tolist()))
        cases = list(chosen)
        if len(cases) > self.max_runs:
            logger.warning(
                "%d runs selected for time histories; writing the first histories.max_runs = "
                "%d", len(cases), self.max_runs)
        return cases[: self.max_runs]


@dataclass(frozen=True)
class Pipeline:
    """A parsed, validated pipeline file.

    Attributes
    ----------
    source : str
        The file (or ``"<pipeline>"``).
    text : str
        The TOML text, verbatim (stored in the result's attributes).
    document : dict
        The parsed TOML.
    catalogue : pathlib.Path or None
        Catalogue file; None for the shipped one.
    azimuth : float or None
        Dock transverse axis [deg clockwise from north].
    horizontal : str or None
        ``"H1"``/``"H2"`` when no azimuth is given.
    response : str
        ``"sensitivity"`` or ``"full"``.
    chain : list of dict or None
        Processing chain; None for the default chain.
    design : AnalysisDesign
        Records x levels x sweep, and the model (:attr:`AnalysisDesign.model`).
    limit_states : tuple of LimitState
    fit : dict
        ``bootstrap``, ``confidence``, ``seed``, ``ida_method``, ``cloud_method``.
    solver : dict
        The model's solver options (rigid model: ``rtol``, ``atol``, ``zeno_omega``).
    chunk_size : int
    scheduler : str or None
    output : pathlib.Path
        Output file (absolute).
    histories : HistoryRequest or None
        Runs whose full time histories are written; None for none.
    max_scale_factor : float
        Largest scale factor [-] a run is made with silently (``design.max_scale_factor``).
    scale_factor_policy : str
        ``"warn"`` (run and report) or ``"refuse"`` (do not make) a run scaled by more.
    strict : bool
        Fail, rather than go on without them, when records are left out or runs refused
        (``records.strict``).
    im_display : tuple of (str, float)
        The unit the pipeline gives its IM levels in (``"g"`` for ``levels_g``, else
        ``design.units``) and its value in SI units: the unit of the messages, of the
        command's output and of the result's ``*_g`` companions.
    target_spectrum : dict or None
        ``[design.target_spectrum]``: ``spectrum`` (:class:`~shipblock.scaling.TargetSpectrum`),
        ``file``, ``units``, ``period_range`` [s], ``match``; None without one.
    """

    source: str
    text: str
    document: dict
    catalogue: Path | None
    azimuth: float | None
    horizontal: str | None
    response: str
    chain: list | None
    design: AnalysisDesign
    limit_states: tuple[LimitState, ...]
    fit: dict
    solver: dict
    chunk_size: int
    scheduler: str | None
    output: Path
    histories: HistoryRequest | None = None
    max_scale_factor: float = DEFAULT_MAX_SCALE_FACTOR
    scale_factor_policy: str = "warn"
    strict: bool = False
    im_display: tuple[str, float] = ("m/s^2", 1.0)
    target_spectrum: dict | None = None

    @property
    def model(self) -> Model:
        """shipblock.models.Model: The model of the study (``[system] model``)."""
        return self.design.model

    def identity(self) -> dict:
        """The parts of the document that determine the results (no output path, scheduler
        or history request).

        Returns
        -------
        dict
        """
        doc = {k: v for k, v in self.document.items()
               if k not in ("output", "title", "description", "histories")}
        doc["execution"] = {"chunk_size": self.chunk_size}
        doc["records"] = {**{k: v for k, v in doc["records"].items() if k != "strict"},
                          "catalogue": str(self.catalogue), "ids": list(self.design.records)}
        return doc


def load_system(path) -> tuple[Model, object]:
    """``(model, system)`` of a file's ``[system]`` table, read as a pipeline's (its keys,
    units and checks; ``model = "section"`` chooses the dock section), for a single run
    (``shipblock simulate --system FILE``). Raises :class:`PipelineError` naming the file and
    the key (``system.<key>``): unreadable, no ``[system]`` table, an invalid key or system."""
    source = str(checks.pathname(path, "path", "a system TOML file"))
    table = checks.toml_file(source, "system file", error=_file_error).get("system")
    if not isinstance(table, Mapping):
        raise PipelineError("system", "missing: the file needs a [system] table", source)
    model = _model(table, source)
    check_table(table, "system", source, model)
    return model, _system(table, model, source)


def load_solver(path, model: Model) -> dict:
    """The solver options a file's ``[solver]`` table gives, read as a pipeline's (its keys,
    units and ``model``'s checks), for a single run (``shipblock simulate --system FILE``): only
    the options the table names; ``{}`` without a table. Raises :class:`PipelineError` naming
    the file and the key (``solver.<key>``)."""
    source = str(checks.pathname(path, "path", "a system TOML file"))
    table = checks.toml_file(source, "system file", error=_file_error).get("solver", {})
    if not isinstance(table, Mapping):
        raise PipelineError("solver", f"must be a table, got {type(table).__name__}", source)
    check_table(table, "solver", source, model)
    options = _solver(table, model, source)
    return {key: options[key] for key in table}


def load_pipeline(path) -> Pipeline:
    """Read and validate a pipeline file.

    Parameters
    ----------
    path : str or os.PathLike
        The TOML file.

    Returns
    -------
    Pipeline

    Raises
    ------
    ParameterTypeError
        If ``path`` is not a path.
    PipelineError
        If the file is missing, not a TOML text file, or invalid; the message names the file
        and the key.
    """
    if not isinstance(path, str | os.PathLike):
        raise ParameterTypeError(f"path must be the pipeline file (a str or os.PathLike), got "
                                 f"{type(path).__name__} {path!r}")
    path = Path(path)
    text = checks.toml_text(path, "pipeline file", error=_file_error)
    return parse_pipeline(text, base=path.resolve().parent, source=str(path))


def _file_error(path: str, problem: str) -> PipelineError:
    """The error of a pipeline or system file that cannot be read as TOML (for
    :func:`shipblock.checks.toml_file`)."""
    return PipelineError("", problem, path)


def parse_pipeline(text: str, base=".", source: str = "<pipeline>") -> Pipeline:
    """Parse and validate pipeline TOML text.

    Parameters
    ----------
    text : str
        The TOML document.
    base : str or os.PathLike
        Directory that relative paths (catalogue, output) are relative to.
    source : str
        Name used in error messages.

    Returns
    -------
    Pipeline

    Raises
    ------
    ParameterTypeError
        Naming the argument, if ``text`` is not a ``str`` (``None``, bytes, a path: use
        :func:`load_pipeline` for a file), ``base`` not a path or ``source`` not a string.
    PipelineError
        Naming the key: unknown key, wrong type, missing section or key, invalid value,
        unknown record id, invalid system, limit state or design; a name (limit state,
        record id) or file name with a control character; nesting deeper than
        :data:`shipblock.checks.MAX_TOML_DEPTH` levels.
    """
    source = checks.text(source, "source", what="a name for the pipeline in messages")
    if not isinstance(text, str):
        raise ParameterTypeError(f"text must be the pipeline's TOML text (a str; "
                                 f"load_pipeline reads a file), got {type(text).__name__} "
                                 f"{text!r:.80}")
    base = Path(checks.pathname(base, "base", "the folder of the pipeline's relative paths"))
    try:
        doc = checks.toml_document(text)
    except TomlNestingError as exc:
        raise PipelineError("", exc.problem, source) from None
    except tomllib.TOMLDecodeError as exc:
        raise PipelineError("", f"is not valid TOML: {exc}", source) from exc
    check_table(doc, "", source)
    version = doc.get("schema_version", SCHEMA_VERSION)
    if version != SCHEMA_VERSION:
        raise PipelineError("schema_version", f"must be {SCHEMA_VERSION}, got {version}", source)
    model = _model(doc["system"], source)
    for section in ("records", "system", "sweep", "design", "fit", "solver", "execution",
                    "histories"):
        if section in doc:
            check_table(doc[section], section, source, model)

    ids, catalogue, azimuth, horizontal, response = _records(doc["records"], base, source)
    chain = _processing(doc, source)
    system = _system(doc["system"], model, source)
    sweep = _sweep(doc.get("sweep", {}), model, source)
    design, cloud_method = _design(doc["design"], ids, system, sweep, model, source)
    limit_states = _limit_states(doc["limit_states"], design, cloud_method, source)
    d = doc["design"]
    f = doc.get("fit", {})
    fit = {
        "bootstrap": value(f, "fit", "bootstrap", source),
        "confidence": value(f, "fit", "confidence", source),
        "seed": value(f, "fit", "seed", source),
        "ida_method": f.get("ida_method", "interval"),
        "cloud_method": cloud_method,
    }
    if fit["ida_method"] in ("mle", "moments"):
        old = "first_exceedance" + ("_moments" if fit["ida_method"] == "moments" else "")
        raise PipelineError("fit.ida_method", f"{fit['ida_method']!r} took the first exceeding "
                            f"level as the capacity; that estimate is now named {old!r} (it "
                            "overestimates the median by up to one level step); the default "
                            "'interval' fits the capacity between the last level that held and "
                            "the first that failed", source)
    value(f, "fit", "ida_method", source)
    solver = _solver(doc.get("solver", {}), model, source)
    ex = doc.get("execution", {})
    chunk_size = value(ex, "execution", "chunk_size", source)
    scheduler = ex.get("scheduler")
    if scheduler is not None and not scheduler.strip():
        raise PipelineError("execution.scheduler", "must be a Dask scheduler address such as "
                                                   "'tcp://host:8786', got an empty string", source)
    histories = None
    if "histories" in doc:
        histories = _parse_histories(doc["histories"], design, limit_states, base, source)
    return Pipeline(
        source=source, text=text, document=doc, catalogue=catalogue, azimuth=azimuth,
        horizontal=horizontal, response=response, chain=chain, design=design,
        limit_states=limit_states, fit=fit, solver=solver, chunk_size=int(chunk_size),
        scheduler=scheduler, output=output_path(doc["output"], base, source),
        histories=histories, **_scaling_limits(doc, source),
        im_display=_im_display(d, design.intensity.measure, source),
        target_spectrum=_target_spectrum(d, design.intensity, base, source),
    )


# --------------------------------------------------------------------------------------------
# sections
# --------------------------------------------------------------------------------------------


def _model(table: Mapping, source: str) -> Model:
    """The model named by ``[system] model`` (default ``"rigid"``)."""
    name = table.get("model", DEFAULT_MODEL)
    try:
        MODEL_KEY.check_type(name, "system.model")
        return get_model(name)
    except FieldError as exc:
        raise PipelineError("system.model", exc.problem, source) from None


def _records(rec: Mapping, base: Path, source: str):
    """``(ids, catalogue, azimuth, horizontal, response)`` of the ``[records]`` table."""
    from shipblock.records.catalogue import load_catalogue  # reads obspy lazily: start-up time

    catalogue = (base / _label(rec["catalogue"], "records.catalogue", "a file name", source,
                               printable=False)).resolve() if "catalogue" in rec else None
    try:
        entries = load_catalogue(catalogue)
    except ShipblockError as exc:
        raise PipelineError("records.catalogue", str(exc), source) from None
    ids = rec["ids"]
    if isinstance(ids, str):
        if ids != "all":
            raise PipelineError("records.ids", f"must be 'all' or a list of ids, got {ids!r}",
                                source)
        ids = list(entries)
    if not ids or not all(isinstance(i, str) for i in ids):
        raise PipelineError("records.ids", "must be a non-empty list of record ids (strings)",
                            source)
    for k, i in enumerate(ids):
        _label(i, f"records.ids[{k}]", "a record id", source)
    repeated = sorted({i for i in ids if ids.count(i) > 1})
    if repeated:
        raise PipelineError("records.ids", f"repeats {', '.join(repeated)}", source)
    missing = [i for i in ids if i not in entries]
    if missing:
        raise PipelineError("records.ids", f"not in the catalogue: {', '.join(missing)}; "
                                           f"known: {', '.join(entries)}", source)
    if "azimuth" in rec and "horizontal" in rec:
        raise PipelineError("records.horizontal", "give azimuth or horizontal, not both", source)
    horizontal = None if "azimuth" in rec else value(rec, "records", "horizontal", source)
    response = value(rec, "records", "response", source)
    azimuth = value(rec, "records", "azimuth", source)
    return ids, catalogue, azimuth, horizontal, response


def _processing(doc: Mapping, source: str):
    """The processing chain (None: the default chain)."""
    if "processing" not in doc:
        return None
    chain = doc["processing"]
    for k, entry in enumerate(chain):
        if not isinstance(entry, dict) or "step" not in entry:
            raise PipelineError(f"processing[{k}]", "must be a table with a 'step' key", source)
    _check_chain(chain, source)
    return chain


def _check_chain(chain, source):
    """Validate the processing chain on a tiny synthetic stream (step names and parameters)."""
    # obspy and the processing stack load lazily: loading a pipeline stays fast to start
    from obspy import Stream, Trace

    from shipblock.processing import STEPS, ProcessingError, apply_chain

    for k, entry in enumerate(chain):
        if entry["step"] not in STEPS:
            raise PipelineError(f"processing[{k}].step", f"unknown step {entry['step']!r}; "
                                                         f"known: {', '.join(sorted(STEPS))}",
                                source)
    tr = Trace(np.sin(np.linspace(0, 20, 4000)))
    tr.stats.delta = 0.005
    try:
        apply_chain(Stream([tr]), chain)
    except ProcessingError as exc:
        k = next((i for i, e in enumerate(chain) if e["step"] == exc.step), None)
        key = "processing" if k is None else f"processing[{k}]"
        if exc.parameter and k is not None:
            key += f".{exc.parameter}"
        raise PipelineError(key, str(exc), source) from None
    except Exception:  # noqa: BLE001 - data-dependent failures surface per record
        pass


def _system(table: Mapping, model: Model, source: str):
    """The model's system from ``[system]``: each value by its declaration, then the model's
    own checks (:meth:`Model.build <shipblock.models.base.Model.build>`)."""
    params = {k: v for k, v in table.items() if k != "model"}
    for key, given in list(params.items()):
        checked = value(params, "system", key, source, model)
        if isinstance(given, str) and not isinstance(checked, str):
            params[key] = checked  # a quantity with a unit ("5000 t"), in SI from here on
    try:
        return model.build(params)
    except FieldError as exc:
        raise PipelineError(f"system.{exc.field}" if exc.field else "system", exc.problem,
                            source) from None
    except (TypeError, ValueError) as exc:
        raise PipelineError("system", str(exc), source) from None


def _sweep(table: Mapping, model: Model, source: str) -> tuple:
    """``((name, values), ...)`` of ``[sweep]`` (names checked against the model's).

    Numbers, or strings for a parameter the model declares as a string (a choice such as the
    section model's ``cap_material``), each checked by that declaration.
    """
    sweep = []
    for name, values in table.items():
        if not values:
            raise PipelineError(f"sweep.{name}", "must be a non-empty list of values", source)
        declared = model.parameters.get(name)
        for v in values:
            if declared is not None and str in declared.types:
                if not isinstance(v, str):
                    raise PipelineError(f"sweep.{name}", f"must hold strings, got {v!r}",
                                        source)
                try:
                    declared.check(v)
                except FieldError as exc:
                    raise PipelineError(f"sweep.{name}", exc.problem, source) from None
            elif isinstance(v, bool) or not isinstance(v, _NUM):
                raise PipelineError(f"sweep.{name}", f"must hold numbers, got {v!r}", source)
        if len(set(values)) != len(values):
            raise PipelineError(f"sweep.{name}", f"sweep {name!r} repeats a value", source)
        sweep.append((name, tuple(values)))
    return tuple(sweep)


def _label(given: str, key: str, what: str, source: str, printable: bool = True) -> str:
    """``given`` (a name that becomes a label, coordinate or file name) checked by
    :func:`shipblock.checks.label`; with ``printable=False`` (the name of a file that exists)
    only a NUL, which no file name holds, is refused."""
    if not printable and "\x00" not in given:
        return given
    try:
        return checks.label(given, key, what=what)
    except ShipblockError as exc:
        raise PipelineError(key, str(exc), source) from None


def _numbers(values, key: str, source: str) -> tuple[float, ...]:
    if not isinstance(values, list) or not values:
        raise PipelineError(key, "must be a non-empty list of numbers", source)
    for v in values:
        if isinstance(v, bool) or not isinstance(v, _NUM) or not math.isfinite(v):
            raise PipelineError(key, f"must hold finite numbers only, got {v!r}", source)
    return tuple(float(v) for v in values)


def _im_factor(measure: str, units: str, key: str, source: str) -> float:
    """SI factor of a unit given for the IM ``measure``."""
    convert = velocity_to_si if measure == "pgv" else acceleration_to_si
    try:
        return float(convert(1.0, units))
    except ValueError as exc:
        raise PipelineError(key, f"{exc} (for {measure.upper()})", source) from None


def _in_range(levels, measure: str, key: str, source: str) -> tuple[float, ...]:
    """SI ``levels`` checked against :data:`~shipblock.fragility.design.IM_LEVEL_RANGE`."""
    low, high = IM_LEVEL_RANGE[measure]
    name = key.split(".")[-1]
    for i, level in enumerate(levels):
        if not low <= level <= high:
            if name.endswith("_g"):
                shown = f"{level / STANDARD_GRAVITY:g} g"
                accepted = f"{low / STANDARD_GRAVITY:g} .. {high / STANDARD_GRAVITY:g} g"
            else:
                units = IM_MEASURES[measure][0]
                shown, accepted = f"{level:g} {units}", f"{low:g} .. {high:g} {units}"
            raise PipelineError(key, f"{name}[{i}] = {shown} is outside the accepted range "
                                     f"{accepted} of {measure.upper()} levels", source)
    return levels


def _levels(design: Mapping, prefix: str, measure: str, source: str):
    """SI levels from ``<prefix>levels_g`` or ``<prefix>levels`` + ``units``."""
    kg, kl = f"{prefix}levels_g", f"{prefix}levels"
    if kg in design and kl in design:
        raise PipelineError(f"design.{kl}", f"give {kg!r} or {kl!r}, not both", source)
    if kg in design:
        if measure == "pgv":
            raise PipelineError(f"design.{kg}", "PGV levels are velocities: use levels = [...] "
                                                "with units = 'm/s' or 'cm/s'", source)
        si = tuple(v * STANDARD_GRAVITY for v in _numbers(design[kg], f"design.{kg}", source))
        return _in_range(si, measure, f"design.{kg}", source)
    if kl in design:
        if "units" not in design:
            raise PipelineError("design.units", f"{kl!r} needs units (e.g. 'm/s^2', 'g', 'm/s')",
                                source)
        f = _im_factor(measure, design["units"], "design.units", source)
        si = tuple(v * f for v in _numbers(design[kl], f"design.{kl}", source))
        return _in_range(si, measure, f"design.{kl}", source)
    return None


def _stripes(value_, ids, source) -> tuple[tuple[str, ...], ...]:
    """Per-level record lists, ids given in full or by their last part."""
    out = []
    for j, stripe in enumerate(value_):
        if not isinstance(stripe, list) or not all(isinstance(r, str) for r in stripe):
            raise PipelineError(f"design.stripes[{j}]", "must be a list of record ids", source)
        full = []
        for r in stripe:
            match = [i for i in ids if i == r] or [i for i in ids if i.split("/")[-1] == r]
            if len(match) != 1:
                raise PipelineError(f"design.stripes[{j}]", f"{r!r} is not one of the records "
                                    f"(records.ids): {', '.join(ids)}", source)
            full.append(match[0])
        out.append(tuple(full))
    return tuple(out)


def _design(d: Mapping, ids, system, sweep, model: Model, source: str):
    """The :class:`AnalysisDesign` of ``[design]`` and ``[sweep]``, and the cloud method."""
    kind = value(d, "design", "type", source)
    measure = value(d, "design", "measure", source)
    levels = _levels(d, "", measure, source)
    v_levels = _levels(d, "vertical_", measure, source)
    if "units" in d and "levels" not in d and "vertical_levels" not in d:
        raise PipelineError("design.units", "is only used with levels = [...]", source)
    intensity = IntensityDesign(
        kind=kind,
        measure=measure,
        levels=levels or (),
        period=value(d, "design", "period", source),
        damping=value(d, "design", "damping", source),
        vertical=value(d, "design", "vertical", source),
        vertical_levels=v_levels,
    )
    try:
        intensity.validate()
    except FieldError as exc:
        field = exc.field
        if field in ("levels", "vertical_levels") and f"{field}_g" in d:
            field += "_g"
        raise PipelineError(f"design.{field}", str(exc), source) from None
    cloud_method = value(d, "design", "cloud_method", source)
    if "cloud_method" in d and kind != "cloud":
        raise PipelineError("design.cloud_method", "applies only to type = 'cloud'", source)
    stripes = None
    if "stripes" in d:
        stripes = _stripes(d["stripes"], ids, source)
        try:
            AnalysisDesign(tuple(ids), intensity, system, (), stripes, model)._validate_stripes()
        except ValueError as exc:
            raise PipelineError("design.stripes", str(exc), source) from None
    design = AnalysisDesign(tuple(ids), intensity, system, sweep, stripes, model)
    if design.n_cases > MAX_RUNS:
        sizes = " x ".join(f"{n} {dim}" for n, dim in zip(design.shape, ("records", "levels",
                                                                          *design.sweep_names),
                                                          strict=True))
        raise PipelineError("sweep" if sweep else "design",
                            f"the study has {design.n_cases:,} runs ({sizes}), more than "
                            f"{MAX_RUNS:,}; split it into several pipelines", source)
    try:
        design.validate()
    except ValueError as exc:
        raise PipelineError(_swept_key(design), str(exc), source) from None
    return design, cloud_method


def _swept_key(design: AnalysisDesign) -> str:
    """The key of an invalid sweep: ``sweep.<name>`` if one parameter alone gives an invalid
    system (each value tried on the base system), else ``sweep``."""
    bad = []
    for name, values in design.sweep:
        for v in values:
            try:
                design.model.vary(design.system, {name: v})
            except ValueError:
                bad.append(name)
                break
    return f"sweep.{bad[0]}" if len(bad) == 1 else "sweep"


def _limit_states(entries, design: AnalysisDesign, cloud_method: str, source: str):
    """The limit states, on the model's EDPs."""
    model = design.model
    for i, entry in enumerate(entries):
        if isinstance(entry, Mapping) and "name" in entry:
            _label(entry["name"], f"limit_states[{i}].name", "a limit state name", source)
    try:
        limit_states = parse_limit_states(entries, model)
    except ValueError as exc:
        raise PipelineError("limit_states", str(exc), source) from None
    if not limit_states:
        raise PipelineError("limit_states", "define at least one [[limit_states]]", source)
    if design.intensity.kind == "cloud" and cloud_method == "regression":
        for ls in limit_states:
            if ls.condition not in ("greater", "greater_equal") or \
                    model.edps[ls.edp].kind != "float":
                raise PipelineError("limit_states", f"limit state {ls.name!r}: the cloud "
                                    "regression needs a threshold on a continuous EDP; use "
                                    "cloud_method = 'probit'", source)
    return limit_states


def _solver(table: Mapping, model: Model, source: str) -> dict:
    """The model's solver options: each by its declaration, then the model's own checks."""
    options = {key: value(table, "solver", key, source, model) for key in model.options}
    try:
        return model.check_options(options)
    except FieldError as exc:
        raise PipelineError(f"solver.{exc.field}" if exc.field else "solver", exc.problem,
                            source) from None


def _target_spectrum(design: Mapping, intensity: IntensityDesign, base: Path, source: str):
    """The ``[design.target_spectrum]`` table, read and checked (see ``Pipeline``)."""
    # the target's reader lives with the scaling stack (obspy), loaded only when needed
    from shipblock.scaling import TargetSpectrumError, read_target_spectrum

    if "target_spectrum" not in design:
        return None
    table = design["target_spectrum"]
    key = "design.target_spectrum"
    check_table(table, key, source)
    if intensity.kind not in ("ida", "msa") or intensity.measure != "sa":
        raise PipelineError(key, "scaling to a target spectrum needs type 'ida' or 'msa' on "
                            "measure = 'sa' (its period is T1, where the target is anchored to "
                            "the levels)", source)
    rng = _numbers(table["period_range"], f"{key}.period_range", source)
    if len(rng) != 2 or not 0 < rng[0] < rng[1]:
        raise PipelineError(f"{key}.period_range", f"must be [T_a, T_b] with 0 < T_a < T_b [s],"
                            f" got {table['period_range']!r}", source)
    match = value(table, key, "match", source)
    try:
        spectrum = read_target_spectrum(
            base / _label(table["file"], f"{key}.file", "a file name", source, printable=False),
            table["units"])
        spectrum.at([rng[0], rng[1], intensity.period])
    except TargetSpectrumError as exc:
        raise PipelineError(f"{key}.file", str(exc), source) from None
    return {"spectrum": spectrum, "file": str(base / table["file"]), "units": table["units"],
            "period_range": rng, "match": match}


def _im_display(design: Mapping, measure: str, source: str) -> tuple[str, float]:
    """The unit the pipeline writes its IM in and its SI value (see ``Pipeline.im_display``)."""
    if "levels_g" in design or ("units" not in design and measure != "pgv"):
        return "g", STANDARD_GRAVITY
    if "units" in design:
        return design["units"], _im_factor(measure, design["units"], "design.units", source)
    return "m/s", 1.0


def _scaling_limits(doc, source) -> dict:
    """``max_scale_factor``, ``scale_factor_policy`` ([design]) and ``strict`` ([records])."""
    d = doc["design"]
    return {"max_scale_factor": value(d, "design", "max_scale_factor", source),
            "scale_factor_policy": value(d, "design", "scale_factor_policy", source),
            "strict": bool(value(doc["records"], "records", "strict", source))}


def output_path(given: str, base: Path, source: str, key: str = "output") -> Path:
    """The output file, absolute: a file name (not empty, not a folder).

    Raises
    ------
    PipelineError
        Naming ``key``.
    """
    if not given.strip() or given.endswith(("/", "\\")) or Path(given).name in ("", ".", ".."):
        raise PipelineError(key, f"must name a NetCDF file such as 'results/study.nc', got "
                                 f"{given!r}", source)
    _label(given, key, "a file name", source)
    path = (base / given).resolve()
    if path.is_dir():
        raise PipelineError(key, f"{path} is a folder; name a NetCDF file in it", source)
    return path


def _parse_histories(table, design, limit_states, base, source) -> HistoryRequest:
    cases: list[int] = []
    for i, selector in enumerate(table.get("runs", [])):
        if not isinstance(selector, dict):
            raise PipelineError(f"histories.runs[{i}]", "must be a table such as "
                                "{record = 'NP.1765', im_level_g = 0.8}", source)
        try:
            cases.extend(select_cases(design, selector).tolist())
        except SelectionError as exc:
            raise PipelineError(f"histories.runs[{i}].{exc.key}", exc.problem, source) from None
    names = [ls.name for ls in limit_states]
    exceeding = table.get("exceeding", [])
    for name in exceeding:
        if name not in names:
            raise PipelineError("histories.exceeding", f"no limit state named {name!r}; "
                                f"limit states: {', '.join(names)}", source)
    if not cases and not exceeding:
        raise PipelineError("histories", "select runs with 'runs' and/or 'exceeding'", source)
    max_runs = value(table, "histories", "max_runs", source)
    directory = ((base / _label(table["directory"], "histories.directory", "a folder name",
                                source)).resolve() if "directory" in table else None)
    return HistoryRequest(tuple(dict.fromkeys(cases)), tuple(exceeding), int(max_runs),
                          directory)
