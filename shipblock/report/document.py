"""The content of a study's report, once, as blocks that :mod:`~shipblock.report.html` and
:mod:`~shipblock.report.pdf` render.

:func:`report_document` turns a result of :func:`~shipblock.fragility.pipeline.run_pipeline`
(and, when there is one, the risk :func:`~shipblock.risk.study.run_risk` added to it) into a
list of blocks (:class:`Heading`, :class:`Paragraph`, :class:`Table`, :class:`Preformatted`,
:class:`Figure`, :class:`Links`), in the order a dock engineer reads them:

1. the study: pipeline title and file, design, the system's parameters with their units, the
   processing chain and the solver options, all read from the result's attributes (the system
   as stored, whatever the model: no system object is built);
2. the records: id, station, channel, event, scale factors, whether each was used and, if not,
   why; with a target spectrum (the study's own match, or ``target=``), each record's spectrum
   against it;
3. the limit-state definitions;
4. the fitted fragility curves with their bootstrap bands (the figures of
   :mod:`shipblock.plot`, titled with study, system and design) and the summary lines
   ``shipblock run`` prints (:func:`shipblock.fragility.report.study_report`);
5. the risk over the docking period (:mod:`shipblock.plot_risk`) when the file holds it;
6. the CSV tables written beside the report.

Every value is the file's (SI inside, shown in the pipeline's unit for intensities), nothing is
fitted again. Figures are blocks holding a function that draws them, so a renderer makes one
figure at a time.
"""

from __future__ import annotations

import json
import textwrap
import tomllib
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np
import xarray as xr

from shipblock import __version__
from shipblock.errors import ParameterError
from shipblock.fragility.report import display_units, im_label, study_report
from shipblock.fragility.store import dataset_model
from shipblock.plot import (
    TITLE_WIDTH,
    default_edp,
    limit_state_text,
    plot_fragility,
    plot_ida,
    plot_median_sweep,
    study_caption,
    sweep_selection,
    sweep_text,
)
from shipblock.plot.study import failures_text
from shipblock.plot_risk import plot_risk
from shipblock.risk.study import risk_lines
from shipblock.scaling import TargetSpectrum, spectrum_match
from shipblock.units import STANDARD_GRAVITY

__all__ = ["RISK", "Figure", "Heading", "Links", "Paragraph", "Preformatted", "Table",
           "check_study", "record_spectra", "report_document", "study_spectra"]

#: The variable ``shipblock risk`` adds to a result (the others go with it).
RISK = "risk_annual_rate"


# ------------------------------------------------------------------------------ blocks
@dataclass(frozen=True)
class Heading:
    """A heading: level 1 the report's title, 2 a section, 3 a part of one."""

    text: str
    level: int = 2


@dataclass(frozen=True)
class Paragraph:
    """Running text; with ``small`` the fine print under the title. Text between backquotes
    is a command or a flag (``<code>`` in HTML); ``lines`` are kept apart (a line break)."""

    lines: tuple[str, ...]
    small: bool = False


@dataclass(frozen=True)
class Table:
    """A table of text cells; ``keys``: a two-column list of names and values, no header."""

    header: tuple[str, ...]
    rows: tuple[tuple[str, ...], ...]
    keys: bool = False


@dataclass(frozen=True)
class Preformatted:
    """Text shown as is (monospaced), under a ``summary`` when it may be folded away."""

    text: str
    summary: str = ""


@dataclass(frozen=True)
class Figure:
    """A figure: ``draw()`` makes it (a new matplotlib figure, closed by the renderer)."""

    draw: Callable[[], object] = field(compare=False)
    alt: str = ""


@dataclass(frozen=True)
class Links:
    """Files written beside the report: name -> path relative to the report."""

    items: tuple[tuple[str, str], ...]


def _p(*lines, small=False) -> Paragraph:
    return Paragraph(tuple(str(x) for x in lines), small)


def _t(header, rows, keys=False) -> Table:
    return Table(tuple(str(h) for h in header), tuple(tuple(str(c) for c in r) for r in rows),
                 keys)


def check_study(ds: xr.Dataset, name: str) -> None:
    """Refuse a dataset that is not the result of a study, naming ``name``.

    Raises
    ------
    ParameterError
        If ``ds`` lacks the fitted curves (``median`` on ``limit_state``) or the pipeline's
        attributes (``pipeline``, ``system``): e.g. a simulation's response or a history file.
    """
    if "median" not in ds or "limit_state" not in ds.dims:
        what = ("a simulation's response (draw it with 'shipblock plot')"
                if "time" in ds.dims else "no fitted fragility (variable 'median')")
        raise ParameterError(f"{name}: not the result of a study ('shipblock run'): {what}")
    missing = [a for a in ("pipeline", "system", "design_type") if a not in ds.attrs]
    if missing:
        raise ParameterError(f"{name}: a study result without the attribute(s) "
                             f"{', '.join(missing)}: written by another program or version")


# ------------------------------------------------------------------------------ text helpers
def _number(value) -> str:
    if isinstance(value, bool) or value is None:
        return str(value).lower() if isinstance(value, bool) else "default"
    if isinstance(value, int | np.integer):
        return str(value)  # a seed, a count: every digit
    if isinstance(value, float | np.floating):
        return f"{value:g}"
    if isinstance(value, list | tuple):
        return ", ".join(_number(v) for v in value)
    return str(value)


#: Width of the study figures [in], whose titles :data:`TITLE_WIDTH` characters fill.
_STUDY_FIGURE_WIDTH = 9.0


def _wrapped(lines, figure_width: float = _STUDY_FIGURE_WIDTH) -> str:
    """A figure title: ``lines`` wrapped to the study figures' width (:data:`TITLE_WIDTH`
    characters on a figure of theirs), shortened in proportion on a narrower figure."""
    width = int(TITLE_WIDTH * min(1.0, figure_width / _STUDY_FIGURE_WIDTH))
    return "\n".join(w for line in lines
                     for w in textwrap.wrap(line, width, break_on_hyphens=False))


def _pipeline_document(ds) -> dict:
    try:
        return tomllib.loads(str(ds.attrs.get("pipeline", "")))
    except tomllib.TOMLDecodeError:
        return {}


def _model(ds):
    return dataset_model(ds)


# ------------------------------------------------------------------------------ sections
def _study_section(ds, name) -> list:
    unit, factor = display_units(ds)
    rows = [("title", ds.attrs.get("title", "")),
            ("pipeline file", ds.attrs.get("pipeline_source", "")),
            ("results file", name),
            ("created", ds.attrs.get("created", "")),
            ("shipblock version", ds.attrs.get("shipblock_version", "")),
            ("pipeline fingerprint", ds.attrs.get("pipeline_fingerprint", ""))]
    out = [Heading("1. Study"), _t(["", ""], rows, keys=True)]
    design = [("analysis", {"ida": "incremental dynamic analysis (IDA)",
                            "msa": "multiple stripe analysis (MSA)",
                            "cloud": "cloud (records at their own intensity)"}.get(
                                ds.attrs["design_type"], ds.attrs["design_type"])),
              ("intensity measure", f"{im_label(ds)}: {ds.attrs.get('im_long_name', '')}")]
    if "im_period" in ds.attrs:
        design.append(("period, damping", f"{float(ds.attrs['im_period']):g} s, "
                                          f"{100 * float(ds.attrs.get('im_damping', 0.05)):g} %"))
    if "im_level" in ds.coords:
        design.append((f"levels [{unit}]", ", ".join(f"{v / factor:.3g}"
                                                     for v in ds["im_level"].values)))
    design += [("records", str(ds.attrs.get("records_used", ds.sizes["record"]))),
               ("horizontal component", ds.attrs.get("component", "")),
               ("vertical", ds.attrs.get("vertical_mode", "")),
               ("catalogue", ds.attrs.get("catalogue", ""))]
    if "max_scale_factor" in ds.attrs:
        design.append(("max_scale_factor", f"{float(ds.attrs['max_scale_factor']):g} "
                       f"(policy {ds.attrs.get('scale_factor_policy', 'warn')!r})"))
    fit = json.loads(ds.attrs.get("fit_options", "{}"))
    if fit:
        design.append(("fit options", ", ".join(f"{k} = {_number(v)}" for k, v in fit.items())))
    out += [Heading("Design", 3), _t(["", ""], design, keys=True)]
    out += _system_blocks(ds)
    chain = json.loads(ds.attrs.get("processing_chain", "[]"))
    out.append(Heading("Processing chain", 3))
    out.append(_p("Applied to every record, in this order, before scaling." if chain else
                  "None: the records as read."))
    if chain:
        out.append(_t(["#", "step", "parameters"], [
            (i + 1, step.get("step", ""), ", ".join(f"{k} = {_number(v)}" for k, v in
                                                    step.items() if k != "step"))
            for i, step in enumerate(chain)]))
    out += _solver_blocks(ds)
    out.append(Preformatted(str(ds.attrs.get("pipeline", "")), "The pipeline file as run"))
    return out


def _system_blocks(ds) -> list:
    """The system as the result stores it (attribute ``system``), with the units and meaning
    of each parameter from the model's description: no system object is built."""
    system = json.loads(ds.attrs["system"])
    model = _model(ds)
    fields = model.parameters if model is not None else {}
    rows = []
    for key, value in system.items():
        spec = fields.get(key)
        units = spec.units if spec is not None else ""
        rows.append((key, _number(value), "-" if units in ("", "1") else units,
                     spec.doc if spec is not None else ""))
    out = [Heading("System", 3),
           _p(f"Model {model.name if model else '?'}: "
              f"{model.description if model else 'not installed here'}. "
              "None: the model's default (see the description)."),
           _t(["parameter", "value", "unit", "what"], rows)]
    sweep = json.loads(ds.attrs.get("sweep", "{}"))
    if sweep:
        out.append(_p("Swept (one fragility per combination):"))
        out.append(_t(["parameter", "values"],
                      [(k, ", ".join(_number(x) for x in v)) for k, v in sweep.items()]))
    return out


def _solver_blocks(ds) -> list:
    options = json.loads(ds.attrs.get("solver_options", "{}"))
    model = _model(ds)
    fields = model.options if model is not None else {}
    rows = [(k, _number(v), "-" if (f := fields.get(k)) is None or f.units in ("", "1")
             else f.units, f.doc if f is not None else "") for k, v in options.items()]
    return [Heading("Solver options", 3), _t(["option", "value", "unit", "what"], rows)]


def _records_table(ds, spectra) -> Table:
    provenance = json.loads(ds.attrs.get("records_provenance", "{}"))
    unit, factor = display_units(ds)
    header = ["record", "station", "site", "horizontal", "event", "scale factors",
              f"{im_label(ds).rsplit(' [', 1)[0]} as processed [{unit}]", "used"]
    if spectra:
        header.insert(-1, "spectrum misfit [-]")
    rows = []
    for i, rid in enumerate(ds["record"].values):
        rid = str(rid)
        md = provenance.get(rid, {})
        station = md.get("station") or {}
        code = ".".join(str(station.get(k, "")) for k in ("network", "station")).strip(".")
        channel = str(md.get("horizontal") or "")
        if channel in (md.get("channels") or {}):
            channel = f"{channel} = {md['channels'][channel]}"
        event = md.get("event") or {}
        when = str(event.get("time") or "")[:19].replace("T", " ")
        if when and event.get("magnitude") is not None:
            when += f" UTC, M {float(event['magnitude']):.3g}"
        factors = ""
        if "scale_factor" in ds:
            f = np.abs(ds["scale_factor"].isel(record=i).values)
            f = f[np.isfinite(f)]
            factors = (f"{f.min():.3g} to {f.max():.3g}" if f.size > 1 and f.min() != f.max()
                       else f"{f[0]:.3g}" if f.size else "-")
        im = float(ds["record_im"].values[i]) / factor if "record_im" in ds else np.nan
        used = bool(ds["record_used"].values[i]) if "record_used" in ds else True
        why = str(ds["record_error"].values[i]) if "record_error" in ds else ""
        row = [rid, code, (md.get("catalogue") or {}).get("site", ""), channel, when, factors,
               f"{im:.3g}" if np.isfinite(im) else "-",
               "yes" if used else f"left out: {why or 'see records_used'}"]
        if spectra:
            match = spectra["matches"].get(rid)
            row.insert(-1, f"{match['misfit']:.3g}" if isinstance(match, dict) else
                       f"not matched: {match}" if match else "-")
        rows.append(row)
    return _t(header, rows)


# ------------------------------------------------------------------------------ spectra
def study_spectra(ds: xr.Dataset) -> dict:
    r"""The records' spectra against the target a study was scaled to, from the file.

    The study stored each record's spectrum as processed (``record_sa``) and the target as
    given (``target_sa``) on the matching periods. Each record is drawn scaled to the target as
    given, by the factor the study's own scale factors imply at every level: for
    ``match = "range"`` the least-squares factor in ln Sa, :math:`\ln f = \frac1n \sum_i
    \ln(S^*_i / S_i)`; for ``"anchor"``, :math:`f = S^*(T_1) / S(T_1)` (``record_im``), the
    target interpolated in (ln T, ln Sa) as :class:`~shipblock.scaling.TargetSpectrum` does.

    Parameters
    ----------
    ds : xarray.Dataset
        A study with ``[design.target_spectrum]`` (variables ``record_sa``, ``target_sa``,
        ``spectrum_misfit``).

    Returns
    -------
    dict
        As :func:`record_spectra`.
    """
    periods = ds["spectrum_period"].values
    target = ds["target_sa"].values
    t1 = float(ds.attrs.get("im_period", np.nan))
    matches = {}
    for i, rid in enumerate(ds["record"].values):
        sa = ds["record_sa"].values[i]
        if not np.all(np.isfinite(sa)):
            matches[str(rid)] = str(ds["record_error"].values[i]) if "record_error" in ds else ""
            continue
        if ds.attrs.get("target_spectrum_match") == "anchor" and periods[0] <= t1 <= periods[-1]:
            # Sa(T1) of the record equals the target's there
            at_t1 = np.exp(np.interp(np.log(t1), np.log(periods), np.log(target)))
            factor = at_t1 / float(ds["record_im"].values[i])
        else:  # least squares in ln Sa over the range (scaling.spectrum_match, "range")
            factor = float(np.exp(np.mean(np.log(target / sa))))
        matches[str(rid)] = {"factor": factor, "sa": sa,
                             "misfit": float(ds["spectrum_misfit"].values[i])}
    lo, hi = ds.attrs["target_spectrum_period_range"]
    return {"periods": periods, "target": target, "matches": matches,
            "source": str(ds.attrs.get("target_spectrum_file", "")),
            "how": (f"the study's match ({ds.attrs.get('target_spectrum_match')!r}) over "
                    f"{float(lo):g} to {float(hi):g} s")}


def record_spectra(ds: xr.Dataset, target: TargetSpectrum, period_range=None) -> dict:
    r"""Each record of a study read and processed again, and matched to a target spectrum.

    The records are read from the study's catalogue with its component (or azimuth) and
    response option, processed with its chain, and their 5 %-damped spectra (the study's
    damping) matched to ``target`` by :func:`shipblock.scaling.spectrum_match` in its
    ``"range"`` mode: the factor :math:`f` minimising the squared log residuals over
    ``period_range``, :math:`\ln f = \frac1n\sum_i \ln(S^*_i / S_i)`, and the RMS of the
    residuals as the misfit.

    Parameters
    ----------
    ds : xarray.Dataset
        A study result.
    target : TargetSpectrum
        [m/s^2].
    period_range : (float, float), optional
        [s]; default the target's own periods.

    Returns
    -------
    dict
        ``periods`` [s], ``target`` [m/s^2], ``matches`` (record id -> ``{"factor", "sa",
        "misfit"}``, or the reason it could not be read), ``source`` and ``how``.

    Raises
    ------
    ParameterError
        If ``period_range`` is not two increasing positive periods.
    TargetSpectrumError
        If the target does not cover ``period_range`` (naming the target's file and range).
    """
    # the records' stack (obspy) is needed only here
    from shipblock.processing import process_motion
    from shipblock.records.catalogue import load_catalogue

    lo, hi = period_range if period_range is not None else (target.periods[0], target.periods[-1])
    if not 0 < lo < hi:
        raise ParameterError(f"period_range must be (T_a, T_b) with 0 < T_a < T_b [s], got "
                             f"({lo:g}, {hi:g})")
    target.at([lo, hi])  # a range beyond the target's is refused before any record is read
    document = _pipeline_document(ds)
    records = document.get("records", {})
    kwargs = {"response": records["response"]} if "response" in records else {}
    if "azimuth" in records:
        kwargs["azimuth"] = float(records["azimuth"])
    else:
        kwargs["horizontal"] = str(records.get("horizontal", ds.attrs.get("component", "H1")))
    catalogue_path = str(ds.attrs.get("catalogue", ""))
    entries = load_catalogue(None if catalogue_path.startswith("shipped ") else catalogue_path)
    chain = json.loads(ds.attrs.get("processing_chain", "null"))
    matches, periods = {}, None
    for rid in (str(r) for r in ds["record"].values):
        try:
            motion = entries[rid].read(**kwargs)
            if chain:
                motion = process_motion(motion, chain)
            m = spectrum_match(motion.horizontal, motion.dt, target, (lo, hi), mode="range",
                               damping=float(ds.attrs.get("im_damping", 0.05)))
        except (KeyError, ValueError, OSError) as exc:
            matches[rid] = f"{type(exc).__name__}: {exc}"
            continue
        periods = m.periods
        matches[rid] = {"factor": m.factor, "sa": m.sa_record, "misfit": m.misfit}
    if periods is None:
        periods = np.geomspace(lo, hi, 40)
    return {"periods": periods, "target": target.at(periods), "matches": matches,
            "source": str(target.source),
            "how": f"each record scaled by its least-squares factor over {lo:g} to {hi:g} s"}


def _spectra_figure(ds, spectra):
    fig, ax = plt.subplots(figsize=(9.0, 5.0), constrained_layout=True)
    periods = spectra["periods"]
    scaled = []
    for i, (rid, m) in enumerate(spectra["matches"].items()):
        if not isinstance(m, dict):
            continue
        sa = m["factor"] * m["sa"]
        scaled.append(sa)
        ax.plot(periods, sa / STANDARD_GRAVITY, color=f"C{i % 10}", lw=1.0, alpha=0.8,
                label=f"{rid.split('/')[-1]} x {m['factor']:.3g}")
    if scaled:
        ax.plot(periods, np.exp(np.mean(np.log(scaled), axis=0)) / STANDARD_GRAVITY, "k--",
                lw=1.8, label="geometric mean of the records")
    ax.plot(periods, spectra["target"] / STANDARD_GRAVITY, "k-", lw=2.6, label="target")
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("period T [s]")
    ax.set_ylabel(f"Sa [g], {100 * float(ds.attrs.get('im_damping', 0.05)):g} % damping")
    ax.grid(True, which="both", lw=0.3, alpha=0.5)
    ax.legend(fontsize=7.5, ncol=2)
    what = (f"spectra of the processed records against the target "
            f"{Path(spectra['source']).name}: {spectra['how']}")
    ax.set_title(_wrapped([*study_caption(ds), what]), fontsize=8.5, loc="left")
    return fig


# ------------------------------------------------------------------------------ fragility, risk
def _limit_states_section(ds) -> list:
    definitions = {d["name"]: d for d in json.loads(ds.attrs.get("limit_states", "[]"))}
    rows = []
    for name in (str(n) for n in ds["limit_state"].values):
        d = definitions.get(name, {})
        edp = d.get("edp", "")
        long_name = ds[edp].attrs.get("long_name", "") if edp in ds else ""
        rows.append((name, limit_state_text(ds, name), long_name, d.get("description", "")))
    return [Heading("3. Limit states"),
            _p("A run exceeds a limit state when its demand meets the condition; a run that "
               f"failed ({failures_text(ds)}) exceeds every response limit state."),
            _t(["limit state", "definition", "demand parameter", "description"], rows)]


def _fit_table(ds) -> Table:
    unit, factor = display_units(ds)
    sweep = [d for d in ds["median"].dims if d != "limit_state"]
    conf = ds["median_lower"].attrs.get("confidence") if "median_lower" in ds else None
    band = f"{100 * float(conf):g} % band" if conf is not None else "band"
    header = ["limit state", *sweep, f"median [{unit}]", f"median {band}", "beta",
              f"beta {band}", "records", "method", "note"]
    rows = []
    for index in np.ndindex(ds["median"].shape):
        def at(var, index=index):
            return ds[var].values[index] if var in ds else np.nan
        median = float(at("median")) / factor
        lo, hi = float(at("median_lower")) / factor, float(at("median_upper")) / factor
        blo, bhi = float(at("beta_lower")), float(at("beta_upper"))
        coords = [_number(ds[d].values[i]) for d, i in zip(sweep, index[1:], strict=True)]
        fitted = np.isfinite(median)
        rows.append([str(ds["limit_state"].values[index[0]]), *coords,
                     f"{median:.3g}" if fitted else "not fitted",
                     f"{lo:.3g} to {hi:.3g}" if np.isfinite(lo) and np.isfinite(hi) else "-",
                     f"{float(at('beta')):.3f}" if fitted else "-",
                     f"{blo:.3f} to {bhi:.3f}" if np.isfinite(blo) and np.isfinite(bhi) else "-",
                     f"{int(at('n_fit_records'))}" if np.isfinite(at("n_fit_records")) else "-",
                     str(at("fit_method")) if "fit_method" in ds else "",
                     str(at("fit_error")) if "fit_error" in ds else ""])
    return _t(header, rows)


def _arrangements(ds) -> list[dict]:
    """The swept values a figure is drawn at: the first of each parameter, then each other
    value of each parameter with the rest at their first ([{}] without a sweep)."""
    first = sweep_selection(ds)
    combos = [first]
    for dim in first:
        combos += [{**first, dim: v} for v in ds[dim].values[1:]]
    return combos


def _fragility_section(ds) -> list:
    out = [Heading("4. Fragility"),
           _p("Lognormal fragility curves, median and dispersion beta, with the bootstrap band "
              "over the records (the values of the results file)."), _fit_table(ds)]
    lines = study_report(ds)
    if lines:
        out += [_p("What `shipblock run` said:"), Preformatted("\n".join(lines))]
    sweep = sweep_selection(ds)
    for combo in _arrangements(ds):
        out.append(Figure(lambda combo=combo: plot_fragility(ds, sweep=combo).figure,
                          "fragility curves" + (f" at {sweep_text(combo, ds)}" if combo else "")))
    for dim in sweep:
        out.append(Figure(lambda dim=dim: plot_median_sweep(ds, dim, sweep=sweep).figure,
                          f"median against {dim}"))
    if "im_level" in ds.coords and default_edp(ds) in ds:
        out.append(Figure(lambda: plot_ida(ds, sweep=sweep).figure, "IDA curves"))
    return out


def _risk_figure(ds, selection, days):
    fig = plot_risk(ds, sweep=selection)[0].figure
    # the figure's title with the study, system and design, as the study figures have
    fig.suptitle(_wrapped([*study_caption(ds, selection),
                           f"risk over a docking period of {days:g} days"
                           + (f", drawn at {sweep_text(selection, ds)}" if selection else "")],
                          fig.get_figwidth()), fontsize=8.5, x=0.01, ha="left")
    return fig


def _risk_section(ds) -> list:
    days = float(ds.attrs["docking_days"])
    sweep = [d for d in ds[RISK].dims if d != "limit_state"]
    banded = f"{RISK}_lower" in ds

    def value(name, index):
        v = float(ds[name].values[index])
        if banded and f"{name}_lower" in ds:
            lo, hi = float(ds[f"{name}_lower"].values[index]), float(ds[f"{name}_upper"].values[index])
            if np.isfinite(lo) and np.isfinite(hi):
                return f"{v:.3g} ({lo:.3g} to {hi:.3g})"
        return f"{v:.3g}" if np.isfinite(v) else "not fitted"

    rows = []
    for index in np.ndindex(ds[RISK].shape):
        rate = float(ds[RISK].values[index])
        rows.append([str(ds["limit_state"].values[index[0]]),
                     *(_number(ds[d].values[i]) for d, i in zip(sweep, index[1:], strict=True)),
                     value(RISK, index), f"{1 / rate:.4g}" if rate > 0 else "-",
                     value("risk_probability", index),
                     f"{float(ds['risk_tail_fraction'].values[index]):.1%}"
                     if "risk_tail_fraction" in ds and rate > 0 else "-"])
    header = ["limit state", *sweep, "annual rate [1/yr]", "return period [yr]",
              f"P({days:g} d) [-]", "from beyond the curve"]
    out = [Heading("5. Risk over the docking period"),
           _p(f"Each fitted fragility convolved with the site hazard curve; probability of at "
              f"least one exceedance during {days:g} days in the dock (Poisson). "
              + (f"In brackets: {float(ds[f'{RISK}_lower'].attrs['confidence']):.0%} bootstrap "
                 "band." if banded else
                 f"No bootstrap band ({ds.attrs.get('risk_band', '')}).")),
           Preformatted(risk_lines(ds)[0]), _t(header, rows)]
    for selection in _arrangements(ds):
        where = f" at {sweep_text(selection, ds)}" if selection else ""
        if not np.isfinite(ds[RISK].sel(selection).values).any():
            out.append(_p(f"No figure{where}: no limit state was fitted there."))
            continue
        out.append(Figure(lambda selection=selection: _risk_figure(ds, selection, days),
                          "hazard, fragilities and deaggregation" + where))
    return out


# ------------------------------------------------------------------------------ the document
def report_document(ds: xr.Dataset, *, name: str = "results", spectra: Mapping | None = None,
                    tables: Mapping[str, str] | None = None) -> list:
    """The report of a study result as blocks, for :func:`shipblock.report.html.report_html` and
    :func:`shipblock.report.pdf.write_pdf`.

    Parameters
    ----------
    ds : xarray.Dataset
        A study result (:func:`check_study`), with the risk variables of
        :func:`~shipblock.risk.study.risk_dataset` or without.
    name : str
        The results file, as the report names it.
    spectra : mapping, optional
        Records' spectra against a target (:func:`record_spectra`, or the study's own match).
    tables : mapping of str to str, optional
        CSV table name -> its path relative to the report.

    Returns
    -------
    list
        :class:`Heading`, :class:`Paragraph`, :class:`Table`, :class:`Preformatted`,
        :class:`Figure` and :class:`Links` blocks, in reading order; the first is the title.
    """
    check_study(ds, name)
    title = str(ds.attrs.get("title", "shipblock study"))
    blocks = [Heading(title, 1), _p(*study_caption(ds), small=True),
              _p(f"Report of {name} by shipblock {__version__}.", small=True),
              *_study_section(ds, name), Heading("2. Records"),
              _p(ds.attrs.get("records_used", "")), _records_table(ds, spectra)]
    if spectra:
        blocks.append(Figure(lambda: _spectra_figure(ds, spectra), "spectra against the target"))
    else:
        blocks.append(_p("No target spectrum: the study matched none and none was given "
                         "(`--target`)."))
    blocks += [*_limit_states_section(ds), *_fragility_section(ds)]
    if RISK in ds:
        blocks += _risk_section(ds)
    else:
        blocks += [Heading("5. Risk over the docking period"),
                   _p("Not computed: make it with `shipblock risk` and pass the file with "
                      "`--hazard-results`.")]
    if tables:
        blocks += [Heading("6. Tables"), _p("The results as CSV, every column with its unit:"),
                   Links(tuple(tables.items()))]
    return blocks
