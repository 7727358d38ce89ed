"""Every real corpus file is recognised as its own format, by exactly one detector.

obspy tries the plug-ins' ``isFormat`` functions one after another and takes the first that says
yes, so two detectors that both accept a file would make the format depend on entry-point order.
Files: the gmprocess test corpus (tests/real_corpus.py; skipped where absent, a failure in CI).
"""

from __future__ import annotations

import warnings

import pytest

from shipblock.errors import RecordError
from shipblock.io import FORMATS, read_record
from tests.real_corpus import REFERENCE, corpus_file

#: Corpus folder -> the format its files are read as (obspy's own name for K-NET and SAC).
FOLDER_FORMATS = {
    "bhrc": "SHIPBLOCK_BHRC", "cosmos": "SHIPBLOCK_COSMOS", "csn": "SAC", "cwb": "SHIPBLOCK_CWB",
    "dmg": "SHIPBLOCK_DMG", "esm": "SHIPBLOCK_ESM", "geonet": "SHIPBLOCK_GEONET",
    "geonet2": "SHIPBLOCK_GEONET", "kiknet": "KNET", "knet": "KNET", "nsmn": "SHIPBLOCK_NSMN",
    "renadic": "SHIPBLOCK_RENADIC", "smc": "SHIPBLOCK_SMC", "unam": "SHIPBLOCK_UNAM",
    "usc": "SHIPBLOCK_USC", "peer": "SHIPBLOCK_AT2", "station_xml_epochs": "MSEED",
}

#: Files that are refused on purpose, with the reason's words.
REFUSED = {
    "dmg/ci15481673/CIWLT.V3": "response spectra",
    "dmg/nc71734741/CE89146.V3": "response spectra",
    "cosmos/ci14155260/Cosmos12TimeSeriesTest2.v1": "contradictory",
}

FILES = sorted(f for f in REFERENCE if f.split("/")[0] in FOLDER_FORMATS)


@pytest.mark.parametrize("relpath", FILES)
def test_detected_by_exactly_its_own_format(relpath):
    path = corpus_file(relpath)
    expected = FOLDER_FORMATS[relpath.split("/")[0]]
    accepted = [name for name, (detect, _) in FORMATS.items()
                if name != "SHIPBLOCK_TEXT" and detect(path)]
    assert accepted == ([expected] if expected.startswith("SHIPBLOCK_") else []), accepted
    if relpath in REFUSED:
        with pytest.raises(RecordError, match=REFUSED[relpath]):
            read_record(path)
        return
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        stream = read_record(path)  # obspy.read's own detection, through the entry points
    assert {trace.stats._format for trace in stream} == {expected}
