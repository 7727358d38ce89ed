"""Full time histories of selected runs of a batch, on request.

A batch keeps only the summary of each run (:data:`~shipblock.fragility.store.RUN_VARIABLES`):
a 100,000-run study would otherwise need gigabytes. The runs whose histories an engineer wants
to look at (a record at the level where the ship first slid, every run that overturned, ...)
are computed again here with :func:`shipblock.simulate` on exactly the input the batch gave
the solver (``factor_h * horizontal``, ``factor_v * vertical``, the same system and solver
options), which reproduces the batch's summary bit for bit, and written one NetCDF file per
run.

A run is selected with a *selector*, a mapping from dimension names to values:

``record``
    Catalogue id, or its last part (``"NP.1765"`` for ``"south-napa-2014/NP.1765"``).
``im_level`` or ``im_level_g``
    A level of the design, in the SI units of the scaling measure (``im_level``) or in g
    (``im_level_g``, PGA and Sa only); matched to the design's levels to 1e-9 relative.
one key per swept parameter
    A value of that parameter's sweep.

A dimension that a selector leaves out selects all its values (:func:`select_cases`);
:func:`case_number` needs the selector to name exactly one run.
"""

from __future__ import annotations

import json
import logging
from collections.abc import Iterable, Mapping
from pathlib import Path

import numpy as np
import xarray as xr

from shipblock.errors import ShipblockError
from shipblock.fragility.design import AnalysisDesign
from shipblock.fragility.store import remove_stale_temporaries, write_dataset
from shipblock.units import STANDARD_GRAVITY

__all__ = [
    "SelectionError",
    "case_dataset",
    "case_number",
    "history_filename",
    "run_case",
    "select_cases",
    "write_histories",
]

logger = logging.getLogger(__name__)

#: Relative tolerance when matching a requested level or swept value to the design's.
MATCH_RTOL = 1e-9


class SelectionError(ShipblockError, ValueError):
    """A run selector names no run of the design; ``key`` is the offending selector key."""

    def __init__(self, key: str, problem: str):
        self.key = key
        self.problem = problem
        super().__init__(f"{key}: {problem}" if key else problem)

    def __reduce__(self):
        """Keep the error picklable."""
        return (type(self), (self.key, self.problem))


def _record_index(design: AnalysisDesign, record) -> int:
    if not isinstance(record, str):
        raise SelectionError("record", f"must be a record id (string), got {record!r}")
    if record in design.records:
        return design.records.index(record)
    matches = [i for i, r in enumerate(design.records) if r.split("/")[-1] == record]
    if len(matches) == 1:
        return matches[0]
    raise SelectionError("record", f"{record!r} is not a record of the design; records: "
                                   f"{', '.join(design.records)}")


def _value_index(values, wanted, key: str, shown, *, given=None, units: str = "") -> int:
    """Index of ``wanted`` in ``values``; the error shows ``given`` (the value as the user gave
    it, default ``wanted``) and ``shown`` (the values in the user's unit ``units``)."""
    if len(values) and all(isinstance(v, str) for v in values):  # a string dimension: names
        if wanted in values:
            return list(values).index(wanted)
        raise SelectionError(key, f"{wanted!r} is not a value of the design; values: "
                                  f"{', '.join(map(repr, values))}")
    if isinstance(wanted, bool) or not isinstance(wanted, int | float | np.integer | np.floating):
        raise SelectionError(key, f"must be a number, got {wanted!r}")
    values = np.asarray(values, dtype=float)
    close = np.flatnonzero(np.isclose(values, float(wanted), rtol=MATCH_RTOL, atol=0.0))
    if close.size != 1:
        unit = "" if units in ("", "1") else f" {units}"
        raise SelectionError(key, f"{wanted if given is None else given!r}{unit} is not a value "
                                  f"of the design; values: "
                                  f"{', '.join(f'{v:g}' for v in shown)}{unit}")
    return int(close[0])


def _selected_indices(design: AnalysisDesign, selector: Mapping) -> list[list[int]]:
    """Indices along ``(record, level, *sweep)`` that a selector picks (all if left out)."""
    intensity = design.intensity
    levels = np.asarray(intensity.levels, dtype=float)
    allowed = {"record", *design.sweep_names}
    if intensity.scaled:
        allowed |= {"im_level", "im_level_g"}
    unknown = [k for k in selector if k not in allowed]
    if unknown:
        raise SelectionError(unknown[0], f"unknown key; a run is selected by "
                                         f"{', '.join(sorted(allowed))}")
    if "record" not in selector:
        raise SelectionError("record", "missing: every selector names a record")
    picks = [[_record_index(design, selector["record"])]]
    if "im_level" in selector and "im_level_g" in selector:
        raise SelectionError("im_level_g", "give im_level or im_level_g, not both")
    if "im_level" in selector:
        picks.append([_value_index(levels, selector["im_level"], "im_level", levels,
                                   units=intensity.units)])
    elif "im_level_g" in selector:
        if intensity.measure == "pgv":
            raise SelectionError("im_level_g", "PGV levels are velocities: use im_level [m/s]")
        given = wanted = selector["im_level_g"]
        if isinstance(wanted, int | float) and not isinstance(wanted, bool):
            wanted = wanted * STANDARD_GRAVITY
        # the error shows the level in g as given, not its value in m/s^2
        picks.append([_value_index(levels, wanted, "im_level_g", levels / STANDARD_GRAVITY,
                                   given=given, units="g")])
    else:
        picks.append(list(range(intensity.n_levels)))
    for name, values in design.sweep:
        if name in selector:
            picks.append([_value_index(values, selector[name], name, values,
                                       units=design.model.sweep_parameters[name][0])])
        else:
            picks.append(list(range(len(values))))
    return picks


def select_cases(design: AnalysisDesign, selector: Mapping) -> np.ndarray:
    """Case numbers of the runs a selector picks.

    Parameters
    ----------
    design : AnalysisDesign
        The grid.
    selector : mapping
        ``record`` (required), ``im_level`` [SI] or ``im_level_g`` [g], swept parameter values;
        a dimension left out selects all its values.

    Returns
    -------
    numpy.ndarray of int
        Case numbers, increasing (only runs of the design: with per-level record sets, not
        those of a record outside a level's stripe).

    Raises
    ------
    SelectionError
        Naming the key that matches nothing (or is unknown).
    """
    picks = _selected_indices(design, selector)
    grid = np.meshgrid(*[np.asarray(p, dtype=np.int64) for p in picks], indexing="ij")
    cases = np.ravel_multi_index([g.ravel() for g in grid], design.shape).astype(np.int64)
    cases = cases[design.in_design(cases)]
    if cases.size == 0:
        raise SelectionError("record", f"{selector['record']!r} is in no stripe of the "
                                       "selected levels")
    return np.sort(cases)


def case_number(design: AnalysisDesign, selector: Mapping) -> int:
    """The case number of the one run a selector names.

    Parameters
    ----------
    design : AnalysisDesign
    selector : mapping
        As for :func:`select_cases`, but naming every dimension with more than one value.

    Returns
    -------
    int

    Raises
    ------
    SelectionError
        If the selector matches no run or several (the message lists the missing keys).
    """
    picks = _selected_indices(design, selector)
    names = ["record", "im_level", *design.sweep_names]
    vague = [name for name, p in zip(names, picks, strict=True) if len(p) > 1]
    if vague:
        raise SelectionError(vague[0], f"the selector matches several runs; also give "
                                       f"{' and '.join(vague)}")
    case = int(np.ravel_multi_index([p[0] for p in picks], design.shape))
    if not design.in_design([case])[0]:
        raise SelectionError("record", f"{selector['record']!r} is not in the stripe of that "
                                       "level (the run was not made)")
    return case


def case_coordinates(design: AnalysisDesign, case: int) -> dict:
    """Coordinates of one case: record id, IM level [SI] (scaled designs) and swept values."""
    r, j, *sweep = np.unravel_index(int(case), design.shape)
    out: dict = {"record": design.records[int(r)]}
    if design.intensity.scaled:
        out["im_level"] = float(design.intensity.levels[int(j)])
    for (name, values), i in zip(design.sweep, sweep, strict=True):
        out[name] = values[int(i)]
    return out


def history_filename(design: AnalysisDesign, case: int) -> str:
    """File name of a case's history: record, level index and sweep indices, e.g.
    ``NP.1765_im3_mu_ground1.nc``.

    Parameters
    ----------
    design : AnalysisDesign
    case : int

    Returns
    -------
    str
    """
    # the records package loads obspy: imported when a history is named, not at start-up
    from shipblock.records.catalogue import record_file_stem

    r, j, *sweep = np.unravel_index(int(case), design.shape)
    parts = [record_file_stem(design.records[int(r)].split("/")[-1])]  # never a hidden file
    if design.intensity.scaled:
        parts.append(f"im{int(j)}")
    parts += [f"{name}{int(i)}" for name, i in zip(design.sweep_names, sweep, strict=True)]
    return "_".join(parts) + ".nc"


def run_case(design: AnalysisDesign, records, case: int, solver_options: Mapping | None = None):
    """Simulate one case of a design with its full histories.

    Parameters
    ----------
    design : AnalysisDesign
        The grid.
    records : sequence of PreparedRecord
        The design's records, prepared as for the batch
        (:func:`~shipblock.fragility.batch.prepare_record`).
    case : int
        Case number.
    solver_options : mapping, optional
        The model's solver options as in the batch (rigid model: ``rtol``, ``atol``,
        ``zeno_omega``).

    Returns
    -------
    shipblock.SimulationResult
        :meth:`Model.simulate <shipblock.models.base.Model.simulate>` of the design's model (a
        :class:`~shipblock.SimulationResult` for the rigid model): equal bit for bit, in every
        summary value, to the batch's run of the case.

    Raises
    ------
    ShipblockError
        If the case's record was left out of the batch (the message gives its error).
    """
    r, j, s = (int(i) for i in design.case_indices([case])[0])
    rec = records[r]
    if rec.error is not None:
        raise ShipblockError(f"record {rec.id} was left out of the batch: {rec.error}")
    h, v, dt, fh, fv = rec.payload()
    # the same input arrays as run_chunk builds
    f_v = fv[j]
    vertical = None if v is None or not np.isfinite(f_v) or f_v == 0.0 else f_v * v
    system = design.system_at(s)
    return design.model.simulate(system, fh[j] * h, vertical, dt, **dict(solver_options or {}))


def case_dataset(result, design: AnalysisDesign, records, case: int,
                 attrs: Mapping | None = None) -> xr.Dataset:
    """The result of :func:`run_case` as a dataset that says which run it is.

    Parameters
    ----------
    result : shipblock.SimulationResult
    design : AnalysisDesign
    records : sequence of PreparedRecord
    case : int
    attrs : mapping, optional
        Extra global attributes (e.g. the pipeline's fingerprint).

    Returns
    -------
    xarray.Dataset
        :meth:`~shipblock.SimulationResult.to_dataset` with global attributes ``case``,
        ``model`` (its name), ``record``, ``im_measure``, ``im_level`` and ``im_units`` (scaled designs),
        ``scale_factor``,
        ``vertical_scale_factor``, ``swept_parameters`` (JSON) and ``record_provenance``
        (JSON).
    """
    r, j, _ = (int(i) for i in design.case_indices([case])[0])
    rec = records[r]
    coords = case_coordinates(design, case)
    ds = result.to_dataset()
    ds.attrs.update({
        "title": f"shipblock time history: case {int(case)}, record {rec.id}",
        "case": int(case),
        "model": design.model.name,
        "record": rec.id,
        "scale_factor": float(rec.factor_h[j]),
        "vertical_scale_factor": float(rec.factor_v[j]),
        "swept_parameters": json.dumps({k: v for k, v in coords.items()
                                        if k not in ("record", "im_level")}, default=float),
        "record_provenance": json.dumps(rec.metadata, default=str, sort_keys=True),
    })
    if design.intensity.scaled:
        ds.attrs["im_measure"] = design.intensity.measure
        ds.attrs["im_level"] = coords["im_level"]
        ds.attrs["im_units"] = design.intensity.units
        ds.attrs["im_long_name"] = design.intensity.long_name
    ds.attrs.update(dict(attrs or {}))
    return ds


def write_histories(design: AnalysisDesign, records, cases: Iterable[int], directory,
                    solver_options: Mapping | None = None, fingerprint: str = "",
                    attrs: Mapping | None = None, progress: bool = False) -> dict[int, Path]:
    """Write the time histories of some cases, one NetCDF file each, resuming.

    A file already in ``directory`` whose ``pipeline_fingerprint`` attribute equals
    ``fingerprint`` is kept (a rerun of a killed batch does not compute it again); every file
    is written atomically. Cases whose record was left out are skipped with a warning.

    Parameters
    ----------
    design : AnalysisDesign
    records : sequence of PreparedRecord
    cases : iterable of int
        Case numbers.
    directory : str or os.PathLike
        Output folder (created).
    solver_options : mapping, optional
        As in the batch.
    fingerprint : str
        Identity of the batch (stored as ``pipeline_fingerprint``).
    attrs : mapping, optional
        Extra global attributes of every file.
    progress : bool
        Show a progress bar.

    Returns
    -------
    dict
        Case number -> file written (or kept).
    """
    from tqdm.auto import tqdm

    directory = Path(directory)
    cases = [int(c) for c in cases]
    written: dict[int, Path] = {}
    for case in tqdm(cases, desc="histories", unit="run", disable=not progress or not cases):
        path = directory / history_filename(design, case)
        remove_stale_temporaries(path)  # left by a run killed while writing this file
        if fingerprint and _same_run(path, fingerprint):
            written[case] = path
            continue
        try:
            result = run_case(design, records, case, solver_options)
        except ShipblockError as exc:
            logger.warning("no history for case %d: %s", case, exc)
            continue
        ds = case_dataset(result, design, records, case,
                          {**dict(attrs or {}), "pipeline_fingerprint": fingerprint})
        write_dataset(ds, path)
        written[case] = path
    return written


def _same_run(path: Path, fingerprint: str) -> bool:
    """Whether ``path`` is a readable history of the run with this fingerprint."""
    if not path.exists():
        return False
    try:
        with xr.open_dataset(path, engine="netcdf4") as ds:
            return ds.attrs.get("pipeline_fingerprint") == fingerprint
    except (OSError, ValueError):
        return False
