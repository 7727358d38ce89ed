"""ESM reader against the real files of the gmprocess test corpus (``testdata/esm/us60004wsq/``).

Reference values: gmprocess 2.8.0's reading of each file (``tests/data/reference/
gmprocess_2.8_peaks.csv``: npts, dt, start time and peak per trace in cm/s^2), and each file's
own header: ``PGA_CM/S^2`` (signed, printed to 6 decimals like the samples) and ``TIME_PGA_S``
(printed to 1e-6 s, relative to the first sample), ``NDATA``, ``SAMPLING_INTERVAL_S``,
``DATE_TIME_FIRST_SAMPLE_YYYYMMDD_HHMMSS`` (milliseconds) and the SEED codes.
"""

from __future__ import annotations

import warnings

import numpy as np
import obspy
import pytest

from shipblock.errors import RecordError, UnitsError
from shipblock.io.esm import UNITS_FROM_HEADER, UNITS_FROM_PGA, is_esm, read_esm
from tests.reader_fuzz import assert_reader_survives
from tests.real_corpus import REFERENCE, assert_peaks_match_gmprocess, corpus_file, reference_files

CM = 0.01  # 1 cm/s^2 = 0.01 m/s^2 (exact)
FILES = reference_files("esm")
OTHER_FORMATS = ["cosmos", "dmg", "knet", "kiknet", "geonet", "cwb", "nsmn", "bhrc", "unam",
                 "renadic", "usc", "smc", "peer", "csn"]


def test_corpus_has_six_files_all_read_by_gmprocess():
    assert len(FILES) == 6
    assert all(row["trace_id"] != "ERROR" for f in FILES for row in REFERENCE[f])


@pytest.mark.parametrize("relpath", FILES)
def test_read_as_gmprocess(relpath):
    (tr,) = read_esm(corpus_file(relpath))
    assert_peaks_match_gmprocess(obspy.Stream([tr]), relpath)
    (row,) = REFERENCE[relpath]
    assert tr.stats.npts == int(row["npts"])
    assert tr.stats.delta == pytest.approx(float(row["delta_s"]), rel=1e-12)
    assert tr.stats.starttime == obspy.UTCDateTime(row["starttime"])
    # gmprocess writes the empty location as "--".
    net, sta, loc, cha = row["trace_id"].split(".")
    assert (tr.stats.network, tr.stats.station, tr.stats.channel) == (net, sta, cha)
    assert loc == "--" and tr.stats.location == ""
    # Same samples, same unit: peaks agree to gmprocess's printed 6 decimals (cm/s^2).
    assert abs(np.max(np.abs(tr.data)) / CM - float(row["peak_abs"])) <= 0.5e-6


@pytest.mark.parametrize("relpath", FILES)
def test_header_values_checked_against_samples(relpath):
    path = corpus_file(relpath)
    (tr,) = read_esm(path)
    esm = tr.stats.shipblock_esm
    # Keys that hold "/" and "^" are parsed (the first reader stopped at VS30_M/S).
    assert {"VS30_M/S", "INSTRUMENT_ANALOG/DIGITAL", "PGA_CM/S^2", "UNITS", "USER5"} <= set(esm)
    assert esm["UNITS"] == "cm/s^2" and tr.stats.original_units == "cm/s^2"
    assert tr.stats.units == "m/s**2" and tr.stats.units_source == UNITS_FROM_HEADER
    assert esm["DATA_TYPE"] == "ACCELERATION" and esm["PROCESSING"].startswith("manual")
    assert tr.stats.npts == int(esm["NDATA"])
    # The first sample is the first line after the 64 header lines.
    first = float(path.read_text().splitlines()[64])
    assert tr.data[0] == pytest.approx(first * CM, abs=1e-15)
    i = int(np.argmax(np.abs(tr.data)))
    pga = float(esm["PGA_CM/S^2"])
    # PGA_CM/S^2 and the samples are both printed to 1e-6 cm/s^2; PGA is signed.
    assert abs(tr.data[i] / CM - pga) <= 1e-6
    assert tr.stats.stated_peak_si == pytest.approx(abs(pga) * CM, rel=1e-12)
    # TIME_PGA_S is the peak's time after the first sample (printed to 1e-6 s).
    assert abs(i * tr.stats.delta - float(esm["TIME_PGA_S"])) <= 1e-6
    # DURATION_S (printed to 1 ms) is NDATA * dt.
    assert abs(tr.stats.npts * tr.stats.delta - float(esm["DURATION_S"])) <= 0.5e-3
    assert tr.stats.starttime == obspy.UTCDateTime.strptime(
        esm["DATE_TIME_FIRST_SAMPLE_YYYYMMDD_HHMMSS"], "%Y%m%d_%H%M%S.%f")
    assert tr.stats.coordinates.latitude == pytest.approx(
        float(esm["STATION_LATITUDE_DEGREE"]), abs=5e-7)
    assert esm["notes"] == []


def _replace_line(path, tmp_path, key, new_line):
    """A copy of a real file with the header line of ``key`` replaced (``None``: removed)."""
    lines = path.read_text().splitlines(keepends=True)
    (index,) = [k for k, line in enumerate(lines[:64]) if line.startswith(f"{key}:")]
    lines[index:index + 1] = [] if new_line is None else [new_line + "\n"]
    out = tmp_path / path.name
    out.write_text("".join(lines))
    return out


def test_units_honoured_and_unknown_refused(tmp_path):
    path = corpus_file(FILES[0])
    (ref,) = read_esm(path)
    # Honoured, not assumed; the PGA_CM/S^2 check then flags the edited unit.
    with pytest.warns(UserWarning, match="PGA_CM/S\\^2=0.300022 disagrees"):
        (tr,) = read_esm(_replace_line(path, tmp_path, "UNITS", "UNITS: m/s^2"))
    np.testing.assert_allclose(tr.data, ref.data / CM, rtol=1e-12)
    assert any("disagrees" in note for note in tr.stats.shipblock_esm.notes)
    with pytest.raises(UnitsError, match="ACC.ASC: unknown acceleration unit 'furlong/s\\^2'"):
        read_esm(_replace_line(path, tmp_path, "UNITS", "UNITS: furlong/s^2"))


def test_missing_units_proved_by_pga_or_refused(tmp_path):
    path = corpus_file(FILES[3])
    (ref,) = read_esm(path)
    no_units = _replace_line(path, tmp_path, "UNITS", None)
    (tr,) = read_esm(no_units)
    np.testing.assert_array_equal(tr.data, ref.data)
    assert tr.stats.original_units == "cm/s^2" and tr.stats.units_source == UNITS_FROM_PGA
    assert tr.stats.shipblock_esm.notes == [UNITS_FROM_PGA]
    (head,) = read_esm(no_units, headonly=True)
    assert head.stats.units_source == UNITS_FROM_PGA and len(head.data) == 0
    # Without UNITS, a PGA that the samples do not match (here 100 times too small: the samples
    # would be in m/s^2 if anything) leaves the unit unknown.
    lines = no_units.read_text().splitlines(keepends=True)
    (k,) = [k for k, line in enumerate(lines) if line.startswith("PGA_CM/S^2:")]
    lines[k] = "PGA_CM/S^2: -0.00227973\n"
    no_units.write_text("".join(lines))
    with pytest.raises(UnitsError, match="UNITS is missing.*not in cm/s\\^2"):
        read_esm(no_units)
    lines.pop(k)
    no_units.write_text("".join(lines))
    with pytest.raises(UnitsError, match="UNITS is missing.*no PGA_CM/S\\^2"):
        read_esm(no_units)


def test_not_acceleration_refused(tmp_path):
    path = corpus_file(FILES[0])
    for data_type in ("VELOCITY", "ACCELERATION RESPONSE SPECTRUM"):
        with pytest.raises(UnitsError, match=f"DATA_TYPE is '{data_type}'"):
            read_esm(_replace_line(path, tmp_path, "DATA_TYPE", f"DATA_TYPE: {data_type}"))


def test_truncated_and_padded_refused(tmp_path):
    raw = corpus_file(FILES[0]).read_bytes()
    lines = raw.splitlines(keepends=True)
    path = tmp_path / "cut.ASC"
    path.write_bytes(b"".join(lines[:-1]))
    with pytest.raises(RecordError, match="cut.ASC: is truncated: NDATA=19128 but 19127"):
        read_esm(path)
    path.write_bytes(raw + lines[-1])
    with pytest.raises(RecordError, match="cut.ASC: is longer than its header says"):
        read_esm(path)


def test_detection():
    for relpath in FILES:
        assert is_esm(corpus_file(relpath)), relpath
    for folder in OTHER_FORMATS:
        for relpath in reference_files(folder)[:2]:
            assert not is_esm(corpus_file(relpath)), relpath


def test_fuzz_real_file():
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        assert_reader_survives(read_esm, corpus_file(FILES[3]).read_bytes())
