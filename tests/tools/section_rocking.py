"""Rocking impacts of the dock-section model: measured restitution vs damping and stiffness, and
forced rocking with a ship on top against the rigid model's plastic rule (issue 29).

Run: ``python tests/tools/section_rocking.py`` (prints the tables quoted in
``docs/theory/section.md``, 'Rocking impacts'); the cases are those of
``tests/test_section_rocking.py``.
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[2]))
from tests.test_section_rocking import HOUSNER, forced_rocking, free_rocking  # noqa: E402

STIFFNESSES = (1e9, 1e10, 1e11, 1e12)


def airborne(res, n_springs=2):
    """Spans [s] during which every keel_top spring is open (the ship off the keel line)."""
    closed = {f"keel_top[{i}]": True for i in range(n_springs)}
    spans, start = [], None
    for ev in res.events:
        if ev.where in closed and ev.kind in ("spring_closes", "spring_detaches"):
            closed[ev.where] = ev.kind == "spring_closes"
            if not any(closed.values()) and start is None:
                start = ev.time
            elif any(closed.values()) and start is not None:
                spans.append(ev.time - start)
                start = None
    return spans


def main():
    zetas = (0.3, 1.0, 2.0, 5.0, 20.0)
    for ship, omega0 in ((10.0, 0.4), (2e5, 0.2)):
        print(f"free rocking, ship {ship:g} kg: e of impacts 1 and 2 (Housner {HOUSNER:.5f})")
        for k in STIFFNESSES:
            cells = []
            for z in zetas:
                e, e_sys, res = free_rocking(k, z, ship_mass=ship, omega0=omega0)
                cells.append(f"z={z:g}: {e[0]:.5f} {e[1]:.5f} air {len(airborne(res))}")
            print(f" k={k:.0e} e_sys={e_sys:.5f} | " + " | ".join(cells), flush=True)
    print("forced rocking with a 200 t ship vs impact_rule='plastic' (3 s, 1.5 Hz, 0.5 g)")
    for z in (0.5, 2.0, 5.0):
        for k in STIFFNESSES:
            diff, peak, impacts, detach, peak_error = forced_rocking(k, z)
            print(f" zeta={z:g} k={k:.0e}: max ||theta|-|theta_rigid|| {diff:.3e} rad "
                  f"(rigid peak {peak:.5f}, {impacts} impacts), keel_top detachments {detach}",
                  flush=True)


if __name__ == "__main__":
    main()
