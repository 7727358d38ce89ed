"""Every read option on the command line and in the catalogue (issue 31), on real files.

The files are records from other public projects in ``shared/records/outside-tests/`` beside the
project (its README names each source); they are read in place, never copied into the
repository, and the tests that need them are skipped where the folder is absent. Each file is
read right against the peak its own header states, or refused with a message that names the
command-line flag, the catalogue key and the Python keyword that read it.
"""

from __future__ import annotations

import logging
from pathlib import Path

import numpy as np
import obspy
import pytest

from shipblock import read_motion
from shipblock.cli import main
from shipblock.errors import ParameterError, RecordError, UnitsError
from shipblock.records.catalogue import load_catalogue, record_file_stem, record_id
from shipblock.records.folders import read_motions
from shipblock.records.motion import require_components
from shipblock.units import STANDARD_GRAVITY

OUTSIDE = Path(__file__).resolve().parents[1].parent / "shared" / "records" / "outside-tests"

needs_outside = pytest.mark.skipif(not OUTSIDE.is_dir(),
                                   reason=f"outside-tests records not found at {OUTSIDE}")

EVT = OUTSIDE / "obspy" / "BI008_MEMA-04823.evt"
SMC_090 = OUTSIDE / "pyrotd" / "A-CAT090.AT2.smc"
SMC_180 = OUTSIDE / "pyrotd" / "A-CAT180.AT2.smc"
V2 = OUTSIDE / "readv2" / "ce89486SampleInput.v2"
LOMA = OUTSIDE / "loma" / "RSN753_LOMAP_CLS000.AT2"
PAIR = [OUTSIDE / "pyrotd" / "RSN8883_14383980_13849090.AT2",
        OUTSIDE / "pyrotd" / "RSN8883_14383980_13849360.AT2"]

#: The peak A-CAT090.AT2.smc states on its line 7 ("pk mtn = 4.136E+1") [cm/s^2].
SMC_090_STATED_PEAK_CM_S2 = 41.36

#: Peaks the CE.89486 V2 file states, channel 1 (180 deg) and 2 (90 deg) [cm/s^2].
V2_STATED_PEAKS_CM_S2 = {"HN1": 388.166, "HNE": 261.805}


def run(capsys, *argv):
    code = main(["-q", *argv])
    out = capsys.readouterr()
    return code, out.out, out.err


# ------------------------------------------------------------------ Kinemetrics EVT: channel map
@needs_outside
def test_evt_refused_without_channel_map_names_the_flag_and_key(capsys):
    code, _, err = run(capsys, "info", str(EVT), "--processing", "none")
    assert code == 2
    assert "--channel-map CHANNEL=H1" in err and "[record.components]" in err
    assert "channel_map=" in err
    # channels "1" and "2" are channel numbers, not orientations: all three are named as unknown
    assert all(f".MEMA..{n}" in err for n in "012")


@needs_outside
def test_evt_with_channel_map_reads_the_headers_peaks(capsys):
    code, out, err = run(capsys, "info", str(EVT), "--processing", "none",
                         "--channel-map", "0=V,1=H1", "--channel-map", "2=H2")
    assert code == 0, err
    # The EVT header states each channel's extreme counts; times the calibration obspy reads
    # (m/s^2 per count) they are the peaks as read.
    motion = read_motion(str(EVT), channel_map={"0": "V", "1": "H1", "2": "H2"})
    raw = obspy.read(str(EVT))
    for trace in raw:
        header = trace.stats.kinemetrics_evt
        stated = max(abs(header.maxpeak), abs(header.minpeak)) * trace.stats.calib
        component = {"0": "V", "1": "H1", "2": "H2"}[trace.stats.channel]
        assert np.abs(motion.components[component]).max() == pytest.approx(stated, rel=1e-9)
        assert f"{stated / STANDARD_GRAVITY:.4f}" in out


@needs_outside
def test_catalogue_of_evt_with_channel_map_reads_back(tmp_path, capsys):
    output = tmp_path / "cat.toml"
    code, out, err = run(capsys, "catalogue", str(EVT), "-o", str(output),
                         "--channel-map", "0=V,1=H1,2=H2")
    assert code == 0, err
    (entry,) = load_catalogue(output).values()
    assert not entry.id.startswith(".") and " " not in entry.id
    motion = entry.read()
    assert set(motion.components) == {"H1", "H2", "V"}


# ------------------------------------------------------------------ SMC of type 0 UNKNOWN
@needs_outside
def test_smc_unknown_type_refused_naming_the_option(capsys):
    code, _, err = run(capsys, "info", str(SMC_090), "--processing", "none")
    assert code == 2
    assert "--data-type acceleration" in err
    assert 'data_type = "acceleration"' in err and "data_type='acceleration'" in err


@needs_outside
def test_smc_with_data_type_reads_its_stated_peak(capsys):
    motion = read_motion(str(SMC_090), data_type="acceleration")
    peak = np.abs(motion.components["H1"]).max()
    # 4 significant digits stated
    assert peak == pytest.approx(SMC_090_STATED_PEAK_CM_S2 / 100, rel=2e-4)
    assert "stated with --data-type" in motion.metadata["units"]["H1"]
    code, out, err = run(capsys, "info", str(SMC_090), "--data-type", "acceleration",
                         "--processing", "none")
    assert code == 0, err
    assert f"{SMC_090_STATED_PEAK_CM_S2 / 100 / STANDARD_GRAVITY:.4f}" in out


@needs_outside
def test_catalogue_entry_with_data_type_and_components_by_file_name(tmp_path):
    catalogue = tmp_path / "cat.toml"
    catalogue.write_text(
        "schema_version = 1\n\n[[record]]\n"
        'id = "CAT"\nstation = "CAT"\n'
        f'files = ["{SMC_090.as_posix()}", "{SMC_180.as_posix()}"]\n'
        'data_type = "acceleration"\n\n'
        "[record.components]\n"
        f'"{SMC_090.name}" = "H1"\n"{SMC_180.name}" = "H2"\n')
    motion = load_catalogue(catalogue)["CAT"].read()
    assert np.abs(motion.components["H1"]).max() == pytest.approx(
        SMC_090_STATED_PEAK_CM_S2 / 100, rel=2e-4)
    assert set(motion.components) == {"H1", "H2"}


def test_catalogue_entry_with_a_wrong_read_option_names_the_key(tmp_path):
    record = tmp_path / "a.txt"
    record.write_text("# accel (g)\n" + "\n".join(["0.0", "0.1", "-0.1", "0.0"] * 10))
    catalogue = tmp_path / "cat.toml"
    catalogue.write_text('schema_version = 1\n[[record]]\nid = "A"\nstation = "A"\n'
                         'files = ["a.txt"]\nalign = "sideways"\n')
    with pytest.raises(RecordError, match=r"record 'A': align must be one of .*\[\[record\]\]"):
        load_catalogue(catalogue)


# ------------------------------------------------------------------ one-column text: --dt
@needs_outside
def test_one_column_text_with_dt_reads_the_at2_peak(tmp_path, capsys):
    at2 = read_motion(str(LOMA))
    column = tmp_path / "corralitos.txt"
    np.savetxt(column, at2.components["H1"] / STANDARD_GRAVITY, fmt="%.8e")
    code, _, err = run(capsys, "info", str(column), "--units", "g", "--processing", "none")
    assert code == 2
    assert "--dt SECONDS" in err and "catalogue key dt" in err
    motion = read_motion(str(column), units="g", dt=at2.dt)
    assert np.abs(motion.horizontal).max() == pytest.approx(np.abs(at2.horizontal).max(),
                                                            rel=1e-7)
    code, out, err = run(capsys, "info", str(column), "--units", "g", "--dt", "0.005",
                         "--processing", "none")
    assert code == 0, err
    assert "as given with --units" in out and "from the file header" not in out
    assert f"{np.abs(at2.horizontal).max() / STANDARD_GRAVITY:.4f}" in out


@needs_outside
@pytest.mark.parametrize(("flag", "value", "readers"), [
    ("--dt", "0.01", "SHIPBLOCK_TEXT"),
    ("--resample-rate", "100", "SHIPBLOCK_USC and SHIPBLOCK_SMC"),
    ("--resample-interval", "0.01", "SHIPBLOCK_DMG"),
])
def test_a_read_option_of_another_format_is_refused_not_ignored(capsys, flag, value, readers):
    """--dt 0.01 given for an AT2 file (which states 0.005 s) was ignored without a word; each
    format's own option, given for a file whose reader does not take it, is refused naming
    the flag, the catalogue key and the formats it is for. The same for the shipped MiniSEED
    records (obspy's reader)."""
    key = flag[2:].replace("-", "_")
    code, _, err = run(capsys, "info", str(LOMA), flag, value, "--processing", "none")
    assert code == 2
    assert f"{key}={float(value)!r} applies to {readers} files only" in err
    assert "this file is SHIPBLOCK_AT2" in err and f"leave out {flag}, catalogue key {key}" in err
    shipped = Path(__file__).resolve().parents[1] / "records" / "south-napa-2014" / "NP.1737.mseed"
    with pytest.raises(RecordError, match=f"{key}=.* applies to .* this file is MSEED"):
        read_motion(str(shipped), **{key: float(value)})


def test_velocity_text_with_units_and_differentiate(tmp_path, capsys):
    # v = V sin(2 pi f t) cm/s: a = 2 pi f V cos(2 pi f t), peak 2 pi f V cm/s^2
    dt, f, amplitude = 0.001, 1.0, 5.0
    t = np.arange(4000) * dt
    path = tmp_path / "velocity.txt"
    np.savetxt(path, amplitude * np.sin(2 * np.pi * f * t))
    with pytest.raises(UnitsError, match="--differentiate"):
        read_motion(str(path), units="cm/s", dt=dt)
    motion = read_motion(str(path), units="cm/s", dt=dt, differentiate=True)
    peak = np.abs(motion.horizontal).max()
    assert peak == pytest.approx(2 * np.pi * f * amplitude / 100, rel=1e-4)
    assert "cm/s -> m/s as given with --units" in motion.metadata["units"]["H1"]
    code, out, err = run(capsys, "info", str(path), "--units", "cm/s", "--differentiate",
                         "--dt", str(dt), "--processing", "none")
    assert code == 0, err


# ------------------------------------------------------------------ different rates: --align
@needs_outside
def test_different_rates_refused_then_resampled(tmp_path, capsys):
    pair = read_motion([str(p) for p in PAIR])
    files = []
    for component, channel in (("H1", "HN1"), ("H2", "HN2")):
        trace = pair.stream.select(channel=pair.metadata["channels"][component].split(".")[-1])[0]
        trace = trace.copy()
        trace.stats.network, trace.stats.station, trace.stats.channel = "XX", "ANA", channel
        if component == "H2":
            trace.decimate(2)  # 100 Hz: obspy's anti-alias filter first
        path = tmp_path / f"ana.{channel}.sac"
        trace.write(str(path), format="SAC")
        files.append(str(path))
    code, _, err = run(capsys, "info", *files, "--units", "m/s^2", "--processing", "none")
    assert code == 2
    assert "--align resample" in err and 'align = "resample"' in err
    code, out, err = run(capsys, "info", *files, "--units", "m/s^2", "--align", "resample",
                         "--processing", "none")
    assert code == 0, err
    assert "dt = 0.01 s" in out
    catalogue = tmp_path / "cat.toml"
    catalogue.write_text('schema_version = 1\n[[record]]\nid = "XX.ANA..HN"\nstation = "ANA"\n'
                         'files = ["ana.HN1.sac", "ana.HN2.sac"]\nunits = "m/s^2"\n'
                         'align = "resample"\n')
    motion = load_catalogue(catalogue)["XX.ANA..HN"].read()
    assert motion.dt == pytest.approx(0.01)
    # the 200 Hz H1 low-passed and resampled to 100 Hz keeps its peak within a few per cent
    assert np.abs(motion.components["H1"]).max() == pytest.approx(
        np.abs(pair.components["H1"]).max(), rel=0.05)


# ------------------------------------------------------------------ V2: default horizontal, peaks
@needs_outside
def test_v2_default_horizontal_is_the_files_first_and_info_shows_raw_and_processed(capsys):
    motion = read_motion(str(V2))
    assert motion.metadata["channels"]["H1"].endswith("HN1")  # the file's channel 1
    stated = V2_STATED_PEAKS_CM_S2["HN1"] / 100
    assert np.abs(motion.horizontal).max() == pytest.approx(stated, rel=1e-5)
    code, out, err = run(capsys, "info", str(V2))
    assert code == 0, err
    assert "as read" in out and "processed" in out and "file states" in out
    line = next(row for row in out.splitlines() if row.startswith("H1 "))
    as_read, processed, states = (float(x) for x in line.split()[2:5])
    assert as_read == pytest.approx(stated / STANDARD_GRAVITY, abs=6e-5)
    assert states == pytest.approx(stated / STANDARD_GRAVITY, abs=6e-5)
    assert processed != as_read  # the band-pass changed it, and the table says which is which
    assert "horizontal used by the solver: H1 (CE.89486..HN1" in out and "rule:" in out


# ------------------------------------------------------------------ catalogue ids
@needs_outside
def test_catalogue_ids_of_peer_files_are_clean(tmp_path):
    found = read_motions([str(LOMA), *map(str, PAIR)])
    ids = sorted(record_id(m) for m in found)
    assert ids == ["ANAHEIM-LAKEVIEW-RIVERDALE.HN", "CORRALITOS.HN"]
    assert record_file_stem(".Anaheim - Lakeview & Riverdale..36") == (
        "Anaheim_-_Lakeview_Riverdale..36")
    assert record_file_stem("south-napa-2014/NP.1765..HN") == "south-napa-2014_NP.1765..HN"


# ------------------------------------------------------------------ components a study needs
@needs_outside
def test_require_components_names_record_and_key():
    loma = read_motion(str(LOMA))
    with pytest.raises(RecordError, match=r'CORRALITOS.HN: has no vertical \(V\); it holds H1,'
                                          r' but vertical = "same" needs it'):
        require_components(loma, ("H1", "V"), record="CORRALITOS.HN", key='vertical = "same"')
    require_components(read_motion(str(V2)), ("H1", "V"), record="CE.89486..HN",
                       key='vertical = "same"')
    with pytest.raises(ParameterError, match="components"):
        require_components(loma, ("X",), record="CORRALITOS.HN", key="k")


# ------------------------------------------------------------------ every option in three places
def _flags(parser, command):
    sub = next(a for a in parser._actions if a.dest == "command").choices[command]
    return {flag for action in sub._actions for flag in action.option_strings}


def test_every_read_option_is_a_flag_of_each_record_command_and_a_catalogue_key():
    import inspect

    from shipblock.checks import READ_OPTIONS
    from shipblock.cli import build_parser
    from shipblock.records.catalogue import READ_KEYS

    parser = build_parser()
    keywords = set(inspect.signature(read_motion).parameters) - {"paths_or_stream",
                                                                 "read_kwargs"}
    keywords |= {"dt", "data_type", "resample_rate", "resample_interval"}  # reader keywords
    assert keywords <= set(READ_OPTIONS)
    for command in ("simulate", "info", "process", "catalogue"):
        flags = _flags(parser, command)
        for keyword, (flag, _) in READ_OPTIONS.items():
            if command == "catalogue" and keyword in ("azimuth", "horizontal"):
                continue  # a property of the dock, chosen when a record is used
            assert flag in flags, (command, flag)
    entry_keys = {key for _, key in READ_OPTIONS.values()}
    assert set(READ_KEYS) <= entry_keys
    # the catalogue entry's own fields carry the rest
    assert entry_keys - set(READ_KEYS) == {"units", "inventory", "event", "components",
                                           "horizontal", "azimuth"}


@needs_outside
def test_simulate_names_the_horizontal_and_takes_quantities(capsys, caplog):
    with caplog.at_level(logging.WARNING, logger="shipblock.system"):
        code, out, err = run(capsys, "simulate", str(V2), "--ship-mass", "20000 t",
                             "--block-mass", "4 t", "--n-blocks", "100", "--half-width", "600mm",
                             "--half-height", "0.75")
    assert code == 0, err
    assert "horizontal  H1 (CE.89486..HN1, azimuth 180 deg)" in out and "rule:" in out
    assert "M = 2e+07 kg on 100 blocks of 4000 kg" in out
    assert not [r for r in caplog.records if r.name == "shipblock.system"]
