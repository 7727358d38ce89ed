"""Running the dock-section model: :func:`simulate_section`, its result, and a batch entry point.

The same shape as :func:`shipblock.simulate`: a system (:class:`DockSection`), a ground motion
(a :class:`~shipblock.records.motion.GroundMotion`, or horizontal and vertical arrays with ``dt``) and
options; a result with histories at the samples, located events, the engineering demand
parameters of every support line and of the ship, the failure (if any), the energy balance and
:meth:`SectionResult.to_dataset`.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace

import numpy as np

from shipblock import checks
from shipblock.errors import ParameterError, ParameterTypeError
from shipblock.section import _kernel as K
from shipblock.section.exponential import StaticSteps, settled_steps, static_steps
from shipblock.section.model import (Assembly, InitialState, NoStaticSolution, SlidesAtRest,
                                     assemble, check_static_state, static_state, sunk_state,
                                     tangent_coordinates)
from shipblock.section.parameters import DockSection

__all__ = ["EVENT_NAMES", "FAILURE_NAMES", "SectionResult", "SectionRunner", "rest_state",
           "simulate_section",
           "simulate_section_batch"]

#: Default relative and absolute tolerances of the integration (SI units of each state).
DEFAULT_RTOL = 1e-6
DEFAULT_ATOL = 1e-9
#: Default lift of the ship off every support at which the run stops as a separation [m].
DEFAULT_SEPARATION_HEIGHT = 0.02
#: Most events in one run before it stops as stalled.
DEFAULT_MAX_EVENTS = 1_000_000
#: exponential steps for a regime other than the static one are made once the dock has spent this
#: long in it without an event [s], for at most this many regimes per run (session 20's
#: measurement: docs/theory/section.md, *Integrator*)
SETTLE_SECONDS = 1.0
SETTLED_REGIMES = 2
#: How long :func:`rest_state` leaves a dock to settle under gravity alone [s], sampled at [s].
REST_SECONDS = 20.0
REST_DT = 0.005

EVENT_NAMES = {
    K.EV_START: "start", K.EV_CLOSE: "spring_closes", K.EV_DETACH: "spring_detaches",
    K.EV_CRUSH: "crushing_starts", K.EV_UNLOAD: "crushing_ends", K.EV_SLIP: "slip",
    K.EV_STICK: "stick", K.EV_OVERTURN: "block_line_overturns", K.EV_SLID_OFF: "slid_off_keel",
    K.EV_TIP: "ship_tips", K.EV_SEPARATION: "separation", K.EV_INVALID: "out_of_validity",
    K.EV_STALL: "stalled",
}
FAILURE_NAMES = {k: v for k, v in EVENT_NAMES.items() if k >= K.EV_OVERTURN}


@dataclass(frozen=True)
class SectionEvent:
    """One located event: its time [s], kind (:data:`EVENT_NAMES`) and where (a line and face,
    or the ship)."""

    time: float
    kind: str
    where: str


@dataclass(frozen=True)
class SectionResult:
    """Response of a dock section to one ground motion.

    Attributes
    ----------
    time : ndarray
        Sample times [s] up to the end of the run (the failure, if any).
    ship : ndarray, shape (n, 3)
        Ship's ``(y_G, z_G, phi)`` from its static position [m, m, rad].
    lines : dict
        Per moving line name (``"keel"``, ``"side0"``, ``"side1"``) its ``(y, z, theta)`` from
        the static position, shape (n, 3).
    normal, friction : dict
        Per strip name (``"keel_top"``, ``"keel_bottom"``, ...) the normal and tangential force per
        block [N], shape (n,).
    ship_velocity : ndarray, shape (n, 3)
        Ship's ``(v_y, v_z, omega)`` [m/s, m/s, rad/s].
    ship_sway : ndarray
        Horizontal offset of the keel's centre from the keel block's top centre, from its static
        value [m].
    events : list of SectionEvent
    failure : str or None
    failure_time : float or None
    summary : dict
        The demand parameters (see :func:`simulate_section`).
    energy : dict
        Terms of the energy balance at the end [J] and its relative residual.
    stats : dict
        Accepted and rejected Dormand-Prince steps, exponential steps, regimes settled in (for
        which the run made exponential steps besides the static regime), events.
    plastic_set : ndarray
        Permanent set of every spring at the end [m] (strips in :attr:`strip_names` order, the
        section's ``n_springs`` springs each).
    strip_names : list of str
    """

    time: np.ndarray
    ship: np.ndarray
    ship_velocity: np.ndarray
    lines: dict
    normal: dict
    friction: dict
    ship_sway: np.ndarray
    events: list
    failure: str | None
    failure_time: float | None
    summary: dict
    energy: dict
    stats: dict
    plastic_set: np.ndarray
    strip_names: list
    section: DockSection = field(repr=False)

    def to_dataset(self):
        """The histories and the summary as an :class:`xarray.Dataset` with units and long names."""
        import xarray as xr  # heavy, and only needed here

        data = {
            "ship_sway": (("time",), self.ship_sway, {"units": "m", "long_name":
                          "keel centre relative to the keel block top, from rest"}),
            "ship_heave": (("time",), self.ship[:, 1], {"units": "m", "long_name":
                           "heave of the ship's centre of gravity from rest"}),
            "ship_roll": (("time",), self.ship[:, 2], {"units": "rad", "long_name":
                          "roll of the ship from rest (positive lifts starboard)"}),
        }
        for name, q in self.lines.items():
            data[f"{name}_slip"] = (("time",), q[:, 0], {"units": "m", "long_name":
                                    f"{name} line: horizontal displacement from rest"})
            data[f"{name}_rotation"] = (("time",), q[:, 2], {"units": "rad", "long_name":
                                        f"{name} line: rotation from rest"})
        for name, n in self.normal.items():
            data[f"{name}_normal"] = (("time",), n, {"units": "N", "long_name":
                                      f"{name}: normal force per block"})
            data[f"{name}_friction"] = (("time",), self.friction[name], {"units": "N",
                                        "long_name": f"{name}: tangential force per block"})
        attrs = {k: (v if v is not None else "none") for k, v in self.summary.items()
                 if isinstance(v, int | float | str | None)}
        return xr.Dataset(data, coords={"time": ("time", self.time, {"units": "s"})},
                          attrs=attrs)


def _inputs(motion, vertical, dt):
    if all(hasattr(motion, a) for a in ("horizontal", "vertical", "dt")):
        if vertical is not None or dt is not None:
            raise ParameterError("give vertical= and dt= only with arrays, not with a GroundMotion")
        ah = checks.acceleration(motion.horizontal, "motion.horizontal")
        av = motion.vertical
        av = np.zeros_like(ah) if av is None else checks.acceleration(av, "motion.vertical")
        return ah, av, checks.time_step(motion.dt, "motion.dt")
    ah = checks.acceleration(motion, "motion")
    if dt is None:
        raise ParameterError("dt is required with an array motion")
    av = np.zeros_like(ah) if vertical is None else checks.acceleration(vertical, "vertical")
    if av.shape != ah.shape:
        raise ParameterError(f"vertical must have as many samples as motion ({ah.size}), got "
                             f"{av.size}")
    return ah, av, checks.time_step(dt, "dt")


def _strip_names(asm: Assembly) -> list[str]:
    names = []
    for j in range(asm.n_strips):
        li = int(asm.strip_line[j])
        line = "keel" if li == 0 else f"side{li - 1}"
        names.append(f"{line}_{'top' if asm.strip_top[j] else 'bottom'}")
    return names


def energy_terms(asm: Assembly, x, reg, dp, dc0, tc0, fs, t) -> dict:
    """Kinetic, potential and elastic energy of a state, and the crushing work done so far [J]."""
    nb, ns = asm.n_bodies, asm.n_strips
    nsp = asm.spring_f.shape[0]
    v = x[3 * nb:6 * nb].reshape(nb, 3)
    kinetic = 0.5 * float(np.sum(asm.mass * (v[:, 0] ** 2 + v[:, 1] ** 2)
                                 + asm.inertia * v[:, 2] ** 2))
    potential = float(np.sum(asm.mass * asm.section.g * x[1:3 * nb:3]))
    delta, ddot, vt, pos = np.zeros(nsp), np.zeros(nsp), np.zeros(ns), np.zeros((nsp, 2))
    K.kinematics(x, nb, asm.strip_f, asm.strip_i, asm.spring_f, delta, ddot, vt, pos)
    k, fy = asm.spring_f[:, K.PF_K], asm.spring_f[:, K.PF_FY]
    elastic = 0.0
    crush = 0.0
    for i in range(nsp):
        if reg[i] == K.R_ELASTIC:
            elastic += 0.5 * k[i] * (delta[i] - dp[i]) ** 2
            crush += fy[i] * dp[i]
        elif reg[i] == K.R_CRUSH:
            elastic += 0.5 * fy[i] ** 2 / k[i]
            crush += fy[i] * (delta[i] - fy[i] / k[i])
        else:
            rem = K.cap_surface(k[i], asm.spring_f[i, K.PF_C], dp[i], dc0[i], tc0[i], t) - dp[i]
            elastic += 0.5 * k[i] * rem * rem
            crush += fy[i] * dp[i]
    u = x[6 * nb:6 * nb + ns]
    stick = float(np.sum(np.where(fs == K.F_STICK, 0.5 * asm.strip_f[:, K.SF_KT] * u * u, 0.0)))
    return {"kinetic": kinetic, "potential": potential, "elastic": elastic + stick,
            "crushing": crush}


def simulate_section(section: DockSection, motion, vertical=None, dt: float | None = None, *,
                     rtol: float = DEFAULT_RTOL, atol: float = DEFAULT_ATOL,
                     separation_height: float = DEFAULT_SEPARATION_HEIGHT,
                     max_events: int = DEFAULT_MAX_EVENTS,
                     initial_velocity=None, exponential_steps: bool = True) -> SectionResult:
    """Simulate a dock section under a horizontal (across the dock) and vertical ground motion.

    The run starts from the elastic static state (:func:`rest_state`)
    and integrates the section's equations (:mod:`shipblock.section.model`) with a Dormand-Prince
    5(4) method, steps ending on the input samples (the input is linear between them); while every
    spring and strip is in the regime it has at rest, one exponential step per sample instead
    (:mod:`shipblock.section.exponential`: the cap modes integrated exactly), and the same in a
    regime the dock has settled in after strong motion (``SETTLE_SECONDS`` without an event, no
    cap crushing, no strip slipping; matrices made then, for at most ``SETTLED_REGIMES``
    regimes per run: :func:`~shipblock.section.exponential.settled_steps`). Every
    change of a contact law (a spring closing, letting go, starting or ending to crush; a strip
    slipping or sticking) and every failure is located in time on the step's dense output; the
    run stops at the first failure.

    Parameters
    ----------
    section : DockSection
    motion : GroundMotion or array_like
        A :class:`~shipblock.records.motion.GroundMotion` (its horizontal, vertical and dt), or the
        horizontal acceleration [m/s^2] (positive to starboard) at ``k dt``.
    vertical : array_like, optional
        Vertical acceleration [m/s^2] (positive up), with an array ``motion``.
    dt : float, optional
        Sample interval [s], with an array ``motion``.
    rtol, atol : float
        Error tolerances of the integration (relative in [1e-12, 1e-2]; absolute [m, m/s] in
        [1e-15, 1e-3]).
    separation_height : float
        Lift of the ship off every support that counts as separation [m], in (0, 1]; a shorter
        lift-off (milliseconds after a rocking impact) is reported, not a failure.
    max_events : int
        Most located events before the run stops as ``"stalled"``.
    initial_velocity : array_like, optional
        Velocities ``(v_y, v_z, omega)`` of every body (the ship, then the moving lines) added to
        the static state at t = 0 [m/s, rad/s], shape (n_bodies, 3); within 10 m/s and 10 rad/s.
    exponential_steps : bool
        Take exponential steps in the static and settled regimes (default); False: Dormand-Prince
        throughout
        (the same response to the tolerance, 3-4 times the CPU on a quiet record).

    Returns
    -------
    SectionResult
        ``summary`` holds, per line name (``keel``, ``side0``, ``side1``) with the prefix
        ``<line>_``: ``peak_load_per_block`` [N] and ``capacity_ratio``; ``peak_top_pressure``,
        ``peak_bottom_pressure`` [Pa] and their ratios to the proportional limit
        (``..._pressure_ratio``; the elastic part of the cap force, the dashpot's excluded);
        ``crushing_set`` [m] (largest permanent set of a spring); ``friction_utilisation_top``,
        ``..._bottom`` (peak ``|F_t| / N``); ``peak_slip``, ``residual_slip`` [m]; ``peak_rotation``,
        ``residual_rotation`` [rad]; ``lift_off_time`` [s] (time the top strip carried nothing,
        at the samples). For the ship: ``peak_sway``, ``residual_sway`` [m] (relative to the keel
        line), ``peak_roll``, ``residual_roll`` [rad]; ``failure`` and ``failure_time``.

    Raises
    ------
    ParameterTypeError, ParameterError
        For a section that is not a :class:`DockSection`, bad records or options (naming them), a
        section without a static state or whose caps crush at rest.
    """
    if not isinstance(section, DockSection):
        raise ParameterTypeError(f"section must be a DockSection, got {type(section).__name__}")
    ah, av, dt = _inputs(motion, vertical, dt)
    return SectionRunner(section, rtol=rtol, atol=atol, separation_height=separation_height,
                         max_events=max_events, initial_velocity=initial_velocity,
                         exponential_steps=exponential_steps)._run(ah, av, dt)


def _options(rtol=DEFAULT_RTOL, atol=DEFAULT_ATOL, separation_height=DEFAULT_SEPARATION_HEIGHT,
             max_events=DEFAULT_MAX_EVENTS, initial_velocity=None, exponential_steps=True):
    """The checked options of :func:`simulate_section` (a batch's too: an unknown one is a
    TypeError)."""
    rtol = checks.real(rtol, "rtol", low=1e-12, high=1e-2)
    atol = checks.real(atol, "atol", low=1e-15, high=1e-3)
    separation_height = checks.real(separation_height, "separation_height", low=0.0, high=1.0,
                                    low_open=True, units="m")
    max_events = checks.whole(max_events, "max_events", low=1, high=10**9)
    if not isinstance(exponential_steps, (bool, np.bool_)):
        raise ParameterTypeError(f"exponential_steps must be True or False, got "
                                 f"{exponential_steps!r}")
    return (rtol, atol, separation_height, max_events, initial_velocity,
            bool(exponential_steps))


def _run(section, asm, init, ah, av, dt, rtol, atol, max_events, initial_velocity,
         steps: StaticSteps | None, final: dict | None = None):
    """:func:`simulate_section` from the checked inputs, the assembly, its static state and the
    static regime's exponential steps for ``dt`` (None: none; a batch makes them once);
    ``final``, a dict, receives the final state (``"x"``, ``"regime"``, ``"friction"``)."""
    nb, ns = asm.n_bodies, asm.n_strips
    nsp = asm.spring_f.shape[0]
    x = init.x.copy()
    reg = init.regime.copy()
    dp = np.zeros(nsp)
    dc0 = np.zeros(nsp)
    tc0 = np.zeros(nsp)
    fs = init.friction.copy()
    if initial_velocity is not None:
        v0 = checks.as_real_array(initial_velocity, "initial_velocity", "an array of velocities")
        if v0.shape != (nb, 3) or not np.all(np.abs(v0) <= 10.0):
            raise ParameterError(f"initial_velocity must have shape ({nb}, 3) (the ship, then the "
                                 f"moving lines) with entries within 10 m/s or rad/s, got "
                                 f"shape {v0.shape}")
        x[3 * nb:6 * nb] += v0.ravel()
        if section.roll_held:
            x[3 * nb + 2] = 0.0
    e0 = energy_terms(asm, x, reg, dp, dc0, tc0, fs, 0.0)
    n = ah.size
    t_end = (n - 1) * dt
    hist_x = np.zeros((n, x.size))
    hist_n = np.zeros((n, ns))
    hist_t = np.zeros((n, ns))
    log = min(max_events + 2, 4 * n + 64)
    ev_t, ev_kind, ev_index = np.zeros(log), np.zeros(log, np.int64), np.zeros(log, np.int64)
    acc = np.zeros(K.N_ACC)
    peak_fe, peak_fn = np.zeros(nsp), np.zeros(nsp)
    peak_util, peak_n = np.zeros(ns), np.zeros(ns)
    if steps is None:
        nm = 6 * nb + ns
        steps = StaticSteps(x, reg, fs, np.zeros((12, 0, 0)), np.zeros((0, 2)),
                            np.zeros((2, 0, 0)), np.zeros((2, 5, 0)), np.zeros((0, 0)),
                            np.zeros(nm), np.zeros(2))
        use_static = False
    else:
        use_static = True
    # the kernel stops when the dock has settled in a regime other than the static one (after
    # strong motion, caps left open): its matrices are made at the state reached and the run goes
    # on (at most SETTLED_REGIMES times: each costs about as much as the static regime's)
    t, n_ev, n_hist, h = 0.0, 0, 0, 0.0
    n_acc = n_rej = n_static = n_settled = 0
    while True:
        settle_after = (int(round(SETTLE_SECONDS / dt))
                        if use_static and n_settled < SETTLED_REGIMES else 0)
        t, n_ev, failure, n_hist, acc_i, rej_i, static_i, h = K.run(
            x, reg, dp, dc0, tc0, fs, nb, asm.mass, asm.inertia, asm.strip_f, asm.strip_i,
            asm.spring_f, asm.opt, asm.theta_c, ah, av, dt, t_end, rtol, atol, dt, max_events,
            hist_x, hist_n, hist_t, ev_t, ev_kind, ev_index, acc, peak_fe, peak_fn, peak_util,
            peak_n, use_static, steps.x_s, steps.regime, steps.friction, steps.mats, steps.b,
            steps.gram, steps.rows, steps.q_vel, steps.wind_grad, steps.rates0, t, n_ev, n_hist,
            h, settle_after)
        n_acc, n_rej, n_static = n_acc + acc_i, n_rej + rej_i, n_static + static_i
        if failure != K.STOP_SETTLED:
            break
        n_settled += 1
        steps = settled_steps(asm, x, reg, fs, dp, dt)
    if final is not None:
        final.update(x=x.copy(), regime=reg.copy(), friction=fs.copy())
    e1 = energy_terms(asm, x, reg, dp, dc0, tc0, fs, t)
    o = 6 * nb + ns
    w_ground, w_wind, d_damp, d_fric = x[o:o + 4]
    energy = {
        "ground_work": float(w_ground), "wind_work": float(w_wind),
        "damping": float(d_damp + acc[K.A_CAP_RELAX]),
        "friction": float(d_fric + acc[K.A_FRIC_EVENT]),
        "crushing": e1["crushing"],
        "kinetic_change": e1["kinetic"] - e0["kinetic"],
        # from the height changes (not a difference of two large energies)
        "potential_change": float(np.sum(asm.mass * section.g * (x[1:3 * nb:3]
                                                                 - init.x[1:3 * nb:3]))),
        "elastic_change": e1["elastic"] - e0["elastic"],
    }
    mech = energy["kinetic_change"] + energy["potential_change"] + energy["elastic_change"]
    losses = energy["damping"] + energy["friction"] + energy["crushing"]
    work = energy["ground_work"] + energy["wind_work"]
    # relative to the largest energy exchanged (the kinetic energy at either end, the work, the
    # losses or the change of the potential or elastic energy)
    scale = max(abs(work), losses, e0["kinetic"], e1["kinetic"], abs(energy["potential_change"]),
                abs(energy["elastic_change"]), 1e-300)
    energy["residual"] = (work - mech - losses) / scale
    return _result(section, asm, init, hist_x[:n_hist], hist_n[:n_hist], hist_t[:n_hist], dt, t,
                   ev_t[:min(n_ev, log)], ev_kind[:min(n_ev, log)], ev_index[:min(n_ev, log)],
                   failure, dp, peak_fe, peak_fn, peak_util, peak_n, energy,
                   {"accepted_steps": int(n_acc), "rejected_steps": int(n_rej),
                    "exponential_steps": int(n_static), "settled_regimes": n_settled,
                    "events": int(n_ev)})


def _result(section, asm, init, hx, hn, ht, dt, t_final, ev_t, ev_kind, ev_index, failure, dp,
            peak_fe, peak_fn, peak_util, peak_n, energy, stats) -> SectionResult:
    nb = asm.n_bodies
    names = _strip_names(asm)
    time = np.arange(hx.shape[0]) * dt
    x0 = init.x
    ship = hx[:, 0:3] - x0[0:3]
    lines = {}
    for b, li in enumerate(asm.body_line, start=1):
        lines["keel" if li == 0 else f"side{li - 1}"] = hx[:, 3 * b:3 * b + 3] - x0[3 * b:3 * b + 3]

    def keel_offset(q):
        ky = q[..., 0] + np.cos(q[..., 2]) * asm.opt[K.O_SHIP_KY] - np.sin(q[..., 2]) * asm.opt[
            K.O_SHIP_KZ]
        ty = q[..., 3] - np.sin(q[..., 5]) * asm.opt[K.O_KEEL_TOP_Z]
        return ky - ty

    sway = keel_offset(hx) - keel_offset(x0)
    n_blocks = np.array([section.lines[li].n_blocks for li in asm.strip_line])
    normal = {nm: hn[:, j] / n_blocks[j] for j, nm in enumerate(names)}
    friction = {nm: ht[:, j] / n_blocks[j] for j, nm in enumerate(names)}
    summary = {}
    for li, line in enumerate(section.lines):
        lname = "keel" if li == 0 else f"side{li - 1}"
        cap_top, cap_bottom = line.block.top, line.block.bottom
        for j in range(asm.n_strips):
            if asm.strip_line[j] != li:
                continue
            a, c = asm.strip_i[j, K.SI_FIRST], asm.strip_i[j, K.SI_COUNT]
            springs = slice(a, a + c)
            pressure = float(np.max(peak_fe[springs] / (line.n_blocks
                                                        * asm.spring_f[springs, K.PF_AREA])))
            face = "top" if asm.strip_top[j] else "bottom"
            cap = cap_top if asm.strip_top[j] else cap_bottom
            summary[f"{lname}_peak_{face}_pressure"] = pressure
            summary[f"{lname}_peak_{face}_pressure_ratio"] = pressure / cap.proportional_limit
            summary[f"{lname}_crushing_set_{face}"] = float(np.max(dp[springs]))
            summary[f"{lname}_friction_utilisation_{face}"] = float(peak_util[j])
            if asm.strip_top[j]:
                load = float(peak_n[j]) / line.n_blocks
                summary[f"{lname}_peak_load_per_block"] = load
                summary[f"{lname}_capacity_ratio"] = load / line.block.capacity
                summary[f"{lname}_lift_off_time"] = float(np.count_nonzero(hn[:, j] <= 0.0) * dt)
        q = lines.get(lname)
        if q is None:
            q = np.zeros((max(hx.shape[0], 1), 3))
        summary[f"{lname}_peak_slip"] = float(np.max(np.abs(q[:, 0]), initial=0.0))
        summary[f"{lname}_residual_slip"] = float(q[-1, 0]) if q.shape[0] else 0.0
        summary[f"{lname}_peak_rotation"] = float(np.max(np.abs(q[:, 2]), initial=0.0))
        summary[f"{lname}_residual_rotation"] = float(q[-1, 2]) if q.shape[0] else 0.0
    summary["peak_sway"] = float(np.max(np.abs(sway), initial=0.0))
    summary["residual_sway"] = float(sway[-1]) if sway.size else 0.0
    summary["peak_roll"] = float(np.max(np.abs(ship[:, 2]), initial=0.0))
    summary["residual_roll"] = float(ship[-1, 2]) if ship.shape[0] else 0.0
    fail = FAILURE_NAMES.get(int(failure)) if failure else None
    summary["failure"] = fail
    summary["failure_time"] = float(t_final) if fail else None
    events = []
    for tt, kd, ix in zip(ev_t, ev_kind, ev_index, strict=True):
        kind = EVENT_NAMES.get(int(kd), str(int(kd)))
        if kd in (K.EV_CLOSE, K.EV_DETACH, K.EV_CRUSH, K.EV_UNLOAD):
            j = int(np.searchsorted(asm.strip_i[:, K.SI_FIRST], ix, side="right") - 1)
            where = f"{names[j]}[{ix - asm.strip_i[j, K.SI_FIRST]}]"
        elif kd in (K.EV_SLIP, K.EV_STICK):
            where = names[int(ix)]
        elif kd == K.EV_OVERTURN:
            li = asm.body_line[int(ix) - 1]
            where = "keel" if li == 0 else f"side{li - 1}"
        else:
            where = "ship"
        events.append(SectionEvent(float(tt), kind, where))
    return SectionResult(time, ship, hx[:, 3 * nb:3 * nb + 3].copy(), lines, normal, friction, sway, events, fail,
                         summary["failure_time"], summary, energy, stats, dp.copy(), names,
                         section)


def rest_state(asm: Assembly) -> InitialState:
    """The static state a run starts from: :func:`~shipblock.section.model.static_state`, and
    where that finds no solution or one that needs more friction than a strip's ``mu_s``, the
    same solve from where the dock comes to rest when left under gravity (and the steady wind)
    alone, each strip's stick spring measured from where it stuck.

    Powell's method on the piecewise smooth static residual stalls from the stress-free start
    on docks that have a static solution, and the solution with every loaded strip sticking
    from the touching position can need more friction than a side cap has where the landing
    slips it a little and it then holds. Of the random campaign's first 600 cases (seed 29), 64
    docks were refused as having no static solution and 80 as sliding at rest; left to settle
    for ``REST_SECONDS`` from the same start (the model's own run under no ground motion,
    Dormand-Prince throughout), 50 and 75 of them have a static state this way, each kept still
    by the dynamics; 13 tip off their supports, 1 crushes a cap, 5 are still refused.

    The settling is a full run (0.3-4 s of CPU): a caller that runs one section many times
    solves this once and hands it to :class:`SectionRunner` (``initial_state``), as the study
    model does (:class:`shipblock.models.section.SectionSystem` carries it).

    Parameters
    ----------
    asm : Assembly
        The section's assembly (its separation height stops the settling run at a separation).

    Returns
    -------
    InitialState
        Its ``settled_separation_height`` that of ``asm`` when the dock was left to settle,
        else None.

    Raises
    ------
    NoStaticSolution, SlidesAtRest
        Where neither solve finds an admissible state (the first solve's error): the message
        adds what the dock did when left to settle (the failure and its time, or that it came
        to rest or was still moving, and why the solve from there failed).
    ParameterError
        As :func:`~shipblock.section.model.static_state` (unstable, caps crushing at rest).
    """
    try:
        return static_state(asm)
    except (NoStaticSolution, SlidesAtRest) as exc:
        first = exc
    start = sunk_state(asm)
    n = int(round(REST_SECONDS / REST_DT)) + 1
    final = {}
    res = _run(asm.section, asm, start, np.zeros(n), np.zeros(n), REST_DT, DEFAULT_RTOL,
               DEFAULT_ATOL, DEFAULT_MAX_EVENTS, None, None, final)
    if res.failure is not None:
        raise type(first)(f"{first}; left under gravity alone from the stress-free position, "
                          f"it fails ({res.failure.replace('_', ' ')}) at t = "
                          f"{res.failure_time:.2f} s") from None
    nb, ns = asm.n_bodies, asm.n_strips
    rest, u = final["x"][:3 * nb], final["x"][6 * nb:6 * nb + ns]
    # what each strip slipped on the way: its tangential displacement less its stick spring's
    # stretch (a strip off its cap at the end starts again unstretched)
    slip = tangent_coordinates(asm, rest) - tangent_coordinates(asm, asm.q0)
    sticks = final["friction"] == K.F_STICK
    slip[sticks] -= u[sticks]
    try:
        state = static_state(asm, start=rest, slip=slip)
    except (NoStaticSolution, SlidesAtRest) as exc:
        speed = float(np.abs(final["x"][3 * nb:6 * nb]).max())
        did = (f"is still moving after {REST_SECONDS:g} s (up to {speed:.2g} m/s or rad/s)"
               if speed > 1e-6 else "comes to rest")
        raise type(first)(f"{first}; left under gravity alone it {did}, and the static "
                          f"solution from there fails too: {exc}") from None
    return replace(state, settled_separation_height=float(asm.opt[K.O_SEP]))


class SectionRunner:
    """Runs of one dock section under many motions, with what does not depend on the motion
    made once: the assembly, the static state and the exponential steps' matrices (per sample
    interval). ``runner(motion, vertical=None, dt=None)`` returns what :func:`simulate_section`
    returns with the same options.

    Parameters
    ----------
    section : DockSection
    initial_state : InitialState, optional
        The section's static state, :func:`rest_state` of its assembly solved once by the
        caller (a dock that must settle first costs a full run to solve); checked against this
        runner's assembly (:func:`~shipblock.section.model.check_static_state`: solved for an
        equal section, settled at the same ``separation_height``), so the runs equal those from
        the runner's own solve. Default: solved here.
    **options
        The options of :func:`simulate_section` (checked here, an unknown one a TypeError).

    Raises
    ------
    ParameterTypeError, ParameterError
        As :func:`simulate_section`; for an ``initial_state`` that is not this section's
        static state at these options.
    """

    def __init__(self, section: DockSection, *, initial_state: InitialState | None = None,
                 **options):
        if not isinstance(section, DockSection):
            raise ParameterTypeError(f"section must be a DockSection, got "
                                     f"{type(section).__name__}")
        (self._rtol, self._atol, separation, self._max_events, self._v0,
         self._expo) = _options(**options)
        self.section = section
        self._asm = assemble(section, separation)
        self._init = (rest_state(self._asm) if initial_state is None
                      else check_static_state(self._asm, initial_state))
        self._steps = {}

    @property
    def initial_state(self) -> InitialState:
        """The static state every run starts from."""
        return self._init

    def __call__(self, motion, vertical=None, dt: float | None = None) -> SectionResult:
        ah, av, dt = _inputs(motion, vertical, dt)
        return self._run(ah, av, dt)

    def _run(self, ah, av, dt) -> SectionResult:
        steps = None
        if self._expo:
            if dt not in self._steps:
                self._steps[dt] = static_steps(self._asm, self._init, dt)
            steps = self._steps[dt]
        return _run(self.section, self._asm, self._init, ah, av, dt, self._rtol, self._atol,
                    self._max_events, self._v0, steps)


def simulate_section_batch(section: DockSection, motions, **options) -> list[dict]:
    """Summaries of one section under many motions (each a GroundMotion, or a tuple
    ``(horizontal, vertical, dt)``), run one after the other; every entry is the ``summary`` of
    :func:`simulate_section` plus its ``energy_residual``. A bad motion or option raises before
    any run; the static state is solved once for all of them (the same results as one call per
    motion)."""
    cases = []
    for i, motion in enumerate(motions):
        if isinstance(motion, tuple):
            if len(motion) != 3:
                raise ParameterError(f"motions[{i}] must be (horizontal, vertical, dt)")
            cases.append(_inputs(motion[0], motion[1], motion[2]))
        else:
            cases.append(_inputs(motion, None, None))
    if not isinstance(section, DockSection):
        raise ParameterTypeError(f"section must be a DockSection, got {type(section).__name__}")
    _options(**options)
    out = []
    if not cases:
        return out
    # the assembly, its static state (an iterative solve of ~12 ms) and the exponential steps'
    # matrices (~25 ms) do not depend on the motion: made once for the batch
    runner = SectionRunner(section, **options)
    for ah, av, dt in cases:
        res = runner._run(ah, av, dt)
        out.append({**res.summary, "energy_residual": res.energy["residual"]})
    return out
