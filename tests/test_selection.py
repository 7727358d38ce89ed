"""Record selection for a target spectrum, on catalogues whose best sets are known: records
that are scaled copies of one sinusoid mix (their spectra are the same curve times the factor,
the spectrum being linear in the record) among records of other shapes."""

from __future__ import annotations

import itertools
import math
from collections import Counter

import numpy as np
import pytest
from obspy import Stream, Trace, UTCDateTime

from shipblock import intensity
from shipblock.records.catalogue import load_catalogue
from shipblock.cli import main
from shipblock.errors import ParameterError
from shipblock.fragility.pipeline import load_pipeline
from shipblock.risk.selection import (
    event_identity,
    match_record,
    select_records,
    selection_toml,
)
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


def write_catalogue(directory, records=RECORDS, extra=None):
    """A catalogue of the records (name -> horizontal, vertical) as miniSEED files; ``extra``:
    name -> more lines of its table (its event)."""
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
                  'license = "CC0"', 'credit = "synthetic"', *(extra or {}).get(name, []),
                  "[record.components]",
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


def test_command_line_takes_the_damping_ids_periods_and_suite_floor_of_the_python_api(
        catalogue, tmp_path, capsys):
    # a target at 2 % damping: the scaled copy a2 of H_A matches it exactly (factor 2, misfit
    # 0) only when the records' spectra are taken at 2 % too; at the default 5 % the misfit
    # is the shape difference of the two dampings, not 0 (a silent mismatch before --damping)
    sa_2 = intensity.spectral_acceleration(H_A, DT, PERIODS, 0.02)
    target = tmp_path / "target_2pct.csv"
    target.write_text("period [s], Sa [m/s^2]\n" + "".join(
        f"{float(p)!r}, {float(v)!r}\n" for p, v in zip(PERIODS, sa_2, strict=True)))
    out = tmp_path / "selected.toml"
    common = ["-q", "select", str(catalogue), "--target", str(target), "-k", "1", "-o", str(out),
              "--no-processing", "--n-periods", str(PERIODS.size),
              "--ids", "syn/a2", "syn/b1", "--ids", "syn/c1"]
    assert main([*common, "--damping", "0.02", "--no-suite-floor"]) == 0
    text = capsys.readouterr().out
    assert "1 of 3 records chosen (H1 horizontal, 2 % damping, 0.1 to 2 s)" in text
    row = next(line for line in text.splitlines() if "syn/a2" in line).split()
    assert row[:3] == ["1", "syn/a2", "2.000"] and float(row[3]) < 5e-4
    assert list(load_catalogue(out)) == ["syn/a2"]
    python = select_records(catalogue, target, 1, processing=[], n_periods=PERIODS.size,
                            ids=["syn/a2", "syn/b1", "syn/c1"], damping=0.02,
                            suite_floor=False)
    assert python.chosen[0].factor == pytest.approx(2.0, rel=1e-9)
    assert python.chosen[0].misfit < 1e-9
    assert main(common) == 0
    text = capsys.readouterr().out
    assert "5 % damping" in text
    default = select_records(catalogue, target, 1, processing=[], n_periods=PERIODS.size,
                             ids=["syn/a2", "syn/b1", "syn/c1"])
    assert default.chosen[0].misfit > 1e-3
    # a percentage given for the fraction is refused, naming it
    assert main([*common, "--damping", "5"]) == 2
    assert "damping must be a number in [0, 1), got 5.0" in capsys.readouterr().err


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


# ------------------------------------------------------------------------------ per earthquake
#: Copies of the target's record scaled by c: unscaled, the misfit of each is |ln c| exactly.
EVENT_RECORDS = {"r1": 1.0, "r2": 1.1, "r3": 1.2, "r4": 1.3, "r5": 1.5}


@pytest.fixture(scope="module")
def event_catalogue(tmp_path_factory):
    """r1, r2, r3 of earthquake A (one QuakeML file), r4 of B and r5 of C (stated by
    event_id)."""
    from obspy.core.event import Catalog, Event, Origin, ResourceIdentifier

    directory = tmp_path_factory.mktemp("events") / "lib"
    directory.mkdir(parents=True)
    event = Event(resource_id=ResourceIdentifier("smi:local/event/A"),
                  origins=[Origin(time=UTCDateTime(2020, 1, 1, 0, 0, 5), latitude=38.2,
                                  longitude=-122.3, depth=8000.0)])
    Catalog([event]).write(str(directory / "eventA.xml"), format="QUAKEML")
    extra = {"r1": ['event = "eventA.xml"'], "r2": ['event = "eventA.xml"'],
             "r3": ['event = "eventA.xml"'], "r4": ['event_id = "B"'], "r5": ['event_id = "C"']}
    records = {name: (c * H_A, c * V_A) for name, c in EVENT_RECORDS.items()}
    return write_catalogue(directory, records, extra)


def _total(ids):
    return sum(abs(math.log(EVENT_RECORDS[i.split("/")[-1]])) for i in ids)


def test_at_most_n_records_per_earthquake_changes_the_suite_to_the_best_within_the_caps(
        event_catalogue):
    chosen = {}
    for cap in (None, 2, 1):
        sel = select(event_catalogue, 3, scale=False, max_per_event=cap)
        chosen[cap] = [m.id for m in sel.chosen]
        # the misfits are the closed form |ln c|
        for m in sel.chosen:
            assert m.misfit == pytest.approx(abs(math.log(EVENT_RECORDS[m.id[4:]])), abs=1e-12)
    assert chosen[None] == ["syn/r1", "syn/r2", "syn/r3"]  # all three of earthquake A
    assert chosen[2] == ["syn/r1", "syn/r2", "syn/r4"]
    assert chosen[1] == ["syn/r1", "syn/r4", "syn/r5"]
    # optimal: no set of 3 within the caps has a smaller total misfit (all 10 sets tried)
    events = {"r1": "A", "r2": "A", "r3": "A", "r4": "B", "r5": "C"}
    for cap in (2, 1):
        allowed = [c for c in itertools.combinations(EVENT_RECORDS, 3)
                   if max(Counter(events[r] for r in c).values()) <= cap]
        assert _total(chosen[cap]) == pytest.approx(min(_total(c) for c in allowed), rel=1e-12)
    sel = select(event_catalogue, 3, scale=False, max_per_event=1)
    assert sel.capped == {"syn/r2": "smi:local/event/A", "syn/r3": "smi:local/event/A"}
    assert [m.event for m in sel.chosen] == ["smi:local/event/A", "B", "C"]
    assert sel.options["max_per_event"] == 1


def test_a_cap_the_catalogue_cannot_meet_and_an_unknown_earthquake_are_refused(
        event_catalogue, catalogue):
    with pytest.raises(ParameterError, match=r"max_per_event = 1 \(--max-per-event\): the 5 "
                                             r"matched records come from 3 earthquake\(s\), so "
                                             r"at most 3 can be chosen, not k = 4 \(-k\)"):
        select(event_catalogue, 4, scale=False, max_per_event=1)
    with pytest.raises(ParameterError, match="max_per_event"):
        select(event_catalogue, 2, max_per_event=0)
    # the records of the first catalogue name no earthquake: refused only with a cap
    assert len(select(catalogue, 2).chosen) == 2
    with pytest.raises(ParameterError, match=r"max_per_event: the earthquake of record "
                                             r"'syn/a1' is not known .* event_id"):
        select(catalogue, 2, max_per_event=1)


def test_event_identity_order(event_catalogue):
    entries = load_catalogue(event_catalogue)
    stated, quakeml = entries["syn/r4"], entries["syn/r1"]
    # the catalogue's event_id wins over what the record says
    assert event_identity(stated, {"event": {"id": "smi:x"}}) == ("B", "catalogue event_id")
    assert event_identity(quakeml, {"event": {"id": "smi:x", "name": "n"}}) == (
        "smi:x", "QuakeML event id")
    origin = {"time": "2020-01-01T00:00:05.250000Z", "latitude": 38.2049, "longitude": -122.31}
    assert event_identity(quakeml, {"event": origin}) == (
        "2020-01-01T00:00:05 at 38.20, -122.31", "origin time and epicentre")
    assert event_identity(quakeml, {"event": {"name": "Northridge-01"}}) == (
        "Northridge-01", "event name in the record")
    assert event_identity(quakeml, {"event": None}) == (
        str(quakeml.event), "catalogue event file")
    # the records as read: the QuakeML file's resource id
    assert event_identity(quakeml, quakeml.read().metadata) == (
        "smi:local/event/A", "QuakeML event id")


def test_command_line_caps_records_per_earthquake(event_catalogue, tmp_path, capsys):
    target = tmp_path / "target.csv"
    target.write_text("period [s], Sa [m/s^2]\n" + "".join(
        f"{float(p)!r}, {float(s)!r}\n" for p, s in zip(PERIODS, TARGET_H.sa, strict=True)))
    out = tmp_path / "selected.toml"
    assert main(["-q", "select", str(event_catalogue), "--target", str(target), "-k", "3",
                 "--no-scale", "--no-processing", "--max-per-event", "1", "-o", str(out)]) == 0
    text = capsys.readouterr().out
    assert "at most 1 per earthquake: 3 earthquake(s)" in text
    assert "left out for max_per_event: syn/r2 (smi:local/event/A)" in text
    back = load_catalogue(out)
    assert list(back) == ["syn/r1", "syn/r4", "syn/r5"]
    assert [back[i].extra["selection_event"] for i in back] == ["smi:local/event/A", "B", "C"]
    assert "# At most 1 record(s) per earthquake" in out.read_text()
    # the refusal names the flags a command-line user gave, not only the Python keywords
    assert main(["-q", "select", str(event_catalogue), "--target", str(target), "-k", "4",
                 "--no-scale", "--no-processing", "--max-per-event", "1", "-o", str(out)]) == 2
    err = capsys.readouterr().err
    assert "max_per_event = 1 (--max-per-event)" in err and "not k = 4 (-k)" in err


def test_command_line_takes_a_processing_chain_file_as_the_python_api(catalogue, tmp_path,
                                                                      capsys):
    """--processing FILE: the records' spectra are taken after the file's chain, as
    select_records(processing=chain) does (a 2 Hz low-pass moves a1, an exact copy of the
    target's record, off its misfit 0); with --no-processing a usage error naming both; a step
    the chain does not know is refused naming the file and the step, before any record."""
    target = tmp_path / "target.csv"
    target.write_text("period [s], Sa [m/s^2]\n" + "".join(
        f"{float(p)!r}, {float(s)!r}\n" for p, s in zip(PERIODS, TARGET_H.sa, strict=True)))
    chain_file = tmp_path / "lowpass.toml"
    chain_file.write_text('[[processing]]\nstep = "lowpass"\nfreq = 2.0\n')
    out = tmp_path / "selected.toml"
    common = ["-q", "select", str(catalogue), "--target", str(target), "-k", "1", "-o",
              str(out), "--n-periods", str(PERIODS.size), "--ids", "syn/a1", "--no-scale",
              "--no-suite-floor"]

    def misfit(text):
        return float(next(line for line in text.splitlines() if "syn/a1" in line).split()[3])

    assert main([*common, "--no-processing"]) == 0
    assert misfit(capsys.readouterr().out) == 0.0
    assert main([*common, "--processing", str(chain_file)]) == 0
    printed = misfit(capsys.readouterr().out)
    python = select_records(catalogue, TARGET_H, 1, processing=[{"step": "lowpass", "freq": 2.0}],
                            n_periods=PERIODS.size, ids=["syn/a1"], scale=False,
                            suite_floor=False)
    assert printed > 0.01 and printed == pytest.approx(python.chosen[0].misfit, abs=5e-4)
    with pytest.raises(SystemExit) as exc:
        main([*common, "--processing", str(chain_file), "--no-processing"])
    assert exc.value.code == 2
    err = capsys.readouterr().err
    assert "--processing" in err and "--no-processing" in err and "not allowed" in err
    chain_file.write_text('[[processing]]\nstep = "lopass"\nfreq = 2.0\n')
    assert main([*common, "--processing", str(chain_file)]) == 2
    err = capsys.readouterr().err
    assert str(chain_file) in err and "processing[0].step" in err and "'lopass'" in err
