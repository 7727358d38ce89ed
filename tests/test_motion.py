"""Tests of shipblock.records.motion: units, components, rotation, alignment and bad input.

Reference values: the South Napa 2014 PGA table of records/south-napa-2014/README.md (USGS NSMP
records, computed there with obspy 1.5.1: demean, remove_sensitivity, max |a|); K-NET header
"Max. Acc. (gal)" of obspy's test file; pySLAMMER's own CSV loader for its sample records;
exact unit factors (g = 9.80665 m/s^2, 1 gal = 0.01 m/s^2).
"""

from __future__ import annotations

import glob
import os
from pathlib import Path

import numpy as np
import obspy
import pytest
from obspy import Stream, Trace, UTCDateTime

from shipblock.errors import ParameterError, RecordError, UnitsError
from shipblock.records.motion import COMPONENT_KEY, GroundMotion, rotate_to_azimuth
from shipblock.records.reading import read_motion

DATA = Path(__file__).parent / "data"
NAPA = Path(__file__).parent.parent / "records" / "south-napa-2014"
G = 9.80665  # standard gravity [m/s^2] (exact by definition)
OBSPY_DIR = Path(obspy.__file__).parent


def _pga(gm):
    st_ = gm.stream.copy()
    st_.detrend("demean")
    return {tr.stats[COMPONENT_KEY]: float(np.abs(tr.data).max()) for tr in st_}


def _trace(data, channel, rate=100.0, start=0.0, station="SYN", network="XX"):
    tr = Trace(np.asarray(data, dtype=float))
    tr.stats.sampling_rate = rate
    tr.stats.starttime = UTCDateTime(start)
    tr.stats.channel = channel
    tr.stats.station = station
    tr.stats.network = network
    return tr


# ---------------------------------------------------------------------------- real records


def test_napa_1765_counts_to_si_with_inventory():
    """NP.1765 PGAs against the README table (H1 4.0537, H2 4.2012, V 3.1614 m/s^2)."""
    gm = read_motion(NAPA / "NP.1765.mseed", inventory=NAPA / "NP.1765.xml",
                     event=NAPA / "event.xml")
    pga = _pga(gm)
    assert pga["H1"] == pytest.approx(4.0537, rel=5e-3)
    assert pga["H2"] == pytest.approx(4.2012, rel=5e-3)
    assert pga["V"] == pytest.approx(3.1614, rel=5e-3)
    assert gm.metadata["channels"] == {"H1": "NP.1765..HNN", "H2": "NP.1765..HNE",
                                       "V": "NP.1765..HNZ"}
    assert gm.metadata["azimuths"] == {"H1": 0.0, "H2": 90.0}
    assert gm.metadata["event"]["magnitude"] == pytest.approx(6.02)
    assert gm.dt == pytest.approx(0.005) and gm.npts == 42000
    assert gm.time[-1] == pytest.approx(41999 * 0.005)
    assert all(tr.stats.units == "m/s**2" for tr in gm.stream)


def test_napa_full_response_within_readme_tolerance():
    """README: remove_response(output='ACC') gives NP.1765 PGAs 4.052/4.207/3.176 m/s^2."""
    gm = read_motion(NAPA / "NP.1765.mseed", inventory=NAPA / "NP.1765.xml", response="full")
    pga = _pga(gm)
    assert pga["H1"] == pytest.approx(4.052, rel=5e-3)
    assert pga["H2"] == pytest.approx(4.207, rel=5e-3)
    assert pga["V"] == pytest.approx(3.176, rel=5e-3)


def test_napa_rotation_to_dock_azimuth():
    gm = read_motion(NAPA / "NP.1759.mseed", inventory=NAPA / "NP.1759.xml", azimuth=90.0)
    np.testing.assert_allclose(gm.horizontal, gm.components["H2"], atol=1e-12)
    gm30 = read_motion(NAPA / "NP.1759.mseed", inventory=NAPA / "NP.1759.xml", azimuth=30.0)
    c = gm30.components
    expected = c["H1"] * np.cos(np.radians(30)) + c["H2"] * np.sin(np.radians(30))
    np.testing.assert_allclose(gm30.horizontal, expected, atol=1e-12)
    gm_h2 = read_motion(NAPA / "NP.1759.mseed", inventory=NAPA / "NP.1759.xml", horizontal="H2")
    np.testing.assert_array_equal(gm_h2.horizontal, c["H2"])
    np.testing.assert_array_equal(gm_h2.vertical, c["V"])


def test_raw_counts_without_units_is_an_error():
    with pytest.raises(UnitsError, match=r"NP\.1765\.mseed.*units of channel .* unknown"):
        read_motion(NAPA / "NP.1765.mseed")


def test_inventory_that_does_not_match():
    with pytest.raises(RecordError, match=r"NP\.1765\.mseed.*NP\.1743\.xml has no channel"):
        read_motion(NAPA / "NP.1765.mseed", inventory=NAPA / "NP.1743.xml")


def test_inventory_and_units_together_refused():
    with pytest.raises(UnitsError, match="give one of them"):
        read_motion(NAPA / "NP.1765.mseed", inventory=NAPA / "NP.1765.xml", units="g")


def test_knet_scale_factor_honoured():
    """obspy's K-NET test file: header Max. Acc. = 4.383 gal (of the demeaned record)."""
    path = OBSPY_DIR / "io" / "nied" / "tests" / "data" / "test.knet"
    if not path.is_file():
        pytest.skip("obspy test data not installed")
    gm = read_motion(path)
    assert set(gm.components) == {"H1"}  # the file holds the EW channel only: the one horizontal
    assert gm.metadata["azimuths"]["H1"] == 90.0
    assert _pga(gm)["H1"] == pytest.approx(4.383 * 0.01, rel=5e-3)


def test_kinemetrics_evt_calibration_honoured():
    """EVT calib = full scale [V] / 2**23 / sensitivity [V/g] * 9.81 (obspy's documented rule)."""
    path = OBSPY_DIR / "io" / "kinemetrics" / "tests" / "data" / "BI008_MEMA-04823.evt"
    if not path.is_file():
        pytest.skip("obspy test data not installed")
    raw = obspy.read(str(path))
    with pytest.raises(RecordError, match="cannot tell the component"):
        read_motion(path)
    gm = read_motion(path, channel_map={"0": "V", "1": "H1", "2": "H2"})
    header = raw[1].stats.kinemetrics_evt
    calib = header.chan_fullscale / 2**23 / header.chan_sensitivity * 9.81  # m/s^2 per count
    np.testing.assert_allclose(gm.components["H1"], raw[1].data * calib, rtol=1e-6)


def _pyslammer_files():
    try:
        import pyslammer
    except ImportError:
        return []
    folder = Path(pyslammer.__file__).parent / "sample_ground_motions"
    return sorted(glob.glob(str(folder / "*.csv")))[:4]


@pytest.mark.parametrize("path", _pyslammer_files() or [None])
def test_pyslammer_records_in_g(path):
    """pySLAMMER sample CSVs (time, accel in g): compare with pySLAMMER's own loader."""
    if path is None:
        pytest.skip("pyslammer not installed")
    from pyslammer.utilities import csv_time_hist

    reference = csv_time_hist(path)
    accel_g = np.asarray(reference[0] if np.ndim(reference[0]) == 1 and len(reference) == 2
                         else reference[0], dtype=float)
    gm = read_motion(path)  # header "Acceleration (g's)" states the unit
    assert gm.components["H1"].size in (accel_g.size, accel_g.size - 1, accel_g.size + 1)
    assert np.abs(gm.horizontal).max() == pytest.approx(np.abs(accel_g).max() * G, rel=1e-6)
    with pytest.raises(UnitsError, match="contradicts"):
        read_motion(path, units="cm/s^2")


# ---------------------------------------------------------------------------- files & components


def test_three_at2_like_files_with_azimuths():
    gm = read_motion([DATA / "helena_synthetic_270.AT2", DATA / "helena_synthetic_180.AT2",
                      DATA / "helena_synthetic_dwn.AT2"], azimuth=180.0)
    # 180 is H1 and 270 is H2 (270 = 180 + 90); projecting on 180 deg gives H1 itself.
    assert gm.metadata["azimuths"] == {"H1": 180.0, "H2": 270.0}
    h180 = np.array([0.1, -0.2, 0.05, 0, -0.01, 0.02, 0.003]) * G
    np.testing.assert_allclose(gm.horizontal, h180, atol=1e-12)
    # the DWN component is flipped to positive up
    np.testing.assert_allclose(gm.vertical, -np.arange(1, 8) * 0.1 * G, atol=1e-12)
    assert any("flipped" in p for p in gm.metadata["processing"])
    # projecting on north (0 deg) is minus the 180 component
    gm0 = read_motion([DATA / "helena_synthetic_180.AT2", DATA / "helena_synthetic_270.AT2"],
                      azimuth=0.0)
    np.testing.assert_allclose(gm0.horizontal, -gm.horizontal, atol=1e-12)


def test_rotate_to_azimuth_is_a_projection():
    h1, h2 = np.array([1.0, 0.0]), np.array([0.0, 1.0])
    np.testing.assert_allclose(rotate_to_azimuth(h1, h2, 0, 90, 45), [2**-0.5, 2**-0.5])
    np.testing.assert_allclose(rotate_to_azimuth(h1, h2, 0, 270, 90), [0.0, -1.0], atol=1e-15)
    with pytest.raises(ValueError, match="not orthogonal"):
        rotate_to_azimuth(h1, h2, 0, 45, 10)


def test_sac_down_vertical_flipped_and_stated_units(tmp_path):
    data = np.array([1.0, 2.0, -3.0])
    st_ = Stream([_trace(data, "HHN"), _trace(data * 2, "HHE"), _trace(data * 3, "HHZ")])
    for tr, (az, inc) in zip(st_, [(0, 90), (90, 90), (0, 180)], strict=True):
        path = tmp_path / f"{tr.stats.channel}.sac"
        tr.write(str(path), format="SAC")
        sac = obspy.read(str(path))[0]
        sac.stats.sac.cmpaz, sac.stats.sac.cmpinc = az, inc
        sac.write(str(path), format="SAC")
    files = sorted(tmp_path.glob("*.sac"))
    with pytest.raises(UnitsError, match="unknown"):
        read_motion(files)
    gm = read_motion(files, units="cm/s^2")
    np.testing.assert_allclose(gm.components["H1"], data * 0.01)
    np.testing.assert_allclose(gm.vertical, -data * 3 * 0.01)


def test_from_arrays_and_with_stream():
    gm = GroundMotion.from_arrays([0.0, 1.0, -0.5], [0.1, 0.2, 0.3], dt=0.02, units="g")
    np.testing.assert_allclose(gm.horizontal, [0.0, G, -0.5 * G])
    np.testing.assert_allclose(gm.vertical, [0.1 * G, 0.2 * G, 0.3 * G])
    assert gm.dt == 0.02
    processed = gm.stream.copy()
    for tr in processed:
        tr.data = tr.data * 2.0
    gm2 = gm.with_stream(processed, "scaled x2")
    np.testing.assert_allclose(gm2.horizontal, 2 * gm.horizontal)
    assert gm2.metadata["processing"] == ["scaled x2"] and gm.metadata["processing"] == []
    assert GroundMotion.from_arrays([1.0, 2.0], dt=0.01).vertical is None
    with pytest.raises(ParameterError, match="vertical must have as many samples as"
                                             " horizontal .2., got 3"):
        GroundMotion.from_arrays([1.0, 2.0], [1.0, 2.0, 3.0], dt=0.01)
    with pytest.raises(ParameterError, match="horizontal has 1 sample.*nan at index 1"):
        GroundMotion.from_arrays([1.0, np.nan], dt=0.01)
    with pytest.raises(ParameterError, match="units must be an acceleration unit .*'furlongs'"):
        GroundMotion.from_arrays([1.0, 2.0], dt=0.01, units="furlongs")


def test_different_sampling_rates_refused_unless_resample_asked():
    t200 = np.arange(2000) / 200.0
    t100 = np.arange(1000) / 100.0
    signal = lambda t: np.sin(2 * np.pi * 1.0 * t)  # noqa: E731 - 1 Hz, well below Nyquist
    alias = np.sin(2 * np.pi * 80.0 * t200)  # 80 Hz: above the 50 Hz Nyquist of 100 Hz
    st_ = Stream([_trace(signal(t200) + alias, "HNN", rate=200.0),
                  _trace(signal(t100), "HNE", rate=100.0)])
    with pytest.raises(RecordError, match=r"different sampling rates \(H1 .*200 Hz.*H2 .*100 Hz"
                                          r".*align='resample'"):
        read_motion(st_, units="m/s^2")
    gm = read_motion(st_, units="m/s^2", align="resample")
    assert gm.dt == pytest.approx(0.01)
    h1 = gm.components["H1"]
    inner = slice(100, -100)
    np.testing.assert_allclose(h1[inner], signal(t100)[inner], atol=0.02)
    assert any("resampled 200 -> 100 Hz" in p for p in gm.metadata["processing"])
    with pytest.raises(RecordError, match="different sampling rates"):
        read_motion(st_, units="m/s^2", align="strict")


def test_lengths_trimmed_within_tolerance_or_refused():
    """Trimming may drop up to 5 % of the record's span (WINDOW_TOLERANCE_FRACTION)."""
    # 1000 samples at 100 Hz (10 s); H2 starts 0.2 s late and ends 0.2 s early: 4 % dropped.
    st_ = Stream([_trace(np.ones(1000), "HNN"), _trace(np.ones(960), "HNE", start=0.2)])
    gm = read_motion(st_, units="gal")
    assert gm.npts == 960 and gm.stream[0].stats.starttime == UTCDateTime(0.2)
    assert any("0.4 s of the 10 s span dropped" in p for p in gm.metadata["processing"])
    with pytest.raises(RecordError, match="differ in start time or length"):
        read_motion(st_, units="gal", align="strict")
    # 0.6 s (6 %) would be dropped: refused with each component's window.
    beyond = Stream([_trace(np.ones(1000), "HNN"), _trace(np.ones(940), "HNE", start=0.3)])
    with pytest.raises(RecordError, match=r"drop 0\.6 s \(6 %\).*H1 \(XX\.SYN\.\.HNN\) 100 Hz,"
                                          r" 0-9\.99 s, 1000 samples; H2 .* 0\.3-9\.69 s, 940"):
        read_motion(beyond, units="gal")
    apart = Stream([_trace(np.ones(10), "HNN"), _trace(np.ones(10), "HNE", start=100.0)])
    with pytest.raises(RecordError, match="do not overlap"):
        read_motion(apart, units="gal")


def test_a_two_sample_component_does_not_trim_the_others():
    """Issue 23: one component of 2 samples trimmed all three to 2 samples; now refused."""
    st_ = Stream([_trace(np.ones(3000), "HNN"), _trace(np.ones(3000), "HNE"),
                  _trace(np.ones(2), "HNZ")])
    with pytest.raises(RecordError, match=r"V \(XX\.SYN\.\.HNZ\) 100 Hz, 0-0\.01 s, 2 samples"):
        read_motion(st_, units="gal")


def test_gaps_refused_or_interpolated_up_to_a_quarter_second():
    a = _trace(np.arange(100.0), "HNN")
    b = _trace(np.arange(120.0, 220.0), "HNN", start=1.2)  # samples 100-119 (0.2 s) missing
    with pytest.raises(RecordError, match=r"1 gap\(s\), the first of 0\.2 s"):
        read_motion(Stream([a, b]), units="gal")
    gm = read_motion(Stream([a, b]), units="gal", gaps="interpolate")
    assert gm.npts == 220
    np.testing.assert_allclose(gm.horizontal[110], 110.0 * 0.01)
    c = _trace(np.arange(150.0, 250.0), "HNN", start=1.5)  # 0.5 s missing: too long to fill
    with pytest.raises(RecordError, match="longer than the 0.25 s gaps='interpolate' fills"):
        read_motion(Stream([a, c]), units="gal", gaps="interpolate")


def test_overlapping_records_must_agree():
    """Repeated samples merge into one; different samples for one time are refused."""
    a = _trace(np.arange(100.0), "HNN")
    repeat = _trace(np.arange(50.0, 150.0), "HNN", start=0.5)  # samples 50-99 again, same values
    gm = read_motion(Stream([a, repeat]), units="gal")
    np.testing.assert_array_equal(gm.horizontal, np.arange(150.0) * 0.01)
    other = _trace(np.arange(50.0, 150.0) + 1.0, "HNN", start=0.5)
    with pytest.raises(RecordError, match="two different recordings of 0.49 s"):
        read_motion(Stream([a, other]), units="gal")


def test_bad_traces(tmp_path):
    with pytest.raises(RecordError, match="zero-length"):
        read_motion(Stream([_trace([], "HNN")]), units="g")
    with pytest.raises(RecordError, match="NaN/inf"):
        read_motion(Stream([_trace([1.0, np.inf], "HNN")]), units="g")
    with pytest.raises(RecordError, match="only a vertical component"):
        read_motion(Stream([_trace([1.0, 2.0], "HNZ")]), units="g")
    only_h1 = read_motion(Stream([_trace([1.0, 2.0], "HNN")]), units="g")
    assert only_h1.vertical is None and "V" not in only_h1.components
    with pytest.raises(RecordError, match="only H1 is available"):
        read_motion(Stream([_trace([1.0, 2.0], "HNN")]), units="g", azimuth=45.0)
    two_stations = Stream([_trace([1.0], "HNN", station="A"), _trace([1.0], "HNE", station="B")])
    with pytest.raises(RecordError, match="several stations"):
        read_motion(two_stations, units="g")


def test_truncated_mseed_is_refused(tmp_path):
    raw = (NAPA / "NP.1765.mseed").read_bytes()
    cut = tmp_path / "cut.mseed"
    cut.write_bytes(raw[: len(raw) // 5 + 1000])
    with pytest.raises(RecordError, match="cut.mseed.*truncated"):
        read_motion(cut, inventory=NAPA / "NP.1765.xml")


def test_missing_inventory_file():
    with pytest.raises(RecordError, match="nothere.xml"):
        read_motion(NAPA / "NP.1765.mseed", inventory=os.fspath(NAPA / "nothere.xml"))


def test_name_of_a_motion_from_arrays_is_the_name_given_never_a_dict_repr():
    """from_arrays keeps its label as given (it is not a file: no basename is taken), after
    processing too, and a motion whose metadata lost its file list still has a readable name."""
    acc = np.sin(np.linspace(0.0, 20.0, 400))
    assert GroundMotion.from_arrays(acc, dt=0.01).name == "synthetic"
    labelled = GroundMotion.from_arrays(acc, dt=0.01, name="runs/case 3")
    assert labelled.name == "runs/case 3"
    assert labelled.with_stream(labelled.stream.copy(), "demean").name == "runs/case 3"
    bare = dict(labelled.metadata, source_files=[])
    assert GroundMotion(labelled.stream, bare).name == "runs/case 3"
    nameless = dict(labelled.metadata, station={"location": "00"}, source_files=[])
    name = GroundMotion(labelled.stream, nameless).name
    assert name == "record" and "{" not in name
