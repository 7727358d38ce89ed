"""Tests of the shipped record catalogue (records/catalogue.toml) and shipblock.records.catalogue.

Reference values: PGA table of records/south-napa-2014/README.md (2014 South Napa Mw 6.0, USGS
NSMP network NP, event nc72282711): PGA after ``detrend('demean')`` and ``remove_sensitivity``
with each station's StationXML, max |a| over the whole record [m/s^2].
"""

from __future__ import annotations

import hashlib

import numpy as np
import pytest

from shipblock.records.catalogue import default_catalogue_path, load_catalogue
from shipblock.errors import RecordError
from shipblock.records.motion import COMPONENT_KEY

#: README table "PGA of each component" [m/s^2]: station -> (H1 = HNN, H2 = HNE, V = HNZ).
README_PGA = {
    "1737": (0.1359, 0.1576, 0.1011),
    "1743": (0.7035, 0.3433, 0.2358),
    "1759": (1.3379, 3.2407, 0.5737),
    "1764": (1.0194, 0.6377, 0.3135),
    "1765": (4.0537, 4.2012, 3.1614),
    "1768": (0.5342, 0.4892, 0.1531),
}

#: README "Stations" table: station -> npts (all 200 samples/s).
README_NPTS = {"1737": 33000, "1743": 15800, "1759": 14800, "1764": 15400, "1765": 42000,
               "1768": 90000}


def test_catalogue_lists_the_six_napa_stations():
    entries = load_catalogue()
    stations = sorted(e.station for e in entries.values())
    assert stations == sorted(README_PGA)
    for entry in entries.values():
        assert entry.credit == "USGS National Strong Motion Project"
        assert "public domain" in entry.license.lower()
        assert entry.components == {"HNN": "H1", "HNE": "H2", "HNZ": "V"}
        assert entry.inventory.is_file() and entry.event.is_file()
        assert all(p.is_file() for p in entry.files)


def test_shipped_files_are_the_archived_ones():
    """sha256 of NP.1765.mseed from the README checksum table."""
    entry = load_catalogue()["south-napa-2014/NP.1765"]
    digest = hashlib.sha256(entry.files[0].read_bytes()).hexdigest()
    assert digest == "98eb3e252ec63ba92a07fea405d832fcf3b1fc46f97ffb6650d5082da0b8ad06"


@pytest.mark.parametrize("station", sorted(README_PGA))
def test_pga_matches_readme_table(station):
    gm = load_catalogue()[f"south-napa-2014/NP.{station}"].read()
    assert gm.dt == pytest.approx(0.005)
    assert gm.npts == README_NPTS[station]
    st = gm.stream.copy()
    st.detrend("demean")
    pga = {tr.stats[COMPONENT_KEY]: float(np.abs(tr.data).max()) for tr in st}
    for component, expected in zip(("H1", "H2", "V"), README_PGA[station], strict=True):
        assert pga[component] == pytest.approx(expected, rel=5e-3), (station, component)
    assert gm.metadata["catalogue"]["credit"] == "USGS National Strong Motion Project"
    assert gm.metadata["event"]["id"].endswith("nc72282711")


def test_default_path_is_the_repository_catalogue():
    assert default_catalogue_path().name == "catalogue.toml"
    assert default_catalogue_path().parent.name == "records"


def test_bad_catalogues(tmp_path):
    with pytest.raises(RecordError, match="not found"):
        load_catalogue(tmp_path / "missing.toml")
    bad = tmp_path / "bad.toml"
    bad.write_text("[[record]\n")
    with pytest.raises(RecordError, match="bad.toml.*not valid TOML"):
        load_catalogue(bad)
    lacking = tmp_path / "lacking.toml"
    lacking.write_text('[[record]]\nid = "x"\nfiles = ["a.mseed"]\n')
    with pytest.raises(RecordError, match="lacks station$"):
        load_catalogue(lacking)
    absent = tmp_path / "absent.toml"
    absent.write_text('[[record]]\nid = "x"\nfiles = ["a.mseed"]\nstation = "S"\n'
                      'license = "PD"\ncredit = "me"\n')
    with pytest.raises(RecordError, match="'a.mseed' does not exist"):
        load_catalogue(absent)
