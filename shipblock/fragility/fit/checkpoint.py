"""Checkpoints of a study's fits: finished fits kept on disk, so a killed run resumes.

The fitting step of a pipeline (:func:`shipblock.fragility.fit_step.fragility_variables`)
fits one curve per (limit state, sweep point); :class:`FitCheckpoint` writes the finished ones
to the run's partial-results directory (:class:`~shipblock.fragility.store.ChunkStore`, group
``"fit"``) at most every :data:`FIT_CHECKPOINT_INTERVAL` seconds, and reads back those of an
interrupted run. Each fit is a function of its own data and seed only, so a resumed run gives
the same results bit for bit.
"""

from __future__ import annotations

import logging
import time

import numpy as np

from shipblock.fragility.store import ChunkStore, StoreError

__all__ = ["FIT_CHECKPOINT_INTERVAL", "FIT_FIELDS", "FitCheckpoint"]

logger = logging.getLogger(__name__)

#: Fitted results are written to the partial-results directory at most this often [s] (and
#: once more when the fits are done): a kill after the batch loses at most this much fitting.
FIT_CHECKPOINT_INTERVAL = 1.0

_FIT_FLOATS = ("median", "beta", "median_lower", "median_upper", "beta_lower", "beta_upper")
_FIT_INTS = ("n_fit_records", "bootstrap_failed")
_FIT_STRINGS = ("fit_method", "fit_error", "bootstrap_failure")
#: The results of one fit, in the order they are stored.
FIT_FIELDS = _FIT_FLOATS + _FIT_INTS + _FIT_STRINGS


class FitCheckpoint:
    """Fitted results of finished (limit state, sweep point) pairs, kept in a ChunkStore.

    Fit ``f = i * n_points + c`` is limit state ``i`` at sweep point ``c``; each file of the
    store's ``"fit"`` group holds some fits (those finished since the previous file), so the
    files' names say nothing about what they hold and a file is never rewritten.

    Parameters
    ----------
    store : ChunkStore
        The run's partial-results directory (opened).
    n_records : int
        Records of the study (the length of a fit's capacity columns).
    """

    def __init__(self, store: ChunkStore, n_records: int):
        self.store = store
        self.n_records = n_records
        self.pending: dict[int, tuple[dict, np.ndarray, np.ndarray]] = {}
        self.last = time.monotonic()
        self.next_id = max(store.completed("fit"), default=-1) + 1

    def load(self) -> dict[int, tuple[dict, np.ndarray, np.ndarray]]:
        """Fits done by an earlier, interrupted run.

        ``{f: (results, capacity column, capacity_held column)}``, the columns over the records.
        """
        done = {}
        for k in sorted(self.store.completed("fit")):
            try:
                fits, arrays = self.store.read(k, "fit")
                capacity, held = (np.asarray(arrays[n], dtype=float).reshape(
                    len(fits), self.n_records) for n in ("capacity", "capacity_held"))
                rows = [dict(zip(FIT_FIELDS, values, strict=True))
                        for values in zip(*(arrays[n].tolist() for n in FIT_FIELDS),
                                          strict=True)]
            except (StoreError, KeyError, ValueError) as exc:
                logger.warning("fitted results %d unusable (%s); fitting again", k, exc)
                self.store.discard(k, "fit")
                continue
            for f, row, col, col_held in zip(fits.tolist(), rows, capacity, held, strict=True):
                done[f] = (row, col, col_held)
        return done

    def add(self, f: int, result: dict, capacity: np.ndarray, held: np.ndarray) -> None:
        """Keep fit ``f``; write the pending fits if the last write is old enough."""
        self.pending[f] = (result, capacity, held)
        if time.monotonic() - self.last >= FIT_CHECKPOINT_INTERVAL:
            self.flush()

    def flush(self) -> None:
        """Write the pending fits as one file of the ``"fit"`` group."""
        if self.pending:
            fits = np.array(list(self.pending), dtype=np.int64)
            rows = [r for r, _, _ in self.pending.values()]
            arrays = {n: np.array([r[n] for r in rows], dtype=float) for n in _FIT_FLOATS}
            arrays.update({n: np.array([r[n] for r in rows], dtype=np.int64) for n in _FIT_INTS})
            arrays.update({n: np.array([r[n] for r in rows], dtype=str) for n in _FIT_STRINGS})
            arrays["capacity"] = np.stack([c for _, c, _ in self.pending.values()])
            arrays["capacity_held"] = np.stack([h for _, _, h in self.pending.values()])
            self.store.write(self.next_id, fits, arrays, group="fit")
            self.next_id += 1
            self.pending = {}
        self.last = time.monotonic()
