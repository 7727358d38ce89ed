"""Benchmark of the record readers: files per second read and converted, per format.

Behind ``shipblock bench --read SOURCE ...``. Every file of the sources is read once to learn its
format (files that cannot be read are counted, not timed); then, per format, the files of that
format are read again and again (:func:`shipblock.io.read_record`) for at least ``min_seconds``,
and the whole set is read and converted into ground motions by
:func:`shipblock.records.folders.read_motions` (grouping, unit conversion, alignment). Measured, never
asserted in unit tests.
"""

from __future__ import annotations

import time
import warnings
from collections import defaultdict

from shipblock.records.folders import NOT_WAVEFORMS, expand_sources, read_motions
from shipblock.errors import ShipblockError
from shipblock.io import read_record

__all__ = ["reader_throughput", "write_reader_throughput"]


def _timed_rounds(call, min_seconds: float) -> tuple[int, float]:
    """Call ``call`` until ``min_seconds`` have passed (at least once); return (rounds, seconds)."""
    rounds, start = 0, time.perf_counter()
    while True:
        call()
        rounds += 1
        elapsed = time.perf_counter() - start
        if elapsed >= min_seconds:
            return rounds, elapsed


def reader_throughput(sources, min_seconds: float = 1.0) -> dict:
    """Files per second and megabytes per second of each format's reader.

    Parameters
    ----------
    sources : str, os.PathLike or list of them
        Folders, glob patterns or files of records.
    min_seconds : float, optional
        Least time each format (and the final read_motions) is timed for [s].

    Returns
    -------
    dict
        ``formats``: ``{format: {"files", "bytes", "files_per_s", "mb_per_s"}}``; ``unreadable``:
        the number of files no reader took; ``motions``: records, files, seconds and
        ``files_per_s`` of read_motions over all sources.
    """
    by_format: dict[str, list] = defaultdict(list)
    unreadable = 0
    paths = [p for p in expand_sources(sources)
             if p.suffix.lower() not in NOT_WAVEFORMS and p.suffix.lower() != ".xml"]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        for path in paths:
            try:
                stream = read_record(path)
            except ShipblockError:
                unreadable += 1
                continue
            by_format[str(stream[0].stats.get("_format", "?"))].append(path)
        formats = {}
        for fmt, files in sorted(by_format.items()):
            size = sum(f.stat().st_size for f in files)

            def read_all(files=files):
                for f in files:
                    read_record(f)

            rounds, seconds = _timed_rounds(read_all, min_seconds)
            formats[fmt] = {
                "files": len(files),
                "bytes": size,
                "files_per_s": rounds * len(files) / seconds,
                "mb_per_s": rounds * size / seconds / 1e6,
            }
        found = []
        rounds, seconds = _timed_rounds(lambda: found.append(read_motions(sources)), min_seconds)
    last = found[-1]
    return {
        "formats": formats,
        "unreadable": unreadable,
        "motions": {
            "records": len(last.motions),
            "failures": len(last.failures),
            "files": len(paths),
            "seconds_per_pass": seconds / rounds,
            "files_per_s": rounds * len(paths) / seconds,
        },
    }


def write_reader_throughput(result: dict, out) -> None:
    """Print :func:`reader_throughput`'s result as a table."""
    out.write("reader throughput (read_record, mean over repeated passes)\n")
    out.write(f"{'format':<20} {'files':>6} {'files/s':>10} {'MB/s':>8}\n")
    for fmt, row in result["formats"].items():
        out.write(f"{fmt:<20} {row['files']:>6} {row['files_per_s']:>10.1f}"
                  f" {row['mb_per_s']:>8.2f}\n")
    m = result["motions"]
    out.write(f"read_motions (read, group, convert to m/s^2, align): {m['files']} files ->"
              f" {m['records']} records, {m['failures']} not used; {m['files_per_s']:.1f} files/s"
              f" ({m['seconds_per_pass']:.3f} s a pass)\n")
    if result["unreadable"]:
        out.write(f"{result['unreadable']} files no reader took (not timed)\n")
