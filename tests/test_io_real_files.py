"""COSMOS reader against headers written by the USGS (tests/data/real/cosmos, see its README).

Each ``*.header`` file holds the first lines of a real COSMOS file from the USGS
groundmotion-processing repository, byte for byte: the text, integer and real headers, the comments
and the data descriptor line. The samples (42000 a file, 380-680 KB) are not stored. Each test
rebuilds a file from the agency's header, synthetic samples in the format the descriptor gives, and
the agency's ``End-of-data`` line. It then reads the file with ``obspy.read`` (format found through
the entry points) and with :func:`shipblock.records.reading.read_motion`.

Expected values come from the header itself: npts from the descriptor line, dt from Real(62) [ms],
start time from Int(40), Int(42)-Int(45) and Real(30) (and text line 8, printed to 1 ms),
network/station from ``Code:`` (line 5), channel/location from the ``|<SCNL>`` comment, unit from
the descriptor's code, and peak and peak time from Real(64)/Real(65) (and text line 11). The
synthetic samples hold that peak at that time and are zero elsewhere. This checks the reader's unit
conversion and time axis against the header, but not on the agency's samples.
"""

from __future__ import annotations

import re
import warnings
from pathlib import Path

import numpy as np
import obspy
import pytest

from shipblock.errors import RecordError, UnitsError
from shipblock.records.reading import read_motion

REAL = Path(__file__).parent / "data" / "real" / "cosmos"
CM = 0.01  # 1 cm/s^2 = 0.01 m/s^2 (exact)

# Values as printed in each header (line numbers are 1-based lines of the file).
FILES = {
    # AK.BMR BNZ, 2018-11-30 M7.0 Anchorage; V2 corrected acceleration (Int(1)=2).
    "us1000hyfh_akbmrp_AKBMR--n.1000hyfh.BNZ.--.acc.V2c": dict(
        network="AK", station="BMR", channel="BNZ", location="",
        npts=42000, fmt="%15.6e", delta=0.005, stage=2,
        start="2018-11-30T17:29:39.137490", start_text="2018-11-30T17:29:39.137",
        unit_code=4, units="m/s**2", peak=-6.851512, peak_text=-6.852, peak_time=76.215,
        end="End-of-data for ChanBNZ acceleration", vertical=True,
    ),
    # NP.8040 HNZ location 03 (Anchorage, R B Atwood building, basement); V1 (Int(1)=1).
    "16371-1605048211R_us1000hyfh_np8040r_NP8040-n.1000hyfh.HNZ.03.V1c": dict(
        network="NP", station="8040", channel="HNZ", location="03",
        npts=42000, fmt="%15.6e", delta=0.005, stage=1,
        start="2018-11-30T17:29:06.331590", start_text="2018-11-30T17:29:06.332",
        unit_code=4, units="m/s**2", peak=-221.811408, peak_text=-221.811, peak_time=37.97,
        end="End-of-data for ChanHNZ acceleration", vertical=True,
    ),
    # NP.8040 HNE location 01, same event and building; V0 raw counts (Int(1)=0, unit code 50).
    "NP8040-n.1000hyfh.HNE.01.V0c": dict(
        network="NP", station="8040", channel="HNE", location="01",
        npts=42000, fmt="%8d", delta=0.005, stage=0,
        start="2018-11-30T17:29:06.331590", start_text="2018-11-30T17:29:06.332",
        unit_code=50, units="counts", peak=1033406, peak_text=1033406, peak_time=45.58,
        end="End-of-data for ChanHNE", vertical=False,
    ),
}


def _peak_tolerance(peak: float) -> float:
    """Half a last digit of Real(64) (F15.6) plus half a last digit of an E15.6 sample [file unit]."""
    return 0.5e-6 + 0.5e-6 * 10.0 ** np.floor(np.log10(abs(peak)))


def _rebuild(name: str, directory: Path) -> Path:
    """Write the agency header, synthetic samples (peak at the header's time) and end line."""
    spec = FILES[name]
    header = (REAL / f"{name}.header").read_text()
    data = np.zeros(spec["npts"])
    data[round(spec["peak_time"] / spec["delta"])] = spec["peak"]
    lines = "".join(spec["fmt"] % v + "\n" for v in data)
    path = directory / name
    path.write_text(header + lines + spec["end"] + "\n")
    return path


def _read(path: Path) -> tuple[obspy.Stream, list[str]]:
    """The stream ``obspy.read`` gives and the warnings it raised."""
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        stream = obspy.read(str(path))
    return stream, [str(w.message) for w in caught]


def test_headers_are_the_agency_bytes():
    # Lengths checked against the stored files: total chars - 42000 sample lines - end line.
    expected = {
        "us1000hyfh_akbmrp_AKBMR--n.1000hyfh.BNZ.--.acc.V2c": (53, 3620),
        "16371-1605048211R_us1000hyfh_np8040r_NP8040-n.1000hyfh.HNZ.03.V1c": (50, 3541),
        "NP8040-n.1000hyfh.HNE.01.V0c": (49, 3523),
    }
    for name, (n_lines, n_chars) in expected.items():
        text = (REAL / f"{name}.header").read_text()
        assert (text.count("\n"), len(text)) == (n_lines, n_chars), name
        assert re.match(rf"^\s*{FILES[name]['npts']} ", text.splitlines()[-1]), name


@pytest.mark.parametrize("name", sorted(FILES))
def test_header_fields(tmp_path, name):
    spec = FILES[name]
    stream, _ = _read(_rebuild(name, tmp_path))
    assert len(stream) == 1
    tr = stream[0]
    assert tr.stats._format == "SHIPBLOCK_COSMOS"
    assert (tr.stats.network, tr.stats.station, tr.stats.location, tr.stats.channel) == (
        spec["network"], spec["station"], spec["location"], spec["channel"])
    assert tr.stats.npts == spec["npts"]
    # Real(62) is printed to 1e-6 ms; 5.000000 ms is exact.
    assert tr.stats.delta == pytest.approx(spec["delta"], abs=5e-10)
    # Real(30) is printed to 1e-6 s, text line 8 to 1 ms.
    assert abs(tr.stats.starttime - obspy.UTCDateTime(spec["start"])) <= 5e-7
    assert abs(tr.stats.starttime - obspy.UTCDateTime(spec["start_text"])) <= 5e-4
    cosmos = tr.stats.shipblock_cosmos
    assert cosmos.processing_stage == spec["stage"]
    assert cosmos.unit_code == spec["unit_code"]
    assert tr.stats.units == spec["units"]


@pytest.mark.parametrize("name", sorted(FILES))
def test_peak_in_si_at_header_time(tmp_path, name):
    spec = FILES[name]
    tr = _read(_rebuild(name, tmp_path))[0][0]
    i = int(np.argmax(np.abs(tr.data)))
    # Real(65) is printed to 1e-6 s but must fall on a sample: half a sample interval.
    assert abs(i * tr.stats.delta - spec["peak_time"]) <= tr.stats.delta / 2
    if spec["units"] == "counts":
        assert tr.data[i] == spec["peak"]  # V0 counts are kept as integers' values
        return
    # Real(64) is printed to 1e-6 cm/s^2 and the samples to 7 digits; text line 11 to 1e-3.
    assert tr.data[i] == pytest.approx(spec["peak"] * CM, abs=_peak_tolerance(spec["peak"]) * CM)
    assert tr.data[i] == pytest.approx(spec["peak_text"] * CM, abs=0.5e-3 * CM)


def test_vertical_with_contradicting_int54_is_not_a_horizontal(tmp_path):
    # AK.BMR: Int(54)=0 (north) but the SCNL comment, the RcrdId and the file name say BNZ and
    # text line 9 says "Other". Before the fix the reader made it HNN, azimuth 0.
    stream, caught = _read(_rebuild("us1000hyfh_akbmrp_AKBMR--n.1000hyfh.BNZ.--.acc.V2c", tmp_path))
    tr = stream[0]
    assert any("Int(54)=0" in w and "BNZ" in w for w in caught)
    assert "azimuth" not in tr.stats and "dip" not in tr.stats
    assert tr.stats.shipblock_cosmos.orientation_code == 0


def test_structure_array_orientation_from_int55(tmp_path):
    # NP.8040 leaves Int(54) unknown; Int(55) gives 400 (up) for HNZ and 90 for HNE.
    z = _read(_rebuild("16371-1605048211R_us1000hyfh_np8040r_NP8040-n.1000hyfh.HNZ.03.V1c",
                       tmp_path))[0][0]
    assert z.stats.dip == -90.0 and "azimuth" not in z.stats
    e = _read(_rebuild("NP8040-n.1000hyfh.HNE.01.V0c", tmp_path))[0][0]
    assert e.stats.dip == 0.0 and "azimuth" not in e.stats  # azimuth then from the code E


@pytest.mark.parametrize("name", [n for n in sorted(FILES) if FILES[n]["vertical"]])
def test_read_motion_keeps_verticals_out_of_the_horizontals(tmp_path, name):
    # A vertical-only file has no horizontal: read_motion must refuse it, not call it H1.
    path = _rebuild(name, tmp_path)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        # (motion.py words it "holds only a vertical component" since the vertical is recognised)
        with pytest.raises(RecordError,
                           match="no horizontal component|only a vertical component"):
            read_motion(path)


def test_read_motion_refuses_v0_counts_without_inventory(tmp_path):
    path = _rebuild("NP8040-n.1000hyfh.HNE.01.V0c", tmp_path)
    with pytest.raises((UnitsError, RecordError), match="counts"):
        read_motion(path)
