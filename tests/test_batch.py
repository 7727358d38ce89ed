"""Tests of the analysis design grid and the chunked batch runner.

Reference values: scale factors are checked against the IM re-measured with
:mod:`shipblock.intensity`; batch results against single :func:`shipblock.simulate` runs of the
same scaled record (bit for bit, since both call the same compiled kernel on the same arrays).
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from shipblock import ShipBlockSystem, intensity, simulate
from shipblock.fragility import batch as batch_mod
from shipblock.models import rigid as rigid_mod
from shipblock.fragility.batch import prepare_record, run_batch, run_chunk, summary_dataset
from shipblock.fragility.design import AnalysisDesign, IntensityDesign, apply_parameters
from shipblock.fragility.store import ChunkStore
from shipblock.records.motion import GroundMotion
from shipblock.solver import MODE_TIME_FIELDS, SUMMARY_FIELDS
from shipblock.units import STANDARD_GRAVITY as G

SYSTEM = ShipBlockSystem(
    ship_mass=5.0e6, block_mass=1200.0, n_blocks=150, half_width=0.3, half_height=0.6,
    mu_s_ground=0.6, mu_k_ground=0.55, mu_s_ship=0.35, mu_k_ship=0.30,
)


# -------------------------------------------------------------------------------------------
# synthetic records (shared with test_pipeline.py)
# -------------------------------------------------------------------------------------------


def synthetic_motion(seed: int, duration: float = 6.0, dt: float = 0.01):
    """Three components of a smooth, enveloped two-tone motion [m/s^2] (peak about 1 m/s^2)."""
    rng = np.random.default_rng(seed)
    t = np.arange(0.0, duration, dt)
    env = np.sin(np.pi * t / duration) ** 2
    f1, f2 = 1.0 + 2.0 * rng.random(), 2.0 + 3.0 * rng.random()
    h1 = env * (np.sin(2 * np.pi * f1 * t) + 0.5 * np.sin(2 * np.pi * f2 * t + rng.random()))
    h2 = env * np.cos(2 * np.pi * f1 * t)
    v = 0.4 * env * np.sin(2 * np.pi * 2.5 * f2 * t)
    return h1, h2, v, dt


def make_catalogue(directory, n_records: int = 2, bad: bool = False,
                   duration: float = 6.0) -> Path:
    """Write MiniSEED records and a catalogue.toml into ``directory``; return its path.

    With ``bad=True`` a record whose file is not a waveform file is added (id ``syn/BAD``).
    """
    from obspy import Stream, Trace, UTCDateTime

    directory = Path(directory)
    directory.mkdir(parents=True, exist_ok=True)
    lines = ["schema_version = 1"]
    for i in range(n_records):
        h1, h2, v, dt = synthetic_motion(i, duration)
        st = Stream()
        for ch, data in (("HNN", h1), ("HNE", h2), ("HNZ", v)):
            tr = Trace(np.asarray(data, dtype=np.float64))
            tr.stats.delta = dt
            tr.stats.network = "XX"
            tr.stats.station = f"S{i}"
            tr.stats.channel = ch
            tr.stats.starttime = UTCDateTime(2020, 1, 1)
            st += tr
        st.write(str(directory / f"S{i}.mseed"), format="MSEED")
        lines += ["[[record]]", f'id = "syn/S{i}"', f'files = ["S{i}.mseed"]', 'units = "m/s^2"',
                  f'station = "S{i}"', 'network = "XX"', 'license = "CC0"',
                  'credit = "synthetic"', "[record.components]", 'HNN = "H1"', 'HNE = "H2"',
                  'HNZ = "V"']
    if bad:
        (directory / "BAD.mseed").write_bytes(b"not a waveform file " * 50)
        lines += ["[[record]]", 'id = "syn/BAD"', 'files = ["BAD.mseed"]', 'units = "m/s^2"',
                  'station = "BAD"', 'license = "CC0"', 'credit = "synthetic"']
    path = directory / "catalogue.toml"
    path.write_text("\n".join(lines) + "\n")
    return path


def _loader(seed, vertical=True):
    h1, _, v, dt = synthetic_motion(seed)
    return lambda: GroundMotion.from_arrays(h1, v if vertical else None, dt=dt,
                                            name=f"syn{seed}")


# -------------------------------------------------------------------------------------------
# design
# -------------------------------------------------------------------------------------------


def _design(levels_g=(0.2, 0.4, 0.6), sweep=(), kind="ida", **kw):
    levels = tuple(x * G for x in levels_g) if kind != "cloud" else ()
    return AnalysisDesign(("a", "b", "c"), IntensityDesign(kind, levels=levels, **kw), SYSTEM,
                          tuple(sweep)).validate()


def test_design_grid_shape_dims_and_coords():
    d = _design(sweep=(("mu_ground", (0.4, 0.5)), ("slenderness", (0.3, 0.5, 0.7))))
    assert d.dims == ("record", "im_level", "mu_ground", "slenderness")
    assert d.shape == (3, 3, 2, 3)
    assert d.n_cases == 54 and d.n_systems == 6
    coords = d.coords()
    assert list(coords["record"][1]) == ["a", "b", "c"]
    np.testing.assert_allclose(coords["im_level"][1], [0.2 * G, 0.4 * G, 0.6 * G])
    assert coords["im_level"][2]["units"] == "m/s^2"
    assert coords["slenderness"][2]["units"] == "1"
    # case numbers are C order over (record, level, *sweep); systems in C order over the sweep
    idx = d.case_indices(np.arange(d.n_cases))
    assert idx.shape == (54, 3)
    r, lvl, a, b = np.unravel_index(37, d.shape)
    assert tuple(idx[37]) == (r, lvl, a * 3 + b)
    systems = d.systems()
    s = systems[1 * 3 + 2]  # mu_ground 0.5, slenderness 0.7
    assert s.mu_s_ground == 0.5
    assert s.mu_k_ground == pytest.approx(0.5 * 0.55 / 0.6)
    assert s.half_width == pytest.approx(0.7 * 0.6) and s.half_height == 0.6
    # chunks cover every case exactly once, in order
    chunks = d.chunks(10)
    assert [len(c) for c in chunks] == [10] * 5 + [4]
    assert np.array_equal(np.concatenate([list(c) for c in chunks]), np.arange(54))


def test_cloud_design_has_no_level_dimension():
    d = _design(kind="cloud")
    assert d.dims == ("record",) and d.shape == (3, 1) and d.n_cases == 3
    assert "im_level" not in d.coords()


def test_apply_parameters_conveniences_and_errors():
    s = apply_parameters(SYSTEM, {"mass_ratio": 0.1, "n_blocks": 100})
    assert s.mass_ratio == pytest.approx(0.1) and s.n_blocks == 100
    with pytest.raises(ValueError, match="slenderness"):
        apply_parameters(SYSTEM, {"slenderness": 0.5, "half_width": 0.2})
    with pytest.raises(ValueError, match="mu_k_ground"):
        apply_parameters(SYSTEM, {"mu_s_ground": 0.3})  # kinetic 0.55 > static 0.3
    with pytest.raises(ValueError, match="unknown"):
        apply_parameters(SYSTEM, {"friction": 0.3})


@pytest.mark.parametrize(
    ("bad", "match"),
    [({"levels": (2.0, 1.0)}, "increasing"), ({"levels": ()}, "at least one"),
     ({"measure": "sa", "levels": (1.0,)}, "period"),
     ({"vertical": "independent", "levels": (1.0,)}, "vertical_levels")],
)
def test_intensity_design_validation(bad, match):
    with pytest.raises(ValueError, match=match):
        IntensityDesign("ida", **bad).validate()


# -------------------------------------------------------------------------------------------
# records: read once, scaled to the targets
# -------------------------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("measure", "levels", "period", "measure_fn"),
    [
        ("pga", (0.5, 2.0, 4.0), None, lambda a, dt: intensity.pga(a, dt)),
        ("pgv", (0.1, 0.3), None, lambda a, dt: intensity.pgv(a, dt)),
        ("sa", (1.0, 5.0), 0.5, lambda a, dt: intensity.spectral_acceleration(a, dt, 0.5)),
    ],
)
def test_scale_factors_achieve_target_im(measure, levels, period, measure_fn):
    design = IntensityDesign("ida", measure=measure, levels=levels, period=period).validate()
    rec = prepare_record("syn0", _loader(0), [], design)
    assert rec.error is None
    h1, _, v, dt = synthetic_motion(0)
    for j, target in enumerate(levels):
        scaled = rec.factor_h[j] * rec.horizontal
        assert measure_fn(scaled, dt) == pytest.approx(target, rel=1e-9)
        assert rec.achieved[j] == pytest.approx(target, rel=1e-9)
        assert rec.factor_v[j] == rec.factor_h[j]  # vertical "same": V/H kept
    np.testing.assert_array_equal(rec.horizontal, h1)  # empty chain: the record as given
    assert rec.im == pytest.approx(measure_fn(h1, dt))


def test_vertical_modes():
    lv = (0.3 * G, 0.6 * G)
    zero = prepare_record("s", _loader(1), [], IntensityDesign("ida", levels=lv,
                                                                vertical="zero"))
    assert np.all(zero.factor_v == 0.0)
    ind = prepare_record("s", _loader(1), [], IntensityDesign(
        "ida", levels=lv, vertical="independent", vertical_levels=(1.0, 2.0)))
    for j, target in enumerate((1.0, 2.0)):
        assert intensity.pga(ind.factor_v[j] * ind.vertical, ind.dt) == pytest.approx(target)
    none = prepare_record("s", _loader(1, vertical=False), [], IntensityDesign("ida", levels=lv))
    assert none.vertical is None and np.all(np.isnan(none.factor_v))


def test_bad_record_is_reported_not_raised():
    def broken():
        raise OSError("disk on fire")

    rec = prepare_record("x", broken, None, IntensityDesign("ida", levels=(1.0, 2.0)))
    assert rec.error == "OSError: disk on fire"
    assert rec.horizontal is None and np.all(np.isnan(rec.factor_h))

    rec = prepare_record("y", _loader(0), [{"step": "no_such_step"}],
                         IntensityDesign("ida", levels=(1.0,)))
    assert "no_such_step" in rec.error


# -------------------------------------------------------------------------------------------
# chunks: equal to single simulate() runs, bit for bit
# -------------------------------------------------------------------------------------------


def test_run_chunk_equals_single_simulate_bit_for_bit():
    lv = (0.3 * G, 0.6 * G, 0.9 * G)
    intens = IntensityDesign("ida", levels=lv)
    recs = [prepare_record(f"s{i}", _loader(i), [], intens) for i in range(2)]
    systems = [SYSTEM, SYSTEM.replace(mu_s_ship=0.5, mu_k_ship=0.45)]
    cases = np.array([[0, 2, 0], [1, 1, 1], [0, 0, 1], [1, 2, 0]])
    out = run_chunk([r.payload() for r in recs], systems, cases)
    assert np.nanmax(out["peak_ship_slip"]) > 0.01  # the cases do slide
    for c, (r, j, s) in enumerate(cases):
        rec = recs[r]
        res = simulate(systems[s], rec.factor_h[j] * rec.horizontal,
                       rec.factor_v[j] * rec.vertical, rec.dt)
        for name in [*SUMMARY_FIELDS, *MODE_TIME_FIELDS, "peak_rotation_ratio"]:
            got, want = float(out[name][c]), float(res.summary[name])
            assert got == want or (math.isnan(got) and math.isnan(want)), (name, c)


def test_solver_errors_become_nan_with_message():
    out = {"failure": np.array([0.0, 3.0, 2.0]), "failure_time": np.array([np.nan, 1.25, 2.0]),
           "peak_ship_slip": np.array([0.1, 0.2, 0.3])}
    msg = batch_mod.mark_solver_errors(out, rigid_mod.RigidModel())
    assert list(msg) == ["", "solver error (failure code 3) at t = 1.25 s", ""]
    assert np.isnan(out["peak_ship_slip"][1]) and np.isnan(out["failure"][1])
    assert out["failure"][2] == 2.0


# -------------------------------------------------------------------------------------------
# the batch: chunk files, resume, error records
# -------------------------------------------------------------------------------------------


def _batch_setup(bad=False):
    intens = IntensityDesign("ida", levels=(0.3 * G, 0.6 * G))
    ids = ("s0", "s1", "bad") if bad else ("s0", "s1")
    design = AnalysisDesign(ids, intens, SYSTEM, (("mu_ship", (0.3, 0.4)),)).validate()
    recs = [prepare_record("s0", _loader(0), [], intens),
            prepare_record("s1", _loader(1), [], intens)]
    if bad:
        recs.append(prepare_record("bad", lambda: 1 / 0, [], intens))
    return design, recs


def test_run_batch_writes_chunks_and_resumes_without_recomputing(tmp_path, monkeypatch):
    design, recs = _batch_setup()
    full = run_batch(design, recs, ChunkStore(tmp_path / "a", "fp").open(), chunk_size=3,
                     progress=False)
    assert len(ChunkStore(tmp_path / "a", "fp").completed()) == 3  # 8 cases in chunks of 3

    store = ChunkStore(tmp_path / "b", "fp").open()
    calls = []
    real = batch_mod.run_chunk

    def counting(*args, **kwargs):
        calls.append(1)
        if len(calls) == 2:
            raise KeyboardInterrupt  # interrupted during the second chunk
        return real(*args, **kwargs)

    monkeypatch.setattr(batch_mod, "run_chunk", counting)
    with pytest.raises(KeyboardInterrupt):
        run_batch(design, recs, store, chunk_size=3, progress=False)
    assert store.completed() == {0}
    calls.clear()
    monkeypatch.setattr(batch_mod, "run_chunk", lambda *a, **k: (calls.append(1), real(*a, **k))[1])
    resumed = run_batch(design, recs, store, chunk_size=3, progress=False)
    assert len(calls) == 2  # chunks 1 and 2 only
    for name in full:
        np.testing.assert_array_equal(resumed[name], full[name])


def test_error_record_kept_with_nan_results(tmp_path):
    design, recs = _batch_setup(bad=True)
    res = run_batch(design, recs, ChunkStore(tmp_path / "p", "fp").open(), chunk_size=5,
                    progress=False)
    ds = summary_dataset(design, recs, res)
    assert "ZeroDivisionError" in str(ds["record_error"].sel(record="bad").values)
    assert ds["record_error"].sel(record="s0").item() == ""
    assert ds["peak_ship_slip"].sel(record="bad").isnull().all()
    assert ds["peak_ship_slip"].sel(record="s0").notnull().all()
    assert ds["failure"].sel(record="s1").notnull().all()
    assert math.isnan(float(ds["scale_factor"].sel(record="bad", im_level=0.3 * G)))


def test_run_chunk_converts_only_the_systems_its_cases_use(monkeypatch):
    intens = IntensityDesign("ida", levels=(0.3 * G, 0.6 * G))
    recs = [prepare_record(f"s{i}", _loader(i), [], intens) for i in range(2)]
    systems = [SYSTEM.replace(mu_s_ship=0.3 + 0.01 * k, mu_k_ship=0.3) for k in range(40)]
    cases = np.array([[0, 1, 7], [1, 0, 31], [0, 1, 31]])
    seen = []
    real = rigid_mod.simulate_batch  # the rigid model's batch entry point

    def spy(systems_, *args, **kwargs):
        seen.append(list(systems_))
        return real(systems_, *args, **kwargs)

    monkeypatch.setattr(rigid_mod, "simulate_batch", spy)
    out = run_chunk([r.payload() for r in recs], systems, cases)
    assert seen == [[systems[7], systems[31]]]
    ref = run_chunk([r.payload() for r in recs], [systems[7], systems[31]],
                    np.array([[0, 1, 0], [1, 0, 1], [0, 1, 1]]))
    for name in out:
        np.testing.assert_array_equal(out[name], ref[name])


def test_run_batch_results_do_not_depend_on_the_chunk_size(tmp_path):
    design, recs = _batch_setup(bad=True)
    results = [run_batch(design, recs, ChunkStore(tmp_path / str(c), "fp").open(),
                         chunk_size=c, progress=False) for c in (1, 3, 5, 100)]
    for other in results[1:]:
        assert set(other) == set(results[0])
        for name in results[0]:
            np.testing.assert_array_equal(other[name], results[0][name])
    assert list(results[0]["run_error"]) == [""] * 12  # the bad record has no run errors


def test_record_scaled_above_100_g_is_left_out_not_run():
    """Sa at a long period can need more than 100 g of ground acceleration: the record is left
    out with the reason (the solver would refuse the run and stop the batch)."""
    design = IntensityDesign("ida", measure="sa", period=20.0, levels=(0.01 * G, 10.0 * G))
    rec = prepare_record("syn0", _loader(0), [], design.validate())
    assert rec.horizontal is None and rec.error is not None
    assert "above the plausibility limit" in rec.error and "100 g" in rec.error
    assert "98.066" in rec.error  # names the level (10 g) it cannot be scaled to
    ok = prepare_record("syn0", _loader(0), [], IntensityDesign(
        "ida", measure="sa", period=20.0, levels=(0.01 * G,)).validate())
    assert ok.error is None
    assert ok.factor_h[0] * np.abs(ok.horizontal).max() < 100 * G
