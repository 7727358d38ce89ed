"""Units and absurd numbers where they enter the readers (issue 23, items 3 and 4).

PEER AT2: the unit word after ``UNITS OF`` in header line 3 is converted with exact factors
(g = 9.80665 m/s^2 by definition, 1 in = 0.0254 m, 1 ft = 0.3048 m, milli = 1e-3, % = 1e-2) or,
when it is not an acceleration unit, refused with the word and the file. The older text readers
(AT2, COSMOS, ESM, plain text) refuse a sampling interval outside 1e-4..1 s and samples above
100 g, as the newer ones do. Files are the synthetic ones of ``tests/data`` and the COSMOS/ESM
texts of :mod:`tests.test_io_formats`, with one header field or sample changed.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from shipblock.errors import RecordError, UnitsError
from shipblock.io.at2 import read_at2
from shipblock.io.cosmos import read_cosmos
from shipblock.io.esm import read_esm
from shipblock.io.text import read_text_record
from shipblock.records.reading import read_motion
from tests.test_io_formats import H1_CM, _cosmos_block, _esm_text

DATA = Path(__file__).parent / "data"
G = 9.80665  # standard gravity [m/s^2] (exact by definition)
HELENA_180_G = np.array([0.1, -0.2, 0.05, 0.0, -0.01, 0.02, 0.003])  # samples of the file
UNITS_LINE = "ACCELERATION TIME SERIES IN UNITS OF G"


def _at2(tmp_path, name="x.AT2", units_line=UNITS_LINE, dt_line=None, scale=1.0) -> Path:
    lines = (DATA / "helena_synthetic_180.AT2").read_text().splitlines()
    lines[2] = units_line
    if dt_line is not None:
        lines[3] = dt_line
    if scale != 1.0:
        values = HELENA_180_G * scale
        lines[4:] = ["".join(f"{v:15.7E}" for v in values[k:k + 5]) for k in range(0, 7, 5)]
    path = tmp_path / name
    path.write_text("\n".join(lines) + "\n")
    return path


# ------------------------------------------------------------------------------ AT2 unit words


@pytest.mark.parametrize(
    ("word", "factor"),
    [
        ("G", G), ("G'S", G), ("MG", 1e-3 * G), ("G/100", 0.01 * G), ("%G", 0.01 * G),
        ("G/10", 0.1 * G), ("GAL", 0.01), ("CM/S2", 0.01), ("CM/S^2", 0.01), ("CM/S**2", 0.01),
        ("CM/SEC/SEC", 0.01), ("CM/SEC2", 0.01), ("MM/S2", 1e-3), ("M/S2", 1.0), ("M/S/S", 1.0),
        ("KM/S2", 1000.0), ("IN/S2", 0.0254), ("IN/SEC/SEC", 0.0254), ("FT/S^2", 0.3048),
        ("FT/S2", 0.3048), ("ft/sec**2", 0.3048),
    ],
)
def test_at2_unit_words_converted(tmp_path, word, factor):
    trace = read_at2(_at2(tmp_path, units_line=f"ACCELERATION TIME SERIES IN UNITS OF {word}"))[0]
    np.testing.assert_allclose(trace.data, HELENA_180_G * factor, rtol=1e-12)
    assert trace.stats.shipblock_at2.units_stated_in_header


def test_at2_milli_g_is_not_g(tmp_path):
    """Issue 23: MG was read as g, 1000 times too high."""
    gm = read_motion(_at2(tmp_path, units_line="ACCELERATION TIME SERIES IN UNITS OF MG"))
    assert np.max(np.abs(gm.horizontal)) == pytest.approx(0.2e-3 * G, rel=1e-12)


@pytest.mark.parametrize(
    ("word", "message"),
    [
        ("CM", r"gives the unit 'CM', a length \(displacement\): not an acceleration"),
        ("IN", r"gives the unit 'IN', a length"),
        ("CM/S", r"gives the unit 'CM/S', a velocity: not an acceleration"),
        ("FT/SEC", r"gives the unit 'FT/SEC', a velocity"),
        ("FURLONGS", r"unknown acceleration unit 'FURLONGS'"),
        ("G/0", r"unknown acceleration unit 'G/0'"),
        ("KG", r"unknown acceleration unit 'KG'"),
    ],
)
def test_at2_unit_words_refused(tmp_path, word, message):
    path = _at2(tmp_path, "word.AT2", units_line=f"ACCELERATION TIME SERIES IN UNITS OF {word}")
    with pytest.raises(UnitsError, match=r"word\.AT2: .*" + message):
        read_at2(path)


def test_at2_velocity_and_displacement_files_refused(tmp_path):
    for line in ("VELOCITY TIME SERIES IN UNITS OF CM/S", "DISPLACEMENT TIME SERIES IN UNITS OF CM"):
        with pytest.raises(UnitsError, match=r"v\.AT2: holds .* not an acceleration time series"):
            read_at2(_at2(tmp_path, "v.AT2", units_line=line))


def test_at2_unit_in_parentheses_or_none(tmp_path):
    stated = read_at2(_at2(tmp_path, units_line="ACCELERATION TIME HISTORY (CM/S2)"))[0]
    np.testing.assert_allclose(stated.data, HELENA_180_G * 0.01, rtol=1e-12)
    # Words in parentheses that are no unit are not a unit statement; AT2 means g.
    bare = read_at2(_at2(tmp_path, units_line="ACCELERATION TIME HISTORY (ROTATED). FILTERED"))[0]
    np.testing.assert_allclose(bare.data, HELENA_180_G * G, rtol=1e-12)
    assert not bare.stats.shipblock_at2.units_stated_in_header


def test_at2_units_given_must_agree_with_the_header(tmp_path):
    path = _at2(tmp_path, "pct.AT2", units_line="ACCELERATION TIME SERIES IN UNITS OF %G")
    with pytest.raises(UnitsError, match=r"pct\.AT2: units='g' contradicts the file's own unit"
                                         r" '%g'"):
        read_motion(path, units="g")


# ------------------------------------------------------------------------------ absurd numbers


@pytest.mark.parametrize("dt", ["1e-320", "0.0", "-.0100", "5.0", "1E-5", "1e999"])
def test_at2_absurd_dt_refused(tmp_path, dt):
    path = _at2(tmp_path, "dt.AT2", dt_line=f"NPTS=     7, DT=   {dt} SEC")
    with pytest.raises(RecordError, match=r"dt\.AT2: (DT .* is outside \[0\.0001, 1\] s|sampling"
                                          r" interval .* is not a positive number|is not a PEER)"):
        read_at2(path)


def test_at2_samples_above_100_g_refused(tmp_path):
    path = _at2(tmp_path, "big.AT2", scale=1000.0)  # 200 g
    with pytest.raises(RecordError, match=r"big\.AT2: the acceleration record \(in g\) has a sample"
                                          r" of 1\.96e\+03 m/s\^2"):
        read_at2(path)


@pytest.mark.parametrize("delta_ms", [1e-30, 1e-3, 5000.0])
def test_cosmos_absurd_interval_refused(tmp_path, delta_ms):
    path = tmp_path / "dt.V2"
    path.write_text(_cosmos_block(H1_CM, delta_ms=delta_ms))
    with pytest.raises(RecordError, match=r"dt\.V2: sampling interval .* s is outside"):
        read_cosmos(path)


def test_cosmos_samples_above_100_g_refused(tmp_path):
    path = tmp_path / "big.V2"
    path.write_text(_cosmos_block([0.1, 150.0, 0.2], unit_code=2, unit_text="g",
                                  with_velocity=False))  # 150 g
    with pytest.raises(RecordError, match=r"big\.V2: channel .* has a sample of 1\.47e\+03 m/s\^2"):
        read_cosmos(path)


def test_esm_absurd_interval_and_samples_refused(tmp_path):
    path = tmp_path / "dt.ASC"
    path.write_text(_esm_text([1.0, 2.0]).replace("SAMPLING_INTERVAL_S: 0.005000",
                                                  "SAMPLING_INTERVAL_S: 1e-30"))
    with pytest.raises(RecordError, match=r"dt\.ASC: sampling interval 1e-30 s is outside"):
        read_esm(path)
    path = tmp_path / "big.ASC"
    path.write_text(_esm_text([1.0, 2e5]))  # 2e5 cm/s^2 = 2000 m/s^2
    with pytest.raises(RecordError, match=r"big\.ASC: channel HGE has a sample of 2e\+03 m/s\^2"):
        read_esm(path)


def test_text_absurd_interval_and_samples_refused(tmp_path):
    path = tmp_path / "plain.txt"
    path.write_text("0.1\n0.2\n-0.3\n")
    for dt in (1e-30, 0.0, -0.01, float("nan"), float("inf"), 10.0):
        with pytest.raises(RecordError, match=r"plain\.txt: sampling interval"):
            read_text_record(path, units="g", dt=dt)
    big = tmp_path / "big.txt"
    big.write_text("0.1\n0.2\n-300\n")  # 300 g
    with pytest.raises(RecordError, match=r"big\.txt: the acceleration column \(in g\) has a"
                                          r" sample of 2\.94e\+03 m/s\^2"):
        read_text_record(big, units="g", dt=0.01)


# ------------------------------------------------------------------------------ fuzz, kept


@pytest.mark.parametrize("reader", ["at2", "cosmos", "esm", "text"])
def test_older_readers_survive_mutations_within_the_limits(tmp_path, reader):
    """Mutated files (tests.reader_fuzz: cuts, dropped lines, numbers replaced by NaN, 1e-320,
    1e999, garbage, bit flips) give a project error or finite samples at 1e-4..1 s under 100 g."""
    from shipblock.io.at2 import read_at2
    from tests.reader_fuzz import assert_reader_survives

    files = {
        "at2": (read_at2, (DATA / "helena_synthetic_180.AT2").read_bytes(), {}),
        "cosmos": (read_cosmos, _cosmos_block(H1_CM).encode(), {}),
        "esm": (read_esm, _esm_text([1.0, -2.0, 3.0, 0.5]).encode(), {}),
        "text": (read_text_record, (DATA / "two_column_gal.csv").read_bytes(), {}),
    }
    read_fn, raw, kwargs = files[reader]
    assert assert_reader_survives(read_fn, raw, seed=23, count=60, **kwargs) > 0
