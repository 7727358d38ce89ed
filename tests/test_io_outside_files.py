"""Real files from other public projects read right: peaks and start times as the files state.

Files: ``../shared/records/outside-tests/`` (its README names each source; :func:`outside_file`
skips where absent, fails in CI). Every expected value is parsed here from the file's own text
(a header's stated peak, trigger or record time), not taken from a previous reading; where a
class of file is tested, copies changed the way that class differs (another azimuth, another
time layout) are read too.
"""

from __future__ import annotations

import re

import numpy as np
import pytest
from obspy import UTCDateTime

from shipblock import read_motion
from shipblock.errors import RecordError, UnitsError
from shipblock.io import read_record
from shipblock.records.folders import read_motions as read_motion_set
from tests.real_corpus import outside_file

pytestmark = pytest.mark.filterwarnings("ignore")

GAL = 0.01  # m/s^2


def _header_value(path, key: str) -> str:
    for line in path.read_text(errors="replace").splitlines()[:17]:
        if line.startswith(key):
            return line[len(key):].strip()
    raise AssertionError(f"{path}: no {key!r} line")


# ------------------------------------------------------------------------------ K-NET

def test_knet_peak_and_start_as_stated():
    """obspy's test.knet: Max. Acc. 4.383 gal (NIED: of the record less its mean); the Record
    Time is JST and includes the recorder's 15 s trigger delay (NIED's format description)."""
    path = outside_file("obspy/test.knet")
    trace = read_record(path)[0]
    stated = float(_header_value(path, "Max. Acc. (gal)"))
    assert stated == 4.383
    peak = float(np.max(np.abs(trace.data))) * trace.stats.calib
    assert peak == pytest.approx(stated * GAL, abs=0.0005 * GAL)
    record_jst = UTCDateTime.strptime(_header_value(path, "Record Time"), "%Y/%m/%d %H:%M:%S")
    assert trace.stats.starttime == record_jst - 9 * 3600 - 15
    assert trace.stats.npts == int(_header_value(path, "Duration Time(s)")) * 100


# ------------------------------------------------------------------------------ CSMIP V2 (DMG)

FERNDALE = "readv2/ce89486SampleInput.v2"
#: Lines of a V2 channel's text header, and where its integer header's orientation code is.
_V2_TEXT_LINES, _ORIENTATION_LINE, _ORIENTATION_COLUMNS = 25, 26, slice(50, 55)


def _channel_blocks(text: str) -> list[list[str]]:
    lines = text.split("\n")
    starts = [i for i, line in enumerate(lines) if line.startswith("Corrected accelerogram")]
    return [lines[a:b] for a, b in zip(starts, [*starts[1:], len(lines)], strict=True)]


def _stated_start(block) -> UTCDateTime:
    """The block's ``Start time: mm/dd/yy, hh:mm:ss.s UTC``, parsed here (blank-padded fields)."""
    match = re.search(r"Start time:\s*(\d+)/(\d+)/(\d+),\s*([\d ]+):([\d ]+):([\d. ]+)UTC",
                      "\n".join(block))
    month, day, year, hour, minute, second = (float(g.strip()) for g in match.groups())
    return UTCDateTime(int(2000 + year), int(month), int(day), int(hour), int(minute)) + second


def _stated_pst(block) -> UTCDateTime:
    """The block's ``Rcrd of Tue Dec 20, 2022 02:34:01.0 PST`` in UTC (PST = UTC - 8 h)."""
    match = re.search(r"Rcrd of \w+ (\w+ \d+, \d{4} \d+:\d+):([\d.]+) PST", "\n".join(block))
    return UTCDateTime.strptime(match.group(1), "%b %d, %Y %H:%M") + float(match.group(2)) + 8 * 3600


def test_cesmd_v2_peaks_and_trigger_time_as_stated():
    """Every channel starts at the header's trigger time (two statements of it agree) and peaks at
    its stated 'Peak acceleration' (cm/sec/sec)."""
    path = outside_file(FERNDALE)
    blocks = _channel_blocks(path.read_text())
    stream = read_record(path)
    assert len(stream) == len(blocks) == 3
    for trace, block in zip(stream, blocks, strict=True):
        assert _stated_start(block) == _stated_pst(block) == UTCDateTime(2022, 12, 20, 10, 34, 1)
        assert trace.stats.starttime == _stated_start(block)
        stated = re.search(r"Peak acceleration =\s*(\S+)\s+cm/sec/sec", "\n".join(block))
        peak = float(np.max(np.abs(trace.data)))
        assert peak == pytest.approx(abs(float(stated.group(1))) * GAL, abs=0.0005 * GAL)


@pytest.mark.parametrize("written", ["10:34:01.0", "10:34: 1.0", "10:34:1", " 9: 5: 3.5",
                                     "23:59:59.99"])
def test_cesmd_v2_trigger_time_layouts(tmp_path, written):
    """The trigger time in the layouts CSMIP writes it (blank- or zero-padded fields)."""
    text = outside_file(FERNDALE).read_text().replace("10:34: 1.0 UTC", f"{written} UTC")
    path = tmp_path / "ferndale.v2"
    path.write_text(text)
    hour, minute, second = (float(v.strip()) for v in written.split(":"))
    expected = UTCDateTime(2022, 12, 20, int(hour), int(minute)) + second
    for trace in read_record(path):
        assert abs(trace.stats.starttime - expected) < 1e-6


def _one_channel_files(tmp_path, azimuths) -> list:
    """The Ferndale V2 split into one file a channel, horizontals turned to ``azimuths``
    (text line and integer-header code both), as CESMD ships free-field sets."""
    blocks = _channel_blocks(outside_file(FERNDALE).read_text())
    files = []
    for number, (block, azimuth) in enumerate(zip(blocks, [*azimuths, None], strict=True), 1):
        block = list(block)
        if azimuth is not None:
            old = re.search(r"Chan  \d: +(\d+) Deg", block[0]).group(1)
            block = [line.replace(f"Chan  {number}: {old:>3} Deg", f"Chan  {number}: {azimuth:>3} Deg")
                     for line in block]
            row = block[_ORIENTATION_LINE]
            block[_ORIENTATION_LINE] = (row[:_ORIENTATION_COLUMNS.start] + f"{azimuth:>5d}"
                                        + row[_ORIENTATION_COLUMNS.stop:])
        path = tmp_path / f"CHAN{number:03d}.V2"
        path.write_text("\n".join(block).rstrip("\n") + "\n")
        files.append(path)
    return files


@pytest.mark.parametrize("azimuths", [(110, 20), (20, 110), (200, 290), (45, 135), (180, 90),
                                      (330, 240)])
def test_cesmd_one_channel_files_keep_two_horizontals(tmp_path, azimuths):
    """Horizontals at any two orthogonal azimuths, one file each: two channel codes, each with its
    stated azimuth; read as one record, and with the channels named by file."""
    files = _one_channel_files(tmp_path, azimuths)
    traces = [read_record(f)[0] for f in files[:2]]
    assert traces[0].stats.channel != traces[1].stats.channel
    assert [tr.stats.azimuth for tr in traces] == [float(a) for a in azimuths]
    motion = read_motion(files)
    assert set(motion.components) == {"H1", "H2", "V"}
    named = read_motion(files, channel_map={files[0].name: "H1", files[1].name: "H2",
                                            files[2].name: "V"})
    np.testing.assert_array_equal(named.components["H1"], traces[0].data)
    np.testing.assert_array_equal(named.components["H2"], traces[1].data)


# ------------------------------------------------------------------------------ PEER AT2

ANAHEIM = ["pyrotd/RSN8883_14383980_13849090.AT2", "pyrotd/RSN8883_14383980_13849360.AT2"]


def _at2_samples(path) -> np.ndarray:
    """The samples of an AT2 file [g], parsed here (5 per line after the 4 header lines)."""
    lines = path.read_text().splitlines()[4:]
    return np.array([float(v) for line in lines for v in line.split()])


BREA = ["pyrotd/RSN8884_14383980_13873090.AT2", "pyrotd/RSN8884_14383980_13873360.AT2"]
LOMA = "loma/RSN753_LOMAP_CLS000.AT2"
G = 9.80665


def test_peer_ids_name_station_and_component():
    """A PEER file states its station in words and its component as a word (``Corralitos, 0``):
    the id is ``.STATION..CHANNEL`` with the name made an upper-case code and the component
    an orientation code (it was ``.Corralitos..0``); the azimuth and the word are kept."""
    expected = {LOMA: (".CORRALITOS..HNN", 0.0, "0", "Corralitos"),
                ANAHEIM[0]: (".ANAHEIM-LAKEVIEW-RIVERDALE..HNE", 90.0, "90",
                             "Anaheim - Lakeview & Riverdale"),
                ANAHEIM[1]: (".ANAHEIM-LAKEVIEW-RIVERDALE..HNN", 0.0, "360",
                             "Anaheim - Lakeview & Riverdale"),
                BREA[0]: (".BREA-CENTRAL-AVE-CALTRANS-YARD..HNE", 90.0, "90",
                          "Brea - Central Ave Caltrans Yard"),
                BREA[1]: (".BREA-CENTRAL-AVE-CALTRANS-YARD..HNN", 0.0, "360",
                          "Brea - Central Ave Caltrans Yard")}
    for rel, (trace_id, azimuth, word, name) in expected.items():
        trace = read_record(outside_file(rel))[0]
        assert trace.id == trace_id, rel
        assert (trace.stats.azimuth, trace.stats.dip) == (azimuth, 0.0)
        assert trace.stats.file_component == word
        assert trace.stats.shipblock_at2.station_name == name


def test_peer_folder_pairs_each_stations_horizontals():
    """Read together, the files of two stations and a single one make three records; each pair
    is one record with H1 the 360 file (azimuth 0) and H2 the 090 file, as before the ids
    changed (a map by the file's component words still works)."""
    paths = [outside_file(rel) for rel in [LOMA, *ANAHEIM, *BREA]]
    found = read_motion_set(paths)
    assert sorted(m.name for m in found) == ["ANAHEIM-LAKEVIEW-RIVERDALE",
                                             "BREA-CENTRAL-AVE-CALTRANS-YARD", "CORRALITOS"]
    for motion in found:
        if motion.name == "CORRALITOS":
            assert set(motion.components) == {"H1"}
            continue
        station = motion.name
        assert motion.metadata["channels"] == {"H1": f".{station}..HNN", "H2": f".{station}..HNE"}
        assert motion.azimuths == {"H1": 0.0, "H2": 90.0}
        files = ANAHEIM if station.startswith("ANAHEIM") else BREA
        np.testing.assert_allclose(motion.components["H1"], _at2_samples(outside_file(files[1])) * G,
                                   rtol=1e-6, atol=1e-12)
    swapped = read_motion([outside_file(rel) for rel in ANAHEIM],
                          channel_map={"90": "H1", "360": "H2"})
    np.testing.assert_allclose(swapped.components["H1"],
                               _at2_samples(outside_file(ANAHEIM[0])) * G, rtol=1e-6, atol=1e-12)


def test_peer_diagonal_pair_and_dotted_station_name(tmp_path):
    """Components 045 and 315 get HN1 and HN2 by their nearer axes, but H1 stays the one the
    other is 90 deg clockwise from (315), as for every PEER pair; a station name with a dot
    (``Mt. Wilson``) gives a code without one, so the id still has four parts."""
    files = []
    for rel, word in zip(ANAHEIM, ("045", "315"), strict=True):
        text = outside_file(rel).read_text()
        text = text.replace("Anaheim - Lakeview & Riverdale, ", "Mt. Wilson - CIT Seis Sta, ", 1)
        files.append(tmp_path / f"{word}.AT2")
        files[-1].write_text(re.sub(r", (90|360)\n", f", {word}\n", text, count=1))
    traces = [read_record(f)[0] for f in files]
    assert [tr.id for tr in traces] == [".MT-WILSON-CIT-SEIS-STA..HN1", ".MT-WILSON-CIT-SEIS-STA..HN2"]
    assert len(traces[0].id.split(".")) == 4
    motion = read_motion(files)
    assert motion.azimuths == {"H1": 315.0, "H2": 45.0}
    np.testing.assert_allclose(motion.components["H1"], _at2_samples(files[1]) * G, rtol=1e-6,
                               atol=1e-12)


def test_peer_fault_normal_component_is_not_taken_for_north(tmp_path):
    """A PEER component rotated to the fault (``FN``) states no azimuth: its code ends in N by
    chance and must not make it the north horizontal of a pair with an east one (``90``); the
    pair is refused until a ``channel_map`` names the component, and then read as named."""
    east, other = tmp_path / "east.AT2", tmp_path / "FN.AT2"
    east.write_text(outside_file(ANAHEIM[0]).read_text())
    other.write_text(re.sub(r", 360\n", ", FN\n", outside_file(ANAHEIM[1]).read_text(), count=1))
    fault = read_record(other)[0]
    assert fault.stats.channel == "FN" and fault.stats.get("azimuth") is None
    with pytest.raises(RecordError, match="FN"):
        read_motion([east, other])
    motion = read_motion([east, other], channel_map={"FN": "H1", "HNE": "H2"})
    np.testing.assert_allclose(motion.components["H1"], _at2_samples(other) * G, rtol=1e-6,
                               atol=1e-12)


@pytest.mark.parametrize(("word", "up"), [("DWN", False), ("DOWN", False), ("UP", True),
                                          ("VER", True), ("V", True)])
def test_peer_triplet_with_labelled_vertical(tmp_path, word, up):
    """A PEER triplet whose vertical is labelled DWN (older records: San Fernando 1971) or UP is
    one record of one sensor: the vertical's word names no SEED sensor of its own."""
    files = [tmp_path / outside_file(rel).name for rel in ANAHEIM]
    for rel, target in zip(ANAHEIM, files, strict=True):
        target.write_text(outside_file(rel).read_text())
    vertical = tmp_path / f"RSN8883_vertical_{word}.AT2"
    vertical.write_text(re.sub(r", 360\n", f", {word}\n", files[1].read_text(), count=1))
    motion = read_motion([*files, vertical])
    assert set(motion.components) == {"H1", "H2", "V"}
    g = 9.80665
    expected = _at2_samples(vertical) * g * (1.0 if up else -1.0)  # positive up in the model
    np.testing.assert_allclose(motion.components["V"], expected, rtol=1e-6, atol=1e-12)
    read = sorted(np.max(np.abs(motion.components[c])) / g for c in ("H1", "H2"))
    stated = sorted(np.max(np.abs(_at2_samples(f))) for f in files)
    np.testing.assert_allclose(read, stated, rtol=1e-6)


# ------------------------------------------------------------------------------ SMC (pyrotd)

@pytest.mark.parametrize("name", ["A-CAT090.AT2.smc", "A-CAT180.AT2.smc"])
def test_smc_of_unknown_data_type_read_when_stated(name):
    """pyrotd's SMC copies of PEER records say '0 UNKNOWN' on line 1: refused with the keyword
    that reads them; read with it, the peak is the text header's 'pk mtn' (cm/s^2)."""
    path = outside_file(f"pyrotd/{name}")
    with pytest.raises(UnitsError, match="data_type='acceleration'"):
        read_record(path)
    trace = read_record(path, data_type="acceleration")[0]
    stated = abs(float(re.search(r"pk mtn =\s*(\S+)", path.read_text()).group(1)))  # cm/s^2
    assert np.max(np.abs(trace.data)) == pytest.approx(stated * GAL, abs=0.005 * GAL)
    assert trace.stats.station == ""
