"""Bad input raises the project's own errors: one ``except ShipblockError`` catches them all,
and they stay ValueErrors for code that expects the conventional type."""

import numpy as np
import pytest

from shipblock import (
    RecordSet,
    ShipBlockSystem,
    intensity,
    scaling,
    simulate,
    simulate_batch,
    system_restitution,
)
from shipblock.errors import ParameterError, ParameterTypeError, RecordError, ShipblockError
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


def _motion(dt=0.01):
    from shipblock.motion import GroundMotion

    return GroundMotion.from_arrays(ACC, None, dt=dt, name="sine")


EX = ShipBlockSystem.example()
BATCH = dict(records=[(ACC, None)], dts=0.01, cases=[[0, 0, 1.0, 1.0]])

# The inputs of issue #23 (a fuzz campaign of bad API calls): each must end in a shipblock error
# that names the argument, not in a numba TypingError, an OverflowError, "too many values to
# unpack", a float() error or a NaN result.
ISSUE_23 = {
    "n_blocks nan": (lambda: EX.replace(n_blocks=float("nan")), "n_blocks"),
    "n_blocks inf": (lambda: EX.replace(n_blocks=float("inf")), "n_blocks"),
    "n_blocks None": (lambda: EX.replace(n_blocks=None), "n_blocks"),
    "n_blocks bool": (lambda: EX.replace(n_blocks=True), "n_blocks"),
    "mu None": (lambda: EX.replace(mu_s_ground=None), "mu_s_ground"),
    "mu string": (lambda: EX.replace(mu_k_ship="0.3"), "mu_k_ship"),
    "restitution string": (lambda: EX.replace(restitution="high"), "restitution"),
    "block_inertia list": (lambda: EX.replace(block_inertia=[1.0]), "block_inertia"),
    "block_inertia above m R^2": (lambda: EX.replace(block_inertia=1e9), "block_inertia"),
    "block_inertia denormal": (lambda: EX.replace(block_inertia=5e-324), "block_inertia"),
    "ship_mass 1e300": (lambda: EX.replace(ship_mass=1e300), "ship_mass"),
    "half_width 1e-300": (lambda: EX.replace(half_width=1e-300), "half_width"),
    "g huge int": (lambda: EX.replace(g=10**400), "g"),
    "impact_rule None": (lambda: EX.replace(impact_rule=None), "impact_rule"),
    "batch without systems": (lambda: simulate_batch([], **BATCH), "systems"),
    "batch empty systems and cases": (lambda: simulate_batch(systems=[], records=[(ACC, None)],
                                                             dts=0.01, cases=[]), "systems"),
    "batch system not a system": (lambda: simulate_batch([EX, "x"], **BATCH), "systems[1]"),
    "batch without records": (lambda: simulate_batch(EX, [], 0.01, []), "records"),
    "batch bare array record": (lambda: simulate_batch(EX, [ACC], 0.01, [[0, 0, 1.0, 1.0]]),
                                "records[0] must be a pair (ax, ay)"),
    "batch record as a 2-D array": (lambda: simulate_batch(EX, [np.stack([ACC, ACC])], 0.01,
                                                           [[0, 0, 1.0, 1.0]]), "records[0]"),
    "batch dts string": (lambda: simulate_batch(EX, [(ACC, None)], "0.01", [[0, 0, 1, 1]]),
                         "dts"),
    "batch cases string": (lambda: simulate_batch(EX, [(ACC, None)], 0.01, "all"), "cases"),
    "batch scale 1e300": (lambda: simulate_batch(EX, [(ACC, None)], 0.01, [[0, 0, 1e300, 1.0]]),
                          "cases[0, 2] (horizontal scale)"),
    "batch vertical scaled above 100 g": (lambda: simulate_batch(EX, [(ACC, ACC)], 0.01,
                                                                 [[0, 0, 1.0, 1e3]]),
                                          "cases[0, 3] (vertical scale)"),
    "batch record of 1e308": (lambda: simulate_batch(EX, [(ACC, None), (np.full(4, 1e308), None)],
                                                     0.01, [[0, 0, 1.0, 1.0]]),
                              "records[1] horizontal"),
    "batch rtol string": (lambda: simulate_batch(EX, **BATCH, rtol="1e-8"), "rtol"),
    "simulate GroundMotion with dt": (lambda: simulate(EX, _motion(), dt=0.01), "dt"),
    "simulate GroundMotion with ay": (lambda: simulate(EX, _motion(), ACC), "ay"),
    "simulate dt 1e300": (lambda: simulate(EX, ACC, None, 1e300), "dt"),
    "simulate dt 1e-300": (lambda: simulate(EX, ACC, None, 1e-300), "dt"),
    "simulate dt string": (lambda: simulate(EX, ACC, None, "0.01"), "dt"),
    "simulate ax 1e300": (lambda: simulate(EX, ACC * 1e300, None, 0.01), "ax"),
    "simulate ay 1e300": (lambda: simulate(EX, ACC, ACC * 1e300, 0.01), "ay"),
    "simulate ax above 100 g": (lambda: simulate(EX, ACC * 1000.0, None, 0.01), "100 g"),
    "simulate ax string": (lambda: simulate(EX, "ACC", None, 0.01), "ax"),
    "simulate ax complex": (lambda: simulate(EX, ACC + 1j, None, 0.01), "ax"),
    "simulate ax 2-D": (lambda: simulate(EX, np.stack([ACC, ACC]), None, 0.01), "ax"),
    "simulate system None": (lambda: simulate(None, ACC, None, 0.01), "system"),
    "simulate rtol nan": (lambda: simulate(EX, ACC, None, 0.01, rtol=float("nan")), "rtol"),
    "simulate rtol 1e-300": (lambda: simulate(EX, ACC, None, 0.01, rtol=1e-300), "rtol"),
    "simulate atol string": (lambda: simulate(EX, ACC, None, 0.01, atol="tight"), "atol"),
    "simulate atol inf": (lambda: simulate(EX, ACC, None, 0.01, atol=float("inf")), "atol"),
    "simulate zeno_omega negative": (lambda: simulate(EX, ACC, None, 0.01, zeno_omega=-1.0),
                                     "zeno_omega"),
    "simulate initial_state string": (lambda: simulate(EX, ACC, None, 0.01, initial_state="rest"),
                                      "initial_state"),
    "simulate initial_state short": (lambda: simulate(EX, ACC, None, 0.01, initial_state=[0, 0]),
                                     "initial_state"),
    "simulate initial_state 1e300 velocity": (
        lambda: simulate(EX, ACC, None, 0.01, initial_state=[0, 0, 0, 1e300, 0, 0]),
        "initial_state v_b"),
    "simulate initial_state beyond critical": (
        lambda: simulate(EX, ACC, None, 0.01, initial_state=[0, 2.0, 0, 0, 0, 0]),
        "initial_state theta"),
    "restitution of the system: alpha": (lambda: system_restitution(0.1, float("nan")), "alpha"),
    "restitution of the system: mass_ratio": (lambda: system_restitution("x", 0.2),
                                              "mass_ratio"),
}


def test_records_at_the_plausibility_limit_run():
    """Exactly 100 g (as given, or a case scaled to it) is accepted and gives finite results;
    the check does not depend on a sum of the samples (no overflow false alarm)."""
    from shipblock.checks import MAX_ACCELERATION

    peak = ACC / np.abs(ACC).max() * MAX_ACCELERATION
    res = simulate(EX, peak, None, 0.01)
    assert np.isfinite(res.x_b).all() and np.isfinite(res.summary["peak_block_slip"])
    out = simulate_batch(EX, [(ACC, None)] * 3, 0.01,
                         [[0, 0, MAX_ACCELERATION / np.abs(ACC).max(), 1.0]])
    assert out["peak_block_slip"][0] == res.summary["peak_block_slip"]


def test_empty_cases_give_empty_results():
    out = simulate_batch(EX, [(ACC, None)], 0.01, np.zeros((0, 4)))
    assert out["peak_block_slip"].shape == (0,)
    assert simulate_batch(EX, [(ACC, None)], 0.01, [])["failure"].shape == (0,)


@pytest.mark.parametrize("case", list(ISSUE_23))
def test_issue_23_api_inputs_raise_a_named_error(case):
    make, named = ISSUE_23[case]
    with pytest.raises(ParameterError) as info:
        make()
    assert named in str(info.value), str(info.value)
    if isinstance(info.value, ParameterTypeError):
        assert isinstance(info.value, TypeError) and isinstance(info.value, ValueError)


def test_a_wrong_type_is_also_a_type_error():
    with pytest.raises(TypeError, match="n_blocks"):
        EX.replace(n_blocks="many")
    with pytest.raises(TypeError, match="records\\[0\\]"):
        simulate_batch(EX, [ACC], 0.01, [[0, 0, 1.0, 1.0]])


def test_whole_float_n_blocks_is_kept_as_an_int():
    system = EX.replace(n_blocks=120.0)
    assert system.n_blocks == 120 and isinstance(system.n_blocks, int)


@pytest.mark.parametrize("case", list(CASES))
def test_bad_input_raises_a_named_shipblock_error(case):
    make, named = CASES[case]
    with pytest.raises(ShipblockError) as info:
        make()
    assert isinstance(info.value, ValueError)
    assert isinstance(info.value, ParameterError | RecordError)
    assert named in str(info.value), str(info.value)


# -------------------------------------------------------------------------------------------
# every public function of intensity, scaling, processing and fit, every argument, garbage
# -------------------------------------------------------------------------------------------


def _stream():
    from obspy import Stream, Trace

    tr = Trace(2.0 * np.sin(np.linspace(0.0, 20.0, 400)))
    tr.stats.delta = 0.01
    return Stream([tr])


def _public_calls():
    from shipblock import processing as P
    from shipblock.fragility import fit as F

    acc = 2.0 * np.sin(np.linspace(0.0, 20.0, 400))
    acc2 = np.cos(np.linspace(0.0, 20.0, 400))
    exceeded = np.array([[0, 0, 1], [0, 1, 1], [0, 1, 1], [1, 1, 1]], dtype=bool)
    im_, sc = intensity, scaling
    return {
        "velocity": (im_.velocity, dict(acc=acc, dt=0.01)),
        "displacement": (im_.displacement, dict(acc=acc, dt=0.01)),
        "pga": (im_.pga, dict(acc=acc, dt=0.01)),
        "pgv": (im_.pgv, dict(acc=acc, dt=0.01)),
        "pgd": (im_.pgd, dict(acc=acc, dt=0.01)),
        "arias_intensity": (im_.arias_intensity, dict(acc=acc, dt=0.01)),
        "husid": (im_.husid, dict(acc=acc, dt=0.01)),
        "significant_duration": (im_.significant_duration,
                                 dict(acc=acc, dt=0.01, start=0.05, end=0.95)),
        "cav": (im_.cav, dict(acc=acc, dt=0.01)),
        "cav5": (im_.cav5, dict(acc=acc, dt=0.01, threshold=0.05)),
        "sdof_response": (im_.sdof_response, dict(acc=acc, dt=0.01, period=0.5, damping=0.05)),
        "response_spectrum": (im_.response_spectrum,
                              dict(acc=acc, dt=0.01, periods=[0.1, 0.5], damping=0.05)),
        "spectral_acceleration": (im_.spectral_acceleration,
                                  dict(acc=acc, dt=0.01, periods=[0.1, 0.5], damping=0.05)),
        "intensity_measures": (im_.intensity_measures,
                               dict(acc=acc, dt=0.01, periods=[0.1, 0.5], damping=0.05)),
        "intensity_measures_hv": (im_.intensity_measures_hv,
                                  dict(horizontal=acc, vertical=acc2, dt=0.01)),
        "measure_value": (sc.measure_value,
                          dict(acc=acc, dt=0.01, measure="sa", period=0.5, damping=0.05)),
        "amplitude_factor": (sc.amplitude_factor, dict(acc=acc, dt=0.01, target=3.0)),
        "scale": (sc.scale, dict(acc=acc, factor=2.0)),
        "scale_record": (sc.scale_record,
                         dict(horizontal=acc, vertical=acc2, dt=0.01, target=3.0)),
        "polynomial_baseline": (P.polynomial_baseline, dict(acc=acc, dt=0.01, order=4)),
        "apply_chain": (P.apply_chain, dict(stream=_stream(), chain=[{"step": "demean"}])),
        "highpass": (P.highpass, dict(stream=_stream(), freq=0.1, corners=4, zerophase=True)),
        "lowpass": (P.lowpass, dict(stream=_stream(), freq=20.0, corners=4)),
        "bandpass": (P.bandpass, dict(stream=_stream(), freqmin=0.1, freqmax=20.0)),
        "taper": (P.taper, dict(stream=_stream(), max_percentage=0.05, type="hann",
                                side="both")),
        "detrend": (P.detrend, dict(stream=_stream(), type="linear")),
        "resample": (P.resample, dict(stream=_stream(), sampling_rate=50.0)),
        "trim": (P.trim, dict(stream=_stream(), start=0.5, end=2.0)),
        "pad": (P.pad, dict(stream=_stream(), before=1.0, after=1.0)),
        "baseline": (P.baseline, dict(stream=_stream(), order=4)),
        "lognormal_fragility": (F.lognormal_fragility, dict(x=[0.1, 1.0], median=0.5, beta=0.4)),
        "fit_mle": (F.fit_mle, dict(im_levels=[1.0, 2.0, 3.0], n_exceed=[1, 3, 8],
                                    n_total=[10, 10, 10])),
        "fit_msa": (F.fit_msa, dict(exceeded=exceeded, im_levels=[1.0, 2.0, 3.0])),
        "ida_capacities": (F.ida_capacities, dict(exceeded=exceeded, im_levels=[1.0, 2.0, 3.0])),
        "fit_ida": (F.fit_ida, dict(capacities=[1.0, 2.0, 3.0, 1.5, 2.5], method="mle")),
        "fit_cloud": (F.fit_cloud, dict(im=[1.0, 2.0, 3.0, 4.0, 5.0, 6.0],
                                        edp=[0.1, 0.3, 0.2, 0.6, 0.5, 1.0], capacity=0.4,
                                        method="regression")),
        "bootstrap": (F.bootstrap, dict(fit_function=F.fit_ida,
                                        records={"capacities": np.array([1.0, 2.0, 3.0, 1.5,
                                                                         2.5])},
                                        n_boot=10, confidence=0.9, seed=1)),
    }


GARBAGE = {"None": None, "string": "abc", "nan": float("nan"), "inf": float("inf"),
           "negative": -1.0, "zero": 0.0, "1e300": 1e300, "1e-300": 1e-300, "empty list": [],
           "2-D list": [[1.0, 2.0], [3.0, 4.0]], "bool": True, "object": object(),
           "array with NaN": np.array([np.nan, 1.0, 2.0])}


def _finite(value) -> bool:
    from obspy import Stream

    parts = value if isinstance(value, tuple) else (value,)
    try:
        return all(np.isfinite(np.asarray(p, dtype=float)).all() for p in parts
                   if not isinstance(p, str | Stream))
    except (TypeError, ValueError):
        return True  # a result object (ScaledRecord, FragilityFit...): not an array


@pytest.mark.filterwarnings("ignore")
@pytest.mark.parametrize("function", list(_public_calls()))
def test_every_public_function_accepts_or_names_a_bad_argument(function):
    """The issue's rule for every public function: each argument replaced in turn by garbage
    gives a finite result or an error that names that argument: a shipblock error, or a
    TypeError that names it - never a numpy or float() error, an OverflowError or NaN."""
    from obspy import Stream

    fn, good = _public_calls()[function]
    fn(**{k: (v.copy() if isinstance(v, Stream) else v) for k, v in good.items()})
    problems = []
    for arg in good:
        for label, bad in GARBAGE.items():
            args = {k: (v.copy() if isinstance(v, Stream) else v) for k, v in good.items()}
            args[arg] = bad
            try:
                out = fn(**args)
            except (ShipblockError, TypeError) as exc:
                message = str(exc)
                names = {arg, "acceleration"} if arg == "acc" else {arg}
                if not any(n in message for n in names):
                    problems.append(f"{arg}={label}: {type(exc).__name__} does not name it: "
                                    f"{message}")
            except Exception as exc:  # noqa: BLE001 - the failure under test
                problems.append(f"{arg}={label}: {type(exc).__name__}: {exc}")
            else:
                if not _finite(out):
                    problems.append(f"{arg}={label}: accepted with a non-finite result")
    assert not problems, "\n".join(problems)
