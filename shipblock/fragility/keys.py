"""The keys of a pipeline file, each declared once.

Every key of a pipeline file (:mod:`shipblock.fragility.schema`) is a
:class:`~shipblock.models.base.Field` here: name, type, unit, range or choices, default and a
one-line doc. From these declarations alone

* the file's tables are checked (:func:`check_table`: unknown keys, types, required keys) and
  each value is checked against its range when it is read (:func:`value`);
* every error is a :class:`PipelineError` that carries the key (:attr:`PipelineError.key`) as
  data: the key comes from the declaration, never from the text of a message;
* the documentation's table of keys is written (:func:`key_table`, rendered by the
  ``pipeline-keys`` directive of ``docs/conf.py`` at every build).

The ``[system]`` and ``[solver]`` tables belong to the study's model
(:attr:`Model.parameters <shipblock.models.base.Model.parameters>`,
:attr:`Model.options <shipblock.models.base.Model.options>`; ``[system] model`` names it) and
``[sweep]`` takes the model's :attr:`~shipblock.models.base.Model.sweep_parameters`: a new model
brings its own keys, with nothing to add here.

Adding a key: declare it in :data:`SECTIONS` (in the order the docs list it), read it in
:func:`shipblock.fragility.schema.parse_pipeline` with :func:`value`, and say in the docs what
changed for a user (``docs/contributing.rst``).
"""

from __future__ import annotations

from collections.abc import Mapping
from types import MappingProxyType

from shipblock.checks import MAX_AZIMUTH, MAX_PERIOD, MIN_PERIOD
from shipblock.errors import ShipblockError
from shipblock.fragility.batch import DEFAULT_CHUNK_SIZE
from shipblock.fragility.design import DESIGN_TYPES, IM_MEASURES, VERTICAL_MODES
from shipblock.fragility.fit import IDA_METHODS
from shipblock.intensity import DEFAULT_DAMPING
from shipblock.models import DEFAULT_MODEL, Field, FieldError, Model, get_model

__all__ = [
    "DEFAULT_BOOTSTRAP",
    "DEFAULT_CHUNK_SIZE",
    "DEFAULT_CONFIDENCE",
    "DEFAULT_MAX_HISTORIES",
    "DEFAULT_MAX_SCALE_FACTOR",
    "DEFAULT_SEED",
    "MATCH_MODES",
    "MODEL_KEY",
    "MAX_BOOTSTRAP",
    "MAX_CHUNK_SIZE",
    "MAX_HISTORIES",
    "MAX_RUNS",
    "MAX_SEED",
    "SCHEMA_VERSION",
    "SECTIONS",
    "PipelineError",
    "check_table",
    "key_table",
    "section_fields",
    "value",
]

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

#: Ways of matching a target spectrum (:data:`shipblock.scaling.MATCH_MODES`; written out so
#: that loading a pipeline does not import the processing stack).
MATCH_MODES = ("range", "anchor")


class PipelineError(ShipblockError, ValueError):
    """A pipeline file is invalid; the message names the file and the key.

    Parameters
    ----------
    key : str
        Dotted key of the problem, e.g. ``"design.levels_g"`` (``""`` for the whole file); also
        :attr:`field`.
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

    @property
    def field(self) -> str:
        """str: The key (as :attr:`shipblock.models.base.FieldError.field`)."""
        return self.key

    def __reduce__(self):
        """Keep the error picklable."""
        return (type(self), (self.key, self.problem, self.source))


def _f(name, types, doc, units="", **kw) -> Field:
    return Field(name, types, doc, units, **kw)


_LIST, _TABLE, _STR, _NUM, _INT, _BOOL = (list,), (dict,), (str,), (float,), (int,), (bool,)

#: Every key of a pipeline file but those of the model (``[system]``, ``[solver]``,
#: ``[sweep]``): section (``""`` for the top level, dotted for a nested table) -> name ->
#: declaration, in the order the docs list them.
SECTIONS: Mapping[str, Mapping[str, Field]] = MappingProxyType({name: MappingProxyType(
    {f.name: f for f in fields}) for name, fields in {
    "": (
        _f("schema_version", _INT, "layout version of the file", default=SCHEMA_VERSION),
        _f("title", _STR, "title of the study (stored with the results)"),
        _f("description", _STR, "free text"),
        _f("output", _STR, "NetCDF file of the results, relative to the pipeline file",
           required=True),
        _f("records", _TABLE, "the records and their component", required=True),
        _f("processing", _LIST, "the processing chain, one [[processing]] table a step "
           "(shipblock.processing)", default_doc="the default chain"),
        _f("system", _TABLE, "the model and its parameters", required=True),
        _f("sweep", _TABLE, "swept parameters of the model, one dimension each"),
        _f("design", _TABLE, "analysis type, intensity measure and levels", required=True),
        _f("limit_states", _LIST, "one [[limit_states]] table each (name, edp, threshold, "
           "condition, description)", required=True),
        _f("fit", _TABLE, "fragility fit"),
        _f("solver", _TABLE, "solver options of the model"),
        _f("execution", _TABLE, "chunks and Dask"),
        _f("histories", _TABLE, "runs whose full time histories are written"),
    ),
    "records": (
        _f("catalogue", _STR, "catalogue file, relative to the pipeline file",
           default_doc="the shipped records/catalogue.toml"),
        _f("ids", (str, list), "'all' or a list of catalogue ids, none repeated",
           required=True),
        _f("azimuth", _NUM, "dock transverse axis, clockwise from north (instead of "
           "horizontal)", "deg", low=-MAX_AZIMUTH, high=MAX_AZIMUTH),
        _f("horizontal", _STR, "one horizontal as recorded (instead of azimuth)",
           default="H1", choices=("H1", "H2")),
        _f("response", _STR, "instrument response: sensitivity only, or full removal",
           default="sensitivity", choices=("sensitivity", "full")),
        _f("strict", _BOOL, "fail if a record is left out or a run refused", default=False),
    ),
    "design": (
        _f("type", _STR, "incremental dynamic, multiple-stripe or cloud analysis",
           required=True, choices=DESIGN_TYPES),
        _f("measure", _STR, "intensity measure the records are scaled on", default="pga",
           choices=tuple(IM_MEASURES)),
        _f("period", _NUM, "oscillator period T1 of Sa (measure 'sa' only)", "s",
           low=MIN_PERIOD, high=MAX_PERIOD),
        _f("damping", _NUM, "damping ratio of Sa", "1", default=DEFAULT_DAMPING, low=0.0,
           high=1.0, high_open=True),
        _f("levels", _LIST, "IM levels in the unit 'units', strictly increasing",
           default_doc="none (or levels_g)"),
        _f("levels_g", _LIST, "IM levels in g (PGA, Sa), strictly increasing", "g",
           default_doc="none (or levels)"),
        _f("units", _STR, "unit of levels and vertical_levels ('m/s^2', 'g', 'm/s', "
           "'cm/s', ...)"),
        _f("vertical", _STR, "vertical component: scaled with the horizontal, to its own "
           "levels, unscaled, or dropped", default="same", choices=VERTICAL_MODES),
        _f("vertical_levels", _LIST, "levels of the vertical (vertical = 'independent'), in "
           "'units'"),
        _f("vertical_levels_g", _LIST, "levels of the vertical (vertical = 'independent')",
           "g"),
        _f("cloud_method", _STR, "cloud fit: probit on the exceedance, or regression of "
           "ln EDP on ln IM", default="probit", choices=("probit", "regression")),
        _f("stripes", _LIST, "msa only: the records of each level, one list per level",
           default_doc="every record at every level"),
        _f("max_scale_factor", _NUM, "largest scale factor made without a warning", "1",
           default=DEFAULT_MAX_SCALE_FACTOR, low=1.0),
        _f("scale_factor_policy", _STR, "runs scaled by more: made and reported, or not made",
           default="warn", choices=("warn", "refuse")),
        _f("target_spectrum", _TABLE, "scale to a target spectrum (ida/msa on 'sa')"),
    ),
    "design.target_spectrum": (
        _f("file", _STR, "two columns: period [s], Sa [units]", required=True),
        _f("units", _STR, "unit of the Sa column", required=True),
        _f("period_range", _LIST, "[T_a, T_b] with 0 < T_a < T_b", "s", required=True),
        _f("match", _STR, "least squares in ln Sa over the range, or Sa(T1) anchored",
           default="range", choices=MATCH_MODES),
    ),
    "fit": (
        _f("bootstrap", _INT, "bootstrap resamples over records (0: no bounds)",
           default=DEFAULT_BOOTSTRAP, low=0, high=MAX_BOOTSTRAP),
        _f("confidence", _NUM, "confidence level of the bootstrap bounds", "1",
           default=DEFAULT_CONFIDENCE, low=0.0, high=1.0, low_open=True, high_open=True),
        _f("seed", _INT, "seed of the bootstrap", default=DEFAULT_SEED, low=0, high=MAX_SEED),
        _f("ida_method", _STR, "IDA fit: capacity between the last level held and the first "
           "failed, or the first failed level", default="interval", choices=IDA_METHODS),
    ),
    "execution": (
        _f("chunk_size", _INT, "cases per chunk (part of the run's identity)",
           default=DEFAULT_CHUNK_SIZE, low=1, high=MAX_CHUNK_SIZE),
        _f("scheduler", _STR, "address of a Dask scheduler, e.g. 'tcp://host:8786'",
           default_doc="none: run here"),
    ),
    "histories": (
        _f("runs", _LIST, "selectors {record = ..., im_level[_g] = ..., <swept> = ...}"),
        _f("exceeding", _LIST, "and every run exceeding one of these limit states"),
        _f("max_runs", _INT, "at most this many files (selectors first)",
           default=DEFAULT_MAX_HISTORIES, low=1, high=MAX_HISTORIES),
        _f("directory", _STR, "folder of the files, relative to the pipeline file",
           default_doc="<output stem>_histories/ beside the output"),
    ),
}.items()})

#: The ``[system] model`` key (the parameters that follow are the model's).
MODEL_KEY = Field("model", _STR, "the model: one registered with shipblock.models", "",
                  default=DEFAULT_MODEL)


def section_fields(section: str, model: Model | None = None) -> Mapping[str, Field]:
    """The declarations of one table of a pipeline file.

    Parameters
    ----------
    section : str
        ``""`` (top level), ``"records"``, ``"system"``, ``"design.target_spectrum"``...
    model : shipblock.models.Model, optional
        The study's model, whose parameters are the ``[system]`` keys and whose options are
        the ``[solver]`` keys (default: the rigid model).

    Returns
    -------
    Mapping[str, Field]
    """
    model = get_model(DEFAULT_MODEL) if model is None else model
    if section == "system":
        return {"model": MODEL_KEY, **model.parameters}
    if section == "solver":
        return dict(model.options)
    if section == "sweep":
        return {name: Field(name, _LIST, f"values of {long_name}", units)
                for name, (units, long_name) in model.sweep_parameters.items()}
    return SECTIONS[section]


def check_table(table: Mapping, section: str, source: str, model: Model | None = None) -> None:
    """Unknown keys, types and required keys of one table, against its declarations.

    Raises
    ------
    PipelineError
        Naming the key: ``unknown key ...; allowed keys: ...``, ``must be a number, got
        ...``, ``missing required key ...`` (``section`` for a table of the top level); a key
        with a control character (a swept parameter ``"a\x00"``) names the section.
    """
    declared = section_fields(section, model)
    for key, given in table.items():
        if not key.isprintable():
            raise PipelineError(section, f"key {key!r} holds a control or other non-printable "
                                f"character; allowed keys: {', '.join(declared) or 'none'}",
                                source)
        dotted = f"{section}.{key}" if section else key
        if key not in declared:
            raise PipelineError(
                dotted, f"unknown key {key!r}; allowed keys: {', '.join(declared) or 'none'}",
                source
            )
        try:
            declared[key].check_type(given, dotted)
        except FieldError as exc:
            raise PipelineError(exc.field, exc.problem, source) from None
    for key, field in declared.items():
        if field.required and key not in table:
            dotted = f"{section}.{key}" if section else key
            what = "section" if not section and field.types in (_TABLE, _LIST) else "key"
            raise PipelineError(dotted, f"missing required {what} {key!r}", source)


def value(table: Mapping, section: str, key: str, source: str, model: Model | None = None):
    """``table[key]`` (or its default) checked against its declaration.

    Returns
    -------
    object
        The value (a number as the declared ``int`` or ``float``), or the default (None
        when the key has none).

    Raises
    ------
    PipelineError
        Naming ``section.key``: a value outside its range or not among its choices.
    """
    field = section_fields(section, model)[key]
    given = table.get(key, field.default)
    if given is None:
        return None
    try:
        return field.check(given, f"{section}.{key}" if section else key)
    except FieldError as exc:
        raise PipelineError(exc.field, exc.problem, source) from None


def key_table(model: Model | str | None = None, sections=None) -> str:
    """The table of every key, as reStructuredText (a ``list-table``).

    Parameters
    ----------
    model : shipblock.models.Model or str, optional
        Whose ``[system]``, ``[solver]`` and ``[sweep]`` keys to list (default: the rigid
        model).
    sections : sequence of str, optional
        Only these sections (e.g. ``("system", "sweep", "solver")``: a model's keys); default
        all.

    Returns
    -------
    str
        Columns: key, type, unit, range or choices, default, description.
    """
    model = get_model(model) if isinstance(model, str) else model
    model = get_model(DEFAULT_MODEL) if model is None else model
    lines = [".. list-table::", "   :header-rows: 1", "   :widths: 22 10 8 20 15 35", "",
             "   * - Key", "     - Type", "     - Unit", "     - Range / choices",
             "     - Default", "     - Description"]
    order = ["", "records", "system", "sweep", "design", "design.target_spectrum", "fit",
             "solver", "execution", "histories"]
    for section in order if sections is None else [o for o in order if o in sections]:
        for name, field in section_fields(section, model).items():
            key = f"{section}.{name}" if section else name
            kind = " or ".join({int: "integer", float: "number", str: "string", list: "list",
                                dict: "table", bool: "boolean"}[t] for t in field.types)
            text = field.range_text(with_units=False).replace("*", r"\*")
            cells = (f"``{key}``", kind, field.units or "", text, field.default_text(),
                     field.doc.replace("*", r"\*"))
            lines.append(f"   * - {cells[0]}")
            lines += [f"     - {c}" if c else "     -" for c in cells[1:]]
    return "\n".join(lines) + "\n"

