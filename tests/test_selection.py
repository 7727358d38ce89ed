"""Record selection for a target spectrum, on catalogues whose best sets are known: records
that are scaled copies of one sinusoid mix (their spectra are the same curve times the factor,
the spectrum being linear in the record) among records of other shapes."""

from __future__ import annotations

import math

import numpy as np
import pytest
from obspy import Stream, Trace, UTCDateTime

from shipblock import intensity
from shipblock.records.catalogue import load_catalogue
from shipblock.cli import main
from shipblock.errors import ParameterError
from shipblock.fragility.pipeline import load_pipeline
from shipblock.risk.selection import match_record, select_records, selection_toml
from shipblock.scaling import TargetSpectrum

from .test_pipeline import PIPELINE

DT = 0.01
T = np.arange(0.0, 12.0, DT)
ENVELOPE = T * np.exp(-T / 1.5)
#: Comparison periods: the targets are given exactly on them (no interpolation error).
PERIODS = np.geomspace(0.1, 2.0, 12)


def shape(*period_amplitude):
    return ENVELOPE * sum(a * np.sin(2 * np.pi * T / p) for p, a in period_amplitude)


H_A = shape((0.3, 1.0), (1.0, 0.5))
V_A = shape((0.1, 0.6), (0.25, 0.3))
H_B = shape((0.12, 1.0))
H_C = shape((1.8, 1.0))

#: record -> (horizontal, vertical): scaled copies of (H_A, V_A) and other shapes.
RECORDS = {
    "a1": (1.0 * H_A, 1.0 * V_A),
    "a2": (0.5 * H_A, 0.5 * V_A),      # best factor 2
    "a3": (3.0 * H_A, 3.0 * V_A),      # best factor 1/3
    "a4": (0.1 * H_A, 0.1 * V_A),      # needs 10, beyond the bound 4
    "a5": (1.0 * H_A, 2.0 * V_A),      # the horizontal of a1, twice its vertical
    "b1": (H_B, 1.0 * V_A),
    "c1": (H_C, 1.0 * V_A),
}


def write_catalogue(directory, records=RECORDS):
    directory.mkdir(parents=True, exist_ok=True)
    lines = ["schema_version = 1"]
    for name, (h, v) in records.items():
        st = Stream()
        for channel, data in (("HNN", h), ("HNZ", v)):
            tr = Trace(np.asarray(data, dtype=np.float64))
            tr.stats.delta = DT
            tr.stats.network, tr.stats.station, tr.stats.channel = "XX", name.upper(), channel
            tr.stats.starttime = UTCDateTime(2020, 1, 1)
            st += tr
        st.write(str(directory / f"{name}.mseed"), format="MSEED")
        lines += ["[[record]]", f'id = "syn/{name}"', f'files = ["{name}.mseed"]',
                  'units = "m/s^2"', f'station = "{name.upper()}"', 'network = "XX"',
                  'license = "CC0"', 'credit = "synthetic"', "[record.components]",
                  'HNN = "H1"', 'HNZ = "V"']
    path = directory / "catalogue.toml"
    path.write_text("\n".join(lines) + "\n")
    return path


def spectrum(acc):
    return intensity.spectral_acceleration(acc, DT, PERIODS)


@pytest.fixture(scope="module")
def catalogue(tmp_path_factory):
    return write_catalogue(tmp_path_factory.mktemp("selection") / "lib")


TARGET_H = TargetSpectrum(PERIODS, spectrum(H_A), "target_h")
TARGET_V = TargetSpectrum(PERIODS, spectrum(V_A), "target_v")


def select(catalogue, k, **kw):
    return select_records(catalogue, TARGET_H, k, processing=[], n_periods=PERIODS.size, **kw)


def test_scaled_copies_are_chosen_with_the_factors_that_undo_their_scaling(catalogue):
    sel = select(catalogue, 4)
    assert {m.id for m in sel.chosen} == {"syn/a1", "syn/a2", "syn/a3", "syn/a5"}
    factors = {m.id: m.factor for m in sel.chosen}
    np.testing.assert_allclose([factors[f"syn/a{i}"] for i in (1, 2, 3, 5)], [1, 2, 1 / 3, 1],
                               rtol=1e-9)
    assert max(m.misfit for m in sel.chosen) < 1e-9
    # the copy that needs a factor of 10 stops at the bound 4: misfit |ln(4 / 10)|
    a4 = next(m for m in sel.ranked if m.id == "syn/a4")
    assert a4.bounded and a4.factor == pytest.approx(4.0)
    assert a4.misfit == pytest.approx(abs(math.log(0.4)), rel=1e-9)
    # the other shapes rank last; the suite's mean is the target
    assert [m.id for m in sel.ranked[-2:]] in (["syn/b1", "syn/c1"], ["syn/c1", "syn/b1"])
    assert sel.suite_ratio_min == pytest.approx(1.0, rel=1e-9)
    assert sel.passes and sel.suite_factor == 1.0


def test_with_the_vertical_a_wrong_v_over_h_costs_its_closed_form_misfit(catalogue):
    # a5's vertical is twice the target's: with weight w the best factor is 2^(-w/(1+w)) and
    # the misfit sqrt(w) ln 2 / (1 + w)
    for w in (1.0, 3.0):
        sel = select(catalogue, 3, vertical_target=TARGET_V, vertical_weight=w)
        assert {m.id for m in sel.chosen} == {"syn/a1", "syn/a2", "syn/a3"}
        a5 = next(m for m in sel.ranked if m.id == "syn/a5")
        assert sel.ranked[3].id == "syn/a5"
        assert a5.factor == pytest.approx(2 ** (-w / (1 + w)), rel=1e-9)
        assert a5.misfit == pytest.approx(math.sqrt(w) * math.log(2) / (1 + w), rel=1e-9)
        assert a5.misfit_h == pytest.approx(w / (1 + w) * math.log(2), rel=1e-9)
        assert a5.misfit_v == pytest.approx(math.log(2) / (1 + w), rel=1e-9)


def test_unscaled_misfit_is_the_log_of_the_scaling(catalogue):
    sel = select(catalogue, 2, scale=False)
    assert {m.id for m in sel.chosen} == {"syn/a1", "syn/a5"}
    misfit = {m.id: m.misfit for m in sel.ranked}
    for name, c in (("a2", 0.5), ("a3", 3.0), ("a4", 0.1)):
        assert misfit[f"syn/{name}"] == pytest.approx(abs(math.log(c)), rel=1e-9)
    assert all(m.factor == 1.0 for m in sel.ranked)


def test_suite_below_90_percent_is_raised_to_the_floor(catalogue):
    # only the other shapes: their least-squares factors leave the mean below the target
    # somewhere; a common factor lifts its lowest point to exactly 90 %
    sel = select(catalogue, 2, ids=["syn/b1", "syn/c1"], max_scale_factor=100.0)
    before = np.mean([m.sa_h * m.factor / sel.suite_factor for m in sel.chosen], axis=0)
    assert (before / TARGET_H.sa).min() < 0.9
    assert sel.suite_factor == pytest.approx(0.9 / (before / TARGET_H.sa).min(), rel=1e-12)
    assert sel.suite_ratio_min == pytest.approx(0.9, rel=1e-12) and sel.passes
    # and without the floor the check fails and says where
    raw = select(catalogue, 2, ids=["syn/b1", "syn/c1"], max_scale_factor=100.0,
                 suite_floor=False)
    assert not raw.passes and raw.suite_factor == 1.0
    assert raw.suite_ratio_min == pytest.approx((before / TARGET_H.sa).min(), rel=1e-12)


def test_match_record_bounds_and_weights():
    target = np.array([1.0, 2.0, 4.0])
    m = match_record("x", target / 8.0, None, target, None, max_scale_factor=4.0)
    assert m.factor == pytest.approx(4.0) and m.bounded
    assert m.misfit == pytest.approx(math.log(2.0))
    m = match_record("x", target * 1.5, None, target, None)
    assert m.factor == pytest.approx(1 / 1.5) and m.misfit == pytest.approx(0.0, abs=1e-15)


def test_selection_is_a_catalogue_a_pipeline_reads(catalogue, tmp_path):
    sel = select(catalogue, 3, vertical_target=TARGET_V)
    entries = load_catalogue(catalogue)
    out = tmp_path / "records" / "catalogue.toml"
    out.parent.mkdir()
    out.write_text(selection_toml(sel, entries, out))
    back = load_catalogue(out)
    assert list(back) == [m.id for m in sel.chosen]
    for rank, m in enumerate(sel.chosen, start=1):
        extra = back[m.id].extra
        assert extra["selection_rank"] == rank
        assert extra["selection_scale_factor"] == pytest.approx(m.factor, rel=1e-15)
        assert back[m.id].files[0].samefile(entries[m.id].files[0])
    pipeline = tmp_path / "p.toml"
    pipeline.write_text(PIPELINE.format(ids='"all"', kind="ida", sweep="", chunk_size=4,
                                        levels="levels_g = [0.2, 0.4]"))
    assert load_pipeline(pipeline).design.records == tuple(m.id for m in sel.chosen)


def test_bad_arguments_are_named(catalogue):
    with pytest.raises(ParameterError, match="k = 9 but only 7 records"):
        select(catalogue, 9)
    with pytest.raises(ParameterError, match="horizontal"):
        select(catalogue, 2, horizontal="H3")
    with pytest.raises(ParameterError, match="ids: not in the catalogue: syn/zz"):
        select(catalogue, 1, ids=["syn/zz"])
    with pytest.raises(ParameterError, match="max_scale_factor"):
        select(catalogue, 1, min_scale_factor=2.0, max_scale_factor=1.0)


def test_command_line_writes_the_selection(catalogue, tmp_path, capsys):
    target = tmp_path / "target.csv"
    target.write_text("period [s], Sa [m/s^2]\n" + "".join(
        f"{float(p)!r}, {float(s)!r}\n" for p, s in zip(PERIODS, TARGET_H.sa, strict=True)))
    out = tmp_path / "selected.toml"
    assert main(["-q", "select", str(catalogue), "--target", str(target), "-k", "3", "-o",
                 str(out), "--no-processing"]) == 0
    text = capsys.readouterr().out
    assert "3 of 7 records chosen" in text and "90 % check passed" in text
    assert len(load_catalogue(out)) == 3
    target.write_text("period, Sa\n0.1, 1\n2.0, 1\n")
    assert main(["-q", "select", str(catalogue), "--target", str(target), "-o", str(out)]) == 2
    assert "give the unit of Sa (units, --units)" in capsys.readouterr().err


def test_azimuth_of_a_north_component_gives_its_spectrum_and_east_its_other():
    # the shipped South Napa records: HNN at 0 deg, HNE at 90 deg (StationXML); rotated onto
    # azimuth 0 the horizontal is H1, onto 90 deg it is H2
    ids = ["south-napa-2014/NP.1765", "south-napa-2014/NP.1743"]
    target = TargetSpectrum(np.array([0.1, 2.0]), np.array([3.0, 0.5]), "flat")
    kw = {"ids": ids, "processing": [], "n_periods": 8}
    for azimuth, horizontal in ((0.0, "H1"), (90.0, "H2")):
        rotated = select_records(None, target, 2, azimuth=azimuth, **kw)
        plain = select_records(None, target, 2, horizontal=horizontal, **kw)
        for a, b in zip(rotated.ranked, plain.ranked, strict=True):
            assert a.id == b.id
            np.testing.assert_allclose(a.sa_h, b.sa_h, rtol=1e-9)
        assert rotated.options["horizontal"] == f"azimuth {azimuth:g} deg"
