"""Static state of the dock section against the elastic hand calculation of docking practice.

The hand calculation takes the ship as rigid on linear elastic supports: line stiffnesses
``K = N E A / t`` (caps of a moving line in series), the keel line's rotational stiffness that
of its caps (a continuous layer: ``K b^2 / 3``, in series top and bottom), the gravity term
``-W h_G`` of the roll stiffness, and the trapezoidal (moment-area) pressure across a cap. It is
a small-deflection theory, and the model's static state is nonlinear (rotations, lift-off): they
agree to the order of the rotations (~1e-6 here), so the tolerances are 1e-4, far below what a
sign or factor error in a load path would give.
"""

import dataclasses

import numpy as np
import pytest

from shipblock.bench.section_campaign import random_case
from shipblock.errors import ParameterError, ParameterTypeError
from shipblock.section import (NAVY_BLOCK, Block, BlockLine, Cap, DockSection, SectionRunner, Ship,
                               Wind)
from shipblock.section import _kernel as K
from shipblock.section import simulate as simulate_mod
from shipblock.section.model import NoStaticSolution, assemble, static_state, sunk_state
from shipblock.section.simulate import rest_state, simulate_section

G = 9.80665


def keel_only(e_g, n_springs=5, modulus=1e12, g_height=2.0):
    cap = Cap(modulus=modulus, proportional_limit=1e9)
    blk = Block(top=cap, bottom=cap)
    ship = Ship(mass=3e5, roll_inertia=3e5 * 4.0, g_height=g_height, keel_half_width=2.0,
                half_beam=5.0, g_offset=e_g)
    return DockSection(ship, BlockLine(block=blk, n_blocks=2), n_springs=n_springs)


def top_springs(asm, state, j=0):
    a, n = asm.strip_i[j, K.SI_FIRST], asm.strip_i[j, K.SI_COUNT]
    return asm.spring_f[a:a + n], state.spring_force[a:a + n]


@pytest.mark.parametrize("e_g", [0.0, 0.05, -0.12])
def test_keel_cap_pressure_is_the_trapezoid_inside_the_kern(e_g):
    sec = keel_only(e_g)
    asm = assemble(sec)
    st = static_state(asm)
    springs, force = top_springs(asm, st)
    blk, n = sec.keel.block, sec.keel.n_blocks
    w = sec.ship.mass * G
    b = blk.half_width
    area, inertia = blk.length * 2 * b, blk.length * (2 * b) ** 3 / 12
    y = springs[:, K.PF_RY]
    pressure = w / n / area + w / n * e_g * y / inertia  # per block, linear across the cap
    expected = pressure * springs[:, K.PF_AREA] * n
    np.testing.assert_allclose(force, expected, rtol=1e-4, atol=1e-4 * expected.max())
    assert st.normal[0] == pytest.approx(w, rel=1e-9)


def test_keel_cap_beyond_the_kern_lifts_off_in_a_triangle():
    """G at half the half-width off the centre (beyond b/3): contact length 3 (b - e), peak
    pressure 2 W / (3 L (b - e)) (the cracked-section formula), sampled by 15 springs."""
    sec = keel_only(0.3, n_springs=15)
    asm = assemble(sec)
    st = static_state(asm)
    springs, force = top_springs(asm, st)
    blk, n = sec.keel.block, sec.keel.n_blocks
    b, e = blk.half_width, 0.3
    w = sec.ship.mass * G / n
    y = springs[:, K.PF_RY]
    p = force / n / springs[:, K.PF_AREA]
    # the pressure is linear over the springs in contact and zero beyond
    loaded = p > 0
    slope, inter = np.polyfit(y[loaded], p[loaded], 1)
    np.testing.assert_allclose(p[loaded], slope * y[loaded] + inter, rtol=1e-4,
                               atol=1e-4 * p.max())
    zero_at = -inter / slope
    assert b - zero_at == pytest.approx(3 * (b - e), rel=2e-2)
    assert slope * b + inter == pytest.approx(2 * w / (3 * blk.length * (b - e)), rel=2e-2)
    # equilibrium exactly: the resultant and its moment
    assert force.sum() == pytest.approx(sec.ship.mass * G, rel=1e-9)


def hand_three_lines(sec):
    """Line loads and roll of a ship on a keel line and a symmetric pair of fixed side lines
    whose contacts all lie in the keel's plane (flat hull): vertical equilibrium and the
    moment about the keel's centre with compatibility ``delta(y) = w - phi y`` (the keel line's
    top settling also by its blocks' weight on the bottom caps)."""
    ship, keel = sec.ship, sec.keel
    s = sec.sides[1]
    d = s.offset
    kb = keel.block
    b = min(kb.half_width, ship.keel_half_width)
    k_top = keel.n_blocks * kb.top.modulus * kb.length * 2 * b / kb.top.thickness
    k_bot = keel.n_blocks * kb.bottom.modulus * kb.length * 2 * kb.half_width / kb.bottom.thickness
    k_keel = 1 / (1 / k_top + 1 / k_bot)
    kr_keel = 1 / (3 / (k_top * b**2) + 3 / (k_bot * kb.half_width**2))
    sb = s.block
    k_side = s.n_blocks * sb.top.modulus * sb.length * 2 * sb.half_width / sb.top.thickness
    w = ship.mass * G
    fw, hw = (sec.wind.lateral_force, sec.wind.height) if sec.wind else (0.0, 0.0)
    kr_side = k_side * sb.half_width**2 / 3  # each side cap's own moment-area stiffness
    phi = -(w * ship.g_offset + fw * hw) / (kr_keel + 2 * (k_side * d**2 + kr_side)
                                             - w * ship.g_height)
    # the keel block's own weight settles its bottom cap: the keel's top sinks by that more
    w_block = keel.n_blocks * kb.block_mass * G
    pre = w_block / k_bot
    sink = (w + k_keel * pre) / (k_keel + 2 * k_side)
    return {"keel": k_keel * (sink - pre), "port": k_side * (sink + phi * d),
            "starboard": k_side * (sink - phi * d), "phi": phi}


def three_lines(e_g, wind=None):
    soft = Cap(shear_ratio=1e-3)  # keel caps: no shear coupling of the block's tilt
    keel = BlockLine(block=Block(top=soft, bottom=soft), n_blocks=4)
    side_block = Block()
    sides = (BlockLine(block=side_block, n_blocks=2, offset=-3.5, moving=False),
             BlockLine(block=side_block, n_blocks=2, offset=3.5, moving=False))
    ship = Ship(mass=6e5, roll_inertia=6e5 * 9.0, g_height=4.0, keel_half_width=0.8,
                half_beam=6.0, g_offset=e_g)
    return DockSection(ship, keel, sides, wind=wind)


@pytest.mark.parametrize("e_g, wind", [
    (0.0, None), (0.15, None), (-0.3, None), (0.0, Wind(height=8.0, force=2e5)),
    (0.1, Wind(height=6.0, pressure=-800.0, area=300.0)),
])
def test_line_loads_with_side_blocks_and_wind_match_the_hand_calculation(e_g, wind):
    sec = three_lines(e_g, wind)
    asm = assemble(sec)
    st = static_state(asm)
    hand = hand_three_lines(sec)
    top = [j for j in range(asm.n_strips) if asm.strip_top[j]]
    loads = dict(zip(("keel", "port", "starboard"), st.normal[top], strict=True))
    total = sum(hand[k] for k in ("keel", "port", "starboard"))
    assert total == pytest.approx(sec.ship.mass * G, rel=1e-12)
    for name, value in loads.items():
        assert value == pytest.approx(hand[name], rel=1e-4, abs=1e-5 * total), name
    phi = st.x[2]
    assert phi == pytest.approx(hand["phi"], rel=2e-3, abs=1e-9)
    if wind is not None:
        # the supports carry the wind: the horizontal forces on the blocks from the hull (normal
        # forces along the rotated hull normals, stick springs along the tangents) sum to it
        c, s_ = np.cos(phi), np.sin(phi)
        horizontal = 0.0
        for j in top:
            ny = c * asm.strip_f[j, K.SF_SNY] - s_ * asm.strip_f[j, K.SF_SNZ]
            nz = s_ * asm.strip_f[j, K.SF_SNY] + c * asm.strip_f[j, K.SF_SNZ]
            u = st.x[6 * asm.n_bodies + j]
            horizontal += st.normal[j] * ny - asm.strip_f[j, K.SF_KT] * u * nz
        assert horizontal == pytest.approx(wind.lateral_force, rel=1e-6)


def test_a_ship_unstable_on_its_keel_alone_is_refused():
    sec = keel_only(0.0, modulus=1e6, g_height=40.0)
    with pytest.raises(ParameterError, match="no static solution|unstable"):
        static_state(assemble(sec))


def test_caps_crushing_at_rest_are_refused_naming_the_line():
    weak = Cap(proportional_limit=1e4)
    sec = DockSection(Ship(mass=6e5, roll_inertia=5e6, g_height=3.0, keel_half_width=0.8,
                           half_beam=6.0), BlockLine(block=Block(top=weak), n_blocks=2))
    with pytest.raises(ParameterError, match="DockSection.keel: the top caps would crush"):
        static_state(assemble(sec))


def _slick_side_line():
    """One side line of slick caps (mu 0.05) under a hull sloped 0.3, G off to starboard."""
    slick = Cap(mu_s=0.05, mu_k=0.05)
    side = BlockLine(block=Block(top=slick, bottom=slick, half_height=24 * 0.0254 + 0.15),
                     n_blocks=2, offset=3.5, hull_height=0.3, hull_slope=0.3)
    ship = Ship(mass=6e5, roll_inertia=6e5 * 9.0, g_height=3.0, keel_half_width=0.8,
                half_beam=6.0, g_offset=0.3)
    return DockSection(ship, BlockLine(n_blocks=4), (side,))


def test_a_side_line_that_would_slide_at_rest_is_refused():
    """One side line under a sloped hull: the static state with the strips sticking from the
    touching position needs more friction than mu_s gives; static_state refuses it naming the
    line, not started out of its cone (rest_state then looks for the state the dock lands in:
    test_a_side_line_that_slips_as_the_ship_lands_starts_from_where_it_stuck)."""
    with pytest.raises(ParameterError, match=r"DockSection.sides\[0\]: at rest its .* face needs"):
        static_state(assemble(_slick_side_line()))


def test_side_lines_preloaded_by_an_interference_lift_the_ship_off_the_keel():
    """Both side lines 2 mm taller than the hull above them (an interference the parameters
    accept): the preload of their caps (3e7 N per line at 2 mm) exceeds the weight, so at rest
    the ship sits on the side lines alone, the keel line's top open, and the vertical components
    of the side loads carry the weight. (Powell's method alone stalled on this kink of the
    residual and refused the dock as having no static solution: found by the random campaign.)"""
    ship = Ship(mass=6e5, roll_inertia=6e5 * 9.0, g_height=4.0, keel_half_width=0.8,
                half_beam=6.0, g_offset=0.3)
    side = Block(half_height=NAVY_BLOCK.half_height + 0.15 + 0.001)
    sides = tuple(BlockLine(block=side, n_blocks=2, offset=s * 3.5, hull_height=0.3,
                            hull_slope=s * 0.08, moving=False) for s in (-1, 1))
    dock = DockSection(ship, BlockLine(n_blocks=4), sides)
    assert dock.side_gap(0) == pytest.approx(-0.002)
    asm = assemble(dock)
    init = static_state(asm)
    keel_top = [j for j in range(asm.n_strips) if asm.strip_top[j] and asm.strip_line[j] == 0]
    assert init.normal[keel_top[0]] == 0.0
    weight = ship.mass * dock.g
    sides_top = [j for j in range(asm.n_strips) if asm.strip_top[j] and asm.strip_line[j] > 0]
    # on the ship: -(N n + F_t t), t = (n_z, -n_y), F_t = -k_t u of the stick spring (the ship's
    # roll, 1e-5 rad, left out)
    nb = asm.n_bodies
    vertical = sum(-init.normal[j] * asm.strip_f[j, K.SF_SNZ]
                   - asm.strip_f[j, K.SF_KT] * init.x[6 * nb + j] * asm.strip_f[j, K.SF_SNY]
                   for j in sides_top)
    assert vertical == pytest.approx(weight, rel=1e-4)
    # G off to starboard: the starboard line carries more
    assert init.normal[sides_top[1]] > init.normal[sides_top[0]]


def _at_rest(dock, seconds=10.0):
    """Largest displacement of any body and the events of a run under no ground motion from the
    dock's static state (a second implementation: the dynamics keep an equilibrium still)."""
    n = int(seconds / 0.005) + 1
    res = simulate_section(dock, np.zeros(n), np.zeros(n), 0.005)
    moved = max([np.abs(res.ship).max()] + [np.abs(a).max() for a in res.lines.values()])
    return moved, [e.kind for e in res.events]


def test_a_static_state_powell_misses_from_the_start_is_found_from_where_the_dock_rests():
    """Campaign case 0 of seed 29 (two moving side lines, steady wind): Powell's method stalls
    from the stress-free start, so the dock was refused as having no static solution; left under
    gravity alone it comes to rest, and the solve from there converges. The state is an
    equilibrium the dynamics keep: 10 s under no ground motion move no body by 1e-12 m."""
    dock, _, _ = random_case(29, 0)
    asm = assemble(dock)
    with pytest.raises(NoStaticSolution):
        static_state(asm)
    init = rest_state(asm)
    assert np.all(init.regime != K.R_CRUSH)
    assert np.all(np.isin(init.friction, (K.F_STICK, K.F_FREE)))
    moved, events = _at_rest(dock)
    assert moved < 1e-12 and events == ["start"]


def test_a_side_line_that_slips_as_the_ship_lands_starts_from_where_it_stuck():
    """The dock of test_a_side_line_that_would_slide_at_rest_is_refused: with its stick spring
    stretched by the whole displacement from the touching position its side line needs more
    friction than mu_s; left to settle, the side cap slips and sticks again, and the static
    state with that slip is inside every strip's cone and kept still by the dynamics."""
    dock = _slick_side_line()
    asm = assemble(dock)
    init = rest_state(asm)
    u = init.x[6 * asm.n_bodies:6 * asm.n_bodies + asm.n_strips]
    demand = np.abs(asm.strip_f[:, K.SF_KT] * u)
    loaded = init.normal > 0.0
    assert np.all(demand[loaded] <= asm.strip_f[loaded, K.SF_MUS] * init.normal[loaded])
    moved, events = _at_rest(dock)
    assert moved < 1e-12 and events == ["start"]


def _counting_rest_state(monkeypatch):
    """Count the calls of rest_state made by SectionRunner (the list of their assemblies)."""
    calls = []

    def counted(asm):
        calls.append(asm)
        return rest_state(asm)

    monkeypatch.setattr(simulate_mod, "rest_state", counted)
    return calls


def test_a_runner_given_the_settled_rest_state_runs_as_one_that_settles_the_dock(monkeypatch):
    """The slick side line settles before its static solve (a full run): a runner handed that
    state (solved once by the caller) does not solve it again, and its runs equal, bit for
    bit, those of a runner that settles the dock itself, under a motion that slides the ship."""
    dock = _slick_side_line()
    init = rest_state(assemble(dock))
    assert init.settled_separation_height == 0.02
    dt = 0.01
    t = np.arange(0.0, 6.0, dt)
    h = 2.0 * np.sin(2 * np.pi * 1.5 * t) * np.sin(np.pi * t / 6.0) ** 2
    v = 0.5 * np.sin(2 * np.pi * 4.0 * t) * np.sin(np.pi * t / 6.0) ** 2
    calls = _counting_rest_state(monkeypatch)
    own = SectionRunner(dock)
    assert len(calls) == 1
    given = SectionRunner(dock, initial_state=init)
    assert len(calls) == 1 and given.initial_state is init
    np.testing.assert_array_equal(own.initial_state.x, init.x)
    a, b = own(h, v, dt), given(h, v, dt)
    assert a.summary == b.summary
    assert a.summary["side0_peak_slip"] > 1e-4  # the motion moves the dock
    np.testing.assert_array_equal(a.ship, b.ship)
    assert a.energy == b.energy and a.events == b.events


def test_a_runner_refuses_a_state_that_is_not_its_sections():
    """A state solved for another section (another ship mass, or no side line), or for this one
    settled at another separation height, the sunk start (not a static state) or something
    else is refused naming initial_state, not run from; one of an equal section built again
    is taken."""
    dock = _slick_side_line()
    init = rest_state(assemble(dock))
    assert init.section == dock
    assert SectionRunner(_slick_side_line(), initial_state=init).initial_state is init
    heavier = dataclasses.replace(dock, ship=dataclasses.replace(dock.ship, mass=6.5e5))
    for other in (heavier, keel_only(0.1)):
        with pytest.raises(ParameterError, match="initial_state is not the static state of "
                                                 "this section: it was solved for another"):
            SectionRunner(other, initial_state=init)
    with pytest.raises(ParameterError, match=r"settled with separation_height = 0.02 m, this "
                                             r"run has 0.05 m"):
        SectionRunner(dock, initial_state=init, separation_height=0.05)
    with pytest.raises(ParameterError, match="it was solved for none"):
        SectionRunner(dock, initial_state=sunk_state(assemble(dock)))
    with pytest.raises(ParameterTypeError, match="initial_state must be an InitialState"):
        SectionRunner(dock, initial_state=init.x)


def test_a_dock_that_tips_when_left_to_settle_is_refused_saying_so():
    """Campaign case 27 of seed 29 (one fixed side line): no static solution, and left under
    gravity alone the ship tips off its supports: refused, the message saying both."""
    dock, _, _ = random_case(29, 27)
    with pytest.raises(NoStaticSolution, match=r"no static solution.*left under gravity alone "
                                               r"from the stress-free position, it fails "
                                               r"\(ship tips\) at t = \d"):
        rest_state(assemble(dock))
