r"""The fitting step of a study: exceedance of every limit state and its fragility fits.

:func:`fragility_variables` evaluates the limit states on the batch's per-run summaries
(:func:`~shipblock.fragility.limit_states.evaluate_limit_states`, on the model's EDPs) and
fits one lognormal curve per (limit state, sweep point) with the estimator of the design
(IDA: :func:`~shipblock.fragility.fit.fit_ida_levels`; MSA:
:func:`~shipblock.fragility.fit.fit_msa`; cloud: :func:`~shipblock.fragility.fit.fit_cloud`)
and its bootstrap bounds over records (:func:`~shipblock.fragility.fit.bootstrap`). Finished
fits are checkpointed (:class:`~shipblock.fragility.fit.checkpoint.FitCheckpoint`), so that a
run killed among the fits resumes without fitting them again.
"""

from __future__ import annotations

import itertools
import logging
import warnings

import numpy as np
import xarray as xr

from shipblock.fragility.design import AnalysisDesign
from shipblock.fragility.fit import (
    FitCheckpoint,
    FragilityFitError,
    bootstrap,
    fit_cloud,
    fit_ida_levels,
    fit_msa,
    ida_capacities,
)
from shipblock.fragility.limit_states import evaluate_limit_states
from shipblock.fragility.store import ChunkStore
from shipblock.units import STANDARD_GRAVITY

__all__ = ["fragility_variables", "limit_state_coords"]

logger = logging.getLogger(__name__)


def _fit_one(kind, e, w, levels, im, edp, ls, fit_opts, rng, workers=None):
    """Fit one limit state for one parameter combination; returns a dict of results."""
    out = {"median": np.nan, "beta": np.nan, "median_lower": np.nan, "median_upper": np.nan,
           "beta_lower": np.nan, "beta_upper": np.nan, "fit_method": "", "fit_error": "",
           "n_fit_records": 0, "bootstrap_failed": 0, "bootstrap_failure": ""}
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
                           bootstrap_failed=b.n_failed, bootstrap_failure=b.failure_text())
            except ValueError as exc:
                out["fit_error"] = f"bootstrap: {exc}"
    except (FragilityFitError, ValueError) as exc:
        out["fit_error"] = f"{type(exc).__name__}: {exc}"
    return out, capacity



def fragility_variables(ds: xr.Dataset, design: AnalysisDesign, limit_states, fit_opts,
                        store: ChunkStore | None = None,
                        im_display: tuple[str, float] = ("", 1.0), workers=None,
                        model=None) -> dict:
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
        are done (at most every
        :data:`~shipblock.fragility.fit.checkpoint.FIT_CHECKPOINT_INTERVAL` seconds), and
        those it holds from an interrupted run are used instead of fitted again. Each fit is a function of
        its own data and seed only, so the results are the same bit for bit.
    im_display : tuple of (str, float)
        Unit the pipeline writes its IM in and its SI value
        (:attr:`Pipeline.im_display <shipblock.fragility.schema.Pipeline.im_display>`): the
        fits are made in it, so that their messages (``fit_error``) quote the levels as the
        pipeline wrote them, and with ``"g"`` the medians are stored in g too (``median_g``,
        ``median_lower_g``, ``median_upper_g``). Default: SI.
    workers : shipblock.fragility.workers.Workers, optional
        Where the bootstrap resamples run (see :func:`~shipblock.fragility.fit.bootstrap`).
    model : shipblock.models.Model, optional
        Whose EDPs the limit states use (default: ``design.model``).

    Returns
    -------
    dict
        Name -> :class:`xarray.DataArray` with ``units`` and ``long_name``: ``exceeded`` and
        ``valid`` on ``(limit_state, *design.dims)``; ``median``, ``beta``, their bounds,
        ``fit_method``, ``fit_error``, ``n_fit_records``, ``bootstrap_failed``,
        ``bootstrap_failure`` on
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
    ex = evaluate_limit_states(limit_states, ds, design.model if model is None else model)
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
    fields["bootstrap_failure"] = np.full((n_ls, *sweep_shape), "", dtype=object)
    n_records = len(design.records)
    capacity = np.full((n_ls, n_records, *sweep_shape), np.nan)
    capacity_held = capacity.copy()
    im = ds["achieved_im"].values / factor if not intensity.scaled else None
    checkpoint = None if store is None else FitCheckpoint(store, n_records)
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
                for k in ("fit_error", "bootstrap_failure"):  # the fits' messages quote levels
                    if res[k]:
                        res[k] += f" [IM in {unit}]"
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
        "bootstrap_failure": ("1", "why bootstrap resamples could not be fitted: the most "
                                   "frequent reason, after how many of the failed gave it "
                                   "(empty if none failed)"),
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


def limit_state_coords(limit_states) -> dict:
    """Coordinates of the ``limit_state`` dimension: name, EDP, condition, threshold.

    Returns
    -------
    dict
        ``{name: (dims, values, attrs)}``.
    """
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
