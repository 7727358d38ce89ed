"""Parameters of the dock-section model: defaults, derived stiffness, range checks by key."""

import math

import numpy as np
import pytest

from shipblock.errors import ParameterError, ParameterTypeError
from shipblock.section import NAVY_BLOCK, Block, BlockLine, Cap, DockSection, Ship, Wind
from shipblock.section import parameters as P
from shipblock.section.model import assemble, lobatto
from shipblock.units import INCH


def ship(**kw):
    base = dict(mass=4e5, roll_inertia=4e5 * 9.0, g_height=4.0, keel_half_width=0.6,
                half_beam=6.0)
    return Ship(**{**base, **kw})


def side(offset, **kw):
    return BlockLine(n_blocks=2, offset=offset, **kw)


def test_navy_block_defaults_and_derived_stiffness():
    b = NAVY_BLOCK
    assert b.half_width == pytest.approx(24 * INCH) and b.length == pytest.approx(42 * INCH)
    assert b.top.thickness == pytest.approx(6 * INCH)
    # 330 long tons force
    assert b.capacity == pytest.approx(330 * 1016.0469088 * 9.80665)
    area = b.length * 2 * b.half_width
    assert b.top.normal_stiffness(area) == pytest.approx(b.top.modulus * area / b.top.thickness)
    assert Cap(stiffness=3e9).normal_stiffness(area) == 3e9
    # concrete core and two oak caps
    expected = area * ((48 - 12) * INCH * 2400 + 12 * INCH * 760)
    assert b.block_mass == pytest.approx(expected)


#: One pound-force per square inch [Pa], from the exact definitions of the pound, g and the inch.
PSI = 0.45359237 * 9.80665 / INCH**2


def test_oak_cap_defaults_are_the_wood_handbook_values():
    """White oak, 12 % moisture content, Wood Handbook 2010 (FPL-GTR-190): the metric table
    (5-3a) and the inch-pound table (5-3b) agree to their rounding; E_T = 0.072 x 1.1 x E_bending
    (Table 5-1 ratio, Table 5-3 footnote: +10 % for shear deflection)."""
    cap = Cap()
    assert cap.proportional_limit == 7.4e6
    assert cap.proportional_limit == pytest.approx(1070 * PSI, rel=0.005)   # Table 5-3b
    assert P.WHITE_OAK_BENDING_MODULUS == pytest.approx(1.78e6 * PSI, rel=0.005)
    assert cap.modulus == pytest.approx(0.072 * 1.10 * 12.3e9, rel=1e-12)
    assert cap.modulus == pytest.approx(0.974e9, rel=1e-3)
    # density from specific gravity 0.68 (oven-dry mass, volume at 12 %) plus 12 % water
    assert P.OAK_DENSITY == pytest.approx(0.68 * 1.12 * 1000.0, rel=0.005)


def test_navy_block_is_the_described_standard_block():
    """42 x 48 in plan, 48 in overall, caps of 6 in oak timbers top and bottom (SBIR N254-122,
    after UFC 4-213-10 Fig. 8-2); its 330 LT load leaves the caps elastic, even green."""
    b = NAVY_BLOCK
    plan = sorted((b.length / INCH, 2 * b.half_width / INCH))
    assert plan == pytest.approx([42.0, 48.0])
    assert 2 * b.half_height / INCH == pytest.approx(48.0)
    assert b.top.thickness / INCH == pytest.approx(6.0) == b.bottom.thickness / INCH
    pressure = b.capacity / (b.length * 2 * b.half_width)
    assert pressure == pytest.approx(330 * 2240 / (42 * 48) * PSI)
    assert pressure < 670 * PSI < b.top.proportional_limit   # green white oak, Table 5-3b


def test_line_stiffness_is_n_blocks_times_e_a_over_t():
    sec = DockSection(ship(), BlockLine(n_blocks=3))
    asm = assemble(sec)
    b = NAVY_BLOCK
    half = min(b.half_width, 0.6)
    k = 3 * b.top.modulus * b.length * 2 * half / b.top.thickness
    assert asm.spring_f[:sec.n_springs, 2].sum() == pytest.approx(k)


@pytest.mark.parametrize("n", [2, 3, 5, 9])
def test_lobatto_rule_integrates_to_degree_2n_minus_3(n):
    x, w = lobatto(n)
    assert x[0] == -1.0 and x[-1] == 1.0
    for degree in range(0, 2 * n - 2):
        exact = 0.0 if degree % 2 else 2.0 / (degree + 1)
        assert sum(w * x**degree) == pytest.approx(exact, abs=1e-12)


def test_lobatto_springs_under_partial_lift_off_converge_at_second_order():
    """A face partly lifted off (a rocking block on its heel): closure ``d + a xi`` on
    ``[-1, 1]``, the layer carrying only where it is positive. The springs' force and moment
    against the continuous Winkler layer's closed forms ``(d + a)^2 / (2 a)`` and
    ``d (1 - xi0^2) / 2 + a (1 - xi0^3) / 3`` (``xi0 = -d / a``, where the face leaves the layer):
    the kink there makes the rule second order, not exact; the worst relative error over
    contact lengths from 5 % to 95 % of the face falls as ``1 / n^2`` (about 25 / n^2: 100 %
    for 5 springs with the shortest contact, 44 % for 7, 0.4 % for 61), the reason a coarse
    strip misjudges a rocking block's corner (docs: *Springs per strip*)."""
    worst = {}
    for n in (5, 7, 15, 31, 61):
        x, w = lobatto(n)
        errors = []
        for xi0 in np.linspace(-0.9, 0.9, 181):
            d = -xi0
            force, moment = (d + 1.0) ** 2 / 2.0, d * (1 - xi0**2) / 2 + (1 - xi0**3) / 3
            carried = np.maximum(d + x, 0.0)
            errors.append(max(abs(np.sum(w * carried) - force) / force,
                              abs(np.sum(w * carried * x) - moment) / abs(moment)))
        worst[n] = max(errors)
    for n, err in worst.items():
        assert 8.0 < err * n**2 < 30.0, (n, err)
    assert worst[61] < 0.005 < 0.3 < worst[7] < worst[5]


@pytest.mark.parametrize("make, key", [
    (lambda: Cap(thickness=-1.0), "Cap.thickness"),
    (lambda: Cap(modulus=0.0), "Cap.modulus"),
    (lambda: Cap(stiffness=0.0), "Cap.stiffness"),
    (lambda: Cap(mu_s=0.3, mu_k=0.4), "Cap.mu_k"),
    (lambda: Block(capacity=0.0), "Block.capacity"),
    (lambda: Block(top=Cap(thickness=0.7), bottom=Cap(thickness=0.6)), "caps thicker"),
    (lambda: BlockLine(n_blocks=0), "BlockLine.n_blocks"),
    (lambda: BlockLine(hull_slope=math.radians(60)), "cannot be cut"),
    (lambda: ship(g_height=-0.5), "G below the keel"),
    (lambda: ship(mass=float("nan")), "Ship.mass"),
    (lambda: Wind(height=5.0), "Wind takes"),
    (lambda: DockSection(ship(), BlockLine(), (side(6.5),)), "not under the hull"),
    (lambda: DockSection(ship(), BlockLine(), (side(0.9),)), "not clear of the keel"),
    (lambda: DockSection(ship(), BlockLine(), (side(3.0, hull_height=0.5),)), "gap of"),
    (lambda: DockSection(ship(), BlockLine(offset=1.0)), "DockSection.keel"),
    (lambda: DockSection(ship(), BlockLine(), n_springs=1), "DockSection.n_springs"),
    # issue 29's bad input, each named by its key
    (lambda: Cap(stiffness=-1e9), "Cap.stiffness"),
    (lambda: Cap(modulus=-1e9), "Cap.modulus"),
    (lambda: Cap(shear_ratio=0.0), "Cap.shear_ratio"),
    (lambda: Cap(proportional_limit=0.0), "Cap.proportional_limit"),
    (lambda: Cap(proportional_limit=-7e6), "Cap.proportional_limit"),
    (lambda: Block(capacity=-1e6), "Block.capacity"),
    (lambda: Block(mass=0.0), "Block.mass"),
    (lambda: Block(half_height=0.1), "caps thicker"),
    (lambda: ship(g_height=0.0), "G below the keel"),
    (lambda: ship(roll_inertia=0.0), "Ship.roll_inertia"),
    (lambda: ship(mass=-4e5), "Ship.mass"),
    (lambda: DockSection(ship(), BlockLine(), (side(-6.0),)), "not under the hull"),
    (lambda: BlockLine(hull_slope=-math.radians(46)), "cannot be cut"),
    # a 2 m wide block 1 m tall: tan(40 deg) * 1 m reaches through its 0.7 m core
    (lambda: BlockLine(block=Block(half_width=1.0, half_height=0.5), hull_slope=math.radians(40)),
     "BlockLine.hull_slope"),
])
def test_bad_values_are_refused_by_key(make, key):
    with pytest.raises(ParameterError, match=key):
        make()


def test_wrong_types_are_type_errors():
    with pytest.raises(ParameterTypeError, match="Cap.modulus"):
        Cap(modulus="1e9")
    with pytest.raises(ParameterTypeError, match="DockSection.sides"):
        DockSection(ship(), BlockLine(), sides=[1])
    with pytest.raises(ParameterTypeError, match="Block.top"):
        Block(top=1.0)
