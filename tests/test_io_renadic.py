"""Tests of the Chilean RENADIC ``.v1`` reader on the real files of the gmprocess corpus."""

from __future__ import annotations

import io

import numpy as np
import pytest
from obspy import UTCDateTime

from shipblock.errors import RecordError, UnitsError
from shipblock.io.renadic import is_renadic, read_renadic
from shipblock.units import STANDARD_GRAVITY
from tests.reader_fuzz import assert_reader_survives
from tests.real_corpus import (
    REFERENCE,
    assert_peaks_match_gmprocess,
    corpus_file,
    gmprocess_read,
    reference_files,
)

RENADIC_FILES = reference_files("renadic")
READ_BY_GMPROCESS = [f for f in RENADIC_FILES if gmprocess_read(f)]
REFUSED_BY_GMPROCESS = [f for f in RENADIC_FILES if not gmprocess_read(f)]

MAULE = "renadic/official20100227063411530_30/"
SMALL = MAULE + "vinacentro1002271parte2.v1"

#: Other folders of the corpus whose files must not be taken for RENADIC files (dmg and usc
#: share the Volume 1 layout).
OTHER_FOLDERS = ("knet", "kiknet", "dmg", "cosmos", "esm", "geonet", "geonet2", "cwb", "nsmn",
                 "bhrc", "usc", "smc", "peer", "unam", "csn", "station_xml_epochs")

#: Half of the last printed digit of the stated MAX and RMS [g], plus float slack.
G_PRINT_TOLERANCE = 0.0005 + 1e-9

#: Half of the last printed digit of a printed time [s], plus float slack.
TIME_PRINT_TOLERANCE_S = 0.0005 + 1e-9


def _raw(relpath: str) -> bytes:
    return corpus_file(relpath).read_bytes()


def test_the_corpus_has_the_renadic_files():
    assert len(RENADIC_FILES) == 28
    # gmprocess's format detection takes most of them for DMG too and refuses them.
    assert len(READ_BY_GMPROCESS) == 5
    assert all(REFERENCE[f][0]["trace_id"] == "ERROR" for f in REFUSED_BY_GMPROCESS)


@pytest.mark.parametrize("relpath", READ_BY_GMPROCESS)
def test_reads_like_gmprocess_but_with_the_right_interval_and_start(relpath):
    stream = read_renadic(corpus_file(relpath))
    # Peaks: gmprocess converts g/10 with 980 cm/s^2, this reader with 980.665 (0.07 %).
    assert_peaks_match_gmprocess(stream, relpath, rel=0.001)
    rows = REFERENCE[relpath]
    assert sorted(tr.stats.npts for tr in stream) == sorted(int(r["npts"]) for r in rows)
    for trace in stream:
        header = trace.stats.shipblock_renadic
        npts = trace.stats.npts
        # dt = RECORD LENGTH / NO. OF POINTS (the time column ends at (n - 1) dt);
        # gmprocess divides by n - 1.
        assert trace.stats.delta == pytest.approx(header.record_length_s / npts, rel=1e-12)
        assert float(rows[0]["delta_s"]) == pytest.approx(
            header.record_length_s / (npts - 1), rel=1e-9)
        # gmprocess starts at the trigger time, a pre-event memory after the first sample.
        assert UTCDateTime(rows[0]["starttime"]) - trace.stats.starttime == pytest.approx(
            header.pre_event_s)
        assert header.pre_event_s in (10.0, 20.0, 20.8)


@pytest.mark.parametrize("relpath", RENADIC_FILES)
def test_every_file_matches_its_stated_max_rms_and_peak_time(relpath):
    stream = read_renadic(corpus_file(relpath))
    assert len(stream) == 3
    assert sorted(tr.stats.channel[-1] == "Z" for tr in stream) == [False, False, True]
    for trace in stream:
        header = trace.stats.shipblock_renadic
        assert trace.stats.units == "m/s**2"
        assert trace.stats.original_units == "G/10"
        assert trace.stats.npts == header.npts
        assert np.all(np.isfinite(trace.data))
        in_g = trace.data / STANDARD_GRAVITY
        peak_index = int(np.argmax(np.abs(in_g)))
        # MAX [g], signed, three decimals.
        assert abs(in_g[peak_index] - header.stated_max_g) <= G_PRINT_TOLERANCE
        assert trace.stats.stated_peak_si == pytest.approx(abs(header.stated_max_g)
                                                           * STANDARD_GRAVITY)
        assert abs(np.sqrt(np.mean(in_g ** 2)) - header.stated_rms_g) <= G_PRINT_TOLERANCE
        # The time of the MAX is counted from the trigger, i.e. from the first sample plus the
        # pre-event memory (first sample at the ORIGIN time of line 3). One sample of slack for
        # ties between equal absolute values.
        peak_time = peak_index * trace.stats.delta - header.get("pre_event_s", 0.0)
        assert abs(peak_time - header.stated_max_time_s) <= (
            trace.stats.delta + TIME_PRINT_TOLERANCE_S)


def test_start_times_of_a_split_record_and_placeholder_dates():
    first = read_renadic(corpus_file(MAULE + "stgopenalolen1002271parte1.v1"))
    second = read_renadic(corpus_file(MAULE + "stgopenalolen1002271parte2.v1"))
    assert first[0].stats.starttime == UTCDateTime(2010, 2, 27, 3, 6, 12)
    assert second[0].stats.starttime == UTCDateTime(2010, 2, 27, 3, 7, 42)
    assert first[0].stats.shipblock_renadic.trigger_time == str(UTCDateTime(2010, 2, 27, 3, 6, 32))
    # parte1 lasts 100 s; parte2 starts 90 s after it (the stated times overlap by 10 s).
    assert first[0].stats.endtime - first[0].stats.starttime == pytest.approx(99.99)
    assert second[0].stats.starttime - first[0].stats.starttime == pytest.approx(90.0)
    # An analogue record dated 1/1/1980 0:00:00 has no absolute time.
    analogue = read_renadic(corpus_file(MAULE + "hualane1002271.v1"))
    assert analogue[0].stats.starttime == UTCDateTime(0)
    assert analogue[0].stats.shipblock_renadic.time_stated is False
    # The GPS-timed ETNA at Vina El Salto: local time on line 3, GMT in the ORIGIN field.
    etna = read_renadic(corpus_file(MAULE + "vinaelsalto1002271.v1"))
    assert etna[0].stats.starttime == UTCDateTime(2010, 2, 27, 6, 35, 20)
    assert etna[0].stats.shipblock_renadic.pre_event_s == pytest.approx(20.8)


def test_orientations_station_and_coordinates():
    stream = read_renadic(corpus_file(MAULE + "stgopenalolen1002271parte1.v1"))
    assert [tr.stats.channel for tr in stream] == ["HNE", "HNN", "HNZ"]
    assert [tr.stats.get("azimuth") for tr in stream] == [90.0, 0.0, None]
    assert stream[2].stats.dip == -90.0
    assert stream[0].stats.station == "670"
    assert stream[0].stats.shipblock_renadic.station_name == "SANTIAGO PE\u00d1ALOLEN"
    assert "coordinates" not in stream[0].stats  # 0.000N 0.000E: unknown
    # L/T of the analogue instruments: horizontals of unstated azimuth, 200 samples/s.
    analogue = read_renadic(corpus_file(MAULE + "hualane1002271.v1"))
    assert [tr.stats.channel for tr in analogue] == ["HN1", "HNZ", "HN2"]
    assert analogue[0].stats.delta == 0.005
    assert "azimuth" not in analogue[0].stats
    arica = read_renadic(corpus_file("renadic/usp000h401/arica0911131.v1"))
    assert (arica[0].stats.coordinates.latitude, arica[0].stats.coordinates.longitude) == (
        -18.483, -70.314)


def test_calibration_channel_is_skipped():
    stream = read_renadic(corpus_file(MAULE + "curico1002271parte1.v1"))
    assert [tr.stats.channel for tr in stream] == ["HNN", "HNZ", "HNE"]
    assert stream[0].stats.shipblock_renadic.skipped_channels == "INTC"


def test_headonly_reads_counts_without_samples():
    stream = read_renadic(corpus_file(SMALL), headonly=True)
    assert [tr.stats.npts for tr in stream] == [3500] * 3
    assert all(tr.data.size == 0 for tr in stream)


def _lines(relpath=SMALL):
    return _raw(relpath).split(b"\r\n")


def test_a_missing_data_line_is_refused():
    lines = _lines()
    del lines[100]
    with pytest.raises(RecordError, match="truncated: NO. OF POINTS=3500"):
        read_renadic(io.BytesIO(b"\r\n".join(lines)))


def test_an_irregular_time_column_is_refused():
    lines = _lines()
    assert lines[100].startswith(b"  3.650")
    lines[100] = b"  3.660" + lines[100][7:]
    with pytest.raises(RecordError, match="sample 365 is at 3.66 s"):
        read_renadic(io.BytesIO(b"\r\n".join(lines)))


def test_a_file_cut_inside_a_block_is_refused():
    raw = _raw(SMALL)
    with pytest.raises(RecordError, match="truncated"):
        read_renadic(io.BytesIO(raw[: int(len(raw) * 0.6)]))


def test_unknown_orientation_and_unit_are_refused():
    raw = _raw(SMALL)
    with pytest.raises(RecordError, match="unknown orientation 'XY'"):
        read_renadic(io.BytesIO(raw.replace(b"CHAN  2: NS ", b"CHAN  2: XY ", 1)))
    with pytest.raises(UnitsError, match="CM/SEC"):
        read_renadic(io.BytesIO(raw.replace(b"AND G/10.", b"AND CM/SEC.", 1)))


def test_detection_accepts_every_renadic_file():
    assert all(is_renadic(corpus_file(f)) for f in RENADIC_FILES)
    with open(corpus_file(SMALL), "rb") as fh:
        assert is_renadic(fh)
        assert fh.tell() == 0


@pytest.mark.parametrize("folder", OTHER_FOLDERS)
def test_detection_rejects_other_formats(folder):
    files = reference_files(folder)
    assert files
    assert not any(is_renadic(corpus_file(f)) for f in files)


def test_detection_rejects_numbers_and_garbage(tmp_path):
    numbers = tmp_path / "numbers.txt"
    numbers.write_text("\n".join(f"{i * 0.01:7.3f}{np.sin(i):7.3f}" for i in range(500)))
    binary = tmp_path / "binary.v1"
    binary.write_bytes(bytes(range(256)) * 10)
    assert not is_renadic(numbers)
    assert not is_renadic(binary)
    assert not is_renadic(tmp_path / "missing.v1")
    with pytest.raises(RecordError, match="not a RENADIC"):
        read_renadic(numbers)


def test_fuzz_survives():
    read = assert_reader_survives(read_renadic, _raw(SMALL))
    assert read >= 1


@pytest.mark.parametrize(("station", "first_index", "stated_shift_s"), [
    ("stgopenalolen", 8001, 90.0), ("stgomaipu", 8001, 92.0), ("angol", 8001, 91.0),
    ("curico", 8001, 93.0), ("vinacentro", 9002, 100.0)])
def test_parte2_repeats_the_end_of_parte1(station, first_index, stated_shift_s):
    """The pre-event memory of parte2 is the end of parte1; the stated times disagree with it."""
    first = read_renadic(corpus_file(f"{MAULE}{station}1002271parte1.v1"))
    second = read_renadic(corpus_file(f"{MAULE}{station}1002271parte2.v1"))
    for one, two in zip(first, second, strict=True):
        assert one.stats.channel == two.stats.channel
        overlap = one.stats.npts - first_index
        assert overlap * one.stats.delta == pytest.approx(two.stats.shipblock_renadic.pre_event_s,
                                                          abs=0.025)
        tail, head = one.data[first_index:], two.data[:overlap]
        assert np.corrcoef(tail, head)[0, 1] > 0.99
        # The correlation peaks at this alignment (to the sample).
        shifts = range(first_index - 3, first_index + 4)
        scores = [np.corrcoef(one.data[k:], two.data[:one.stats.npts - k])[0, 1] for k in shifts]
        assert shifts[int(np.argmax(scores))] == first_index
    assert second[0].stats.starttime - first[0].stats.starttime == stated_shift_s
    assert stated_shift_s > first_index * first[0].stats.delta
