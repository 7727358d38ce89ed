"""Exponential steps of the dock section in its static regime (shipblock.section.exponential):
the matrix functions and the energy integrals against brute-force quadrature, and whole runs
against Dormand-Prince at tight tolerances (a second implementation of the same equations)."""

import dataclasses

import numpy as np
import pytest
import scipy.integrate
import scipy.linalg

from shipblock.bench.section import navy_dock, record
from shipblock.errors import ParameterTypeError
from shipblock.section import simulate as section_simulate
from shipblock.section.exponential import settled_steps, static_steps
from shipblock.section.model import assemble, static_state
from shipblock.section.simulate import simulate_section, simulate_section_batch

TIGHT = {"rtol": 1e-10, "atol": 1e-13, "exponential_steps": False}


@pytest.fixture(scope="module")
def navy():
    dock = navy_dock()
    asm = assemble(dock)
    init = static_state(asm)
    return dock, asm, init, static_steps(asm, init, 0.005)


def _trajectory(a, w, s):
    """y(s) of y' = A y + g0 + s c from the augmented exponential, w = (y0, g0, c) in full."""
    n = a.shape[0]
    m = np.zeros((3 * n, 3 * n))
    m[:n, :n] = a
    m[:n, n:2 * n] = np.eye(n)
    m[n:2 * n, 2 * n:] = np.eye(n)
    return (scipy.linalg.expm(m * s) @ w)[:n]


def _step_data(steps, seed):
    nm = steps.mats.shape[1]
    nv = steps.q_vel.shape[0]
    rng = np.random.default_rng(seed)
    y0 = np.zeros(nm)
    y0[:nv] = rng.normal(size=nv) * 1e-4
    y0[nv:] = rng.normal(size=nm - nv) * 1e-3
    g0, c = np.zeros(nm), np.zeros(nm)
    g0[nv:] = rng.normal(size=nm - nv) * 1e-2
    c[nv:] = rng.normal(size=nm - nv)
    w_red = np.concatenate([y0, g0[nv:], c[nv:]])
    return y0, g0, c, w_red


def test_step_matrices_are_the_exponential_and_phi_functions(navy):
    _, _, _, st = navy
    a, h = st.mats[0], 0.005
    e = scipy.linalg.expm(a * h)
    assert np.allclose(st.mats[1], e, rtol=1e-8, atol=1e-9 * np.abs(e).max())
    # h phi1(hA) A = e^{hA} - I and h^2 phi2(hA) A = h phi1(hA) - h I
    assert np.allclose(st.mats[2] @ a, e - np.eye(a.shape[0]), atol=1e-7 * np.abs(e).max())
    assert np.allclose(st.mats[3] @ a, st.mats[2] - h * np.eye(a.shape[0]),
                       atol=1e-7 * np.abs(st.mats[2]).max())
    assert np.allclose(st.mats[4], scipy.linalg.expm(a * h / 2), atol=1e-9 * np.abs(e).max())


@pytest.mark.parametrize("seed", [1, 2])
def test_step_integrals_equal_quadrature_of_the_trajectory(navy, seed):
    """The damping's quadratic form and the ground work's functionals over one step against
    Simpson's rule on 2001 points of the exact trajectory."""
    _, asm, _, st = navy
    a = st.mats[0]
    nm = a.shape[0]
    nv = st.q_vel.shape[0]
    y0, g0, c, w_red = _step_data(st, seed)
    w = np.concatenate([y0, g0, c])
    s = np.linspace(0.0, 0.005, 2001)
    ys = np.array([_trajectory(a, w, si) for si in s])
    vel = ys[:, nv:2 * nv]
    damping = scipy.integrate.simpson(np.einsum("ti,ij,tj->t", vel, st.q_vel, vel), x=s)
    assert w_red @ st.gram[0] @ w_red == pytest.approx(damping, rel=1e-6)
    mom_y = vel[:, 0::3] @ asm.mass
    assert st.rows[0][0] @ w_red == pytest.approx(scipy.integrate.simpson(mom_y, x=s), rel=1e-6)
    assert st.rows[0][1] @ w_red == pytest.approx(scipy.integrate.simpson(s * mom_y, x=s), rel=1e-6)
    mom_z = vel[:, 1::3] @ asm.mass
    assert st.rows[0][3] @ w_red == pytest.approx(scipy.integrate.simpson(s * mom_z, x=s), rel=1e-6)
    assert nm == 6 * asm.n_bodies + asm.n_strips


@pytest.mark.parametrize("pga", [0.02, 0.1])
def test_a_quiet_run_is_exponential_throughout_and_matches_dormand_prince(navy, pga):
    dock = navy[0]
    h, v, dt = record(duration=20.0, pga=pga)
    res = simulate_section(dock, h, v, dt)
    ref = simulate_section(dock, h, v, dt, **TIGHT)
    if pga == 0.02:  # every sample interval in one exponential step
        assert res.stats["exponential_steps"] == h.size - 1
        assert res.stats["accepted_steps"] == 0
    else:  # some refused for their error (half steps, or Dormand-Prince for a while)
        assert res.stats["exponential_steps"] > 0.8 * (h.size - 1)
    assert abs(res.energy["residual"]) < 1e-6
    assert res.energy["damping"] == pytest.approx(ref.energy["damping"], rel=1e-5)
    assert res.energy["ground_work"] == pytest.approx(ref.energy["ground_work"], rel=1e-5)
    for got, want in [(res.ship, ref.ship)] + [(res.lines[k], ref.lines[k]) for k in ref.lines]:
        err = np.abs(got - want).max(axis=0) / np.abs(want).max(axis=0)
        assert np.all(err < 1e-4), err
    for key in ("keel_peak_load_per_block", "side0_peak_load_per_block",
                "side1_peak_load_per_block", "peak_sway", "peak_roll",
                "keel_peak_top_pressure", "side0_friction_utilisation_top"):
        assert res.summary[key] == pytest.approx(ref.summary[key], rel=1e-4), key


def test_a_run_with_events_hands_over_to_dormand_prince_and_back(navy):
    """0.2 g: the first event at 8.7 s, then the dock comes back to its static regime."""
    dock = navy[0]
    h, v, dt = record(duration=20.0, pga=0.2)
    res = simulate_section(dock, h, v, dt)
    ref = simulate_section(dock, h, v, dt, **TIGHT)
    assert res.stats["events"] == ref.stats["events"] > 10
    assert 0 < res.stats["accepted_steps"] and res.stats["exponential_steps"] > 0.5 * h.size
    assert abs(res.events[1].time - ref.events[1].time) < 1e-6
    assert res.events[1].kind == ref.events[1].kind
    assert abs(res.energy["residual"]) < 1e-6
    for key in ref.summary:
        want = ref.summary[key]
        if isinstance(want, float) and np.isfinite(want) and "residual" not in key:
            assert res.summary[key] == pytest.approx(want, rel=1e-3, abs=1e-9), key


def test_settled_steps_at_the_static_state_are_the_static_steps(navy):
    """The matrices for a settled regime, made at the static state in its regime, are the static
    regime's (the same linearisation point: the static state is at rest)."""
    _, asm, init, steps = navy
    again = settled_steps(asm, init.x, init.regime, init.friction, np.zeros(asm.spring_f.shape[0]),
                          0.005)
    for name in ("x_s", "mats", "b", "gram", "rows", "q_vel", "wind_grad", "rates0"):
        assert np.array_equal(getattr(again, name), getattr(steps, name)), name
    moving = init.x.copy()
    moving[3 * asm.n_bodies:6 * asm.n_bodies] = 0.1  # velocities: not part of the point
    assert np.array_equal(settled_steps(asm, moving, init.regime, init.friction,
                                        np.zeros(asm.spring_f.shape[0]), 0.005).mats, steps.mats)


def test_a_run_settled_after_strong_motion_goes_on_in_exponential_steps(navy, monkeypatch):
    """0.3 g over 20 s: the last event at 18.6 s leaves caps open (not the static regime); one
    second later the run stops, makes the matrices of that regime and goes on in exponential
    steps. Up to the stop the run is bitwise the one without; after it, its histories, energy
    terms and demand parameters agree with Dormand-Prince's from the same state. (Five springs
    per cap, the dock this case was found on: with seven the caps close again.)"""
    dock = dataclasses.replace(navy[0], n_springs=5)
    h, v, dt = record(duration=20.0, pga=0.3)
    res = simulate_section(dock, h, v, dt)
    monkeypatch.setattr(section_simulate, "SETTLED_REGIMES", 0)
    ref = simulate_section(dock, h, v, dt)
    assert res.stats["settled_regimes"] == 1 and ref.stats["settled_regimes"] == 0
    assert res.stats["events"] == ref.stats["events"] > 100
    last = res.events[-1].time
    differ = np.flatnonzero(np.any(res.ship != ref.ship, axis=1))
    assert differ.size and differ[0] * dt >= last + section_simulate.SETTLE_SECONDS - 1e-9
    # every sample after the stop in one exponential step
    tail = h.size - differ[0]
    assert res.stats["exponential_steps"] - ref.stats["exponential_steps"] >= tail - 1
    for got, want in [(res.ship, ref.ship)] + [(res.lines[k], ref.lines[k]) for k in ref.lines]:
        err = np.abs(got - want).max(axis=0) / np.abs(want).max(axis=0)
        assert np.all(err < 1e-5), err
    assert abs(res.energy["residual"]) < 1e-6
    assert res.energy["damping"] == pytest.approx(ref.energy["damping"], rel=1e-6)
    for key in ref.summary:
        want = ref.summary[key]
        if isinstance(want, float) and np.isfinite(want):
            assert res.summary[key] == pytest.approx(want, rel=1e-4, abs=1e-9), key


def test_exponential_steps_can_be_turned_off_and_are_checked(navy):
    dock = navy[0]
    h, v, dt = record(duration=2.0, pga=0.05)
    assert simulate_section(dock, h, v, dt, exponential_steps=False).stats[
        "exponential_steps"] == 0
    with pytest.raises(ParameterTypeError, match="exponential_steps"):
        simulate_section(dock, h, v, dt, exponential_steps="yes")
    batch = simulate_section_batch(dock, [(h, v, dt)], exponential_steps=False)
    assert batch[0]["keel_peak_load_per_block"] == pytest.approx(
        simulate_section(dock, h, v, dt).summary["keel_peak_load_per_block"], rel=1e-5)
