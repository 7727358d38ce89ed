"""What a file system refuses: names too long, a full disk; said with the file and the cause.

A study writes its output NetCDF file and, beside it, files of its own making: the temporary
file of the atomic write (``.<name>.<8 random>.tmp``, :mod:`shipblock.fragility.store`), the
partial-results directory ``<name>.partial`` and the lock ``<name>.lock``
(:mod:`shipblock.fragility.lock`). The longest of these names must fit the file system's limit
on one name (``NAME_MAX``, 255 bytes on most): :func:`output_name_problem` checks it before a
run starts, so a name that could never be written is refused at once rather than after the
batch.

A write that fails for want of space surfaces from the NetCDF library as ``RuntimeError:
NetCDF: HDF error``, naming neither the file nor the cause; :func:`write_failure` says both
(the errno's words for an :class:`OSError`, else the free space measured while the failed
temporary file is still there).
"""

from __future__ import annotations

import errno
import os
import shutil
from pathlib import Path

__all__ = ["BESIDE_OUTPUT", "name_max", "output_name_problem", "write_failure"]

#: Names a run gives files beside its output ``name``: the temporary file of the atomic write
#: (8 random characters), the partial-results directory and the lock.
BESIDE_OUTPUT = (".{name}.XXXXXXXX.tmp", "{name}.partial", "{name}.lock")

#: ``NAME_MAX`` assumed where the file system does not say [bytes].
DEFAULT_NAME_MAX = 255

#: Free space [bytes] under which a failed write is put down to a full disk, whatever the size
#: of what was written.
FULL_BELOW = 1 << 20


def _existing_folder(path: Path) -> Path:
    """The nearest folder of ``path`` that exists (a run creates the missing ones)."""
    folder = path.parent
    while not folder.is_dir() and folder != folder.parent:
        folder = folder.parent
    return folder


def name_max(folder) -> int:
    """Longest file name [bytes] the file system of ``folder`` takes (``pathconf`` ``NAME_MAX``)."""
    try:
        return int(os.pathconf(folder, "PC_NAME_MAX"))
    except (OSError, ValueError, AttributeError):  # no pathconf (Windows) or no answer
        return DEFAULT_NAME_MAX


def output_name_problem(path) -> str | None:
    """Why the output ``path``, or a file a run writes beside it, cannot be named; None if fine.

    Parameters
    ----------
    path : str or os.PathLike
        The output file (its folder need not exist yet).

    Returns
    -------
    str or None
        The name, its length in bytes, the longest name written beside it and the file system's
        limit, or None when every name fits.
    """
    path = Path(os.path.abspath(os.fspath(path)))
    folder = _existing_folder(path)
    limit = name_max(folder)
    names = [path.name] + [p.format(name=path.name) for p in BESIDE_OUTPUT]
    longest = max(names, key=lambda n: len(os.fsencode(n)))
    size = len(os.fsencode(longest))
    if size <= limit:
        return None
    room = limit - (size - len(os.fsencode(path.name)))
    return (f"the file name {path.name!r} is {len(os.fsencode(path.name))} bytes long and a run "
            f"writes {longest!r} ({size} bytes) beside it, but names on the file system of "
            f"{folder} are at most {limit} bytes: choose an output name of at most {room} bytes")


def write_failure(path, exc: BaseException, size: int | None = None) -> str | None:
    """What a failed write of ``path`` ran into, in words; None if ``exc`` is not a write error.

    Call it before the temporary file of the failed write is removed: the free space it
    measures then is what the write met.

    Parameters
    ----------
    path : str or os.PathLike
        The file being written (its folder is where the space is measured).
    exc : BaseException
        What the write raised: an :class:`OSError` (its errno decides), or the NetCDF
        library's ``RuntimeError`` (the free space decides).
    size : int, optional
        Bytes the write needed, about (the dataset's uncompressed size): less free space
        than this also counts as a full disk.

    Returns
    -------
    str or None
    """
    if not isinstance(exc, OSError | RuntimeError):
        return None
    folder = _existing_folder(Path(path))
    code = getattr(exc, "errno", None)
    if code == errno.ENAMETOOLONG:
        return (f"a file name is too long for the file system of {folder} (at most "
                f"{name_max(folder)} bytes)")
    try:
        free = shutil.disk_usage(folder).free
    except OSError:
        free = None
    if code in (errno.ENOSPC, errno.EDQUOT) or (
            free is not None and free < max(FULL_BELOW, size or 0)):
        space = "" if free is None else f", {free / 1e6:.1f} MB free"
        what = "quota exceeded" if code == errno.EDQUOT else "the disk is full"
        return f"{what} ({folder}{space}): free some space and run again"
    cause = os.strerror(code) if isinstance(code, int) and code > 0 else str(exc)
    space = "" if free is None else f"; {free / 1e6:.1f} MB free on {folder}"
    return f"{cause or type(exc).__name__}{space}"
