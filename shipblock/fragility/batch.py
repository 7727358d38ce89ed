"""Batch execution of an analysis design: records prepared once, cases run in chunks.

The work of a design is done in three steps:

1. :func:`prepare_record` reads and processes each record **once** and computes its scale
   factors at every IM level (:func:`shipblock.scaling.scale_record`). A record that cannot be
   read, processed or scaled keeps its error message and takes no part in the runs.
2. :func:`run_batch` splits the case numbers into chunks (:meth:`AnalysisDesign.chunks`) and
   runs every chunk not yet on disk with :func:`run_chunk`, either here (one call of the
   model's batch entry point per chunk, :meth:`Model.run_batch
   <shipblock.models.base.Model.run_batch>`: for the rigid model one
   :func:`shipblock.simulate_batch` call, numba threads over all cores) or as Dask
   tasks when a ``distributed.Client`` is given. Each finished chunk is written at once to a
   :class:`~shipblock.fragility.store.ChunkStore`, so a killed batch resumes where it stopped.
3. :func:`summary_dataset` arranges the per-case results on the design's dimensions.

:func:`run_chunk` is a pure function of its arguments, so the result of a case does not depend
on the executor or on the other cases of its chunk: local and Dask runs agree bit for bit.
Each case runs the solver on ``factor_h * horizontal`` and ``factor_v * vertical`` (the arrays
:func:`~shipblock.scaling.scale_record` returns), so it equals
``shipblock.simulate(system, factor_h * h, factor_v * v, dt)`` bit for bit.
"""

from __future__ import annotations

import hashlib
import json
import logging
import time
from collections.abc import Callable, Iterable, Mapping
from dataclasses import dataclass, field

import numpy as np
import xarray as xr

from shipblock.fragility.chunk import mark_solver_errors, run_chunk
from shipblock.fragility.design import AnalysisDesign, IntensityDesign
from shipblock.fragility.store import ChunkStore, StoreError
from shipblock.fragility.workers import host_task_threads, run_chunk_task

__all__ = [
    "DEFAULT_CHUNK_SIZE",
    "mark_solver_errors",
    "PreparedRecord",
    "prepare_record",
    "run_batch",
    "run_chunk",
    "summary_dataset",
]

logger = logging.getLogger(__name__)

#: Default largest number of cases per chunk [-]: large enough that the fixed cost of a chunk
#: (about 1 ms: one :func:`~shipblock.simulate_batch` call, one file written and synced) is
#: small against its runs even at tens of microseconds per run, small enough that a killed
#: batch loses little.
DEFAULT_CHUNK_SIZE = 1024


@dataclass
class PreparedRecord:
    """A record read, processed and scaled once, ready for the solver.

    Attributes
    ----------
    id : str
        Record id.
    horizontal : numpy.ndarray or None
        Processed horizontal acceleration the solver uses [m/s^2] (None after an error).
    vertical : numpy.ndarray or None
        Processed vertical acceleration, positive up [m/s^2]; None if absent.
    dt : float
        Sampling interval [s] (NaN after an error).
    factor_h : numpy.ndarray, shape (n_levels,)
        Scale factor of the horizontal at each level [-].
    factor_v : numpy.ndarray, shape (n_levels,)
        Scale factor of the vertical at each level [-]; NaN without a vertical, 0 when the
        vertical is dropped.
    achieved : numpy.ndarray, shape (n_levels,)
        IM of the scaled horizontal at each level, measured again with
        :mod:`shipblock.intensity` [SI units of the IM].
    achieved_v : numpy.ndarray, shape (n_levels,)
        Same measure of the scaled vertical (NaN without a vertical).
    im : float
        IM of the processed, unscaled horizontal [SI units of the IM].
    metadata : dict
        Provenance of the record (station, event, files, units, processing).
    error : str or None
        Why the record could not be used, or None.
    """

    id: str
    horizontal: np.ndarray | None
    vertical: np.ndarray | None
    dt: float
    factor_h: np.ndarray
    factor_v: np.ndarray
    achieved: np.ndarray
    achieved_v: np.ndarray
    im: float
    metadata: dict = field(default_factory=dict)
    error: str | None = None

    @property
    def npts(self) -> int:
        """int: Number of samples (0 after an error)."""
        return 0 if self.horizontal is None else int(self.horizontal.size)

    def payload(self) -> tuple:
        """The arrays a chunk task needs: ``(h, v, dt, factor_h, factor_v)``."""
        return (self.horizontal, self.vertical, self.dt, self.factor_h, self.factor_v)

    def digest(self) -> str:
        """SHA-256 of the data and factors (part of the run fingerprint).

        Returns
        -------
        str
            Hex digest.
        """
        h = hashlib.sha256(self.id.encode())
        h.update(str(self.error).encode())
        for arr in (self.horizontal, self.vertical, self.factor_h, self.factor_v):
            h.update(b"-" if arr is None else np.ascontiguousarray(arr, float).tobytes())
        h.update(np.float64(self.dt).tobytes())
        return h.hexdigest()


def _failed(record_id: str, n_levels: int, error: str, metadata=None) -> PreparedRecord:
    nan = np.full(n_levels, np.nan)
    return PreparedRecord(record_id, None, None, float("nan"), nan, nan.copy(), nan.copy(),
                          nan.copy(), float("nan"), dict(metadata or {}), error)


def prepare_record(
    record_id: str,
    load: Callable[[], object],
    chain: Iterable[Mapping] | None,
    intensity: IntensityDesign,
) -> PreparedRecord:
    """Read, process and scale one record; never raises for a bad record.

    Parameters
    ----------
    record_id : str
        Record id (used in messages).
    load : callable
        Returns the :class:`shipblock.records.motion.GroundMotion` (e.g. ``entry.read``).
    chain : iterable of mapping or None
        Processing chain (:func:`shipblock.processing.apply_chain`); None for the default
        chain, ``[]`` for none.
    intensity : IntensityDesign
        Measure, levels and vertical treatment.

    Returns
    -------
    PreparedRecord
        With ``error`` set (and no data) if reading, processing or scaling failed (also if a
        level needs a scaled record above :data:`shipblock.checks.MAX_ACCELERATION`, 100 g,
        which :func:`~shipblock.scaling.scale_record` refuses).
    """
    # the processing stack (obspy) loads when the first record is prepared: start-up time
    from shipblock.processing import process_motion
    from shipblock.records.motion import require_components
    from shipblock.scaling import measure_value, scale_record

    n = intensity.n_levels
    metadata: dict = {}
    try:
        motion = load()
        metadata = motion.metadata
        if intensity.vertical == "same":  # else the runs would be horizontal-only, silently
            require_components(motion, ("H1", "V"), record=record_id, key='vertical = "same"')
        if chain is None or list(chain):  # process_motion fails on an empty chain
            motion = process_motion(motion, chain)
            metadata = motion.metadata
        h = np.ascontiguousarray(motion.horizontal, dtype=float)
        v = motion.vertical
        v = None if v is None else np.ascontiguousarray(v, dtype=float)
        dt = float(motion.dt)
        fh, fv, ach, ach_v = (np.full(n, np.nan) for _ in range(4))
        for j in range(n):
            s = scale_record(h, v, dt, **intensity.scale_options(j))
            fh[j] = s.factor_h
            ach[j] = s.achieved
            if s.factor_v is not None:
                fv[j] = s.factor_v
                ach_v[j] = s.achieved_v
        im = measure_value(h, dt, intensity.measure, intensity.period, intensity.damping)
    except Exception as exc:  # noqa: BLE001 - a bad record is reported, the batch goes on
        message = f"{type(exc).__name__}: {exc}"
        logger.warning("record %s left out: %s", record_id, message)
        return _failed(record_id, n, message, metadata)
    return PreparedRecord(record_id, h, v, dt, fh, fv, ach, ach_v, float(im), metadata)


# --------------------------------------------------------------------------------------------
# the batch
# --------------------------------------------------------------------------------------------

class _Task:
    """What one chunk needs: its cases, the runnable ones and their local indices."""

    def __init__(self, design: AnalysisDesign, chunk: range, ok_records: np.ndarray,
                 in_stripe: np.ndarray):
        self.chunk = chunk
        self.cases = np.arange(chunk.start, chunk.stop, dtype=np.int64)
        idx = design.case_indices(self.cases)
        self.runnable = ok_records[idx[:, 0]] & in_stripe[idx[:, 0], idx[:, 1]]
        idx = idx[self.runnable]
        self.records, local = np.unique(idx[:, 0], return_inverse=True)
        self.local_cases = np.column_stack([local.ravel(), idx[:, 1], idx[:, 2]])

    def assemble(self, out: dict | None, model) -> tuple[np.ndarray, np.ndarray]:
        """Full-chunk results (NaN for cases of failed records) from the model's output.

        Returns
        -------
        values : numpy.ndarray, shape (len(model.outputs), n)
            One row per run variable, in the order of ``model.outputs``.
        errors : numpy.ndarray of str, shape (n,)
            ``run_error`` of each case.
        """
        names = tuple(model.outputs)
        n = self.cases.size
        values = np.full((len(names), n), np.nan)
        errors = np.full(n, "", dtype="U80")
        if out is not None:
            out = {name: np.asarray(out[name], dtype=float) for name in names}
            msg = mark_solver_errors(out, model)
            values[:, self.runnable] = np.stack([out[name] for name in names])
            errors[self.runnable] = msg
        return values, errors


def run_batch(
    design: AnalysisDesign,
    records: list[PreparedRecord],
    store: ChunkStore,
    *,
    chunk_size: int = DEFAULT_CHUNK_SIZE,
    client=None,
    progress: bool = True,
    solver_options: Mapping | None = None,
    timings: dict | None = None,
    runs=None,
) -> dict:
    """Run every case of a design, resuming from the chunks already in ``store``.

    Parameters
    ----------
    design : AnalysisDesign
        The grid of runs.
    records : list of PreparedRecord
        One per ``design.records``, in order.
    store : ChunkStore
        Where finished chunks are written (opened by the caller).
    chunk_size : int
        Largest number of cases per chunk.
    client : distributed.Client, optional
        Run chunks as Dask tasks on this client; None runs them here.
    progress : bool
        Show a tqdm progress bar (runs done, rate, time left).
    solver_options : mapping, optional
        ``rtol``, ``atol``, ``zeno_omega`` for :func:`run_chunk`.
    timings : dict, optional
        ``timings["solver"]`` is increased by the wall time spent in :func:`run_chunk` [s]
        (local runs only).
    runs : array_like of bool, shape (n_records, n_levels), optional
        The (record, level) pairs to run (e.g. without those scaled beyond a limit); the others
        get NaN like a record's failure. Default: :meth:`AnalysisDesign.stripe_mask`.

    Returns
    -------
    dict of numpy.ndarray
        One array of length ``design.n_cases`` per name of
        the model's outputs (:attr:`Model.outputs <shipblock.models.base.Model.outputs>`; for the
        rigid model :data:`~shipblock.fragility.store.RUN_VARIABLES`; NaN for runs without a
        result) and
        ``run_error`` (strings, empty for good runs).
    """
    from tqdm.auto import tqdm

    opts = dict(solver_options or {})
    model = design.model
    names = tuple(model.outputs)
    systems = design.systems()
    chunks = design.chunks(chunk_size)
    n = design.n_cases
    # one row per run variable: filled a chunk at a time, returned as row views
    table = np.full((len(names), n), np.nan)
    run_error = np.full(n, "", dtype=object)

    def fill(chunk: range, values: np.ndarray, errors: np.ndarray):
        table[:, chunk.start:chunk.stop] = values
        bad = np.flatnonzero(errors != "")
        run_error[chunk.start + bad] = errors[bad]

    pending = []
    done_cases = 0
    available = store.completed()
    for k, chunk in enumerate(chunks):
        if k in available:
            try:
                cases, arrays = store.read(k)
                values = np.stack([np.asarray(arrays[name], dtype=float) for name in names])
                errors = np.asarray(arrays["run_error"], dtype=str)
            except (StoreError, KeyError, ValueError) as exc:
                logger.warning("chunk %d unusable (%s); recomputing it", k, exc)
                store.discard(k)
            else:
                if np.array_equal(cases, np.arange(chunk.start, chunk.stop)):
                    fill(chunk, values, errors)
                    done_cases += len(chunk)
                    continue
                store.discard(k)
        pending.append(k)
    if done_cases:
        logger.info("resuming: %d of %d runs already done", done_cases, n)

    ok = np.array([r.error is None for r in records], dtype=bool)
    bar = tqdm(total=n, initial=done_cases, unit="run", desc="shipblock", disable=not progress,
               smoothing=0.1)
    try:
        in_stripe = design.stripe_mask() if runs is None else np.asarray(runs, dtype=bool)
        tasks = {k: _Task(design, chunks[k], ok, in_stripe) for k in pending}

        def finish(k: int, out):
            task = tasks.pop(k)
            values, errors = task.assemble(out, model)
            store.write(k, task.cases, {**dict(zip(names, values, strict=True)),
                                        "run_error": errors})
            fill(task.chunk, values, errors)
            bar.update(len(task.chunk))

        runnable = [k for k in pending if tasks[k].local_cases.size]
        for k in pending:
            if k not in runnable:
                finish(k, None)
        if client is None:
            for k in runnable:
                t = tasks[k]
                payload = [records[r].payload() for r in t.records]
                t0 = time.perf_counter()
                out = run_chunk(payload, systems, t.local_cases, model=model, **opts)
                if timings is not None:
                    timings["solver"] = timings.get("solver", 0.0) + time.perf_counter() - t0
                finish(k, out)
        else:
            _run_dask(client, records, systems, tasks, runnable, {"model": model, **opts}, finish)
    finally:
        bar.close()
    results = dict(zip(names, table, strict=True))
    results["run_error"] = run_error
    return results


def _run_dask(client, records, systems, tasks, runnable, opts, finish):
    """Submit the runnable chunks as Dask tasks and finish them as they complete.

    Each task runs on its share of its host's cores (numba threads:
    :func:`~shipblock.fragility.workers.run_chunk_task`).
    """
    from distributed import as_completed  # optional dependency: only with a client

    hosts = host_task_threads(client)

    needed = sorted({int(r) for k in runnable for r in tasks[k].records})
    scattered = {r: client.scatter(records[r].payload(), hash=False) for r in needed}
    sys_future = client.scatter(systems, hash=False, broadcast=True)
    futures = {}
    for k in runnable:
        t = tasks[k]
        fut = client.submit(run_chunk_task, [scattered[int(r)] for r in t.records], sys_future,
                            t.local_cases, hosts, pure=False, **opts)
        futures[fut] = k
    try:
        for fut in as_completed(futures):
            finish(futures[fut], fut.result())
    finally:
        client.cancel(list(futures))


# --------------------------------------------------------------------------------------------
# dataset
# --------------------------------------------------------------------------------------------


def summary_dataset(design: AnalysisDesign, records: list[PreparedRecord],
                    results: Mapping) -> xr.Dataset:
    """Arrange per-case results and record data on the design's dimensions.

    Parameters
    ----------
    design : AnalysisDesign
        The grid.
    records : list of PreparedRecord
        One per record of the design.
    results : mapping
        As returned by :func:`run_batch`.

    Returns
    -------
    xarray.Dataset
        Per-run variables of the model's outputs (rigid model:
        :data:`~shipblock.fragility.store.RUN_VARIABLES`) and
        ``run_error`` on ``design.dims``; per record and level ``scale_factor``,
        ``vertical_scale_factor``, ``achieved_im``, ``achieved_im_vertical`` (and
        ``in_stripe`` for a design with per-level record sets); per record
        ``record_error``, ``record_dt``, ``record_npts``, ``record_im``. All with ``units`` and
        ``long_name``.
    """
    intensity = design.intensity
    dims = design.dims
    shape = design.shape
    cloud = not intensity.scaled

    def grid(values):
        arr = np.asarray(values).reshape(shape)
        return arr[:, 0] if cloud else arr

    data = {}
    for name, (units, long_name) in design.model.outputs.items():
        data[name] = (dims, grid(results[name]), {"units": units, "long_name": long_name})
    data["run_error"] = (
        dims, grid(np.asarray(results["run_error"], dtype=object)),
        {"units": "1", "long_name": "solver error of the run (empty if none)"},
    )
    im_units = intensity.units
    lvl_dims = ("record",) if cloud else ("record", "im_level")

    def per_level(attr):
        arr = np.array([getattr(r, attr) for r in records], dtype=float)
        return arr[:, 0] if cloud else arr

    data["scale_factor"] = (lvl_dims, per_level("factor_h"),
                            {"units": "1", "long_name": "scale factor of the horizontal"})
    data["vertical_scale_factor"] = (
        lvl_dims, per_level("factor_v"),
        {"units": "1", "long_name": f"scale factor of the vertical (mode {intensity.vertical!r};"
                                    " NaN without vertical)"},
    )
    data["achieved_im"] = (lvl_dims, per_level("achieved"),
                           {"units": im_units,
                            "long_name": f"achieved {intensity.long_name} after scaling"})
    data["achieved_im_vertical"] = (
        lvl_dims, per_level("achieved_v"),
        {"units": im_units, "long_name": f"{intensity.measure.upper()} of the scaled vertical"},
    )
    if design.stripes is not None:
        data["in_stripe"] = (lvl_dims, design.stripe_mask(),
                             {"units": "1", "long_name": "record belongs to the stripe of the "
                                                         "level (runs outside are not made)"})
    data["record_error"] = (
        ("record",), np.array([r.error or "" for r in records], dtype=object),
        {"units": "1", "long_name": "why the record was left out (empty if used)"},
    )
    data["record_dt"] = (("record",), np.array([r.dt for r in records], dtype=float),
                         {"units": "s", "long_name": "sampling interval of the processed record"})
    data["record_npts"] = (("record",), np.array([r.npts for r in records], dtype=np.int64),
                           {"units": "1", "long_name": "number of samples of the processed record"})
    data["record_im"] = (("record",), np.array([r.im for r in records], dtype=float),
                         {"units": im_units,
                          "long_name": f"{intensity.long_name}, processed record as recorded"})
    coords = design.coords()
    return xr.Dataset(data, coords={k: xr.Variable(*v) for k, v in coords.items()})


def records_provenance(records: list[PreparedRecord]) -> str:
    """JSON text of every record's metadata and error (for a global attribute).

    Parameters
    ----------
    records : list of PreparedRecord

    Returns
    -------
    str
    """
    doc = {r.id: {"error": r.error, **r.metadata} for r in records}
    return json.dumps(doc, default=str, sort_keys=True)
