"""What every sub-command of the command line shares: the user error, the log, the system
flags and saving a figure."""

from __future__ import annotations

import logging
from pathlib import Path

log = logging.getLogger("shipblock")

SYSTEM_FLAGS = {
    "ship_mass": ("--ship-mass", str, "ship mass M: kg, or with a unit: '20000 t'"),
    "block_mass": ("--block-mass", str, "mass of one keel block m: kg, or with a unit: '4 t'"),
    "n_blocks": ("--n-blocks", int, "number of keel blocks n"),
    "half_width": ("--half-width", str, "block half width B: m, or with a unit: 600mm"),
    "half_height": ("--half-height", str, "block half height H: m, or with a unit: 750mm"),
    "mu_s_ground": ("--mu-s-ground", float, "static friction blocks/ground"),
    "mu_k_ground": ("--mu-k-ground", float, "kinetic friction blocks/ground"),
    "mu_s_ship": ("--mu-s-ship", float, "static friction blocks/ship"),
    "mu_k_ship": ("--mu-k-ship", float, "kinetic friction blocks/ship"),
    "restitution": ("--restitution", float, "restitution theta_dot+/theta_dot- (default: system value)"),
    "impact_rule": ("--impact-rule", str, "impact rule: momentum (default), paper or plastic"),
}


class UserError(Exception):
    """An error caused by the user's input: reported in one line, no traceback."""


def _save_figure(make, path):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig = make()
    Path(path).parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=130)
    plt.close(fig)
