"""Property tests of the API's argument checks (issue #23, "keep it found").

Whatever arguments hypothesis makes up for :class:`~shipblock.ShipBlockSystem`,
:func:`~shipblock.simulate` and :func:`~shipblock.simulate_batch`, the call either returns a
result with finite summaries or raises a :class:`~shipblock.errors.ParameterError` that names
the argument at fault: never another exception type, a NaN result or a hang. The reader side
(:func:`~shipblock.read_motion`, :func:`~shipblock.read_record`,
:meth:`~shipblock.GroundMotion.from_arrays`, :func:`~shipblock.rotate_to_azimuth`,
:func:`~shipblock.load_catalogue`) is held to the same rule on three 7-sample PEER files. An oracle written
from the documented limits (:data:`shipblock.system.FIELD_LIMITS`, :mod:`shipblock.checks`)
says which arguments are wrong, so a message naming a good argument fails the test too.

Records are a few tens of samples, so each example costs well under a millisecond once the
solver is compiled (the compilation is shared with the other solver tests).
"""

from __future__ import annotations

import math
import os
import re
import shutil
import tempfile
import time
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, event, given, settings
from hypothesis import strategies as st

from shipblock import ShipBlockSystem, simulate, simulate_batch
from shipblock.records.catalogue import load_catalogue
from shipblock.checks import MAX_ACCELERATION, MAX_TIME_STEP, MIN_TIME_STEP
from shipblock.errors import ParameterError, RecordError, ShipblockError
from shipblock.io import read_record
from shipblock.records.motion import GroundMotion, rotate_to_azimuth
from shipblock.records.reading import read_motion
from shipblock.system import FIELD_LIMITS, MIN_INERTIA_RATIO
from shipblock.units import ACCELERATION_UNITS_TO_SI, canonical_unit, canonical_velocity_unit

SETTINGS = settings(max_examples=300, deadline=None, derandomize=True,
                    suppress_health_check=[HealthCheck.too_slow])

#: Longest a single example may take [s]: far above the cost of these tiny inputs, far below
#: what a hang would take.
SLOW = 20.0

BASE = ShipBlockSystem(ship_mass=2e6, block_mass=1500.0, n_blocks=100, half_width=0.35,
                       half_height=0.6, mu_s_ground=0.6, mu_k_ground=0.5, mu_s_ship=0.5,
                       mu_k_ship=0.4)

# -------------------------------------------------------------------------------------------
# strategies: a mix of good values and the garbage of the fuzz campaign
# -------------------------------------------------------------------------------------------

def mostly(good, bad, weight: int = 6):
    """``good`` about ``weight`` times as often as ``bad``."""
    return st.sampled_from([True] * weight + [False]).flatmap(lambda ok: good if ok else bad)


GARBAGE = st.sampled_from([None, "1.0", "abc", b"1", True, False, [1.0], (2.0,), {"a": 1},
                           np.array([1.0, 2.0]), 1 + 2j, object()])
EXTREMES = st.sampled_from([math.nan, math.inf, -math.inf, 0.0, -0.0, -1.0, 1e300, -1e300,
                            1e-300, 5e-324, 10**400, 2**63, -(2**63)])


def field_value(name):
    """Values for one ShipBlockSystem field: mostly in range, often not."""
    low, high, _ = FIELD_LIMITS[name]
    high = 1e12 if high is None else high
    if name == "n_blocks":
        good = st.integers(low, high) | st.integers(low, 500).map(float)
    else:
        good = st.floats(max(low, 1e-12), high, allow_nan=False)
    out = mostly(good, st.one_of(EXTREMES, GARBAGE, st.floats(allow_nan=True,
                                                               allow_infinity=True)), 3)
    if name in ("restitution", "block_inertia"):
        out = out | st.none()
    return out


def is_good(name, value) -> bool:
    """The oracle: whether ``value`` is acceptable on its own for the field ``name``."""
    if value is None and name in ("restitution", "block_inertia"):
        return True
    if isinstance(value, bool | np.bool_) or not isinstance(value, int | float | np.integer
                                                             | np.floating):
        return False
    try:
        x = float(value)
    except OverflowError:
        return False
    low, high, _ = FIELD_LIMITS[name]
    if not math.isfinite(x):
        return False
    if name == "n_blocks" and x != math.floor(x):
        return False
    if name == "block_inertia":
        return x > 0.0
    return low <= x and (high is None or x <= high)


NUMERIC = [n for n in FIELD_LIMITS]


@st.composite
def system_arguments(draw):
    """Constructor arguments, most fields taken from a good system, some drawn."""
    values = BASE.to_dict()
    for name in draw(st.lists(st.sampled_from(NUMERIC), max_size=3, unique=True)):
        values[name] = draw(field_value(name))
    if draw(st.booleans()) and draw(st.booleans()):
        values["impact_rule"] = draw(st.sampled_from(["momentum", "paper", "Momentum", "",
                                                      None, 1, ["paper"]]))
    return values


def assert_names_a_bad_argument(exc: Exception, bad: set[str]):
    """The error is a ParameterError whose message starts with one of the ``bad`` names."""
    assert isinstance(exc, ParameterError), f"{type(exc).__name__}: {exc}"
    first = str(exc).split()[0].split("[")[0].rstrip(":")
    assert first in bad, f"{exc!s} (wrong arguments: {sorted(bad)})"


def run(call):
    """``call()`` timed: (result or None, error or None)."""
    t0 = time.perf_counter()
    try:
        out, err = call(), None
    except Exception as exc:  # noqa: BLE001 - what is raised is what is tested
        out, err = None, exc
    assert time.perf_counter() - t0 < SLOW, "a hang"
    event("accepted" if err is None else f"refused: {type(err).__name__}"
          if isinstance(err, RecordError) else f"refused: {str(err).split()[0].split('[')[0]}")
    return out, err


# -------------------------------------------------------------------------------------------
# ShipBlockSystem
# -------------------------------------------------------------------------------------------


@SETTINGS
@given(values=system_arguments())
def test_system_accepts_good_fields_and_names_a_bad_one(values):
    system, err = run(lambda: ShipBlockSystem(**values))
    bad = {n for n in NUMERIC if not is_good(n, values[n])}
    if not (isinstance(values["impact_rule"], str)
            and values["impact_rule"] in ("momentum", "paper")):
        bad.add("impact_rule")
    # relations between fields that are fine alone
    for iface in ("ground", "ship"):
        mus, muk = f"mu_s_{iface}", f"mu_k_{iface}"
        if not {mus, muk} & bad and float(values[muk]) > float(values[mus]):
            bad.add(muk)
    size = ("block_mass", "half_width", "half_height", "block_inertia")
    if values["block_inertia"] is not None and not set(size) & bad:
        most = float(values["block_mass"]) * (float(values["half_width"]) ** 2
                                              + float(values["half_height"]) ** 2)
        if not MIN_INERTIA_RATIO * most <= float(values["block_inertia"]) <= most:
            bad.add("block_inertia")
    if err is None:
        assert not bad, f"accepted {sorted(bad)}: {values}"
        p = system.to_parameter_vector()
        assert np.isfinite(p).all()
        assert 0.0 <= system.effective_restitution <= 1.0
        return
    assert_names_a_bad_argument(err, bad)


# -------------------------------------------------------------------------------------------
# simulate
# -------------------------------------------------------------------------------------------

SAMPLE = st.one_of(st.floats(-50.0, 50.0), st.floats(-MAX_ACCELERATION, MAX_ACCELERATION),
                   st.sampled_from([math.nan, math.inf, 1e300, -1e300, 2 * MAX_ACCELERATION]))
RECORD = mostly(
    st.lists(st.floats(-30.0, 30.0), min_size=2, max_size=30).map(np.array)
    | st.lists(st.floats(-MAX_ACCELERATION, MAX_ACCELERATION), min_size=2,
               max_size=30).map(np.array),
    st.one_of(
        st.lists(SAMPLE, min_size=0, max_size=30).map(np.array),
        st.lists(st.floats(-5.0, 5.0), min_size=2, max_size=8).map(lambda x: np.array([x, x])),
        GARBAGE,
    ), 4)
DT = mostly(st.floats(MIN_TIME_STEP, MAX_TIME_STEP) | st.sampled_from([0.005, 0.01, 0.02]),
            st.one_of(EXTREMES, GARBAGE))
RTOL = mostly(st.just(1e-8) | st.floats(1e-14, 0.5), st.one_of(EXTREMES, GARBAGE))
ATOL = mostly(st.just(1e-10) | st.floats(1e-16, 1.0), st.one_of(EXTREMES, GARBAGE))
ZENO = mostly(st.just(1e-7) | st.floats(0.0, 1e3), st.one_of(EXTREMES, GARBAGE))
STATE = mostly(st.none() | st.lists(st.floats(-0.05, 0.05), min_size=6, max_size=6),
               st.one_of(st.lists(st.floats(allow_nan=True), min_size=0, max_size=7), GARBAGE))


def good_record(x) -> bool:
    try:
        arr = np.asarray(x)
    except Exception:  # noqa: BLE001
        return False
    return (not isinstance(x, str | bytes | dict) and x is not None
            and arr.dtype.kind in "iuf" and arr.ndim == 1 and arr.size >= 2
            and bool(np.all(np.abs(arr.astype(float)) <= MAX_ACCELERATION)))


def good_real(x, low, high, high_open=False) -> bool:
    if isinstance(x, bool | np.bool_) or not isinstance(x, int | float | np.integer | np.floating):
        return False
    try:
        v = float(x)
    except OverflowError:
        return False
    return math.isfinite(v) and low <= v and (v < high if high_open else v <= high)


def assert_finite_result(res):
    summary = {k: v for k, v in res.summary.items() if not (k == "failure_time"
                                                          and res.failure is None)}
    bad = [k for k, v in summary.items() if not np.isfinite(float(v))]
    assert not bad, f"non-finite summary entries {bad}"
    end = res.time.size if res.failure is None else int(np.searchsorted(res.time,
                                                                         res.failure_time))
    for name in ("x_b", "theta", "x_s", "v_b", "theta_dot", "v_s"):
        assert np.isfinite(getattr(res, name)[:end]).all(), name


@SETTINGS
@pytest.mark.filterwarnings("ignore::RuntimeWarning")  # the Painleve fallback warns, by design
@given(ax=RECORD, vertical=st.booleans(), ay=RECORD, dt=DT, rtol=RTOL, atol=ATOL,
       zeno=ZENO, state=STATE)
def test_simulate_returns_finite_results_or_names_the_argument(ax, vertical, ay, dt, rtol,
                                                               atol, zeno, state):
    ay = ay if vertical else None
    res, err = run(lambda: simulate(BASE, ax, ay, dt, rtol=rtol, atol=atol, zeno_omega=zeno,
                                    initial_state=state))
    bad = set()
    if not good_record(ax):
        bad.add("ax")
    if ay is not None and not (good_record(ay) and np.size(ay) == np.size(ax)):
        bad.add("ay")
    if not good_real(dt, MIN_TIME_STEP * (1 - 1e-9), MAX_TIME_STEP * (1 + 1e-9)):
        bad.add("dt")
    for name, value, low, high, open_ in (("rtol", rtol, 1e-14, 1.0, True),
                                          ("atol", atol, 1e-16, 1.0, False),
                                          ("zeno_omega", zeno, 0.0, 1e3, False)):
        if not good_real(value, low, high, open_):
            bad.add(name)
    if state is not None:
        try:
            y = np.asarray(state, dtype=float)
            ok = (y.shape == (6,) and np.isfinite(y).all()
                  and abs(y[1]) < BASE.critical_angle
                  and bool(np.all(np.abs(y[[0, 2, 3, 4, 5]]) <= 100.0)))
        except (TypeError, ValueError):
            ok = False
        if not ok:
            bad.update({"initial_state"})
    if err is None:
        assert not bad, f"accepted {sorted(bad)}"
        assert_finite_result(res)
    else:
        assert_names_a_bad_argument(err, bad)


# -------------------------------------------------------------------------------------------
# simulate_batch
# -------------------------------------------------------------------------------------------


@SETTINGS
@given(
    systems=mostly(st.just(BASE) | st.lists(st.just(BASE), min_size=1, max_size=3),
                   st.one_of(st.just([]), GARBAGE,
                             st.lists(st.one_of(st.just(BASE), GARBAGE), min_size=1,
                                      max_size=3)), 3),
    records=mostly(
        st.lists(st.tuples(RECORD, st.one_of(st.none(), RECORD)), min_size=1, max_size=3),
        st.one_of(st.just([]), st.lists(RECORD, min_size=1, max_size=2), GARBAGE), 3),
    dts=mostly(DT, st.lists(DT, min_size=0, max_size=4), 3),
    cases=mostly(
        st.lists(st.tuples(st.integers(0, 2), st.integers(0, 2), st.floats(-3.0, 3.0),
                           st.floats(-3.0, 3.0)), min_size=0, max_size=4),
        st.one_of(
            st.lists(st.tuples(st.integers(-1, 3), st.integers(-1, 3), st.floats(-1e3, 1e3),
                               st.floats(-1e3, 1e3)), min_size=1, max_size=4),
            st.lists(st.lists(st.one_of(st.floats(allow_nan=True), st.integers(0, 1), EXTREMES),
                              min_size=0, max_size=5), min_size=0, max_size=3),
            GARBAGE), 3),
)
@pytest.mark.filterwarnings("ignore::RuntimeWarning")
def test_simulate_batch_returns_finite_results_or_raises_a_named_error(systems, records, dts,
                                                                      cases):
    out, err = run(lambda: simulate_batch(systems, records, dts, cases))
    if err is not None:
        assert isinstance(err, ShipblockError), f"{type(err).__name__}: {err}"
        assert isinstance(err, ParameterError), f"{type(err).__name__}: {err}"
        first = str(err).split()[0].split("[")[0].rstrip(":")
        assert first in {"systems", "records", "dts", "cases"}, str(err)
        return
    # accepted: every input was good, and so is every output
    n = len(np.asarray(cases, dtype=float).reshape(-1, 4))
    for name, value in out.items():
        assert value.shape == (n,)
        if name != "failure_time":
            assert np.isfinite(value).all(), name
    assert all(good_record(h) and (v is None or good_record(v)) for h, v in records)
    table = np.asarray(cases, dtype=float).reshape(-1, 4)
    for r, _, sh, sv in table:
        h, v = records[int(r)]
        assert abs(sh) * np.abs(np.asarray(h, float)).max() <= MAX_ACCELERATION * (1 + 1e-12)
        if v is not None:
            assert abs(sv) * np.abs(np.asarray(v, float)).max() <= MAX_ACCELERATION * (1 + 1e-12)


@st.composite
def valid_systems(draw):
    """Systems anywhere within FIELD_LIMITS (log-uniform over the wide ranges)."""

    def log_uniform(low, high):
        return st.floats(math.log10(low), math.log10(high)).map(lambda e: 10.0**e)

    mu_s = [draw(st.floats(0.0, 100.0) | st.floats(0.0, 1.0)) for _ in range(2)]
    mu_k = [draw(st.floats(0.0, 1.0)) * m for m in mu_s]
    return ShipBlockSystem(
        ship_mass=draw(log_uniform(1e-9, 1e10)), block_mass=draw(log_uniform(1e-6, 1e8)),
        n_blocks=draw(st.integers(1, 100_000)), half_width=draw(log_uniform(1e-4, 100.0)),
        half_height=draw(log_uniform(1e-4, 100.0)), mu_s_ground=mu_s[0], mu_k_ground=mu_k[0],
        mu_s_ship=mu_s[1], mu_k_ship=mu_k[1],
        restitution=draw(st.none() | st.floats(0.0, 1.0)),
        impact_rule=draw(st.sampled_from(["momentum", "paper"])),
        g=draw(st.floats(0.1, 100.0)),
    )


@settings(max_examples=100, deadline=None, derandomize=True,
          suppress_health_check=[HealthCheck.too_slow])
@pytest.mark.filterwarnings("ignore::RuntimeWarning")  # the Painleve fallback warns, by design
@given(system=valid_systems(),
       ax=st.lists(st.floats(-MAX_ACCELERATION, MAX_ACCELERATION), min_size=2, max_size=20),
       ay=st.none() | st.lists(st.floats(-MAX_ACCELERATION, MAX_ACCELERATION), min_size=20,
                               max_size=20),
       dt=st.floats(MIN_TIME_STEP, MAX_TIME_STEP))
def test_any_valid_system_and_record_give_finite_results(system, ax, ay, dt):
    """Within the limits, every run ends with finite results (or a flagged failure), fast."""
    ax = np.array(ax)
    ay = None if ay is None else np.array(ay[: ax.size])
    res, err = run(lambda: simulate(system, ax, ay, dt))
    assert err is None, f"{type(err).__name__}: {err}"
    assert_finite_result(res)
    out, err = run(lambda: simulate_batch(system, [(ax, ay)], dt, [[0, 0, 1.0, 1.0]]))
    assert err is None, f"{type(err).__name__}: {err}"
    assert out["peak_block_slip"][0] == res.summary["peak_block_slip"]


# -------------------------------------------------------------------------------------------
# the reader side: read_motion, read_record, GroundMotion.from_arrays, rotate_to_azimuth,
# load_catalogue
# -------------------------------------------------------------------------------------------

READER_SETTINGS = settings(max_examples=80, deadline=None, derandomize=True,
                           suppress_health_check=[HealthCheck.too_slow])

DATA = Path(__file__).parent / "data"
#: Three one-component PEER files of 7 samples (g): H1 (channel 180), H2 (270) and V (DWN).
HELENA = [str(DATA / f"helena_synthetic_{c}.AT2") for c in ("180", "270", "dwn")]

GOOD_UNITS = ["g", "G", "m/s^2", "cm/s2", "gal", "mg", "cm/s", "M/S"]
BAD_WORDS = ["furlongs", "", "g/100", "%g", "xx", "XX", "H3", "partial", "fill", "yes"]
WORDS = st.sampled_from(GOOD_UNITS + BAD_WORDS)


def first_name(exc: Exception) -> str:
    """The argument a message starts with (``"sensor='XX' matches..."`` -> ``"sensor"``)."""
    return re.match(r"[A-Za-z_][A-Za-z_0-9]*", str(exc)).group(0)


def a_unit(value, velocity=True) -> bool:
    if not isinstance(value, str):
        return False
    acceleration = canonical_unit(value) is not None
    return acceleration or (velocity and canonical_velocity_unit(value) is not None)


def good_samples(x, min_size: int) -> bool:
    """Whether ``x`` is a 1-D array of at least ``min_size`` real numbers (any size)."""
    if x is None or isinstance(x, str | bytes | dict):
        return False
    try:
        arr = np.asarray(x)
    except Exception:  # noqa: BLE001
        return False
    return arr.dtype.kind in "iuf" and arr.ndim == 1 and arr.size >= min_size


def an_azimuth(value) -> bool:
    return good_real(value, -360.0, 360.0)


def one_of(value, choices) -> bool:
    return isinstance(value, str) and value in choices


AZIMUTH = st.one_of(st.none(), st.floats(-360.0, 360.0), st.integers(-400, 400), EXTREMES,
                    GARBAGE)


def option(good, bad):
    """One of the ``good`` values six times in seven, else a bad one or garbage."""
    return mostly(st.sampled_from(good), st.one_of(st.sampled_from(bad), GARBAGE), 6)


#: An azimuth, mostly a good one (None is not an azimuth here).
ANGLE = mostly(st.floats(-360.0, 360.0) | st.integers(-360, 360),
               st.one_of(st.none(), EXTREMES, GARBAGE, st.integers(361, 10**6)), 6)


@READER_SETTINGS
@pytest.mark.filterwarnings("ignore")
@given(units=mostly(st.none() | st.sampled_from(["g", "G"]), st.one_of(WORDS, GARBAGE), 6),
       azimuth=mostly(st.none() | st.floats(-360.0, 360.0), AZIMUTH, 6),
       horizontal=option([None, None, "H1", "H2"], ["H3", "h1", ""]),
       response=option(["sensitivity", "full"], ["partial", "Full", ""]),
       gaps=option(["refuse", "interpolate"], ["fill", ""]),
       align=option(["trim", "resample", "strict"], ["pad", ""]),
       differentiate=option([False, True], ["yes", 1, 0.0]),
       sensor=mostly(st.none(), st.one_of(WORDS, GARBAGE), 4),
       fmt=option([None, None, "SHIPBLOCK_AT2", "shipblock_at2", "MSEED"], ["AT2", "XYZ", ""]),
       channel_map=option([None, {"180": "H1", "270": "H2"}, {"180": "H2", "DWN": "V"}],
                          [{"180": "X"}, {1: "H1"}, ["180"], {"180": None}]),
       source=mostly(st.sampled_from([HELENA, HELENA[:2], HELENA[0], str(DATA / "reference")]),
                     st.sampled_from([None, [], "no_such.AT2", [HELENA[0], None], 5]), 5))
def test_read_motion_reads_or_names_the_argument(units, azimuth, horizontal, response, gaps,
                                                 align, differentiate, sensor, fmt,
                                                 channel_map, source):
    """read_motion with options drawn good or bad: a GroundMotion within the plausibility
    limits, a record error when every argument is good (the record and the options may not
    suit each other: units= contradicting the file's g, one horizontal and an azimuth...), or
    an error naming a wrong argument: never another exception."""
    out, err = run(lambda: read_motion(source, units=units, azimuth=azimuth,
                                       horizontal=horizontal, response=response, gaps=gaps,
                                       align=align, differentiate=differentiate, sensor=sensor,
                                       format=fmt, channel_map=channel_map))
    # 'bad': wrong before any file is read; a sensor code is known wrong only once the record is
    # read (no code matches a PEER file's channels), after a record error, if any
    bad = set()
    if source not in (HELENA, HELENA[:2], HELENA[0], str(DATA / "reference")):
        bad.add("paths_or_stream")
    if units is not None and not a_unit(units):
        bad.add("units")
    if azimuth is not None and not an_azimuth(azimuth):
        bad.add("azimuth")
    if horizontal is not None and not one_of(horizontal, ("H1", "H2")):
        bad.add("horizontal")
    if azimuth is not None and horizontal is not None:
        bad.add("azimuth")
    for name, value, choices in (("response", response, ("sensitivity", "full")),
                                 ("gaps", gaps, ("refuse", "interpolate")),
                                 ("align", align, ("trim", "resample", "strict"))):
        if not one_of(value, choices):
            bad.add(name)
    if not isinstance(differentiate, bool):
        bad.add("differentiate")
    if sensor is not None and not (isinstance(sensor, str) and sensor.strip()):
        bad.add("sensor")
    if fmt is not None and not (isinstance(fmt, str) and fmt.upper() in ("SHIPBLOCK_AT2",
                                                                         "MSEED")):
        bad.add("format")
    if channel_map is not None and not (
            isinstance(channel_map, dict) and all(isinstance(k, str) and v in ("H1", "H2", "V")
                                                  for k, v in channel_map.items())):
        bad.add("channel_map")
    if err is None:
        assert not bad and sensor is None, f"accepted {sorted(bad)}, sensor={sensor!r}"
        for values in out.components.values():
            assert np.isfinite(values).all() and np.abs(values).max() <= MAX_ACCELERATION
        assert MIN_TIME_STEP <= out.dt <= MAX_TIME_STEP
        if azimuth is not None and {"H1", "H2"} <= set(out.components):
            # the projection of (H1 at 180 deg, H2 at 270 deg: the files' channels) on the
            # azimuth, by hand
            assert out.azimuths == {"H1": 180.0, "H2": 270.0}
            a = math.radians(float(azimuth))
            expected = (out.components["H1"] * math.cos(a - math.pi)
                        + out.components["H2"] * math.cos(a - 1.5 * math.pi))
            np.testing.assert_allclose(out.horizontal, expected, rtol=1e-12, atol=1e-12)
        return
    assert isinstance(err, ShipblockError), f"{type(err).__name__}: {err}"
    if not bad:
        assert isinstance(err, RecordError) or (sensor is not None
                                                and first_name(err) == "sensor"), str(err)
    elif isinstance(err, RecordError):  # a path that names no file: the message names it
        assert "paths_or_stream" in bad and "paths_or_stream" in str(err), str(err)
    else:
        assert first_name(err) in bad, f"{err} (wrong arguments: {sorted(bad)})"


@READER_SETTINGS
@pytest.mark.filterwarnings("ignore")
@given(path=mostly(st.sampled_from(HELENA + [str(DATA / "two_column_gal.csv")]),
                   st.sampled_from([None, "", "no_such.AT2", str(DATA), 3.0, b"x.AT2",
                                    Path("no_such.AT2")]), 4),
       fmt=option([None, None, "SHIPBLOCK_AT2", "SHIPBLOCK_TEXT", "sac"], ["AT2", "", "XYZ"]),
       units=st.one_of(st.none(), st.none(), WORDS, GARBAGE),
       dt=mostly(st.none() | st.sampled_from([0.005, 0.01]), st.one_of(EXTREMES, GARBAGE), 3),
       resample_rate=mostly(st.none() | st.floats(1.0, 1e4), st.one_of(EXTREMES, GARBAGE), 4))
def test_read_record_reads_or_names_the_argument(path, fmt, units, dt, resample_rate):
    """read_record with arguments drawn good or bad: a Stream of finite samples, a record
    error when the arguments are good but do not suit the file, or an error naming the wrong
    argument."""
    out, err = run(lambda: read_record(path, format=fmt, units=units, dt=dt,
                                       resample_rate=resample_rate))
    bad = set()
    if not (isinstance(path, str) and os.path.isfile(path)):
        bad.add("path")
    if fmt is not None and not (isinstance(fmt, str) and fmt.upper() in
                                ("SHIPBLOCK_AT2", "SHIPBLOCK_TEXT", "SAC")):
        bad.add("format")
    if units is not None and not a_unit(units):
        bad.add("units")
    if dt is not None and not good_real(dt, MIN_TIME_STEP * (1 - 1e-9),
                                        MAX_TIME_STEP * (1 + 1e-9)):
        bad.add("dt")
    if resample_rate is not None and not good_real(resample_rate, 1.0, 1e4):
        bad.add("resample_rate")
    if err is None:
        assert not bad, f"accepted {sorted(bad)}"
        assert all(np.isfinite(tr.data).all() for tr in out)
        return
    assert isinstance(err, ShipblockError), f"{type(err).__name__}: {err}"
    if not bad:
        assert isinstance(err, RecordError), f"all arguments good, yet {err}"
    elif isinstance(err, RecordError):
        assert "path" in bad and "path must name a record file" in str(err), str(err)
    else:
        assert first_name(err) in bad, f"{err} (wrong arguments: {sorted(bad)})"


ARRAY = mostly(
    st.lists(st.floats(-3.0, 3.0), min_size=2, max_size=30).map(np.array),
    st.one_of(st.lists(SAMPLE, min_size=0, max_size=30).map(np.array),
              st.lists(st.floats(-5.0, 5.0), min_size=2, max_size=6).map(lambda x: [x, x]),
              GARBAGE), 3)


@READER_SETTINGS
@given(horizontal=ARRAY, vertical=st.none() | ARRAY, dt=DT,
       units=mostly(st.sampled_from(["m/s^2", "g", "gal", "cm/s^2", "mg"]),
                    st.one_of(WORDS, GARBAGE), 4),
       name=mostly(st.sampled_from(["synthetic", "x"]), st.sampled_from(["", " ", None, 5]), 6),
       azimuth_h1=AZIMUTH)
def test_from_arrays_builds_a_plausible_motion_or_names_the_argument(horizontal, vertical, dt,
                                                                     units, name, azimuth_h1):
    """GroundMotion.from_arrays: the samples in m/s^2 (the unit factor applied exactly), or a
    ParameterError naming a wrong argument."""
    out, err = run(lambda: GroundMotion.from_arrays(horizontal, vertical, dt=dt, units=units,
                                                    name=name, azimuth_h1=azimuth_h1))
    factor = (ACCELERATION_UNITS_TO_SI[canonical_unit(units)]
              if a_unit(units, velocity=False) else None)

    def good_array(x):
        if factor is None or not good_samples(x, 2):
            return False
        with np.errstate(all="ignore"):
            return bool(np.all(np.abs(np.asarray(x, float) * factor) <= MAX_ACCELERATION))

    bad = set()
    if factor is None:
        bad.add("units")
    elif not good_array(horizontal):
        bad.add("horizontal")
    if vertical is not None and factor is not None and not (
            good_array(vertical) and np.size(vertical) == np.size(horizontal)):
        bad.add("vertical")
    if not good_real(dt, MIN_TIME_STEP * (1 - 1e-9), MAX_TIME_STEP * (1 + 1e-9)):
        bad.add("dt")
    if not (isinstance(name, str) and name.strip()):
        bad.add("name")
    if azimuth_h1 is not None and not an_azimuth(azimuth_h1):
        bad.add("azimuth_h1")
    if err is None:
        assert not bad, f"accepted {sorted(bad)}"
        np.testing.assert_array_equal(out.horizontal, np.asarray(horizontal, float) * factor)
        if vertical is not None:
            np.testing.assert_array_equal(out.vertical, np.asarray(vertical, float) * factor)
        assert out.dt == pytest.approx(float(dt), rel=1e-14)  # obspy keeps 1 / (1 / dt)
        return
    assert isinstance(err, ParameterError), f"{type(err).__name__}: {err}"
    assert first_name(err) in bad, f"{err} (wrong arguments: {sorted(bad)})"


@READER_SETTINGS
@given(h1=ARRAY, h2=ARRAY, azimuth_h1=ANGLE,
       turn=st.sampled_from([90.0, -90.0, 270.0, -270.0, 90.0, -90.0, 45.0]), azimuth=ANGLE)
def test_rotate_to_azimuth_projects_or_names_the_argument(h1, h2, azimuth_h1, turn, azimuth):
    """rotate_to_azimuth: the projection a1 cos(t - a_1) + a2 cos(t - a_2), which keeps the
    horizontal vector's length when the target turns by 90 deg; or an error naming a wrong
    argument."""
    azimuth_h2 = (float(azimuth_h1) + turn if an_azimuth(azimuth_h1)
                  and abs(float(azimuth_h1) + turn) <= 360.0 else azimuth_h1)
    out, err = run(lambda: rotate_to_azimuth(h1, h2, azimuth_h1, azimuth_h2, azimuth))
    bad = {n for n, v in (("h1", h1), ("h2", h2)) if not (
        good_samples(v, 1) and bool(np.all(np.abs(np.asarray(v, float)) <= MAX_ACCELERATION)))}
    if not bad and np.size(h1) != np.size(h2):
        bad.add("h2")
    for n, v in (("azimuth_h1", azimuth_h1), ("azimuth_h2", azimuth_h2), ("azimuth", azimuth)):
        if not an_azimuth(v):
            bad.add(n)
    if not {"azimuth_h1", "azimuth_h2"} & bad and (turn == 45.0 or azimuth_h2 == azimuth_h1):
        bad.add("azimuth_h2")
    if err is None:
        assert not bad, f"accepted {sorted(bad)}"
        other = rotate_to_azimuth(h1, h2, azimuth_h1, azimuth_h2, float(azimuth) + 90.0
                                  if float(azimuth) <= 270.0 else float(azimuth) - 90.0)
        h1_, h2_ = np.asarray(h1, float), np.asarray(h2, float)
        np.testing.assert_allclose(out**2 + other**2, h1_**2 + h2_**2, rtol=1e-9, atol=1e-12)
        return
    assert isinstance(err, ParameterError), f"{type(err).__name__}: {err}"
    assert first_name(err) in bad, f"{err} (wrong arguments: {sorted(bad)})"


TOML_VALUE = st.one_of(st.sampled_from(['"g"', '"furlongs"', '"cm/s"', "5", "[]", '""',
                                        '["a.AT2"]', '{ a = 1 }', "true", "nan"]))


@settings(max_examples=40, deadline=None, derandomize=True,
          suppress_health_check=[HealthCheck.too_slow])
@given(key=st.sampled_from(["units", "files", "components", "station", "id", "inventory"]),
       value=TOML_VALUE)
def test_load_catalogue_accepts_or_names_the_record_and_key(key, value):
    """A catalogue with one value replaced loads, or fails with a RecordError that names the
    catalogue file and the record's key, never with another exception."""
    with tempfile.TemporaryDirectory() as folder:
        shutil.copy(HELENA[0], folder)
        table = {"id": '"syn/H"', "files": '["helena_synthetic_180.AT2"]', "station": '"H"',
                 "units": '"g"', key: value}
        components = table.pop("components", None)
        lines = ["[[record]]"] + [f"{k} = {v}" for k, v in table.items()]
        if components is not None:
            lines.append(f"components = {components}")
        path = Path(folder) / "catalogue.toml"
        path.write_text("\n".join(lines) + "\n")
        out, err = run(lambda: load_catalogue(path))
        if err is None:
            (entry,) = out.values()
            assert entry.units is None or a_unit(entry.units)
            assert all(p.is_file() for p in entry.files)
            assert set(entry.components.values()) <= {"H1", "H2", "V"}
            return
        assert isinstance(err, RecordError), f"{type(err).__name__}: {err}"
        assert err.source == str(path)
        assert key.rstrip("s") in str(err) and "record" in str(err), str(err)
