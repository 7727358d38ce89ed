"""A study's report: one self-contained HTML file, with its tables as CSV beside it.

:func:`write_report` (``shipblock report results.nc -o report.html``) turns a result of
:func:`~shipblock.fragility.pipeline.run_pipeline` (and, when there is one, the risk
:func:`~shipblock.risk.study.run_risk` added to it) into a document a dock engineer can file:

1. the study: pipeline title and file, design, the system's parameters with their units, the
   processing chain and the solver options, all read from the result's attributes;
2. the records: id, station, channel, event, scale factors, whether each was used and, if not,
   why; with a target spectrum (the study's own match, or ``target=``), each record's spectrum
   against it;
3. the limit-state definitions;
4. the fitted fragility curves with their bootstrap bands (the figures of
   :mod:`shipblock.plot`, titled with study, system and design) and the summary lines
   ``shipblock run`` prints (:func:`shipblock.fragility.report.study_report`);
5. the risk over the docking period (:mod:`shipblock.plot_risk`) when the file holds it.

Figures are embedded as base64 PNG: the file opens anywhere, without network or the files it
came from. Every value is the file's (SI inside, shown in the pipeline's unit for intensities),
nothing is fitted again; the tables go to ``<report>_csv/`` through
:func:`shipblock.fragility.export.write_csv`, the risk columns with them when there is a risk.
"""

from __future__ import annotations

import base64
import html
import io
import json
import textwrap
import tomllib
from collections.abc import Mapping
from pathlib import Path

import matplotlib
import matplotlib.pyplot as plt
import numpy as np
import xarray as xr

from shipblock import __version__
from shipblock.errors import ParameterError
from shipblock.fragility.export import write_csv
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

__all__ = ["check_study", "record_spectra", "report_html", "study_spectra", "write_report"]

#: The risk variables ``shipblock risk`` adds to a result.
_RISK = "risk_annual_rate"


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
def _e(value) -> str:
    return html.escape(str(value), quote=True)


def _table(header, rows, cls="") -> str:
    head = "".join(f"<th>{_e(h)}</th>" for h in header)
    body = "".join("<tr>" + "".join(f"<td>{_e(c)}</td>" for c in row) + "</tr>" for row in rows)
    return f'<table class="{cls}"><thead><tr>{head}</tr></thead><tbody>{body}</tbody></table>'


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


def _wrapped(lines) -> str:
    """A figure title: ``lines`` wrapped to the study figures' width (:data:`TITLE_WIDTH`)."""
    return "\n".join(w for line in lines for w in textwrap.wrap(line, TITLE_WIDTH))


def _figure(fig, alt: str) -> str:
    """A matplotlib figure as an embedded PNG (the figure is closed)."""
    buffer = io.BytesIO()
    fig.savefig(buffer, format="png", dpi=110)
    plt.close(fig)
    data = base64.b64encode(buffer.getvalue()).decode("ascii")
    return f'<figure><img alt="{_e(alt)}" src="data:image/png;base64,{data}"></figure>'


def _pipeline_document(ds) -> dict:
    try:
        return tomllib.loads(str(ds.attrs.get("pipeline", "")))
    except tomllib.TOMLDecodeError:
        return {}


def _model(ds):
    return dataset_model(ds)


# ------------------------------------------------------------------------------ sections
def _study_section(ds, name) -> str:
    unit, factor = display_units(ds)
    rows = [("title", ds.attrs.get("title", "")),
            ("pipeline file", ds.attrs.get("pipeline_source", "")),
            ("results file", name),
            ("created", ds.attrs.get("created", "")),
            ("shipblock version", ds.attrs.get("shipblock_version", "")),
            ("pipeline fingerprint", ds.attrs.get("pipeline_fingerprint", ""))]
    out = ["<h2>1. Study</h2>", _table(["", ""], rows, "keys")]
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
    out += ["<h3>Design</h3>", _table(["", ""], design, "keys")]
    out.append(_system_table(ds))
    chain = json.loads(ds.attrs.get("processing_chain", "[]"))
    out.append("<h3>Processing chain</h3>")
    out.append("<p>Applied to every record, in this order, before scaling.</p>" if chain else
               "<p>None: the records as read.</p>")
    if chain:
        out.append(_table(["#", "step", "parameters"], [
            (i + 1, step.get("step", ""), ", ".join(f"{k} = {_number(v)}" for k, v in
                                                    step.items() if k != "step"))
            for i, step in enumerate(chain)]))
    out.append(_solver_table(ds))
    out.append("<details><summary>The pipeline file as run</summary><pre>"
               f"{_e(ds.attrs.get('pipeline', ''))}</pre></details>")
    return "\n".join(out)


def _system_table(ds) -> str:
    system = json.loads(ds.attrs["system"])
    model = _model(ds)
    fields = model.parameters if model is not None else {}
    rows = []
    for key, value in system.items():
        field = fields.get(key)
        units = field.units if field is not None else ""
        rows.append((key, _number(value), "-" if units in ("", "1") else units,
                     field.doc if field is not None else ""))
    out = ["<h3>System</h3>",
           f"<p>Model {_e(model.name if model else '?')}: "
           f"{_e(model.description if model else 'not installed here')}. "
           "None: the model's default (see the description).</p>",
           _table(["parameter", "value", "unit", "what"], rows)]
    sweep = json.loads(ds.attrs.get("sweep", "{}"))
    if sweep:
        out.append("<p>Swept (one fragility per combination):</p>")
        out.append(_table(["parameter", "values"],
                          [(k, ", ".join(_number(x) for x in v)) for k, v in sweep.items()]))
    return "\n".join(out)


def _solver_table(ds) -> str:
    options = json.loads(ds.attrs.get("solver_options", "{}"))
    model = _model(ds)
    fields = model.options if model is not None else {}
    rows = [(k, _number(v), "-" if (f := fields.get(k)) is None or f.units in ("", "1")
             else f.units, f.doc if f is not None else "") for k, v in options.items()]
    return "<h3>Solver options</h3>" + _table(["option", "value", "unit", "what"], rows)


def _records_table(ds, spectra) -> str:
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
    return _table(header, rows)


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
def _limit_states_section(ds) -> str:
    definitions = {d["name"]: d for d in json.loads(ds.attrs.get("limit_states", "[]"))}
    rows = []
    for name in (str(n) for n in ds["limit_state"].values):
        d = definitions.get(name, {})
        edp = d.get("edp", "")
        long_name = ds[edp].attrs.get("long_name", "") if edp in ds else ""
        rows.append((name, limit_state_text(ds, name), long_name, d.get("description", "")))
    return ("<h2>3. Limit states</h2><p>A run exceeds a limit state when its demand meets the "
            f"condition; a run that failed ({_e(failures_text(ds))}) exceeds every response "
            "limit state.</p>" + _table(["limit state", "definition", "demand parameter",
                                    "description"], rows))


def _fit_table(ds) -> str:
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
    return _table(header, rows)


def _arrangements(ds) -> list[dict]:
    """The swept values a figure is drawn at: the first of each parameter, then each other
    value of each parameter with the rest at their first ([{}] without a sweep)."""
    first = sweep_selection(ds)
    combos = [first]
    for dim in first:
        combos += [{**first, dim: v} for v in ds[dim].values[1:]]
    return combos


def _fragility_section(ds) -> str:
    out = ["<h2>4. Fragility</h2>",
           "<p>Lognormal fragility curves, median and dispersion beta, with the bootstrap band "
           "over the records (the values of the results file).</p>", _fit_table(ds)]
    lines = study_report(ds)
    if lines:
        out.append("<p>What <code>shipblock run</code> said:</p><pre>"
                   + _e("\n".join(lines)) + "</pre>")
    sweep = sweep_selection(ds)
    for combo in _arrangements(ds):
        out.append(_figure(plot_fragility(ds, sweep=combo).figure,
                           "fragility curves" + (f" at {sweep_text(combo)}" if combo else "")))
    for dim in sweep:
        out.append(_figure(plot_median_sweep(ds, dim, sweep=sweep).figure,
                           f"median against {dim}"))
    if "im_level" in ds.coords and default_edp(ds) in ds:
        out.append(_figure(plot_ida(ds, sweep=sweep).figure, "IDA curves"))
    return "\n".join(out)


def _risk_section(ds) -> str:
    days = float(ds.attrs["docking_days"])
    sweep = [d for d in ds[_RISK].dims if d != "limit_state"]
    banded = f"{_RISK}_lower" in ds

    def value(name, index):
        v = float(ds[name].values[index])
        if banded and f"{name}_lower" in ds:
            lo, hi = float(ds[f"{name}_lower"].values[index]), float(ds[f"{name}_upper"].values[index])
            if np.isfinite(lo) and np.isfinite(hi):
                return f"{v:.3g} ({lo:.3g} to {hi:.3g})"
        return f"{v:.3g}" if np.isfinite(v) else "not fitted"

    rows = []
    for index in np.ndindex(ds[_RISK].shape):
        rate = float(ds[_RISK].values[index])
        rows.append([str(ds["limit_state"].values[index[0]]),
                     *(_number(ds[d].values[i]) for d, i in zip(sweep, index[1:], strict=True)),
                     value(_RISK, index), f"{1 / rate:.4g}" if rate > 0 else "-",
                     value("risk_probability", index),
                     f"{float(ds['risk_tail_fraction'].values[index]):.1%}"
                     if "risk_tail_fraction" in ds and rate > 0 else "-"])
    header = ["limit state", *sweep, "annual rate [1/yr]", "return period [yr]",
              f"P({days:g} d) [-]", "from beyond the curve"]
    out = ["<h2>5. Risk over the docking period</h2>",
           f"<p>Each fitted fragility convolved with the site hazard curve; probability of at "
           f"least one exceedance during {days:g} days in the dock (Poisson). "
           + (f"In brackets: {float(ds[f'{_RISK}_lower'].attrs['confidence']):.0%} bootstrap "
              "band." if banded else
              f"No bootstrap band ({_e(ds.attrs.get('risk_band', ''))}).") + "</p>",
           "<pre>" + _e(risk_lines(ds)[0]) + "</pre>", _table(header, rows)]
    for selection in _arrangements(ds):
        where = f" at {sweep_text(selection)}" if selection else ""
        if not np.isfinite(ds[_RISK].sel(selection).values).any():
            out.append(f"<p>No figure{_e(where)}: no limit state was fitted there.</p>")
            continue
        fig = plot_risk(ds, sweep=selection)[0].figure
        # the figure's title with the study, system and design, as the study figures have
        fig.suptitle(_wrapped([*study_caption(ds, selection),
                               f"risk over a docking period of {days:g} days"
                               + (f", drawn at {sweep_text(selection)}" if selection else "")]),
                     fontsize=8.5, x=0.01, ha="left")
        out.append(_figure(fig, "hazard, fragilities and deaggregation" + where))
    return "\n".join(out)


# ------------------------------------------------------------------------------ the document
_STYLE = """
body { font-family: sans-serif; max-width: 1100px; margin: 2em auto; color: #222; }
h1 { font-size: 1.5em; } h2 { border-bottom: 1px solid #999; margin-top: 2em; }
table { border-collapse: collapse; margin: 0.6em 0; font-size: 0.9em; }
th, td { border: 1px solid #bbb; padding: 3px 7px; text-align: left; vertical-align: top; }
th { background: #eee; } table.keys thead { display: none; }
table.keys td:first-child { font-weight: bold; white-space: nowrap; }
figure { margin: 1em 0; } img { max-width: 100%; border: 1px solid #ddd; }
pre { background: #f6f6f6; padding: 0.6em; overflow-x: auto; font-size: 0.85em; }
.small { font-size: 0.85em; color: #555; }
"""


def report_html(ds: xr.Dataset, *, name: str = "results", spectra: Mapping | None = None,
                tables: Mapping[str, str] | None = None) -> str:
    """The report of a study result as one HTML document.

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
        CSV table name -> link written beside the report.

    Returns
    -------
    str
    """
    check_study(ds, name)
    title = str(ds.attrs.get("title", "shipblock study"))
    parts = [f"<!DOCTYPE html><html lang='en'><head><meta charset='utf-8'>"
             f"<title>{_e(title)}</title><style>{_STYLE}</style></head><body>",
             f"<h1>{_e(title)}</h1>",
             "<p class='small'>" + "<br>".join(_e(line) for line in study_caption(ds)) + "</p>",
             f"<p class='small'>Report of {_e(name)} by shipblock {_e(__version__)}.</p>",
             _study_section(ds, name), "<h2>2. Records</h2>",
             f"<p>{_e(ds.attrs.get('records_used', ''))}</p>", _records_table(ds, spectra)]
    if spectra:
        parts.append(_figure(_spectra_figure(ds, spectra), "spectra against the target"))
    else:
        parts.append("<p>No target spectrum: the study matched none and none was given "
                     "(<code>--target</code>).</p>")
    parts += [_limit_states_section(ds), _fragility_section(ds)]
    if _RISK in ds:
        parts.append(_risk_section(ds))
    else:
        parts.append("<h2>5. Risk over the docking period</h2><p>Not computed: make it with "
                     "<code>shipblock risk</code> and pass the file with "
                     "<code>--hazard-results</code>.</p>")
    if tables:
        parts.append("<h2>6. Tables</h2><p>The results as CSV, every column with its unit:</p>"
                     "<ul>" + "".join(f"<li><a href='{_e(link)}'>{_e(t)}</a></li>"
                                      for t, link in tables.items()) + "</ul>")
    parts.append("</body></html>")
    return "\n".join(parts)


def _open(path) -> xr.Dataset:
    path = Path(path)
    if not path.is_file():
        raise FileNotFoundError(f"{path}: no such results file")
    try:
        with xr.open_dataset(path) as ds:
            return ds.load()
    except ValueError as exc:
        raise ParameterError(f"{path}: not a NetCDF results file ({exc})") from None


def write_report(results, output, *, hazard_results=None, target: TargetSpectrum | None = None,
                 period_range=None) -> list[Path]:
    """Write the HTML report of a study and its CSV tables.

    Parameters
    ----------
    results : str or os.PathLike
        NetCDF of ``shipblock run`` (or of ``shipblock risk``, which holds the study too).
    output : str or os.PathLike
        The HTML file; the tables go to the folder ``<output stem>_csv`` beside it.
    hazard_results : str or os.PathLike, optional
        NetCDF of ``shipblock risk`` for this study (the same pipeline fingerprint): its risk
        goes into the report and the tables.
    target : TargetSpectrum, optional
        Target spectrum to draw the records' spectra against (:func:`record_spectra`); default
        the study's own, if it matched one.
    period_range : (float, float), optional
        Periods of the match with ``target`` [s].

    Returns
    -------
    list of Path
        The HTML file, then the CSV tables.

    Raises
    ------
    ParameterError
        If a file is not a study result (named), or the risk file belongs to another study.
    """
    matplotlib.use("Agg")  # figures to PNG only; no display needed
    ds = _open(results)
    check_study(ds, str(results))
    if hazard_results is not None:
        risk = _open(hazard_results)
        check_study(risk, str(hazard_results))
        if _RISK not in risk:
            raise ParameterError(f"{hazard_results}: holds no risk ({_RISK}); make it with "
                                 "'shipblock risk'")
        mine, theirs = (d.attrs.get("pipeline_fingerprint") for d in (ds, risk))
        if mine != theirs:
            raise ParameterError(f"{hazard_results}: the risk of another study (pipeline "
                                 f"fingerprint {str(theirs)[:12]}..., {results} has "
                                 f"{str(mine)[:12]}...)")
        ds = risk
    spectra = None
    if target is not None:
        spectra = record_spectra(ds, target, period_range)
    elif "record_sa" in ds:
        spectra = study_spectra(ds)
    output = Path(output)
    output.parent.mkdir(parents=True, exist_ok=True)
    csv = write_csv(ds, output.with_name(output.stem + "_csv"))
    links = {p.name: f"{p.parent.name}/{p.name}" for p in csv}
    text = report_html(ds, name=str(results), spectra=spectra, tables=links)
    partial = output.with_name(output.name + ".part")
    partial.write_text(text, encoding="utf-8")
    partial.replace(output)
    return [output, *csv]
