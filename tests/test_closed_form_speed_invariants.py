"""Shortcuts of the closed-form span and the kernel that must not change a result.

Each shortcut skips work the direct computation would do (a division in the slip screen, the
sample-by-sample screen of a rest phase, an event log grown while the run goes on); these tests
check that the shortcut decides or returns exactly what the direct computation does.
"""

import numpy as np
import pytest

from shipblock import ShipBlockSystem, simulate, simulate_batch
from shipblock.equations import solve_mode
from shipblock.solver._closed_form import (
    add_repeated,
    held_fails_at,
    held_interval,
    rest_breaks,
    skip_rest,
    slip_may_stop,
)
from shipblock.solver._layout import (
    N_SPAN_WORK,
    N_SUMMARY,
    S_PEAK_FX,
    S_PEAK_SFX,
    S_PEAK_UTIL_G,
    S_PEAK_UTIL_S,
    W_NOTED,
    parameter_tuple,
)
from shipblock.solver._running_peaks import note_span_extremes
from shipblock.system import P_B, P_G, P_H, P_MUS1, P_MUS2


def direct_slip_screen(sig, v0, u0, u1, h):
    """The screen as the root search sets it up: q(s) = sig v0 + d0 s + c s^2."""
    c = sig * (u1 - u0) / (2.0 * h)
    d0 = sig * u0
    return sig * v0 + h * (d0 + c * h) < 0.0 or (d0 < 0.0 and d0 + 2.0 * c * h > 0.0)


def test_slip_screen_without_division_decides_as_the_direct_screen():
    rng = np.random.default_rng(1)
    n_suspect = 0
    for _ in range(40000):
        sig = float(rng.choice([-1.0, 1.0]))
        h = 0.01 if rng.random() < 0.5 else 0.01 * 10.0 ** rng.uniform(-12, 0)
        scale = 10.0 ** rng.uniform(-3, 1)
        u0, u1 = rng.normal(size=2) * scale
        if rng.random() < 0.2:
            u1 = u0 * (1 + rng.normal() * 1e-15)  # no curvature, up to round-off
        v0 = rng.normal() * scale * h
        kind = rng.integers(4)
        if kind == 1:
            # ends at zero up to a few ulps: the screen's decision rests on round-off
            q1 = sig * h * (u0 + 0.5 * (u1 - u0))
            v0 = -sig * q1 * (1 + rng.integers(-4, 5) * 2.0**-52)
        elif kind == 2:
            v0 = 0.0  # just started slipping
        elif kind == 3:
            # slope turning from negative to positive right at the end
            u0 = -sig * abs(u0)
            u1 = u0 * (-1 + rng.integers(-4, 5) * 2.0**-52)
        want = direct_slip_screen(sig, v0, u0, u1, h)
        assert slip_may_stop(sig, v0, u0, u1, h) == want, (sig, v0, u0, u1, h)
        n_suspect += want
    assert 1000 < n_suspect < 39000  # both outcomes well represented


def rest_coefficients(system):
    """Response vectors of rest (mode 1) as the span takes them."""
    p = parameter_tuple(system.to_parameter_vector())
    wa, wg = np.empty(7), np.empty(7)
    assert solve_mode(p, 0, 0, 0, 1.0, 1.0, 1.0, 0.0, 0.0, 1.0, 0.0, wa)
    assert solve_mode(p, 0, 0, 0, 1.0, 1.0, 1.0, 0.0, 0.0, 0.0, 1.0, wg)
    # grav, fx_a, fx_g, fy_a, fy_g, Fx_a, Fx_g, Fy_a, Fy_g, mus1, mus2, B, H
    return (p[P_G], wa[3], wg[3], wa[4], wg[4], wa[5], wg[5], wa[6], wg[6], p[P_MUS1], p[P_MUS2],
            p[P_B], p[P_H])


def span_rest_screen(a1, b1, c):
    """The span's screen at the end of an interval of rest, every event armed (Python)."""
    grav, fx_a, fx_g, fy_a, fy_g, Fx_a, Fx_g, Fy_a, Fy_g, mus1, mus2, B, H = c
    G1 = grav + b1
    fx1, fy1 = fx_a * a1 + fx_g * G1, fy_a * a1 + fy_g * G1
    Fx1, Fy1 = Fx_a * a1 + Fx_g * G1, Fy_a * a1 + Fy_g * G1
    return (fy1 <= 0.0 or Fy1 <= 0.0 or B * (fy1 + Fy1) < H * abs(fx1 + Fx1)
            or mus1 * fy1 < abs(fx1) or mus2 * Fy1 < abs(Fx1))


@pytest.mark.parametrize("fast", [True, False])
@pytest.mark.parametrize("has_ay", [True, False])
def test_rest_blocks_skip_exactly_the_passing_samples(has_ay, fast):
    system = ShipBlockSystem.example()
    c = rest_coefficients(system)
    rng = np.random.default_rng(2)
    n, dt, sh, sv = 3000, 0.005, 1.3, 0.7
    ax = rng.normal(size=n) * 0.5
    ay = rng.normal(size=n) * 0.5
    # sparse samples strong enough to break rest, some of them right at the friction limit
    for j in rng.choice(n, 25, replace=False):
        ax[j] = rng.choice([-1, 1]) * (8.0 if rng.random() < 0.5 else 0.6 * 9.80665 / sh)
    breaks = np.array([span_rest_screen(sh * ax[j], sv * ay[j] if has_ay else 0.0, c)
                       for j in range(n)])
    assert breaks.sum() > 10
    for j in range(n):
        assert rest_breaks(ax[j], ay[j], has_ay, sh, sv, *c) == breaks[j]
    lo, hi = held_interval(0, 0, *c) if fast and not has_ay else (1.0, -1.0)
    for k0 in list(rng.choice(n - 1, 60, replace=False)) + [0, n - 40, n - 2]:
        k, time, _, _ = skip_rest(ax, ay, has_ay, sh, sv, int(k0), dt, 0.25, *c, lo, hi,
                                  np.bool_(False), 0.0, 0.0, np.inf, -np.inf)
        assert k0 <= k <= n - 1
        assert not breaks[k0 + 1:k + 1].any()  # nothing skipped that the screen would stop at
        assert k == n - 1 or breaks[k + 1]  # stops at the first break
        want = 0.25
        for _ in range(k - k0):
            want += dt  # interval by interval, as the span adds it
        assert time == want


def direct_rest_peaks(p, c, a_values):
    """Peaks of |fx|, |Fx| and the two friction utilisations of rest over the scaled
    accelerations ``a_values`` (no vertical input), each sample noted (Python)."""
    grav, fx_a, fx_g, fy_a, fy_g, Fx_a, Fx_g, Fy_a, Fy_g, mus1, mus2 = c[:11]
    fx = np.abs(fx_a * a_values + fx_g * grav)
    Fx = np.abs(Fx_a * a_values + Fx_g * grav)
    return (fx.max(), Fx.max(), (fx / (mus1 * (fy_g * grav))).max(),
            (Fx / (mus2 * (Fy_g * grav))).max())


@pytest.mark.parametrize("seed", [3, 4])
def test_rest_blocks_keep_the_range_whose_loads_equal_those_of_every_sample(seed):
    """skip_rest with loads keeps the range of the scaled input over the samples it passes;
    noting the loads at its ends (note_span_extremes, with the range already noted per mode)
    gives the peaks of noting every sample passed, to the bit, though most blocks are passed
    by two comparisons a sample; and the break found is the one found without loads."""
    system = ShipBlockSystem.example()
    c = rest_coefficients(system)
    grav, fx_a, fx_g, _, fy_g, Fx_a, Fx_g, _, Fy_g = c[:9]
    p = system.to_parameter_vector()
    rng = np.random.default_rng(seed)
    n, dt, sh = 20000, 0.005, 1.3
    # growing amplitude (new peaks keep coming) below the limit of rest, a few strong samples
    ax = rng.normal(size=n) * np.linspace(0.05, 0.45, n)
    for j in rng.choice(n, 8, replace=False):
        ax[j] = 8.0
    ay = np.zeros(n)
    lo, hi = held_interval(0, 0, *c)
    assert lo < hi
    k = 0
    summary = np.zeros(N_SUMMARY)
    work = np.zeros(N_SPAN_WORK)
    work[W_NOTED], work[W_NOTED + 1] = np.inf, -np.inf  # slot 0: rest, nothing noted yet
    passed = np.zeros(n, dtype=bool)
    n_spans = n_widened = 0
    while k < n - 1:
        k0 = k
        k_plain, _, _, _ = skip_rest(ax, ay, False, sh, 0.0, k0, dt, 0.0, *c, lo, hi,
                                     np.bool_(False), 0.0, 0.0, np.inf, -np.inf)
        noted = (work[W_NOTED], work[W_NOTED + 1])
        # (an empty range to start with: k0 is the break passed over, not at rest)
        k, _, a_lo, a_hi = skip_rest(ax, ay, False, sh, 0.0, k0, dt, 0.0, *c, lo, hi,
                                     np.bool_(True), np.inf, -np.inf, *noted)
        assert k == k_plain
        passed[k0 + 1:k + 1] = True
        note_span_extremes(p, work, 0, fx_a, fx_g, fy_g, Fx_a, Fx_g, Fy_g, a_lo, a_hi, grav,
                           summary)
        n_widened += (work[W_NOTED], work[W_NOTED + 1]) != noted
        if passed.any():
            want = direct_rest_peaks(p, c, sh * ax[passed])  # every sample passed so far
            got = (summary[S_PEAK_FX], summary[S_PEAK_SFX], summary[S_PEAK_UTIL_G],
                   summary[S_PEAK_UTIL_S])
            assert got == want, (k0, k, got, want)
        n_spans += 1
        k += 1  # over the break
    assert n_spans > 5
    # the peaks grew through the record: the noted range widened again and again
    assert n_widened > 3
    assert 0.3 < summary[S_PEAK_UTIL_G] < 1.0


def test_rest_interval_passes_the_screen_near_its_ends():
    c = rest_coefficients(ShipBlockSystem.example())
    lo, hi = held_interval(0, 0, *c)
    assert lo < 0.0 < hi
    a = np.concatenate([np.linspace(lo, hi, 2001), lo + (hi - lo) * 1e-12 * np.arange(50),
                        hi - (hi - lo) * 1e-12 * np.arange(50)])
    assert not any(rest_breaks(x, 0.0, False, 1.0, 0.0, *c) for x in a)
    # and it is not much narrower than the screen: slightly beyond either end rest breaks
    assert rest_breaks(lo * (1 + 1e-6), 0.0, False, 1.0, 0.0, *c)
    assert rest_breaks(hi * (1 + 1e-6), 0.0, False, 1.0, 0.0, *c)


def slot_coefficients(system, slip1, sig1, slip2, sig2):
    """Response vectors of a non-rocking mode as the span takes them (None if singular)."""
    p = parameter_tuple(system.to_parameter_vector())
    wa, wg = np.empty(7), np.empty(7)
    if not (solve_mode(p, slip1, 0, slip2, 1.0, sig1, sig2, 0.0, 0.0, 1.0, 0.0, wa)
            and solve_mode(p, slip1, 0, slip2, 1.0, sig1, sig2, 0.0, 0.0, 0.0, 1.0, wg)):
        return None
    return (p[P_G], wa[3], wg[3], wa[4], wg[4], wa[5], wg[5], wa[6], wg[6], p[P_MUS1], p[P_MUS2],
            p[P_B], p[P_H])


def span_held_screen(slip1, slip2, a1, G1, c):
    """The held conditions of the span's screen written out (Python): normal forces, the
    moment criterion, the friction cone of each sticking interface."""
    _, fx_a, fx_g, fy_a, fy_g, Fx_a, Fx_g, Fy_a, Fy_g, mus1, mus2, B, H = c
    fx1, fy1 = fx_a * a1 + fx_g * G1, fy_a * a1 + fy_g * G1
    Fx1, Fy1 = Fx_a * a1 + Fx_g * G1, Fy_a * a1 + Fy_g * G1
    return (fy1 <= 0.0 or Fy1 <= 0.0 or B * (fy1 + Fy1) < H * abs(fx1 + Fx1)
            or (not slip1 and mus1 * fy1 < abs(fx1)) or (not slip2 and mus2 * Fy1 < abs(Fx1)))


@pytest.mark.parametrize("system", [
    ShipBlockSystem.example(),
    ShipBlockSystem.example().replace(mu_s_ground=0.1, mu_k_ground=0.08, mu_s_ship=0.3,
                                      mu_k_ship=0.25, half_height=2.0),
])
def test_held_interval_of_every_non_rocking_mode_passes_the_screen(system):
    """Inside the interval of a non-rocking mode the held conditions pass as the span computes
    them, up to the ends (the span then skips computing them); just beyond an end they fail,
    so the interval is not needlessly narrow."""
    rng = np.random.default_rng(4)
    n_known = 0
    for slip1, sig1 in ((0, 1.0), (1, 1.0), (1, -1.0)):
        for slip2, sig2 in ((0, 1.0), (1, 1.0), (1, -1.0)):
            c = slot_coefficients(system, slip1, sig1, slip2, sig2)
            if c is None:
                continue
            grav = c[0]
            lo, hi = held_interval(slip1, slip2, *c)
            # the compiled screen is the screen written out, on random inputs with and
            # without a vertical component
            for a1, b1 in zip(rng.normal(size=300) * 8.0, rng.normal(size=300) * 3.0, strict=True):
                for G1 in (grav + 0.0, grav + b1):
                    assert held_fails_at(slip1, slip2, a1, G1, *c[1:]) == span_held_screen(
                        slip1, slip2, a1, G1, c)
            if lo > hi:
                continue  # no interval known: every sample is screened in full
            n_known += 1
            if not np.isfinite(hi - lo):
                # a does not enter the held conditions (they are then constant and hold): the
                # blocks slip, so the forces are friction forces and what moves the ship with them
                assert slip1 and c[1] == 0.0 and c[5] == 0.0
                assert not any(span_held_screen(slip1, slip2, x, grav + 0.0, c)
                               for x in rng.normal(size=200) * 1e3)
                continue
            a = np.concatenate([np.linspace(lo, hi, 2001), lo + (hi - lo) * 1e-12 * np.arange(50),
                                hi - (hi - lo) * 1e-12 * np.arange(50)])
            assert not any(span_held_screen(slip1, slip2, x, grav + 0.0, c) for x in a)
            width = hi - lo
            if not (slip1 and slip2) and not (slip1 and hi - lo > 1e3 * grav):
                # bounded by a friction cone or the moment criterion, not by the cap
                assert span_held_screen(slip1, slip2, lo - 1e-6 * width, grav + 0.0, c)
                assert span_held_screen(slip1, slip2, hi + 1e-6 * width, grav + 0.0, c)
    assert n_known >= 7  # rest, the one-interface slides and the two-layer slides


def test_repeated_addition_equals_the_loop():
    rng = np.random.default_rng(3)
    cases = []
    for _ in range(20000):
        dt = float(rng.choice([0.005, 0.01, 0.02, 0.0025, 1 / 3])) if rng.random() < 0.7 \
            else 10.0 ** rng.uniform(-6, 0)
        t = 0.0 if rng.random() < 0.1 else dt * int(rng.integers(0, 5000)) * rng.choice(
            [1.0, 1.0 + 1e-12]) if rng.random() < 0.5 else rng.uniform(0.0, 60.0)
        cases.append((t, dt, int(rng.integers(0, 6000))))
    # ties: dt an odd number of half ulps of t, whose rounding depends on the parity of t
    for e in range(-8, 6):
        u = 2.0 ** (e - 53)
        for m in (1, 3, 5, 101):
            for t in (2.0 ** (e - 1), 2.0 ** (e - 1) + u, 0.75 * 2.0 ** e):
                cases.append((t, m * 0.5 * u, 9))
    for t, dt, n in cases:
        want = t
        for _ in range(n):
            want += dt
        assert add_repeated(t, dt, n) == want, (t, dt, n)


def test_event_log_longer_than_the_record():
    # a rocking block settling through hundreds of impacts in a 6-sample record: the log the
    # kernel is first given is too short, and the run is made again with room for every event
    system = ShipBlockSystem(ship_mass=5e6, block_mass=1500.0, n_blocks=150, half_width=0.12,
                             half_height=0.8, mu_s_ground=0.8, mu_k_ground=0.8, mu_s_ship=0.8,
                             mu_k_ship=0.8)
    ax = np.zeros(6)
    ax[1] = 1.6
    res = simulate(system, ax, None, 0.5)
    n_ev = int(res.summary["n_events"])
    assert n_ev > ax.size + 16
    assert len(res.events) == n_ev == res.events.time.size
    assert res.events[0].kind == "start" and res.events[-1].kind == "rocking_stop"
    assert np.all(np.diff(res.events.time) >= 0.0)
    assert res.summary["n_impacts"] == sum(e.kind in ("impact", "rocking_stop") for e in res.events)
    batch = simulate_batch(system, [(ax, None)], 0.5, [[0, 0, 1.0, 1.0]])
    assert batch["n_events"][0] == n_ev
