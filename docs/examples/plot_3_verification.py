"""
Verification against closed forms
=================================

Three of the comparisons of the test suite (see :doc:`/verification`), re-run here with their
errors printed and plotted:

1. Newmark's rigid sliding block under a rectangular acceleration pulse (closed form);
2. Housner's free rocking block: impact times from an energy quadrature;
3. the energy balance on a random two-component record that visits all eight modes.

The references are computed in this script from first principles (numpy and
:func:`scipy.integrate.quad`), not from shipblock.
"""

import math

import matplotlib.pyplot as plt
import numpy as np
from scipy.integrate import quad

from shipblock import ShipBlockSystem, simulate

G0 = 9.80665

# %%
# Newmark sliding block
# ---------------------
# Blocks that cannot rock (B/H = 3) slide under a ship held by friction. A pulse of
# acceleration A lasting ``n_pulse`` samples (then a one-sample ramp to zero, since the input is
# linear between samples) gives the ground a velocity V and displacement D_p at the end of the
# pulse t_p. The blocks accelerate at mu G until they move with the ground, at
# t_stop = V / (mu G); their slip relative to the ground is then
# -(D_p + V (t_stop - t_p) - V^2 / (2 mu G)).


def ground_kinematics(a, dt):
    """Velocity and displacement at the last sample, exact for piecewise-linear a."""
    v = d = 0.0
    for a0, a1 in zip(a[:-1], a[1:], strict=True):
        d += v * dt + dt * dt / 6.0 * (2.0 * a0 + a1)
        v += 0.5 * dt * (a0 + a1)
    return v, d


mu, dt, n_pulse = 0.2, 0.01, 30
sliding = ShipBlockSystem(
    ship_mass=1e6, block_mass=6000.0, n_blocks=50, half_width=1.5, half_height=0.5,
    mu_s_ground=mu, mu_k_ground=mu, mu_s_ship=0.8, mu_k_ship=0.8,
)
amplitudes = np.linspace(0.25, 1.0, 7) * G0
simulated, closed_form = [], []
for A in amplitudes:
    a = np.zeros(400)
    a[: n_pulse + 1] = A
    res = simulate(sliding, a, None, dt)
    V, Dp = ground_kinematics(a[: n_pulse + 2], dt)
    t_stop = V / (mu * G0)
    closed_form.append(-(Dp + V * (t_stop - (n_pulse + 1) * dt) - V**2 / (2 * mu * G0)))
    simulated.append(res.x_b[-1])
simulated, closed_form = np.array(simulated), np.array(closed_form)
rel_err = np.abs(simulated - closed_form) / np.abs(closed_form)
print(f"Newmark pulse: max relative error of the final slip = {rel_err.max():.1e}")

fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(9, 3.5), constrained_layout=True)
ax1.plot(amplitudes / G0, -100 * closed_form, "-", color="0.4", label="closed form")
ax1.plot(amplitudes / G0, -100 * simulated, "o", color="tab:blue", label="shipblock")
ax1.set_xlabel("pulse amplitude A [g]")
ax1.set_ylabel("final block slip $-x_b$ [cm]")
ax1.legend()
ax2.semilogy(amplitudes / G0, np.maximum(rel_err, 1e-17), "o-", color="tab:blue")
ax2.set_xlabel("pulse amplitude A [g]")
ax2.set_ylabel("relative error [-]")
ax2.set_title("test tolerance: 1e-10")

# %%
# Housner free rocking
# --------------------
# A single block (the ship's mass is negligible) released from rest at 0.6 times its critical
# angle rocks freely. Energy conservation between impacts gives the time from an amplitude
# theta_k down to theta = 0 as a quadrature; at each impact the angular velocity is multiplied
# by Housner's restitution e = 1 - 1.5 sin^2(alpha), so the next amplitude follows from
# cos(alpha - theta_{k+1}) = cos(alpha) + e^2 (cos(alpha - theta_k) - cos(alpha)).

block = ShipBlockSystem(
    ship_mass=1e-6, block_mass=1000.0, n_blocks=1, half_width=0.2, half_height=1.0,
    mu_s_ground=10.0, mu_k_ground=10.0, mu_s_ship=10.0, mu_k_ship=10.0,
)
alpha, R = block.critical_angle, block.half_diagonal
J = block.inertia + block.block_mass * R**2  # inertia about the pivot [kg m^2]
W = block.block_mass * G0 * R  # [J]
e = block.effective_restitution


def quarter_time(theta_k):
    """Time from rest at theta_k to theta = 0 (substitution theta = theta_k (1 - u^2))."""

    def integrand(u):
        th = theta_k * (1 - u * u)
        de = math.cos(alpha - theta_k) - math.cos(alpha - th)
        return 2 * theta_k * u / math.sqrt(2 * W / J * de) if de > 0 else 0.0

    return quad(integrand, 0.0, 1.0, epsabs=1e-13, epsrel=1e-12, limit=200)[0]


theta0 = 0.6 * alpha
reference, th, t_ref = [], theta0, quarter_time(theta0)
for _ in range(12):
    reference.append(t_ref)
    th = alpha - math.acos(math.cos(alpha) + e * e * (math.cos(alpha - th) - math.cos(alpha)))
    t_ref += 2 * quarter_time(th)
reference = np.array(reference)

rock = simulate(block, np.zeros(800), None, 0.01, initial_state=(0, theta0, 0, 0, 0, 0),
                rtol=1e-11, atol=1e-13)
impacts = np.array([ev.time for ev in rock.events_of("impact")])[:12]
print(f"Housner rocking: e = {e:.6f}, max |impact time error| over 12 impacts = "
      f"{np.abs(impacts - reference).max():.1e} s")

fig, ax = plt.subplots(figsize=(9, 3.5), constrained_layout=True)
ax.plot(rock.time, rock.theta / alpha, color="tab:orange", lw=1.0, label="shipblock")
ax.plot(reference, np.zeros_like(reference), "k|", ms=14, mew=1.5,
        label="impact times, quadrature")
ax.set_xlim(0, reference[-1] + 0.2)
ax.set_xlabel("time [s]")
ax.set_ylabel(r"$\theta / \alpha$ [-]")
ax.set_title("test tolerance on impact times: 1e-8 s")
ax.legend(loc="upper right")

# %%
# Energy balance in all eight modes
# ---------------------------------
# With T the kinetic and V the potential energy, W_in the work of the ground motion, D the
# friction dissipation and E_imp the impact losses, every run satisfies
# Delta(T + V) = W_in - D - E_imp. On a random record with a vertical component, with blocks
# whose friction is close to their slenderness, all eight modes occur; the residual stays at
# the level of the integration tolerance.

rng = np.random.default_rng(3)
kernel = np.hanning(15) / np.hanning(15).sum()
dt = 0.005
a = np.convolve(rng.normal(0, 7.5, 3000), kernel, mode="same")
ay = np.convolve(rng.normal(0, 6.0, 3000), kernel, mode="same")
stack = ShipBlockSystem(
    ship_mass=2e5, block_mass=2000.0, n_blocks=20, half_width=0.25, half_height=1.0,
    mu_s_ground=0.26, mu_k_ground=0.2, mu_s_ship=0.3, mu_k_ship=0.2,
)
res = simulate(stack, a, ay, dt, rtol=1e-12, atol=1e-14)
visited = [m for m in range(1, 9) if res.summary[f"time_in_mode_{m}"] > 0]
ok = np.isfinite(res.energy.residual)
scale = np.abs(res.energy.input_work[ok]).max()
rel = np.abs(res.energy.residual[ok]) / scale
print(f"energy balance: modes visited {visited}, max |residual| / max |W_in| = {rel.max():.1e}")

fig, (ax1, ax2) = plt.subplots(2, 1, sharex=True, figsize=(9, 5), constrained_layout=True)
E = res.energy
ax1.plot(res.time, E.input_work / 1e3, label="input work $W_{in}$")
ax1.plot(res.time, E.friction / 1e3, label="friction $D$")
ax1.plot(res.time, E.impact / 1e3, label="impacts $E_{imp}$")
ax1.plot(res.time, (E.kinetic + E.potential) / 1e3, label="$T + V$")
ax1.set_ylabel("energy [kJ]")
ax1.legend(ncol=2, fontsize=8)
ax2.semilogy(res.time[ok], np.maximum(rel, 1e-18), color="0.3", lw=0.8)
ax2.axhline(1e-8, color="red", ls="--", lw=0.8, label="test tolerance")
ax2.set_ylabel("|residual| / max $|W_{in}|$ [-]")
ax2.set_xlabel("time [s]")
ax2.legend()
plt.show()
