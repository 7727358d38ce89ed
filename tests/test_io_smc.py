"""USGS SMC reader (shipblock.io.smc) against the real files of the gmprocess corpus.

Event nc216859 (Loma Prieta, 1989) has three free-field corrected files (``0111a/b/c.smc``, even
200 samples/s), which gmprocess 2.8.0 reads: peaks, npts, dt and start time must agree. It refuses
the other twelve ("not a free-field" sensor): eleven channels of a CRA-1 in a 42-storey building
(575 Market St., floors 42, 34, 25 and ground) and one SMA-1 on the crest of Del Valle Dam. They
are uncorrected film records digitized unevenly, stored as (time, acceleration) pairs. shipblock
reads them, interpolated at 200 samples/s, and reports ``stats.sensor_site == "structure"`` so a
caller can refuse them. Their own values are the check: the maximum and minimum the real header
states (reals 29 and 31, also printed on text line 7) and the orientation and site fields.
"""

from __future__ import annotations

import io

import numpy as np
import pytest
from obspy import UTCDateTime

from shipblock.errors import RecordError, UnitsError
from shipblock.io import read_record
from shipblock.io.smc import is_smc, read_smc
from tests.reader_fuzz import assert_reader_survives
from tests.real_corpus import (
    REFERENCE,
    assert_peaks_match_gmprocess,
    corpus_file,
    gmprocess_read,
    reference_files,
)

FILES = reference_files("smc")
READ_BY_GMPROCESS = [f for f in FILES if gmprocess_read(f)]
REFUSED_BY_GMPROCESS = [f for f in FILES if not gmprocess_read(f)]

CM = 0.01  # 1 cm/s^2 in m/s^2 (exact)
DIR = "smc/nc216859/"

#: Per file, read off the file: line-6 component (azimuth or "up"), site, where the sensor is,
#: the last digitized time [s] of a pair file (None for even files) and the first value [cm/s^2].
STATED = {
    "0111a.smc": (360, "free-field", "not a structure", None, 1.5057),
    "0111b.smc": ("up", "free-field", "not a structure", None, None),
    "0111c.smc": (270, "free-field", "not a structure", None, None),
    "891018_1.cra-1.0210a.smc": (45, "structure", "building, floor 42", 48.549, -0.64596),
    "891018_1.cra-1.0210b.smc": (225, "structure", "building, floor 42", 48.555, None),
    "891018_1.cra-1.0210c.smc": (135, "structure", "building, floor 42", 48.529, None),
    "891018_1.cra-1.0210d.smc": (45, "structure", "building, floor 34", 48.543, None),
    "891018_1.cra-1.0210e.smc": (225, "structure", "building, floor 34", 48.504, None),
    "891018_1.cra-1.0210f.smc": ("up", "structure", "building, floor 34", 48.540, None),
    "891018_1.cra-1.0210g.smc": (45, "structure", "building, floor 25", 48.492, None),
    "891018_1.cra-1.0210h.smc": (225, "structure", "building, floor 25", 48.560, None),
    "891018_1.cra-1.0210i.smc": (135, "structure", "building, floor 25", 48.502, None),
    "891018_1.cra-1.0210j.smc": ("up", "structure", "building, floor 1", 48.518, None),
    "891018_1.cra-1.0210k.smc": (315, "structure", "building, floor 1", 48.538, None),
    "891018_1.sma-1.0444a.smc": (65, "structure", "dam, on the crest of the dam", 29.655,
                                 -0.08604),
}

#: Files of other formats that must not be taken for SMC (two per folder).
OTHER_FORMATS = [
    f for folder in ("knet", "kiknet", "dmg", "cosmos", "esm", "geonet", "geonet2", "cwb", "unam",
                     "renadic", "usc", "bhrc", "peer", "nsmn", "csn")
    for f in reference_files(folder)[:2]
]


def _raw(relpath: str) -> bytes:
    return corpus_file(relpath).read_bytes()


def test_corpus_lists_the_fifteen_files():
    assert sorted(DIR + f for f in STATED) == FILES
    assert len(READ_BY_GMPROCESS) == 3


@pytest.mark.parametrize("relpath", READ_BY_GMPROCESS)
def test_free_field_files_match_gmprocess(relpath):
    stream = read_smc(corpus_file(relpath))
    assert len(stream) == 1
    assert_peaks_match_gmprocess(stream, relpath)
    (row,) = REFERENCE[relpath]
    trace = stream[0]
    assert trace.stats.npts == int(row["npts"])
    assert trace.stats.delta == pytest.approx(float(row["delta_s"]), rel=1e-12)
    assert trace.stats.starttime == UTCDateTime(row["starttime"])
    assert trace.stats.network == "US" and trace.stats.station == "SAF0"
    assert trace.stats.units == "m/s**2" and trace.stats.original_units == "cm/s^2"


@pytest.mark.parametrize("relpath", FILES)
def test_stated_values(relpath):
    component, site, where, last_time, first_value = STATED[relpath.removeprefix(DIR)]
    trace = read_smc(corpus_file(relpath))[0]
    header = trace.stats.shipblock_smc
    peak = float(np.max(np.abs(trace.data)))
    # Line 7 prints the signed peak to 0.1 cm/s^2; reals 29/31 (5E15.7) give it in full.
    assert abs(abs(header.text_peak_cm_s2) * CM - trace.stats.stated_peak_si) <= 0.051 * CM
    assert trace.stats.sensor_site == site == header.sensor_site
    assert header.sensor_location == where
    if component == "up":
        assert trace.stats.dip == -90.0 and trace.stats.channel == "HNZ"
        assert "azimuth" not in trace.stats
    else:
        assert trace.stats.dip == 0.0
        assert trace.stats.azimuth == component % 360
    if last_time is None:
        # Even samples (E10.4, 5 significant digits): the stated peak is a sample.
        assert header.time_value_pairs is False
        assert peak == pytest.approx(trace.stats.stated_peak_si, rel=5e-5)
    else:
        # Digitized pairs: the stated peak is the largest digitized value; interpolation at
        # 200 samples/s keeps it within 0.5 % (0.41 % at worst on these files).
        assert header.time_value_pairs is True
        assert header.digitized_peak_cm_s2 * CM == pytest.approx(trace.stats.stated_peak_si,
                                                                   rel=5e-5)
        assert 0.995 * trace.stats.stated_peak_si <= peak <= trace.stats.stated_peak_si
        assert trace.stats.delta == 0.005
        # The grid runs from the first digitized time (0) to the last one.
        duration = trace.stats.endtime - trace.stats.starttime
        assert last_time - 0.005 < duration <= last_time
        # The pair files end with one stray line of four pairs, which is not data.
        assert header.ignored_trailing_values == 8
    assert header.start_time_nominal is True
    if first_value is not None:
        assert trace.data[0] == pytest.approx(first_value * CM, rel=1e-9)
    # Integer header: 1989, day 291, 00:04 (the event's minute; the film has no clock).
    assert trace.stats.starttime == UTCDateTime("1989-10-18T00:04:00")


def test_structure_locations_and_codes():
    """Channels of the building keep their floor in the location code; all are read."""
    locations = {f: read_smc(corpus_file(DIR + f), headonly=True)[0].stats.location
                 for f in ("891018_1.cra-1.0210a.smc", "891018_1.cra-1.0210j.smc",
                           "891018_1.sma-1.0444a.smc", "0111a.smc")}
    assert locations == {"891018_1.cra-1.0210a.smc": "42", "891018_1.cra-1.0210j.smc": "01",
                         "891018_1.sma-1.0444a.smc": "", "0111a.smc": ""}


def test_coordinates_and_header():
    trace = read_smc(corpus_file(DIR + "0111a.smc"))[0]
    assert trace.stats.coordinates.latitude == pytest.approx(37.728)
    assert trace.stats.coordinates.longitude == pytest.approx(-122.385)
    assert trace.stats.shipblock_smc.instrument == "SMA-1"
    assert trace.stats.shipblock_smc.station_number == 1675
    assert trace.stats.stated_peak_si == pytest.approx(104.4078 * CM, rel=1e-7)


def test_resample_rate_option_and_headonly():
    relpath = DIR + "891018_1.cra-1.0210a.smc"
    fine = read_smc(corpus_file(relpath), resample_rate=1000.0)[0]
    assert fine.stats.delta == pytest.approx(0.001)
    # A finer grid passes through the digitized peak (-228.3932 cm/s^2 at 13.71643 s).
    assert float(np.max(np.abs(fine.data))) == pytest.approx(228.3932 * CM, rel=1e-4)
    head = read_smc(corpus_file(relpath), headonly=True)[0]
    full = read_smc(corpus_file(relpath))[0]
    assert head.stats.npts == full.stats.npts and head.data.size == 0
    assert (read_smc(io.BytesIO(_raw(relpath)))[0].data == full.data).all()


@pytest.mark.parametrize("relpath", [f for f in FILES if STATED[f.rsplit("/", 1)[1]][3] is None])
def test_resample_rate_refused_for_an_even_file(relpath):
    """0111a/b/c.smc are evenly sampled at 200 samples/s: resample_rate, which only sets the grid
    of (time, value) pairs, would leave them as stored, so it is refused naming the option and
    the file (it was accepted and ignored, the user believing the record resampled). Without
    it they read at their own rate, and the option still applies to a pair file."""
    path = corpus_file(relpath)
    with pytest.raises(RecordError) as caught:
        read_record(path, resample_rate=100.0)
    message = str(caught.value)
    assert message.startswith(f"{path}: resample_rate=100.0 cannot apply")
    assert "evenly sampled at 200 samples/s" in message
    assert "leave out --resample-rate, catalogue key resample_rate" in message
    assert read_smc(path)[0].stats.sampling_rate == 200.0
    pairs = read_record(corpus_file(DIR + "891018_1.sma-1.0444a.smc"), resample_rate=100.0)[0]
    assert pairs.stats.sampling_rate == 100.0
    assert pairs.stats.shipblock_smc.resample_rate_hz == 100.0


def test_detection():
    for relpath in FILES:
        assert is_smc(corpus_file(relpath)), relpath
    for relpath in OTHER_FORMATS:
        assert not is_smc(corpus_file(relpath)), relpath
    assert not is_smc(io.BytesIO(b"0.01 0.02\n0.03 -0.04\n" * 50))
    assert not is_smc(io.BytesIO(b"1 UNCORRECTED ACCELEROGRAM\n"))
    assert not is_smc(io.BytesIO(b"\x00\x01binary"))


def _replace_line(raw: bytes, index: int, new: bytes) -> bytes:
    lines = raw.split(b"\r\n")
    lines[index] = new
    return b"\r\n".join(lines)


def test_refusals_name_the_file(tmp_path):
    raw = _raw(DIR + "0111a.smc")
    with pytest.raises(UnitsError, match="velocity"):
        read_smc(io.BytesIO(_replace_line(raw, 0, b"3 VELOCITY")))
    with pytest.raises(RecordError, match="not a time series"):
        read_smc(io.BytesIO(_replace_line(raw, 0, b"5 RESPONSE SPECTRA")))
    with pytest.raises(UnitsError, match="does not state its data type"):
        read_smc(io.BytesIO(_replace_line(raw, 0, b"*")))
    path = tmp_path / "cut.smc"
    path.write_bytes(raw[: len(raw) // 2])
    with pytest.raises(RecordError, match=r"cut\.smc: is truncated: 6001 data values stated"):
        read_smc(path)
    path.write_bytes(raw.replace(b"0.2000000E+03", b"0.1000000E+07", 1))
    with pytest.raises(RecordError, match="sampling rate"):
        read_smc(path)


def test_pair_file_defects():
    raw = _raw(DIR + "891018_1.sma-1.0444a.smc")
    lines = raw.split(b"\r\n")
    first_data = 27 + 8
    # Two data lines swapped: the times go backwards.
    swapped = lines[:first_data] + [lines[first_data + 1], lines[first_data]] + lines[
        first_data + 2:]
    with pytest.raises(RecordError, match="go backwards"):
        read_smc(io.BytesIO(b"\r\n".join(swapped)))
    # A data line lost: the stray last line would become data after a 0.4 s jump.
    dropped = lines[: first_data + 10] + lines[first_data + 11:]
    with pytest.raises(RecordError, match="jump by"):
        read_smc(io.BytesIO(b"\r\n".join(dropped)))
    with pytest.raises(RecordError, match="resample rate"):
        read_smc(io.BytesIO(raw), resample_rate=-1.0)


@pytest.mark.parametrize("relpath", [DIR + "0111b.smc", DIR + "891018_1.sma-1.0444a.smc"])
def test_fuzz(relpath):
    assert_reader_survives(read_smc, _raw(relpath), count=60)
