"""BHRC Volume 1 reader (shipblock.io.bhrc) against the real files of the gmprocess corpus.

The six ``*.V1`` files of event usp000jq5p are read and compared with gmprocess 2.8.0. Peaks and
npts agree. The sampling interval deliberately does not: each channel states 200 samples/s
(Real(7)) and a ``DURATION`` equal to npts/200, so dt is 0.005 s; gmprocess divides the duration
by npts - 1. The test checks that the two differ by exactly that convention. The files state no
record start time (gmprocess puts 1970-01-01; shipblock leaves obspy's default and says so).
"""

from __future__ import annotations

import io

import numpy as np
import pytest
from obspy import UTCDateTime

from shipblock.errors import RecordError, UnitsError
from shipblock.io.bhrc import is_bhrc, read_bhrc
from tests.reader_fuzz import assert_reader_survives
from tests.real_corpus import (
    REFERENCE,
    assert_peaks_match_gmprocess,
    corpus_file,
    gmprocess_read,
    reference_files,
)

FILES = reference_files("bhrc")

#: What the station lines of the six files state: name, latitude, longitude, altitude [m],
#: azimuth of L and of T [deg], NO. OF POINTS and DURATION [s] (read off the files by eye).
STATED = {
    "bhrc/usp000jq5p/5520-1.V1": ("Ahar", 38.474, 47.059, 1360.0, 352.0, 82.0, 15616, 78.080),
    "bhrc/usp000jq5p/5522-1.V1": ("Ajab Shir", 37.485, 45.891, 1333.0, 324.0, 54.0, 9984, 49.920),
    "bhrc/usp000jq5p/5523-1.V1": ("Amand", 38.231, 46.156, 1495.0, 177.0, 267.0, 13056, 65.280),
    "bhrc/usp000jq5p/5526-1.V1": ("Avin", 37.734, 47.801, 2026.0, 50.0, 140.0, 9472, 47.360),
    "bhrc/usp000jq5p/5528-1.V1": ("Basmanj", 37.996, 46.471, 1743.0, 316.0, 46.0, 15360, 76.800),
    "bhrc/usp000jq5p/5529-1.V1": ("Band", 37.498, 44.999, 1417.0, 106.0, 196.0, 9472, 47.360),
}

#: Files of other formats that must not be taken for BHRC (one or two per folder).
OTHER_FORMATS = [
    f for folder in ("knet", "kiknet", "dmg", "cosmos", "esm", "geonet", "geonet2", "cwb", "unam",
                     "renadic", "usc", "smc", "peer", "nsmn", "csn")
    for f in reference_files(folder)[:2]
]


def test_corpus_lists_the_six_files():
    assert sorted(STATED) == FILES


@pytest.mark.parametrize("relpath", FILES)
def test_matches_gmprocess(relpath):
    assert gmprocess_read(relpath)
    stream = read_bhrc(corpus_file(relpath))
    assert len(stream) == 3
    assert_peaks_match_gmprocess(stream, relpath)
    for row in REFERENCE[relpath]:
        for trace in stream:
            npts = int(row["npts"])
            assert trace.stats.npts == npts
            # Same record length, different convention: gmprocess spans DURATION with npts - 1
            # intervals, the file's rate (200/s) spans it with npts.
            assert trace.stats.delta * npts == pytest.approx(float(row["delta_s"]) * (npts - 1),
                                                             rel=1e-12)
            # gmprocess invents a start of 1970-01-01; the file states none, nor does shipblock.
            assert row["starttime"].startswith("1970-01-01T00:00:00")
            assert trace.stats.shipblock_bhrc.start_time_stated is False


@pytest.mark.parametrize("relpath", FILES)
def test_header_values(relpath):
    name, lat, lon, alt, az_l, az_t, npts, duration = STATED[relpath]
    stream = read_bhrc(corpus_file(relpath))
    assert [tr.stats.shipblock_bhrc.component for tr in stream] == ["L", "V", "T"]
    assert [tr.stats.get("azimuth") for tr in stream] == [az_l, None, az_t]
    assert [tr.stats.dip for tr in stream] == [0.0, -90.0, 0.0]
    assert [tr.stats.channel for tr in stream] == ["HN1", "HNZ", "HN2"]
    assert (az_t - az_l) % 360.0 == 90.0  # T is L + 90 deg in every file
    for trace in stream:
        header = trace.stats.shipblock_bhrc
        assert (trace.stats.network, trace.stats.station) == ("I1", relpath[-9:-5])
        assert header.station_name == name
        assert header.origin_time == "2012-08-11T12:23:16.000000Z"
        assert header.instrument == "SSA-2"
        assert (trace.stats.units, trace.stats.original_units) == ("m/s**2", "G/10")
        assert trace.stats.coordinates.latitude == lat
        assert trace.stats.coordinates.longitude == lon
        assert trace.stats.coordinates.elevation == alt
        assert trace.stats.npts == npts
        assert trace.stats.delta == 0.005
        assert trace.stats.npts * trace.stats.delta == pytest.approx(duration, abs=5e-4)
        assert trace.stats.starttime == UTCDateTime(0)  # obspy's default: not stated
        assert "stated_peak_si" not in trace.stats  # the files state no peaks


def test_samples_are_g_over_10():
    stream = read_bhrc(corpus_file(FILES[0]))
    # The first sample of channel L is printed as .854257E-03 (g/10).
    assert stream[0].data[0] == pytest.approx(0.854257e-3 * 9.80665 / 10, rel=1e-12)
    # SSA-2 samples are scaled 12-bit counts: whole multiples of one step of about 2 g / 4096.
    for trace in stream:
        gaps = np.diff(np.unique(trace.data)) / (9.80665 / 10)
        step = np.median(gaps[gaps < 1.5 * gaps.min()])
        assert step == pytest.approx(20 / 4096, rel=0.01)
        assert np.all(np.abs(gaps / step - np.round(gaps / step)) < 0.02)


def test_headonly_reads_no_samples():
    stream = read_bhrc(corpus_file(FILES[1]), headonly=True)
    assert [tr.stats.npts for tr in stream] == [9984] * 3
    assert all(tr.data.size == 0 for tr in stream)


def test_detection():
    for relpath in FILES:
        assert is_bhrc(corpus_file(relpath))
    assert len(OTHER_FORMATS) >= 20
    for relpath in OTHER_FORMATS:
        assert not is_bhrc(corpus_file(relpath)), relpath


def test_detection_false_on_plain_text_and_never_raises(tmp_path):
    numbers = tmp_path / "numbers.txt"
    numbers.write_text("  .100000E+00  .200000E+00\n" * 100)
    assert not is_bhrc(numbers)
    assert not is_bhrc(tmp_path / "missing.V1")
    binary = tmp_path / "binary.dat"
    binary.write_bytes(bytes(range(256)) * 4)
    assert not is_bhrc(binary)


def test_fuzz_on_a_real_file():
    raw = corpus_file("bhrc/usp000jq5p/5526-1.V1").read_bytes()
    assert assert_reader_survives(read_bhrc, raw) > 0


def _write(tmp_path, raw: bytes):
    path = tmp_path / "record.V1"
    path.write_bytes(raw)
    return path


def test_damaged_files_are_refused(tmp_path):
    raw = corpus_file("bhrc/usp000jq5p/5529-1.V1").read_bytes()
    lines = raw.split(b"\r\n")
    last_marker = max(i for i, line in enumerate(lines) if line.strip() == b"/&")
    # Cut before the last channel's /& line: truncated.
    with pytest.raises(RecordError, match="channel T .* no closing '/&'"):
        read_bhrc(_write(tmp_path, b"\r\n".join(lines[:last_marker])))
    # One sample line less in the last channel.
    short = lines[: last_marker - 1] + lines[last_marker:]
    with pytest.raises(RecordError, match="channel T is truncated: NO. OF POINTS = 9472 but 9470"):
        read_bhrc(_write(tmp_path, b"\r\n".join(short)))
    # Cut inside the second channel's header.
    second = [i for i, line in enumerate(lines) if line.startswith(b"* VOL")][1]
    with pytest.raises(RecordError, match="header starting at line .* is incomplete"):
        read_bhrc(_write(tmp_path, b"\r\n".join(lines[: second + 10])))
    # A duration that contradicts the rate (gmprocess would silently change dt).
    with pytest.raises(RecordError, match="last 47.36 s, but DURATION = 50"):
        read_bhrc(_write(tmp_path, raw.replace(b"DURATION =  47.360", b"DURATION =  50.000", 1)))
    with pytest.raises(RecordError, match="sampling interval 2 s is outside"):
        read_bhrc(_write(tmp_path, raw.replace(b"  .200000E+03", b"  .500000E+00")
                         .replace(b"DURATION =  47.360", b"DURATION =18944.000")))
    # Truncation is seen also when only the headers are read.
    with pytest.raises(RecordError, match="channel T is truncated"):
        read_bhrc(_write(tmp_path, b"\r\n".join(short)), headonly=True)
    # The integer header's count must agree with the text line.
    with pytest.raises(RecordError, match="integer header says 9473"):
        read_bhrc(_write(tmp_path, raw.replace(b"    0 9472    0", b"    0 9473    0", 1)))
    with pytest.raises(RecordError, match="NaN/inf"):
        read_bhrc(_write(tmp_path, raw.replace(b"  .669326E-03", b"          nan", 1)))
    with pytest.raises(RecordError, match="not a ground acceleration"):
        read_bhrc(_write(tmp_path, raw.replace(b"  .669326E-03", b"  .669326E+09", 1)))
    with pytest.raises(UnitsError, match="unknown acceleration unit 'CM/SEC'"):
        read_bhrc(_write(tmp_path, raw.replace(b"AND G/10", b"AND CM/SEC", 1)))
    with pytest.raises(RecordError, match="component 'X' is not L, T or V"):
        read_bhrc(_write(tmp_path, raw.replace(b"\r\nL\r\n", b"\r\nX\r\n", 1)))
    with pytest.raises(RecordError, match="is not a BHRC file") as info:
        read_bhrc(_write(tmp_path, b"  .1  .2\r\n"))
    assert str(tmp_path / "record.V1") in str(info.value)


def test_rate_missing_falls_back_to_duration(tmp_path):
    raw = corpus_file("bhrc/usp000jq5p/5529-1.V1").read_bytes()
    stream = read_bhrc(io.BytesIO(raw.replace(b"  .200000E+03", b"  .000000E+00")))
    assert [tr.stats.delta for tr in stream] == [pytest.approx(47.36 / 9472, rel=1e-12)] * 3
