"""Storage of batch results: per-chunk partial files and the final NetCDF dataset.

Two layers, both crash-safe:

* :class:`ChunkStore` keeps one small ``.npz`` file per finished chunk in a directory
  (``<output>.partial/``), and in the same way the fitted fragility results after the batch
  (group ``"fit"``, see :func:`shipblock.fragility.fit_step.fragility_variables`). Each file is
  written to a temporary name in the same directory and moved into place with
  :func:`os.replace`, which is atomic on POSIX and Windows, so a file with the final name is
  always complete. A ``manifest.json`` holds the fingerprint of the run (the pipeline, the
  shipblock version and the prepared records); a rerun with another fingerprint refuses to mix
  results.
* :func:`write_dataset` writes the final :class:`xarray.Dataset` to NetCDF-4 (engine
  ``netcdf4``, zlib compression of every numeric variable) through a temporary file and
  :func:`os.replace`; :func:`open_results` reads it back.

A run killed while it writes leaves its temporary file (``.<name>.<random>.tmp``) behind; the
next run removes those of its own files (:func:`remove_stale_temporaries`,
:meth:`ChunkStore.open`), never anything else.

Every variable and coordinate of a result dataset carries ``units`` and ``long_name``;
:attr:`Model.outputs <shipblock.models.base.Model.outputs>` lists those of the per-run summaries
(:data:`RUN_VARIABLES` those of the rigid model); :func:`dataset_model` says which model wrote a
result (its ``model`` attribute, or the ``[system]`` table of the pipeline it stores).
"""

from __future__ import annotations

import contextlib
import glob
import json
import os
import re
import secrets
import shutil
import tomllib
import zipfile
from pathlib import Path

import numpy as np
import xarray as xr

from shipblock import checks
from shipblock.errors import ShipblockError
from shipblock.fragility.filesystem import write_failure
from shipblock.models import DEFAULT_MODEL, Model, get_model, model_names
from shipblock.models.rigid import RUN_VARIABLES

__all__ = [
    "COMPRESSION_LEVEL",
    "RUN_VARIABLES",
    "ChunkStore",
    "StoreError",
    "check_metadata",
    "dataset_model",
    "open_results",
    "remove_stale_temporaries",
    "write_dataset",
]

#: zlib compression level of numeric NetCDF variables [-] (1 fastest ... 9 smallest).
COMPRESSION_LEVEL = 4

_MANIFEST = "manifest.json"
#: File groups of a partial-results directory: batch chunks and fitted results.
_GROUPS = ("chunk", "fit")
#: The random part of a temporary file's name: 8 hex characters (:func:`_temporary`), or the 8
#: characters ``tempfile.mkstemp`` used in earlier builds, so that their leftovers go too.
_RANDOM = r"[A-Za-z0-9_]{8}"


class StoreError(ShipblockError, ValueError):
    """A partial-results directory or result file cannot be used."""


# --------------------------------------------------------------------------------------------
# partial results
# --------------------------------------------------------------------------------------------


def _temporary(path: Path) -> tuple[int, str]:
    """A new temporary file for ``path``, in its folder: ``.<name>.<8 random hex>.tmp``.

    Opened exclusively with mode 0666, which the umask reduces as for any new file (0644 under
    the usual 022): ``tempfile.mkstemp`` creates its files 0600 whatever the umask, and the
    rename would keep that, leaving result files unreadable to the rest of a team.
    """
    for _ in range(100):
        tmp = path.parent / f".{path.name}.{secrets.token_hex(4)}.tmp"
        try:
            return os.open(tmp, os.O_RDWR | os.O_CREAT | os.O_EXCL, 0o666), str(tmp)
        except FileExistsError:
            continue
    raise StoreError(f"cannot create a temporary file next to {path}")


def _is_temporary_of(name: str, target: str) -> bool:
    """Whether the file name ``name`` is one of :func:`_temporary`'s names for ``target``."""
    return re.fullmatch(re.escape(f".{target}.") + _RANDOM + r"\.tmp", name) is not None


def remove_stale_temporaries(path) -> list[Path]:
    """Delete the temporary files a killed writer of ``path`` left in its folder.

    Only files named as :func:`write_dataset` names its temporary files for this very output
    (``.<name>.<8 random characters>.tmp``) are removed. Call it before a run starts writing
    ``path``: a temporary file of a writer still running would be removed too.

    Parameters
    ----------
    path : str or os.PathLike
        The output file.

    Returns
    -------
    list of pathlib.Path
        The files removed.
    """
    path = Path(path)
    removed = []
    if not path.parent.is_dir():
        return removed
    for candidate in path.parent.glob(f".{glob.escape(path.name)}.*.tmp"):
        if _is_temporary_of(candidate.name, path.name) and candidate.is_file():
            with contextlib.suppress(FileNotFoundError):
                candidate.unlink()
                removed.append(candidate)
    return removed


def _failed(path: Path, exc: BaseException, tmp: str | None, size: int | None = None):
    """Remove the temporary file of a failed write; a StoreError naming the file and the cause
    (:func:`~shipblock.fragility.filesystem.write_failure`), or None for other exceptions."""
    problem = write_failure(path, exc, size)  # measured with the temporary file still there
    if tmp is not None:
        with contextlib.suppress(OSError):
            # emptied first: HDF5 keeps a file it failed to close open, and an unlinked file
            # still open would hold its space until the process ends
            os.truncate(tmp, 0)
        with contextlib.suppress(OSError):
            os.unlink(tmp)
    return None if problem is None else StoreError(f"cannot write {path}: {problem}")


def _atomic_write(path: Path, write) -> None:
    """Write ``path`` through a temporary file in the same directory and ``os.replace``."""
    tmp = None
    try:
        fd, tmp = _temporary(path)
        with os.fdopen(fd, "wb") as fh:
            write(fh)
            fh.flush()
            os.fsync(fh.fileno())
        os.replace(tmp, path)
    except BaseException as exc:
        error = _failed(path, exc, tmp)
        if error is None:
            raise
        raise error from exc


class ChunkStore:
    """One ``.npz`` file per finished chunk, in a directory.

    Parameters
    ----------
    directory : str or os.PathLike
        The partial-results directory (created when needed).
    fingerprint : str
        Identity of the run; chunks of a run with another fingerprint are never used.

    Raises
    ------
    StoreError
        From :meth:`open` if the directory holds chunks of another run.
    """

    def __init__(self, directory, fingerprint: str):
        self.directory = Path(directory)
        self.fingerprint = str(fingerprint)

    def open(self, info: dict | None = None) -> ChunkStore:
        """Create the directory and its manifest, or check the manifest of an existing one.

        Temporary files a killed writer left in the directory are removed.

        Parameters
        ----------
        info : dict, optional
            Extra JSON-serialisable facts written to a new manifest (case count, chunk size).

        Returns
        -------
        ChunkStore
            ``self``.

        Raises
        ------
        StoreError
            If an existing manifest has another fingerprint or cannot be read.
        """
        self.directory.mkdir(parents=True, exist_ok=True)
        own = re.compile(r"\.(?:" + "|".join(_GROUPS) + r")-\d{6}\.npz\." + _RANDOM + r"\.tmp")
        for candidate in self.directory.glob(".*.tmp"):
            if own.fullmatch(candidate.name) or _is_temporary_of(candidate.name, _MANIFEST):
                with contextlib.suppress(FileNotFoundError):
                    candidate.unlink()
        manifest = self.directory / _MANIFEST
        if manifest.exists():
            try:
                found = json.loads(manifest.read_text())["fingerprint"]
            except (OSError, ValueError, KeyError) as exc:
                raise StoreError(f"{manifest}: unreadable manifest ({exc})") from exc
            if found != self.fingerprint:
                raise StoreError(
                    f"{self.directory} holds partial results of a different run (the pipeline, "
                    "the records or the shipblock version changed); delete the directory to "
                    "start again"
                )
            return self
        text = json.dumps({"fingerprint": self.fingerprint, **(info or {})}, indent=1)
        _atomic_write(manifest, lambda fh: fh.write(text.encode()))
        return self

    def _path(self, chunk_id: int, group: str = "chunk") -> Path:
        if group not in _GROUPS:
            raise StoreError(f"unknown file group {group!r}; groups: {', '.join(_GROUPS)}")
        return self.directory / f"{group}-{int(chunk_id):06d}.npz"

    def completed(self, group: str = "chunk") -> set[int]:
        """Ids of the chunks (of a file group) whose files exist.

        Parameters
        ----------
        group : {"chunk", "fit"}
            Batch chunks, or fitted results.

        Returns
        -------
        set of int
        """
        if not self.directory.is_dir():
            return set()
        prefix = self._path(0, group).name[:-len("000000.npz")]
        out = set()
        for p in self.directory.glob(f"{prefix}*.npz"):
            with contextlib.suppress(ValueError):
                out.add(int(p.stem[len(prefix):]))
        return out

    def write(self, chunk_id: int, cases, arrays: dict, group: str = "chunk") -> None:
        """Write one finished chunk atomically.

        The float arrays are stored as the rows of one 2-D array (a few large entries in the
        ``.npz`` file rather than one per variable), string arrays at their narrowest width.

        Parameters
        ----------
        chunk_id : int
            The chunk number.
        cases : array_like of int
            Case numbers of the chunk.
        arrays : dict of numpy.ndarray
            Per-case results (float arrays of the length of ``cases``) and optional string
            arrays (``run_error``) or other arrays.
        group : {"chunk", "fit"}
            Batch chunk (``cases`` are case numbers) or fitted results (``cases`` are fit
            numbers).
        """
        cases = np.asarray(cases, dtype=np.int64)
        payload = {"cases": cases}
        names = []
        rows = []
        for name, value in arrays.items():
            value = np.asarray(value)
            if value.dtype == np.float64 and value.shape == cases.shape:
                names.append(name)
                rows.append(value)
            elif value.dtype.kind == "U" and value.size:
                width = max(1, int(np.char.str_len(value).max()))
                payload[f"v_{name}"] = value.astype(f"U{width}")
            else:
                payload[f"v_{name}"] = value
        if rows:
            payload["names"] = np.array(names)
            payload["values"] = np.stack(rows)
        _atomic_write(self._path(chunk_id, group), lambda fh: np.savez(fh, **payload))

    def read(self, chunk_id: int, group: str = "chunk") -> tuple[np.ndarray, dict]:
        """Read a finished chunk.

        Parameters
        ----------
        chunk_id : int
            The chunk number.
        group : {"chunk", "fit"}
            Its file group.

        Returns
        -------
        cases : numpy.ndarray of int
        arrays : dict of numpy.ndarray

        Raises
        ------
        StoreError
            If the file is unreadable (it is then best deleted and recomputed).
        """
        path = self._path(chunk_id, group)
        try:
            with np.load(path, allow_pickle=False) as data:
                cases = data["cases"]
                arrays = {}
                if "values" in data.files:
                    arrays.update(zip(data["names"].tolist(), data["values"], strict=True))
                arrays.update({k[2:]: data[k] for k in data.files if k.startswith("v_")})
        except (OSError, ValueError, KeyError, zipfile.BadZipFile) as exc:
            raise StoreError(f"{path}: unreadable chunk file ({exc})") from exc
        return cases, arrays

    def discard(self, chunk_id: int, group: str = "chunk") -> None:
        """Delete one chunk file (e.g. an unreadable one)."""
        with contextlib.suppress(FileNotFoundError):
            self._path(chunk_id, group).unlink()

    def remove(self) -> None:
        """Delete the whole directory."""
        shutil.rmtree(self.directory, ignore_errors=True)


# --------------------------------------------------------------------------------------------
# final dataset
# --------------------------------------------------------------------------------------------


def dataset_model(ds) -> Model | None:
    """The model that wrote a result or history dataset.

    Parameters
    ----------
    ds : xarray.Dataset
        A result of :func:`shipblock.run_pipeline` or a run's histories.

    Returns
    -------
    shipblock.models.Model or None
        The model named by the attribute ``model``, else by ``[system] model`` of the stored
        pipeline (a file of an earlier version), else the default (rigid) model; None if the
        model named is not registered here.
    """
    name = ds.attrs.get("model")
    if name is None:
        try:
            doc = tomllib.loads(str(ds.attrs.get("pipeline", "")))
        except tomllib.TOMLDecodeError:
            doc = {}
        system = doc.get("system", {})
        name = system.get("model", DEFAULT_MODEL) if isinstance(system, dict) else DEFAULT_MODEL
    name = str(name)
    return get_model(name) if name in model_names() else None


def check_metadata(ds: xr.Dataset) -> None:
    """Check that every variable and coordinate has ``units`` and ``long_name``.

    Parameters
    ----------
    ds : xarray.Dataset

    Raises
    ------
    StoreError
        Naming the first variable that lacks one.
    """
    for name, var in ds.variables.items():
        for key in ("units", "long_name"):
            if key not in var.attrs:
                raise StoreError(f"variable {name!r} has no {key!r} attribute")


def _encoding(ds: xr.Dataset) -> dict:
    enc = {}
    for name, var in ds.variables.items():
        if var.dtype.kind in "fiub" and var.ndim > 0:
            enc[name] = {"zlib": True, "complevel": COMPRESSION_LEVEL}
    return enc


def write_dataset(ds: xr.Dataset, path) -> Path:
    """Write a result dataset to NetCDF-4 atomically.

    The file is written with the ``netcdf4`` engine and zlib compression of every numeric
    variable to a temporary file next to ``path``, then renamed over ``path``: a reader (or a
    crash) never sees a half-written file. It gets the permissions of any new file (0666 less
    the umask: 0644 under the usual umask 022).

    Parameters
    ----------
    ds : xarray.Dataset
        The dataset; must pass :func:`check_metadata`.
    path : str or os.PathLike
        Destination (parent directories are created).

    Returns
    -------
    pathlib.Path
        ``path``.

    Raises
    ------
    StoreError
        If the file cannot be written: naming it and the cause (a full disk, with the space
        left; a name too long; ...) rather than the NetCDF library's ``HDF error``. Nothing
        is left behind.
    """
    check_metadata(ds)
    path = Path(path)
    tmp = None
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        fd, tmp = _temporary(path)
        os.close(fd)
        ds.to_netcdf(tmp, engine="netcdf4", format="NETCDF4", encoding=_encoding(ds))
        os.replace(tmp, path)
    except BaseException as exc:
        error = _failed(path, exc, tmp, ds.nbytes)
        if error is None:
            raise
        raise error from exc
    return path


def open_results(path) -> xr.Dataset:
    """Read a result dataset fully into memory (the file is closed on return).

    Parameters
    ----------
    path : str or os.PathLike
        A file written by :func:`write_dataset`.

    Returns
    -------
    xarray.Dataset

    Raises
    ------
    ParameterTypeError
        If ``path`` is not a path (``None``, bytes, a number).
    """
    path = checks.pathname(path, "path", "a result file (NetCDF)")
    with xr.open_dataset(path, engine="netcdf4") as ds:
        return ds.load()
