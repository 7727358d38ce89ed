"""The Python API as a newcomer meets it (issue 31): the lazy names in ``dir(shipblock)``, what
``simulate`` says when given the pair ``scale_motion`` returns, and a readable result repr."""

from __future__ import annotations

import numpy as np
import pytest

import shipblock
from shipblock import ShipBlockSystem, simulate
from shipblock.errors import ParameterTypeError
from shipblock.records.motion import GroundMotion
from shipblock.scaling import scale_motion

DT = 0.005


@pytest.fixture(scope="module")
def motion():
    t = np.arange(0.0, 2.0, DT)
    return GroundMotion.from_arrays(3.0 * np.sin(2 * np.pi * t), dt=DT, name="sine")


def test_dir_lists_the_names_loaded_on_first_use():
    names = dir(shipblock)
    for name in ("simulate", "run_pipeline", "read_motion", "scaling", "ShipBlockSystem"):
        assert name in names
    assert set(shipblock._LAZY) <= set(names)
    assert names == sorted(names)


def test_simulate_says_to_pass_the_motion_of_what_scale_motion_returned(motion):
    pair = scale_motion(motion, factor=2.0)
    with pytest.raises(ParameterTypeError) as info:
        simulate(ShipBlockSystem.example(), pair)
    message = str(info.value)
    assert "tuple (GroundMotion, ScaledRecord)" in message
    assert "scale_motion(motion, ...)[0]" in message
    assert "dt is required" not in message and "dt [s] is required" not in message
    with pytest.raises(ParameterTypeError, match=r"ScaledRecord .*scaled\.horizontal"):
        simulate(ShipBlockSystem.example(), pair[1])


def test_result_repr_summarises_instead_of_dumping_arrays(motion):
    scaled, record = scale_motion(motion, factor=2.0)
    assert record.factor_h == 2.0
    res = simulate(ShipBlockSystem.example(), scaled)
    text = repr(res)
    assert "\n" not in text and len(text) < 300
    assert text.startswith(f"SimulationResult({res.time[-1]:.4g} s, {res.time.size} samples at "
                           f"dt = {DT:.4g} s, failure none")
    assert f"|x_s| {100 * res.summary['peak_ship_slip']:.4g} cm" in text
    assert f"{len(res.events)} events" in text
    assert "array(" not in text
