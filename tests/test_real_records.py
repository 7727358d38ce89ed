"""Real agency records through read_motion, read_motions and the catalogue command.

Files: the gmprocess test corpus (see tests/real_corpus.py; skipped where it is absent, a failure
in CI). Expected values: gmprocess 2.8.0's peaks (tests/data/reference), the files' own stated
peaks (K-NET "Max. Acc."), and conversions recomputed here from the StationXML's numbers.
"""

from __future__ import annotations

import shutil

import numpy as np
import obspy
import pytest

from shipblock.records.catalogue import load_catalogue
from shipblock.cli import main
from shipblock.records.folders import read_motions
from shipblock.errors import ParameterError, RecordError, UnitsError
from shipblock.io import read_record
from shipblock.records.reading import read_motion
from shipblock.units import STANDARD_GRAVITY
from tests.real_corpus import assert_peaks_match_gmprocess, corpus_file, reference_files

pytestmark = pytest.mark.filterwarnings("ignore")

EPOCHS = "station_xml_epochs/nc73631381"
NP1767 = [f"{EPOCHS}/NP.1767..HN{c}.mseed" for c in "NEZ"]


def _copy(relpaths, directory):
    """Copy corpus files into a folder (flat); return the copies."""
    out = []
    for rel in relpaths:
        target = directory / rel.split("/")[-1]
        shutil.copyfile(corpus_file(rel), target)
        out.append(target)
    return out


# ---------------------------------------------------------------- K-NET and KiK-net

def _stated_max_acc_gal(path) -> float:
    """The ``Max. Acc. (gal)`` a K-NET file's header states (line 15), parsed here."""
    for line in path.read_text(errors="replace").splitlines()[:17]:
        if line.startswith("Max"):
            return float(line.split()[-1])
    raise AssertionError(f"{path}: no Max. Acc. line")


@pytest.mark.parametrize("relpath", reference_files("knet") + reference_files("kiknet"))
def test_knet_kiknet_peaks_as_stated_and_gmprocess(relpath):
    """The peak read is the header's Max. Acc. (NIED: the record less its mean); the counts with
    the offset put back are gmprocess's raw peaks (it keeps the offset until processing)."""
    path = corpus_file(relpath)
    stream = read_record(path)
    trace = stream[0]
    peak = float(np.max(np.abs(trace.data))) * trace.stats.calib
    stated = _stated_max_acc_gal(path) * 0.01
    assert abs(peak - stated) <= 0.0005 * 0.01 + 1e-6 * stated, (peak, stated)
    assert abs(trace.data.mean()) < 1e-6 * np.max(np.abs(trace.data))
    raw = stream.copy()
    for tr in raw:
        tr.data = (tr.data + tr.stats.knet_offset_counts) * tr.stats.calib
    assert_peaks_match_gmprocess(raw, relpath)


def test_kiknet_borehole_and_surface_are_two_sensors(tmp_path):
    names = [f"kiknet/usp000hzq8/NGNH311106302345.{d}{k}" for d in ("NS", "EW", "UD") for k in "12"]
    files = _copy(names, tmp_path)
    stream = obspy.Stream()
    for f in files:
        stream += read_record(f)
    codes = {(tr.stats.knet_direction, tr.stats.location, tr.stats.channel, tr.stats.sensor_site)
             for tr in stream}
    assert codes == {("NS1", "01", "HNN", "borehole"), ("EW1", "01", "HNE", "borehole"),
                     ("UD1", "01", "HNZ", "borehole"), ("NS2", "02", "HNN", "surface"),
                     ("EW2", "02", "HNE", "surface"), ("UD2", "02", "HNZ", "surface")}
    with pytest.raises(RecordError, match="several sensors.*--sensor"):
        read_motion(files)
    surface = read_motion(files, sensor="02.HN")
    assert surface.metadata["channels"] == {"H1": "BO.NGNH31.02.HNN", "H2": "BO.NGNH31.02.HNE",
                                            "V": "BO.NGNH31.02.HNZ"}
    # UD is vertical (it used to be taken for a horizontal '2'); the peak is UD2's stated
    # Max. Acc. (gmprocess's raw 0.279 m/s^2 keeps the digitiser's offset).
    stated = _stated_max_acc_gal(corpus_file(names[5])) * 0.01
    assert np.max(np.abs(surface.components["V"])) == pytest.approx(stated, abs=0.0005 * 0.01)
    with pytest.raises(ParameterError, match="matches none"):
        read_motion(files, sensor="03.HN")
    found = read_motions(tmp_path)
    assert len(found) == 2 and not found.failures
    assert {m.metadata["station"]["location"] for m in found} == {"01", "02"}


# ---------------------------------------------------------------- StationXML

def _sensitivity_only(path, directory):
    inventory = obspy.read_inventory(str(path))
    for channel in (ch for net in inventory for sta in net for ch in sta):
        channel.response.response_stages = []
    out = directory / "sensitivity_only.xml"
    inventory.write(str(out), format="STATIONXML")
    return out


def test_sensitivity_only_stationxml(tmp_path):
    files = [corpus_file(f) for f in NP1767]
    xml = corpus_file(f"{EPOCHS}/NP.1767.xml")
    stripped = _sensitivity_only(xml, tmp_path)
    full_xml = read_motion(files, inventory=xml)
    only = read_motion(files, inventory=stripped)
    for component in ("H1", "H2", "V"):
        np.testing.assert_array_equal(only.components[component], full_xml.components[component])
    fallback = read_motion(files, inventory=stripped, response="full")
    assert "no stages" in fallback.metadata["units"]["H1"]
    raw = obspy.read(str(files[0]))[0].data.astype(float)
    # 160431.975 counts/(m/s^2): the sensitivity of the epoch that holds 2021-09-30.
    np.testing.assert_allclose(fallback.components["H1"], raw / 160431.975, rtol=1e-12)


def test_channel_epoch_chosen_by_record_start():
    files = [corpus_file(f"station_xml_epochs/nc73631381_ad/{f.split('/')[-1]}") for f in NP1767]
    xml = corpus_file("station_xml_epochs/nc73631381_ad/NP.1767.xml")
    now = read_motion(files, inventory=xml)
    assert "160432 counts" in now.metadata["units"]["H1"]
    stream = obspy.Stream()
    for f in files:
        stream += obspy.read(str(f))
    for tr in stream:
        tr.stats.starttime = obspy.UTCDateTime("2005-01-01")  # the 426212 counts/(m/s^2) epoch
        tr.stats.source_file = str(f)
    old = read_motion(stream, inventory=xml)
    assert "426212 counts" in old.metadata["units"]["H1"]
    np.testing.assert_allclose(old.components["H1"] * 426212.0,
                               now.components["H1"] * 160431.975, rtol=1e-12)


def test_nanometre_input_units():
    files = [corpus_file(f"fdsn/us70008dx7/SL.KOGS..HN{c}__20200322T052358Z__20200322T052533Z.mseed")
             for c in "NEZ"]
    xml = corpus_file("fdsn/us70008dx7/SL.KOGS.xml")
    gm = read_motion(files, inventory=xml)
    sens = obspy.read_inventory(str(xml)).select(channel="HNN")[0][0][0].response
    value = sens.instrument_sensitivity.value
    assert sens.instrument_sensitivity.input_units.upper() == "NM/S**2"
    raw = obspy.read(str(files[0]))[0]
    offset = round((gm.starttime - raw.stats.starttime) / raw.stats.delta)  # common window
    expected = raw.data[offset: offset + gm.npts].astype(float) / value * 1e-9
    np.testing.assert_allclose(gm.components["H1"], expected, rtol=1e-12)


def test_velocity_sensor_needs_differentiate():
    files = [corpus_file(f"fdsn/nc51194936/BK.CVS..BH{c}__20080119T231135Z__20080119T232005Z.mseed")
             for c in "NEZ"]
    xml = corpus_file("fdsn/nc51194936/BK.CVS.xml")
    with pytest.raises(UnitsError, match="--differentiate"):
        read_motion(files, inventory=xml)
    gm = read_motion(files, inventory=xml, differentiate=True)
    assert "differentiated" in gm.metadata["units"]["H1"]
    response = obspy.read_inventory(str(xml)).select(channel="BHN")[0][0][0].response
    raw = obspy.read(str(files[0]))[0]
    velocity = raw.data.astype(float) / response.instrument_sensitivity.value
    np.testing.assert_allclose(gm.components["H1"][5:-5],
                               np.gradient(velocity, raw.stats.delta)[5:-5], rtol=1e-9, atol=1e-15)


def test_response_attached_to_stream_is_used():
    files = [corpus_file(f) for f in NP1767]
    xml = corpus_file(f"{EPOCHS}/NP.1767.xml")
    stream = obspy.Stream()
    for f in files:
        stream += obspy.read(str(f))
    stream.attach_response(obspy.read_inventory(str(xml)))
    attached = read_motion(stream)
    assert "attached to the stream" in attached.metadata["units"]["H1"]
    np.testing.assert_array_equal(attached.components["H1"],
                                  read_motion(files, inventory=xml).components["H1"])


# ---------------------------------------------------------------- SAC (Community Seismic Network)

def test_csn_sac_gravity_in_g_refused_then_read_with_units():
    files = [corpus_file(f"csn/ci38457511/20190706031952.CJ.T001230.HN{c}.sac") for c in "NEZ"]
    with pytest.raises(UnitsError, match="--units g"):
        read_motion(files)
    gm = read_motion(files, units="g")
    assert any("gravity" in note for note in gm.metadata["notes"])
    # The file's DEPMEN of the vertical (1.0026952 g) is its mean.
    assert gm.components["V"].mean() / STANDARD_GRAVITY == pytest.approx(1.0026952, rel=1e-6)
    sac = obspy.read(str(files[0]))[0]
    assert np.max(gm.components["H1"]) / STANDARD_GRAVITY == pytest.approx(sac.stats.sac.depmax,
                                                                          rel=1e-6)


# ---------------------------------------------------------------- stations with several sensors

def test_station_with_two_sensors_and_vertical_only():
    mikb = [corpus_file(f"fdsn/ci38445975/CI.MIKB..{b}N{c}.mseed") for b in "BH" for c in "NEZ"]
    xml = corpus_file("fdsn/ci38445975/CI.MIKB.xml")
    with pytest.raises(RecordError, match=r"\.BN .*\.HN|\.HN .*\.BN"):
        read_motion(mikb, inventory=xml)
    gm = read_motion(mikb, inventory=xml, sensor="HN")
    assert set(gm.metadata["channels"].values()) == {"CI.MIKB..HNN", "CI.MIKB..HNE", "CI.MIKB..HNZ"}
    sbt = corpus_file("fdsn/nc51194936/NN.SBT..SHZ__20080119T231135Z__20080119T232005Z.mseed")
    with pytest.raises(RecordError, match="only a vertical component"):
        read_motion(sbt, inventory=corpus_file("fdsn/nc51194936/NN.SBT.xml"))


# ---------------------------------------------------------------- folders and catalogues

def test_folder_with_a_bad_file_yields_the_good_records(tmp_path):
    names = [f"knet/us2000cnnl/AOM00{k}1801241951.{d}" for k in "12" for d in ("NS", "EW", "UD")]
    _copy(names, tmp_path)
    (tmp_path / "BROKEN.NS").write_bytes(b"Origin Time       2018/01/24\n\x00\x01garbage")
    (tmp_path / "event.json").write_text("{}")
    found = read_motions(tmp_path)
    assert sorted(m.metadata["station"]["station"] for m in found) == ["AOM001", "AOM002"]
    assert [f.split("/")[-1] for f, _ in found.failures] == ["BROKEN.NS"]
    assert any(p.endswith("event.json") for p in found.skipped)
    with pytest.raises(RecordError, match="holds 2 records"):
        read_motion(tmp_path)
    one = read_motion(str(tmp_path / "AOM001*"))
    assert one.metadata["station"]["station"] == "AOM001"


def test_catalogue_command_writes_a_catalogue_that_reads_back(tmp_path, capsys):
    folder = tmp_path / "records"
    folder.mkdir()
    names = [f"knet/us2000cnnl/AOM00{k}1801241951.{d}" for k in "34" for d in ("NS", "EW", "UD")]
    _copy(names, folder)
    output = tmp_path / "cat" / "catalogue.toml"
    assert main(["catalogue", str(folder), "-o", str(output), "--credit", "NIED"]) == 0
    assert "2 records written" in capsys.readouterr().out
    entries = load_catalogue(output)
    assert len(entries) == 2
    text = output.read_text()
    for entry in entries.values():
        gm = entry.read()
        table = entry.extra
        assert entry.credit == "NIED" and entry.license == ""
        for component, data in gm.components.items():
            assert table[f"pga_{component}_m_s2"] == pytest.approx(np.max(np.abs(data)), rel=1e-12)
        assert table["dt_s"] == 0.01 and table["npts"] == gm.npts
    assert "license" not in text


def test_cli_info_on_a_folder_with_sensor_flag(tmp_path, capsys):
    names = [f"kiknet/usp000hzq8/NGNH351106302345.{d}{k}" for d in ("NS", "EW", "UD") for k in "12"]
    _copy(names, tmp_path)
    assert main(["info", str(tmp_path), "--processing", "none"]) == 2
    assert "holds 2 records" in capsys.readouterr().err
    assert main(["info", *map(str, sorted(tmp_path.iterdir())), "--sensor", "01.HN",
                 "--processing", "none"]) == 0
    files = [line.split()[-1] for line in capsys.readouterr().out.splitlines()
             if line.startswith("file")]
    assert sorted(f[-3:] for f in files) == ["EW1", "NS1", "UD1"]  # the borehole sensor only


def test_negative_sensitivity_restores_polarity():
    """BK.VALB's channels have sensitivity -4279779.834 counts/(m/s^2) in the real StationXML.

    HN1 is the vertical there (dip -90), HN2 and HN3 the horizontals at 336 and 246 deg.
    """
    files = [corpus_file(f"fdsn/nc73300395/BK.VALB.40.HN{c}__20191103T203452Z__20191103T203627Z.mseed")
             for c in "123"]
    xml = corpus_file("fdsn/nc73300395/BK.VALB.xml")
    gm = read_motion(files, inventory=xml)
    response = obspy.read_inventory(str(xml)).select(channel="HN1")[0][0][0].response
    value = response.instrument_sensitivity.value
    assert value == -4279779.834
    assert gm.metadata["channels"] == {"H1": "BK.VALB.40.HN3", "H2": "BK.VALB.40.HN2",
                                       "V": "BK.VALB.40.HN1"}
    raw = obspy.read(str(files[0]))[0]
    offset = round((gm.starttime - raw.stats.starttime) / raw.stats.delta)
    np.testing.assert_allclose(gm.components["V"],
                               raw.data[offset: offset + gm.npts] / value, rtol=1e-12)
    assert "polarity is reversed" in gm.metadata["units"]["V"]


def test_structure_and_borehole_sensors_are_said():
    structure = read_motion(corpus_file("smc/nc216859/891018_1.cra-1.0210a.smc"))
    assert any("not free-field" in note for note in structure.metadata["notes"])
    files = [corpus_file(f"kiknet/usp000hzq8/NGNH311106302345.{d}1") for d in ("NS", "EW", "UD")]
    assert any("borehole" in note for note in read_motion(files).metadata["notes"])


def test_every_corpus_folder_grouped_into_records():
    """Copies and split recordings become separate records; every failure is a named reason."""
    expected = {"dmg": (10, 2), "geonet2": (6, 0), "renadic": (28, 0), "usc": (4, 0),
                "station_xml_epochs": (2, 0)}
    for folder, (records, failures) in expected.items():
        found = read_motions([corpus_file(rel) for rel in _FOLDER_FILES[folder]])
        assert (len(found), len(found.failures)) == (records, failures), (folder, found.failures)
        for motion in found:
            ids = list(motion.metadata["channels"].values())
            assert len(ids) == len(set(ids))


_FOLDER_FILES = {
    "dmg": ["dmg/ci15481673/CIWLT.RAW", "dmg/ci15481673/CIWLT.V2", "dmg/ci15481673/CIWLT.V3",
            "dmg/ci3031425/NEWPORT.RAW", "dmg/ci3031425/ce23583r_HESPERIA.RAW",
            "dmg/ci3144585/LA116TH.RAW", "dmg/nc1091100/ce36456p_CE36456.V2",
            "dmg/nc71734741/BadHeader.V2", "dmg/nc71734741/CE89146.V1",
            "dmg/nc71734741/CE89146.V2", "dmg/nc71734741/CE89146.V3",
            "dmg/nc72282711/CE58667.V2"],
    "geonet2": ["geonet2/2019p314352/20190427_072659_HCDS_20.V1A",
                "geonet2/2019p314352/20190427_072700_HNPS_20.V1A",
                "geonet2/2019p322376/20190430_064319_INHS_21.V1A",
                "geonet2/2019p322376/20190430_064339_TBAS_20.V1A",
                "geonet2/2019p323787/20190430_191422_HCDS_20.V1A",
                "geonet2/2019p323787/20190430_191422_HNPS_20.V1A"],
    "renadic": [f for f in reference_files("renadic")],
    "usc": [f"usc/ci3144585/017m30{n}" for n in ("bt.s0a", "cc.y0a", "lw.e0a", "lw.e0b", "lw.e0c",
                                                  "lw.s0a", "lw.s0b", "lw.s0c")],
    "station_xml_epochs": [f"station_xml_epochs/{d}/NP.1767{s}" for d in ("nc73631381",
                           "nc73631381_ad") for s in ("..HNE.mseed", "..HNN.mseed", "..HNZ.mseed",
                                                      ".xml")],
}


def test_folder_sensor_flag_picks_one_record(tmp_path):
    names = [f"kiknet/usp000hzq8/NGNH351106302345.{d}{k}" for d in ("NS", "EW", "UD") for k in "12"]
    _copy(names, tmp_path)
    with pytest.raises(RecordError, match="holds 2 records.*--sensor"):
        read_motion(tmp_path)
    surface = read_motion(tmp_path, sensor="02.HN")
    assert surface.metadata["channels"]["V"] == "BO.NGNH35.02.HNZ"
    with pytest.raises(RecordError, match="for sensor '03.HN'"):
        read_motion(tmp_path, sensor="03.HN")
