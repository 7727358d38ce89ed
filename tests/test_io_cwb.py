"""CWB (Taiwan) reader (shipblock.io.cwb) against the real files of the gmprocess corpus.

The five files of event us1000chhc are read and compared with gmprocess 2.8.0 (peaks per component
kind, npts, dt, start time) and with what each header states (``#AmplitudeMAX. X: max~min`` per
component, station, coordinates, local start time).
"""

from __future__ import annotations

import io
import re

import numpy as np
import pytest
from obspy import UTCDateTime

from shipblock.errors import RecordError, UnitsError
from shipblock.io.cwb import is_cwb, read_cwb
from tests.reader_fuzz import assert_reader_survives
from tests.real_corpus import (
    REFERENCE,
    assert_peaks_match_gmprocess,
    corpus_file,
    gmprocess_read,
    reference_files,
)

FILES = reference_files("cwb")

GAL = 0.01  # 1 gal in m/s^2 (exact)

#: Files of other formats that must not be taken for CWB files (every file of each folder).
OTHER_FORMATS = [
    f for folder in ("knet", "kiknet", "dmg", "cosmos", "esm", "nsmn", "bhrc", "unam", "renadic",
                     "usc", "smc", "peer", "geonet", "geonet2", "csn")
    for f in reference_files(folder)
]

#: Station code, latitude and longitude [deg] of each file, read off the headers by eye.
STATIONS = {
    "cwb/us1000chhc/1-EAS.dat": ("EAS", 22.381, 120.857),
    "cwb/us1000chhc/2-ECU.dat": ("ECU", 22.860, 121.092),
    "cwb/us1000chhc/2-EDH.dat": ("EDH", 22.972, 121.305),
    "cwb/us1000chhc/2-EGF.dat": ("EGF", 23.685, 121.483),
    "cwb/us1000chhc/2-ELD.dat": ("ELD", 23.187, 121.025),
}


def test_corpus_lists_the_five_files():
    assert sorted(STATIONS) == FILES
    assert all(gmprocess_read(f) for f in FILES)


@pytest.mark.parametrize("relpath", FILES)
def test_matches_gmprocess(relpath):
    stream = read_cwb(corpus_file(relpath))
    assert len(stream) == 3
    assert_peaks_match_gmprocess(stream, relpath)
    for row in REFERENCE[relpath]:
        for trace in stream:
            assert trace.stats.npts == int(row["npts"])
            assert trace.stats.delta == pytest.approx(float(row["delta_s"]), rel=1e-12)
            assert trace.stats.starttime == UTCDateTime(row["starttime"])


@pytest.mark.parametrize("relpath", FILES)
def test_values_stated_by_the_header(relpath):
    text = corpus_file(relpath).read_text()
    station, latitude, longitude = STATIONS[relpath]
    stream = read_cwb(corpus_file(relpath))
    # "#DataSequence: Time U(+); N(+); E(+)"
    assert [tr.stats.channel for tr in stream] == ["BNZ", "BNN", "BNE"]
    assert [tr.stats.get("azimuth") for tr in stream] == [None, 0.0, 90.0]
    assert [tr.stats.dip for tr in stream] == [-90.0, 0.0, 0.0]
    for trace, letter in zip(stream, "UNE", strict=True):
        assert (trace.stats.network, trace.stats.station, trace.stats.location) == (
            "TW", station, "")
        assert trace.stats.units == "m/s**2"
        assert trace.stats.original_units == "gal"
        assert trace.stats.coordinates.latitude == latitude
        assert trace.stats.coordinates.longitude == longitude
        # "#StartTime(GMT+08): 2018/02/06-23:50:29.000" is local time, 8 h ahead of UTC.
        assert trace.stats.starttime == UTCDateTime("2018-02-06T15:50:29")
        assert trace.stats.sampling_rate == 50.0
        assert trace.stats.npts == 120 * 50  # "#RecordLength(sec): 120" x "#SampleRate(Hz): 50"
        # "#AmplitudeMAX. U:    0.658~   -0.837": the largest and smallest sample [gal, 3 decimals].
        high, low = map(float, re.search(
            rf"#AmplitudeMAX\. {letter}:\s*(\S+)~\s*(\S+)", text).groups())
        assert np.max(trace.data) == pytest.approx(high * GAL, abs=1e-9)
        assert np.min(trace.data) == pytest.approx(low * GAL, abs=1e-9)
        assert trace.stats.stated_peak_si == pytest.approx(max(high, -low) * GAL, rel=1e-12)


def test_first_samples_in_gal():
    stream = read_cwb(corpus_file(FILES[0]))
    rows = [line.split() for line in corpus_file(FILES[0]).read_text().splitlines()
            if line.strip() and not line.startswith("#")]
    table = np.array(rows[:6000], dtype=float)
    for trace, column in zip(stream, (1, 2, 3), strict=True):
        np.testing.assert_allclose(trace.data, table[:, column] * GAL, rtol=0, atol=1e-12)


def test_headonly_reads_no_samples():
    stream = read_cwb(corpus_file(FILES[0]), headonly=True)
    assert [tr.stats.npts for tr in stream] == [6000] * 3
    assert all(tr.data.size == 0 for tr in stream)
    assert stream[0].stats.stated_peak_si == pytest.approx(0.837 * GAL)


def test_detection():
    for relpath in FILES:
        assert is_cwb(corpus_file(relpath))
    assert len(OTHER_FORMATS) >= 100
    for relpath in OTHER_FORMATS:
        assert not is_cwb(corpus_file(relpath)), relpath


def test_detection_false_on_plain_text_and_never_raises(tmp_path):
    numbers = tmp_path / "numbers.dat"
    numbers.write_text("     0.000     0.000     0.000     0.000\n" * 100)
    assert not is_cwb(numbers)
    commented = tmp_path / "commented.dat"
    commented.write_text("#Earthquake Information\n# a note\n1 2 3 4\n")
    assert not is_cwb(commented)
    assert not is_cwb(tmp_path / "missing.dat")
    binary = tmp_path / "binary.dat"
    binary.write_bytes(bytes(range(256)) * 4)
    assert not is_cwb(binary)


def test_survives_fuzz():
    raw = corpus_file(FILES[0]).read_bytes()
    assert assert_reader_survives(read_cwb, raw) > 0


def _write(tmp_path, raw: bytes):
    path = tmp_path / "record.dat"
    path.write_bytes(raw)
    return path


def test_damaged_files_are_refused(tmp_path):
    raw = corpus_file(FILES[0]).read_bytes()
    lines = raw.split(b"\r\n")
    with pytest.raises(RecordError, match="5999 data rows but .* = 6000 samples") as info:
        read_cwb(_write(tmp_path, b"\r\n".join(lines[:-2]) + b"\r\n"))
    assert str(tmp_path / "record.dat") in str(info.value)
    with pytest.raises(RecordError, match="6001 data rows"):
        read_cwb(_write(tmp_path, raw + b"   120.000     0.000     0.000     0.000\r\n"))
    # A row lost and one added elsewhere: the count is right but the time column is not.
    assert lines[-1] == b""  # the file ends with CR-LF
    shuffled = b"\r\n".join(
        lines[:30] + lines[31:-1] + [b"   120.000     0.000     0.000     0.000"])
    with pytest.raises(RecordError, match="time column is not evenly spaced"):
        read_cwb(_write(tmp_path, shuffled + b"\r\n"))
    with pytest.raises(RecordError, match="NaN/inf"):
        read_cwb(_write(tmp_path, raw.replace(b"     0.020     0.000", b"     0.020       nan", 1)))
    with pytest.raises(RecordError, match="not a ground acceleration"):
        read_cwb(_write(tmp_path, raw.replace(b"     0.020     0.000", b"     0.020 1.000e+99", 1)))
    with pytest.raises(RecordError, match="characters long"):
        read_cwb(_write(tmp_path, raw.replace(b"     0.020     0.000", b"     0.020    0.000", 1)))
    with pytest.raises(RecordError, match="SampleRate 0 Hz is not positive"):
        read_cwb(_write(tmp_path, raw.replace(b"#SampleRate(Hz): 50", b"#SampleRate(Hz): 0", 1)))
    with pytest.raises(RecordError, match="#DataSequence"):
        read_cwb(_write(tmp_path, raw.replace(b"#DataSequence:", b"#Sequence:", 1)))
    with pytest.raises(RecordError, match="time zone"):
        read_cwb(_write(tmp_path, raw.replace(b"#StartTime(GMT+08)", b"#StartTime", 1)))
    with pytest.raises(RecordError, match="not a yyyy/mm/dd"):
        read_cwb(_write(tmp_path, raw.replace(b"2018/02/06-23:50:29", b"2018/02/30-23:50:29", 1)))
    with pytest.raises(RecordError, match="is not a CWB file"):
        read_cwb(_write(tmp_path, b"1 2 3 4\n"))


def test_units(tmp_path):
    raw = corpus_file(FILES[0]).read_bytes()
    metres = read_cwb(_write(tmp_path, raw.replace(b"gal. DCoffset", b"m/s^2 DCoffset", 1)))
    reference = read_cwb(io.BytesIO(raw))
    np.testing.assert_allclose(metres[1].data, reference[1].data * 100.0, rtol=1e-12)
    with pytest.raises(UnitsError, match="unknown acceleration unit 'cm/s'"):
        read_cwb(_write(tmp_path, raw.replace(b"gal. DCoffset", b"cm/s DCoffset", 1)))
    with pytest.raises(UnitsError, match="AmplitudeUnit"):
        read_cwb(_write(tmp_path, raw.replace(b"#AmplitudeUnit:", b"#Amplitude:", 1)))


def test_other_column_order_and_signs(tmp_path):
    """A hand-written file: 200 Hz, columns N, W(-) (= east), U, whitespace-separated rows."""
    text = "\n".join([
        "#Earthquake Information",
        "#StationCode: TST",
        "#StartTime(GMT+08): 2020/01/02-03:04:05.500",
        "#RecordLength(sec): 0.015",
        "#SampleRate(Hz): 200",
        "#AmplitudeUnit: gal",
        "#DataSequence: Time N(+); W(-); D(-)",
        "#Data: free",
        "0.000 1.0 -2.0 3.0",
        "0.005 0.5 0.0 0.0",
        "0.010 0.0 0.0 -4.0",
        "",
    ])
    stream = read_cwb(_write(tmp_path, text.encode()))
    assert [tr.stats.channel for tr in stream] == ["HNN", "HNE", "HNZ"]
    assert [tr.stats.get("azimuth") for tr in stream] == [0.0, 90.0, None]
    assert stream[2].stats.dip == -90.0  # "D(-)": positive down reversed = positive up
    assert stream[1].data.tolist() == pytest.approx([-0.02, 0.0, 0.0])
    assert stream[0].stats.starttime == UTCDateTime("2020-01-01T19:04:05.5")
    assert "coordinates" not in stream[0].stats
    assert "stated_peak_si" not in stream[0].stats
