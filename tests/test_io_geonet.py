"""GeoNet V1A/V2A reader (shipblock.io.geonet) against the real files of the gmprocess corpus.

The 13 files of folders ``geonet`` and ``geonet2`` are read and compared with gmprocess 2.8.0
(peaks per component kind, npts, dt) and with what each block states about itself (peak value and
time, number of points, site coordinates, component direction). Start times differ from
gmprocess's on purpose: gmprocess drops the milliseconds of the buffer start and does not move a
corrected (V2A) record back by its prepended 5 s; the tests check shipblock's times against the
header and against the stated time of each peak.
"""

from __future__ import annotations

import io
import re

import numpy as np
import pytest
from obspy import UTCDateTime

from shipblock.errors import RecordError, UnitsError
from shipblock.io.geonet import is_geonet, read_geonet
from tests.reader_fuzz import assert_reader_survives
from tests.real_corpus import (
    REFERENCE,
    assert_peaks_match_gmprocess,
    corpus_file,
    gmprocess_read,
    reference_files,
)

FILES = reference_files("geonet") + reference_files("geonet2")

MM = 0.001  # 1 mm/s^2 in m/s^2 (exact)

#: Channel codes and azimuths [deg] expected from the ``Component`` lines (N28W -> 332 ...).
ORIENTATION = {
    "WPWS": (["1", "2", "Z"], [196.0, 106.0, None]),  # S16W, S74E, Up
    "WTMC": (["1", "2", "Z"], [332.0, 242.0, None]),  # N28W, S62W, Up
    "HSES": (["1", "2", "Z"], [10.0, 280.0, None]),  # N10E, N80W, Up
    "THZ": (["E", "N", "Z"], [90.0, 0.0, None]),  # S90E, N00E, Up
    "HCDS": (["1", "2", "Z"], [320.0, 230.0, None]),  # N40W, S50W, Up
    "HNPS": (["1", "2", "Z"], [280.0, 190.0, None]),  # N80W, S10W, Up
    "INHS": (["1", "2", "Z"], [115.0, 25.0, None]),  # S65E, N25E, Up
    "TBAS": (["E", "N", "Z"], [91.0, 1.0, None]),  # S89E, N01E, Up (within 1 deg of E/N)
}

#: Files of other formats that must not be taken for GeoNet files (every file of each folder).
OTHER_FORMATS = [
    f for folder in ("knet", "kiknet", "dmg", "cosmos", "esm", "nsmn", "bhrc", "unam", "renadic",
                     "usc", "smc", "peer", "cwb", "csn")
    for f in reference_files(folder)
]

WPWS = "geonet/nz2018p115908/20180212_211557_WPWS_20.V2A"
INHS = "geonet2/2019p322376/20190430_064319_INHS_21.V1A"


def _text_lines(relpath):
    return corpus_file(relpath).read_text().splitlines()


def _block_starts(lines):
    return [i for i, line in enumerate(lines) if "accelerogram" in line and "GNS" in line]


def test_corpus_lists_the_thirteen_files():
    assert len(FILES) == 13
    assert all(gmprocess_read(f) for f in FILES)  # gmprocess refuses none of them


@pytest.mark.parametrize("relpath", FILES)
def test_matches_gmprocess(relpath):
    stream = read_geonet(corpus_file(relpath))
    assert len(stream) == 3
    assert_peaks_match_gmprocess(stream, relpath)
    rows = REFERENCE[relpath]
    for trace in stream:
        assert trace.stats.npts == int(rows[0]["npts"])
        assert trace.stats.delta == pytest.approx(float(rows[0]["delta_s"]), rel=1e-12)
        # gmprocess starts at the buffer start cut to whole seconds (plus a stray microsecond):
        # shipblock keeps the milliseconds and moves a V2A record back by its prepended time.
        buffer_start = trace.stats.starttime + trace.stats.shipblock_geonet.prepended_s
        assert 0.0 <= buffer_start - UTCDateTime(rows[0]["starttime"]) < 1.0
        assert buffer_start == UTCDateTime(trace.stats.shipblock_geonet.buffer_start)


@pytest.mark.parametrize("relpath", FILES)
def test_values_stated_by_the_blocks(relpath):
    lines = _text_lines(relpath)
    starts = _block_starts(lines)
    assert len(starts) == 3
    stream = read_geonet(corpus_file(relpath))
    station = re.search(r"_([A-Z0-9]+)_(\d\d)\.V[12]A$", relpath)
    channels, azimuths = ORIENTATION[station.group(1)]
    corrected = relpath.endswith(".V2A")
    band = "B" if corrected else "H"  # 50 Hz corrected, 200 Hz raw
    assert [tr.stats.channel for tr in stream] == [f"{band}N{c}" for c in channels]
    assert [tr.stats.get("azimuth") for tr in stream] == azimuths
    assert [tr.stats.dip for tr in stream] == [0.0, 0.0, -90.0]
    for trace, start in zip(stream, starts, strict=True):
        text = lines[start:start + 16]
        header = trace.stats.shipblock_geonet
        assert (trace.stats.network, trace.stats.station) == ("NZ", station.group(1))
        assert trace.stats.location == station.group(2)  # _20 / _21 of the record identifier
        assert trace.stats.units == "m/s**2"
        assert trace.stats.original_units == "mm/s/s"
        assert header.processing == ("corrected" if corrected else "uncorrected")
        # "Number of points  5800" and the interval printed in the text.
        assert trace.stats.npts == int(re.search(r"Number of points\s+(\d+)", text[9]).group(1))
        printed_dt = float(re.search(r"(\d\.\d+)\s*s", text[10]).group(1))
        assert trace.stats.delta == pytest.approx(printed_dt, abs=1e-9)
        # "Site WTMC      42 37 10S  173 03 13E": latitude south, longitude east.
        d1, m1, s1, d2, m2, s2 = map(int, re.findall(r"\d+", text[1].split("file")[0])[:6])
        assert trace.stats.coordinates.latitude == pytest.approx(-(d1 + m1 / 60 + s1 / 3600))
        assert trace.stats.coordinates.longitude == pytest.approx(d2 + m2 / 60 + s2 / 3600)
        # "Acceleration:  peak  -9733.1 mm/s/s at  44.88 sec": the peak (one decimal; samples
        # of 10^4 mm/s^2 and more are printed without decimals, e.g. -11026 for -11026.2).
        stated = float(text[13].split()[2])
        assert trace.stats.stated_peak_si == pytest.approx(abs(stated) * MM, rel=1e-12)
        peak = np.max(np.abs(trace.data))
        assert peak == pytest.approx(abs(stated) * MM, rel=2e-5, abs=0.051 * MM)
        # The stated time of the peak counts from the buffer start; a V2A record starts the
        # prepended time (5 s) earlier. Ties between neighbouring samples allow one sample.
        peak_time = np.argmax(np.abs(trace.data)) * trace.stats.delta - header.prepended_s
        assert peak_time == pytest.approx(header.stated_peak_time_s, abs=trace.stats.delta + 0.006)
        assert header.prepended_s == (5.0 if corrected else 0.0)


@pytest.mark.parametrize("station", ["WTMC", "HSES", "THZ"])
def test_v1a_and_v2a_of_one_station_line_up(station):
    """The corrected record starts 5 s before the raw one; their horizontal peaks coincide."""
    raw = read_geonet(corpus_file(next(f for f in FILES if f"_{station}_" in f and "V1A" in f)))
    corrected = read_geonet(corpus_file(
        next(f for f in FILES if f"_{station}_" in f and "V2A" in f)))
    for one, two in zip(raw, corrected, strict=True):
        assert two.stats.starttime == one.stats.starttime - 5.0
        assert two.stats.get("azimuth") == one.stats.get("azimuth")
        if one.stats.dip == 0.0:
            t_raw = one.stats.starttime + np.argmax(np.abs(one.data)) * one.stats.delta
            t_cor = two.stats.starttime + np.argmax(np.abs(two.data)) * two.stats.delta
            assert abs(t_raw - t_cor) <= 0.03


def test_start_time_keeps_the_milliseconds():
    # Integer header: buffer start 2016 11 13 11 (minute) 2 (s x 1000) 19715.
    stream = read_geonet(corpus_file("geonet/us1000778i/20161113_110259_WTMC_20.V1A"))
    assert stream[0].stats.starttime == UTCDateTime("2016-11-13T11:02:19.715")
    stream = read_geonet(corpus_file("geonet/us1000778i/20161113_110259_WTMC_20.V2A"))
    assert stream[0].stats.starttime == UTCDateTime("2016-11-13T11:02:14.715")


def test_headonly_reads_no_samples():
    stream = read_geonet(corpus_file(WPWS), headonly=True)
    assert [tr.stats.npts for tr in stream] == [5800] * 3
    assert all(tr.data.size == 0 for tr in stream)
    assert stream[2].stats.stated_peak_si == pytest.approx(0.0273)


def test_detection():
    for relpath in FILES:
        assert is_geonet(corpus_file(relpath)), relpath
    assert len(OTHER_FORMATS) >= 100
    for relpath in OTHER_FORMATS:
        assert not is_geonet(corpus_file(relpath)), relpath


def test_detection_false_on_plain_text_and_never_raises(tmp_path):
    numbers = tmp_path / "numbers.txt"
    numbers.write_text("     0.1    -0.2     0.3\n" * 100)
    assert not is_geonet(numbers)
    assert not is_geonet(tmp_path / "missing.V1A")
    binary = tmp_path / "binary.V1A"
    binary.write_bytes(bytes(range(256)) * 4)
    assert not is_geonet(binary)
    # A DMG/CSMIP title alone is not enough.
    dmg = tmp_path / "x.V2"
    dmg.write_text("CORRECTED ACCELEROGRAM   36456-S4384-83123.01   CHAN  1:  90 DEG\n" * 30)
    assert not is_geonet(dmg)
    assert not is_geonet(io.BytesIO(b"Corrected accelerogram x GNS Science\n"))


@pytest.mark.parametrize("relpath", [WPWS, INHS])
def test_survives_fuzz(relpath):
    raw = corpus_file(relpath).read_bytes()
    assert read_geonet(io.BytesIO(raw))[0].stats.npts > 0
    assert_reader_survives(read_geonet, raw)


def _write(tmp_path, raw: bytes):
    path = tmp_path / "record.V2A"
    path.write_bytes(raw)
    return path


def _lines(relpath):
    return corpus_file(relpath).read_bytes().split(b"\n")


def test_damaged_files_are_refused(tmp_path):
    lines = _lines(WPWS)
    raw = b"\n".join(lines)
    with pytest.raises(RecordError, match="truncated") as info:
        read_geonet(_write(tmp_path, b"\n".join(lines[:-200])))
    assert str(tmp_path / "record.V2A") in str(info.value)
    with pytest.raises(RecordError, match="component 3 of 3 is missing"):
        read_geonet(_write(tmp_path, b"\n".join(lines[:_block_starts(
            [ln.decode() for ln in lines])[2]])))
    with pytest.raises(RecordError, match="unexpected content after the third component"):
        read_geonet(_write(tmp_path, raw + b"     1.0     2.0\n"))
    # A data line lost in block 1 shifts block 2's header.
    with pytest.raises(RecordError, match="component 2 .* does not start with a GNS header"):
        read_geonet(_write(tmp_path, b"\n".join(lines[:100] + lines[101:])))
    with pytest.raises(RecordError, match="text says 5801 points"):
        read_geonet(_write(tmp_path, raw.replace(b"Number of points  5800", b"Number of points  5801", 1)))
    with pytest.raises(RecordError, match="not a positive number"):
        read_geonet(_write(tmp_path, raw.replace(b"0.0050  0.0200", b"0.0050  0.0000", 1)))
    with pytest.raises(RecordError, match="NaN/inf"):
        read_geonet(_write(tmp_path, raw.replace(b"     0.0    -0.0", b"     nan    -0.0", 1)))
    with pytest.raises(RecordError, match="not a ground acceleration"):
        read_geonet(_write(tmp_path, raw.replace(b"     0.0    -0.0", b"9.99e+99    -0.0", 1)))
    with pytest.raises(RecordError, match=r"sampling interval 2 s is outside"):
        read_geonet(_write(tmp_path, raw.replace(b"0.0050  0.0200", b"0.0050  2.0000", 1)))
    with pytest.raises(RecordError, match="'x' is not a number"):
        read_geonet(_write(tmp_path, raw.replace(b"     0.0    -0.0", b"       x    -0.0", 1)))
    with pytest.raises(RecordError, match="characters long"):
        read_geonet(_write(tmp_path, raw.replace(b"     0.0    -0.0", b"    0.0    -0.0", 1)))
    with pytest.raises(RecordError, match="not a valid date"):
        read_geonet(_write(tmp_path, raw.replace(b"     0       0    2018       2",
                                                  b"     0       0    2018      13", 1)))
    with pytest.raises(RecordError, match="is not a direction"):
        read_geonet(_write(tmp_path, raw.replace(b"Component S16W", b"Component X16Q", 1)))
    with pytest.raises(RecordError, match="not a GeoNet"):
        read_geonet(_write(tmp_path, b"0.1 0.2\n"))


def test_units_of_a_raw_record(tmp_path):
    raw = corpus_file(INHS).read_bytes()
    reference = read_geonet(io.BytesIO(raw))
    scaled = read_geonet(_write(tmp_path, raw.replace(
        b"Raw readings in units of 1.00 mm/s/s", b"Raw readings in units of 2.00 cm/s/s")))
    for one, two in zip(reference, scaled, strict=True):
        np.testing.assert_allclose(two.data, one.data * 20.0, rtol=1e-12)
        assert two.stats.original_units == "cm/s/s"
    with pytest.raises(UnitsError, match="unknown acceleration unit 'mm/s'"):
        read_geonet(_write(tmp_path, raw.replace(
            b"Raw readings in units of 1.00 mm/s/s", b"Raw readings in units of 1.00 mm/s  ")))


def test_down_component_points_down(tmp_path):
    raw = corpus_file(INHS).read_bytes().replace(b"Component Up", b"Component Down")
    stream = read_geonet(_write(tmp_path, raw))
    assert stream[2].stats.channel == "HNZ"
    assert stream[2].stats.dip == 90.0
