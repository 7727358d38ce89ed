"""Exponential steps of the dock section in its static regime: the matrices, made once per dock.

While every spring keeps the regime it has at rest and every strip keeps its stick or free state
(the *static regime*), the section's equations are linear but for the large-rotation geometry
and the vertical input's product with the rotations. With ``y = x - x_s`` (the mechanical
states: positions, velocities, stick-spring extensions; ``x_s`` the static state) they read

.. math::

    \\dot y = A y + g(t, y), \\qquad g = f(t, x) - A y,

``A`` the Jacobian at the static state and ``g`` the ground motion, gravity, wind and the small
nonlinear remainder. Over a sample interval of length ``h`` the input is linear in time; with
``g(s) = g_0 + s c`` linear too, the step is exact (exponential time differencing; Cox and
Matthews 2002, Hochbruck and Ostermann 2010 eq. 2.9):

.. math::

    y(s) = e^{sA} y_0 + s\\varphi_1(sA)\\, g_0 + s^2\\varphi_2(sA)\\, c,
    \\qquad \\varphi_1(z) = \\frac{e^z - 1}{z},\\quad \\varphi_2(z) = \\frac{e^z - 1 - z}{z^2}.

All three are blocks of one exponential of the augmented matrix of ``(y, p, c)`` with
``y' = A y + p``, ``p' = c``, ``c' = 0`` (Van Loan 1978; Al-Mohy and Higham 2011 for the
``phi`` functions by one exponential). The stiff cap modes are integrated exactly, so the step is
the sample interval whatever the caps' stiffness; the kernel (:func:`shipblock.section._kernel.run`)
takes such a step at a sample while the dock is in its static regime and the step's error
estimate and event functions allow it, and Dormand-Prince otherwise.

Energy integrals over the step, from the same trajectory:

- ground work ``-sum_b m_b (a_y v_y + a_z v_z)`` is linear in the velocities with the input
  linear in time: exact from ``int y ds`` and ``int s y ds``, the blocks of two more integrator
  states (``q_1' = y``, ``q_2' = q_1``, so ``int s y ds = h q_1(h) - q_2(h)``);
- damping ``sum c delta_dot^2`` is a quadratic form ``y^T Q y`` of the velocities in the
  linearised geometry (``Q`` by polarisation of the rate at the static state): its integral is
  ``w^T G w`` with ``w = (y_0, g_0, c)`` and ``G = int_0^h exp(M^T s) Q exp(M s) ds`` (Van Loan
  1978, from one exponential of ``[[-M^T, Q], [0, M]]`` over a short enough interval, then
  doubled: :func:`_gramian`);
- wind work's linear part exactly as the ground work's;
- what the geometry adds to the damping and wind rates beyond those forms (small: second order
  in the rotations) by Simpson's rule on the rates at the step's ends and middle.

References
----------
Van Loan, C. F. (1978). Computing integrals involving the matrix exponential. IEEE Transactions
on Automatic Control 23(3), 395-404.

Cox, S. M. and Matthews, P. C. (2002). Exponential time differencing for stiff systems. Journal
of Computational Physics 176, 430-455.

Hochbruck, M. and Ostermann, A. (2010). Exponential integrators. Acta Numerica 19, 209-286.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.linalg
from threadpoolctl import threadpool_limits

from shipblock.section._forces import rhs
from shipblock.section._kernel import _force_arrays
from shipblock.section.model import Assembly, InitialState

__all__ = ["StaticSteps", "settled_steps", "static_steps"]

#: Matrices of :attr:`StaticSteps.mats`, in this order (H: at h/2, Q: at h/4, C: the error
#: estimate's for a step of h and of h/2).
(MAT_A, MAT_E, MAT_P1, MAT_PC, MAT_EH, MAT_P1H, MAT_PCH, MAT_EQ, MAT_P1Q, MAT_PCQ, MAT_C,
 MAT_CH) = range(12)
#: Rows of :attr:`StaticSteps.rows` (functionals of ``w = (y_0, g_0, c)``).
ROW_GY0, ROW_GY1, ROW_GZ0, ROW_GZ1, ROW_WIND = range(5)


@dataclass(frozen=True)
class StaticSteps:
    """The static regime's matrices for steps of one sample interval (arrays for the kernel).

    Attributes
    ----------
    x_s : ndarray
        The static state (the whole state vector, the linearisation point).
    regime, friction : ndarray
        The springs' regimes and the strips' friction states that make the static regime.
    mats : ndarray, shape (12, n, n)
        ``A``; ``e^{hA}``, ``h phi_1(hA)``, ``h^2 phi_2(hA)``; the same for ``h/2`` (the step's
        middle, and a half step) and ``h/4`` (a half step's middle); ``4 h (phi_2 - 2
        phi_3)(hA)`` and the same for ``h/2``: what a remainder ``4 d theta (1 - theta)`` over
        the step adds to ``y_1`` (the error estimate's); ``n`` the number of mechanical
        states.
    b : ndarray, shape (n, 2)
        Rates per unit horizontal and vertical ground acceleration (the predictor's input slope).
    gram : ndarray, shape (2, n + 2 n_r, n + 2 n_r)
        ``G`` for a step of ``h`` and of ``h/2``: the damping over a step is ``w^T G w``, with
        ``w`` = ``y_0`` and the ``n_r`` rows of ``g_0`` and ``c`` after the positions' (whose
        are zero: the positions' rates are the velocities).
    rows : ndarray, shape (2, 5, n + 2 n_r)
        ``int V_y ds``, ``int s V_y ds``, the same for ``V_z`` (``V = sum_b m_b v_b``) and the wind
        power's linear part, as functionals of ``w``.
    q_vel : ndarray, shape (3 n_b, 3 n_b)
        ``Q`` on the velocities (the damping rate's quadratic form).
    wind_grad : ndarray, shape (n,)
        Gradient of the wind power at the static state.
    rates0 : ndarray, shape (2,)
        Wind power and damping rate at the static state.
    """

    x_s: np.ndarray
    regime: np.ndarray
    friction: np.ndarray
    mats: np.ndarray
    b: np.ndarray
    gram: np.ndarray
    rows: np.ndarray
    q_vel: np.ndarray
    wind_grad: np.ndarray
    rates0: np.ndarray


def _expm(m):
    """``exp(m)`` of a badly scaled matrix (cap stiffnesses over masses next to ones): balanced
    by a diagonal similarity first (:func:`scipy.linalg.matrix_balance`), which keeps the
    scaling-and-squaring short and its rounding small."""
    b, scale = scipy.linalg.matrix_balance(m, permute=False, separate=True)
    d = scale[0]
    return (d[:, None] * scipy.linalg.expm(b)) / d[None, :]


def _gramian(m, q, h, rho):
    """``int_0^t exp(M^T s) Q exp(M s) ds`` for ``t = h`` and ``h/2``, ``M`` with eigenvalues
    up to ``rho`` in modulus.

    Van Loan's (1978, Theorem 1) block exponential of ``[[-M^T, Q], [0, M]]`` loses everything
    to cancellation once ``exp(-M^T h)`` grows like ``exp(rho h)`` (stiff caps: ``rho h`` of 10 to
    100); so it is used on ``h / 2^k`` with ``rho h / 2^k <= 1``, then doubled ``k`` times with
    ``G(2t) = G(t) + exp(M t)^T G(t) exp(M t)`` (sums of positive semi-definite terms)."""
    n = m.shape[0]
    k = max(1, int(np.ceil(np.log2(max(rho * h, 1.0)))))
    t = h / 2.0**k
    vl = np.zeros((2 * n, 2 * n))
    vl[:n, :n] = -m.T
    vl[:n, n:] = q
    vl[n:, n:] = m
    c = _expm(vl * t)
    phi = c[n:, n:]
    gram = phi.T @ c[:n, n:]
    for _ in range(k - 1):
        gram = gram + phi.T @ gram @ phi
        phi = phi @ phi
    half = 0.5 * (gram + gram.T)
    gram = gram + phi.T @ gram @ phi
    return [0.5 * (gram + gram.T), half]


def static_steps(asm: Assembly, init: InitialState, dt: float) -> StaticSteps:
    """The matrices of exponential steps of length ``dt`` in the static regime of ``init``.

    ``A`` and ``B`` by central differences of the right-hand side at the static state (any ``A``
    keeps the step consistent: the remainder ``g`` carries what it misses), ``Q`` by
    polarisation (exact for a quadratic form), the matrix functions by
    :func:`scipy.linalg.expm`. About 10-30 ms for the benchmark dock; a batch makes them once.
    The linear algebra runs on one BLAS thread: its results do not depend on how many threads
    a process has (a Dask worker has one), so a study gives the same bits everywhere.
    """
    return _regime_steps(asm, init.x, init.regime, init.friction,
                         np.zeros(asm.spring_f.shape[0]), dt)


def settled_steps(asm: Assembly, x: np.ndarray, regime: np.ndarray, friction: np.ndarray,
                  plastic_set: np.ndarray, dt: float) -> StaticSteps:
    """The matrices of exponential steps of length ``dt`` in the regime a run has settled in.

    As :func:`static_steps`, linearised at the positions (and stick-spring extensions) of ``x``
    at rest: ``x_s`` is ``x`` with its velocities set to zero, so that the damping's and the
    wind's forms are those of motion about it; ``x`` need not be an equilibrium (what it leaves
    unbalanced is part of the remainder ``g``, integrated as the input is). The kernel stops
    for these (:data:`shipblock.section._kernel.STOP_SETTLED`) when the dock has spent a while
    without an event in a regime (springs' contacts, strips' stick or free states) other than
    the static one, typically after strong motion leaves caps open and blocks shifted.
    """
    nb = asm.n_bodies
    x_s = np.array(x, dtype=float)
    x_s[3 * nb:6 * nb] = 0.0
    return _regime_steps(asm, x_s, regime, friction, plastic_set, dt)


def _regime_steps(asm, x_s, regime, friction, plastic_set, dt) -> StaticSteps:
    """:func:`static_steps` for the regime ``(regime, friction)``, linearised at ``x_s``, on one
    BLAS thread (its results do not depend on how many threads a process has)."""
    with threadpool_limits(limits=1, user_api="blas"):
        return _steps(asm, np.array(x_s, dtype=float), np.array(regime, dtype=np.int64),
                      np.array(friction, dtype=np.int64), np.array(plastic_set, dtype=float), dt)


def _steps(asm: Assembly, x_s, reg, fs, dp, dt: float) -> StaticSteps:
    nb, ns = asm.n_bodies, asm.n_strips
    nm = 6 * nb + ns
    o_e = nm
    work = _force_arrays(asm.spring_f.shape[0], ns)
    out = np.zeros(x_s.size)

    def f(x, ay=0.0, az=0.0):
        rhs(0.0, x, nb, ns, asm.mass, asm.inertia, asm.strip_f, asm.strip_i, asm.spring_f, reg,
            dp, fs, asm.opt, np.array([ay, ay]), np.array([az, az]), 1.0, *work, out)
        return out.copy()

    f0 = f(x_s)
    a = np.zeros((nm, nm))
    grad_wind = np.zeros(nm)
    for m in range(nm):
        e = 1e-7 * max(1e-3, abs(x_s[m]))
        xp, xm = x_s.copy(), x_s.copy()
        xp[m] += e
        xm[m] -= e
        fp, fm = f(xp), f(xm)
        a[:, m] = (fp[:nm] - fm[:nm]) / (2.0 * e)
        grad_wind[m] = (fp[o_e + 1] - fm[o_e + 1]) / (2.0 * e)
    # the positions' rates are the velocities, exactly: so are their rows of A, which makes the
    # positions' rows of g and c zero (the steps and the damping's form use only the others)
    nv = 3 * nb
    a[:nv] = 0.0
    a[:nv, nv:2 * nv] = np.eye(nv)
    b = np.stack([f(x_s, 1.0, 0.0)[:nm] - f0[:nm], f(x_s, 0.0, 1.0)[:nm] - f0[:nm]], axis=1)
    b[:nv] = 0.0
    # the damping rate's quadratic form on the velocities, by polarisation
    q_vel = np.zeros((nv, nv))
    ev = 1e-3

    def damping(v):
        x = x_s.copy()
        x[nv:2 * nv] += v
        return f(x)[o_e + 2] - f0[o_e + 2]

    for i in range(nv):
        for j in range(i, nv):
            ui, uj = np.zeros(nv), np.zeros(nv)
            ui[i] = ev
            uj[j] = ev
            q_vel[i, j] = q_vel[j, i] = (damping(ui + uj) - damping(ui - uj)) / (4.0 * ev * ev)
    eye = np.eye(nm)
    # (y, p, c, q1, q2): y' = A y + p, p' = c, q1' = y, q2' = q1
    m5 = np.zeros((5 * nm, 5 * nm))
    m5[:nm, :nm] = a
    m5[:nm, nm:2 * nm] = eye
    m5[nm:2 * nm, 2 * nm:3 * nm] = eye
    m5[3 * nm:4 * nm, :nm] = eye
    m5[4 * nm:, 3 * nm:4 * nm] = eye
    m3 = m5[:3 * nm, :3 * nm]
    # a forcing 4 d theta (1 - theta) over a step of length h moves y1 by
    # 4 h (phi2 - 2 phi3)(hA) d: phi3 from the augmented matrix of a quadratic forcing
    m4 = np.zeros((4 * nm, 4 * nm))
    m4[:3 * nm, :3 * nm] = m3
    m4[2 * nm:3 * nm, 3 * nm:] = eye
    mom_y, mom_z = np.zeros(nm), np.zeros(nm)
    mom_y[nv:2 * nv:3] = asm.mass
    mom_z[nv + 1:2 * nv:3] = asm.mass
    # w = (y0, g0, c) reduced to (y0, g0 and c without their zero position rows)
    keep = np.r_[0:3 * nm][np.r_[0:nm, nm + nv:2 * nm, 2 * nm + nv:3 * nm]]
    q3 = np.zeros((3 * nm, 3 * nm))
    q3[nv:2 * nv, nv:2 * nv] = q_vel
    rho = np.max(np.abs(np.linalg.eigvals(a)))
    # one exponential at h/4 (h/2 for the quadratic forcing's), squared for the longer steps
    quarter = _expm(m5 * (0.25 * dt))
    big = {0.25: quarter}
    big[0.5] = quarter @ quarter
    big[1.0] = big[0.5] @ big[0.5]
    e4 = {0.5: _expm(m4 * (0.5 * dt))}
    e4[1.0] = e4[0.5] @ e4[0.5]
    grams = _gramian(m3, q3, dt, rho)
    blocks, checks, rows = [a], [], []
    for part in (1.0, 0.5):  # a whole sample interval, and half of one
        h = part * dt
        e = big[part]
        blocks += [e[:nm, :nm], e[:nm, nm:2 * nm], e[:nm, 2 * nm:3 * nm]]
        e = e4[part]
        checks.append(4.0 / h * e[:nm, 2 * nm:3 * nm] - 8.0 / h**2 * e[:nm, 3 * nm:])
        q1 = big[part][3 * nm:4 * nm, :3 * nm]  # int y ds as a map of w = (y0, g0, c)
        s_q = h * q1 - big[part][4 * nm:, :3 * nm]  # int s y ds
        rows.append(np.stack([mom_y @ q1, mom_y @ s_q, mom_z @ q1, mom_z @ s_q,
                              grad_wind @ q1])[:, keep])
    e = quarter  # the middle of a half step
    blocks += [e[:nm, :nm], e[:nm, nm:2 * nm], e[:nm, 2 * nm:3 * nm]]
    grams = [g[np.ix_(keep, keep)] for g in grams]
    mats = np.stack(blocks + checks)
    gram, rows = np.stack(grams), np.stack(rows)
    return StaticSteps(x_s, reg, fs, np.ascontiguousarray(mats), np.ascontiguousarray(b),
                       np.ascontiguousarray(gram), np.ascontiguousarray(rows), q_vel, grad_wind,
                       np.array([f0[o_e + 1], f0[o_e + 2]]))
