"""One run per output: an advisory lock ``<output>.lock`` held while a run writes its output.

Two runs of one output would both compute everything, and each removes, as left by a killed
run, the temporary files it finds beside the output and in ``<output>.partial/``: one could
delete a file the other is writing. :func:`hold_output` lets one run at a time hold an output;
a second run is refused, naming the holder's process id and host, or waits for it
(``wait=True``, ``shipblock run --wait``).

The lock is ``flock(2)`` on the file ``<output>.lock`` (the kernel drops it when its holder
ends, however it ends), which holds the holder's pid, host and start time for the message.
A lock still held although the pid it names is dead on this host is held by processes that
outlived their run (they inherited the file at a fork): it is taken over, with a warning. The
holder removes the file when it is done; a run that takes the lock checks that the file it
locked is still the one of that name, so two runs can never both hold it.

Notes
-----
``flock`` is advisory: it keeps shipblock runs apart, not other programs. On NFS, Linux
emulates it with ``fcntl`` byte-range locks, which the server keeps; a file system that has no
locks at all gets a warning and no lock. Without :mod:`fcntl` (Windows) there is no lock.
"""

from __future__ import annotations

import contextlib
import errno
import json
import logging
import os
import socket
import time
from datetime import UTC, datetime
from pathlib import Path

from shipblock.errors import ShipblockError

try:
    import fcntl
except ImportError:  # Windows
    fcntl = None

__all__ = ["LOCK_SUFFIX", "OutputLockedError", "hold_output", "lock_path"]

logger = logging.getLogger(__name__)

#: Suffix of the lock file beside an output.
LOCK_SUFFIX = ".lock"

#: Seconds between two tries of a waiting run.
WAIT_POLL = 0.5


class OutputLockedError(ShipblockError):
    """Another run holds the output; ``holder`` is what its lock file says (pid, host, start)."""

    def __init__(self, output, holder: dict):
        self.output = str(output)
        self.holder = dict(holder)
        super().__init__(f"{self.output} is being written by another run ({_who(holder)}): "
                         "wait for it to end, or run again with --wait to start once it has")

    def __reduce__(self):
        """Keep the error picklable."""
        return (type(self), (self.output, self.holder))


def lock_path(output) -> Path:
    """The lock file of an output: ``<output>.lock`` beside it."""
    output = Path(output)
    return output.with_name(output.name + LOCK_SUFFIX)


def _who(holder: dict) -> str:
    if not holder.get("pid"):
        return "pid not yet written"
    return (f"pid {holder['pid']} on {holder.get('host', '?')}, started "
            f"{holder.get('started', '?')}")


def _read_holder(fd: int) -> dict:
    """What the lock file open at ``fd`` says about its holder ({} if nothing readable)."""
    with contextlib.suppress(OSError, ValueError):
        text = os.pread(fd, 4096, 0).decode()
        found = json.loads(text) if text.strip() else {}
        if isinstance(found, dict):
            return found
    return {}


def _holder_is_dead(holder: dict) -> bool:
    """Whether the holder's process is known to be gone: a pid on this host that is not running."""
    pid = holder.get("pid")
    if not isinstance(pid, int) or pid <= 0 or holder.get("host") != socket.gethostname():
        return False
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return True
    except OSError:  # EPERM: it runs, as another user
        return False
    return False


def _same_file(fd: int, path: Path) -> bool:
    """Whether ``fd`` is still the file named ``path`` (a releasing holder unlinks it)."""
    try:
        a, b = os.fstat(fd), os.stat(path)
    except FileNotFoundError:
        return False
    return (a.st_dev, a.st_ino) == (b.st_dev, b.st_ino)


def _try_lock(path: Path) -> tuple[int | None, dict]:
    """One try: (the locked descriptor, {}) or (None, the holder)."""
    fd = os.open(path, os.O_RDWR | os.O_CREAT | getattr(os, "O_CLOEXEC", 0), 0o666)
    try:
        fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
    except BlockingIOError:
        holder = _read_holder(fd)
        os.close(fd)
        return None, holder
    except BaseException:
        os.close(fd)
        raise
    if not _same_file(fd, path):  # locked a file its holder has just removed: try again
        os.close(fd)
        return None, {}
    return fd, {}


def _acquire(output: Path, wait: bool) -> int | None:
    path = lock_path(output)
    said = None
    while True:
        try:
            fd, holder = _try_lock(path)
        except OSError as exc:
            if exc.errno in (errno.ENOLCK, errno.EOPNOTSUPP, errno.ENOSYS):
                logger.warning("the file system of %s has no locks: nothing stops a second run "
                               "of the same output (%s)", output, exc)
                return None
            raise
        if fd is not None:
            os.ftruncate(fd, 0)
            os.pwrite(fd, json.dumps({
                "pid": os.getpid(), "host": socket.gethostname(),
                "started": datetime.now(UTC).isoformat(timespec="seconds")}).encode(), 0)
            return fd
        if _holder_is_dead(holder):
            logger.warning("%s: the run that locked it (%s) is gone but processes it left "
                           "still hold the lock; taking it over", path, _who(holder))
            with contextlib.suppress(FileNotFoundError):
                path.unlink()
            continue
        if holder and not wait:
            raise OutputLockedError(output, holder)
        if holder and holder != said:
            logger.warning("waiting for the run that holds %s (%s)", output, _who(holder))
            said = holder
        time.sleep(WAIT_POLL if holder else 0.01)


@contextlib.contextmanager
def hold_output(output, wait: bool = False):
    """Hold ``output`` for the block: no other shipblock run writes it meanwhile.

    Parameters
    ----------
    output : str or os.PathLike
        The output file; its folder must exist. The lock is ``<output>.lock``.
    wait : bool
        If another run holds the output: wait until it ends (True) or raise (False).

    Yields
    ------
    pathlib.Path or None
        The lock file, or None where locks are not available.

    Raises
    ------
    OutputLockedError
        If another run holds the output and ``wait`` is False: the message gives its pid, host
        and start time.
    """
    output = Path(output)
    fd = None if fcntl is None else _acquire(output, bool(wait))
    try:
        yield None if fd is None else lock_path(output)
    finally:
        if fd is not None:
            with contextlib.suppress(FileNotFoundError):
                lock_path(output).unlink()  # while still locked: see _try_lock
            os.close(fd)
