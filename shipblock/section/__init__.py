"""The dock section: a ship that sways, heaves and rolls on a keel-block line and side-block lines
with compliant timber caps (issue 29; ``docs/theory/section.md``)."""

from __future__ import annotations

from shipblock.section.parameters import (
    LONG_TON_FORCE,
    NAVY_BLOCK,
    Block,
    BlockLine,
    Cap,
    DockSection,
    Ship,
    Wind,
)
from shipblock.section.simulate import (SectionResult, SectionRunner, simulate_section,
                                        simulate_section_batch)

__all__ = ["LONG_TON_FORCE", "NAVY_BLOCK", "Block", "BlockLine", "Cap", "DockSection",
           "SectionResult", "SectionRunner", "Ship", "Wind", "simulate_section",
           "simulate_section_batch"]
