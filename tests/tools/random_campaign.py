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
  the counts in the summary equal to the log's.

``tests/test_random_campaign.py`` runs a short campaign with a fixed seed in the test suite.
This script runs long ones and lists the runs that break a check or whose residual exceeds
a threshold, with the numbers to re-run them::

    python tests/tools/random_campaign.py --runs 200000 --seed 1
    python tests/tools/random_campaign.py --seed 1 --case 4711        # one case, in detail
    python tests/tools/random_campaign.py --runs 200000 --compare 1e-10,1e-12

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


def cases(seed: int, n: int):
    """The first ``n`` cases of ``seed``, as ``(index, system, ax, ay, dt)``."""
    rng = np.random.default_rng(seed)
    for i in range(n):
        yield (i, *random_case(rng))


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
    return RunCheck(index, resid, scale, gain, problems, res.failure, res.summary["n_jams"],
                    res.summary["n_impacts"], system.impact_rule,
                    tuple(res.events.kind_code.tolist()), res.summary["peak_rotation_ratio"])


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
    parser.add_argument("--case", type=int, default=None, help="run one case and print it")
    parser.add_argument("--threshold", type=float, default=1e-6,
                        help="residual / input work above which a run is listed")
    parser.add_argument("--compare", default=None, metavar="RTOL,ATOL",
                        help="re-run the listed runs with these tolerances, e.g. 1e-10,1e-12")
    args = parser.parse_args(argv)
    if args.case is not None:
        for i, system, ax, ay, dt in cases(args.seed, args.case + 1):
            if i == args.case:
                res = run_case(system, ax, ay, dt)
                rc = check_run(i, system, res)
                print(system)
                print(f"dt {dt} s, {ax.size} samples, vertical {ay is not None}")
                print(f"failure {res.failure} at {res.failure_time}, residual {rc.residual:.3e}, "
                      f"impacts {rc.n_impacts}, jams {rc.n_jams}, problems {rc.problems}")
                for e in res.events:
                    print(f"  {e.time:.9f} {e.kind} {e.from_mode} -> {e.to_mode}")
        return 0
    t0 = time.perf_counter()
    n_fail = {}
    worst = (0.0, -1)
    listed, broken, jam_runs = [], [], 0
    for i, system, ax, ay, dt in cases(args.seed, args.runs):
        res = run_case(system, ax, ay, dt)
        rc = check_run(i, system, res)
        n_fail[rc.failure] = n_fail.get(rc.failure, 0) + 1
        jam_runs += rc.n_jams > 0
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
    print(f"seed {args.seed}: {args.runs} runs in {elapsed:.0f} s; failures {n_fail}; "
          f"runs with jams {jam_runs}; worst residual {worst[0]:.3e} (case {worst[1]})")
    print(f"{len(listed)} runs with residual above {args.threshold:g}:")
    for line in listed:
        print("  " + line)
    print(f"{len(broken)} runs breaking a check:")
    for rc in broken:
        print(f"  case {rc.index}: {rc.problems}")
    return 1 if broken else 0


if __name__ == "__main__":
    sys.exit(main())
