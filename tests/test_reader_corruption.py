"""Damaged MiniSEED records are refused by name, cheaply, and never read as good (issue 23).

Every damaged file here is made from a shipped record, ``records/south-napa-2014/NP.1737.mseed``
(USGS NSMP, raw counts, Steim2, 4096-byte records: 10 of HNN, 10 of HNE, 12 of HNZ, 2014-08-24
10:20:26-10:23:10.995 at 200 Hz), by patching bytes the way the issue's fuzz campaign did: a record's
year or day-of-year (bytes 20-23 of its fixed header, SEED manual ch. 8), a file cut short, single bit
flips in Steim2 data frames. Each test first shows what obspy alone makes of the damaged file (the
truth a reader must not hide), then that shipblock refuses it with a :class:`RecordError` naming
the file. Time and memory are measured in development, not asserted here: the refusal of a record
moved 100 years away takes about 6 ms and 0.5 MB (tracemalloc) instead of allocating the span.
"""

from __future__ import annotations

import shutil
import struct
import warnings
from pathlib import Path

import numpy as np
import obspy
import pytest

from shipblock.records.catalogue import load_catalogue
from shipblock.records.folders import read_motions
from shipblock.errors import RecordError
from shipblock.io import read_record
from shipblock.records.reading import read_motion

NAPA = Path(__file__).parent.parent / "records" / "south-napa-2014"
RECORD = 4096  # record length of the shipped files [bytes]
YEAR, DAY = 20, 22  # offsets of the BTIME year and day-of-year in a fixed header [bytes]


def _raw(station: str = "NP.1737") -> bytes:
    return (NAPA / f"{station}.mseed").read_bytes()


def _with_time_field(raw: bytes, record: int, offset: int, value: int) -> bytes:
    patched = bytearray(raw)
    start = record * RECORD + offset
    patched[start:start + 2] = struct.pack(">H", value)
    return bytes(patched)


def _write(tmp_path: Path, name: str, raw: bytes) -> Path:
    path = tmp_path / name
    path.write_bytes(raw)
    return path


def _obspy_read(path: Path):
    """What obspy alone reads, and the warnings it gives."""
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        stream = obspy.read(str(path))
    return stream, [str(w.message) for w in caught]


# ------------------------------------------------------------------------ damaged record times


@pytest.mark.parametrize(
    ("record", "offset", "value", "words"),
    [
        (5, DAY, 300, r"N has 2 gap\(s\).* the longest 5\.52951e\+06 s \(64 days\)"),  # 236 -> 300
        (5, YEAR, 2114, r"N has 2 gap\(s\).* the longest 3\.15567e\+09 s \(100 years\)"),
        (0, YEAR, 1914, r"N has 1 gap\(s\), the first of 3\.15576e\+09 s \(100 years\)"),  # first
        (31, YEAR, 2114, r"Z has 1 gap\(s\), the first of 3\.15567e\+09 s \(100 years\)"),  # last
    ],
)
@pytest.mark.parametrize("gaps", ["refuse", "interpolate"])
def test_record_time_moved_far_away_is_refused_before_merging(tmp_path, record, offset, value,
                                                              words, gaps):
    path = _write(tmp_path, "NP.1737.mseed", _with_time_field(_raw(), record, offset, value))
    stream, _ = _obspy_read(path)
    span = max(tr.stats.endtime for tr in stream) - min(tr.stats.starttime for tr in stream)
    assert span > 5e6  # merging with fill would allocate > 1e9 samples (the 10.9 GB)
    with pytest.raises(RecordError, match=r"NP\.1737\.mseed: channel NP\.1737\.\.HN" + words):
        read_motion(path, inventory=NAPA / "NP.1737.xml", gaps=gaps)


def test_record_year_beyond_any_earthquake_is_refused_when_read(tmp_path):
    path = _write(tmp_path, "NP.1737.mseed", _with_time_field(_raw(), 5, YEAR, 2014 ^ 0x8000))
    with pytest.raises(RecordError, match=r"NP\.1737\.mseed: channel NP\.1737\.\.HNN starts"
                                          r" 1\.03547e\+12 s from 1970-01-01, outside 1900-2200"):
        read_record(path)


def test_damaged_file_costs_one_named_failure_in_a_folder_and_a_catalogue(tmp_path):
    for name in ("NP.1765.mseed", "NP.1765.xml", "NP.1737.xml"):
        shutil.copy(NAPA / name, tmp_path / name)
    _write(tmp_path, "NP.1737.mseed", _with_time_field(_raw(), 5, DAY, 300))
    found = read_motions(tmp_path)
    assert [m.metadata["station"]["station"] for m in found] == ["1765"]
    assert len(found.failures) == 1
    where, why = found.failures[0]
    assert "NP.1737.mseed" in where and "64 days" in why
    # The displaced record (18 s of HNN in October) does not become a record of its own.
    assert all(m.npts == 42000 for m in found)

    catalogue = tmp_path / "catalogue.toml"
    catalogue.write_text("".join(
        f'[[record]]\nid = "{sta}"\nfiles = ["{sta}.mseed"]\ninventory = "{sta}.xml"\n'
        f'station = "{sta}"\n[record.components]\nHNN = "H1"\nHNE = "H2"\nHNZ = "V"\n\n'
        for sta in ("NP.1737", "NP.1765")
    ))
    entries = load_catalogue(catalogue)
    with pytest.raises(RecordError, match=r"NP\.1737\.mseed: .*64 days"):
        entries["NP.1737"].read()
    assert entries["NP.1765"].read().npts == 42000


# ---------------------------------------------------------------------------- truncated files


@pytest.mark.parametrize("inside", [2500, 3500, 4000])
def test_file_cut_inside_a_record_is_refused(tmp_path, inside):
    """libmseed drops a last record cut after ~2 kB of its 4 kB without a warning."""
    cut = 12 * RECORD + inside  # inside the third HNE record
    path = _write(tmp_path, "cut.mseed", _raw()[:cut])
    stream, messages = _obspy_read(path)
    assert messages == [] and stream.select(channel="HNE")[0].stats.mseed.number_of_records == 2
    with pytest.raises(RecordError, match=rf"cut\.mseed: is damaged: its records hold {12 * RECORD}"
                                          rf" bytes but the file has {cut}"):
        read_record(path)


def test_file_cut_where_libmseed_warns_is_refused(tmp_path):
    path = _write(tmp_path, "cut.mseed", _raw()[: 12 * RECORD + 1000])
    _, messages = _obspy_read(path)
    assert any("Unexpected end of file" in m for m in messages)
    with pytest.raises(RecordError, match=r"cut\.mseed: is damaged .*Unexpected end of file"):
        read_motion(path, inventory=NAPA / "NP.1737.xml")


def test_file_cut_between_records_refused_when_a_component_loses_too_much(tmp_path):
    """Cut after record 30: HNZ ends 20.7 s (12.6 %) before the horizontals: refused."""
    path = _write(tmp_path, "cut.mseed", _raw()[: 30 * RECORD])
    stream, messages = _obspy_read(path)
    assert messages == [] and stream.select(channel="HNZ")[0].stats.npts == 33000 - 997 - 3145
    with pytest.raises(RecordError, match=r"cut\.mseed: components do not cover one time window:"
                                          r" .*drop 20\.71 s \(12\.6 %\) of the record's 165 s"):
        read_motion(path, inventory=NAPA / "NP.1737.xml")


def test_file_cut_between_records_within_tolerance_is_trimmed_truthfully(tmp_path):
    """Cut after record 31: HNZ loses its last 997 samples (4.985 s, 3 %): the three components
    are trimmed to the common window, which holds the intact file's samples, and it is said."""
    path = _write(tmp_path, "cut.mseed", _raw()[: 31 * RECORD])
    intact = read_motion(NAPA / "NP.1737.mseed", inventory=NAPA / "NP.1737.xml")
    cut = read_motion(path, inventory=NAPA / "NP.1737.xml")
    assert cut.npts == 33000 - 997
    for component, data in cut.components.items():
        np.testing.assert_array_equal(data, intact.components[component][: cut.npts])
    assert any("4.985 s of the 165 s span dropped" in p for p in cut.metadata["processing"])


def test_catalogue_mapping_names_a_component_the_file_lost(tmp_path):
    """Cut after the horizontals: the file holds no HNZ, which the mapping names V."""
    path = _write(tmp_path, "cut.mseed", _raw()[: 20 * RECORD])
    with pytest.raises(RecordError, match=r"cut\.mseed: the component mapping names V \(HNZ\)"
                                          r" but the files hold no such channel"):
        read_motion(path, inventory=NAPA / "NP.1737.xml",
                    channel_map={"HNN": "H1", "HNE": "H2", "HNZ": "V"})


# ------------------------------------------------------------------------- Steim2 bit flips


@pytest.mark.parametrize(("position", "bit"), [(3 * RECORD + 700, 2), (14 * RECORD + 2000, 6),
                                               (25 * RECORD + 3333, 0), (31 * RECORD + 100, 4)])
def test_steim2_bit_flip_is_refused(tmp_path, position, bit):
    damaged = bytearray(_raw())
    damaged[position] ^= 1 << bit
    path = _write(tmp_path, "flip.mseed", bytes(damaged))
    stream, messages = _obspy_read(path)
    intact = obspy.read(str(NAPA / "NP.1737.mseed"))
    assert any("Data integrity check for Steim2 failed" in m for m in messages)
    assert any(not np.array_equal(a.data, b.data) for a, b in zip(stream, intact, strict=True))
    with pytest.raises(RecordError, match=r"flip\.mseed: is damaged .*Data integrity check for"
                                          r" Steim2 failed"):
        read_motion(path, inventory=NAPA / "NP.1737.xml")


# -------------------------------------------------------------- components of different rates


def test_a_1_hz_component_does_not_resample_the_motion():
    """Issue 23: a 1 Hz channel resampled the whole motion to 1 Hz; now refused."""
    stream = obspy.read(str(NAPA / "NP.1737.mseed"))
    vertical = stream.select(channel="HNZ")[0]
    vertical.data = vertical.data[::200].copy()
    vertical.stats.sampling_rate = 1.0
    with pytest.raises(RecordError, match=r"different sampling rates \(H1 \(NP\.1737\.\.HNN\) 200 Hz"
                                          r".*V \(NP\.1737\.\.HNZ\) 1 Hz, 0-164 s, 165 samples"):
        read_motion(stream, inventory=NAPA / "NP.1737.xml")


# ------------------------------------------------------------------------- random damage, kept


def test_random_damage_is_refused_or_harmless(tmp_path):
    """Random cuts and single bit flips (data frames and headers) of NP.1737: each read is refused
    or gives exactly the intact record; never changed samples (issue 23: 58 of 114 cuts and 323 of
    360 Steim2 flips read changed before)."""
    import random

    inventory = obspy.read_inventory(str(NAPA / "NP.1737.xml"))
    intact = read_motion(NAPA / "NP.1737.mseed", inventory=inventory).components
    raw = _raw()
    rng = random.Random(23)
    cases = [("cut", rng.randrange(1, len(raw)), 0) for _ in range(40)]
    cases += [("flip", rng.randrange(len(raw) // RECORD) * RECORD + rng.randrange(RECORD),
               rng.randrange(8)) for _ in range(160)]
    refused = 0
    for kind, position, bit in cases:
        damaged = bytearray(raw[:position] if kind == "cut" else raw)
        if kind == "flip":
            damaged[position] ^= 1 << bit
        path = _write(tmp_path, "damaged.mseed", bytes(damaged))
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                got = read_motion(path, inventory=inventory).components
        except RecordError as exc:
            assert "damaged.mseed" in str(exc), (kind, position, exc)
            refused += 1
            continue
        assert set(got) == set(intact), (kind, position, bit)
        for component, data in got.items():
            np.testing.assert_array_equal(data, intact[component], err_msg=f"{kind} {position}")
    assert refused >= 180  # every cut and most flips damage the samples (194 of 200)
