"""Convergence of the dock-section model to the rigid solver as the caps stiffen (issue 29).

Run: ``python tests/tools/section_rigid_limit.py`` (prints the tables quoted in
``docs/theory/section.md``); the cases are those of ``tests/test_section_rigid_limit.py``.
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
from test_section_rigid_limit import G, rates, rocking_differences, sliding_differences  # noqa: E402


def main():
    dt = 0.002
    t = np.arange(0.0, 2.0, dt)
    ks = np.array([1e8, 1e9, 1e10, 1e11, 1e12])
    pulse = 0.5 * G * np.sin(2 * np.pi * 2 * t) * (t < 0.25)
    d, slip = sliding_differences(pulse, dt, ks)
    print("one-sided pulse, rigid slip", slip, "\n k, max |slip - rigid| [m], rate per decade")
    for k, x, r in zip(ks, d, [np.nan, *rates(d)], strict=True):
        print(f" {k:.0e} {x:.3e} {r:.2f}")
    t = np.arange(0.0, 1.6, dt)
    cyc = 0.4 * G * np.sin(2 * np.pi * 2 * t) * (t < 1.0)
    d, slip = sliding_differences(cyc, dt, ks)
    print("reversals, rigid peak slip", slip)
    for k, x, r in zip(ks, d, [np.nan, *rates(d)], strict=True):
        print(f" {k:.0e} {x:.3e} {r:.2f}")
    ks = ks[1:]
    onset, peak, ref = rocking_differences(ks)
    print("rocking (0.3 s), rigid peak rotation", ref, "\n k, |onset diff| [s], rate, |peak diff|"
          " [rad], rate")
    for k, a, ra, b, rb in zip(ks, onset, [np.nan, *rates(onset)], peak, [np.nan, *rates(peak)],
                               strict=True):
        print(f" {k:.0e} {a:.3e} {ra:.2f} {b:.3e} {rb:.2f}")


if __name__ == "__main__":
    main()
