"""Contact loads: the interface forces per block, their peaks in the run summary and histories,
and limit states on them.

References: closed forms of the rigid system at rest and sliding (Newton's second law on the
ship and the block stack), the independent symbolic derivation of tests/sympy_model.py for the
rocking forces, and the same run on a ten times finer sampling of the same piecewise-linear
input for the peaks between samples.
"""

from __future__ import annotations

import numpy as np
import pytest

from shipblock import ShipBlockSystem, simulate, simulate_batch
from shipblock.fragility.limit_states import LimitState, exceedance
from shipblock.interface_forces import LOAD_FIELDS
from shipblock.units import STANDARD_GRAVITY as G

try:
    from . import sympy_model as sm
except ImportError:  # pragma: no cover - run from the tests folder
    import sympy_model as sm

M, m, n = 5.0e6, 1200.0, 150
MU_S1, MU_K1, MU_S2, MU_K2 = 0.6, 0.55, 0.35, 0.30
SYSTEM = ShipBlockSystem(ship_mass=M, block_mass=m, n_blocks=n, half_width=0.3, half_height=0.6,
                         mu_s_ground=MU_S1, mu_k_ground=MU_K1, mu_s_ship=MU_S2, mu_k_ship=MU_K2)
DT = 0.01
N_SAMPLES = 300

#: A slender block under a one-cycle sine pulse: it rocks (about 0.3 s of mode 3).
SLENDER = ShipBlockSystem(ship_mass=2e6, block_mass=1500.0, n_blocks=120, half_width=0.15,
                          half_height=0.6, mu_s_ground=0.8, mu_k_ground=0.75, mu_s_ship=0.8,
                          mu_k_ship=0.75)


def _pulse(dt=DT, amplitude=0.45 * G, freq=2.0, duration=4.0):
    t = np.arange(int(round(duration / dt)) + 1) * dt
    return t, np.where(t < 1 / freq, amplitude * np.sin(2 * np.pi * freq * t), 0.0)


def _loads(summary):
    return {k: summary[k] for k in LOAD_FIELDS}


def test_at_rest_under_gravity_the_blocks_carry_their_share_of_the_ship():
    """N per block = (M/n + m) g on the floor and M g / n under the ship; no friction. With a
    constant vertical acceleration a_v, g becomes g + a_v."""
    res = simulate(SYSTEM, np.zeros(N_SAMPLES), None, DT)
    loads = _loads(res.summary)
    assert loads["peak_ground_normal_force"] == pytest.approx((M / n + m) * G, rel=1e-14)
    assert loads["peak_ship_normal_force"] == pytest.approx(M * G / n, rel=1e-14)
    for name in ("peak_ground_friction_force", "peak_ship_friction_force",
                 "peak_ground_friction_utilisation", "peak_ship_friction_utilisation",
                 "peak_corner_load"):
        assert loads[name] == 0.0
    av = 0.3 * G
    res = simulate(SYSTEM, np.zeros(N_SAMPLES), np.full(N_SAMPLES, av), DT)
    assert res.summary["peak_ground_normal_force"] == pytest.approx((M / n + m) * (G + av),
                                                                    rel=1e-14)
    np.testing.assert_allclose(res.forces.ground_normal, (M / n + m) * (G + av), rtol=1e-14)


def test_constant_horizontal_acceleration_below_slip_is_carried_by_friction():
    """Mode 1 under a constant a: friction = mass above the interface times a (per block
    (M/n + m) a on the floor, (M/n) a under the ship); utilisation a / (mu_s g)."""
    a = 0.2 * G
    res = simulate(SYSTEM, np.full(N_SAMPLES, a), None, DT)
    assert res.summary["peak_ship_slip"] == 0.0 and not res.summary["uplift"]
    loads = _loads(res.summary)
    assert loads["peak_ground_friction_force"] == pytest.approx((M / n + m) * a, rel=1e-13)
    assert loads["peak_ship_friction_force"] == pytest.approx(M / n * a, rel=1e-13)
    assert loads["peak_ground_friction_utilisation"] == pytest.approx(a / (MU_S1 * G), rel=1e-13)
    assert loads["peak_ship_friction_utilisation"] == pytest.approx(a / (MU_S2 * G), rel=1e-13)
    # the same in a batch, and in the history at every sample (the floor pushes the stack along
    # the ground's acceleration: positive friction)
    batch = simulate_batch(SYSTEM, [(np.full(N_SAMPLES, a), None)], [DT], [[0, 0, 1.0, 1.0]])
    for name, value in loads.items():
        assert batch[name][0] == pytest.approx(value, rel=1e-14)
    np.testing.assert_allclose(res.forces.ground_friction, (M / n + m) * a, rtol=1e-13)
    np.testing.assert_allclose(res.forces.ship_friction, M / n * a, rtol=1e-13)


def test_a_sliding_ship_carries_kinetic_friction():
    """a = 0.4 g > mu_s2 g: the ship slides at once, |F_x| = mu_k2 M g / n, utilisation
    mu_k2 / mu_s2; the blocks stick and carry their own inertia on top: m a + mu_k2 M g / n."""
    a = 0.4 * G
    res = simulate(SYSTEM, np.full(N_SAMPLES, a), None, DT)
    assert res.summary["peak_ship_slip"] > 0.1
    loads = _loads(res.summary)
    assert loads["peak_ship_friction_force"] == pytest.approx(MU_K2 * M * G / n, rel=1e-13)
    assert loads["peak_ship_friction_utilisation"] == pytest.approx(MU_K2 / MU_S2, rel=1e-13)
    assert loads["peak_ground_friction_force"] == pytest.approx(
        m * a + MU_K2 * M * G / n, rel=1e-13)


def test_slip_onset_peak_is_the_static_limit_between_samples():
    """A ramp of a through mu_s2 g: the ship friction peaks at the static limit
    mu_s2 M g / n at the instant of slip (between samples), then drops to the kinetic value;
    the samples of the history see neither exactly, the summary sees the limit."""
    t = np.arange(N_SAMPLES) * DT
    ramp = np.minimum(t, 1.0) * 0.37 * G  # crosses 0.35 g between samples
    res = simulate(SYSTEM, ramp, None, DT)
    assert res.summary["peak_ship_friction_force"] == pytest.approx(MU_S2 * M * G / n,
                                                                    rel=1e-9)
    assert res.summary["peak_ship_friction_utilisation"] == pytest.approx(1.0, rel=1e-9)
    assert np.nanmax(np.abs(res.forces.ship_friction)) < MU_S2 * M * G / n * (1 - 1e-4)


def test_rocking_forces_equal_the_independent_derivation_and_peaks_are_kept_between_samples():
    """While the blocks rock the history's forces equal the symbolic model's (Lagrange, with the
    normal gaps as coordinates; tests/sympy_model.py) at every sample; the corner load peak of
    the summary is at least the samples' and matches the same run sampled ten times finer to
    1e-4 (the peaks between step ends are what the kernel may miss)."""
    t, ax = _pulse()
    res = simulate(SLENDER, ax, None, DT)
    rocking = np.isin(res.mode, (3, 6, 7, 8))
    assert rocking.sum() > 20 and res.failure is None
    f = res.forces
    p = SLENDER.to_parameter_vector()
    inertia = SLENDER.to_parameter_vector()[2] / SLENDER.n_blocks
    for k in np.flatnonzero(rocking)[::3]:
        assert res.mode[k] == 3
        th, om = res.theta[k], res.theta_dot[k]
        s = 1.0 if th > 0 or (th == 0 and om > 0) else -1.0
        z = sm.solve_numeric(3, (SLENDER.ship_mass, SLENDER.block_mass, SLENDER.n_blocks,
                                 inertia, SLENDER.half_width, SLENDER.half_height, p[13], ax[k],
                                 0.0, th, om, s, 1.0, 1.0, SLENDER.mu_k_ground,
                                 SLENDER.mu_k_ship))
        assert f.ground_normal[k] == pytest.approx(z[sm.fy] / SLENDER.n_blocks, rel=1e-9)
        assert f.ground_friction[k] == pytest.approx(z[sm.fx] / SLENDER.n_blocks, rel=1e-9)
        assert f.ship_normal[k] == pytest.approx(z[sm.Fy] / SLENDER.n_blocks, rel=1e-9)
    corner = res.summary["peak_corner_load"]
    assert corner >= np.max(f.ground_normal[rocking])
    k = 10
    fine_t = np.arange((t.size - 1) * k + 1) * DT / k
    fine = simulate(SLENDER, np.interp(fine_t, t, ax), None, DT / k)
    fine_rock = np.isin(fine.mode, (3, 6, 7, 8))
    assert corner == pytest.approx(np.max(fine.forces.ground_normal[fine_rock]), rel=1e-4)
    assert res.summary["peak_ground_normal_force"] >= corner
    # rocking lifts the load onto the edge: above the static share
    assert corner > (SLENDER.ship_mass / SLENDER.n_blocks + SLENDER.block_mass) * G


def test_histories_hold_the_forces_with_units():
    _, ax = _pulse()
    ds = simulate(SLENDER, ax, None, DT).to_dataset()
    for name, units in (("ground_normal_force", "N"), ("ground_friction_force", "N"),
                        ("ship_normal_force", "N"), ("ship_friction_force", "N"),
                        ("ground_friction_utilisation", "1"), ("ship_friction_utilisation", "1")):
        assert ds[name].dims == ("time",)
        assert ds[name].attrs["units"] == units and ds[name].attrs["long_name"]
    assert float(ds["ground_normal_force"].max()) <= ds.attrs["summary_peak_ground_normal_force"]
    # after an overturning the forces stop with the run
    res = simulate(SLENDER, 3 * ax, None, DT)
    assert res.failure == "overturning"
    assert np.isnan(res.forces.ground_normal[res.mode == 0]).all()


def test_a_limit_state_on_the_keel_block_load():
    """'Keel block load above its capacity': exceeded where the peak normal force per block
    passes the capacity, by collapse too (the run stopped at it)."""
    ls = LimitState("block_crushing", "peak_ground_normal_force", threshold=4.0e5).validate()
    summary = {"peak_ground_normal_force": np.array([3.4e5, 4.2e5, 3.9e5, np.nan]),
               "failure": np.array([0.0, 0.0, 2.0, 0.0])}
    ex = exceedance(ls, summary)
    np.testing.assert_array_equal(ex.exceeded, [False, True, True, False])
    np.testing.assert_array_equal(ex.valid, [True, True, True, False])


@pytest.mark.parametrize("vertical", [False, True])
def test_peaks_over_rest_are_those_of_the_samples_exactly(vertical):
    """A random record too weak to move anything: the forces are linear between samples, so the
    summary's peaks are the maxima over the history's samples, to rounding (the kernel takes
    them from the extremes of the input over each span)."""
    rng = np.random.default_rng(4)
    ax = 0.2 * G * rng.uniform(-1, 1, 2000)
    ay = 0.2 * G * rng.uniform(-1, 1, 2000) if vertical else None
    res = simulate(SYSTEM, ax, ay, DT)
    assert (res.mode == 1).all()
    f = res.forces
    expect = {
        "peak_ground_normal_force": np.max(f.ground_normal),
        "peak_ground_friction_force": np.max(np.abs(f.ground_friction)),
        "peak_ship_normal_force": np.max(f.ship_normal),
        "peak_ship_friction_force": np.max(np.abs(f.ship_friction)),
        "peak_ground_friction_utilisation": np.max(f.ground_utilisation),
        "peak_ship_friction_utilisation": np.max(f.ship_utilisation),
    }
    for name, value in expect.items():
        assert res.summary[name] == pytest.approx(value, rel=1e-12), name
    if vertical:  # the largest friction and the largest utilisation at different samples
        assert np.argmax(np.abs(f.ground_friction)) != np.argmax(f.ground_utilisation)


@pytest.mark.parametrize(("system", "level"), [
    (SYSTEM.replace(mu_s_ship=0.1, mu_k_ship=0.08), 0.3),  # the ship slides on the blocks
    (SYSTEM.replace(mu_s_ground=0.12, mu_k_ground=0.1, mu_s_ship=0.9, mu_k_ship=0.85), 0.3),
])
def test_stick_slip_peaks_from_the_span_extremes_equal_a_scan_of_every_sample(system, level):
    """Without a vertical input the closed-form spans note the loads from the least and
    greatest input over each span (the forces are monotone in it); with a vertical input of
    zeros (the same motion) every sample is scanned. The peaks agree to rounding, through
    hundreds of slip starts and stops."""
    rng = np.random.default_rng(11)
    ax = level * G * np.convolve(rng.normal(size=4000), np.ones(8) / 8, mode="same")
    folded = simulate(system, ax, None, DT)
    scanned = simulate(system, ax, np.zeros_like(ax), DT)
    assert len(folded.events) > 100
    assert not folded.summary["uplift"]
    np.testing.assert_array_equal(folded.mode, scanned.mode)
    for name in LOAD_FIELDS:
        assert folded.summary[name] == pytest.approx(scanned.summary[name], rel=1e-13, abs=0.0), name
    # the slip starts: the friction utilisation of the interface that slips reaches its static limit
    slipping = "ship" if system.mu_s_ship < system.mu_s_ground else "ground"
    assert folded.summary[f"peak_{slipping}_friction_utilisation"] == pytest.approx(1.0, rel=1e-6)
