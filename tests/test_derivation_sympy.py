"""Independent symbolic verification of the equations of motion (all 8 modes).

The reference is ``tests/sympy_model.py``: Lagrange's equations from T and V written from the
corner kinematics (normal gaps and stick/no-rocking constraints as Lagrange multipliers =
interface forces, Coulomb friction as generalised forces), cross-checked against
Newton-Euler free-body diagrams.  Against it we check

* the physics notes (``shared/reference/physics-notes.md``): mass matrix, closed forms per
  mode (sec. 2), limits (sec. 4), restitution (sec. 5), errata table (sec. 3);
* every printed equation of the paper (``ship-block-formulation.md``, eqs. 2-57 and the
  impact rule): as printed, and, where it is wrong, the corrected form;
* the numeric implementation ``shipblock.equations.mode_response``.

See ``docs/theory/derivation.md`` and ``docs/theory/errata.md``.
"""

from __future__ import annotations

import itertools
from fractions import Fraction

import numpy as np
import pytest
import sympy as sp

try:  # tests/ as a package or as a plain directory
    from . import sympy_model as sm
except ImportError:
    import sympy_model as sm

B, G, H, M, Ib, Mn, R = sm.B, sm.G, sm.H, sm.M, sm.Ib, sm.Mn, sm.R
Xp, Yp, Fx, Fy, a, ay = sm.Xp, sm.Yp, sm.Fx, sm.Fy, sm.a, sm.ay
cphi, sphi, fx, fy, g, m, n = sm.cphi, sm.sphi, sm.fx, sm.fy, sm.g, sm.m, sm.n
mu1, mu2, nI, nm, s, sig1, sig2 = sm.mu1, sm.mu2, sm.nI, sm.nm, sm.s, sm.sig1, sm.sig2
tau, th, thd, thdd, xbdd, xsdd = sm.tau, sm.th, sm.thd, sm.thdd, sm.xbdd, sm.xsdd

SIGNS = list(itertools.product((1.0, -1.0), repeat=3))  # (s, sigma1, sigma2)
RTOL = 1e-10  # round-off agreement; a sign error gives O(1) relative differences
N_POINTS = 12  # random parameter points per sign combination


# ------------------------------------------------------------------------------------------
# helpers
# ------------------------------------------------------------------------------------------
def _points(mode, uniform_inertia=False, seed=0, signs=SIGNS):
    rng = np.random.default_rng(seed + 101 * mode)
    rock = sm.MODES[mode][1]
    for sv, s1, s2 in signs:
        for _ in range(N_POINTS):
            yield sm.rand_params(rng, sv, s1, s2, uniform_inertia=uniform_inertia, rocking=rock)


def _rel(x, y, scale):
    return abs(x - y) / scale


_ALL = sm.PARAMS + sm.UNKNOWNS


def _exact_points(k=3, seed=7):
    """Exact rational points on {c^2+s^2=1, R^2=B^2+H^2} for every sign combination."""
    rng = np.random.default_rng(seed)
    triples = [(3, 4, 5), (5, 12, 13), (8, 15, 17), (7, 24, 25), (20, 21, 29)]
    for sv, s1, s2 in itertools.product((1, -1), repeat=3):
        for _ in range(k):
            u = Fraction(int(rng.integers(1, 9)), int(rng.integers(10, 19)))
            bt, ht, rt = triples[int(rng.integers(0, len(triples)))]
            if rng.random() < 0.5:
                bt, ht = ht, bt
            q = Fraction(int(rng.integers(1, 7)), 7)

            def r(lo=1, hi=9):
                return sp.Rational(int(rng.integers(lo, hi)), int(rng.integers(1, 5)))

            yield {
                sm.cph: sp.Rational((1 - u**2) / (1 + u**2)),
                sm.sph: sp.Rational(2 * u / (1 + u**2)),
                B: sp.Rational(bt * q), H: sp.Rational(ht * q), sm.Rs: sp.Rational(rt * q),
                s: sv, sig1: s1, sig2: s2,
                M: r(), m: r(), n: r(1, 6), Ib: r(), g: r(), a: r(-9, 9), ay: r(-5, 5),
                thd: r(-5, 5), mu1: r(1, 5) / 7, mu2: r(1, 5) / 7,
            }


def _exact_zero(expr, k=3):
    """Exact (rational-arithmetic) evaluation of ``expr`` (written in theta or phi) at random
    points of the constraint variety, for all 8 sign combinations: all must give exactly 0."""
    e = sm.to_phi(expr)
    for pt in _exact_points(k):
        val = sp.nsimplify(e.xreplace(pt)) if e.free_symbols - set(pt) else e.xreplace(pt)
        if sp.simplify(val) != 0:
            return False
    return True


# ------------------------------------------------------------------------------------------
# 1. the derivation itself: Lagrange == Newton-Euler
# ------------------------------------------------------------------------------------------
def test_lagrange_equations_are_jacobian_transpose_of_newton_euler():
    """E_Lagrange(q_i) = sum_j dr_j/dq_i . E_NewtonEuler(j), exactly (symbolic residual 0)."""
    L = sm.lagrange_equations()[0]
    NE = sm.newton_euler_equations()
    _, rb, _, rs = sm.kinematics()
    body = [rb[0], rb[1], sm.Q_COORDS[2], rs[0], rs[1]]
    for i, q in enumerate(sm.Q_COORDS):
        comb = sum(sm._to_symbols(sp.diff(body[j], q)) * NE[j] for j in range(5))
        assert sp.simplify(sp.expand(L[i] - comb).subs(s**2, 1)) == 0


@pytest.mark.parametrize("mode", range(1, 9))
def test_lagrange_and_newton_euler_solutions_agree(mode):
    """Both derivations give the same accelerations and interface forces in every mode."""
    for p in _points(mode):
        zl = sm.solve_numeric(mode, p, lagrange=True)
        zn = sm.solve_numeric(mode, p, lagrange=False)
        scale = 1 + max(abs(v) for v in zl.values())
        for u in sm.UNKNOWNS:
            assert _rel(zl[u], zn[u], scale) < RTOL


def test_kinetic_energy_matrix_and_potential():
    """T = 1/2 qdot^T K qdot with the notes' K(theta); V = (nm+2M) G R(cos phi - cos theta_c)
    plus the work potential of the horizontal inertial force (the notes' V, with g -> G, is only
    the vertical part)."""
    _, T, V = sm.lagrange_equations()
    vel = [sp.Symbol(nm_) for nm_ in ("vxb", "vth", "vxs")]
    rep = {sm.Q_COORDS[0].diff(sm.t): vel[0], sm.Q_COORDS[2].diff(sm.t): vel[1],
           sm.Q_COORDS[3].diff(sm.t): vel[2], sm.Q_COORDS[1].diff(sm.t): 0,
           sm.Q_COORDS[4].diff(sm.t): 0}
    Tq = sm._to_symbols(T.subs(rep))
    K = sp.hessian(Tq, vel)
    Rc = R * cphi
    K_notes = sp.Matrix([[nm + M, -(nm + 2 * M) * Rc, M],
                         [-(nm + 2 * M) * Rc, nI + (nm + 4 * M) * R**2, -2 * M * Rc],
                         [M, -2 * M * Rc, M]])
    for i, j in itertools.product(range(3), repeat=2):
        assert sm.is_identity(K[i, j] - K_notes[i, j])
    Vq = sm._to_symbols(V)
    xb0, xs0 = sp.Symbol("xb0"), sp.Symbol("xs0")
    V_expected = ((nm + 2 * M) * G * R * (cphi - H / R)
                  + a * ((nm + M) * xb0 + M * xs0 - (nm + 2 * M) * s * R * (B / R - sphi)))
    const = (nm + 2 * M) * G * H + a * M * s * B  # rest-position value (centroid at height H)
    assert sm.is_identity(Vq - V_expected - const)


# ------------------------------------------------------------------------------------------
# 2. the physics notes, sec. 2: closed forms per mode (general inertia)
# ------------------------------------------------------------------------------------------
def _notes_closed_forms():
    kap = Ib / (m * R**2)
    c, sn = cphi, sphi
    q1, q2 = sig1 * mu1, sig2 * mu2
    forms = {
        1: {xbdd: 0, thdd: 0, xsdd: 0},
        2: {xbdd: -a - q1 * G},
        3: {thdd: R * (nm + 2 * M) * (a * c - s * G * sn) / (nI + (nm + 4 * M) * R**2)},
        4: {xsdd: -a - q2 * G},
        5: {xbdd: -a - (q1 * (Mn + 1) - q2) * G / Mn, xsdd: (Mn + 1) * (q1 - q2) * G / Mn},
    }
    th6 = -(Mn + 2) * (s * sn + q1 * c) * ((Mn + 1) * G - (Mn + 2) * R * c * thd**2) / (
        R * (Mn * (kap * (Mn + 1) + 1) + (Mn + 2) ** 2 * (sn**2 + q1 * s * sn * c)))
    forms[6] = {thdd: th6, xbdd: -a - q1 * G + R * (Mn + 2) / (Mn + 1) * (
        (c - q1 * s * sn) * th6 + (s * sn + q1 * c) * thd**2)}
    th7 = (Mn * (a * c - s * G * sn) - 2 * (s * sn + q2 * c) * (G - 2 * R * c * thd**2)) / (
        R * (Mn * (1 + kap) + 4 * (sn**2 + q2 * s * sn * c)))
    forms[7] = {thdd: th7, xsdd: -a - q2 * G + 2 * R * (
        (c - q2 * s * sn) * th7 + (s * sn + q2 * c) * thd**2)}
    th8 = -((Mn + 2) * s * sn * G + (q1 * (Mn + 1) + q2) * c * G
            - R * c * thd**2 * ((Mn + 4) * s * sn + (q1 * (Mn + 2) + 2 * q2) * c)) / (
        R * (kap * Mn + (Mn + 4) * sn**2 + (q1 * (Mn + 2) + 2 * q2) * s * sn * c))
    X8 = Xp.subs(thdd, th8)
    Y8 = Yp.subs(thdd, th8)
    forms[8] = {thdd: th8,
                xbdd: -a - X8 - (q1 * ((Mn + 1) * G + (Mn + 2) * Y8) - q2 * (G + 2 * Y8)) / Mn,
                xsdd: -X8 + (q1 * ((Mn + 1) * G + (Mn + 2) * Y8) - q2 * (Mn + 1) * (G + 2 * Y8)) / Mn}
    # forces, the same in every mode (written with the mode's accelerations)
    forces = {Fy: M * (G + 2 * Yp), Fx: M * (a + xbdd + xsdd + 2 * Xp),
              fy: M * ((Mn + 1) * G + (Mn + 2) * Yp),
              fx: M * ((Mn + 1) * (a + xbdd) + (Mn + 2) * Xp + xsdd)}
    return forms, forces


@pytest.mark.parametrize("mode", range(1, 9))
def test_notes_closed_forms_numeric(mode):
    """Notes sec. 2 table and force formulas vs the derivation, general kappa, s, sigma = +-1."""
    forms, forces = _notes_closed_forms()
    fns = {u: sp.lambdify(_ALL, e, "numpy") for u, e in {**forms[mode], **forces}.items()}
    for p in _points(mode, seed=1):
        z = sm.solve_numeric(mode, p)
        zz = [z[u] for u in sm.UNKNOWNS]
        scale = 1 + max(abs(v) for v in zz)
        for u, f in fns.items():
            assert _rel(z[u], f(*p, *zz), scale) < RTOL, (mode, u)


@pytest.mark.parametrize("mode", [2, 3, 4, 5, 7])
def test_notes_closed_forms_exact(mode):
    """Same, but in exact rational arithmetic on the constraint variety (no round-off)."""
    forms, _ = _notes_closed_forms()
    sol = sm.mode_solution(mode)
    for u, e in forms[mode].items():
        assert _exact_zero(sol[u] - e, k=1), (mode, u)


def test_mode8_theta_dd_is_independent_of_ground_acceleration():
    sol = sm.mode_solution(8)
    assert a not in sol[thdd].free_symbols or sp.simplify(sp.diff(sol[thdd], a)) == 0
    assert a in sm.mode_solution(7)[thdd].free_symbols  # (but it does in mode 7)


# ------------------------------------------------------------------------------------------
# 3. limits (notes sec. 4)
# ------------------------------------------------------------------------------------------
def test_housner_limit():
    """Mode 3 with M -> 0, uniform block: Housner (1963) with theta_H = -theta and
    p^2 = 3 g'/(4R), g' = g + yg''.  Exact for s = +-1."""
    th3 = sm.subs_rational(sm.mode_solution(3)[thdd].subs(Ib, m * (B**2 + H**2) / 3), {M: 0})
    thH = -th
    alpha = sm.thc
    sgnH = -s
    p2 = 3 * G / (4 * R)
    housner = -p2 * (sp.sin(alpha * sgnH - thH) + a / G * sp.cos(alpha * sgnH - thH))
    # theta_H'' = -theta''
    for sv in (1, -1):
        e = (-th3 - housner).subs(s, sv)
        e = sp.expand_trig(e.subs(sp.atan(B / H), sp.Symbol("al")))
        e = e.subs({sp.sin(sp.Symbol("al")): B / R, sp.cos(sp.Symbol("al")): H / R})
        assert sp.simplify(e) == 0
    # and with g instead of g' the form is wrong as soon as yg'' != 0
    wrong = -3 * g / (4 * R) * (sp.sin(alpha * sgnH - thH) + a / G * sp.cos(alpha * sgnH - thH))
    f = sp.lambdify(sm.PARAMS, -th3 - wrong)
    assert abs(f(1, 1, 1, 1, 0.3, 1.0, 9.81, 1.0, 3.0, 0.1, 0, 1, 1, 1, 0.3, 0.3)) > 0.1


def test_ship_only_limit():
    """Mn -> 0 (massless blocks): theta'' = (a c - s G sn)/(2R), a point mass at 2R."""
    th3 = sm.subs_rational(sm.mode_solution(3)[thdd], {m: 0, Ib: 0})
    assert sm.is_identity(th3 - (a * cphi - s * G * sphi) / (2 * R))


def test_newmark_and_sliding_limits():
    """Mode 2 = Newmark sliding block, independent of M; mode 4 the same for the ship alone."""
    assert sp.simplify(sm.mode_solution(2)[xbdd] - (-a - sig1 * mu1 * G)) == 0
    assert sp.simplify(sm.mode_solution(4)[xsdd] - (-a - sig2 * mu2 * G)) == 0
    assert sp.simplify(sp.diff(sm.mode_solution(2)[xbdd], M)) == 0


def _abs_accelerations(mode, p):
    z = sm.solve_numeric(mode, p)
    Mv, mv, nv, Iv, Bv, Hv, gv, av, ayv, thv, thdv, sv = p[:12]
    Rv = np.hypot(Bv, Hv)
    ph = np.arctan(Bv / Hv) - sv * thv
    Xv = -Rv * (np.cos(ph) * z[thdd] + sv * np.sin(ph) * thdv**2)
    block = av + z[xbdd] + Xv
    ship = av + z[xbdd] + z[xsdd] + 2 * Xv
    return block, ship, nv * mv * block + Mv * ship


def test_frictionless_limits():
    """mu1 = 0 in mode 6: the SYSTEM mass centre is horizontally fixed -- the block centroid is
    NOT (notes sec. 4 say 'block centroid'); mu2 = 0 in mode 7: ship fixed; mode 8 with
    mu1 = mu2 = 0: block centroid and ship fixed and theta'' independent of a."""
    rng = np.random.default_rng(5)
    moved = 0.0
    for sv, s1, s2 in SIGNS:
        p = list(sm.rand_params(rng, sv, s1, s2))
        p6 = tuple(p[:14] + [0.0, p[15]])
        blk, shp, com = _abs_accelerations(6, p6)
        assert abs(com) < 1e-12 * (1 + abs(blk) + abs(shp))
        moved = max(moved, abs(blk))
        p7 = tuple(p[:15] + [0.0])
        _, shp, _ = _abs_accelerations(7, p7)
        assert abs(shp) < 1e-12 * (1 + abs(p[7]))
        p8 = tuple(p[:14] + [0.0, 0.0])
        blk, shp, _ = _abs_accelerations(8, p8)
        assert abs(blk) < 1e-12 * (1 + abs(p[7])) and abs(shp) < 1e-12 * (1 + abs(p[7]))
    assert moved > 1e-2  # the block centroid of mode 6 does accelerate


# ------------------------------------------------------------------------------------------
# 4. impacts (notes sec. 5, paper sec. 4)
# ------------------------------------------------------------------------------------------
def _impact_jacobians():
    """Velocity Jacobians d(v_block, omega, v_ship)/d(qdot) at theta = 0 for s = +1 and -1."""
    xb_, th_, xs_ = sp.symbols("xb_ th_ xs_")
    out = {}
    for sv in (1, -1):
        _, rb, _, rs = sm.kinematics(xb=xb_, yb=0, theta=th_, xs=xs_, ys=0)
        r = sp.Matrix([rb[0], rb[1], th_, rs[0], rs[1]]).subs(s, sv)
        out[sv] = r.jacobian([xb_, th_, xs_]).subs(th_, 0)
    mass = sp.diag(nm, nm, nI, M, M)
    return out, mass


def test_system_restitution_from_momentum_projection():
    """Plastic impact at theta = 0 (pivot s = +1 -> -1), both interfaces sticking: conserving
    the generalised momentum of the post-impact rocking coordinate gives the notes' e_sys."""
    J, Mb = _impact_jacobians()
    jm, jp = J[1][:, 1], J[-1][:, 1]
    e = sp.simplify((jp.T * Mb * jm)[0] / (jp.T * Mb * jp)[0])
    e_notes = (nI + (nm + 4 * M) * (H**2 - B**2)) / (nI + (nm + 4 * M) * (H**2 + B**2))
    assert sp.simplify(e - e_notes) == 0
    # same as angular momentum about the new pivot P2 = (B, -H) with the ship lumped at C2
    om_m = sp.Symbol("om")
    L_before = nI * om_m + nm * ((-B) * (om_m * B) - H * (-om_m * H)) \
        + M * ((-2 * B) * (om_m * 2 * B) - 2 * H * (-om_m * 2 * H))
    L_after_per_om = nI + nm * (B**2 + H**2) + 4 * M * (B**2 + H**2)
    assert sp.simplify(L_before / om_m / L_after_per_om - e_notes) == 0
    # uniform block: 1 - 3/2 sin^2(alpha) (Mn+4)/(Mn+3); Housner for M -> 0, cos(2 alpha) for m -> 0
    Mn_, al = sp.symbols("M_n alpha", positive=True)
    Rr = sp.Symbol("Rr", positive=True)
    e_uni = e_notes.subs(Ib, m * (B**2 + H**2) / 3).subs(
        {m: Mn_ * M / n, B: Rr * sp.sin(al), H: Rr * sp.cos(al)}, simultaneous=True)
    target = 1 - sp.Rational(3, 2) * sp.sin(al) ** 2 * (Mn_ + 4) / (Mn_ + 3)
    assert sp.simplify(sp.expand_trig(e_uni - target)) == 0
    assert sp.simplify(sp.limit(target, Mn_, sp.oo) - (1 - sp.Rational(3, 2) * sp.sin(al) ** 2)) == 0
    assert sp.simplify(sp.expand_trig(target.subs(Mn_, 0) - sp.cos(2 * al))) == 0
    # the notes' worked numbers (sec. 5)
    f = sp.lambdify((Mn_, al), target)
    assert round(1 - 1.5 * np.sin(0.2) ** 2, 3) == 0.941
    assert (round(f(0.02, 0.2), 3), round(f(0.5, 0.2), 3)) == (0.921, 0.924)
    assert round(1 - 1.5 * np.sin(0.675) ** 2, 3) == 0.414
    assert (round(f(0.02, 0.675), 3), round(f(0.5, 0.675), 3)) == (0.220, 0.247)


def test_paper_impact_rule_creates_energy():
    """Paper sec. 4: theta_dot+ = 2 e theta_dot-.  At theta = 0 the rocking kinetic energy is
    K_thth/2 theta_dot^2 on both sides, so the energy ratio is 4e^2 > 1 for e > 1/2; with
    e = e_sys (> 1/2 for slender blocks) the printed rule gains energy, theta_dot+ = e
    theta_dot- does not."""
    nI_, nm_ = sp.symbols("nI nm", positive=True)
    e_sys = sp.lambdify((nI_, nm_, M, B, H), (nI_ + (nm_ + 4 * M) * (H**2 - B**2)) / (
        nI_ + (nm_ + 4 * M) * (H**2 + B**2)))
    e = e_sys(0.5 * 0.26 / 3, 0.5, 1.0, 0.1, 0.5)
    assert 0.5 < e < 1
    assert (2 * e) ** 2 > 1 and e**2 < 1


def test_sliding_impact_projection_row():
    """Notes sec. 5: with arbitrary pre-impact velocities, the theta-row of the post-impact
    generalised momentum is K_th . qdot- - 2 (nm + 4M) B^2 theta_dot-, and the x_b / x_s rows
    (momenta of the slipping coordinates) are continuous."""
    J, Mb = _impact_jacobians()
    qd = sp.Matrix(sp.symbols("vb om vs"))
    v_minus = J[1] * qd  # true body velocities before the impact (pivot s = +1)
    p_post_coords = J[-1].T * Mb * v_minus  # momenta in the post-impact coordinates
    K0 = J[-1].T * Mb * J[-1]  # = K(theta = 0), the same for both pivots
    assert sp.simplify(K0 - J[1].T * Mb * J[1]) == sp.zeros(3, 3)
    Kq = K0 * qd
    assert sp.simplify(p_post_coords[1] - (Kq[1] - 2 * (nm + 4 * M) * B**2 * qd[1])) == 0
    assert sp.simplify(p_post_coords[0] - Kq[0]) == 0
    assert sp.simplify(p_post_coords[2] - Kq[2]) == 0


def _plastic_projection(free_b, free_s):
    """The plastic impact (generalised Housner) from the kinematics: the post-impact momenta
    p = J+^T M J- qdot- (impulses only at the new pivot and the new ship contact); the rows of
    the free coordinates (the rotation, and the slips of interfaces that slip: frictionless
    impulses) keep them, the held slips are zero. Returns (qdot-, qdot+)."""
    J, Mb = _impact_jacobians()
    qd = sp.Matrix(sp.symbols("vb om vs", real=True))
    p = J[-1].T * Mb * J[1] * qd
    K0 = J[-1].T * Mb * J[-1]
    free = [0] * free_b + [1] + [2] * free_s
    q_plus = sp.zeros(3, 1)
    sol = K0.extract(free, free).LUsolve(p.extract(free, [0]))
    for k, i in enumerate(free):
        q_plus[i] = sol[k]
    if not free_b:
        qd[0] = 0
    if not free_s:
        qd[2] = 0
    return qd, q_plus.subs({sp.Symbol("vb", real=True): qd[0], sp.Symbol("vs", real=True): qd[2]})


def _plastic_restitution(free_b, free_s):
    """e_F = 1 - 2 (nm + 4M) B^2 / J_eff,F, J_eff,F the rotation's inertia with the momenta of
    the slipping coordinates held (Schur complement of K(theta = 0))."""
    K0 = sp.Matrix([[nm + M, -(nm + 2 * M) * H, M],
                    [-(nm + 2 * M) * H, nI + (nm + 4 * M) * (B**2 + H**2), -2 * M * H],
                    [M, -2 * M * H, M]])
    S = [0] * free_b + [2] * free_s
    j_eff = K0[1, 1]
    if S:
        j_eff -= (K0.extract([1], S) * K0.extract(S, S).inv() * K0.extract(S, [1]))[0]
    return 1 - 2 * (nm + 4 * M) * B**2 / j_eff


@pytest.mark.parametrize("free_b,free_s", [(0, 0), (1, 0), (0, 1), (1, 1)],
                         ids=["stick", "ground-slips", "ship-slips", "both-slip"])
def test_plastic_impact_rule_is_generalised_housner(free_b, free_s):
    """impact_rule="plastic": the post-impact velocities from the momentum balance about the
    new pivot (the momenta of the post-impact coordinates, J+^T M J- qdot-), frictionless
    impulses at the interfaces that slip. The ratio theta_dot+/theta_dot- is
    e_F = 1 - 2 (nm + 4M) B^2 / J_eff,F: it depends on *which* interfaces slip, not on how
    fast (symbolic); with both sticking it is e_sys (notes sec. 5) and, for a single block
    without ship, Housner's 1 - 3/2 sin^2(alpha); a single block sliding on a frictionless
    ground gets (I - m B^2)/(I + m B^2). The implementation (shipblock.impact) gives the same
    velocities and never gains energy."""
    qd, q_plus = _plastic_projection(free_b, free_s)
    om = qd[1]
    e_f = _plastic_restitution(free_b, free_s)
    assert sp.simplify(q_plus[1] - e_f * om) == 0
    if not free_b:
        assert q_plus[0] == 0
    if not free_s:
        assert q_plus[2] == 0
    e_notes = (nI + (nm + 4 * M) * (H**2 - B**2)) / (nI + (nm + 4 * M) * (H**2 + B**2))
    al = sp.Symbol("alpha", positive=True)
    uniform = {Ib: m * (B**2 + H**2) / 3}
    single = sp.limit(e_f.subs(uniform), M, 0)
    if (free_b, free_s) == (0, 0):
        assert sp.simplify(e_f - e_notes) == 0
        housner = single.subs({B: sp.sin(al), H: sp.cos(al)})
        assert sp.simplify(sp.expand_trig(housner - (1 - sp.Rational(3, 2) * sp.sin(al) ** 2))) == 0
    if (free_b, free_s) == (1, 0):
        assert sp.simplify(sp.limit(e_f, M, 0) - (Ib - m * B**2) / (Ib + m * B**2)) == 0
        # B/H = 0.2: 0.793 on a frictionless ground, against Housner's 0.942
        assert float(single.subs({B: 0.2, H: 1.0})) == pytest.approx(0.92 / 1.16, rel=1e-12)
    # the implementation, at random points
    from shipblock import ShipBlockSystem
    from shipblock.impact import impact_velocities

    f_plus = sp.lambdify((M, m, n, Ib, B, H, *sp.symbols("vb om vs", real=True)),
                         list(q_plus), "numpy")
    rng = np.random.default_rng(5)
    for _ in range(20):
        Mv, mv, nv = rng.uniform(10, 5e3), rng.uniform(10, 2e3), int(rng.integers(1, 9))
        Bv, Hv = rng.uniform(0.1, 0.5), rng.uniform(0.5, 1.5)
        Iv = mv * (Bv**2 + Hv**2) * rng.uniform(0.2, 0.45)
        system = ShipBlockSystem(ship_mass=Mv, block_mass=mv, n_blocks=nv, half_width=Bv,
                                 half_height=Hv, mu_s_ground=0.5, mu_k_ground=0.4,
                                 mu_s_ship=0.5, mu_k_ship=0.4, block_inertia=Iv,
                                 impact_rule="plastic")
        vb = rng.uniform(-1, 1) if free_b else 0.0
        vs = rng.uniform(-1, 1) if free_s else 0.0
        w = rng.choice([-1.0, 1.0]) * rng.uniform(0.1, 2.0)
        vb2, w2, vs2, loss = impact_velocities(system, w, vb, vs)
        want = f_plus(Mv, mv, nv, Iv, Bv, Hv, vb, w, vs)
        e_num = float(e_f.subs({M: Mv, m: mv, n: nv, Ib: Iv, B: Bv, H: Hv}))
        if e_num <= 0:  # no rotation onto the new pivot: the rocking stops (theta_dot = 0)
            assert w2 == 0.0
            continue
        np.testing.assert_allclose([vb2, w2, vs2], want, rtol=1e-11, atol=1e-13)
        assert loss >= 0.0
        # the momentum rule at the same impact: e_sys theta_dot, the slip momenta kept
        _, w_mom, _, _ = impact_velocities(system.replace(impact_rule="momentum"), w, vb, vs)
        assert w2 / w_mom == pytest.approx(e_num / system.effective_restitution, rel=1e-11)


# ------------------------------------------------------------------------------------------
# 5. the paper's printed equations, one by one
# ------------------------------------------------------------------------------------------
PAPER = sm.paper_equations()
PRINTED_WRONG = {"7", "16", "21", "22", "36", "41", "42", "46b", "47", "48", "49", "50", "53",
                 "55", "56", "57", "21/23 in mode 6 (text: 'f_y, F_y as eqs. 2, 4')"}


@pytest.mark.parametrize("entry", PAPER, ids=[e[0].split(" ")[0] + f"-m{e[1]}" for e in PAPER])
def test_paper_equation(entry):
    """Printed form holds to round-off (status OK), or differs by O(1) and the corrected form
    holds (typo / sign / wrong).  Uniform blocks (kappa = 1/3), s, sigma1, sigma2 = +-1."""
    eq, mode, lhs, printed, corrected = entry
    assert (corrected is not None) == (eq in PRINTED_WRONG)
    f_pr = sp.lambdify(_ALL, lhs - printed, "numpy")
    f_co = sp.lambdify(_ALL, lhs - corrected, "numpy") if corrected is not None else None
    worst_pr = worst_co = 0.0
    for p in _points(mode, uniform_inertia=True, seed=3):
        z = sm.solve_numeric(mode, p)
        zz = [z[u] for u in sm.UNKNOWNS]
        scale = 1 + max(abs(v) for v in zz[3:7]) / (p[0] * 9.8) + max(abs(v) for v in zz[:3])
        worst_pr = max(worst_pr, abs(f_pr(*p, *zz)) / scale)
        if f_co is not None:
            worst_co = max(worst_co, abs(f_co(*p, *zz)) / scale)
    if corrected is None:
        assert worst_pr < 1e-11
    else:
        assert worst_pr > 1e-2
        assert worst_co < 1e-11


def test_paper_kinematics():
    """Eqs. 17-20 (38-39, 45-46, 51-52 add x_b, x_s): centroid and ship displacements."""
    _, rb, C, rs = sm.kinematics(xb=0, yb=0, theta=th, xs=0, ys=0)
    sin_c, cos_c = B / R, H / R  # sin(theta_c), cos(theta_c)
    d = sin_c - sphi
    assert sm.is_identity(rb[0] - 0 - (-s * R * d))  # rest centroid at (0, H)
    assert sm.is_identity(rb[1] - H - R * (cphi - cos_c))
    assert sm.is_identity(rs[0] - s * B - (-2 * s * R * d))  # rest corner at (sB, 2H)
    assert sm.is_identity(rs[1] - 2 * H - 2 * R * (cphi - cos_c))
    # a sign slip in eq. 17 would be caught
    assert not sm.is_identity(rb[0] - (s * R * d))


def test_paper_eq43_exact_and_eq25_needs_uniform_block():
    """Eq. 43 exact as printed (kappa = 1/3); eq. 25 exact only for I = m(B^2+H^2)/3."""
    entry = {e[0]: e for e in PAPER}
    _, _, lhs, pr, _ = entry["43"]
    sol = sm.mode_solution(6)
    uni = {Ib: m * (B**2 + H**2) / 3}
    assert _exact_zero((sol[thdd] - pr).subs(uni), k=1)
    _, _, lhs, pr, _ = entry["25"]
    sol3 = sm.mode_solution(3)[thdd]
    assert sm.is_identity((sol3 - pr).subs(uni))
    assert not sm.is_identity(sol3 - pr)


# ------------------------------------------------------------------------------------------
# 6. something neither the paper nor the notes mention: Painleve-type sign change
# ------------------------------------------------------------------------------------------
def test_painleve_regime_exists_for_heavy_ship():
    """With s*sigma1 = -1 (pivot side opposite to the slip, which is how rocking starts from
    mode 2) and mu_k1 > B/H, the mode-6 'effective inertia' becomes negative for a heavy ship:
    the mode-6 equations then give s*theta'' < 0 at theta = 0, so neither mode 2 (rocking margin
    violated) nor mode 6 (wrong-way rotation) is consistent."""
    Bv, Hv, mv, nv, Mv, mu = 0.2, 1.0, 0.01, 2.0, 1.0, 0.6  # alpha = 0.197, Mn = 0.02
    p = (Mv, mv, nv, mv * (Bv**2 + Hv**2) / 3, Bv, Hv, 9.80665, 0.0, 0.0, 0.0, 0.0,
         1.0, -1.0, 1.0, mu, 0.3)
    fA, _ = sm.mode_matrix_function(6)
    z = sm.solve_numeric(6, p)
    assert z[thdd] * p[11] < 0
    # the rocking margin of sliding mode 2 is violated at the same state
    z2 = sm.solve_numeric(2, p)
    assert Hv * abs(z2[fx] + z2[Fx]) > Bv * (z2[fy] + z2[Fy])
    # the same state with a light ship is regular
    pl = (0.01,) + p[1:]
    assert sm.solve_numeric(6, pl)[thdd] * p[11] > 0


# ------------------------------------------------------------------------------------------
# 7. the numeric implementation
# ------------------------------------------------------------------------------------------
@pytest.mark.parametrize("mode", range(1, 9))
def test_implementation_matches_derivation(mode):
    """shipblock.equations.mode_response vs the independent derivation, ~1e-10 relative."""
    eqmod = pytest.importorskip("shipblock.equations")
    from shipblock import ShipBlockSystem

    for p in _points(mode, seed=11):
        Mv, mv, nv, Iv, Bv, Hv, gv, av, ayv, thv, thdv, sv, s1, s2, m1, m2 = p
        system = ShipBlockSystem(ship_mass=Mv, block_mass=mv, n_blocks=int(nv), half_width=Bv,
                                 half_height=Hv, mu_s_ground=m1 + 0.1, mu_k_ground=m1,
                                 mu_s_ship=m2 + 0.1, mu_k_ship=m2, block_inertia=Iv)
        acc, forces = eqmod.mode_response(system, mode, thv, thdv, av, ayv, s=sv,
                                          sigma_ground=s1, sigma_ship=s2)
        z = sm.solve_numeric(mode, (Mv, mv, nv, Iv, Bv, Hv, 9.80665) + p[7:])
        ref_acc = np.array([z[xbdd], z[thdd], z[xsdd]])
        ref_f = np.array([z[fx], z[fy], z[Fx], z[Fy]])
        assert np.abs(acc - ref_acc).max() <= RTOL * (1 + np.abs(ref_acc).max())
        assert np.abs(forces - ref_f).max() <= RTOL * np.abs(ref_f).max()


def test_implementation_restitution():
    eqsys = pytest.importorskip("shipblock.system")
    nI_, nm_ = sp.symbols("nI nm", positive=True)
    e_notes = (nI_ + (nm_ + 4 * M) * (H**2 - B**2)) / (nI_ + (nm_ + 4 * M) * (H**2 + B**2))
    f = sp.lambdify((nI_, nm_, M, B, H), e_notes)
    rng = np.random.default_rng(3)
    for _ in range(20):
        Mv, mv, nv = rng.uniform(0.5, 5), rng.uniform(0.05, 2), int(rng.integers(1, 10))
        Bv, Hv = rng.uniform(0.05, 0.4), rng.uniform(0.5, 1.5)
        kap = rng.uniform(0.2, 0.5)
        Iv = kap * mv * (Bv**2 + Hv**2)
        ref = f(nv * Iv, nv * mv, Mv, Bv, Hv)
        got = eqsys.system_restitution(nv * mv / Mv, np.arctan(Bv / Hv), kap)
        assert abs(got - max(ref, 0.0)) < 1e-12
