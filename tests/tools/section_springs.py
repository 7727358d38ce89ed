"""Convergence of the dock section's demand parameters in the number of springs per cap.

The benchmark dock (``shipblock.bench.section.navy_dock``) under seeded records (the benchmark's
generator, seeds ``1..n_records``) at three PGA levels, run with ``n_springs`` = 3, 5, 7, 9 and
15; for each demand parameter and level, the geometric mean over the records of its ratio to the
15-spring run, with a bootstrap 90 % interval (what a fragility study's median sees), and the
median of the per-record relative differences.

Run: ``python tests/tools/section_springs.py [n_records] [out.jsonl]`` (prints the table; the
runs are appended to ``out.jsonl`` as they finish and read back from it, so an interrupted run
goes on where it stopped). Cost: ~0.5 s of one core per run, 15 runs per record.
"""

from __future__ import annotations

import dataclasses
import json
import sys
import time
from pathlib import Path

import numpy as np
from shipblock.bench.section import navy_dock, record

from shipblock.section.simulate import simulate_section

LEVELS = (0.25, 0.4, 0.55)
SPRINGS = (3, 5, 7, 9, 15)
KEYS = ("keel_peak_load_per_block", "keel_peak_top_pressure_ratio", "keel_peak_rotation",
        "keel_peak_slip", "side0_peak_load_per_block", "side0_peak_top_pressure_ratio",
        "side0_peak_rotation", "side0_peak_slip", "peak_sway", "peak_roll")


def _runs(n_records, path):
    done = {}
    if path.exists():
        for line in path.read_text().splitlines():
            row = json.loads(line)
            done[(row["seed"], row["pga"], row["n"])] = row
    dock = navy_dock()
    with path.open("a") as out:
        for seed in range(1, n_records + 1):
            for pga in LEVELS:
                h, v, dt = record(pga=pga, seed=seed)
                for n in SPRINGS:
                    if (seed, pga, n) in done:
                        continue
                    t0 = time.process_time()
                    res = simulate_section(dataclasses.replace(dock, n_springs=n), h, v, dt)
                    row = {"seed": seed, "pga": pga, "n": n, "cpu": time.process_time() - t0,
                           "events": res.stats["events"], "failure": res.summary["failure"],
                           "summary": {k: float(res.summary[k]) for k in KEYS}}
                    out.write(json.dumps(row) + "\n")
                    out.flush()
                    done[(seed, pga, n)] = row
    return done


def main(n_records=36, path="section_springs.jsonl"):
    runs = _runs(n_records, Path(path))
    ref = SPRINGS[-1]
    rng = np.random.default_rng(0)
    for pga in LEVELS:
        seeds = [s for s in range(1, n_records + 1)
                 if all(runs[(s, pga, n)]["failure"] is None for n in SPRINGS)]
        print(f"PGA {pga} g, {len(seeds)} records without failure: geometric mean of the ratio "
              f"to n = {ref} [bootstrap 90 %] (median relative difference)")
        for key in KEYS:
            cells = []
            for n in SPRINGS[:-1]:
                ratio = np.log([runs[(s, pga, n)]["summary"][key]
                                / runs[(s, pga, ref)]["summary"][key] for s in seeds])
                boot = [rng.choice(ratio, ratio.size).mean() for _ in range(2000)]
                lo, hi = np.exp(np.percentile(boot, [5, 95]))
                cells.append(f"n={n}: {np.exp(ratio.mean()):.3f} [{lo:.2f}, {hi:.2f}] "
                             f"({np.median(np.abs(np.expm1(ratio))):.3f})")
            print(f"  {key:30s} " + "  ".join(cells))
    for n in SPRINGS:
        rows = [r for r in runs.values() if r["n"] == n]
        print(f"n = {n}: median CPU {np.median([r['cpu'] for r in rows]):.3f} s, median events "
              f"{np.median([r['events'] for r in rows]):.0f}")


if __name__ == "__main__":
    main(*(int(a) if i == 0 else a for i, a in enumerate(sys.argv[1:])))
