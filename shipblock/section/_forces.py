"""Contact laws and equations of motion of the dock-section model (compiled): the layout of
the state and of the strip and spring tables, every spring's and strip's kinematics and force,
and the right-hand side of the equations, per spring (:func:`rhs`) and from per-regime sums
(:func:`stage_rhs`). :mod:`shipblock.section._kernel` integrates them with located events.

The section is a set of rigid bodies in the transverse plane (body 0 the ship; then every moving
block line), each with state ``(y, z, angle)`` in the floor's frame, joined by *strips*: the cap
of a block face (carried by body ``C``: a moving line, or a fixed line whose pose is given)
pressed against a straight surface of body ``S`` (the ship's hull, or the floor). A strip holds
``n`` compression-only springs at Gauss-Lobatto points of the face and one tangential stick spring
at the centre of pressure of their forces (:func:`friction_offset`; the face centre while the
strip carries nothing). :mod:`shipblock.section.model` explains every law; this module only
evaluates them.

State vector: ``q`` (3 per body), ``v`` (3 per body), ``u`` (per strip: the stick spring's
extension while it sticks; while it slips, the energy it has lost since the slip began, which
bounds the next stick's preload), then the running integrals ``W_ground, W_wind, D_damping, D_friction`` (not error-controlled).

numba's cache of :func:`shipblock.section._kernel.run` holds these functions compiled in, and it
is keyed on ``_kernel.py`` only: after editing this module, touch ``_kernel.py`` (or clear its
``__pycache__``) so that the kernel is compiled again.
"""

from __future__ import annotations

import math

from numba import njit

# --- layout of the strip and spring tables -------------------------------------------------
SF_SQY, SF_SQZ, SF_SNY, SF_SNZ, SF_CY, SF_CZ, SF_KT, SF_CT, SF_MUS, SF_MUK = range(10)
SF_PY, SF_PZ, SF_PA = 10, 11, 12  # fixed pose of C when C is not a body
N_SF = 13
SI_C, SI_S, SI_FIRST, SI_COUNT = range(4)
N_SI = 4
PF_RY, PF_RZ, PF_K, PF_C, PF_FY, PF_AREA = range(6)
N_PF = 6

# --- regimes -----------------------------------------------------------------------------
R_FREE, R_ELASTIC, R_CRUSH = 0, 1, 2  # spring: not carrying / elastic / crushing
F_STICK, F_FREE = 0, 2  # strip: stick, +1/-1 slip in that direction of v_t, free (no load)

# --- options vector --------------------------------------------------------------------------
O_G, O_WIND_F, O_WIND_Y, O_WIND_Z, O_ROLL_HELD, O_SEP, O_TIP_POS, O_TIP_NEG = range(8)
O_KEEL_B, O_KEEL_TOP_Y, O_KEEL_TOP_Z, O_SHIP_KY, O_SHIP_KZ = 8, 9, 10, 11, 12
O_MAX_ANGLE, O_MAX_DISP = 13, 14
N_OPT = 15


@njit(cache=True, inline="always")
def _pose(x, body, fy, fz, fa):
    if body < 0:
        return fy, fz, fa
    return x[3 * body], x[3 * body + 1], x[3 * body + 2]


@njit(cache=True, inline="always")
def _vel(x, nb, body):
    if body < 0:
        return 0.0, 0.0, 0.0
    o = 3 * nb + 3 * body
    return x[o], x[o + 1], x[o + 2]


@njit(cache=True, inline="always")
def _trig(body, angle):
    """cos and sin of a pose's angle; the floor's zero angle without a call (the same values)."""
    if body < 0 and angle == 0.0:
        return 1.0, 0.0
    return math.cos(angle), math.sin(angle)


@njit(cache=True, inline="always")
def _frame(x, nb, j, strip_f, strip_i):
    """What every spring of strip j needs, so that a spring costs a few products.

    With C's pose ``(c, R_C)``, S's ``(s, R_S)``, a spring at ``rho = R_C r`` from c (``r`` its
    point in C's frame), S's surface point ``q`` and normal ``n``, and ``w = omega_S - omega_C``:
    closure ``delta = D0 - r . a`` with ``a = R_C^T n``; the moment arm ``m = rho x n = r x a``;
    closure rate ``delta_dot = E0 + w m``; the force ``f n`` at the spring has the moment
    ``f m`` about c and ``-f (L0 + m)`` about s. Returns ``(cb, sb, ny, nz, a1, a2, D0, E0, w, L0,
    cy, cz, cc, cs, T0, P0)``; ``T0`` and ``P0`` give the tangential slip rate and the moment
    about s of a tangential force at a point of C (see :func:`rhs`).
    """
    cb, sb = strip_i[j, SI_C], strip_i[j, SI_S]
    cy, cz, ca = _pose(x, cb, strip_f[j, SF_PY], strip_f[j, SF_PZ], strip_f[j, SF_PA])
    sy, sz, sa = _pose(x, sb, 0.0, 0.0, 0.0)
    cvy, cvz, cw = _vel(x, nb, cb)
    svy, svz, sw = _vel(x, nb, sb)
    cc, cs = _trig(cb, ca)
    sc, ss = _trig(sb, sa)
    ny = sc * strip_f[j, SF_SNY] - ss * strip_f[j, SF_SNZ]
    nz = ss * strip_f[j, SF_SNY] + sc * strip_f[j, SF_SNZ]
    qy = sy + sc * strip_f[j, SF_SQY] - ss * strip_f[j, SF_SQZ]
    qz = sz + ss * strip_f[j, SF_SQY] + sc * strip_f[j, SF_SQZ]
    a1 = cc * ny + cs * nz
    a2 = cc * nz - cs * ny
    dy, dz = cy - sy, cz - sz
    d0 = (qy - cy) * ny + (qz - cz) * nz
    # relative velocity of S's and C's points at c
    ry_ = svy - cvy - sw * dz
    rz_ = svz - cvz + sw * dy
    e0 = ry_ * ny + rz_ * nz
    t0 = ry_ * nz - rz_ * ny
    return (cb, sb, ny, nz, a1, a2, d0, e0, sw - cw, dy * nz - dz * ny, cy, cz, cc, cs, t0,
            dy * ny + dz * nz)


@njit(cache=True)
def kinematics(x, nb, strip_f, strip_i, spring_f, delta, delta_dot, vt, pos):
    """Closure and closure rate of every spring, tangential slip rate of every strip at its face
    centre (:func:`contact_forces` moves it to the centre of pressure of a loaded strip).

    ``pos[i] = (py, pz)`` is the world position of spring i's point on C (where its force acts).
    """
    strips_kinematics(x, nb, 0, strip_i.shape[0], strip_f, strip_i, spring_f, delta, delta_dot,
                      vt, pos)


@njit(cache=True, inline="always")
def strips_kinematics(x, nb, j0, j1, strip_f, strip_i, spring_f, delta, delta_dot, vt, pos):
    """:func:`kinematics` of strips ``j0 .. j1 - 1`` (their springs' entries only)."""
    for j in range(j0, j1):
        (cb, sb, ny, nz, a1, a2, d0, e0, w, l0, cy, cz, cc, cs, t0,
         p0) = _frame(x, nb, j, strip_f, strip_i)
        first, count = strip_i[j, SI_FIRST], strip_i[j, SI_COUNT]
        for i in range(first, first + count):
            ry, rz = spring_f[i, PF_RY], spring_f[i, PF_RZ]
            pos[i, 0] = cy + cc * ry - cs * rz
            pos[i, 1] = cz + cs * ry + cc * rz
            delta[i] = d0 - (ry * a1 + rz * a2)
            delta_dot[i] = e0 + w * (ry * a2 - rz * a1)
        # tangent t = (n_z, -n_y): (1, 0) on the floor; C's face centre slips at w (r . a) - T0
        vt[j] = w * (strip_f[j, SF_CY] * a1 + strip_f[j, SF_CZ] * a2) - t0


@njit(cache=True, inline="always")
def friction_offset(total, f_ra, ra_first, ra_last, dc):
    """Offset along n from c (``r . a``, see :func:`_frame`) of the point of C's face where the
    strip's friction acts and its slip is measured: the centre of pressure of its spring forces,
    ``sum f_i (r_i . a) / sum f_i`` (a rocking block's loaded corner, as the sticking pivot of
    the rigid model), or the face centre's ``dc`` while the strip carries nothing.

    Only ``r . a`` of that point enters the slip rate ``w (r . a) - T0`` and the tangential
    force's moments, and it is a ratio of sums, so the per-regime sums give it as well
    (:func:`stage_rhs`). It is kept between the face's end springs ``ra_first``, ``ra_last``:
    with every spring force >= 0 (any state the event functions accept) the centre of pressure
    lies there anyway; the bound only keeps a stage's trial state, where a spring about to
    detach may pull, from putting the point off the face.
    """
    if total <= 0.0:
        return dc
    p = f_ra / total
    lo, hi = min(ra_first, ra_last), max(ra_first, ra_last)
    return min(max(p, lo), hi)


@njit(cache=True, inline="always")
def _face_ends(spring_f, first, count, a1, a2):
    """``r . a`` of the strip's first and last springs (the ends of the face: Lobatto points)."""
    last = first + count - 1
    return (spring_f[first, PF_RY] * a1 + spring_f[first, PF_RZ] * a2,
            spring_f[last, PF_RY] * a1 + spring_f[last, PF_RZ] * a2)


@njit(cache=True, inline="always")
def cap_surface(k, c, dp, dc0, t0, t):
    """Compression of a detached cap at time t: it relaxes from dc0 towards its set dp."""
    if c <= 0.0 or dc0 <= dp:
        return dp
    return dp + (dc0 - dp) * math.exp(-(k / c) * (t - t0))


@njit(cache=True)
def contact_forces(x, o_u, nb, strip_f, strip_i, spring_f, reg, dp, fs, delta, delta_dot, vt,
                   fe, fn, normal, tang):
    """Spring forces (total ``fn``, elastic ``fe``) and strip normal/tangential forces; the slip
    rate ``vt`` of a loaded strip moved to its centre of pressure (:func:`friction_offset`)."""
    strips_forces(x, o_u, nb, 0, strip_i.shape[0], strip_f, strip_i, spring_f, reg, dp, fs,
                  delta, delta_dot, vt, fe, fn, normal, tang)


@njit(cache=True, inline="always")
def strips_forces(x, o_u, nb, j0, j1, strip_f, strip_i, spring_f, reg, dp, fs, delta, delta_dot,
                  vt, fe, fn, normal, tang):
    """:func:`contact_forces` of strips ``j0 .. j1 - 1`` (from their kinematics)."""
    for j in range(j0, j1):
        first, count = strip_i[j, SI_FIRST], strip_i[j, SI_COUNT]
        total = 0.0
        f_delta = 0.0  # sum f delta: r . a = D0 - delta of every spring
        for i in range(first, first + count):
            k, c, fy = spring_f[i, PF_K], spring_f[i, PF_C], spring_f[i, PF_FY]
            if reg[i] == R_ELASTIC:
                fe[i] = k * (delta[i] - dp[i])
                fn[i] = fe[i] + c * delta_dot[i]
            elif reg[i] == R_CRUSH:
                fe[i] = fy
                fn[i] = fy + c * delta_dot[i]
            else:
                fe[i] = 0.0
                fn[i] = 0.0
            total += fn[i]
            f_delta += fn[i] * delta[i]
        normal[j] = total
        if total > 0.0:
            (cb, sb, ny, nz, a1, a2, d0, e0, w, l0, cy, cz, cc, cs, t0,
             p0) = _frame(x, nb, j, strip_f, strip_i)
            ra_a, ra_b = _face_ends(spring_f, first, count, a1, a2)
            dc = strip_f[j, SF_CY] * a1 + strip_f[j, SF_CZ] * a2
            vt[j] = w * friction_offset(total, total * d0 - f_delta, ra_a, ra_b, dc) - t0
        if fs[j] == F_STICK:
            tang[j] = -strip_f[j, SF_KT] * x[o_u + j] - strip_f[j, SF_CT] * vt[j]
        elif fs[j] == F_FREE:
            tang[j] = 0.0
        else:
            tang[j] = -fs[j] * strip_f[j, SF_MUK] * total


@njit(cache=True, inline="always")
def _start_rates(t, x, nb, mass, opt, ag_y, ag_z, dt_rec, xdot):
    """Rates of the positions and the bodies' inertial loads (momentum rates before contact);
    returns the ground acceleration ``(a_y, a_z)``, linear between the samples."""
    s = t / dt_rec
    k = int(s)
    if k >= ag_y.shape[0] - 1:
        ay, az = ag_y[-1], ag_z[-1]
    else:
        w = s - k
        ay = ag_y[k] + w * (ag_y[k + 1] - ag_y[k])
        az = ag_z[k] + w * (ag_z[k + 1] - ag_z[k])
    o_v = 3 * nb
    g = opt[O_G]
    for b in range(nb):
        xdot[3 * b] = x[o_v + 3 * b]
        xdot[3 * b + 1] = x[o_v + 3 * b + 1]
        xdot[3 * b + 2] = x[o_v + 3 * b + 2]
        xdot[o_v + 3 * b] = -mass[b] * ay
        xdot[o_v + 3 * b + 1] = -mass[b] * (g + az)
        xdot[o_v + 3 * b + 2] = 0.0
    return ay, az


@njit(cache=True, inline="always")
def _strip_load(x, nb, j, strip_f, fs, cb, sb, ny, nz, l0, p0, total, moment, dc, vtj, xdot):
    """Friction of strip j (stick spring, kinetic or none) and the strip's normal force
    ``total`` (moment ``moment`` about c) and friction applied to C, the opposite to S.

    ``dc`` is the offset along n from c of the point of C where the friction acts (the centre
    of pressure, :func:`friction_offset`), ``vtj`` its slip rate. Returns the
    friction force and the strip's damping (stick dashpot) and friction loss rates."""
    o_v, o_u = 3 * nb, 6 * nb
    d_damp = 0.0
    d_fric = 0.0
    if fs[j] == F_STICK:
        ft = -strip_f[j, SF_KT] * x[o_u + j] - strip_f[j, SF_CT] * vtj
        xdot[o_u + j] = vtj
        d_damp = strip_f[j, SF_CT] * vtj * vtj
    elif fs[j] == F_FREE:
        ft = 0.0
        xdot[o_u + j] = 0.0
    else:
        ft = -fs[j] * strip_f[j, SF_MUK] * total
        d_fric = -ft * vtj
        xdot[o_u + j] = d_fric  # the energy the face has lost since its slip began
    # normal force total n and tangential ft t (t = (n_z, -n_y)) on C, the opposite on S
    fy_ = total * ny + ft * nz
    fz_ = total * nz - ft * ny
    if cb >= 0:
        xdot[o_v + 3 * cb] += fy_
        xdot[o_v + 3 * cb + 1] += fz_
        xdot[o_v + 3 * cb + 2] += moment - ft * dc
    if sb >= 0:
        xdot[o_v + 3 * sb] -= fy_
        xdot[o_v + 3 * sb + 1] -= fz_
        xdot[o_v + 3 * sb + 2] += ft * (p0 + dc) - total * l0 - moment
    return ft, d_damp, d_fric


@njit(cache=True, inline="always")
def _finish_rates(x, nb, ns, mass, inertia, opt, ay, az, d_damp, d_fric, xdot):
    """Wind on the ship, accelerations from the momentum rates, a held roll, energy rates."""
    o_v = 3 * nb
    # wind on the ship at its point (O_WIND_Y, O_WIND_Z) in the ship's frame
    fw = opt[O_WIND_F]
    w_wind = 0.0
    if fw != 0.0:
        ca, sa = math.cos(x[2]), math.sin(x[2])
        rz = sa * opt[O_WIND_Y] + ca * opt[O_WIND_Z]
        xdot[o_v] += fw
        xdot[o_v + 2] += -rz * fw
        w_wind = fw * (x[o_v] - x[o_v + 2] * rz)
    w_ground = 0.0
    for b in range(nb):
        o = o_v + 3 * b
        w_ground -= mass[b] * (ay * x[o] + az * x[o + 1])
        xdot[o] /= mass[b]
        xdot[o + 1] /= mass[b]
        xdot[o + 2] /= inertia[b]
    if opt[O_ROLL_HELD] != 0.0:
        xdot[2] = 0.0
        xdot[o_v + 2] = 0.0
    o_e = 6 * nb + ns
    xdot[o_e] = w_ground
    xdot[o_e + 1] = w_wind
    xdot[o_e + 2] = d_damp
    xdot[o_e + 3] = d_fric


@njit(cache=True)
def rhs(t, x, nb, ns, mass, inertia, strip_f, strip_i, spring_f, reg, dp, fs, opt, ag_y, ag_z,
        dt_rec, delta, delta_dot, vt, pos, fe, fn, normal, tang, xdot):
    """Time derivative of the state (Newton-Euler of every body, contact laws, energy rates).

    One pass per strip does what :func:`kinematics` and :func:`contact_forces` do (the same
    formulas, :func:`_frame`, filling the same work arrays) and applies the strip's resultant
    force and moment to C and S once. The integrator's inner stages use :func:`stage_rhs`.
    """
    ay, az = _start_rates(t, x, nb, mass, opt, ag_y, ag_z, dt_rec, xdot)
    d_damp = 0.0
    d_fric = 0.0
    for j in range(ns):
        (cb, sb, ny, nz, a1, a2, d0, e0, w, l0, cy, cz, cc, cs, t0,
         p0) = _frame(x, nb, j, strip_f, strip_i)
        first, count = strip_i[j, SI_FIRST], strip_i[j, SI_COUNT]
        total = 0.0
        moment = 0.0  # sum of f m: the springs' moment about c
        f_ra = 0.0  # sum of f (r . a): the centre of pressure's offset times the normal force
        for i in range(first, first + count):
            ry, rz = spring_f[i, PF_RY], spring_f[i, PF_RZ]
            m = ry * a2 - rz * a1
            ra = ry * a1 + rz * a2
            di = d0 - ra
            ddi = e0 + w * m
            delta[i] = di
            delta_dot[i] = ddi
            c = spring_f[i, PF_C]
            ri = reg[i]
            if ri == R_ELASTIC:
                fei = spring_f[i, PF_K] * (di - dp[i])
                f = fei + c * ddi
                d_damp += c * ddi * ddi
            elif ri == R_CRUSH:
                fei = spring_f[i, PF_FY]
                f = fei + c * ddi
                d_damp += c * ddi * ddi
            else:
                fei = 0.0
                f = 0.0
            fe[i] = fei
            fn[i] = f
            total += f
            moment += f * m
            f_ra += f * ra
        normal[j] = total
        # the friction point (centre of pressure): its offset along n from c and its slip rate
        ra_a, ra_b = _face_ends(spring_f, first, count, a1, a2)
        dc = friction_offset(total, f_ra, ra_a, ra_b,
                             strip_f[j, SF_CY] * a1 + strip_f[j, SF_CZ] * a2)
        vtj = w * dc - t0
        vt[j] = vtj
        ft, dd, df = _strip_load(x, nb, j, strip_f, fs, cb, sb, ny, nz, l0, p0, total, moment,
                                 dc, vtj, xdot)
        tang[j] = ft
        d_damp += dd
        d_fric += df
    _finish_rates(x, nb, ns, mass, inertia, opt, ay, az, d_damp, d_fric, xdot)


# --- regime sums of a strip (moments of its springs' stiffness, yield force and damping over
# their body-fixed points ry, rz), constant between events ------------------------------------
(RS_K, RS_KY, RS_KZ, RS_KD, RS_KDY, RS_KDZ, RS_KYY, RS_KZZ, RS_KYZ, RS_F, RS_FY, RS_FZ, RS_C,
 RS_CY, RS_CZ, RS_CYY, RS_CZZ, RS_CYZ) = range(18)
N_RS = 18


@njit(cache=True)
def regime_sums(strip_i, spring_f, reg, dp, sums):
    """Per strip, the sums over its elastic springs of ``k, k ry, k rz, k dp, k dp ry, k dp rz,
    k ry^2, k rz^2, k ry rz``, over its crushing springs of ``F_y, F_y ry, F_y rz``, and over its
    carrying springs of ``c, c ry, c rz, c ry^2, c rz^2, c ry rz``: with them a strip's force,
    moment and damping loss are closed forms (:func:`stage_rhs`). To be redone after every
    change of a regime or a set."""
    for j in range(strip_i.shape[0]):
        for q in range(N_RS):
            sums[j, q] = 0.0
        first, count = strip_i[j, SI_FIRST], strip_i[j, SI_COUNT]
        for i in range(first, first + count):
            ry, rz = spring_f[i, PF_RY], spring_f[i, PF_RZ]
            if reg[i] == R_FREE:
                continue
            if reg[i] == R_ELASTIC:
                k = spring_f[i, PF_K]
                kd = k * dp[i]
                sums[j, RS_K] += k
                sums[j, RS_KY] += k * ry
                sums[j, RS_KZ] += k * rz
                sums[j, RS_KD] += kd
                sums[j, RS_KDY] += kd * ry
                sums[j, RS_KDZ] += kd * rz
                sums[j, RS_KYY] += k * ry * ry
                sums[j, RS_KZZ] += k * rz * rz
                sums[j, RS_KYZ] += k * ry * rz
            else:
                fy = spring_f[i, PF_FY]
                sums[j, RS_F] += fy
                sums[j, RS_FY] += fy * ry
                sums[j, RS_FZ] += fy * rz
            c = spring_f[i, PF_C]
            sums[j, RS_C] += c
            sums[j, RS_CY] += c * ry
            sums[j, RS_CZ] += c * rz
            sums[j, RS_CYY] += c * ry * ry
            sums[j, RS_CZZ] += c * rz * rz
            sums[j, RS_CYZ] += c * ry * rz


@njit(cache=True)
def stage_rhs(t, x, nb, ns, mass, inertia, strip_f, strip_i, spring_f, fs, opt, ag_y, ag_z, dt_rec,
              sums, xdot, stage_n):
    """:func:`rhs` from the regime sums (:func:`regime_sums`): a strip costs the same whatever
    its number of springs, and no spring's force is kept (the integrator's inner stages).

    With a spring's closure ``delta_i = D0 - dp_i - (ry a1 + rz a2)``, rate ``E0 + w m_i`` and
    arm ``m_i = ry a2 - rz a1`` (:func:`_frame`), the strip's normal force ``sum f_i`` and
    moment ``sum f_i m_i`` are linear and quadratic forms in ``(a1, a2)`` with the sums as
    coefficients; the damping loss rate ``sum c_i (E0 + w m_i)^2`` likewise, and the
    centre of pressure where the friction acts (``sum f_i (r_i . a) / sum f_i``,
    :func:`friction_offset`) from one more quadratic form. Equal to :func:`rhs` but for
    rounding. ``stage_n[j]`` is raised to strip j's normal force if that is larger (the
    integrator looks inside a step for a peak of the force when a stage's exceeds the ends').
    """
    ay, az = _start_rates(t, x, nb, mass, opt, ag_y, ag_z, dt_rec, xdot)
    d_damp = 0.0
    d_fric = 0.0
    for j in range(ns):
        (cb, sb, ny, nz, a1, a2, d0, e0, w, l0, cy, cz, cc, cs, t0,
         p0) = _frame(x, nb, j, strip_f, strip_i)
        sm = sums[j]
        # sums over the springs: m = ry a2 - rz a1, r . a = ry a1 + rz a2
        k_m = sm[RS_KY] * a2 - sm[RS_KZ] * a1
        k_ra = sm[RS_KY] * a1 + sm[RS_KZ] * a2
        k_ra_m = a1 * a2 * (sm[RS_KYY] - sm[RS_KZZ]) + (a2 * a2 - a1 * a1) * sm[RS_KYZ]
        c_m = sm[RS_CY] * a2 - sm[RS_CZ] * a1
        c_mm = a2 * a2 * sm[RS_CYY] - 2.0 * a1 * a2 * sm[RS_CYZ] + a1 * a1 * sm[RS_CZZ]
        # normal force (elastic, crushing, dashpot) and its moment about c
        total = sm[RS_K] * d0 - sm[RS_KD] - k_ra + sm[RS_F] + sm[RS_C] * e0 + w * c_m
        if total > stage_n[j]:
            stage_n[j] = total
        moment = (d0 * k_m - (sm[RS_KDY] * a2 - sm[RS_KDZ] * a1) - k_ra_m
                  + sm[RS_FY] * a2 - sm[RS_FZ] * a1 + e0 * c_m + w * c_mm)
        d_damp += e0 * e0 * sm[RS_C] + 2.0 * e0 * w * c_m + w * w * c_mm
        # sum f (r . a) for the centre of pressure, where the friction acts
        f_ra = (d0 * k_ra - (sm[RS_KDY] * a1 + sm[RS_KDZ] * a2)
                - (a1 * a1 * sm[RS_KYY] + 2.0 * a1 * a2 * sm[RS_KYZ] + a2 * a2 * sm[RS_KZZ])
                + sm[RS_FY] * a1 + sm[RS_FZ] * a2 + e0 * (sm[RS_CY] * a1 + sm[RS_CZ] * a2)
                + w * (a1 * a2 * (sm[RS_CYY] - sm[RS_CZZ]) + (a2 * a2 - a1 * a1) * sm[RS_CYZ]))
        ra_a, ra_b = _face_ends(spring_f, strip_i[j, SI_FIRST], strip_i[j, SI_COUNT], a1, a2)
        dc = friction_offset(total, f_ra, ra_a, ra_b,
                             strip_f[j, SF_CY] * a1 + strip_f[j, SF_CZ] * a2)
        _, dd, df = _strip_load(x, nb, j, strip_f, fs, cb, sb, ny, nz, l0, p0, total, moment,
                                dc, w * dc - t0, xdot)
        d_damp += dd
        d_fric += df
    _finish_rates(x, nb, ns, mass, inertia, opt, ay, az, d_damp, d_fric, xdot)


@njit(cache=True, inline="always")
def strip_of(i, strip_i):
    """The strip spring i belongs to."""
    for j in range(strip_i.shape[0]):
        if strip_i[j, SI_FIRST] <= i < strip_i[j, SI_FIRST] + strip_i[j, SI_COUNT]:
            return j
    return -1
