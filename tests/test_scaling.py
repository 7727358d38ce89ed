"""Tests of shipblock.scaling: targets reached, factors consistent, errors raised.

Reference values: the measures are positively homogeneous (IM(k a) = |k|^p IM(a), p = 1 for
PGA/PGV/PGD/CAV/Sa, p = 2 for Arias), so each target must be reached to rounding.
"""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from shipblock import intensity as im
from shipblock.errors import RecordError
from shipblock.scaling import MEASURES, amplitude_factor, measure_value, scale, scale_record

DT = 0.01


@pytest.fixture
def record():
    """Synthetic H/V pair: two windowed sines (V/H PGA ratio about 0.6)."""
    t = np.arange(2000) * DT
    env = np.exp(-(((t - 8.0) / 3.0) ** 2))
    h = 2.0 * env * np.sin(2 * np.pi * 1.3 * t)
    v = 1.2 * env * np.sin(2 * np.pi * 3.1 * t + 0.4)
    return h, v


@pytest.mark.parametrize(
    ("measure", "period", "target"),
    [
        ("pga", None, 3.0),
        ("pgv", None, 0.4),
        ("pgd", None, 0.05),
        ("sa", 0.5, 7.0),
        ("sa", 2.0, 0.9),
        ("cav", None, 5.0),
        ("arias", None, 1.5),
    ],
)
def test_target_reached(record, measure, period, target):
    h, v = record
    h_in, v_in = h.copy(), v.copy()
    out = scale_record(h, v, DT, target=target, measure=measure, period=period)
    assert out.achieved == pytest.approx(target, rel=1e-12)
    assert measure_value(out.horizontal, DT, measure, period) == pytest.approx(target, rel=1e-12)
    np.testing.assert_array_equal(out.horizontal, out.factor_h * h)
    # default vertical mode keeps V/H
    assert out.factor_v == out.factor_h
    assert im.pga(out.vertical, DT) / im.pga(out.horizontal, DT) == pytest.approx(
        im.pga(v, DT) / im.pga(h, DT), rel=1e-12
    )
    # inputs untouched
    np.testing.assert_array_equal(h, h_in)
    np.testing.assert_array_equal(v, v_in)


def test_arias_factor_is_square_root(record):
    """Arias is quadratic in amplitude: doubling Ia needs factor sqrt(2)."""
    h, _ = record
    ia = im.arias_intensity(h, DT)
    assert amplitude_factor(h, DT, 2 * ia, "arias") == pytest.approx(np.sqrt(2), rel=1e-12)
    assert amplitude_factor(h, DT, 2 * im.pga(h, DT), "pga") == pytest.approx(2.0)


def test_scale_by_factor_and_reverse(record):
    h, v = record
    out = scale_record(h, v, DT, factor=1.5, reverse=True)
    assert out.factor_h == -1.5 and out.factor_v == 1.5
    np.testing.assert_array_equal(out.horizontal, -1.5 * h)
    np.testing.assert_array_equal(out.vertical, 1.5 * v)
    assert out.achieved == pytest.approx(1.5 * im.pga(h, DT))
    rev = scale_record(h, v, DT, reverse=True, reverse_vertical=True)
    np.testing.assert_array_equal(rev.horizontal, -h)
    np.testing.assert_array_equal(rev.vertical, -v)
    np.testing.assert_array_equal(scale(h, -2.0), -2.0 * h)


def test_vertical_independent_target(record):
    h, v = record
    out = scale_record(
        h,
        v,
        DT,
        target=3.0,
        vertical_mode="independent",
        vertical_target=1.0,
        vertical_measure="sa",
        vertical_period=0.2,
    )
    assert out.achieved == pytest.approx(3.0, rel=1e-12)
    assert out.achieved_v == pytest.approx(1.0, rel=1e-12)
    assert im.spectral_acceleration(out.vertical, DT, 0.2) == pytest.approx(1.0, rel=1e-12)
    out = scale_record(h, v, DT, target=3.0, vertical_mode="independent", vertical_factor=0.5)
    np.testing.assert_array_equal(out.vertical, 0.5 * v)
    out = scale_record(h, v, DT, target=3.0, vertical_mode="independent", vertical_target=2.0)
    assert im.pga(out.vertical, DT) == pytest.approx(2.0, rel=1e-12)


def test_vertical_unscaled_zero_and_absent(record):
    h, v = record
    out = scale_record(h, v, DT, target=3.0, vertical_mode="unscaled")
    np.testing.assert_array_equal(out.vertical, v)
    assert out.factor_v == 1.0
    out = scale_record(h, v, DT, target=3.0, vertical_mode="zero")
    assert out.factor_v == 0.0 and not np.any(out.vertical)
    out = scale_record(h, None, DT, target=3.0)
    assert out.vertical is None and out.factor_v is None and out.achieved_v is None


@settings(max_examples=30, deadline=None)
@given(
    target=st.floats(1e-4, 1e3),
    measure=st.sampled_from(sorted(MEASURES)),
)
def test_targets_property(target, measure):
    """Any positive target of any measure is reached (homogeneity), unless the scaled record
    would exceed the plausibility limit of 100 g: then a ParameterError names the target."""
    from shipblock.checks import MAX_ACCELERATION
    from shipblock.errors import ParameterError

    t = np.arange(500) * DT
    h = np.sin(2 * np.pi * 2.0 * t) * np.exp(-t)
    period = 0.3 if measure == "sa" else None
    factor = amplitude_factor(h, DT, target, measure=measure, period=period)
    if factor * np.abs(h).max() > MAX_ACCELERATION:
        with pytest.raises(ParameterError, match="target"):
            scale_record(h, None, DT, target=target, measure=measure, period=period)
        return
    out = scale_record(h, None, DT, target=target, measure=measure, period=period)
    assert out.achieved == pytest.approx(target, rel=1e-10)


@pytest.mark.parametrize(
    ("kwargs", "error", "match"),
    [
        ({"target": -1.0}, ValueError, "positive"),
        ({"target": 0.0}, ValueError, "positive"),
        ({"target": 1.0, "measure": "sa", "period": 0.0}, ValueError, "period"),
        ({"target": 1.0, "measure": "sa", "period": -0.5}, ValueError, "period"),
        ({"target": 1.0, "measure": "sa"}, ValueError, "period"),
        ({"target": 1.0, "period": 1.0}, ValueError, "period applies only"),
        ({"target": 1.0, "measure": "cav5"}, ValueError, "unknown scaling measure"),
        ({"target": 1.0, "factor": 2.0}, ValueError, "not both"),
        ({"factor": -2.0}, ValueError, "reverse"),
        ({"target": 1.0, "vertical_mode": "sideways"}, ValueError, "vertical_mode"),
        ({"target": 1.0, "vertical_target": 1.0}, ValueError, "independent"),
        ({"target": 1.0, "vertical_mode": "independent"}, ValueError, "exactly one"),
    ],
)
def test_bad_options(record, kwargs, error, match):
    h, v = record
    with pytest.raises(error, match=match):
        scale_record(h, v, DT, **kwargs)


def test_zero_record_cannot_reach_target(record):
    h, v = record
    with pytest.raises(RecordError, match="zero PGA"):
        scale_record(np.zeros_like(h), v, DT, target=1.0)
    with pytest.raises(RecordError, match="<vertical>"):
        scale_record(
            h, np.zeros_like(v), DT, target=1.0, vertical_mode="independent", vertical_target=1.0
        )
    with pytest.raises(RecordError, match="samples"):
        scale_record(h, v[:-1], DT, target=1.0)


def test_scale_motion_integration(record):
    """Integration with shipblock.records.motion: PGA target reached on the solver's horizontal."""
    from shipblock.records.motion import GroundMotion
    from shipblock.scaling import scale_motion

    h, v = record
    gm = GroundMotion.from_arrays(h, v, dt=DT)
    out, scaled = scale_motion(gm, target=4.0, reverse=True)
    assert im.pga(out.horizontal, DT) == pytest.approx(4.0, rel=1e-12)
    np.testing.assert_allclose(out.horizontal, scaled.horizontal, rtol=1e-15)
    np.testing.assert_allclose(out.vertical, scaled.vertical, rtol=1e-15)
    assert scaled.factor_h < 0
    np.testing.assert_array_equal(gm.horizontal, h)
    assert "scale_record(" in out.metadata["processing"][-1]


# ---------------------------------------------------------------------------------------------
# scaling to a target spectrum
# ---------------------------------------------------------------------------------------------
def _spectrum_record():
    rng = np.random.default_rng(21)
    t = np.arange(3000) * DT
    return rng.standard_normal(t.size) * np.exp(-(((t - 10.0) / 4.0) ** 2))


def test_read_target_spectrum_units_header_comments_and_errors(tmp_path):
    from shipblock.scaling import TargetSpectrumError, read_target_spectrum

    path = tmp_path / "target.csv"
    path.write_text("# design spectrum\nperiod_s, sa_g\n0.1, 0.8\n1.0, 1.0  # plateau end\n"
                    "4.0; 0.25\n")
    spec = read_target_spectrum(path, "g")
    np.testing.assert_array_equal(spec.periods, [0.1, 1.0, 4.0])
    np.testing.assert_allclose(spec.sa, np.array([0.8, 1.0, 0.25]) * 9.80665, rtol=1e-15)
    # log-log interpolation: Sa ~ 1/T between 1 and 4 s
    assert spec.at(2.0)[0] == pytest.approx(0.5 * 9.80665, rel=1e-12)
    with pytest.raises(TargetSpectrumError, match="covers 0.1 to 4 s"):
        spec.at(5.0)
    path.write_text("0.1 0.8\n0.5 x\n")
    with pytest.raises(TargetSpectrumError, match=r"target.csv, line 2: expected two numbers"):
        read_target_spectrum(path, "g")
    path.write_text("0.5 0.8\n0.1 0.9\n")
    with pytest.raises(TargetSpectrumError, match="strictly increasing"):
        read_target_spectrum(path, "m/s^2")
    with pytest.raises(TargetSpectrumError, match="unit"):
        read_target_spectrum(path, "furlongs")


def test_spectrum_match_is_least_squares_in_ln_sa_and_reports_the_rms_misfit():
    """Target = c Sa_rec(T) exp(e(T)): the least-squares factor is c exp(mean e) (normal
    equation of ln Sa_target - ln f - ln Sa_rec), the misfit the RMS of e - mean e; checked
    against a numerical minimisation of the same sum of squares."""
    from scipy import optimize

    from shipblock.scaling import TargetSpectrum, spectrum_match

    acc = _spectrum_record()
    grid = np.geomspace(0.05, 5.0, 60)
    sa_rec = im.spectral_acceleration(acc, DT, grid)
    e = 0.3 * np.sin(3 * np.log(grid))
    target = TargetSpectrum(grid, 2.5 * sa_rec * np.exp(e))
    m = spectrum_match(acc, DT, target, (0.2, 2.0), n_periods=25)
    periods = np.geomspace(0.2, 2.0, 25)
    np.testing.assert_allclose(m.periods, periods)
    resid = np.log(target.at(periods) / im.spectral_acceleration(acc, DT, periods))
    assert m.factor == pytest.approx(np.exp(resid.mean()), rel=1e-12)
    assert m.misfit == pytest.approx(resid.std(), rel=1e-10)
    best = optimize.minimize_scalar(lambda lf: np.sum((resid - lf) ** 2),
                                    bracket=(0.0, 2.0), tol=1e-12)
    assert np.log(m.factor) == pytest.approx(best.x, abs=1e-7)
    # a target of the record's own spectral shape: its factor, misfit 0
    own = TargetSpectrum(periods, 2.5 * im.spectral_acceleration(acc, DT, periods))
    same = spectrum_match(acc, DT, own, (0.2, 2.0), n_periods=25)
    assert same.factor == pytest.approx(2.5, rel=1e-12)
    assert same.misfit < 1e-12


def test_spectrum_match_anchored_at_t1_matches_there_exactly():
    from shipblock.scaling import TargetSpectrum, spectrum_match

    acc = _spectrum_record()
    target = TargetSpectrum([0.05, 0.5, 5.0], [8.0, 10.0, 1.0])
    m = spectrum_match(acc, DT, target, (0.2, 2.0), mode="anchor", anchor_period=1.0)
    assert m.factor * im.spectral_acceleration(acc, DT, 1.0) == pytest.approx(
        target.at(1.0)[0], rel=1e-12)
    ranged = spectrum_match(acc, DT, target, (0.2, 2.0))
    assert ranged.misfit <= m.misfit  # least squares is the smallest RMS over the range
    with pytest.raises(ValueError, match="anchor_period"):
        spectrum_match(acc, DT, target, (0.2, 2.0), mode="anchor")
    with pytest.raises(ValueError, match="0 < T_a < T_b"):
        spectrum_match(acc, DT, target, (2.0, 0.2))
