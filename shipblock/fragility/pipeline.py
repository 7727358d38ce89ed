r"""Pipelines: a TOML file that fully reproduces a fragility study, and :func:`run_pipeline`.

A pipeline file names the records (a catalogue and record ids), the processing chain, the
component, the ship-block system and the parameters swept, the analysis design (IDA, MSA or
cloud; scaling IM and levels), the limit states, the fit and solver options and the output
file. :func:`load_pipeline` parses and validates it (every error names the offending key) and
:func:`run_pipeline` runs it end to end: records read and processed once, all runs in chunks
(locally or on Dask), exceedance of every limit state, lognormal fragility fits with bootstrap
bounds over records, and one NetCDF file.

Schema (``schema_version = 1``; units in brackets, paths relative to the pipeline file)::

    schema_version = 1
    title = "..."                       # optional
    output = "results/demo.nc"          # required

    [records]
    catalogue = "../records/catalogue.toml"   # optional; default: the shipped catalogue
    ids = "all"                         # or a list of catalogue ids
    azimuth = 0.0                       # dock transverse axis [deg from north], or
    horizontal = "H1"                   # one horizontal as recorded (default "H1")
    response = "sensitivity"            # or "full" (instrument response removal)
    strict = false                      # true: fail if a record is left out or a run refused

    [[processing]]                      # optional; absent: shipblock.processing.DEFAULT_CHAIN
    step = "demean"                     # processing = [] for no processing

    [system]                            # ShipBlockSystem fields [SI]; slenderness = B/H may
    ship_mass = 5.0e6                   # replace half_width, mass_ratio = n m / M block_mass
    ...

    [sweep]                             # optional; one dimension per parameter
    mu_ground = [0.3, 0.4, 0.5]
    slenderness = [0.4, 0.5, 0.6]

    [design]
    type = "ida"                        # "ida", "msa" or "cloud"
    measure = "pga"                     # "pga" (default), "pgv" or "sa" (then period [s])
    levels_g = [0.1, 0.2, 0.4]          # or levels = [...] with units = "m/s^2" ("m/s" for PGV)
    vertical = "same"                   # "same", "independent" (+ vertical_levels[_g]),
                                        # "unscaled" or "zero"
    stripes = [["NP.1737", "NP.1743"], ["NP.1759", "NP.1765"], ...]
                                        # msa only, optional: the records of each level
    max_scale_factor = 5.0              # warn about runs scaled by more (default 5) [-]
    scale_factor_policy = "warn"        # or "refuse": runs scaled by more are not made

    [design.target_spectrum]            # optional, ida/msa on measure "sa" (T1 = period)
    file = "target.csv"                 # two columns: period [s], Sa [units]
    units = "g"                         # unit of the Sa column (required)
    period_range = [0.2, 2.0]           # [T_a, T_b] [s]
    match = "range"                     # least squares in ln Sa over the range (default), or
                                        # "anchor": Sa(T1) matched, misfit over the range
    cloud_method = "probit"             # cloud only: "probit" or "regression"

    [[limit_states]]                    # see shipblock.fragility.limit_states
    name = "block_slip"
    edp = "peak_block_slip"
    threshold = 0.02                    # [m]

    [fit]
    bootstrap = 200                     # resamples over records (0: no bounds)
    confidence = 0.9
    seed = 1
    ida_method = "interval"             # capacity between the last level held and the first
                                        # failed (default); or "first_exceedance" (the first
                                        # failed level, biased high), "first_exceedance_moments"

    [solver]
    rtol = 1e-8
    atol = 1e-10
    zeno_omega = 1e-7                   # [rad/s]

    [execution]
    chunk_size = 1024                   # cases per chunk (part of the run's identity)
    scheduler = "tcp://host:8786"       # optional Dask scheduler

    [histories]                         # optional: full time histories of some runs
    runs = [{record = "NP.1765", im_level_g = 0.8}]   # selectors (see below)
    exceeding = ["ship_slip"]           # and every run exceeding one of these limit states
    max_runs = 100                      # at most this many files (selectors first)
    directory = "results/demo_histories"  # default: <output stem>_histories/ beside the output

A selector names a record (catalogue id or its last part) and optionally ``im_level`` [SI] or
``im_level_g`` [g] and values of swept parameters; what it leaves out, it takes all of
(:mod:`shipblock.fragility.histories`). The histories are computed after the batch by
:func:`shipblock.simulate` on the batch's own input, one NetCDF file per run, and are listed in
the result's ``history_file`` variable.

Every value is checked when the file is loaded, with the key named: types, choices and the
ranges of the module constants (:data:`MAX_BOOTSTRAP`, :data:`MAX_SEED`, :data:`MAX_CHUNK_SIZE`,
:data:`MAX_HISTORIES`, :data:`MAX_RUNS`), of
:data:`~shipblock.fragility.design.IM_LEVEL_RANGE` for the levels, of
:data:`shipblock.system.FIELD_LIMITS` for the system and the sweep, and of
:func:`shipblock.simulate` for the solver options.

IM levels are converted to SI once, here: ``levels_g`` multiplies by
:data:`shipblock.units.STANDARD_GRAVITY`; ``levels`` with ``units`` goes through
:func:`shipblock.units.acceleration_to_si` (:func:`shipblock.units.velocity_to_si` for PGV).
The dataset stores the levels, medians and achieved IMs in SI; with ``levels_g`` the levels and
medians also in g (``im_level_g``, ``median_g``, ...), and the fits, their messages and the
command's output use the pipeline's unit.
"""

from __future__ import annotations

import hashlib
import itertools
import json
import logging
import math
import os
import time
import tomllib
import warnings
from collections.abc import Mapping
from dataclasses import dataclass
from datetime import UTC, datetime
from pathlib import Path

import numpy as np
import xarray as xr

from shipblock.errors import ParameterError, ParameterTypeError, ShipblockError
from shipblock.fragility.batch import (
    DEFAULT_CHUNK_SIZE,
    prepare_record,
    records_provenance,
    run_batch,
    summary_dataset,
)
from shipblock.fragility.design import (
    IM_LEVEL_RANGE,
    IM_MEASURES,
    SWEEP_PARAMETERS,
    SYSTEM_FIELDS,
    AnalysisDesign,
    IntensityDesign,
)
from shipblock.fragility.fit import (
    IDA_METHODS,
    FragilityFitError,
    bootstrap,
    fit_cloud,
    fit_ida_levels,
    fit_msa,
    ida_capacities,
)
from shipblock.fragility.filesystem import output_name_problem
from shipblock.fragility.histories import (
    SelectionError,
    case_dataset,
    case_number,
    run_case,
    select_cases,
    write_histories,
)
from shipblock.fragility.limit_states import (
    EDP_VARIABLES,
    LimitState,
    evaluate_limit_states,
    parse_limit_states,
)
from shipblock.fragility.lock import hold_output
from shipblock.fragility.store import (
    ChunkStore,
    StoreError,
    open_results,
    remove_stale_temporaries,
    write_dataset,
)
from shipblock.fragility.workers import Workers
from shipblock.solver import DEFAULT_ATOL, DEFAULT_RTOL, DEFAULT_ZENO_OMEGA
from shipblock.solver._inputs import check_options
from shipblock.system import ShipBlockSystem
from shipblock.units import STANDARD_GRAVITY, acceleration_to_si, velocity_to_si

__all__ = [
    "FIT_CHECKPOINT_INTERVAL",
    "MAX_BOOTSTRAP",
    "MAX_CHUNK_SIZE",
    "MAX_HISTORIES",
    "MAX_RUNS",
    "MAX_SEED",
    "SCHEMA_VERSION",
    "HistoryRequest",
    "Pipeline",
    "PipelineError",
    "fragility_variables",
    "load_pipeline",
    "parse_pipeline",
    "rerun_case",
    "run_pipeline",
]

logger = logging.getLogger(__name__)

#: Pipeline layout version this module reads.
SCHEMA_VERSION = 1

#: Default largest number of time-history files of a pipeline's [histories] request.
DEFAULT_MAX_HISTORIES = 100

#: Default largest scale factor of a run made without a warning [-]: a common practical
#: ceiling of amplitude scaling (studies commonly keep factors below about 4 to 5).
DEFAULT_MAX_SCALE_FACTOR = 5.0

#: Defaults of the [fit] table.
DEFAULT_BOOTSTRAP = 200
DEFAULT_CONFIDENCE = 0.9
DEFAULT_SEED = 0

#: Largest ``fit.bootstrap`` [resamples]: bounds converge with a few thousand; a larger number
#: only makes the fits last.
MAX_BOOTSTRAP = 10_000
#: Largest ``fit.seed`` (seeds are 0 .. 2**63 - 1).
MAX_SEED = 2**63 - 1
#: Largest ``execution.chunk_size`` [runs].
MAX_CHUNK_SIZE = 1_000_000
#: Largest ``histories.max_runs`` [files].
MAX_HISTORIES = 100_000
#: Largest number of runs of one study (records x levels x swept values): the per-run results
#: are held in memory, about 250 bytes a run.
MAX_RUNS = 10_000_000


class PipelineError(ShipblockError, ValueError):
    """A pipeline file is invalid; the message names the file and the key.

    Parameters
    ----------
    key : str
        Dotted key of the problem, e.g. ``"design.levels_g"`` (``""`` for the whole file).
    problem : str
        What is wrong.
    source : str, optional
        The pipeline file.
    """

    def __init__(self, key: str, problem: str, source: str = "<pipeline>"):
        self.key = key
        self.problem = problem
        self.source = source
        where = f"{source}: " + (f"[{key}] " if key else "")
        super().__init__(where + problem)

    def __reduce__(self):
        """Keep the error picklable."""
        return (type(self), (self.key, self.problem, self.source))


# --------------------------------------------------------------------------------------------
# schema
# --------------------------------------------------------------------------------------------

_NUM = (int, float)
_SCHEMA: dict[str, dict[str, tuple]] = {
    # section -> key -> (accepted python types, required)
    "": {
        "schema_version": ((int,), False),
        "title": ((str,), False),
        "description": ((str,), False),
        "output": ((str,), True),
        "records": ((dict,), True),
        "processing": ((list,), False),
        "system": ((dict,), True),
        "sweep": ((dict,), False),
        "design": ((dict,), True),
        "limit_states": ((list,), True),
        "fit": ((dict,), False),
        "solver": ((dict,), False),
        "execution": ((dict,), False),
        "histories": ((dict,), False),
    },
    "records": {
        "catalogue": ((str,), False),
        "ids": ((str, list), True),
        "azimuth": (_NUM, False),
        "horizontal": ((str,), False),
        "response": ((str,), False),
        "strict": ((bool,), False),
    },
    "system": {
        **{name: (_NUM, False) for name in SYSTEM_FIELDS if name != "impact_rule"},
        "impact_rule": ((str,), False),
        "slenderness": (_NUM, False),
        "mass_ratio": (_NUM, False),
    },
    "design": {
        "type": ((str,), True),
        "measure": ((str,), False),
        "period": (_NUM, False),
        "damping": (_NUM, False),
        "levels": ((list,), False),
        "levels_g": ((list,), False),
        "units": ((str,), False),
        "vertical": ((str,), False),
        "vertical_levels": ((list,), False),
        "vertical_levels_g": ((list,), False),
        "cloud_method": ((str,), False),
        "stripes": ((list,), False),
        "max_scale_factor": (_NUM, False),
        "scale_factor_policy": ((str,), False),
        "target_spectrum": ((dict,), False),
    },
    "design.target_spectrum": {
        "file": ((str,), True),
        "units": ((str,), True),
        "period_range": ((list,), True),
        "match": ((str,), False),
    },
    "fit": {
        "bootstrap": ((int,), False),
        "confidence": (_NUM, False),
        "seed": ((int,), False),
        "ida_method": ((str,), False),
    },
    "solver": {"rtol": (_NUM, False), "atol": (_NUM, False), "zeno_omega": (_NUM, False)},
    "execution": {"chunk_size": ((int,), False), "scheduler": ((str,), False)},
    "histories": {"runs": ((list,), False), "exceeding": ((list,), False),
                  "max_runs": ((int,), False), "directory": ((str,), False)},
}
_REQUIRED_SYSTEM = ("ship_mass", "n_blocks", "half_height", "mu_s_ground",
                    "mu_k_ground", "mu_s_ship", "mu_k_ship")
_TYPE_NAMES = {int: "an integer", float: "a number", str: "a string", list: "a list",
               dict: "a table", bool: "true/false"}


def _type_ok(value, types) -> bool:
    if isinstance(value, bool):
        return bool in types
    return isinstance(value, types)


def _check_table(table: Mapping, section: str, source: str) -> None:
    schema = _SCHEMA[section]
    for key, value in table.items():
        dotted = f"{section}.{key}" if section else key
        if key not in schema:
            raise PipelineError(
                dotted, f"unknown key {key!r}; allowed keys: {', '.join(schema)}", source
            )
        types = schema[key][0]
        if not _type_ok(value, types):
            want = " or ".join(_TYPE_NAMES[t] for t in dict.fromkeys(
                float if t is int and float in types else t for t in types))
            raise PipelineError(dotted, f"must be {want}, got {type(value).__name__} "
                                        f"{value!r}", source)
    for key, (_, required) in schema.items():
        if required and key not in table:
            dotted = f"{section}.{key}" if section else key
            what = "section" if _SCHEMA[""].get(key, ((),))[0] in ((dict,), (list,)) else "key"
            raise PipelineError(dotted, f"missing required {what} {key!r}", source)


def _numbers(values, key: str, source: str) -> tuple[float, ...]:
    if not isinstance(values, list) or not values:
        raise PipelineError(key, "must be a non-empty list of numbers", source)
    for v in values:
        if isinstance(v, bool) or not isinstance(v, _NUM) or not math.isfinite(v):
            raise PipelineError(key, f"must hold finite numbers only, got {v!r}", source)
    return tuple(float(v) for v in values)


def _stripes(value, ids, source) -> tuple[tuple[str, ...], ...]:
    """Per-level record lists, ids given in full or by their last part."""
    out = []
    for j, stripe in enumerate(value):
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
                value = f"{level / STANDARD_GRAVITY:g} g"
                accepted = f"{low / STANDARD_GRAVITY:g} .. {high / STANDARD_GRAVITY:g} g"
            else:
                units = IM_MEASURES[measure][0]
                value, accepted = f"{level:g} {units}", f"{low:g} .. {high:g} {units}"
            raise PipelineError(key, f"{name}[{i}] = {value} is outside the accepted range "
                                     f"{accepted} of {measure.upper()} levels", source)
    return levels


def _integer(table: Mapping, key: str, default: int, low: int, high: int, section: str,
             source: str) -> int:
    """``table[key]`` (or ``default``) checked to be an integer in ``[low, high]``."""
    value = table.get(key, default)
    if not low <= value <= high:
        raise PipelineError(f"{section}.{key}", f"must be an integer in [{low}, {high}], got "
                                                f"{value}", source)
    return int(value)


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
            Summaries with ``exceeded`` and ``valid`` (:func:`fragility_variables`).
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
            logger.warning("%d runs selected for time histories; writing the first "
                           "histories.max_runs = %d", len(cases), self.max_runs)
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
        Records x levels x sweep.
    limit_states : tuple of LimitState
    fit : dict
        ``bootstrap``, ``confidence``, ``seed``, ``ida_method``, ``cloud_method``.
    solver : dict
        ``rtol``, ``atol``, ``zeno_omega``.
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
    try:
        data = path.read_bytes()
    except OSError as exc:
        raise PipelineError("", f"cannot read the pipeline file ({exc})", str(path)) from exc
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError as exc:
        raise PipelineError("", f"is not a pipeline file: not UTF-8 text (byte 0x{data[exc.start]:02x} "
                                f"at offset {exc.start}); a pipeline is a TOML text file",
                            str(path)) from None
    if "\x00" in text:
        raise PipelineError("", f"is not a pipeline file: binary data (a NUL byte at offset "
                                f"{text.index(chr(0))}); a pipeline is a TOML text file",
                            str(path))
    return parse_pipeline(text, base=path.resolve().parent, source=str(path))


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
    PipelineError
        Naming the key: unknown key, wrong type, missing section or key, invalid value,
        unknown record id, invalid system, limit state or design.
    """
    from shipblock.catalogue import load_catalogue

    base = Path(base)
    try:
        doc = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise PipelineError("", f"is not valid TOML: {exc}", source) from exc
    _check_table(doc, "", source)
    version = doc.get("schema_version", SCHEMA_VERSION)
    if version != SCHEMA_VERSION:
        raise PipelineError("schema_version", f"must be {SCHEMA_VERSION}, got {version}", source)
    for section in ("records", "system", "design", "fit", "solver", "execution", "histories"):
        if section in doc:
            _check_table(doc[section], section, source)

    # records
    rec = doc["records"]
    catalogue = (base / rec["catalogue"]).resolve() if "catalogue" in rec else None
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
    repeated = sorted({i for i in ids if ids.count(i) > 1})
    if repeated:
        raise PipelineError("records.ids", f"repeats {', '.join(repeated)}", source)
    missing = [i for i in ids if i not in entries]
    if missing:
        raise PipelineError("records.ids", f"not in the catalogue: {', '.join(missing)}; "
                                           f"known: {', '.join(entries)}", source)
    if "azimuth" in rec and "horizontal" in rec:
        raise PipelineError("records.horizontal", "give azimuth or horizontal, not both", source)
    horizontal = rec.get("horizontal", None if "azimuth" in rec else "H1")
    if horizontal is not None and horizontal not in ("H1", "H2"):
        raise PipelineError("records.horizontal", f"must be 'H1' or 'H2', got {horizontal!r}",
                            source)
    response = rec.get("response", "sensitivity")
    if response not in ("sensitivity", "full"):
        raise PipelineError("records.response", "must be 'sensitivity' or 'full'", source)
    azimuth = None
    if "azimuth" in rec:
        azimuth = float(rec["azimuth"])
        if not -360.0 <= azimuth <= 360.0:  # also false for NaN
            raise PipelineError("records.azimuth", f"must be a finite angle in [-360, 360] [deg "
                                                   f"clockwise from north], got {azimuth}", source)

    # processing
    chain = None
    if "processing" in doc:
        chain = doc["processing"]
        for k, entry in enumerate(chain):
            if not isinstance(entry, dict) or "step" not in entry:
                raise PipelineError(f"processing[{k}]", "must be a table with a 'step' key",
                                    source)
        _check_chain(chain, source)

    # system
    sys_table = dict(doc["system"])
    for key in _REQUIRED_SYSTEM:
        if key not in sys_table:
            raise PipelineError(f"system.{key}", f"missing required key {key!r}", source)
    if "slenderness" in sys_table:
        if "half_width" in sys_table:
            raise PipelineError("system.slenderness", "give slenderness or half_width, not both",
                                source)
        sys_table["half_width"] = float(sys_table.pop("slenderness")) * sys_table["half_height"]
    elif "half_width" not in sys_table:
        raise PipelineError("system.half_width", "missing (give half_width or slenderness)",
                            source)
    if "mass_ratio" in sys_table:
        if "block_mass" in sys_table:
            raise PipelineError("system.mass_ratio", "give mass_ratio or block_mass, not both",
                                source)
        n = sys_table["n_blocks"]
        if isinstance(n, bool) or not isinstance(n, int) or n < 1:
            raise PipelineError("system.n_blocks", f"must be a whole number >= 1, got {n!r}",
                                source)
        sys_table["block_mass"] = float(sys_table.pop("mass_ratio")) * sys_table["ship_mass"] / n
    elif "block_mass" not in sys_table:
        raise PipelineError("system.block_mass", "missing (give block_mass or mass_ratio)",
                            source)
    try:
        system = ShipBlockSystem(**sys_table)
    except (TypeError, ValueError) as exc:
        field = str(exc).split()[0]
        given = {"half_width": "slenderness", "block_mass": "mass_ratio"}.get(field)
        if given in doc["system"]:
            field = given  # the field was computed from the convenience given
        key = f"system.{field}" if field in _SCHEMA["system"] else "system"
        raise PipelineError(key, str(exc), source) from None

    # sweep
    sweep = []
    for name, values in doc.get("sweep", {}).items():
        if name not in SWEEP_PARAMETERS:
            raise PipelineError(f"sweep.{name}", f"unknown parameter {name!r}; sweepable: "
                                                 f"{', '.join(SWEEP_PARAMETERS)}", source)
        if not isinstance(values, list) or not values:
            raise PipelineError(f"sweep.{name}", "must be a non-empty list of values", source)
        for v in values:
            if isinstance(v, bool) or not isinstance(v, _NUM):
                raise PipelineError(f"sweep.{name}", f"must hold numbers, got {v!r}", source)
        sweep.append((name, tuple(values)))

    # design
    d = doc["design"]
    measure = d.get("measure", "pga")
    if measure not in ("pga", "pgv", "sa"):
        raise PipelineError("design.measure", f"must be 'pga', 'pgv' or 'sa', got {measure!r}",
                            source)
    levels = _levels(d, "", measure, source)
    v_levels = _levels(d, "vertical_", measure, source)
    if "units" in d and "levels" not in d and "vertical_levels" not in d:
        raise PipelineError("design.units", "is only used with levels = [...]", source)
    kind = d["type"]
    intensity = IntensityDesign(
        kind=kind,
        measure=measure,
        levels=levels or (),
        period=None if "period" not in d else float(d["period"]),
        damping=float(d.get("damping", 0.05)),
        vertical=d.get("vertical", "same"),
        vertical_levels=v_levels,
    )
    try:
        intensity.validate()
    except ValueError as exc:
        field = str(exc).split()[0].split("[")[0].rstrip(":")
        if field in ("levels", "vertical_levels"):
            key = f"design.{field}_g" if f"{field}_g" in d else f"design.{field}"
        else:
            key = f"design.{field}" if field in _SCHEMA["design"] else "design"
        raise PipelineError(key, str(exc), source) from None
    cloud_method = d.get("cloud_method", "probit")
    if cloud_method not in ("probit", "regression"):
        raise PipelineError("design.cloud_method", "must be 'probit' or 'regression'", source)
    if "cloud_method" in d and kind != "cloud":
        raise PipelineError("design.cloud_method", "applies only to type = 'cloud'", source)
    stripes = None
    if "stripes" in d:
        stripes = _stripes(d["stripes"], ids, source)
        try:
            AnalysisDesign(tuple(ids), intensity, system, (), stripes)._validate_stripes()
        except ValueError as exc:
            raise PipelineError("design.stripes", str(exc), source) from None
    design = AnalysisDesign(tuple(ids), intensity, system, tuple(sweep), stripes)
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
        swept = [name for name, _ in sweep if repr(name) in str(exc) or f"'{name}'" in str(exc)]
        raise PipelineError(f"sweep.{swept[0]}" if len(swept) == 1 else "sweep", str(exc),
                            source) from None

    # limit states
    try:
        limit_states = parse_limit_states(doc["limit_states"])
    except ValueError as exc:
        raise PipelineError("limit_states", str(exc), source) from None
    if not limit_states:
        raise PipelineError("limit_states", "define at least one [[limit_states]]", source)
    if kind == "cloud" and cloud_method == "regression":
        for ls in limit_states:
            if ls.condition not in ("greater", "greater_equal") or \
                    EDP_VARIABLES[ls.edp].kind != "float":
                raise PipelineError("limit_states", f"limit state {ls.name!r}: the cloud "
                                    "regression needs a threshold on a continuous EDP; use "
                                    "cloud_method = 'probit'", source)

    # fit, solver, execution
    f = doc.get("fit", {})
    fit = {
        "bootstrap": _integer(f, "bootstrap", DEFAULT_BOOTSTRAP, 0, MAX_BOOTSTRAP, "fit", source),
        "confidence": float(f.get("confidence", DEFAULT_CONFIDENCE)),
        "seed": _integer(f, "seed", DEFAULT_SEED, 0, MAX_SEED, "fit", source),
        "ida_method": f.get("ida_method", "interval"),
        "cloud_method": cloud_method,
    }
    if not 0 < fit["confidence"] < 1:
        raise PipelineError("fit.confidence", f"must lie in (0, 1), got {fit['confidence']}",
                            source)
    if fit["ida_method"] in ("mle", "moments"):
        old = "first_exceedance" + ("_moments" if fit["ida_method"] == "moments" else "")
        raise PipelineError("fit.ida_method", f"{fit['ida_method']!r} took the first exceeding "
                            f"level as the capacity; that estimate is now named {old!r} (it "
                            "overestimates the median by up to one level step); the default "
                            "'interval' fits the capacity between the last level that held and "
                            "the first that failed", source)
    if fit["ida_method"] not in IDA_METHODS:
        raise PipelineError("fit.ida_method", f"must be one of {', '.join(map(repr, IDA_METHODS))}"
                            f", got {fit['ida_method']!r}", source)
    s = doc.get("solver", {})
    solver = {"rtol": float(s.get("rtol", DEFAULT_RTOL)),
              "atol": float(s.get("atol", DEFAULT_ATOL)),
              "zeno_omega": float(s.get("zeno_omega", DEFAULT_ZENO_OMEGA))}
    try:
        check_options(**solver)
    except ParameterError as exc:
        raise PipelineError(f"solver.{str(exc).split()[0]}", str(exc), source) from None
    ex = doc.get("execution", {})
    chunk_size = _integer(ex, "chunk_size", DEFAULT_CHUNK_SIZE, 1, MAX_CHUNK_SIZE, "execution",
                          source)
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
        scheduler=scheduler, output=_output_path(doc["output"], base, source),
        histories=histories, **_scaling_limits(doc, source),
        im_display=_im_display(d, measure, source),
        target_spectrum=_target_spectrum(d, intensity, base, source),
    )


def _target_spectrum(design: Mapping, intensity: IntensityDesign, base: Path, source: str):
    """The ``[design.target_spectrum]`` table, read and checked (see ``Pipeline``)."""
    from shipblock.scaling import MATCH_MODES, TargetSpectrumError, read_target_spectrum

    if "target_spectrum" not in design:
        return None
    table = design["target_spectrum"]
    _check_table(table, "design.target_spectrum", source)
    key = "design.target_spectrum"
    if intensity.kind not in ("ida", "msa") or intensity.measure != "sa":
        raise PipelineError(key, "scaling to a target spectrum needs type 'ida' or 'msa' on "
                            "measure = 'sa' (its period is T1, where the target is anchored to "
                            "the levels)", source)
    rng = _numbers(table["period_range"], f"{key}.period_range", source)
    if len(rng) != 2 or not 0 < rng[0] < rng[1]:
        raise PipelineError(f"{key}.period_range", f"must be [T_a, T_b] with 0 < T_a < T_b [s],"
                            f" got {table['period_range']!r}", source)
    match = table.get("match", "range")
    if match not in MATCH_MODES:
        raise PipelineError(f"{key}.match", f"must be one of {', '.join(map(repr, MATCH_MODES))}"
                            f", got {match!r}", source)
    try:
        spectrum = read_target_spectrum(base / table["file"], table["units"])
        spectrum.at([rng[0], rng[1], intensity.period])
    except TargetSpectrumError as exc:
        raise PipelineError(f"{key}.file", str(exc), source) from None
    return {"spectrum": spectrum, "file": str(base / table["file"]), "units": table["units"],
            "period_range": rng, "match": match}


def _match_target_spectrum(pipe: Pipeline, record) -> dict | None:
    """Scale a prepared record to the target spectrum at every level (in place).

    The batch scaled it to Sa(T1) = level (``match = "anchor"``: kept). With ``"range"`` the
    factor at level ``j`` becomes ``level_j / Sa_target(T1) * f``, ``f`` the least-squares
    factor of the record to the target over the range (the target anchored at each level is
    the file's spectrum times ``level_j / Sa_target(T1)``): every factor and achieved IM is
    multiplied by ``f Sa_record(T1) / Sa_target(T1)``, as is the vertical's in mode "same".

    Returns
    -------
    dict or None
        ``misfit`` [-], ``sa_record`` on the matching periods [m/s^2]; None for a record left
        out.
    """
    from shipblock.scaling import spectrum_match

    target = pipe.target_spectrum
    if target is None or record.error is not None:
        return None
    intensity = pipe.design.intensity
    try:
        m = spectrum_match(record.horizontal, record.dt, target["spectrum"],
                           target["period_range"], mode=target["match"],
                           anchor_period=intensity.period, damping=intensity.damping)
    except ShipblockError as exc:
        record.error = f"{type(exc).__name__}: {exc}"
        return None
    if target["match"] == "range":
        ratio = m.factor * record.im / float(target["spectrum"].at(intensity.period)[0])
        record.factor_h = record.factor_h * ratio
        record.achieved = record.achieved * ratio
        if intensity.vertical == "same":
            record.factor_v = record.factor_v * ratio
            record.achieved_v = record.achieved_v * ratio
    return {"misfit": m.misfit, "periods": m.periods, "sa_record": m.sa_record,
            "sa_target": m.sa_target}


def _spectrum_variables(pipe: Pipeline, matches) -> tuple[dict, dict]:
    """Variables and attributes of the target-spectrum match (none without a target)."""
    target = pipe.target_spectrum
    if target is None:
        return {}, {}
    ok = [m for m in matches if m is not None]
    periods = ok[0]["periods"] if ok else np.geomspace(*target["period_range"], 40)
    n = periods.size
    misfit = np.array([np.nan if m is None else m["misfit"] for m in matches])
    sa = np.array([np.full(n, np.nan) if m is None else m["sa_record"] for m in matches])
    lo, hi = target["period_range"]
    coords = {"spectrum_period": ("spectrum_period", periods,
                                  {"units": "s", "long_name": "period of the spectrum match"})}
    data = {
        "spectrum_misfit": (("record",), misfit, {
            "units": "1", "long_name": f"RMS of ln(Sa scaled / Sa target) from {lo:g} to "
            f"{hi:g} s (match {target['match']!r})"}),
        "record_sa": (("record", "spectrum_period"), sa, {
            "units": "m/s^2", "long_name": "pseudo-spectral acceleration of the processed, "
                                           "unscaled record"}),
        "target_sa": (("spectrum_period",), target["spectrum"].at(periods), {
            "units": "m/s^2", "long_name": "target spectrum as given (at each level it is "
            "scaled to Sa(T1) = level)"}),
    }
    attrs = {"target_spectrum_file": target["file"], "target_spectrum_units": target["units"],
             "target_spectrum_period_range": list(target["period_range"]),
             "target_spectrum_match": target["match"]}
    return {"coords": coords, "data": data}, attrs


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
    limit = d.get("max_scale_factor", DEFAULT_MAX_SCALE_FACTOR)
    if not (math.isfinite(limit) and limit >= 1.0):
        raise PipelineError("design.max_scale_factor", f"must be a number >= 1, got {limit!r}",
                            source)
    policy = d.get("scale_factor_policy", "warn")
    if policy not in ("warn", "refuse"):
        raise PipelineError("design.scale_factor_policy",
                            f"must be 'warn' or 'refuse', got {policy!r}", source)
    return {"max_scale_factor": float(limit), "scale_factor_policy": policy,
            "strict": bool(doc["records"].get("strict", False))}


def _output_path(value: str, base: Path, source: str, key: str = "output") -> Path:
    """The output file, absolute: a file name (not empty, not a folder)."""
    if not value.strip() or value.endswith(("/", "\\")) or Path(value).name in ("", ".", ".."):
        raise PipelineError(key, f"must name a NetCDF file such as 'results/study.nc', got "
                                 f"{value!r}", source)
    path = (base / value).resolve()
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
    max_runs = _integer(table, "max_runs", DEFAULT_MAX_HISTORIES, 1, MAX_HISTORIES, "histories",
                        source)
    directory = (base / table["directory"]).resolve() if "directory" in table else None
    return HistoryRequest(tuple(dict.fromkeys(cases)), tuple(exceeding), int(max_runs),
                          directory)


def _check_chain(chain, source):
    """Validate the processing chain on a tiny synthetic stream (step names and parameters)."""
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


# --------------------------------------------------------------------------------------------
# fragility
# --------------------------------------------------------------------------------------------


def _fit_one(kind, e, w, levels, im, edp, ls, fit_opts, rng, workers=None):
    """Fit one limit state for one parameter combination; returns a dict of results."""
    out = {"median": np.nan, "beta": np.nan, "median_lower": np.nan, "median_upper": np.nan,
           "beta_lower": np.nan, "beta_upper": np.nan, "fit_method": "", "fit_error": "",
           "n_fit_records": 0, "bootstrap_failed": 0}
    keep = w.any(axis=1) if e.ndim == 2 else w
    out["n_fit_records"] = int(keep.sum())
    capacity = None
    n_boot = fit_opts["bootstrap"]
    try:
        if not keep.any():
            raise FragilityFitError("no record has a valid run: nothing to fit")
        if kind == "ida":
            capacity = ida_capacities(e[keep], levels, w[keep])
            args = {"exceeded": e[keep], "valid": w[keep]}
            fn, kw = fit_ida_levels, {"im_levels": levels, "method": fit_opts["ida_method"]}
        elif kind == "msa":
            args = {"exceeded": e[keep], "valid": w[keep]}
            fn, kw = fit_msa, {"im_levels": levels}
        elif fit_opts["cloud_method"] == "probit":
            args = {"im": im[keep], "edp": e[keep].astype(float)}
            fn, kw = fit_cloud, {"capacity": 0.5, "method": "probit"}
        else:
            args = {"im": im[keep], "edp": np.abs(edp[keep])}
            fn, kw = fit_cloud, {"capacity": ls.threshold, "method": "regression"}
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", RuntimeWarning)
            fit = fn(**args, **kw)
        out.update(median=fit.median, beta=fit.beta, fit_method=fit.method)
        if n_boot:
            try:
                with warnings.catch_warnings():
                    warnings.simplefilter("ignore", RuntimeWarning)
                    b = bootstrap(fn, args, n_boot=n_boot, confidence=fit_opts["confidence"],
                                  seed=rng, workers=workers, **kw)
                out.update(median_lower=b.fit.median_ci[0], median_upper=b.fit.median_ci[1],
                           beta_lower=b.fit.beta_ci[0], beta_upper=b.fit.beta_ci[1],
                           bootstrap_failed=b.n_failed)
            except ValueError as exc:
                out["fit_error"] = f"bootstrap: {exc}"
    except (FragilityFitError, ValueError) as exc:
        out["fit_error"] = f"{type(exc).__name__}: {exc}"
    return out, capacity


_FIT_FLOATS = ("median", "beta", "median_lower", "median_upper", "beta_lower", "beta_upper")
_FIT_INTS = ("n_fit_records", "bootstrap_failed")
_FIT_STRINGS = ("fit_method", "fit_error")

#: Fitted results are written to the partial-results directory at most this often [s] (and
#: once more when the fits are done): a kill after the batch loses at most this much fitting.
FIT_CHECKPOINT_INTERVAL = 1.0


class _FitCheckpoint:
    """Fitted results of finished (limit state, sweep point) pairs, kept in a ChunkStore.

    Fit ``f = i * n_points + c`` is limit state ``i`` at sweep point ``c``; each file of the
    store's ``"fit"`` group holds some fits (those finished since the previous file), so the
    files' names say nothing about what they hold and a file is never rewritten.
    """

    def __init__(self, store: ChunkStore, n_records: int):
        self.store = store
        self.n_records = n_records
        self.pending: dict[int, tuple[dict, np.ndarray, np.ndarray]] = {}
        self.last = time.monotonic()
        self.next_id = max(store.completed("fit"), default=-1) + 1

    def load(self) -> dict[int, tuple[dict, np.ndarray, np.ndarray]]:
        """Fits done by an earlier, interrupted run.

        ``{f: (results, capacity column, capacity_held column)}``, the columns over the records.
        """
        done = {}
        for k in sorted(self.store.completed("fit")):
            try:
                fits, arrays = self.store.read(k, "fit")
                capacity, held = (np.asarray(arrays[n], dtype=float).reshape(
                    len(fits), self.n_records) for n in ("capacity", "capacity_held"))
                rows = [dict(zip(_FIT_FLOATS + _FIT_INTS + _FIT_STRINGS, values, strict=True))
                        for values in zip(*(arrays[n].tolist() for n in
                                             _FIT_FLOATS + _FIT_INTS + _FIT_STRINGS),
                                          strict=True)]
            except (StoreError, KeyError, ValueError) as exc:
                logger.warning("fitted results %d unusable (%s); fitting again", k, exc)
                self.store.discard(k, "fit")
                continue
            for f, row, col, col_held in zip(fits.tolist(), rows, capacity, held, strict=True):
                done[f] = (row, col, col_held)
        return done

    def add(self, f: int, result: dict, capacity: np.ndarray, held: np.ndarray) -> None:
        self.pending[f] = (result, capacity, held)
        if time.monotonic() - self.last >= FIT_CHECKPOINT_INTERVAL:
            self.flush()

    def flush(self) -> None:
        if self.pending:
            fits = np.array(list(self.pending), dtype=np.int64)
            rows = [r for r, _, _ in self.pending.values()]
            arrays = {n: np.array([r[n] for r in rows], dtype=float) for n in _FIT_FLOATS}
            arrays.update({n: np.array([r[n] for r in rows], dtype=np.int64) for n in _FIT_INTS})
            arrays.update({n: np.array([r[n] for r in rows], dtype=str) for n in _FIT_STRINGS})
            arrays["capacity"] = np.stack([c for _, c, _ in self.pending.values()])
            arrays["capacity_held"] = np.stack([h for _, _, h in self.pending.values()])
            self.store.write(self.next_id, fits, arrays, group="fit")
            self.next_id += 1
            self.pending = {}
        self.last = time.monotonic()


def fragility_variables(ds: xr.Dataset, design: AnalysisDesign, limit_states, fit_opts,
                        store: ChunkStore | None = None,
                        im_display: tuple[str, float] = ("", 1.0), workers=None) -> dict:
    """Exceedance, fitted median/beta and bootstrap bounds of every limit state.

    Parameters
    ----------
    ds : xarray.Dataset
        Per-run summaries on ``design.dims`` (from
        :func:`~shipblock.fragility.batch.summary_dataset`).
    design : AnalysisDesign
        The grid.
    limit_states : sequence of LimitState
        The limit states (the ``limit_state`` dimension).
    fit_opts : dict
        ``bootstrap`` (resamples), ``confidence``, ``seed``, ``ida_method``, ``cloud_method``.
    store : ChunkStore, optional
        The run's partial-results directory (opened): fitted results are written to it as they
        are done (at most every :data:`FIT_CHECKPOINT_INTERVAL` seconds), and those it holds
        from an interrupted run are used instead of fitted again. Each fit is a function of
        its own data and seed only, so the results are the same bit for bit.
    im_display : tuple of (str, float)
        Unit the pipeline writes its IM in and its SI value (:attr:`Pipeline.im_display`): the
        fits are made in it, so that their messages (``fit_error``) quote the levels as the
        pipeline wrote them, and with ``"g"`` the medians are stored in g too (``median_g``,
        ``median_lower_g``, ``median_upper_g``). Default: SI.
    workers : shipblock.fragility.workers.Workers, optional
        Where the bootstrap resamples run (see :func:`~shipblock.fragility.fit.bootstrap`).

    Returns
    -------
    dict
        Name -> :class:`xarray.DataArray` with ``units`` and ``long_name``: ``exceeded`` and
        ``valid`` on ``(limit_state, *design.dims)``; ``median``, ``beta``, their bounds,
        ``fit_method``, ``fit_error``, ``n_fit_records``, ``bootstrap_failed`` on
        ``(limit_state, *sweep)``; ``ida_capacity`` and ``ida_capacity_lower`` (the first
        level that failed and the last that held) on ``(limit_state, record, *sweep)`` for
        IDA. Bootstrap resampling of combination ``c`` of limit state ``i`` is seeded with
        ``[seed, i, c]``.
    """
    intensity = design.intensity
    kind = intensity.kind
    unit, factor = im_display
    unit = unit or intensity.units
    levels = np.asarray(intensity.levels, dtype=float) / factor  # in the pipeline's unit
    ex = evaluate_limit_states(limit_states, ds)
    names = [ls.name for ls in limit_states]
    sweep_dims = design.sweep_names
    sweep_shape = design.sweep_shape
    n_ls = len(limit_states)
    fields = {k: np.full((n_ls, *sweep_shape), np.nan) for k in (
        "median", "beta", "median_lower", "median_upper", "beta_lower", "beta_upper")}
    fields["n_fit_records"] = np.zeros((n_ls, *sweep_shape), dtype=np.int64)
    fields["bootstrap_failed"] = np.zeros((n_ls, *sweep_shape), dtype=np.int64)
    fields["fit_method"] = np.full((n_ls, *sweep_shape), "", dtype=object)
    fields["fit_error"] = np.full((n_ls, *sweep_shape), "", dtype=object)
    n_records = len(design.records)
    capacity = np.full((n_ls, n_records, *sweep_shape), np.nan)
    capacity_held = capacity.copy()
    im = ds["achieved_im"].values / factor if not intensity.scaled else None
    checkpoint = None if store is None else _FitCheckpoint(store, n_records)
    done = {} if checkpoint is None else checkpoint.load()
    if done:
        logger.info("resuming: %d of %d fits already done", len(done),
                    n_ls * design.n_systems)
    for i, ls in enumerate(limit_states):
        e_all = ex[ls.name].exceeded.transpose(*design.dims).values
        w_all = ex[ls.name].valid.transpose(*design.dims).values
        edp_all = ds[ls.edp].transpose(*design.dims).values
        lead = e_all.ndim - len(sweep_shape)
        for c, combo in enumerate(itertools.product(*(range(n) for n in sweep_shape))):
            f = i * design.n_systems + c
            if f in done:
                res, col, col_held = done[f]
            else:
                sel = (slice(None),) * lead + combo
                rng = np.random.default_rng([int(fit_opts["seed"]), i, c])
                res, caps = _fit_one(kind, e_all[sel], w_all[sel], levels, im, edp_all[sel],
                                     ls, fit_opts, rng, workers)
                for k in ("median", "median_lower", "median_upper"):
                    res[k] *= factor  # back to SI
                if res["fit_error"]:
                    res["fit_error"] += f" [IM in {unit}]"
                col = np.full(n_records, np.nan)
                col_held = np.full(n_records, np.nan)
                if caps is not None:
                    keep = w_all[sel].any(axis=1)
                    col[keep] = caps.capacity * factor
                    col_held[keep] = caps.held * factor
                if checkpoint is not None:
                    checkpoint.add(f, res, col, col_held)
            for k, v in res.items():
                fields[k][(i, *combo)] = v
            capacity[(i, slice(None), *combo)] = col
            capacity_held[(i, slice(None), *combo)] = col_held
    if checkpoint is not None:
        checkpoint.flush()
    im_units = intensity.units
    dims_fit = ("limit_state", *sweep_dims)
    info = {
        "median": (im_units,
                   f"median capacity theta of the fragility curve ({intensity.long_name})"),
        "beta": ("1", "logarithmic standard deviation beta of the fragility curve"),
        "median_lower": (im_units, "lower bootstrap confidence bound of the median"),
        "median_upper": (im_units, "upper bootstrap confidence bound of the median"),
        "beta_lower": ("1", "lower bootstrap confidence bound of beta"),
        "beta_upper": ("1", "upper bootstrap confidence bound of beta"),
        "fit_method": ("1", "fitting method (shipblock.fragility.fit)"),
        "fit_error": ("1", "why the fit (or its bootstrap) failed (empty if it did not)"),
        "n_fit_records": ("1", "number of records with at least one valid run"),
        "bootstrap_failed": ("1", "bootstrap resamples that could not be fitted"),
    }
    out = {}
    for k, (units, long_name) in info.items():
        attrs = {"units": units, "long_name": long_name}
        if k.endswith(("_lower", "_upper")):
            attrs["confidence"] = fit_opts["confidence"]
            attrs["n_bootstrap"] = int(fit_opts["bootstrap"])
        out[k] = xr.DataArray(fields[k], dims=dims_fit, attrs=attrs)
    if unit == "g" and factor == STANDARD_GRAVITY:
        for k in ("median", "median_lower", "median_upper"):
            out[f"{k}_g"] = xr.DataArray(fields[k] / factor, dims=dims_fit, attrs={
                **out[k].attrs, "units": "g", "long_name": out[k].attrs["long_name"] + " in g"})
    dims_run = ("limit_state", *design.dims)
    out["exceeded"] = xr.DataArray(
        np.stack([ex[n].exceeded.transpose(*design.dims).values for n in names]), dims=dims_run,
        attrs={"units": "1", "long_name": "limit state exceeded by the run "
                                          "(collapse exceeds every response limit state)"})
    out["valid"] = xr.DataArray(
        np.stack([ex[n].valid.transpose(*design.dims).values for n in names]), dims=dims_run,
        attrs={"units": "1", "long_name": "run produced a usable result for the limit state"})
    if kind == "ida":
        out["ida_capacity"] = xr.DataArray(
            capacity, dims=("limit_state", "record", *sweep_dims),
            attrs={"units": im_units, "long_name": "IDA capacity, upper bound: first IM level "
                   "exceeding the limit state (inf: never; NaN: no valid run)"})
        out["ida_capacity_lower"] = xr.DataArray(
            capacity_held, dims=("limit_state", "record", *sweep_dims),
            attrs={"units": im_units, "long_name": "IDA capacity, lower bound: last IM level "
                   "that held below the first exceedance (0: exceeded at the first level; NaN: "
                   "no valid run)"})
    return out


def _limit_state_coords(limit_states) -> dict:
    return {
        "limit_state": ("limit_state", np.array([ls.name for ls in limit_states], dtype=object),
                        {"units": "1", "long_name": "limit state"}),
        "limit_state_edp": ("limit_state", np.array([ls.edp for ls in limit_states],
                                                    dtype=object),
                            {"units": "1", "long_name": "EDP of the limit state"}),
        "limit_state_condition": (
            "limit_state", np.array([ls.condition for ls in limit_states], dtype=object),
            {"units": "1", "long_name": "condition of the limit state"}),
        "limit_state_threshold": (
            "limit_state",
            np.array([np.nan if ls.threshold is None else float(ls.threshold)
                      for ls in limit_states]),
            {"units": "EDP units (see limit_state_edp)",
             "long_name": "threshold of the limit state (NaN for 'nonzero')"}),
    }


# --------------------------------------------------------------------------------------------
# run
# --------------------------------------------------------------------------------------------


class _StageClock:
    """Adds the wall time since the previous lap to ``timings[stage]`` (no-op without a dict)."""

    def __init__(self, timings: dict | None):
        self.timings = timings
        self.t = time.perf_counter()

    def lap(self, stage: str) -> None:
        now = time.perf_counter()
        if self.timings is not None:
            self.timings[stage] = self.timings.get(stage, 0.0) + now - self.t
        self.t = now


def _fingerprint(pipe: Pipeline, records) -> str:
    from shipblock import __version__

    h = hashlib.sha256(json.dumps(pipe.identity(), sort_keys=True, default=str).encode())
    h.update(__version__.encode())
    for r in records:
        h.update(r.digest().encode())
    return h.hexdigest()


def _prepare_output_folder(out_path: Path, source: str) -> None:
    """Check the output's name, create its folder and check it is writable.

    Done before any work, so that an output that cannot be written fails at once, not after
    the batch.
    """
    if (problem := output_name_problem(out_path)) is not None:  # issue 33
        raise PipelineError("output", problem, source)
    try:
        out_path.parent.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise PipelineError("output", f"cannot create the folder of {out_path} ({exc})",
                            source) from None
    if not os.access(out_path.parent, os.W_OK | os.X_OK):
        raise PipelineError("output", f"cannot write in the folder {out_path.parent}", source)


def _dask_client_class(scheduler: str, source: str):
    """``distributed.Client``, or a PipelineError saying which extra to install."""
    try:
        from distributed import Client
    except ImportError as exc:
        raise PipelineError(
            "execution.scheduler",
            f"running on the Dask scheduler {scheduler!r} needs Dask, which is not installed "
            f"({exc}); install it with: pip install \"shipblock[dask]\"", source) from None
    return Client


def _scale_factors(pipe: Pipeline, records) -> np.ndarray:
    """|Scale factor| of every (record, level) [-]: the horizontal's, and the vertical's when it
    is scaled to its own targets; NaN for a record left out."""
    f = np.array([np.abs(r.factor_h) for r in records], dtype=float)
    if pipe.design.intensity.vertical == "independent":
        fv = np.array([np.abs(r.factor_v) for r in records], dtype=float)
        f = np.fmax(f, fv)
    return f


def _record_use(pipe: Pipeline, records):
    """Runs scaled beyond the limit, those refused, and the records left out (with reasons).

    Returns ``(above, refused, left_out)``: two (record, level) masks and ``{id: reason}``.
    Warns about runs above the limit; raises :class:`PipelineError` under ``records.strict``
    if a record is left out or a run refused.
    """
    design = pipe.design
    factors = _scale_factors(pipe, records)
    with np.errstate(invalid="ignore"):
        above = (factors > pipe.max_scale_factor) & design.stripe_mask()
    if not design.intensity.scaled:
        above[:] = False
    refused = above if pipe.scale_factor_policy == "refuse" else np.zeros_like(above)
    left_out = {}
    for i, r in enumerate(records):
        if r.error is not None:
            left_out[r.id] = r.error
        elif not (design.stripe_mask()[i] & ~refused[i]).any():
            f = factors[i][design.stripe_mask()[i]]
            left_out[r.id] = (f"every run refused: scale factors {f.min():.4g} to {f.max():.4g} "
                              f"above max_scale_factor {pipe.max_scale_factor:g}")
    if above.any():
        worst = np.unravel_index(np.nanargmax(np.where(above, factors, np.nan)), above.shape)
        what = "not run" if pipe.scale_factor_policy == "refuse" else "run"
        unit, per_unit = pipe.im_display
        logger.warning(
            "%d of %d runs have a scale factor above max_scale_factor = %g (%s; the largest, %.4g, "
            "is %s at %s %.4g %s)", int(above.sum()), int(design.stripe_mask().sum()),
            pipe.max_scale_factor, what, factors[worst], design.records[worst[0]],
            design.intensity.measure.upper(), design.intensity.levels[worst[1]] / per_unit, unit)
    if pipe.strict and (left_out or refused.any()):
        why = [f"{rid} ({reason})" for rid, reason in left_out.items()]
        if refused.any():
            why.append(f"{int(refused.sum())} runs refused for their scale factor")
        raise PipelineError("records.strict", "the study would go on without some of its "
                            f"records or runs: {'; '.join(why)}", pipe.source)
    for rid, reason in left_out.items():
        if records[design.records.index(rid)].error is None:  # errors were said when read
            logger.warning("record %s left out: %s", rid, reason)
    return above, refused, left_out


def records_used_message(n_records: int, left_out: Mapping[str, str]) -> str:
    """``"7 of 9 records used, 2 left out: A (why); B (why)"``.

    Parameters
    ----------
    n_records : int
        Records named by the study.
    left_out : mapping
        Record id -> reason, for the records left out.

    Returns
    -------
    str
    """
    used = n_records - len(left_out)
    text = f"{used} of {n_records} records used"
    if left_out:
        text += f", {len(left_out)} left out: " + "; ".join(
            f"{rid} ({reason})" for rid, reason in left_out.items())
    return text


def _add_record_use(ds, pipe: Pipeline, records, above, refused, left_out) -> xr.Dataset:
    """Scale-factor limit, refused runs and records used, as variables and attributes."""
    design = pipe.design
    limit = pipe.max_scale_factor
    if design.intensity.scaled:
        ds["scale_factor_above_limit"] = xr.DataArray(
            above, dims=("record", "im_level"),
            attrs={"units": "1", "long_name": f"scale factor above max_scale_factor = {limit:g} "
                   f"(policy {pipe.scale_factor_policy!r}: "
                   f"{'not run' if pipe.scale_factor_policy == 'refuse' else 'run, reported'})",
                   "max_scale_factor": limit})
        if refused.any():
            factors = _scale_factors(pipe, records)
            errors = ds["run_error"].transpose(*design.dims).values.copy()
            for r, j in zip(*np.nonzero(refused), strict=True):
                errors[r, j, ...] = (f"not run: scale factor {factors[r, j]:.4g} above "
                                     f"max_scale_factor {limit:g}")
            ds["run_error"] = ds["run_error"].copy(data=errors)
    ds["record_used"] = xr.DataArray(
        np.array([r not in left_out for r in design.records]), dims=("record",),
        attrs={"units": "1", "long_name": "record used in the study (see record_error or "
                                          "the attribute records_used for why not)"})
    for rid, reason in left_out.items():
        if not ds["record_error"].sel(record=rid).item():
            ds["record_error"].loc[{"record": rid}] = reason
    ds.attrs.update({
        "max_scale_factor": limit,
        "scale_factor_policy": pipe.scale_factor_policy,
        "n_records_used": len(design.records) - len(left_out),
        "records_used": records_used_message(len(design.records), left_out),
    })
    return ds


def _loader(entry, pipe: Pipeline):
    def load():
        kwargs = {"response": pipe.response}
        if pipe.azimuth is not None:
            return entry.read(azimuth=pipe.azimuth, **kwargs)
        return entry.read(horizontal=pipe.horizontal, **kwargs)

    return load


def run_pipeline(path, output=None, client=None, scheduler=None, progress: bool = True,
                 timings: dict | None = None, wait: bool = False) -> xr.Dataset:
    """Run a pipeline file end to end and return the dataset it wrote.

    Parameters
    ----------
    path : str or os.PathLike
        The pipeline TOML file.
    output : str or os.PathLike, optional
        Output NetCDF file; overrides the file's ``output``. Finished chunks, and then the
        fitted results, are kept in ``<output>.partial/`` until the final file is written;
        rerunning resumes from them. Temporary files a killed final write left beside the
        output (``.<name>.<random>.tmp``) are removed when the run starts.
    client : distributed.Client, optional
        Run the chunks as tasks on this Dask client.
    scheduler : str, optional
        Address of a Dask scheduler (``"tcp://host:port"``) to connect to (overrides the file's
        ``execution.scheduler``); ignored when ``client`` is given.
    progress : bool
        Show a progress bar (runs done, rate, time left).
    timings : dict, optional
        Filled with the wall time of each stage [s]: ``records`` (pipeline parsed, records
        read, processed and scaled, partial-results directory opened),
        ``runs`` (all chunks, with ``solver`` the part spent in
        :func:`~shipblock.fragility.batch.run_chunk` when run locally), ``fragility``
        (dataset, limit states, fits), ``histories`` (time histories, if requested),
        ``write`` (NetCDF written and read back).
    wait : bool
        If another run holds the output (:func:`~shipblock.fragility.lock.hold_output`): wait
        for it to end, then run (True), or raise
        :class:`~shipblock.fragility.lock.OutputLockedError` naming its process (False).

    Returns
    -------
    xarray.Dataset
        The results, as read back from the output file. With a ``[histories]`` request, the
        runs' time-history files are written first (resuming like the runs) and listed in the
        variable ``history_file``.

    Raises
    ------
    PipelineError
        If the pipeline is invalid, the output cannot be written, Dask is asked for but not
        installed (``pip install "shipblock[dask]"``) or its scheduler cannot be reached, every
        record was left out, or the partial directory belongs to another run. All of these
        are found before the batch starts.
    OutputLockedError
        If another run holds the output and ``wait`` is False.
    """
    for name, value, types, what in (("output", output, str | os.PathLike, "a file path"),
                                     ("scheduler", scheduler, str, "a scheduler address"),
                                     ("timings", timings, dict, "a dict")):
        if value is not None and not isinstance(value, types):
            raise ParameterTypeError(f"{name} must be {what} or None, got "
                                     f"{type(value).__name__} {value!r}")
    clock = _StageClock(timings)
    pipe = load_pipeline(path)
    out_path = (pipe.output if output is None
                else _output_path(os.fspath(output), Path.cwd(), "run_pipeline(output=...)"))
    _prepare_output_folder(out_path, pipe.source)
    with hold_output(out_path, wait=wait):  # issue 33: one run per output
        return _run_held(pipe, out_path, client, scheduler, progress, timings, clock)


def _run_held(pipe: Pipeline, out_path: Path, client, scheduler, progress: bool, timings,
              clock: _StageClock) -> xr.Dataset:
    """:func:`run_pipeline` once the run holds its output (the files left beside it are no
    live run's)."""
    from shipblock import __version__
    from shipblock.catalogue import load_catalogue
    from shipblock.processing import DEFAULT_CHAIN

    for stale in remove_stale_temporaries(out_path):
        logger.info("removed %s, left by an interrupted write of %s", stale.name, out_path.name)
    scheduler = scheduler or pipe.scheduler
    connect = _dask_client_class(scheduler, pipe.source) if client is None and scheduler else None
    design = pipe.design
    entries = load_catalogue(pipe.catalogue)
    records = [
        prepare_record(rid, _loader(entries[rid], pipe), pipe.chain, design.intensity)
        for rid in design.records
    ]
    matches = [_match_target_spectrum(pipe, r) for r in records]
    above, refused, left_out = _record_use(pipe, records)
    if len(left_out) == len(records):
        reasons = "; ".join(f"{rid}: {why}" for rid, why in left_out.items())
        raise PipelineError("records.ids", f"every record was left out, so there is nothing to "
                                           f"run: {reasons}", pipe.source)
    fingerprint = _fingerprint(pipe, records)
    own_client = None
    if connect is not None:
        try:
            client = own_client = connect(scheduler)
        except (OSError, TimeoutError) as exc:
            raise PipelineError("execution.scheduler", f"cannot connect to the Dask scheduler "
                                                       f"{scheduler!r}: {exc}", pipe.source) from None
    try:
        store = ChunkStore(out_path.with_name(out_path.name + ".partial"), fingerprint)
        try:
            store.open({"n_cases": design.n_cases, "chunk_size": pipe.chunk_size,
                        "pipeline": pipe.source})
        except StoreError as exc:
            raise PipelineError("output", str(exc), pipe.source) from None
        clock.lap("records")
        results = run_batch(design, records, store, chunk_size=pipe.chunk_size, client=client,
                            progress=progress, solver_options=pipe.solver, timings=timings,
                            runs=design.stripe_mask() & ~refused)
        clock.lap("runs")
        ds = summary_dataset(design, records, results)
        ds = ds.assign_coords({k: xr.Variable(*v) for k, v in _limit_state_coords(
            pipe.limit_states).items()})
        # the bootstrap resamples on the client's workers too, or on local processes
        with Workers(client) as workers:
            ds = ds.assign(fragility_variables(ds, design, pipe.limit_states, pipe.fit, store,
                                               im_display=pipe.im_display, workers=workers))
    finally:
        if own_client is not None:
            own_client.close()
    if pipe.im_display[0] == "g" and design.intensity.scaled:
        ds = ds.assign_coords(im_level_g=("im_level", ds["im_level"].values / STANDARD_GRAVITY, {
            "units": "g", "long_name": ds["im_level"].attrs["long_name"] + " in g"}))
    chain = [dict(e) for e in (DEFAULT_CHAIN if pipe.chain is None else pipe.chain)]
    intensity = design.intensity
    ds.attrs = {
        "title": pipe.document.get("title", "shipblock fragility study"),
        "shipblock_version": __version__,
        "created": datetime.now(UTC).isoformat(timespec="seconds"),
        "pipeline": pipe.text,
        "pipeline_source": str(pipe.source),
        "pipeline_fingerprint": fingerprint,
        "design_type": intensity.kind,
        "im_measure": intensity.measure,
        "im_units": intensity.units,
        "im_long_name": intensity.long_name,
        "im_damping": intensity.damping,
        "im_display_units": pipe.im_display[0],
        "im_display_factor": pipe.im_display[1],
        "vertical_mode": intensity.vertical,
        "component": (f"azimuth {pipe.azimuth:g} deg" if pipe.azimuth is not None
                      else str(pipe.horizontal)),
        "catalogue": str(pipe.catalogue or "shipped records/catalogue.toml"),
        "system": json.dumps(design.system.to_dict(), sort_keys=True),
        "sweep": json.dumps({k: list(v) for k, v in design.sweep}),
        "processing_chain": json.dumps(chain, sort_keys=True),
        "records_provenance": records_provenance(records),
        "limit_states": json.dumps([ls.to_dict() for ls in pipe.limit_states]),
        "fit_options": json.dumps(pipe.fit, sort_keys=True),
        "solver_options": json.dumps(pipe.solver, sort_keys=True),
    }
    if intensity.period is not None:
        ds.attrs["im_period"] = intensity.period
    ds = _add_record_use(ds, pipe, records, above, refused, left_out)
    spectrum, spectrum_attrs = _spectrum_variables(pipe, matches)
    if spectrum:
        ds = ds.assign_coords({k: xr.Variable(*v) for k, v in spectrum["coords"].items()})
        ds = ds.assign({k: xr.Variable(*v) for k, v in spectrum["data"].items()})
        ds.attrs.update(spectrum_attrs)
    clock.lap("fragility")
    if pipe.histories is not None:
        ds = _add_histories(ds, pipe, records, out_path, fingerprint, progress)
        clock.lap("histories")
    write_dataset(ds, out_path)
    store.remove()
    logger.info("wrote %s", out_path)
    ds = open_results(out_path)
    clock.lap("write")
    return ds


# --------------------------------------------------------------------------------------------
# time histories
# --------------------------------------------------------------------------------------------


def _add_histories(ds, pipe: Pipeline, records, out_path: Path, fingerprint: str,
                   progress: bool) -> xr.Dataset:
    """Write the requested time histories and list them in ``ds["history_file"]``."""
    design = pipe.design
    request = pipe.histories
    directory = request.directory or out_path.with_name(out_path.stem + "_histories")
    cases = request.select(ds, design)
    attrs = {"pipeline": pipe.text, "pipeline_source": str(pipe.source),
             "solver_options": json.dumps(pipe.solver, sort_keys=True),
             "im_display_units": pipe.im_display[0], "im_display_factor": pipe.im_display[1]}
    written = write_histories(design, records, cases, directory, pipe.solver, fingerprint,
                              attrs, progress)
    files = np.full(design.n_cases, "", dtype=object)
    for case, path in written.items():
        files[case] = Path(os.path.relpath(path, out_path.parent)).as_posix()
    shape = design.shape if design.intensity.scaled else (design.shape[0], *design.shape[2:])
    ds["history_file"] = xr.DataArray(
        files.reshape(shape), dims=design.dims,
        attrs={"units": "1", "long_name": "NetCDF file of the run's full time histories, "
                                          "relative to this file's folder (empty: none)"})
    ds.attrs["histories_directory"] = Path(os.path.relpath(directory, out_path.parent)).as_posix()
    logger.info("%d time histories in %s", len(written), directory)
    return ds


def rerun_case(path, record: str, *, im_level=None, im_level_g=None, **sweep):
    """Simulate one run of a pipeline again, with its full time histories.

    The record is read and processed as the pipeline does it and the run gets the same input,
    system and solver options as in the batch, so its summary equals the batch's bit for bit.

    Parameters
    ----------
    path : str or os.PathLike
        The pipeline file.
    record : str
        Record id (or its last part, e.g. ``"NP.1765"``).
    im_level, im_level_g : float, optional
        The IM level [SI units of the measure] or [g] (PGA, Sa); required if the design has
        several levels.
    **sweep
        Values of the swept parameters (each required if it has several values).

    Returns
    -------
    shipblock.SimulationResult

    Raises
    ------
    PipelineError
        If the pipeline is invalid or the selection names no single run (names the key).
    ShipblockError
        If the record cannot be read, processed or scaled.

    Examples
    --------
    >>> res = rerun_case("pipelines/demo.toml", "NP.1765", im_level_g=0.8)  # doctest: +SKIP
    >>> res.summary["peak_ship_slip"]  # doctest: +SKIP
    """
    return _rerun(path, record, im_level=im_level, im_level_g=im_level_g, **sweep)[1]


def _rerun(path, record, im_level=None, im_level_g=None, **sweep):
    """Run one case of a pipeline; returns ``(dataset of the run, result)``."""
    from shipblock.catalogue import load_catalogue

    pipe = load_pipeline(path)
    design = pipe.design
    selector = {"record": record, **sweep}
    if im_level is not None:
        selector["im_level"] = im_level
    if im_level_g is not None:
        selector["im_level_g"] = im_level_g
    try:
        case = case_number(design, selector)
    except SelectionError as exc:
        raise PipelineError(exc.key, exc.problem, pipe.source) from None
    r = int(design.case_indices([case])[0, 0])
    rid = design.records[r]
    records = [None] * len(design.records)
    records[r] = prepare_record(rid, _loader(load_catalogue(pipe.catalogue)[rid], pipe),
                                pipe.chain, design.intensity)
    _match_target_spectrum(pipe, records[r])
    result = run_case(design, records, case, pipe.solver)
    ds = case_dataset(result, design, records, case,
                      {"pipeline": pipe.text, "pipeline_source": str(pipe.source),
                       "solver_options": json.dumps(pipe.solver, sort_keys=True),
                       "im_display_units": pipe.im_display[0],
                       "im_display_factor": pipe.im_display[1]})
    return ds, result
