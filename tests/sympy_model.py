"""Independent symbolic derivation of the ship-on-keel-blocks equations of motion.

Used only by ``tests/test_derivation_sympy.py`` (and to produce the closed forms quoted in
``docs/theory/derivation.md``).  Nothing here is imported from ``shipblock``: the model is
re-derived from the kinematics, twice:

* **Lagrange**: kinetic energy ``T`` and potential ``V`` (gravity plus the ground-acceleration
  inertial forces) written from the corner positions, with the two normal-contact gaps
  ``y_b`` (pivot corner above the ground) and ``y_s`` (ship above the block corner) kept as
  extra coordinates.  Their multipliers are the normal forces ``fy`` and ``Fy``.  Stick and
  no-rocking constraints add the multipliers ``fx``, ``Fx`` and the base couple ``tau``;
  slipping interfaces replace a constraint by the Coulomb law ``fx = -sigma1*mu1*fy``.
* **Newton-Euler**: free-body diagrams of the block stack and of the ship.

Sign conventions (paper / physics notes): X right, Y up, theta counter-clockwise.  For pivot
sign ``s = +1`` the block pivots on its bottom-left corner and the ship rides on its top-right
corner; ``s = -1`` is the mirror image.  ``(fx, fy)`` is the force of the ground on the blocks,
``(Fx, Fy)`` the force of the blocks on the ship.  ``G = g + yg''``.
"""

from __future__ import annotations

import functools

import numpy as np
import sympy as sp

# --------------------------------------------------------------------------------------
# Symbols
# --------------------------------------------------------------------------------------
t = sp.Symbol("t", real=True)
M, m, n, Ib, B, H, g = sp.symbols("M m n I B H g", positive=True)
a, ay = sp.symbols("a a_y", real=True)  # ground accelerations xg'', yg''
s, sig1, sig2 = sp.symbols("s sigma1 sigma2", real=True)  # +-1 signs
mu1, mu2 = sp.symbols("mu1 mu2", nonnegative=True)  # kinetic friction ground / ship
th, thd = sp.symbols("theta thetadot", real=True)
xbdd, thdd, xsdd = sp.symbols("xbdd thetadd xsdd", real=True)
fx, fy, Fx, Fy, tau = sp.symbols("f_x f_y F_x F_y tau", real=True)

G = g + ay
nm = n * m
nI = n * Ib

# time functions for the derivation
_xb, _yb, _th, _xs, _ys = (sp.Function(nm_)(t) for nm_ in ("x_b", "y_b", "th", "x_s", "y_s"))
Q_COORDS = (_xb, _yb, _th, _xs, _ys)

#: order of the numeric parameter vector used by every lambdified function
PARAMS = (M, m, n, Ib, B, H, g, a, ay, th, thd, s, sig1, sig2, mu1, mu2)
ACC = (xbdd, thdd, xsdd)
FORCES = (fx, fy, Fx, Fy)
UNKNOWNS = (xbdd, thdd, xsdd, fx, fy, Fx, Fy, tau)

#: paper numbering: mode -> (ground slips, blocks rock, ship slips)
MODES = {
    1: (False, False, False),
    2: (True, False, False),
    3: (False, True, False),
    4: (False, False, True),
    5: (True, False, True),
    6: (True, True, False),
    7: (False, True, True),
    8: (True, True, True),
}


def _rot(angle, v):
    c, sn = sp.cos(angle), sp.sin(angle)
    return sp.Matrix([c * v[0] - sn * v[1], sn * v[0] + c * v[1]])


# --------------------------------------------------------------------------------------
# Kinematics (ground frame; origin below the block centroid at rest)
# --------------------------------------------------------------------------------------
def kinematics(xb=_xb, yb=_yb, theta=_th, xs=_xs, ys=_ys):
    """Positions of pivot P, block centroid, top contact corner C and ship reference point."""
    P = sp.Matrix([xb - s * B, yb])  # bottom pivot corner (slides by x_b, lifts by y_b)
    rb = P + _rot(theta, (s * B, H))  # centroid = pivot + rotated (sB, H)
    C = P + _rot(theta, (2 * s * B, 2 * H))  # diagonal corner carrying the ship
    rs = C + sp.Matrix([xs, ys])  # ship: translates with the corner plus its own slip/lift
    return P, rb, C, rs


def _to_symbols(expr):
    """Replace time functions by the state/acceleration symbols at y_b = y_s = 0."""
    d = sp.Derivative
    rep = {
        d(_xb, (t, 2)): xbdd, d(_th, (t, 2)): thdd, d(_xs, (t, 2)): xsdd,
        d(_yb, (t, 2)): 0, d(_ys, (t, 2)): 0,
    }
    expr = expr.subs(rep)
    expr = expr.subs({d(_th, t): thd, d(_yb, t): 0, d(_ys, t): 0})
    # x_b, x_s velocities never appear (translation invariance), positions likewise
    expr = expr.subs({d(_xb, t): sp.Symbol("xbd"), d(_xs, t): sp.Symbol("xsd")})
    expr = expr.subs({_th: th, _yb: 0, _ys: 0, _xb: sp.Symbol("xb0"), _xs: sp.Symbol("xs0")})
    return sp.expand(expr)


@functools.cache
def lagrange_equations():
    """Euler-Lagrange residuals for q = (x_b, y_b, theta, x_s, y_s) (each must vanish).

    Generalised forces: fx on x_b, fy on y_b, tau on theta (base couple, zero while rocking),
    Fx on x_s and Fy on y_s (the ship-block contact forces do work only through the relative
    coordinates x_s, y_s).
    """
    P, rb, C, rs = kinematics()
    vb, vs = rb.diff(t), rs.diff(t)
    T = sp.Rational(1, 2) * (nm * vb.dot(vb) + nI * _th.diff(t) ** 2 + M * vs.dot(vs))
    V = nm * (a * rb[0] + G * rb[1]) + M * (a * rs[0] + G * rs[1])
    L = T - V
    Q = (fx, fy, tau, Fx, Fy)
    res = []
    for q, Qq in zip(Q_COORDS, Q, strict=True):
        e = sp.diff(sp.diff(L, q.diff(t)), t) - sp.diff(L, q) - Qq
        res.append(_to_symbols(e))
    # T and V at y_b = y_s = 0 for reporting
    return tuple(res), T, V


@functools.cache
def newton_euler_equations():
    """Free-body diagrams: block x, block y, block moment about its centroid, ship x, ship y."""
    P, rb, C, rs = kinematics()
    ab = rb.diff(t, 2)
    as_ = rs.diff(t, 2)
    f = sp.Matrix([fx, fy])
    F = sp.Matrix([Fx, Fy])
    inert = sp.Matrix([a, G])  # ground acceleration plus gravity, per unit mass

    def cross(r, v):
        return r[0] * v[1] - r[1] * v[0]

    blk = nm * (ab + inert) - (f - F)  # ground force f at P, ship reaction -F at C
    mom = nI * _th.diff(t, 2) - (cross(P - rb, f) + cross(C - rb, -F) + tau)
    shp = M * (as_ + inert) - F
    eqs = [blk[0], blk[1], mom, shp[0], shp[1]]
    return tuple(_to_symbols(e) for e in eqs)


def mode_equations(mode, lagrange=True):
    """Linear equations (residuals) for the 8 unknowns of a mode."""
    slip_g, rock, slip_s = MODES[mode]
    eqs = list(lagrange_equations()[0] if lagrange else newton_euler_equations())
    eqs.append(fx + sig1 * mu1 * fy if slip_g else xbdd)
    eqs.append(tau if rock else thdd)
    eqs.append(Fx + sig2 * mu2 * Fy if slip_s else xsdd)
    if not rock:
        eqs = [e.subs({th: 0, thd: 0}) for e in eqs]
    return eqs


@functools.cache
def mode_solution(mode, lagrange=True):
    """Solve a mode symbolically; dict unknown -> expression."""
    eqs = mode_equations(mode, lagrange)
    A, b = sp.linear_eq_to_matrix(eqs, UNKNOWNS)
    sol = sp.solve_linear_system_LU(A.row_join(b), UNKNOWNS)
    return sol


@functools.cache
def mode_matrix_function(mode, lagrange=True):
    """Lambdified (A, b) of the mode's linear system; numeric solve is fast and exact."""
    eqs = mode_equations(mode, lagrange)
    A, b = sp.linear_eq_to_matrix(eqs, UNKNOWNS)
    return sp.lambdify(PARAMS, A, "numpy"), sp.lambdify(PARAMS, b, "numpy")


def solve_numeric(mode, p, lagrange=True):
    """Numeric solution (dict symbol -> float) at parameter tuple ``p`` (order PARAMS)."""
    fA, fb = mode_matrix_function(mode, lagrange)
    A = np.array(fA(*p), dtype=float)
    b = np.array(fb(*p), dtype=float).ravel()
    z = np.linalg.solve(A, b)
    return dict(zip(UNKNOWNS, z, strict=True))


# --------------------------------------------------------------------------------------
# Helper quantities in the paper's notation
# --------------------------------------------------------------------------------------
R = sp.sqrt(B**2 + H**2)
thc = sp.atan(B / H)
phi = thc - s * th  # = theta_c - |theta| for s = sign(theta)
cphi, sphi = sp.cos(phi), sp.sin(phi)
Mn = nm / M
#: rocking parts of the block-centroid acceleration (notes sec. 1)
Xp = -R * (cphi * thdd + s * sphi * thd**2)
Yp = R * (s * sphi * thdd - cphi * thd**2)


def rand_params(rng, s_val=1.0, sig1_val=1.0, sig2_val=1.0, uniform_inertia=False, rocking=True):
    """A random, physically sensible parameter tuple (order PARAMS)."""
    Mv = rng.uniform(0.5, 5.0)
    mv = rng.uniform(0.05, 2.0)
    nv = float(rng.integers(1, 12))
    Bv = rng.uniform(0.1, 1.0)
    Hv = rng.uniform(0.1, 1.5)
    Iv = mv * (Bv**2 + Hv**2) / 3.0 if uniform_inertia else mv * (Bv**2 + Hv**2) * rng.uniform(
        0.1, 0.6)
    gv = 9.80665
    av = rng.uniform(-8.0, 8.0)
    ayv = rng.uniform(-4.0, 4.0)
    thcv = np.arctan(Bv / Hv)
    thv = s_val * rng.uniform(0.0, 0.95 * thcv) if rocking else 0.0
    thdv = rng.uniform(-2.0, 2.0) if rocking else 0.0
    return (Mv, mv, nv, Iv, Bv, Hv, gv, av, ayv, thv, thdv, s_val, sig1_val, sig2_val,
            rng.uniform(0.05, 0.9), rng.uniform(0.05, 0.9))


# --------------------------------------------------------------------------------------
# Symbolic identity checks in the paper's variables phi = theta_c - |theta|
# --------------------------------------------------------------------------------------
cph, sph, Rs = sp.symbols("c_phi s_phi R", positive=True)
#: pure +-1 and Pythagorean relations used to reduce polynomials to a canonical remainder
_RELATIONS = [cph**2 + sph**2 - 1, Rs**2 - B**2 - H**2, s**2 - 1, sig1**2 - 1, sig2**2 - 1]
_REL_GENS = (sph, cph, H, B, Rs, s, sig1, sig2)
#: theta -> phi substitution: theta = s(theta_c - phi)
TH_TO_PHI = {sp.cos(th): (H * cph + B * sph) / Rs, sp.sin(th): s * (B * cph - H * sph) / Rs}
#: phi-form helpers to write the paper's equations
PHI_SUBS = {sp.cos(phi): cph, sp.sin(phi): sph, R: Rs}


def to_phi(expr):
    """Write an expression of theta (and R, cos/sin(phi)) in c_phi, s_phi, R."""
    al = sp.Symbol("alpha_c")
    expr = sp.sympify(expr).subs(sp.atan(B / H), al)
    if expr.has(al):  # trig of (alpha_c -+ s theta): expand, sin(s th) = s sin(th) for s = +-1
        expr = sp.expand_trig(expr)
        expr = expr.subs({sp.sin(s * th): s * sp.sin(th), sp.cos(s * th): sp.cos(th)})
        expr = expr.subs({sp.sin(al): B / Rs, sp.cos(al): H / Rs})
    expr = expr.subs(sp.sqrt(B**2 + H**2), Rs).subs(TH_TO_PHI)
    assert not expr.has(th), "theta left after the phi substitution"
    return expr


def is_identity(expr):
    """True if ``expr`` vanishes identically for s, sigma = +-1 (exact, no floating point).

    The numerator is reduced modulo c^2 + s^2 = 1, R^2 = B^2 + H^2 and s^2 = sigma^2 = 1
    (these polynomials form a Groebner basis, so the remainder is canonical).
    """
    num = sp.numer(sp.together(to_phi(expr)))
    num = sp.expand(num)
    if num == 0:
        return True
    gens = tuple(sorted(num.free_symbols - set(_REL_GENS), key=str)) + _REL_GENS
    _, r = sp.reduced(num, _RELATIONS, *gens, order="lex")
    return sp.expand(r) == 0


# --------------------------------------------------------------------------------------
# The paper's printed equations, transcribed (S(theta) = s, S(xb') = sigma1, S(xs') = sigma2,
# cos(theta_c - |theta|) = c, sin(...) = sn, yg'' + g = G, xg'' = a).  ``None`` = no fix.
# --------------------------------------------------------------------------------------
c_, sn_ = cphi, sphi
cos2, sin2 = 2 * c_**2 - 1, 2 * sn_ * c_
sinthc, costhc = B / R, H / R
Sx = sp.Symbol("S_xg", real=True)  # S(xg') printed in A2 of eq. 42 (read as sigma1 below)
xi = sp.Symbol("xi", real=True)
Gs = G
p1, p2 = sig1 * mu1, sig2 * mu2
Ypaper = R * (s * thdd * sn_ - thd**2 * c_)  # bracket R[S th'' sin - th'^2 cos]
Xpaper = R * (thdd * c_ + s * thd**2 * sn_)  # bracket R[th'' cos + S th'^2 sin]


def _mode6_A():
    return dict(
        A1=-a * c_ + s * Gs * sn_,
        A2=c_ - Sx * s * mu1 * sn_,
        A3=sig1 * 1 * mu1 * a,  # S(yg''+g) = 1
        A4=s * sn_ + sig1 * mu1 * c_,
        A5=(c_ - sig1 * s * mu1 * sn_) * c_,
        A6=Gs - 2 * R * c_ * thd**2,
        A7=Mn * (Gs - R * c_ * thd**2),
        A8=cos2 - sig1 * s * mu1 * sin2,
        M1=(Mn + 1) / (Mn + 2),
        M2=(Mn + 2) / (Mn + 3),
    )


def _mode7_A(corrected=False):
    A = dict(
        A1=2 * R * (s * sn_ + sig2 * mu2 * c_) * thd**2,
        A2=c_ - sig2 * s * mu2 * sn_,
        A3=Mn * (a * c_ - s * Gs * sn_),
        A4=-s * Gs * sn_,
        A5=(s * R * sin2 + 2 * R * mu2 * sig2 * c_**2) * thd**2,
        A6=cos2 - sig2 * s * mu2 * sin2 - 1,
    )
    if corrected:
        A["A4"] = -(s * sn_ + sig2 * mu2 * c_) * Gs
    return A


def _mode8_A(corrected=False):
    A = dict(
        A1=-2 * R * thd**2 * (3 * s * sn_ + (p1 + 2 * p2) * c_),
        # printed "3S(theta)[cos - 3(theta)(S(xb)mu_k2 S(xs)mu_k2 sin)] sin": read 3(theta)=3S(theta)
        A2=3 * s * (c_ - 3 * s * (sig1 * mu2 * sig2 * mu2 * sn_)) * sn_,
        A3=sig1 * mu1 * (-2 + 3 * c_**2 - 9 * s * sig2 * mu2 * c_ * sn_),
        A4=-2 * R * thd**2 * (2 * s * sn_ + (p1 + p2) * c_),
        A5=3 * s * sn_ * (c_ - 2 * sig2 * s * mu2 * sn_)
        + sig1 * mu1 * (-1 + 3 * c_**2 - 6 * sig2 * s * mu2 * c_ * sn_),
        A6=12 * (-sig2 * mu2 * sn_**2 * Gs - s * sig1 * sig2 * mu1 * mu2 * c_ * Gs),
        A7=Mn * (4 + 3 * c_**2 - 3 * s * sig1 * mu1 * c_ * sn_),
        A8=6 * (-2 + 2 * c_**2 - s * c_ * sn_) * (p1 + p2),
        A9=a * c_ - s * Gs * sn_
        - 2 * c_ / (Mn + 2) * (a - 2 * R * thd**2 * (s * sn_ + p2 * c_)),
        A10=4 * (3 * sn_**2 + Mn + 3 * s * p2 * c_ * sn_),
        A11=-Mn * (Gs - R * thd**2 * c_ * (s * sn_ + p1 * c_)),
        A12=(2 * s * sn_ + p1 * c_) * Gs,
    )
    if corrected:
        A["A7"] = Mn * (-4 + 3 * c_**2 - 3 * s * sig1 * mu1 * c_ * sn_)
        A["A8"] = 6 * (-2 + 2 * c_**2 - s * c_ * sn_ * (p1 + p2))
        A["A11"] = Mn * (Gs - R * thd**2 * c_) * (s * sn_ + p1 * c_)
        A["A12"] = (2 * s * sn_ + (p1 + p2) * c_) * Gs
    return A


def paper_equations():
    """List of (eq, mode, lhs, printed_rhs, corrected_rhs) with lhs/rhs sympy expressions.

    ``lhs`` is written with the unknown symbols (accelerations, forces); a check evaluates
    ``lhs - rhs`` at the derived solution of ``mode``.  ``corrected_rhs`` is None when the
    printed form is correct.
    """
    A6_, A7_, A8_ = _mode7_A(), _mode7_A(True), _mode8_A()
    A8c = _mode8_A(True)
    A6m = _mode6_A()
    eqs = []
    add = eqs.append
    MG = M * Gs
    # ---- mode 1
    add(("2", 1, Fy, M * Gs, None))
    add(("3", 1, Fx, M * a, None))
    add(("4", 1, fy, M * (Mn + 1) * Gs, None))
    add(("5", 1, fx, M * (Mn + 1) * a, None))
    # eq 6 solved for xi, against eq 7 (forces act at +-xi: ground at xi, ship reaction at -xi)
    xi_derived = tau / (fy + Fy) - s * B  # position of the ground resultant from tau
    add(("6", 1, (fx / n + Fx / n) * H + (fy / n + Fy / n) * xi_derived, 0, None))
    add(("7", 1, xi_derived, (fx + Fx) / (fy + Fy) * H, -(fx + Fx) / (fy + Fy) * H))
    add(("9", 1, sp.Abs(fx) / fy, sp.Abs(a) / Gs, None))
    add(("10", 1, H * sp.Abs(fx + Fx) / (B * (fy + Fy)), sp.Abs(a / Gs) / (B / H), None))
    add(("11", 1, sp.Abs(Fx) / Fy, sp.Abs(a) / Gs, None))
    # ---- mode 2
    add(("12", 2, Fx, M * (a + xbdd), None))
    add(("13", 2, fx, -sig1 * mu1 * M * (Mn + 1) * Gs, None))
    add(("14", 2, xbdd, -sig1 * mu1 * Gs - a, None))
    add(("15", 2, sp.Abs(Fx) / Fy, sp.Abs(-sig1 * mu1 * Gs) / Gs, None))
    add(("16", 2, sp.Abs(fx + Fx) / (fy + Fy),
         sp.Abs(-sig1 * mu1 * M * (Mn + 1) * Gs - sig1 * mu1 * Gs) / ((Mn + 2) * Gs),
         sp.Abs(-sig1 * mu1 * M * (Mn + 1) * Gs - sig1 * mu1 * M * Gs) / (M * (Mn + 2) * Gs)))
    # ---- mode 3 (forces, eq 25, conditions 26, 27)
    add(("21", 3, Fy, M * Gs + 2 * Ypaper, M * (Gs + 2 * Ypaper)))
    add(("22", 3, Fx, M * (a + 2 * Xpaper), M * (a - 2 * Xpaper)))
    add(("23", 3, fy, M * ((Mn + 1) * Gs + (Mn + 2) * Ypaper), None))
    add(("24", 3, fx, M * ((Mn + 1) * a - (Mn + 2) * Xpaper), None))
    add(("25", 3, thdd,
         sp.Rational(3, 4) / R * (Mn + 2) / (Mn + 3) * (a * c_ - s * Gs * sn_), None))
    k1 = (Mn + 1) / (Mn + 2)
    add(("26", 3, sp.Abs(fx / fy), sp.Abs((k1 * a - Xpaper) / (k1 * Gs + Ypaper)), None))
    add(("27", 3, sp.Abs(Fx / Fy), sp.Abs((a - 2 * Xpaper) / (Gs + 2 * Ypaper)), None))
    # ---- mode 4
    add(("28", 4, Fx, -sig2 * mu2 * M * Gs, None))
    add(("29", 4, fx, M * (Mn * a - sig2 * mu2 * Gs), None))
    add(("30", 4, xsdd, -sig2 * mu2 * Gs - a, None))
    add(("31", 4, sp.Abs(fx) / fy,
         sp.Abs(Mn / (Mn + 1) * a / Gs - sig2 * mu2 / (Mn + 1)), None))
    add(("32", 4, sp.Abs(fx + Fx) / (fy + Fy),
         sp.Abs(Mn / (Mn + 2) * a / Gs - sig2 * mu2 * 2 / (Mn + 2)), None))
    # ---- mode 5
    add(("33", 5, Fx, -sig2 * mu2 * MG, None))
    add(("34", 5, fx, -sig1 * mu1 * M * (Mn + 1) * Gs, None))
    add(("35", 5, xbdd, Gs / Mn * (-sig1 * mu1 * (Mn + 1) + sig2 * mu2) - a, None))
    add(("36", 5, xsdd, (Mn + 1) / Mn * Gs * (p1 + p2), (Mn + 1) / Mn * Gs * (p1 - p2)))
    add(("37", 5, sp.Abs(fx + Fx) / (fy + Fy),
         sp.Abs(p1 * (Mn + 1) / (Mn + 2) + p2 / (Mn + 2)), None))
    # ---- mode 6
    add(("40", 6, Fx, M * (a + xbdd - 2 * Xpaper), None))
    add(("41", 6, fx,
         -sig2 * mu1 * M * ((Mn + 1) * Gs + (Mn + 2) * R * (s * thd * sn_ - thd**2 * c_)),
         -sig1 * mu1 * M * ((Mn + 1) * Gs + (Mn + 2) * Ypaper)))
    add(("21/23 in mode 6 (text: 'f_y, F_y as eqs. 2, 4')", 6, Fy + fy,
         M * Gs + M * (Mn + 1) * Gs, M * (Gs + 2 * Ypaper) + M * ((Mn + 1) * Gs + (Mn + 2) * Ypaper)))
    A = {k: v.subs(Sx, sig1) for k, v in A6m.items()}
    eq42 = (A["A1"] + A["A2"] + 4 * R / (3 * A["M2"]) * (A["A3"] / A["M1"] - R * thd**2 * A["A4"])
            ) / (4 * A["M1"] / (3 * A["M2"]) - A["A5"])
    eq42c = -a - p1 * Gs + R * (Mn + 2) / (Mn + 1) * (A["A2"] * thdd + A["A4"] * thd**2)
    add(("42", 6, xbdd, eq42, eq42c))
    eq43 = 6 * (2 + Mn) * (A["A6"] + A["A7"]) * A["A4"] / (
        R * (12 * (-1 + A["A8"]) + Mn * (-5 + 3 * A["A8"]) * (Mn + 4)))
    add(("43", 6, thdd, eq43, None))
    add(("44", 6, sp.Abs(Fx) / Fy,
         sp.Abs(a + xbdd - 2 * Xpaper) / (Gs + 2 * Ypaper), None))
    # ---- mode 7
    add(("46b", 7, Fx, -sig2 * mu2 * M * Gs + 2 * Ypaper, -sig2 * mu2 * M * (Gs + 2 * Ypaper)))
    add(("47", 7, fx,
         nm * (a - R * (thdd * c_ - s * thd**2 * sn_)) - sig2 * mu2 * M * Gs + 2 * Ypaper,
         nm * (a - Xpaper) - sig2 * mu2 * M * (Gs + 2 * Ypaper)))
    A, Ac = A6_, A7_
    add(("48", 7, xsdd,
         -a + A["A1"] - 3 * A["A2"] * (A["A3"] + 2 * (A["A4"] + A["A5"])) / (-2 * Mn + 3 * A["A6"]),
         -a - p2 * Gs + Ac["A1"]
         - 3 * Ac["A2"] * (Ac["A3"] + 2 * (Ac["A4"] + Ac["A5"])) / (-2 * Mn + 3 * Ac["A6"])))
    add(("49", 7, thdd,
         3 * (A["A3"] + 2 * (A["A4"] + A["A5"])) / (2 * R * (2 * Mn - 3 * A["A6"])),
         3 * (Ac["A3"] + 2 * (Ac["A4"] + Ac["A5"])) / (2 * R * (2 * Mn - 3 * Ac["A6"]))))
    den50 = (Mn + 1) * Gs + (Mn + 2) * Ypaper
    num50 = Mn * a - p2 * Gs - R * (thdd * (Mn * c_ + 2 * p2 * s * sn_)
                                    - thd**2 * (s * sn_ + 2 * p2 * c_))
    num50c = Mn * a - p2 * Gs - R * (thdd * (Mn * c_ + 2 * p2 * s * sn_)
                                     + thd**2 * (Mn * s * sn_ - 2 * p2 * c_))
    add(("50", 7, sp.Abs(fx / fy), sp.Abs(num50 / den50), sp.Abs(num50c / den50)))
    # ---- mode 8
    add(("53", 8, Fx, -sig2 * mu2 * M * Gs + 2 * Ypaper, -sig2 * mu2 * M * (Gs + 2 * Ypaper)))
    add(("54", 8, fx, -sig1 * mu1 * ((nm + M) * Gs + (nm + 2 * M) * Ypaper), None))
    A, Ac = A8_, A8c
    D, Dc = A["A7"] + A["A8"], Ac["A7"] + Ac["A8"]
    eq55 = (2 * (A["A1"] + (A["A2"] + A["A3"]) * Gs) + Mn * (A["A4"] + A["A5"] * Gs) + A["A6"]) / D
    eq56 = -(Mn + 2) / (Mn * c_) * (
        (A["A9"] + A["A10"] * (A["A11"] - A["A12"] - A["A4"] * c_)) / ((Mn + 2) * D))
    eq57 = 3 * (A["A11"] + A["A12"] + A["A4"] * c_) / (R * D)
    eq57c = 3 * (Ac["A11"] + Ac["A12"] + Ac["A4"] * c_) / (R * Dc)
    Xn = -Xpaper
    Yn = Ypaper
    xs8 = -Xn + (p1 * ((Mn + 1) * Gs + (Mn + 2) * Yn) - p2 * (Mn + 1) * (Gs + 2 * Yn)) / Mn
    xb8 = -a - Xn - (p1 * ((Mn + 1) * Gs + (Mn + 2) * Yn) - p2 * (Gs + 2 * Yn)) / Mn
    add(("55", 8, xsdd, eq55, xs8))
    add(("56", 8, xbdd, eq56, xb8))
    add(("57", 8, thdd, eq57, eq57c))
    return eqs


def subs_rational(expr, subs):
    """Substitute into numerator and denominator separately (for limits such as M -> 0 where
    the LU solution has removable 0/0 factors)."""
    num, den = sp.fraction(sp.together(expr))
    num0, den0 = sp.expand(num).subs(subs), sp.expand(den).subs(subs)
    if den0 == 0:
        raise ZeroDivisionError("substitution is singular")
    return num0 / den0
