"""Tests of the CSMIP/CDMG ("DMG") volume 1/2 reader against the real files of the gmprocess corpus."""

from __future__ import annotations

import io

import numpy as np
import pytest
from obspy import UTCDateTime

from shipblock.errors import RecordError, UnitsError
from shipblock.io.dmg import FORMAT, is_dmg, read_dmg
from shipblock.units import STANDARD_GRAVITY
from tests.reader_fuzz import assert_reader_survives
from tests.real_corpus import (
    REFERENCE,
    assert_peaks_match_gmprocess,
    corpus_file,
    gmprocess_read,
    reference_files,
)

DMG_FILES = reference_files("dmg")
READ_BY_GMPROCESS = [f for f in DMG_FILES if gmprocess_read(f)]
#: Volume 1 files whose real header gives the peak to 3 decimals of g only.
OLD_V1_FILES = ["dmg/ci3031425/NEWPORT.RAW", "dmg/ci3031425/ce23583r_HESPERIA.RAW",
                "dmg/ci3144585/LA116TH.RAW"]
V3_FILES = ["dmg/ci15481673/CIWLT.V3", "dmg/nc71734741/CE89146.V3"]

#: Files of other formats that is_dmg must refuse (RENADIC copies the volume 1 layout; USC files
#: share the titles).
OTHER_FORMAT_FILES = [
    "renadic/official20100227063411530_30/angol1002271parte1.v1",
    "renadic/official20100227063411530_30/llolleo1002271.v1",
    "renadic/usp000h401/arica0911131.v1",
    "cosmos/ftbragg/NP1795-n.305.v0c",
    "cosmos/us1000hyfh/us1000hyfh_akbmrp_AKBMR--n.1000hyfh.BNZ.--.acc.V2c",
    "usc/ci3144585/017m30bt.s0a",
    "usc/ci3144585/017m30cc.y0a",
]


def _kind(trace) -> str:
    return "V" if abs(abs(trace.stats.dip) - 90.0) < 1.0 else "H"


def _printed_half_unit_si(trace) -> float:
    """Half the last printed digit of the stated peak, in m/s^2."""
    text = trace.stats.shipblock_dmg.stated_peak_text
    number = text.split("=")[1].split()[0]
    digits = len(number.split(".")[1])
    unit = text.split("=")[1].split()[1].rstrip(",").lower()
    factor = STANDARD_GRAVITY if unit == "g" else 0.01
    return 0.5 * 10.0 ** -digits * factor


def test_format_name():
    assert FORMAT == "SHIPBLOCK_DMG"


@pytest.mark.parametrize("relpath", READ_BY_GMPROCESS)
def test_matches_gmprocess(relpath):
    stream = read_dmg(corpus_file(relpath))
    assert_peaks_match_gmprocess(stream, relpath)
    rows = REFERENCE[relpath]
    ours = sorted((tr.stats.npts, round(tr.stats.delta, 9)) for tr in stream)
    theirs = sorted((int(r["npts"]), round(float(r["delta_s"]), 9)) for r in rows)
    assert ours == theirs
    for trace in stream:
        assert trace.stats.units == "m/s**2"
        assert trace.data.dtype == np.float64
    # Start times: gmprocess leaves 1970 where the file states none (NEWPORT.RAW).
    stated = [UTCDateTime(r["starttime"]) for r in rows if UTCDateTime(r["starttime"]).year != 1970]
    for trace in stream:
        if stated:
            assert min(abs(trace.stats.starttime - t) for t in stated) < 1e-3
        else:
            assert trace.stats.shipblock_dmg.start_time_text == ""
            assert trace.stats.starttime == UTCDateTime(0)


@pytest.mark.parametrize("relpath", READ_BY_GMPROCESS + ["dmg/nc71734741/BadHeader.V2",
                                                        "dmg/nc72282711/CE58667.V2"])
def test_stated_peaks(relpath):
    """Every channel states its peak ("Peak acceleration =" in V2, "Max =" in V1)."""
    stream = read_dmg(corpus_file(relpath))
    assert len(stream) == 3
    for trace in stream:
        peak = float(np.max(np.abs(trace.data)))
        assert abs(peak - trace.stats.stated_peak_si) <= _printed_half_unit_si(trace) * 1.0001
        # The real header repeats the peak (V1: g, V2: cm/s^2), to 7 digits in the newer files.
        header = trace.stats.shipblock_dmg
        if relpath in OLD_V1_FILES:
            continue
        factor = STANDARD_GRAVITY if header.volume == "V1" else 0.01
        # V1 samples have 6 decimals of g: half a digit of theirs is the tolerance.
        tolerance = 0.501e-6 * STANDARD_GRAVITY if header.volume == "V1" else 0.0
        assert peak == pytest.approx(abs(header.real_header_peak) * factor, rel=2e-6,
                                     abs=tolerance)


def test_v2_values_and_header():
    stream = read_dmg(corpus_file("dmg/ci15481673/CIWLT.V2"))
    assert [tr.stats.channel for tr in stream] == ["BNE", "BNN", "BNZ"]
    assert [tr.stats.get("azimuth") for tr in stream] == [90.0, 0.0, None]
    assert [tr.stats.dip for tr in stream] == [0.0, 0.0, -90.0]
    first = stream[0]
    assert (first.stats.network, first.stats.station) == ("CI", "WLT")
    assert first.stats.original_units == "cm/s^2"
    # First and last samples (8f10.6 and, in channel 2, 8f10.5), converted to m/s^2.
    assert first.data[:3] == pytest.approx([0.01046e-3, 0.01378e-3, 0.01088e-3], rel=1e-9)
    assert stream[1].data[0] == pytest.approx(-0.00035e-2, rel=1e-9)
    coordinates = first.stats.coordinates
    assert (coordinates.latitude, coordinates.longitude) == (34.00948, -117.9508)
    assert first.stats.starttime == UTCDateTime("2014-03-29T04:09:34")


def test_old_v2_pdt_start_time_and_dos_padding():
    """1983 file: trigger time in PDT, 8F10.3 data without a format, Ctrl-Z padding at the end."""
    stream = read_dmg(corpus_file("dmg/nc1091100/ce36456p_CE36456.V2"))
    assert [tr.stats.npts for tr in stream] == [3251, 3250, 3250]
    for trace in stream:
        assert trace.stats.starttime == UTCDateTime("1983-05-02T23:42:48.2")
        assert trace.stats.network == "CE" and trace.stats.station == "36456"
    assert stream[0].data[:2] == pytest.approx([-0.03038, -0.00787], rel=1e-9)
    assert stream[1].stats.dip == -90.0
    assert stream[0].stats.stated_peak_si == pytest.approx(2.67957)


def test_time_value_pairs_in_tenths_of_g():
    """NEWPORT.RAW: digitised film, (time, value) pairs in g/10 at uneven times."""
    stream = read_dmg(corpus_file("dmg/ci3031425/NEWPORT.RAW"))
    east = stream[0]
    header = east.stats.shipblock_dmg
    assert east.stats.original_units == "g/10"
    assert header.time_value_pairs and header.interpolated and header.original_npts == 12080
    assert east.stats.npts == 12000 and east.stats.delta == 0.005
    # The largest pair value is -.549 (g/10) at 15.992 s; the header says MAX = -.055 G.
    assert np.max(np.abs(east.data)) == pytest.approx(0.0549 * STANDARD_GRAVITY, rel=0.01)
    assert east.stats.stated_peak_si == pytest.approx(0.055 * STANDARD_GRAVITY)
    assert np.argmax(np.abs(east.data)) * 0.005 == pytest.approx(15.992, abs=0.006)
    # The file states no trigger time; the reader says so instead of guessing.
    assert any("no start" in note for note in header.notes)
    # A finer grid on request.
    fine = read_dmg(corpus_file("dmg/ci3031425/NEWPORT.RAW"), resample_interval=0.0025)
    assert fine[0].stats.npts == 23999 + 1 and fine[0].stats.delta == 0.0025


@pytest.mark.parametrize(("relpath", "stored"), [("dmg/nc71734741/CE89146.V2", "0.005 s"),
                                                 ("dmg/ci15481673/CIWLT.RAW", "0.01 s"),
                                                 ("dmg/ci15481673/CIWLT.V2", "0.02 s")])
def test_resample_interval_refused_for_an_even_file(relpath, stored):
    """resample_interval sets the grid of uneven time/value pairs only (NEWPORT.RAW above); a
    file with none is read as stored, so the option is refused naming it, not ignored."""
    with pytest.raises(RecordError, match=rf"resample_interval=0\.01 cannot apply: the record is"
                                          rf" evenly sampled at {stored} intervals"):
        read_dmg(corpus_file(relpath), resample_interval=0.01)
    stream = read_dmg(corpus_file(relpath))
    assert not any(trace.stats.shipblock_dmg.interpolated for trace in stream)


def test_h1_h2_horizontals_gmprocess_refuses():
    """CE58667.V2 names its horizontals H1/H2: horizontals whose azimuth the file does not state."""
    stream = read_dmg(corpus_file("dmg/nc72282711/CE58667.V2"))
    assert [tr.stats.channel for tr in stream] == ["HN1", "HNZ", "HN2"]
    assert [tr.stats.dip for tr in stream] == [0.0, -90.0, 0.0]
    assert "azimuth" not in stream[0].stats and "azimuth" not in stream[2].stats
    assert [tr.stats.stated_peak_si for tr in stream] == pytest.approx([0.27114, 0.11244, 0.26411])
    assert stream[0].stats.starttime == UTCDateTime("2014-08-24T10:20:33")


def test_bad_header_read_from_its_text():
    """BadHeader.V2 = CE89146.V2 with a damaged header: the text orientation and data are right."""
    bad = read_dmg(corpus_file("dmg/nc71734741/BadHeader.V2"))
    good = read_dmg(corpus_file("dmg/nc71734741/CE89146.V2"))
    for b, g in zip(bad, good, strict=True):
        assert b.id == g.id
        assert np.array_equal(b.data, g.data)
        assert b.stats.starttime == g.stats.starttime == UTCDateTime("2012-02-13T21:06:45")
        assert b.stats.coordinates.latitude == pytest.approx(40.9406)
    assert bad[0].stats.channel == "HNN" and bad[0].stats.azimuth == 0.0
    assert any("900" in note for note in bad[0].stats.shipblock_dmg.notes)


@pytest.mark.parametrize("relpath", V3_FILES)
def test_v3_refused(relpath):
    path = corpus_file(relpath)
    assert is_dmg(path)
    with pytest.raises(RecordError, match="V3 holds response spectra, not a time series; use the"
                                          " V2 file"):
        read_dmg(path)


@pytest.mark.parametrize("relpath", DMG_FILES)
def test_detected(relpath):
    assert is_dmg(corpus_file(relpath))


def _other_folders_sample():
    folders = sorted({f.split("/", 1)[0] for f in REFERENCE} - {"dmg"})
    return [f for folder in folders for f in reference_files(folder)[:2]]


@pytest.mark.parametrize("relpath", OTHER_FORMAT_FILES + _other_folders_sample())
def test_not_detected_on_other_formats(relpath):
    path = corpus_file(relpath)
    assert not is_dmg(path)
    if relpath.startswith("renadic"):
        with pytest.raises(RecordError, match="RENADIC"):
            read_dmg(path)


def test_detection_never_raises(tmp_path):
    binary = tmp_path / "x.bin"
    binary.write_bytes(bytes(range(256)) * 4)
    assert not is_dmg(binary)
    assert not is_dmg(tmp_path / "missing.V2")
    assert not is_dmg(io.BytesIO(b""))


def test_file_object_input():
    path = corpus_file("dmg/nc71734741/CE89146.V1")
    by_path = read_dmg(path)
    with open(path, "rb") as fh:
        assert is_dmg(fh)
        assert fh.tell() == 0
        by_handle = read_dmg(fh)
    by_bytes = read_dmg(io.BytesIO(path.read_bytes()))
    for a, b, c in zip(by_path, by_handle, by_bytes, strict=True):
        assert a.id == b.id == c.id
        assert np.array_equal(a.data, b.data) and np.array_equal(a.data, c.data)
    assert [tr.stats.npts for tr in by_path] == [13200] * 3


def test_headonly():
    stream = read_dmg(corpus_file("dmg/nc71734741/CE89146.V2"), headonly=True)
    assert [tr.stats.npts for tr in stream] == [12000] * 3
    assert all(tr.data.size == 0 for tr in stream)


@pytest.mark.parametrize("relpath", ["dmg/nc1091100/ce36456p_CE36456.V2",
                                     "dmg/ci3031425/ce23583r_HESPERIA.RAW",
                                     "dmg/ci3144585/LA116TH.RAW"])
def test_fuzz(relpath):
    raw = corpus_file(relpath).read_bytes()
    assert assert_reader_survives(read_dmg, raw, count=60) > 0  # some damage is harmless


# ----------------------------------------------------------------------------------------------
# Synthetic files, for cases the corpus lacks (written here from the layout; no corpus text).
# ----------------------------------------------------------------------------------------------

def _channel(number, orientation, values, code=-999, unit="cm/sec2", stated_max_g=None,
             with_end=True):
    """One volume 1 channel block, 8F10.6 data."""
    values = np.asarray(values, dtype=float)
    if stated_max_g is None:
        stated_max_g = np.max(np.abs(values)) * (0.01 if unit == "cm/sec2" else 1.0) / 9.80665
    text = [
        "Uncorrected Accelerogram Data             Processed: 01/05/20, CGS  synth",
        "Synthetic record",
        "(Origin:  none)",
        "99999-X0000-20001.01                 Start time:  1/02/20, 03:04:05.5 UTC (GPS)",
        "Station No. 99999   35.000N, 118.500W      Etna  s/n 0001  (2 Chns of  2 at Sta)",
        "Test site",
        f"Chan  {number}: {orientation}",
        "", "", "",
        f"No. of Points = {values.size:6d}  Record Length = 1.000 sec   at 100 Samples/sec",
        f"Units of uncor data are sec and g .        Max  = {stated_max_g:7.3f} g , at   0.010 sec.",
        "RMS",
    ]
    ints = [0] * 100
    ints[23], ints[26], ints[27] = 2020, code, values.size
    int_lines = ["".join(f"{v:5d}" for v in ints[k:k + 16]) for k in range(0, 100, 16)]
    reals = [0.0] * 50
    real_lines = ["".join(f"{v:10.6f}" for v in reals[k:k + 8]) for k in range(0, 50, 8)]
    start = f"{values.size:6d} Accelerogram points at 100 pts/sec in units of {unit} .   Format: (8f10.6)"
    data = ["".join(f"{v:10.6f}" for v in values[k:k + 8]) for k in range(0, values.size, 8)]
    end = [f"/&  ----------  End of Data for Channel {number}  ----------"] if with_end else []
    return text + int_lines + real_lines + [start] + data + end


def _file(*channels) -> io.BytesIO:
    return io.BytesIO(("\r\n".join(line for ch in channels for line in ch) + "\r\n").encode())


VALUES = np.array([-99.123456, -12.345678, 1.5, 0.25, -0.125, 3.0, 4.0, 5.0, 6.0, -7.0, 8.5])


def test_synthetic_abutting_numbers_and_orientations():
    stream = read_dmg(_file(_channel(1, "Down", VALUES), _channel(2, "N45E", VALUES, code=45),
                            _channel(3, "Roof", VALUES)))
    assert len(stream) == 3
    assert stream[0].data == pytest.approx(VALUES * 0.01, rel=1e-12)  # "-99.123456-12.345678"
    assert (stream[0].stats.channel, stream[0].stats.dip) == ("HNZ", 90.0)
    assert (stream[1].stats.channel, stream[1].stats.azimuth) == ("HN1", 45.0)
    # A word the reader does not know: no dip or azimuth, channel named by its number.
    assert stream[2].stats.channel == "HN3"
    assert "dip" not in stream[2].stats and "azimuth" not in stream[2].stats
    assert stream[0].stats.starttime == UTCDateTime("2020-01-02T03:04:05.5")
    assert (stream[0].stats.network, stream[0].stats.station) == ("CE", "99999")
    assert stream[0].stats.coordinates.longitude == -118.5


def test_synthetic_duplicate_channel_codes_get_locations():
    stream = read_dmg(_file(_channel(1, "90 Deg", VALUES), _channel(2, "90 Deg", VALUES)))
    assert [tr.id for tr in stream] == ["CE.99999.01.HNE", "CE.99999.02.HNE"]


def test_synthetic_orientation_conflict():
    with pytest.raises(RecordError, match="says '90 Deg'.*code is 360"):
        read_dmg(_file(_channel(1, "90 Deg", VALUES, code=360)))


def test_synthetic_unit_inconsistent_with_stated_peak():
    # Samples labelled g/10 but the header's Max says 0.101 g: the g/10 reading gives 0.99 g.
    with pytest.raises(UnitsError, match="states a peak"):
        read_dmg(_file(_channel(1, "Up", VALUES, unit="g/10", stated_max_g=0.101)))
    with pytest.raises(UnitsError, match="velocity or displacement"):
        read_dmg(_file(_channel(1, "Up", VALUES, unit="cm/sec")))


def test_synthetic_truncations():
    lines = _channel(1, "Up", VALUES)
    with pytest.raises(RecordError, match="truncated"):
        read_dmg(_file(lines[:-2]))  # last data line lost with the end line
    with pytest.raises(RecordError, match="truncated"):
        read_dmg(_file(lines[:-3] + lines[-2:]))  # first data line lost: the count is short
    extra = _channel(1, "Up", VALUES)
    extra.insert(-1, extra[-2])
    with pytest.raises(RecordError, match="unexpected text"):
        read_dmg(_file(extra))
    # Without the end line a complete last channel is still read (the marker is optional at EOF).
    stream = read_dmg(_file(_channel(1, "Up", VALUES, with_end=False)))
    assert stream[0].stats.npts == VALUES.size


def test_synthetic_bad_numbers():
    for bad in ("       nan", "       inf", "   1.0e+99"):
        lines = _channel(1, "Up", VALUES)
        lines[28] = bad + lines[28][10:]
        with pytest.raises(RecordError):
            read_dmg(_file(lines))


def test_not_dmg():
    with pytest.raises(RecordError, match="not a CSMIP/DMG file"):
        read_dmg(io.BytesIO(b"PEER NGA STRONG MOTION DATABASE RECORD\n1 2 3\n"))
