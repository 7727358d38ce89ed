"""COSMOS reader against the real files of the gmprocess test corpus (``testdata/cosmos/``).

Reference values: gmprocess 2.8.0's reading of each file (``tests/data/reference/
gmprocess_2.8_peaks.csv``: npts, dt, start time and peak per trace), and each file's own header:
Real(64)/Real(65) (peak, signed, and its time) and text line 11 (``Max = -161.962 cm/sec2 at
27.850 sec``). Tolerances follow the printed digits (given at each assertion).

The files: NP.8040 HNE.01 (V0 counts, one channel), NP.1795 (V0 counts, three channels with
``(10I8)`` samples that run together), AK.BMR BNZ (V2, cm/s^2, Int(54) contradicting the channel),
and the two CESMD-style ``Cosmos12TimeSeriesTest*.v1`` test files (V2, ``/&`` end-of-data lines;
the second has unknown Int(1)/Int(2)/Real(30), and a second channel whose Int(3)=25 (degrees)
contradicts its data line's ``cm/sec2(04)``).
"""

from __future__ import annotations

import warnings

import numpy as np
import obspy
import pytest

from shipblock.errors import RecordError, UnitsError
from shipblock.io.cosmos import is_cosmos, read_cosmos
from tests.reader_fuzz import assert_reader_survives
from tests.real_corpus import (
    REFERENCE,
    assert_peaks_match_gmprocess,
    corpus_file,
    gmprocess_read,
    reference_files,
)

CM = 0.01  # 1 cm/s^2 = 0.01 m/s^2 (exact)

V0_FILES = ["cosmos/ak018fcnsk91/NP8040-n.1000hyfh.HNE.01.V0c", "cosmos/ftbragg/NP1795-n.305.v0c"]
BMR = "cosmos/us1000hyfh/us1000hyfh_akbmrp_AKBMR--n.1000hyfh.BNZ.--.acc.V2c"
TEST1 = "cosmos/ci14155260/Cosmos12TimeSeriesTest.v1"
TEST2 = "cosmos/ci14155260/Cosmos12TimeSeriesTest2.v1"

#: Tolerance of |Real(64)| against the samples' peak [file units]: V0 counts are integers; AK.BMR's
#: Real(64) (F15.6) and samples (E15.6, 7 significant digits) are both printed to 1e-6; the test
#: file's Real(64) repeats text line 11 (printed to 1e-3) with zeros appended.
STATED_PEAK_TOL = {V0_FILES[0]: 0.0, V0_FILES[1]: 0.0, BMR: 0.5e-6, TEST1: 0.5e-3}

#: One file of each other format folder of the corpus, for the detection test.
OTHER_FORMATS = ["dmg", "knet", "kiknet", "geonet", "cwb", "nsmn", "bhrc", "unam", "renadic", "usc",
                 "smc", "esm", "peer", "csn"]


def _read(relpath):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # AK.BMR's orientation warning is tested on its own
        return read_cosmos(corpus_file(relpath))


def _kind(trace) -> str:
    return "V" if abs(abs(trace.stats.dip) - 90.0) < 1.0 else "H"


def test_reference_lists_the_corpus_files():
    assert reference_files("cosmos") == sorted([*V0_FILES, BMR, TEST1, TEST2])
    assert not gmprocess_read(TEST2) and REFERENCE[TEST2][0]["units"] == "ValueError"


@pytest.mark.parametrize("relpath", [f for f in reference_files("cosmos") if gmprocess_read(f)])
def test_npts_delta_start_as_gmprocess(relpath):
    stream = _read(relpath)
    rows = REFERENCE[relpath]
    assert len(stream) == len(rows)
    mine = sorted((tr.stats.npts, tr.stats.delta, tr.stats.starttime.timestamp) for tr in stream)
    theirs = sorted(
        (int(r["npts"]), float(r["delta_s"]), obspy.UTCDateTime(r["starttime"]).timestamp)
        for r in rows
    )
    for (n, dt, t0), (n_ref, dt_ref, t0_ref) in zip(mine, theirs, strict=True):
        assert n == n_ref
        assert dt == pytest.approx(dt_ref, rel=1e-12)
        # Real(30) is printed to 1e-6 s; gmprocess truncates it to whole microseconds.
        assert abs(t0 - t0_ref) <= 1.5e-6


def test_test1_peaks_match_gmprocess():
    stream = _read(TEST1)
    assert_peaks_match_gmprocess(stream, TEST1)
    tr = stream[0]
    assert (tr.id, tr.stats.azimuth, tr.stats.dip) == ("CE.J2236..HN1", 340.0, 0.0)
    assert tr.stats.units == "m/s**2" and tr.stats.original_units == "cm/s^2"
    assert tr.stats.shipblock_cosmos.processing_stage == 2


@pytest.mark.parametrize("relpath", V0_FILES)
def test_v0_counts_peaks_equal_gmprocess(relpath):
    # gmprocess reports raw counts too: the peaks of integer counts must be equal.
    stream = _read(relpath)
    assert all(tr.stats.units == "counts" for tr in stream)
    assert all(tr.stats.shipblock_cosmos.processing_stage == 0 for tr in stream)
    mine = sorted(float(np.max(np.abs(tr.data))) for tr in stream)
    theirs = sorted(float(r["peak_abs"]) for r in REFERENCE[relpath])
    assert all(r["units"] == "counts" for r in REFERENCE[relpath])
    assert mine == theirs
    # Kinds: gmprocess calls the channels HN1/HN2/HNZ; ours keep the SCNL codes and Int(54).
    by_kind = sorted((_kind(tr), float(np.max(np.abs(tr.data)))) for tr in stream)
    ref_kind = sorted(("V" if r["trace_id"].endswith("Z") else "H", float(r["peak_abs"]))
                      for r in REFERENCE[relpath])
    assert by_kind == ref_kind


def test_ftbragg_three_channels_codes_and_orientation():
    stream = _read(V0_FILES[1])
    assert [tr.id for tr in stream] == ["NP.1795..HNE", "NP.1795..HNN", "NP.1795..HNZ"]
    e, n, z = stream
    assert (e.stats.azimuth, e.stats.dip, n.stats.azimuth, n.stats.dip) == (90.0, 0.0, 0.0, 0.0)
    assert z.stats.dip == -90.0 and "azimuth" not in z.stats
    assert e.stats.coordinates.latitude == pytest.approx(37.746639, abs=5e-7)


def test_bmr_vertical_kept_vertical_disagreeing_with_gmprocess():
    # gmprocess follows Int(54)=0 and calls this record HN1 (a north horizontal). The SCNL comment,
    # RcrdId and file name say BNZ and text line 9 says "Other": shipblock keeps it vertical.
    with pytest.warns(UserWarning, match="Int\\(54\\)=0 says horizontal.*BNZ says vertical"):
        stream = read_cosmos(corpus_file(BMR))
    (tr,) = stream
    assert tr.id == "AK.BMR..BNZ" and "azimuth" not in tr.stats and "dip" not in tr.stats
    (row,) = REFERENCE[BMR]
    assert row["trace_id"] == "AK.BMR.--.HN1" and row["units"] == "cm/s/s"
    # Same samples: the peaks agree (gmprocess's peak is printed to 7 significant digits).
    assert float(np.max(np.abs(tr.data))) == pytest.approx(float(row["peak_abs"]) * CM, rel=1e-6)


@pytest.mark.parametrize("relpath", sorted(STATED_PEAK_TOL))
def test_stated_peak_and_time_match_the_samples(relpath):
    for tr in _read(relpath):
        header = tr.stats.shipblock_cosmos
        factor = CM if tr.stats.units == "m/s**2" else 1.0
        i = int(np.argmax(np.abs(tr.data)))
        peak = abs(tr.data[i]) / factor  # in the file's unit
        assert abs(peak - abs(header.stated_peak)) <= STATED_PEAK_TOL[relpath] + 1e-9 * peak
        # Real(65) must fall on the peak's sample (half a sample interval).
        assert abs(i * tr.stats.delta - header.stated_peak_time) <= tr.stats.delta / 2
        if tr.stats.units == "counts":
            assert "stated_peak_si" not in tr.stats  # counts are no acceleration
        else:
            assert np.sign(tr.data[i]) == np.sign(header.stated_peak)  # V1/V2: signed peak
            assert tr.stats.stated_peak_si == pytest.approx(abs(header.stated_peak) * CM,
                                                            rel=1e-12)
        if header.text_peak is not None:
            # Text line 11 is printed to 1e-3 (file units) and at 1e-3 s.
            assert abs(header.text_peak - header.stated_peak) <= 0.5e-3
            assert abs(header.text_peak_time - header.stated_peak_time) <= 0.5e-3


def test_test2_refused_for_its_contradicting_unit_codes():
    # gmprocess stops at channel 1's unknown Int(1) ("Unknown process level"). That alone does not
    # prevent reading; but channel 2 states cm/sec2 (04) on its data line and degrees (25) in
    # Int(3): one of them is wrong, so the file is refused, naming the block.
    with pytest.raises(UnitsError, match="Test2.v1: channel block at line 923.*04.*Int\\(3\\) says"
                                         " 25 \\(deg\\)"):
        read_cosmos(corpus_file(TEST2))


def test_test2_first_channel_is_a_valid_record(tmp_path):
    # The agency bytes up to channel 1's "/&" line: Int(1), Int(2) and Real(30) unknown, Int(54)
    # 400 (up), line 13 without null values. Its samples are those of Cosmos12TimeSeriesTest.v1.
    lines = corpus_file(TEST2).read_text().splitlines(keepends=True)
    assert lines[921].startswith("/&")
    path = tmp_path / "test2_channel1.v1"
    path.write_text("".join(lines[:922]))
    (tr,) = read_cosmos(path)
    (ref,) = _read(TEST1)
    np.testing.assert_array_equal(tr.data, ref.data)
    assert tr.id == "CI.J2236..HNZ" and tr.stats.dip == -90.0
    header = tr.stats.shipblock_cosmos
    assert header.processing_stage == 2  # from "Corrected acceleration" on line 1
    assert any("Int(1) unknown" in n for n in header.notes)
    # Real(30) unknown: the start from text line 8 (printed to 1 ms) equals file 1's Real(30).
    assert tr.stats.starttime == obspy.UTCDateTime("2005-06-16T20:53:04.400")
    assert abs(tr.stats.starttime - obspy.UTCDateTime(REFERENCE[TEST1][0]["starttime"])) < 1e-6
    assert tr.stats.coordinates.elevation == 0.0  # Real(3) unknown


def test_end_of_data_variants_and_headonly():
    # Three end-of-data spellings across the corpus; headonly gives the same header values.
    for relpath in (TEST1, V0_FILES[1], BMR):
        full = _read(relpath)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            head = read_cosmos(corpus_file(relpath), headonly=True)
        assert [(t.id, t.stats.npts, t.stats.starttime) for t in head] == [
            (t.id, t.stats.npts, t.stats.starttime) for t in full]
        assert all(len(t.data) == 0 for t in head)


def test_detection():
    for relpath in reference_files("cosmos"):
        assert is_cosmos(corpus_file(relpath)), relpath
    for folder in OTHER_FORMATS:
        for relpath in reference_files(folder)[:2]:
            assert not is_cosmos(corpus_file(relpath)), relpath


def test_truncated_real_file_refused(tmp_path):
    raw = corpus_file(V0_FILES[1]).read_bytes()
    path = tmp_path / "cut.v0c"
    for fraction in (0.3, 0.7):
        path.write_bytes(raw[: int(len(raw) * fraction)])
        with pytest.raises(RecordError, match="cut.v0c"):
            read_cosmos(path)
    lines = raw.splitlines(keepends=True)
    assert lines[-1].startswith(b"End-of-data for 1795.HNZ")
    # Cut 5 characters into the last (full, 10I8) data line: the last field still parses as a
    # number (-2378631 -> -237863), so only the field alignment shows the cut.
    path.write_bytes(b"".join(lines[:-1])[:-6])
    with pytest.raises(RecordError, match="cut.v0c: line 6155: .*ends inside a 8-character field"):
        read_cosmos(path)
    # Cut at the line boundary after the samples: complete data but no end-of-data line.
    path.write_bytes(b"".join(lines[:-1]))
    with pytest.raises(RecordError, match="cut.v0c: line 6156: expected the end-of-data line"):
        read_cosmos(path)


@pytest.mark.parametrize("relpath", [TEST1, V0_FILES[1]])
def test_fuzz_real_file(relpath):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        assert_reader_survives(read_cosmos, corpus_file(relpath).read_bytes())
