"""Property tests of the API's argument checks (issue #23, "keep it found").

Whatever arguments hypothesis makes up for :class:`~shipblock.ShipBlockSystem`,
:func:`~shipblock.simulate` and :func:`~shipblock.simulate_batch`, the call either returns a
result with finite summaries or raises a :class:`~shipblock.errors.ParameterError` that names
the argument at fault: never another exception type, a NaN result or a hang. An oracle written
from the documented limits (:data:`shipblock.system.FIELD_LIMITS`, :mod:`shipblock.checks`)
says which arguments are wrong, so a message naming a good argument fails the test too.

Records are a few tens of samples, so each example costs well under a millisecond once the
solver is compiled (the compilation is shared with the other solver tests).
"""

from __future__ import annotations

import math
import time

import numpy as np
import pytest
from hypothesis import HealthCheck, event, given, settings
from hypothesis import strategies as st

from shipblock import ShipBlockSystem, simulate, simulate_batch
from shipblock.checks import MAX_ACCELERATION, MAX_TIME_STEP, MIN_TIME_STEP
from shipblock.errors import ParameterError, ShipblockError
from shipblock.system import FIELD_LIMITS, MIN_INERTIA_RATIO

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
    event("accepted" if err is None else f"refused: {str(err).split()[0].split('[')[0]}")
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
