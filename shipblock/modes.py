"""Modes of motion, transition events and failure kinds, as data.

The eight modes of the paper are the combinations of three independent interface states:

========  =====================  ================  ====================
mode      blocks on the ground   blocks            ship on the blocks
========  =====================  ================  ====================
1         stick                  at rest           stick
2         slide                  at rest           stick
3         stick                  rocking           stick
4         stick                  at rest           slide
5         slide                  at rest           slide
6         slide                  rocking           stick
7         stick                  rocking           slide
8         slide                  rocking           slide
========  =====================  ================  ====================

The solver never branches on the mode number: it works on the three flags
``(ground_slip, rocking, ship_slip)`` and the general equations of :mod:`shipblock.equations`.
"""

from __future__ import annotations

from enum import IntEnum

import numpy as np


class Mode(IntEnum):
    """Mode of motion, numbered as in the paper (Sect. 3.1 to 3.8)."""

    REST = 1
    BLOCK_SLIDE = 2
    BLOCK_ROCK = 3
    SHIP_SLIDE = 4
    BOTH_SLIDE = 5
    BLOCK_SLIDE_ROCK = 6
    BLOCK_ROCK_SHIP_SLIDE = 7
    ALL = 8

    @property
    def ground_slip(self) -> bool:
        """True when the blocks slide on the ground in this mode."""
        return bool(MODE_FLAGS[self.value, 0])

    @property
    def rocking(self) -> bool:
        """True when the blocks rock in this mode."""
        return bool(MODE_FLAGS[self.value, 1])

    @property
    def ship_slip(self) -> bool:
        """True when the ship slides on the blocks in this mode."""
        return bool(MODE_FLAGS[self.value, 2])

    @property
    def description(self) -> str:
        """Plain-language name of the mode (the paper's wording)."""
        return MODE_DESCRIPTIONS[self.value]


#: ``MODE_FLAGS[mode] = (ground_slip, rocking, ship_slip)``; row 0 is the "failed/stopped" code.
MODE_FLAGS = np.array(
    [
        [0, 0, 0],  # 0: no mode (after failure)
        [0, 0, 0],
        [1, 0, 0],
        [0, 1, 0],
        [0, 0, 1],
        [1, 0, 1],
        [1, 1, 0],
        [0, 1, 1],
        [1, 1, 1],
    ],
    dtype=np.int64,
)

#: ``MODE_NUMBER[ground_slip, rocking, ship_slip]`` is the paper's mode number.
MODE_NUMBER = np.zeros((2, 2, 2), dtype=np.int64)
for _m in range(1, 9):
    MODE_NUMBER[MODE_FLAGS[_m, 0], MODE_FLAGS[_m, 1], MODE_FLAGS[_m, 2]] = _m
del _m

MODE_DESCRIPTIONS = {
    0: "stopped (failure)",
    1: "rest",
    2: "blocks slide",
    3: "blocks rock",
    4: "ship slides",
    5: "blocks and ship slide",
    6: "blocks slide and rock",
    7: "blocks rock, ship slides",
    8: "blocks slide and rock, ship slides",
}


class EventKind(IntEnum):
    """What happened at an event."""

    START = 0  #: initial mode chosen at t = 0
    GROUND_SLIP_START = 1  #: block-ground friction exceeded the static limit
    GROUND_SLIP_STOP = 2  #: block slip velocity reached zero
    UPLIFT = 3  #: the moment criterion was met: rocking starts
    IMPACT = 4  #: theta reached zero while rocking: impact, pivot changes
    ROCKING_STOP = 5  #: impacts accumulated (Zeno) and rocking stopped
    SHIP_SLIP_START = 6  #: block-ship friction exceeded the static limit
    SHIP_SLIP_STOP = 7  #: ship slip velocity reached zero
    OVERTURNING = 8  #: ``|theta|`` reached theta_c = atan(B/H): failure
    SEPARATION = 9  #: a normal force reached zero: failure
    SOLVER_ERROR = 10  #: the integrator could not continue (reported, run stopped)
    JAM = 11  #: a slipping interface jammed: an impulsive friction force stopped its slip


class Failure(IntEnum):
    """Failure code of a run (0 when the run survived)."""

    NONE = 0
    SEPARATION = 1
    OVERTURNING = 2
    SOLVER_ERROR = 3


FAILURE_NAMES = {0: None, 1: "separation", 2: "overturning", 3: "solver_error"}
