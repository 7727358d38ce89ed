"""Accuracy against cost of the dock-section integrator (issue 29): the benchmark dock and
record run at several tolerances, errors of the demand parameters against a run at rtol 1e-11.

Run: ``python tests/tools/section_tradeoff.py`` (prints a table).
"""

from __future__ import annotations

import time

import numpy as np
from shipblock.bench.section import navy_dock, record

from shipblock.section.simulate import simulate_section

KEYS = ("keel_peak_load_per_block", "side1_peak_load_per_block", "peak_sway", "peak_roll",
        "side1_peak_slip", "keel_friction_utilisation_bottom")


def main(duration=20.0):
    dock = navy_dock()
    h, v, dt = record()
    n = int(duration / dt)
    h, v = h[:n], v[:n]
    ref = simulate_section(dock, h, v, dt, rtol=1e-11, atol=1e-14)
    print(f"{'rtol':>8} {'atol':>8} {'steps':>7} {'rejected':>8} {'cpu s':>7} {'energy':>9} "
          + " ".join(f"{k[:18]:>18}" for k in KEYS))
    for rtol, atol in ((1e-4, 1e-7), (1e-5, 1e-8), (1e-6, 1e-9), (1e-7, 1e-9), (1e-8, 1e-11),
                       (1e-9, 1e-12)):
        t0 = time.process_time()
        res = simulate_section(dock, h, v, dt, rtol=rtol, atol=atol)
        cpu = time.process_time() - t0
        errs = [abs(res.summary[k] - ref.summary[k]) / max(abs(ref.summary[k]), 1e-300)
                for k in KEYS]
        print(f"{rtol:8.0e} {atol:8.0e} {res.stats['accepted_steps']:7d} "
              f"{res.stats['rejected_steps']:8d} {cpu:7.3f} {res.energy['residual']:9.1e} "
              + " ".join(f"{e:18.2e}" for e in errs))
    print("reference steps", ref.stats, "peak values", {k: ref.summary[k] for k in KEYS})
    print("max |sway - ref|", np.max(np.abs(res.ship_sway - ref.ship_sway)))


if __name__ == "__main__":
    main()
