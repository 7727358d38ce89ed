"""NSMN/AFAD reader (shipblock.io.nsmn) against the real files of the gmprocess corpus.

The three files of event us20009ynd are read and compared with gmprocess 2.8.0 (peaks, npts, dt,
start time) and with what the files state themselves (PGA per component, station, coordinates).
The fuzz test runs on a real file shortened to its first rows (the mutations only touch the first
20 kB, and a whole file takes 60 ms a read).
"""

from __future__ import annotations

import io

import numpy as np
import pytest
from obspy import UTCDateTime

from shipblock.errors import RecordError, UnitsError
from shipblock.io.nsmn import is_nsmn, read_nsmn
from tests.reader_fuzz import assert_reader_survives
from tests.real_corpus import (
    REFERENCE,
    assert_peaks_match_gmprocess,
    corpus_file,
    gmprocess_read,
    reference_files,
)

FILES = reference_files("nsmn")

#: What the headers of the three files state (station, latitude, longitude, altitude [m],
#: RECORD TIME, NUMBER OF DATA, RAW PGA [gal] N-S/E-W/U-D), read off the files by eye.
STATED = {
    "nsmn/us20009ynd/20170720223109_0921.txt": (
        "0921", 37.87470, 27.59223, 66.0, "2017-07-20T22:30:58", 28683,
        (13.200332, 12.163827, 9.840572)),
    "nsmn/us20009ynd/20170720223109_4304.txt": (
        "4304", 38.99478, 29.40040, 735.0, "2017-07-20T22:31:14", 37671,
        (1.218825, 1.207812, 0.645862)),
    "nsmn/us20009ynd/20170720223109_5405.txt": (
        "5405", 40.79609, 30.73520, 173.0, "2017-07-20T22:31:58", 42516,
        (1.023915, 1.107856, 0.385138)),
}

#: Files of other formats that must not be taken for NSMN (one or two per folder).
OTHER_FORMATS = [
    f for folder in ("knet", "kiknet", "dmg", "cosmos", "esm", "geonet", "geonet2", "cwb", "unam",
                     "renadic", "usc", "smc", "peer", "bhrc", "csn")
    for f in reference_files(folder)[:2]
]


def test_corpus_lists_the_three_files():
    assert sorted(STATED) == FILES


@pytest.mark.parametrize("relpath", FILES)
def test_matches_gmprocess(relpath):
    assert gmprocess_read(relpath)
    stream = read_nsmn(corpus_file(relpath))
    assert len(stream) == 3
    assert_peaks_match_gmprocess(stream, relpath)
    for row in REFERENCE[relpath]:
        for trace in stream:
            assert trace.stats.npts == int(row["npts"])
            assert trace.stats.delta == pytest.approx(float(row["delta_s"]), rel=1e-12)
            assert trace.stats.starttime == UTCDateTime(row["starttime"])


@pytest.mark.parametrize("relpath", FILES)
def test_header_values_and_stated_pga(relpath):
    station, lat, lon, alt, start, npts, pga_gal = STATED[relpath]
    stream = read_nsmn(corpus_file(relpath))
    assert [tr.stats.channel for tr in stream] == ["HNN", "HNE", "HNZ"]
    assert [tr.stats.get("azimuth") for tr in stream] == [0.0, 90.0, None]
    assert [tr.stats.dip for tr in stream] == [0.0, 0.0, -90.0]
    for trace, stated_gal in zip(stream, pga_gal, strict=True):
        assert (trace.stats.network, trace.stats.station) == ("TK", station)
        assert trace.stats.units == "m/s**2"
        assert trace.stats.original_units == "gal"
        assert trace.stats.coordinates.latitude == pytest.approx(lat, abs=1e-9)
        assert trace.stats.coordinates.longitude == pytest.approx(lon, abs=1e-9)
        assert trace.stats.coordinates.elevation == alt
        assert trace.stats.starttime == UTCDateTime(start)
        assert trace.stats.npts == npts
        assert trace.stats.sampling_rate == 100.0
        # The stated PGA [gal] is the peak of the samples, both printed to 1e-6 gal.
        assert trace.stats.stated_peak_si == pytest.approx(stated_gal * 0.01, rel=1e-12)
        assert np.max(np.abs(trace.data)) == pytest.approx(stated_gal * 0.01, abs=0.6e-8)


def test_turkish_code_page_is_decoded():
    header = read_nsmn(corpus_file(FILES[0]), headonly=True)[0].stats.shipblock_nsmn
    # Byte 0xFD of the file is the Turkish dotless i in cp1254 (not y-acute as in Latin-1).
    assert header.place == "AYD\u0131N GERMENCIK DEVLET HASTANESI"
    assert header.recorder_type == "Sara acebox"


def test_headonly_reads_no_samples():
    stream = read_nsmn(corpus_file(FILES[0]), headonly=True)
    assert [tr.stats.npts for tr in stream] == [28683] * 3
    assert all(tr.data.size == 0 for tr in stream)


def test_detection():
    for relpath in FILES:
        assert is_nsmn(corpus_file(relpath))
    assert len(OTHER_FORMATS) >= 20
    for relpath in OTHER_FORMATS:
        assert not is_nsmn(corpus_file(relpath)), relpath


def test_detection_false_on_plain_text_and_never_raises(tmp_path):
    numbers = tmp_path / "numbers.txt"
    numbers.write_text("0.1 0.2 0.3\n" * 100)
    assert not is_nsmn(numbers)
    assert not is_nsmn(tmp_path / "missing.txt")
    binary = tmp_path / "binary.dat"
    binary.write_bytes(bytes(range(256)) * 4)
    assert not is_nsmn(binary)


def _short_copy(relpath, rows):
    """A real file cut to its first ``rows`` sample rows, with NUMBER OF DATA set to match."""
    lines = corpus_file(relpath).read_bytes().split(b"\r\n")
    title = next(i for i, line in enumerate(lines) if line.split() == [b"N-S", b"E-W", b"U-D"])
    head = [
        line.split(b":")[0] + b": " + str(rows).encode() if line.startswith(b"NUMBER OF DATA")
        else line
        for line in lines[: title + 1]
    ]
    return b"\r\n".join(head + lines[title + 1: title + 1 + rows]) + b"\r\n"


def test_short_copy_reads_and_survives_fuzz():
    raw = _short_copy(FILES[0], 400)
    stream = read_nsmn(io.BytesIO(raw))
    assert [tr.stats.npts for tr in stream] == [400] * 3
    assert read_nsmn(io.BytesIO(raw))[0].data[0] == pytest.approx(0.000909 * 0.01)
    assert assert_reader_survives(read_nsmn, raw) > 0


def _write(tmp_path, raw: bytes):
    path = tmp_path / "record.txt"
    path.write_bytes(raw)
    return path


def test_truncated_and_inconsistent_files_are_refused(tmp_path):
    raw = _short_copy(FILES[1], 50)
    with pytest.raises(RecordError, match="truncated: NUMBER OF DATA = 50 but 49 rows"):
        read_nsmn(_write(tmp_path, raw.rsplit(b"\r\n", 2)[0] + b"\r\n"))
    with pytest.raises(RecordError, match="longer than its header"):
        read_nsmn(_write(tmp_path, raw + b"   0.1 0.2 0.3\r\n"))
    with pytest.raises(RecordError, match=r"line 19: 2 numbers where 3 columns"):
        read_nsmn(_write(tmp_path, raw.replace(b"    0.000010     0.000207", b"    0.000010", 1)))
    with pytest.raises(RecordError, match="truncated"):  # seen without reading the samples
        read_nsmn(_write(tmp_path, raw.rsplit(b"\r\n", 2)[0]), headonly=True)
    with pytest.raises(RecordError, match="NaN/inf"):
        read_nsmn(_write(tmp_path, raw.replace(b"-0.000200", b"nan", 1)))
    with pytest.raises(RecordError, match="not a ground acceleration"):
        read_nsmn(_write(tmp_path, raw.replace(b"-0.000200", b"1e300", 1)))
    with pytest.raises(RecordError, match="not a positive number"):
        read_nsmn(_write(tmp_path, raw.replace(b"(sec) : 0.01", b"(sec) : 0", 1)))
    with pytest.raises(RecordError, match="SAMPLING INTERVAL = 1e-05 s is outside"):
        read_nsmn(_write(tmp_path, raw.replace(b"(sec) : 0.01", b"(sec) : 0.00001", 1)))
    with pytest.raises(RecordError, match="NUMBER OF DATA = 'nan' is not a sample count"):
        read_nsmn(_write(tmp_path, raw.replace(b"DATA          : 50", b"DATA          : nan")))
    with pytest.raises(RecordError, match="RECORD TIME"):
        read_nsmn(_write(tmp_path, raw.replace(b"20/07/2017 22:31:14", b"31/02/2017 22:31:14")))
    with pytest.raises(RecordError, match="is not an NSMN file") as info:
        read_nsmn(_write(tmp_path, b"0.1 0.2 0.3\n"))
    assert str(tmp_path / "record.txt") in str(info.value)


def test_missing_unit_is_a_units_error(tmp_path):
    raw = _short_copy(FILES[2], 20).replace(b"RAW PGA VALUES (gal)", b"RAW PGA VALUES      ")
    with pytest.raises(UnitsError, match="states no unit"):
        read_nsmn(_write(tmp_path, raw))
    raw = _short_copy(FILES[2], 20).replace(b"(gal)", b"(cm/s)")
    with pytest.raises(UnitsError, match="unknown acceleration unit 'cm/s'"):
        read_nsmn(_write(tmp_path, raw))


def test_utf8_file_and_other_column_order(tmp_path):
    """A hand-written file: UTF-8 Turkish text, columns in another order, m/s^2 as unit."""
    text = "\n".join([
        "STRONG GROUND MOTION RECORDS OF TURKIYE",
        "PLACE                   : İZMİR ŞİRİNYER",
        "STATION ID              : 3519",
        "STATION COORDINATES     : 38.39470S-27.10223W",
        "RECORD TIME             : 01/02/2020 03:04:05.250000 (GMT)",
        "NUMBER OF DATA          : 3",
        "SAMPLING INTERVAL (sec) : 0.005",
        "RAW PGA VALUES (m/s^2)  : (N-S) 3.0 (E-W) 2.0 (U-D) 1.0",
        "       U-D          N-S          E-W",
        "  1.0 -3.0 2.0", "  0.5 1.0 -1.0", "  0.0 0.0 0.0", "",
    ]).encode("utf-8")
    stream = read_nsmn(_write(tmp_path, text))
    assert [tr.stats.channel for tr in stream] == ["HNZ", "HNN", "HNE"]
    assert stream[0].stats.shipblock_nsmn.place == "İZMİR ŞİRİNYER"
    assert stream[1].data.tolist() == [-3.0, 1.0, 0.0]
    assert [tr.stats.stated_peak_si for tr in stream] == [1.0, 3.0, 2.0]
    assert stream[0].stats.coordinates.latitude == -38.3947
    assert stream[0].stats.coordinates.longitude == -27.10223
    assert stream[0].stats.coordinates.elevation == 0.0
    assert stream[0].stats.starttime == UTCDateTime("2020-02-01T03:04:05.25")
    assert stream[0].stats.sampling_rate == 200.0
