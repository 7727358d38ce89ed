"""Compare the plastic impact rule with the momentum rule (e_sys x theta_dot) on random runs.

The two rules agree when both interfaces stick at an impact. While an interface slips, the
plastic rule's ratio theta_dot+/theta_dot- is e_F = 1 - 2 (nm + 4M) B^2 / J_eff,F (J_eff,F the
rotation's inertia with the slipping momenta held, docs/theory/impact.rst), the momentum rule's
is e_sys. This script prints the coefficients for a few systems, then runs the random
campaign's cases (tests/tools/random_campaign.py) under both rules, with the system's own
restitution, and reports how often impacts happen while an interface slips and how much the
runs' peak rotation, residual slips and outcome differ::

    python tests/tools/compare_impact_rules.py --runs 20000 --seed 3
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[2]))

from shipblock import ShipBlockSystem  # noqa: E402
from shipblock.modes import EventKind  # noqa: E402
from tests.tools.random_campaign import cases, run_case  # noqa: E402


def plastic_coefficients(system: ShipBlockSystem) -> dict:
    """The plastic rule's theta_dot+/theta_dot- by slipping interfaces (uniform formula)."""
    M, nm = system.ship_mass, system.total_block_mass
    B, H = system.half_width, system.half_height
    nI = system.n_blocks * system.inertia
    K = np.array([[nm + M, -(nm + 2 * M) * H, M],
                  [-(nm + 2 * M) * H, nI + (nm + 4 * M) * (B * B + H * H), -2 * M * H],
                  [M, -2 * M * H, M]])
    out = {}
    for name, S in (("stick", []), ("ground slips", [0]), ("ship slips", [2]),
                    ("both slip", [0, 2])):
        j_eff = K[1, 1] - (K[1, S] @ np.linalg.solve(K[np.ix_(S, S)], K[S, 1]) if S else 0.0)
        out[name] = 1.0 - 2.0 * (nm + 4 * M) * B * B / j_eff
    return out


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--seed", type=int, default=3)
    parser.add_argument("--runs", type=int, default=5000)
    args = parser.parse_args(argv)
    print("theta_dot+/theta_dot- of the plastic rule (e_sys = the momentum rule's):")
    for bh in (0.2, 0.4):
        for mn in (0.02, 0.5, 1e6):
            m = 1000.0
            system = ShipBlockSystem(ship_mass=20 * m / mn, block_mass=m, n_blocks=20,
                                     half_width=bh, half_height=1.0, mu_s_ground=0.5,
                                     mu_k_ground=0.4, mu_s_ship=0.5, mu_k_ship=0.4)
            c = plastic_coefficients(system)
            print(f"  B/H {bh}, Mn {mn:g}: " + ", ".join(f"{k} {v:.3f}" for k, v in c.items()))
    n_rock = n_slip_runs = 0
    imp_total = imp_slip = 0
    changed_outcome = 0
    fail_mom = fail_pla = 0
    lower = 0
    d_peak, d_xb, d_xs = [], [], []
    for _, system, ax, ay, dt in cases(args.seed, args.runs):
        mom = system.replace(impact_rule="momentum", restitution=None)
        pla = system.replace(impact_rule="plastic", restitution=None)
        a = run_case(mom, ax, ay, dt)
        if a.summary["n_impacts"] == 0:
            continue
        b = run_case(pla, ax, ay, dt)
        n_rock += 1
        ev = a.events
        at_impact = ev.from_mode[(ev.kind_code == EventKind.IMPACT)
                                 | (ev.kind_code == EventKind.ROCKING_STOP)]
        imp_total += at_impact.size
        sliding = int(np.count_nonzero(at_impact != 3))
        imp_slip += sliding
        if a.failure != b.failure:
            changed_outcome += 1
        fail_mom += a.failure is not None
        fail_pla += b.failure is not None
        if sliding == 0:
            continue
        n_slip_runs += 1
        if a.failure is None and b.failure is None:
            pa, pb = a.summary["peak_rotation"], b.summary["peak_rotation"]
            d_peak.append(abs(pb - pa) / max(pa, 1e-300))
            lower += pb < pa
            for key, acc in (("residual_block_slip", d_xb), ("residual_ship_slip", d_xs)):
                va, vb = a.summary[key], b.summary[key]
                scale = max(abs(va), abs(vb))
                if scale > 1e-6:
                    acc.append(abs(vb - va) / scale)
    print(f"seed {args.seed}, {args.runs} cases: {n_rock} rock (momentum rule); "
          f"{imp_total} impacts, {imp_slip} ({100 * imp_slip / max(imp_total, 1):.1f} %) "
          f"while an interface slips, in {n_slip_runs} runs")
    print(f"outcome (failure or none) differs between the rules in {changed_outcome} runs; "
          f"runs that fail: {fail_mom} (momentum), {fail_pla} (plastic)")
    if d_peak:
        print(f"  the plastic rule's peak rotation is the lower in {lower} of {len(d_peak)}")
    for name, d in (("peak rotation", d_peak), ("residual block slip", d_xb),
                    ("residual ship slip", d_xs)):
        if d:
            q = np.percentile(d, [50, 90, 99])
            print(f"  {name}: relative difference median {q[0]:.2e}, 90 % {q[1]:.2e}, "
                  f"99 % {q[2]:.2e} (over {len(d)} surviving runs with sliding impacts)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
