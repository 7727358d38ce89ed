"""Ground input of the solver: the record's samples, scaled, linear in time between them."""

from __future__ import annotations

from numba import njit


@njit(cache=True, forceinline=False, _nrt=False)
def ground_motion_at(ax, ay, has_ay, sh, sv, k, tau, dt):
    """Scaled ground acceleration (a, ay) at t_k + tau, linear between samples [m/s^2]."""
    n = ax.shape[0]
    while tau > dt and k < n - 2:
        tau -= dt
        k += 1
    if k >= n - 1:
        b = sv * ay[n - 1] if has_ay else 0.0
        return sh * ax[n - 1], b
    # scale the samples first, then interpolate: the same arithmetic as a pre-scaled record
    f = tau / dt
    a0 = sh * ax[k]
    a = a0 + (sh * ax[k + 1] - a0) * f
    b = 0.0
    if has_ay:
        b0 = sv * ay[k]
        b = b0 + (sv * ay[k + 1] - b0) * f
    return a, b
