"""Bootstrap over records: confidence bands of a fragility fit.

:func:`bootstrap` resamples the records with replacement, refits each resample with the same
estimator and takes percentiles of the medians, dispersions and curves. Each resample has its
own seed (``numpy.random.SeedSequence.spawn``), so the result does not depend on where the
resamples run (:class:`~shipblock.fragility.workers.Workers`: here, local processes or Dask).
"""

from __future__ import annotations

import time
import warnings
from collections import Counter
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np

from shipblock import checks
from shipblock.errors import ParameterError, ParameterTypeError
from shipblock.fragility.fit._core import FragilityFit, FragilityFitError, _lognormal, _reals
from shipblock.fragility.workers import PROBE_REPLICATES, blocks

#: Default bootstrap band grid: number of points and half-width in units of beta [-].
_GRID_POINTS = 100
_GRID_HALF_WIDTH = 3.0


# ---------------------------------------------------------------------------------------------
# Bootstrap over records
# ---------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class BootstrapResult:
    """Percentile bootstrap of a fragility fit over records.

    Attributes
    ----------
    fit : FragilityFit
        Fit to the original data, with ``median_ci``, ``beta_ci`` and ``ci_level`` filled in.
    im : numpy.ndarray, shape (k,)
        IM grid of the curve band [IM units].
    lower, upper : numpy.ndarray, shape (k,)
        Pointwise percentile band of the probability of exceedance at ``im`` [-].
    medians, betas : numpy.ndarray, shape (n_ok,)
        Medians [IM units] and dispersions [-] of the successful bootstrap refits.
    n_failed : int
        Number of resamples whose refit raised :class:`FragilityFitError` (e.g. a resample with no
        exceedance); they are left out of the percentiles, which therefore condition on
        identifiable resamples.
    failures : dict of str to int
        Why they could not be refitted: the :class:`FragilityFitError` message -> how many
        resamples raised it, most frequent first (empty when none failed).
    """

    fit: FragilityFit
    im: np.ndarray
    lower: np.ndarray
    upper: np.ndarray
    medians: np.ndarray
    betas: np.ndarray
    n_failed: int
    failures: dict = field(default_factory=dict)

    def failure_text(self) -> str:
        """The most frequent reason a resample could not be refitted, with how many of the
        failed resamples gave it: ``"the most frequent reason (48 of 66): every record's
        ..."`` (``""`` if none failed)."""
        return _failure_text(self.failures, self.n_failed)


def _failure_text(failures: Mapping[str, int], n_failed: int) -> str:
    if not failures:
        return ""
    reason, count = next(iter(failures.items()))
    return f"the most frequent reason ({count} of {n_failed}): {reason}"


def bootstrap(
    fit_function: Callable[..., FragilityFit],
    records: Mapping[str, Any],
    *,
    im=None,
    n_boot: int = 1000,
    confidence: float = 0.9,
    seed: int | np.random.Generator | np.random.SeedSequence | None = None,
    workers=None,
    **fit_kwargs,
) -> BootstrapResult:
    """Bootstrap confidence bands of a fragility fit by resampling records with replacement.

    Each replicate draws ``n_records`` record indices with replacement, takes those rows
    (axis 0) of every array in ``records``, and refits with
    ``fit_function(**resampled_records, **fit_kwargs)``. Replicate ``k`` draws from its own
    generator, seeded with the ``k``-th child of the seed's :class:`numpy.random.SeedSequence`
    (``SeedSequence.spawn``), so the replicates can be spread over processes or a Dask cluster
    (``workers``) in any blocks with the same result. The band is the pointwise
    ``(1 - confidence)/2`` and ``(1 + confidence)/2`` percentiles of the refitted curves;
    ``median_ci`` and ``beta_ci`` are the same percentiles of the refitted parameters (Efron &
    Tibshirani 1993 [1]_, percentile method).

    Parameters
    ----------
    fit_function : callable
        One of :func:`fit_msa`, :func:`fit_ida`, :func:`fit_cloud` (or any function returning a
        :class:`FragilityFit`).
    records : Mapping[str, array_like]
        Per-record data, resampled jointly along axis 0, passed by keyword. For example
        ``{"exceeded": E, "valid": V}`` for :func:`fit_msa`, ``{"capacities": c}`` (and
        per-record ``censored_at``) for :func:`fit_ida`, ``{"im": im, "edp": edp}`` for
        :func:`fit_cloud`.
    im : array_like, optional
        IM grid for the band [IM units]. Default: 100 points log-spaced over
        ``[median / exp(3 beta), median * exp(3 beta)]`` of the original fit.
    n_boot : int
        Number of bootstrap replicates [-].
    confidence : float
        Confidence level of the bands, in (0, 1) [-].
    seed : int, numpy.random.Generator or numpy.random.SeedSequence, optional
        Seed of the resampling (a generator's own seed sequence is spawned from); no global
        random state is used.
    workers : shipblock.fragility.workers.Workers, optional
        Where the replicates run, in blocks: a Dask client, local processes, or here (default),
        depending on the time the others are estimated to take here, from the time of the first
        ``PROBE_REPLICATES`` (run here). ``fit_function`` and the arrays must then be picklable (the fits of
        this module are).
    **fit_kwargs
        Arguments that are not resampled (``im_levels=...``, ``capacity=...``, ...).

    Returns
    -------
    BootstrapResult

    Raises
    ------
    ValueError
        If the record arrays differ in length, or if fewer than half of the replicates could
        be refitted.

    References
    ----------
    .. [1] Efron, B., & Tibshirani, R. J. (1993). *An Introduction to the Bootstrap*. Chapman &
       Hall, ch. 13.
    """
    if not callable(fit_function):
        raise ParameterTypeError(f"fit_function must be a fitting function such as fit_ida, got "
                                 f"{type(fit_function).__name__}")
    if not isinstance(records, Mapping) or not records:
        raise ParameterTypeError("records must be a non-empty mapping of per-record arrays, "
                                 f"got {type(records).__name__}")
    checks.real(confidence, "confidence", low=0.0, high=1.0, low_open=True, high_open=True)
    n_boot = checks.whole(n_boot, "n_boot", low=1, high=1_000_000)
    if im is not None:
        im = _reals(im, "im")
    arrays = {name: np.asarray(value) for name, value in records.items()}
    lengths = {name: a.shape[0] if a.ndim else None for name, a in arrays.items()}
    n_rec = set(lengths.values())
    if len(n_rec) != 1 or None in n_rec:
        raise ParameterError(f"all record arrays need the same length along axis 0, got {lengths}")
    (n_rec,) = n_rec
    try:
        seeds = _replicate_seeds(seed, int(n_boot))
    except (TypeError, ValueError) as exc:
        raise ParameterTypeError(f"seed must be None, a non-negative integer (or sequence of "
                                 f"them) or a numpy Generator, got {seed!r} ({exc})") from None
    base = fit_function(**arrays, **fit_kwargs)
    grid = (
        base.median
        * np.exp(np.linspace(-_GRID_HALF_WIDTH, _GRID_HALF_WIDTH, _GRID_POINTS) * base.beta)
        if im is None
        else np.asarray(im, dtype=float)
    )
    if workers is None:
        parts = [_bootstrap_block(fit_function, arrays, fit_kwargs, seeds)]
    else:
        # the first replicates here, timed: the estimate of where the others should go
        t0 = time.perf_counter()
        parts = [_bootstrap_block(fit_function, arrays, fit_kwargs, seeds[:PROBE_REPLICATES])]
        rest = seeds[PROBE_REPLICATES:]
        if rest:
            estimate = (time.perf_counter() - t0) / PROBE_REPLICATES * len(rest)
            items = [(fit_function, arrays, fit_kwargs, rest[b.start:b.stop])
                     for b in blocks(len(rest), workers.slots())]
            parts += workers.map(_bootstrap_block, items, estimated_seconds=estimate)
    fitted = np.concatenate([p[0] for p in parts], axis=1) if parts else np.zeros((2, 0))
    reasons = Counter()
    for _, part_reasons in parts:
        reasons.update(part_reasons)
    ok = np.isfinite(fitted[0])
    medians, betas = fitted[0, ok].tolist(), fitted[1, ok].tolist()
    n_failed = int(np.count_nonzero(~ok))
    failures = dict(reasons.most_common())
    why = f"; {_failure_text(failures, n_failed)}" if failures else ""
    if len(medians) < max(2, n_boot / 2):
        raise ParameterError(
            f"only {len(medians)} of {n_boot} bootstrap refits succeeded; the data are too "
            f"sparse for a bootstrap{why}"
        )
    if n_failed:
        warnings.warn(
            f"{n_failed} of {n_boot} bootstrap resamples could not be fitted and were "
            f"dropped{why}",
            RuntimeWarning,
            stacklevel=2,
        )
    medians, betas = np.asarray(medians), np.asarray(betas)
    q = 100 * np.array([(1 - confidence) / 2, (1 + confidence) / 2])
    curves = _lognormal(grid[None, :], medians[:, None], betas[:, None])
    lower, upper = np.percentile(curves, q, axis=0)
    fit = replace(
        base,
        median_ci=tuple(float(v) for v in np.percentile(medians, q)),
        beta_ci=tuple(float(v) for v in np.percentile(betas, q)),
        ci_level=float(confidence),
    )
    return BootstrapResult(
        fit=fit,
        im=grid,
        lower=lower,
        upper=upper,
        medians=medians,
        betas=betas,
        n_failed=n_failed,
        failures=failures,
    )


def _replicate_seeds(seed, n_boot: int) -> list:
    """One :class:`numpy.random.SeedSequence` per bootstrap replicate, spawned from ``seed``."""
    if isinstance(seed, np.random.Generator):
        sequence = seed.bit_generator.seed_seq
    elif isinstance(seed, np.random.SeedSequence):
        sequence = seed
    else:
        sequence = np.random.SeedSequence(seed)
    return sequence.spawn(n_boot)


def _bootstrap_block(fit_function, arrays, fit_kwargs, seeds) -> tuple[np.ndarray, dict]:
    """Medians and betas of the replicates with these seeds: shape (2, len(seeds)), NaN if
    unfittable; and why those were not (the :class:`FragilityFitError` message -> count).

    A pure function of its arguments (a task for local processes or Dask): replicate ``k``
    resamples the records with ``numpy.random.default_rng(seeds[k])``.
    """
    n_rec = next(iter(arrays.values())).shape[0]
    out = np.full((2, len(seeds)), np.nan)
    reasons = {}
    for k, child in enumerate(seeds):
        idx = np.random.default_rng(child).integers(0, n_rec, size=n_rec)
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore", RuntimeWarning)
                f = fit_function(**{name: a[idx] for name, a in arrays.items()}, **fit_kwargs)
        except FragilityFitError as exc:
            reasons[str(exc)] = reasons.get(str(exc), 0) + 1
            continue
        out[0, k], out[1, k] = f.median, f.beta
    return out, reasons

