"""Tests of the record-format readers (shipblock.io) and their obspy plug-in registration.

Reference values: the synthetic files in tests/data and the COSMOS/ESM texts built below hold
samples chosen by hand; expected values are those samples times the exact unit factors
(g = 9.80665 m/s^2 by definition, 1 gal = 1 cm/s^2 = 0.01 m/s^2, 1 in = 0.0254 m).
"""

from __future__ import annotations

import io
import math
from pathlib import Path

import numpy as np
import obspy
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from shipblock.errors import RecordError, ShipblockError, UnitsError
from shipblock.io import FORMATS, read_record
from shipblock.io.at2 import is_at2, read_at2
from shipblock.io.cosmos import is_cosmos, read_cosmos
from shipblock.io.esm import is_esm, read_esm
from shipblock.io.text import is_text, read_text_record

DATA = Path(__file__).parent / "data"
G = 9.80665  # standard gravity [m/s^2], CGPM 1901 (exact by definition)


# ---------------------------------------------------------------------------- PEER AT2


def test_at2_values_in_si_and_header():
    st_ = read_at2(DATA / "helena_synthetic_180.AT2")
    tr = st_[0]
    expected = np.array([0.1, -0.2, 0.05, 0.0, -0.01, 0.02, 0.003]) * G
    np.testing.assert_allclose(tr.data, expected, rtol=1e-12)
    assert tr.stats.delta == pytest.approx(0.01)
    assert tr.stats.units == "m/s**2"
    assert tr.stats.original_units == "g"
    assert tr.stats.azimuth == 180.0 and tr.stats.dip == 0.0
    assert tr.id == ".CARROLL-COLLEGE..HN1"  # 180 deg: nearer north-south, not north
    assert tr.stats.shipblock_at2.station_name == "Carroll College"
    assert tr.stats.file_component == "180"
    assert tr.stats.shipblock_at2.event == "Helena Montana-01"


def test_at2_registered_with_obspy_read():
    st_ = obspy.read(str(DATA / "helena_synthetic_180.AT2"))
    assert st_[0].stats._format == "SHIPBLOCK_AT2"
    assert st_[0].data[0] == pytest.approx(0.1 * G)


def test_at2_old_layout_and_down_component():
    tr = read_at2(DATA / "helena_synthetic_dwn.AT2")[0]
    assert tr.stats.npts == 7 and tr.stats.dip == 90.0
    assert tr.data[-1] == pytest.approx(0.7 * G)


def test_at2_file_object_and_detection():
    raw = (DATA / "helena_synthetic_180.AT2").read_bytes()
    assert is_at2(io.BytesIO(raw))
    assert not is_at2(DATA / "two_column_gal.csv")
    assert read_at2(io.BytesIO(raw))[0].stats.npts == 7


def test_at2_truncated(tmp_path):
    lines = (DATA / "helena_synthetic_180.AT2").read_text().splitlines()
    bad = tmp_path / "cut.AT2"
    bad.write_text("\n".join(lines[:-1]) + "\n")
    with pytest.raises(RecordError, match=r"cut\.AT2.*truncated.*NPTS=7 but 5"):
        read_at2(bad)


def test_at2_corrupt_sample(tmp_path):
    text = (DATA / "helena_synthetic_180.AT2").read_text().replace("-.2000000E+00", " abc?garbage")
    bad = tmp_path / "bad.AT2"
    bad.write_text(text)
    with pytest.raises(RecordError, match="bad.AT2"):
        read_at2(bad)


def test_at2_nan_refused(tmp_path):
    text = (DATA / "helena_synthetic_180.AT2").read_text().replace(".5000000E-01", "NaN")
    bad = tmp_path / "nan.AT2"
    bad.write_text(text)
    with pytest.raises(RecordError, match="nan.AT2"):
        read_at2(bad)


def test_at2_velocity_refused(tmp_path):
    text = (DATA / "helena_synthetic_180.AT2").read_text().replace(
        "ACCELERATION TIME SERIES IN UNITS OF G", "VELOCITY TIME SERIES IN UNITS OF CM/S"
    )
    bad = tmp_path / "v.VT2"
    bad.write_text(text)
    with pytest.raises(UnitsError, match="v.VT2.*not an acceleration"):
        read_at2(bad)


# ---------------------------------------------------------------------------- COSMOS


def _cosmos_block(samples, unit_code=4, unit_text="cm/sec2", orientation=360, channel=1,
                  int_units_code=None, delta_ms=10.0, stage=2, with_velocity=True):
    """Build one COSMOS v1.20 channel block (layout of the 2001 specification)."""
    ints = [-999] * 100
    ints[0] = stage  # Int(1) processing stage
    ints[1] = 1  # Int(2) acceleration
    ints[2] = unit_code if int_units_code is None else int_units_code  # Int(3) unit code
    ints[39], ints[41], ints[42], ints[43], ints[44] = 2014, 8, 24, 10, 20  # start date/time
    ints[53] = orientation  # Int(54)
    reals = [-999.0] * 100
    reals[0], reals[1], reals[2] = 38.33, -122.3185, 20.0  # Real(1-3) lat, lon, elev
    reals[29] = 37.5  # Real(30) start second
    reals[61] = delta_ms  # Real(62) sampling interval [ms]
    reals[62] = len(samples) * delta_ms / 1000.0  # Real(63) length [s]
    text = [
        "Corrected accelerogram    (Format v01.20 with 13 text lines) synthetic test file",
        "Record of                 Earthquake of Sun Aug 24, 2014 03:20 PDT",
        "Hypocenter: 38.215  -122.312  H= 11km (NCSN)   Mw=6.0",
        "Origin: 08/24/2014, 10:20:44.0 UTC (NCSN)",
        "Statn No: 05- 68150  Code:CE-68150  Napa - synthetic",
        "Coords: 38.3300  -122.3185   Site geology: unknown",
        "Recorder: Etna   s/n 0000 (  3 Chns of  3 at Sta) Sensor: FBA       s/n 0000",
        "Rcrd start time: 8/24/2014, 10:20:37.500 UTC (Q=5) RcrdId: synthetic",
        f"Sta Chan   {channel}: {orientation} deg (Rcrdr Chan  {channel}) Location: free field",
        "Raw record length =  0.050 sec, Uncor max = 1 counts, at 0.0 sec.",
        "Processed: 08/26/14 12:00 PDT",
        "Record filtered below 0.10 Hz (periods over 10.0 secs), and above 50.0 Hz",
        "Values used when parameter or data value is unknown/unspecified:   -999, -999.0",
    ]
    out = list(text)
    out.append(" 100 Integer-header values follow on  10 lines, Format= (10I8)")
    out += ["".join(f"{v:8d}" for v in ints[k:k + 10]) for k in range(0, 100, 10)]
    out.append(" 100 Real-header values follow on  17 lines, Format= (6E13.5)")
    out += ["".join(f"{v:13.5E}" for v in reals[k:k + 6]) for k in range(0, 100, 6)]
    out.append('   1 Comment line(s) follow, each starting with a "|":')
    out.append("| synthetic record for shipblock tests")

    def section(kind, values, utext, code):
        lines = [f"{len(values):8d} {kind} pts, approx    0 secs, units={utext} ({code:02d}),"
                 "Format=(8F10.5)"]
        lines += ["".join(f"{v:10.5f}" for v in values[k:k + 8]) for k in range(0, len(values), 8)]
        return lines

    out += section("acceleration", samples, unit_text, unit_code)
    if with_velocity:
        out += section("velocity", [99.0] * len(samples), "cm/sec", 5)
        out += section("displacement", [99.0] * len(samples), "cm", 6)
    out.append(f"End-of-data for Chan  {channel} acceleration")
    return "\n".join(out) + "\n"


H1_CM = [1.0, -2.0, 3.5, 0.25, -0.5, 4.0, 0.0, 1.5, -1.0, 2.0]
H2_CM = [0.5, 0.5, -1.0, 2.0, 3.0, -3.0, 1.0, 0.0, 0.0, 0.125]
UP_CM = [0.1, 0.2, 0.3, -0.4, 0.5, -0.6, 0.7, 0.8, -0.9, 1.0]


@pytest.fixture
def cosmos_file(tmp_path):
    path = tmp_path / "CE68150.V2"
    path.write_text(
        _cosmos_block(H1_CM, orientation=360, channel=1)
        + _cosmos_block(UP_CM, orientation=400, channel=2)
        + _cosmos_block(H2_CM, orientation=90, channel=3)
    )
    return path


def test_cosmos_v2_three_channels(cosmos_file):
    assert is_cosmos(cosmos_file)
    st_ = obspy.read(str(cosmos_file))  # through the registered plug-in
    assert len(st_) == 3 and st_[0].stats._format == "SHIPBLOCK_COSMOS"
    h1, up, h2 = st_
    np.testing.assert_allclose(h1.data, np.array(H1_CM) * 0.01, rtol=1e-12)
    np.testing.assert_allclose(h2.data, np.array(H2_CM) * 0.01, rtol=1e-12)
    np.testing.assert_allclose(up.data, np.array(UP_CM) * 0.01, rtol=1e-12)
    assert (h1.stats.azimuth, h2.stats.azimuth, up.stats.dip) == (0.0, 90.0, -90.0)
    assert h1.stats.network == "CE" and h1.stats.station == "68150"
    assert h1.stats.delta == pytest.approx(0.01)
    assert h1.stats.starttime == obspy.UTCDateTime(2014, 8, 24, 10, 20, 37.5)
    assert h1.stats.shipblock_cosmos.unit_code == 4
    assert h1.stats.coordinates.latitude == pytest.approx(38.33)


@pytest.mark.parametrize(
    ("code", "text", "factor"),
    [(2, "g", G), (10, "gal", 0.01), (7, "in/sec2", 0.0254), (11, "mg", G / 1000)],
)
def test_cosmos_unit_codes_honoured(tmp_path, code, text, factor):
    path = tmp_path / "unit.V1"
    path.write_text(_cosmos_block(H1_CM, unit_code=code, unit_text=text, stage=1,
                                  with_velocity=False))
    tr = read_cosmos(path)[0]
    np.testing.assert_allclose(tr.data, np.array(H1_CM) * factor, rtol=1e-12)


def test_cosmos_counts_kept_as_counts(tmp_path):
    path = tmp_path / "raw.V0"
    path.write_text(_cosmos_block([1.0, 2.0], unit_code=50, unit_text="counts", stage=0,
                                  with_velocity=False))
    assert read_cosmos(path)[0].stats.units == "counts"


def test_cosmos_unit_code_conflict(tmp_path):
    path = tmp_path / "conflict.V2"
    path.write_text(_cosmos_block(H1_CM, unit_code=4, int_units_code=2))
    with pytest.raises(UnitsError, match="conflict.V2.*unit code 04.*Int\\(3\\) says 02"):
        read_cosmos(path)


def test_cosmos_truncated(tmp_path, cosmos_file):
    text = cosmos_file.read_text()
    for fraction in (0.1, 0.2, 0.5, 0.9):
        cut = tmp_path / "cut.V2"
        cut.write_text(text[: int(len(text) * fraction)])
        with pytest.raises(RecordError, match="cut.V2"):
            read_cosmos(cut)


# ---------------------------------------------------------------------------- ESM


def _esm_text(samples, units="cm/s^2", stream="HGE", ndata=None):
    header = {
        "EVENT_NAME": "CENTRAL_ITALY", "EVENT_ID": "EMSC-20161030_0000029",
        "EVENT_DATE_YYYYMMDD": "20161030", "EVENT_TIME_HHMMSS": "064017",
        "NETWORK": "IT", "STATION_CODE": "NRC", "STATION_NAME": "NORCIA",
        "STATION_LATITUDE_DEGREE": "42.792", "STATION_LONGITUDE_DEGREE": "13.096",
        "STATION_ELEVATION_M": "624", "LOCATION": "", "STREAM": stream,
        "DATE_TIME_FIRST_SAMPLE_YYYYMMDD_HHMMSS": "20161030_064010.000",
        "SAMPLING_INTERVAL_S": "0.005000", "NDATA": str(len(samples) if ndata is None else ndata),
        "DATA_TYPE": "ACCELERATION", "UNITS": units, "USER5": "",
    }
    lines = [f"{k}: {v}" for k, v in header.items()]
    return "\n".join(lines + [f"{v:.6E}" for v in samples]) + "\n"


def test_esm_values_and_codes(tmp_path):
    path = tmp_path / "IT.NRC..HGE.D.20161030.064017.C.ACC.ASC"
    path.write_text(_esm_text([10.0, -20.0, 5.5]))
    assert is_esm(path)
    tr = obspy.read(str(path))[0]
    assert tr.stats._format == "SHIPBLOCK_ESM"
    np.testing.assert_allclose(tr.data, [0.1, -0.2, 0.055], rtol=1e-12)
    assert (tr.stats.network, tr.stats.station, tr.stats.channel) == ("IT", "NRC", "HGE")
    assert tr.stats.starttime == obspy.UTCDateTime(2016, 10, 30, 6, 40, 10)


def test_esm_missing_units_and_truncation(tmp_path):
    path = tmp_path / "nounits.ASC"
    path.write_text(_esm_text([1.0, 2.0], units=""))
    with pytest.raises(UnitsError, match="nounits.ASC.*UNITS"):
        read_esm(path)
    path = tmp_path / "short.ASC"
    path.write_text(_esm_text([1.0, 2.0], ndata=5))
    with pytest.raises(RecordError, match="short.ASC.*truncated"):
        read_esm(path)


# ---------------------------------------------------------------------------- plain text


def test_text_two_columns_header_units():
    assert is_text(DATA / "two_column_gal.csv")
    tr = read_text_record(DATA / "two_column_gal.csv")[0]
    np.testing.assert_allclose(tr.data, [0.01, -0.02, 0.03, -0.04, 0.005], rtol=1e-12)
    assert tr.stats.delta == pytest.approx(0.005)
    assert tr.stats.original_units == "gal"


def test_text_units_conflict_and_missing(tmp_path):
    with pytest.raises(UnitsError, match="two_column_gal.csv.*contradicts"):
        read_text_record(DATA / "two_column_gal.csv", units="g")
    plain = tmp_path / "plain.txt"
    plain.write_text("0.1\n0.2\n-0.3\n")
    assert not is_text(plain)  # no stated units: never auto-detected
    with pytest.raises(UnitsError, match="plain.txt.*units unknown"):
        read_text_record(plain, dt=0.01)
    with pytest.raises(RecordError, match="plain.txt.*sampling interval is unknown"):
        read_text_record(plain, units="g")
    tr = obspy.read(str(plain), format="SHIPBLOCK_TEXT", units="g", dt=0.02)[0]
    np.testing.assert_allclose(tr.data, np.array([0.1, 0.2, -0.3]) * G, rtol=1e-12)


def test_text_bad_layouts(tmp_path):
    cases = {
        "three.csv": "0,1,2\n0.01,1,2\n",
        "nonuniform.csv": "0,1\n0.01,2\n0.05,3\n",
        "ragged.csv": "0,1\n0.01\n",
        "empty.csv": "# nothing\n",
        "letters.csv": "0,1\n0.01,x\n",
    }
    for name, content in cases.items():
        path = tmp_path / name
        path.write_text(content)
        with pytest.raises(RecordError, match=name):
            read_text_record(path, units="g", dt=0.01)


def test_read_record_unknown_format_and_missing_file(tmp_path):
    junk = tmp_path / "junk.bin"
    junk.write_bytes(bytes(range(256)) * 8)
    with pytest.raises(RecordError, match="junk.bin"):
        read_record(junk)
    prose = tmp_path / "notes.txt"
    prose.write_text("This is not a seismogram.\nJust words.\n")
    with pytest.raises(RecordError, match="notes.txt.*unknown format"):
        read_record(prose)
    with pytest.raises(RecordError, match="nope.mseed.*no such file"):
        read_record(tmp_path / "nope.mseed")


def test_formats_registry_lists_the_plugins():
    from obspy.core.util.base import ENTRY_POINTS

    for name in FORMATS:
        assert name in ENTRY_POINTS["waveform"], f"{name} not registered; pip install -e ."


# ---------------------------------------------------------------------------- fuzzing

_text_lines = st.lists(
    st.one_of(
        st.text(alphabet="0123456789.-+eE,; \t#()gsalmc/^*NaIf", max_size=40),
        st.sampled_from(["NPTS= 3, DT= .01 SEC", "PEER NGA", "UNITS OF G", "nan", "inf", "1e999",
                         "(Format v01.20 with 13 text lines)", "EVENT_NAME: x", "EVENT_ID: y",
                         " 100 Integer-header values follow on  10 lines, Format= (10I8)"]),
    ),
    max_size=30,
)


@settings(max_examples=150, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(lines=_text_lines, prefix=st.sampled_from(["", "PEER NGA STRONG MOTION DATABASE RECORD\n",
                                                  "EVENT_NAME: a\nEVENT_ID: b\n"]))
def test_fuzz_text_readers_raise_only_project_errors(lines, prefix):
    raw = (prefix + "\n".join(lines)).encode()
    for detect, reader in FORMATS.values():
        assert detect(io.BytesIO(raw)) in (True, False)
        for kwargs in ({}, {"units": "g", "dt": 0.01}):
            try:
                stream = reader(io.BytesIO(raw), **kwargs)
            except ShipblockError:
                continue
            for tr in stream:
                assert np.all(np.isfinite(tr.data))
                assert tr.stats.delta > 0 and math.isfinite(tr.stats.delta)
