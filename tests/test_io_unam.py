"""Tests of the Mexican ASA (UNAM) reader on the real files of the gmprocess corpus."""

from __future__ import annotations

import io
import re

import numpy as np
import pytest
from obspy import UTCDateTime

from shipblock.errors import RecordError, UnitsError
from shipblock.io.unam import is_unam, read_unam
from tests.reader_fuzz import assert_reader_survives
from tests.real_corpus import (
    REFERENCE,
    assert_peaks_match_gmprocess,
    corpus_file,
    gmprocess_read,
    reference_files,
)

UNAM_FILES = reference_files("unam")

#: The 2004 file: two padding rows, stated peak sample numbers counted from 0.
CUP5 = "unam/usp000cgtd/CUP50401.012"

#: Other folders of the corpus whose files must not be taken for ASA files.
OTHER_FOLDERS = ("knet", "kiknet", "dmg", "cosmos", "esm", "geonet", "geonet2", "cwb", "nsmn",
                 "bhrc", "usc", "smc", "peer", "renadic", "csn", "station_xml_epochs")


def _raw(relpath: str) -> bytes:
    return corpus_file(relpath).read_bytes()


def _replace_value(raw: bytes, key: bytes, value: bytes) -> bytes:
    """Replace the value of header key ``key`` (``KEY   : value``) in a file's bytes."""
    pattern = re.compile(re.escape(key) + rb"(\s*:)[^\r\n]*")
    new, count = pattern.subn(lambda m: key + m.group(1) + b" " + value, raw, count=1)
    assert count == 1, key
    return new


def test_the_corpus_has_the_unam_files():
    assert len(UNAM_FILES) == 4
    assert all(gmprocess_read(f) for f in UNAM_FILES)


@pytest.mark.parametrize("relpath", UNAM_FILES)
def test_reads_like_gmprocess(relpath):
    stream = read_unam(corpus_file(relpath))
    assert_peaks_match_gmprocess(stream, relpath, rel=1e-6)
    rows = REFERENCE[relpath]
    assert len(stream) == len(rows) == 3
    for trace in stream:
        assert trace.stats.units == "m/s**2"
        assert trace.stats.original_units == "Gal (cm/s/s)"
        assert trace.data.dtype == np.float64
    for row in rows:
        matches = [tr for tr in stream if tr.stats.station == row["trace_id"].split(".")[1]]
        assert all(tr.stats.npts == int(row["npts"]) for tr in matches)
        assert all(tr.stats.delta == pytest.approx(float(row["delta_s"]), rel=1e-12)
                   for tr in matches)
        assert all(tr.stats.starttime == UTCDateTime(row["starttime"]) for tr in matches)


def test_orientations_and_header_values_of_acac():
    stream = read_unam(corpus_file("unam/us2000ar20/ACAC1709.191"))
    # ORIENTACION C1-C6: /V/N00E/N90E
    assert [tr.stats.channel for tr in stream] == ["HNZ", "HNN", "HNE"]
    assert stream[0].stats.dip == -90.0
    assert [tr.stats.azimuth for tr in stream[1:]] == [0.0, 90.0]
    assert stream[0].stats.station == "ACAC"
    coords = stream[0].stats.coordinates
    assert (coords.latitude, coords.longitude, coords.elevation) == (16.84851, -99.85157, 13.0)
    assert stream[0].stats.starttime == UTCDateTime(2017, 9, 19, 18, 14, 18)
    # DURACION DEL REGISTRO 178.00 s = 35600 samples at 0.005 s
    assert all(tr.stats.npts * tr.stats.delta == pytest.approx(178.0) for tr in stream)


def test_cup5_column_order_differs():
    # ORIENTACION C1-C6: /V/N90E/N00E
    stream = read_unam(corpus_file(CUP5))
    assert [tr.stats.channel for tr in stream] == ["HNZ", "HNE", "HNN"]


@pytest.mark.parametrize("relpath", UNAM_FILES)
def test_stated_peaks_and_their_sample_numbers(relpath):
    """ACEL. MAX. (signed, printed with 2 or 4 decimals) and EN LA MUESTRA, checked per channel."""
    stream = read_unam(corpus_file(relpath))
    header = stream[0].stats.shipblock_unam
    peaks = header["acel. max.(gal), c1-c6"].strip("/").split("/")
    samples = header["acel. max., c1-c6, en la muestra"].strip("/").split("/")
    # The 2017 files count samples from 1, the 2004 file from 0.
    first_sample_number = 0 if relpath == CUP5 else 1
    for trace, peak, sample in zip(stream, peaks, samples, strict=True):
        decimals = len(peak.split(".")[1])
        tolerance = 0.5 * 10.0 ** -decimals * 0.01 + 1e-12
        assert trace.stats.stated_peak_si == pytest.approx(abs(float(peak)) * 0.01)
        assert abs(np.max(np.abs(trace.data)) - trace.stats.stated_peak_si) <= tolerance
        value = trace.data[int(sample) - first_sample_number]
        assert abs(value - float(peak) * 0.01) <= tolerance  # the sign too


def test_cup5_padding_rows_are_dropped_and_start_is_next_day():
    stream = read_unam(corpus_file(CUP5))
    assert all(tr.stats.npts == 17500 for tr in stream)
    assert stream[0].stats.shipblock_unam.padding_rows == 2
    # Earthquake 2004/01/01 23:58:02.7, first sample 00:00:01: the next day.
    assert stream[0].stats.starttime == UTCDateTime(2004, 1, 2, 0, 0, 1)
    # The last stated sample is the one the padding repeats.
    assert stream[0].data[-1] == pytest.approx(0.036 * 0.01)


def test_padding_that_does_not_repeat_the_last_sample_is_refused():
    raw = _raw(CUP5)
    lines = raw.split(b"\r\n")
    last = max(i for i, line in enumerate(lines) if line.strip())
    lines[last] = b"     0.036     0.098    -0.058"
    with pytest.raises(RecordError, match="longer than its header says"):
        read_unam(io.BytesIO(b"\r\n".join(lines)))


def test_truncated_file_is_refused():
    raw = _raw(CUP5)
    cut = raw[: int(len(raw) * 0.7)]
    cut = cut[: cut.rfind(b"\n") + 1]
    with pytest.raises(RecordError, match="truncated: 17500 samples stated"):
        read_unam(io.BytesIO(cut))


def test_start_before_midnight_of_an_early_morning_earthquake():
    raw = _raw(CUP5)
    raw = _replace_value(raw, b"FECHA DEL SISMO [GMT]", b"2004/01/02")
    raw = _replace_value(raw, b"HORA EPICENTRO (GMT)", b"00:00:05")
    raw = _replace_value(raw, b"HORA DE LA PRIMERA MUESTRA (GMT)", b"23:59:50.5")
    stream = read_unam(io.BytesIO(raw))
    assert stream[0].stats.starttime == UTCDateTime(2004, 1, 1, 23, 59, 50.5)


def test_quadrant_bearings_become_azimuths():
    raw = _replace_value(_raw(CUP5), b"ORIENTACION C1-C6 (rumbo;orientacion)",
                         b"/V/N10W/S80W")
    stream = read_unam(io.BytesIO(raw))
    assert [tr.stats.azimuth for tr in stream[1:]] == [350.0, 260.0]
    assert [tr.stats.channel for tr in stream] == ["HNZ", "HN1", "HN2"]


def test_touching_fixed_width_fields_are_split():
    raw = _raw(CUP5)
    lines = raw.split(b"\r\n")
    first = lines.index(b"    -0.084    -0.052     0.108")
    lines[first] = b"-1234.5678-1234.5678 1234.5678"
    stream = read_unam(io.BytesIO(b"\r\n".join(lines)))
    assert [tr.data[0] for tr in stream] == pytest.approx([-12.345678, -12.345678, 12.345678])


def test_velocity_units_are_refused():
    raw = _replace_value(_raw(CUP5), b"UNIDADES DE LOS DATOS", b"cm/s")
    with pytest.raises(UnitsError, match="cm/s"):
        read_unam(io.BytesIO(raw))


@pytest.mark.parametrize("value", [b"/0/0.004/0.004", b"/-0.004/0.004/0.004", b"/x/0.004/0.004"])
def test_bad_sampling_interval_is_refused(value):
    raw = _replace_value(_raw(CUP5), b"INTERVALO DE MUESTREO, C1-C6 (s)", value)
    with pytest.raises(RecordError):
        read_unam(io.BytesIO(raw))


def test_interval_and_rate_must_agree():
    raw = _replace_value(_raw(CUP5), b"VEL. DE MUESTREO, C1-C6 (muestras/s)", b"/200/250/250")
    with pytest.raises(RecordError, match="disagree"):
        read_unam(io.BytesIO(raw))


def test_headonly_reads_counts_without_samples():
    stream = read_unam(corpus_file(CUP5), headonly=True)
    assert [tr.stats.npts for tr in stream] == [17500] * 3
    assert all(tr.data.size == 0 for tr in stream)


def test_detection_accepts_every_unam_file():
    assert all(is_unam(corpus_file(f)) for f in UNAM_FILES)
    with open(corpus_file(CUP5), "rb") as fh:
        assert is_unam(fh)
        assert fh.tell() == 0


@pytest.mark.parametrize("folder", OTHER_FOLDERS)
def test_detection_rejects_other_formats(folder):
    files = reference_files(folder)
    assert files
    assert not any(is_unam(corpus_file(f)) for f in files)


def test_detection_rejects_numbers_and_garbage(tmp_path):
    numbers = tmp_path / "numbers.txt"
    numbers.write_text("\n".join(f"{i * 0.01:.3f} {np.sin(i):.5f}" for i in range(500)))
    empty = tmp_path / "empty.txt"
    empty.write_bytes(b"")
    binary = tmp_path / "binary.bin"
    binary.write_bytes(bytes(range(256)) * 10)
    assert not is_unam(numbers)
    assert not is_unam(empty)
    assert not is_unam(binary)
    assert not is_unam(tmp_path / "missing.191")
    with pytest.raises(RecordError, match="not an ASA file"):
        read_unam(numbers)


def test_fuzz_survives():
    read = assert_reader_survives(read_unam, _raw(CUP5))
    assert read >= 1
