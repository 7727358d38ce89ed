"""``shipblock simulate --system FILE`` with ``[system] model = "section"``: one record on the
dock section, through :func:`shipblock.cli.main`.

Checks: at a static-like motion (the record scaled by 1e-5) the printed and stored keel-block
load is the weight per block, W / n, and its ratio to the rated capacity; ``--ship-mass``
replaces the file's mass (the load doubles with it); the histories are written as NetCDF
(``SectionRun.to_dataset``) and the response figure drawn; the rigid model's flags and a bad
key are refused by name.
"""

from __future__ import annotations

import numpy as np
import pytest
import xarray as xr

from shipblock.cli import main
from shipblock.section import NAVY_BLOCK
from shipblock.units import STANDARD_GRAVITY as G

from .test_batch import make_catalogue
from .test_section_study import SETTLING, _counting_rest_state
from .test_section_study import SYSTEM  # a 30 t ship on two narrow Navy keel blocks


@pytest.fixture(scope="module")
def records(tmp_path_factory):
    folder = tmp_path_factory.mktemp("records")
    return make_catalogue(folder, n_records=1)


def _simulate(tmp_path, records, *extra, system=SYSTEM):
    path = tmp_path / "dock.toml"
    path.write_text(system)
    return main(["simulate", "--catalogue", str(records), "--record", "S0", "--horizontal", "H1",
                 "--system", str(path), *extra])


def test_a_section_system_runs_the_section_model(tmp_path, records, capsys):
    out = tmp_path / "run.nc"
    assert _simulate(tmp_path, records, "--scale", "1e-5", "-o", str(out)) == 0
    text = capsys.readouterr().out
    load = 30e3 * G / 2  # the ship's weight on two keel blocks, at rest
    ratio = load / NAVY_BLOCK.capacity
    assert "failure  " in text and "none" in text.split("failure", 1)[1].splitlines()[0]
    assert f"peak {load / 1e3:.1f} kN per block = {ratio:.3f} of capacity" in text
    assert "peak / residual roll" in text and "events:" in text
    assert "side blocks" not in text  # no side lines
    with xr.open_dataset(out) as ds:
        assert ds.attrs["model"] == "section"
        assert ds.attrs["keel_capacity_ratio"] == pytest.approx(ratio, rel=1e-6)
        assert ds.attrs["failure_name"] == "none"
        for name in ("ship_sway", "ship_roll", "ground_acceleration_h"):
            assert name in ds and ds[name].dims == ("time",)
        # the ground the run was given: the record scaled by 1e-5, peak about 1e-5 m/s^2
        assert 0 < np.abs(ds["ground_acceleration_h"]).max() < 1e-4
    assert out.with_suffix(".png").stat().st_size > 0


def test_ship_mass_replaces_the_files_mass(tmp_path, records, capsys):
    assert _simulate(tmp_path, records, "--scale", "1e-5", "--ship-mass", "60 t",
                     "--figure", str(tmp_path / "r.png")) == 0
    text = capsys.readouterr().out
    load = 60e3 * G / 2
    assert f"peak {load / 1e3:.1f} kN per block = {load / NAVY_BLOCK.capacity:.3f}" in text
    assert "ship 60 t" in text
    assert (tmp_path / "r.png").stat().st_size > 0


def test_a_real_motion_loads_the_blocks_beyond_their_static_share(tmp_path, records, capsys):
    """At the record's own strength (peak about 1 m/s^2) the ship rocks on its two blocks:
    the peak load per block exceeds the static W / n, never by more than the whole weight."""
    out = tmp_path / "strong.nc"
    assert _simulate(tmp_path, records, "-o", str(out)) == 0
    capsys.readouterr()
    with xr.open_dataset(out) as ds:
        peak = ds.attrs["keel_peak_load_per_block"]
        assert 30e3 * G / 2 < peak < 30e3 * G * 1.5
        assert abs(ds.attrs["energy_residual"]) < 1e-3


@pytest.mark.parametrize("extra, needle", [
    (("--n-blocks", "4"), "--n-blocks sets the rigid model's system"),
    (("--mu-s-ship", "0.3"), "--mu-s-ship sets the rigid model's system"),
])
def test_rigid_flags_are_refused_for_a_section_system(tmp_path, records, capsys, extra,
                                                       needle):
    assert _simulate(tmp_path, records, *extra) != 0
    assert needle in capsys.readouterr().err


def test_a_bad_key_of_the_section_system_is_named(tmp_path, records, capsys):
    assert _simulate(tmp_path, records, system=SYSTEM + "keel_block = 3\n") != 0
    err = capsys.readouterr().err
    assert "dock.toml" in err and "keel_block" in err
    assert _simulate(tmp_path, records, system=SYSTEM.replace('"30 t"', '"30 m"')) != 0
    err = capsys.readouterr().err
    assert "[system.ship_mass]" in err


def test_a_pipelines_rigid_system_table_runs_the_rigid_model(tmp_path, records, capsys):
    """``model = "rigid"`` (a rigid pipeline's ``[system]``): the rigid model, with the system
    flags applied to it."""
    rigid = ('[system]\nmodel = "rigid"\nship_mass = "5000 t"\nblock_mass = "1.2 t"\n'
             'n_blocks = 150\nhalf_width = 0.3\nhalf_height = 0.6\nmu_s_ground = 0.6\n'
             'mu_k_ground = 0.55\nmu_s_ship = 0.35\nmu_k_ship = 0.3\n')
    assert _simulate(tmp_path, records, "--n-blocks", "100", system=rigid) == 0
    text = capsys.readouterr().out
    assert "M = 5e+06 kg on 100 blocks of 1200 kg" in text and "peak ship slip" in text


def test_atol_reaches_the_section_solver_and_is_checked_against_its_range(tmp_path, records,
                                                                          capsys):
    """--atol (with --rtol) is passed to the section model's integrator: the tolerances used
    are stored with the response; a value outside the section model's range (at most 1e-3)
    is refused naming the flag, not run."""
    out = tmp_path / "tol.nc"
    assert _simulate(tmp_path, records, "--scale", "1e-5", "--atol", "1e-8", "--rtol", "1e-7",
                     "-o", str(out)) == 0
    capsys.readouterr()
    with xr.open_dataset(out) as ds:
        assert ds.attrs["solver_atol"] == 1e-8 and ds.attrs["solver_rtol"] == 1e-7
    assert _simulate(tmp_path, records, "--atol", "0.01") == 2
    err = capsys.readouterr().err
    assert "--atol must be" in err and "1e-15, 0.001" in err and "section model" in err


def test_no_exponential_steps_reaches_the_section_solver(tmp_path, records, capsys):
    """--no-exponential-steps runs Dormand-Prince throughout: the same keel load to the
    tolerance, stored as solver_exponential_steps = 0 (1 by default); refused, naming the flag,
    for the rigid model."""
    loads = {}
    for flag, stored in (((), 1), (("--no-exponential-steps",), 0)):
        out = tmp_path / f"run{stored}.nc"
        assert _simulate(tmp_path, records, "--scale", "0.5", *flag, "-o", str(out)) == 0
        capsys.readouterr()
        with xr.open_dataset(out) as ds:
            assert ds.attrs["solver_exponential_steps"] == stored
            loads[stored] = float(ds["keel_top_normal"].max())
    assert loads[0] == pytest.approx(loads[1], rel=1e-4)
    rigid = ('[system]\nmodel = "rigid"\nship_mass = "5000 t"\nblock_mass = "1.2 t"\n'
             'n_blocks = 150\nhalf_width = 0.3\nhalf_height = 0.6\nmu_s_ground = 0.6\n'
             'mu_k_ground = 0.55\nmu_s_ship = 0.35\nmu_k_ship = 0.3\n')
    assert _simulate(tmp_path, records, "--no-exponential-steps", system=rigid) == 2
    assert "--no-exponential-steps applies to the section model" in capsys.readouterr().err


def test_the_system_files_solver_table_reaches_the_run(tmp_path, records, capsys):
    """A ``[solver]`` table beside ``[system]`` (a pipeline's, the same keys and checks) sets the
    run's options, where it was ignored: ``max_events = 3`` stops the real motion as stalled
    after three events, the options used are stored with the response; a flag overrides the
    file; an unknown key is refused naming the file and the key, before the record is read."""
    out = tmp_path / "solver.nc"
    with_solver = SYSTEM + "\n[solver]\nmax_events = 3\nseparation_height = 0.05\nrtol = 1e-7\n"
    assert _simulate(tmp_path, records, "-o", str(out), "--rtol", "1e-8",
                     system=with_solver) == 0
    assert "stalled at t =" in capsys.readouterr().out
    with xr.open_dataset(out) as ds:
        assert ds.attrs["failure_name"] == "stalled"
        assert ds.attrs["solver_max_events"] == 3
        assert ds.attrs["solver_separation_height"] == 0.05
        assert ds.attrs["solver_rtol"] == 1e-8  # the flag's, not the file's 1e-7
    assert _simulate(tmp_path, records, system=SYSTEM + "\n[solver]\nmax_event = 3\n") == 2
    err = capsys.readouterr().err
    assert "dock.toml" in err and "[solver.max_event] unknown key 'max_event'" in err


def test_a_plain_rigid_system_file_names_its_missing_keys(tmp_path, records, capsys):
    """A plain ``[system]`` table (no ``model``) without its friction coefficients: the missing
    keys named, not a Python signature; its ``[solver]`` table reaches the rigid solver."""
    plain = ('[system]\nship_mass = "5000 t"\nblock_mass = "1.2 t"\nn_blocks = 150\n'
             'half_width = 0.3\nhalf_height = 0.6\n')
    assert _simulate(tmp_path, records, system=plain) != 0
    err = capsys.readouterr().err
    assert "missing system parameter(s) ['mu_s_ground', 'mu_k_ground', 'mu_s_ship', " in err
    out = tmp_path / "rigid.nc"
    full = plain + ('mu_s_ground = 0.6\nmu_k_ground = 0.55\nmu_s_ship = 0.35\nmu_k_ship = 0.3\n'
                    '[solver]\nrtol = 1e-6\n')
    assert _simulate(tmp_path, records, "-o", str(out), system=full) == 0
    capsys.readouterr()
    with xr.open_dataset(out) as ds:
        assert ds.attrs["solver_rtol"] == 1e-6


def test_a_settling_dock_is_settled_once_per_simulate(tmp_path, records, capsys, monkeypatch):
    """``simulate --system`` on a dock that must settle before its static solve (a full run):
    the state the system's check solved is the one the run starts from (one solve, not two);
    with ``--ship-mass`` the file's dock is checked and the heavier one solved (two)."""
    calls = _counting_rest_state(monkeypatch)
    table = "\n".join(f"{k} = {v}" for k, v in SETTLING.items())
    system = f'[system]\nmodel = "section"\n{table}\n'
    assert _simulate(tmp_path, records, "--scale", "1e-5", system=system) == 0
    assert len(calls) == 1
    assert "none" in capsys.readouterr().out.split("failure", 1)[1].splitlines()[0]
    calls.clear()
    assert _simulate(tmp_path, records, "--scale", "1e-5", "--ship-mass", "650 t",
                     system=system) == 0
    assert [asm.section.ship.mass for asm in calls] == [6e5, 6.5e5]
