"""Bad input raises the project's own errors: one ``except ShipblockError`` catches them all,
and they stay ValueErrors for code that expects the conventional type."""

from pathlib import Path

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
from shipblock.checks import MAX_ACCELERATION
from shipblock.errors import ParameterError, ParameterTypeError, RecordError, ShipblockError
from shipblock.fragility.design import AnalysisDesign, IntensityDesign
from shipblock.fragility.fit import fit_mle
from shipblock.fragility.limit_states import LimitState
from shipblock.processing import process_motion
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
    "process_motion of an array": (lambda: process_motion(ACC), "motion"),
    "scale_motion of a tuple": (lambda: scaling.scale_motion((ACC, None), target=1.0), "motion"),
}


def _motion(dt=0.01):
    from shipblock.records.motion import GroundMotion

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


# -------------------------------------------------------------------------------------------
# the reader-side entry points, every argument, garbage
# -------------------------------------------------------------------------------------------

DATA = Path(__file__).parent / "data"
#: Three one-component PEER files of 7 samples: H1 (180 deg), H2 (270 deg) and V.
HELENA = [str(DATA / f"helena_synthetic_{c}.AT2") for c in ("180", "270", "dwn")]


def _reader_calls():
    from shipblock.io import read_record
    from shipblock.records.catalogue import catalogue_toml, default_catalogue_path, load_catalogue
    from shipblock.records.folders import expand_sources, read_motions
    from shipblock.records.motion import GroundMotion, rotate_to_azimuth
    from shipblock.records.reading import read_motion

    acc = 2.0 * np.sin(np.linspace(0.0, 20.0, 400))
    acc2 = np.cos(np.linspace(0.0, 20.0, 400))
    motion = GroundMotion.from_arrays(acc, acc2, dt=0.01, name="sine")
    return {
        "read_record": (read_record, dict(path=HELENA[0], format=None, units=None, dt=None)),
        "read_motion": (read_motion, dict(paths_or_stream=HELENA, inventory=None, units=None,
                                          azimuth=30.0, horizontal=None,
                                          response="sensitivity", channel_map=None, event=None,
                                          gaps="refuse", align="trim", format=None,
                                          differentiate=False, sensor=None)),
        "read_motions": (read_motions, dict(source=HELENA, inventory=None, units=None,
                                            response="sensitivity", differentiate=False,
                                            align="trim", gaps="refuse", event=None)),
        "expand_sources": (expand_sources, dict(source=HELENA)),
        "load_catalogue": (load_catalogue, dict(path=default_catalogue_path())),
        "catalogue_toml": (catalogue_toml, dict(motions=read_motions(HELENA),
                                                output="catalogue.toml", licence="CC0",
                                                credit="synthetic", units=None)),
        "from_arrays": (GroundMotion.from_arrays, dict(horizontal=acc, vertical=acc2, dt=0.01,
                                                      units="m/s^2", name="sine",
                                                      azimuth_h1=None)),
        "GroundMotion": (GroundMotion, dict(stream=motion.stream, metadata=motion.metadata,
                                            azimuth=None, horizontal="H1")),
        "with_stream": (motion.with_stream, dict(stream=motion.stream, note="scaled x2")),
        "rotate_to_azimuth": (rotate_to_azimuth, dict(h1=acc, h2=acc2, azimuth_h1=0.0,
                                                      azimuth_h2=90.0, azimuth=30.0)),
    }


#: Garbage for the reader arguments on top of GARBAGE: the values issue #23 names.
READER_GARBAGE = {**GARBAGE, "unknown word": "furlongs", "sensor XX": "XX",
                  "response partial": "partial", "a folder": str(DATA / "reference"),
                  "a missing file": str(DATA / "no_such_record.AT2"), "empty string": "",
                  "a Path": DATA / "no_such_record.AT2", "negative int": -5,
                  "dict": {"H1": "X"}}


@pytest.mark.filterwarnings("ignore")
@pytest.mark.parametrize("function", list(_reader_calls()))
def test_every_reader_entry_point_accepts_or_names_a_bad_argument(function, tmp_path,
                                                                 monkeypatch):
    """The same rule for the reader side: read_record, read_motion, read_motions,
    load_catalogue, catalogue_toml, GroundMotion and its constructors: each argument replaced
    in turn by garbage (wrong types, NaN/inf, 1e300, unknown words, missing files, folders)
    gives a good result or a shipblock error (or TypeError) whose message names the argument."""
    from obspy import Stream

    from shipblock.records.motion import GroundMotion

    monkeypatch.chdir(tmp_path)  # 'abc' or 'furlongs' must name no file
    fn, good = _reader_calls()[function]

    def fresh(value):
        return value.copy() if isinstance(value, Stream) else value

    fn(**{k: fresh(v) for k, v in good.items()})
    problems, refused = [], 0
    for arg in good:
        for label, bad in READER_GARBAGE.items():
            args = {k: fresh(v) for k, v in good.items()}
            args[arg] = bad
            try:
                out = fn(**args)
            except (ShipblockError, TypeError) as exc:
                refused += 1
                # a folder that exists but holds no usable record is a record problem: named
                # by the folder, the way every record error names its file
                about_the_folder = (isinstance(exc, RecordError) and label == "a folder"
                                    and exc.source == str(bad))
                if arg not in str(exc) and not about_the_folder:
                    problems.append(f"{arg}={label}: {type(exc).__name__} does not name it: "
                                    f"{exc}")
            except Exception as exc:  # noqa: BLE001 - the failure under test
                problems.append(f"{arg}={label}: {type(exc).__name__}: {exc}")
            else:
                if isinstance(out, GroundMotion) and not all(
                        np.isfinite(c).all() and np.abs(c).max() <= MAX_ACCELERATION
                        for c in out.components.values()):
                    problems.append(f"{arg}={label}: accepted with samples NaN or above 100 g")
                elif not _finite(out):
                    problems.append(f"{arg}={label}: accepted with a non-finite result")
    assert not problems, "\n".join(problems)
    assert refused >= len(good) * 8  # most garbage is refused, not quietly taken


READER_CASES = {
    "units furlongs": (lambda: _read(units="furlongs"), ParameterError,
                       "units must be an acceleration unit .*'furlongs'"),
    "units not a string": (lambda: _read(units=9.81), ParameterTypeError, "units"),
    "sensor XX": (lambda: _read(sensor="XX"), ParameterError, "sensor='XX' matches none"),
    "response partial": (lambda: _read(response="partial"), ParameterError,
                         "response must be one of 'sensitivity', 'full', got 'partial'"),
    "azimuth NaN": (lambda: _read(azimuth=float("nan")), ParameterError,
                    r"azimuth must be a number in \[-360, 360\] \[deg\], got nan"),
    "azimuth 1e300": (lambda: _read(azimuth=1e300), ParameterError, "azimuth"),
    "azimuth and horizontal": (lambda: _read(azimuth=0.0, horizontal="H1"), ParameterError,
                               "not both"),
    "horizontal H3": (lambda: _read(horizontal="H3"), ParameterError, "horizontal"),
    "differentiate 'yes'": (lambda: _read(differentiate="yes"), ParameterTypeError,
                            "differentiate must be True or False"),
    "channel_map list": (lambda: _read(channel_map=["HN1"]), ParameterTypeError,
                         "channel_map must be a dict"),
    "channel_map value": (lambda: _read(channel_map={"180": "X"}), ParameterError,
                          r"channel_map\['180'\] must be one of 'H1', 'H2', 'V'"),
    "format unknown": (lambda: _read(format="SEISMO"), ParameterError,
                       "format must be None .*MSEED.*SHIPBLOCK_AT2.*got 'SEISMO'"),
    "dt of a text file NaN": (lambda: _read(dt=float("nan")), ParameterError, "dt must be"),
    "missing record": (lambda: _read(DATA / "no_such.AT2"), RecordError,
                       "no_such.AT2: no such file .paths_or_stream must name"),
    "record is a folder in a list": (lambda: _read([HELENA[0], DATA]), RecordError,
                                     r"is a folder, not a file .paths_or_stream\[1\]"),
    "no record": (lambda: _read([]), ParameterError, "paths_or_stream .* got an empty list"),
    "record None": (lambda: _read(None), ParameterTypeError, "paths_or_stream must be"),
    "inventory is a folder": (lambda: _read(inventory=DATA), RecordError,
                              "is a folder, not a file .inventory must name a StationXML"),
    "inventory missing": (lambda: _read(inventory="nothere.xml"), RecordError,
                          "nothere.xml: no such file .inventory"),
    "event of a number": (lambda: _read(event=7), ParameterTypeError, "event must be"),
    "event missing": (lambda: _read(event="nothere.xml"), RecordError, "no such file .event"),
    "empty folder": (lambda: _read(Path.cwd()), RecordError, "holds no file .an empty folder"),
    "read_motions response": (lambda: _read_all(response="partial"), ParameterError,
                              "response"),
    "read_motions units": (lambda: _read_all(units="furlongs"), ParameterError, "units"),
    "read_motions no source": (lambda: _read_all(source=None), ParameterTypeError,
                               "source must be a path"),
    "read_motions missing source": (lambda: _read_all(source="nothere/"), RecordError,
                                    "nothere/: no such file or folder .source"),
    "read_record folder": (lambda: _record(DATA), RecordError,
                           "is a folder, not a file .path must name a record file"),
    "read_record None": (lambda: _record(None), ParameterTypeError, "path must be a path"),
    "read_record units": (lambda: _record(HELENA[0], units="furlongs"), ParameterError,
                          "units"),
    "read_record resample_rate": (lambda: _record(HELENA[0], resample_rate=0.0),
                                  ParameterError, r"resample_rate must be a number in \[1, "),
    "catalogue folder": (lambda: _catalogue(DATA), RecordError,
                         "is a folder, not a file .path must name a catalogue"),
    "catalogue number": (lambda: _catalogue(5), ParameterTypeError, "path must be a path"),
    "catalogue entry units": (lambda: _entry().read(units="g"), ParameterError,
                              "units is set by the catalogue entry 'south-napa-2014/NP.1737'"),
    "catalogue entry azimuth": (lambda: _entry().read(azimuth="N"), ParameterTypeError,
                                "azimuth must be a number"),
    "from_arrays 100 g": (lambda: _arrays(ACC * 1e3), ParameterError,
                          "horizontal has .* above the plausibility limit .*100 g"),
    "from_arrays 200 g in g": (lambda: _arrays(ACC * 200.0, units="g"), ParameterError,
                               r"horizontal \(in m/s\^2, from g\) has"),
    "from_arrays NaN vertical": (lambda: _arrays(ACC, np.r_[ACC[:-1], np.nan]), ParameterError,
                                 "vertical has 1 sample.*nan at index 499"),
    "from_arrays dt 1e-300": (lambda: _arrays(ACC, dt=1e-300), ParameterError,
                              r"dt must be a number in \[0.0001, 1\] \[s\], got 1e-300"),
    "from_arrays dt 1e300": (lambda: _arrays(ACC, dt=1e300), ParameterError, "dt must be"),
    "from_arrays dt None": (lambda: _arrays(ACC, dt=None), ParameterTypeError, "dt must be"),
    "from_arrays one sample": (lambda: _arrays([1.0]), ParameterError,
                               "horizontal must have at least 2 samples"),
    "from_arrays units furlongs": (lambda: _arrays(ACC, units="furlongs"), ParameterError,
                                   "units must be an acceleration unit"),
    "from_arrays velocity units": (lambda: _arrays(ACC, units="cm/s"), ParameterError,
                                   "units must be an acceleration unit"),
    "GroundMotion of a list": (lambda: _gm_class()([ACC]), ParameterTypeError,
                               "stream must be an obspy Stream"),
    "GroundMotion above 100 g": (lambda: _gm_class()(_stream_of(ACC * 1e3)), RecordError,
                                 "H1 .* has a sample of .* not a ground acceleration"),
    "GroundMotion dt 1e-30": (lambda: _gm_class()(_stream_of(ACC, delta=1e-30)), RecordError,
                              "sampling interval 1e-30 s is outside"),
}


_HELENA = object()


def _read(source=_HELENA, **kwargs):
    from shipblock.records.reading import read_motion

    return read_motion(HELENA if source is _HELENA else source, **kwargs)


def _read_all(source=HELENA, **kwargs):
    from shipblock.records.folders import read_motions

    return read_motions(source, **kwargs)


def _record(path, **kwargs):
    from shipblock.io import read_record

    return read_record(path, **kwargs)


def _catalogue(path):
    from shipblock.records.catalogue import load_catalogue

    return load_catalogue(path)


def _entry():
    from shipblock.records.catalogue import load_catalogue

    return load_catalogue()["south-napa-2014/NP.1737"]


def _arrays(horizontal, vertical=None, **kwargs):
    from shipblock.records.motion import GroundMotion

    return GroundMotion.from_arrays(horizontal, vertical, **kwargs)


def _gm_class():
    from shipblock.records.motion import GroundMotion

    return GroundMotion


def _stream_of(data, delta=0.01):
    from obspy import Stream, Trace

    from shipblock.records.motion import COMPONENT_KEY

    trace = Trace(np.asarray(data, dtype=float))
    trace.stats.delta = delta
    trace.stats[COMPONENT_KEY] = "H1"
    return Stream([trace])


@pytest.mark.filterwarnings("ignore")
@pytest.mark.parametrize("case", list(READER_CASES))
def test_reader_arguments_of_issue_23_raise_a_named_error(case, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    make, kind, message = READER_CASES[case]
    with pytest.raises(kind, match=message):
        make()


def test_masked_samples_are_refused_not_computed_with():
    """A masked array's masked slots hold arbitrary values: simulating with them is refused by
    name; an array whose mask hides nothing runs exactly as its data."""
    system = ShipBlockSystem.example()
    t = np.arange(2000) * 0.01
    ah = 6.0 * np.sin(2 * np.pi * t)  # above the friction limit: the ship slides
    masked = np.ma.masked_array(ah.copy(), mask=np.zeros(ah.size, bool))
    masked.data[500:600] = 1e3  # what a gap's slots may hold
    masked.mask[500:600] = True
    with pytest.raises(ParameterError, match=r"100 masked samples \(the first at index 500\)"):
        simulate(system, masked, dt=0.01)
    clear = np.ma.masked_array(ah, mask=np.zeros(ah.size, bool))
    np.testing.assert_array_equal(simulate(system, clear, dt=0.01).x_s,
                                  simulate(system, ah, dt=0.01).x_s)
