r"""Pipelines: a TOML file that fully reproduces a fragility study, and :func:`run_pipeline`.

A pipeline file names the records, the processing chain, the component, the model and its
parameters, the parameters swept, the analysis design, the limit states, the fit and solver
options and the output file; :func:`~shipblock.fragility.schema.load_pipeline` parses and
validates it (every error names the offending key; every key is declared once, in
:mod:`shipblock.fragility.keys`, and listed in the user guide). :func:`run_pipeline` runs it
end to end: records read and processed once, all runs in chunks by the study's model (locally
or on Dask, :mod:`shipblock.fragility.batch`), exceedance of every limit state and lognormal
fragility fits with bootstrap bounds over records (:mod:`shipblock.fragility.fit_step`), the
requested time histories (:mod:`shipblock.fragility.reruns`), and one NetCDF file.

The dataset stores the levels, medians and achieved IMs in SI; with ``levels_g`` the levels and
medians also in g (``im_level_g``, ``median_g``, ...), and the fits, their messages and the
command's output use the pipeline's unit.

The names of the parser (:func:`~shipblock.fragility.schema.load_pipeline`,
:func:`~shipblock.fragility.schema.parse_pipeline`, :class:`~shipblock.fragility.schema.Pipeline`,
:class:`~shipblock.fragility.keys.PipelineError`, the ``MAX_*`` limits of
:mod:`shipblock.fragility.keys`), of the fitting step
(:func:`~shipblock.fragility.fit_step.fragility_variables`) and of the reruns
(:func:`~shipblock.fragility.reruns.rerun_case`) are importable from here as before.
"""

from __future__ import annotations

import hashlib
import json
import logging
import os
import time
from collections.abc import Mapping
from datetime import UTC, datetime
from pathlib import Path

import numpy as np
import xarray as xr

from shipblock import __version__
from shipblock.errors import ParameterTypeError
from shipblock.fragility.batch import (
    prepare_record,
    records_provenance,
    run_batch,
    summary_dataset,
)
from shipblock.fragility.filesystem import output_name_problem
from shipblock.fragility.fit_step import fragility_variables, limit_state_coords
from shipblock.fragility.keys import (  # noqa: F401  (importable from here as before)
    MAX_BOOTSTRAP,
    MAX_CHUNK_SIZE,
    MAX_HISTORIES,
    MAX_RUNS,
    MAX_SEED,
    SCHEMA_VERSION,
    PipelineError,
)
from shipblock.fragility.lock import hold_output
from shipblock.fragility.reruns import _rerun  # noqa: F401  (the CLI's rerun imports it here)
from shipblock.fragility.reruns import (  # noqa: F401  (rerun_case: importable as before)
    add_histories,
    match_target_spectrum,
    record_loader,
    rerun_case,
)
from shipblock.fragility.schema import (  # noqa: F401  (importable from here as before)
    HistoryRequest,
    Pipeline,
    load_pipeline,
    output_path,
    parse_pipeline,
)
from shipblock.fragility.store import (
    ChunkStore,
    StoreError,
    open_results,
    remove_stale_temporaries,
    write_dataset,
)
from shipblock.fragility.workers import Workers
from shipblock.units import STANDARD_GRAVITY

# The parser's, the fitting step's and the reruns' names stay importable from here (documented
# where they are defined).
__all__ = ["records_used_message", "run_pipeline"]

logger = logging.getLogger(__name__)


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
    """Identity of a run: the pipeline's result-determining parts, the version, the records."""
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
                else output_path(os.fspath(output), Path.cwd(), "run_pipeline(output=...)"))
    _prepare_output_folder(out_path, pipe.source)
    with hold_output(out_path, wait=wait):  # issue 33: one run per output
        return _run_held(pipe, out_path, client, scheduler, progress, timings, clock)


def _run_held(pipe, out_path: Path, client, scheduler, progress: bool, timings,
              clock: _StageClock) -> xr.Dataset:
    """:func:`run_pipeline` once the run holds its output (the files left beside it are no
    live run's)."""
    # the records' stack (obspy) loads when records are read: start-up time of the CLI
    from shipblock.processing import DEFAULT_CHAIN
    from shipblock.records.catalogue import load_catalogue

    for stale in remove_stale_temporaries(out_path):
        logger.info("removed %s, left by an interrupted write of %s", stale.name, out_path.name)
    scheduler = scheduler or pipe.scheduler
    connect = _dask_client_class(scheduler, pipe.source) if client is None and scheduler else None
    design = pipe.design
    entries = load_catalogue(pipe.catalogue)
    records = [
        prepare_record(rid, record_loader(entries[rid], pipe), pipe.chain, design.intensity)
        for rid in design.records
    ]
    matches = [match_target_spectrum(pipe, r) for r in records]
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
        ds = ds.assign_coords({k: xr.Variable(*v) for k, v in limit_state_coords(
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
        "model": design.model.name,
        "system": json.dumps(design.model.describe(design.system), sort_keys=True),
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
        ds = add_histories(ds, pipe, records, out_path, fingerprint, progress)
        clock.lap("histories")
    write_dataset(ds, out_path)
    store.remove()
    logger.info("wrote %s", out_path)
    ds = open_results(out_path)
    clock.lap("write")
    return ds
