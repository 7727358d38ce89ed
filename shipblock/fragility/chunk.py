"""One chunk of a study's cases, run by the study's model in one batch call.

:func:`run_chunk` is what a chunk task does, here or on a Dask worker
(:func:`shipblock.fragility.workers.run_chunk_task`); :func:`mark_solver_errors` turns the runs
the model's solver gave up on into missing results. Both know the model only through
:class:`shipblock.models.base.Model`.
"""

from __future__ import annotations

import numpy as np

from shipblock.models import DEFAULT_MODEL, Model, get_model

__all__ = ["mark_solver_errors", "run_chunk"]


def run_chunk(records, systems, cases, *, model: Model | None = None, **options) -> dict:
    """Run the cases of one chunk with one call of the model's batch entry point.

    Pure: the output depends only on the arguments (safe as a Dask task).

    Parameters
    ----------
    records : sequence of tuple
        ``(h, v, dt, factor_h, factor_v)`` per record (see
        :meth:`~shipblock.fragility.batch.PreparedRecord.payload`): accelerations [m/s^2],
        sampling interval [s], factors per level [-].
    systems : sequence
        The model's systems the cases refer to.
    cases : array_like of int, shape (n, 3)
        ``(record index into records, level index, system index)`` per case.
    model : shipblock.models.Model, optional
        The model (default: the rigid model, whose entry point is
        :func:`shipblock.simulate_batch`).
    **options
        Solver options of the model (for the rigid model ``rtol``, ``atol``, ``zeno_omega``,
        see :func:`shipblock.simulate`).

    Returns
    -------
    dict of numpy.ndarray
        :meth:`Model.run_batch <shipblock.models.base.Model.run_batch>`'s outputs, one value per
        case.
    """
    model = get_model(DEFAULT_MODEL) if model is None else model
    cases = np.asarray(cases, dtype=np.int64).reshape(-1, 3)
    # each (record, level) pair is scaled once and each system converted once, and only those
    # the chunk uses: the cost of a chunk does not grow with the size of the whole design
    n_levels = int(cases[:, 1].max(initial=0)) + 1
    pairs, pair_of_case = np.unique(cases[:, 0] * n_levels + cases[:, 1], return_inverse=True)
    used, system_of_case = np.unique(cases[:, 2], return_inverse=True)
    inputs, dts = [], []
    for pair in pairs.tolist():
        r, j = divmod(pair, n_levels)
        h, v, dt, fh, fv = records[r]
        f_v = fv[j]
        vertical = None if v is None or not np.isfinite(f_v) or f_v == 0.0 else f_v * v
        inputs.append((fh[j] * h, vertical))
        dts.append(dt)
    local = np.column_stack([pair_of_case.ravel(), system_of_case.ravel()])
    return model.run_batch([systems[i] for i in used.tolist()], inputs, dts, local, **options)


def mark_solver_errors(out: dict, model: Model) -> np.ndarray:
    """Turn runs the solver failed on into NaN results and return their error messages.

    Parameters
    ----------
    out : dict of numpy.ndarray
        Float outputs of :func:`run_chunk` (changed in place).
    model : shipblock.models.Model
        Its :attr:`~shipblock.models.base.Model.solver_error_code` marks the failed runs.

    Returns
    -------
    numpy.ndarray of str
        The message of each run (empty for good runs).
    """
    failure = out["failure"]
    messages = np.full(failure.shape, "", dtype="U80")
    code = model.solver_error_code
    if code is None:
        return messages
    bad = failure == code
    if not bad.any():
        return messages
    times = out.get("failure_time")
    for i in np.flatnonzero(bad):
        messages[i] = f"solver error (failure code {code})" + (
            "" if times is None or not np.isfinite(times[i]) else f" at t = {times[i]:.6g} s")
    for name in out:
        out[name] = np.where(bad, np.nan, out[name])
    return messages
