"""Quantities with units on the command line and in TOML, and the plausibility warnings
(issue 31): a README system given in tonnes as kilograms must not run silently."""

from __future__ import annotations

import logging

import pytest

from shipblock.cli import _system_from_args, build_parser
from shipblock.errors import ParameterError, ParameterTypeError
from shipblock.quantities import to_si
from shipblock.system import ShipBlockSystem, implausible

README_KG = ["--ship-mass", "20000", "--block-mass", "4", "--n-blocks", "100",
             "--half-width", "0.6", "--half-height", "0.75"]


@pytest.mark.parametrize("value, unit, expected", [
    ("20000 t", "kg", 2.0e7),
    ("4 tonne", "kg", 4000.0),
    ("600mm", "m", 0.6),
    ("75 cm", "m", 0.75),
    ("2 ft", "m", 0.6096),          # international foot, exact
    ("1 lb", "kg", 0.45359237),      # avoirdupois pound, exact
    ("0.6", "m", 0.6),              # a plain number is SI
    (0.6, "m", 0.6),
    (20000, "kg", 20000.0),
])
def test_to_si_converts_quantities_and_keeps_plain_numbers(value, unit, expected):
    assert to_si(value, unit, "key") == pytest.approx(expected, rel=1e-12)


def test_to_si_refuses_a_wrong_dimension_naming_the_key():
    # pint reads "kt" as the knot: a speed, not kilotonnes
    with pytest.raises(ParameterError, match=r"--ship-mass .*'20 kt' is a \[length\] / \[time\]"):
        to_si("20 kt", "kg", "--ship-mass")
    with pytest.raises(ParameterError, match="half_width .*not defined"):
        to_si("3 blocks", "m", "half_width")
    with pytest.raises(ParameterTypeError, match="ship_mass"):
        to_si(None, "kg", "ship_mass")


def test_system_table_takes_quantities(tmp_path):
    toml = tmp_path / "system.toml"
    toml.write_text('[system]\nship_mass = "20000 t"\nblock_mass = "4 t"\nn_blocks = 100\n'
                    'half_width = "600 mm"\nhalf_height = 0.75\nmu_s_ground = 0.5\n'
                    'mu_k_ground = 0.4\nmu_s_ship = 0.6\nmu_k_ship = 0.5\n')
    system = ShipBlockSystem.from_toml(toml)
    assert system.ship_mass == pytest.approx(2.0e7)
    assert system.block_mass == pytest.approx(4000.0)
    assert system.half_width == pytest.approx(0.6)
    toml.write_text(toml.read_text().replace('"600 mm"', '"600 kg"'))
    with pytest.raises(ParameterError, match=r"system.toml: half_width must be .*\[mass\]"):
        ShipBlockSystem.from_toml(toml)


def test_command_line_quantities_give_the_same_system_as_si_numbers():
    args = build_parser().parse_args(["simulate", "--ship-mass", "20000 t", "--block-mass",
                                      "4 t", "--n-blocks", "100", "--half-width", "600mm",
                                      "--half-height", "750 mm"])
    si = build_parser().parse_args(["simulate", "--ship-mass", "2e7", "--block-mass", "4000",
                                    "--n-blocks", "100", "--half-width", "0.6",
                                    "--half-height", "0.75"])
    assert _system_from_args(args) == _system_from_args(si)


def test_readme_system_in_kilograms_warns_loudly(caplog):
    args = build_parser().parse_args(["simulate", *README_KG])
    with caplog.at_level(logging.WARNING, logger="shipblock.system"):
        system = _system_from_args(args)
    messages = [r.getMessage() for r in caplog.records if r.levelno == logging.WARNING]
    # 4 kg in 1.2 m x 1.5 m x 1 m: 2.2 kg/m^3; 20000 kg x g / 100 = 1.96 kN per block
    assert any("block density 2.22 kg/m^3" in m for m in messages)
    assert any("ship weight per block 1.96 kN" in m for m in messages)
    assert len(implausible(system)) == 2


def test_plausible_docks_do_not_warn():
    assert implausible(ShipBlockSystem.example()) == []
    tonnes = ShipBlockSystem.from_mapping({
        "ship_mass": "20000 t", "block_mass": "4 t", "n_blocks": 100, "half_width": 0.6,
        "half_height": 0.75, "mu_s_ground": 0.5, "mu_k_ground": 0.4, "mu_s_ship": 0.6,
        "mu_k_ship": 0.5})
    assert implausible(tonnes) == []


def test_blocks_heavier_than_the_ship_warn():
    # 100 blocks of 40 t under a 2000 t ship: blocks outweigh the ship
    system = ShipBlockSystem.example().replace(ship_mass=2.0e6, block_mass=4.0e4, n_blocks=100,
                                               half_width=1.0, half_height=2.0)
    found = implausible(system)
    assert any("M/(n m) = 0.5" in f for f in found)


def test_a_pipeline_system_takes_quantities_with_units():
    """``ship_mass = "5000 t"`` and ``half_height = "600 mm"`` in a pipeline's [system] give
    the same system as the SI numbers; a quantity of the wrong dimension names the key."""
    from pathlib import Path

    from shipblock.fragility.keys import PipelineError
    from shipblock.fragility.schema import parse_pipeline

    folder = Path(__file__).resolve().parents[1] / "pipelines"
    text = (folder / "demo.toml").read_text()
    assert "ship_mass = 5.0e6" in text and "half_height = 0.6 " in text
    si = parse_pipeline(text, base=folder).design.system
    with_units = text.replace("ship_mass = 5.0e6", 'ship_mass = "5000 t"').replace(
        "half_height = 0.6 ", 'half_height = "600 mm" ')
    assert parse_pipeline(with_units, base=folder).design.system == si
    with pytest.raises(PipelineError, match=r"'5000 m' is a \[length\], not a \[mass\]") as err:
        parse_pipeline(text.replace("ship_mass = 5.0e6", 'ship_mass = "5000 m"'), base=folder)
    assert err.value.key == "system.ship_mass"


def test_a_record_without_vertical_is_left_out_when_the_vertical_is_scaled_with_it():
    """vertical = "same" needs a vertical: a horizontal-only record is left out with the key
    named, not run horizontal-only (whose only trace would be NaNs in the results)."""
    from pathlib import Path

    from shipblock import read_motion
    from shipblock.fragility.batch import prepare_record
    from shipblock.fragility.design import IntensityDesign

    data = Path(__file__).resolve().parent / "data"
    horizontal_only = read_motion(str(data / "helena_synthetic_180.AT2"))
    assert horizontal_only.vertical is None
    levels = [1.0, 2.0]
    same = IntensityDesign("ida", levels=levels, vertical="same").validate()
    left_out = prepare_record("helena.180", lambda: horizontal_only, [], same)
    assert left_out.error is not None and 'vertical = "same"' in left_out.error
    assert "has no vertical" in left_out.error
    zero = IntensityDesign("ida", levels=levels, vertical="zero").validate()
    assert prepare_record("helena.180", lambda: horizontal_only, [], zero).error is None
