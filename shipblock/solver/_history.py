"""History columns of the solver: the state, its energies and the mode at a sample (compiled)."""

from __future__ import annotations

from numba import njit

from shipblock.equations import kinetic_energy, potential_energy
from shipblock.solver._layout import H_KIN, H_POT, MS_ROCK, MS_S, N_STATE, Y_OM, Y_TH, Y_VB, Y_VS


@njit(cache=True, forceinline=False, _nrt=False)
def store_sample(p, ms, y, hist, modes, k, mode):
    """Write the state, kinetic and potential energy and mode number ``mode`` of sample ``k``.

    ``mode`` is 0 after a failure. (A block of rest samples, all the same column, is written
    row by row by :mod:`~shipblock.solver._closed_form`.)
    """
    for i in range(N_STATE):
        hist[i, k] = y[i]
    s = float(ms[MS_S]) if ms[MS_ROCK] else 1.0
    hist[H_KIN, k] = kinetic_energy(p, y[Y_TH], s, ms[MS_ROCK], y[Y_VB], y[Y_OM], y[Y_VS])
    # theta = 0 unless rocking: the potential energy's reference, without a cosine
    hist[H_POT, k] = potential_energy(p, y[Y_TH]) if ms[MS_ROCK] else 0.0
    modes[k] = mode
