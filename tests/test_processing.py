"""Tests of shipblock.processing: each step's effect, provenance, purity and errors.

Reference values: filter amplitudes from the Butterworth magnitude response (|H| = 1/sqrt(2)
at a corner, so a zero-phase two-pass filter gives 1/2); baseline drifts that lie exactly in
the fitted polynomial space must be removed to rounding.
"""

from __future__ import annotations

import numpy as np
import pytest
from obspy import Stream, Trace, UTCDateTime

from shipblock import processing as P
from shipblock.intensity import displacement

T0 = UTCDateTime(2020, 1, 1)


def _stream(data_by_channel, dt):
    return Stream(
        [
            Trace(np.asarray(d, dtype=float), header={"delta": dt, "channel": c, "starttime": T0})
            for c, d in data_by_channel.items()
        ]
    )


def _amplitude(x, t, freq):
    """Least-squares amplitude of the sinusoid at ``freq`` in ``x(t)``."""
    basis = np.column_stack(
        [np.sin(2 * np.pi * freq * t), np.cos(2 * np.pi * freq * t), np.ones_like(t)]
    )
    coef, *_ = np.linalg.lstsq(basis, x, rcond=None)
    return float(np.hypot(coef[0], coef[1]))


@pytest.fixture
def noisy():
    rng = np.random.default_rng(7)
    return _stream(
        {
            "HN1": rng.standard_normal(3000),
            "HN2": rng.standard_normal(3000),
            "HNZ": rng.standard_normal(3000),
        },
        0.01,
    )


# ---------------------------------------------------------------------------------------------
# filters
# ---------------------------------------------------------------------------------------------
def test_bandpass_removes_long_period_keeps_5hz():
    """Zero-phase 4-pole bandpass 0.1-25 Hz: |H|^2 at 0.01 Hz is about (0.01/0.1)^8 = 1e-8, at
    5 Hz about 1 - (5/25)^8 (Butterworth magnitude); at the 0.1 Hz corner exactly 1/2."""
    dt = 0.01
    t = np.arange(int(400 / dt)) * dt
    mid = slice(t.size // 4, 3 * t.size // 4)
    x = np.sin(2 * np.pi * 0.01 * t) + np.sin(2 * np.pi * 5.0 * t) + np.sin(2 * np.pi * 0.1 * t)
    out = P.bandpass(_stream({"HN1": x}, dt), freqmin=0.1, freqmax=25.0)[0].data
    assert _amplitude(out[mid], t[mid], 5.0) == pytest.approx(1.0, abs=2e-3)
    assert _amplitude(out[mid], t[mid], 0.01) < 2e-3
    assert _amplitude(out[mid], t[mid], 0.1) == pytest.approx(0.5, abs=0.02)


def test_highpass_and_lowpass_corners():
    """Two-pass Butterworth: amplitude 1/2 at the corner; far pass band ~1, stop band ~0."""
    dt = 0.005
    t = np.arange(int(60 / dt)) * dt
    mid = slice(t.size // 4, 3 * t.size // 4)
    x = np.sin(2 * np.pi * 0.5 * t) + np.sin(2 * np.pi * 2.0 * t) + np.sin(2 * np.pi * 20.0 * t)
    low = P.lowpass(_stream({"HN1": x}, dt), freq=2.0)[0].data
    high = P.highpass(_stream({"HN1": x}, dt), freq=2.0)[0].data
    assert _amplitude(low[mid], t[mid], 0.5) == pytest.approx(1.0, abs=1e-3)
    assert _amplitude(low[mid], t[mid], 2.0) == pytest.approx(0.5, abs=0.01)
    assert _amplitude(low[mid], t[mid], 20.0) < 1e-3
    assert _amplitude(high[mid], t[mid], 20.0) == pytest.approx(1.0, abs=1e-3)
    assert _amplitude(high[mid], t[mid], 2.0) == pytest.approx(0.5, abs=0.01)
    assert _amplitude(high[mid], t[mid], 0.5) < 1e-3


def test_zerophase_false_is_causal_and_different(noisy):
    causal = P.lowpass(noisy, freq=5.0, zerophase=False)
    acausal = P.lowpass(noisy, freq=5.0)
    assert not np.allclose(causal[0].data, acausal[0].data)


def test_nyquist_check_and_cap(noisy):
    """fs = 100 Hz: freqmax 60 Hz is above Nyquist (error); with cap 0.8 it becomes 40 Hz."""
    with pytest.raises(P.ProcessingError, match="freqmax.*Nyquist"):
        P.bandpass(noisy, freqmin=0.1, freqmax=60.0)
    capped = P.bandpass(noisy, freqmin=0.1, freqmax=60.0, nyquist_cap=0.8)
    explicit = P.bandpass(noisy, freqmin=0.1, freqmax=40.0)
    np.testing.assert_array_equal(capped[0].data, explicit[0].data)
    with pytest.raises(P.ProcessingError, match="'nyquist_cap'"):
        P.bandpass(noisy, freqmin=0.1, freqmax=20.0, nyquist_cap=1.5)
    with pytest.raises(P.ProcessingError, match="'freqmin'"):
        P.bandpass(noisy, freqmin=45.0, freqmax=60.0, nyquist_cap=0.8)


# ---------------------------------------------------------------------------------------------
# baseline
# ---------------------------------------------------------------------------------------------
def test_baseline_removes_quadratic_displacement_drift():
    """A constant acceleration offset a0 is the displacement drift a0 t^2/2, which lies in the
    fitted space span{t^2..t^6}: it must vanish to rounding."""
    dt = 0.01
    out = P.baseline(_stream({"HN1": np.full(2000, 0.03)}, dt))[0].data
    np.testing.assert_allclose(out, 0.0, atol=1e-12)


def test_baseline_is_blind_to_in_space_drift():
    """Linearity of least squares: adding a drift d = c t^2 + e t^3 (acceleration 2c + 6e t,
    exactly integrated) to a record does not change the corrected record."""
    dt = 0.01
    t = np.arange(4000) * dt
    clean = np.exp(-(((t - 15) / 4) ** 2)) * np.sin(2 * np.pi * 1.5 * t)
    drift = 2 * 0.02 + 6 * -0.001 * t
    a = P.baseline(_stream({"HN1": clean}, dt))[0].data
    b = P.baseline(_stream({"HN1": clean + drift}, dt))[0].data
    np.testing.assert_allclose(b, a, atol=1e-10)


def test_baseline_reduces_drift_of_offset_record():
    """A small offset makes the displacement end far from zero; after correction the final
    displacement is at least 100 times smaller."""
    dt = 0.01
    t = np.arange(4000) * dt
    a = np.exp(-(((t - 15) / 4) ** 2)) * np.sin(2 * np.pi * 1.5 * t) + 0.002
    corrected = P.baseline(_stream({"HN1": a}, dt), order=6)[0].data
    assert abs(displacement(corrected, dt)[-1]) < abs(displacement(a, dt)[-1]) / 100


def test_polynomial_baseline_order2_is_constant():
    """Order 2 fits c2 t^2 only, whose second derivative is the constant 2 c2."""
    rng = np.random.default_rng(2)
    base = P.polynomial_baseline(rng.standard_normal(500), 0.02, order=2)
    np.testing.assert_allclose(base, base[0], rtol=1e-12)


# ---------------------------------------------------------------------------------------------
# simple steps
# ---------------------------------------------------------------------------------------------
def test_demean_detrend_taper():
    dt = 0.01
    t = np.arange(1000) * dt
    x = 3.0 + 0.5 * t + np.sin(2 * np.pi * 2 * t)
    st = _stream({"HN1": x}, dt)
    assert abs(P.demean(st)[0].data.mean()) < 1e-12
    detrended = P.detrend(st)[0].data
    slope = np.polyfit(t, detrended, 1)
    np.testing.assert_allclose(slope, 0.0, atol=1e-12)
    tapered = P.taper(_stream({"HN1": np.ones(1000)}, dt), max_percentage=0.05)[0].data
    assert tapered[0] == 0.0 and tapered[-1] == 0.0
    np.testing.assert_array_equal(tapered[60:940], 1.0)
    assert np.all(tapered[:50] < 1.0)


def test_resample_fft_and_interpolate():
    """Down-sampling 100 -> 40 Hz keeps a 2 Hz sine (well below the new Nyquist of 20 Hz)."""
    dt = 0.01
    t = np.arange(2000) * dt
    x = np.sin(2 * np.pi * 2.0 * t) * np.hanning(t.size)
    st = _stream({"HN1": x}, dt)
    for method in ("fft", "lanczos", "cubic", "linear"):
        out = P.resample(st, sampling_rate=40.0, method=method)[0]
        assert out.stats.sampling_rate == 40.0
        assert out.stats.npts == pytest.approx(800, abs=1)
        t_new = np.arange(out.stats.npts) / 40.0
        ref = np.sin(2 * np.pi * 2.0 * t_new) * np.interp(t_new, t, np.hanning(t.size))
        np.testing.assert_allclose(out.data[20:-20], ref[20:-20], atol=0.02)


def test_resample_fft_keeps_pass_band_amplitude():
    """FFT resampling 100 -> 40 Hz must not attenuate a 15 Hz sine (below the new Nyquist of
    20 Hz) nor shift it: the resampled record equals the sine at the new sample times."""
    dt = 0.01
    t = np.arange(20000) * dt
    out = P.resample(_stream({"HN1": np.sin(2 * np.pi * 15.0 * t)}, dt), sampling_rate=40.0)[0]
    t_new = np.arange(out.stats.npts) / 40.0
    np.testing.assert_allclose(out.data, np.sin(2 * np.pi * 15.0 * t_new), atol=1e-6)


def test_trim_and_pad():
    dt = 0.01
    st = _stream({"HN1": np.arange(1000.0), "HNZ": np.arange(1000.0)}, dt)
    cut = P.trim(st, start=1.0, end=5.0)
    assert cut[0].stats.starttime == T0 + 1.0
    assert cut[0].stats.npts == 401 and cut[0].data[0] == 100.0
    padded = P.pad(st, before=0.5, after=1.0)[1]
    assert padded.stats.npts == 1000 + 50 + 100
    assert padded.stats.starttime == T0 - 0.5
    assert not np.any(padded.data[:50]) and not np.any(padded.data[-100:])
    np.testing.assert_array_equal(padded.data[50:1050], np.arange(1000.0))


@pytest.mark.parametrize("window, key", [({"start": 10.0}, "start"),   # record is 9.99 s long
                                         ({"start": 25.0, "end": 30.0}, "start"),
                                         ({"start": 9.995}, "start")])
def test_trim_beyond_the_record_names_the_window(window, key):
    st = _stream({"HN1": np.arange(1000.0), "HNZ": np.arange(1000.0)}, 0.01)
    with pytest.raises(P.ProcessingError, match="at or after the end of trace") as err:
        P.trim(st, **window)
    assert err.value.parameter == key and "9.990 s" in str(err.value)


# ---------------------------------------------------------------------------------------------
# registry, provenance, purity, errors
# ---------------------------------------------------------------------------------------------
VALID_PARAMS = {
    "demean": {},
    "detrend": {"type": "linear"},
    "taper": {"max_percentage": 0.1},
    "highpass": {"freq": 0.5},
    "lowpass": {"freq": 10.0},
    "bandpass": {"freqmin": 0.1, "freqmax": 25.0},
    "baseline": {"order": 6},
    "resample": {"sampling_rate": 50.0},
    "trim": {"start": 1.0, "end": 20.0},
    "pad": {"before": 1.0},
}


def test_every_step_has_a_test_entry():
    assert set(VALID_PARAMS) == set(P.STEPS)


@pytest.mark.parametrize("name", sorted(VALID_PARAMS))
def test_step_is_pure_and_records_provenance(noisy, name):
    before = noisy.copy()
    noisy[0].stats.processing = ["earlier entry"]
    out = P.STEPS[name](noisy, **VALID_PARAMS[name])
    assert out is not noisy
    for tr_in, tr_ref in zip(noisy, before, strict=True):
        np.testing.assert_array_equal(tr_in.data, tr_ref.data)
        assert tr_in.stats.npts == tr_ref.stats.npts
    assert noisy[0].stats.processing == ["earlier entry"]
    for tr in out:
        entries = [e for e in tr.stats.processing if e != "earlier entry"]
        assert len(entries) == 1, entries  # ObsPy's own entries are replaced
        assert entries[0].startswith(f"shipblock.processing.{name}(")
    assert out[0].stats.processing[0] == "earlier entry"


def test_bandpass_provenance_string(noisy):
    out = P.bandpass(noisy, freqmin=0.1, freqmax=25.0)
    assert out[0].stats.processing == [
        "shipblock.processing.bandpass(freqmin=0.1, freqmax=25.0, corners=4, zerophase=True, "
        "nyquist_cap=None)"
    ]


def test_default_chain_and_provenance_round_trip(noisy):
    out = P.apply_chain(noisy, P.DEFAULT_CHAIN)
    assert [e.split("(")[0] for e in out[0].stats.processing] == [
        f"shipblock.processing.{e['step']}" for e in P.DEFAULT_CHAIN
    ]
    chain = P.chain_from_provenance(out[0])
    assert chain == P.default_chain()
    again = P.apply_chain(noisy, chain)
    for a, b in zip(out, again, strict=True):
        np.testing.assert_array_equal(a.data, b.data)
    with pytest.raises(TypeError):
        P.DEFAULT_CHAIN[0]["step"] = "x"


def test_chain_accepts_toml_style_numbers(noisy):
    """TOML gives ints where floats are meant (freqmin = 1): accepted and equal."""
    a = P.apply_chain(noisy, [{"step": "bandpass", "freqmin": 1, "freqmax": 10}])
    b = P.apply_chain(noisy, [{"step": "bandpass", "freqmin": 1.0, "freqmax": 10.0}])
    np.testing.assert_array_equal(a[0].data, b[0].data)


@pytest.mark.parametrize(
    ("chain", "step", "parameter"),
    [
        ([{"step": "wiggle"}], "wiggle", None),
        ([{"freq": 1.0}], "<chain>", "step"),
        (["bandpass"], "<chain>", None),
        ([{"step": "bandpass", "freqmin": 0.1}], "bandpass", "freqmax"),
        ([{"step": "bandpass", "freqmin": 0.1, "freqmax": 20, "order": 4}], "bandpass", "order"),
        ([{"step": "bandpass", "freqmin": 2.0, "freqmax": 1.0}], "bandpass", "freqmin"),
        ([{"step": "lowpass", "freq": 5.0, "corners": 0}], "lowpass", "corners"),
        ([{"step": "lowpass", "freq": 5.0, "zerophase": "yes"}], "lowpass", "zerophase"),
        ([{"step": "taper", "max_percentage": 0.7}], "taper", "max_percentage"),
        ([{"step": "detrend", "type": "cubic"}], "detrend", "type"),
        ([{"step": "baseline", "order": 1}], "baseline", "order"),
        ([{"step": "resample", "sampling_rate": -5.0}], "resample", "sampling_rate"),
        ([{"step": "trim", "start": 5.0, "end": 1.0}], "trim", "end"),
        ([{"step": "pad", "before": "1s"}], "pad", "before"),
    ],
)
def test_chain_errors_name_step_and_parameter(noisy, chain, step, parameter):
    with pytest.raises(P.ProcessingError) as info:
        P.apply_chain(noisy, chain)
    assert info.value.step == step
    assert info.value.parameter == parameter
    assert repr(step) in str(info.value)
    if parameter:
        assert repr(parameter) in str(info.value)
    assert isinstance(info.value, ValueError)


def test_process_motion_returns_new_ground_motion():
    """Integration with shipblock.records.motion: tags, metadata note and purity."""
    from shipblock.records.motion import GroundMotion

    rng = np.random.default_rng(11)
    gm = GroundMotion.from_arrays(rng.standard_normal(3000), rng.standard_normal(3000), dt=0.01)
    h_before = gm.horizontal.copy()
    out = P.process_motion(gm)
    np.testing.assert_array_equal(gm.horizontal, h_before)
    assert out is not gm and out.dt == gm.dt and out.npts == gm.npts
    expected = P.apply_chain(gm.stream, P.DEFAULT_CHAIN)
    np.testing.assert_array_equal(out.horizontal, expected[0].data)
    note = out.metadata["processing"][-1]
    assert note.startswith("shipblock.processing.demean()") and "baseline(order=6)" in note
