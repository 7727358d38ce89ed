"""The random campaign: random systems and records through the solver, every run checked.

Each case is a random ship-block system (masses, block sizes, friction at both interfaces,
impact rule, restitution) under a random smoothed two-component record (or a horizontal one),
drawn from one seeded generator, so that case ``i`` of seed ``s`` is always the same run. Every
run is checked for

* its **energy balance**: the largest residual of :math:`\\Delta(T+V) = W_{in} - D - E_{imp}`
  over the samples, relative to the largest input work;
* the **sign of the impact loss**: under the ``"momentum"`` and ``"plastic"`` rules no impact
  or jam may gain kinetic energy (the ``"paper"`` rule can, by design);
* its **event sequence** (:func:`event_problems`): times in order, each event starting from the
  mode the one before ended in, each kind leaving a mode it can leave (an impact from a rocking
  mode, a slip arrest from a slipping one, ...), a failure last and matching the run's failure,
  the counts in the summary equal to the log's;
* its **constraints** (:func:`constraint_audit`, issue 32): every condition the mode holds (the
  static friction cone of each sticking interface, the blocks' moment criterion at rest, both
  normal forces positive) to the force tolerance of the mode selection, ``FORCE_TOL`` of the
  weight it is relative to: at every accepted step, sample and event as the kernel tracks it
  (the summary's ``least_constraint_margin``), and at every sample recomputed here from the
  histories (:attr:`~shipblock.result.SimulationResult.forces`).

Besides the general draw (stratum ``general``), ``--stratum`` draws from the regions where a
constraint is hardest to keep (:data:`STRATA`): slender blocks near the Painleve threshold of
either interface (``painleve``), ground friction just above the blocks' slenderness so that
they slide, then rock (``slide-rock``), and slender blocks on low friction at both interfaces,
rocking while both slip (``mode8``).

``tests/test_random_campaign.py`` runs a short campaign with a fixed seed in the test suite.
This script runs long ones and lists the runs that break a check or whose residual exceeds
a threshold, with the numbers to re-run them::

    python tests/tools/random_campaign.py --runs 200000 --seed 1
    python tests/tools/random_campaign.py --seed 1 --case 4711        # one case, in detail
    python tests/tools/random_campaign.py --runs 200000 --compare 1e-10,1e-12
    python tests/tools/random_campaign.py --runs 200000 --stratum painleve --seed 3

``--compare RTOL,ATOL`` re-runs every run above the residual threshold with those tolerances
and reports its residual there and whether its event sequence is the same: the residuals of
the default tolerance that exceed 1e-6 of the input work converge with the tolerances (see
``docs/theory/solver.md``, "Energy balance").
"""

from __future__ import annotations

import argparse
import sys
import time
import warnings
from dataclasses import dataclass, field

import numpy as np

from shipblock import ShipBlockSystem, simulate
from shipblock.modes import MODE_FLAGS, EventKind
from shipblock.modes import Failure
from shipblock.solver import DEFAULT_ATOL, DEFAULT_RTOL, DEFAULT_ZENO_OMEGA
from shipblock.solver import _kernel as K
from shipblock.solver._layout import FORCE_TOL

#: Share of each impact rule among the random systems.
RULES = (("momentum", 0.6), ("paper", 0.2), ("plastic", 0.2))

_ROCKING = {m for m in range(1, 9) if MODE_FLAGS[m, 1]}
_GROUND_SLIP = {m for m in range(1, 9) if MODE_FLAGS[m, 0]}
_SHIP_SLIP = {m for m in range(1, 9) if MODE_FLAGS[m, 2]}
_FAILURES = {EventKind.SEPARATION: "separation", EventKind.OVERTURNING: "overturning",
             EventKind.SOLVER_ERROR: "solver_error"}


def random_case(rng: np.random.Generator):
    """One random case: ``(system, ax, ay, dt)`` [SI units; ``ay`` may be None].

    Block height 0.2-1.5 m and width 0.1-1.5 times it, ship 1 t to 10,000 t on 1-299 blocks of
    0.1-5 t, friction 0.05-0.9 (kinetic 0.5-1 times static), restitution from the system in
    70 % of the momentum and paper cases; 300-1500 samples at 0.002, 0.005 or 0.01 s of white
    noise of 0.5-15 m/s^2 smoothed by a Hann window of 3-30 samples, vertical in 70 %.
    """
    H = rng.uniform(0.2, 1.5)
    mu1, mu2 = rng.uniform(0.05, 0.9, 2)
    u = rng.random()
    rule = RULES[0][0] if u < RULES[0][1] else (
        RULES[1][0] if u < RULES[0][1] + RULES[1][1] else RULES[2][0])
    restitution = None if rng.random() < 0.7 else rng.uniform(0.0, 1.0)
    system = ShipBlockSystem(
        ship_mass=10 ** rng.uniform(3, 7), block_mass=rng.uniform(100, 5000),
        n_blocks=int(rng.integers(1, 300)), half_width=H * rng.uniform(0.1, 1.5),
        half_height=H, mu_s_ground=mu1, mu_k_ground=mu1 * rng.uniform(0.5, 1.0),
        mu_s_ship=mu2, mu_k_ship=mu2 * rng.uniform(0.5, 1.0), impact_rule=rule,
        restitution=None if rule == "plastic" else restitution)
    n = int(rng.integers(300, 1500))
    dt = float(rng.choice([0.002, 0.005, 0.01]))
    kernel = np.hanning(int(rng.integers(3, 30)))
    kernel /= kernel.sum()
    amp = rng.uniform(0.5, 15.0)
    ax = np.convolve(rng.normal(0, amp, n), kernel, mode="same")
    ay = (np.convolve(rng.normal(0, amp * rng.uniform(0, 0.8), n), kernel, mode="same")
          if rng.random() < 0.7 else None)
    return system, ax, ay, dt


def _record(rng, amp_lo=0.5, amp_hi=15.0, vertical=0.7):
    """A random smoothed record: ``(ax, ay, dt)`` as in :func:`random_case`."""
    n = int(rng.integers(300, 1500))
    dt = float(rng.choice([0.002, 0.005, 0.01]))
    kernel = np.hanning(int(rng.integers(3, 30)))
    kernel /= kernel.sum()
    amp = rng.uniform(amp_lo, amp_hi)
    ax = np.convolve(rng.normal(0, amp, n), kernel, mode="same")
    ay = (np.convolve(rng.normal(0, amp * rng.uniform(0, 0.8), n), kernel, mode="same")
          if rng.random() < vertical else None)
    return ax, ay, dt


def _slender_system(rng, slenderness, mu_ground, mu_ship, mass_ratio):
    """A system of blocks ``B/H = slenderness`` under a ship ``nm/M = mass_ratio``, with the
    static friction ``mu_ground``, ``mu_ship`` (kinetic 0.7-1 times it) and a random rule."""
    H = rng.uniform(0.3, 1.5)
    block_mass = rng.uniform(100, 5000)
    n_blocks = int(rng.integers(1, 300))
    u = rng.random()
    rule = RULES[0][0] if u < RULES[0][1] else (
        RULES[1][0] if u < RULES[0][1] + RULES[1][1] else RULES[2][0])
    restitution = None if rng.random() < 0.7 else rng.uniform(0.0, 1.0)
    return ShipBlockSystem(
        ship_mass=n_blocks * block_mass / mass_ratio, block_mass=block_mass, n_blocks=n_blocks,
        half_width=H * slenderness, half_height=H, mu_s_ground=mu_ground,
        mu_k_ground=mu_ground * rng.uniform(0.7, 1.0), mu_s_ship=mu_ship,
        mu_k_ship=mu_ship * rng.uniform(0.7, 1.0), impact_rule=rule,
        restitution=None if rule == "plastic" else restitution)


def painleve_thresholds(slenderness, mass_ratio, kappa=1.0 / 3.0):
    r"""Friction above which a slipping interface makes the rocking's effective inertia negative
    at theta = 0 (the Painleve regime): ``(mu_ground, mu_ship)``.

    From the denominators of the mode-6 and mode-7 closed forms
    (``/work/shared/reference/physics-notes.md`` section 2, with
    :math:`\psi` against the rocking): :math:`\mu_1^* = (\bar s^2 + M_n(\kappa(M_n+1)+1)/
    (M_n+2)^2)/(\bar s c)` and :math:`\mu_2^* = (\bar s^2 + M_n(1+\kappa)/4)/(\bar s c)`,
    :math:`c = H/R`, :math:`\bar s = B/R`.
    """
    R = np.hypot(1.0, slenderness)
    c, sn = 1.0 / R, slenderness / R
    mn = mass_ratio
    mu1 = (sn * sn + mn * (kappa * (mn + 1) + 1) / (mn + 2) ** 2) / (sn * c)
    mu2 = (sn * sn + mn * (1 + kappa) / 4) / (sn * c)
    return mu1, mu2


def stratum_case(rng: np.random.Generator, stratum: str):
    """One random case of a stratum (see :data:`STRATA`): ``(system, ax, ay, dt)``."""
    if stratum == "general":
        return random_case(rng)
    if stratum == "painleve":
        # slender blocks under a heavy ship, each friction within 25 % of its threshold
        slender = rng.uniform(0.08, 0.35)
        mass_ratio = 10 ** rng.uniform(-3, -0.5)
        mu1, mu2 = painleve_thresholds(slender, mass_ratio)
        system = _slender_system(rng, slender, min(mu1 * rng.uniform(0.8, 1.25), 1.5),
                                 min(mu2 * rng.uniform(0.8, 1.25), 1.5), mass_ratio)
        return (system, *_record(rng, 1.0, 12.0))
    if stratum == "slide-rock":
        # kinetic ground friction just above B/H: the blocks slide, then rock (paper eq. 16);
        # the ship held by more friction, or not
        slender = rng.uniform(0.1, 0.6)
        mu_k1 = slender * rng.uniform(0.95, 1.3)
        system = _slender_system(rng, slender, mu_k1 * rng.uniform(1.0, 1.4),
                                 mu_k1 * rng.uniform(0.8, 2.0), 10 ** rng.uniform(-3, 1))
        system = system.replace(mu_k_ground=min(mu_k1, system.mu_s_ground))
        return (system, *_record(rng, 1.0, 12.0))
    if stratum == "mode8":
        # slender blocks on low friction at both interfaces: they rock while both slip
        slender = rng.uniform(0.05, 0.3)
        system = _slender_system(rng, slender, slender * rng.uniform(0.8, 2.0),
                                 slender * rng.uniform(0.8, 2.0), 10 ** rng.uniform(-2.5, 1))
        return (system, *_record(rng, 2.0, 15.0, vertical=0.5))
    raise ValueError(f"--stratum: unknown stratum {stratum!r}; one of {', '.join(STRATA)}")


#: The strata of ``--stratum``.
STRATA = ("general", "painleve", "slide-rock", "mode8")


def cases(seed: int, n: int, stratum: str = "general"):
    """The first ``n`` cases of ``seed`` in a stratum, as ``(index, system, ax, ay, dt)``."""
    rng = np.random.default_rng(seed)
    for i in range(n):
        yield (i, *stratum_case(rng, stratum))


def event_problems(res) -> list[str]:
    """What is wrong with a run's event log (an empty list when nothing is)."""
    ev = res.events
    kind, frm, to, t = ev.kind_code, ev.from_mode, ev.to_mode, ev.time
    out = []
    if len(t) == 0:
        return ["no events"]
    if t[0] != 0.0 or frm[0] != 0 or kind[0] not in (EventKind.START, *_FAILURES):
        out.append("the log does not begin with the start at t = 0")
    if np.any(np.diff(t) < 0.0):
        out.append("event times not in order")
    if np.any(frm[1:] != to[:-1]):
        j = int(np.argmax(frm[1:] != to[:-1])) + 1
        out.append(f"event {j} starts from mode {frm[j]}, the one before ended in {to[j - 1]}")
    for j in range(1, len(t)):
        k, f, m = int(kind[j]), int(frm[j]), int(to[j])
        bad = None
        if k in (EventKind.IMPACT, EventKind.ROCKING_STOP, EventKind.OVERTURNING):
            bad = f not in _ROCKING
        elif k == EventKind.UPLIFT:
            bad = f in _ROCKING or (m not in _ROCKING and j + 1 == len(t))
        elif k == EventKind.GROUND_SLIP_STOP:
            bad = f not in _GROUND_SLIP
        elif k == EventKind.GROUND_SLIP_START:
            bad = f in _GROUND_SLIP
        elif k == EventKind.SHIP_SLIP_STOP:
            bad = f not in _SHIP_SLIP
        elif k == EventKind.SHIP_SLIP_START:
            bad = f in _SHIP_SLIP
        elif k == EventKind.JAM:
            bad = f not in _GROUND_SLIP | _SHIP_SLIP
        if bad:
            out.append(f"event {j} ({EventKind(k).name.lower()}) from mode {f} to {m}")
    last = int(kind[-1])
    failure = _FAILURES.get(last)
    if res.failure != failure:
        out.append(f"failure {res.failure!r} but the last event is {EventKind(last).name.lower()}")
    if failure is not None and (to[-1] != 0 or np.any(np.isin(kind[:-1], list(_FAILURES)))):
        out.append("a failure that is not the last event, or not into mode 0")
    n_imp = int(np.count_nonzero((kind == EventKind.IMPACT) | (kind == EventKind.ROCKING_STOP)))
    if n_imp != res.summary["n_impacts"]:
        out.append(f"{n_imp} impacts in the log, {res.summary['n_impacts']} in the summary")
    n_jam = int(np.count_nonzero(kind == EventKind.JAM))
    if n_jam != res.summary["n_jams"]:
        out.append(f"{n_jam} jams in the log, {res.summary['n_jams']} in the summary")
    return out


#: Rounding allowed beyond ``FORCE_TOL`` in the kernel's margin (event functions of order 1,
#: compared at differences of 1e-10: an event found on its level is there to some 1e-16) [-].
KERNEL_ROUNDING = 1e-14
#: Rounding allowed beyond ``FORCE_TOL`` when the audit recomputes the margins at the samples
#: (the general equations there, the kernel's reduced ones in its steps) [-].
AUDIT_ROUNDING = 1e-12


def sample_margins(res) -> dict:
    """The least margin of each held condition over the samples, from the histories.

    Each margin is scaled as the solver's event functions: the friction cones and normal forces
    by the weight they bear (``(nm + M) g`` at the ground, ``M g`` at the ship), the moment
    criterion :math:`B(f_y + F_y) - H|f_x + F_x|` by the weight times ``R``; a condition counts
    only at the samples whose mode holds it (1 elsewhere).
    """
    system = res.system
    forces = res.forces  # per block
    n = system.n_blocks
    mode = np.clip(res.mode, 0, 8)
    live = res.mode > 0
    weight = (system.total_block_mass + system.ship_mass) * system.g / n
    ship_weight = system.ship_mass * system.g / n
    fy, fx = forces.ground_normal, forces.ground_friction
    Fy, Fx = forces.ship_normal, forces.ship_friction
    with np.errstate(invalid="ignore"):
        margins = {
            "ground stick": np.where(live & (MODE_FLAGS[mode, 0] == 0),
                                     (system.mu_s_ground * fy - np.abs(fx)) / weight, 1.0),
            "ship stick": np.where(live & (MODE_FLAGS[mode, 2] == 0),
                                   (system.mu_s_ship * Fy - np.abs(Fx)) / ship_weight, 1.0),
            "rest": np.where(live & (MODE_FLAGS[mode, 1] == 0),
                             (system.half_width * (fy + Fy) - system.half_height * np.abs(fx + Fx))
                             / (weight * system.half_diagonal), 1.0),
            "ground contact": np.where(live, fy / weight, 1.0),
            "ship contact": np.where(live, Fy / ship_weight, 1.0),
        }
    # a sample whose forces cannot be computed (NaN) breaks the audit too
    return {name: float(np.min(np.where(np.isnan(m), -np.inf, m))) for name, m in margins.items()}


def constraint_audit(res) -> list[str]:
    """The constraint violations of a run (an empty list when there are none).

    Every condition a mode holds must hold to ``FORCE_TOL`` (the tolerance of the mode
    selection, relative to the weight) at each accepted step and sample and up to each event,
    as the kernel tracks it (``least_constraint_margin``, to ``FORCE_TOL`` +
    ``KERNEL_ROUNDING``; the event's own function is left out, at its level there to within
    the root's 1e-12 s; the mode an event enters is judged by the mode selection itself,
    1e-8 s after it), and at each sample as recomputed from the histories (to ``FORCE_TOL`` +
    ``AUDIT_ROUNDING``).
    """
    out = []
    least = res.summary["least_constraint_margin"]
    if not least >= -FORCE_TOL - KERNEL_ROUNDING:
        out.append(f"a held condition violated by {-least:.3e} of the weight in the kernel")
    for name, m in sample_margins(res).items():
        if not m >= -FORCE_TOL - AUDIT_ROUNDING:
            out.append(f"{name} violated by {-m:.3e} of the weight at a sample")
    return out


@dataclass
class RunCheck:
    """The checks of one run."""

    index: int
    residual: float  #: largest |energy residual| / largest |input work| [-]
    input_work: float  #: largest |input work| [J]
    impact_gain: float  #: largest gain of the impact-loss account over a sample, / input work [-]
    problems: list = field(default_factory=list)
    failure: str | None = None
    n_jams: int = 0
    n_impacts: int = 0
    rule: str = ""
    events: tuple = ()
    peak_ratio: float = 0.0  #: peak rotation / critical angle [-]
    least_margin: float = 1.0  #: least margin of a held condition (the kernel's) [-]
    violations: list = field(default_factory=list)  #: :func:`constraint_audit`
    mode_time: tuple = ()  #: time in modes 1..8 [s]


def check_run(index, system, res) -> RunCheck:
    """Energy residual, impact-loss sign and event sequence of one run."""
    ok = np.isfinite(res.energy.residual)
    scale = float(np.abs(res.energy.input_work[ok]).max())
    resid = float(np.abs(res.energy.residual[ok]).max()) / scale if scale > 0 else 0.0
    gain = 0.0
    if scale > 0 and ok.sum() > 1:
        gain = max(0.0, -float(np.diff(res.energy.impact[ok]).min()) / scale)
    problems = event_problems(res)
    if system.impact_rule != "paper" and gain > 1e-9:
        problems.append(f"an impact or jam gained {gain:.2e} of the input work")
    if res.failure not in (None, "separation", "overturning"):
        problems.append(f"failure {res.failure}")
    violations = constraint_audit(res)
    problems.extend(violations)
    return RunCheck(index, resid, scale, gain, problems, res.failure, res.summary["n_jams"],
                    res.summary["n_impacts"], system.impact_rule,
                    tuple(res.events.kind_code.tolist()), res.summary["peak_rotation_ratio"],
                    res.summary["least_constraint_margin"], violations,
                    tuple(res.summary[f"time_in_mode_{m}"] for m in range(1, 9)))


def kernel_summary(system, ax, ay, dt) -> np.ndarray:
    """The compiled kernel's summary vector of one case, without histories (as a batch runs
    it), at the default tolerances: ``--fast`` audits the kernel's constraint margin
    (``S_MARGIN``) and failure on it, several times faster than :func:`run_case` and
    :func:`check_run`."""
    summary = np.empty(K.N_SUMMARY)
    has_ay = ay is not None
    K.run(system.to_parameter_vector(), ax, ay if has_ay else ax, has_ay, 1.0, 1.0, float(dt),
          DEFAULT_RTOL, DEFAULT_ATOL, DEFAULT_ZENO_OMEGA, False, *K.no_histories(), summary,
          np.zeros(6))
    return summary


def fast_audit(args) -> int:
    """``--fast``: the kernel's constraint audit (and no solver error) over many runs."""
    t0 = time.perf_counter()
    least, n_violating, n_errors, n_fail = (np.inf, -1), 0, 0, {}
    mode_runs = np.zeros(8, dtype=int)
    bad = []
    jam_runs = 0
    for i, system, ax, ay, dt in cases(args.seed, args.runs, args.stratum):
        summary = kernel_summary(system, ax, ay, dt)
        margin = summary[K.S_MARGIN]
        failure = int(summary[K.S_FAILURE])
        n_fail[failure] = n_fail.get(failure, 0) + 1
        mode_runs += summary[K.S_MODE_TIME:K.S_MODE_TIME + 8] > 0
        jam_runs += summary[K.S_N_JAMS] > 0
        if margin < least[0]:
            least = (margin, i)
        violating = not margin >= -FORCE_TOL - KERNEL_ROUNDING
        n_violating += violating
        n_errors += failure == Failure.SOLVER_ERROR
        if violating or failure == Failure.SOLVER_ERROR:
            bad.append(f"case {i}: least margin {margin:.3e}, failure {failure}")
    print(f"seed {args.seed}, stratum {args.stratum}, kernel audit: {args.runs} runs in "
          f"{time.perf_counter() - t0:.0f} s; failures (code: runs) {n_fail}")
    print("runs entering modes 1..8: " + ", ".join(str(v) for v in mode_runs)
          + f"; runs with jams {jam_runs}")
    print(f"constraint audit: {n_violating} runs violating a held condition beyond FORCE_TOL "
          f"= {FORCE_TOL:g}; least margin {least[0]:.3e} of the weight (case {least[1]}); "
          f"{n_errors} runs failing with a solver error")
    for line in bad:
        print("  " + line)
    return 1 if bad else 0


def run_case(system, ax, ay, dt, rtol=None, atol=None):
    """Simulate one case (default tolerances unless given)."""
    kw = {}
    if rtol is not None:
        kw["rtol"] = rtol
    if atol is not None:
        kw["atol"] = atol
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # a run that warns is a finding
        return simulate(system, ax, ay, dt, **kw)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--runs", type=int, default=10000)
    parser.add_argument("--stratum", default="general", choices=STRATA,
                        help="region of the draw (default: general)")
    parser.add_argument("--fast", action="store_true",
                        help="the kernel's constraint audit only, without histories")
    parser.add_argument("--case", type=int, default=None, help="run one case and print it")
    parser.add_argument("--threshold", type=float, default=1e-6,
                        help="residual / input work above which a run is listed")
    parser.add_argument("--compare", default=None, metavar="RTOL,ATOL",
                        help="re-run the listed runs with these tolerances, e.g. 1e-10,1e-12")
    args = parser.parse_args(argv)
    if args.case is not None:
        for i, system, ax, ay, dt in cases(args.seed, args.case + 1, args.stratum):
            if i == args.case:
                res = run_case(system, ax, ay, dt)
                rc = check_run(i, system, res)
                print(system)
                print(f"dt {dt} s, {ax.size} samples, vertical {ay is not None}")
                print(f"failure {res.failure} at {res.failure_time}, residual {rc.residual:.3e}, "
                      f"impacts {rc.n_impacts}, jams {rc.n_jams}, problems {rc.problems}, "
                      f"least constraint margin {rc.least_margin:.3e}")
                for e in res.events:
                    print(f"  {e.time:.9f} {e.kind} {e.from_mode} -> {e.to_mode}")
        return 0
    if args.fast:
        return fast_audit(args)
    t0 = time.perf_counter()
    n_fail = {}
    worst = (0.0, -1)
    listed, broken, jam_runs = [], [], 0
    least = (np.inf, -1)
    n_violating = 0
    mode_time = np.zeros(8)
    mode_runs = np.zeros(8, dtype=int)
    for i, system, ax, ay, dt in cases(args.seed, args.runs, args.stratum):
        res = run_case(system, ax, ay, dt)
        rc = check_run(i, system, res)
        n_fail[rc.failure] = n_fail.get(rc.failure, 0) + 1
        jam_runs += rc.n_jams > 0
        n_violating += bool(rc.violations)
        if rc.least_margin < least[0]:
            least = (rc.least_margin, i)
        mode_time += rc.mode_time
        mode_runs += np.asarray(rc.mode_time) > 0
        if rc.residual > worst[0]:
            worst = (rc.residual, i)
        if rc.problems:
            broken.append(rc)
        if rc.residual > args.threshold:
            line = (f"case {i}: residual {rc.residual:.3e} of W = {rc.input_work:.3e} J, "
                    f"rule {rc.rule}, impacts {rc.n_impacts}, jams {rc.n_jams}, "
                    f"peak rotation {rc.peak_ratio:.1e} theta_c")
            if args.compare is not None:
                rtol, atol = (float(v) for v in args.compare.split(","))
                tight = run_case(system, ax, ay, dt, rtol=rtol, atol=atol)
                rt = check_run(i, system, tight)
                line += (f"; at rtol {rtol:g}, atol {atol:g}: residual {rt.residual:.3e}, "
                         f"same events {rt.events == rc.events}")
            listed.append(line)
    elapsed = time.perf_counter() - t0
    print(f"seed {args.seed}, stratum {args.stratum}: {args.runs} runs in {elapsed:.0f} s; "
          f"failures {n_fail}; runs with jams {jam_runs}; worst residual {worst[0]:.3e} "
          f"(case {worst[1]})")
    print("runs entering modes 1..8: " + ", ".join(str(v) for v in mode_runs)
          + "; time in them [s]: " + ", ".join(f"{v:.4g}" for v in mode_time))
    print(f"constraint audit: {n_violating} runs violating a held condition beyond FORCE_TOL "
          f"= {FORCE_TOL:g}; least margin {least[0]:.3e} of the weight (case {least[1]})")
    print(f"{len(listed)} runs with residual above {args.threshold:g}:")
    for line in listed:
        print("  " + line)
    print(f"{len(broken)} runs breaking a check:")
    for rc in broken:
        print(f"  case {rc.index}: {rc.problems}")
    return 1 if broken else 0


if __name__ == "__main__":
    sys.exit(main())
