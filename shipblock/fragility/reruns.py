"""Runs of a pipeline made again: one case with its full time histories, and the histories
a pipeline asks for.

:func:`rerun_case` reads and processes the case's record as the pipeline does and runs the
case on the same input, system and solver options as the batch did, through the study's model
(:meth:`Model.simulate <shipblock.models.base.Model.simulate>`), so that its summary equals the
batch's bit for bit. :func:`add_histories` does the same for the runs of a ``[histories]``
request, after the batch. :func:`record_loader` and :func:`match_target_spectrum` are the
record preparation both share with :func:`~shipblock.fragility.pipeline.run_pipeline`.
"""

from __future__ import annotations

import json
import logging
import os
from pathlib import Path

import numpy as np
import xarray as xr

from shipblock.errors import ShipblockError
from shipblock.fragility.batch import prepare_record
from shipblock.fragility.histories import (
    SelectionError,
    case_dataset,
    case_number,
    run_case,
    write_histories,
)
from shipblock.fragility.schema import Pipeline, PipelineError, load_pipeline

__all__ = ["add_histories", "match_target_spectrum", "record_loader", "rerun_case"]

logger = logging.getLogger(__name__)


def record_loader(entry, pipe: Pipeline):
    """A function reading the record of a catalogue ``entry`` as the pipeline asks (component,
    response): what :func:`~shipblock.fragility.batch.prepare_record` calls."""

    def load():
        kwargs = {"response": pipe.response}
        if pipe.azimuth is not None:
            return entry.read(azimuth=pipe.azimuth, **kwargs)
        return entry.read(horizontal=pipe.horizontal, **kwargs)

    return load


def match_target_spectrum(pipe: Pipeline, record) -> dict | None:
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
    # the scaling stack (obspy) loads only for a study with a target spectrum
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


def add_histories(ds, pipe: Pipeline, records, out_path: Path, fingerprint: str,
                  progress: bool) -> xr.Dataset:
    """Write the requested time histories and list them in ``ds["history_file"]``.

    The runs of ``pipe.histories`` are simulated again by the model
    (:func:`~shipblock.fragility.histories.write_histories`), one NetCDF file each, resuming.
    """
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
        The model's result (:meth:`Model.simulate <shipblock.models.base.Model.simulate>`).

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
    from shipblock.records.catalogue import load_catalogue  # obspy: loaded when a record is read

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
    records[r] = prepare_record(rid, record_loader(load_catalogue(pipe.catalogue)[rid], pipe),
                                pipe.chain, design.intensity)
    match_target_spectrum(pipe, records[r])
    result = run_case(design, records, case, pipe.solver)
    ds = case_dataset(result, design, records, case,
                      {"pipeline": pipe.text, "pipeline_source": str(pipe.source),
                       "solver_options": json.dumps(pipe.solver, sort_keys=True),
                       "im_display_units": pipe.im_display[0],
                       "im_display_factor": pipe.im_display[1]})
    return ds, result
