"""Real agency files for the reader tests: where to find them, what gmprocess read from them.

Two collections of real files are used, both kept outside the project's history (the project
takes no data out of other repositories into its own) in the team's shared folder beside the
project root, ``../shared/records/``:

* ``gmprocess-testdata/``: the strong-motion test corpus of the USGS ``groundmotion-processing``
  (gmprocess) repository, folder ``gmprocess/data/testdata/<format>/`` at commit
  :data:`CORPUS_COMMIT` (:func:`corpus_file`);
* ``outside-tests/``: files from other public projects, its README naming each source
  (:func:`outside_file`).

The environment variables ``SHIPBLOCK_REAL_CORPUS`` and ``SHIPBLOCK_OUTSIDE_TESTS`` name other
folders laid out the same way. A file that is absent skips its test on a developer's machine but
fails it in CI (environment variable ``CI`` set to ``true`` or ``1``): the real-file tests must
run there, not skip.

:data:`REFERENCE` is the table of peaks that gmprocess 2.8.0's own readers give for every file of
the corpus (``tests/data/reference/gmprocess_2.8_peaks.csv``, made by
``tests/tools/gmprocess_reference_peaks.py``): the acceptance test of issue 19 compares each of
shipblock's readers with it.
"""

from __future__ import annotations

import csv
import os
from collections import defaultdict
from pathlib import Path

import pytest

#: Commit of usgs/groundmotion-processing whose ``gmprocess/data/testdata`` the tests use.
CORPUS_COMMIT = "11df19fe8ebe11dbbbff8e974a4521637185cb65"

PROJECT = Path(__file__).resolve().parents[1]
SHARED_RECORDS = PROJECT.parent / "shared" / "records"
REFERENCE_CSV = PROJECT / "tests" / "data" / "reference" / "gmprocess_2.8_peaks.csv"


def in_ci() -> bool:
    """Whether the tests run in CI (``CI`` set to ``true``/``1``/``yes``, as CI services do)."""
    return os.environ.get("CI", "").strip().lower() in ("true", "1", "yes")


def _folder(variable: str, default: str) -> Path:
    env = os.environ.get(variable)
    return Path(env) if env else SHARED_RECORDS / default


def corpus_dir() -> Path:
    """Folder of the gmprocess corpus (``testdata/``)."""
    return _folder("SHIPBLOCK_REAL_CORPUS", "gmprocess-testdata")


def outside_dir() -> Path:
    """Folder of the files from other projects."""
    return _folder("SHIPBLOCK_OUTSIDE_TESTS", "outside-tests")


def find_corpus_file(relpath: str) -> Path | None:
    """Return ``testdata/<relpath>`` of the gmprocess corpus, or ``None`` if it is absent."""
    candidate = corpus_dir() / relpath
    return candidate if candidate.is_file() else None


def _missing(what: str, folder: Path, variable: str):
    message = (f"real test file {what} not found in {folder} (the team's shared records beside"
               f" the project root, or the folder named by {variable})")
    if in_ci():
        pytest.fail(message + "; CI must run the real-file tests, not skip them", pytrace=False)
    pytest.skip(message)


def corpus_file(relpath: str) -> Path:
    """Return ``testdata/<relpath>``; skip the test if the corpus is absent (fail in CI)."""
    path = find_corpus_file(relpath)
    if path is None:
        _missing(relpath, corpus_dir(), "SHIPBLOCK_REAL_CORPUS")
    return path


def outside_file(relpath: str) -> Path:
    """Return ``outside-tests/<relpath>``; skip the test if it is absent (fail in CI)."""
    path = outside_dir() / relpath
    if not path.is_file():
        _missing(relpath, outside_dir(), "SHIPBLOCK_OUTSIDE_TESTS")
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
