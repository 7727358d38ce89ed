r"""Contact loads: the interface forces of a run, as histories and as peak summaries.

The solver computes the forces at both interfaces at every step: :math:`(f_x, f_y)`, the force
of the ground on the blocks, and :math:`(F_x, F_y)`, that of the blocks on the ship
(:mod:`shipblock.equations`; totals over the :math:`n` blocks). A keel block is checked for
the load it carries, so shipblock reports them **per block** (divided by :math:`n`):

.. list-table::
   :header-rows: 1

   * - summary / EDP
     - unit
     - peak over the run of
   * - ``peak_ground_normal_force``
     - N
     - :math:`f_y / n`, a block on the dock floor
   * - ``peak_ground_friction_force``
     - N
     - :math:`|f_x| / n`
   * - ``peak_ship_normal_force``
     - N
     - :math:`F_y / n`, the ship on one block
   * - ``peak_ship_friction_force``
     - N
     - :math:`|F_x| / n`
   * - ``peak_ground_friction_utilisation``
     - 1
     - :math:`|f_x| / (\mu_{s1} f_y)`
   * - ``peak_ship_friction_utilisation``
     - 1
     - :math:`|F_x| / (\mu_{s2} F_y)`
   * - ``peak_corner_load``
     - N
     - :math:`f_y / n` while the blocks rock, when the whole load rests on their pivot edges
       (0 if they never rock)

At rest under gravity alone :math:`f_y/n = (M/n + m)g` and :math:`F_y/n = Mg/n`; under a
constant horizontal acceleration :math:`a` below slip the friction forces are
:math:`(M/n + m)a` and :math:`(M/n)a`; while an interface slides its utilisation is
:math:`\mu_k/\mu_s`. Utilisation 1 is the onset of slip: a run that never slid shows how close
it came.

The peaks are kept by the compiled solver (:mod:`shipblock.solver._force_sampling`) between the samples
too: exactly in rest and sliding (the forces are linear between samples there), at every
integration step's end and on both sides of every event while rocking (steps of at most one
sample; tests/test_loads.py measures the remaining error against the same run on a ten times
finer sampling of the same input). Impacts are instantaneous in the rigid-body model; their
impulses are not forces and are not part of the peaks.

:func:`interface_forces` recomputes the forces at the samples of a stored response (the
histories of :meth:`shipblock.SimulationResult.to_dataset`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numba import njit

from shipblock.equations import I_FX, I_FY, I_SFX, I_SFY, I_XB_DD, I_XS_DD, N_SOLVE_OUT, solve_mode
from shipblock.modes import MODE_FLAGS
from shipblock.system import P_G

__all__ = ["InterfaceForces", "LOAD_FIELDS", "interface_forces"]

#: Contact-load summaries of a run: name -> (units, long name). Forces are per block.
LOAD_FIELDS = {
    "peak_ground_normal_force": ("N", "peak normal force of the dock floor on one block"),
    "peak_ground_friction_force": ("N", "peak friction force of the dock floor on one block"),
    "peak_ship_normal_force": ("N", "peak normal force of one block on the ship"),
    "peak_ship_friction_force": ("N", "peak friction force of one block on the ship"),
    "peak_ground_friction_utilisation": (
        "1", "peak friction utilisation |f_x| / (mu_s f_y) of the blocks on the floor"),
    "peak_ship_friction_utilisation": (
        "1", "peak friction utilisation |F_x| / (mu_s F_y) of the ship on the blocks"),
    "peak_corner_load": ("N", "peak normal force on the pivot edge of one rocking block "
                              "(0: no rocking)"),
}


@dataclass(frozen=True)
class InterfaceForces:
    """Interface forces at the samples of a run, per block [N].

    Attributes
    ----------
    ground_normal, ground_friction : numpy.ndarray
        :math:`f_y/n` and :math:`f_x/n`, the dock floor on one block (friction positive to the
        right).
    ship_normal, ship_friction : numpy.ndarray
        :math:`F_y/n` and :math:`F_x/n`, one block on the ship.
    ground_utilisation, ship_utilisation : numpy.ndarray
        :math:`|f_x|/(\\mu_{s1} f_y)` and :math:`|F_x|/(\\mu_{s2} F_y)` [-].

    All NaN after a failure (the run stopped).
    """

    ground_normal: np.ndarray
    ground_friction: np.ndarray
    ship_normal: np.ndarray
    ship_friction: np.ndarray
    ground_utilisation: np.ndarray
    ship_utilisation: np.ndarray


@njit(cache=True)
def _forces_at_samples(p, mode, theta, omega, vb, vs, ax, ay, flags, out):  # pragma: no cover
    w = np.empty(N_SOLVE_OUT)
    for k in range(mode.shape[0]):
        m = mode[k]
        if m == 0:
            for i in range(4):
                out[i, k] = np.nan
            continue
        slip1, rock, slip2 = flags[m, 0], flags[m, 1], flags[m, 2]
        th = theta[k] if rock else 0.0
        om = omega[k] if rock else 0.0
        s = -1.0 if rock and (th < 0.0 or (th == 0.0 and om < 0.0)) else 1.0
        # slip directions: the velocity's; at a slip's very start (zero velocity) the one whose
        # acceleration agrees with it
        ok = False
        for c1 in range(2):
            sig1 = 1.0 if vb[k] > 0.0 else (-1.0 if vb[k] < 0.0 else (1.0 if c1 == 0 else -1.0))
            for c2 in range(2):
                sig2 = 1.0 if vs[k] > 0.0 else (-1.0 if vs[k] < 0.0 else (1.0 if c2 == 0 else -1.0))
                if solve_mode(p, slip1, rock, slip2, s, sig1, sig2, th, om, ax[k], p[P_G] + ay[k],
                              w):
                    ok = (not slip1 or vb[k] != 0.0 or sig1 * w[I_XB_DD] >= 0.0) and (
                        not slip2 or vs[k] != 0.0 or sig2 * w[I_XS_DD] >= 0.0)
                if ok:
                    break
            if ok:
                break
        if not ok:
            for i in range(4):
                out[i, k] = np.nan
            continue
        out[0, k] = w[I_FX]
        out[1, k] = w[I_FY]
        out[2, k] = w[I_SFX]
        out[3, k] = w[I_SFY]


def interface_forces(system, mode, theta, theta_dot, v_b, v_s, ax, ay) -> InterfaceForces:
    """Interface forces at the samples of a response, per block.

    Parameters
    ----------
    system : ShipBlockSystem
        The system simulated.
    mode : array_like of int
        Mode at each sample (0 after a failure).
    theta, theta_dot : array_like
        Rotation [rad] and angular velocity [rad/s].
    v_b, v_s : array_like
        Slip velocities of the blocks and the ship [m/s].
    ax, ay : array_like
        Ground acceleration at the samples, as used [m/s^2].

    Returns
    -------
    InterfaceForces
        The forces in the mode of each sample, from :func:`shipblock.equations.solve_mode`.
    """
    mode = np.ascontiguousarray(mode, dtype=np.int64)
    arrays = [np.ascontiguousarray(np.nan_to_num(x), dtype=float)
              for x in (theta, theta_dot, v_b, v_s, ax, ay)]
    out = np.empty((4, mode.size))
    _forces_at_samples(system.to_parameter_vector(), mode, *arrays, MODE_FLAGS, out)
    n = system.n_blocks
    fx, fy, sfx, sfy = out / n
    with np.errstate(invalid="ignore", divide="ignore"):
        util_g = np.where(fy > 0, np.abs(fx) / (system.mu_s_ground * fy), np.nan)
        util_s = np.where(sfy > 0, np.abs(sfx) / (system.mu_s_ship * sfy), np.nan)
    return InterfaceForces(fy, fx, sfy, sfx, util_g, util_s)
