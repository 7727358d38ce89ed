"""Tests of shipblock.fragility.limit_states: parsing, validation and exceedance rules.

Expected values are worked out by hand from the definitions in the module docstring (collapse
exceeds every response limit state; NaN means an errored run, which is not valid).
"""

from __future__ import annotations

import tomllib

import numpy as np
import pytest
import xarray as xr

from shipblock.fragility import (
    EDP_VARIABLES,
    LimitState,
    evaluate_limit_states,
    exceedance,
    fit_msa,
    parse_limit_states,
)

PIPELINE_TOML = """
[[limit_states]]
name = "ship_slip"
edp = "peak_ship_slip"
threshold = 0.05        # exceeded when edp > threshold
[[limit_states]]
name = "any_failure"
edp = "failure"
condition = "nonzero"
[[limit_states]]
name = "block_rocking"
edp = "peak_rotation_ratio"
threshold = 0.5
description = "rocking to half the overturning angle"
"""

NAN = np.nan


def summary():
    """Six runs: quiet, slipping, separated, overturned with NaN EDPs, errored, failure NaN."""
    return {
        "peak_ship_slip": np.array([0.01, 0.20, 0.02, NAN, NAN, 0.30]),  # [m]
        "peak_rotation_ratio": np.array([0.1, 0.6, 0.0, NAN, NAN, 0.2]),  # [-]
        "residual_ship_slip": np.array([0.0, -0.08, 0.01, NAN, NAN, 0.0]),  # [m], signed
        "uplift": np.array([False, True, False, True, False, False]),
        "n_impacts": np.array([0, 3, 0, 1, 0, 0]),
        "failure": np.array([0, 0, 1, 2, 0, NAN]),
    }


# ---------------------------------------------------------------------------------------------
# Parsing and validation
# ---------------------------------------------------------------------------------------------


def test_parse_pipeline_example():
    states = parse_limit_states(tomllib.loads(PIPELINE_TOML)["limit_states"])
    assert states == (
        LimitState("ship_slip", "peak_ship_slip", 0.05),
        LimitState("any_failure", "failure", None, "nonzero"),
        LimitState(
            "block_rocking",
            "peak_rotation_ratio",
            0.5,
            description="rocking to half the overturning angle",
        ),
    )


def test_to_dict_round_trips():
    states = parse_limit_states(tomllib.loads(PIPELINE_TOML)["limit_states"])
    assert parse_limit_states([s.to_dict() for s in states]) == states
    assert "threshold" not in states[1].to_dict()


@pytest.mark.parametrize(
    ("entries", "match"),
    [
        (
            [{"name": "a", "edp": "peak_slip", "threshold": 1.0}],
            r"limit_states\[0\] \('a'\).*unknown edp 'peak_slip'",
        ),
        ([{"name": "a", "edp": "failure_time", "threshold": 1.0}], "failure_time is not an EDP"),
        ([{"name": "a", "edp": "peak_ship_slip"}], r"limit_states\[0\] \('a'\).*missing threshold"),
        (
            [
                {"name": "a", "edp": "peak_ship_slip", "threshold": 0.1},
                {"name": "b", "edp": "peak_block_slip", "threshold": 0.1},
                {"name": "a", "edp": "peak_rotation", "threshold": 0.1},
            ],
            r"limit_states\[2\] \('a'\): duplicate limit state name 'a'.*limit_states\[0\]",
        ),
        ([{"name": "a", "edp": "peak_ship_slip", "treshold": 0.1}], "unknown key.*'treshold'"),
        ([{"edp": "peak_ship_slip", "threshold": 0.1}], r"limit_states\[0\]: missing.*'name'"),
        ([{"name": "a", "threshold": 0.1}], "missing required key 'edp'"),
        ([{"name": "", "edp": "peak_ship_slip", "threshold": 0.1}], "non-empty"),
        (
            [{"name": "a", "edp": "failure", "condition": "nonzero", "threshold": 0}],
            "threshold is not used",
        ),
        ([{"name": "a", "edp": "peak_ship_slip", "threshold": "5 cm"}], "finite number"),
        ([{"name": "a", "edp": "peak_ship_slip", "threshold": True}], "finite number"),
        ([{"name": "a", "edp": "peak_ship_slip", "threshold": float("nan")}], "finite number"),
        ([{"name": "a", "edp": "peak_ship_slip", "threshold": -0.1}], "negative"),
        ([{"name": "a", "edp": "peak_ship_slip", "threshold": 1e300}], r"beyond any value.*1000 m"),
        ([{"name": "a", "edp": "peak_rotation", "threshold": 4.0}], r"beyond any value"),
        ([{"name": "a", "edp": "peak_corner_load", "threshold": 1e11}], r"at most 1e\+10 N"),
        (
            [{"name": "a", "edp": "peak_ship_slip", "threshold": 0.1, "condition": "less"}],
            "unknown condition 'less'",
        ),
        ([{"name": "a", "edp": "uplift", "threshold": 0.5}], "does not apply.*nonzero"),
        (
            [{"name": "a", "edp": "peak_ship_slip", "threshold": 0.1, "condition": "equal"}],
            "does not apply",
        ),
        (
            [{"name": "a", "edp": "failure", "threshold": 3, "condition": "equal"}],
            "not a failure code",
        ),
        ([{"name": "a", "edp": "failure", "threshold": 1}], "does not apply"),
        (["ship_slip"], r"limit_states\[0\]: expected a table"),
        ({"name": "a", "edp": "peak_ship_slip", "threshold": 0.1}, "list of tables"),
    ],
)
def test_parse_errors_name_the_entry_and_key(entries, match):
    with pytest.raises(ValueError, match=match):
        parse_limit_states(entries)


def test_construction_does_not_validate_but_exceedance_does():
    bad = LimitState("a", "no_such_edp", 1.0)  # no error: config objects do no work in __init__
    with pytest.raises(ValueError, match="unknown edp"):
        exceedance(bad, summary())


def test_every_documented_summary_variable_except_failure_time_is_an_edp():
    expected = {
        "peak_block_slip",
        "peak_ship_slip",
        "peak_rotation",
        "peak_rotation_ratio",
        "residual_block_slip",
        "residual_ship_slip",
        "uplift",
        "n_impacts",
        "failure",
        # contact loads per block (shipblock.interface_forces)
        "peak_ground_normal_force",
        "peak_ground_friction_force",
        "peak_ship_normal_force",
        "peak_ship_friction_force",
        "peak_ground_friction_utilisation",
        "peak_ship_friction_utilisation",
        "peak_corner_load",
    }
    assert set(EDP_VARIABLES) == expected
    # every EDP is a summary variable of the solver
    from shipblock.solver import SUMMARY_FIELDS

    assert set(EDP_VARIABLES) - {"peak_rotation_ratio"} <= set(SUMMARY_FIELDS)


# ---------------------------------------------------------------------------------------------
# Exceedance on numpy arrays
# ---------------------------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("limit_state", "exceeded", "valid"),
    [
        # quiet, slipping, separated (small EDP), overturned (NaN EDP), errored, failure NaN
        (LimitState("slip", "peak_ship_slip", 0.05), [0, 1, 1, 1, 0, 0], [1, 1, 1, 1, 0, 0]),
        (
            LimitState("slip_ge", "peak_ship_slip", 0.20, "greater_equal"),
            [0, 1, 1, 1, 0, 0],
            [1, 1, 1, 1, 0, 0],
        ),
        (LimitState("rock", "peak_rotation_ratio", 0.5), [0, 1, 1, 1, 0, 0], [1, 1, 1, 1, 0, 0]),
        # residual slip is compared by magnitude: -0.08 exceeds 0.05
        (
            LimitState("residual", "residual_ship_slip", 0.05),
            [0, 1, 1, 1, 0, 0],
            [1, 1, 1, 1, 0, 0],
        ),
        # bool and count EDPs cannot be NaN here: only the failure code can make a run invalid
        (LimitState("uplift", "uplift", None, "nonzero"), [0, 1, 1, 1, 0, 0], [1, 1, 1, 1, 1, 0]),
        (
            LimitState("impacts", "n_impacts", 3, "greater_equal"),
            [0, 1, 1, 1, 0, 0],
            [1, 1, 1, 1, 1, 0],
        ),
        # limit states on the failure code itself: no collapse override
        (
            LimitState("any_failure", "failure", None, "nonzero"),
            [0, 0, 1, 1, 0, 0],
            [1, 1, 1, 1, 1, 0],
        ),
        (LimitState("overturning", "failure", 2, "equal"), [0, 0, 0, 1, 0, 0], [1, 1, 1, 1, 1, 0]),
        (LimitState("separation", "failure", 1, "equal"), [0, 0, 1, 0, 0, 0], [1, 1, 1, 1, 1, 0]),
    ],
)
def test_exceedance_numpy(limit_state, exceeded, valid):
    result = exceedance(limit_state, summary())
    np.testing.assert_array_equal(result.exceeded, np.array(exceeded, dtype=bool))
    np.testing.assert_array_equal(result.valid, np.array(valid, dtype=bool))
    assert result.exceeded.dtype == bool and result.valid.dtype == bool


def test_exceedance_keeps_shape_of_a_record_by_level_grid():
    s = {k: np.tile(v, (4, 1)) for k, v in summary().items()}  # (record, im_level) = (4, 6)
    result = exceedance(LimitState("slip", "peak_ship_slip", 0.05), s)
    assert result.exceeded.shape == result.valid.shape == (4, 6)


def test_exceedance_needs_failure_for_response_edps():
    s = summary()
    del s["failure"]
    with pytest.raises(KeyError, match="'failure'"):
        exceedance(LimitState("slip", "peak_ship_slip", 0.05), s)
    with pytest.raises(KeyError, match="'peak_rotation'"):
        exceedance(LimitState("rot", "peak_rotation", 0.05), summary())


def test_exceedance_rejects_mismatched_shapes():
    s = summary()
    s["failure"] = np.zeros(5)
    with pytest.raises(ValueError, match="shape"):
        exceedance(LimitState("slip", "peak_ship_slip", 0.05), s)


# ---------------------------------------------------------------------------------------------
# Exceedance on xarray
# ---------------------------------------------------------------------------------------------


def dataset():
    """The six runs of :func:`summary` as a (record=2, im_level=3) Dataset."""
    coords = {"record": ["RSN1", "RSN2"], "im_level": [0.1, 0.2, 0.3]}
    return xr.Dataset(
        {k: (("record", "im_level"), v.reshape(2, 3)) for k, v in summary().items()},
        coords=coords,
    )


@pytest.mark.parametrize(
    "limit_state",
    [
        LimitState("slip", "peak_ship_slip", 0.05),
        LimitState("residual", "residual_ship_slip", 0.05),
        LimitState("uplift", "uplift", None, "nonzero"),
        LimitState("overturning", "failure", 2, "equal"),
    ],
)
def test_exceedance_xarray_matches_numpy_and_keeps_dims(limit_state):
    ds = dataset()
    result = exceedance(limit_state, ds)
    reference = exceedance(limit_state, summary())
    for got, want in zip(result, reference, strict=True):
        assert isinstance(got, xr.DataArray)
        assert got.dims == ("record", "im_level")
        assert got.dtype == bool
        xr.testing.assert_equal(got.coords.to_dataset(), ds.coords.to_dataset())
        np.testing.assert_array_equal(got.values.ravel(), want)
    assert result.exceeded.name == limit_state.name
    assert result.exceeded.attrs["limit_state_edp"] == limit_state.edp


def test_evaluate_limit_states_and_fit_from_a_dataset():
    """End to end: Dataset of runs -> exceedance with valid mask -> MSA fit."""
    rng = np.random.default_rng(0)
    levels = np.array([0.5, 1.0, 2.0, 4.0])  # [m/s^2]
    capacity = np.exp(0.5 * rng.standard_normal(50))  # median 1.0 [m/s^2]
    slip = 0.05 * levels[None, :] / capacity[:, None]  # slip > 0.05 m iff IM > capacity
    failure = np.where(slip > 0.15, 2, 0).astype(float)
    slip[failure == 2] = NAN  # solver stopped at overturning: EDP not available
    failure[0, 1] = slip[0, 1] = NAN  # one errored run
    ds = xr.Dataset(
        {
            "peak_ship_slip": (("record", "im_level"), slip),
            "failure": (("record", "im_level"), failure),
        },
        coords={"im_level": levels},
    )
    states = parse_limit_states(tomllib.loads(PIPELINE_TOML)["limit_states"][:2])
    out = evaluate_limit_states(states, ds)
    assert list(out) == ["ship_slip", "any_failure"]
    ex = out["ship_slip"]
    assert int(ex.valid.sum()) == 199
    fit = fit_msa(ex.exceeded.values, levels, ex.valid.values)
    assert fit.n == 199
    assert 0.6 < fit.median < 1.6  # true median 1.0; 50 records
