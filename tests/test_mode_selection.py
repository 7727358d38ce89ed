"""Mode selection after an event: the ordered, early-stopping search in the kernel picks the
same mode as comparing every candidate by the rule of docs/theory/transitions."""

import itertools

import numpy as np
import pytest

from shipblock import ShipBlockSystem
from shipblock.equations import mode_response
from shipblock.modes import MODE_NUMBER
from shipblock.solver import _kernel as K
from shipblock.solver._layout import ACC_TOL, FORCE_TOL, N_SPAN_WORK
from shipblock.system import FIELD_LIMITS


def reference_choice(system, y, a, ay, trigger):
    """Every candidate solved and ranked: consistent first, fewest new motions, releases the
    trigger, lower mode number, enumeration order; else least violation. Returns the mode
    state (slip1, rock, slip2, s, sig1, sig2) and whether it was consistent."""
    g = system.g
    weight = (system.total_block_mass + system.ship_mass) * g
    ship_weight = system.ship_mass * g
    vb, th, om, vs = y[3], y[1], y[4], y[5]
    rot = th if th != 0 else om

    def options(v):
        return [(1, 1 if v > 0 else -1, 0)] if v != 0 else [(0, 1, 0), (1, 1, 1), (1, -1, 1)]

    ranked = []
    for n_enum, ((f1, s1, n1), (fr, sr, nr), (f2, s2, n2)) in enumerate(
            itertools.product(options(vb), options(rot), options(vs))):
        mode = int(MODE_NUMBER[f1, fr, f2])
        try:
            acc, (fx, fy, Fx, Fy) = mode_response(system, mode, th, om, a, ay, s=sr,
                                                  sigma_ground=s1, sigma_ship=s2)
        except ValueError:
            continue
        viol = 0.0
        if fy <= 0 or Fy <= 0:
            viol += max(0, -fy / weight) + max(0, -Fy / ship_weight) + 1
        checks = [
            (f1 == 0, (abs(fx) - system.mu_s_ground * fy) / weight, n1, s1 * acc[0] / g),
            (fr == 0, (system.half_height * abs(fx + Fx) - system.half_width * (fy + Fy))
             / (weight * system.half_diagonal), nr, sr * acc[1] * system.half_diagonal / g),
            (f2 == 0, (abs(Fx) - system.mu_s_ship * Fy) / ship_weight, n2, s2 * acc[2] / g),
        ]
        for at_rest, excess, new, push in checks:
            if at_rest and excess > FORCE_TOL:
                viol += excess
            elif not at_rest and new and push <= ACC_TOL:
                viol += ACC_TOL - push
        releases = [n1, nr, n2][trigger] if trigger >= 0 else 0
        consistent = viol == 0
        key = (0, n1 + nr + n2) if consistent else (1, viol)
        ranked.append((key, 0 if releases else 1, mode, n_enum, (f1, fr, f2, sr, s1, s2)))
    best = min(ranked)
    return best[4], best[0][0] == 0


def reference_ship_liftoff(system, y, a, ay):
    """Whether the ship leaving the blocks is consistent: some rocking motion of the blocks
    alone (a ship of 1e-12 of their mass, or the smallest ship mass a system takes) is
    consistent and drops the ship's corner faster than the ship falls. Every combination
    solved, as for reference_choice."""
    g = system.g
    alone = system.replace(ship_mass=max(1e-12 * system.total_block_mass,
                                         FIELD_LIMITS["ship_mass"][0]))
    weight = system.total_block_mass * g
    R = system.half_diagonal
    vb, th, om = y[3], y[1], y[4]
    rot = th if th != 0 else om

    def options(v):
        return [(1, 1 if v > 0 else -1, 0)] if v != 0 else [(0, 1, 0), (1, 1, 1), (1, -1, 1)]

    for (f1, s1, n1), (fr, sr, nr) in itertools.product(options(vb), options(rot)):
        if not fr:
            continue
        acc, (fx, fy, _, _) = mode_response(alone, int(MODE_NUMBER[f1, 1, 0]), th, om, a, ay,
                                            s=sr, sigma_ground=s1)
        phi = system.critical_angle - sr * th
        corner = 2 * R * (sr * np.sin(phi) * acc[1] - np.cos(phi) * om**2)
        ok = fy > 0 and (-(g + ay) - corner) / g > ACC_TOL
        ok &= abs(fx) - system.mu_s_ground * fy <= FORCE_TOL * weight if not f1 else True
        ok &= s1 * acc[0] / g > ACC_TOL if n1 else True
        ok &= sr * acc[1] * R / g > ACC_TOL if nr else True
        if ok:
            return True
    return False


@pytest.mark.parametrize("seed", range(4))
def test_kernel_choice_equals_exhaustive_ranking(seed):
    rng = np.random.default_rng(seed)
    system = ShipBlockSystem(ship_mass=4e5, block_mass=1500.0, n_blocks=20, half_width=0.3,
                             half_height=0.8, mu_s_ground=0.35, mu_k_ground=0.3,
                             mu_s_ship=0.3, mu_k_ship=0.25)
    p = system.to_parameter_vector()  # the kernel passes the array (see select_mode)
    w7 = np.zeros(7)
    work = np.zeros(N_SPAN_WORK)  # one system: its response cache serves every call
    ms = np.zeros(6, dtype=np.int64)
    n_checked = 0
    for _ in range(150):
        y = np.zeros(9)
        # each interface at rest or moving either way; theta zero (rest or impact) or not
        y[3] = rng.choice([0.0, 0.2, -0.2])
        y[5] = rng.choice([0.0, 0.1, -0.1])
        if rng.random() < 0.4:
            y[1] = rng.choice([0.05, -0.05])
            y[4] = rng.normal() * 0.3
        elif rng.random() < 0.3:
            y[4] = rng.choice([0.4, -0.4])  # just after an impact
        a, ay = rng.normal() * 4.0, rng.normal() * 2.0
        trigger = int(rng.integers(-1, 3))
        status = K.select_mode(p, y, ms, a, ay, trigger, w7, work, 0.0, 0.0)
        want, consistent = reference_choice(system, y, a, ay, trigger)
        if status == 2:
            continue
        assert status == (0 if consistent else 1)
        if consistent:  # (with none consistent, the kernel jams or separates: test_painleve)
            assert tuple(int(v) for v in ms) == want
        n_checked += 1
    assert n_checked > 100


def test_ship_lifting_off_is_a_separation():
    """Found by random testing (seed 7 of the campaign, case 982, t = 0.157 s): a heavy ship
    (M_n = 0.044) on rocking blocks under 1.5 g; the ship's friction reaches its static limit,
    and with the ship slipping either way its contact force would be negative: no mode with
    contact is consistent. The blocks without the ship then rotate back so fast that their
    corner drops away from the ship (the ship lifts off): the selection reports separation
    (before, it took the least-violating mode and warned). Here at 1.53 g, clear of the
    friction limit (0.6 % of the ship's weight beyond it)."""
    system = ShipBlockSystem(ship_mass=8922846.75, block_mass=4365.626, n_blocks=89,
                             half_width=0.82062, half_height=1.32863, mu_s_ground=0.750368,
                             mu_k_ground=0.468188, mu_s_ship=0.833125, mu_k_ship=0.569886,
                             restitution=0.568)
    y = np.zeros(9)
    y[1] = -0.0044
    a, ay = 15.0, 0.0
    want, consistent = reference_choice(system, y, a, ay, 2)
    assert not consistent
    assert reference_ship_liftoff(system, y, a, ay)
    ms = np.zeros(6, dtype=np.int64)
    status = K.select_mode(system.to_parameter_vector(), y, ms, a, ay, 2, np.zeros(7),
                           np.zeros(N_SPAN_WORK), 0.0, 0.0)
    assert status == 2
    # the same state as a run's start: it separates at t = 0, without a warning
    import warnings

    from shipblock import simulate

    with warnings.catch_warnings():
        warnings.simplefilter("error")
        res = simulate(system, np.full(20, a), None, 0.005, initial_state=y[:6])
    assert res.failure == "separation" and res.failure_time == 0.0


def test_nonrocking_candidates_use_the_response_cache():
    """At rest a candidate's forces are superposed from the run's response vectors (solved into
    the cache on first use): the same as solving the mode at (a, G), to rounding."""
    from shipblock.equations import solve_mode
    from shipblock.solver._closed_form import response_slot
    from shipblock.solver._layout import W_RESP_STATE

    system = ShipBlockSystem(ship_mass=4e5, block_mass=1500.0, n_blocks=20, half_width=1.0,
                             half_height=0.8, mu_s_ground=0.2, mu_k_ground=0.15,
                             mu_s_ship=0.6, mu_k_ship=0.5)
    p = system.to_parameter_vector()
    w7, want = np.zeros(7), np.zeros(7)
    work = np.zeros(N_SPAN_WORK)
    ms = np.zeros(6, dtype=np.int64)
    weight = (system.total_block_mass + system.ship_mass) * system.g
    scale = np.array([system.g] * 3 + [weight] * 4)
    for a, ay in [(0.5, 0.3), (-0.7, -1.0), (4.0, 0.0), (-4.0, 1.5)]:
        status = K.select_mode(p, np.zeros(9), ms, a, ay, -1, w7, work, 0.0, 0.0)
        assert status == 0 and ms[1] == 0  # rest, or the blocks sliding: no rocking
        slip1, slip2, sig1, sig2 = int(ms[0]), int(ms[2]), float(ms[4]), float(ms[5])
        assert work[W_RESP_STATE + response_slot(slip1, sig1, slip2, sig2)] == 1.0
        assert solve_mode(p, slip1, 0, slip2, 1.0, sig1, sig2, 0.0, 0.0, a, system.g + ay, want)
        assert np.all(np.abs(w7 - want) <= 1e-12 * scale)
    assert work[W_RESP_STATE + response_slot(1, 1.0, 0, 1.0)] == 1.0  # both slip directions met
    assert work[W_RESP_STATE + response_slot(1, -1.0, 0, 1.0)] == 1.0
