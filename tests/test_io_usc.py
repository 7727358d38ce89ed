"""USC Volume I/II reader (shipblock.io.usc) against the real files of the gmprocess corpus.

Event ci3144585 (Northridge, 1994): seven Volume I files (uncorrected film records digitized
unevenly, in g/10) that gmprocess 2.8.0 reads after interpolating them at 200 samples/s; shipblock
does the same, so npts, dt, start time and peaks must agree. ``017m30bt.s0a`` is refused by
gmprocess ("Not a supported volume"): it is a Volume II (corrected acceleration at 0.02 s in
cm/s^2, then velocity and displacement), which shipblock reads; its stated peak and peak time are
the check. The stated RMS acceleration of each Volume I checks the g/10 unit.
"""

from __future__ import annotations

import io

import numpy as np
import pytest
from obspy import UTCDateTime

from shipblock.errors import RecordError, UnitsError
from shipblock.io.usc import is_usc, read_usc
from shipblock.units import STANDARD_GRAVITY
from tests.reader_fuzz import assert_reader_survives
from tests.real_corpus import (
    REFERENCE,
    assert_peaks_match_gmprocess,
    corpus_file,
    gmprocess_read,
    reference_files,
)

FILES = reference_files("usc")
READ_BY_GMPROCESS = [f for f in FILES if gmprocess_read(f)]
DIR = "usc/ci3144585/"
V2 = DIR + "017m30bt.s0a"
CM = 0.01  # 1 cm/s^2 in m/s^2 (exact)

#: Read off each file: the COMP text's azimuth [deg] ("up" for verticals), the station number,
#: the RMS acceleration of the text header [g/10] and the first digitized value [g/10].
STATED = {
    "017m30cc.y0a": (0, 57, 0.638, -0.049),
    "017m30lw.e0a": (185, 17, 0.211, 0.046),
    "017m30lw.e0b": ("up", 17, 0.143, 0.099),
    "017m30lw.e0c": (95, 17, 0.179, -0.006),
    "017m30lw.s0a": (90, 16, 0.400, -0.005),
    "017m30lw.s0b": ("up", 16, 0.300, 0.066),
    "017m30lw.s0c": (0, 16, 0.356, -0.026),
}

#: Files of other formats that must not be taken for USC: every DMG file (same family of
#: layouts) and two of each other folder.
OTHER_FORMATS = reference_files("dmg") + [
    f for folder in ("knet", "kiknet", "cosmos", "esm", "geonet", "geonet2", "cwb", "unam",
                     "renadic", "smc", "bhrc", "peer", "nsmn", "csn")
    for f in reference_files(folder)[:2]
]


def _raw(relpath: str) -> bytes:
    return corpus_file(relpath).read_bytes()


def test_corpus_lists_the_eight_files():
    assert sorted([DIR + f for f in STATED] + [V2]) == FILES
    assert sorted(DIR + f for f in STATED) == READ_BY_GMPROCESS


@pytest.mark.parametrize("relpath", READ_BY_GMPROCESS)
def test_volume1_matches_gmprocess(relpath):
    stream = read_usc(corpus_file(relpath))
    assert len(stream) == 1
    assert_peaks_match_gmprocess(stream, relpath)
    (row,) = REFERENCE[relpath]
    trace = stream[0]
    assert trace.stats.npts == int(row["npts"])
    assert trace.stats.delta == pytest.approx(float(row["delta_s"]), rel=1e-12)
    assert trace.stats.starttime == UTCDateTime(row["starttime"])
    assert trace.id.rsplit(".", 1)[0] == row["trace_id"].rsplit(".", 2)[0] + "."


@pytest.mark.parametrize("relpath", READ_BY_GMPROCESS)
def test_volume1_stated_values(relpath):
    azimuth, station, rms_g10, first = STATED[relpath.removeprefix(DIR)]
    trace = read_usc(corpus_file(relpath))[0]
    header = trace.stats.shipblock_usc
    g10 = 0.1 * STANDARD_GRAVITY
    assert trace.stats.original_units == "g/10" and trace.stats.units == "m/s**2"
    assert trace.stats.station == str(station) and trace.stats.network == "LA"
    # The header's RMS (3 decimals of g/10) is of the digitized record; the 200/s grid keeps it
    # to 1 % (a wrong unit would be off by a factor of 10 or 98).
    rms = float(np.sqrt(np.mean(trace.data**2)))
    assert rms == pytest.approx(rms_g10 * g10, rel=0.01)
    assert header.stated_rms_si == pytest.approx(rms_g10 * g10, rel=1e-12)
    # The first digitized point is at 0 s, on the grid.
    assert trace.data[0] == pytest.approx(first * g10, rel=1e-9)
    # The peak of the grid is the digitized peak, or just below it.
    peak = float(np.max(np.abs(trace.data)))
    assert 0.99 * header.digitized_peak_si <= peak <= header.digitized_peak_si
    if azimuth == "up":
        assert trace.stats.dip == -90.0 and trace.stats.channel == "HNZ"
    else:
        assert trace.stats.dip == 0.0 and trace.stats.azimuth == azimuth
    assert header.start_time_nominal is True
    assert trace.stats.starttime == UTCDateTime("1994-01-17T12:30:00")


def test_volume2_file_gmprocess_refuses():
    assert not gmprocess_read(V2)
    stream = read_usc(corpus_file(V2))
    assert len(stream) == 1  # the velocity and displacement blocks are not traces
    trace = stream[0]
    header = trace.stats.shipblock_usc
    assert header.volume == "II"
    assert trace.stats.npts == 1887 and trace.stats.delta == 0.02
    assert trace.stats.original_units == "cm/s^2"
    # "PEAK ACCELERATION =  -242.39450  CMS/SEC/SEC AT    4.580   SEC." and the samples (F10.3).
    assert trace.stats.stated_peak_si == pytest.approx(242.3945 * CM, rel=1e-9)
    index = int(np.argmax(np.abs(trace.data)))
    assert index * trace.stats.delta == pytest.approx(4.58)
    # The samples hold +242.395 there: the file's stated extremes all have the samples' opposite
    # sign (acceleration, velocity and displacement alike); the reader reports it.
    assert trace.data[index] == pytest.approx(242.395 * CM, abs=0.0005 * CM)
    assert header.stated_peak_sign_matches_samples is False
    # COMP N08W: azimuth 352 deg; 50 samples/s gives band code B.
    assert trace.stats.azimuth == 352.0 and trace.stats.channel == "BN1"
    assert trace.stats.station == "61"
    assert trace.stats.coordinates.latitude == pytest.approx(34 + 17 / 60 + 11 / 3600)
    assert trace.stats.coordinates.longitude == pytest.approx(-(118 + 13 / 60 + 31 / 3600))
    assert "BAND-PASS FILTERED" in header.processing


def test_longitude_printed_north_is_west():
    """017m30lw.s0a prints ``118 26 05N``: the reader keeps the text and puts it west."""
    trace = read_usc(corpus_file(DIR + "017m30lw.s0a"))[0]
    assert trace.stats.shipblock_usc.longitude_hemisphere_text == "N"
    assert trace.stats.coordinates.longitude == pytest.approx(-(118 + 26 / 60 + 5 / 3600))
    assert trace.stats.coordinates.latitude == pytest.approx(34 + 5 / 60 + 22 / 3600)


def test_file_object_headonly_and_resample_rate():
    relpath = DIR + "017m30cc.y0a"
    full = read_usc(corpus_file(relpath))[0]
    assert (read_usc(io.BytesIO(_raw(relpath)))[0].data == full.data).all()
    head = read_usc(corpus_file(relpath), headonly=True)[0]
    assert head.stats.npts == full.stats.npts == 6206 and head.data.size == 0
    fine = read_usc(corpus_file(relpath), resample_rate=1000.0)[0]
    # 0 to 31.026 s at 1 ms; the grid passes through every digitized time (printed to 1 ms).
    assert fine.stats.npts == 31027
    assert float(np.max(np.abs(fine.data))) == pytest.approx(
        fine.stats.shipblock_usc.digitized_peak_si, rel=1e-12)


def test_resample_rate_refused_for_a_volume_ii_file():
    """017m30bt.s0a is a Volume II, evenly sampled at 0.02 s: resample_rate (the grid of Volume
    I's digitized points) would leave it as stored, so it is refused, not ignored."""
    path = corpus_file(DIR + "017m30bt.s0a")
    with pytest.raises(RecordError, match=r"017m30bt\.s0a: resample_rate=100\.0 cannot apply: the"
                                          r" record is a Volume II, evenly sampled at 50 samples/s"):
        read_usc(path, resample_rate=100.0)
    assert read_usc(path)[0].stats.delta == 0.02


def test_concatenated_channels():
    """Channels may follow each other in one file (blank lines between are allowed)."""
    raw = _raw(DIR + "017m30lw.e0a") + _raw(DIR + "017m30lw.e0b") + _raw(DIR + "017m30lw.e0c")
    stream = read_usc(io.BytesIO(raw))
    assert [tr.stats.channel for tr in stream] == ["HN1", "HNZ", "HN2"]
    assert [tr.stats.npts for tr in stream] == [6003, 6007, 6007]


def test_detection():
    for relpath in FILES:
        assert is_usc(corpus_file(relpath)), relpath
    for relpath in OTHER_FORMATS:
        assert not is_usc(corpus_file(relpath)), relpath
    assert not is_usc(io.BytesIO(b"0.000 -0.049 0.004 -0.038\n" * 50))
    assert not is_usc(io.BytesIO(b"\x00binary"))


def test_dmg_detector_does_not_claim_usc_files():
    dmg = pytest.importorskip("shipblock.io.dmg")
    for relpath in FILES:
        assert not dmg.is_dmg(corpus_file(relpath)), relpath


def _replace(raw: bytes, old: bytes, new: bytes) -> bytes:
    assert raw.count(old) >= 1
    return raw.replace(old, new, 1)


def test_refusals_name_the_file(tmp_path):
    raw = _raw(DIR + "017m30lw.e0a")
    path = tmp_path / "cut.e0a"
    path.write_bytes(raw[: len(raw) // 2])
    with pytest.raises(RecordError, match=r"cut\.e0a: is truncated: 7065 digitized points"):
        read_usc(path)
    # The text says G/10, real 5 says 0.01 g: the unit is in doubt.
    with pytest.raises(UnitsError, match="G/10"):
        read_usc(io.BytesIO(_replace(raw, b"      .100     1.690", b"      .010     1.690")))
    # A point count that disagrees with "NO. OF POINTS".
    with pytest.raises(RecordError, match="point count"):
        read_usc(io.BytesIO(_replace(raw, b"4  185 7065", b"4  185 7064")))
    # Orientation code and COMP text disagree.
    with pytest.raises(RecordError, match="disagrees with the text COMP S05W"):
        read_usc(io.BytesIO(_replace(raw, b"4  185 7065", b"4  175 7065")))
    # Two digitized points swapped: time goes backwards.
    with pytest.raises(RecordError, match="go backwards"):
        read_usc(io.BytesIO(_replace(raw, b"    .000   .046   .004   .022",
                                     b"    .004   .046   .000   .022")))
    v2 = _raw(V2)
    with pytest.raises(UnitsError, match="cm/sec"):
        read_usc(io.BytesIO(_replace(v2, b"IN UNITS CM/SEC/SEC", b"IN UNITS CM/SEC")))
    with pytest.raises(RecordError, match="Volume III"):
        read_usc(io.BytesIO(b"RESPONSE AND FOURIER AMPLITUDE SPECTRA\r\n" + v2))
    with pytest.raises(RecordError, match="does not start a USC"):
        read_usc(io.BytesIO(b"hello\n" + v2))


@pytest.mark.parametrize("relpath", [DIR + "017m30cc.y0a", V2])
def test_fuzz(relpath):
    assert_reader_survives(read_usc, _raw(relpath), count=60)
