"""A small seeded random campaign of the dock section (the full one: tests/tools/section_campaign.py):
random docks and motions run without an exception other than a refused dock, with finite
results, the energy balance within 1e-5, non-negative losses and friction inside its cone."""

import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent / "tools"))
from section_campaign import run  # noqa: E402


def test_random_docks_and_motions():
    out = run(12, seed=2029)
    assert out["ran"] >= 6  # most random docks are accepted
    assert out["worst_energy"] < 1e-5
    assert out["worst_cone_excess"] < 1e-6
