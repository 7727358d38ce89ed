"""Real agency files for the reader tests: where to find them, what gmprocess read from them.

The files are the strong-motion test corpus of the USGS ``groundmotion-processing`` (gmprocess)
repository, folder ``gmprocess/data/testdata/<format>/`` at commit :data:`CORPUS_COMMIT`. They are
not committed here: the project takes no data out of other repositories into its own history. A
test asks :func:`corpus_file` for a file by its path below ``testdata/`` and gets a local copy
from the first of these that has it, or is skipped with the reason:

1. the folder named by the environment variable ``SHIPBLOCK_REAL_CORPUS`` (laid out as
   ``testdata/``: ``<folder>/dmg/ci15481673/CIWLT.V2``);
2. ``shared/records/gmprocess-testdata/`` beside the project (the team's shared data);
3. a git snapshot of the repository (``SHIPBLOCK_GMPROCESS_GIT``, or
   ``.mirror/usgs+groundmotion-processing/repo`` beside the project), read with ``git show``
   into a cache folder below the system's temporary directory.

:data:`REFERENCE` is the table of peaks that gmprocess 2.8.0's own readers give for every file of
the corpus (``tests/data/reference/gmprocess_2.8_peaks.csv``, made by
``tests/tools/gmprocess_reference_peaks.py``): the acceptance test of issue 19 compares each of
shipblock's readers with it.
"""

from __future__ import annotations

import csv
import os
import shutil
import subprocess
import tempfile
from collections import defaultdict
from pathlib import Path

import pytest

#: Commit of usgs/groundmotion-processing whose ``gmprocess/data/testdata`` the tests use.
CORPUS_COMMIT = "11df19fe8ebe11dbbbff8e974a4521637185cb65"

#: Folder of the corpus inside that repository.
CORPUS_PREFIX = "gmprocess/data/testdata"

PROJECT = Path(__file__).resolve().parents[1]
REFERENCE_CSV = PROJECT / "tests" / "data" / "reference" / "gmprocess_2.8_peaks.csv"


def _directories():
    env = os.environ.get("SHIPBLOCK_REAL_CORPUS")
    if env:
        yield Path(env)
    yield PROJECT.parent / "shared" / "records" / "gmprocess-testdata"


def _git_dirs():
    env = os.environ.get("SHIPBLOCK_GMPROCESS_GIT")
    if env:
        yield Path(env)
    yield PROJECT.parent / ".mirror" / "usgs+groundmotion-processing" / "repo"
    yield Path("/work/.mirror/usgs+groundmotion-processing/repo")


def _cache_dir() -> Path:
    return Path(tempfile.gettempdir()) / f"shipblock-real-corpus-{CORPUS_COMMIT[:12]}"


def find_corpus_file(relpath: str) -> Path | None:
    """Return a local copy of ``testdata/<relpath>``, or ``None`` if no source has it."""
    for directory in _directories():
        candidate = directory / relpath
        if candidate.is_file():
            return candidate
    cached = _cache_dir() / relpath
    if cached.is_file():
        return cached
    git = shutil.which("git")
    if git is None:
        return None
    for git_dir in _git_dirs():
        if not git_dir.is_dir():
            continue
        result = subprocess.run(
            [git, f"--git-dir={git_dir}", "show", f"{CORPUS_COMMIT}:{CORPUS_PREFIX}/{relpath}"],
            capture_output=True,
            check=False,
        )
        if result.returncode == 0 and result.stdout:
            cached.parent.mkdir(parents=True, exist_ok=True)
            partial = cached.with_name(cached.name + f".{os.getpid()}.part")
            partial.write_bytes(result.stdout)
            partial.replace(cached)  # atomic: parallel test processes never see half a file
            return cached
    return None


def corpus_file(relpath: str) -> Path:
    """Return a local copy of ``testdata/<relpath>``; skip the test if the corpus is absent."""
    path = find_corpus_file(relpath)
    if path is None:
        pytest.skip(
            f"real corpus file {relpath} not found (set SHIPBLOCK_REAL_CORPUS, or put the"
            " gmprocess testdata in shared/records/gmprocess-testdata)"
        )
    return path


def _load_reference():
    rows = defaultdict(list)
    with open(REFERENCE_CSV, newline="") as fh:
        lines = (line for line in fh if not line.startswith("#"))
        for row in csv.DictReader(lines):
            rows[row["file"]].append(row)
    return dict(rows)


#: ``{file below testdata/: [row, ...]}`` of gmprocess 2.8.0's reading (one row a trace; a single
#: row with ``trace_id == "ERROR"`` where gmprocess refused the file).
REFERENCE = _load_reference()


def reference_files(folder: str) -> list[str]:
    """Files of one corpus folder (``"dmg"``, ``"geonet"``, ...) in the reference table."""
    return sorted(f for f in REFERENCE if f.split("/", 1)[0] == folder)


def gmprocess_read(relpath: str) -> bool:
    """Whether gmprocess 2.8.0 read the file (it has no ``ERROR`` row)."""
    return all(row["trace_id"] != "ERROR" for row in REFERENCE[relpath])


def _kind(channel_or_id: str) -> str:
    """``"V"`` for a vertical channel code (last letter Z/U), else ``"H"``."""
    return "V" if channel_or_id.strip()[-1:].upper() in ("Z", "U") else "H"


#: Factors to m/s^2 of the units gmprocess reports for accelerations.
_GMPROCESS_UNITS_TO_SI = {"cm/s^2": 0.01, "cm/s/s": 0.01, "cm/s**2": 0.01}


def gmprocess_peaks_si(relpath: str) -> dict[str, list[float]]:
    """gmprocess's peaks of one file in m/s^2, ``{"H": sorted peaks, "V": [peak]}``.

    Traces whose units are not an acceleration in cm/s^2 (raw counts) are left out.
    """
    peaks = defaultdict(list)
    for row in REFERENCE[relpath]:
        factor = _GMPROCESS_UNITS_TO_SI.get(row["units"])
        if row["trace_id"] == "ERROR" or factor is None:
            continue
        peaks[_kind(row["trace_id"].split(".")[-1])].append(float(row["peak_abs"]) * factor)
    return {kind: sorted(values) for kind, values in peaks.items()}


def stream_peaks_si(stream) -> dict[str, list[float]]:
    """Peaks of a Stream in its own units (m/s^2 for shipblock's readers), as above.

    The kind of a trace is taken from ``stats.dip`` when set (vertical if ``|dip| == 90``), else
    from the channel code's last letter.
    """
    import numpy as np

    peaks = defaultdict(list)
    for trace in stream:
        dip = trace.stats.get("dip")
        kind = ("V" if abs(abs(dip) - 90.0) < 1.0 else "H") if dip is not None else _kind(
            trace.stats.channel
        )
        peaks[kind].append(float(np.max(np.abs(trace.data))))
    return {kind: sorted(values) for kind, values in peaks.items()}


def assert_peaks_match_gmprocess(stream, relpath: str, rel: float = 0.01) -> None:
    """Assert that a Stream's peaks per component kind agree with gmprocess's within ``rel``."""
    expected = gmprocess_peaks_si(relpath)
    got = stream_peaks_si(stream)
    assert {k: len(v) for k, v in got.items()} == {k: len(v) for k, v in expected.items()}, (
        relpath, got, expected)
    for kind, values in expected.items():
        for mine, theirs in zip(got[kind], values, strict=True):
            assert abs(mine - theirs) <= rel * abs(theirs), (relpath, kind, mine, theirs)
