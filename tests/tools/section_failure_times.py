"""Failure times of the dock section against the rigid solver's as the caps stiffen (issue 29).

Run: ``python tests/tools/section_failure_times.py [CASE ...]`` (prints the table quoted in
``docs/theory/section.md``, 'Rigid limit of failure times'); the cases are those of
``tests/test_section_failure_times.py``, plus a broadband record.
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[2]))
from shipblock.bench.section import record  # noqa: E402
from tests.test_section_failure_times import CASES, DT, failure_times  # noqa: E402

STIFFNESSES = (1e9, 1e10, 1e11, 1e12)


def main():
    # a broadband record (seeded filtered noise, 0.7 g): 13 rigid impacts before it overturns
    CASES["B/H 0.25, 100 t, noise (seed 1) 0.7 g"] = (
        0.25, 1.0, 1e5, lambda: record(duration=12.0, dt=DT, pga=0.7, seed=1)[0])
    chosen = [int(a) for a in sys.argv[1:]] or range(len(CASES))
    for case in [list(CASES)[i] for i in chosen]:
        t_rigid, impacts, times, residuals = failure_times(case, STIFFNESSES)
        err = np.abs(times - t_rigid)
        rates = np.log10(err[:-1] / err[1:])
        print(f"{case}: rigid {t_rigid:.5f} s after {impacts} impacts")
        for k, t, e, r, w in zip(STIFFNESSES, times, err, [np.nan, *rates], residuals, strict=True):
            print(f"  k={k:.0e}: {t:.5f} s, error {e:.2e} s, rate {r:.2f}, energy residual "
                  f"{w:.1e}", flush=True)


if __name__ == "__main__":
    main()
