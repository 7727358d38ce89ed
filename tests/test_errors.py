"""Bad input raises the project's own errors: one ``except ShipblockError`` catches them all,
and they stay ValueErrors for code that expects the conventional type."""

import numpy as np
import pytest

from shipblock import RecordSet, ShipBlockSystem, intensity, scaling, simulate, simulate_batch
from shipblock.errors import ParameterError, RecordError, ShipblockError
from shipblock.fragility.design import AnalysisDesign, IntensityDesign
from shipblock.fragility.fit import fit_mle
from shipblock.fragility.limit_states import LimitState
from shipblock.units import acceleration_to_si, velocity_to_si

ACC = np.sin(np.linspace(0.0, 10.0, 500))

CASES = {
    "negative ship mass": (lambda: ShipBlockSystem.example().replace(ship_mass=-1.0),
                           "ship_mass"),
    "kinetic above static": (lambda: ShipBlockSystem.example().replace(mu_k_ship=0.9),
                             "mu_k_ship"),
    "zero dt": (lambda: intensity.pga(ACC, 0.0), "dt"),
    "negative period": (lambda: intensity.response_spectrum(ACC, 0.01, [-1.0]), "periods"),
    "unknown measure": (lambda: scaling.measure_value(ACC, 0.01, "pgx"), "pgx"),
    "negative target": (lambda: scaling.amplitude_factor(ACC, 0.01, target=-1.0), "target"),
    "unknown acceleration unit": (lambda: acceleration_to_si(1.0, "furlong/s^2"), "furlong"),
    "unknown velocity unit": (lambda: velocity_to_si(1.0, "knots"), "knots"),
    "decreasing levels": (lambda: IntensityDesign("ida", levels=(2.0, 1.0)).validate(),
                          "increasing"),
    "empty design": (lambda: AnalysisDesign((), IntensityDesign("cloud"),
                                            ShipBlockSystem.example()).validate(), "records"),
    "counts above totals": (lambda: fit_mle([1.0, 2.0], [3, 1], [2, 2]), "n_exceed"),
    "unknown EDP": (lambda: LimitState("x", "ship_slipp", 0.1).validate(), "ship_slipp"),
    "simulate dt": (lambda: simulate(ShipBlockSystem.example(), ACC, None, -0.01), "dt"),
    "simulate NaN": (lambda: simulate(ShipBlockSystem.example(), np.r_[ACC, np.nan], None, 0.01),
                     "non-finite"),
    "simulate H/V lengths": (lambda: simulate(ShipBlockSystem.example(), ACC, ACC[:-1], 0.01),
                             "same length"),
    "batch case index": (lambda: simulate_batch([ShipBlockSystem.example()], [(ACC, None)], 0.01,
                                                [[1, 0, 1.0, 1.0]]), "record index"),
    "batch system index": (lambda: simulate_batch([ShipBlockSystem.example()], [(ACC, None)], 0.01,
                                                 [[0, 1, 1.0, 1.0]]), "system index"),
    "batch fractional index": (lambda: simulate_batch(ShipBlockSystem.example(),
                                                      [(ACC, None), (ACC, None)], 0.01,
                                                      [[0, 0, 1.0, 1.0], [0.5, 0, 1.0, 1.0]]),
                               "cases[1, 0] (record index) is 0.5"),
    "batch NaN scale": (lambda: simulate_batch(ShipBlockSystem.example(), [(ACC, None)], 0.01,
                                               [[0, 0, np.nan, 1.0]]),
                        "cases[0, 2] (horizontal scale) is nan"),
    "batch infinite vertical scale": (lambda: simulate_batch(ShipBlockSystem.example(),
                                                             [(ACC, ACC)], 0.01,
                                                             [[0, 0, 1.0, np.inf]]),
                                      "cases[0, 3] (vertical scale) is inf"),
    "batch NaN index": (lambda: simulate_batch(ShipBlockSystem.example(), [(ACC, None)], 0.01,
                                               [[np.nan, 0, 1.0, 1.0]]), "record index"),
    "batch NaN": (lambda: simulate_batch(ShipBlockSystem.example(),
                                         [(ACC, None), (ACC, np.r_[ACC[:-1], np.inf])], 0.01,
                                         [[0, 0, 1.0, 1.0]]), "records[1] vertical"),
    "batch dt of one record": (lambda: simulate_batch(ShipBlockSystem.example(),
                                                      [(ACC, None), (ACC, None)], [0.01, 0.0],
                                                      [[0, 0, 1.0, 1.0]]), "record 1"),
    "packed H/V lengths": (lambda: RecordSet([(ACC, ACC[:-1])], 0.01), "records[0]"),
    "packed records and dts": (lambda: simulate_batch(ShipBlockSystem.example(),
                                                      RecordSet([(ACC, None)], 0.01), 0.01,
                                                      [[0, 0, 1.0, 1.0]]), "dts"),
    "batch without dts": (lambda: simulate_batch(ShipBlockSystem.example(), [(ACC, None)],
                                                 cases=[[0, 0, 1.0, 1.0]]), "dts"),
}


def test_batch_finiteness_check_has_no_false_alarm():
    """simulate_batch checks finiteness on the sum of all records: finite samples whose sum
    overflows must still run (the check falls back to sample by sample)."""
    huge = np.full(4, 1e308)
    out = simulate_batch(ShipBlockSystem.example(), [(ACC, None), (huge, None)], 0.01,
                         [[0, 0, 1.0, 1.0]])
    assert np.isfinite(out["peak_block_slip"]).all()


@pytest.mark.parametrize("case", list(CASES))
def test_bad_input_raises_a_named_shipblock_error(case):
    make, named = CASES[case]
    with pytest.raises(ShipblockError) as info:
        make()
    assert isinstance(info.value, ValueError)
    assert isinstance(info.value, ParameterError | RecordError)
    assert named in str(info.value), str(info.value)
