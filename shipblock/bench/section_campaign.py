"""Random campaign of the dock-section model (issue 29): random docks and motions, every run
checked, each against a run at much tighter tolerances.

Case ``i`` of seed ``s`` is drawn from its own generator (``numpy.random.default_rng((s, i))``),
so any case re-runs alone. A dock is a keel line with zero, one or two side lines (each moving
or fixed to the floor), with or without a steady wind, random geometry, caps and friction within
the ranges :mod:`shipblock.section.parameters` accepts; a motion is a random sum of sines in a
strong-motion envelope, with or without a vertical component. Every run is checked for

* no exception other than a refused dock (:class:`~shipblock.errors.ParameterError`, counted
  by reason);
* finite histories, summaries and energy terms (no NaN);
* its **energy balance**: ``|residual| <= ENERGY_TOL`` (relative to the largest energy exchanged)
  and no loss negative; a negative residual is an energy gain;
* every strip's friction inside its cone at the samples;
* **no event missed**: the same run at ``rtol = COMPARE_RTOL`` (1000 times tighter, and with
  Dormand-Prince throughout where the run takes exponential steps in the static regime; for every
  case, or every ``--compare-every``-th to reach more cases in the same time) must end
  with the same failure (kind, and time within ``FAILURE_TIME_TOL``), log the same kinds of
  event at the same places, and give the same demand parameters (largest relative difference
  of the summary, each with a floor of its own unit, below ``SUMMARY_TOL``).

Each case's record is written as one JSON line as soon as it is done (a campaign never loses a
finished case; ``--start`` continues one). Run::

    nice -n 19 python -m shipblock.bench.section_campaign --runs 2000 --seed 29 --out c.jsonl
    nice -n 19 python -m shipblock.bench.section_campaign --runs 2000 --compare-every 4 ...
    python -m shipblock.bench.section_campaign --seed 29 --case 17        # one case, in detail
    python -m shipblock.bench.section_campaign --summary c.jsonl          # summarise a file

``tests/test_section_campaign.py`` runs a seeded slice of it in the test suite.
"""

from __future__ import annotations

import argparse
import json
import math
import sys
import time
import traceback
from collections import Counter

import numpy as np

from shipblock.errors import ParameterError
from shipblock.section import Block, BlockLine, Cap, DockSection, Ship, Wind
from shipblock.section.simulate import DEFAULT_ATOL, DEFAULT_RTOL, SectionRunner, simulate_section
from shipblock.units import STANDARD_GRAVITY

__all__ = ["COMPARE_RTOL", "ENERGY_TOL", "campaign", "random_case", "run_case", "summarise"]

#: Largest |energy residual| accepted (relative to the largest energy exchanged).
ENERGY_TOL = 1e-5
#: Tolerances of the comparison run (1000 times tighter than the default).
COMPARE_RTOL, COMPARE_ATOL = 1e-9, 1e-12
#: Largest difference of the failure time from the tight run's [s].
FAILURE_TIME_TOL = 1e-3
#: Largest relative difference of a demand parameter from the tight run's.
SUMMARY_TOL = 1e-2
#: Summary values of the *total* cap force (the dashpot's included), whose peak is often a short
#: dashpot spike inside a step: held to ``SUMMARY_TOL`` with the others, and also reported apart
#: (``peak_total_load_diff``; taken at step ends and events only they were up to 16 % off, now
#: the kernel looks inside the steps).
PEAK_TOTAL_KEYS = ("peak_load_per_block", "capacity_ratio")
#: Floor of each kind of summary value below which differences are not relative (its unit).
_FLOORS = (("load_per_block", 1e2), ("pressure_ratio", 1e-5), ("pressure", 1e3),
           ("capacity_ratio", 1e-5), ("utilisation", 1e-4), ("crushing_set", 1e-7),
           ("lift_off_time", 1e-2), ("slip", 1e-5), ("sway", 1e-5), ("rotation", 1e-6),
           ("roll", 1e-6))


def _cap(rng) -> Cap:
    mu_s = rng.uniform(0.2, 0.7)
    return Cap(thickness=rng.uniform(0.05, 0.2), modulus=rng.uniform(0.3e9, 3e9),
               proportional_limit=rng.uniform(3e6, 10e6), damping_ratio=rng.uniform(0.05, 0.5),
               mu_s=mu_s, mu_k=mu_s * rng.uniform(0.7, 1.0), shear_ratio=rng.uniform(0.2, 1.0))


def _blocks_for(mass: float, blk: Block, rng) -> int:
    """Blocks enough for ``mass`` to press the weaker cap at 10-60 % of its proportional limit
    on average (as a docking plan sizes a line; the campaign would otherwise mostly draw docks
    whose caps crush at rest)."""
    sigma = min(blk.top.proportional_limit, blk.bottom.proportional_limit)
    area = 2.0 * blk.half_width * blk.length
    return max(2, math.ceil(mass * STANDARD_GRAVITY / (rng.uniform(0.1, 0.6) * sigma * area)))


def random_dock(rng) -> tuple[DockSection, dict]:
    """A random dock section and a short description of its kind."""
    keel_blk = Block(half_width=rng.uniform(0.4, 0.8), half_height=rng.uniform(0.45, 1.0),
                     length=rng.uniform(0.8, 1.5), top=_cap(rng), bottom=_cap(rng))
    beam = rng.uniform(4.0, 12.0)
    mass = rng.uniform(1e5, 2e6)
    ship = Ship(mass=mass, roll_inertia=mass * (0.35 * 2 * beam) ** 2,
                g_height=rng.uniform(1.5, 8.0), keel_half_width=rng.uniform(0.4, 1.2),
                half_beam=beam, g_offset=rng.uniform(-0.3, 0.3))
    n_sides = int(rng.integers(0, 3))
    starboard = [True, False] if n_sides == 2 else [bool(rng.uniform() < 0.5)] * n_sides
    sides, moving = [], []
    for stbd in starboard:
        sign = 1.0 if stbd else -1.0
        top = _cap(rng)
        b = rng.uniform(0.3, 0.7)
        hull = rng.uniform(0.0, 0.5)
        # gap (> 0) or interference at rest, within the cap's compression at its proportional
        # limit (a larger interference crushes the cap when the ship is set down)
        gap = rng.uniform(-0.3, 1.0) * top.thickness * top.proportional_limit / top.modulus
        blk = Block(half_width=b, half_height=keel_blk.half_height + (hull - gap) / 2,
                    length=rng.uniform(0.8, 1.5), top=top, bottom=_cap(rng))
        inner = max(keel_blk.half_width, ship.keel_half_width) + b + 0.05
        offset = rng.uniform(inner, max(inner, beam - b))
        moving.append(bool(rng.uniform() < 0.6))
        sides.append(BlockLine(block=blk, n_blocks=_blocks_for(0.3 * mass, blk, rng),
                               offset=sign * offset,
                               moving=moving[-1], hull_height=hull,
                               hull_slope=sign * rng.uniform(0.0, 0.3)))
    wind = None
    if rng.uniform() < 0.5:
        wind = Wind(height=rng.uniform(0.5, 1.5) * (ship.g_height + 2.0),
                    force=rng.uniform(-0.03, 0.03) * mass * STANDARD_GRAVITY)
    dock = DockSection(ship, BlockLine(block=keel_blk, n_blocks=_blocks_for(mass, keel_blk, rng)),
                       tuple(sides), wind=wind, n_springs=int(rng.integers(2, 8)))
    kind = {"sides": n_sides, "moving": moving, "wind": wind is not None,
            "n_springs": dock.n_springs}
    return dock, kind


def random_motion(rng) -> tuple[np.ndarray, np.ndarray, float, dict]:
    """A random record: four sines in an envelope, PGA 0.1-1 g, vertical 0 or up to 0.5 of it."""
    dt = 0.005
    duration = rng.uniform(2.0, 5.0)
    t = np.arange(0.0, duration, dt)
    pga = rng.uniform(0.1, 1.0) * STANDARD_GRAVITY
    h = sum(rng.normal() * np.sin(2 * np.pi * rng.uniform(0.5, 8.0) * t + rng.uniform(0, 2 * np.pi))
            for _ in range(4))
    env = np.exp(-((t - duration / 3) / (duration / 4)) ** 2)
    h = pga * env * h / np.max(np.abs(env * h))
    ratio = rng.uniform(0.0, 0.5) if rng.uniform() < 0.6 else 0.0
    v = ratio * np.roll(h, int(rng.integers(1, 50)))
    return h, v, dt, {"pga_g": pga / STANDARD_GRAVITY, "vertical_ratio": ratio,
                      "duration": duration}


def random_case(seed: int, case: int):
    """Case ``case`` of seed ``seed``: (dock, (h, v, dt), description); raises ParameterError for
    a dock the parameters refuse."""
    rng = np.random.default_rng((seed, case))
    dock, kind = random_dock(rng)
    h, v, dt, motion = random_motion(rng)
    return dock, (h, v, dt), {**kind, **motion}


def _floor(key: str) -> float:
    return next((f for name, f in _FLOORS if name in key), 1e-9)


def _checks(dock: DockSection, res) -> dict:
    """The invariants of one run: finite values, energy, losses, friction cone."""
    e = res.energy
    finite = (all(math.isfinite(x) for x in e.values())
              and all(np.all(np.isfinite(a)) for a in (res.ship, res.ship_velocity, res.ship_sway,
                                                       *res.lines.values(), *res.normal.values(),
                                                       *res.friction.values()))
              and all(math.isfinite(v) for v in res.summary.values()
                      if isinstance(v, float)))
    scale = max(abs(e["ground_work"]) + abs(e["wind_work"]), 1.0)
    negative = min(e["damping"], e["crushing"], e["friction"]) / scale
    cone = 0.0
    for name in res.normal:
        line, face = name.split("_")
        blk = dock.keel.block if line == "keel" else dock.sides[int(line[4:])].block
        n, f = res.normal[name], res.friction[name]
        over = np.abs(f) - getattr(blk, face).mu_s * n
        cone = max(cone, float(np.max(over / max(np.abs(n).max(), 1.0))))
    return {"finite": bool(finite), "residual": float(e["residual"]),
            "negative_loss": float(min(negative, 0.0)), "cone_excess": cone}


def _events(res) -> Counter:
    return Counter(f"{ev.kind}@{ev.where.split('[')[0]}" for ev in res.events)


def _compare(res, tight) -> dict:
    """Differences of a run from its tight-tolerance twin."""
    same_failure = res.failure == tight.failure
    dt_fail = (abs(res.failure_time - tight.failure_time)
               if res.failure and tight.failure else None)
    a, b = _events(res), _events(tight)
    missed = sorted(k for k in b if k not in a)
    extra = sorted(k for k in a if k not in b)
    worst, key, worst_peak = 0.0, None, 0.0
    for k, v in tight.summary.items():
        w = res.summary.get(k)
        if isinstance(v, float) and isinstance(w, float):
            d = abs(w - v) / max(abs(v), abs(w), _floor(k))
            if k.endswith(PEAK_TOTAL_KEYS):
                worst_peak = max(worst_peak, d)
            if d > worst:
                worst, key = d, k
    ok = (same_failure and (dt_fail is None or dt_fail <= FAILURE_TIME_TOL) and not missed
          and not extra and worst <= SUMMARY_TOL)
    return {"agrees": bool(ok), "same_failure": bool(same_failure), "tight_failure": tight.failure,
            "failure_time_diff": dt_fail, "missed_kinds": missed, "extra_kinds": extra,
            "events": sum(a.values()), "tight_events": sum(b.values()),
            "summary_diff": worst, "summary_key": key, "peak_total_load_diff": worst_peak}


def run_case(seed: int, case: int, compare: bool = True) -> dict:
    """Run and check one case; returns its record (JSON-serialisable)."""
    rec = {"seed": seed, "case": case}
    t0 = time.process_time()
    try:
        dock, (h, v, dt), desc = random_case(seed, case)
        rec.update(desc)
        runner = SectionRunner(dock)  # its static state serves the tight run too
        res = runner(h, v, dt)
    except ParameterError as err:
        rec.update(outcome="refused", reason=_reason(str(err)))
        return rec
    except Exception:  # a campaign records every other exception and goes on  # noqa: BLE001
        rec.update(outcome="exception", error=traceback.format_exc(limit=3))
        return rec
    rec.update(outcome="ran", failure=res.failure, failure_time=res.failure_time,
               cpu=time.process_time() - t0,
               steps=res.stats["accepted_steps"] + res.stats["exponential_steps"],
               settled_regimes=res.stats["settled_regimes"],
               **_checks(dock, res))
    if compare:
        try:
            # Dormand-Prince throughout: a second integrator, not only a tighter tolerance
            tight = SectionRunner(dock, initial_state=runner.initial_state, rtol=COMPARE_RTOL,
                                  atol=COMPARE_ATOL, exponential_steps=False)(h, v, dt)
        except Exception:  # noqa: BLE001
            rec.update(outcome="exception", error="tight run: " + traceback.format_exc(limit=3))
            return rec
        rec["compare"] = _compare(res, tight)
    return rec


def _reason(message: str) -> str:
    """A refusal's kind, from its message."""
    for key, reason in (("crush", "caps crush at rest"), ("would slide", "slides at rest"),
                        ("no static solution", "no static solution"),
                        ("unstable", "unstable static state")):
        if key in message:
            return reason
    return message.split(":")[0][:80]


def campaign(runs: int, seed: int = 29, start: int = 0, out=None, compare_every: int = 1) -> list:
    """Run cases ``start .. start + runs - 1`` of ``seed``, every ``compare_every``-th against its
    tight-tolerance twin (0: none); each record goes to ``out`` (a text stream) as a JSON line as
    soon as it is done. Returns the records."""
    records = []
    for case in range(start, start + runs):
        rec = run_case(seed, case, compare_every > 0 and case % compare_every == 0)
        records.append(rec)
        if out is not None:
            out.write(json.dumps(rec) + "\n")
            out.flush()
    return records


def _violations(rec: dict) -> list[str]:
    """The checks a ran case breaks."""
    out = []
    if not rec["finite"]:
        out.append("not finite")
    if abs(rec["residual"]) > ENERGY_TOL:
        out.append("energy gain" if rec["residual"] < 0 else "energy residual")
    if rec["negative_loss"] < -1e-9:
        out.append("negative loss")
    if rec["cone_excess"] > 1e-6:
        out.append("friction outside its cone")
    if "compare" in rec and not rec["compare"]["agrees"]:
        out.append("differs from the tight run")
    return out


def summarise(records: list) -> dict:
    """Counts of outcomes, refusals, failures and broken checks; the energy residuals'
    distribution; the cases that differ from their tight run."""
    ran = [r for r in records if r["outcome"] == "ran"]
    res = np.array([abs(r["residual"]) for r in ran]) if ran else np.zeros(1)
    gains = [r["residual"] for r in ran if r["residual"] < 0]
    compared = [r for r in ran if "compare" in r]
    differ = [r for r in compared if not r["compare"]["agrees"]]
    return {
        "cases": len(records),
        "outcomes": dict(Counter(r["outcome"] for r in records)),
        "refused": dict(Counter(r["reason"] for r in records if r["outcome"] == "refused")),
        "exceptions": [(r["case"], r["error"].splitlines()[-1]) for r in records
                       if r["outcome"] == "exception"],
        "failures": dict(Counter(r["failure"] or "none" for r in ran)),
        "kinds_ran": dict(Counter(f"{r['sides']} sides{' wind' if r['wind'] else ''}"
                                  for r in ran)),
        "violations": dict(Counter(v for r in ran for v in _violations(r))),
        "residual_percentiles": {p: float(np.percentile(res, p)) for p in (50, 90, 99, 100)},
        "largest_gain": float(-min(gains)) if gains else 0.0,
        "worst_cone_excess": max((r["cone_excess"] for r in ran), default=0.0),
        "compared": len(compared),
        "differ": len(differ),
        "differ_cases": [{"case": r["case"], **{k: r["compare"][k] for k in (
            "same_failure", "tight_failure", "failure_time_diff", "missed_kinds", "extra_kinds",
            "summary_diff", "summary_key")}, "failure": r["failure"]} for r in differ],
        "summary_diff_percentiles": {p: float(np.percentile(
            [r["compare"]["summary_diff"] for r in compared] or [0.0], p)) for p in (50, 90, 99,
                                                                                    100)},
        "peak_total_load_diff_percentiles": {p: float(np.percentile(
            [r["compare"].get("peak_total_load_diff", 0.0) for r in compared] or [0.0], p))
            for p in (50, 90, 99, 100)},
        "cpu_per_run": float(np.mean([r["cpu"] for r in ran])) if ran else 0.0,
    }


def _detail(seed: int, case: int) -> None:
    dock, (h, v, dt), desc = random_case(seed, case)
    print(json.dumps(desc), dock, sep="\n")
    for rtol, atol in ((DEFAULT_RTOL, DEFAULT_ATOL), (COMPARE_RTOL, COMPARE_ATOL)):
        res = simulate_section(dock, h, v, dt, rtol=rtol, atol=atol)
        print(f"rtol {rtol:g}: failure {res.failure} at {res.failure_time}, residual "
              f"{res.energy['residual']:.2e}, events {dict(_events(res))}")
        print(" ", {k: v for k, v in res.summary.items() if isinstance(v, float)})


def main(argv=None) -> int:
    p = argparse.ArgumentParser(prog="python -m shipblock.bench.section_campaign",
                                description=__doc__.splitlines()[0])
    p.add_argument("--runs", type=int, default=100, help="number of cases (default 100)")
    p.add_argument("--seed", type=int, default=29, help="seed of the draw (default 29)")
    p.add_argument("--start", type=int, default=0, help="first case (to continue a campaign)")
    p.add_argument("--out", help="append each case's record to this JSON-lines file")
    p.add_argument("--compare-every", type=int, default=1, metavar="N",
                   help="compare every N-th case with a run at tighter tolerances (default 1: "
                        "all; 0: none)")
    p.add_argument("--case", type=int, help="run one case in detail and stop")
    p.add_argument("--summary", help="summarise a JSON-lines file of records and stop")
    a = p.parse_args(argv)
    if a.runs < 0 or a.start < 0 or a.compare_every < 0:
        p.error("--runs, --start and --compare-every must be >= 0")
    if a.case is not None:
        _detail(a.seed, a.case)
        return 0
    if a.summary:
        with open(a.summary, encoding="utf-8") as f:
            records = [json.loads(line) for line in f if line.strip()]
    elif a.out:
        with open(a.out, "a", encoding="utf-8") as f:
            records = campaign(a.runs, a.seed, a.start, f, a.compare_every)
    else:
        records = campaign(a.runs, a.seed, a.start, None, a.compare_every)
    print(json.dumps(summarise(records), indent=1))
    return 0


if __name__ == "__main__":
    sys.exit(main())
