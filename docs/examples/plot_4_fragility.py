"""
A small fragility curve
=======================

A multiple-stripe analysis with the six shipped South Napa records: each processed record is
scaled to ten levels of peak ground acceleration (the vertical by the same factor), all sixty
runs go through :func:`shipblock.simulate_batch` in one compiled, parallel call, a limit state
turns each run's summary into exceeded / not exceeded, and
:func:`shipblock.fragility.fit.fit_msa` fits a lognormal fragility curve by maximum likelihood.

Six records are far too few for a real study; the point is the sequence of calls.
"""

import matplotlib.pyplot as plt
import numpy as np

from shipblock import ShipBlockSystem, load_catalogue, simulate_batch
from shipblock.fragility import (
         evaluate_limit_states,
         fit_msa,
         lognormal_fragility,
         parse_limit_states,
)
from shipblock.intensity import pga
from shipblock.processing import process_motion
from shipblock.units import STANDARD_GRAVITY as G0

motions = [process_motion(entry.read()) for entry in load_catalogue().values()]
records = [(m.horizontal, m.vertical) for m in motions]
dts = [m.dt for m in motions]
pga_records = np.array([pga(m.horizontal, m.dt) for m in motions])  # [m/s^2]

# %%
# Cases are rows ``(record index, system index, horizontal factor, vertical factor)``.
system = ShipBlockSystem.example()
levels = np.linspace(0.1, 1.0, 10) * G0  # target PGA [m/s^2]
cases = [(r, 0, lv / pga_records[r], lv / pga_records[r])
         for r in range(len(records)) for lv in levels]
summary = simulate_batch(system, records, dts, cases)
summary = {k: v.reshape(len(records), len(levels)) for k, v in summary.items()}
print("peak ship slip [cm], records x PGA levels:")
print(np.round(100 * summary["peak_ship_slip"], 1))

# %%
# The limit state, as it would be written in a pipeline file's ``[[limit_states]]`` table:
# the ship slides more than 2 cm on the blocks. A run that failed (separation, overturning)
# would count as exceeding it.
(limit_state,) = parse_limit_states(
    [{"name": "ship_slip_2cm", "edp": "peak_ship_slip", "threshold": 0.02}]
)
outcome = evaluate_limit_states([limit_state], summary)["ship_slip_2cm"]
fit = fit_msa(outcome.exceeded, levels / G0, outcome.valid)
print(f"median = {fit.median:.3f} g, beta = {fit.beta:.3f} ({fit.method}, n = {fit.n})")

# %%
# Observed fractions at each stripe and the fitted curve.
fig, ax = plt.subplots(figsize=(6, 4), constrained_layout=True)
fraction = outcome.exceeded.sum(axis=0) / outcome.valid.sum(axis=0)
ax.plot(levels / G0, fraction, "o", label="fraction of records exceeding")
x = np.linspace(0.01, 1.2, 200)
ax.plot(x, lognormal_fragility(x, fit.median, fit.beta), label="lognormal MLE fit")
ax.set_xlabel("PGA [g]")
ax.set_ylabel("P(ship slip > 2 cm) [-]")
ax.legend()
plt.show()
