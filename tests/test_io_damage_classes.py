"""Damaged files whose own contents contradict the read are refused (issue 33, item 2).

Each class of damage is made here from real files (the gmprocess corpus and the files of other
projects, :mod:`tests.real_corpus`) copied into ``tmp_path`` and changed the way the reliability
campaign changed them: samples deleted or doubled, unit words replaced, a value cut short, a block
repeated, a file cut at a boundary. The expectation is the format's own statement (a header's
duration x rate, a stated unit, a stated sample count), never the result of one reading: a read
that contradicts the file is a :class:`~shipblock.errors.ShipblockError` that names the file and
the field; an undamaged copy still reads to the file's stated values.
"""

from __future__ import annotations

import re
import shutil
import tarfile
import zlib
from pathlib import Path

import numpy as np
import obspy
import pytest

from shipblock import read_motion, read_motions
from shipblock.errors import RecordError, UnitsError
from shipblock.io import read_record, screen
from tests.real_corpus import PROJECT, corpus_file, outside_file, reference_files

pytestmark = pytest.mark.filterwarnings("ignore")


def _copy(source, tmp_path, name=None):
    target = tmp_path / (name or source.name)
    shutil.copyfile(source, target)
    return target


# ------------------------------------------------------------------------------ K-NET

KNET_FILES = ["knet/us2000cnnl/AOM0011801241951.EW", "knet/usb000syza/CHB0031412312349.UD",
              "kiknet/usp000hzq8/NGNH311106302345.NS1"]
#: Header lines of a K-NET file before the samples.
KNET_HEADER_LINES = 17


def _knet_sources():
    return [("outside", "obspy/test.knet")] + [("corpus", rel) for rel in KNET_FILES]


def _knet_path(kind, rel):
    return outside_file(rel) if kind == "outside" else corpus_file(rel)


def _mutate_samples(path, where: str, change: int):
    """Delete (``change < 0``) or repeat (``change > 0``) ``|change|`` samples of a K-NET file at
    the start, middle or end of its data; return the new text."""
    lines = path.read_text().splitlines()
    head, data = lines[:KNET_HEADER_LINES], lines[KNET_HEADER_LINES:]
    row = {"start": 0, "middle": len(data) // 2, "end": len(data) - 1}[where]
    tokens = data[row].split()
    if change < 0:
        tokens = tokens[:len(tokens) + change] if len(tokens) > -change else []
    else:
        tokens = tokens + tokens[:change]
    data[row] = "".join(f"{t:>9}" for t in tokens)
    return "\n".join(head + data) + "\n"


@pytest.mark.parametrize(("kind", "rel"), _knet_sources())
@pytest.mark.parametrize("where", ["start", "middle", "end"])
@pytest.mark.parametrize("change", [-1, -3, 2])
def test_knet_missing_or_extra_samples_refused(tmp_path, kind, rel, where, change):
    """Duration x rate in the header is the sample count; a hole or a doubled value breaks it."""
    source = _knet_path(kind, rel)
    damaged = tmp_path / source.name
    damaged.write_text(_mutate_samples(source, where, change))
    with pytest.raises(RecordError, match=r"Duration Time.*\b(missing|extra)\b") as info:
        read_record(damaged)
    assert source.name in str(info.value)
    assert f"{abs(change)} samples" in str(info.value)


@pytest.mark.parametrize(("kind", "rel"), _knet_sources())
def test_knet_changed_peak_sample_refused(tmp_path, kind, rel):
    """A sample changed so that the record's peak is no longer the header's Max. Acc."""
    source = _knet_path(kind, rel)
    lines = source.read_text().splitlines()
    counts = np.array([int(t) for line in lines[KNET_HEADER_LINES:] for t in line.split()])
    offset = counts.mean()
    peak = int(np.argmax(np.abs(counts - offset)))
    counts[peak] = int(round(offset + 2.0 * (counts[peak] - offset)))  # the peak doubled
    body = ["".join(f"{c:>9d}" for c in counts[i:i + 8]) for i in range(0, counts.size, 8)]
    damaged = tmp_path / source.name
    damaged.write_text("\n".join(lines[:KNET_HEADER_LINES] + body) + "\n")
    with pytest.raises(RecordError, match="Max. Acc."):
        read_record(damaged)
    # The same rewrite without the change reads (the check is of the values, not the layout).
    undamaged = tmp_path / ("copy_" + source.name)
    original = np.array([int(t) for line in lines[KNET_HEADER_LINES:] for t in line.split()])
    body = ["".join(f"{c:>9d}" for c in original[i:i + 8]) for i in range(0, original.size, 8)]
    undamaged.write_text("\n".join(lines[:KNET_HEADER_LINES] + body) + "\n")
    assert read_record(undamaged)[0].stats.npts == original.size


# ------------------------------------------------------------------------------ ESM / AFAD

ESM_FILES = ["esm/us60004wsq/HI.ARS1..HNE.D.20190728.160908.C.ACC.ASC",
             "esm/us60004wsq/HL.DLFA..HNZ.D.20190728.160908.C.ACC.ASC"]


def _esm_key(text: str, key: str) -> str:
    return re.search(rf"^{re.escape(key)}: ?(.*)$", text, re.MULTILINE).group(1).strip()


def _esm_set(text: str, key: str, value: str) -> str:
    return re.sub(rf"^{re.escape(key)}:.*$", f"{key}: {value}", text, count=1, flags=re.MULTILINE)


@pytest.mark.parametrize("rel", ESM_FILES)
@pytest.mark.parametrize("place", ["Kahramanmaras Merkez", "PAZARCIK", "4614 Istasyonu"])
def test_afad_layout_time_and_place_name(tmp_path, rel, place):
    """AFAD's exports in the ESM layout: time written YYYY/MM/DD hh:mm:ss.ffffff, a place name
    under LOCATION. The start is the stated instant; the SEED location code stays empty."""
    text = corpus_file(rel).read_text()
    stated = _esm_key(text, "DATE_TIME_FIRST_SAMPLE_YYYYMMDD_HHMMSS")  # 20190728_160919.870
    date, time = stated.split("_")
    afad = f"{date[:4]}/{date[4:6]}/{date[6:]} {time[:2]}:{time[2:4]}:{time[4:]}000"
    text = _esm_set(_esm_set(text, "DATE_TIME_FIRST_SAMPLE_YYYYMMDD_HHMMSS", afad),
                    "LOCATION", place)
    path = tmp_path / "afad.asc"
    path.write_text(text)
    trace = read_record(path)[0]
    expected = (int(date[:4]), int(date[4:6]), int(date[6:]), int(time[:2]), int(time[2:4]))
    assert (trace.stats.starttime.year, trace.stats.starttime.month, trace.stats.starttime.day,
            trace.stats.starttime.hour, trace.stats.starttime.minute) == expected
    assert trace.stats.starttime.second + trace.stats.starttime.microsecond * 1e-6 == (
        pytest.approx(float(time[4:]), abs=1e-6))
    assert trace.stats.location == ""
    assert any(place in note for note in trace.stats.shipblock_esm.notes)


@pytest.mark.parametrize("rel", ESM_FILES)
@pytest.mark.parametrize("written", ["28/07/2019 16:09:19", "yesterday", "2019-13-45T00:00:00"])
def test_esm_unreadable_start_time_refused(tmp_path, rel, written):
    """A first-sample time in no known layout is refused by key, not read as 1970."""
    path = tmp_path / "esm.asc"
    path.write_text(_esm_set(corpus_file(rel).read_text(),
                             "DATE_TIME_FIRST_SAMPLE_YYYYMMDD_HHMMSS", written))
    with pytest.raises(RecordError, match="DATE_TIME_FIRST_SAMPLE_YYYYMMDD_HHMMSS"):
        read_record(path)


@pytest.mark.parametrize("rel", ESM_FILES)
@pytest.mark.parametrize("factor", [0.8, 2.0, 0.5, 1.1])
def test_esm_interval_against_duration(tmp_path, rel, factor):
    """SAMPLING_INTERVAL_S changed: NDATA x interval is no longer DURATION_S."""
    text = corpus_file(rel).read_text()
    interval = float(_esm_key(text, "SAMPLING_INTERVAL_S"))
    path = tmp_path / "esm.asc"
    path.write_text(_esm_set(text, "SAMPLING_INTERVAL_S", f"{interval * factor:.6f}"))
    with pytest.raises(RecordError, match="DURATION_S"):
        read_record(path)
    # DURATION_S changed to match: the file no longer contradicts itself and is read.
    ndata = int(_esm_key(text, "NDATA"))
    path.write_text(_esm_set(path.read_text(), "DURATION_S", f"{ndata * interval * factor:.3f}"))
    assert read_record(path)[0].stats.delta == pytest.approx(interval * factor)


# ------------------------------------------------------------------------------ COSMOS

COSMOS_FILES = ["cosmos/ftbragg/NP1795-n.305.v0c", "cosmos/ci14155260/Cosmos12TimeSeriesTest.v1",
                "cosmos/us1000hyfh/us1000hyfh_akbmrp_AKBMR--n.1000hyfh.BNZ.--.acc.V2c"]
_COSMOS_DATA_LINE = re.compile(r"^(\s*\d+\s+(?:raw\s+)?acc[\w.]*\s+pts,\s*approx\s+)(\d+)(\s+secs)",
                               re.IGNORECASE | re.MULTILINE)
_COSMOS_END = re.compile(r"^(?:/&|End-of-data).*$", re.IGNORECASE | re.MULTILINE)


def _cosmos_blocks(text: str) -> list[str]:
    """The channel blocks of a COSMOS file, each up to and with its end-of-data line."""
    ends = [m.end() for m in _COSMOS_END.finditer(text)]
    return [text[a:b].lstrip("\n") for a, b in zip([0, *ends[:-1]], ends, strict=True)]


@pytest.mark.parametrize("rel", COSMOS_FILES)
@pytest.mark.parametrize("factor", [0.5, 0.8, 1.25, 2.0])
def test_cosmos_interval_against_approx_secs(tmp_path, rel, factor):
    """The 'approx N secs' of every acceleration data line, changed: the samples x Real(62) no
    longer span it (the same as a damaged interval)."""
    text = corpus_file(rel).read_text()
    stated = [int(m.group(2)) for m in _COSMOS_DATA_LINE.finditer(text)]
    assert stated, rel
    damaged = _COSMOS_DATA_LINE.sub(
        lambda m: f"{m.group(1)}{round(int(m.group(2)) * factor)}{m.group(3)}", text)
    path = tmp_path / corpus_file(rel).name
    path.write_text(damaged)
    with pytest.raises(RecordError, match="approx"):
        read_record(path)
    path.write_text(text)
    stream = read_record(path)
    assert abs(stream[0].stats.npts * stream[0].stats.delta - stated[0]) <= 1.0 + 0.01 * stated[0]


@pytest.mark.parametrize("rel", COSMOS_FILES)
@pytest.mark.parametrize("where", ["after", "end"])
def test_cosmos_duplicated_block_refused(tmp_path, rel, where):
    """A channel block written twice is one channel, not a second horizontal."""
    text = corpus_file(rel).read_text()
    blocks = _cosmos_blocks(text)
    repeated = blocks[:1] + blocks[:1] + blocks[1:] if where == "after" else blocks + blocks[:1]
    path = tmp_path / corpus_file(rel).name
    path.write_text("\n".join(b.rstrip("\n") for b in repeated) + "\n")
    with pytest.raises(RecordError, match="repeats") as info:
        read_record(path)
    assert path.name in str(info.value)
    path.write_text("\n".join(b.rstrip("\n") for b in blocks) + "\n")
    assert len(read_record(path)) == len(blocks)


# ------------------------------------------------------------------------------ PEER AT2

AT2_FILES = ["loma/RSN753_LOMAP_CLS000.AT2", "pyrotd/RSN8883_14383980_13849090.AT2",
             "pyrotd/RSN8884_14383980_13873360.AT2"]
G = 9.80665  # standard gravity [m/s^2]


def _at2_lines(rel):
    return outside_file(rel).read_text().splitlines()


def _at2_values(lines) -> np.ndarray:
    return np.array([float(v) for line in lines[4:] for v in line.split()])


@pytest.mark.parametrize("rel", AT2_FILES)
@pytest.mark.parametrize(("word", "factor", "refused"), [
    ("CM/S", None, "velocity"), ("CM/SEC", None, "velocity"), ("CM", None, "displacement"),
    ("IN", None, "displacement"), ("FOO", None, "unknown acceleration unit"),
    ("XYZ/Q", None, "unknown acceleration unit"), ("MILLI-G", 1e-3 * G, None),
    ("CM/S2", 0.01, None), ("G", G, None), ("ROTATED", G, None), ("HP=0.1 HZ LP=25 HZ", G, None),
])
def test_at2_unit_word_in_parentheses(tmp_path, rel, word, factor, refused):
    """The units line's word in parentheses is the unit: converted, or refused; never g
    unless it says g (or is a processing word or a phrase, which state no unit)."""
    lines = _at2_lines(rel)
    lines[2] = f"ACCELERATION TIME SERIES ({word})"
    path = tmp_path / "x.AT2"
    path.write_text("\n".join(lines) + "\n")
    if refused:
        with pytest.raises(UnitsError, match=refused):
            read_record(path)
        return
    np.testing.assert_allclose(read_record(path)[0].data, _at2_values(lines) * factor, rtol=1e-12)


@pytest.mark.parametrize("rel", AT2_FILES)
def test_at2_decimal_comma_in_dt_refused(tmp_path, rel):
    """``DT= 1,5`` was read as DT = 1 s; every DT written with a comma is refused."""
    lines = _at2_lines(rel)
    stated = re.search(r"DT=\s*([\d.]+)", lines[3]).group(1)
    for comma in (stated.replace(".", ","), "1,5", "0,005"):
        lines[3] = re.sub(r"DT=\s*[\d.]+", f"DT= {comma}", _at2_lines(rel)[3])
        path = tmp_path / "comma.AT2"
        path.write_text("\n".join(lines) + "\n")
        with pytest.raises(RecordError, match="decimal comma"):
            read_record(path)


@pytest.mark.parametrize("rel", AT2_FILES)
@pytest.mark.parametrize("cut", [1, 2, 3, 4, 6])
def test_at2_last_value_cut_short_refused(tmp_path, rel, cut):
    """The file cut inside its last value: the count still matches, the value does not."""
    text = outside_file(rel).read_text().rstrip()
    path = tmp_path / "cut.AT2"
    path.write_text(text[:-cut] + "\n")
    last = text[:-cut].split()[-1]
    if re.fullmatch(r"[-+]?\.?", last):
        return  # the cut left no digit: one value fewer, the count check refuses it
    with pytest.raises(RecordError, match=r"cut short|truncated|not a number"):
        read_record(path)
    path.write_text(text + "\n")
    assert read_record(path)[0].stats.npts == _at2_values(text.splitlines()).size


# ------------------------------------------------------------------------------ CSMIP (DMG)

DMG_FILES = [("outside", "readv2/ce89486SampleInput.v2"), ("corpus", "dmg/ci15481673/CIWLT.V2"),
             ("corpus", "dmg/nc72282711/CE58667.V2"), ("corpus", "dmg/ci3144585/LA116TH.RAW"),
             ("corpus", "dmg/nc71734741/CE89146.V1")]
_DMG_TITLE = re.compile(r"^(Corrected accelerogram|Uncorrected accelerogram data)", re.IGNORECASE)


def _dmg_blocks(text: str) -> list[list[str]]:
    lines = text.split("\n")
    title = "CORRECTED ACCELEROGRAM" if lines[0].upper().startswith("CORRECTED") else "UNCORRECTED"
    starts = [i for i, line in enumerate(lines) if line.upper().startswith(title)]
    return [lines[a:b] for a, b in zip(starts, [*starts[1:], len(lines)], strict=True)]


@pytest.mark.parametrize(("kind", "rel"), DMG_FILES)
def test_dmg_cut_at_a_channel_boundary_refused(tmp_path, kind, rel):
    """Two of three channels (the file cut after a whole channel) contradict the header's channel
    count; one channel alone is a channel file and is read."""
    source = outside_file(rel) if kind == "outside" else corpus_file(rel)
    blocks = _dmg_blocks(source.read_text(errors="replace"))
    assert len(blocks) == 3, rel
    path = tmp_path / source.name
    path.write_text("\n".join(line for block in blocks[:2] for line in block).rstrip("\n") + "\n")
    with pytest.raises(RecordError, match="cut at a channel boundary") as info:
        read_record(path)
    assert "states 3" in str(info.value)
    path.write_text("\n".join(blocks[0]).rstrip("\n") + "\n")
    assert len(read_record(path)) == 1


# ------------------------------------------------------------------------------ plain text

def _loma_g() -> np.ndarray:
    """Loma Prieta, Corralitos 000 (PEER AT2, in g): the samples put into text files below."""
    lines = outside_file("loma/RSN753_LOMAP_CLS000.AT2").read_text().splitlines()
    return np.array([float(v) for line in lines[4:] for v in line.split()])


@pytest.mark.parametrize("where", [1, 0.5, -2])
def test_text_blank_line_in_one_column_refused(tmp_path, where):
    """A blank line among one column of samples (a sample lost?) is refused, by line number."""
    values = _loma_g()
    rows = [f"{v:.7e}" for v in values]
    at = int(where * len(rows)) if isinstance(where, float) else where % len(rows)
    path = tmp_path / "one.txt"
    path.write_text("# acceleration (g)\n" + "\n".join(rows[:at] + [""] + rows[at:]) + "\n")
    with pytest.raises(RecordError, match=rf"line {at + 2} is blank between samples"):
        read_record(path, format="SHIPBLOCK_TEXT", dt=0.005)
    path.write_text("# acceleration (g)\n" + "\n".join(rows) + "\n\n\n")  # blank lines at the end
    np.testing.assert_allclose(read_record(path, format="SHIPBLOCK_TEXT", dt=0.005)[0].data,
                               values * 9.80665, rtol=1e-7)
    two = tmp_path / "two.csv"  # two columns: the time column tells a blank line is no sample
    rows2 = [f"{k * 0.005:.3f},{v:.7e}" for k, v in enumerate(values)]
    two.write_text("# time (s), acceleration (g)\n" + "\n".join(rows2[:at] + [""] + rows2[at:]))
    assert read_record(two)[0].stats.npts == values.size


@pytest.mark.parametrize(("header", "units", "refused"), [
    ("# time (s), accel (g)\n# units: cm/s^2", None, "contradictory units"),
    ("# accel (g) [gal]", None, "contradictory units"),
    ("# time (s), accel (gal)", "g", "contradicts"),
    ("# time (s), velocity (cm/s)", "g", "contradicts"),
    ("# time (s), accel (cm/s)", None, "calls the samples acceleration.*--units"),
    ("# time (s), accel (cm/s)", "g", None),  # a self-contradicting header: the caller decides
    ("# time (s), accel (m/s^2)", "cm/s", "contradicts"),
    ("# time (s), accel (cm/s^2)\n# units: gal", None, None),
    ("# time (s), accel (gal)", "cm/s^2", None),
    ("# PGV (cm/s) = 12.3\n# time (s), accel (g)", None, None),
])
def test_text_unit_words_must_agree(tmp_path, header, units, refused):
    """Unit statements of one file (header lines, the caller's units=) must name one unit."""
    values = _loma_g()[:400]
    path = tmp_path / "rec.csv"
    path.write_text(header + "\n" + "\n".join(f"{k * 0.005:.3f},{v:.7e}"
                                              for k, v in enumerate(values)) + "\n")
    if refused:
        with pytest.raises(UnitsError, match=refused):
            read_record(path, format="SHIPBLOCK_TEXT", units=units)
        return
    trace = read_record(path, format="SHIPBLOCK_TEXT", units=units)[0]
    factor = 9.80665 if "(g)" in header or units == "g" else 0.01
    np.testing.assert_allclose(trace.data, values * factor, rtol=1e-7)


def test_text_velocity_unit_given_is_differentiated(tmp_path):
    """One column of velocity with units='cm/s' reads (issue 31: 'unknown acceleration unit
    cm/s'); read_motion differentiates it when asked to, and says which flag otherwise."""
    t = np.arange(2000) * 0.005
    velocity_cm_s = 10.0 * np.sin(2 * np.pi * 1.0 * t)
    path = tmp_path / "vel.txt"
    path.write_text("\n".join(f"{v:.9e}" for v in velocity_cm_s) + "\n")
    motion = read_motion(path, units="cm/s", dt=0.005, differentiate=True)
    # d/dt of 0.1 sin(2 pi t) m/s is 0.2 pi cos(2 pi t) m/s^2 (central differences: O(dt^2)).
    inner = slice(1, -1)
    np.testing.assert_allclose(motion.horizontal[inner],
                               0.2 * np.pi * np.cos(2 * np.pi * t[inner]), atol=2e-4)
    with pytest.raises(UnitsError, match="--differentiate"):
        read_motion(path, units="cm/s", dt=0.005)


# ------------------------------------------------------------------------------ MiniSEED / SEED

NAPA = [f"records/south-napa-2014/NP.{s}.mseed" for s in ("1737", "1765")]


def _blockette_1000(raw: bytes, pos: int) -> int:
    """Offset in the file of the blockette 1000 of the record at ``pos`` (big-endian headers)."""
    offset = int.from_bytes(raw[pos + 46:pos + 48], "big")
    while offset:
        kind = int.from_bytes(raw[pos + offset:pos + offset + 2], "big")
        if kind == 1000:
            return pos + offset
        offset = int.from_bytes(raw[pos + offset + 2:pos + offset + 4], "big")
    raise AssertionError("no blockette 1000")


@pytest.mark.parametrize("rel", NAPA)
@pytest.mark.parametrize("record", [0, 3, -1])
@pytest.mark.parametrize("encoding", [1, 3, 4])
def test_mseed_encoding_byte_changed_refused(tmp_path, rel, record, encoding):
    """Steim-2 records whose encoding byte says INT16/INT32/FLOAT32 decode to wrong numbers;
    the Steim frames' own integration constants show it."""
    raw = bytearray((PROJECT / rel).read_bytes())
    length = 2 ** raw[_blockette_1000(raw, 0) + 6]
    pos = (record % (len(raw) // length)) * length
    b1000 = _blockette_1000(raw, pos)
    assert raw[b1000 + 4] == 11  # Steim-2 as written
    raw[b1000 + 4] = encoding
    path = tmp_path / "changed.mseed"
    path.write_bytes(bytes(raw))
    with pytest.raises(RecordError, match=rf"record at byte {pos} .*(STEIM2|damaged)|damaged"):
        read_record(path)


def test_mseed_plain_encodings_still_read(tmp_path):
    """Records really written as INT16, INT32, FLOAT32, FLOAT64 are not taken for Steim."""
    stream = read_record(PROJECT / NAPA[0])
    for encoding, dtype in (("INT16", np.int16), ("INT32", np.int32), ("FLOAT32", np.float32),
                            ("FLOAT64", np.float64)):
        copy = stream.copy()
        for trace in copy:
            trace.data = np.clip(trace.data, -30000, 30000).astype(dtype)
        path = tmp_path / f"{encoding}.mseed"
        copy.write(str(path), format="MSEED", encoding=encoding, reclen=4096)
        back = read_record(path)
        for a, b in zip(back, copy, strict=True):
            np.testing.assert_array_equal(a.data, b.data)


def _obspy_test_file(*parts):

    path = Path(obspy.__file__).parent.joinpath(*parts)
    if not path.is_file():
        pytest.skip(f"obspy's test data {path.name} not installed")
    return path


def test_full_seed_volume_read_with_its_own_response():
    """A full SEED volume (control headers V, A, S, T before the data) is read, not refused as
    damaged; its own response converts the counts (obspy's arclink_full.seed)."""
    path = _obspy_test_file("io", "xseed", "tests", "data", "arclink_full.seed")
    stream = read_record(path)
    plain = obspy.read(str(path))
    assert [tr.id for tr in stream] == [tr.id for tr in plain]
    np.testing.assert_array_equal(stream[0].data, plain[0].data)
    assert stream[0].stats.seed_volume.control_header_bytes == 4 * 4096
    expected = obspy.read_inventory(str(path), format="SEED").get_response(
        stream[0].id, stream[0].stats.starttime)
    assert stream[0].stats.response.instrument_sensitivity.value == (
        expected.instrument_sensitivity.value)


def test_full_seed_volume_cut_short_still_refused(tmp_path):
    """Counting the control headers does not hide a data record cut short."""
    path = _obspy_test_file("io", "xseed", "tests", "data", "arclink_full.seed")
    raw = path.read_bytes()
    for cut in (100, 2000):
        damaged = tmp_path / "cut.seed"
        damaged.write_bytes(raw[:-cut])
        with pytest.raises(RecordError, match="damaged|truncated|cannot be read"):
            read_record(damaged)


def test_telemetry_volume_header_counted():
    """A telemetry volume (blockette 008, 512-byte records: obspy's RJOB fullseed) is read; obspy
    cannot parse its metadata, which is said."""
    path = _obspy_test_file("io", "mseed", "tests", "data", "RJOB.BW.EHZ.D.300806.0000.fullseed")
    with pytest.warns(UserWarning, match="full SEED volume"):
        stream = read_record(path)
    assert stream[0].stats.seed_volume.control_header_bytes == 512


# ------------------------------------------------------------------------------ folders: junk, links

def _real_records():
    """Real records of many formats (each must pass the large-file screen)."""
    return [PROJECT / "records/south-napa-2014/NP.1737.mseed", outside_file("obspy/test.knet"),
            outside_file("loma/RSN753_LOMAP_CLS000.AT2"), outside_file(FERNDALE_REL),
            corpus_file("cosmos/ftbragg/NP1795-n.305.v0c"),
            corpus_file("esm/us60004wsq/HI.ARS1..HNE.D.20190728.160908.C.ACC.ASC")]


FERNDALE_REL = "readv2/ce89486SampleInput.v2"


@pytest.mark.parametrize("junk", ["zeros", "random", "text", "almost_seed", "almost_sac"])
def test_large_junk_refused_before_obspy_sniffs(tmp_path, monkeypatch, junk):
    """A large file that is no record is refused from its first bytes: obspy's archive sniffing
    (tarfile.is_tarfile scans zeros to the end) and detectors are never reached. The screen's
    threshold is lowered here so the files stay small; real records above it still read."""


    monkeypatch.setattr(screen, "SCREEN_BYTES", 100_000)
    rng = np.random.default_rng(33)
    size = 300_000
    content = {
        "zeros": bytes(size),
        "random": rng.integers(0, 256, size, dtype=np.uint8).tobytes(),
        "text": (b"lorem ipsum dolor sit amet, consectetur\n" * (size // 40)),
        "almost_seed": b"00000XD " + bytes(size),  # a letter among the sequence digits
        "almost_sac": struct_sac_header(npts=123) + bytes(size),  # size is not 632 + 4 x NPTS
    }[junk]
    path = tmp_path / "junk.dat"
    path.write_bytes(content)

    def sniffed(*args, **kwargs):
        raise AssertionError("obspy's archive sniffing was reached")

    monkeypatch.setattr(tarfile, "is_tarfile", sniffed)
    with pytest.raises(RecordError, match="unknown format.*--format"):
        read_record(path)
    monkeypatch.undo()  # obspy's sniffing back, for the real records
    monkeypatch.setattr(screen, "SCREEN_BYTES", 1000)  # every real record is "large" now
    for record in _real_records():
        assert len(read_record(record)) >= 1, record


def struct_sac_header(npts: int) -> bytes:
    """A 632-byte SAC header (little-endian) with ``npts`` in word 79."""
    header = bytearray(632)
    header[316:320] = int(npts).to_bytes(4, "little", signed=True)
    return bytes(header)


def test_folder_names_broken_links_and_junk(tmp_path, monkeypatch):
    """A folder with a broken symbolic link and a junk file: both named among the failures, the
    record read."""
    monkeypatch.setattr(screen, "SCREEN_BYTES", 100_000)
    record = _copy(outside_file("loma/RSN753_LOMAP_CLS000.AT2"), tmp_path)
    (tmp_path / "gone.AT2").symlink_to(tmp_path / "nowhere" / "gone.AT2")
    (tmp_path / "junk.bin").write_bytes(bytes(200_000))
    found = read_motions(tmp_path)
    assert len(found) == 1 and found.motions[0].npts == 7995
    reasons = dict(found.failures)
    assert "broken symbolic link" in reasons[str(tmp_path / "gone.AT2")]
    assert "unknown format" in reasons[str(tmp_path / "junk.bin")]
    assert record.exists()


def test_broadband_platform_three_components():
    """pyrotd's accel_ts.bbp (SCEC broadband platform: time and NS, EW, UD columns; its header
    says 'Acceleration ... in units of cm/s'): refused as contradictory without units=, read as
    three components with it, each column in order."""
    path = outside_file("pyrotd/accel_ts.bbp")
    with pytest.raises(UnitsError, match="contradictory.*--units"):
        read_record(path)
    stream = read_record(path, units="cm/s^2")
    table = np.loadtxt(path, delimiter=",", comments="#")
    assert [tr.stats.channel for tr in stream] == ["HNN", "HNE", "HNZ"]
    assert [tr.stats.get("azimuth") for tr in stream] == [0.0, 90.0, None]
    for column, trace in enumerate(stream, start=1):
        np.testing.assert_allclose(trace.data, table[:, column] * 0.01, rtol=1e-12)
        assert trace.stats.delta == pytest.approx(table[1, 0] - table[0, 0])


@pytest.mark.parametrize("rel", reference_files("knet") + reference_files("kiknet"))
def test_knet_every_corpus_file_line_lost_or_doubled(tmp_path, rel):
    """Every K-NET/KiK-net file of the corpus with a data line dropped, then doubled, at a
    place drawn from a generator seeded by the file name: refused both ways; intact, read."""
    source = corpus_file(rel)
    lines = source.read_text().splitlines()
    rng = np.random.default_rng(zlib.crc32(rel.encode()))
    row = int(rng.integers(KNET_HEADER_LINES, len(lines) - 1))
    path = tmp_path / source.name
    for damaged in (lines[:row] + lines[row + 1:], lines[:row + 1] + lines[row:]):
        path.write_text("\n".join(damaged) + "\n")
        with pytest.raises(RecordError, match="Duration Time"):
            read_record(path)
    path.write_text("\n".join(lines) + "\n")
    assert read_record(path)[0].stats.npts == sum(len(x.split()) for x in lines[KNET_HEADER_LINES:])


def test_at2_free_format_values_not_taken_for_cut(tmp_path):
    """Values in free format (digits varying: '0.0', '0.0012') are no fixed format to check."""
    values = _at2_values(_at2_lines(AT2_FILES[0]))[:500]
    rows = ["0.0"] * 5 + [repr(round(float(v), 6)) for v in values[5:]]
    lines = _at2_lines(AT2_FILES[0])[:4]
    lines[3] = "NPTS=    500, DT=   .0050 SEC"
    path = tmp_path / "free.AT2"
    path.write_text("\n".join(lines + [" ".join(rows[k:k + 5]) for k in range(0, 500, 5)]) + "\n")
    data = read_record(path)[0].data
    np.testing.assert_allclose(data[5:] / 9.80665, [float(r) for r in rows[5:]], rtol=1e-12)
