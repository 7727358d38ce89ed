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


@njit(cache=True, forceinline=False, _nrt=False)
def one_sided_motion(ax, ay, has_ay, sh, sv, k, tau, lead, dt):
    """Scaled ground acceleration ``lead`` after t_k + tau along the input's line there [m/s^2].

    The mode selection's one-sided limit of the input after an event: on the line of the
    sample interval the event is in, extrapolated past its end sample when the event is
    within ``lead`` of it (and not on it, to within 1e-12 of the interval). Read on the next
    interval, the probe would see the input after its kink at the sample instead of the
    input's course after the event (issue 32: a friction margin that was falling to the sample
    looked held from just before it, and the event fired again and again as the margin went on
    falling to the sample).
    """
    if tau + lead <= dt or dt - tau <= 1e-12 * dt or k >= ax.shape[0] - 1:
        return ground_motion_at(ax, ay, has_ay, sh, sv, k, tau + lead, dt)
    f = (tau + lead) / dt
    a0 = sh * ax[k]
    a = a0 + (sh * ax[k + 1] - a0) * f
    b = 0.0
    if has_ay:
        b0 = sv * ay[k]
        b = b0 + (sv * ay[k + 1] - b0) * f
    return a, b
